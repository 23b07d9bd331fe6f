//! The wipe tower: a block beside the objects where each filament tool, just selected, purges
//! the material that oozed or cooled in its nozzle while it stood by, before it prints on the
//! part.
//!
//! Place in the pipeline: a pass over the built [`Program`] (after [`super::build`], before the
//! writer), run when `[wipe_tower]` is enabled and the program changes tools. It adds paths of
//! [`Role::WipeTower`] and changes nothing else.
//!
//! # The tower
//!
//! A rectangle `width` (along X) by `depth` (along Y), standing on the bed from the first layer
//! to the last layer with a tool change (PrusaSlicer's wipe tower, with its keys and defaults).
//! Its depth is the largest purge any layer needs: the sum of that layer's bands (below) over
//! the width, never less than [`MIN_DEPTH_MM`].
//!
//! On every layer of the tower:
//! - **Purge bands.** Right after each change to a filament tool, the new tool fills a band of
//!   the rectangle with lines along X, one bead apart, until it has laid `purge_volume` mm³
//!   (rounded up to whole lines). The bands of one layer lie one after the other from the front.
//! - **The loop.** The first tool to print on the tower on a layer first lays one loop round
//!   the whole rectangle: it anchors the line ends and walls the tower in.
//! - **The rest.** What the bands leave of the rectangle gets lines along Y every
//!   `sparse_spacing` mm, by the last tool that purged (or, on a layer without a change, by the
//!   active tool at the layer's start): the next layer's purge lines, along X, bridge them. The
//!   rest's lines stand at the same X on every layer, so they stack into walls.
//! - **The first layer** is solid: the rest is filled one bead apart too, for adhesion. Its
//!   first tool lays the **brim** before the loop: loops round the tower, outside it, from the
//!   outermost in, `brim_width` wide in whole beads (PrusaSlicer's `wipe_tower_brim_width`), so
//!   a tall, narrow tower standing on one bead's width of its loop holds to the bed.
//!
//! Paste tools are not purged (their flow is switched, not oozing plastic); a change to one adds
//! nothing to the tower. A layer whose only tool is a paste tool gets no tower layer either
//! (the tower's lines above it then bridge one more layer height), and the count of such layers
//! is reported.
//!
//! # Where it stands
//!
//! At `x`, `y` (its front-left corner) when both are given, else beside the objects: right of
//! them, behind, left or in front, the first of those that fits on the bed [`GAP_MM`] clear of
//! every path of the program. A tower that overlaps the objects' paths (within [`MIN_GAP_MM`])
//! or leaves the bed is an error. The brim counts as part of the tower in both.
//!
//! Turned by `rotation` degrees (PrusaSlicer's `wipe_tower_rotation_angle`, anticlockwise seen
//! from above) about its centre: the tower is built as above and every path of it turned, and
//! the box round the turned tower and brim is what must fit on the bed clear of the objects
//! (`x`, `y` stay the corner of the tower before it is turned, as in PrusaSlicer).

use serde::{Deserialize, Serialize};

use crate::geom::Point3;
use crate::program::{Event, LayerItem, Program, Role, Toolpath};

/// Smallest depth of the tower, mm: a narrow tower tips over.
pub const MIN_DEPTH_MM: f64 = 5.0;
/// Clear gap between the objects' paths and a tower placed automatically, mm.
pub const GAP_MM: f64 = 5.0;
/// Smallest clear gap between the objects' paths and a tower placed at `x`, `y`, mm.
pub const MIN_GAP_MM: f64 = 1.0;

/// How the wipe tower is built (`[wipe_tower]` in the config, whose keys these are). Lengths
/// in mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct TowerParams {
    /// Build a wipe tower when the print changes tools. Default false.
    pub enabled: bool,
    /// X of the tower's front-left corner on the bed. Default absent: the tower is placed
    /// beside the objects (set `x` and `y` together).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(example = 180.0)]
    pub x: Option<f64>,
    /// Y of the tower's front-left corner on the bed. Default absent (see `x`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(example = 140.0)]
    pub y: Option<f64>,
    /// Size along X, 5 to 300. Default 60 (PrusaSlicer's `wipe_tower_width`).
    pub width: f64,
    /// Plastic purged on the tower after each change to a filament tool, mm³, 0 to 10000.
    /// Default 140 (PrusaSlicer's default wiping volume).
    pub purge_volume: f64,
    /// Gap between the lines of the tower's sparse part, 1 to 50. Default 10 (PrusaSlicer's
    /// `wipe_tower_bridging`).
    pub sparse_spacing: f64,
    /// Print speed on the tower, mm/s, at most `printer.max_print_speed` (the first layer at
    /// `slice.first_layer_speed`). Default 40.
    pub speed: f64,
    /// Width of the brim round the tower's first layer, 0 to 50 (rounded to whole beads; 0 for
    /// none). Default 2 (PrusaSlicer's `wipe_tower_brim_width`).
    pub brim_width: f64,
    /// Turn of the tower about its centre, degrees anticlockwise seen from above, −360 to 360.
    /// Default 0 (PrusaSlicer's `wipe_tower_rotation_angle`).
    pub rotation: f64,
}

impl Default for TowerParams {
    fn default() -> Self {
        Self {
            enabled: false,
            x: None,
            y: None,
            width: 60.0,
            purge_volume: 140.0,
            sparse_spacing: 10.0,
            speed: 40.0,
            brim_width: 2.0,
            rotation: 0.0,
        }
    }
}

