//! Object File Format (OFF) mesh reader.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
