//! The modal machine: positions, units, absolute/relative XYZ and E, `G92`, homing, feed rate,
//! tool, feature role and width, stepped line by line, turning each motion command into a
//! [`Move`].
//!
//! Part of the `formats/` layer and conduit's one G-code interpreter:
//! [`summarize`](crate::summarize) walks a file with it for `conduit info`; conduit's `check`,
//! `preview` and `postprocess` step it (or call [`moves`]) and add their own state (heaters,
//! time, findings, layers, edits) on top. Everything the machine does not model (temperatures,
//! dwells, fans, firmware retraction `G10`/`G11`, macros) is left to the caller, who sees every
//! line.
//!
//! # Model
//!
//! - `G0`/`G1` linear moves; `G2`/`G3` arcs in the XY plane with `I`/`J` (centre offset from the
//!   start) or `R` (radius; negative for the long way round), helical when Z changes, sampled
//!   every 10° at most. A line of bare coordinates (`X1 Y2`) continues the last motion command.
//! - `G90`/`G91` absolute/relative XYZ, and E as [`Firmware`] says; `M82`/`M83` absolute/relative
//!   E.
//! - `G20`/`G21` inches/millimetres: every length, E and F included, is scaled by 25.4 in inch
//!   mode.
//! - `G92` sets the named axes (`G92 E0`); `G28` homes the named axes (all when none is named)
//!   to the machine's home position ([`Machine::with_home`]; 0 unless set).
//! - `T<n>` selects a tool; `F` sets the feed rate (mm/min in the file, kept in mm/s).
//! - Comment lines `;TYPE:<role>` / `; FEATURE: <role>` set the feature role, `;WIDTH:<mm>` the
//!   extrusion width, and `;DISPENSE:ON` / `;DISPENSE:OFF` open and close a paste tool's valve
//!   (XY moves then print although they carry no E).
//!
//! How a line's words are read — the first command only, as firmware does, or every command
//! word, for statistics — is the [`Reading`].
//!
//! # Example
//!
//! ```
//! use conduit_gcode::{Firmware, Machine};
//!
//! let g = conduit_gcode::parse(b"G28\nM83\nG1 X10 Y5 E0.5 F1200\nG91\nG1 X2 E0.1\n")?;
//! let mut machine = Machine::new(Firmware::Marlin, 25.0);
//! let moves: Vec<_> = g.lines.iter().filter_map(|l| machine.step(l)).collect();
//! assert_eq!(moves[0].to, [Some(10.0), Some(5.0), Some(0.0)]);
//! assert_eq!(moves[0].feed, 20.0);
//! assert_eq!(moves[1].to, [Some(12.0), Some(5.0), Some(0.0)]);
//! assert!(moves[1].extruding && machine.e_is_relative());
//! # Ok::<(), conduit_gcode::GcodeError>(())
//! ```

use std::collections::BTreeSet;
use std::f64::consts::PI;
use std::sync::Arc;

use crate::{Gcode, Line};

/// A machine position [X, Y, Z], mm; an axis is `None` while its position is unknown (before it
/// is homed, set by `G92` or moved to absolutely).
pub type Position = [Option<f64>; 3];

/// The firmware dialect, for what `G90`/`G91` do to E.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Firmware {
    /// Marlin 2: `G90`/`G91` set the mode of every axis, E included; `M82`/`M83` then set E's.
    #[default]
    Marlin,
    /// Klipper: `G91` makes E relative as well, `G90` leaves E to `M82`/`M83`.
    Klipper,
    /// RepRapFirmware: only `M82`/`M83` set E's mode.
    RepRapFirmware,
}