impl TowerParams {
    /// What is wrong with the settings, one message each (empty when they are usable).
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (name, v, lo, hi) in [
            ("width", self.width, 5.0, 300.0),
            ("purge_volume", self.purge_volume, 0.0, 10_000.0),
            ("sparse_spacing", self.sparse_spacing, 1.0, 50.0),
            ("speed", self.speed, 1.0, 1000.0),
            ("brim_width", self.brim_width, 0.0, 50.0),
            ("rotation", self.rotation, -360.0, 360.0),
        ] {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                out.push(format!(
                    "wipe_tower.{name} must be between {lo} and {hi}, got {v}"
                ));
            }
        }
        for (name, v) in [("x", self.x), ("y", self.y)] {
            if v.is_some_and(|v| !v.is_finite()) {
                out.push(format!("wipe_tower.{name} must be a finite number"));
            }
        }
        if self.x.is_some() != self.y.is_some() {
            out.push("wipe_tower.x and wipe_tower.y are set together or not at all".to_owned());
        }
        out
    }
}

/// What the pass needs besides the [`TowerParams`]: the machine and the tools.
#[derive(Debug, Clone, PartialEq)]
pub struct TowerMachine {
    /// The bed: `[min x, min y, max x, max y]`, mm.
    pub bed: [f64; 4],
    /// Per tool: whether it is a filament tool (purged on the tower).
    pub filament: Vec<bool>,
    /// Per tool: the bead width on the tower, mm.
    pub width: Vec<f64>,
    /// Speed of the tower's first layer, mm/s.
    pub first_layer_speed: f64,
}

impl TowerMachine {
    fn is_filament(&self, tool: usize) -> bool {
        self.filament.get(tool).copied().unwrap_or(false)
    }

    fn bead(&self, tool: usize) -> f64 {
        self.width.get(tool).copied().unwrap_or(0.45)
    }
}

/// The tower as built, for the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TowerSummary {
    /// Front-left corner, mm.
    pub x: f64,
    /// Front-left corner, mm.
    pub y: f64,
    /// Size along X, mm.
    pub width: f64,
    /// Size along Y, mm.
    pub depth: f64,
    /// Layers of the tower (from the first).
    pub layers: usize,
    /// Purges made (changes to a filament tool).
    pub purges: usize,
    /// Plastic purged, mm³ (the bands' lines, width × height × length).
    pub purged_volume: f64,
    /// Layers up to the tower's top that got no tower layer (their only tool pastes).
    pub skipped_layers: usize,
    /// Width of the brim laid round the first layer, mm (whole beads; 0 for none).
    pub brim_width: f64,
    /// Turn of the tower about its centre, degrees anticlockwise.
    pub rotation: f64,
}

/// Why no tower could be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TowerError {
    /// No place beside the objects holds the tower on the bed.
    #[error(
        "no room for the {width:.1} × {depth:.1} mm wipe tower on the bed beside the objects \
         (set wipe_tower.x and wipe_tower.y, or a smaller wipe_tower.width)"
    )]
    NoRoom {
        /// Tower width, mm.
        width: f64,
        /// Tower depth, mm.
        depth: f64,
    },
    /// The tower set at `x`, `y` overlaps the objects or leaves the bed.
    #[error("the wipe tower at x {x}, y {y} ({width:.1} × {depth:.1} mm) {why}")]
    BadPlace {
        /// Corner, mm.
        x: f64,
        /// Corner, mm.
        y: f64,
        /// Tower width, mm.
        width: f64,
        /// Tower depth, mm.
        depth: f64,
        /// What is wrong.
        why: String,
    },
}

/// One layer's plan: the changes to a filament tool (item index of the event, tool).
struct LayerPlan {
    purges: Vec<(usize, usize)>,
    /// The active tool at the layer's start.
    first_tool: Option<usize>,
}

