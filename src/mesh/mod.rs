//! The indexed triangle mesh every reader produces and every slicer consumes, with validation
//! ([`topology`]) and repair ([`repair`]).
//!
//! Place in the pipeline: `scene` builds meshes from files; `slice` reads them. Coordinates are
//! `f64` millimetres; source units are converted on read.

mod edges;
mod indexed;
pub mod repair;
pub mod topology;

pub use indexed::Mesh;
pub use repair::RepairReport;
pub use topology::{Orientation, TopologyReport};
