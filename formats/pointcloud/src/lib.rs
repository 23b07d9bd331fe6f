//! Point cloud readers: PLY (ASCII and binary) and XYZ.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
//! Both readers produce a [`PointCloud`]: points with optional per-point normals and colours, plus
//! the PLY faces (fan-triangulated) when the file has them, so a scanned or exported surface can
//! be used either as a cloud or as a mesh by `conform`.
//!
//! * [`read_ply`] ([`ply`]): `ascii`, `binary_little_endian` and `binary_big_endian`; `vertex`
//!   with `x`/`y`/`z` of any numeric type, optional `nx`/`ny`/`nz` and `red`/`green`/`blue`;
//!   `face` with a `vertex_indices` (or `vertex_index`) list; every other element and property,
//!   lists included, is skipped.
//! * [`read_xyz`] ([`xyz`]): `x y z [extra columns]` per line; columns 4–6 become colours or
//!   normals by the rule documented in [`xyz`].
//!
//! Both are bounded: no buffer is sized from a count the file has not backed with data.
//!
//! ```
//! let cloud = conduit_pointcloud::read_xyz(b"# x y z r g b\n0 0 0 255 0 0\n1 2 3 0 128 255\n")?;
//! assert_eq!(cloud.points, vec![[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]);
//! assert_eq!(cloud.colors, Some(vec![[255, 0, 0], [0, 128, 255]]));
//! # Ok::<(), conduit_pointcloud::XyzError>(())
//! ```

pub mod ply;
pub mod xyz;

pub use ply::{PlyError, read_ply};
pub use xyz::{XyzError, read_xyz};

/// Points with optional per-point attributes, and the faces of a PLY mesh if it has any.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    /// Point positions in file units.
    pub points: Vec<[f64; 3]>,
    /// Per-point normals as written in the file (not normalised), same length as `points`.
    pub normals: Option<Vec<[f64; 3]>>,
    /// Per-point colours, 0..=255 per channel, same length as `points`.
    pub colors: Option<Vec<[u8; 3]>>,
    /// PLY faces as 0-based indices into `points`, fan-triangulated; empty for XYZ.
    pub triangles: Vec<[u32; 3]>,
}

#[cfg(test)]
mod tests;
