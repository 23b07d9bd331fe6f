//! A* search for one wire, steppable: a test or a viewer can run it one expansion at a time.
//!
//! Place in the pipeline: the core of routing, between the per-wire graph (`graph.rs`) and the
//! assembled trace (`trace.rs`). [`route`](super::route) runs one [`Search`] per wire;
//! [`route_wire`] runs one on layers as given.
//!
//! - **Targets**: the target pad, and the traces of the target's net already connected to it
//!   ([`Tap`]s, given by the board): a route may end on its net's copper anywhere, as a T joint,
//!   instead of running beside that copper to the pad. A vertex within one grid step of a tap,
//!   joined to it by a straight link inside the material, reaches the target through that link.
//! - **Heuristic**: the 3D straight distance to the nearest target (pad or tap segment) times
//!   the smallest weight, plus, per layer between the vertex and that target, the least a layer
//!   change can cost (`layer_change_penalty + interlayer_overlap × base_weight`). Every edge
//!   costs at least the heuristic's drop along it (layer changes are floored to make sure), so
//!   the heuristic is consistent (a minimum of consistent ones) and the first path to reach a
//!   target is the cheapest in the graph explored. It is computed once per vertex.
//! - **Lazy growth**: expanding a vertex inside the infill region adds grid vertices one
//!   `grid_step` away in the eight 45° directions (reusing a vertex within a third of a step) and
//!   edges to every vertex within one step, at `base_weight`; in the squeeze region (see
//!   `graph.rs`) the same grid grows at `squeeze_weight`; it also tries the layer changes of
//!   `interlayer.rs` and the taps.
//! - **Determinism**: the open list is a binary heap ordered by (f, larger g, vertex id) with
//!   total float order; vertex ids follow creation order, which depends only on the input; hash
//!   maps are only looked up, never iterated.

use super::graph::{self, Ends, Graph, IntSet, LayerInput, PreparedLayer, VertexId, Zone};
use super::index::{dist, lerp};
use super::interlayer::{FitMemo, Parent, piece_fits, walk_back};
use super::{RouteLayer, RouteParams, Unrouted, Wire, WireRoute, layer_of, trace};
use crate::geom::{Point2, polyline_length, scaled, segment_distance, segment_param, unscaled};
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::ops::RangeInclusive;

/// Where a [`Search`] stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchState {
    /// Vertices remain to expand.
    Running,
    /// The target pad was reached; [`Search::result`] holds the route.
    Found,
    /// The target cannot be reached (or `max_expansions` was used up).
    Failed,
}

/// An entry of the open list.
#[derive(Debug, Clone, Copy)]
struct Open {
    f: f64,
    g: f64,
    v: VertexId,
}

impl PartialEq for Open {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Open {}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Open {
    /// The heap pops the greatest: smallest f, then largest g (deepest), then smallest id.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .f
            .total_cmp(&self.f)
            .then(self.g.total_cmp(&other.g))
            .then(other.v.cmp(&self.v))
    }
}

/// The eight 45° grid directions, in lattice steps.
const GRID_DIRECTIONS: [(i64, i64); 8] = [
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
    (0, -1),
    (1, -1),
];

/// Fraction of a grid step within which a new grid point reuses an existing vertex.
const GRID_REUSE: f64 = 1.0 / 3.0;

/// The layers a wire may use: from the lower endpoint layer − `layer_span` to the upper one +
/// `layer_span`.
pub(crate) fn layer_range(
    layers: &[RouteLayer],
    wire: &Wire,
    params: &RouteParams,
) -> Option<RangeInclusive<usize>> {
    let (a, b) = (layer_of(layers, wire.from.z)?, layer_of(layers, wire.to.z)?);
    let span = params.layer_span;
    Some(a.min(b).saturating_sub(span)..=(a.max(b) + span).min(layers.len() - 1))
}

/// Smallest cost per mm of any edge.
pub(crate) fn min_weight(params: &RouteParams) -> f64 {
    params
        .perimeter_weights
        .iter()
        .chain([
            &params.base_weight,
            &params.outside_weight,
            &params.squeeze_weight,
        ])
        .copied()
        .fold(f64::INFINITY, f64::min)
        .max(0.0)
}

