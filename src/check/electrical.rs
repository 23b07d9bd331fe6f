//! The electrical check of a G-code file: the conductive beads rebuilt from the replayed moves,
//! and whether they connect each net's pins, keep nets apart, stay inside the solid, and whether
//! every part is placed once its cavity is complete.
//!
//! Place in the pipeline: beside [`super::check`], after `emit` (or after `conduit postprocess`).
//! It trusts nothing the router decided: only the G-code (the conductive tool's extrusions, the
//! plastic's, the part event markers) and the circuit with its placement, which say where the
//! pads are. The pads are placed on the bed by [`place_circuit`], the function the slicer uses.
//!
//! # Frame
//!
//! Where the placement's coordinates land on the bed ([`Frame`]):
//!
//! - [`Frame::Printed`] (a host slicer's file, edited by `conduit postprocess`): the G-code's
//!   coordinates are the frame, as in `postprocess`. `origin = "model"` gives bed coordinates;
//!   with `origin = "bbox_center"`, x and y are measured from the centre of the bounding box of
//!   the object's plastic (every extrusion of the other tools, skirt, brim and start G-code
//!   excluded, each bead counted with its width) and z from the bed. For `bbox_center` this
//!   is also right for conduit's own output, which centres its objects on the bed.
//! - [`Frame::Objects`] (conduit's own output with `origin = "model"`): the model's bounding
//!   boxes and the offsets that put each object on the bed, as `conduit slice` computed them
//!   (the CLI takes them from `--model`).
//!
//! # Beads and connections
//!
//! Each extruding segment of the conductive tool is a bead: a capsule of its width (`;WIDTH:`,
//! else [`ElectricalParams::default_width`]) at its z, as high as its layer. Two beads touch
//! when their capsules overlap in xy and they lie in one layer or in two adjacent ones (their z
//! differ by at most the upper bead's height). A pad is reached by a bead that overlaps its
//! copper outline within one layer height of the seating plane; a waypoint by a bead whose
//! capsule holds it. Candidate pairs come from a uniform grid; the touching ones are joined in
//! a union-find. A net is connected when all its placed pins and waypoints share one
//! component.
//!
//! # Shorts
//!
//! Each bead takes the net of the nearest terminal (in hops through touching beads). Two beads
//! (or a bead and a pad) of different nets that touch are a short; closer than
//! [`ElectricalParams::spacing`] (`route.channel_extra`, the clearance the router keeps between
//! nets' copper) they are reported too, with the gap. One entry per pair of nets, where the gap
//! is smallest.
//!
//! # Outside the solid
//!
//! A bead point is inside when it lies within the outline of the plastic of its layer (the
//! highest plastic layer at or below it; the plastic's beads united, every hole filled: traces
//! run in channels and cavities the plastic leaves open). Beads above the object's top are
//! outside. Runs of outside beads are reported with their length.
//!
//! # Part events
//!
//! Each part placed by the machine or by hand has an event marker (`;PICK_AND_PLACE PART=`,
//! `;MANUAL_INSERT PART=`). It must come after the plastic has reached the part's top (seating
//! plane + body height: before that, walls are still printed around the part), and before a
//! layer above the part's top has been printed over its footprint (the lid). An auto part's
//! marker must name the position the placement gives.

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::fmt;

use rayon::prelude::*;
use serde::Serialize;

use conduit_gcode::{Gcode, Move, moves};

use crate::circuit::stage::{
    Electronics, ElectronicsError, ElectronicsParams, PlacedCircuit, place_circuit,
};
use crate::circuit::{PlacedPart, PlacingMethod};
use crate::geom::{
    BoundingBox, Cap, ExPolygon, FillRule, Join, Point2, Polyline, offset, polygons_to_expolygons,
    stroke, union,
};
use crate::program::Role;
use crate::program::machine::Flavor;
use conduit_gcode::events::part_event;

/// What the electrical check is configured with.
#[derive(Debug, Clone, PartialEq)]
pub struct ElectricalParams {
    /// The tool whose extrusions are conductive (`route.conductive_tool`).
    pub conductive_tool: usize,
    /// Smallest gap between two nets' conductive material, mm (`route.channel_extra`).
    pub spacing: f64,
    /// Width of a conductive move without a `;WIDTH:` comment, mm (`route.conductive_width`).
    pub default_width: f64,
    /// Width of a plastic move without a `;WIDTH:` comment, mm. Default 0.45.
    pub plastic_width: f64,
    /// Slack of the geometric tests, mm: G-code coordinates are written to 1 µm and outlines
    /// are polygons. Default 0.005.
    pub tolerance: f64,
    /// Spacing of the points tested along a bead for the outside check, mm. Default 0.1.
    pub sample_step: f64,
    /// Problems listed per kind; the rest are counted. Default 20.
    pub max_listed: usize,
}

impl ElectricalParams {
    /// The check of the circuit the electronics stage with `params` would build.
    pub fn of(params: &ElectronicsParams) -> Self {
        Self {
            conductive_tool: params.conductive_tool,
            spacing: params.route.channel_extra,
            default_width: params.route.conductive_width,
            plastic_width: 0.45,
            tolerance: 0.005,
            sample_step: 0.1,
            max_listed: 20,
        }
    }
}

