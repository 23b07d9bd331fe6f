//! The 3D view of a job: one self-contained HTML page that draws G-code toolpaths in 3D with
//! three.js, with the model and the circuit when given.
//!
//! Place in the pipeline: the end of the line, after `check`. It reads G-code (conduit's or any
//! other slicer's, planar, curved, conformal or jetted) replayed and measured by [`crate::check`],
//! the placed circuit ([`crate::circuit`]) and meshes, and never reaches back into slicing or
//! the config: the walks (`cli/`) hand it what it draws.
//!
//! - [`job`]: one G-code file as line buffers per feature role and tool, layers with times,
//!   retraction and z-hop markers, part events, figures and warnings.
//! - [`overlay`]: the model's meshes and the circuit (parts, pads, cavities, unrouted wires).
//! - [`encode`]: the compact number streams the page carries (µm varint deltas in base64).
//! - [`page`]: the HTML with three.js and the page's modules (`web/`) inlined.
//! - [`studio`]: the placement the studio edits, its poses and the parts the checks flag.

pub mod encode;
pub mod job;
pub mod overlay;
pub mod page;
pub mod studio;

pub use job::{JobView, job_of, job_view};
pub use overlay::{CircuitView, MeshView, circuit_of, circuit_view, mesh_views};
pub use page::{Entry, ViewData, page, page_for};
