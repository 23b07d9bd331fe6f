//! The routing board: the wires routed so far and their channels, with rip-up and reroute.
//!
//! Place in the pipeline: the driver of [`route`](super::route). It routes the wires one after
//! another (order from `order.rs`), each as an A* search (`astar.rs`) on layers from which the
//! channels of other nets' wires and the copper of other nets' pads (each on its layer and the
//! two next to it) are removed.
//!
//! Sequential routing fails when an early wire walls off a later one, for example by passing
//! round a connector whose pins still have to be reached. A failed wire then gets a **rip-up
//! and reroute** attempt: it is searched again with other nets' traces as no obstacle but a cost
//! (each mm inside one costs 25 times more, so the probe runs into as few as it can; pads still
//! count), the routed wires whose channels that probe route runs into (on its layer or an
//! adjacent one) are ripped up, with the wires that end on their traces, the failed wire is
//! routed first, and the ripped wires are routed again after it; the wires this leaves failing
//! get an attempt of their own, `RIP_UP_DEPTH` levels deep. An attempt that does not leave more
//! wires routed than before it is undone. Rounds stop at the first one that keeps no attempt,
//! or after `rip_up_rounds`.
//!
//! Routing stops at the deadline: no search starts once it has passed, a running search looks
//! at the clock every `CLOCK_EVERY` steps and gives up, and no rip-up round or attempt starts.
//! The wires this leaves without a route are reported [`Unrouted::TimeLimit`]; an attempt cut
//! short is undone like any other that routes no more wires. Routing itself stops
//! [`EXPLAIN_SHARE`] of the time before the deadline: the rest is kept for looking at what
//! blocks the wires that failed ([`Board::diagnose`]), so a run that uses all its time still
//! says why, within the limit.
//!
//! Each ordered search runs first in a tight window round its pads (a third of their distance
//! plus a few mm), accepting only a route cheaper than any that leaves it (its length out and
//! back, plus the layer changes every route between its pads needs), and in the full window
//! only if that finds none: most wires of a board run close to their straight line, and a
//! small window's layers are much quicker to carve.
//!
//! With more than one thread, the first pass searches wires whose tight windows lie apart side
//! by side, and keeps each search only if the wires placed before it in turn left what it
//! looked at untouched: the routes are the same on any number of threads.
//!
//! Each search may end on the traces already connected to the wire's far pad ([`Tap`]s): the
//! board follows the routed wires of the net from each pad and starts the search at the pad
//! whose side has less copper, so the target has the most.

use super::astar::{Search, SearchState, Tap, change_cost, cost_limit, layer_range, min_weight};
use super::congestion::History;
use super::graph::{
    Eroded, Grown, LayerGeometry, LayerInput, PENALTY_FACTOR, bbox, box_union, boxes_meet, prepare,
};
use super::index::{dist, lerp};
use super::{
    Blockage, NearPad, PadCopper, Phase, RoundLog, RouteProgress, Strategy, Unrouted, wire_order,
};
use super::{RouteLayer, RouteParams, Wire, WireRoute, channels, layer_of, trace};
use crate::geom::{
    ExPolygon, Point2, Point3, intersection, scaled, segment_distance, union, unscaled,
};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock, PoisonError};
use std::time::Instant;

mod negotiate;

/// Steps of one A* search between two looks at the clock.
const CLOCK_EVERY: usize = 256;

/// The share of the time left to the deadline that routing leaves to [`Board::diagnose`]: on
/// the corpus RedBot board at the default 180 s, 9 s, enough to probe a handful of failed wires.
const EXPLAIN_SHARE: f64 = 0.05;

/// When routing stops, given the `deadline` it has from `now`: [`EXPLAIN_SHARE`] of the time
/// between them earlier.
fn routing_deadline(deadline: Instant, now: Instant) -> Instant {
    now + deadline
        .saturating_duration_since(now)
        .mul_f64(1.0 - EXPLAIN_SHARE)
}

/// A channel area (mm²) below which two channels count as not touching: polygon noise.
const TOUCH_MM2: f64 = 1e-6;

/// How deep a rip-up and reroute attempt may go: the wires an attempt leaves failing get an
/// attempt of their own, down to this many levels.
const RIP_UP_DEPTH: usize = 2;

/// Expansions of the short look from a wire's far pad (see [`Board::search`]): a pad boxed in
/// by other nets' traces is proven so in a few dozen.
const ENCLOSURE_EXPANSIONS: usize = 400;

/// What one search may spend beyond its own limits: routes up to `cost`, `expansions` steps.
#[derive(Debug, Clone, Copy)]
struct Budget {
    cost: f64,
    expansions: usize,
}

impl Budget {
    /// No more than the search's own detour and expansion limits.
    const FULL: Budget = Budget {
        cost: f64::INFINITY,
        expansions: usize::MAX,
    };
}

/// Wires searched ahead per thread in the first pass (see [`Board::first_pass`]): enough
/// that a thread rarely waits for a long search on the other, few enough that most searches
/// made ahead are still valid in their turn.
const LOOK_AHEAD: usize = 2;

/// How far down the order the first pass looks for wires to search ahead.
const LOOK_SCAN: usize = 12;

/// Extra margin of a wire's routing window beyond the farthest its route may go, mm.
const WINDOW_MARGIN_MM: f64 = 2.0;

/// The first, tight routing window of an ordered search grows the pads' box by this fraction
/// of their distance in the plane…
const TIGHT_FRACTION: f64 = 0.35;

/// …plus this many mm (room for a layer change and the walk round a pad or two).
const TIGHT_MARGIN_MM: f64 = 4.0;

/// How far (mm) the tight window of `wire` grows the pads' box.
fn tight_grow(wire: &Wire) -> f64 {
    let d = (wire.to.x - wire.from.x).hypot(wire.to.y - wire.from.y);
    TIGHT_FRACTION * d + TIGHT_MARGIN_MM
}

