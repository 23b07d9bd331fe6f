//! Slicer plugin mode: read another slicer's G-code, understand its layers, and edit it in place.
//!
//! Place in the pipeline: the other front door. Instead of slicing a model, conduit takes the
//! G-code of a host slicer (PrusaSlicer, SuperSlicer, OrcaSlicer, Cura, Slic3r, or any G-code
//! with extrusion moves) that calls it as a post-processing script, and adds what the host cannot
//! (cavities, channels and conductive traces for a circuit, part placement events), leaving every
//! other line byte for byte as the host wrote it ([`conduit_gcode`]'s round-trip guarantee).
//!
//! The steps, one module each:
//!
//! 1. [`read_gcode`]: the file as lines; binary G-code is refused ([`PostprocessError::Gcode`]).
//! 2. [`host`]: which slicer wrote it and which layer comments it uses ([`detect_host`]).
//! 3. The host's settings from the `SLIC3R_<KEY>` environment of the call and from the file
//!    itself, as a conduit config: that is configuration, read in `crate::config`
//!    (`HostSettings`); the walk builds these stages' [`PostprocessParams`] from it.
//! 4. [`layers`]: the host's layers rebuilt ([`read_layers`]): line ranges, z, height, E mode,
//!    tools, retraction style, extrusions as polylines with role and width ([`comments`] reads the
//!    structured comments, [`roles`] maps feature names to conduit's roles).
//! 5. [`regions`]: the area printed in each layer ([`printed_regions`]).
//! 6. [`plan`]: with a circuit, the electronics stage of `conduit slice` run on the host's
//!    layers ([`plan_circuit`]): the printed areas stand in for sliced islands, the circuit is
//!    placed in bed coordinates, and cavities, channels, traces and part events come out per
//!    host layer.
//! 7. [`rewrite`] (with [`cut`]): the file edited for the plan — extrusion removed from
//!    cavities and channels with E kept exact, traces and part events inserted at layer ends in
//!    the host's own retraction style, OctoPNP's part description of the parts placed by the
//!    machine after the last layer's last extrusion (before the host's end G-code), a summary at
//!    the top; every other line untouched.
//! 8. [`verify`]: an independent check of an edited file against the host's original (lines
//!    kept in order, no plastic left in a cavity, traces on the conductive tool, parts placed
//!    after their cavities are done, OctoPNP's part description right, `conduit check` clean).
//! 9. [`report`]: what was found and done, for `--report` and the one-line summary.
//!
//! The post-processing walk (`crate::pipeline::postprocess`: the host's print read with its
//! settings, the edit of steps 6 and 7) runs these steps with the parameters of one config;
//! the `conduit postprocess` command (`src/cli/postprocess.rs`) calls it and writes the file
//! back only when something changed (a temporary file beside it, then a rename).

pub mod comments;
pub mod cut;
pub mod host;
pub mod layers;
pub mod plan;
pub mod regions;
pub mod report;
pub mod rewrite;
pub mod roles;
pub mod verify;

pub use comments::{HostComment, LayerMarker, read_comment};
pub use host::{Host, HostInfo, detect_host};
pub use layers::{
    EMode, ExtrusionPath, HostLayer, HostLayers, LayerMethod, LayerParams, PathMove,
    RetractionStyle, RoleWidth, WidthSource, Z_TOLERANCE, ZSource, read_layers,
};
pub use plan::{CircuitPlan, LayerPlan, host_islands, plan_circuit};
pub use regions::{RegionParams, printed_regions};
pub use report::{PostprocessReport, SettingCounts};
pub use rewrite::{RewriteStats, rewrite};
pub use roles::role_of;
pub use verify::{VerifyReport, verify};

use std::path::{Path, PathBuf};

use conduit_gcode::{Gcode, GcodeError};

use crate::check::CheckParams;
use crate::circuit::{ElectronicsError, ElectronicsParams};
use crate::emit::gcode::{EmitError, GcodeParams};

