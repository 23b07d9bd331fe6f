//! Aerosol-jet toolpaths for free-standing micro-walls: corner fillets by a rule table, sharp
//! corners split, shutter gaps that move every layer, direction reversed every block of
//! layers, structures interleaved layer by layer, and the corner accumulation model.
//!
//! Place in the pipeline: a design (2D polylines) → **jet** → Program → G-code (written by the
//! project's G-code writer, [`crate::emit::gcode`], in its switched-tool style). The stages, one
//! file each:
//!
//! 1. [`design`]: SVG or DXF → [`design::Outline`]s (one structure each).
//! 2. [`fill`]: outlines → lines (walls, contour-parallel loops or a serpentine).
//! 3. [`corners`]: the angle of each corner and the rule table (`jet.corner_rules`).
//! 4. [`fillet`]: tangent arcs per the rules, shrunk (and reported) where segments are short;
//!    corners below `jet.split_below` split the line. Shapes are [`path::Chain`]s of lines and
//!    arcs.
//! 5. [`contour`]: closed contours get a gap whose place cycles over straight stretches.
//! 6. [`schedule`]: layers, direction blocks, structures in turn.
//! 7. [`program`]: the layers as a [`crate::program::Program`]: every path a toolpath of lines
//!    and arcs between a shutter switch-on and switch-off (with the shutter lead time).
//! 8. [`model`] and [`report`]: the accumulation model and the JSON report (with the writer's
//!    totals, [`JetStats`]).
//!
//! Lengths are millimetres (the CLI converts from micrometres); the 2D work here is float
//! geometry on arcs (as for curved paths), with the fills' offsets and clipping done by the
//! project's integer-grid operations.

pub mod contour;
pub mod corners;
pub mod design;
pub mod fill;
pub mod fillet;
pub mod model;
pub mod path;
pub mod program;
pub mod report;
pub mod schedule;
pub mod settings;

pub use design::{DesignError, Outline};
pub use model::{ModelInput, ModelResult, accumulation};
pub use program::program;
pub use report::{JetReport, JetStats};
pub use schedule::{JetLayer, JetParams, Structure};
pub use settings::{JetFill, JetSettings};

use crate::program::machine::{Tool, ToolKind};

/// Why a jet job cannot run.
#[derive(Debug, thiserror::Error)]
pub enum JetError {
    /// A design file could not be read.
    #[error(transparent)]
    Design(#[from] DesignError),
    /// Width, layer height or layer count out of range.
    ///
    /// How to fix: give a positive width and layer height and at least one layer.
    #[error("{0}")]
    Params(String),
    /// `jet.tool` is not a paste tool of the config.
    ///
    /// How to fix: point `jet.tool` at a `[tools.N]` table with `kind = "paste"` (the default
    /// config's tool 1), or add one.
    #[error("jet.tool = {tool}: {message}")]
    Tool {
        /// The tool number.
        tool: usize,
        /// What is wrong.
        message: String,
    },
}

/// A planned job: structures and layers.
#[derive(Debug, Clone, PartialEq)]
pub struct JetJob {
    /// The structures, prepared.
    pub structures: Vec<Structure>,
    /// The layers in print order.
    pub layers: Vec<JetLayer>,
}

/// Checks the parameters and the jet tool (`settings.tool`, one of `tools`).
pub fn validate(
    params: &JetParams,
    settings: &JetSettings,
    tools: &[Tool],
) -> Result<(), JetError> {
    if !(params.width.is_finite() && params.width > 0.0) {
        return Err(JetError::Params(format!(
            "line width must be > 0, got {} mm",
            params.width
        )));
    }
    if !(params.layer_height.is_finite() && params.layer_height > 0.0) {
        return Err(JetError::Params(format!(
            "layer height must be > 0, got {} mm",
            params.layer_height
        )));
    }
    if params.layers == 0 {
        return Err(JetError::Params("at least one layer is needed".to_owned()));
    }
    let tool = settings.tool;
    match tools.get(tool) {
        None => Err(JetError::Tool {
            tool,
            message: format!("the config defines only {} tool(s)", tools.len()),
        }),
        Some(t) if t.kind != ToolKind::Paste => Err(JetError::Tool {
            tool,
            message: "an aerosol jet is switched by its shutter: the tool must be kind = \"paste\""
                .to_owned(),
        }),
        Some(_) => Ok(()),
    }
}

/// Plans a job: outlines → structures → layers.
pub fn plan(
    outlines: &[Outline],
    params: &JetParams,
    settings: &JetSettings,
    tools: &[Tool],
) -> Result<JetJob, JetError> {
    validate(params, settings, tools)?;
    let structures = schedule::prepare(outlines, params, settings);
    let layers = schedule::schedule(&structures, params, settings);
    Ok(JetJob { structures, layers })
}