/// The shortest a route from `start.from` to `start.to` or to one of `taps` can be (mm, in the
/// plane) if it leaves `frame` (scaled box). Such a route crosses one of the frame's four side
/// lines: to an end on the start's side of that line it is at least as long as the straight
/// way from the start's mirror image in the line, to an end beyond the line at least as long as
/// the straight way from the start itself. A tap crossing the line counts with its two parts.
fn exit_bound(start: &Wire, taps: &[Tap], frame: [i64; 4]) -> f64 {
    let a = Point2::from_mm(start.from.x, start.from.y);
    let target = Point2::from_mm(start.to.x, start.to.y);
    let ends: Vec<(Point2, Point2)> = std::iter::once((target, target))
        .chain(taps.iter().map(|t| (t.a, t.b)))
        .collect();
    let mut bound = f64::INFINITY;
    // Each side line as (axis, coordinate, sign): a point is on the frame's side where
    // `sign · (p[axis] − coordinate) ≥ 0`.
    for (axis, at, sign) in [
        (0, frame[0], 1),
        (1, frame[1], 1),
        (0, frame[2], -1),
        (1, frame[3], -1),
    ] {
        let coord = |p: Point2| if axis == 0 { p.x } else { p.y };
        let side = |p: Point2| sign * (coord(p) - at);
        let mirror = |p: Point2| {
            if axis == 0 {
                Point2::new(2 * at - p.x, p.y)
            } else {
                Point2::new(p.x, 2 * at - p.y)
            }
        };
        let m = mirror(a);
        for &(p, q) in &ends {
            let (sp, sq) = (side(p), side(q));
            let d = if sp >= 0 && sq >= 0 {
                segment_distance(m, p, q)
            } else if sp < 0 && sq < 0 {
                segment_distance(a, p, q)
            } else {
                // The piece crosses the line at `x`: its near part is reached over the line,
                // its far part straight.
                let x = lerp(p, q, sp as f64 / (sp - sq) as f64);
                let (near, far) = if sp >= 0 { (p, q) } else { (q, p) };
                segment_distance(m, near, x).min(segment_distance(a, x, far))
            };
            bound = bound.min(d);
        }
    }
    unscaled(1) * bound
}

/// The shortest a route from `start.from` to `start.to` or one of `taps` can be, mm in the
/// plane: the straight way to the nearest of them.
fn least_length(start: &Wire, taps: &[Tap]) -> f64 {
    let a = Point2::from_mm(start.from.x, start.from.y);
    let target = Point2::from_mm(start.to.x, start.to.y);
    let tap = taps
        .iter()
        .map(|t| segment_distance(a, t.a, t.b))
        .fold(f64::INFINITY, f64::min);
    unscaled(1) * tap.min(dist(a, target))
}

/// `pads` grouped by layer and [`PAD_GROUP_MM`] cell of their centres, in a fixed order.
fn group_pads(pads: &[PadObstacle]) -> Vec<PadGroup> {
    let cell = scaled(PAD_GROUP_MM).max(1);
    let mut groups: std::collections::BTreeMap<(usize, i64, i64), PadGroup> =
        std::collections::BTreeMap::new();
    for (k, p) in pads.iter().enumerate() {
        let key = (
            p.layer,
            p.centre.x.div_euclid(cell),
            p.centre.y.div_euclid(cell),
        );
        let reach = p.grown.bbox().map_or(p.bbox, |b| box_union(b, p.bbox));
        let g = groups.entry(key).or_insert_with(|| PadGroup {
            layer: p.layer,
            pads: Vec::new(),
            bbox: reach,
        });
        g.pads.push(k);
        g.bbox = box_union(g.bbox, reach);
    }
    groups.into_values().collect()
}

/// An axis-aligned box, scaled units: `[min x, min y, max x, max y]`.
type BBox = [i64; 4];

/// What the traces of other nets are to a search.
#[derive(Debug, Clone)]
pub(crate) enum Traces {
    /// Holes in the material, with keep-outs no trace centre enters: a normal search.
    Obstacles,
    /// No obstacle but each mm inside their keep-outs costs [`PENALTY_FACTOR`] times more: the
    /// rip-up probe looking for the route that runs into the fewest of them.
    Probe,
    /// No obstacle but each link inside their keep-outs costs `factor` times more, and every
    /// link `1 + history` times more: a negotiation round.
    Priced {
        /// Present-congestion factor of the round.
        factor: f64,
        /// Congestion history of the earlier rounds.
        history: Arc<History>,
    },
}

impl Traces {
    /// The cost factor of their keep-outs, if they are priced rather than holes.
    fn penalty_factor(&self) -> Option<f64> {
        match self {
            Traces::Obstacles => None,
            Traces::Probe => Some(PENALTY_FACTOR),
            Traces::Priced { factor, .. } => Some(*factor),
        }
    }

    /// The congestion history's cap (0 without one).
    fn history_cap(&self) -> f64 {
        match self {
            Traces::Priced { history, .. } => history.cap(),
            _ => 0.0,
        }
    }
}

/// The unions of pad groups' grown holes by (group, net), see [`Board::pad_union`].
type PadUnions = HashMap<(usize, String), Arc<Grown>>;

/// Layer geometry by (layer, net, routing window), shared by the searches that see the
/// layers alike.
type Geometries = HashMap<(usize, String, BBox), Arc<LayerGeometry>>;

/// A part of the board: a box on a range of layers. What a search looks at (other nets'
/// traces within its window, on its layers and the layers next to them, whose traces touch
/// its own), or where a wire is expected to look and place its channels.
#[derive(Debug, Clone)]
struct Reach {
    frame: BBox,
    /// `None` for nowhere (a wire with no layer to be routed on, a search that looked at no
    /// trace).
    layers: Option<std::ops::RangeInclusive<usize>>,
}

impl Reach {
    /// No part of the board.
    fn nowhere() -> Self {
        Self {
            frame: bbox(&[]),
            layers: None,
        }
    }

    /// `frame` on the layers of `range` and the layers next to them.
    fn around(range: &std::ops::RangeInclusive<usize>, frame: BBox) -> Self {
        Self {
            frame,
            layers: Some(range.start().saturating_sub(1)..=range.end().saturating_add(1)),
        }
    }

    /// Whether the two share a layer and a point.
    fn meets(&self, other: &Reach) -> bool {
        match (&self.layers, &other.layers) {
            (Some(a), Some(b)) => {
                a.start() <= b.end()
                    && b.start() <= a.end()
                    && boxes_meet(&self.frame, &other.frame)
            }
            _ => false,
        }
    }

    /// Whether a box `b` on layer `l` lies (partly) within.
    fn holds(&self, l: usize, b: &BBox) -> bool {
        self.layers
            .as_ref()
            .is_some_and(|layers| layers.contains(&l) && boxes_meet(b, &self.frame))
    }
}

/// A wire's search and what of the board it looked at: placing a wire elsewhere leaves the
/// search as it was.
#[derive(Debug)]
struct Searched {
    route: WireRoute,
    looked: Reach,
}

impl Searched {
    /// A search that looked at no trace (no layer for it, or no time).
    fn unlooked(route: WireRoute) -> Self {
        Self {
            route,
            looked: Reach::nowhere(),
        }
    }
}