/// Why a host file cannot be post-processed.
#[derive(Debug, thiserror::Error)]
pub enum PostprocessError {
    /// The file is not text G-code: binary G-code (`.bgcode`) or a file with NUL bytes.
    ///
    /// # How to fix
    /// Turn off binary G-code in the host slicer (PrusaSlicer: Printer Settings > General >
    /// Firmware > "Supports binary G-code") and export again.
    #[error(transparent)]
    Gcode(#[from] GcodeError),
    /// The circuit does not fit the print: the placement names unknown parts or pins, a part
    /// lies outside every layer, or the config has no conductive tool.
    ///
    /// # How to fix
    /// The message names the problem; correct the placement, or pass a conduit config with
    /// `-c` whose `route.conductive_tool` is one of its `[tools.N]`.
    #[error(transparent)]
    Electronics(#[from] ElectronicsError),
    /// The file prints nothing conduit can place a circuit in.
    ///
    /// # How to fix
    /// Post-process the G-code of a print with at least one layer of extrusion.
    #[error("the file has no printed layers to place the circuit in")]
    NothingPrinted,
    /// A layer is not above the one before it, as when the host prints several objects one
    /// after the other (sequential printing).
    ///
    /// # How to fix
    /// Turn off sequential printing ("complete objects") in the host.
    #[error(
        "layer {layer} is at z {z} mm, not above the layer before it (z {below} mm): \
         sequential printing is not supported"
    )]
    LayersNotAscending {
        /// The layer's 0-based index.
        layer: usize,
        /// Its z, mm.
        z: f64,
        /// The z of the layer before it, mm.
        below: f64,
    },
    /// The machine is in a state conduit cannot write moves in at a place it must edit.
    ///
    /// # How to fix
    /// Let the host write absolute coordinates in millimetres (`G90`, `G21`) while printing.
    #[error("line {line}: cannot insert moves while the machine is in {what}")]
    MachineState {
        /// 1-based line number.
        line: usize,
        /// What is in force.
        what: &'static str,
    },
    /// The inserted G-code could not be written (a tool the config lacks, a bad template).
    ///
    /// # How to fix
    /// The message names the tool or template; correct the config given with `-c`.
    #[error(transparent)]
    Emit(#[from] EmitError),
}

/// Parses a host's G-code for post-processing. Any text is accepted (lines that are not G-code
/// are kept as they are).
///
/// # Errors
/// [`PostprocessError::Gcode`] for binary G-code ([`GcodeError::BinaryGcode`], whose message
/// tells how to turn it off in the host) and for files with NUL bytes (naming the line).
pub fn read_gcode(bytes: &[u8]) -> Result<Gcode, PostprocessError> {
    Ok(conduit_gcode::parse(bytes)?)
}

/// What the post-processing stages are configured with, built by the walk from the run's
/// config (`crate::config::Config::postprocess_params`): the host's settings, or the user's
/// `-c` file.
#[derive(Debug, Clone, PartialEq)]
pub struct PostprocessParams {
    /// The layer reconstruction's (give them the host's bead model with
    /// [`LayerParams::for_host`]).
    pub layers: LayerParams,
    /// The electronics stage's, run on the host's layers ([`plan_circuit`]).
    pub electronics: ElectronicsParams,
    /// The G-code writer's, for the blocks inserted at layer ends ([`rewrite()`]).
    pub gcode: GcodeParams,
    /// `conduit check`'s, for an edited file ([`verify()`]).
    pub check: CheckParams,
}

/// The file through which a post-processing script renames the host's output: `<path>.output_name`
/// beside the G-code `path`. PrusaSlicer (and its descendants) read the new name from its first
/// line after the script ends (a name without folder stays in the output folder).
///
/// ```
/// use std::path::Path;
/// assert_eq!(
///     conduit::postprocess::output_name_file(Path::new("/tmp/part.gcode.pp")),
///     Path::new("/tmp/part.gcode.pp.output_name")
/// );
/// ```
pub fn output_name_file(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".output_name");
    PathBuf::from(name)
}
