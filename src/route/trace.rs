//! From a found path to the reported trace: segments per layer with their staircase overlaps,
//! and the route's measures.
//!
//! Place in the pipeline: the end of one wire's search (`astar.rs`); its segments then become the
//! wire's channels (`channels.rs`).

use super::graph::{Graph, PreparedLayer, VertexId};
use super::index::{RegionIndex, lerp};
use super::{Wire, WireRoute};
use crate::geom::{Point2, Point3, unscaled};

/// The report of a wire that could not be routed.
pub(crate) fn unrouted(wire: &Wire) -> WireRoute {
    WireRoute {
        net: wire.net.clone(),
        routed: false,
        segments: Vec::new(),
        length: 0.0,
        lower_bound: (wire.to - wire.from).norm(),
        layer_changes: 0,
        perimeter_crossings: 0,
    }
}

fn at(p: Point2, z: f64) -> Point3 {
    Point3::new(unscaled(p.x), unscaled(p.y), z)
}

/// How many times the polyline passes between inside and outside of `region`. The polyline is
/// cut at every point where it meets the boundary; each piece is inside or outside by its
/// midpoint, pieces along the boundary (within `tol`) are skipped, and every change of side
/// between consecutive pieces is one crossing. (Route vertices often lie exactly on the boundary,
/// where a segment-by-segment crossing test would see only touching.)
fn boundary_crossings(points: &[Point2], region: &RegionIndex, tol: i64) -> usize {
    let mut sides: Vec<bool> = Vec::new();
    for w in points.windows(2) {
        let (a, b) = (w[0], w[1]);
        let mut ts: Vec<f64> = vec![0.0, 1.0];
        ts.extend(region.hits(a, b).iter().map(|h| h.t));
        ts.sort_by(f64::total_cmp);
        for t in ts.windows(2).filter(|t| t[1] > t[0]) {
            let m = lerp(a, b, (t[0] + t[1]) / 2.0);
            if !region.near_boundary(m, tol) {
                sides.push(region.contains(m));
            }
        }
    }
    sides.windows(2).filter(|s| s[0] != s[1]).count()
}

/// The route of `wire` along `path` (vertices from source to target, each with the staircase
/// piece of the layer change into it, if any); `tol` (scaled units) is the boundary tolerance.
pub(crate) fn assemble(
    wire: &Wire,
    layers: &[PreparedLayer],
    graph: &Graph,
    path: &[(VertexId, Option<u32>)],
    overlaps: &[Vec<Point2>],
    tol: i64,
) -> WireRoute {
    let lo = layers.first().map_or(0, |l| l.index);
    let z_of = |l: usize| layers[l - lo].z;
    let mut segments: Vec<(usize, Vec<Point2>)> = Vec::new();
    let mut length = 0.0;
    let mut layer_changes = 0;
    let mut prev: Option<Point3> = Some(wire.from);
    for &(v, piece) in path {
        let (l, p) = (graph.layer(v), graph.pos(v));
        let here = at(p, z_of(l));
        if let Some(q) = prev {
            length += (here - q).norm();
        }
        prev = Some(here);
        match segments.last_mut() {
            Some((sl, pts)) if *sl == l => {
                if pts.last() != Some(&p) {
                    pts.push(p);
                }
            }
            _ => {
                let mut pts: Vec<Point2> = Vec::new();
                if !segments.is_empty() {
                    layer_changes += 1;
                    if let Some(k) = piece {
                        pts.extend(overlaps[k as usize].iter().copied());
                    }
                }
                if pts.last() != Some(&p) {
                    pts.push(p);
                }
                segments.push((l, pts));
            }
        }
    }
    if let Some(q) = prev {
        length += (wire.to - q).norm();
    }
    let perimeter_crossings = segments
        .iter()
        .map(|(l, pts)| boundary_crossings(pts, &layers[l - lo].material, tol))
        .sum();
    WireRoute {
        net: wire.net.clone(),
        routed: true,
        segments: segments
            .into_iter()
            .map(|(l, pts)| {
                let z = z_of(l);
                (l, pts.into_iter().map(|p| at(p, z)).collect())
            })
            .collect(),
        length,
        lower_bound: (wire.to - wire.from).norm(),
        layer_changes,
        perimeter_crossings,
    }
}