/// How the words of a line are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Reading {
    /// As firmware executes the line: its first `G`/`M`/`T` word is the command (`G20 G90`
    /// switches to inches only), a non-integer command (`G29.1`) does nothing, `G92` without
    /// axes does nothing, `G92 X1 X2` takes the first X, and a line that starts with an
    /// extended command (`SET_KINEMATIC_POSITION X=0`) never moves.
    #[default]
    Firmware,
    /// Every command word of the line, in order, with the line's motion applied last (`G20 G90`
    /// switches to inches and absolute): the lenient reading of a file's statistics. Command
    /// numbers are integers up to 10⁶; `G92` without axes sets X, Y, Z and E to 0, and
    /// `G92 X1 X2` takes the last X; `M6 T<n>` selects tool n too.
    Survey,
}

/// A command of the modal state, as [`Machine::step_with`] reports it before applying it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Command {
    /// `G0`–`G3` (the number), also for a line of bare coordinates that continues it.
    Motion(u8),
    /// `G20`: inches.
    Inches,
    /// `G21`: millimetres.
    Millimetres,
    /// `G28`: home.
    Home,
    /// `G90`: absolute positioning.
    Absolute,
    /// `G91`: relative positioning.
    Relative,
    /// `G92`: set position.
    SetPosition,
    /// `M82`: absolute E.
    AbsoluteE,
    /// `M83`: relative E.
    RelativeE,
    /// `T<n>` (or, in the [`Reading::Survey`], `M6 T<n>`): select tool n.
    Tool(usize),
}

impl Command {
    /// The modal command of a command word with an integer number, other than motion.
    fn of(letter: u8, n: i64) -> Option<Command> {
        Some(match (letter, n) {
            (b'G', 20) => Command::Inches,
            (b'G', 21) => Command::Millimetres,
            (b'G', 28) => Command::Home,
            (b'G', 90) => Command::Absolute,
            (b'G', 91) => Command::Relative,
            (b'G', 92) => Command::SetPosition,
            (b'M', 82) => Command::AbsoluteE,
            (b'M', 83) => Command::RelativeE,
            (b'T', t) if t >= 0 => Command::Tool(usize::try_from(t).ok()?),
            _ => return None,
        })
    }
}

/// One motion command (`G0`–`G3`, or a line of bare coordinates continuing one) as the machine
/// executes it.
#[derive(Debug, Clone, PartialEq)]
pub struct Move {
    /// 1-based line number in the file.
    pub line: usize,
    /// Where the move starts, mm.
    pub from: Position,
    /// Where the move ends, mm.
    pub to: Position,
    /// The path as a polyline: `[from, to]` for a straight move, the sampled arc (every 10° at
    /// most, both ends included) for `G2`/`G3`.
    pub path: Vec<Position>,
    /// Path length (r·θ, helical when Z changes, for arcs), mm; 0 when a position is unknown.
    pub length: f64,
    /// E change of the move, mm (negative for a retraction).
    pub e: f64,
    /// The line names X or Y.
    pub has_xy: bool,
    /// The move extrudes: it names X or Y and E increases (or, for `G1`–`G3`, a paste tool's
    /// valve is open).
    pub extruding: bool,
    /// A `G2`/`G3` arc.
    pub arc: bool,
    /// Why the arc's path could not be computed (an `R` radius shorter than half the chord, no
    /// centre); the move is then treated as straight.
    pub arc_error: Option<String>,
    /// Feed rate in effect, mm/s (after this line's `F`).
    pub feed: f64,
    /// Active tool.
    pub tool: usize,
    /// Feature role from the latest `;TYPE:` (PrusaSlicer, Cura, conduit) or `; FEATURE:`
    /// (OrcaSlicer, BambuStudio) comment, as written (`External perimeter`, `WALL-OUTER`).
    pub role: Option<Arc<str>>,
    /// Extrusion width from the latest `;WIDTH:` comment, mm.
    pub width: Option<f64>,
    /// 0-based printed layer, set by [`moves`] (see [`Moves`]); 0 from [`Machine::step`].
    pub layer: usize,
}

