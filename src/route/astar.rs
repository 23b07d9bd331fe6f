//! A* search for one wire, steppable: a test or a viewer can run it one expansion at a time.
//!
//! Place in the pipeline: the core of routing, between the per-wire graph (`graph.rs`) and the
//! assembled trace (`trace.rs`). [`route`](super::route) runs one [`Search`] per wire;
//! [`route_wire`] runs one on layers as given.
//!
//! - **Heuristic**: the 3D straight distance to the target pad times the smallest weight, plus,
//!   per layer between the vertex and the target, the least a layer change can cost
//!   (`layer_change_penalty + interlayer_overlap × base_weight`). Every edge costs at least the
//!   heuristic's drop along it (layer changes are floored to make sure), so the heuristic is
//!   consistent and the first path to reach the target is the cheapest in the graph explored.
//! - **Lazy growth**: expanding a vertex inside the infill region adds grid vertices one
//!   `grid_step` away in the eight 45° directions (reusing a vertex within a third of a step) and
//!   edges to every vertex within one step, at `base_weight`; it also tries the layer changes of
//!   `interlayer.rs`.
//! - **Determinism**: the open list is a binary heap ordered by (f, larger g, vertex id) with
//!   total float order; vertex ids follow creation order, which depends only on the input; hash
//!   maps are only looked up, never iterated.

use super::graph::{self, Ends, Graph, LayerInput, PENALTY_FACTOR, PreparedLayer, VertexId};
use super::index::{dist, lerp};
use super::interlayer::{Parent, piece_fits, polyline_length, walk_back};
use super::{RouteLayer, RouteParams, Wire, WireRoute, layer_of, trace};
use crate::geom::{Point2, scaled, unscaled};
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
        .chain([&params.base_weight, &params.outside_weight])
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
/// base-weight mm, plus `detour_slack`; a rip-up probe (`probe`) may also run through 5 mm of
/// other traces. A route within the limit is at most `limit / min_weight` mm long.
pub(crate) fn cost_limit(
    params: &RouteParams,
    distance: f64,
    layer_changes: usize,
    probe: bool,
) -> f64 {
    let least = min_weight(params);
    let straight = distance.max(0.0)
        + change_cost(params) * layer_changes as f64 / least.max(f64::MIN_POSITIVE);
    let mut limit = params.max_detour.max(1.0) * straight * params.base_weight.max(least)
        + params.detour_slack.max(0.0);
    if probe {
        limit += PENALTY_FACTOR * 5.0;
    }
    limit
}

/// The A* search of one wire's route, one expansion per [`Search::step`].
#[derive(Debug, Clone)]
pub struct Search {
    params: RouteParams,
    wire: Wire,
    layers: Vec<PreparedLayer>,
    graph: Graph,
    target: VertexId,
    overlaps: Vec<Vec<Point2>>,
    g: Vec<f64>,
    parents: Vec<Parent>,
    closed: Vec<bool>,
    open: BinaryHeap<Open>,
    state: SearchState,
    expansions: usize,
    /// Smallest cost per mm of any edge.
    min_weight: f64,
    /// Least cost of one layer change.
    change_cost: f64,
    /// Routes costing more than this are not searched for (see [`RouteParams::max_detour`]).
    cost_limit: f64,
}

impl Search {
    /// A search for `wire` on `layers` as given: their islands are the material, nothing is
    /// blocked. Only the layers from the lower pad's layer − `layer_span` to the upper pad's +
    /// `layer_span` are used.
    pub fn new(layers: &[RouteLayer], wire: &Wire, params: &RouteParams) -> Self {
        let inputs = layer_range(layers, wire, params).map_or(Vec::new(), |range| {
            range
                .map(|l| LayerInput {
                    index: l,
                    z: layers[l].z,
                    islands: layers[l].islands.clone(),
                    original: layers[l].islands.clone(),
                    blocked: Vec::new(),
                    penalty: Vec::new(),
                })
                .collect()
        });
        Self::with_layers(inputs, layers, wire, params)
    }

