//! G-code for FFF printers with filament and paste tools, and for switched-tool jobs (an
//! aerosol jet): Marlin, RepRapFirmware, Klipper. The project's one G-code writer.
//!
//! Place in the pipeline: Program → **emit** → file. [`write_gcode`] writes a whole file; the
//! body is produced by a state machine that sends lines and motions to a [`GcodeSink`]
//! ([`write_program`]), so the same code can feed a preview or a test [`Recorder`]. What it
//! writes is decided by the Program and the [`GcodeParams`] alone: the FFF printer's style
//! (below), or with [`GcodeParams::switched`] the switched-tool style of [`SwitchedParams`]
//! (the jet walk's: `;TYPE:Jet wall`, the shutter snippets around every path at
//! [`crate::program::Event::Switch`] events, run-ins and early switch-offs for their lead
//! times, `G2`/`G3` arcs of paths with [`crate::program::Toolpath::segments`] or chords, `E` =
//! length; the totals in [`GcodeStats::switched`]).
//!
//! # Output
//!
//! - A header: `; conduit <version>`, flavour, E mode, layer count, tools used, filament per
//!   tool (mm, cm³, g) and the estimated time (every move planned by
//!   [`crate::program::motion`], the model `conduit check` uses). The totals are known only at the
//!   end, so the body is built in memory and the header written before it.
//! - Fan off (`M107`), then, as PrusaSlicer does, the first-layer bed and tool temperatures when
//!   the start G-code sets none itself; `;TYPE:Custom` and the rendered `printer.start_gcode`;
//!   `G21`, `G90`, `M82`/`M83`, `G92 E0`; a preheat (to the standby or first-layer
//!   temperature) of the other used tools the start G-code leaves cold; `T<n>` of the first tool
//!   on multi-tool prints; a wait for the first tool when the start G-code does not wait for it.
//! - Per layer, PrusaSlicer's markers: `;LAYER_CHANGE`, `;Z:<z>`, `;HEIGHT:<h>`, the rendered
//!   `before_layer_gcode`, then `G1 Z<z>` (after a retraction when the way to the layer's first
//!   path is long), in absolute E mode `G92 E0`, and the rendered `layer_gcode`. On layer 1 the bed and tool temperatures change to their
//!   after-first-layer values. The fan is off for the first `disable_fan_first_layers` layers,
//!   then follows the layer's extrusion time as PrusaSlicer's cooling does with its default
//!   thresholds: `fan_max_speed` under 5 s, `fan_min_speed` over 60 s, linear in between
//!   (`M106 S0-255`, written only when it changes). An [`crate::program::Event::PartFan`]
//!   raises it for the paths after it (bridges and overhangs) to its speed if that is higher,
//!   and returns it to the layer's; not on the layers with the fan off.
//! - Per path: a travel (`G1 X Y F<travel>`; longer than `retract_before_travel`: retract
//!   first, and with `retract_lift > 0` a z-hop up before and back down after — except after
//!   an [`crate::program::Event::TravelInsideInfill`], a travel inside the internal infill,
//!   which never retracts), un-retract,
//!   `;TYPE:<role>` and `;WIDTH:<w>` when they change (`;HEIGHT:` too, within a layer), `G1 F`
//!   when the speed changes, then `G1 X Y [Z] E` moves (a closed path returns to its start).
//!   Filament tools: `E = length × bead area / filament area × extrusion_multiplier`
//!   ([`crate::program::extrusion`]). Paste tools: `paste_on_gcode`, moves without E,
//!   `paste_off_gcode`.
//! - Tool changes: retract, `before_tool_change_gcode` (`{previous_tool}`, `{next_tool}`), the
//!   old tool to its standby temperature, `T<n>` (left out when the snippet selects the tool
//!   itself, as PrusaSlicer does for `T{next_extruder}`), heat-and-wait for the new tool,
//!   `after_tool_change_gcode`, `G92 E0` (absolute E). The old tool's `end_gcode` comes before
//!   the tool-change snippets, the new tool's `start_gcode` after them (and after the start
//!   G-code for the first tool). Coordinates of tool `n` are the program's
//!   minus `tools.n.offset` (PrusaSlicer's `extruder_offset` convention). Flavour differences
//!   are listed in [`flavor`](self#flavours).
//! - Events: `;PICK_AND_PLACE PART=.. X=.. Y=.. Z=.. ROTATION=..` (a marker for a host plugin),
//!   a manual-insert pause in the flavour's way, comments, `G4 P<ms>` dwells, the active paste
//!   tool's `paste_on_gcode`/`paste_off_gcode` for a switch on/off.
//! - Arcs of paths with segments are written as chords within half the output resolution.
//! - Custom G-code is replayed as it is written: the writer takes over the position, Z, feed
//!   and (absolute E) the E register it leaves.
//! - The end: retract, `;TYPE:Custom`, every tool's `end_gcode`, the rendered
//!   `printer.end_gcode`, then PrusaSlicer's
//!   footer lines (`; filament used [mm] = ...`, `; estimated printing time (normal mode) =
//!   ...`) that OctoPrint and other tools read.
//!
//! # Flavours
//!
//! See the table in the `flavor` module source: temperatures are `M104 T`/`M109 T` on Marlin
//! and Klipper (without the `T` when the print uses tool 0 alone, as PrusaSlicer writes a
//! single-extruder print), `G10 P S R`/`M116 P` on RepRapFirmware (which handles standby itself);
//! firmware retraction is `G10`/`G11` on all three.
//!
//! # Blocks in another program
//!
//! [`write_block`] writes paths and events into another slicer's G-code (the slicer plugin
//! mode): the writer takes over the machine state where the block goes ([`Resume`]) and leaves
//! it as it found it — same tool (primed), position, E register and feed rate.
//!
//! Every number goes through [`conduit_gcode::fmt_xyz`], [`conduit_gcode::fmt_e`] and
//! [`conduit_gcode::fmt_f`]; nothing depends on clocks, hashing or thread count, so the output is
//! byte-identical across runs.

