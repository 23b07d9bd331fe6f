//! Point cloud readers: PLY (ASCII and binary) and XYZ.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
