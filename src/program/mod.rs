//! The Program: ordered layers of toolpaths and events, what every machine-program writer
//! consumes.
//!
//! Place in the pipeline: Scene → slice → regions → **program** → emit. This stage turns each
//! layer's regions (2D centrelines in nanometres, by role) into 3D [`Toolpath`]s with a role,
//! tool, width, height and speed, orders them to keep travel short, and puts [`Event`]s (tool
//! changes, pick-and-place, pauses) between them. Writers (`emit`) never look further upstream.
//!
//! - [`toolpath`]: the types: [`Role`], [`Toolpath`], [`Event`], [`Layer`], [`Program`].
//! - [`extrusion`]: the flow model (bead cross-section, E per millimetre, paste tools).
//! - [`build`]: regions → Program ([`build_program`]).
//! - [`order`]: travel ordering (nearest neighbour, then 2-opt / or-opt, deterministic).

pub mod build;
pub mod extrusion;
pub mod machine;
pub mod order;
pub mod toolpath;

pub use build::{
    LayerExtras, ObjectLayers, ProgramParams, RoleSpeeds, ToolPathParams, build_program,
    build_program_with,
};
pub use extrusion::{BeadShape, Feed, bead_area, e_per_mm, filament_area};
pub use order::{Group, OrderParams, SeamRule, order_groups, order_paths, travel_length};
pub use toolpath::{Event, Layer, LayerItem, Program, Role, Toolpath};