/// Adds the wipe tower to `program` (see the module docs); `None` when the program never
/// changes tools (nothing to purge) or the tower is off.
pub fn add_wipe_tower(
    program: &mut Program,
    params: &TowerParams,
    machine: &TowerMachine,
) -> Result<Option<TowerSummary>, TowerError> {
    if !params.enabled {
        return Ok(None);
    }
    let plans = plan(program, machine);
    let Some(top) = plans.iter().rposition(|p| !p.purges.is_empty()) else {
        return Ok(None);
    };
    // The deepest layer's bands, each rounded up to whole lines.
    let depth_needed = plans[..=top]
        .iter()
        .zip(&program.layers)
        .map(|(plan, layer)| {
            plan.purges
                .iter()
                .map(|&(_, tool)| band_depth(params, machine.bead(tool), layer.height))
                .sum::<f64>()
        })
        .fold(0.0, f64::max);
    let loop_bead = machine.width.iter().copied().fold(0.0, f64::max);
    let depth = (depth_needed + 2.0 * loop_bead).max(MIN_DEPTH_MM);
    // The brim is laid, in its beads, by the first layer's first tool on the tower: the tool of
    // its first purge, else its first tool if that prints filament ([`tower_tool`]). A first
    // layer with neither gets no tower layer, and so no brim.
    let brim_bead = plans
        .first()
        .and_then(|p| p.purges.first().map(|&(_, t)| t).or(tower_tool(p, machine)))
        .map(|t| machine.bead(t));
    let brim_loops = brim_bead.map_or(0, |b| brim_loops(params.brim_width, b));
    let brim_width = brim_bead.map_or(0.0, |b| brim_loops as f64 * b);
    let (x, y) = place(program, params, machine, depth, brim_width)?;
    let tower = Rect {
        x0: x,
        y0: y,
        x1: x + params.width,
        y1: y + depth,
    };
    let mut summary = TowerSummary {
        x,
        y,
        width: params.width,
        depth,
        layers: top + 1,
        purges: 0,
        purged_volume: 0.0,
        skipped_layers: 0,
        brim_width,
        rotation: params.rotation,
    };
    let turn = Turn::new(params.rotation, &tower);
    for (k, plan) in plans.iter().enumerate().take(top + 1) {
        let layer = &mut program.layers[k];
        let speed = if k == 0 {
            machine.first_layer_speed.min(params.speed)
        } else {
            params.speed
        };
        let mut builder = LayerBuilder {
            tower,
            z: layer.z,
            height: layer.height,
            speed,
            solid: k == 0,
            brim_loops: if k == 0 { brim_loops } else { 0 },
            turn,
            next_y: tower.y0,
            looped: false,
        };
        // Inserted from the back so that earlier item indices stay valid.
        let mut inserts: Vec<(usize, Vec<Toolpath>)> = Vec::new();
        let last_purge = plan.purges.len().checked_sub(1);
        for (n, &(at, tool)) in plan.purges.iter().enumerate() {
            let bead = machine.bead(tool);
            let mut paths = builder.ring(tool, bead);
            let band = builder.band(tool, bead, params.purge_volume);
            summary.purges += 1;
            summary.purged_volume += band.iter().map(volume).sum::<f64>();
            paths.extend(band);
            if Some(n) == last_purge {
                paths.extend(builder.rest(tool, bead, params.sparse_spacing));
            }
            inserts.push((at + 1, paths));
        }
        if plan.purges.is_empty() {
            match tower_tool(plan, machine) {
                Some(tool) => {
                    let bead = machine.bead(tool);
                    let mut paths = builder.ring(tool, bead);
                    paths.extend(builder.rest(tool, bead, params.sparse_spacing));
                    inserts.push((0, paths));
                }
                None => summary.skipped_layers += 1,
            }
        }
        for (at, paths) in inserts.into_iter().rev() {
            let at = at.min(layer.items.len());
            layer
                .items
                .splice(at..at, paths.into_iter().map(LayerItem::Path));
        }
    }
    Ok(Some(summary))
}

/// Each layer's changes to a filament tool (the machine's tool kinds decide which changes
/// purge) and its first tool. A layer's first tool is the one active when it starts: the
/// previous layer's last, or the program's first tool.
fn plan(program: &Program, machine: &TowerMachine) -> Vec<LayerPlan> {
    let mut active = program.first_tool();
    let mut plans = Vec::with_capacity(program.layers.len());
    for layer in &program.layers {
        let first_tool = active.or_else(|| layer.paths().next().map(|p| p.tool));
        let mut purges = Vec::new();
        for (i, item) in layer.items.iter().enumerate() {
            match item {
                LayerItem::Event(Event::ToolChange { tool }) => {
                    active = Some(*tool);
                    if machine.is_filament(*tool) {
                        purges.push((i, *tool));
                    }
                }
                LayerItem::Path(p) if active.is_none() => active = Some(p.tool),
                _ => {}
            }
        }
        plans.push(LayerPlan { purges, first_tool });
    }
    plans
}

/// The tool that lays a layer's tower layer when the layer purges nothing: its first tool, if
/// that prints filament (a paste tool lays no tower layer).
fn tower_tool(plan: &LayerPlan, machine: &TowerMachine) -> Option<usize> {
    plan.first_tool.filter(|&t| machine.is_filament(t))
}

/// How many loops of `bead` make a brim `width` mm wide: the nearest whole number, at least one
/// for any width above zero.
fn brim_loops(width: f64, bead: f64) -> usize {
    if width <= 0.0 || bead <= 0.0 {
        return 0;
    }
    ((width / bead).round() as usize).max(1)
}

/// Depth along Y of a band of `purge_volume` in lines of `bead` at `height`, mm: whole lines.
fn band_depth(params: &TowerParams, bead: f64, height: f64) -> f64 {
    let line_area = bead * height;
    if line_area <= 0.0 || params.purge_volume <= 0.0 {
        return 0.0;
    }
    let length = params.width - 3.0 * bead;
    if length <= 0.0 {
        return 0.0;
    }
    (params.purge_volume / (line_area * length)).ceil() * bead
}

/// The axis a zig-zag's lines run along.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Axis {
    X,
    Y,
}

/// Line `n` of a zig-zag whose lines run along `axis` between `ends` at `at` on the other axis:
/// even lines from the first end to the second, odd lines back.
fn zigzag_line(n: usize, ends: (f64, f64), at: f64, axis: Axis) -> [[f64; 2]; 2] {
    let (a, b) = if n % 2 == 0 { ends } else { (ends.1, ends.0) };
    match axis {
        Axis::X => [[a, at], [b, at]],
        Axis::Y => [[at, a], [at, b]],
    }
}

/// Plastic in a path, mm³.
fn volume(p: &Toolpath) -> f64 {
    p.length() * p.width * p.height
}