/// Every move of a file, with printed layers numbered.
///
/// Layers are the distinct Z heights (to 1 µm) of extruding moves with a known Z, in
/// increasing order, as `conduit check` counts them. An extruding move belongs to the layer of
/// its end Z; any other move (travel, retraction, lift, extrusion at unknown Z) to the layer of
/// the next extruding move, since it leads there — moves after the last extrusion to the last
/// layer, and every move to layer 0 when nothing extrudes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Moves {
    /// The moves in file order.
    pub moves: Vec<Move>,
    /// Z of each layer, mm, increasing.
    pub layer_z: Vec<f64>,
}

impl Moves {
    /// The layer of the first extruding move after line `line` (1-based): the layer printed
    /// next, e.g. over a part placed at that line. The last layer when nothing extrudes after it.
    pub fn next_extruding_layer(&self, line: usize) -> usize {
        let from = self.moves.partition_point(|m| m.line <= line);
        self.moves[from..]
            .iter()
            .find(|m| m.extruding)
            .map_or(self.layer_z.len().saturating_sub(1), |m| m.layer)
    }
}

/// Replays `gcode` as `firmware` would (at 25 mm/s before the first `F`) and returns its moves
/// with layers numbered.
///
/// ```
/// use conduit_gcode::{Firmware, moves};
///
/// let g = conduit_gcode::parse(b"G28\nG1 Z0.2\n;TYPE:Perimeter\nG1 X10 E1\nG1 Y10 E2\n")?;
/// let m = moves(&g, Firmware::Marlin);
/// assert_eq!(m.layer_z, vec![0.2]);
/// assert_eq!(m.moves.len(), 3);
/// assert!(m.moves[2].extruding);
/// assert_eq!(m.moves[2].to, [Some(10.0), Some(10.0), Some(0.2)]);
/// assert_eq!(m.moves[2].role.as_deref(), Some("Perimeter"));
/// # Ok::<(), conduit_gcode::GcodeError>(())
/// ```
pub fn moves(gcode: &Gcode, firmware: impl Into<Firmware>) -> Moves {
    moves_on(gcode, Machine::new(firmware, 25.0))
}

/// [`moves`] stepped on `machine` (its firmware, home position, start state).
///
/// ```
/// use conduit_gcode::{Firmware, Machine, moves_on};
///
/// let g = conduit_gcode::parse(b"G28\nG1 X10\nG28 X\nG1 Y5\n")?;
/// let m = moves_on(&g, Machine::new(Firmware::Marlin, 25.0).with_home([0.0, 0.0, 250.0]));
/// assert_eq!(m.moves[0].from, [Some(0.0), Some(0.0), Some(250.0)]);
/// assert_eq!(m.moves[1].from, [Some(0.0), Some(0.0), Some(250.0)]);
/// # Ok::<(), conduit_gcode::GcodeError>(())
/// ```
pub fn moves_on(gcode: &Gcode, mut machine: Machine) -> Moves {
    let mut moves: Vec<Move> = gcode.lines.iter().filter_map(|l| machine.step(l)).collect();
    let level = |m: &Move| -> Option<i64> {
        m.to[2]
            .filter(|_| m.extruding)
            .map(|z| (z * 1000.0).round() as i64)
    };
    let levels: Vec<i64> = moves
        .iter()
        .filter_map(level)
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect();
    let mut next = levels.len().saturating_sub(1);
    for m in moves.iter_mut().rev() {
        if let Some(l) = level(m) {
            // `levels` holds every level, so the search always finds it.
            next = levels.binary_search(&l).unwrap_or(next);
        }
        m.layer = next;
    }
    Moves {
        moves,
        layer_z: levels.iter().map(|&l| l as f64 / 1000.0).collect(),
    }
}

/// The modal machine state. [`Machine::step`] applies one line: motion commands return a
/// [`Move`]; `G20`/`G21`, `G28`, `G90`/`G91`, `G92`, `M82`/`M83`, `T<n>` and the role, width and
/// dispense comments update the state (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct Machine {
    firmware: Firmware,
    reading: Reading,
    pos: Position,
    /// Where `G28` puts each axis, mm.
    home: [f64; 3],
    e: f64,
    coord_relative: bool,
    e_relative_flag: bool,
    scale: f64,
    feed: f64,
    tool: Option<usize>,
    last_motion: Option<u8>,
    role: Option<Arc<str>>,
    width: Option<f64>,
    /// Between `;DISPENSE:ON` and `;DISPENSE:OFF`: a paste tool's valve is open, so XY moves
    /// print although they carry no E.
    dispensing: bool,
}

