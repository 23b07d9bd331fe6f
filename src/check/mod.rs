//! `conduit check`: replay any G-code file on a model of the printer and report what would go
//! wrong, plus what the print consists of (layers, filament, extent, time).
//!
//! Place in the pipeline: the last station, after `emit` (or after any other slicer): it reads a
//! parsed [`conduit_gcode::Gcode`] and a [`CheckParams`] (built from the config with
//! `Config::check_params`) and never reaches back into the pipeline. The test suites use it
//! on conduit's own output, as PrusaSlicer's tests re-parse their G-code and check the machine
//! state; the CLI exits 1 when [`CheckReport::has_errors`].
//!
//! # Machine model
//!
//! The replay follows Marlin unless [`CheckParams::flavor`] says otherwise:
//!
//! - `G90`/`G91` absolute/relative XYZ; in Marlin they set E's mode too, in Klipper `G91` makes
//!   E relative and `G90` leaves E to `M82`/`M83`, in RepRapFirmware only `M82`/`M83` set E's
//!   mode. `M82`/`M83` absolute/relative E.
//! - `G92` sets the named axes (`G92 E0`), `G20`/`G21` inches/millimetres (every length,
//!   E and F included, is scaled by 25.4 in inch mode), `G28` homes the named axes (all when
//!   none is named) to the home position ([`CheckParams::home`], `printer.home`). Positions are unknown before they are homed, set by `G92` or moved to
//!   absolutely; moves with unknown positions are not bounds-checked.
//! - `G0`/`G1` linear moves, `G2`/`G3` arcs in the XY plane with `I`/`J` (centre offset from
//!   the start) or `R` (radius; negative for the long way round), helical when Z changes; arc
//!   length is r·θ. A line of bare coordinates continues the last motion command.
//! - `G10`/`G11` firmware retraction (`G10` with `P`/`S`/`R` is RepRapFirmware's tool
//!   temperature command, as is `M568`), `T<n>` tool changes, `M104`/`M109` with optional
//!   `T`, `M116`,
//!   `M140`/`M190`, `M106`/`M107`, `G4` dwell. Klipper's `SET_HEATER_TEMPERATURE` and
//!   `TEMPERATURE_WAIT` are understood; other macros (`PRINT_START` …) are noted, since they may
//!   heat the tools (known harmless ones such as `EXCLUDE_OBJECT_*` are not).
//!
//! # Findings
//!
//! See [`FindingKind`] for every finding with its severity; [`air`] explains the rule for
//! extrusion into air. Temperature rules: a tool extrudes
//! only once its target temperature is reached — after `M109`/`M116`/`TEMPERATURE_WAIT`, or
//! [`CheckParams::heat_up_time_s`] of estimated print time after an `M104` that raised it.
//! Extruding with a target set but not yet reached is a warning; extruding with a tool that
//! was never heated (or whose heater was turned off) is an error.
//!
//! # Statistics
//!
//! Layers are counted as in `bench/gcode_layers.awk`: the distinct Z heights (to 1 µm) at which a
//! move with X or Y extrudes (E increases). Filament used counts the E increase of such moves,
//! the convention of PrusaSlicer's and Slic3r's `; filament used` footers (retractions and their
//! un-retractions are not filament used). The time estimate plans moves as firmware does: a
//! trapezoidal speed profile per move at [`CheckParams::max_acceleration`], the feed rate capped
//! at [`CheckParams::max_feedrate`], and the speed through each junction limited by a classic
//! jerk rule ([`CheckParams::jerk`]: no axis changes speed by more than that) and by what the
//! neighbouring moves can brake from. Motion stops at dwells, homing, heating waits and tool
//! changes. Dwells count; heating waits do not (their length is unknown). With `jerk = 0` every
//! move starts and ends at standstill: `L/v + v/a`, or `2·√(L/a)` for moves too short to reach
//! `v`.
//!
//! # Moves
//!
//! The motion replay is the modal [`Machine`] of `conduit-gcode` (see
//! [`conduit_gcode::machine`]), re-exported here: [`moves`] returns every move of a file (ends,
//! path, E change, tool, feature role, width, layer, line) for other consumers such as
//! [`emit::preview`](crate::emit::preview), and the checker steps the same machine, with
//! [`CheckParams::flavor`] as its [`Firmware`].

