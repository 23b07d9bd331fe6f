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
//! 3. [`settings`]: the host's settings from the `SLIC3R_<KEY>` environment of the call and
//!    from the file itself ([`HostSettings::collect`]), as a conduit [`Config`].
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
//!    the host's own retraction style, a summary at the top; every other line untouched.
//!    [`edit`] runs steps 6 and 7 ([`edit_circuit`] also returns what was done).
//! 8. [`verify`]: an independent check of an edited file against the host's original (lines
//!    kept in order, no plastic left in a cavity, traces on the conductive tool, parts placed
//!    after their cavities are done, `conduit check` clean).
//! 9. [`report`]: what was found and done, for `--report` and the one-line summary.
//!
//! The `conduit postprocess` command (`src/cli/postprocess.rs`) runs these steps and writes the
//! file back only when something changed (a temporary file beside it, then a rename).

pub mod comments;
pub mod cut;
pub mod host;
pub mod layers;
pub mod plan;
pub mod regions;
pub mod report;
pub mod rewrite;
pub mod roles;
pub mod settings;
pub mod verify;

pub use comments::{HostComment, LayerMarker, read_comment};
pub use host::{Host, HostInfo, detect_host};
pub use layers::{
    EMode, ExtrusionPath, HostLayer, HostLayers, LayerMethod, LayerParams, PathMove,
    RetractionStyle, RoleWidth, WidthSource, Z_TOLERANCE, ZSource, read_layers,
};
pub use plan::{CircuitPlan, LayerPlan, host_islands, plan_circuit};
pub use regions::{RegionParams, printed_regions};
pub use report::PostprocessReport;
pub use rewrite::{RewriteStats, rewrite};
pub use roles::role_of;
pub use settings::{HostSettings, Setting, SettingSource};
pub use verify::{VerifyReport, verify};

use std::path::{Path, PathBuf};

use conduit_gcode::{Gcode, GcodeError};

