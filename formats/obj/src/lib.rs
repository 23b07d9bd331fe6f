//! Wavefront OBJ reader (via tobj) and writer.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