/// Least cost of one layer change: its penalty and the overlap printed twice.
pub(crate) fn change_cost(params: &RouteParams) -> f64 {
    (params.layer_change_penalty + params.interlayer_overlap * params.base_weight).max(0.0)
}

/// The cost above which the search of a wire gives up, for pads `distance` mm apart (3D) and
/// `layer_changes` layers apart: `max_detour` times the least cost the heuristic promises, in
/// base-weight mm, plus `detour_slack`. A search with penalty regions (a rip-up probe, a
/// negotiation round) may also run through 5 mm of them at their `penalty_factor`, and one with
/// a congestion history capped at `history_cap` may find every link up to `1 + history_cap`
/// times dearer. A route within the plain limit is at most `limit / min_weight` mm long.
pub(crate) fn cost_limit(
    params: &RouteParams,
    distance: f64,
    layer_changes: usize,
    penalty_factor: Option<f64>,
    history_cap: f64,
) -> f64 {
    let least = min_weight(params);
    let straight = distance.max(0.0)
        + change_cost(params) * layer_changes as f64 / least.max(f64::MIN_POSITIVE);
    let mut limit = params.max_detour.max(1.0) * straight * params.base_weight.max(least)
        + params.detour_slack.max(0.0);
    limit *= 1.0 + history_cap.max(0.0);
    if let Some(factor) = penalty_factor {
        limit += factor.max(1.0) * 5.0;
    }
    limit
}

/// A piece of an already routed trace of the wire's net, connected to its target pad: the
/// route may end anywhere on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Tap {
    /// Layer of the trace piece.
    pub layer: usize,
    /// Start of the piece (a segment of the trace's centreline).
    pub a: Point2,
    /// End of the piece.
    pub b: Point2,
    /// Index of the routed wire the piece belongs to.
    pub wire: usize,
}

/// The A* search of one wire's route, one expansion per [`Search::step`].
#[derive(Debug, Clone)]
pub struct Search {
    params: RouteParams,
    wire: Wire,
    layers: Vec<PreparedLayer>,
    graph: Graph,
    target: VertexId,
    /// Trace pieces the route may end on besides the target pad.
    taps: Vec<Tap>,
    /// How the target was last reached through a tap: the point on the trace and the tap's
    /// wire (`None` when it was reached at the pad).
    arrival: Option<(Point2, usize)>,
    /// Heuristic per vertex, computed once (NaN until then).
    h: Vec<f64>,
    overlaps: Vec<Vec<Point2>>,
    g: Vec<f64>,
    parents: Vec<Parent>,
    closed: Vec<bool>,
    open: BinaryHeap<Open>,
    state: SearchState,
    /// Why the search failed (meaningful once it has).
    failure: Unrouted,
    expansions: usize,
    /// Smallest cost per mm of any edge.
    min_weight: f64,
    /// Least cost of one layer change.
    change_cost: f64,
    /// Routes costing more than this are not searched for (see [`RouteParams::max_detour`]).
    cost_limit: f64,
    /// Grid pairs (from, to) [`Search::grid_weight`] refused an edge.
    refused: IntSet<(VertexId, VertexId)>,
    /// Region tests of staircase pieces on neighbour layers.
    fit_memo: FitMemo,
}

impl Search {
    /// A search for `wire` on `layers` as given: their islands are the material, nothing is
    /// blocked. Only the layers from the lower pad's layer − `layer_span` to the upper pad's +
    /// `layer_span` are used.
    pub fn new(layers: &[RouteLayer], wire: &Wire, params: &RouteParams) -> Self {
        let inputs = layer_range(layers, wire, params).map_or(Vec::new(), |range| {
            range
                .map(|l| LayerInput::plain(l, layers[l].z, &layers[l].islands, params))
                .collect()
        });
        Self::with_layers(inputs, layers, wire, params, Vec::new())
    }

