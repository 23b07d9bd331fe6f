//! The state machine that walks a [`Program`] and writes G-code lines to a [`GcodeSink`]: the
//! FFF printer's style here, the switched-tool style (an aerosol jet) in [`switched`].

mod layer_events;
mod switched;

pub(super) use switched::header as switched_header;

use std::collections::VecDeque;

use conduit_gcode::{fmt_e, fmt_f, fmt_xyz};

use super::GcodeParams;
use super::flavor::{Dialect, fan, set_bed, wait_bed};
use super::macros::{Globals, Value, Var};
use super::sink::{GcodeSink, Motion, MotionKind};
use super::{EmitError, GcodeStats, Resume, ToolStats};
use crate::geom::Point3;
use crate::program::machine::{Flavor, ToolKind};
use crate::program::motion::{DEFAULT_FEEDRATE_MM_S, JERK_MM_S, MAX_FEEDRATE_MM_S, Planner};
use crate::program::{Event, Feed, Layer, LayerItem, Program, Role, Toolpath};

/// Largest distance between an arc of a path's segments and the chords the FFF style writes
/// for it, mm: half the output resolution.
const ARC_CHORD_TOLERANCE: f64 = 0.0005;

/// Refinements of a layer's slow-down factor: the planned time is not quite proportional to
/// the speeds (acceleration), so the factor is corrected by the time it gives, a few times.
const SLOWDOWN_ROUNDS: usize = 4;

/// Per-tool state and settings prepared once.
struct ToolState {
    /// Filament or paste.
    feed: Feed,
    /// Factor on E.
    multiplier: f64,
    /// Rendered `paste_on_gcode` lines (paste tools).
    paste_on: Vec<String>,
    /// Rendered `paste_off_gcode` lines (paste tools).
    paste_off: Vec<String>,
    /// Filament currently retracted, mm (0 = primed).
    retracted: f64,
    /// Whether the writer has waited for this tool's temperature since it was selected.
    waited: bool,
    /// Totals.
    filament_mm: f64,
    extrusion_time_s: f64,
}

impl ToolState {
    /// Material laid so far, mm³: filament fed times its cross-section, or paste flow times
    /// the time it was on.
    fn volume_mm3(&self, tool: &crate::program::machine::Tool) -> f64 {
        match self.feed {
            Feed::Filament { .. } => self.filament_mm * tool.filament_area(),
            Feed::Paste => self.extrusion_time_s * tool.paste_flow_mm3_s,
        }
    }
}

/// Renders `template` for `tool`, naming the template in errors.
fn render(
    cfg: &GcodeParams,
    name: &str,
    template: &str,
    tool: usize,
    vars: &[(&str, Var)],
    globals: &mut Globals,
) -> Result<Vec<String>, EmitError> {
    if template.trim().is_empty() {
        return Ok(Vec::new());
    }
    match cfg.render_template_with(template, tool, vars, globals) {
        Ok(text) => Ok(text.lines().map(str::to_owned).collect()),
        Err(error) => Err(EmitError::Template {
            template: name.to_owned(),
            error,
        }),
    }
}

/// PrusaSlicer's writable variable for where the nozzle is.
const POSITION: &str = "position";

/// A scalar variable of a template.
fn scalar(v: impl Into<Value>) -> Var {
    Var::Scalar(v.into())
}

/// Replaces line breaks and `;` in text that goes into one G-code line or comment.
fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| {
            if matches!(c, '\n' | '\r' | ';') {
                ' '
            } else {
                c
            }
        })
        .collect()
}

pub(super) struct Writer<'a, S: GcodeSink> {
    cfg: &'a GcodeParams,
    sink: &'a mut S,
    dialect: Dialect,
    relative_e: bool,
    tools: Vec<ToolState>,
    /// Nozzle position (machine coordinates) the writer's moves start from; `None` until the
    /// first XY move and after custom G-code that moved it somewhere unknown.
    pos: Option<Point3>,
    /// Nozzle position as the motion model follows it, custom G-code's moves included
    /// (`G28` to `printer.home`, the start G-code's prime line): where the next planned move
    /// starts; `None` while an axis is unknown.
    at: Option<Point3>,
    /// Z written last, when known, and as written.
    z: Option<f64>,
    z_str: Option<String>,
    /// Absolute E position (absolute mode).
    e: f64,
    /// F word written last (mm/min, formatted).
    feed: Option<String>,
    tool: Option<usize>,
    layer_index: usize,
    layer_z: f64,
    /// Top of the previous layer (0 before the first): where the events of
    /// `printer.custom_gcode_per_print_z` written so far end.
    below_z: f64,
    type_name: Option<&'static str>,
    width: Option<String>,
    height: Option<String>,
    /// Every move written, planned as `conduit check` plans it (its id counts the moves).
    planner: Planner,
    /// Per move pushed to the planner and not yet timed: the tool that extruded in it, if it
    /// extruded; the first is move `planned_from`.
    planned: VecDeque<Option<usize>>,
    /// Id of the first move in `planned`.
    planned_from: usize,
    /// Id of the next move pushed to the planner.
    next_move: usize,
    /// Dwells written, s.
    dwell_s: f64,
    /// The current layer's slow-down factor on print speeds (1: none), see
    /// [`Self::slowdown`].
    speed_factor: f64,
    /// Tools the program uses, ascending.
    used: Vec<usize>,
    /// Fan command written last.
    fan: Option<String>,
    /// The current layer's own fan speed, percent (what [`Event::PartFan`] returns to).
    layer_fan: f64,
    /// Position, carried `E` and totals of a switched-tool job.
    switch: switched::SwitchState,
    /// The next travel stays inside the internal infill ([`Event::TravelInsideInfill`]): no
    /// retraction for it.
    travel_inside: bool,
    /// The template variables that describe the whole print ([`print_variables`]), set by
    /// [`Self::start`] and given to every later template, as PrusaSlicer keeps them.
    print_vars: Vec<(&'static str, Var)>,
    /// The `global` variables the templates defined so far.
    globals: Globals,
    /// Where the last template rendered said its G-code leaves the nozzle, if it said so.
    set_position: Option<[f64; 3]>,
}

