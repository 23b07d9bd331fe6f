//! Smoothing a found route: straight shortcuts instead of the search's grid zigzags.
//!
//! Place in the pipeline: between the A* path (`astar.rs`) and the assembled trace
//! (`trace.rs`). The search moves on 45° grid steps and along decimated ring points, so a
//! diagonal run across open infill comes out as a staircase of grid edges, longer than it needs
//! to be (a conductive trace's resistance grows with its length) and with corners the nozzle
//! has to slow down for. Each run of a route on one layer is pulled taut like a string: from
//! each kept point the route jumps to the farthest later point it can reach in a straight line
//! that stays inside the layer's innermost deflated area (the infill region, where the search
//! lays its grid) and out of every keep-out. The innermost area keeps all `perimeters` widths of
//! plastic between a channel and the walls, holes and other nets' channels, as the perimeter
//! weights ask for, so a shortcut never trades the walls for length. Points that must stay
//! where they are — the pads, the staircase overlap pieces shared with the neighbour layers, and
//! points outside the innermost area (routes along the outer deflated traces, links into a pad
//! row, crossings of a hole) — are never skipped. Last, points that lie on the line between
//! their neighbours (supersampled straight sections) are dropped, so a straight run is one move.

use super::graph::PreparedLayer;
use super::index::{RegionIndex, dist};
use crate::geom::{Point2, segment_distance, segment_param};

/// Farthest a shortcut looks ahead, in route points: bounds the work per point on long runs.
const LOOKAHEAD: usize = 64;

/// Whether the segment `a`–`b` runs inside (or along the boundary of) `region`: every stretch
/// between boundary crossings has its midpoint inside or within `tol` of the boundary.
fn stays_inside(region: &RegionIndex, a: Point2, b: Point2, tol: i64) -> bool {
    region
        .stretch_midpoints(a, b)
        .into_iter()
        .all(|m| region.inside_or_on(m, tol))
}

/// Whether the route may run straight from `a` to `b` on `layer`. In a negotiation round (a
/// layer with a congestion history) the shortcut also keeps to one side of other nets'
/// keep-outs: the search priced the way in or round them, and a shortcut taken for free
/// would undo that.
fn shortcut_ok(layer: &PreparedLayer, a: Point2, b: Point2, tol: i64) -> bool {
    !layer.blocked_segment(a, b)
        && stays_inside(&layer.infill, a, b, tol)
        && (layer.history.is_none() || !layer.penalty.crosses(a, b))
}

/// The run `points` of a route on `layer`, pulled taut; `fixed[i]` marks points that must be
/// kept (the first and last always are). The result starts and ends where `points` does and
/// keeps every fixed point, in order.
pub(crate) fn pull_taut(
    points: &[Point2],
    fixed: &[bool],
    layer: &PreparedLayer,
    tol: i64,
) -> Vec<Point2> {
    if points.len() < 3 {
        return points.to_vec();
    }
    let movable = |i: usize| !fixed[i] && layer.infill.inside_or_on(points[i], tol);
    // Kept points with whether they are fixed.
    let mut out: Vec<(Point2, bool)> = vec![(points[0], true)];
    let mut i = 0;
    while i + 1 < points.len() {
        // The farthest j reachable in a straight line, skipping only movable points.
        let mut next = i + 1;
        let mut j = i + 2;
        while j < points.len() && j - i <= LOOKAHEAD && movable(j - 1) {
            if shortcut_ok(layer, points[i], points[j], tol) {
                next = j;
            }
            j += 1;
        }
        if out.last().is_none_or(|&(q, _)| dist(q, points[next]) > 0.0) {
            out.push((points[next], fixed[next] || next + 1 == points.len()));
        }
        i = next;
    }
    drop_collinear(out)
}

/// Points closer than this to the line through their neighbours are on it (scaled units: 1 µm,
/// far below the printer's resolution).
const COLLINEAR_NM: f64 = 1_000.0;

