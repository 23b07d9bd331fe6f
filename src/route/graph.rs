//! The routing graph: deflated perimeter traces, direct connections and wire endpoints per layer.
//!
//! Place in the pipeline: built per wire, before its A* search (`astar.rs`), over the layers
//! between the wire's endpoint layers ± 1. The search grows it lazily (infill grid, inter-layer
//! edges); this file builds the static part:
//!
//! - **Deflated perimeter traces**: the layer islands (with other nets' channels as holes) shrunk
//!   by `i·perimeter_width + (conductive_width + channel_extra)/2` for `i = 1..=perimeters`; every
//!   ring of each result is a closed chain of vertices whose edges cost `length ×
//!   perimeter_weights[i-1]`.
//! - **Squeeze rings**: the boundary of the squeeze region (the islands shrunk just past other
//!   nets' keep-outs, within the first deflated area of the original islands), where it is not
//!   a first deflated trace already, at `squeeze_weight` per mm: the only way through gaps too
//!   narrow for two perimeter traces, such as between a fine-pitch part's pad rows.
//! - **Direct connections**: the wire's rubberband projected into the layer, split where it meets
//!   the rings, the island boundaries and the keep-outs of other nets' traces. Sections inside
//!   the material cost `base_weight` per mm, sections across holes and notches of one island
//!   `outside_weight`; sections inside a keep-out or bridging two separate islands are left out.
//!   The split points are inserted into the ring edges they lie on, connecting the two.
//! - **Endpoints**: each pad becomes a vertex on its layer, joined to the nearest point of every
//!   ring within the perimeter zone (plus a grid step), to the first point of every ring in each
//!   of the eight 45° directions within that reach, and to every vertex within a grid step.
//!
//! The deflated areas are not deflated afresh for every search. Shrinking the islands less some
//! holes by `d` is shrinking the islands by `d` and taking out the holes grown by `d`: each
//! layer's islands are shrunk once per inset ([`Eroded`]), each pad and channel is grown once
//! per inset when a search first meets it ([`Grown`]), and a search takes the grown holes in its
//! window out of the shrunk islands (`carve`) — a subtraction of the holes near the route
//! instead of an offset of the whole layer with all of its holes.
//!
//! Rings and sections are supersampled so consecutive vertices are at most
//! `min(interlayer_overlap, grid_step)` apart. Ring samples sit at fixed arc lengths from the
//! ring's canonical start, so identical rings on neighbouring layers give identical vertices, and
//! each new vertex is snapped to a vertex of the neighbour layers within `align_tolerance`:
//! inter-layer edges then join vertices of exactly the same xy.

use super::RouteParams;
use super::congestion::History;
use super::index::{Hit, RegionIndex, dist, lerp};
use crate::geom::{
    ExPolygon, Join, Point2, difference, intersection, offset, scaled, segment_distance,
    segment_param, union, unscaled,
};
use rayon::prelude::*;
use std::collections::{BTreeMap, HashMap};
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::Arc;

/// A small multiplicative hasher for the integer keys of the vertex maps (the std SipHash is
/// built against adversarial keys, which these are not). Maps are only looked up, never
/// iterated, so the hasher does not affect the output.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct IntHasher(u64);

impl Hasher for IntHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }

    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    fn write_i64(&mut self, v: i64) {
        self.write_u64(v as u64);
    }

    fn write_u32(&mut self, v: u32) {
        self.write_u64(u64::from(v));
    }

    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }
}

/// A hash map with [`IntHasher`].
pub(crate) type IntMap<K, V> = HashMap<K, V, BuildHasherDefault<IntHasher>>;

/// A hash set with [`IntHasher`].
pub(crate) type IntSet<K> = std::collections::HashSet<K, BuildHasherDefault<IntHasher>>;

/// Vertex number within one wire's graph.
pub(crate) type VertexId = u32;

/// Chord deviation of the round corners of deflated traces, mm.
const ROUND_DEVIATION_MM: f64 = 0.01;

/// Points of one layer closer than this are one vertex (scaled units: 1 µm, far above the
/// nanometre rounding of intersection points and far below a trace width).
pub(crate) const MERGE_NM: i64 = 1_000;

/// One layer's input to the router, with the state left by the wires already routed.
#[derive(Debug, Clone)]
pub(crate) struct LayerInput {
    /// Index of the layer in the caller's list.
    pub index: usize,
    /// Top of the layer, mm.
    pub z: f64,
    /// The caller's islands, eroded once per layer for every deflation inset.
    pub eroded: Arc<Eroded>,
    /// The routing window (`[min x, min y, max x, max y]`, scaled): the deflated areas end
    /// where the window shrunk by the same inset does. `None` for the whole layer.
    pub window: Option<[i64; 4]>,
    /// Other nets' channels and pads in the window, grown by every inset: what they take out
    /// of the eroded islands.
    pub holes: Vec<Arc<Grown>>,
    /// Where no trace centre of this wire may run (other nets' traces grown by two channel
    /// half-widths, and their pads'); the pieces may overlap.
    pub blocked: Vec<ExPolygon>,
    /// Where links cost `penalty_factor` times more: other nets' traces, when a rip-up probe
    /// looks for the route that runs into the fewest of them, or a negotiation round routes
    /// through them at a price. Empty in a normal search.
    pub penalty: Vec<ExPolygon>,
    /// Cost multiplier of links in `penalty` ([`PENALTY_FACTOR`] for a rip-up probe).
    pub penalty_factor: f64,
    /// Congestion history of negotiated routing: links cost `1 + history` times more.
    pub history: Option<Arc<History>>,
}

impl LayerInput {
    /// Layer `index` at `z` with `islands` as its material, nothing in the way and nothing
    /// priced.
    pub(crate) fn plain(index: usize, z: f64, islands: &[ExPolygon], params: &RouteParams) -> Self {
        Self {
            index,
            z,
            eroded: Arc::new(Eroded::new(islands, params)),
            window: None,
            holes: Vec::new(),
            blocked: Vec::new(),
            penalty: Vec::new(),
            penalty_factor: 1.0,
            history: None,
        }
    }
}