impl Machine {
    /// A machine at power-on: positions unknown, absolute coordinates and E, millimetres, tool
    /// 0, feed rate `default_feedrate` (mm/s) until the first `F`, [`Reading::Firmware`].
    pub fn new(firmware: impl Into<Firmware>, default_feedrate: f64) -> Self {
        Self {
            firmware: firmware.into(),
            reading: Reading::Firmware,
            pos: [None; 3],
            home: [0.0; 3],
            e: 0.0,
            coord_relative: false,
            e_relative_flag: false,
            scale: 1.0,
            feed: default_feedrate,
            tool: None,
            last_motion: None,
            role: None,
            width: None,
            dispensing: false,
        }
    }

    /// This machine reading lines as `reading` says.
    pub fn with_reading(mut self, reading: Reading) -> Self {
        self.reading = reading;
        self
    }

    /// This machine at `position` instead of where it is (`[Some(0.0); 3]`: as firmware counts
    /// before homing).
    pub fn with_position(mut self, position: Position) -> Self {
        self.pos = position;
        self
    }

    /// This machine with its home position at `home` [X, Y, Z] (mm): where `G28` puts the axes
    /// it homes, as the firmware's endstops do (`[0, 0, 0]` unless set).
    pub fn with_home(mut self, home: [f64; 3]) -> Self {
        self.home = home;
        self
    }

    /// The home position [X, Y, Z], mm.
    pub fn home(&self) -> [f64; 3] {
        self.home
    }

    /// The active tool (0 until a tool is selected).
    pub fn tool(&self) -> usize {
        self.tool.unwrap_or(0)
    }

    /// The tool last selected, `None` before any selection.
    pub fn selected_tool(&self) -> Option<usize> {
        self.tool
    }

    /// The current position, mm.
    pub fn position(&self) -> Position {
        self.pos
    }

    /// The E register (what `G92 E` sets and absolute E values are measured against), mm.
    pub fn e(&self) -> f64 {
        self.e
    }

    /// The feed rate in effect, mm/s.
    pub fn feed(&self) -> f64 {
        self.feed
    }

    /// Whether X, Y and Z are read as relative now (after `G91`).
    pub fn is_relative(&self) -> bool {
        self.coord_relative
    }

    /// Whether the file's units are inches now (after `G20`).
    pub fn is_inches(&self) -> bool {
        self.scale > 1.0
    }

    /// Whether E values are read as relative now: after `M83`, or after `G91` where the
    /// [`Firmware`] makes E follow it.
    pub fn e_is_relative(&self) -> bool {
        match self.firmware {
            Firmware::Klipper => self.coord_relative || self.e_relative_flag,
            Firmware::Marlin | Firmware::RepRapFirmware => self.e_relative_flag,
        }
    }

    /// Applies one line; returns the move when it is a motion command.
    pub fn step(&mut self, line: &Line) -> Option<Move> {
        self.step_with(line, |_, _| {})
    }

