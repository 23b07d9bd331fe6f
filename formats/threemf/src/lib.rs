//! 3MF (3D Manufacturing Format) core-spec reader and writer.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
