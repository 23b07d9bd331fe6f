//! The checker: heaters, time, statistics and findings on top of the modal [`Machine`] (see the
//! module docs of [`super`]).

use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::PI;

use conduit_gcode::{Gcode, Line, Machine, Move, Position};

use super::{Bounds3, CheckParams, CheckReport, Finding, FindingKind, Severity, Stats, ToolUsage};
use crate::program::machine::ToolKind;
use crate::program::motion::Planner;

/// Heater state of one tool.
#[derive(Debug, Clone, Default)]
struct Heater {
    /// Last target set, °C (`None`: never set).
    target: Option<f64>,
    /// Line of the command that set the target.
    target_line: usize,
    /// Estimated print time when the target was set, s.
    set_at: f64,
    /// Temperature last waited for (reached), °C.
    reached: Option<f64>,
    /// A temperature finding was reported since the target last changed.
    reported: bool,
}

#[derive(Debug, Clone, Default)]
struct Usage {
    filament_mm: f64,
    e_net_mm: f64,
    extrusion_moves: usize,
}

struct Checker<'a> {
    p: &'a CheckParams,
    machine: Machine,
    heaters: Vec<Heater>,
    macro_seen: Option<String>,
    planner: Planner,
    dwell: f64,
    z_levels: BTreeSet<i64>,
    usage: BTreeMap<usize, Usage>,
    bounds: Option<Bounds3>,
    stats: Stats,
    findings: Vec<Finding>,
    counts: BTreeMap<FindingKind, usize>,
    errors: usize,
    warnings: usize,
}

/// Klipper commands (by prefix) that are known not to heat anything, so they do not soften a
/// cold-extrusion error the way an unknown macro (`PRINT_START`) does.
const NON_HEATING_MACROS: &[&str] = &[
    "EXCLUDE_OBJECT",
    "SET_PRESSURE_ADVANCE",
    "SET_VELOCITY_LIMIT",
    "SET_RETRACTION",
    "SET_GCODE_OFFSET",
    "SET_FAN_SPEED",
    "SET_PRINT_STATS_INFO",
    "SAVE_GCODE_STATE",
    "RESTORE_GCODE_STATE",
    "BED_MESH_",
    "SET_KINEMATIC_POSITION",
];

pub(super) fn replay(g: &Gcode, p: &CheckParams) -> CheckReport {
    let mut m = Checker {
        p,
        machine: Machine::new(p.flavor, p.default_feedrate).with_home(p.home),
        heaters: Vec::new(),
        macro_seen: None,
        planner: Planner::new(p.max_acceleration, p.jerk),
        dwell: 0.0,
        z_levels: BTreeSet::new(),
        usage: BTreeMap::new(),
        bounds: None,
        stats: Stats::default(),
        findings: Vec::new(),
        counts: BTreeMap::new(),
        errors: 0,
        warnings: 0,
    };
    for line in &g.lines {
        m.step(line);
    }
    m.finish(g.lines.len())
}