/// `points` without the ones that are not fixed and lie on the line between their kept
/// neighbours (supersampled straight sections, where no shortcut was needed), so each straight
/// run of a trace is one G-code move.
fn drop_collinear(points: Vec<(Point2, bool)>) -> Vec<Point2> {
    let mut kept: Vec<(Point2, bool)> = Vec::with_capacity(points.len());
    for (k, &(p, fixed)) in points.iter().enumerate() {
        let on_line = !fixed
            && kept.last().is_some_and(|&(prev, _)| {
                points.get(k + 1).is_some_and(|&(next, _)| {
                    segment_distance(p, prev, next) < COLLINEAR_NM
                        && segment_param(p, prev, next) > 0.0
                        && segment_param(p, prev, next) < 1.0
                })
            });
        if !on_line {
            kept.push((p, fixed));
        }
    }
    kept.into_iter().map(|(p, _)| p).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{ExPolygon, Polygon};
    use crate::route::RouteParams;
    use crate::route::graph::LayerInput;

    fn plate() -> PreparedLayer {
        let square = ExPolygon {
            contour: Polygon::new(vec![
                Point2::from_mm(0.0, 0.0),
                Point2::from_mm(40.0, 0.0),
                Point2::from_mm(40.0, 40.0),
                Point2::from_mm(0.0, 40.0),
            ]),
            holes: Vec::new(),
        };
        let params = RouteParams::default();
        let input = LayerInput::plain(0, 0.2, &[square], &params);
        PreparedLayer::new(&input, &params)
    }

    #[test]
    fn a_staircase_in_open_material_becomes_one_segment() {
        let layer = plate();
        // 10 steps right-up in 1 mm grid moves from (10, 10) to (20, 15).
        let mut pts = vec![Point2::from_mm(10.0, 10.0)];
        for k in 0..5 {
            let x = 10.0 + 2.0 * k as f64;
            let y = 10.0 + k as f64;
            pts.push(Point2::from_mm(x + 1.0, y));
            pts.push(Point2::from_mm(x + 2.0, y + 1.0));
        }
        let fixed = vec![false; pts.len()];
        let out = pull_taut(&pts, &fixed, &layer, 50_000);
        assert_eq!(out, vec![pts[0], pts[pts.len() - 1]]);
    }

    #[test]
    fn fixed_points_stay_and_walls_are_not_cut() {
        let layer = plate();
        // A straight run with a fixed point in the middle: that point stays.
        let pts = vec![
            Point2::from_mm(5.0, 10.0),
            Point2::from_mm(8.0, 10.0),
            Point2::from_mm(12.0, 10.0),
            Point2::from_mm(15.0, 10.0),
            Point2::from_mm(20.0, 10.0),
        ];
        let mut fixed = vec![false; pts.len()];
        fixed[2] = true;
        let out = pull_taut(&pts, &fixed, &layer, 50_000);
        assert_eq!(out, vec![pts[0], pts[2], pts[4]]);
        // A point outside the innermost deflated area (1.75 mm in from the wall) is kept.
        let edge = vec![
            Point2::from_mm(5.0, 5.0),
            Point2::from_mm(6.0, 1.5),
            Point2::from_mm(7.0, 5.0),
        ];
        let out = pull_taut(&edge, &[false; 3], &layer, 50_000);
        assert_eq!(out, edge);
    }

    #[test]
    fn straight_runs_outside_the_infill_become_one_move() {
        let layer = plate();
        // Supersampled along the wall, 1 mm in: outside the innermost area, so no shortcut is
        // tried, but the points between the ends lie on the line and add nothing.
        let pts: Vec<Point2> = (0..=10)
            .map(|k| Point2::from_mm(5.0 + 0.5 * k as f64, 1.0))
            .collect();
        let out = pull_taut(&pts, &[false; 11], &layer, 50_000);
        assert_eq!(out, vec![pts[0], pts[10]]);
        // A fixed point on the line stays.
        let mut fixed = [false; 11];
        fixed[4] = true;
        let out = pull_taut(&pts, &fixed, &layer, 50_000);
        assert_eq!(out, vec![pts[0], pts[4], pts[10]]);
    }
}