/// The distances the router deflates a layer's material by, mm: one per deflated perimeter
/// trace, `i·perimeter_width + (conductive_width + channel_extra)/2` for `i = 1..=perimeters`
/// (half a channel alone without perimeters, where a trace centre keeps its channel inside).
pub(crate) fn insets(params: &RouteParams) -> Vec<f64> {
    let half = params.channel_half_width();
    if params.perimeters == 0 {
        return vec![half];
    }
    (1..=params.perimeters)
        .map(|i| i as f64 * params.perimeter_width + half)
        .collect()
}

/// The squeeze region's two distances, mm: clear of other nets' keep-outs (which reach a
/// polygonal channel's circumscribed half-width past their holes, so the squeeze rings are
/// themselves usable), and one perimeter inside the layer's own walls.
fn squeeze_insets(params: &RouteParams) -> (f64, f64) {
    let half = params.channel_half_width();
    (
        super::channels::keep_out_radius(params) - super::channels::circumscribed(half)
            + ROUND_DEVIATION_MM,
        params.perimeter_width + half,
    )
}

/// A layer's islands eroded by every inset (see [`insets`]), made once per layer: eroding
/// the islands less the holes of other nets' channels and pads by `d` is eroding the islands by
/// `d` and taking out the holes grown by `d`, so each search only subtracts its holes' grown
/// shapes ([`Grown`]) instead of deflating the whole layer again.
#[derive(Debug, Default)]
pub(crate) struct Eroded {
    /// The islands shrunk by each inset of [`insets`].
    areas: Vec<Vec<ExPolygon>>,
    /// The islands shrunk by both squeeze distances (see [`squeeze_insets`]); empty when the
    /// squeeze region is off.
    squeeze: Vec<ExPolygon>,
    /// The islands (inside/outside decisions, perimeter crossings).
    material: Arc<RegionIndex>,
    /// Outer contours of the islands, grouped by island.
    contours: Arc<RegionIndex>,
}

impl Eroded {
    /// `islands` eroded for `params`.
    pub(crate) fn new(islands: &[ExPolygon], params: &RouteParams) -> Self {
        let erode = |d: f64| offset(islands, -d, Join::Round(ROUND_DEVIATION_MM));
        let areas = insets(params).into_iter().map(erode).collect();
        let squeeze = if params.squeeze_weight.is_finite() {
            let (clear, walls) = squeeze_insets(params);
            intersection(&erode(clear), &erode(walls))
        } else {
            Vec::new()
        };
        let contours: Vec<(u32, &[Point2])> = islands
            .iter()
            .enumerate()
            .map(|(k, ex)| (k as u32, ex.contour.points.as_slice()))
            .collect();
        Self {
            areas,
            squeeze,
            material: Arc::new(RegionIndex::of_regions(islands)),
            contours: Arc::new(RegionIndex::new(&contours)),
        }
    }
}

/// A region and its box.
type Boxed = (Vec<ExPolygon>, [i64; 4]);

/// A hole in the material (another net's channel or pad) grown by every inset of [`insets`]
/// and by the squeeze clearance, each with its box: what it takes out of the [`Eroded`]
/// islands.
#[derive(Debug, Default)]
pub(crate) struct Grown {
    /// Grown by each inset.
    areas: Vec<Boxed>,
    /// Grown by the squeeze clearance.
    squeeze: Boxed,
}

impl Grown {
    /// A hole grown by `grow(d)` for each distance `d` (mm) it is needed at.
    pub(crate) fn new(params: &RouteParams, grow: impl Fn(f64) -> Vec<ExPolygon>) -> Self {
        let boxed = |d: f64| {
            let region = grow(d);
            let b = bbox(&region);
            (region, b)
        };
        Self {
            areas: insets(params).into_iter().map(boxed).collect(),
            squeeze: if params.squeeze_weight.is_finite() {
                boxed(squeeze_insets(params).0)
            } else {
                (Vec::new(), bbox(&[]))
            },
        }
    }

    /// The union of `parts`, inset by inset.
    pub(crate) fn union(parts: &[&Grown]) -> Self {
        let merge = |pick: &dyn Fn(&Grown) -> Option<&Boxed>| -> Boxed {
            let all: Vec<ExPolygon> = parts
                .iter()
                .filter_map(|g| pick(g))
                .flat_map(|b| b.0.iter().cloned())
                .collect();
            let region = if all.is_empty() { all } else { union(&all) };
            let b = bbox(&region);
            (region, b)
        };
        let insets = parts.iter().map(|g| g.areas.len()).max().unwrap_or(0);
        Self {
            areas: (0..insets).map(|k| merge(&|g| g.areas.get(k))).collect(),
            squeeze: merge(&|g| Some(&g.squeeze)),
        }
    }

    /// The box of the largest growth, if any.
    pub(crate) fn bbox(&self) -> Option<[i64; 4]> {
        self.areas
            .iter()
            .chain(std::iter::once(&self.squeeze))
            .filter(|b| !b.0.is_empty())
            .map(|b| b.1)
            .reduce(box_union)
    }

    /// A polygonal hole, grown by offsetting with round corners.
    pub(crate) fn of_polygons(hole: &[ExPolygon], params: &RouteParams) -> Self {
        Self::new(params, |d| {
            decimate(offset(hole, d, Join::Round(ROUND_DEVIATION_MM)))
        })
    }
}

/// The box around every point of `regions` (an empty box for none), scaled units.
pub(crate) fn bbox(regions: &[ExPolygon]) -> [i64; 4] {
    points_box(regions.iter().flat_map(|ex| &ex.contour.points))
}