impl Checker<'_> {
    /// Estimated print time so far, s.
    fn now(&self) -> f64 {
        self.planner.total + self.dwell
    }

    fn heater(&mut self, tool: usize) -> &mut Heater {
        if self.heaters.len() <= tool {
            self.heaters.resize(tool + 1, Heater::default());
        }
        &mut self.heaters[tool]
    }

    fn report(&mut self, severity: Severity, kind: FindingKind, line: usize, message: String) {
        let count = self.counts.entry(kind).or_insert(0);
        *count += 1;
        match severity {
            Severity::Error => self.errors += 1,
            Severity::Warning => self.warnings += 1,
        }
        if *count <= self.p.max_findings_per_kind {
            self.findings.push(Finding {
                severity,
                kind,
                line,
                message,
            });
        }
    }

    /// Reports the parameters of a move (`G0`-`G3`) or position (`G92`) command that did not
    /// read as numbers.
    fn unreadable_parameters(&mut self, line: &Line) {
        let is_position_command =
            matches!(line.command(), Some((b'G', n)) if [0.0, 1.0, 2.0, 3.0, 92.0].contains(&n));
        if !is_position_command {
            return;
        }
        for span in &line.unparsed {
            let token = &line.text[span.clone()];
            if !token.first().is_some_and(u8::is_ascii_alphabetic) {
                continue;
            }
            // Printable ASCII only, so one finding stays one line.
            let shown: String = token
                .iter()
                .take(24)
                .map(|&b| if b.is_ascii_graphic() { b as char } else { '?' })
                .collect();
            self.report(
                Severity::Error,
                FindingKind::UnreadableParameter,
                line.number,
                format!("`{shown}` is not a number; this move would not go where it is meant to"),
            );
        }
    }

    fn step(&mut self, line: &Line) {
        // The machine applies motion and the modal state (units, modes, G92, homing, tool);
        // the checker adds heaters, time and statistics.
        self.unreadable_parameters(line);
        let tool_before = self.machine.tool();
        if let Some(mv) = self.machine.step(line) {
            self.motion(&mv);
            return;
        }
        let Some((letter, number)) = line.command() else {
            if let Some(name) = line.extended_command() {
                self.extended(line, name);
            }
            return;
        };
        if number.fract() != 0.0 {
            return;
        }
        let n = number as i64;
        let current = self.machine.tool();
        match (letter, n) {
            (b'G', 4) => {
                let ms = line.get(b'P').unwrap_or(0.0) + line.get(b'S').unwrap_or(0.0) * 1000.0;
                self.planner.flush();
                self.dwell += ms.max(0.0) / 1000.0;
            }
            (b'G', 10) => {
                if line.get(b'P').is_some() || line.get(b'S').is_some() || line.get(b'R').is_some()
                {
                    // RepRapFirmware: G10 P<tool> S<active> R<standby> sets temperatures.
                    let tool = line.get(b'P').map_or(current, |t| t.max(0.0) as usize);
                    if let Some(s) = line.get(b'S') {
                        self.set_target(tool, s, line.number, false);
                    }
                } else {
                    self.stats.retractions += 1;
                }
            }
            (b'G', 28) => self.planner.flush(),
            (b'M', 104 | 109) => {
                let tool = line.get(b'T').map_or(current, |t| t.max(0.0) as usize);
                let wait = n == 109;
                if wait {
                    self.planner.flush();
                }
                match line.get(b'S').or_else(|| line.get(b'R')) {
                    Some(s) => self.set_target(tool, s, line.number, wait),
                    None if wait => {
                        let h = self.heater(tool);
                        h.reached = h.target;
                    }
                    None => {}
                }
            }
            (b'M', 568) => {
                // RepRapFirmware 3.3+: M568 P<tool> S<active> R<standby>.
                let tool = line.get(b'P').map_or(current, |t| t.max(0.0) as usize);
                if let Some(s) = line.get(b'S') {
                    self.set_target(tool, s, line.number, false);
                }
            }
            (b'M', 116) => {
                self.planner.flush();
                let only = line.get(b'P').map(|t| t.max(0.0) as usize);
                for (i, h) in self.heaters.iter_mut().enumerate() {
                    if only.is_none_or(|t| t == i) {
                        h.reached = h.target;
                    }
                }
            }
            (b'M', 140 | 190) => {
                if n == 190 {
                    self.planner.flush();
                }
                if let Some(s) = line.get(b'S').or_else(|| line.get(b'R')) {
                    let max = self.stats.max_bed_temperature.get_or_insert(s);
                    *max = max.max(s);
                }
            }
            (b'T', t) if t >= 0 => {
                self.planner.flush();
                if t as usize != tool_before {
                    self.stats.tool_changes += 1;
                }
            }
            _ => {}
        }
    }

    fn set_target(&mut self, tool: usize, target: f64, line: usize, wait: bool) {
        let time = self.now();
        let h = self.heater(tool);
        if h.target != Some(target) {
            h.reported = false;
        }
        h.target = Some(target);
        h.target_line = line;
        h.set_at = time;
        if wait {
            h.reached = Some(target);
        }
    }

    /// Klipper's temperature commands; any other macro is remembered as a possible heater.
    fn extended(&mut self, line: &Line, name: &str) {
        let text = String::from_utf8_lossy(&line.text);
        let params: BTreeMap<String, String> = text
            .split_whitespace()
            .skip(1)
            .take_while(|t| !t.starts_with(';'))
            .filter_map(|t| t.split_once('='))
            .map(|(k, v)| (k.to_ascii_uppercase(), v.to_owned()))
            .collect();
        let extruder = |key: &str| -> Option<usize> {
            let h = params.get(key)?.to_ascii_lowercase();
            let rest = h.strip_prefix("extruder")?;
            if rest.is_empty() {
                Some(0)
            } else {
                rest.parse().ok()
            }
        };
        let num = |key: &str| params.get(key).and_then(|v| v.parse::<f64>().ok());
        match name.to_ascii_uppercase().as_str() {
            "SET_HEATER_TEMPERATURE" => {
                if let (Some(t), Some(target)) = (extruder("HEATER"), num("TARGET")) {
                    self.set_target(t, target, line.number, false);
                }
            }
            "TEMPERATURE_WAIT" => {
                if let (Some(t), Some(min)) = (extruder("SENSOR"), num("MINIMUM")) {
                    let h = self.heater(t);
                    h.reached = Some(min.max(h.reached.unwrap_or(min)));
                }
            }
            other => {
                let harmless = NON_HEATING_MACROS.iter().any(|p| other.starts_with(p));
                if self.macro_seen.is_none() && !harmless {
                    self.macro_seen = Some(other.to_owned());
                }
            }
        }
    }

    fn motion(&mut self, mv: &Move) {
        self.stats.moves += 1;
        if mv.arc {
            self.stats.arcs += 1;
        }
        if let Some(msg) = &mv.arc_error {
            self.report(
                Severity::Error,
                FindingKind::InvalidArc,
                mv.line,
                msg.clone(),
            );
        }
        let (length, de, has_xy, path) = (mv.length, mv.e, mv.has_xy, &mv.path);

        // Time.
        self.planner
            .push_gcode_move(mv.line, mv, self.p.max_feedrate);

        // XY moves that extrude, or that dispense paste between `;DISPENSE:` markers.
        let extruding = mv.extruding;
        let usage = self.usage.entry(mv.tool).or_default();
        usage.e_net_mm += de;
        if extruding {
            usage.filament_mm += de;
            usage.extrusion_moves += 1;
            self.stats.extrusion_moves += 1;
            self.stats.print_distance_mm += length;
            if let Some(z) = mv.to[2] {
                self.z_levels.insert((z * 1000.0).round() as i64);
            }
            for q in path {
                self.grow_bounds(*q);
            }
            self.check_temperature(mv.line);
            self.check_flow(mv.line, de, length);
        } else if has_xy {
            self.stats.travel_moves += 1;
            self.stats.travel_distance_mm += length;
        }
        if de < 0.0 {
            self.stats.retractions += 1;
            let drop = -de;
            if drop > self.p.lost_reset_drop {
                self.report(
                    Severity::Error,
                    FindingKind::LostExtrusionReset,
                    mv.line,
                    format!(
                        "E drops by {drop:.3} mm in one move: a missing `G92 E0` or the wrong \
                         M82/M83 extrusion mode?"
                    ),
                );
            } else if has_xy && length > 0.0 && drop > self.p.max_moving_retraction {
                self.report(
                    Severity::Warning,
                    FindingKind::RetractionWhileMoving,
                    mv.line,
                    format!(
                        "retraction of {drop:.3} mm during a {length:.3} mm move (more than \
                         {} mm)",
                        self.p.max_moving_retraction
                    ),
                );
            }
        }
        self.check_bounds(mv.line, path, extruding);
    }

    fn grow_bounds(&mut self, q: Position) {
        let [Some(x), Some(y), Some(z)] = q else {
            return;
        };
        let b = self.bounds.get_or_insert(Bounds3 {
            min: [x, y, z],
            max: [x, y, z],
        });
        for (i, v) in [x, y, z].into_iter().enumerate() {
            b.min[i] = b.min[i].min(v);
            b.max[i] = b.max[i].max(v);
        }
    }

    fn check_temperature(&mut self, line: usize) {
        let tool = self.machine.tool();
        let tc = self.p.tool(tool);
        if tc.kind != ToolKind::Filament {
            return;
        }
        let (tol, heat_up, time) = (
            self.p.temperature_tolerance,
            self.p.heat_up_time_s,
            self.now(),
        );
        let macro_seen = self.macro_seen.clone();
        let h = self.heater(tool).clone();
        if h.reported {
            return;
        }
        let finding = match h.target {
            Some(target) if target > 0.0 => {
                let waited = h.reached.is_some_and(|r| r >= target - tol);
                let timed = time - h.set_at >= heat_up;
                if !(waited || timed) {
                    Some((
                        Severity::Warning,
                        FindingKind::HeatingNotWaited,
                        format!(
                            "tool {tool} extrudes while heating to {target} °C: the target set at \
                             line {} was not waited for (M109/M116), and only {:.0} s passed",
                            h.target_line,
                            time - h.set_at
                        ),
                    ))
                } else {
                    let temp = if waited {
                        target.min(h.reached.unwrap_or(target))
                    } else {
                        target
                    };
                    (temp < tc.min_extrude_temperature).then(|| {
                        (
                            Severity::Error,
                            FindingKind::BelowMinTemperature,
                            format!(
                                "tool {tool} extrudes at {temp} °C, below the {} °C at which \
                                 firmware allows extrusion",
                                tc.min_extrude_temperature
                            ),
                        )
                    })
                }
            }
            _ => {
                let what = match h.target {
                    None => "was never heated".to_owned(),
                    Some(_) => format!("has its heater off (line {})", h.target_line),
                };
                match &macro_seen {
                    Some(m) => Some((
                        Severity::Warning,
                        FindingKind::ColdExtrusion,
                        format!("tool {tool} extrudes but {what}; the macro {m} may heat it"),
                    )),
                    None => Some((
                        Severity::Error,
                        FindingKind::ColdExtrusion,
                        format!("tool {tool} extrudes but {what}"),
                    )),
                }
            }
        };
        if let Some((sev, kind, msg)) = finding {
            self.heater(tool).reported = true;
            self.report(sev, kind, line, msg);
        }
    }

    fn check_flow(&mut self, line: usize, de: f64, length: f64) {
        let tc = self.p.tool(self.machine.tool());
        if tc.kind != ToolKind::Filament || length < self.p.flow_check_min_length {
            return;
        }
        let filament_area = PI * tc.filament_diameter * tc.filament_diameter / 4.0;
        let nozzle_area = PI * tc.nozzle_diameter * tc.nozzle_diameter / 4.0;
        let section = de * filament_area / length;
        let factor = section / nozzle_area;
        if factor > self.p.max_flow_factor {
            self.report(
                Severity::Warning,
                FindingKind::ExcessiveExtrusion,
                line,
                format!(
                    "{section:.3} mm³ of filament per mm of path, {factor:.1}× the nozzle's \
                     area (limit {}×)",
                    self.p.max_flow_factor
                ),
            );
        }
    }

    fn check_bounds(&mut self, line: usize, path: &[Position], extruding: bool) {
        let p = self.p;
        let m = p.bed_margin;
        let mut outside = None;
        let mut below = None;
        let mut above = None;
        // The start point was checked with the previous move.
        for q in path.iter().skip(1) {
            if let (Some(x), Some(y)) = (q[0], q[1]) {
                let out_x = x < p.bed_origin[0] - m || x > p.bed_origin[0] + p.bed_size[0] + m;
                let out_y = y < p.bed_origin[1] - m || y > p.bed_origin[1] + p.bed_size[1] + m;
                if (out_x || out_y) && outside.is_none() {
                    outside = Some((x, y));
                }
            }
            if let Some(z) = q[2] {
                if z < -1e-9 && below.is_none() {
                    below = Some(z);
                }
                if z > p.max_height + m && above.is_none() {
                    above = Some(z);
                }
            }
        }
        if let Some((x, y)) = outside {
            let (x0, y0) = (p.bed_origin[0], p.bed_origin[1]);
            self.report(
                Severity::Warning,
                FindingKind::OutsideBed,
                line,
                format!(
                    "{} to X{x:.3} Y{y:.3}, outside the bed X {x0}..{} Y {y0}..{} (margin {m} mm)",
                    if extruding { "extrusion" } else { "move" },
                    x0 + p.bed_size[0],
                    y0 + p.bed_size[1]
                ),
            );
        }
        if let Some(z) = below {
            let sev = if extruding {
                Severity::Error
            } else {
                Severity::Warning
            };
            self.report(
                sev,
                FindingKind::BelowBed,
                line,
                format!(
                    "{} to Z{z:.3}, below the bed",
                    if extruding { "extrusion" } else { "move" }
                ),
            );
        }
        if let Some(z) = above {
            self.report(
                Severity::Warning,
                FindingKind::AboveMaxHeight,
                line,
                format!("move to Z{z:.3}, above max_height {} mm", p.max_height),
            );
        }
    }

    fn finish(mut self, lines: usize) -> CheckReport {
        self.stats.lines = lines;
        self.stats.layers = self.z_levels.len();
        if let (Some(lo), Some(hi)) = (self.z_levels.first(), self.z_levels.last()) {
            self.stats.layer_z_range = Some([*lo as f64 / 1000.0, *hi as f64 / 1000.0]);
        }
        self.stats.extrusion_bounds = self.bounds;
        self.planner.flush();
        self.stats.estimated_time_s = self.now();
        self.stats.tools = self
            .usage
            .iter()
            .filter(|(_, u)| u.extrusion_moves > 0 || u.e_net_mm != 0.0)
            .map(|(&tool, u)| {
                let d = self.p.tool(tool).filament_diameter;
                ToolUsage {
                    tool,
                    filament_mm: u.filament_mm,
                    filament_mm3: u.filament_mm * PI * d * d / 4.0,
                    e_net_mm: u.e_net_mm,
                    extrusion_moves: u.extrusion_moves,
                }
            })
            .collect();
        CheckReport {
            findings: self.findings,
            counts: self.counts,
            errors: self.errors,
            warnings: self.warnings,
            stats: self.stats,
            move_times: std::mem::take(&mut self.planner.times),
        }
    }
}
