//! The Program: ordered layers of toolpaths and events, what every machine-program writer
//! consumes, and the machine it runs on.
//!
//! Place in the pipeline: vocabulary. The toolpaths stage (`crate::toolpaths`) builds a
//! Program from each layer's regions and the per-layer contributions of the other stages
//! ([`LayerExtras`]); the curved, conform and jet stages build theirs directly; writers (`emit`)
//! consume it and never look further upstream.
//!
//! - [`toolpath`]: the types: [`Role`], [`Toolpath`], [`Event`], [`Layer`], [`Program`], and
//!   what a layer gets besides its regions ([`LayerExtras`]).
//! - [`segment`]: planar line and arc [`Segment`]s, the moves of toolpaths with arcs, and their
//!   geometry (length, cutting, starting direction, chords).
//! - [`extrusion`]: the flow model (bead cross-section, E per millimetre, paste tools).
//! - [`machine`]: the printer, its tools and the part-placement commands.
//! - [`motion`]: the motion model behind every time estimate (header, cooling, `check`).

pub mod extrusion;
pub mod machine;
pub mod motion;
pub mod segment;
pub mod toolpath;

pub use extrusion::{BeadShape, Feed, bead_area, e_per_mm, filament_area};
pub use segment::Segment;
pub use toolpath::{Event, Layer, LayerExtras, LayerInsert, LayerItem, Program, Role, Toolpath};
