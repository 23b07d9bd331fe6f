//! Shared geometry vocabulary used by every pipeline stage.
//!
//! 2D work (layer regions, offsets, booleans) is done in scaled integers where one unit is one
//! nanometre, so boolean and offset operations are exact; 3D work (meshes, curved and conformal
//! paths) is done in `f64` millimetres. Convert between the two only through [`scaled`] and
//! [`unscaled`].

mod clip;
mod point;
mod polygon;
mod segment;
mod tolerances;
mod tool_frame;
mod transform;

pub use clip::{
    Cap, FillRule, Join, clip_intervals, clip_polylines, difference, intersection, offset,
    polygons_to_expolygons, stroke, union,
};
pub use point::{Coord, Point2, Point3, Vector3, scaled, unscaled};
pub use polygon::{ExPolygon, Polygon, Polyline, polyline_length};
pub use segment::{segment_distance, segment_distance2, segment_param};
pub use tolerances::{Tolerance, Tolerances};
pub use tool_frame::tool_frame;
pub use transform::{BoundingBox, Transform};
