//! From a found path to the reported trace: segments per layer with their staircase overlaps,
//! and the route's measures.
//!
//! Place in the pipeline: the end of one wire's search (`astar.rs`); its segments then become the
//! wire's channels (`channels.rs`).

use super::graph::{Graph, PreparedLayer, VertexId};
use super::index::RegionIndex;
use super::smooth::pull_taut;
use super::{Unrouted, Wire, WireRoute};
use crate::geom::{Point2, Point3, unscaled};

/// The report of a wire that could not be routed.
pub(crate) fn unrouted(wire: &Wire, reason: Unrouted) -> WireRoute {
    WireRoute {
        net: wire.net.clone(),
        routed: false,
        segments: Vec::new(),
        length: 0.0,
        lower_bound: (wire.to - wire.from).norm(),
        layer_changes: 0,
        perimeter_crossings: 0,
        ends_on_wire: None,
        reason: Some(reason),
        blockage: None,
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
        for m in region.stretch_midpoints(w[0], w[1]) {
            if !region.near_boundary(m, tol) {
                sides.push(region.contains(m));
            }
        }
    }
    sides.windows(2).filter(|s| s[0] != s[1]).count()
}

/// One visit of a layer by a route: the staircase piece it starts with (printed here too,
/// already counted on the layer before) and its own points.
struct Run {
    layer: usize,
    piece: Vec<Point2>,
    own: Vec<Point2>,
}

/// The route of `wire` along `path` (vertices from source to target, each with the staircase
/// piece of the layer change into it, if any), each layer's run pulled taut (`smooth.rs`);
/// `tol` (scaled units) is the boundary tolerance. With `end` (a point on the trace of another
/// wire of the net, and that wire) the route ends there, on the layer of the path's last
/// vertex, instead of at the `to` pad.
pub(crate) fn assemble(
    wire: &Wire,
    layers: &[PreparedLayer],
    graph: &Graph,
    path: &[(VertexId, Option<u32>)],
    overlaps: &[Vec<Point2>],
    tol: i64,
    end: Option<(Point2, usize)>,
) -> WireRoute {
    let lo = layers.first().map_or(0, |l| l.index);
    let z_of = |l: usize| layers[l - lo].z;
    let mut runs: Vec<Run> = Vec::new();
    for &(v, piece) in path {
        let (l, p) = (graph.layer(v), graph.pos(v));
        match runs.last_mut() {
            Some(run) if run.layer == l => {
                if run.own.last() != Some(&p) {
                    run.own.push(p);
                }
            }
            _ => runs.push(Run {
                layer: l,
                piece: match (runs.is_empty(), piece) {
                    (false, Some(k)) => overlaps[k as usize].clone(),
                    _ => Vec::new(),
                },
                own: vec![p],
            }),
        }
    }
    if let (Some((q, _)), Some(run)) = (end, runs.last_mut()) {
        if run.own.last() != Some(&q) {
            run.own.push(q);
        }
    }
    // Pull each run taut, keeping its ends and the points the next layer's piece repeats.
    for k in 0..runs.len() {
        let keep: Vec<Point2> = runs.get(k + 1).map_or(Vec::new(), |r| r.piece.clone());
        let run = &mut runs[k];
        let last = run.own.len().saturating_sub(1);
        let fixed: Vec<bool> = run
            .own
            .iter()
            .enumerate()
            .map(|(i, p)| i == 0 || i == last || keep.contains(p))
            .collect();
        run.own = pull_taut(&run.own, &fixed, &layers[run.layer - lo], tol);
    }
    let mut length = 0.0;
    let mut prev = wire.from;
    for run in &runs {
        for &p in &run.own {
            let here = at(p, z_of(run.layer));
            length += (here - prev).norm();
            prev = here;
        }
    }
    let finish = match (end, runs.last()) {
        (Some((q, _)), Some(run)) => at(q, z_of(run.layer)),
        _ => wire.to,
    };
    length += (finish - prev).norm();
    let layer_changes = runs.len().saturating_sub(1);
    let segments: Vec<(usize, Vec<Point2>)> = runs
        .into_iter()
        .map(|run| {
            let mut pts = run.piece;
            for p in run.own {
                if pts.last() != Some(&p) {
                    pts.push(p);
                }
            }
            (run.layer, pts)
        })
        .collect();
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
        lower_bound: (finish - wire.from).norm(),
        layer_changes,
        perimeter_crossings,
        ends_on_wire: end.map(|(_, w)| w),
        reason: None,
        blockage: None,
    }
}
