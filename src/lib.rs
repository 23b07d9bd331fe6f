//! conduit turns 3D models and circuit designs into machine programs for printed electronics and
//! non-planar printing.
//!
//! Every command is one walk along one line; nothing downstream reaches back upstream
//! (`ARCHITECTURE.md` is the map):
//!
//! ```text
//! files ──read──► Scene, Circuit, Placement, Surface, Design ──stages──► Program ──emit──► files
//! ```
//!
//! **Vocabulary** — the data every stage speaks:
//! - [`geom`]: scaled-integer 2D points (1 nm), f64 3D points, polygons with holes, transforms,
//!   tolerances, tool frames.
//! - [`mesh`]: the indexed triangle mesh with validation and repair.
//! - [`scene`]: every supported file read into a [`scene::Scene`] (or a circuit, a point cloud,
//!   a G-code listing), and meshes written back out.
//! - [`program`]: toolpaths and events in print order — what every writer consumes — and the
//!   machine they run on.
//! - [`surface`]: height fields and scanned surfaces (mesh queries on parry) that the curved
//!   and conform stages follow.
//! - [`config`]: the one TOML configuration (and PrusaSlicer `.ini` import) that the walks turn
//!   into each stage's parameters.
//!
//! **Stages** — each a function from its parameters and inputs to data:
//! - [`slice`]: meshes cut into layers of polygons with holes.
//! - [`region`]: perimeters, gap fill, skins, bridges, infill patterns, skirt and cavities per
//!   layer.
//! - [`circuit`]: the circuit model (EAGLE circuits, placements, rubberbands) and the
//!   electronics stage (parts placed, cavities carved, wires routed, pick-and-place records).
//! - [`route`]: weighted A* trace routing on per-layer perimeter graphs.
//! - [`curved`]: non-planar top surfaces over a planar core; `clfff`: curved-layer FFF.
//! - [`toolpaths`]: regions and the other stages' per-layer contributions → [`program::Program`]
//!   (roles, widths, speeds, travel order, tool changes).
//! - [`conform`]: 2D designs laid onto scanned surfaces — registration, projection,
//!   nozzle-aware corrections, tool orientation, deposit report.
//! - [`robot`]: robot set-up and calibration — tool centre point, frame registration, gap
//!   compensation, calibration patterns.
//! - [`jet`]: aerosol-jet toolpaths — corner fillets, shutter gaps, direction blocks, the
//!   corner accumulation model.
//! - [`emit`]: writers — G-code (Marlin, RepRapFirmware, Klipper), robot programs, previews,
//!   routing views.
//! - [`check`]: replaying any G-code to find problems and measure it.
//! - [`view`]: the 3D page of G-code, model and circuit (`conduit view`, `conduit studio`).
//! - [`postprocess`]: slicer plugin mode — another slicer's G-code read into layers, the circuit
//!   planned on them, the file rewritten, verified and reported.
//!
//! **Walks** — one library call per command:
//! - [`pipeline`]: scene to G-code (planar, curved tops, curved-layer FFF), scene to routing
//!   view, scan and design to a conformal program ([`pipeline::conform`]), another slicer's
//!   G-code with its settings read and a circuit built in ([`pipeline::postprocess`]).
//!
//! The `conduit` binary (`src/main.rs`, `src/cli/`, behind the default `cli` feature) parses
//! command lines, calls one walk, writes files and prints.

// Vocabulary.
pub mod interrupt;
pub mod geom;
pub mod mesh;
pub mod scene;
pub mod program;
pub mod surface;
pub mod config;

// Stages.
pub mod slice;
pub mod region;
pub mod circuit;
pub mod route;
pub mod curved;
pub mod toolpaths;
pub mod conform;
pub mod robot;
pub mod jet;
pub mod emit;
pub mod check;
pub mod view;
pub mod postprocess;

// Walks.
pub mod pipeline;