/// The box around `points` (an empty box for none), scaled units.
fn points_box<'p>(points: impl IntoIterator<Item = &'p Point2>) -> [i64; 4] {
    let mut b = [i64::MAX, i64::MAX, i64::MIN, i64::MIN];
    for p in points {
        b = [b[0].min(p.x), b[1].min(p.y), b[2].max(p.x), b[3].max(p.y)];
    }
    b
}

/// The box around two boxes.
pub(crate) fn box_union(a: [i64; 4], b: [i64; 4]) -> [i64; 4] {
    [
        a[0].min(b[0]),
        a[1].min(b[1]),
        a[2].max(b[2]),
        a[3].max(b[3]),
    ]
}

/// Whether two boxes share a point.
pub(crate) fn boxes_meet(a: &[i64; 4], b: &[i64; 4]) -> bool {
    a[0] <= b[2] && b[0] <= a[2] && a[1] <= b[3] && b[1] <= a[3]
}

/// Whether box `inner` lies within box `outer`.
fn box_within(inner: &[i64; 4], outer: &[i64; 4]) -> bool {
    outer[0] <= inner[0] && outer[1] <= inner[1] && inner[2] <= outer[2] && inner[3] <= outer[3]
}

/// `eroded` (the islands shrunk by `inset` mm) within `window` shrunk by the same inset, less
/// `holes` (grown by it; only those that reach the rest are taken out).
fn carve<'h>(
    eroded: &[ExPolygon],
    window: Option<[i64; 4]>,
    inset: f64,
    holes: impl Iterator<Item = &'h Boxed>,
) -> Vec<ExPolygon> {
    let clipped = match window {
        None => eroded.to_vec(),
        Some(w) => {
            let d = scaled(inset);
            let frame = [w[0] + d, w[1] + d, w[2] - d, w[3] - d];
            if frame[0] >= frame[2] || frame[1] >= frame[3] {
                return Vec::new();
            }
            // Only the parts that reach into the frame matter to the intersection.
            let mut near: Vec<ExPolygon> = Vec::new();
            let mut inside = true;
            for ex in eroded {
                let b = bbox(std::slice::from_ref(ex));
                if !boxes_meet(&b, &frame) {
                    continue;
                }
                inside &= box_within(&b, &frame);
                near.push(ExPolygon {
                    contour: ex.contour.clone(),
                    holes: ex
                        .holes
                        .iter()
                        .filter(|h| boxes_meet(&points_box(&h.points), &frame))
                        .cloned()
                        .collect(),
                });
            }
            if inside {
                near
            } else {
                let rect = ExPolygon {
                    contour: crate::geom::Polygon::new(vec![
                        Point2::new(frame[0], frame[1]),
                        Point2::new(frame[2], frame[1]),
                        Point2::new(frame[2], frame[3]),
                        Point2::new(frame[0], frame[3]),
                    ]),
                    holes: Vec::new(),
                };
                intersection(&near, &[rect])
            }
        }
    };
    let reach = bbox(&clipped);
    let holes: Vec<ExPolygon> = holes
        .filter(|(_, b)| boxes_meet(b, &reach))
        .flat_map(|(region, _)| region.iter().cloned())
        .collect();
    if holes.is_empty() || clipped.is_empty() {
        decimate(clipped)
    } else {
        decimate(difference(&clipped, &holes))
    }
}

/// Cost multiplier of links in a [`LayerInput::penalty`] region.
pub(crate) const PENALTY_FACTOR: f64 = 25.0;

/// One deflated perimeter trace.
#[derive(Debug, Clone)]
pub(crate) struct Ring {
    /// The ring's points (closed).
    pub points: Vec<Point2>,
    /// Cost per mm along it.
    pub weight: f64,
}

/// A layer made ready for routing: its geometry (shared by the searches that see the layer
/// alike, such as one wire's searches in successive negotiation rounds) and its prices.
#[derive(Debug, Clone)]
pub(crate) struct PreparedLayer {
    /// Index of the layer in the caller's list.
    pub index: usize,
    /// Top of the layer, mm.
    pub z: f64,
    /// The rings and the regions the router queries.
    pub geometry: Arc<LayerGeometry>,
    /// Where links cost `penalty_factor` times more.
    pub penalty: RegionIndex,
    /// Cost multiplier of links in `penalty`.
    pub penalty_factor: f64,
    /// Congestion history of negotiated routing, if any.
    pub history: Option<Arc<History>>,
}

impl std::ops::Deref for PreparedLayer {
    type Target = LayerGeometry;

    fn deref(&self) -> &LayerGeometry {
        &self.geometry
    }
}

impl PreparedLayer {
    /// Deflates the islands of `input` into rings and indexes the regions.
    #[cfg(test)]
    pub(crate) fn new(input: &LayerInput, params: &RouteParams) -> Self {
        Self::with_geometry(input, Arc::new(LayerGeometry::new(input, params)))
    }

    /// `input`'s layer with `geometry` already made from it (or from an input alike but for
    /// its penalty and history), and `input`'s prices.
    pub(crate) fn with_geometry(input: &LayerInput, geometry: Arc<LayerGeometry>) -> Self {
        Self {
            index: input.index,
            z: input.z,
            geometry,
            penalty: RegionIndex::of_regions(&input.penalty),
            penalty_factor: input.penalty_factor,
            history: input.history.clone(),
        }
    }
}

/// `inputs` made ready for routing, each with its `known` geometry, or, where none is known,
/// the geometry deflated from it. The layers without are deflated on rayon's threads: each is a
/// function of its input alone, so the result is the same on any number of threads.
pub(crate) fn prepare(
    inputs: &[LayerInput],
    known: Vec<Option<Arc<LayerGeometry>>>,
    params: &RouteParams,
) -> Vec<PreparedLayer> {
    let missing: Vec<bool> = known.iter().map(Option::is_none).collect();
    let built: Vec<Option<LayerGeometry>> = inputs
        .par_iter()
        .zip(missing.par_iter())
        .map(|(input, &missing)| missing.then(|| LayerGeometry::new(input, params)))
        .collect();
    inputs
        .iter()
        .zip(known.into_iter().zip(built))
        .map(|(input, pair)| {
            let geometry = match pair {
                (Some(g), _) => g,
                (None, new) => Arc::new(new.unwrap_or_else(|| LayerGeometry::new(input, params))),
            };
            PreparedLayer::with_geometry(input, geometry)
        })
        .collect()
}