use crate::circuit::{Electronics, ElectronicsError};
use crate::config::{Config, ConfigError};
use crate::emit::gcode::EmitError;

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
    /// The host's settings could not be turned into a conduit configuration.
    ///
    /// # How to fix
    /// The message names the setting; correct it in the host, or pass a conduit config with
    /// `-c`.
    #[error("the host's settings: {0}")]
    Settings(#[from] ConfigError),
    /// The circuit does not fit the print: the placement names unknown parts or pins, a part
    /// lies outside every layer, or the config has no conductive tool.
    ///
    /// # How to fix
    /// The message names the problem; correct the placement, or pass a conduit config with
    /// `-c` whose `route.conductive_tool` is one of its `[tools.N]`.
    #[error("{0}")]
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
    #[error("{0}")]
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

/// Everything read from a host's G-code.
#[derive(Debug, Clone, PartialEq)]
pub struct HostPrint {
    /// The slicer and its layer comments.
    pub host: HostInfo,
    /// The slicer's settings.
    pub settings: HostSettings,
    /// The layers.
    pub layers: HostLayers,
}

impl HostPrint {
    /// Reads `gcode` with the host's own settings: the host is detected, its settings collected
    /// from the file and `env` (the `SLIC3R_<KEY>` variables of the call), and the layers rebuilt
    /// with the flavour and filament of those settings. Returns the print and the config the
    /// settings give (see [`HostSettings::to_config`]).
    ///
    /// # Errors
    /// [`PostprocessError::Settings`] when a setting cannot be read.
    pub fn read(
        gcode: &Gcode,
        env: impl IntoIterator<Item = (String, String)>,
    ) -> Result<(HostPrint, Config), PostprocessError> {
        let host = detect_host(gcode);
        let settings = HostSettings::collect(gcode, host.host, env);
        let (config, _warnings) = settings.to_config()?;
        let params = LayerParams::from_config(&config).for_host(host.host);
        let print = Self::read_with(gcode, host, settings, &params);
        Ok((print, config))
    }

    /// Rebuilds the layers of `gcode` with `params` (built from any config, for instance one the
    /// user gave instead of the host's settings, and [`LayerParams::for_host`]).
    pub fn read_with(
        gcode: &Gcode,
        host: HostInfo,
        settings: HostSettings,
        params: &LayerParams,
    ) -> HostPrint {
        let layers = read_layers(gcode, &host.markers, params);
        HostPrint {
            host,
            settings,
            layers,
        }
    }
}

/// What post-processing does to the file.
#[derive(Debug, Clone, PartialEq)]
pub enum Edit {
    /// Nothing to change: the file stays as the host wrote it (and is not rewritten).
    Unchanged,
    /// The edited file, to be written in place of the host's.
    Rewritten(Gcode),
}

/// Plans the edits of `gcode` (read as `print`) for `electronics`, with the tools, routing and
/// part-event settings of `config`: none without a circuit; with one, see [`edit_circuit`].
///
/// # Errors
/// See [`edit_circuit`].
pub fn edit(
    gcode: &Gcode,
    print: &HostPrint,
    electronics: Option<&Electronics>,
    config: &Config,
) -> Result<Edit, PostprocessError> {
    match electronics {
        None => Ok(Edit::Unchanged),
        Some(e) => Ok(Edit::Rewritten(
            edit_circuit(gcode, print, e, config)?.gcode,
        )),
    }
}

/// A host file with a circuit built in.
#[derive(Debug, Clone, PartialEq)]
pub struct CircuitEdit {
    /// The edited file.
    pub gcode: Gcode,
    /// The circuit on the host's layers.
    pub plan: CircuitPlan,
    /// What the rewrite changed.
    pub stats: RewriteStats,
    /// The summary lines written at the top of the file.
    pub summary: Vec<String>,
}

/// Builds `electronics` into `gcode`: plans the circuit on the host's layers
/// ([`plan_circuit`]) and rewrites the file for it ([`rewrite()`]). The result is the same for
/// the same inputs, byte for byte.
///
/// # Errors
/// [`PostprocessError::Electronics`] when the placement does not fit the circuit or the config
/// has no conductive tool, [`PostprocessError::NothingPrinted`],
/// [`PostprocessError::LayersNotAscending`] (sequential printing),
/// [`PostprocessError::MachineState`] and [`PostprocessError::Emit`] (see [`rewrite()`]).
pub fn edit_circuit(
    gcode: &Gcode,
    print: &HostPrint,
    electronics: &Electronics,
    config: &Config,
) -> Result<CircuitEdit, PostprocessError> {
    let plan = plan_circuit(print, electronics, config)?;
    let mut summary = Vec::new();
    let (gcode, stats) = rewrite(gcode, print, &plan, config, |stats| {
        summary = summary_lines(&plan, stats, electronics, config);
        summary.clone()
    })?;
    Ok(CircuitEdit {
        gcode,
        plan,
        stats,
        summary,
    })
}

/// The summary block: one `; conduit postprocess: ...` line per item. No line holds ` = `, so
/// hosts that read `; key = value` settings from comments do not take them for settings.
fn summary_lines(
    plan: &CircuitPlan,
    stats: &RewriteStats,
    e: &Electronics,
    config: &Config,
) -> Vec<String> {
    use conduit_gcode::fmt_xyz;
    use rewrite::SUMMARY_PREFIX as P;
    let origin = match e.placement.origin {
        crate::circuit::Origin::Model => "bed coordinates (origin model)".to_owned(),
        crate::circuit::Origin::BboxCenter => format!(
            "x, y from the object's centre ({}, {}), z from the bed (origin bbox_center)",
            fmt_xyz((plan.bbox.min[0] + plan.bbox.max[0]) / 2.0),
            fmt_xyz((plan.bbox.min[1] + plan.bbox.max[1]) / 2.0)
        ),
    };
    let r = &plan.report;
    let names = |parts: &mut dyn Iterator<Item = String>| parts.collect::<Vec<_>>().join(", ");
    let mut lines = vec![
        format!(
            "{P} circuit of {} parts and {} nets, placed in {origin}",
            e.circuit.parts.len(),
            e.circuit.nets.len()
        ),
        format!(
            "{P} {} cavities ({})",
            plan.cavities.len(),
            names(&mut plan.parts.iter().map(|p| {
                format!(
                    "{} z {}-{}",
                    p.name,
                    fmt_xyz(p.position.z),
                    fmt_xyz(p.position.z + p.body_height)
                )
            }))
        ),
        format!(
            "{P} {} traces ({} mm) on tool {}, {} of {} wires routed",
            plan.trace_count(),
            fmt_xyz(plan.trace_length()),
            config.route.conductive_tool,
            r.routed,
            r.wires.len()
        ),
        format!(
            "{P} {} part events ({})",
            plan.event_count(),
            names(&mut r.parts.iter().map(|p| format!(
                "{} {} after z {}",
                p.name,
                p.method,
                fmt_xyz(p.placed_after_z)
            )))
        ),
        format!(
            "{P} {} extrusion moves cut ({} mm of extrusion, {} mm of filament removed)",
            stats.cut_moves,
            fmt_xyz(stats.removed_length),
            fmt_xyz(stats.removed_e)
        ),
    ];
    for w in r.wires.iter().filter(|w| !w.routed) {
        lines.push(format!("{P} wire {} {}-{} not routed", w.net, w.from, w.to));
    }
    for w in &r.warnings {
        lines.push(format!("{P} warning: {}", w.replace(" = ", " ")));
    }
    lines
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