pub mod air;
pub mod electrical;
mod machine;

pub use conduit_gcode::{Firmware, Machine, Move, Moves, Position, moves, moves_on};
pub use electrical::{ElectricalParams, ElectricalReport, Frame, check_electrical};

use std::collections::BTreeMap;
use std::fmt;

use serde::Serialize;

use crate::program::machine::{Flavor, Printer, Tool, ToolKind};

/// What the checker needs to know about the printer. Build it with
/// `Config::check_params`; [`Default`] is the default config's.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckParams {
    /// Firmware dialect, for the `G90`/`G91` effect on E (see the module docs).
    pub flavor: Flavor,
    /// Front-left corner of the bed [X, Y], mm.
    pub bed_origin: [f64; 2],
    /// Bed size [X, Y], mm.
    pub bed_size: [f64; 2],
    /// Highest allowed Z, mm.
    pub max_height: f64,
    /// Where `G28` puts the axes [X, Y, Z], mm (`printer.home`, by default the bed's
    /// front-left corner at `max_height`).
    pub home: [f64; 3],
    /// How far outside the bed (XY) and above `max_height` moves may go without a finding, mm:
    /// slicers prime at the bed edge (PrusaSlicer's MK3 prime line runs at Y = −3). Default 5.
    pub bed_margin: f64,
    /// The tools by number; tools past the end are checked as [`ToolCheck::default`].
    pub tools: Vec<ToolCheck>,
    /// Largest plausible extrusion cross-section (filament volume per mm of path) as a multiple
    /// of the nozzle's area π·d²/4. Default 4 (a 0.45 × 0.2 mm line is 0.72).
    pub max_flow_factor: f64,
    /// Moves shorter than this are not flow-checked, mm (E is rounded to 5 decimals, so the
    /// flow of very short moves is noise). Default 0.5.
    pub flow_check_min_length: f64,
    /// Largest retraction during an XY move (a wipe) that is normal, mm of E. Default 5.
    pub max_moving_retraction: f64,
    /// An E drop larger than this in one move is an error (a missing `G92 E0` or a wrong
    /// `M82`/`M83`), mm of E. Default 50.
    pub lost_reset_drop: f64,
    /// How far below its target a tool may be and still extrude, °C. Default 5.
    pub temperature_tolerance: f64,
    /// Estimated print time after an `M104` that raised a target, after which the target counts
    /// as reached even without a wait, s. Default 120.
    pub heat_up_time_s: f64,
    /// Acceleration of the time estimate, mm/s². Default `printer.max_acceleration`.
    pub max_acceleration: f64,
    /// Largest instantaneous speed change of an axis at a junction, for the time estimate,
    /// mm/s (Marlin's classic jerk). Default 10.
    pub jerk: f64,
    /// Feed rate cap of the time estimate, mm/s. Default 500.
    pub max_feedrate: f64,
    /// Feed rate before the first `F`, mm/s. Default 25 (Marlin's 1500 mm/min).
    pub default_feedrate: f64,
    /// Findings of one kind listed in [`CheckReport::findings`]; the rest are only counted.
    /// Default 20.
    pub max_findings_per_kind: usize,
}

/// What the checker needs to know about one tool.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolCheck {
    /// Filament tools get temperature and flow checks; paste tools (unheated, E not filament)
    /// only bounds checks.
    pub kind: ToolKind,
    /// Filament diameter, mm.
    pub filament_diameter: f64,
    /// Nozzle diameter, mm.
    pub nozzle_diameter: f64,
    /// Lowest temperature at which the firmware extrudes at all, °C (Marlin's
    /// `EXTRUDE_MINTEMP` is 170). Default 170.
    pub min_extrude_temperature: f64,
}

