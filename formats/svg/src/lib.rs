//! SVG path reader for 2D designs: shapes, transforms and curves flattened to polylines.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