/// A layer's rings and the regions the router queries: everything of a [`PreparedLayer`] but its
/// prices.
#[derive(Debug, Clone)]
pub(crate) struct LayerGeometry {
    /// All deflated perimeter traces, outermost offset first.
    pub rings: Vec<Ring>,
    /// Edges of `rings`, grouped by ring number.
    pub ring_edges: RegionIndex,
    /// The first deflated area: where a trace centre keeps its channel inside the material and
    /// clear of other channels.
    pub clearance: RegionIndex,
    /// The innermost deflated area, explored on the grid.
    pub infill: RegionIndex,
    /// Where a channel fits at all: clear of other nets' channels and pads (the islands shrunk by
    /// half a channel) and one perimeter inside the layer's own walls (the original islands
    /// shrunk by `perimeter_width` + half a channel). The grid reaches the gaps the deflated
    /// traces leave out here, at `squeeze_weight`.
    pub squeeze: RegionIndex,
    /// The original islands (inside/outside decisions, perimeter crossings).
    pub material: Arc<RegionIndex>,
    /// Outer contours of the original islands, grouped by island.
    pub contours: Arc<RegionIndex>,
    /// Keep-outs of other nets' traces.
    pub blocked: RegionIndex,
}

impl LayerGeometry {
    /// Deflates the islands of `input` into rings and indexes the regions.
    pub(crate) fn new(input: &LayerInput, params: &RouteParams) -> Self {
        let eroded = &input.eroded;
        let insets = insets(params);
        let areas: Vec<Vec<ExPolygon>> = eroded
            .areas
            .iter()
            .zip(&insets)
            .enumerate()
            .map(|(k, (base, &d))| {
                let holes = input.holes.iter().filter_map(|g| g.areas.get(k));
                carve(base, input.window, d, holes)
            })
            .collect();
        let mut rings = Vec::new();
        if params.perimeters > 0 {
            for (k, area) in areas.iter().enumerate() {
                let weight = params.perimeter_weight(k + 1);
                for ex in area {
                    for ring in std::iter::once(&ex.contour).chain(&ex.holes) {
                        if ring.points.len() >= 3 {
                            rings.push(Ring {
                                points: ring.points.clone(),
                                weight,
                            });
                        }
                    }
                }
            }
        }
        let squeeze = if eroded.squeeze.is_empty() {
            Vec::new()
        } else {
            let (clear, walls) = squeeze_insets(params);
            let holes = input.holes.iter().map(|g| &g.squeeze);
            carve(&eroded.squeeze, input.window, clear.max(walls), holes)
        };
        // Away from other nets' channels and pads the squeeze region ends where the first
        // deflated area does: those rings are there already.
        let sorted = |pts: &[Point2]| {
            let mut v = pts.to_vec();
            v.sort_unstable();
            v
        };
        let first: Vec<Vec<Point2>> = areas
            .first()
            .into_iter()
            .flatten()
            .flat_map(|ex| std::iter::once(&ex.contour).chain(&ex.holes))
            .map(|r| sorted(&r.points))
            .collect();
        for ex in &squeeze {
            for ring in std::iter::once(&ex.contour).chain(&ex.holes) {
                if ring.points.len() >= 3 && !first.contains(&sorted(&ring.points)) {
                    rings.push(Ring {
                        points: ring.points.clone(),
                        weight: params.squeeze_weight,
                    });
                }
            }
        }
        let ring_refs: Vec<(u32, &[Point2])> = rings
            .iter()
            .enumerate()
            .map(|(k, r)| (k as u32, r.points.as_slice()))
            .collect();
        let blocked = if input.blocked.len() > 1 {
            union(&input.blocked)
        } else {
            input.blocked.clone()
        };
        Self {
            squeeze: RegionIndex::of_regions(&squeeze),
            ring_edges: RegionIndex::new(&ring_refs),
            clearance: RegionIndex::of_regions(areas.first().map_or(&[], Vec::as_slice)),
            infill: RegionIndex::of_regions(areas.last().map_or(&[], Vec::as_slice)),
            material: Arc::clone(&eroded.material),
            contours: Arc::clone(&eroded.contours),
            blocked: RegionIndex::of_regions(&blocked),
            rings,
        }
    }

    /// Whether the segment `a`–`b` runs into a keep-out.
    pub(crate) fn blocked_segment(&self, a: Point2, b: Point2) -> bool {
        !self.blocked.is_empty()
            && (self.blocked.crosses(a, b)
                || self.blocked.contains(a)
                || self.blocked.contains(b)
                || self.blocked.contains(lerp(a, b, 0.5)))
    }

    /// Whether `a` and `b` lie within (or on) the outer contour of one island.
    pub(crate) fn same_island(&self, a: Point2, b: Point2, tol: i64) -> bool {
        let (ga, gb) = (
            self.contours.groups_at(a, tol),
            self.contours.groups_at(b, tol),
        );
        ga.iter().any(|g| gb.binary_search(g).is_ok())
    }

    /// Cost per mm of a straight link `a`–`b` on this layer, or `None` if it may not be used:
    /// it enters a keep-out, or it runs outside the material between two separate islands.
    pub(crate) fn link_weight(
        &self,
        a: Point2,
        b: Point2,
        params: &RouteParams,
        tol: i64,
    ) -> Option<f64> {
        if self.blocked_segment(a, b) {
            return None;
        }
        if self.material.inside_or_on(lerp(a, b, 0.5), tol) {
            Some(params.base_weight)
        } else if self.same_island(a, b, tol) {
            Some(params.outside_weight)
        } else {
            None
        }
    }
}