impl<'a, S: GcodeSink> Writer<'a, S> {
    pub fn new(cfg: &'a GcodeParams, sink: &'a mut S) -> Result<Self, EmitError> {
        let mut tools = Vec::with_capacity(cfg.tools.len());
        for (i, t) in cfg.tools.iter().enumerate() {
            let (feed, paste_on, paste_off) = match t.kind {
                ToolKind::Filament => (
                    Feed::Filament {
                        diameter: t.filament_diameter,
                    },
                    Vec::new(),
                    Vec::new(),
                ),
                // A switched-tool job switches with its own snippets.
                ToolKind::Paste if cfg.switched.is_some() => (Feed::Paste, Vec::new(), Vec::new()),
                ToolKind::Paste => (
                    Feed::Paste,
                    render(
                        cfg,
                        &format!("tools.{i}.paste_on_gcode"),
                        &t.paste_on_gcode,
                        i,
                        &[],
                        &mut Globals::new(),
                    )?,
                    render(
                        cfg,
                        &format!("tools.{i}.paste_off_gcode"),
                        &t.paste_off_gcode,
                        i,
                        &[],
                        &mut Globals::new(),
                    )?,
                ),
            };
            tools.push(ToolState {
                feed,
                multiplier: t.extrusion_multiplier,
                paste_on,
                paste_off,
                retracted: 0.0,
                waited: false,
                filament_mm: 0.0,
                extrusion_time_s: 0.0,
            });
        }
        Ok(Self {
            cfg,
            sink,
            dialect: super::flavor::Dialect(cfg.printer.flavor),
            relative_e: cfg.printer.use_relative_e_distances,
            tools,
            pos: None,
            at: None,
            z: None,
            z_str: None,
            e: 0.0,
            feed: None,
            tool: None,
            layer_index: 0,
            layer_z: 0.0,
            below_z: 0.0,
            type_name: None,
            width: None,
            height: None,
            planner: Planner::new(cfg.printer.max_acceleration, JERK_MM_S),
            planned: VecDeque::new(),
            planned_from: 0,
            next_move: 0,
            dwell_s: 0.0,
            speed_factor: 1.0,
            used: Vec::new(),
            fan: None,
            layer_fan: 0.0,
            switch: switched::SwitchState::default(),
            travel_inside: false,
            print_vars: Vec::new(),
            globals: Globals::new(),
            set_position: None,
        })
    }

    fn line(&mut self, line: &str) {
        self.plan_command(line);
        self.sink.line(line);
    }

    /// Writes custom G-code (templates, part events) as is and follows it as the firmware
    /// runs it: its moves are planned from where the nozzle is (after `G28`, from
    /// `printer.home`), so the header's estimate includes them as `check`'s does. A block that
    /// moves the nozzle away from where the writer knows it leaves the writer's position, Z and
    /// feed as the block left them (unknown when the block leaves them so), so the next move
    /// writes its own.
    fn lines(&mut self, lines: &[String]) {
        use conduit_gcode::{Line, LineEnding, Machine};
        let start = self
            .at
            .map_or([None; 3], |p| [Some(p.x), Some(p.y), Some(p.z)]);
        let feed = self
            .feed
            .as_deref()
            .and_then(|f| f.parse::<f64>().ok())
            .map_or(DEFAULT_FEEDRATE_MM_S, |f| f / 60.0);
        let mut machine = Machine::new(self.cfg.printer.flavor, feed)
            .with_home(self.cfg.printer.home_position())
            .with_position(start);
        let e_mode = if self.relative_e { "M83" } else { "M82" };
        machine.step(&Line::new(e_mode, LineEnding::Lf));
        machine.step(&Line::new(
            format!("G92 E{}", fmt_e(self.e)),
            LineEnding::Lf,
        ));
        let (mut moved_xy, mut moved_z, mut sets_feed) = (false, false, false);
        let mut names_e = false;
        for l in lines {
            let parsed = Line::new(l.as_str(), LineEnding::Lf);
            self.plan_parsed(&parsed);
            sets_feed |= parsed.get(b'F').is_some();
            names_e |= parsed.get(b'E').is_some();
            if let Some(mv) = machine.step(&parsed) {
                moved_xy |= mv.from[0] != mv.to[0] || mv.from[1] != mv.to[1];
                moved_z |= mv.from[2] != mv.to[2];
                self.plan_custom(&mv);
            }
            self.sink.line(l);
        }
        let end = machine.position();
        self.at = match end {
            [Some(x), Some(y), Some(z)] => Some(Point3::new(x, y, z)),
            _ => None,
        };
        // The writer's own state where the block changed it: a position it knew and the block
        // moved (the next travel starts there), a Z it wrote (the next move writes Z again
        // when the block left it elsewhere), the F in force.
        if moved_xy && self.pos.is_some() {
            self.pos = self.at;
        }
        if moved_z && self.z.is_some() {
            match end[2] {
                Some(z) => self.set_z(z),
                None => {
                    self.z = None;
                    self.z_str = None;
                }
            }
            if let (Some(p), Some(z)) = (self.pos.as_mut(), end[2]) {
                p.z = z;
            }
        }
        if sets_feed {
            self.feed = None;
        }
        // A block that sets or moves E (a layer G-code's `G92 E0`) leaves the absolute E
        // register where the next extrusion counts from.
        if names_e && !self.relative_e {
            self.e = machine.e();
        }
        // A template that set `position` has the last word on where the nozzle is.
        if let Some([x, y, z]) = self.set_position.take() {
            let at = Point3::new(x, y, z);
            self.at = Some(at);
            if self.pos.is_some() {
                self.pos = Some(at);
            }
            if self.z.is_some() {
                self.set_z(z);
            }
        }
    }

    /// Plans a move of custom G-code as `check` does.
    fn plan_custom(&mut self, mv: &conduit_gcode::Move) {
        self.planner
            .push_gcode_move(self.next_move, mv, MAX_FEEDRATE_MM_S);
        self.count_planned(None);
    }

    /// Plans a straight move of `length` mm at `feed` mm/s (capped) along `direction`,
    /// extruded by `tool` if any.
    fn plan_straight(&mut self, length: f64, feed: f64, direction: [f64; 3], tool: Option<usize>) {
        self.planner.push(
            self.next_move,
            length,
            feed.min(MAX_FEEDRATE_MM_S),
            direction,
            direction,
        );
        self.count_planned(tool);
    }

    /// Records the move just pushed to the planner: its id, and the tool that extruded in it.
    fn count_planned(&mut self, tool: Option<usize>) {
        self.next_move += 1;
        self.planned.push_back(tool);
    }

    /// The motion model's side of a command line the writer writes (custom G-code is followed
    /// by [`Self::lines`], which plans its parsed lines the same way): the
    /// firmware empties its queue at a dwell, a heat-up wait, homing and a tool change, and
    /// `check` plans it so; a dwell's time counts. Moves (`G0`/`G1`, the bulk of the file) are
    /// planned where they are written ([`Self::motion`]) and skipped here unparsed; other lines
    /// are read by the G-code crate's tokenizer, as `check` reads them.
    fn plan_command(&mut self, line: &str) {
        let line = line.trim_start();
        if !matches!(
            line.as_bytes().first(),
            Some(b'G' | b'g' | b'M' | b'm' | b'T' | b't')
        ) || line.starts_with("G1 ")
            || line.starts_with("G0 ")
        {
            return;
        }
        self.plan_parsed(&conduit_gcode::Line::new(
            line,
            conduit_gcode::LineEnding::Lf,
        ));
    }

    /// [`Self::plan_command`] of a line already parsed.
    fn plan_parsed(&mut self, parsed: &conduit_gcode::Line) {
        match parsed.command() {
            Some((b'G', 4.0)) => {
                self.planner.flush();
                let ms = parsed.get(b'P').unwrap_or(0.0) + parsed.get(b'S').unwrap_or(0.0) * 1000.0;
                self.dwell_s += ms.max(0.0) / 1000.0;
            }
            Some((b'G', 28.0) | (b'M', 109.0 | 190.0 | 116.0)) => self.planner.flush(),
            Some((b'T', t)) if t >= 0.0 && t.fract() == 0.0 => self.planner.flush(),
            _ => {}
        }
    }