    /// A search over prepared inputs (consecutive layers, ascending); `all` gives the pads'
    /// layers.
    pub(crate) fn with_layers(
        inputs: Vec<LayerInput>,
        all: &[RouteLayer],
        wire: &Wire,
        params: &RouteParams,
    ) -> Self {
        let layers: Vec<PreparedLayer> = inputs
            .iter()
            .map(|i| PreparedLayer::new(i, params))
            .collect();
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
            overlaps: Vec::new(),
            g: Vec::new(),
            parents: Vec::new(),
            closed: Vec::new(),
            open: BinaryHeap::new(),
            state,
            expansions: 0,
            min_weight,
            change_cost,
            cost_limit: f64::INFINITY,
        };
        if search.state == SearchState::Running {
            let (a, b) = (search.graph.pos(source), search.graph.pos(target));
            let (la, lb) = (search.graph.layer(source), search.graph.layer(target));
            let dz = search.layer(la).z - search.layer(lb).z;
            let dxy = unscaled(1) * dist(a, b);
            let probe = search.layers.iter().any(|l| !l.penalty.is_empty());
            search.cost_limit =
                cost_limit(params, (dxy * dxy + dz * dz).sqrt(), la.abs_diff(lb), probe);
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
            return self.state;
        };
        let u = top.v;
        if self.closed[u as usize] || top.g > self.g[u as usize] {
            return self.state;
        }
        if top.f > self.cost_limit {
            // Every route left costs more than the detour limit allows.
            self.state = SearchState::Failed;
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
            return self.state;
        }
        self.explore_grid(u);
        self.explore_layers(u);
        let penalised = !self.layer(self.graph.layer(u)).penalty.is_empty();
        for k in 0..self.graph.adj[u as usize].len() {
            let e = self.graph.adj[u as usize][k];
            let mut cost = e.cost;
            if penalised && self.graph.layer(e.to) == self.graph.layer(u) {
                let mid = lerp(self.graph.pos(u), self.graph.pos(e.to), 0.5);
                if self.layer(self.graph.layer(u)).penalty.contains(mid) {
                    cost *= PENALTY_FACTOR;
                }
            }
            self.relax(u, e.to, cost, None);
        }
        self.state
    }

    /// The route: assembled if the target was found, else an unrouted report.
    pub fn result(&self) -> WireRoute {
        if self.state != SearchState::Found {
            return trace::unrouted(&self.wire);
        }
        let mut path = Vec::new();
        let mut v = self.target;
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
        )
    }

    /// Sizes the per-vertex arrays to the graph.
    fn grow(&mut self) {
        let n = self.graph.verts.len();
        self.g.resize(n, f64::INFINITY);
        self.parents.resize(n, None);
        self.closed.resize(n, false);
    }

    fn layer(&self, l: usize) -> &PreparedLayer {
        &self.layers[l - self.layers[0].index]
    }

    fn in_range(&self, l: usize) -> bool {
        let lo = self.layers[0].index;
        l >= lo && l < lo + self.layers.len()
    }

    fn heuristic(&self, v: VertexId) -> f64 {
        let (a, b) = (self.graph.pos(v), self.graph.pos(self.target));
        let (la, lb) = (self.graph.layer(v), self.graph.layer(self.target));
        let dz = self.layer(la).z - self.layer(lb).z;
        let dxy = unscaled(1) * dist(a, b);
        self.min_weight * (dxy * dxy + dz * dz).sqrt() + self.change_cost * la.abs_diff(lb) as f64
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
            let f = g + self.heuristic(v);
            self.open.push(Open { f, g, v });
            return true;
        }
        false
    }

    /// Whether a planar grid edge `a`–`b` stays in the infill region of `layer`, given that `b`
    /// is in it.
    fn grid_edge_ok(&self, layer: &PreparedLayer, a: Point2, b: Point2, tol: i64) -> bool {
        !layer.infill.crosses(a, b) && layer.infill.inside_or_on(lerp(a, b, 0.5), tol)
    }

    /// Whether vertex `v` lies in its layer's infill region (asked once per vertex).
    fn in_infill(&mut self, v: VertexId, tol: i64) -> bool {
        if let Some(known) = self.graph.verts[v as usize].infill {
            return known;
        }
        let (l, p) = (self.graph.layer(v), self.graph.pos(v));
        let inside = self.layer(l).infill.inside_or_on(p, tol);
        self.graph.verts[v as usize].infill = Some(inside);
        inside
    }

    /// Grows the infill grid around `u` (once per vertex), if `u` is in the infill region.
    fn explore_grid(&mut self, u: VertexId) {
        let ui = u as usize;
        if self.graph.verts[ui].explored {
            return;
        }
        self.graph.verts[ui].explored = true;
        let l = self.graph.layer(u);
        let p = self.graph.pos(u);
        let tol = scaled(self.params.align_tolerance).max(1);
        if !self.in_infill(u, tol) {
            return;
        }
        let step = scaled(self.params.grid_step).max(1);
        let reuse = (step as f64 * GRID_REUSE) as i64;
        let base = self.params.base_weight;
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
                if self.in_infill(v, tol)
                    && self.grid_edge_ok(self.layer(l), p, self.graph.pos(v), tol)
                {
                    self.graph.link(u, v, base);
                }
                continue;
            }
            let layer = self.layer(l);
            if !layer.infill.inside_or_on(q, tol) || !self.grid_edge_ok(layer, p, q, tol) {
                continue;
            }
            let (v, created) = self.graph.add_vertex(l, q);
            self.graph.link(u, v, base);
            if created {
                self.grow();
                self.link_neighbours(v, |s, w| {
                    (s.in_infill(w, tol)
                        && s.grid_edge_ok(s.layer(l), s.graph.pos(w), s.graph.pos(v), tol))
                    .then_some(base)
                });
            }
        }
        for v in self.graph.within(l, p, step) {
            if v != u
                && self.in_infill(v, tol)
                && self.grid_edge_ok(self.layer(l), p, self.graph.pos(v), tol)
            {
                self.graph.link(u, v, base);
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
            if !self.in_range(other) || !piece_fits(&piece, &self.graph, self.layer(other), tol) {
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
            let printed = unscaled(1) * polyline_length(&piece) * self.params.base_weight;
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