/// Where the placement's coordinates land on the bed (see the [module docs](self#frame)).
#[derive(Debug, Clone, PartialEq)]
pub enum Frame {
    /// The G-code's own coordinates, the object's box taken from its plastic.
    Printed,
    /// The scene's objects: model bounding boxes and bed offsets, by object index.
    Objects {
        /// Model-space bounding box of each object.
        bboxes: Vec<BoundingBox>,
        /// Translation of each object from model to bed coordinates, mm.
        offsets: Vec<[f64; 3]>,
    },
}

/// One net's connectivity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NetCheck {
    /// Net name.
    pub net: String,
    /// Placed pins (`PART.PAD`) and waypoints (`NET:NAME`) that must be connected.
    pub terminals: usize,
    /// All of them in one component.
    pub connected: bool,
    /// When open: the terminals grouped by component, each group sorted, groups by their
    /// first terminal.
    pub groups: Vec<Vec<String>>,
}

/// Two nets' conductive material touching or closer than the spacing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Short {
    /// The two nets, in name order.
    pub nets: [String; 2],
    /// Where the gap is smallest: x, y (midway between the two), z, mm.
    pub at: [f64; 3],
    /// The smallest gap between the two nets' material, mm (0 when touching).
    pub gap: f64,
    /// The material touches: the nets are connected.
    pub touching: bool,
    /// A G-code line of one of the two beads (1-based; 0 when both are pads).
    pub line: usize,
}

/// A run of conductive beads outside the solid.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutsideRun {
    /// Length of bead outside, mm.
    pub length: f64,
    /// Where the run starts: x, y, z, mm.
    pub at: [f64; 3],
    /// The run lies above the object's top (no plastic at or above its height).
    pub above_top: bool,
    /// G-code line of its first bead (1-based).
    pub line: usize,
}

/// What is wrong with a part's event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EventProblemKind {
    /// The event comes before the plastic has reached the part's top.
    Early,
    /// A layer above the part's top was printed over its footprint before the event.
    Late,
    /// A part the machine or a person places has no event.
    Missing,
    /// The pick-and-place marker names another position than the placement.
    Misplaced,
}

/// One problem with a part event.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventProblem {
    /// Part name.
    pub part: String,
    /// What is wrong.
    pub kind: EventProblemKind,
    /// The event's G-code line (1-based; 0 when missing).
    pub line: usize,
    /// What is wrong, with the values involved.
    pub message: String,
}

/// The result of [`check_electrical`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ElectricalReport {
    /// Every net with placed pins, by name.
    pub nets: Vec<NetCheck>,
    /// Pairs of nets touching or too close, at most [`ElectricalParams::max_listed`].
    pub shorts: Vec<Short>,
    /// Number of pairs of nets touching or too close, listed or not.
    pub short_count: usize,
    /// Runs of conductive material outside the solid, at most
    /// [`ElectricalParams::max_listed`].
    pub outside: Vec<OutsideRun>,
    /// Number of such runs, listed or not.
    pub outside_count: usize,
    /// Total length of conductive material outside the solid, mm.
    pub outside_length: f64,
    /// Part events missing, early, late or misplaced.
    pub events: Vec<EventProblem>,
    /// Part events found.
    pub events_found: usize,
    /// Conductive beads (extruding segments of the conductive tool).
    pub beads: usize,
    /// Their total length, mm.
    pub conductive_length: f64,
    /// Beads reaching no pin or waypoint.
    pub floating_beads: usize,
    /// Net pins on parts the placement does not place (`NET: PART.PAD`): not checked.
    pub unplaced_pins: Vec<String>,
    /// The circuit as the check placed it: parts and wires in bed coordinates (the 3D view
    /// draws them). Not serialised.
    #[serde(skip)]
    pub placed: PlacedCircuit,
}

impl ElectricalReport {
    /// Open nets.
    pub fn open_nets(&self) -> impl Iterator<Item = &NetCheck> {
        self.nets.iter().filter(|n| !n.connected)
    }

    /// Number of problems: open nets, shorts, outside runs and event problems.
    pub fn problems(&self) -> usize {
        self.open_nets().count() + self.short_count + self.outside_count + self.events.len()
    }

    /// True when there is no problem.
    pub fn is_ok(&self) -> bool {
        self.problems() == 0
    }
}

/// A 2D point, mm.
type P2 = [f64; 2];

/// One conductive bead.
#[derive(Debug, Clone, Copy)]
struct Bead {
    a: P2,
    b: P2,
    z: f64,
    /// Layer height at its z.
    h: f64,
    /// Half its width.
    r: f64,
    line: usize,
}

/// Something a net must reach: a pad (its copper outline) or a waypoint (one point).
#[derive(Debug, Clone)]
struct Terminal {
    net: usize,
    label: String,
    z: f64,
    /// Outline, counter-clockwise; one point for a waypoint.
    outline: Vec<P2>,
}