/// What [`Board::route_all`] ran.
#[derive(Debug, Clone, Default)]
pub(crate) struct Summary {
    /// Rip-up and reroute rounds.
    pub rounds: usize,
    /// Negotiated-congestion rounds.
    pub negotiation_rounds: usize,
    /// Wires still in conflict when negotiation stopped.
    pub negotiation_conflicts: usize,
    /// Where routing stood after each pass and round.
    pub log: Vec<RoundLog>,
}

/// A routed wire's channel and keep-out on one layer.
#[derive(Debug, Clone)]
struct Placed {
    wire: usize,
    net: String,
    /// The trace's centreline on the layer.
    centreline: Vec<Point2>,
    channel: Vec<ExPolygon>,
    keep_out: Vec<ExPolygon>,
    /// Box of the keep-out (which holds the channel).
    bbox: BBox,
    /// The channel grown by every deflation inset, made when a search first needs it.
    grown: OnceLock<Arc<Grown>>,
}

impl Placed {
    /// The channel grown by every deflation inset (see [`Grown`]).
    fn grown(&self, params: &RouteParams) -> Arc<Grown> {
        let half = params.channel_half_width();
        Arc::clone(self.grown.get_or_init(|| {
            Arc::new(Grown::new(params, |d| {
                channels::polyline_grown(&self.centreline, half + d)
            }))
        }))
    }
}

/// Another net's pad as an obstacle: its layer, net, hole and keep-out.
#[derive(Debug, Clone)]
struct PadObstacle<'a> {
    /// Index of the pad in the caller's list.
    index: usize,
    /// Centre of the pad's box.
    centre: Point2,
    layer: usize,
    net: Option<&'a str>,
    /// The hole grown by every deflation inset.
    grown: Arc<Grown>,
    keep_out: Vec<ExPolygon>,
    /// Box of the keep-out (which holds the hole).
    bbox: BBox,
}

/// Side of the cells pads are grouped by (mm): the pads of one part's row fall into a few.
const PAD_GROUP_MM: f64 = 5.0;

/// Pads of one layer whose centres share a [`PAD_GROUP_MM`] cell: their grown holes, which
/// overlap where the pads are close, are subtracted as one union per net that does not own
/// them.
#[derive(Debug, Clone)]
struct PadGroup {
    layer: usize,
    /// Indices into the board's pads.
    pads: Vec<usize>,
    /// Box of the pads' keep-outs and grown holes.
    bbox: BBox,
}

/// The state of routing: every wire's route so far and the channels on every layer.
#[derive(Debug, Clone)]
pub(crate) struct Board<'a> {
    layers: &'a [RouteLayer],
    wires: &'a [Wire],
    params: &'a RouteParams,
    pads: Vec<PadObstacle<'a>>,
    /// The pads grouped by layer and place.
    pad_groups: Vec<PadGroup>,
    /// Per pad group and net, the union of the group's grown holes of the pads of other nets,
    /// made when first needed.
    pad_unions: Arc<Mutex<PadUnions>>,
    placed: Vec<Vec<Placed>>,
    /// Each layer's islands eroded by every deflation inset, made when first needed.
    eroded: Vec<OnceLock<Arc<Eroded>>>,
    routes: Vec<Option<WireRoute>>,
    /// Layer geometry of negotiation rounds (see [`Geometries`]): the material less other
    /// nets' pads, the same in every round.
    geometry: Geometries,
    /// When routing must stop (see [`routing_deadline`]); once routing is over, when looking at
    /// what blocks the failed wires must stop.
    deadline: Option<Instant>,
    /// The deadline the board was given: the end of [`Board::diagnose`].
    explain_until: Option<Instant>,
    /// Whether the deadline stopped any work.
    stopped: bool,
}

impl<'a> Board<'a> {
    /// An empty board: nothing routed yet.
    pub(crate) fn new(
        layers: &'a [RouteLayer],
        wires: &'a [Wire],
        pads: &'a [PadCopper],
        params: &'a RouteParams,
        deadline: Option<Instant>,
    ) -> Self {
        let pads: Vec<PadObstacle> = pads
            .iter()
            .enumerate()
            .filter_map(|(index, p)| {
                let [hole, keep_out] = channels::pad_obstacle(&p.outline, params);
                let pts = &p.outline.points;
                let (x0, x1) = (
                    pts.iter().map(|q| q.x).min()?,
                    pts.iter().map(|q| q.x).max()?,
                );
                let (y0, y1) = (
                    pts.iter().map(|q| q.y).min()?,
                    pts.iter().map(|q| q.y).max()?,
                );
                Some(PadObstacle {
                    index,
                    centre: Point2::new(x0 + (x1 - x0) / 2, y0 + (y1 - y0) / 2),
                    layer: layer_of(layers, p.z)?,
                    net: p.net.as_deref(),
                    bbox: bbox(&keep_out),
                    grown: Arc::new(Grown::of_polygons(&hole, params)),
                    keep_out,
                })
            })
            .collect();
        let pad_groups = group_pads(&pads);
        Self {
            layers,
            wires,
            params,
            pads,
            pad_groups,
            pad_unions: Arc::new(Mutex::new(HashMap::new())),
            placed: vec![Vec::new(); layers.len()],
            eroded: (0..layers.len()).map(|_| OnceLock::new()).collect(),
            routes: vec![None; wires.len()],
            geometry: Geometries::new(),
            deadline: deadline.map(|d| routing_deadline(d, Instant::now())),
            explain_until: deadline,
            stopped: false,
        }
    }

    /// Routes every wire: by negotiated congestion ([`Strategy::Negotiated`], see
    /// `negotiate.rs`) or one after another in [`wire_order`]; then runs the rip-up and reroute
    /// rounds for the wires left without a route, telling the progress callback after each wire
    /// and attempt.
    pub(crate) fn route_all(&mut self) -> Summary {
        let total = self.wires.len();
        let order = wire_order(self.wires, self.params);
        let mut summary = Summary::default();
        if self.params.strategy == Strategy::Negotiated {
            (summary.negotiation_rounds, summary.negotiation_conflicts) =
                self.negotiate(&order, &mut summary.log);
        } else {
            self.first_pass(&order);
            summary.log.push(self.log_line(Phase::FirstPass, 1, 0));
        }
        for round in 1..=self.params.rip_up_rounds {
            if self.routed_count() == total || self.past_deadline() {
                break;
            }
            summary.rounds = round;
            self.tell(total, round);
            let kept = self.rip_up_round(round);
            summary.log.push(self.log_line(Phase::RipUp, round, 0));
            if !kept {
                break;
            }
        }
        summary
    }

