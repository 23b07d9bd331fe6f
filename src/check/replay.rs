//! The motion replay shared by `check` and `preview`: the modal machine state (positions, units,
//! absolute/relative XYZ and E, feed rate, tool, feature role and width) stepped line by line,
//! turning each motion command into a [`Move`].
//!
//! [`moves`] replays a whole file and numbers the printed layers; the checker steps a
//! [`Replay`] itself and adds its own state (heaters, time, findings) on top.

use std::collections::BTreeSet;
use std::f64::consts::PI;
use std::sync::Arc;

use conduit_gcode::{Gcode, Line};

use crate::config::Flavor;

/// A machine position [X, Y, Z], mm; an axis is `None` while its position is unknown (before it
/// is homed, set by `G92` or moved to absolutely).
pub type Position = [Option<f64>; 3];

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
    /// The move extrudes: it names X or Y and E increases.
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
    /// 0-based printed layer, set by [`moves`] (see [`Moves`]); 0 from [`Replay::step`].
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

/// Replays `gcode` as firmware of `flavor` would and returns its moves with layers numbered.
///
/// ```
/// use conduit::check::moves;
/// use conduit::config::Flavor;
///
/// let g = conduit_gcode::parse(b"G28\nG1 Z0.2\n;TYPE:Perimeter\nG1 X10 E1\nG1 Y10 E2\n")?;
/// let m = moves(&g, Flavor::Marlin);
/// assert_eq!(m.layer_z, vec![0.2]);
/// assert_eq!(m.moves.len(), 3);
/// assert!(m.moves[2].extruding);
/// assert_eq!(m.moves[2].to, [Some(10.0), Some(10.0), Some(0.2)]);
/// assert_eq!(m.moves[2].role.as_deref(), Some("Perimeter"));
/// # Ok::<(), conduit_gcode::GcodeError>(())
/// ```
pub fn moves(gcode: &Gcode, flavor: Flavor) -> Moves {
    let mut replay = Replay::new(flavor, 25.0);
    let mut moves: Vec<Move> = gcode.lines.iter().filter_map(|l| replay.step(l)).collect();
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

/// The modal machine state. [`Replay::step`] applies one line: motion commands return a
/// [`Move`]; `G20`/`G21`, `G28`, `G90`/`G91`, `G92`, `M82`/`M83`, `T<n>` and the role and width
/// comments update the state. Everything else (temperatures, dwells...) is left to the caller.
#[derive(Debug, Clone)]
pub struct Replay {
    flavor: Flavor,
    pos: Position,
    e: f64,
    coord_relative: bool,
    e_relative_flag: bool,
    scale: f64,
    feed: f64,
    tool: usize,
    last_motion: Option<u8>,
    role: Option<Arc<str>>,
    width: Option<f64>,
    /// Between `;DISPENSE:ON` and `;DISPENSE:OFF`: a paste tool's valve is open, so XY moves
    /// print although they carry no E.
    dispensing: bool,
}

impl Replay {
    /// A machine at power-on: positions unknown, absolute coordinates and E, millimetres, tool
    /// 0, feed rate `default_feedrate` (mm/s) until the first `F`.
    pub fn new(flavor: Flavor, default_feedrate: f64) -> Self {
        Self {
            flavor,
            pos: [None; 3],
            e: 0.0,
            coord_relative: false,
            e_relative_flag: false,
            scale: 1.0,
            feed: default_feedrate,
            tool: 0,
            last_motion: None,
            role: None,
            width: None,
            dispensing: false,
        }
    }

    /// The active tool.
    pub fn tool(&self) -> usize {
        self.tool
    }

    /// Whether E values are read as relative now: after `M83`, or after `G91` where the flavour
    /// makes E follow it (see the [module docs](super)).
    pub fn e_is_relative(&self) -> bool {
        self.e_relative()
    }

    fn e_relative(&self) -> bool {
        match self.flavor {
            Flavor::Klipper => self.coord_relative || self.e_relative_flag,
            Flavor::Marlin | Flavor::RepRapFirmware => self.e_relative_flag,
        }
    }

    /// Applies one line; returns the move when it is a motion command.
    pub fn step(&mut self, line: &Line) -> Option<Move> {
        let Some((letter, number)) = line.command() else {
            if line.extended_command().is_some() {
                return None;
            }
            if line
                .words
                .iter()
                .any(|w| matches!(w.letter, b'X' | b'Y' | b'Z' | b'E'))
            {
                // Bare coordinates continue the last motion command (CNC modal style).
                return self.last_motion.map(|n| self.motion(line, n));
            }
            if line.words.is_empty() {
                self.comment(line);
            }
            return None;
        };
        if number.fract() != 0.0 {
            return None;
        }
        let n = number as i64;
        match (letter, n) {
            (b'G', 0..=3) => {
                self.last_motion = Some(n as u8);
                return Some(self.motion(line, n as u8));
            }
            (b'G', 20) => self.scale = 25.4,
            (b'G', 21) => self.scale = 1.0,
            (b'G', 28) => {
                let named: Vec<usize> = [b'X', b'Y', b'Z']
                    .iter()
                    .enumerate()
                    .filter(|(_, l)| line.words.iter().any(|w| w.letter == **l))
                    .map(|(i, _)| i)
                    .collect();
                if named.is_empty() {
                    self.pos = [Some(0.0); 3];
                } else {
                    for i in named {
                        self.pos[i] = Some(0.0);
                    }
                }
            }
            (b'G', 90) => {
                self.coord_relative = false;
                if self.flavor == Flavor::Marlin {
                    self.e_relative_flag = false;
                }
            }
            (b'G', 91) => {
                self.coord_relative = true;
                if self.flavor == Flavor::Marlin {
                    self.e_relative_flag = true;
                }
            }
            (b'G', 92) => {
                for (i, l) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
                    if let Some(v) = line.get(l) {
                        self.pos[i] = Some(v * self.scale);
                    }
                }
                if let Some(v) = line.get(b'E') {
                    self.e = v * self.scale;
                }
            }
            (b'M', 82) => self.e_relative_flag = false,
            (b'M', 83) => self.e_relative_flag = true,
            (b'T', t) if t >= 0 => self.tool = t as usize,
            _ => {}
        }
        None
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
            Some(v) if self.e_relative() => {
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
            tool: self.tool,
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