/// The objects' boxes and bed offsets `frame` gives: from the plastic of the file for
/// [`Frame::Printed`].
fn frame_boxes(
    frame: &Frame,
    plastic: &[&Move],
    params: &ElectricalParams,
) -> (Vec<BoundingBox>, Vec<[f64; 3]>) {
    match frame {
        Frame::Printed => (
            vec![printed_bbox(plastic, params.plastic_width)],
            vec![[0.0; 3]],
        ),
        Frame::Objects { bboxes, offsets } => (bboxes.clone(), offsets.clone()),
    }
}

/// The plastic moves of a replay (see `is_plastic`).
fn plastic_of<'a>(moves: &'a [Move], params: &ElectricalParams) -> Vec<&'a Move> {
    moves
        .iter()
        .filter(|m| is_plastic(m, params.conductive_tool))
        .collect()
}

/// Replays `gcode` (with the firmware of `flavor`) and checks the circuit of `e` in it, placed
/// by `frame` (see the [module docs](self)).
///
/// # Errors
/// The placement does not fit the circuit or the frame ([`ElectronicsError`]).
pub fn check_electrical(
    gcode: &Gcode,
    flavor: Flavor,
    e: &Electronics,
    frame: &Frame,
    stage: &ElectronicsParams,
    params: &ElectricalParams,
) -> Result<ElectricalReport, ElectronicsError> {
    let replay = moves(gcode, flavor);
    let heights = layer_heights(&replay.layer_z);
    let plastic = plastic_of(&replay.moves, params);
    let (bboxes, offsets) = frame_boxes(frame, &plastic, params);
    let placed = place_circuit(e, &bboxes, &offsets, stage)?;
    let nets: Vec<String> = e.circuit.nets.iter().map(|n| n.name.clone()).collect();
    let terminals = terminals(e, &placed.parts, &nets, &bboxes, &offsets)?;
    let beads = beads(&replay.moves, &heights, params);

    let graph = Graph::build(&beads, &terminals, params);
    let mut report = ElectricalReport {
        nets: net_checks(&nets, &terminals, &graph, beads.len()),
        shorts: Vec::new(),
        short_count: 0,
        outside: Vec::new(),
        outside_count: 0,
        outside_length: 0.0,
        events: Vec::new(),
        events_found: 0,
        beads: beads.len(),
        conductive_length: beads.iter().map(|b| dist(b.a, b.b)).sum(),
        floating_beads: 0,
        unplaced_pins: placed
            .unplaced
            .iter()
            .map(|(net, pin)| format!("{net}: {pin}"))
            .collect(),
        placed: PlacedCircuit::default(),
    };
    let labels = graph.labels(&terminals, beads.len());
    report.floating_beads = labels[..beads.len()].iter().filter(|l| l.is_none()).count();
    let shorts = shorts(&graph, &labels, &beads, &nets);
    report.short_count = shorts.len();
    report.shorts = shorts.into_iter().take(params.max_listed).collect();

    let runs = outside_runs(&beads, &plastic, params);
    report.outside_count = runs.len();
    report.outside_length = runs.iter().map(|r| r.length).fold(0.0, |a, b| a + b);
    report.outside = runs.into_iter().take(params.max_listed).collect();

    let (problems, found) = event_problems(gcode, &placed.parts, &plastic, &heights, params);
    report.events = problems;
    report.events_found = found;
    report.placed = placed;
    Ok(report)
}

/// The height of each printed layer: its z less the one below (the first: its z).
fn layer_heights(layer_z: &[f64]) -> Vec<f64> {
    layer_z
        .iter()
        .enumerate()
        .map(|(i, &z)| if i == 0 { z } else { z - layer_z[i - 1] })
        .collect()
}

/// The height of the layer of an extruding move.
fn height_of(m: &Move, heights: &[f64]) -> f64 {
    heights.get(m.layer).copied().unwrap_or(0.2)
}

/// An extruding move of the object's plastic: another tool than the conductive one, and not
/// skirt, brim, start G-code (roles as `postprocess` reads them), support or a tower.
fn is_plastic(m: &Move, conductive_tool: usize) -> bool {
    if !m.extruding || !m.has_xy || m.tool == conductive_tool || m.to[2].is_none() {
        return false;
    }
    let Some(name) = m.role.as_deref() else {
        return true;
    };
    if matches!(
        crate::postprocess::role_of(name),
        Some(Role::Skirt | Role::Support | Role::SupportInterface | Role::Custom)
    ) {
        return false;
    }
    // Unknown names count as the object's (a host file without feature comments keeps the
    // role of a block inserted before), except the features beside the object.
    let lower = name.to_ascii_lowercase();
    !["support", "tower", "wipe", "prime"]
        .iter()
        .any(|w| lower.contains(w))
}

/// The xy points of a move's path (unknown positions dropped).
fn path_xy(m: &Move) -> Vec<P2> {
    m.path.iter().filter_map(|p| Some([p[0]?, p[1]?])).collect()
}

/// The bounding box of the plastic beads (each point grown by half its width), z from 0 to
/// the highest; an empty box at the origin when nothing is printed.
fn printed_bbox(plastic: &[&Move], default_width: f64) -> BoundingBox {
    let (mut min, mut max) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let mut top: f64 = 0.0;
    for m in plastic {
        let r = m.width.unwrap_or(default_width) / 2.0;
        for p in path_xy(m) {
            min = [min[0].min(p[0] - r), min[1].min(p[1] - r)];
            max = [max[0].max(p[0] + r), max[1].max(p[1] + r)];
        }
        top = top.max(m.to[2].unwrap_or(0.0));
    }
    if min[0] > max[0] {
        return BoundingBox {
            min: [0.0; 3],
            max: [0.0; 3],
        };
    }
    BoundingBox {
        min: [min[0], min[1], 0.0],
        max: [max[0], max[1], top],
    }
}

