//! The post-processing walk (`conduit postprocess`, slicer plugin mode): another slicer's G-code
//! in, the same file with a circuit built in out, as library calls.
//!
//! Steps: **read** the host's print ([`HostPrint::read`] / [`HostPrint::read_with`]: the host
//! detected, its settings collected — the run's config comes from them unless the user gives
//! one — and its layers rebuilt with the config's flavour and filament) → **plan** the circuit
//! on the host's layers ([`crate::postprocess::plan_circuit`], the electronics stage of
//! `conduit slice`) → **rewrite** the file for the plan ([`crate::postprocess::rewrite()`],
//! with OctoPNP's part description and the summary lines of [`edit_circuit`]) → **report**
//! ([`HostPrint::report`]). [`edit`] and [`edit_circuit`] run plan and rewrite with the
//! parameters of one [`Config`]; the stages themselves live in [`crate::postprocess`] and never
//! see the config.

use conduit_gcode::Gcode;

use crate::circuit::Electronics;
use crate::circuit::octopnp::{collected, octopnp_block};
use crate::config::{Config, ConfigError, HostSettings, SettingSource};
use crate::postprocess::{
    CircuitPlan, HostInfo, HostLayers, LayerParams, PostprocessError, PostprocessReport,
    RewriteStats, SettingCounts, detect_host, plan_circuit, read_layers, rewrite,
};

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
    /// [`ConfigError::Ini`] naming the setting when a setting cannot be read.
    pub fn read(
        gcode: &Gcode,
        env: impl IntoIterator<Item = (String, String)>,
    ) -> Result<(HostPrint, Config), ConfigError> {
        let host = detect_host(gcode);
        let settings = HostSettings::collect(gcode, host.host, env);
        let (config, _warnings) = settings.to_config()?;
        let params = config.host_layer_params().for_host(host.host);
        let print = Self::read_with(gcode, host, settings, &params);
        Ok((print, config))
    }

    /// Rebuilds the layers of `gcode` with `params` (built from any config, for instance one the
    /// user gave instead of the host's settings: [`Config::host_layer_params`] and
    /// [`LayerParams::for_host`]).
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

    /// The report of this print: `changed` says whether the file was rewritten, `done` what
    /// building a circuit in did (when one was).
    pub fn report(&self, changed: bool, done: Option<&CircuitEdit>) -> PostprocessReport {
        let settings = SettingCounts {
            environment: self.settings.count_from(SettingSource::Environment),
            gcode: self.settings.count_from(SettingSource::Gcode),
        };
        let report = PostprocessReport::new(&self.host, &self.layers, settings, changed);
        match done {
            Some(done) => report.with_circuit(&done.stats, &done.plan.report),
            None => report,
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
/// ([`plan_circuit`], with [`Config::electronics_params`]) and rewrites the file for it
/// ([`rewrite()`], with [`Config::gcode_params`]), OctoPNP's part description of the parts
/// placed by the machine included (named by [`object_name`]; with a warning in the plan's
/// report when host lines hold text OctoPNP would read with it). The result is the same for
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
    edit_circuit_watched(gcode, print, electronics, config, None)
}

/// [`edit_circuit`], with `routing` told how far the router got. Routing is bounded by
/// `route.time_limit` from the start of the plan.
///
/// # Errors
/// Those of [`edit_circuit`].
pub fn edit_circuit_watched(
    gcode: &Gcode,
    print: &HostPrint,
    electronics: &Electronics,
    config: &Config,
    routing: Option<&super::ProgressFn>,
) -> Result<CircuitEdit, PostprocessError> {
    let params = super::watched_params(config, routing);
    let mut plan = plan_circuit(&print.layers, electronics, &params)?;
    let description = octopnp_block(&electronics.circuit, &plan.parts, &object_name(print));
    if !description.is_empty() {
        plan.report.warnings.extend(angle_bracket_warning(gcode));
    }
    let mut summary = Vec::new();
    let writer = config.gcode_params();
    let (gcode, stats) = rewrite(
        gcode,
        &print.layers,
        &plan,
        &writer,
        &description,
        |stats| {
            summary = summary_lines(&plan, stats, electronics, config);
            summary.clone()
        },
    )?;
    Ok(CircuitEdit {
        gcode,
        plan,
        stats,
        summary,
    })
}

/// The name of the `<object>` of OctoPNP's part description: the file stem of the name the
/// host gives its output (PrusaSlicer's and its descendants' `SLIC3R_PP_OUTPUT_NAME`, such as
/// `cube_0.2mm_PLA_1h` for `/home/user/cube_0.2mm_PLA_1h.gcode`), else `object`. Never the
/// name of the file being edited: PrusaSlicer hands the script a temporary file
/// (`*.gcode.pp`), so the description would change with every export.
pub fn object_name(print: &HostPrint) -> String {
    print
        .settings
        .output_name()
        .and_then(|name| std::path::Path::new(name).file_stem())
        .map(|stem| stem.to_string_lossy().into_owned())
        .filter(|stem| !stem.trim().is_empty())
        .unwrap_or_else(|| "object".to_owned())
}

/// The warning for host lines that OctoPNP would collect with its part description (text
/// between `<` and a later `>`; see [`collected`]), such as a custom G-code template with a
/// comparison written into PrusaSlicer's settings at the end of its file: OctoPNP reads them
/// into the description and cannot parse it. The host's lines are never changed, so the user
/// is told which line to take out of the host's settings; `None` when there is none.
fn angle_bracket_warning(gcode: &Gcode) -> Option<String> {
    let mut lines = gcode
        .lines
        .iter()
        .enumerate()
        .filter(|(_, l)| collected(&l.text).is_some())
        .map(|(i, _)| i + 1);
    let first = lines.next()?;
    let which = match lines.count() {
        0 => format!("the host's line {first} holds"),
        n => format!("the host's lines {first} and {n} more hold"),
    };
    Some(format!(
        "{which} text in angle brackets, which OctoPNP reads with its part description and \
         then cannot parse it; take it out of the host's custom G-code or settings"
    ))
}

/// The summary block: one `; conduit postprocess: ...` line per item. No line holds ` = `, so
/// hosts that read `; key = value` settings from comments do not take them for settings.
fn summary_lines(
    plan: &CircuitPlan,
    stats: &RewriteStats,
    e: &Electronics,
    config: &Config,
) -> Vec<String> {
    use crate::postprocess::rewrite::SUMMARY_PREFIX as P;
    use conduit_gcode::fmt_xyz;
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