    /// A search over prepared inputs (consecutive layers, ascending); `all` gives the pads'
    /// layers; `taps` are trace pieces the route may end on besides the target pad (those on
    /// layers outside the inputs are dropped).
    pub(crate) fn with_layers(
        inputs: Vec<LayerInput>,
        all: &[RouteLayer],
        wire: &Wire,
        params: &RouteParams,
        taps: Vec<Tap>,
    ) -> Self {
        let known = vec![None; inputs.len()];
        let layers = graph::prepare(&inputs, known, params);
        Self::with_prepared(layers, all, wire, params, taps)
    }

    /// A search over prepared layers (consecutive, ascending); see [`Search::with_layers`].
    pub(crate) fn with_prepared(
        layers: Vec<PreparedLayer>,
        all: &[RouteLayer],
        wire: &Wire,
        params: &RouteParams,
        taps: Vec<Tap>,
    ) -> Self {
        let min_weight = min_weight(params);
        let change_cost = change_cost(params);
        let ends = match (layer_of(all, wire.from.z), layer_of(all, wire.to.z)) {
            (Some(from_layer), Some(to_layer)) if !layers.is_empty() => Some(Ends {
                from: Point2::from_mm(wire.from.x, wire.from.y),
                from_layer,
                to: Point2::from_mm(wire.to.x, wire.to.y),
                to_layer,
            }),
            _ => None,
        };
        let (graph, source, target, state) = match ends {
            Some(ends) => {
                let (graph, s, t) = graph::build(&layers, &ends, params);
                (graph, s, t, SearchState::Running)
            }
            None => (Graph::new(1, 1), 0, 0, SearchState::Failed),
        };
        let mut search = Self {
            params: params.clone(),
            wire: wire.clone(),
            layers,
            graph,
            target,
            taps: Vec::new(),
            arrival: None,
            h: Vec::new(),
            overlaps: Vec::new(),
            g: Vec::new(),
            parents: Vec::new(),
            closed: Vec::new(),
            open: BinaryHeap::new(),
            state,
            failure: Unrouted::NoLayer,
            expansions: 0,
            min_weight,
            change_cost,
            cost_limit: f64::INFINITY,
            refused: IntSet::default(),
            fit_memo: FitMemo::default(),
        };
        if search.state == SearchState::Running {
            search.taps = taps
                .into_iter()
                .filter(|t| search.in_range(t.layer))
                .collect();
            let (a, b) = (search.graph.pos(source), search.graph.pos(target));
            let (la, lb) = (search.graph.layer(source), search.graph.layer(target));
            let dz = search.layer(la).z - search.layer(lb).z;
            let dxy = unscaled(1) * dist(a, b);
            let penalty_factor = search
                .layers
                .iter()
                .find(|l| !l.penalty.is_empty())
                .map(|l| l.penalty_factor);
            let history_cap = search.layers[0].history.as_ref().map_or(0.0, |h| h.cap());
            search.cost_limit = cost_limit(
                params,
                (dxy * dxy + dz * dz).sqrt(),
                la.abs_diff(lb),
                penalty_factor,
                history_cap,
            );
            search.grow();
            search.g[source as usize] = 0.0;
            let f = search.heuristic(source);
            search.open.push(Open {
                f,
                g: 0.0,
                v: source,
            });
        }
        search
    }

    /// Gives up on routes costing more than `cap` too (a search confined to a window whose
    /// routes are only answers below what leaving it would cost).
    pub(crate) fn cap_cost(&mut self, cap: f64) {
        self.cost_limit = self.cost_limit.min(cap);
    }

    /// Gives up after `n` expansions too (failing with [`Unrouted::SearchLimit`]).
    pub(crate) fn cap_expansions(&mut self, n: usize) {
        self.params.max_expansions = self.params.max_expansions.min(n);
    }

    /// Where the search stands.
    pub fn state(&self) -> SearchState {
        self.state
    }

    /// Vertices expanded so far.
    pub fn expansions(&self) -> usize {
        self.expansions
    }

