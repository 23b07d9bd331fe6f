//! conduit turns 3D models and circuit designs into machine programs for printed electronics and
//! non-planar printing.
//!
//! The pipeline runs one way (see `design.md` in the project notes):
//!
//! ```text
//! files ──read──► Scene (meshes, transforms) ──slice──► Layers ──► Program ──emit──► G-code, reports
//! ```
//!
//! - [`geom`]: the shared geometry vocabulary (scaled-integer 2D points, f64 3D points, transforms,
//!   tolerances).
//! - [`mesh`]: the indexed triangle mesh with validation and repair.
//! - [`scene`]: reading every supported file into a [`scene::Scene`] (or a circuit, a point cloud,
//!   a G-code listing) and writing meshes back out.
//!
//! The `conduit` binary (`src/main.rs`, `src/cli/`) turns command lines into calls of these modules.

pub mod check;
pub mod config;
pub mod emit;
pub mod geom;
pub mod mesh;
pub mod program;
pub mod region;
pub mod scene;
pub mod slice;