    /// [`Machine::step`], calling `seen` with each command of the line and the machine as it is
    /// before the command applies (the motion, when the line moves, last).
    pub fn step_with(
        &mut self,
        line: &Line,
        mut seen: impl FnMut(&Machine, Command),
    ) -> Option<Move> {
        if line.words.is_empty() {
            if line.extended_command().is_none() {
                self.comment(line);
            }
            return None;
        }
        let motion = match self.reading {
            Reading::Firmware => {
                let Some((letter, number)) = line.command() else {
                    if line.extended_command().is_some() {
                        return None;
                    }
                    return self.continuation(line, seen);
                };
                if number.fract() != 0.0 {
                    return None;
                }
                let n = number as i64;
                if letter == b'G' && (0..=3).contains(&n) {
                    n as u8
                } else {
                    if let Some(command) = Command::of(letter, n) {
                        seen(self, command);
                        self.apply(command, line);
                    }
                    return None;
                }
            }
            Reading::Survey => {
                let mut motion = None;
                let mut has_command = false;
                let first = line.command().map(|(letter, _)| letter);
                for w in &line.words {
                    if !matches!(w.letter, b'G' | b'M' | b'T') {
                        continue;
                    }
                    has_command = true;
                    let Some(n) = code(w.value) else { continue };
                    let command = match (w.letter, n) {
                        (b'G', 0..=3) => {
                            motion = Some(n as u8);
                            continue;
                        }
                        (b'M', 6) => line.get(b'T').and_then(code).map(Command::Tool),
                        (b'T', _) if first != Some(b'T') => None,
                        (letter, n) => Command::of(letter, n as i64),
                    };
                    if let Some(command) = command {
                        seen(self, command);
                        self.apply(command, line);
                    }
                }
                match motion {
                    Some(m) => m,
                    None if !has_command => return self.continuation(line, seen),
                    None => return None,
                }
            }
        };
        self.last_motion = Some(motion);
        seen(self, Command::Motion(motion));
        Some(self.motion(line, motion))
    }

    /// A line without a command: bare coordinates continue the last motion command (CNC modal
    /// style).
    fn continuation(
        &mut self,
        line: &Line,
        mut seen: impl FnMut(&Machine, Command),
    ) -> Option<Move> {
        let motion = self.last_motion.filter(|_| {
            line.words
                .iter()
                .any(|w| matches!(w.letter, b'X' | b'Y' | b'Z' | b'E'))
        })?;
        seen(self, Command::Motion(motion));
        Some(self.motion(line, motion))
    }

    /// Applies a modal command other than motion.
    fn apply(&mut self, command: Command, line: &Line) {
        let marlin = self.firmware == Firmware::Marlin;
        match command {
            Command::Motion(_) => {}
            Command::Inches => self.scale = 25.4,
            Command::Millimetres => self.scale = 1.0,
            Command::Home => {
                let named: Vec<usize> = [b'X', b'Y', b'Z']
                    .iter()
                    .enumerate()
                    .filter(|(_, l)| line.words.iter().any(|w| w.letter == **l))
                    .map(|(i, _)| i)
                    .collect();
                if named.is_empty() {
                    self.pos = self.home.map(Some);
                }
                for i in named {
                    self.pos[i] = Some(self.home[i]);
                }
            }
            Command::Absolute => {
                self.coord_relative = false;
                if marlin {
                    self.e_relative_flag = false;
                }
            }
            Command::Relative => {
                self.coord_relative = true;
                if marlin {
                    self.e_relative_flag = true;
                }
            }
            Command::SetPosition => self.set_position(line),
            Command::AbsoluteE => self.e_relative_flag = false,
            Command::RelativeE => self.e_relative_flag = true,
            Command::Tool(t) => self.tool = Some(t),
        }
    }

    /// `G92`: sets the named axes (see [`Reading`] for a `G92` without any).
    fn set_position(&mut self, line: &Line) {
        let mut set = |letter: u8, v: f64| {
            let v = v * self.scale;
            match letter {
                b'X' => self.pos[0] = Some(v),
                b'Y' => self.pos[1] = Some(v),
                b'Z' => self.pos[2] = Some(v),
                _ => self.e = v,
            }
        };
        match self.reading {
            Reading::Firmware => {
                for letter in [b'X', b'Y', b'Z', b'E'] {
                    if let Some(v) = line.get(letter) {
                        set(letter, v);
                    }
                }
            }
            Reading::Survey => {
                let mut named = false;
                for w in &line.words {
                    if matches!(w.letter, b'X' | b'Y' | b'Z' | b'E') {
                        named = true;
                        set(w.letter, w.value);
                    }
                }
                if !named {
                    self.pos = [Some(0.0); 3];
                    self.e = 0.0;
                }
            }
        }
    }