    /// Adds the planned time of the moves the planner has committed to their tools' extrusion
    /// time, and forgets them: `planned` holds only the moves still queued.
    fn take_planned_times(&mut self) {
        for (id, t) in std::mem::take(&mut self.planner.times) {
            while self.planned_from < id {
                self.planned.pop_front();
                self.planned_from += 1;
            }
            if self.planned_from == id {
                self.planned_from += 1;
                if let Some(Some(tool)) = self.planned.pop_front()
                    && let Some(ts) = self.tools.get_mut(tool)
                {
                    ts.extrusion_time_s += t;
                }
            }
        }
    }

    fn motion(
        &mut self,
        kind: MotionKind,
        to: Point3,
        e: f64,
        feed: f64,
        role: Option<crate::program::Role>,
    ) {
        let distance = match (kind, self.at) {
            (MotionKind::Retract | MotionKind::Unretract, _) => e.abs(),
            (_, Some(from)) => (to - from).norm(),
            (_, None) => 0.0,
        };
        let direction = match (kind, self.at) {
            (MotionKind::Retract | MotionKind::Unretract, _) => [0.0; 3],
            (_, Some(from)) if distance > 0.0 => {
                let d = (to - from) / distance;
                [d.x, d.y, d.z]
            }
            _ => [0.0; 3],
        };
        let extruding = kind == MotionKind::Extrude;
        self.plan_straight(distance, feed, direction, self.tool.filter(|_| extruding));
        if extruding
            && let Some(tool) = self.tool
            && let Some(ts) = self.tools.get_mut(tool)
        {
            ts.filament_mm += e;
        }
        let m = Motion {
            kind,
            tool: self.tool,
            role,
            from: self.pos,
            to,
            e,
            feed,
        };
        self.sink.motion(&m);
        if !matches!(kind, MotionKind::Retract | MotionKind::Unretract) {
            self.at = Some(to);
        }
    }

    /// The F word for `mm_s`, or nothing when it is the one in force.
    fn feed_word(&mut self, mm_s: f64) -> Option<String> {
        let f = fmt_f(mm_s * 60.0);
        if self.feed.as_deref() == Some(f.as_str()) {
            None
        } else {
            self.feed = Some(f.clone());
            Some(format!(" F{f}"))
        }
    }

    /// Temperature of `tool` on the current layer.
    fn temperature(&self, tool: usize) -> f64 {
        self.cfg.tools.get(tool).map_or(0.0, |t| {
            if self.layer_index == 0 {
                t.first_layer_temperature
            } else {
                t.temperature
            }
        })
    }

    fn standby_temperature(&self, tool: usize) -> f64 {
        let temp = self.temperature(tool);
        self.cfg
            .tools
            .get(tool)
            .and_then(|t| t.standby_temperature)
            .unwrap_or(temp)
    }

    /// Machine coordinates of a program point printed with `tool`: the point minus the tool's
    /// offset (PrusaSlicer's `extruder_offset` convention: the offset is where the tool's
    /// nozzle sits relative to tool 0's, so the carriage moves the other way).
    fn machine(&self, p: &Point3, tool: usize) -> Point3 {
        let [dx, dy] = self.cfg.tools.get(tool).map_or([0.0, 0.0], |t| t.offset);
        Point3::new(p.x - dx, p.y - dy, p.z)
    }

    fn retract(&mut self) {
        let Some(tool) = self.tool else { return };
        let len = self.cfg.retract_length(tool);
        let is_filament = matches!(
            self.tools.get(tool).map(|t| t.feed),
            Some(Feed::Filament { .. })
        );
        if !is_filament || len <= 0.0 || self.tools[tool].retracted > 0.0 {
            return;
        }
        let speed = self.cfg.printer.retract_speed;
        let at = self
            .pos
            .unwrap_or_else(|| Point3::new(0.0, 0.0, self.z.unwrap_or(0.0)));
        if self.cfg.printer.use_firmware_retraction {
            self.line("G10 ; retract");
        } else {
            let f = self.feed_word(speed).unwrap_or_default();
            let word = if self.relative_e {
                fmt_e(-len)
            } else {
                self.e -= len;
                fmt_e(self.e)
            };
            self.line(&format!("G1 E{word}{f}"));
        }
        self.tools[tool].retracted = len;
        self.motion(MotionKind::Retract, at, -len, speed, None);
    }

    fn unretract(&mut self) {
        let Some(tool) = self.tool else { return };
        let len = self.tools.get(tool).map_or(0.0, |t| t.retracted);
        if len <= 0.0 {
            return;
        }
        let speed = self.cfg.deretract_speed();
        let at = self
            .pos
            .unwrap_or_else(|| Point3::new(0.0, 0.0, self.z.unwrap_or(0.0)));
        if self.cfg.printer.use_firmware_retraction {
            self.line("G11 ; unretract");
        } else {
            let f = self.feed_word(speed).unwrap_or_default();
            let word = if self.relative_e {
                fmt_e(len)
            } else {
                self.e += len;
                fmt_e(self.e)
            };
            self.line(&format!("G1 E{word}{f}"));
        }
        self.tools[tool].retracted = 0.0;
        self.motion(MotionKind::Unretract, at, len, speed, None);
    }

    /// Records that Z `z` was written.
    fn set_z(&mut self, z: f64) {
        self.z = Some(z);
        self.z_str = Some(fmt_xyz(z));
    }

    /// Moves Z alone to `z` at travel speed.
    fn move_z(&mut self, z: f64) {
        if self.z_str.as_deref() == Some(fmt_xyz(z).as_str()) {
            return;
        }
        let speed = self.cfg.printer.travel_speed;
        let f = self.feed_word(speed).unwrap_or_default();
        self.line(&format!("G1 Z{}{f}", fmt_xyz(z)));
        self.set_z(z);
        if let Some(p) = self.pos {
            let to = Point3::new(p.x, p.y, z);
            self.motion(MotionKind::Travel, to, 0.0, speed, None);
            self.pos = Some(to);
        } else if let Some(a) = self.at {
            // Where custom G-code left the nozzle: timed, though the writer's moves do not
            // start there.
            self.plan_straight((z - a.z).abs(), speed, [0.0, 0.0, (z - a.z).signum()], None);
            self.at = Some(Point3::new(a.x, a.y, z));
        }
    }

