//! Conductive trace routing through a sliced object: weighted A* on per-layer perimeter graphs.
//!
//! Place in the pipeline: after slicing and regions (the object's islands per layer, with
//! cavities for parts already removed), before the Program. Input is one [`RouteLayer`] per
//! layer and the [`Wire`]s (rubberbands) of the circuit; output ([`RouteResult`]) is, per wire,
//! the conductive trace as 3D polylines per layer, and, per layer, the channels the caller carves
//! from the plastic regions before the conductive material is printed into them.
//!
//! The method is topology-aware routing for FDM-printed electronics:
//!
//! 1. **Routing graph per layer** (`graph.rs`): the layer islands shrunk by
//!    `i·perimeter_width + (conductive_width + channel_extra)/2` for `i = 1..=perimeters` give the
//!    *deflated perimeter traces*, closed chains of vertices weighted by `perimeter_weights[i-1]`
//!    per mm (decreasing inward, so routes hug the inner traces and stay clear of the outer
//!    walls); the wire's own rubberband projected into the layer (the *direct connection*) is
//!    split where it meets those rings and weighted `base_weight` inside the material and
//!    `outside_weight` across holes and notches; the innermost deflated area (the *infill
//!    region*) is explored lazily on a grid of 45° steps during the search. Gaps narrower than
//!    two perimeter traces (between the pad rows of a fine-pitch part, beside earlier channels)
//!    hold no deflated trace; the *squeeze region*, where a channel still fits clear of other
//!    nets' keep-outs and one perimeter inside the walls, adds its own rings and grid there at
//!    `squeeze_weight` (above every perimeter weight, so it is used only where nothing else
//!    gets through).
//! 2. **Inter-layer connections** (`interlayer.rs`): a route may change layer where its last
//!    `interlayer_overlap + grid_step` millimetres can be printed on the neighbour layer too; that
//!    piece is printed on both layers (the staircase overlap), so the traces of consecutive layers
//!    touch over at least `interlayer_overlap` mm.
//! 3. **A\*** (`astar.rs`) per wire, steppable ([`Search::step`]), deterministic; the path found
//!    is pulled taut layer by layer (`smooth.rs`) before it becomes the trace (`trace.rs`). A
//!    wire's target is its far pad or any trace of its net already connected to that pad: the
//!    route may end on that copper as a T joint ([`WireRoute::ends_on_wire`]), so a net is
//!    built as a tree on its copper, not only pad to pad.
//! 4. **Collisions and order** (`order.rs`, `channels.rs`, `board.rs`): wires are routed one
//!    after another, fewest rubberband collisions first, then shortest; each routed wire's
//!    channel becomes a hole in the islands of the following wires of other nets (new perimeter
//!    traces form around it) and a keep-out for their direct connections, on its own layer and
//!    on the layers just above and below: a trace fills its channel to the layer's top, so traces
//!    of adjacent layers would touch, and one route passes over another only with a layer of
//!    plastic between them. Other nets' pads are holes and keep-outs on their layer and the two
//!    next to it (where the start of their own trace would be touched). Wires that fail get
//!    rounds of rip-up and reroute: the wires in their way are routed again after them, and an
//!    attempt is kept only if it leaves more wires routed.
//!
//! Routing is bounded in time: [`RouteParams::time_limit`] (or the job-wide
//! [`RouteWatch::deadline`]) stops the router from starting new searches, and cuts a running
//! search short, once it has passed; what is routed stays routed and the rest is reported
//! [`Unrouted::TimeLimit`]. The deadline only ever stops work, so a run that finishes in time
//! gives the same result with or without it. [`RouteWatch::progress`] hears how far routing got
//! after every wire and rip-up attempt.
//!
//! Units: millimetres in the public types, nanometre integers ([`Point2`]) inside.

mod astar;
mod board;
mod channels;
mod congestion;
mod graph;
mod index;
mod interlayer;
mod order;
mod smooth;
mod trace;

#[cfg(test)]
mod tests;

pub use astar::{Search, SearchState, route_wire};
pub use channels::trace_channel;
pub use order::{collision_counts, wire_order};

use crate::geom::{ExPolygon, Point2, Point3, Polygon};
use std::fmt;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// One planar layer as the router sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteLayer {
    /// Top of the layer, mm: traces are printed at this z.
    pub z: f64,
    /// Layer height, mm: the layer spans `z - height .. z`.
    pub height: f64,
    /// Material of this layer where a channel may be carved (cavities already removed).
    pub islands: Vec<ExPolygon>,
}