impl Default for ToolCheck {
    /// A 1.75 mm filament tool with a 0.4 mm nozzle.
    fn default() -> Self {
        Self {
            kind: ToolKind::Filament,
            filament_diameter: 1.75,
            nozzle_diameter: 0.4,
            min_extrude_temperature: 170.0,
        }
    }
}

impl CheckParams {
    /// The `printer` and `tools`, with the default thresholds.
    pub fn for_machine(p: &Printer, tools: &[Tool]) -> Self {
        Self {
            flavor: p.flavor,
            bed_origin: p.bed_origin,
            bed_size: p.bed_size,
            max_height: p.max_height,
            home: p.home_position(),
            bed_margin: 5.0,
            tools: tools
                .iter()
                .map(|t| ToolCheck {
                    kind: t.kind,
                    filament_diameter: t.filament_diameter,
                    nozzle_diameter: t.nozzle_diameter,
                    min_extrude_temperature: match t.kind {
                        ToolKind::Filament => 170.0,
                        ToolKind::Paste => 0.0,
                    },
                })
                .collect(),
            max_flow_factor: 4.0,
            flow_check_min_length: 0.5,
            max_moving_retraction: 5.0,
            lost_reset_drop: 50.0,
            temperature_tolerance: 5.0,
            heat_up_time_s: 120.0,
            max_acceleration: p.max_acceleration,
            jerk: crate::program::motion::JERK_MM_S,
            max_feedrate: crate::program::motion::MAX_FEEDRATE_MM_S,
            default_feedrate: crate::program::motion::DEFAULT_FEEDRATE_MM_S,
            max_findings_per_kind: 20,
        }
    }

    /// The tool `n`, or the default tool past the end of [`CheckParams::tools`].
    pub fn tool(&self, n: usize) -> ToolCheck {
        self.tools.get(n).cloned().unwrap_or_default()
    }
}

impl Default for CheckParams {
    /// [`CheckParams::for_machine`] of the default printer with the default two tools (a
    /// filament extruder and a paste dispenser), as the default config has them.
    fn default() -> Self {
        Self::for_machine(&Printer::default(), &[Tool::filament(), Tool::paste()])
    }
}

/// How bad a finding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// The print will fail or damage something; `conduit check` exits 1.
    Error,
    /// Suspicious; the print may be fine.
    Warning,
}

/// What a finding is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FindingKind {
    /// Error: a filament tool extrudes but was never given a temperature, or its heater was
    /// turned off (`M104 S0`). (A warning instead when a macro that may heat was called.)
    ColdExtrusion,
    /// Warning: a filament tool extrudes while heating to a target it has not been waited for.
    HeatingNotWaited,
    /// Error: the reached temperature is below [`ToolCheck::min_extrude_temperature`]; the
    /// firmware will refuse to extrude.
    BelowMinTemperature,
    /// Warning: a move ends (or an arc passes) outside the bed plus [`CheckParams::bed_margin`].
    OutsideBed,
    /// Error when extruding, warning when travelling: Z below 0.
    BelowBed,
    /// Warning: Z above `max_height` plus the margin.
    AboveMaxHeight,
    /// Warning: a retraction during an XY move larger than
    /// [`CheckParams::max_moving_retraction`].
    RetractionWhileMoving,
    /// Error: E drops by more than [`CheckParams::lost_reset_drop`] in one move.
    LostExtrusionReset,
    /// Warning: more filament per mm of path than [`CheckParams::max_flow_factor`] allows.
    ExcessiveExtrusion,
    /// Error: an `R` arc whose radius is shorter than half its chord, or an arc without centre.
    InvalidArc,
    /// Error: a move or position command has a parameter whose value is not a number (`XNaN`,
    /// `Yinf`, `X` alone): firmware would skip that axis or reject the line, so the machine does
    /// not go where the file's author meant.
    UnreadableParameter,
    /// Warning: a layer lays plastic over air, an overhang steeper than 45° with no support
    /// beneath (one finding per layer, see [`air`]).
    ExtrusionIntoAir,
}

