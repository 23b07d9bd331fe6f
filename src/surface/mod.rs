//! Surfaces to print on and to print over: the vocabulary the curved and conform stages share.
//!
//! Place in the pipeline: vocabulary, built from a placed mesh or a scan before the stages that
//! follow a surface.
//!
//! - [`height_field`]: a mesh's upward-facing triangles in a uniform xy grid — the exact top
//!   height and slope at (x, y), the triangle edges a segment crosses ([`HeightField`]); the
//!   curved tops and curved-layer FFF project their paths onto it.
//! - [`mesh`]: a scanned surface as a queryable mesh (parry): top by ray cast, closest point,
//!   normal, built from a mesh or a point cloud ([`Surface`]); conformal printing and gap
//!   compensation ask it, and it answers its many height queries from a [`HeightField`].

pub mod height_field;
pub mod mesh;

pub use height_field::{HeightField, SurfaceHit, SurfaceTriangle, densify_path};
pub use mesh::{CloudInfo, Surface, SurfaceError};