    /// Routes the wires of `order` one after another on the board as each leaves it.
    ///
    /// With more than one thread, the wires next in order are searched side by side, each on
    /// the board as it stands when the batch starts, [`LOOK_AHEAD`] per thread. A wire's search
    /// is kept for its turn if no wire placed in between lies where it looked
    /// ([`Board::still_valid`]): it is then the search the wire would have had in its turn,
    /// so the routes are the same on any number of threads. Wires far apart on a board, which
    /// are most neighbours in the order, are routed in parallel; the others are searched
    /// again in their turn.
    fn first_pass(&mut self, order: &[usize]) {
        let threads = rayon::current_num_threads();
        // The wires placed so far, in turn, and the searches made ahead with how many of
        // those had been placed when each was made.
        let mut placed_in_turn: Vec<usize> = Vec::new();
        let mut ahead: HashMap<usize, (Searched, usize)> = HashMap::new();
        let reach: Vec<Reach> = if threads < 2 {
            Vec::new()
        } else {
            (0..self.wires.len()).map(|w| self.reach(w)).collect()
        };
        for (k, &i) in order.iter().enumerate() {
            let valid = |board: &Self, w: usize, (searched, since): &(Searched, usize)| {
                placed_in_turn[*since..]
                    .iter()
                    .all(|&c| board.still_valid(c, w, searched))
            };
            let made = ahead.remove(&i).filter(|made| valid(self, i, made));
            let searched = match made {
                Some((searched, _)) => searched,
                None if threads < 2 || self.past_deadline() => {
                    self.route_one(i);
                    placed_in_turn.push(i);
                    self.tell(k + 1, 0);
                    continue;
                }
                None => {
                    // Worth a search ahead: a wire whose tight window meets none of those of
                    // the wires before it, which are placed in them as a rule.
                    let scan = &order[k..(k + LOOK_SCAN).min(order.len())];
                    let apart =
                        |m: usize| scan[..m].iter().all(|&w| !reach[w].meets(&reach[scan[m]]));
                    let batch: Vec<usize> = std::iter::once(i)
                        .chain(
                            (1..scan.len())
                                .filter(|&m| apart(m))
                                .map(|m| scan[m])
                                .filter(|w| {
                                    !ahead.get(w).is_some_and(|made| valid(self, *w, made))
                                }),
                        )
                        .take(threads * LOOK_AHEAD)
                        .collect();
                    let obstacles = Traces::Obstacles;
                    let mut made: Vec<Searched> = batch
                        .par_iter()
                        .map(|&w| self.search(w, &obstacles, &mut Geometries::new()))
                        .collect();
                    let first = made.remove(0);
                    let since = placed_in_turn.len();
                    for (w, searched) in batch[1..].iter().zip(made) {
                        ahead.insert(*w, (searched, since));
                    }
                    first
                }
            };
            self.stopped |= matches!(searched.route.reason, Some(Unrouted::TimeLimit(_)));
            self.place(i, searched.route);
            placed_in_turn.push(i);
            self.tell(k + 1, 0);
        }
    }

    /// Where wire `i`'s channels lie when its tight search finds its route: the tight
    /// window grown by a keep-out, on the layers of its search and the next ones.
    fn reach(&self, i: usize) -> Reach {
        let wire = &self.wires[i];
        let Some(range) = layer_range(self.layers, wire, self.params) else {
            return Reach::nowhere();
        };
        let frame = bbox(&self.window(wire, &Traces::Obstacles, Some(tight_grow(wire))));
        let d = scaled(channels::keep_out_radius(self.params));
        Reach::around(
            &range,
            [frame[0] - d, frame[1] - d, frame[2] + d, frame[3] + d],
        )
    }

    /// Whether wire `j`'s search `searched`, made before wire `i` was placed, is still the one
    /// it would have now: it did not run out of time, `i` is of another net (whose traces are
    /// not `j`'s to end on), and no channel of `i` lies where the search looked.
    fn still_valid(&self, i: usize, j: usize, searched: &Searched) -> bool {
        if matches!(searched.route.reason, Some(Unrouted::TimeLimit(_)))
            || self.wires[i].net == self.wires[j].net
        {
            return false;
        }
        !self.placed.iter().enumerate().any(|(l, placed)| {
            placed
                .iter()
                .any(|p| p.wire == i && searched.looked.holds(l, &p.bbox))
        })
    }

    /// Whether the deadline has passed; if so, routing stops (and says so).
    fn past_deadline(&mut self) -> bool {
        let past = self.deadline_passed();
        self.stopped |= past;
        past
    }

