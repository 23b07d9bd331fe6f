//! STL reader and writer (ASCII and binary).
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