    /// `;TYPE:<role>`, `; FEATURE: <role>`, `;WIDTH:<mm>` and `;DISPENSE:ON|OFF` comment lines.
    fn comment(&mut self, line: &Line) {
        let Some(text) = line.comment_text() else {
            return;
        };
        if let Some(role) = text
            .strip_prefix("TYPE:")
            .or_else(|| text.strip_prefix("FEATURE:"))
        {
            let role = role.trim();
            if self.role.as_deref() != Some(role) {
                self.role = Some(Arc::from(role));
            }
        } else if let Some(state) = text.strip_prefix("DISPENSE:") {
            match state.trim() {
                "ON" => self.dispensing = true,
                "OFF" => self.dispensing = false,
                _ => {}
            }
        } else if let Some(w) = text.strip_prefix("WIDTH:") {
            if let Ok(w) = w.trim().parse::<f64>() {
                if w.is_finite() && w > 0.0 {
                    self.width = Some(w);
                }
            }
        }
    }

    fn motion(&mut self, line: &Line, g: u8) -> Move {
        let scale = self.scale;
        if let Some(f) = line.get(b'F') {
            if f > 0.0 {
                self.feed = f * scale / 60.0;
            }
        }
        let start = self.pos;
        let mut end = start;
        for (i, l) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
            if let Some(v) = line.get(l) {
                let v = v * scale;
                end[i] = if self.coord_relative {
                    start[i].map(|s| s + v)
                } else {
                    Some(v)
                };
            }
        }
        let de = match line.get(b'E') {
            Some(v) if self.e_is_relative() => {
                self.e += v * scale;
                v * scale
            }
            Some(v) => {
                let d = v * scale - self.e;
                self.e = v * scale;
                d
            }
            None => 0.0,
        };
        let has_xy = line.get(b'X').is_some() || line.get(b'Y').is_some();
        // Path: a polyline (two points for a line, samples for an arc) and its length.
        let mut path: Vec<Position> = vec![start, end];
        let mut length = None;
        let mut arc_error = None;
        let arc = g == 2 || g == 3;
        if arc {
            match self.arc(line, g == 2, start, end) {
                Ok(Some((len, samples))) => {
                    length = Some(len);
                    path = samples;
                }
                Ok(None) => {}
                Err(msg) => arc_error = Some(msg),
            }
        }
        let length = length.or_else(|| distance(start, end)).unwrap_or(0.0);
        self.pos = end;
        Move {
            line: line.number,
            from: start,
            to: end,
            path,
            length,
            e: de,
            has_xy,
            extruding: has_xy && (de > 0.0 || (self.dispensing && g != 0)),
            arc,
            arc_error,
            feed: self.feed,
            tool: self.tool(),
            role: self.role.clone(),
            width: self.width,
            layer: 0,
        }
    }

    /// Length and sampled points of an arc, `Ok(None)` when a position is unknown.
    #[allow(clippy::type_complexity)]
    fn arc(
        &self,
        line: &Line,
        clockwise: bool,
        start: Position,
        end: Position,
    ) -> Result<Option<(f64, Vec<Position>)>, String> {
        let (Some(x0), Some(y0), Some(x1), Some(y1)) = (start[0], start[1], end[0], end[1]) else {
            return Ok(None);
        };
        let s = self.scale;
        let (cx, cy, r, sweep);
        if let Some(rr) = line.get(b'R') {
            let rr = rr * s;
            let (dx, dy) = (x1 - x0, y1 - y0);
            let chord = dx.hypot(dy);
            if chord == 0.0 || rr.abs() < chord / 2.0 - 1e-9 {
                return Err(format!(
                    "arc radius R{} is shorter than half the chord ({chord:.4} mm)",
                    rr / s
                ));
            }
            r = rr.abs();
            let h = (r * r - chord * chord / 4.0).max(0.0).sqrt();
            // Centre to the left of the chord for a CCW short arc, right for CW; R<0 flips.
            let left = (!clockwise) ^ (rr < 0.0);
            let (mx, my) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
            let (nx, ny) = (-dy / chord, dx / chord);
            let sign = if left { 1.0 } else { -1.0 };
            cx = mx + sign * h * nx;
            cy = my + sign * h * ny;
            let short = 2.0 * (chord / (2.0 * r)).min(1.0).asin();
            sweep = if rr < 0.0 { 2.0 * PI - short } else { short };
        } else {
            let (i, j) = (line.get(b'I'), line.get(b'J'));
            if i.is_none() && j.is_none() {
                return Err("arc without I/J centre or R radius".to_owned());
            }
            cx = x0 + i.unwrap_or(0.0) * s;
            cy = y0 + j.unwrap_or(0.0) * s;
            r = (x0 - cx).hypot(y0 - cy);
            let a0 = (y0 - cy).atan2(x0 - cx);
            let a1 = (y1 - cy).atan2(x1 - cx);
            let mut d = if clockwise { a0 - a1 } else { a1 - a0 };
            d = d.rem_euclid(2.0 * PI);
            // Same start and end: a full circle.
            if d < 1e-9 {
                d = 2.0 * PI;
            }
            sweep = d;
        }
        let planar = r * sweep;
        let dz = match (start[2], end[2]) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        let length = planar.hypot(dz);
        let a0 = (y0 - cy).atan2(x0 - cx);
        let steps = ((sweep / (PI / 18.0)).ceil() as usize).max(1);
        let dir = if clockwise { -1.0 } else { 1.0 };
        let mut samples = Vec::with_capacity(steps + 1);
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            let a = a0 + dir * sweep * t;
            let z = match (start[2], end[2]) {
                (Some(za), Some(zb)) => Some(za + (zb - za) * t),
                _ => end[2],
            };
            samples.push([Some(cx + r * a.cos()), Some(cy + r * a.sin()), z]);
        }
        if let Some(last) = samples.last_mut() {
            *last = end;
        }
        Ok(Some((length, samples)))
    }
}