    /// Vertices in the graph so far (it grows as the search explores).
    pub fn vertex_count(&self) -> usize {
        self.graph.verts.len()
    }

    /// Takes the best open vertex and expands it: one step of A*.
    pub fn step(&mut self) -> SearchState {
        if self.state != SearchState::Running {
            return self.state;
        }
        let Some(top) = self.open.pop() else {
            self.state = SearchState::Failed;
            self.failure = Unrouted::NoPath;
            return self.state;
        };
        let u = top.v;
        if self.closed[u as usize] || top.g > self.g[u as usize] {
            return self.state;
        }
        if top.f > self.cost_limit {
            // Every route left costs more than the detour limit allows.
            self.state = SearchState::Failed;
            self.failure = Unrouted::Detour;
            return self.state;
        }
        self.closed[u as usize] = true;
        if u == self.target {
            self.state = SearchState::Found;
            return self.state;
        }
        self.expansions += 1;
        if self.expansions > self.params.max_expansions {
            self.state = SearchState::Failed;
            self.failure = Unrouted::SearchLimit;
            return self.state;
        }
        self.explore_grid(u);
        self.explore_layers(u);
        self.explore_taps(u);
        let (lu, pu) = (self.graph.layer(u), self.graph.pos(u));
        for k in 0..self.graph.adj[u as usize].len() {
            let e = self.graph.adj[u as usize][k];
            let cost = if self.graph.layer(e.to) == lu {
                self.link_cost(lu, pu, self.graph.pos(e.to), e.cost)
            } else {
                e.cost
            };
            self.relax(u, e.to, cost, None);
        }
        self.state
    }

    /// The route: assembled if the target was found, else an unrouted report.
    pub fn result(&self) -> WireRoute {
        if self.state != SearchState::Found {
            return trace::unrouted(&self.wire, self.failure);
        }
        let mut path = Vec::new();
        // A route that ends on a trace stops at the point of the trace, on the layer of the
        // vertex that reached it; the target pad is not part of it.
        let (mut v, end) = match (self.arrival, self.parents[self.target as usize]) {
            (Some((q, wire)), Some((p, _))) => (p, Some((q, wire))),
            _ => (self.target, None),
        };
        loop {
            let parent = self.parents[v as usize];
            path.push((v, parent.and_then(|p| p.1)));
            match parent {
                Some((p, _)) => v = p,
                None => break,
            }
        }
        path.reverse();
        let tol = scaled(self.params.align_tolerance).max(1);
        trace::assemble(
            &self.wire,
            &self.layers,
            &self.graph,
            &path,
            &self.overlaps,
            tol,
            end,
        )
    }

    /// The cost of the planar link `a`–`b` on layer `l`, `cost` before the penalty regions
    /// and the congestion history are priced in (at the link's midpoint).
    fn link_cost(&self, l: usize, a: Point2, b: Point2, cost: f64) -> f64 {
        let layer = self.layer(l);
        if layer.penalty.is_empty() && layer.history.is_none() {
            return cost;
        }
        let mid = lerp(a, b, 0.5);
        let mut cost = cost;
        if !layer.penalty.is_empty() {
            if layer.history.is_some() {
                // Negotiation: priced by the share of the link inside, so a long link (a pad's
                // link to the rings, a direct connection) cannot cross a trace unpriced.
                let inside = layer.penalty.inside_fraction(a, b);
                cost *= 1.0 + (layer.penalty_factor - 1.0) * inside;
            } else if layer.penalty.contains(mid) {
                cost *= layer.penalty_factor;
            }
        }
        if let Some(history) = &layer.history {
            cost *= 1.0 + history.at(l, mid);
        }
        cost
    }

    /// Sizes the per-vertex arrays to the graph.
    fn grow(&mut self) {
        let n = self.graph.verts.len();
        self.g.resize(n, f64::INFINITY);
        self.parents.resize(n, None);
        self.closed.resize(n, false);
        self.h.resize(n, f64::NAN);
    }