impl FindingKind {
    fn name(self) -> &'static str {
        match self {
            FindingKind::ColdExtrusion => "cold_extrusion",
            FindingKind::HeatingNotWaited => "heating_not_waited",
            FindingKind::BelowMinTemperature => "below_min_temperature",
            FindingKind::OutsideBed => "outside_bed",
            FindingKind::BelowBed => "below_bed",
            FindingKind::AboveMaxHeight => "above_max_height",
            FindingKind::RetractionWhileMoving => "retraction_while_moving",
            FindingKind::LostExtrusionReset => "lost_extrusion_reset",
            FindingKind::ExcessiveExtrusion => "excessive_extrusion",
            FindingKind::InvalidArc => "invalid_arc",
            FindingKind::UnreadableParameter => "unreadable_parameter",
            FindingKind::ExtrusionIntoAir => "extrusion_into_air",
        }
    }
}

impl fmt::Display for FindingKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One problem found, at one line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Finding {
    /// Error or warning.
    pub severity: Severity,
    /// What it is about.
    pub kind: FindingKind,
    /// 1-based line number in the file.
    pub line: usize,
    /// What is wrong, with the values involved.
    pub message: String,
}

/// Filament (or paste) used by one tool.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ToolUsage {
    /// Tool number.
    pub tool: usize,
    /// E increase of extruding moves (moves with X or Y that extrude), mm.
    pub filament_mm: f64,
    /// The same as a volume, mm³ (filament cross-section × `filament_mm`).
    pub filament_mm3: f64,
    /// Sum of every E change, retractions included, mm.
    pub e_net_mm: f64,
    /// Number of extruding moves.
    pub extrusion_moves: usize,
}

/// An axis-aligned box, mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Bounds3 {
    /// Smallest X, Y, Z.
    pub min: [f64; 3],
    /// Largest X, Y, Z.
    pub max: [f64; 3],
}

/// What the print consists of.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct Stats {
    /// Lines in the file.
    pub lines: usize,
    /// Motion commands (`G0`–`G3`, and bare-coordinate continuations).
    pub moves: usize,
    /// Moves with X or Y that extrude.
    pub extrusion_moves: usize,
    /// Moves with X or Y that do not extrude.
    pub travel_moves: usize,
    /// `G2`/`G3` arcs.
    pub arcs: usize,
    /// Moves that lower E, and `G10` firmware retractions.
    pub retractions: usize,
    /// `T<n>` commands that changed the tool.
    pub tool_changes: usize,
    /// Printed layers: distinct Z heights (to 1 µm) of extruding moves.
    pub layers: usize,
    /// Lowest and highest of those Z heights, mm.
    pub layer_z_range: Option<[f64; 2]>,
    /// Filament per tool, for tools that extruded, by tool number.
    pub tools: Vec<ToolUsage>,
    /// Extent of the extruding moves (both ends; arcs sampled), mm.
    pub extrusion_bounds: Option<Bounds3>,
    /// Path length of extruding moves, mm.
    pub print_distance_mm: f64,
    /// Path length of non-extruding XY moves, mm.
    pub travel_distance_mm: f64,
    /// Estimated print time, s (see the module docs for the model).
    pub estimated_time_s: f64,
    /// Highest bed target temperature set, °C.
    pub max_bed_temperature: Option<f64>,
}

/// The result of [`check`]: findings and statistics.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckReport {
    /// Findings in file order, at most [`CheckParams::max_findings_per_kind`] of each kind.
    pub findings: Vec<Finding>,
    /// Number of findings of each kind, listed or not.
    pub counts: BTreeMap<FindingKind, usize>,
    /// Number of error-level findings.
    pub errors: usize,
    /// Number of warning-level findings.
    pub warnings: usize,
    /// What the print consists of.
    pub stats: Stats,
    /// The time estimate move by move: (G-code line, s) for each move that takes time, in file
    /// order (dwells not included); sums to [`Stats::estimated_time_s`] less the dwells. Not
    /// serialised: the 3D view's layer times come from it.
    #[serde(skip)]
    pub move_times: Vec<(usize, f64)>,
}

impl CheckReport {
    /// True when any finding is an error (`conduit check` then exits 1).
    pub fn has_errors(&self) -> bool {
        self.errors > 0
    }

