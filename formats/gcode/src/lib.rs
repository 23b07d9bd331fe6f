//! G-code tokenizer that round-trips every line byte for byte.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