/// The pads of the placed parts that belong to a net, and the placement's waypoints, in bed
/// coordinates.
fn terminals(
    e: &Electronics,
    parts: &[PlacedPart],
    nets: &[String],
    bboxes: &[BoundingBox],
    offsets: &[[f64; 3]],
) -> Result<Vec<Terminal>, ElectronicsError> {
    let net_index = |name: &str| nets.iter().position(|n| n == name);
    let mut out = Vec::new();
    for part in parts {
        for pad in &part.pads {
            let Some(net) = pad.net.as_deref().and_then(net_index) else {
                continue;
            };
            out.push(Terminal {
                net,
                label: format!("{}.{}", part.name, pad.name),
                z: pad.centre.z,
                outline: pad.outline.points_mm(),
            });
        }
    }
    let model = e.placement.to_model(bboxes)?;
    for n in &model.nets {
        let Some(net) = net_index(&n.name) else {
            continue;
        };
        for w in &n.waypoints {
            let d = offsets.get(w.object).copied().unwrap_or([0.0; 3]);
            out.push(Terminal {
                net,
                label: format!("{}:{}", n.name, w.name),
                z: w.z + d[2],
                outline: vec![[w.x + d[0], w.y + d[1]]],
            });
        }
    }
    Ok(out)
}

/// The conductive tool's extruding segments.
fn beads(all: &[Move], heights: &[f64], params: &ElectricalParams) -> Vec<Bead> {
    let mut out = Vec::new();
    for m in all {
        if !m.extruding || !m.has_xy || m.tool != params.conductive_tool {
            continue;
        }
        let Some(z) = m.to[2] else { continue };
        let r = m.width.unwrap_or(params.default_width) / 2.0;
        let h = height_of(m, heights);
        if !(z.is_finite() && r.is_finite() && r >= 0.0) {
            continue;
        }
        for w in path_xy(m).windows(2) {
            if !w.iter().flatten().all(|v| v.is_finite()) {
                continue;
            }
            out.push(Bead {
                a: w[0],
                b: w[1],
                z,
                h,
                r,
                line: m.line,
            });
        }
    }
    out
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The point of segment `a`–`b` nearest `p`.
fn nearest_on(p: P2, a: P2, b: P2) -> P2 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    [a[0] + t * d[0], a[1] + t * d[1]]
}

