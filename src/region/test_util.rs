//! Fixtures and measurements shared by the region tests.

pub(crate) use super::infill::lines::contains;
use crate::geom::{ExPolygon, Point2, Polygon, Polyline};

/// An axis-aligned rectangle `[x0, x1] × [y0, y1]` (mm), counter-clockwise.
pub(crate) fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon {
    Polygon::new(vec![
        Point2::from_mm(x0, y0),
        Point2::from_mm(x1, y0),
        Point2::from_mm(x1, y1),
        Point2::from_mm(x0, y1),
    ])
}

/// An axis-aligned square `[x0, x0+side] × [y0, y0+side]` (mm), counter-clockwise.
pub(crate) fn square(x0: f64, y0: f64, side: f64) -> Polygon {
    rect(x0, y0, x0 + side, y0 + side)
}

/// A hole-free rectangular island.
pub(crate) fn rect_island(x0: f64, y0: f64, x1: f64, y1: f64) -> ExPolygon {
    ExPolygon {
        contour: rect(x0, y0, x1, y1),
        holes: vec![],
    }
}

/// A hole-free square island.
pub(crate) fn square_island(x0: f64, y0: f64, side: f64) -> ExPolygon {
    ExPolygon {
        contour: square(x0, y0, side),
        holes: vec![],
    }
}

/// Length of a polyline, mm.
pub(crate) fn polyline_length(p: &Polyline) -> f64 {
    points_length(&p.points)
}

/// Length of the open polyline through `points`, mm.
pub(crate) fn points_length(points: &[crate::geom::Point2]) -> f64 {
    crate::geom::polyline_length(points) / 1e6
}

/// Total length of polylines, mm.
pub(crate) fn total_length(lines: &[Polyline]) -> f64 {
    lines.iter().map(polyline_length).sum()
}

/// Net area of regions, mm².
pub(crate) fn total_area(a: &[ExPolygon]) -> f64 {
    a.iter().map(ExPolygon::area_mm2).sum()
}

/// `(min_x, min_y, max_x, max_y)` of a polygon, mm.
pub(crate) fn bounds(p: &Polygon) -> (f64, f64, f64, f64) {
    let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
    for q in &p.points {
        let (x, y) = q.to_mm();
        lo = (lo.0.min(x), lo.1.min(y));
        hi = (hi.0.max(x), hi.1.max(y));
    }
    (lo.0, lo.1, hi.0, hi.1)
}

/// Asserts that `p` is the axis-aligned square `[lo, hi]²` to within 2 nm, up to vertex order.
pub(crate) fn assert_square(p: &Polygon, lo: f64, hi: f64) {
    let (x0, y0, x1, y1) = bounds(p);
    for (got, want) in [(x0, lo), (y0, lo), (x1, hi), (y1, hi)] {
        assert!(
            (got - want).abs() < 2e-6,
            "bounds {:?} != [{lo}, {hi}]²",
            bounds(p)
        );
    }
    let area = (hi - lo) * (hi - lo);
    assert!(
        (p.area_mm2().abs() - area).abs() < 1e-4,
        "area {} != {area}",
        p.area_mm2()
    );
}