/// One connection to route: a rubberband between two pads of one net.
#[derive(Debug, Clone, PartialEq)]
pub struct Wire {
    /// Net name. Wires of one net may touch each other; wires of different nets never do.
    pub net: String,
    /// Start pad, mm.
    pub from: Point3,
    /// End pad, mm.
    pub to: Point3,
}

impl Wire {
    /// The same connection from its end pad to its start pad.
    pub fn reversed(&self) -> Wire {
        Wire {
            net: self.net.clone(),
            from: self.to,
            to: self.from,
        }
    }
}

/// The copper of one pad: an obstacle to the traces of every net but its own.
#[derive(Debug, Clone, PartialEq)]
pub struct PadCopper {
    /// Net of the pad; `None` for a pin no net uses, which every trace keeps clear of.
    pub net: Option<String>,
    /// Seating plane, mm: the pad lies on the layer whose top this is (see [`layer_of`]).
    pub z: f64,
    /// Copper outline in xy, counter-clockwise.
    pub outline: Polygon,
}

impl PadCopper {
    /// A round pad of `diameter` mm centred on `at` (16-gon circumscribing the circle).
    pub fn round(net: Option<&str>, at: Point3, diameter: f64) -> Self {
        let outline = channels::disc(Point2::from_mm(at.x, at.y), diameter / 2.0)
            .pop()
            .map(|e| e.contour)
            .unwrap_or_else(|| Polygon::new(vec![Point2::from_mm(at.x, at.y)]));
        Self {
            net: net.map(str::to_owned),
            z: at.z,
            outline,
        }
    }
}

/// Parameters of the router. Lengths in mm; weights are cost multipliers per mm of trace.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteParams {
    /// Number of deflated perimeter traces per layer (default 3).
    pub perimeters: usize,
    /// Perimeter extrusion width, mm (default 0.45).
    pub perimeter_width: f64,
    /// Width of the conductive trace, mm (default 0.6).
    pub conductive_width: f64,
    /// Δ: clearance added to the conductive width to make the channel, mm (default 0.2). The
    /// channel is the trace grown by `(conductive_width + channel_extra) / 2`.
    pub channel_extra: f64,
    /// Cost multiplier per mm along deflated perimeter trace `i = 1..=perimeters` (outermost
    /// first), decreasing inward so inner traces are preferred and the outer walls stay intact
    /// (default `[3.0, 2.0, 1.0]`). Traces past the end of the list use its last value (1.0 if
    /// empty).
    pub perimeter_weights: Vec<f64>,
    /// Cost multiplier per mm of direct connections inside the material and of infill grid edges
    /// and staircase overlaps (default 1.0).
    pub base_weight: f64,
    /// Cost multiplier per mm of direct connections outside the material: across holes and notches
    /// of one island (default 100, so a route crosses a hole only when going around costs more
    /// than 100 times the crossing). Gaps between separate islands are never bridged.
    pub outside_weight: f64,
    /// Cost multiplier per mm of grid edges outside the infill region, through gaps the
    /// deflated perimeter traces do not reach (between pad rows, beside earlier channels),
    /// where a channel still fits one perimeter inside the walls (default 4.0: above every
    /// perimeter weight, so such gaps are used only where the graph has no other way;
    /// infinity turns them off).
    pub squeeze_weight: f64,
    /// Step of the lazily explored infill grid, mm (default 1.0).
    pub grid_step: f64,
    /// Minimum xy overlap of the traces of two consecutive layers at a layer change, mm
    /// (default 2.0).
    pub interlayer_overlap: f64,
    /// Fixed cost of one layer change, in mm-equivalents (default 5.0).
    pub layer_change_penalty: f64,
    /// Layers below the lower pad's layer and above the upper pad's a route may use (default
    /// 2). Traces of different nets on adjacent layers touch, so one route passes another
    /// at least two layers away.
    pub layer_span: usize,
    /// Rounds of rip-up and reroute for wires that fail (default 3; 0 routes each wire once,
    /// in order).
    pub rip_up_rounds: usize,
    /// How the wires share the material (default [`Strategy::Ordered`]).
    pub strategy: Strategy,
    /// Most rounds of negotiated congestion ([`Strategy::Negotiated`]; default 12).
    pub negotiation_rounds: usize,
    /// Longest route worth printing, as a multiple of the straight 3D distance between the
    /// pads, plus `detour_slack` (default 3): a conductive trace's resistance grows with its
    /// length, so a wire that needs a longer route is reported unrouted, and the search stops
    /// there instead of exploring the whole object.
    pub max_detour: f64,
    /// Cost added to the detour limit, in mm-equivalents (default 30: room for layer changes and
    /// a way round a part even on the shortest wires).
    pub detour_slack: f64,
    /// Safety cap on A* expansions per wire; a wire that needs more is reported unrouted
    /// (default 2 000 000).
    pub max_expansions: usize,
    /// Vertices of neighbouring layers closer than this (mm) are snapped to one xy, and points
    /// this close to a region's boundary count as on it (default 0.05 mm: a tenth of a trace
    /// width, far above the nanometre rounding of intersection points).
    pub align_tolerance: f64,
    /// Longest time routing may take, seconds (default 180; 0 = no limit). Measured from the
    /// start of [`route`] unless [`RouteWatch::deadline`] sets a deadline shared by several
    /// calls (all objects of a job); also the figure named in [`Unrouted::TimeLimit`].
    pub time_limit: f64,
    /// The job's deadline and the progress callback, set by the caller (none by default).
    pub watch: RouteWatch,
}