fn cross(o: P2, a: P2, b: P2) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Whether the segments `a`–`b` and `c`–`d` cross (proper crossings only; touching ends are
/// found by the distance).
fn crosses(a: P2, b: P2, c: P2, d: P2) -> bool {
    let (d1, d2) = (cross(a, b, c), cross(a, b, d));
    let (d3, d4) = (cross(c, d, a), cross(c, d, b));
    d1 * d2 < 0.0 && d3 * d4 < 0.0
}

/// The distance between segments `a`–`b` and `c`–`d` and the midpoint of the closest pair of
/// points.
fn segment_gap(a: P2, b: P2, c: P2, d: P2) -> (f64, P2) {
    if crosses(a, b, c, d) {
        // Where they cross: the intersection of the lines.
        let t = cross(c, d, a) / (cross(c, d, a) - cross(c, d, b));
        return (0.0, [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
    }
    [
        (a, c, d, true),
        (b, c, d, true),
        (c, a, b, false),
        (d, a, b, false),
    ]
    .into_iter()
    .map(|(p, s, e, _)| {
        let q = nearest_on(p, s, e);
        (dist(p, q), [(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0])
    })
    .fold(
        (f64::INFINITY, a),
        |best, x| if x.0 < best.0 { x } else { best },
    )
}

/// Whether `p` lies inside the polygon `ring` (even-odd).
fn inside(p: P2, ring: &[P2]) -> bool {
    let n = ring.len();
    let mut c = false;
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
        {
            c = !c;
        }
    }
    c
}

/// The gap between a bead's centreline `a`–`b` and an outline (0 when it enters it), and
/// where.
fn outline_gap(a: P2, b: P2, ring: &[P2]) -> (f64, P2) {
    if ring.len() == 1 {
        let q = nearest_on(ring[0], a, b);
        return (dist(q, ring[0]), ring[0]);
    }
    if ring.len() >= 3 && (inside(a, ring) || inside(b, ring)) {
        return (0.0, if inside(a, ring) { a } else { b });
    }
    let n = ring.len();
    (0..n)
        .map(|i| segment_gap(a, b, ring[i], ring[(i + 1) % n]))
        .fold(
            (f64::INFINITY, a),
            |best, x| if x.0 < best.0 { x } else { best },
        )
}

/// Two beads at `z1`, `z2` (heights `h1`, `h2`) lie in one layer or adjacent ones.
fn stacked(z1: f64, h1: f64, z2: f64, h2: f64, tol: f64) -> bool {
    let upper_h = if z1 >= z2 { h1 } else { h2 };
    (z1 - z2).abs() <= upper_h.max(0.0) + tol
}

/// Most grid cells along the beads' extent.
const GRID_SPAN: f64 = 256.0;

/// Most points tested along one bead or plastic move.
const MAX_SAMPLES: usize = 10_000;

/// An edge of the bead graph: nodes are beads (`0..n`) then terminals (`n..`).
#[derive(Debug, Clone, Copy)]
struct Edge {
    u: usize,
    v: usize,
    gap: f64,
    at: [f64; 3],
    line: usize,
}

/// Beads and terminals with the pairs that touch (edges) and the pairs closer than the spacing.
struct Graph {
    parent: Vec<usize>,
    touching: Vec<Edge>,
    near: Vec<Edge>,
    nodes: usize,
}

impl Graph {
    fn build(beads: &[Bead], terminals: &[Terminal], params: &ElectricalParams) -> Self {
        let n = beads.len();
        let reach = params.spacing + params.tolerance;
        let max_r = beads.iter().map(|b| b.r).fold(0.0, f64::max);
        // At most GRID_SPAN cells along the beads' extent, so a stray move far off the bed
        // cannot make a bead cover millions of cells.
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for b in beads {
            lo = lo.min(b.a[0].min(b.b[0])).min(b.a[1].min(b.b[1]));
            hi = hi.max(b.a[0].max(b.b[0])).max(b.a[1].max(b.b[1]));
        }
        let extent = if hi > lo { hi - lo } else { 0.0 };
        let cell = (2.0 * max_r + reach).max(0.5).max(extent / GRID_SPAN);
        let key = |x: f64| (x / cell).floor() as i64;
        let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
        let grown = |b: &Bead| {
            let g = b.r + reach / 2.0;
            [
                b.a[0].min(b.b[0]) - g,
                b.a[1].min(b.b[1]) - g,
                b.a[0].max(b.b[0]) + g,
                b.a[1].max(b.b[1]) + g,
            ]
        };
        let boxes: Vec<[f64; 4]> = beads.iter().map(grown).collect();
        for (i, bx) in boxes.iter().enumerate() {
            for ix in key(bx[0])..=key(bx[2]) {
                for iy in key(bx[1])..=key(bx[3]) {
                    grid.entry((ix, iy)).or_default().push(i);
                }
            }
        }
        let mut touching = Vec::new();
        let mut near = Vec::new();
        let mut classify = |u: usize, v: usize, gap: f64, at: [f64; 3], line: usize| {
            let e = Edge {
                u,
                v,
                gap: gap.max(0.0),
                at,
                line,
            };
            if gap <= params.tolerance {
                touching.push(e);
            } else if gap < params.spacing - params.tolerance {
                near.push(e);
            }
        };
        let mut cells: Vec<(&(i64, i64), &Vec<usize>)> = grid.iter().collect();
        cells.sort_unstable_by_key(|(k, _)| **k);
        for (&(ix, iy), list) in cells {
            for (k, &i) in list.iter().enumerate() {
                for &j in &list[k + 1..] {
                    // Each pair once: in the cell holding the corner of their boxes' overlap.
                    let (bi, bj) = (boxes[i], boxes[j]);
                    if bi[2] < bj[0] || bj[2] < bi[0] || bi[3] < bj[1] || bj[3] < bi[1] {
                        continue;
                    }
                    if key(bi[0].max(bj[0])) != ix || key(bi[1].max(bj[1])) != iy {
                        continue;
                    }
                    let (p, q) = (&beads[i], &beads[j]);
                    if !stacked(p.z, p.h, q.z, q.h, params.tolerance) {
                        continue;
                    }
                    let (d, at) = segment_gap(p.a, p.b, q.a, q.b);
                    classify(i, j, d - p.r - q.r, [at[0], at[1], p.z.max(q.z)], p.line);
                }
            }
        }
        for (t, term) in terminals.iter().enumerate() {
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for p in &term.outline {
                lo = [lo[0].min(p[0]), lo[1].min(p[1])];
                hi = [hi[0].max(p[0]), hi[1].max(p[1])];
            }
            let mut seen: Vec<usize> = Vec::new();
            for ix in key(lo[0] - reach)..=key(hi[0] + reach) {
                for iy in key(lo[1] - reach)..=key(hi[1] + reach) {
                    if let Some(list) = grid.get(&(ix, iy)) {
                        seen.extend(list);
                    }
                }
            }
            seen.sort_unstable();
            seen.dedup();
            for i in seen {
                let b = &beads[i];
                if (b.z - term.z).abs() > b.h + params.tolerance {
                    continue;
                }
                let (d, at) = outline_gap(b.a, b.b, &term.outline);
                classify(i, n + t, d - b.r, [at[0], at[1], b.z], b.line);
            }
        }
        let nodes = n + terminals.len();
        let mut g = Graph {
            parent: (0..nodes).collect(),
            touching,
            near,
            nodes,
        };
        for k in 0..g.touching.len() {
            let (u, v) = (g.touching[k].u, g.touching[k].v);
            g.join(u, v);
        }
        g
    }

    fn root(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.root(a), self.root(b));
        if ra != rb {
            self.parent[ra.max(rb)] = ra.min(rb);
        }
    }

    /// The net of each node: a terminal's own; a bead's that of the nearest terminal in hops
    /// through touching beads (`None` when it reaches none).
    fn labels(&self, terminals: &[Terminal], n: usize) -> Vec<Option<usize>> {
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); self.nodes];
        for e in &self.touching {
            adj[e.u].push(e.v);
            adj[e.v].push(e.u);
        }
        let mut label: Vec<Option<usize>> = vec![None; self.nodes];
        let mut queue = VecDeque::new();
        for (t, term) in terminals.iter().enumerate() {
            label[n + t] = Some(term.net);
            queue.push_back(n + t);
        }
        while let Some(u) = queue.pop_front() {
            for &v in &adj[u] {
                if v < n && label[v].is_none() {
                    label[v] = label[u];
                    queue.push_back(v);
                }
            }
        }
        label
    }
}