    fn layer(&self, l: usize) -> &PreparedLayer {
        &self.layers[l - self.layers[0].index]
    }

    fn in_range(&self, l: usize) -> bool {
        let lo = self.layers[0].index;
        l >= lo && l < lo + self.layers.len()
    }

    /// The least cost from a point on layer `la` to one `dxy` scaled units away (in xy) on
    /// layer `lb`.
    fn bound(&self, la: usize, lb: usize, dxy: f64) -> f64 {
        let dz = self.layer(la).z - self.layer(lb).z;
        let dxy = unscaled(1) * dxy;
        self.min_weight * (dxy * dxy + dz * dz).sqrt() + self.change_cost * la.abs_diff(lb) as f64
    }

    fn heuristic(&mut self, v: VertexId) -> f64 {
        let known = self.h[v as usize];
        if !known.is_nan() {
            return known;
        }
        let (p, l) = (self.graph.pos(v), self.graph.layer(v));
        let to_pad = self.bound(
            l,
            self.graph.layer(self.target),
            dist(p, self.graph.pos(self.target)),
        );
        let h = self.taps.iter().fold(to_pad, |h, t| {
            h.min(self.bound(l, t.layer, segment_distance(p, t.a, t.b)))
        });
        self.h[v as usize] = h;
        h
    }