/// How far routing has got: told to [`RouteWatch::progress`] after every wire searched in the
/// first pass and every rip-up and reroute attempt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RouteProgress {
    /// Wires searched in the first pass so far (all of them once the rip-up rounds run).
    pub done: usize,
    /// Wires to route.
    pub total: usize,
    /// Rip-up and reroute round running (0 before the rip-up rounds).
    pub round: usize,
    /// Negotiated-congestion round running (0 outside negotiation).
    pub negotiation: usize,
    /// Wires whose routes touch another net's trace after the last negotiation round.
    pub conflicts: usize,
    /// Wires without a route so far.
    pub unrouted: usize,
}

/// A callback told how far routing has got; shared, so one callback serves every object of a
/// job.
pub type ProgressFn = Arc<dyn Fn(RouteProgress) + Send + Sync>;

/// What the caller of [`route`] watches it with: a deadline and a progress callback.
#[derive(Clone, Default)]
pub struct RouteWatch {
    /// When routing must stop; `None` takes [`RouteParams::time_limit`] from the start of the
    /// call.
    pub deadline: Option<Instant>,
    /// Told how far routing has got.
    pub progress: Option<ProgressFn>,
}

impl RouteWatch {
    /// A deadline `seconds` from now (none for 0, a negative or a non-finite value).
    pub fn deadline_in(seconds: f64) -> Option<Instant> {
        if seconds > 0.0 && seconds.is_finite() {
            Duration::try_from_secs_f64(seconds)
                .ok()
                .and_then(|d| Instant::now().checked_add(d))
        } else {
            None
        }
    }
}

impl fmt::Debug for RouteWatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RouteWatch")
            .field("deadline", &self.deadline)
            .field("progress", &self.progress.as_ref().map(|_| "callback"))
            .finish()
    }
}

impl PartialEq for RouteWatch {
    /// Same deadline and the same callback (or none).
    fn eq(&self, other: &Self) -> bool {
        self.deadline == other.deadline
            && match (&self.progress, &other.progress) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                (None, None) => true,
                _ => false,
            }
    }
}

/// How the router shares the material out between the wires.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Strategy {
    /// Wire after wire, each avoiding the traces routed before it, then rounds of rip-up and
    /// reroute for the wires that failed.
    #[default]
    Ordered,
    /// Negotiated congestion: every wire routed with the others' traces as a cost rather than an
    /// obstacle, rising round by round where traces still touch, until none do; the wires
    /// still in conflict are then routed in order (see `board/negotiate.rs`).
    Negotiated,
}

/// Why a wire has no route.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Unrouted {
    /// A pad lies on no layer (there are none).
    NoLayer,
    /// The material (less other nets' traces and pads) holds no way between the pads.
    NoPath,
    /// Every way left is longer than [`RouteParams::max_detour`] allows.
    Detour,
    /// The search used up [`RouteParams::max_expansions`].
    SearchLimit,
    /// The deadline passed before the wire was routed (the figure is
    /// [`RouteParams::time_limit`], seconds).
    TimeLimit(f64),
}