/// Each net's terminals, connected or grouped by component.
fn net_checks(nets: &[String], terminals: &[Terminal], graph: &Graph, n: usize) -> Vec<NetCheck> {
    let mut parent = graph.parent.clone();
    let mut root = |mut x: usize| {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    };
    let mut out = Vec::new();
    for (k, name) in nets.iter().enumerate() {
        let mut groups: BTreeMap<usize, Vec<String>> = BTreeMap::new();
        let mut count = 0;
        for (t, term) in terminals.iter().enumerate().filter(|(_, t)| t.net == k) {
            groups
                .entry(root(n + t))
                .or_default()
                .push(term.label.clone());
            count += 1;
        }
        if count == 0 {
            continue;
        }
        let connected = groups.len() <= 1;
        let mut groups: Vec<Vec<String>> = groups.into_values().collect();
        for g in &mut groups {
            g.sort();
        }
        groups.sort();
        out.push(NetCheck {
            net: name.clone(),
            terminals: count,
            connected,
            groups: if connected { Vec::new() } else { groups },
        });
    }
    out
}

/// The pairs of nets whose material touches or comes closer than the spacing, smallest gap
/// each, touching pairs first, then by gap and names.
fn shorts(graph: &Graph, labels: &[Option<usize>], beads: &[Bead], nets: &[String]) -> Vec<Short> {
    let n = beads.len();
    let mut best: BTreeMap<(usize, usize), Short> = BTreeMap::new();
    for e in graph.touching.iter().chain(&graph.near) {
        let (Some(a), Some(b)) = (labels[e.u], labels[e.v]) else {
            continue;
        };
        if a == b {
            continue;
        }
        let key = (a.min(b), a.max(b));
        let short = Short {
            nets: [nets[key.0].clone(), nets[key.1].clone()],
            at: e.at.map(|v| (v * 1000.0).round() / 1000.0),
            gap: (e.gap * 1000.0).round() / 1000.0,
            touching: e.gap <= 0.0,
            line: if e.u < n { e.line } else { 0 },
        };
        match best.get(&key) {
            Some(s) if s.gap <= short.gap => {}
            _ => {
                best.insert(key, short);
            }
        }
    }
    let mut out: Vec<Short> = best.into_values().collect();
    out.sort_by(|a, b| {
        b.touching
            .cmp(&a.touching)
            .then(a.gap.total_cmp(&b.gap))
            .then(a.nets.cmp(&b.nets))
    });
    out
}

/// The z key of a level, µm.
fn level_key(z: f64) -> i64 {
    (z * 1000.0).round() as i64
}

/// The runs of conductive beads outside the solid (see the [module docs](self#outside-the-solid)).
fn outside_runs(beads: &[Bead], plastic: &[&Move], params: &ElectricalParams) -> Vec<OutsideRun> {
    let mut by_level: BTreeMap<i64, Vec<&Move>> = BTreeMap::new();
    for m in plastic {
        if let Some(z) = m.to[2] {
            by_level.entry(level_key(z)).or_default().push(m);
        }
    }
    let top = by_level.keys().next_back().copied();
    // The plastic level of each bead: the highest at or below it.
    let level_of = |z: f64| -> Option<i64> {
        by_level
            .range(..=level_key(z + params.tolerance))
            .next_back()
            .map(|(k, _)| *k)
    };
    let mut wanted: Vec<i64> = beads.iter().filter_map(|b| level_of(b.z)).collect();
    wanted.sort_unstable();
    wanted.dedup();
    let outlines: HashMap<i64, Vec<ExPolygon>> = wanted
        .par_iter()
        .map(|k| {
            let moves = by_level.get(k).map_or(&[][..], Vec::as_slice);
            (*k, filled_outline(moves, params))
        })
        .collect();

    let mut runs: Vec<OutsideRun> = Vec::new();
    let mut last_end: Option<(P2, f64)> = None;
    for b in beads {
        let above = top.is_none_or(|t| level_key(b.z - params.tolerance) > t);
        let len = dist(b.a, b.b);
        let out_len = if above {
            len
        } else {
            let outline = level_of(b.z).and_then(|k| outlines.get(&k));
            let steps = ((len / params.sample_step).ceil() as usize).clamp(1, MAX_SAMPLES);
            let outside = (0..=steps)
                .filter(|&s| {
                    let t = s as f64 / steps as f64;
                    let p = Point2::from_mm(
                        b.a[0] + t * (b.b[0] - b.a[0]),
                        b.a[1] + t * (b.b[1] - b.a[1]),
                    );
                    !outline.is_some_and(|o| o.iter().any(|x| x.contains(p)))
                })
                .count();
            len * outside as f64 / (steps + 1) as f64
        };
        if out_len <= params.tolerance {
            last_end = None;
            continue;
        }
        let continues = last_end.is_some_and(|(p, z)| dist(p, b.a) <= params.tolerance && z == b.z);
        match runs.last_mut() {
            Some(run) if continues => run.length += out_len,
            _ => runs.push(OutsideRun {
                length: 0.0,
                at: [b.a[0], b.a[1], b.z],
                above_top: above,
                line: b.line,
            }),
        }
        if !continues {
            if let Some(run) = runs.last_mut() {
                run.length = out_len;
            }
        }
        last_end = Some((b.b, b.z));
    }
    for r in &mut runs {
        r.length = (r.length * 1000.0).round() / 1000.0;
    }
    runs
}