/// Ring points closer than this to the previous kept point are dropped (scaled units: 0.2 mm).
/// Round corners of the deflated traces come in chords a few micrometres long; a vertex every
/// 0.2 mm is dense enough for routing, and the chords left stray less than 0.01 mm from the arc
/// for radii above 0.5 mm.
const RING_POINT_SPACING_NM: i64 = 200_000;

/// `regions` with ring points closer than [`RING_POINT_SPACING_NM`] to the previous kept one
/// dropped; rings left with fewer than three points are kept whole.
fn decimate(mut regions: Vec<ExPolygon>) -> Vec<ExPolygon> {
    let min2 = (RING_POINT_SPACING_NM as i128).pow(2);
    let thin = |pts: &mut Vec<Point2>| {
        let mut kept: Vec<Point2> = Vec::with_capacity(pts.len());
        for &p in pts.iter() {
            if kept.last().is_none_or(|&q| q.distance_squared(p) >= min2) {
                kept.push(p);
            }
        }
        while kept.len() > 3 && kept[0].distance_squared(kept[kept.len() - 1]) < min2 {
            kept.pop();
        }
        if kept.len() >= 3 {
            *pts = kept;
        }
    };
    for ex in &mut regions {
        thin(&mut ex.contour.points);
        for h in &mut ex.holes {
            thin(&mut h.points);
        }
    }
    regions
}

/// One vertex of the routing graph.
/// Where a vertex lies for the lazily explored grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Zone {
    /// Where no trace centre may run, or off every region.
    Out,
    /// In the squeeze region but not the infill region.
    Squeeze,
    /// In the infill region (the innermost deflated area).
    Infill,
}

#[derive(Debug, Clone)]
pub(crate) struct Vertex {
    /// Position, scaled units.
    pub p: Point2,
    /// Layer index (the caller's numbering).
    pub layer: usize,
    /// Whether the infill grid has been explored around it.
    pub explored: bool,
    /// Which grid zone it lies in, once asked.
    pub zone: Option<Zone>,
}

/// One directed edge.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Edge {
    /// Head of the edge.
    pub to: VertexId,
    /// Cost, mm-equivalents.
    pub cost: f64,
}

/// Vertices keyed by their scaled (x, y, layer), with planar edges and a spatial hash.
#[derive(Debug, Clone)]
pub(crate) struct Graph {
    /// Vertices by id.
    pub verts: Vec<Vertex>,
    /// Outgoing planar edges per vertex.
    pub adj: Vec<Vec<Edge>>,
    by_pos: IntMap<(usize, i64, i64), VertexId>,
    cells: IntMap<(usize, i64, i64), Vec<VertexId>>,
    cell: i64,
    align: i64,
}

impl Graph {
    /// An empty graph with spatial-hash cells of `cell` scaled units and neighbour-layer snapping
    /// within `align` scaled units.
    pub(crate) fn new(cell: i64, align: i64) -> Self {
        Self {
            verts: Vec::new(),
            adj: Vec::new(),
            by_pos: IntMap::default(),
            cells: IntMap::default(),
            cell: cell.max(1),
            align,
        }
    }

    /// Calls `visit` with every vertex of `layer` within `radius` of `p` and its squared
    /// distance to `p`, in no particular order.
    fn near(&self, layer: usize, p: Point2, radius: i64, mut visit: impl FnMut(VertexId, i128)) {
        let (x0, x1) = (
            (p.x - radius).div_euclid(self.cell),
            (p.x + radius).div_euclid(self.cell),
        );
        let (y0, y1) = (
            (p.y - radius).div_euclid(self.cell),
            (p.y + radius).div_euclid(self.cell),
        );
        let r2 = (radius as i128) * (radius as i128);
        for cx in x0..=x1 {
            for cy in y0..=y1 {
                let Some(list) = self.cells.get(&(layer, cx, cy)) else {
                    continue;
                };
                for &v in list {
                    let d = self.verts[v as usize].p.distance_squared(p);
                    if d <= r2 {
                        visit(v, d);
                    }
                }
            }
        }
    }

    /// Vertices of `layer` within `radius` of `p`, by increasing id.
    pub(crate) fn within(&self, layer: usize, p: Point2, radius: i64) -> Vec<VertexId> {
        let mut out: Vec<VertexId> = Vec::new();
        self.near(layer, p, radius, |v, _| out.push(v));
        out.sort_unstable();
        out
    }

    /// The vertex of `layer` nearest to `p` within `radius` (ties to the lower id).
    pub(crate) fn nearest(&self, layer: usize, p: Point2, radius: i64) -> Option<VertexId> {
        if let Some(&v) = self.by_pos.get(&(layer, p.x, p.y)) {
            return Some(v);
        }
        let mut best: Option<(i128, VertexId)> = None;
        self.near(layer, p, radius, |v, d| {
            if best.is_none_or(|b| (d, v) < b) {
                best = Some((d, v));
            }
        });
        best.map(|(_, v)| v)
    }

    /// The vertex at `p` on `layer`: an existing one within [`MERGE_NM`], else a new one, snapped
    /// to the xy of the nearest vertex of a neighbour layer within the alignment tolerance.
    /// Returns the vertex and whether it was created.
    pub(crate) fn add_vertex(&mut self, layer: usize, p: Point2) -> (VertexId, bool) {
        if let Some(v) = self.nearest(layer, p, MERGE_NM) {
            return (v, false);
        }
        let mut q = p;
        for other in [layer.checked_sub(1), Some(layer + 1)]
            .into_iter()
            .flatten()
        {
            if let Some(v) = self.nearest(other, p, self.align) {
                q = self.verts[v as usize].p;
                break;
            }
        }
        if let Some(&v) = self.by_pos.get(&(layer, q.x, q.y)) {
            return (v, false);
        }
        let id = self.verts.len() as VertexId;
        self.verts.push(Vertex {
            p: q,
            layer,
            explored: false,
            zone: None,
        });
        self.adj.push(Vec::new());
        self.by_pos.insert((layer, q.x, q.y), id);
        self.cells
            .entry((layer, q.x.div_euclid(self.cell), q.y.div_euclid(self.cell)))
            .or_default()
            .push(id);
        (id, true)
    }