pub mod estimate;
mod flavor;
pub mod macros;
mod params;
mod sink;
mod template;
mod writer;

#[cfg(test)]
mod tests;

pub use params::{GcodeParams, SwitchedParams};
pub use sink::{GcodeSink, Motion, MotionKind, Recorder};
pub use template::TemplateError;

use std::io::Write;

use conduit_gcode::{fmt_e, fmt_f, fmt_xyz};
use serde::Serialize;

use crate::geom::Point3;
use crate::program::machine::ToolKind;
use crate::program::{LayerItem, Program};
use estimate::format_duration;
use writer::{Writer, used_tools};

/// Why G-code could not be written.
///
/// A variant that wraps another error shows it in its own message rather than chaining it as
/// a source, so an error printed with its chain names the cause once.
#[derive(Debug, thiserror::Error)]
pub enum EmitError {
    /// Writing the output failed.
    ///
    /// How to fix: check the output path, the free space and the permissions.
    #[error("writing G-code: {0}")]
    Io(#[from] std::io::Error),
    /// A custom G-code template cannot be filled: a placeholder names neither a config key, a
    /// profile key nor a variable the writer provides, or a macro has a syntax or type error.
    ///
    /// How to fix: correct the placeholder on the named line of the named template;
    /// `conduit config --defaults` lists the keys. The writer provides `{previous_tool}`,
    /// `{next_tool}`, `{layer_num}` and `{layer_z}` in tool-change templates; `{initial_tool}`,
    /// `{initial_extruder}`, `{total_layer_count}`, `{max_layer_z}`, `{has_wipe_tower}`,
    /// `{is_extruder_used[N]}` and `{first_layer_print_min}` / `_max` / `_size` from the start
    /// G-code on; `{layer_num}` and `{layer_z}` in the end G-code.
    #[error("{template}, {error}")]
    Template {
        /// Which template (`printer.start_gcode`, `tools.1.paste_on_gcode`, ...).
        template: String,
        /// The line, the placeholder and the problem.
        error: TemplateError,
    },
    /// The program uses a tool the config does not define.
    ///
    /// How to fix: add a `[tools.N]` table for it, or assign the object to an existing tool.
    #[error("the program uses tool {tool}, but the config defines only {count} tool(s)")]
    UnknownTool {
        /// The tool index.
        tool: usize,
        /// Number of tools in the config.
        count: usize,
    },
    /// A path has a coordinate, width, height or speed that is NaN or infinite, or a speed that
    /// is not positive.
    ///
    /// How to fix: this is a bug in the stage that made the program; please file an issue.
    #[error("layer {layer}: a toolpath has a non-finite coordinate or size, or no speed")]
    NotFinite {
        /// The layer index.
        layer: usize,
    },
}

/// Material used by one tool.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ToolStats {
    /// Tool index.
    pub tool: usize,
    /// Tool name from the config.
    pub name: String,
    /// Filament or paste.
    pub kind: ToolKind,
    /// Filament pushed, mm (0 for paste tools).
    pub filament_mm: f64,
    /// Material volume, cm³ (paste: flow × time the paste is on).
    pub volume_cm3: f64,
    /// Material weight, g (volume × density).
    pub grams: f64,
    /// Time spent extruding, s.
    pub extrusion_time_s: f64,
}