/// An axis-aligned rectangle, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Rect {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Rect {
    /// Whether the two come closer than `gap`.
    fn near(&self, other: &Rect, gap: f64) -> bool {
        self.x0 < other.x1 + gap
            && other.x0 < self.x1 + gap
            && self.y0 < other.y1 + gap
            && other.y0 < self.y1 + gap
    }

    /// Whether `self` lies within `outer`.
    fn within(&self, outer: &Rect) -> bool {
        outer.x0 <= self.x0 && outer.y0 <= self.y0 && self.x1 <= outer.x1 && self.y1 <= outer.y1
    }
}

/// The box of every path of `program` (and its beads), if any.
fn footprint(program: &Program) -> Option<Rect> {
    let mut b: Option<Rect> = None;
    for p in program.paths() {
        let r = p.width / 2.0;
        for q in &p.points {
            let e = b.get_or_insert(Rect {
                x0: q.x,
                y0: q.y,
                x1: q.x,
                y1: q.y,
            });
            e.x0 = e.x0.min(q.x - r);
            e.y0 = e.y0.min(q.y - r);
            e.x1 = e.x1.max(q.x + r);
            e.y1 = e.y1.max(q.y + r);
        }
    }
    b
}

/// Where the tower's front-left corner goes (see the module docs), the tower `depth` deep
/// with a brim `brim` mm wide round it.
fn place(
    program: &Program,
    params: &TowerParams,
    machine: &TowerMachine,
    depth: f64,
    brim: f64,
) -> Result<(f64, f64), TowerError> {
    let bed = Rect {
        x0: machine.bed[0],
        y0: machine.bed[1],
        x1: machine.bed[2],
        y1: machine.bed[3],
    };
    let width = params.width;
    // The box round the tower and its brim, turned about their centre: `fw` × `fd`, its corner
    // `ox`, `oy` from the tower's.
    let (sin, cos) = turn_sin_cos(params.rotation).unwrap_or((0.0, 1.0));
    let (gw, gd) = (width + 2.0 * brim, depth + 2.0 * brim);
    let (fw, fd) = (
        cos.abs() * gw + sin.abs() * gd,
        sin.abs() * gw + cos.abs() * gd,
    );
    let (ox, oy) = ((width - fw) / 2.0, (depth - fd) / 2.0);
    let at = |x: f64, y: f64| Rect {
        x0: x + ox,
        y0: y + oy,
        x1: x + ox + fw,
        y1: y + oy + fd,
    };
    let objects = footprint(program);
    if let (Some(x), Some(y)) = (params.x, params.y) {
        let tower = at(x, y);
        let bad = |why: &str| TowerError::BadPlace {
            x,
            y,
            width,
            depth,
            why: why.to_owned(),
        };
        if !tower.within(&bed) {
            return Err(bad("does not fit on the bed"));
        }
        if objects.is_some_and(|o| tower.near(&o, MIN_GAP_MM)) {
            return Err(bad("overlaps the objects' paths"));
        }
        return Ok((x, y));
    }
    let Some(o) = objects else {
        return Ok((bed.x0 + GAP_MM - ox, bed.y0 + GAP_MM - oy));
    };
    // Right, behind, left, in front: the near side of the box round the tower and brim GAP_MM
    // from the objects', aligned with their front (or left) edge, or moved back onto the bed
    // along that side.
    let along = |lo: f64, size: f64, bed_lo: f64, bed_hi: f64| lo.min(bed_hi - size).max(bed_lo);
    let candidates = [
        (o.x1 + GAP_MM, along(o.y0, fd, bed.y0, bed.y1)),
        (along(o.x0, fw, bed.x0, bed.x1), o.y1 + GAP_MM),
        (o.x0 - GAP_MM - fw, along(o.y0, fd, bed.y0, bed.y1)),
        (along(o.x0, fw, bed.x0, bed.x1), o.y0 - GAP_MM - fd),
    ];
    candidates
        .into_iter()
        .map(|(fx, fy)| (fx - ox, fy - oy))
        .find(|&(x, y)| {
            let t = at(x, y);
            t.within(&bed) && !t.near(&o, GAP_MM - 1e-9)
        })
        .ok_or(TowerError::NoRoom { width, depth })
}

/// Sine and cosine of a turn by `degrees`; `None` for a whole number of turns (no turn: the
/// paths stay exactly as built).
fn turn_sin_cos(degrees: f64) -> Option<(f64, f64)> {
    (degrees.rem_euclid(360.0) != 0.0).then(|| degrees.to_radians().sin_cos())
}

/// A turn about a point in the plane (none when the angle is a whole turn or zero).
#[derive(Debug, Clone, Copy)]
struct Turn {
    /// Sine and cosine of the angle, `None` for no turn.
    sin_cos: Option<(f64, f64)>,
    /// The point turned about.
    centre: [f64; 2],
}

impl Turn {
    /// The turn by `degrees` (anticlockwise) about the centre of `r`.
    fn new(degrees: f64, r: &Rect) -> Self {
        Self {
            sin_cos: turn_sin_cos(degrees),
            centre: [(r.x0 + r.x1) / 2.0, (r.y0 + r.y1) / 2.0],
        }
    }

    /// `p` turned.
    fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        let Some((sin, cos)) = self.sin_cos else {
            return p;
        };
        let [cx, cy] = self.centre;
        let (dx, dy) = (p[0] - cx, p[1] - cy);
        [cx + cos * dx - sin * dy, cy + sin * dx + cos * dy]
    }
}