    /// Whether the deadline has passed or a stop was requested (without saying so).
    fn deadline_passed(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d) || crate::interrupt::requested()
    }

    /// Whether the deadline stopped any work: a search not started or cut short, a round or
    /// attempt not run.
    pub(crate) fn stopped_by_deadline(&self) -> bool {
        self.stopped
    }

    /// Where routing stands after `phase`'s round `round`, with `conflicts` wires in conflict.
    fn log_line(&self, phase: Phase, round: usize, conflicts: usize) -> RoundLog {
        let routed = self.routed_count();
        RoundLog {
            phase,
            round,
            routed,
            unrouted: self.wires.len() - routed,
            conflicts,
        }
    }

    /// Tells the progress callback, if any, where routing stands.
    fn tell(&self, done: usize, round: usize) {
        self.tell_negotiation(done, round, 0, 0);
    }

    /// Tells the progress callback, if any, where routing stands, in negotiation round
    /// `negotiation` with `conflicts` wires in conflict.
    fn tell_negotiation(&self, done: usize, round: usize, negotiation: usize, conflicts: usize) {
        if let Some(progress) = &self.params.watch.progress {
            progress(RouteProgress {
                done,
                total: self.wires.len(),
                round,
                negotiation,
                conflicts,
                unrouted: self
                    .routes
                    .iter()
                    .filter(|r| r.as_ref().is_some_and(|r| !r.routed))
                    .count(),
            });
        }
    }

    /// Looks at what stands in the way of every wire left without a route (not for lack of a
    /// layer or time), until the board's deadline (routing stopped a little before it, see
    /// [`routing_deadline`]): see [`Blockage`]. Whether the deadline stopped
    /// routing is left as it was: this only explains the result.
    pub(crate) fn diagnose(&mut self) {
        let stopped = self.stopped;
        self.deadline = self.explain_until;
        for i in 0..self.wires.len() {
            let explain = self.routes[i].as_ref().is_none_or(|r| {
                !r.routed && !matches!(r.reason, Some(Unrouted::TimeLimit(_) | Unrouted::NoLayer))
            });
            if !explain || self.past_deadline() {
                continue;
            }
            let blockage = self.blockage(i);
            let route = self.routes[i]
                .get_or_insert_with(|| trace::unrouted(&self.wires[i], Unrouted::NoPath));
            route.blockage = blockage;
        }
        self.stopped = stopped;
    }

    /// What stands in the way of wire `i`: the traces its rip-up probe runs into, and the pads
    /// of other nets too close to its own; `None` if the deadline cut the probe short.
    fn blockage(&mut self, i: usize) -> Option<Blockage> {
        let probe = self.searched(i, &Traces::Probe);
        if matches!(probe.reason, Some(Unrouted::TimeLimit(_))) {
            return None;
        }
        let traces = if probe.routed {
            self.blockers(i, &probe)
        } else {
            Vec::new()
        };
        let wire = &self.wires[i];
        let spacing = scaled(channels::keep_out_radius(self.params)) as f64;
        let mut pads: Vec<NearPad> = Vec::new();
        for (near_to, end) in [(false, wire.from), (true, wire.to)] {
            let Some(l) = layer_of(self.layers, end.z) else {
                continue;
            };
            let at = Point2::from_mm(end.x, end.y);
            for p in &self.pads {
                let d = super::index::dist(p.centre, at);
                if p.layer.abs_diff(l) <= 1
                    && p.net != Some(wire.net.as_str())
                    && d < spacing
                    && !pads.iter().any(|n| n.pad == p.index)
                {
                    pads.push(NearPad {
                        pad: p.index,
                        distance: d * unscaled(1),
                        near_to,
                    });
                }
            }
        }
        pads.sort_by(|a, b| a.distance.total_cmp(&b.distance).then(a.pad.cmp(&b.pad)));
        Some(Blockage {
            traces,
            pads,
            way_without_traces: probe.routed,
        })
    }

    /// A wire stopped by the deadline.
    fn out_of_time(&self, i: usize) -> WireRoute {
        trace::unrouted(&self.wires[i], Unrouted::TimeLimit(self.params.time_limit))
    }

    /// Number of wires with a route.
    fn routed_count(&self) -> usize {
        self.routes
            .iter()
            .filter(|r| r.as_ref().is_some_and(|r| r.routed))
            .count()
    }

    /// The routes, one per wire in input order, and the union of the channels per layer.
    pub(crate) fn finish(self) -> (Vec<WireRoute>, Vec<Vec<ExPolygon>>) {
        let channels = self
            .placed
            .iter()
            .map(|ps| {
                let all: Vec<ExPolygon> =
                    ps.iter().flat_map(|p| p.channel.iter().cloned()).collect();
                if all.is_empty() { all } else { union(&all) }
            })
            .collect();
        let routes = self
            .routes
            .into_iter()
            .zip(self.wires)
            .map(|(r, w)| r.unwrap_or_else(|| trace::unrouted(w, Unrouted::NoPath)))
            .collect();
        (routes, channels)
    }

    /// One rip-up and reroute round over the wires that failed, in wire order (see
    /// [`Board::attempt`]); returns whether any attempt was kept.
    fn rip_up_round(&mut self, round: usize) -> bool {
        let mut improved = false;
        for f in self.failed() {
            if self.past_deadline() {
                break;
            }
            improved |= self.attempt(f, RIP_UP_DEPTH);
            self.tell(self.wires.len(), round);
        }
        improved
    }

    /// The wires without a route, in wire order.
    fn failed(&self) -> Vec<usize> {
        wire_order(self.wires, self.params)
            .into_iter()
            .filter(|&i| !self.routes[i].as_ref().is_some_and(|r| r.routed))
            .collect()
    }

    /// One rip-up and reroute of failed wire `f`: probe, rip up the blockers, route `f`, reroute
    /// the blockers; with `depth` left, the wires that this leaves failing get an attempt of
    /// their own. Kept only if more wires are routed than before (a failed wire routed at the
    /// cost of another is undone); returns whether it was kept.
    fn attempt(&mut self, f: usize, depth: usize) -> bool {
        if depth == 0 || self.routes[f].as_ref().is_some_and(|r| r.routed) || self.past_deadline() {
            return false;
        }
        let probe = self.searched(f, &Traces::Probe);
        if !probe.routed {
            return false; // unroutable even on an empty board
        }
        let blockers = self.blockers(f, &probe);
        if blockers.is_empty() {
            return false;
        }
        let before = self.routed_count();
        let failed_before = self.failed();
        let saved = self.clone();
        let mut ripped = Vec::new();
        for &b in &blockers {
            self.rip_up(b, &mut ripped);
        }
        self.route_one(f);
        for b in ripped {
            self.route_one(b);
        }
        for g in self.failed() {
            if !failed_before.contains(&g) {
                self.attempt(g, depth - 1);
            }
        }
        if self.routed_count() > before {
            true
        } else {
            let stopped = self.stopped;
            *self = saved;
            self.stopped = stopped;
            false
        }
    }

    /// Routes wire `i` on the board as it stands and places its channels (none, once the
    /// deadline has passed).
    fn route_one(&mut self, i: usize) {
        self.route_with(i, &Traces::Obstacles);
    }

    /// Routes wire `i` with other nets' traces as `traces` says and places its channels (none,
    /// once the deadline has passed).
    fn route_with(&mut self, i: usize, traces: &Traces) {
        let result = if self.past_deadline() {
            self.out_of_time(i)
        } else {
            self.searched(i, traces)
        };
        self.place(i, result);
    }

    /// Wire `i`'s search on the board as it stands (see [`Board::search`]), saying so if the
    /// deadline cut it short. A negotiation round's layer geometry (the material less other
    /// nets' pads) is the same in every round, only the prices change: it is kept from search
    /// to search; other searches build their own.
    fn searched(&mut self, i: usize, traces: &Traces) -> WireRoute {
        let keep = matches!(traces, Traces::Priced { .. });
        let mut cache = if keep {
            std::mem::take(&mut self.geometry)
        } else {
            Geometries::new()
        };
        let route = self.search(i, traces, &mut cache).route;
        if keep {
            self.geometry = cache;
        }
        self.stopped |= matches!(route.reason, Some(Unrouted::TimeLimit(_)));
        route
    }

    /// Places wire `i`'s `result`: its channels on their layers, and the route.
    fn place(&mut self, i: usize, result: WireRoute) {
        let half = self.params.channel_half_width();
        let keep_out_radius = channels::keep_out_radius(self.params);
        for (l, points) in &result.segments {
            let xy: Vec<Point2> = points.iter().map(|p| Point2::from_mm(p.x, p.y)).collect();
            let keep_out = channels::polyline_channel(&xy, keep_out_radius);
            self.placed[*l].push(Placed {
                wire: i,
                net: self.wires[i].net.clone(),
                channel: channels::polyline_channel(&xy, half),
                centreline: xy,
                bbox: bbox(&keep_out),
                keep_out,
                grown: OnceLock::new(),
            });
        }
        self.routes[i] = Some(result);
    }

    /// Removes wire `i`'s route and channels, and those of the wires that end on its trace (and
    /// so on): without it they would join nothing. Appends the wires removed to `ripped`.
    fn rip_up(&mut self, i: usize, ripped: &mut Vec<usize>) {
        if self.routes[i].is_none() {
            return;
        }
        for layer in &mut self.placed {
            layer.retain(|p| p.wire != i);
        }
        self.routes[i] = None;
        ripped.push(i);
        let dependants: Vec<usize> = (0..self.routes.len())
            .filter(|&w| {
                self.routes[w]
                    .as_ref()
                    .is_some_and(|r| r.ends_on_wire == Some(i))
            })
            .collect();
        for w in dependants {
            self.rip_up(w, ripped);
        }
    }

    /// The pads connected to `pad` by the routed wires of `net` (`pad` included), and those
    /// wires, by increasing index.
    fn connected(&self, net: &str, pad: Point3) -> (Vec<Point3>, Vec<usize>) {
        let mut pads = vec![pad];
        let mut wires: Vec<usize> = Vec::new();
        loop {
            let before = wires.len();
            for (i, w) in self.wires.iter().enumerate() {
                let routed = self.routes[i].as_ref().is_some_and(|r| r.routed);
                if !routed || w.net != net || wires.contains(&i) {
                    continue;
                }
                let (a, b) = (pads.contains(&w.from), pads.contains(&w.to));
                if a || b {
                    wires.push(i);
                    for p in [w.from, w.to] {
                        if !pads.contains(&p) {
                            pads.push(p);
                        }
                    }
                }
            }
            if wires.len() == before {
                break;
            }
        }
        wires.sort_unstable();
        (pads, wires)
    }

    /// The trace pieces of `wires`, as [`Tap`]s.
    fn taps(&self, wires: &[usize]) -> Vec<Tap> {
        let mut out = Vec::new();
        for &w in wires {
            let Some(route) = &self.routes[w] else {
                continue;
            };
            for (layer, points) in &route.segments {
                let xy: Vec<Point2> = points.iter().map(|p| Point2::from_mm(p.x, p.y)).collect();
                for s in xy.windows(2) {
                    out.push(Tap {
                        layer: *layer,
                        a: s[0],
                        b: s[1],
                        wire: w,
                    });
                }
            }
        }
        out
    }

    /// The routed wires of other nets whose channels the route `probe` of wire `i` runs into,
    /// on its layer or an adjacent one; by increasing index.
    fn blockers(&self, i: usize, probe: &WireRoute) -> Vec<usize> {
        let half = self.params.channel_half_width();
        let net = &self.wires[i].net;
        let mut out: Vec<usize> = Vec::new();
        for (l, points) in &probe.segments {
            let xy: Vec<Point2> = points.iter().map(|p| Point2::from_mm(p.x, p.y)).collect();
            let mine = channels::polyline_channel(&xy, half);
            for p in self.near(*l).filter(|p| &p.net != net) {
                if out.contains(&p.wire) {
                    continue;
                }
                let common = intersection(&mine, &p.channel);
                if common.iter().map(ExPolygon::area_mm2).sum::<f64>() > TOUCH_MM2 {
                    out.push(p.wire);
                }
            }
        }
        out.sort_unstable();
        out
    }

    /// The channels placed on layer `l` and the layers just below and above it: a trace fills
    /// its channel up to the layer's top and the next layer is printed on it, so traces of
    /// adjacent layers touch where they overlap.
    fn near(&self, l: usize) -> impl Iterator<Item = &Placed> {
        let near = l.saturating_sub(1)..=(l + 1).min(self.layers.len() - 1);
        self.placed[near].iter().flatten()
    }

    /// Runs the A* search of wire `i`, with the channels of other nets' wires as `traces` says;
    /// other nets' pads are always in the way.
    ///
    /// The route may end on the traces already connected to either pad (see [`Tap`]): it starts
    /// at the pad whose side has less trace and ends on the other side's pad or traces, so it
    /// has the most copper to aim at.
    ///
    /// A search still running at the deadline gives up: the wire is out of time.
    ///
    /// The layer geometry is taken from `cache` where it holds it, and what is built is added:
    /// the board as it stands is the same for every search of one wire (from either pad).
    fn search(&self, i: usize, traces: &Traces, cache: &mut Geometries) -> Searched {
        let wire = &self.wires[i];
        let Some(range) = layer_range(self.layers, wire, self.params) else {
            return Searched::unlooked(trace::unrouted(wire, Unrouted::NoLayer));
        };
        let out_of_time = || Searched::unlooked(self.out_of_time(i));
        let (from_pads, from_wires) = self.connected(&wire.net, wire.from);
        let (_, to_wires) = self.connected(&wire.net, wire.to);
        let (start, taps) = if from_pads.contains(&wire.to) {
            // Already connected: a plain pad-to-pad route.
            (wire.clone(), Vec::new())
        } else {
            let (from_taps, to_taps) = (self.taps(&from_wires), self.taps(&to_wires));
            if from_taps.len() > to_taps.len() {
                (wire.reversed(), from_taps)
            } else {
                (wire.clone(), to_taps)
            }
        };
        // A route in open material runs close to the straight line, and most of the full
        // window's geometry is never looked at. An ordered search therefore first runs in a
        // window a fraction of the size, where it may only accept a route cheaper than any
        // route that leaves that window could be ([`exit_bound`]): no route through the rest of
        // the full window is cheaper, so only the wires that need the room pay for it (their
        // tight search is the price, about a tenth more time where the layers are plain and
        // the search itself dominates, as on the 100-net benchmark).
        let window = self.window(wire, traces, None);
        let seen = |route: WireRoute, window: &[ExPolygon]| Searched {
            route,
            looked: Reach::around(&range, bbox(window)),
        };
        if matches!(traces, Traces::Obstacles) {
            let tight = self.window(wire, traces, Some(tight_grow(wire)));
            let frame = bbox(&tight);
            let reach = exit_bound(&start, &taps, frame) - 2.0 * self.params.align_tolerance;
            // A window every route leaves (a trace of the net close by, outside it) is not
            // worth a search.
            if !tight.is_empty() && frame != bbox(&window) && reach > least_length(&start, &taps) {
                // Every route, in the window or out of it, also changes layer at least as
                // often as its start and nearest end lie apart, and each change costs at
                // least `change_cost`.
                let changes = self.layer_gap(&start, &taps) as f64;
                let budget = Budget {
                    cost: min_weight(self.params) * reach + change_cost(self.params) * changes,
                    ..Budget::FULL
                };
                match self.run(
                    i,
                    range.clone(),
                    &start,
                    taps.clone(),
                    &tight,
                    traces,
                    budget,
                    cache,
                ) {
                    None => return out_of_time(),
                    Some(route) if route.routed => return seen(route, &tight),
                    Some(_) => {}
                }
            }
        }
        // With no trace of the net to end on, the route may be searched from either pad, and
        // the two searches differ: a pad boxed in by other nets' traces is proven unreachable
        // from its own side in a few dozen expansions, where the search from the other side
        // floods everything within the detour limit first; and each search's grid is laid out
        // from its own start, so a narrow gap one of them misses the other may pass. So the
        // far pad gets a short look first, and the whole search from it when the near one
        // runs out of detour.
        let reverse = taps.is_empty().then(|| start.reversed());
        if let Some(reverse) = &reverse {
            let budget = Budget {
                expansions: ENCLOSURE_EXPANSIONS,
                ..Budget::FULL
            };
            let look = self.run(
                i,
                range.clone(),
                reverse,
                Vec::new(),
                &window,
                traces,
                budget,
                cache,
            );
            match look {
                None => return out_of_time(),
                Some(r) if r.routed || r.reason == Some(Unrouted::NoPath) => {
                    return seen(r, &window);
                }
                Some(_) => {}
            }
        }
        let Some(route) = self.run(
            i,
            range.clone(),
            &start,
            taps,
            &window,
            traces,
            Budget::FULL,
            cache,
        ) else {
            return out_of_time();
        };
        let route = match reverse {
            Some(reverse) if route.reason == Some(Unrouted::Detour) => {
                match self.run(
                    i,
                    range.clone(),
                    &reverse,
                    Vec::new(),
                    &window,
                    traces,
                    Budget::FULL,
                    cache,
                ) {
                    None => return out_of_time(),
                    Some(r) if r.routed => r,
                    Some(_) => route,
                }
            }
            _ => route,
        };
        seen(route, &window)
    }

    /// The fewest layers between `start`'s pad and its end: its far pad or the nearest of
    /// `taps` by layer.
    fn layer_gap(&self, start: &Wire, taps: &[Tap]) -> usize {
        let layer = |z: f64| layer_of(self.layers, z);
        let Some(from) = layer(start.from.z) else {
            return 0;
        };
        layer(start.to.z)
            .into_iter()
            .chain(taps.iter().map(|t| t.layer))
            .map(|l| l.abs_diff(from))
            .min()
            .unwrap_or(0)
    }

    /// Runs the search of wire `i` (from `start`, ending on its far pad or `taps`) on the
    /// layers of `range` within `window`, within `budget`, with the layer geometry `cache`
    /// holds (and adding what it builds); `None` if the deadline passed while it ran.
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        i: usize,
        range: std::ops::RangeInclusive<usize>,
        start: &Wire,
        taps: Vec<Tap>,
        window: &[ExPolygon],
        traces: &Traces,
        budget: Budget,
        cache: &mut Geometries,
    ) -> Option<WireRoute> {
        let wire = &self.wires[i];
        let frame = bbox(window);
        let keys: Vec<(usize, String, BBox)> =
            range.map(|l| (l, wire.net.clone(), frame)).collect();
        let known: Vec<Option<Arc<LayerGeometry>>> =
            keys.iter().map(|k| cache.get(k).cloned()).collect();
        let inputs: Vec<LayerInput> = keys
            .iter()
            .zip(&known)
            .map(|(k, g)| self.input(k.0, wire, traces, window, g.is_some()))
            .collect();
        let layers = prepare(&inputs, known, self.params);
        for (key, layer) in keys.into_iter().zip(&layers) {
            cache
                .entry(key)
                .or_insert_with(|| Arc::clone(&layer.geometry));
        }
        let mut search = Search::with_prepared(layers, self.layers, start, self.params, taps);
        search.cap_cost(budget.cost);
        search.cap_expansions(budget.expansions);
        let mut steps = 0usize;
        while search.step() == SearchState::Running {
            steps += 1;
            if steps % CLOCK_EVERY == 0 && self.deadline_passed() {
                return None;
            }
        }
        Some(search.result())
    }

    /// The routing window of `wire`: the box no route within the detour limit leaves. A route
    /// of length at most `L` between pads `d` apart lies in the ellipse with the pads as foci
    /// and `L` as major axis, whose box is the pads' box grown by `(L - d) / 2`. `L` is the
    /// search's [`cost_limit`] over the smallest weight per mm. (The search measures `d` between
    /// the pads' vertices, which may sit up to `align_tolerance` away; the window's margin
    /// covers that.)
    /// With `cap`, the window grows by at most `cap` mm around the pads' box.
    fn window(&self, wire: &Wire, traces: &Traces, cap: Option<f64>) -> Vec<ExPolygon> {
        let p = self.params;
        let d = ((wire.to.x - wire.from.x).powi(2)
            + (wire.to.y - wire.from.y).powi(2)
            + (wire.to.z - wire.from.z).powi(2))
        .sqrt();
        let (Some(a), Some(b)) = (
            layer_of(self.layers, wire.from.z),
            layer_of(self.layers, wire.to.z),
        ) else {
            return Vec::new();
        };
        // A negotiation round's window leaves out the room its present factor adds to the
        // search's limit (5 mm through other traces): the window, and so the layer geometry
        // made for it, stays the same from round to round.
        let penalty = match traces {
            Traces::Priced { .. } => None,
            _ => traces.penalty_factor(),
        };
        let limit = cost_limit(p, d, a.abs_diff(b), penalty, traces.history_cap());
        let min_weight = min_weight(p).max(1e-9);
        let grow = ((limit / min_weight - d) / 2.0).max(0.0) + WINDOW_MARGIN_MM;
        let grow = cap.map_or(grow, |cap| grow.min(cap));
        if !grow.is_finite() {
            return Vec::new();
        }
        let (x0, x1) = (
            wire.from.x.min(wire.to.x) - grow,
            wire.from.x.max(wire.to.x) + grow,
        );
        let (y0, y1) = (
            wire.from.y.min(wire.to.y) - grow,
            wire.from.y.max(wire.to.y) + grow,
        );
        vec![ExPolygon {
            contour: crate::geom::Polygon::new(vec![
                Point2::from_mm(x0, y0),
                Point2::from_mm(x1, y0),
                Point2::from_mm(x1, y1),
                Point2::from_mm(x0, y1),
            ]),
            holes: Vec::new(),
        }]
    }

    /// The union of the grown holes of pad group `g`'s pads that are not of `net` (made on first
    /// use); `None` if all are of `net`.
    fn pad_union(&self, g: usize, net: &str) -> Option<Arc<Grown>> {
        let key = (g, net.to_owned());
        let unions = || {
            self.pad_unions
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
        };
        if let Some(known) = unions().get(&key) {
            return Some(Arc::clone(known));
        }
        let members: Vec<&Grown> = self.pad_groups[g]
            .pads
            .iter()
            .map(|&k| &self.pads[k])
            .filter(|p| p.net != Some(net))
            .map(|p| p.grown.as_ref())
            .collect();
        if members.is_empty() {
            return None;
        }
        let union = Arc::new(Grown::union(&members));
        // Two searches on two threads may both make it: the same union either way.
        Some(Arc::clone(unions().entry(key).or_insert(union)))
    }

    /// Layer `l`'s islands eroded by every deflation inset (made on first use).
    fn eroded(&self, l: usize) -> Arc<Eroded> {
        Arc::clone(
            self.eroded[l]
                .get_or_init(|| Arc::new(Eroded::new(&self.layers[l].islands, self.params))),
        )
    }

    /// Layer `l` as `wire` sees it within `window` (everything if empty): the islands less the
    /// holes of other nets' pads and, if `traces` are obstacles, channels, and their keep-outs;
    /// else other nets' traces are no obstacle but a penalty (their keep-outs).
    /// With `prices_only`, only the penalty and the history are filled in (the geometry is
    /// known already).
    fn input(
        &self,
        l: usize,
        wire: &Wire,
        traces: &Traces,
        window: &[ExPolygon],
        prices_only: bool,
    ) -> LayerInput {
        let mut holes: Vec<Arc<Grown>> = Vec::new();
        let mut blocked: Vec<ExPolygon> = Vec::new();
        let mut penalty: Vec<ExPolygon> = Vec::new();
        let frame = if window.is_empty() {
            [i64::MIN, i64::MIN, i64::MAX, i64::MAX]
        } else {
            bbox(window)
        };
        for p in self
            .near(l)
            .filter(|p| p.net != wire.net && boxes_meet(&p.bbox, &frame))
        {
            if matches!(traces, Traces::Obstacles) {
                if !prices_only {
                    holes.push(p.grown(self.params));
                    blocked.extend(p.keep_out.iter().cloned());
                }
            } else {
                penalty.extend(p.keep_out.iter().cloned());
            }
        }
        if !prices_only {
            // A pad is an obstacle on the layers just below and above its own too: its net's
            // trace leaves it on the pad's layer, and another net's trace under or over that
            // start would touch it (as between any two traces of adjacent layers) and wall the
            // pad in.
            for (g, group) in self.pad_groups.iter().enumerate() {
                if group.layer.abs_diff(l) > 1 || !boxes_meet(&group.bbox, &frame) {
                    continue;
                }
                if let Some(union) = self.pad_union(g, &wire.net) {
                    holes.push(union);
                }
                for pad in group.pads.iter().map(|&k| &self.pads[k]) {
                    if pad.net != Some(wire.net.as_str()) && boxes_meet(&pad.bbox, &frame) {
                        blocked.extend(pad.keep_out.iter().cloned());
                    }
                }
            }
        }
        LayerInput {
            index: l,
            z: self.layers[l].z,
            eroded: self.eroded(l),
            window: (!window.is_empty()).then_some(frame),
            holes,
            blocked,
            penalty: if penalty.is_empty() {
                penalty
            } else {
                union(&penalty)
            },
            penalty_factor: traces.penalty_factor().unwrap_or(1.0),
            history: match traces {
                Traces::Priced { history, .. } => Some(Arc::clone(history)),
                _ => None,
            },
        }
    }
}