/// What a G-code file contains, for reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GcodeStats {
    /// Number of layers.
    pub layers: usize,
    /// Estimated print time, s (see [`estimate`]).
    pub estimated_time_s: f64,
    /// Per tool used, ascending.
    pub tools: Vec<ToolStats>,
    /// Heights (mm) of the events of `printer.custom_gcode_per_print_z` above the last layer,
    /// which were not written.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub events_above_print: Vec<f64>,
    /// The totals of a switched-tool job ([`SwitchedParams`]); `None` otherwise. Not part of
    /// reports.
    #[serde(skip)]
    pub switched: Option<SwitchedStats>,
}

/// What a switched-tool job ([`SwitchedParams`]) wrote.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SwitchedStats {
    /// Paths printed (switch-on cycles).
    pub paths: usize,
    /// Length of the depositing moves, mm (along arcs; run-ins not counted).
    pub printed_mm: f64,
    /// Travel length, mm (XY).
    pub travel_mm: f64,
    /// Time of every move at its feed, without acceleration, s.
    pub time_s: f64,
}

/// Writes the body of the G-code for `program` (start G-code to end G-code, no header or
/// footer) to `sink`, and returns the totals. With [`GcodeParams::switched`] the body is a
/// switched-tool job's (see [`SwitchedParams`]).
pub fn write_program<S: GcodeSink>(
    program: &Program,
    cfg: &GcodeParams,
    sink: &mut S,
) -> Result<GcodeStats, EmitError> {
    let used = used_tools(program);
    if let Some(&tool) = used.iter().find(|&&t| t >= cfg.tools.len()) {
        return Err(EmitError::UnknownTool {
            tool,
            count: cfg.tools.len(),
        });
    }
    let first_tool = program.first_tool().or(used.first().copied()).unwrap_or(0);
    let mut w = Writer::new(cfg, sink)?;
    if let Some(switched) = &cfg.switched {
        return w.switched_program(program, switched, first_tool);
    }
    w.start(program, first_tool)?;
    for layer in &program.layers {
        w.layer(layer)?;
    }
    w.finish(program)
}

/// The machine state at the place in another program's G-code where conduit writes a block
/// (see [`write_block`]): what the other program expects to find again after it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resume {
    /// The active tool.
    pub tool: usize,
    /// The nozzle position, machine coordinates, mm.
    pub position: Point3,
    /// Whether E is relative (`M83`).
    pub relative_e: bool,
    /// The E register (absolute E mode), mm.
    pub e: f64,
    /// The feed rate in force, mm/s.
    pub feed: f64,
    /// The layer the block follows: its index (for first-layer temperatures and templates) and
    /// its print height, mm (part events lift `pnp.lift` above it).
    pub layer_index: usize,
    /// See [`Resume::layer_index`].
    pub layer_z: f64,
}

