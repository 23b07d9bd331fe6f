//! EAGLE 6-9 schematic (.sch) and board (.brd) reader.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