/// The outline of one level's plastic: the beads stroked at their widths, united, every hole
/// filled, grown by the tolerance.
fn filled_outline(moves: &[&Move], params: &ElectricalParams) -> Vec<ExPolygon> {
    let mut by_width: BTreeMap<i64, Vec<Polyline>> = BTreeMap::new();
    let mut last: Option<(i64, P2)> = None;
    for m in moves {
        let w = level_key(m.width.unwrap_or(params.plastic_width));
        let pts = path_xy(m);
        let Some(&first) = pts.first() else { continue };
        let lines = by_width.entry(w).or_default();
        let joined = last.is_some_and(|(lw, p)| lw == w && dist(p, first) < 1e-9);
        match lines.last_mut() {
            Some(line) if joined => {
                line.points
                    .extend(pts[1..].iter().map(|p| Point2::from_mm(p[0], p[1])));
            }
            _ => lines.push(Polyline {
                points: pts.iter().map(|p| Point2::from_mm(p[0], p[1])).collect(),
            }),
        }
        last = pts.last().map(|&p| (w, p));
    }
    let mut beads: Vec<ExPolygon> = Vec::new();
    for (w, lines) in &by_width {
        beads.extend(stroke(
            lines,
            *w as f64 / 1000.0,
            Join::Round(0.01),
            Cap::Round(0.01),
        ));
    }
    let united = union(&beads);
    let contours: Vec<_> = united.iter().map(|r| r.contour.clone()).collect();
    let filled = polygons_to_expolygons(&contours, FillRule::NonZero);
    offset(&filled, params.tolerance.max(0.01), Join::Miter(2.0))
}

/// The part events in the file and what is wrong with them; and how many were found.
fn event_problems(
    gcode: &Gcode,
    parts: &[PlacedPart],
    plastic: &[&Move],
    heights: &[f64],
    params: &ElectricalParams,
) -> (Vec<EventProblem>, usize) {
    // Highest plastic printed up to each plastic move, in file order.
    let mut highest = Vec::with_capacity(plastic.len());
    let mut h = f64::NEG_INFINITY;
    for m in plastic {
        h = h.max(m.to[2].unwrap_or(h));
        highest.push(h);
    }
    let mut found = 0;
    let mut seen: Vec<&str> = Vec::new();
    let mut problems = Vec::new();
    for (index, line) in gcode.lines.iter().enumerate() {
        let Some(event) = line
            .comment_text()
            .and_then(|text| part_event(text, index + 1))
        else {
            continue;
        };
        let name = event.part.as_str();
        let Some(part) = parts.iter().find(|p| p.name.replace(' ', "_") == name) else {
            continue;
        };
        found += 1;
        seen.push(&part.name);
        let number = index + 1;
        let top = part.position.z + part.body_height;
        let before = plastic.partition_point(|m| m.line < number);
        let printed = if before == 0 {
            0.0
        } else {
            highest[before - 1]
        };
        if printed < top - 1e-3 {
            problems.push(EventProblem {
                part: part.name.clone(),
                kind: EventProblemKind::Early,
                line: number,
                message: format!(
                    "part {} is placed at line {number} when the plastic reaches z {printed:.3} \
                     mm, below its top ({top:.3} mm): walls are still printed around it",
                    part.name
                ),
            });
        }
        if let Some(z) = lid_before(part, top, &plastic[..before], heights) {
            problems.push(EventProblem {
                part: part.name.clone(),
                kind: EventProblemKind::Late,
                line: number,
                message: format!(
                    "part {} is placed at line {number}, after the layer at z {z:.3} mm was \
                     printed over its cavity (top {top:.3} mm)",
                    part.name
                ),
            });
        }
        if event.machine {
            // A coordinate missing or not a number is off.
            let at = event.at;
            let want = [part.position.x, part.position.y, part.position.z];
            let off = at
                .iter()
                .zip(want)
                .any(|(got, want)| got.is_none_or(|g| (g - want).abs() > 0.01 + params.tolerance));
            if off {
                let show = |v: Option<f64>| v.map_or("?".to_owned(), |v| format!("{v}"));
                problems.push(EventProblem {
                    part: part.name.clone(),
                    kind: EventProblemKind::Misplaced,
                    line: number,
                    message: format!(
                        "part {}'s pick-and-place event at line {number} places it at ({}, {}, \
                         {}), the placement at ({:.3}, {:.3}, {:.3}) (is the frame right? \
                         conduit's own output with origin = \"model\" needs --model)",
                        part.name,
                        show(at[0]),
                        show(at[1]),
                        show(at[2]),
                        want[0],
                        want[1],
                        want[2]
                    ),
                });
            }
        }
    }
    for part in parts {
        if part.method != PlacingMethod::None && !seen.contains(&part.name.as_str()) {
            problems.push(EventProblem {
                part: part.name.clone(),
                kind: EventProblemKind::Missing,
                line: 0,
                message: format!(
                    "part {} ({}) has no event in the file",
                    part.name,
                    if part.method == PlacingMethod::Auto {
                        "pick and place"
                    } else {
                        "inserted by hand"
                    }
                ),
            });
        }
    }
    (problems, found)
}