/// Makes one layer's tower paths, band after band from the front.
struct LayerBuilder {
    tower: Rect,
    z: f64,
    height: f64,
    speed: f64,
    /// Fill the rest one bead apart (the first layer).
    solid: bool,
    /// Loops of the brim laid before the first loop (the first layer's).
    brim_loops: usize,
    /// How the tower's paths are turned.
    turn: Turn,
    /// Where the next band starts (Y of its front edge), mm.
    next_y: f64,
    /// Whether the loop is laid on this layer.
    looped: bool,
}

impl LayerBuilder {
    fn path(&self, points: Vec<[f64; 2]>, closed: bool, tool: usize, bead: f64) -> Toolpath {
        Toolpath {
            points: points
                .into_iter()
                .map(|p| {
                    let [x, y] = self.turn.apply(p);
                    Point3::new(x, y, self.z)
                })
                .collect(),
            closed,
            role: Role::WipeTower,
            tool,
            width: bead,
            height: self.height,
            speed: self.speed,
            tool_axis: None,
            segments: None,
        }
    }

    /// The loop round the tower, the first time a tool prints on it this layer.
    fn ring(&mut self, tool: usize, bead: f64) -> Vec<Toolpath> {
        if self.looped {
            return Vec::new();
        }
        self.looped = true;
        let t = self.tower;
        self.next_y = t.y0 + bead;
        // The brim's loops from the outermost in, each a bead outside the one before; the
        // innermost touches the tower's edge, as the loop does from inside.
        let rect = |grow: f64| {
            vec![
                [t.x0 - grow, t.y0 - grow],
                [t.x1 + grow, t.y0 - grow],
                [t.x1 + grow, t.y1 + grow],
                [t.x0 - grow, t.y1 + grow],
            ]
        };
        (1..=self.brim_loops)
            .rev()
            .map(|n| (n as f64 - 0.5) * bead)
            .chain(std::iter::once(-bead / 2.0))
            .map(|grow| self.path(rect(grow), true, tool, bead))
            .collect()
    }

    /// Lines along X inside the loop from `next_y`, one bead apart, joined end to end, until
    /// they hold `volume` mm³ (whole lines), or the tower's back is reached.
    fn band(&mut self, tool: usize, bead: f64, volume: f64) -> Vec<Toolpath> {
        let t = self.tower;
        let (left, right) = (t.x0 + 1.5 * bead, t.x1 - 1.5 * bead);
        let back = t.y1 - bead;
        let line = (right - left) * bead * self.height;
        if line <= 0.0 || volume <= 0.0 {
            return Vec::new();
        }
        let lines = (volume / line).ceil() as usize;
        let mut points = Vec::new();
        for n in 0..lines {
            let y = self.next_y + bead / 2.0;
            if y > back - bead / 2.0 + 1e-9 {
                break;
            }
            points.extend(zigzag_line(n, (left, right), y, Axis::X));
            self.next_y += bead;
        }
        if points.len() < 2 {
            return Vec::new();
        }
        vec![self.path(points, false, tool, bead)]
    }