impl fmt::Display for Unrouted {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Unrouted::NoLayer => write!(f, "no layer holds the pads"),
            Unrouted::NoPath => write!(f, "no path through the material"),
            Unrouted::Detour => write!(f, "no path within the detour limit (route.max_detour)"),
            Unrouted::SearchLimit => write!(f, "search limit reached"),
            Unrouted::TimeLimit(s) => write!(f, "time limit reached (route.time_limit = {s} s)"),
        }
    }
}

impl Default for RouteParams {
    fn default() -> Self {
        Self {
            perimeters: 3,
            perimeter_width: 0.45,
            conductive_width: 0.6,
            channel_extra: 0.2,
            perimeter_weights: vec![3.0, 2.0, 1.0],
            base_weight: 1.0,
            outside_weight: 100.0,
            squeeze_weight: 4.0,
            grid_step: 1.0,
            interlayer_overlap: 2.0,
            layer_change_penalty: 5.0,
            layer_span: 2,
            rip_up_rounds: 3,
            strategy: Strategy::Ordered,
            negotiation_rounds: 12,
            max_detour: 3.0,
            detour_slack: 30.0,
            max_expansions: 2_000_000,
            align_tolerance: 0.05,
            time_limit: 180.0,
            watch: RouteWatch::default(),
        }
    }
}

impl RouteParams {
    /// Half the channel width, mm: `(conductive_width + channel_extra) / 2`.
    pub fn channel_half_width(&self) -> f64 {
        (self.conductive_width + self.channel_extra) / 2.0
    }

    /// Weight per mm of deflated perimeter trace `i` (1-based).
    pub fn perimeter_weight(&self, i: usize) -> f64 {
        self.perimeter_weights
            .get(i.saturating_sub(1))
            .or(self.perimeter_weights.last())
            .copied()
            .unwrap_or(1.0)
    }
}

/// The route of one wire.
#[derive(Debug, Clone, PartialEq)]
pub struct WireRoute {
    /// Net of the wire.
    pub net: String,
    /// Whether a route was found. Unrouted wires have no segments and zero length.
    pub routed: bool,
    /// The trace, one polyline per visit of a layer: (layer index, points at the layer's z).
    /// At a layer change the last `≥ interlayer_overlap` mm of one segment are repeated at the
    /// start of the next (the staircase overlap).
    pub segments: Vec<(usize, Vec<Point3>)>,
    /// Length of the conductor's centreline from pad to pad, mm, in 3D: layer changes add their
    /// z step, staircase overlaps are counted once.
    pub length: f64,
    /// Straight 3D distance between the route's ends, mm: no route is shorter. That is the
    /// pads, or, for a route that ends on a trace of its net ([`WireRoute::ends_on_wire`]), the
    /// start pad and the point of that trace.
    pub lower_bound: f64,
    /// Number of layer changes.
    pub layer_changes: usize,
    /// Crossings of the route with the layers' original island boundaries (outer perimeters and
    /// hole walls): each outside section of a route adds two.
    pub perimeter_crossings: usize,
    /// The wire (index in the input) whose trace this route ends on, as a T joint, instead of
    /// running to its `to` pad: that trace is already connected to the pad. `None` when the
    /// route ends at the pad.
    pub ends_on_wire: Option<usize>,
    /// Why the wire has no route; `None` when it is routed.
    pub reason: Option<Unrouted>,
    /// What stands in the way of an unrouted wire (`None` when it is routed, or when the
    /// deadline left no time to look).
    pub blockage: Option<Blockage>,
}

/// A pad of another net too close to one of a wire's pads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NearPad {
    /// Index of the pad in the pads given to [`route`].
    pub pad: usize,
    /// Distance from the wire's pad, centre to centre, mm.
    pub distance: f64,
    /// Whether it is near the wire's `to` pad (else its `from` pad).
    pub near_to: bool,
}

/// What stands in the way of a wire the router could not route: found by searching once more
/// with other nets' traces as a cost instead of an obstacle (the rip-up probe) and by looking at
/// the pads round the wire's ends.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Blockage {
    /// Routed wires of other nets (indices in the input) whose traces the wire's best way runs
    /// into, by increasing index. Empty when that way is free of traces or there is none.
    pub traces: Vec<usize>,
    /// Pads of other nets closer to one of the wire's pads, centre to centre, than two traces
    /// can run ([`min_trace_spacing`]); closest first.
    pub pads: Vec<NearPad>,
    /// Whether a way exists at all once other nets' traces are out of the way (within the
    /// detour limit): if not, only the pads and the material are in the way.
    pub way_without_traces: bool,
}