#[cfg(test)]
mod window_tests {
    use super::*;

    #[test]
    fn routing_leaves_the_last_twentieth_of_its_time_to_the_diagnosis() {
        let now = Instant::now();
        let d = now + std::time::Duration::from_secs(180);
        assert_eq!(
            routing_deadline(d, now),
            now + std::time::Duration::from_secs(171)
        );
        // A deadline already past stays past.
        assert_eq!(
            routing_deadline(now, now + std::time::Duration::from_secs(1)),
            now + std::time::Duration::from_secs(1)
        );
    }

    fn wire(from: [f64; 2], to: [f64; 2]) -> Wire {
        Wire {
            net: "N".into(),
            from: Point3::new(from[0], from[1], 0.2),
            to: Point3::new(to[0], to[1], 0.2),
        }
    }

    fn frame(b: [f64; 4]) -> [i64; 4] {
        [scaled(b[0]), scaled(b[1]), scaled(b[2]), scaled(b[3])]
    }

    #[test]
    fn exit_bound_of_a_straight_wire_is_the_way_over_the_nearest_side() {
        // Pads 10 mm apart along x in a box grown by 3 mm: the cheapest way out runs over the
        // top or bottom side, √(6² + 10²) long.
        let w = wire([0.0, 0.0], [10.0, 0.0]);
        let bound = exit_bound(&w, &[], frame([-3.0, -3.0, 13.0, 3.0]));
        assert!((bound - (36.0f64 + 100.0).sqrt()).abs() < 1e-6, "{bound}");
        // Over an end side instead when that is nearer: grown by 3 mm in y, 0.5 mm in x, the
        // way back round the start's end is 0.5 + 0.5 + 10 mm.
        let bound = exit_bound(&w, &[], frame([-0.5, -3.0, 10.5, 3.0]));
        assert!((bound - 11.0).abs() < 1e-6, "{bound}");
        assert!((least_length(&w, &[]) - 10.0).abs() < 1e-6);
    }

    #[test]
    fn a_tap_beyond_the_frame_bounds_the_way_out_by_its_distance() {
        let w = wire([0.0, 0.0], [10.0, 0.0]);
        // A trace of the net running from (5, 2) up to (5, 8), across the top side at y = 3.
        let tap = Tap {
            layer: 0,
            a: Point2::from_mm(5.0, 2.0),
            b: Point2::from_mm(5.0, 8.0),
            wire: 0,
        };
        let bound = exit_bound(
            &w,
            std::slice::from_ref(&tap),
            frame([-3.0, -3.0, 13.0, 3.0]),
        );
        // The far part starts at (5, 3): √(5² + 3²) from the start, straight.
        assert!((bound - 34.0f64.sqrt()).abs() < 1e-6, "{bound}");
        assert!((least_length(&w, &[tap]) - 29.0f64.sqrt()).abs() < 1e-6);
    }
}