    /// The part of the tower behind the bands: lines along Y every `spacing` mm (one bead
    /// apart on the first layer), joined end to end.
    fn rest(&mut self, tool: usize, bead: f64, spacing: f64) -> Vec<Toolpath> {
        let t = self.tower;
        let (front, back) = (self.next_y + bead / 2.0, t.y1 - 1.5 * bead);
        if back - front < bead {
            return Vec::new();
        }
        let (left, right) = (t.x0 + 1.5 * bead, t.x1 - 1.5 * bead);
        let step = if self.solid { bead } else { spacing };
        let count = ((right - left) / step).floor() as usize + 1;
        let mut points = Vec::new();
        for n in 0..count {
            let x = left + n as f64 * step;
            points.extend(zigzag_line(n, (front, back), x, Axis::Y));
        }
        self.next_y = t.y1;
        vec![self.path(points, false, tool, bead)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::Layer;

    const BEAD: f64 = 0.45;
    const HEIGHT: f64 = 0.2;

    /// A 10 mm square at (20, 20) printed by `tool` at `z`.
    fn square(tool: usize, z: f64) -> Toolpath {
        let p = |x: f64, y: f64| Point3::new(x, y, z);
        Toolpath {
            points: vec![p(20.0, 20.0), p(30.0, 20.0), p(30.0, 30.0), p(20.0, 30.0)],
            closed: true,
            role: Role::Perimeter,
            tool,
            width: BEAD,
            height: HEIGHT,
            speed: 40.0,
            tool_axis: None,
            segments: None,
        }
    }

    /// Layers of 0.2 mm: each a list of tools, printed in turn with a change between two
    /// different tools (the first tool of the program is implied).
    fn program(layers: &[&[usize]]) -> Program {
        let mut active: Option<usize> = None;
        let layers = layers
            .iter()
            .enumerate()
            .map(|(k, tools)| {
                let z = HEIGHT * (k + 1) as f64;
                let mut items = Vec::new();
                for &t in tools.iter() {
                    if active.is_some_and(|a| a != t) {
                        items.push(LayerItem::Event(Event::ToolChange { tool: t }));
                    }
                    active = Some(t);
                    items.push(LayerItem::Path(square(t, z)));
                }
                Layer {
                    index: k,
                    z,
                    height: HEIGHT,
                    items,
                }
            })
            .collect();
        Program { layers }
    }

    fn machine(filament: &[bool]) -> TowerMachine {
        TowerMachine {
            bed: [0.0, 0.0, 200.0, 200.0],
            filament: filament.to_vec(),
            width: vec![BEAD; filament.len()],
            first_layer_speed: 20.0,
        }
    }

    /// The tower on, without a brim (the brim has its own test).
    fn on() -> TowerParams {
        TowerParams {
            enabled: true,
            brim_width: 0.0,
            ..TowerParams::default()
        }
    }

    /// The tower's paths of layer `k`, with the index of each among the layer's items.
    fn tower_paths(program: &Program, k: usize) -> Vec<(usize, &Toolpath)> {
        program.layers[k]
            .items
            .iter()
            .enumerate()
            .filter_map(|(i, item)| match item {
                LayerItem::Path(p) if p.role == Role::WipeTower => Some((i, p)),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn every_change_to_a_filament_tool_is_followed_by_its_purge_of_the_volume_asked() {
        // Two tools on layers 0–3, tool 0 alone on 4–5: the tower ends at layer 3.
        let mut p = program(&[&[0, 1], &[1, 0], &[0, 1], &[1, 0], &[0], &[0]]);
        let params = on();
        let summary = add_wipe_tower(&mut p, &params, &machine(&[true, true]))
            .expect("placed")
            .expect("built");
        assert_eq!(summary.layers, 4);
        assert_eq!(summary.purges, 4);
        assert_eq!(summary.skipped_layers, 0);
        for k in 0..4 {
            let layer = &p.layers[k];
            let change = layer
                .items
                .iter()
                .position(|i| matches!(i, LayerItem::Event(Event::ToolChange { .. })))
                .expect("a change");
            let LayerItem::Event(Event::ToolChange { tool }) = layer.items[change] else {
                unreachable!()
            };
            let tower = tower_paths(&p, k);
            // Loop, band, rest: right after the change, by the new tool, one after the other.
            let at: Vec<usize> = tower.iter().map(|(i, _)| *i).collect();
            assert_eq!(
                at,
                (change + 1..change + 1 + tower.len()).collect::<Vec<_>>()
            );
            assert!(tower.iter().all(|(_, t)| t.tool == tool && t.z_is(layer.z)));
            // The band: lines along X, 60 − 3 × 0.45 = 58.65 mm long, one bead apart; whole
            // lines until 140 mm³ are laid: ceil(140 / (58.65 × 0.45 × 0.2)) = 27 lines.
            let band = tower[1].1;
            let lines = band.points.len() / 2;
            assert_eq!(lines, 27);
            let line = 58.65 * BEAD * HEIGHT;
            let laid = volume(band);
            assert!(laid >= params.purge_volume && laid < params.purge_volume + line + 1.0);
            // With one purge a layer the bands fill the tower: 27 lines and the loop's two
            // beads, 12.15 + 0.9 mm deep.
            assert!((summary.depth - 13.05).abs() < 1e-9, "{}", summary.depth);
        }
        assert!(tower_paths(&p, 4).is_empty() && tower_paths(&p, 5).is_empty());
        assert!((summary.purged_volume - 4.0 * volume(tower_paths(&p, 1)[1].1)).abs() < 1e-9);
    }

    impl Toolpath {
        fn z_is(&self, z: f64) -> bool {
            self.points.iter().all(|p| (p.z - z).abs() < 1e-12)
        }
    }

    #[test]
    fn layers_without_a_change_below_the_top_get_a_sparse_layer_by_the_active_tool() {
        // Changes only on layer 3: layers 0–2 are tool 0 alone.
        let mut p = program(&[&[0], &[0], &[0], &[0, 1]]);
        let params = on();
        let summary = add_wipe_tower(&mut p, &params, &machine(&[true, true]))
            .expect("placed")
            .expect("built");
        assert_eq!(summary.layers, 4);
        assert_eq!(summary.purges, 1);
        for k in 0..3 {
            let tower = tower_paths(&p, k);
            // The loop and the rest, first thing on the layer, by tool 0.
            assert_eq!(tower.iter().map(|(i, _)| *i).collect::<Vec<_>>(), [0, 1]);
            assert!(tower.iter().all(|(_, t)| t.tool == 0));
            let rest = tower[1].1;
            // Lines along Y, every 10 mm from 1.5 beads in (every bead on the first layer):
            // floor(58.65 / step) + 1 of them, all at the same X on every sparse layer.
            let step = if k == 0 { BEAD } else { params.sparse_spacing };
            assert_eq!(rest.points.len() / 2, (58.65 / step).floor() as usize + 1);
            for pair in rest.points.chunks(2) {
                assert!((pair[0].x - pair[1].x).abs() < 1e-12);
            }
            // First layer at the first layer's speed.
            let speed = if k == 0 { 20.0 } else { params.speed };
            assert!(tower.iter().all(|(_, t)| t.speed == speed));
        }
        let xs =
            |k: usize| -> Vec<f64> { tower_paths(&p, k)[1].1.points.iter().map(|q| q.x).collect() };
        assert_eq!(xs(1), xs(2));
    }

    #[test]
    fn paste_tools_are_not_purged_but_the_filament_tool_coming_back_is() {
        // Tool 1 is a paste dispenser: layers 0–1 change 0 → 1 → (next layer) 0.
        let mut p = program(&[&[0, 1], &[1, 0], &[0]]);
        let summary = add_wipe_tower(&mut p, &on(), &machine(&[true, false]))
            .expect("placed")
            .expect("built");
        // Layer 0's only change is to the paste tool: tool 0 prints the loop and the rest at
        // the layer's start; layer 1's change back to tool 0 purges.
        assert_eq!(summary.purges, 1);
        assert_eq!(summary.layers, 2);
        assert!(tower_paths(&p, 0).iter().all(|(_, t)| t.tool == 0));
        assert_eq!(tower_paths(&p, 0)[0].0, 0);
        assert!(tower_paths(&p, 1).iter().all(|(_, t)| t.tool == 0));
        assert!(p.paths().all(|t| t.role != Role::WipeTower || t.tool == 0));
    }

    /// A first layer printed by a paste tool alone gets no tower layer, so no brim either: the
    /// summary says 0, and no tower path lies on that layer.
    #[test]
    fn a_paste_only_first_layer_has_no_tower_layer_and_no_brim() {
        // Tool 1 pastes: layer 0 is tool 1's alone, layer 1 changes to the filament tool 0.
        let mut p = program(&[&[1], &[1, 0]]);
        let params = TowerParams {
            enabled: true,
            ..TowerParams::default()
        };
        let summary = add_wipe_tower(&mut p, &params, &machine(&[true, false]))
            .expect("placed")
            .expect("built");
        assert_eq!((summary.skipped_layers, summary.purges), (1, 1));
        assert_eq!(summary.brim_width, 0.0);
        assert!(tower_paths(&p, 0).is_empty());
        assert!(!tower_paths(&p, 1).is_empty());
    }

    #[test]
    fn no_tower_without_a_change_or_when_off() {
        let mut p = program(&[&[0], &[0]]);
        let before = p.clone();
        assert_eq!(
            add_wipe_tower(&mut p, &on(), &machine(&[true, true])),
            Ok(None)
        );
        let mut two = program(&[&[0, 1]]);
        let two_before = two.clone();
        assert_eq!(
            add_wipe_tower(&mut two, &TowerParams::default(), &machine(&[true, true])),
            Ok(None)
        );
        assert_eq!((p, two), (before, two_before));
    }

    #[test]
    fn the_tower_stands_beside_the_objects_on_the_bed_or_says_why_not() {
        let m = machine(&[true, true]);
        // The square spans 20–30 mm (and half a bead): right of it, 5 mm clear.
        let mut p = program(&[&[0, 1]]);
        let s = add_wipe_tower(&mut p, &on(), &m)
            .expect("placed")
            .expect("built");
        assert!((s.x - (30.225 + GAP_MM)).abs() < 1e-9 && (s.y - 19.775).abs() < 1e-9);
        // A bed ending 60 mm right of the square: no room there, so behind it.
        let narrow = TowerMachine {
            bed: [0.0, 0.0, 90.0, 200.0],
            ..m.clone()
        };
        let mut p = program(&[&[0, 1]]);
        let s = add_wipe_tower(&mut p, &on(), &narrow)
            .expect("placed")
            .expect("built");
        assert!((s.x - 19.775).abs() < 1e-9 && (s.y - (30.225 + GAP_MM)).abs() < 1e-9);
        // A bed too small anywhere: an error naming the tower's size.
        let tiny = TowerMachine {
            bed: [10.0, 10.0, 60.0, 45.0],
            ..m.clone()
        };
        let err = add_wipe_tower(&mut program(&[&[0, 1]]), &on(), &tiny).expect_err("no room");
        assert_eq!(
            err.to_string(),
            "no room for the 60.0 × 13.1 mm wipe tower on the bed beside the objects \
             (set wipe_tower.x and wipe_tower.y, or a smaller wipe_tower.width)"
        );
        // Set by hand: over the square, or off the bed, is an error; beside it is kept.
        let at = |x: f64, y: f64| TowerParams {
            x: Some(x),
            y: Some(y),
            ..on()
        };
        let over = add_wipe_tower(&mut program(&[&[0, 1]]), &at(0.0, 25.0), &m);
        assert!(
            matches!(over, Err(TowerError::BadPlace { ref why, .. }) if why.contains("overlaps"))
        );
        let off = add_wipe_tower(&mut program(&[&[0, 1]]), &at(150.0, 25.0), &m);
        assert!(matches!(off, Err(TowerError::BadPlace { ref why, .. }) if why.contains("bed")));
        let ok = add_wipe_tower(&mut program(&[&[0, 1]]), &at(100.0, 100.0), &m);
        assert!(matches!(
            ok,
            Ok(Some(TowerSummary {
                x: 100.0,
                y: 100.0,
                ..
            }))
        ));
    }

    #[test]
    fn the_first_layer_has_a_brim_round_the_tower_that_stays_clear_of_the_objects() {
        let m = machine(&[true, true]);
        let brim = TowerParams {
            brim_width: 2.0,
            ..on()
        };
        let mut p = program(&[&[0, 1], &[1, 0]]);
        let s = add_wipe_tower(&mut p, &brim, &m)
            .expect("placed")
            .expect("built");
        // round(2 / 0.45) = 4 loops of 0.45 mm: 1.8 mm.
        assert!((s.brim_width - 1.8).abs() < 1e-9, "{}", s.brim_width);
        // Right of the square (20–30 mm and half a bead), the brim's outer edge 5 mm clear.
        assert!((s.x - (30.225 + GAP_MM + 1.8)).abs() < 1e-9, "{}", s.x);
        let first = tower_paths(&p, 0);
        // Four brim loops from the outermost in, then the loop and the band (which fills the
        // tower), all by tool 1 (the first to print on the tower), right after the change.
        assert_eq!(first.len(), 6);
        assert!(first.iter().all(|(_, t)| t.tool == 1));
        for (n, (_, loop_path)) in first[..5].iter().enumerate() {
            assert!(loop_path.closed);
            // The loop's centreline: (3.5 − n) beads outside the tower's edge for the brim,
            // half a bead inside it for the tower's own loop.
            let grow = (3.5 - n as f64) * BEAD;
            let xs: Vec<f64> = loop_path.points.iter().map(|q| q.x).collect();
            let min = xs.iter().copied().fold(f64::INFINITY, f64::min);
            let max = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            assert!((min - (s.x - grow)).abs() < 1e-9, "loop {n}: {min}");
            assert!(
                (max - (s.x + s.width + grow)).abs() < 1e-9,
                "loop {n}: {max}"
            );
        }
        let second = tower_paths(&p, 1);
        assert_eq!(second.len(), 2, "no brim above the first layer");
        // A brim that would leave the bed is an error, though the tower alone fits.
        let edge = TowerParams {
            x: Some(0.5),
            y: Some(100.0),
            ..brim.clone()
        };
        let off = add_wipe_tower(&mut program(&[&[0, 1]]), &edge, &m);
        assert!(matches!(off, Err(TowerError::BadPlace { ref why, .. }) if why.contains("bed")));
        let no_brim = TowerParams {
            brim_width: 0.0,
            ..edge
        };
        assert!(add_wipe_tower(&mut program(&[&[0, 1]]), &no_brim, &m).is_ok());
        assert_eq!((brim_loops(0.1, BEAD), brim_loops(0.0, BEAD)), (1, 0));
    }

    /// The box round the tower's paths of layer `k` (bead centres).
    fn path_box(program: &Program, k: usize) -> [f64; 4] {
        let mut b = [f64::MAX, f64::MAX, f64::MIN, f64::MIN];
        for (_, t) in tower_paths(program, k) {
            for q in &t.points {
                b = [b[0].min(q.x), b[1].min(q.y), b[2].max(q.x), b[3].max(q.y)];
            }
        }
        b
    }

    #[test]
    fn a_turned_tower_turns_about_its_centre_and_its_box_stays_clear_of_the_objects() {
        let m = machine(&[true, true]);
        let turned = |rotation: f64| TowerParams { rotation, ..on() };
        let straight = {
            let mut p = program(&[&[0, 1], &[1, 0]]);
            let s = add_wipe_tower(&mut p, &on(), &m)
                .expect("placed")
                .expect("built");
            (path_box(&p, 1), s)
        };
        // A quarter turn: the 60 mm side lies along Y, about the same centre as the tower
        // placed for it, and the box round it starts 5 mm right of the square (30.225 mm).
        let mut p = program(&[&[0, 1], &[1, 0]]);
        let s = add_wipe_tower(&mut p, &turned(90.0), &m)
            .expect("placed")
            .expect("built");
        assert_eq!(s.rotation, 90.0);
        let b = path_box(&p, 1);
        let (w, d) = (s.width, s.depth);
        let (cx, cy) = (s.x + w / 2.0, s.y + d / 2.0);
        let (sw, sd) = (straight.0[2] - straight.0[0], straight.0[3] - straight.0[1]);
        assert!(((b[2] - b[0]) - sd).abs() < 1e-9 && ((b[3] - b[1]) - sw).abs() < 1e-9);
        assert!(((b[0] + b[2]) / 2.0 - cx).abs() < 1e-9);
        assert!(((b[1] + b[3]) / 2.0 - cy).abs() < 1e-9);
        assert!((cx - d / 2.0 - (30.225 + GAP_MM)).abs() < 1e-9, "{cx}");
        // An eighth of a turn: every bead lies within the box placed for it, clear of the
        // square by 5 mm.
        let mut p = program(&[&[0, 1], &[1, 0]]);
        let s = add_wipe_tower(&mut p, &turned(45.0), &m)
            .expect("placed")
            .expect("built");
        let half = (s.width + s.depth) * std::f64::consts::FRAC_1_SQRT_2 / 2.0;
        let cx = s.x + s.width / 2.0;
        for k in 0..2 {
            let b = path_box(&p, k);
            assert!(b[0] >= cx - half && b[2] <= cx + half, "{b:?}");
            assert!(b[0] - BEAD / 2.0 >= 30.225 + GAP_MM - 1e-9, "{b:?}");
        }
        // A whole turn is none: the same paths as unturned.
        let mut p = program(&[&[0, 1], &[1, 0]]);
        add_wipe_tower(&mut p, &turned(360.0), &m)
            .expect("placed")
            .expect("built");
        assert_eq!(path_box(&p, 1), straight.0);
        assert_eq!(straight.1.rotation, 0.0);
    }

    #[test]
    fn settings_out_of_range_are_named() {
        let bad = TowerParams {
            width: 2.0,
            x: Some(10.0),
            ..TowerParams::default()
        };
        assert_eq!(
            bad.problems(),
            [
                "wipe_tower.width must be between 5 and 300, got 2",
                "wipe_tower.x and wipe_tower.y are set together or not at all",
            ]
        );
        assert!(TowerParams::default().problems().is_empty());
    }
}