    /// Offers the target to `u` through the nearest tap on its layer within one grid step, if
    /// the straight link to it stays inside the material and clear of keep-outs.
    fn explore_taps(&mut self, u: VertexId) {
        if self.taps.is_empty() || u == self.target {
            return;
        }
        let (l, p) = (self.graph.layer(u), self.graph.pos(u));
        let reach = scaled(self.params.grid_step).max(1) as f64;
        let Some((d, q, wire)) = self
            .taps
            .iter()
            .filter(|t| t.layer == l)
            .map(|t| {
                let q = lerp(t.a, t.b, segment_param(p, t.a, t.b));
                (dist(p, q), q, t.wire)
            })
            .filter(|(d, _, _)| *d <= reach)
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)))
        else {
            return;
        };
        let tol = scaled(self.params.align_tolerance).max(1);
        let base = self.params.base_weight;
        if self.layer(l).link_weight(p, q, &self.params, tol) != Some(base) {
            return;
        }
        let g = self.g[u as usize] + self.link_cost(l, p, q, unscaled(1) * d * base);
        let t = self.target as usize;
        if !self.closed[t] && g < self.g[t] {
            self.g[t] = g;
            self.parents[t] = Some((u, None));
            self.arrival = Some((q, wire));
            self.open.push(Open {
                f: g,
                g,
                v: self.target,
            });
        }
    }

    fn relax(&mut self, u: VertexId, v: VertexId, cost: f64, piece: Option<u32>) -> bool {
        self.grow();
        if self.closed[v as usize] {
            return false;
        }
        let g = self.g[u as usize] + cost;
        if g < self.g[v as usize] {
            self.g[v as usize] = g;
            self.parents[v as usize] = Some((u, piece));
            if v == self.target {
                self.arrival = None;
            }
            let f = g + self.heuristic(v);
            self.open.push(Open { f, g, v });
            return true;
        }
        false
    }

    /// The grid zone of point `p` on `layer`.
    fn zone_at(&self, layer: &PreparedLayer, p: Point2, tol: i64) -> Zone {
        if layer.infill.inside_or_on(p, tol) {
            Zone::Infill
        } else if !layer.squeeze.is_empty()
            && layer.squeeze.inside_or_on(p, tol)
            && !layer.blocked.contains(p)
        {
            Zone::Squeeze
        } else {
            Zone::Out
        }
    }

    /// The grid zone of vertex `v` (worked out once per vertex).
    fn zone(&mut self, v: VertexId, tol: i64) -> Zone {
        if let Some(known) = self.graph.verts[v as usize].zone {
            return known;
        }
        let (l, p) = (self.graph.layer(v), self.graph.pos(v));
        let zone = self.zone_at(self.layer(l), p, tol);
        self.graph.verts[v as usize].zone = Some(zone);
        zone
    }

    /// Weight per mm of a planar grid edge `a`–`b` between points of zones `za` and `zb`:
    /// `base_weight` inside the infill region, `squeeze_weight` inside the squeeze region and
    /// clear of keep-outs, else no edge.
    fn grid_weight(
        &self,
        layer: &PreparedLayer,
        (a, za): (Point2, Zone),
        (b, zb): (Point2, Zone),
        tol: i64,
    ) -> Option<f64> {
        if za == Zone::Out || zb == Zone::Out {
            return None;
        }
        let mid = lerp(a, b, 0.5);
        if za == Zone::Infill
            && zb == Zone::Infill
            && !layer.infill.crosses(a, b)
            && layer.infill.inside_or_on(mid, tol)
        {
            return Some(self.params.base_weight);
        }
        (!layer.squeeze.crosses(a, b)
            && layer.squeeze.inside_or_on(mid, tol)
            && !layer.blocked_segment(a, b))
        .then_some(self.params.squeeze_weight)
    }

    /// Grows the grid around `u` (once per vertex), if `u` is in the infill or squeeze region.
    fn explore_grid(&mut self, u: VertexId) {
        let ui = u as usize;
        if self.graph.verts[ui].explored {
            return;
        }
        self.graph.verts[ui].explored = true;
        let l = self.graph.layer(u);
        let p = self.graph.pos(u);
        let tol = scaled(self.params.align_tolerance).max(1);
        let zu = self.zone(u, tol);
        if zu == Zone::Out {
            return;
        }
        let step = scaled(self.params.grid_step).max(1);
        let reuse = (step as f64 * GRID_REUSE) as i64;
        // Grid points lie on one lattice of `grid_step` for every layer: steps from a lattice
        // point are exact 45° steps, steps from a ring or pad vertex land on the nearest
        // lattice point, and the same points recur on neighbouring layers (exact inter-layer
        // matches) instead of each vertex seeding a lattice of its own.
        let snap = |v: i64| (v as f64 / step as f64).round() as i64 * step;
        for (dx, dy) in GRID_DIRECTIONS {
            let q = Point2::new(snap(p.x + dx * step), snap(p.y + dy * step));
            if q == p {
                continue;
            }
            if let Some(v) = self.graph.nearest(l, q, reuse) {
                self.grid_link(u, v, zu, tol);
                continue;
            }
            let layer = self.layer(l);
            let zq = self.zone_at(layer, q, tol);
            let Some(w) = self.grid_weight(layer, (p, zu), (q, zq), tol) else {
                continue;
            };
            let (v, created) = self.graph.add_vertex(l, q);
            self.graph.link(u, v, w);
            if created {
                self.grow();
                self.link_neighbours(v, |s, w| {
                    let (zw, zv) = (s.zone(w, tol), s.zone(v, tol));
                    let (pw, pv) = (s.graph.pos(w), s.graph.pos(v));
                    s.grid_weight(s.layer(l), (pw, zw), (pv, zv), tol)
                });
            }
        }
        for v in self.graph.within(l, p, step) {
            self.grid_link(u, v, zu, tol);
        }
    }

    /// Links `u` (of zone `zu`) to `v` on their layer if [`Search::grid_weight`] accepts the
    /// edge. A pair already linked, or already refused, is not weighed again: the weight is a
    /// function of the two points and their zones, which never change.
    fn grid_link(&mut self, u: VertexId, v: VertexId, zu: Zone, tol: i64) {
        if u == v || self.graph.linked(u, v) || self.refused.contains(&(u, v)) {
            return;
        }
        let zv = self.zone(v, tol);
        let (l, p, pv) = (self.graph.layer(u), self.graph.pos(u), self.graph.pos(v));
        match self.grid_weight(self.layer(l), (p, zu), (pv, zv), tol) {
            Some(w) => self.graph.link(u, v, w),
            None => {
                self.refused.insert((u, v));
            }
        }
    }

    /// Joins the new vertex `v` to the vertices of its layer within one grid step that `weight`
    /// accepts, and offers `v` the paths of those already expanded.
    fn link_neighbours(
        &mut self,
        v: VertexId,
        mut weight: impl FnMut(&mut Self, VertexId) -> Option<f64>,
    ) {
        let (l, p) = (self.graph.layer(v), self.graph.pos(v));
        let step = scaled(self.params.grid_step).max(1);
        for w in self.graph.within(l, p, step) {
            if w == v {
                continue;
            }
            if let Some(weight) = weight(self, w) {
                self.graph.link(w, v, weight);
                if self.closed[w as usize] {
                    let cost = unscaled(1) * dist(self.graph.pos(w), p) * weight;
                    self.relax(w, v, cost, None);
                }
            }
        }
    }

    /// Tries to step from `u` to the layers above and below (see `interlayer.rs`).
    fn explore_layers(&mut self, u: VertexId) {
        let l = self.graph.layer(u);
        let need = scaled(self.params.interlayer_overlap + self.params.grid_step) as f64;
        let Some(piece) = walk_back(&self.graph, &self.parents, &self.overlaps, u, need) else {
            return;
        };
        let tol = scaled(self.params.align_tolerance).max(1);
        let p = self.graph.pos(u);
        for other in [l.checked_sub(1), Some(l + 1)].into_iter().flatten() {
            if !self.in_range(other)
                || !piece_fits(
                    &piece,
                    &self.graph,
                    // The field, not `self.layer(other)`, so the memo can be borrowed beside it.
                    &self.layers[other - self.layers[0].index],
                    tol,
                    &mut self.fit_memo,
                )
            {
                continue;
            }
            let (v, created) = self.graph.add_vertex(other, p);
            self.grow();
            if self.closed[v as usize] {
                continue;
            }
            if created {
                let params = self.params.clone();
                self.link_neighbours(v, |s, w| {
                    let (a, b) = (s.graph.pos(w), s.graph.pos(v));
                    let layer = s.layer(other);
                    layer
                        .clearance
                        .inside_or_on(lerp(a, b, 0.5), tol)
                        .then(|| layer.link_weight(a, b, &params, tol))
                        .flatten()
                });
            }
            let dz = (self.layer(other).z - self.layer(l).z).abs();
            // The piece is printed on the other layer too, where it pays that layer's prices.
            let target = self.layer(other);
            let printed = if target.penalty.is_empty() && target.history.is_none() {
                unscaled(1) * polyline_length(&piece) * self.params.base_weight
            } else {
                piece
                    .windows(2)
                    .map(|s| {
                        let plain = unscaled(1) * dist(s[0], s[1]) * self.params.base_weight;
                        self.link_cost(other, s[0], s[1], plain)
                    })
                    .sum()
            };
            let cost = (printed + self.params.layer_change_penalty)
                .max(self.change_cost + self.min_weight * dz);
            if self.g[u as usize] + cost < self.g[v as usize] {
                let k = self.overlaps.len() as u32;
                self.overlaps.push(piece.clone());
                self.relax(u, v, cost, Some(k));
            }
        }
    }
}

/// Routes one wire on `layers` as given (see [`Search::new`]), running the search to the end.
pub fn route_wire(layers: &[RouteLayer], wire: &Wire, params: &RouteParams) -> WireRoute {
    let mut search = Search::new(layers, wire, params);
    while search.step() == SearchState::Running {}
    search.result()
}

#[cfg(test)]
impl Search {
    /// Along the route found, the least of (cost still to go − heuristic), negative where the
    /// heuristic promised more than the route costs; and the route's cost.
    pub(crate) fn heuristic_slack(&mut self) -> (f64, f64) {
        let to_go = self.g[self.target as usize];
        let mut slack = f64::INFINITY;
        let mut at = Some(self.target);
        while let Some(v) = at {
            let h = self.heuristic(v);
            slack = slack.min(to_go - self.g[v as usize] - h);
            at = self.parents[v as usize].map(|(p, _)| p);
        }
        (slack, to_go)
    }
}
