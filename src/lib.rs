//! conduit turns 3D models and circuit designs into machine programs for printed electronics and
//! non-planar printing.
//!
//! The pipeline runs one way:
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
//! - [`config`]: the one TOML configuration (printer, tools, slicing), PrusaSlicer `.ini` import.
//! - [`slice`]: meshes cut into layers of polygons with holes.
//! - [`conform`]: conformal printing — 2D designs laid onto scanned surfaces (registration,
//!   projection, nozzle-aware corrections, deposit report).
//! - [`curved`]: non-planar top surfaces — top solid layers of gentle top surfaces projected onto
//!   the mesh, with head collision checks (`--curved tops`).
//! - [`region`]: perimeters, top/bottom skins, infill patterns and skirt per layer.
//! - [`program`]: toolpaths and events in print order — what every writer consumes.
//! - [`emit`]: G-code (Marlin, RepRapFirmware, Klipper) from a program.
//! - [`check`]: replaying any G-code to find problems and measure it.
//! - [`jet`]: aerosol-jet toolpaths from 2D designs — corner fillets, shutter gaps, direction
//!   blocks, the corner accumulation model (`conduit jet`).
//! - [`pipeline`]: the stages above as one walk, scene to G-code.
//! - [`postprocess`]: slicer plugin mode — another slicer's G-code read into layers (z, widths,
//!   extrusions, printed regions) to be edited in place.
//!
//! The `conduit` binary (`src/main.rs`, `src/cli/`) turns command lines into calls of these modules.

pub mod check;
pub mod circuit;
pub mod config;
pub mod conform;
pub mod curved;
pub mod emit;
pub mod geom;
pub mod jet;
pub mod mesh;
pub mod pipeline;
pub mod postprocess;
pub mod program;
pub mod region;
pub mod route;
pub mod scene;
pub mod slice;