    /// Joins `a` and `b` both ways at `weight` per mm of their distance (once).
    pub(crate) fn link(&mut self, a: VertexId, b: VertexId, weight: f64) {
        if a == b || self.linked(a, b) {
            return;
        }
        let cost = unscaled(1) * dist(self.verts[a as usize].p, self.verts[b as usize].p) * weight;
        self.adj[a as usize].push(Edge { to: b, cost });
        self.adj[b as usize].push(Edge { to: a, cost });
    }

    /// Whether `a` and `b` are linked.
    pub(crate) fn linked(&self, a: VertexId, b: VertexId) -> bool {
        self.adj[a as usize].iter().any(|e| e.to == b)
    }

    /// Position of vertex `v`.
    pub(crate) fn pos(&self, v: VertexId) -> Point2 {
        self.verts[v as usize].p
    }

    /// Layer of vertex `v`.
    pub(crate) fn layer(&self, v: VertexId) -> usize {
        self.verts[v as usize].layer
    }
}

/// A wire's pads, snapped to their layers.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ends {
    /// Start pad xy.
    pub from: Point2,
    /// Start layer.
    pub from_layer: usize,
    /// End pad xy.
    pub to: Point2,
    /// End layer.
    pub to_layer: usize,
}

impl Ends {
    /// The piece of the rubberband projected into `layer`, if any.
    ///
    /// Between pads on different layers the rubberband is shared out by layer index: each of the
    /// `k + 1` layers from the start layer to the end layer gets `1/(k + 1)` of it, in order, so
    /// the endpoint layers get a piece too (pads usually sit at a layer's top, where the raw z
    /// range would give them none). The pieces of consecutive layers meet at the same point, the
    /// rubberband's crossing of the layer boundary. A wire within one layer gets the whole
    /// segment there and on the layers just above and below, so it can change layer to pass a
    /// channel.
    pub(crate) fn piece(&self, layer: usize) -> Option<(Point2, Point2)> {
        let (la, lb) = (self.from_layer, self.to_layer);
        if la == lb {
            return (layer.abs_diff(la) <= 1).then_some((self.from, self.to));
        }
        if layer < la.min(lb) || layer > la.max(lb) {
            return None;
        }
        let shares = (la.abs_diff(lb) + 1) as f64;
        let k = layer.abs_diff(la) as f64;
        Some((
            lerp(self.from, self.to, k / shares),
            lerp(self.from, self.to, (k + 1.0) / shares),
        ))
    }
}

/// A point to insert into edge `edge` of a ring, at parameter `u` along the edge.
#[derive(Debug, Clone, Copy)]
struct Insert {
    edge: usize,
    u: f64,
    point: Point2,
}

/// Most samples on one ring or one straight section: a longer one is sampled more sparsely,
/// so a far pad or a huge island cannot make a loop or a list without bound.
const MAX_SAMPLES: f64 = (1 << 18) as f64;

/// Ring points: corners, inserted points and samples every `spacing` of arc length from the
/// ring's start (sparser on a ring longer than [`MAX_SAMPLES`] samples), in order along the
/// ring, without repeats.
fn sample_ring(ring: &[Point2], inserts: &[Insert], spacing: f64) -> Vec<Point2> {
    let perimeter: f64 = (0..ring.len())
        .map(|k| dist(ring[k], ring[(k + 1) % ring.len()]))
        .sum();
    let spacing = spacing.max(perimeter / MAX_SAMPLES);
    let mut out: Vec<Point2> = Vec::new();
    let mut arc = 0.0;
    for k in 0..ring.len() {
        let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
        let len = dist(a, b);
        let mut at: Vec<(f64, Point2)> = vec![(0.0, a)];
        at.extend(
            inserts
                .iter()
                .filter(|i| i.edge == k)
                .map(|i| (i.u, i.point)),
        );
        if len > 0.0 {
            let mut j = (arc / spacing).floor() + 1.0;
            while j * spacing < arc + len {
                let u = (j * spacing - arc) / len;
                at.push((u, lerp(a, b, u)));
                j += 1.0;
            }
        }
        at.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        for (_, p) in at {
            if out
                .last()
                .is_none_or(|&q| q.distance_squared(p) > (MERGE_NM as i128).pow(2))
            {
                out.push(p);
            }
        }
        arc += len;
    }
    while out.len() > 1 && out[0].distance_squared(out[out.len() - 1]) <= (MERGE_NM as i128).pow(2)
    {
        out.pop();
    }
    out
}

/// Points of the straight section `a`–`b` so no two consecutive are more than `spacing` apart
/// (at most [`MAX_SAMPLES`] sections: a longer one gets longer sections).
pub(crate) fn supersample(a: Point2, b: Point2, spacing: f64) -> Vec<Point2> {
    let n = (dist(a, b) / spacing).ceil().clamp(1.0, MAX_SAMPLES) as usize;
    (0..=n).map(|i| lerp(a, b, i as f64 / n as f64)).collect()
}

