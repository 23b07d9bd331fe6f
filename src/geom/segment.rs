//! The point of a segment nearest to a point, and the distance to it: the one projection that
//! routing, infill clipping, simplification and toolpath grouping share.
//!
//! Place in the pipeline: vocabulary. Integer points are projected in `f64` nanometres: the
//! parameter is a ratio, so it cannot stay on the grid.

use super::Point2;

/// Parameter t ∈ [0, 1] of the point of the segment `a`–`b` nearest to `p` (0 for a segment of
/// zero length).
pub fn segment_param(p: Point2, a: Point2, b: Point2) -> f64 {
    let (dx, dy) = ((b.x - a.x) as f64, (b.y - a.y) as f64);
    let len2 = dx * dx + dy * dy;
    if len2 > 0.0 {
        (((p.x - a.x) as f64 * dx + (p.y - a.y) as f64 * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Squared distance (nm², as `f64`) from `p` to the segment `a`–`b`.
pub fn segment_distance2(p: Point2, a: Point2, b: Point2) -> f64 {
    let t = segment_param(p, a, b);
    let (dx, dy) = ((b.x - a.x) as f64, (b.y - a.y) as f64);
    let (ex, ey) = (
        a.x as f64 + t * dx - p.x as f64,
        a.y as f64 + t * dy - p.y as f64,
    );
    ex * ex + ey * ey
}

/// Distance (nm, as `f64`) from `p` to the segment `a`–`b`.
pub fn segment_distance(p: Point2, a: Point2, b: Point2) -> f64 {
    segment_distance2(p, a, b).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projects_inside_beyond_and_on_a_point_segment() {
        let (a, b) = (Point2::new(0, 0), Point2::new(10, 0));
        assert_eq!(segment_param(Point2::new(4, 3), a, b), 0.4);
        assert_eq!(segment_distance(Point2::new(4, 3), a, b), 3.0);
        // Beyond the ends the nearest point is the end.
        assert_eq!(segment_param(Point2::new(-6, 8), a, b), 0.0);
        assert_eq!(segment_distance(Point2::new(-6, 8), a, b), 10.0);
        assert_eq!(segment_param(Point2::new(13, 4), a, b), 1.0);
        assert_eq!(segment_distance2(Point2::new(13, 4), a, b), 25.0);
        // A segment of zero length is its point.
        assert_eq!(segment_distance(Point2::new(3, 4), a, a), 5.0);
    }
}
