//! Slicing: meshes → layers of 2D regions.
//!
//! Place in the pipeline: Scene → **slice** → regions → Program → G-code. This stage takes each
//! placed object mesh of the scene and cuts it into horizontal layers ([`layer_schedule`] says
//! where); every layer's regions ([`SlicedLayer::islands`], ExPolygons in nanometre coordinates)
//! feed the `region` stage (perimeters, infill, cavities, channels) and routing.
//!
//! - [`planar`]: mesh → one set of islands per planar layer ([`slice_mesh`]).
//! - `schedule`: the layer heights ([`SliceParams`], [`LayerZ`], [`layer_schedule`]).
//!
//! Curved-layer and non-planar slicing (`curved.rs`, `nonplanar.rs` in the design) will live here
//! too.

mod chain;
pub mod planar;
mod schedule;

pub use planar::{DEFAULT_MAX_GAP_MM, SliceReport, SlicedLayer, slice_mesh, slice_mesh_with_gap};
pub use schedule::{LayerZ, SliceParams, SliceParamsError, layer_schedule};