/// The static graph of one wire over `layers` (consecutive, ascending), and the vertices of its
/// two pads.
pub(crate) fn build(
    layers: &[PreparedLayer],
    ends: &Ends,
    params: &RouteParams,
) -> (Graph, VertexId, VertexId) {
    let spacing = scaled(sample_spacing(params)) as f64;
    let tol = scaled(params.align_tolerance).max(1);
    let step = scaled(params.grid_step).max(1);
    let mut graph = Graph::new(step, tol);
    let reach = scaled(
        params.perimeters as f64 * params.perimeter_width
            + params.channel_half_width()
            + params.grid_step,
    );
    let mut pads: BTreeMap<usize, Vec<Point2>> = BTreeMap::new();
    pads.entry(ends.from_layer).or_default().push(ends.from);
    pads.entry(ends.to_layer).or_default().push(ends.to);
    let mut source = None;
    let mut target = None;
    for layer in layers {
        let l = layer.index;
        let piece = ends.piece(l);
        let layer_pads = pads.get(&l).cloned().unwrap_or_default();
        // Where the direct connection and the pads' links meet the rings.
        let mut inserts: Vec<Vec<Insert>> = vec![Vec::new(); layer.rings.len()];
        let ring_hits: Vec<Hit> = piece.map_or(Vec::new(), |(a, b)| layer.ring_edges.hits(a, b));
        for h in &ring_hits {
            inserts[h.group as usize].push(Insert {
                edge: h.edge as usize,
                u: h.u,
                point: h.point,
            });
        }
        let mut pad_links: Vec<(Point2, Point2)> = Vec::new();
        for &pad in &layer_pads {
            for (r, ring) in layer.rings.iter().enumerate() {
                if let Some(ins) = nearest_on_ring(&ring.points, pad, reach) {
                    inserts[r].push(ins);
                    pad_links.push((pad, ins.point));
                }
            }
            // A pad in a row of other nets' pads can only be left along the gap between its
            // neighbours, which the nearest ring point may not face: also link it to the
            // first point of every ring in each of the eight 45° directions.
            for k in 0..8 {
                let angle = k as f64 * std::f64::consts::FRAC_PI_4;
                let end = Point2::new(
                    pad.x + (reach as f64 * angle.cos()).round() as i64,
                    pad.y + (reach as f64 * angle.sin()).round() as i64,
                );
                let mut seen: Vec<u32> = Vec::new();
                for h in layer.ring_edges.hits(pad, end) {
                    if seen.contains(&h.group) {
                        continue;
                    }
                    seen.push(h.group);
                    inserts[h.group as usize].push(Insert {
                        edge: h.edge as usize,
                        u: h.u,
                        point: h.point,
                    });
                    pad_links.push((pad, h.point));
                }
            }
        }
        for (ring, ins) in layer.rings.iter().zip(&inserts) {
            let pts = sample_ring(&ring.points, ins, spacing);
            let ids: Vec<VertexId> = pts.iter().map(|&p| graph.add_vertex(l, p).0).collect();
            for k in 0..ids.len() {
                graph.link(ids[k], ids[(k + 1) % ids.len()], ring.weight);
            }
        }
        if let Some((a, b)) = piece {
            add_direct(&mut graph, layer, a, b, &ring_hits, params, spacing, tol);
        }
        for &pad in &layer_pads {
            let (v, _) = graph.add_vertex(l, pad);
            if l == ends.from_layer && pad == ends.from && source.is_none() {
                source = Some(v);
            }
            if l == ends.to_layer && pad == ends.to {
                target = Some(v);
            }
            for &(_, q) in pad_links.iter().filter(|(p, _)| *p == pad) {
                if let Some(w) = layer.link_weight(pad, q, params, tol) {
                    // The ring's own sample of `q`, which may have been snapped to a vertex of
                    // the layer below.
                    let u = graph
                        .nearest(l, q, tol)
                        .unwrap_or_else(|| graph.add_vertex(l, q).0);
                    graph.link(v, u, w);
                }
            }
            for u in graph.within(l, graph.pos(v), step) {
                if let Some(w) = layer.link_weight(graph.pos(v), graph.pos(u), params, tol) {
                    graph.link(v, u, w);
                }
            }
        }
    }
    // The pads' layers are always in `layers`; should they not be, the pads still get vertices
    // (unconnected) so the search fails cleanly.
    let source = source.unwrap_or_else(|| graph.add_vertex(ends.from_layer, ends.from).0);
    let target = target.unwrap_or_else(|| graph.add_vertex(ends.to_layer, ends.to).0);
    (graph, source, target)
}

/// Largest distance between consecutive vertices along rings and sections, mm.
pub(crate) fn sample_spacing(params: &RouteParams) -> f64 {
    params
        .interlayer_overlap
        .min(params.grid_step)
        .max(params.align_tolerance * 4.0)
}

/// The point of `ring` nearest to `p`, if within `reach` scaled units.
fn nearest_on_ring(ring: &[Point2], p: Point2, reach: i64) -> Option<Insert> {
    let mut best: Option<(f64, Insert)> = None;
    for k in 0..ring.len() {
        let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
        let d = segment_distance(p, a, b);
        if d <= reach as f64 && best.as_ref().is_none_or(|(bd, _)| d < *bd) {
            let u = segment_param(p, a, b);
            best = Some((
                d,
                Insert {
                    edge: k,
                    u,
                    point: lerp(a, b, u),
                },
            ));
        }
    }
    best.map(|(_, i)| i)
}