    /// Travels to `target` (machine coordinates): retract and z-hop when the travel is longer
    /// than `retract_before_travel`, unless an [`Event::TravelInsideInfill`] came before it.
    fn travel_to(&mut self, target: Point3) {
        let inside = std::mem::take(&mut self.travel_inside);
        let speed = self.cfg.printer.travel_speed;
        let Some(cur) = self.pos else {
            // Position unknown (after the start G-code or a part placement). Above the target:
            // XY first, then down, so the nozzle does not come down over a placed part.
            if self.z.is_some_and(|z| z > target.z) {
                let f = self.feed_word(speed).unwrap_or_default();
                self.line(&format!(
                    "G1 X{} Y{}{f}",
                    fmt_xyz(target.x),
                    fmt_xyz(target.y)
                ));
                let over = Point3::new(target.x, target.y, self.z.unwrap_or(target.z));
                self.motion(MotionKind::Travel, over, 0.0, speed, None);
                self.pos = Some(over);
                self.move_z(target.z);
                return;
            }
            // Otherwise Z first, then XY.
            self.move_z(target.z);
            let f = self.feed_word(speed).unwrap_or_default();
            self.line(&format!(
                "G1 X{} Y{}{f}",
                fmt_xyz(target.x),
                fmt_xyz(target.y)
            ));
            self.motion(MotionKind::Travel, target, 0.0, speed, None);
            self.pos = Some(target);
            return;
        };
        let distance = (target - cur).norm();
        let same_xy = fmt_xyz(cur.x) == fmt_xyz(target.x) && fmt_xyz(cur.y) == fmt_xyz(target.y);
        if same_xy {
            self.move_z(target.z);
            self.pos = Some(target);
            return;
        }
        let long = distance > self.cfg.printer.retract_before_travel && !inside;
        if long {
            self.retract();
        }
        let lift = self
            .tool
            .map_or(self.cfg.printer.retract_lift, |t| self.cfg.travel_lift(t));
        let hop = long && lift > 0.0;
        if hop {
            self.move_z(cur.z + lift);
        }
        let f = self.feed_word(speed).unwrap_or_default();
        let z_word = match self.z {
            Some(_) if !hop && self.z_str.as_deref() != Some(fmt_xyz(target.z).as_str()) => {
                format!(" Z{}", fmt_xyz(target.z))
            }
            _ => String::new(),
        };
        self.line(&format!(
            "G1 X{} Y{}{z_word}{f}",
            fmt_xyz(target.x),
            fmt_xyz(target.y)
        ));
        let at = Point3::new(
            target.x,
            target.y,
            if hop { cur.z + lift } else { target.z },
        );
        self.motion(MotionKind::Travel, at, 0.0, speed, None);
        self.pos = Some(at);
        if !z_word.is_empty() {
            self.set_z(target.z);
        }
        if hop {
            self.move_z(target.z);
        }
        self.pos = Some(target);
    }

    /// Tool `tool` as temperature commands name it: `None` (no `T` word) when the print uses
    /// tool 0 alone, as PrusaSlicer writes a print whose highest extruder is the first.
    fn named(&self, tool: usize) -> Option<usize> {
        (tool != 0 || self.used.iter().any(|&t| t > 0)).then_some(tool)
    }

    /// Waits for `tool`'s temperature if it is heated and the writer has not done so since it
    /// was selected.
    fn wait_for_tool(&mut self, tool: usize) {
        let temp = self.temperature(tool);
        if temp > 0.0 && self.tools.get(tool).is_some_and(|t| !t.waited) {
            let l = self.dialect.wait_tool_temperature(self.named(tool), temp);
            self.line(&l);
        }
        if let Some(t) = self.tools.get_mut(tool) {
            t.waited = true;
        }
    }

    /// Switches to `tool`: retract, before snippet, standby for the old tool, `T`, wait, after
    /// snippet, E reset.
    fn tool_change(&mut self, tool: usize) -> Result<(), EmitError> {
        if self.tool == Some(tool) {
            return Ok(());
        }
        let Some(old) = self.tool else {
            self.line(&format!("T{tool}"));
            self.tool = Some(tool);
            return Ok(());
        };
        self.retract();
        let cfg = self.cfg;
        let mut vars = vec![
            ("previous_tool", scalar(old)),
            ("next_tool", scalar(tool)),
            ("layer_num", scalar(self.layer_index)),
            ("layer_z", scalar(self.layer_z)),
        ];
        vars.extend(self.print_vars.iter().cloned());
        vars.extend(self.extruded_vars());
        // As PrusaSlicer: the old filament's end G-code before the tool-change G-code, the new
        // one's start G-code after it.
        self.filament_gcode(old, true, &vars)?;
        let before = self.render_custom(
            "printer.before_tool_change_gcode",
            &cfg.printer.before_tool_change_gcode,
            old,
            &vars,
        )?;
        self.lines(&before);
        if self.temperature(old) > 0.0
            && let Some(standby) = self.cfg.tools.get(old).and_then(|t| t.standby_temperature)
            && let Some(l) = self.dialect.standby(old, standby)
        {
            self.line(&l);
        }
        if let Some(t) = self.tools.get_mut(old) {
            // A tool that cooled to standby must be waited for again.
            t.waited = false;
        }
        // A before snippet that selects the new tool itself (PrusaSlicer's convention for
        // `T{next_extruder}` in its tool-change G-code) replaces conduit's own `T` line.
        let selects = |l: &String| {
            let code = l.split(';').next().unwrap_or_default().trim();
            code.strip_prefix('T') == Some(tool.to_string().as_str())
        };
        if !before.iter().any(selects) {
            self.line(&format!("T{tool}"));
        }
        self.tool = Some(tool);
        self.wait_for_tool(tool);
        let after = self.render_custom(
            "printer.after_tool_change_gcode",
            &cfg.printer.after_tool_change_gcode,
            tool,
            &vars,
        )?;
        self.lines(&after);
        self.filament_gcode(tool, false, &vars)?;
        if !self.relative_e {
            self.line("G92 E0");
            self.e = 0.0;
        }
        self.type_name = None;
        self.width = None;
        Ok(())
    }

    /// Renders a custom G-code template with the file's `global` variables and PrusaSlicer's
    /// writable `position` ([x, y, z] where the nozzle is, mm). A template that assigns
    /// `position` says where its G-code leaves the nozzle (the XL's tool change lifts Z by
    /// `position[2] = position[2] + 2`): the writer takes that over once it has written the
    /// lines ([`Self::lines`]).
    fn render_custom(
        &mut self,
        name: &str,
        template: &str,
        tool: usize,
        vars: &[(&str, Var)],
    ) -> Result<Vec<String>, EmitError> {
        let here = match self.at {
            Some(p) => [p.x, p.y, p.z],
            None => [0.0, 0.0, self.z.unwrap_or(self.layer_z)],
        };
        let seeded = Var::Vector(here.iter().map(|&c| Value::Float(c)).collect());
        self.globals.insert(POSITION.to_owned(), seeded.clone());
        let lines = render(self.cfg, name, template, tool, vars, &mut self.globals);
        let set = self.globals.remove(POSITION).filter(|v| *v != seeded);
        let lines = lines?;
        self.set_position = match set {
            None => None,
            Some(var) => {
                let xyz: Option<Vec<f64>> = match var {
                    Var::Vector(v) => v.iter().map(|c| c.as_f64().ok()).collect(),
                    Var::Scalar(_) => None,
                };
                match xyz.as_deref() {
                    Some(&[x, y, z]) if [x, y, z].iter().all(|c| c.is_finite()) => Some([x, y, z]),
                    _ => {
                        return Err(EmitError::Template {
                            template: name.to_owned(),
                            error: super::macros::TemplateError {
                                line: 1,
                                placeholder: POSITION.to_owned(),
                                problem: super::macros::Problem::NotNumeric,
                            },
                        });
                    }
                }
            }
        };
        Ok(lines)
    }