/// The z of a plastic layer lying wholly above `top` that was printed over the part's footprint
/// (0.1 mm in from its edge) among `before`, if any.
fn lid_before(part: &PlacedPart, top: f64, before: &[&Move], heights: &[f64]) -> Option<f64> {
    let ring: Vec<P2> = part.footprint.points_mm();
    if ring.len() < 3 {
        return None;
    }
    let n = ring.len();
    let deep = |p: P2| {
        inside(p, &ring) && (0..n).all(|i| dist(p, nearest_on(p, ring[i], ring[(i + 1) % n])) > 0.1)
    };
    before.iter().find_map(|m| {
        let z = m.to[2]?;
        if z - height_of(m, heights) < top - 1e-3 {
            return None;
        }
        let pts = path_xy(m);
        let hit = pts.windows(2).any(|w| {
            let steps = ((dist(w[0], w[1]) / 0.5).ceil() as usize).clamp(1, MAX_SAMPLES);
            (0..=steps).any(|s| {
                let t = s as f64 / steps as f64;
                deep([
                    w[0][0] + t * (w[1][0] - w[0][0]),
                    w[0][1] + t * (w[1][1] - w[0][1]),
                ])
            })
        });
        hit.then_some(z)
    })
}

impl ElectricalReport {
    /// One line per problem (open nets, shorts, conductive material outside the solid, event
    /// problems, and how many more were found than listed), as `conduit check` prints them.
    pub fn problem_lines(&self) -> Vec<String> {
        let mut lines = Vec::new();
        for n in self.open_nets() {
            let groups: Vec<String> = n.groups.iter().map(|g| g.join(" ")).collect();
            lines.push(format!(
                "open: net {} is in {} pieces: {}",
                n.net,
                n.groups.len(),
                groups.join(" | ")
            ));
        }
        for s in &self.shorts {
            let what = if s.touching {
                "touch".to_owned()
            } else {
                format!("are {:.3} mm apart", s.gap)
            };
            lines.push(format!(
                "short: nets {} and {} {what} at ({:.3}, {:.3}, z {:.3}){}",
                s.nets[0],
                s.nets[1],
                s.at[0],
                s.at[1],
                s.at[2],
                if s.line > 0 {
                    format!(", line {}", s.line)
                } else {
                    String::new()
                }
            ));
        }
        if self.short_count > self.shorts.len() {
            lines.push(format!(
                "... and {} more shorts",
                self.short_count - self.shorts.len()
            ));
        }
        for r in &self.outside {
            lines.push(format!(
                "outside: {:.2} mm of conductive material {} from ({:.3}, {:.3}, z {:.3}), line {}",
                r.length,
                if r.above_top {
                    "above the object's top"
                } else {
                    "outside the solid"
                },
                r.at[0],
                r.at[1],
                r.at[2],
                r.line
            ));
        }
        if self.outside_count > self.outside.len() {
            lines.push(format!(
                "... and {} more runs outside",
                self.outside_count - self.outside.len()
            ));
        }
        for e in &self.events {
            lines.push(format!("event: {}", e.message));
        }
        lines
    }
}

impl fmt::Display for ElectricalReport {
    /// The text summary: one line per problem, then the counts.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for line in self.problem_lines() {
            writeln!(f, "{line}")?;
        }
        if !self.unplaced_pins.is_empty() {
            writeln!(
                f,
                "not checked: {} pins on unplaced parts",
                self.unplaced_pins.len()
            )?;
        }
        let connected = self.nets.iter().filter(|n| n.connected).count();
        writeln!(
            f,
            "circuit: {connected} of {} nets connected, {} shorts, {} runs outside the solid \
             ({:.2} mm), {} event problems ({} events)",
            self.nets.len(),
            self.short_count,
            self.outside_count,
            self.outside_length,
            self.events.len(),
            self.events_found
        )?;
        write!(
            f,
            "conductive: {} beads, {:.1} mm, {} not reaching a pin",
            self.beads, self.conductive_length, self.floating_beads
        )
    }
}