/// The integer value of a command word (`G1` → 1), or `None` for `G29.1`, `G-1` and the like.
fn code(v: f64) -> Option<usize> {
    (v.fract() == 0.0 && (0.0..=1e6).contains(&v)).then_some(v as usize)
}

fn distance(a: Position, b: Position) -> Option<f64> {
    let mut sum = 0.0;
    for i in 0..3 {
        match (a[i], b[i]) {
            (Some(p), Some(q)) => sum += (q - p) * (q - p),
            (None, None) => {}
            // Moving from or to an unknown position: the length is unknown.
            _ => return None,
        }
    }
    Some(sum.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parse;

    /// The moves of `src` on a Marlin machine, and the machine after them.
    fn run(src: &str) -> (Machine, Vec<Move>) {
        let g = parse(src.as_bytes()).expect("test G-code parses");
        let mut machine = Machine::new(Firmware::Marlin, 25.0);
        let moves = g.lines.iter().filter_map(|l| machine.step(l)).collect();
        (machine, moves)
    }

    fn e_modes(firmware: Firmware) -> Vec<bool> {
        let mut m = Machine::new(firmware, 25.0);
        ["G91", "G90", "M83", "G90", "M82", "G91"]
            .iter()
            .map(|l| {
                m.step(&Line::new(*l, crate::LineEnding::None));
                m.e_is_relative()
            })
            .collect()
    }

    #[test]
    fn g90_and_g91_set_e_as_the_firmware_does() {
        let (t, f) = (true, false);
        assert_eq!(e_modes(Firmware::Marlin), vec![t, f, t, f, f, t]);
        assert_eq!(e_modes(Firmware::Klipper), vec![t, f, t, t, f, t]);
        assert_eq!(e_modes(Firmware::RepRapFirmware), vec![f, f, t, t, f, f]);
    }

    #[test]
    fn positions_are_unknown_until_homed_set_or_moved_to() {
        let (_, mv) = run("G91\nG1 X1\nG90\nG1 Y2\nG28 Z0\nG92 X5\nG1 X6 F600\n");
        assert_eq!(mv[0].to, [None; 3]);
        assert_eq!(mv[0].length, 0.0);
        assert_eq!(mv[1].to, [None, Some(2.0), None]);
        assert_eq!(mv[2].from, [Some(5.0), Some(2.0), Some(0.0)]);
        assert_eq!((mv[2].length, mv[2].feed), (1.0, 10.0));
        // Inches scale positions, E and F.
        let (m, mv) = run("G28\nG20\nG1 X1 E1 F60\n");
        assert_eq!(mv[0].to[0], Some(25.4));
        assert_eq!((mv[0].e, mv[0].feed), (25.4, 25.4));
        assert!(m.is_inches() && !m.is_relative());
    }

    #[test]
    fn arcs_are_sampled_and_measured() {
        let (_, mv) = run("G28\nG1 X10 Y0\nG3 X0 Y10 I-10 J0 E1\nG2 X10 Y0 R-10\nG2 X0 Y0 R1\n");
        assert!(mv[1].arc && mv[1].extruding);
        assert!((mv[1].length - 5.0 * PI).abs() < 1e-9);
        assert_eq!(mv[1].path.len(), 10);
        assert!((mv[2].length - 15.0 * PI).abs() < 1e-9);
        assert!(mv[3].arc_error.is_some());
        assert_eq!(mv[3].length, 10.0);
    }

    #[test]
    fn paste_moves_between_dispense_markers_print_without_e() {
        // A paste tool writes no E: the writer's `;DISPENSE:` markers say when its valve is open.
        let g = parse(
            b"G28\nT1\nG1 X0 Y0 Z1\n;DISPENSE:ON\nG1 X10 Y0\nG1 X10 Y10 Z1.5\n\
              ;DISPENSE:OFF\nG1 X0 Y0\n",
        )
        .expect("parses");
        let m = moves(&g, Firmware::Marlin);
        let printing: Vec<bool> = m.moves.iter().map(|m| m.extruding).collect();
        assert_eq!(printing, vec![false, true, true, false]);
        assert!(m.moves.iter().all(|m| m.tool == 1));
        // Both heights of the dispensed moves are printed layers.
        assert_eq!(m.layer_z, vec![1.0, 1.5]);
    }

    #[test]
    fn the_survey_reads_every_command_word() {
        let src = "G20 G90\nG1 X1 Y1 E1\nX2\nG92\nM6 T3\nG92 X1 X2 E0\nT1 M83\n";
        let mut seen = Vec::new();
        let mut survey = Machine::new(Firmware::Marlin, 25.0)
            .with_reading(Reading::Survey)
            .with_position([Some(0.0); 3]);
        let g = parse(src.as_bytes()).expect("parses");
        for l in &g.lines {
            survey.step_with(l, |before, c| seen.push((before.selected_tool(), c)));
        }
        use Command::*;
        let commands: Vec<Command> = seen.iter().map(|s| s.1).collect();
        assert_eq!(
            commands,
            vec![
                Inches,
                Absolute,
                Motion(1),
                Motion(1),
                SetPosition,
                Tool(3),
                SetPosition,
                Tool(1),
                RelativeE
            ]
        );
        assert_eq!(seen[7].0, Some(3));
        assert_eq!(survey.position(), [Some(2.0 * 25.4), Some(0.0), Some(0.0)]);
        assert!(survey.e_is_relative());

        // The firmware reading: first command only, `G92` alone does nothing, first X wins.
        let (firmware, _) = run(src);
        assert_eq!(firmware.position(), [Some(25.4), Some(25.4), None]);
        assert_eq!((firmware.tool(), firmware.e()), (1, 0.0));
        assert!(!firmware.e_is_relative());
    }
}