/// Adds the direct connection `a`–`b` on `layer`: split at the rings (at the very points
/// inserted into them), the island boundaries and the keep-outs; each section weighted by where
/// it runs, or left out.
#[allow(clippy::too_many_arguments)]
fn add_direct(
    graph: &mut Graph,
    layer: &PreparedLayer,
    a: Point2,
    b: Point2,
    ring_hits: &[Hit],
    params: &RouteParams,
    spacing: f64,
    tol: i64,
) {
    let mut cuts: Vec<(f64, Point2)> = vec![(0.0, a), (1.0, b)];
    cuts.extend(ring_hits.iter().map(|h| (h.t, h.point)));
    cuts.extend(layer.material.hits(a, b).iter().map(|h| (h.t, h.point)));
    cuts.extend(layer.blocked.hits(a, b).iter().map(|h| (h.t, h.point)));
    // A stable sort: among equal parameters the section's ends and the ring points come first,
    // so a split point is the very point inserted into the ring.
    cuts.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut points: Vec<Point2> = Vec::new();
    for (_, p) in cuts {
        if points
            .last()
            .is_none_or(|&q| q.distance_squared(p) > (MERGE_NM as i128).pow(2))
        {
            points.push(p);
        }
    }
    for w in points.windows(2) {
        let (p, q) = (w[0], w[1]);
        // The section is split at every boundary, so its midpoint tells where all of it runs.
        let mid = lerp(p, q, 0.5);
        if layer.blocked.contains(mid) {
            continue;
        }
        let weight = if layer.material.inside_or_on(mid, tol) {
            params.base_weight
        } else if layer.same_island(p, q, tol) {
            params.outside_weight
        } else {
            continue;
        };
        let pts = supersample(p, q, spacing);
        let mut prev = None;
        for s in pts {
            let (v, _) = graph.add_vertex(layer.index, s);
            if let Some(u) = prev {
                graph.link(u, v, weight);
            }
            prev = Some(v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Polygon;

    fn square(x0: f64, s: f64) -> Polygon {
        Polygon::new(vec![
            Point2::from_mm(x0, x0),
            Point2::from_mm(x0 + s, x0),
            Point2::from_mm(x0 + s, x0 + s),
            Point2::from_mm(x0, x0 + s),
        ])
    }

    fn annulus_input(index: usize) -> LayerInput {
        let mut hole = square(15.0, 30.0);
        hole.points.reverse();
        let islands = vec![ExPolygon {
            contour: square(0.0, 60.0),
            holes: vec![hole],
        }];
        LayerInput::plain(
            index,
            0.2 * (index + 1) as f64,
            &islands,
            &RouteParams::default(),
        )
    }

    #[test]
    fn annulus_deflates_into_three_weighted_ring_pairs() {
        let params = RouteParams::default();
        let layer = PreparedLayer::new(&annulus_input(0), &params);
        assert_eq!(layer.rings.len(), 6);
        let weights: Vec<f64> = layer.rings.iter().map(|r| r.weight).collect();
        assert_eq!(weights, vec![3.0, 3.0, 2.0, 2.0, 1.0, 1.0]);
        // The innermost outer ring is 3·0.45 + 0.4 = 1.75 mm inside the outer wall.
        let x_min = |r: &Ring| r.points.iter().map(|p| p.x).min().unwrap_or(0);
        assert_eq!(x_min(&layer.rings[4]), scaled(1.75));
        assert!(layer.infill.contains(Point2::from_mm(5.0, 30.0)));
        assert!(!layer.infill.contains(Point2::from_mm(14.0, 30.0)));
        assert!(layer.clearance.contains(Point2::from_mm(14.0, 30.0)));
    }

    #[test]
    fn identical_layers_get_vertices_at_identical_xy() {
        let params = RouteParams::default();
        let layers: Vec<PreparedLayer> = (0..3)
            .map(|i| PreparedLayer::new(&annulus_input(i), &params))
            .collect();
        let ends = Ends {
            from: Point2::from_mm(5.0, 30.0),
            from_layer: 0,
            to: Point2::from_mm(55.0, 30.0),
            to_layer: 2,
        };
        let (graph, s, t) = build(&layers, &ends, &params);
        assert_eq!((graph.layer(s), graph.layer(t)), (0, 2));
        // Every vertex of layer 1 on a ring has a twin on layer 0 or 2 at exactly its xy.
        let mut twins = 0;
        for v in graph.verts.iter().filter(|v| v.layer == 1) {
            if graph.by_pos.contains_key(&(0, v.p.x, v.p.y))
                || graph.by_pos.contains_key(&(2, v.p.x, v.p.y))
            {
                twins += 1;
            }
        }
        let on_1 = graph.verts.iter().filter(|v| v.layer == 1).count();
        assert!(twins as f64 > 0.95 * on_1 as f64, "{twins} of {on_1}");
        // Apart from the pads' links, edges are at most min(overlap, grid step) long, plus what
        // snapping to a neighbour layer may add at both ends.
        let longest = scaled(sample_spacing(&params) + 2.0 * params.align_tolerance) as f64;
        for (v, edges) in graph.adj.iter().enumerate() {
            for e in edges.iter().filter(|e| ![s, t].contains(&e.to)) {
                if ![s, t].contains(&(v as VertexId)) {
                    assert!(dist(graph.pos(v as VertexId), graph.pos(e.to)) <= longest);
                }
            }
        }
    }

    #[test]
    fn rubberband_is_shared_out_by_layer() {
        let ends = Ends {
            from: Point2::from_mm(0.0, 0.0),
            from_layer: 2,
            to: Point2::from_mm(30.0, 0.0),
            to_layer: 4,
        };
        assert_eq!(ends.piece(1), None);
        assert_eq!(
            ends.piece(2),
            Some((Point2::from_mm(0.0, 0.0), Point2::from_mm(10.0, 0.0)))
        );
        assert_eq!(
            ends.piece(4),
            Some((Point2::from_mm(20.0, 0.0), Point2::from_mm(30.0, 0.0)))
        );
        let flat = Ends {
            to_layer: 2,
            ..ends
        };
        assert_eq!(flat.piece(3), Some((flat.from, flat.to)));
        assert_eq!(flat.piece(4), None);
    }

    #[test]
    fn sections_and_rings_a_billion_millimetres_long_are_sampled_boundedly() {
        let (a, b) = (Point2::from_mm(0.0, 0.0), Point2::from_mm(0.0, -1e9));
        let pts = supersample(a, b, 500_000.0);
        assert_eq!(pts.len(), MAX_SAMPLES as usize + 1);
        assert_eq!((pts[0], pts[pts.len() - 1]), (a, b));
        assert_eq!(
            supersample(a, Point2::from_mm(0.0, 2.0), 500_000.0).len(),
            5
        );
        let ring = [a, Point2::from_mm(1.0, 0.0), Point2::from_mm(1.0, -1e9), b];
        let n = sample_ring(&ring, &[], 500_000.0).len();
        assert!(n as f64 <= MAX_SAMPLES + 8.0, "{n}");
    }
}