/// Routes of all wires and the channels to carve.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteResult {
    /// One route per wire, in input order.
    pub wires: Vec<WireRoute>,
    /// Per layer (same indices as the input layers), the union of the channels of all routed
    /// wires: regions to carve from the plastic before the conductive material fills them.
    pub channels: Vec<Vec<ExPolygon>>,
    /// Rip-up and reroute rounds run.
    pub rounds: usize,
    /// Negotiated-congestion rounds run (0 with [`Strategy::Ordered`]).
    pub negotiation_rounds: usize,
    /// Wires whose negotiated routes still touched other nets' traces when negotiation stopped,
    /// and were routed again in order.
    pub negotiation_conflicts: usize,
    /// Whether the deadline stopped routing before it was done.
    pub time_limit_reached: bool,
    /// Where routing stood after each pass and round, in order.
    pub log: Vec<RoundLog>,
}

/// A stage of routing, for [`RoundLog`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Phase {
    /// Every wire routed once, in order ([`Strategy::Ordered`]).
    FirstPass,
    /// A negotiated-congestion round.
    Negotiation,
    /// The conflicts left by negotiation settled and their wires routed in order.
    Settle,
    /// A rip-up and reroute round.
    RipUp,
}

/// Where routing stood after one pass or round.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct RoundLog {
    /// The stage.
    pub phase: Phase,
    /// Its round (1 for a first pass or the settling).
    pub round: usize,
    /// Wires routed after it.
    pub routed: usize,
    /// Wires without a route after it.
    pub unrouted: usize,
    /// Wires whose routes overlap another net's (only negotiation leaves any).
    pub conflicts: usize,
}

/// Heights closer than this (mm) count as equal when a pad is matched to a layer: float noise in
/// layer tops computed as sums of heights, far below any layer height.
const Z_TOLERANCE_MM: f64 = 1e-6;

/// Index of the layer for a pad at height `z`: the layer whose range `z - height ..= z` holds it,
/// else the nearest one; a pad on the boundary of two layers (within 1e-6 mm) belongs to the
/// lower one, whose top it sits on. `None` when there are no layers.
pub fn layer_of(layers: &[RouteLayer], z: f64) -> Option<usize> {
    layers
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let outside = if z > l.z {
                z - l.z
            } else {
                (l.z - l.height - z).max(0.0)
            };
            ((outside - Z_TOLERANCE_MM).max(0.0), (z - l.z).abs(), i)
        })
        .min_by(|a, b| {
            a.0.total_cmp(&b.0)
                .then(a.1.total_cmp(&b.1))
                .then(a.2.cmp(&b.2))
        })
        .map(|(_, _, i)| i)
}

/// Smallest distance (mm) between the centrelines of two traces of different nets on one
/// layer: two channel widths' worth, `conductive_width + channel_extra`, plus what the polygonal
/// channels add.
pub fn min_trace_spacing(params: &RouteParams) -> f64 {
    channels::keep_out_radius(params)
}

/// Routes every wire through the layers, in the order of [`wire_order`], each wire avoiding the
/// channels of the wires of other nets routed before it (on its layer and the adjacent ones)
/// and the copper of other nets' pads and of unconnected pads (on the pad's layer and the two
/// next to it). Wires that cannot be routed are reported with `routed = false`; routing goes on
/// with the others, and failed wires get `rip_up_rounds` rounds of rip-up and reroute (see
/// `board.rs`). Once the deadline ([`RouteWatch::deadline`], else [`RouteParams::time_limit`]
/// from now) has passed no search starts and a running one gives up: the wires left are
/// reported [`Unrouted::TimeLimit`].
pub fn route(
    layers: &[RouteLayer],
    wires: &[Wire],
    pads: &[PadCopper],
    params: &RouteParams,
) -> RouteResult {
    let deadline = params
        .watch
        .deadline
        .or_else(|| RouteWatch::deadline_in(params.time_limit));
    let mut board = board::Board::new(layers, wires, pads, params, deadline);
    let summary = board.route_all();
    let time_limit_reached = board.stopped_by_deadline();
    board.diagnose();
    let (wires, channels) = board.finish();
    RouteResult {
        wires,
        channels,
        rounds: summary.rounds,
        negotiation_rounds: summary.negotiation_rounds,
        negotiation_conflicts: summary.negotiation_conflicts,
        time_limit_reached,
        log: summary.log,
    }
}
