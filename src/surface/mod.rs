//! Surfaces to print on and to print over, and the tool that must not run into them: the
//! vocabulary the curved and conform stages share.
//!
//! Place in the pipeline: vocabulary, built from a placed mesh or a scan before the stages that
//! follow a surface, and from a stage's tool settings.
//!
//! - [`height_field`]: a mesh's upward-facing triangles in a uniform xy grid — the exact top
//!   height and slope at (x, y), the triangle edges a segment crosses ([`HeightField`]); the
//!   curved tops and curved-layer FFF project their paths onto it.
//! - [`mesh`]: a scanned surface as a queryable mesh (parry): top by ray cast, closest point,
//!   normal, built from a mesh or a point cloud ([`Surface`]); conformal printing and gap
//!   compensation ask it, and it answers its many height queries from a [`HeightField`].
//! - [`tool`]: the tool as one solid of stacked discs, cylinders and cones above its tip
//!   ([`ToolSolid`]) — the FFF head of the curved stages and the dispensing nozzle of conform
//!   are two values of it — with its radius, floor, widest and top queries.
//! - [`replay`]: the one replay walk ([`walk`]): tip positions sampled along moves, beads or
//!   paths, each asked against an [`Obstacle`] (a scanned surface, or material printed so far),
//!   what each stretch printed laid down after it.
//! - [`clearance`]: the exact highest point of the surface inside a disc (the tip, a tilted
//!   tool's cross-section) or a cone's annulus, per triangle from the [`HeightField`]'s grid.
//! - [`contact`]: the tool solid against a scanned surface (tip disc, whole solid vertical or
//!   along a tilted axis), and the [`Surface`] as an obstacle of the walk.

pub mod clearance;
pub mod contact;
pub mod height_field;
pub mod mesh;
pub mod replay;
pub mod tool;

pub use height_field::{HeightField, SurfaceHit, SurfaceTriangle, densify_path};
pub use mesh::{CloudInfo, MAX_EXTENT, Surface, SurfaceError};
pub use replay::{Hit, Next, Obstacle, Sample, Spacing, Stretch, walk};
pub use tool::{Piece, PieceShape, ToolPart, ToolSolid};