/// Writes `items` (paths and events, as in a [`crate::program::Layer`]) as a block to insert
/// into another program's G-code where the machine is in state `at`, with the tool
/// (temperatures, offsets, paste snippets), retraction and part-event settings of `cfg`.
///
/// The block leaves the machine as it found it: the tool at `at` is the primed tool `at.tool`
/// (the writer retracts it before its first tool change or part event and un-retracts it at the
/// end), and after the paths and events the block selects `at.tool` again (with the usual tool
/// change: snippets, standby and wait), travels back to `at.position` (over the current layer
/// when a part event lifted the nozzle), un-retracts, and restores the E register
/// (`G92 E<at.e>`, absolute E) and the feed rate (`G1 F`) when they changed. `E` words follow
/// `at.relative_e` whatever `cfg` says. Nothing is written for an empty `items`.
///
/// # Errors
/// [`EmitError::UnknownTool`] when `at.tool` or a path's tool is not in `cfg`; template errors
/// of the tool-change snippets.
pub fn write_block<S: GcodeSink>(
    items: &[LayerItem],
    cfg: &GcodeParams,
    at: &Resume,
    sink: &mut S,
) -> Result<(), EmitError> {
    if items.is_empty() {
        return Ok(());
    }
    let mut w = Writer::new(cfg, sink)?;
    w.block(items, at)
}

/// Writes a complete G-code file for `program` to `w`: header, body ([`write_program`]) and
/// footer (a switched-tool job has a header of its own and no footer). See the module docs for
/// what it contains.
pub fn write_gcode(
    program: &Program,
    cfg: &GcodeParams,
    w: &mut impl Write,
) -> Result<GcodeStats, EmitError> {
    let mut body: Vec<u8> = Vec::new();
    let stats = write_program(program, cfg, &mut body)?;
    let mut head = String::new();
    let mut foot = String::new();
    match &cfg.switched {
        Some(switched) => writer::switched_header(program, cfg, switched, &mut head),
        None => {
            header(&stats, cfg, &mut head);
            footer(&stats, &mut foot);
        }
    }
    w.write_all(head.as_bytes())?;
    w.write_all(&body)?;
    w.write_all(foot.as_bytes())?;
    w.flush()?;
    Ok(stats)
}

fn header(stats: &GcodeStats, cfg: &GcodeParams, out: &mut String) {
    let version = env!("CARGO_PKG_VERSION");
    out.line(&format!("; conduit {version}"));
    out.line(&format!("; generated by conduit {version}"));
    out.line(&format!("; flavor = {}", cfg.printer.flavor));
    out.line(&format!(
        "; extrusion = {}",
        if cfg.printer.use_relative_e_distances {
            "relative (M83)"
        } else {
            "absolute (M82)"
        }
    ));
    out.line(&format!("; layer count = {}", stats.layers));
    let tools: Vec<String> = stats
        .tools
        .iter()
        .map(|t| format!("{} ({})", t.tool, t.name))
        .collect();
    out.line(&format!("; tools used = {}", tools.join(", ")));
    for t in &stats.tools {
        let kind = match t.kind {
            ToolKind::Filament => "filament",
            ToolKind::Paste => "paste",
        };
        out.line(&format!(
            "; tool {} {kind} used = {} mm, {} cm3, {} g",
            t.tool,
            fmt_xyz(t.filament_mm),
            fmt_e(t.volume_cm3),
            fmt_xyz(t.grams)
        ));
    }
    out.line(&format!(
        "; estimated printing time = {} ({} s)",
        format_duration(stats.estimated_time_s),
        fmt_f(stats.estimated_time_s)
    ));
    out.line("");
}

fn footer(stats: &GcodeStats, out: &mut String) {
    let join =
        |f: &dyn Fn(&ToolStats) -> String| stats.tools.iter().map(f).collect::<Vec<_>>().join(", ");
    out.line("");
    out.line(&format!(
        "; filament used [mm] = {}",
        join(&|t| fmt_xyz(t.filament_mm))
    ));
    out.line(&format!(
        "; filament used [cm3] = {}",
        join(&|t| fmt_xyz(t.volume_cm3))
    ));
    out.line(&format!(
        "; filament used [g] = {}",
        join(&|t| fmt_xyz(t.grams))
    ));
    out.line(&format!(
        "; total filament used [g] = {}",
        fmt_xyz(stats.tools.iter().map(|t| t.grams).sum())
    ));
    out.line(&format!(
        "; estimated printing time (normal mode) = {}",
        format_duration(stats.estimated_time_s)
    ));
}