    /// The listed findings of one kind.
    pub fn of_kind(&self, kind: FindingKind) -> impl Iterator<Item = &Finding> {
        self.findings.iter().filter(move |f| f.kind == kind)
    }
}

/// Replays `gcode` on the printer described by `params` and reports problems and statistics.
pub fn check(gcode: &conduit_gcode::Gcode, params: &CheckParams) -> CheckReport {
    let mut report = machine::replay(gcode, params);
    let layers = air::air_layers(&moves(gcode, params.flavor), params);
    report.add_air(&layers, params.max_findings_per_kind);
    report
}

impl CheckReport {
    /// One [`FindingKind::ExtrusionIntoAir`] warning per layer of `layers`, listed in line
    /// order among the other findings up to `max_listed`.
    fn add_air(&mut self, layers: &[air::AirLayer], max_listed: usize) {
        if layers.is_empty() {
            return;
        }
        let kind = FindingKind::ExtrusionIntoAir;
        for (i, l) in layers.iter().enumerate() {
            if i < max_listed {
                self.findings.push(Finding {
                    severity: Severity::Warning,
                    kind,
                    line: l.line,
                    message: format!(
                        "layer at Z {:.3} mm lays {:.1} mm of extrusion over air (an overhang \
                         steeper than 45° with nothing beneath), first at X {:.3} Y {:.3}{}",
                        l.z,
                        l.length,
                        l.at[0],
                        l.at[1],
                        l.role
                            .as_deref()
                            .map(|r| format!(" ({r})"))
                            .unwrap_or_default()
                    ),
                });
            }
        }
        *self.counts.entry(kind).or_insert(0) += layers.len();
        self.warnings += layers.len();
        self.findings.sort_by_key(|f| f.line);
    }
}

/// `1h 2m 3s` / `17m 0s` / `42s`.
fn format_duration(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    let (h, m, s) = (s / 3600, s / 60 % 60, s % 60);
    if h > 0 {
        format!("{h}h {m}m {s}s")
    } else if m > 0 {
        format!("{m}m {s}s")
    } else {
        format!("{s}s")
    }
}

impl fmt::Display for CheckReport {
    /// The human-readable report of `conduit check`: findings, then statistics.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for finding in &self.findings {
            let sev = match finding.severity {
                Severity::Error => "error",
                Severity::Warning => "warning",
            };
            writeln!(
                f,
                "{sev}: line {}: {} [{}]",
                finding.line, finding.message, finding.kind
            )?;
        }
        for (kind, &count) in &self.counts {
            let listed = self.of_kind(*kind).count();
            if count > listed {
                writeln!(f, "... and {} more {kind} findings", count - listed)?;
            }
        }
        let s = &self.stats;
        writeln!(
            f,
            "layers: {}{}",
            s.layers,
            s.layer_z_range
                .map(|[a, b]| format!(" (Z {a:.3} to {b:.3} mm)"))
                .unwrap_or_default()
        )?;
        writeln!(
            f,
            "moves: {} ({} extruding, {} travel, {} arcs), {} retractions, {} tool changes",
            s.moves, s.extrusion_moves, s.travel_moves, s.arcs, s.retractions, s.tool_changes
        )?;
        for t in &s.tools {
            writeln!(
                f,
                "tool {}: {:.2} mm filament ({:.2} cm³)",
                t.tool,
                t.filament_mm,
                t.filament_mm3 / 1000.0
            )?;
        }
        if let Some(b) = s.extrusion_bounds {
            writeln!(
                f,
                "extrusion extent: X {:.3}..{:.3}, Y {:.3}..{:.3}, Z {:.3}..{:.3} mm",
                b.min[0], b.max[0], b.min[1], b.max[1], b.min[2], b.max[2]
            )?;
        }
        writeln!(
            f,
            "estimated time: {} (print {:.0} mm, travel {:.0} mm)",
            format_duration(s.estimated_time_s),
            s.print_distance_mm,
            s.travel_distance_mm
        )?;
        write!(f, "{} errors, {} warnings", self.errors, self.warnings)
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod corpus_tests;