    /// Writes tool `tool`'s own G-code, its `start_gcode` (`end` false) or its `end_gcode`
    /// (PrusaSlicer's `start_filament_gcode` / `end_filament_gcode`), with
    /// `{filament_extruder_id}` the tool and `vars` besides.
    fn filament_gcode(
        &mut self,
        tool: usize,
        end: bool,
        vars: &[(&'static str, Var)],
    ) -> Result<(), EmitError> {
        let cfg = self.cfg;
        let Some(t) = cfg.tools.get(tool) else {
            return Ok(());
        };
        let (key, template) = if end {
            ("end_gcode", &t.end_gcode)
        } else {
            ("start_gcode", &t.start_gcode)
        };
        let mut all = vec![("filament_extruder_id", scalar(tool))];
        all.extend(vars.iter().cloned());
        let lines = self.render_custom(&format!("tools.{tool}.{key}"), template, tool, &all)?;
        self.lines(&lines);
        Ok(())
    }

    /// Writes `items` into another program's G-code at the machine state `at` (see
    /// [`super::write_block`]): the writer takes over `at`'s tool, position, E and feed, writes
    /// the paths and events, then selects `at.tool` again, travels back to `at.position`,
    /// un-retracts, and restores the E register (absolute E) and the feed rate.
    pub fn block(&mut self, items: &[LayerItem], at: &Resume) -> Result<(), EmitError> {
        if at.tool >= self.tools.len() {
            return Err(EmitError::UnknownTool {
                tool: at.tool,
                count: self.tools.len(),
            });
        }
        self.tool = Some(at.tool);
        self.pos = Some(at.position);
        self.at = Some(at.position);
        self.set_z(at.position.z);
        self.e = at.e;
        self.relative_e = at.relative_e;
        self.feed = Some(fmt_f(at.feed * 60.0));
        self.layer_index = at.layer_index;
        self.layer_z = at.layer_z;
        // The host's tool and the block's.
        let mut used = item_tools(items);
        if let Err(k) = used.binary_search(&at.tool) {
            used.insert(k, at.tool);
        }
        self.used = used;
        // The other program has brought the tool to its temperature.
        self.tools[at.tool].waited = true;
        for item in items {
            match item {
                LayerItem::Path(p) => self.path(p)?,
                LayerItem::Event(e) => self.event(e)?,
            }
        }
        self.tool_change(at.tool)?;
        self.travel_to(at.position);
        self.unretract();
        if !self.relative_e && fmt_e(self.e) != fmt_e(at.e) {
            self.line(&format!("G92 E{}", fmt_e(at.e)));
            self.e = at.e;
        }
        if let Some(f) = self.feed_word(at.feed) {
            self.line(&format!("G1{f}"));
        }
        Ok(())
    }

    pub fn start(&mut self, program: &Program, first_tool: usize) -> Result<(), EmitError> {
        let cfg = self.cfg;
        let layers = program.layers.len();
        let max_z = max_layer_z(program);
        self.print_vars = print_variables(program, cfg.tools.len());
        self.print_vars.extend([
            ("initial_tool", scalar(first_tool)),
            ("initial_extruder", scalar(first_tool)),
            ("total_layer_count", scalar(layers)),
            ("max_layer_z", scalar(max_z)),
        ]);
        let mut vars = self.print_vars.clone();
        // PrusaSlicer's current z-hop: none before the print.
        vars.push(("zhop", scalar(0.0)));
        let start = self.render_custom(
            "printer.start_gcode",
            &cfg.printer.start_gcode,
            first_tool,
            &vars,
        )?;
        let used = used_tools(program);
        self.used = used.clone();
        let scan = scan_start_gcode(&start);
        let rrf = cfg.printer.flavor == Flavor::RepRapFirmware;
        self.line("M107");
        self.fan = Some("M107".to_owned());
        if !scan.bed && cfg.printer.first_layer_bed_temperature > 0.0 {
            self.line(&wait_bed(cfg.printer.first_layer_bed_temperature));
        }
        // As PrusaSlicer: a start G-code that heats no tool gets every used tool heated before
        // it (and a wait for the first one after it). RepRapFirmware always gets its tools'
        // active and standby temperatures (`G10 P S R`), which it needs before selecting them.
        for &t in &used {
            let temp = self.temperature(t);
            if temp > 0.0 && (!scan.any_tool || rrf) {
                let standby = self.standby_temperature(t);
                let l = self
                    .dialect
                    .set_tool_temperature(self.named(t), temp, standby);
                self.line(&l);
            }
        }
        self.line(";TYPE:Custom");
        self.lines(&start);
        self.line("G21 ; set units to millimeters");
        self.line("G90 ; use absolute coordinates");
        self.line(if self.relative_e {
            "M83 ; use relative distances for extrusion"
        } else {
            "M82 ; use absolute distances for extrusion"
        });
        self.line("G92 E0");
        for &t in &scan.waited {
            if let Some(ts) = self.tools.get_mut(t) {
                ts.waited = true;
            }
        }
        // Tools the start G-code leaves cold are preheated to their standby (or first-layer)
        // temperature, so their first tool change does not wait from cold.
        if scan.any_tool && !rrf {
            for &t in used
                .iter()
                .filter(|&&t| t != first_tool && !scan.heats.contains(&t))
            {
                let temp = self.standby_temperature(t);
                if temp > 0.0 {
                    let l = self.dialect.set_tool_temperature(Some(t), temp, temp);
                    self.line(&l);
                }
            }
        }
        if used.len() > 1 || first_tool != 0 {
            self.line(&format!("T{first_tool}"));
        }
        self.tool = Some(first_tool);
        if !scan.any_tool {
            self.wait_for_tool(first_tool);
        }
        let vars = self.print_vars.clone();
        self.filament_gcode(first_tool, false, &vars)?;
        Ok(())
    }

    /// Extrusion time of `layer` with its print speeds times `factor` (never below
    /// `printer.min_print_speed` unless already slower), s: each path planned by the motion
    /// model ([`Planner`]) from a stop to a stop (a travel or a retraction lies between paths).
    fn layer_time(&self, layer: &Layer, factor: f64) -> f64 {
        let mut planner = Planner::new(self.cfg.printer.max_acceleration, JERK_MM_S);
        for path in layer.paths() {
            let speed = self.slowed(path.speed, factor);
            let closing = path.closed.then(|| path.points[0]);
            for (a, b) in path
                .points
                .iter()
                .zip(path.points.iter().skip(1).chain(closing.iter()))
            {
                let d = b - a;
                let length = d.norm();
                if length > 0.0 {
                    let dir = [d.x / length, d.y / length, d.z / length];
                    planner.push(0, length, speed.min(MAX_FEEDRATE_MM_S), dir, dir);
                }
            }
            planner.flush();
        }
        planner.total
    }

    /// `speed` times the layer's slow-down `factor`, not below `printer.min_print_speed` (a
    /// speed already below it is kept).
    fn slowed(&self, speed: f64, factor: f64) -> f64 {
        if factor >= 1.0 {
            speed
        } else {
            (speed * factor).max(self.cfg.printer.min_print_speed.min(speed))
        }
    }

    /// The factor on `layer`'s print speeds that makes it take `printer.slowdown_below_layer_time`
    /// (PrusaSlicer's cooling slow-down), 1 when it takes that long anyway; and the layer's
    /// time at full speed, s.
    fn slowdown(&self, layer: &Layer) -> (f64, f64) {
        let target = self.cfg.printer.slowdown_below_layer_time;
        let time = self.layer_time(layer, 1.0);
        if !(time > 0.0 && time < target) {
            return (1.0, time);
        }
        let mut factor = time / target;
        for _ in 0..SLOWDOWN_ROUNDS {
            let t = self.layer_time(layer, factor);
            if t <= 0.0 || (t - target).abs() < 1e-3 * target {
                break;
            }
            factor = (factor * t / target).min(1.0);
        }
        (factor, time)
    }

    /// Part-cooling fan for a layer that takes `time` s at full speed, percent: off on the first
    /// `disable_fan_first_layers` layers; then, as PrusaSlicer's cooling logic, full speed
    /// (`fan_max_speed`) for layers faster than `slowdown_below_layer_time`, `fan_min_speed` for
    /// layers slower than `fan_below_layer_time`, linear in between.
    fn fan_speed(&self, layer: &Layer, time: f64) -> f64 {
        let p = &self.cfg.printer;
        if layer.index < p.disable_fan_first_layers {
            return 0.0;
        }
        let (lo, hi) = (p.fan_min_speed, p.fan_max_speed);
        let (fast, slow) = (p.slowdown_below_layer_time, p.fan_below_layer_time);
        if time <= fast {
            hi
        } else if time >= slow || slow <= fast {
            lo
        } else {
            hi - (hi - lo) * (time - fast) / (slow - fast)
        }
    }

    pub fn layer(&mut self, layer: &Layer) -> Result<(), EmitError> {
        let cfg = self.cfg;
        self.layer_index = layer.index;
        self.layer_z = layer.z;
        self.line(";LAYER_CHANGE");
        self.line(&format!(";Z:{}", fmt_xyz(layer.z)));
        let h = fmt_xyz(layer.height);
        self.line(&format!(";HEIGHT:{h}"));
        self.height = Some(h);
        // As PrusaSlicer: the layer's number from 0, its top and the print's highest layer.
        let mut layer_vars = vec![
            ("layer_num", scalar(layer.index)),
            ("layer_z", scalar(layer.z)),
        ];
        layer_vars.extend(self.print_vars.iter().cloned());
        layer_vars.extend(self.extruded_vars());
        let tool = self.tool.unwrap_or(0);
        let before = self.render_custom(
            "printer.before_layer_gcode",
            &cfg.printer.before_layer_gcode,
            tool,
            &layer_vars,
        )?;
        self.lines(&before);
        if layer.index == 1 {
            if cfg.printer.bed_temperature != cfg.printer.first_layer_bed_temperature {
                self.line(&set_bed(cfg.printer.bed_temperature));
            }
            // Marlin and Klipper: the active tool now; the others get their temperature from
            // the wait at their next tool change. RepRapFirmware: every tool's active value.
            let tools = if cfg.printer.flavor == Flavor::RepRapFirmware {
                self.used.clone()
            } else {
                self.tool.into_iter().collect()
            };
            for t in tools {
                let Some(tool) = cfg.tools.get(t) else {
                    continue;
                };
                if tool.temperature > 0.0 && tool.temperature != tool.first_layer_temperature {
                    let standby = self.standby_temperature(t);
                    let l =
                        self.dialect
                            .set_tool_temperature(self.named(t), tool.temperature, standby);
                    self.line(&l);
                }
            }
        }
        self.take_planned_times();
        let (factor, time) = self.slowdown(layer);
        self.speed_factor = factor;
        self.layer_fan = self.fan_speed(layer, time);
        let fan_line = fan(self.layer_fan);
        if self.fan.as_deref() != Some(fan_line.as_str()) {
            self.line(&fan_line);
            self.fan = Some(fan_line);
        }
        // Retract before leaving the last layer's end when the way to this layer's first path
        // is long; then lift to the layer.
        let next = layer
            .paths()
            .next()
            .map(|p| (p.tool, p.points.first().copied()));
        if let (Some(cur), Some((tool, Some(first)))) = (self.pos, next)
            && self.tool == Some(tool)
            && (self.machine(&first, tool) - cur).norm() > cfg.printer.retract_before_travel
        {
            self.retract();
        }
        self.move_z(layer.z);
        if !self.relative_e {
            self.line("G92 E0");
            self.e = 0.0;
        }
        let after = self.render_custom(
            "printer.layer_gcode",
            &cfg.printer.layer_gcode,
            tool,
            &layer_vars,
        )?;
        self.lines(&after);
        self.layer_events(layer, &layer_vars)?;
        for item in &layer.items {
            match item {
                LayerItem::Path(p) => self.path(p)?,
                LayerItem::Event(e) => self.event(e)?,
            }
        }
        Ok(())
    }

    fn path(&mut self, path: &Toolpath) -> Result<(), EmitError> {
        if path.points.len() < 2 {
            return Ok(());
        }
        if !is_finite(path) {
            return Err(EmitError::NotFinite {
                layer: self.layer_index,
            });
        }
        let tool = path.tool;
        if tool >= self.tools.len() {
            return Err(EmitError::UnknownTool {
                tool,
                count: self.tools.len(),
            });
        }
        self.tool_change(tool)?;
        self.travel_to(self.machine(&path.points[0], tool));
        self.wait_for_tool(tool);
        self.unretract();
        self.markers(path);
        let h = fmt_xyz(path.height);
        if self.height.as_deref() != Some(h.as_str()) {
            self.line(&format!(";HEIGHT:{h}"));
            self.height = Some(h);
        }
        let speed = self.slowed(path.speed, self.speed_factor);
        if let Some(f) = self.feed_word(speed) {
            self.line(&format!("G1{f}"));
        }
        let ts = &self.tools[tool];
        let e_per_mm = ts
            .feed
            .e_per_mm(path.role.bead_shape(), path.width, path.height)
            .map(|e| e * ts.multiplier);
        let paste_on = ts.paste_on.clone();
        let paste_off = ts.paste_off.clone();
        let is_paste = ts.feed == Feed::Paste;
        if is_paste {
            self.lines(&paste_on);
            // Marks the dispensing moves, which carry no E, for `conduit check` and preview.
            self.line(";DISPENSE:ON");
        }
        let chords = path.chords(ARC_CHORD_TOLERANCE);
        let (points, closed) = match &chords {
            Some(c) => (c.as_slice(), false),
            None => (path.points.as_slice(), path.closed),
        };
        let closing = closed.then(|| path.points[0]);
        let start = self
            .pos
            .unwrap_or_else(|| self.machine(&path.points[0], tool));
        let mut last_xy = (fmt_xyz(start.x), fmt_xyz(start.y));
        // Relative E of points dropped for being closer than the output resolution.
        let mut pending_de = 0.0;
        for p in points.iter().skip(1).chain(closing.iter()) {
            let to = self.machine(p, tool);
            let from = self.pos.unwrap_or(to);
            let de = e_per_mm.map_or(0.0, |k| (to - from).norm() * k);
            let (xs, ys, zs) = (fmt_xyz(to.x), fmt_xyz(to.y), fmt_xyz(to.z));
            let z_changes = self.z_str.as_deref() != Some(zs.as_str());
            if !self.relative_e {
                self.e += de;
            }
            if xs == last_xy.0 && ys == last_xy.1 && !z_changes {
                // The same position once written: merge into the next move (absolute E is
                // cumulative; relative E is carried).
                pending_de += de;
                self.motion(MotionKind::Extrude, to, de, speed, Some(path.role));
                self.pos = Some(to);
                continue;
            }
            let mut words = format!("G1 X{xs} Y{ys}");
            if z_changes {
                words.push_str(" Z");
                words.push_str(&zs);
                self.set_z(to.z);
            }
            if e_per_mm.is_some() {
                let e = if self.relative_e {
                    fmt_e(de + pending_de)
                } else {
                    fmt_e(self.e)
                };
                words.push_str(" E");
                words.push_str(&e);
            }
            pending_de = 0.0;
            self.line(&words);
            self.motion(MotionKind::Extrude, to, de, speed, Some(path.role));
            self.pos = Some(to);
            last_xy = (xs, ys);
        }
        if is_paste {
            self.lines(&paste_off);
            self.line(";DISPENSE:OFF");
        }
        Ok(())
    }

    fn event(&mut self, event: &Event) -> Result<(), EmitError> {
        match event {
            Event::ToolChange { tool } => {
                if *tool >= self.tools.len() {
                    return Err(EmitError::UnknownTool {
                        tool: *tool,
                        count: self.tools.len(),
                    });
                }
                self.tool_change(*tool)?;
            }
            Event::PickAndPlace {
                id,
                part,
                x,
                y,
                z,
                rotation_deg,
            } => {
                let name = one_line(part).replace(' ', "_");
                self.line(&format!(
                    ";PICK_AND_PLACE PART={name} X={} Y={} Z={} ROTATION={}",
                    fmt_xyz(*x),
                    fmt_xyz(*y),
                    fmt_xyz(*z),
                    fmt_xyz(*rotation_deg)
                ));
                let fill = |t: &str| {
                    t.replace("{id}", &id.to_string())
                        .replace("{part}", &name)
                        .replace("{x}", &fmt_xyz(*x))
                        .replace("{y}", &fmt_xyz(*y))
                        .replace("{z}", &fmt_xyz(*z))
                        .replace("{rotation}", &fmt_xyz(*rotation_deg))
                };
                let snippet = fill(&self.cfg.pnp.auto_gcode);
                self.part_event(&snippet);
            }
            Event::ManualInsertPause { part, message } => {
                let name = one_line(part).replace(' ', "_");
                self.line(&format!(";MANUAL_INSERT PART={name}"));
                self.line(&format!("M117 Insert {name}"));
                let pause = self.dialect.pause(one_line(message).trim()).join("\n");
                let snippet = self
                    .cfg
                    .pnp
                    .manual_gcode
                    .replace("{part}", &name)
                    .replace("{pause}", &pause);
                self.part_event(&snippet);
            }
            Event::Comment(text) => {
                for l in text.lines() {
                    self.line(&format!("; {}", l.trim_end()));
                }
            }
            Event::Switch { on, .. } => self.switch_snippet(*on),
            Event::PartFan { at_least } => self.part_fan(*at_least),
            Event::TravelInsideInfill => self.travel_inside = true,
            Event::Dwell { seconds } => {
                if seconds.is_finite() && *seconds > 0.0 {
                    // Its time counts as the line is written (see `plan_command`).
                    self.line(&format!("G4 P{}", fmt_f(seconds * 1000.0)));
                }
            }
        }
        Ok(())
    }

    /// The fan at `at_least` percent or the layer's speed, whichever is higher (`None`: the
    /// layer's), written when it changes; nothing on the layers printed with the fan off.
    fn part_fan(&mut self, at_least: Option<f64>) {
        if self.layer_index < self.cfg.printer.disable_fan_first_layers {
            return;
        }
        let speed = at_least.map_or(self.layer_fan, |p| p.min(100.0).max(self.layer_fan));
        let l = fan(speed);
        if self.fan.as_deref() != Some(l.as_str()) {
            self.line(&l);
            self.fan = Some(l);
        }
    }

    /// The active tool's output switched on or off outside a switched-tool job: the paste
    /// tool's `paste_on_gcode` or `paste_off_gcode` (nothing for a filament tool).
    fn switch_snippet(&mut self, on: bool) {
        let Some(ts) = self.tool.and_then(|t| self.tools.get(t)) else {
            return;
        };
        let lines = if on {
            ts.paste_on.clone()
        } else {
            ts.paste_off.clone()
        };
        self.lines(&lines);
    }

    /// Around a part placement: retract, lift `pnp.lift` above the current layer, the
    /// `snippet` (one line per `\n`), then the active tool selected again. The head's XY is
    /// unknown afterwards, so the next travel goes over at the lifted height before coming down
    /// (see [`Self::travel_to`]).
    fn part_event(&mut self, snippet: &str) {
        self.retract();
        // Over the layer, never lower than the nozzle already is.
        let lifted = (self.layer_z + self.cfg.pnp.lift.max(0.0)).max(self.z.unwrap_or(0.0));
        self.move_z(lifted);
        let lines: Vec<String> = snippet
            .replace("{lift_z}", &fmt_xyz(lifted))
            .split("\n")
            .flat_map(|l| l.lines().map(str::to_owned).collect::<Vec<_>>())
            .filter(|l| !l.trim().is_empty())
            .collect();
        self.lines(&lines);
        if let Some(tool) = self.tool {
            self.line(&format!("T{tool}"));
        }
        self.pos = None;
    }

    pub fn finish(&mut self, program: &Program) -> Result<GcodeStats, EmitError> {
        let cfg = self.cfg;
        self.retract();
        let tool = self.tool.unwrap_or(0);
        let mut vars = vec![
            ("layer_num", scalar(self.layer_index)),
            // As PrusaSlicer: where the nozzle is, a lift after the last retraction included.
            ("layer_z", scalar(self.z.unwrap_or(self.layer_z))),
            ("max_layer_z", scalar(max_layer_z(program))),
        ];
        vars.extend(self.print_vars.iter().cloned());
        vars.extend(self.extruded_vars());
        self.line(";TYPE:Custom");
        // As PrusaSlicer: every tool's end G-code, in tool order, before the printer's.
        for t in 0..cfg.tools.len() {
            self.filament_gcode(t, true, &vars)?;
        }
        let end = self.render_custom("printer.end_gcode", &cfg.printer.end_gcode, tool, &vars)?;
        self.lines(&end);
        self.planner.flush();
        self.take_planned_times();
        Ok(GcodeStats {
            layers: program.layers.len(),
            estimated_time_s: self.planner.total + self.dwell_s,
            tools: self.tool_stats(program),
            events_above_print: self.events_above_print(),
            switched: None,
        })
    }

    /// PrusaSlicer's running totals for custom G-code: `extruded_volume[N]` (mm³) and
    /// `extruded_weight[N]` (g) of each tool so far, and their sums `extruded_volume_total` and
    /// `extruded_weight_total` (a Prusa profile sets the acceleration by the weight carried).
    fn extruded_vars(&self) -> [(&'static str, Var); 4] {
        let (volumes, weights): (Vec<f64>, Vec<f64>) = self
            .tools
            .iter()
            .zip(&self.cfg.tools)
            .map(|(ts, tc)| {
                let v = ts.volume_mm3(tc);
                (v, v / 1000.0 * tc.filament_density)
            })
            .unzip();
        let (volume, weight) = (volumes.iter().sum::<f64>(), weights.iter().sum::<f64>());
        let vector = |xs: Vec<f64>| Var::Vector(xs.into_iter().map(Value::from).collect());
        [
            ("extruded_volume", vector(volumes)),
            ("extruded_weight", vector(weights)),
            ("extruded_volume_total", scalar(volume)),
            ("extruded_weight_total", scalar(weight)),
        ]
    }

    /// Material used by each tool `program` uses.
    fn tool_stats(&self, program: &Program) -> Vec<ToolStats> {
        let cfg = self.cfg;
        used_tools(program)
            .into_iter()
            .filter_map(|t| {
                let (ts, tc) = (self.tools.get(t)?, cfg.tools.get(t)?);
                let volume_mm3 = ts.volume_mm3(tc);
                Some(ToolStats {
                    tool: t,
                    name: tc.name.clone(),
                    kind: tc.kind,
                    filament_mm: ts.filament_mm,
                    volume_cm3: volume_mm3 / 1000.0,
                    grams: volume_mm3 / 1000.0 * tc.filament_density,
                    extrusion_time_s: ts.extrusion_time_s,
                })
            })
            .collect()
    }
}

/// Whether every coordinate, the width and the height of `path` are finite and its speed is
/// positive.
fn is_finite(path: &Toolpath) -> bool {
    let points = path
        .points
        .iter()
        .all(|p| p.x.is_finite() && p.y.is_finite() && p.z.is_finite());
    points
        && path.width.is_finite()
        && path.height.is_finite()
        && path.speed.is_finite()
        && path.speed > 0.0
}

/// Tools the program extrudes with or changes to, ascending.
/// The highest layer's z, mm (0 without layers).
fn max_layer_z(program: &Program) -> f64 {
    program.layers.iter().map(|l| l.z).fold(0.0, f64::max)
}

/// The template variables that describe the print, as PrusaSlicer names them (set before the
/// start G-code and kept for every later template):
/// `first_layer_print_min`, `_max` and `_size` (the bounding box of the material the first
/// layer lays down: every path's centre line grown by half its width, skirt, brim and wipe
/// tower included, close to PrusaSlicer's hull of the layer's outlines; zeros without any),
/// `is_extruder_used` (one flag per tool, and false up to tool 255 as in PrusaSlicer, since an
/// index past a vector's end reads element 0) and `has_wipe_tower`.
fn print_variables(program: &Program, tools: usize) -> Vec<(&'static str, Var)> {
    let mut min = [f64::INFINITY; 2];
    let mut max = [f64::NEG_INFINITY; 2];
    for p in program.layers.first().into_iter().flat_map(|l| l.paths()) {
        let r = p.width.max(0.0) / 2.0;
        for q in &p.points {
            min = [min[0].min(q.x - r), min[1].min(q.y - r)];
            max = [max[0].max(q.x + r), max[1].max(q.y + r)];
        }
    }
    if min[0] > max[0] {
        (min, max) = ([0.0; 2], [0.0; 2]);
    }
    let pair = |a: f64, b: f64| Var::Vector(vec![Value::Float(a), Value::Float(b)]);
    let used = used_tools(program);
    let flags = (0..tools.max(256))
        .map(|t| Value::Bool(used.contains(&t)))
        .collect();
    let tower = program.paths().any(|p| p.role == Role::WipeTower);
    vec![
        ("first_layer_print_min", pair(min[0], min[1])),
        ("first_layer_print_max", pair(max[0], max[1])),
        (
            "first_layer_print_size",
            pair(max[0] - min[0], max[1] - min[1]),
        ),
        ("is_extruder_used", Var::Vector(flags)),
        ("has_wipe_tower", scalar(tower)),
    ]
}

/// The tools `program` extrudes with or changes to, ascending.
pub(super) fn used_tools(program: &Program) -> Vec<usize> {
    item_tools(program.layers.iter().flat_map(|l| &l.items))
}

/// The tools `items` extrude with or change to, ascending.
fn item_tools<'i>(items: impl IntoIterator<Item = &'i LayerItem>) -> Vec<usize> {
    let mut tools: Vec<usize> = items
        .into_iter()
        .filter_map(|item| match item {
            LayerItem::Path(p) => Some(p.tool),
            LayerItem::Event(Event::ToolChange { tool }) => Some(*tool),
            LayerItem::Event(_) => None,
        })
        .collect();
    tools.sort_unstable();
    tools.dedup();
    tools
}

/// What the rendered start G-code does itself.
#[derive(Debug, Default)]
struct StartScan {
    /// Sets the bed temperature (`M140`, `M190`).
    bed: bool,
    /// Sets some tool temperature (`M104`, `M109`, `M116`, `M568`, `G10 P.. S..`,
    /// `SET_HEATER_TEMPERATURE`).
    any_tool: bool,
    /// Tools whose temperature it sets (`T`/`P` word, tool 0 without one).
    heats: Vec<usize>,
    /// Tools it waits for (`M109`, `M116`).
    waited: Vec<usize>,
}

fn scan_start_gcode(lines: &[String]) -> StartScan {
    let mut scan = StartScan::default();
    let text = lines.join("\n");
    let Ok(g) = conduit_gcode::parse(text.as_bytes()) else {
        return scan;
    };
    for l in &g.lines {
        let index = |letter| l.get(letter).map_or(0, |v| v.max(0.0) as usize);
        if l.is_command(b'M', 140) || l.is_command(b'M', 190) {
            scan.bed = true;
        }
        if l.is_command(b'M', 104) || l.is_command(b'M', 109) {
            scan.any_tool = true;
            scan.heats.push(index(b'T'));
        }
        if l.is_command(b'M', 568) || (l.is_command(b'G', 10) && l.get(b'S').is_some()) {
            scan.any_tool = true;
            scan.heats.push(index(b'P'));
        }
        if l.is_command(b'M', 109) {
            scan.waited.push(index(b'T'));
        }
        if l.is_command(b'M', 116) {
            scan.any_tool = true;
            scan.waited.push(index(b'P'));
        }
        if l.extended_command()
            .is_some_and(|c| c.eq_ignore_ascii_case("SET_HEATER_TEMPERATURE"))
        {
            scan.any_tool = true;
        }
    }
    scan
}
