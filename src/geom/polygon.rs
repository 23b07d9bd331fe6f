//! Closed polygons, polygons with holes and open polylines in scaled integer coordinates.

use super::point::Point2;

/// Length of the open polyline through `points`, scaled units.
pub fn polyline_length(points: &[Point2]) -> f64 {
    points
        .windows(2)
        .map(|w| (w[0].distance_squared(w[1]) as f64).sqrt())
        .sum()
}

/// A closed polygon; the last point connects back to the first (it is not repeated).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Polygon {
    /// The vertices in order.
    pub points: Vec<Point2>,
}

impl Polygon {
    /// A polygon from its vertices.
    pub fn new(points: Vec<Point2>) -> Self {
        Self { points }
    }

    /// The convex hull of `points` (Andrew's monotone chain, exact in integers),
    /// counter-clockwise, without collinear vertices; fewer than three distinct points are
    /// returned as they are, sorted.
    pub fn convex_hull(points: &[Point2]) -> Self {
        let mut pts = points.to_vec();
        pts.sort_unstable();
        pts.dedup();
        if pts.len() < 3 {
            return Self::new(pts);
        }
        let mut hull: Vec<Point2> = Vec::with_capacity(pts.len() + 1);
        for pass in 0..2 {
            let start = hull.len();
            let iter: Box<dyn Iterator<Item = &Point2>> = if pass == 0 {
                Box::new(pts.iter())
            } else {
                Box::new(pts.iter().rev())
            };
            for &p in iter {
                while hull.len() >= start + 2
                    && hull[hull.len() - 2].cross(hull[hull.len() - 1], p) <= 0
                {
                    hull.pop();
                }
                hull.push(p);
            }
            hull.pop(); // the last point starts the other chain
        }
        Self::new(hull)
    }

    /// Twice the signed area in square nanometres (positive when counter-clockwise), exact.
    pub fn signed_area2(&self) -> i128 {
        let n = self.points.len();
        (0..n)
            .map(|i| {
                let a = self.points[i];
                let b = self.points[(i + 1) % n];
                a.x as i128 * b.y as i128 - b.x as i128 * a.y as i128
            })
            .sum()
    }

    /// The vertices as `[x, y]` in mm.
    pub fn points_mm(&self) -> Vec<[f64; 2]> {
        self.points
            .iter()
            .map(|p| {
                let (x, y) = p.to_mm();
                [x, y]
            })
            .collect()
    }

    /// Signed area in mm² (positive when counter-clockwise).
    pub fn area_mm2(&self) -> f64 {
        self.signed_area2() as f64 / 2.0 / 1e12
    }

    /// The width (mm) of a strip with this polygon's area and half its perimeter, `2A/P`: a
    /// long band's width, a disc's radius. Near 0 for the slivers booleans leave where two
    /// operands' edges almost coincide. 0 for a polygon of fewer than three points.
    pub fn mean_width_mm(&self) -> f64 {
        let (Some(&first), Some(&last)) = (self.points.first(), self.points.last()) else {
            return 0.0;
        };
        let closing = (first.distance_squared(last) as f64).sqrt();
        let perimeter_mm = (polyline_length(&self.points) + closing) / super::point::UNITS_PER_MM;
        if self.points.len() < 3 || perimeter_mm <= 0.0 {
            return 0.0;
        }
        2.0 * self.area_mm2().abs() / perimeter_mm
    }

    /// Whether the vertices run counter-clockwise.
    pub fn is_counter_clockwise(&self) -> bool {
        self.signed_area2() > 0
    }

    /// Whether `p` is inside (even-odd crossing test, exact in `i128`; points on the boundary
    /// may go either way).
    pub fn contains(&self, p: Point2) -> bool {
        let pts = &self.points;
        let mut result = false;
        for i in 0..pts.len() {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            if (a.y > p.y) != (b.y > p.y) {
                let lhs = (p.x - a.x) as i128 * (b.y - a.y) as i128;
                let rhs = (b.x - a.x) as i128 * (p.y - a.y) as i128;
                if (lhs < rhs) == (b.y > a.y) {
                    result = !result;
                }
            }
        }
        result
    }
}

/// An outer contour (counter-clockwise) with holes (clockwise).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ExPolygon {
    /// The outer boundary.
    pub contour: Polygon,
    /// The holes inside it.
    pub holes: Vec<Polygon>,
}

impl ExPolygon {
    /// Net area in mm²: the contour minus the holes.
    pub fn area_mm2(&self) -> f64 {
        self.contour.area_mm2().abs() - self.holes.iter().map(|h| h.area_mm2().abs()).sum::<f64>()
    }

    /// Whether `p` is inside the contour and outside every hole (points on a boundary may go
    /// either way).
    pub fn contains(&self, p: Point2) -> bool {
        self.contour.contains(p) && !self.holes.iter().any(|h| h.contains(p))
    }
}

/// An open chain of points.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Polyline {
    /// The points in order.
    pub points: Vec<Point2>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_with_hole_has_analytic_area() {
        let sq = |s: f64| {
            Polygon::new(vec![
                Point2::from_mm(0.0, 0.0),
                Point2::from_mm(s, 0.0),
                Point2::from_mm(s, s),
                Point2::from_mm(0.0, s),
            ])
        };
        let outer = sq(10.0);
        assert!(outer.is_counter_clockwise());
        assert_eq!(outer.area_mm2(), 100.0);
        let mut hole = sq(2.0);
        hole.points.reverse();
        assert!(!hole.is_counter_clockwise());
        let ex = ExPolygon {
            contour: outer,
            holes: vec![hole],
        };
        assert_eq!(ex.area_mm2(), 96.0);
        // Inside the contour, in the hole, outside.
        assert!(ex.contains(Point2::from_mm(5.0, 5.0)));
        assert!(!ex.contains(Point2::from_mm(1.0, 1.0)));
        assert!(!ex.contains(Point2::from_mm(11.0, 5.0)));
        assert!(ex.contour.contains(Point2::from_mm(1.0, 1.0)));
    }

    #[test]
    fn mean_width_is_a_bands_width_and_tells_slivers() {
        let rect = |w: f64, h: f64| {
            Polygon::new(vec![
                Point2::from_mm(0.0, 0.0),
                Point2::from_mm(w, 0.0),
                Point2::from_mm(w, h),
                Point2::from_mm(0.0, h),
            ])
        };
        // 2A/P of a 10 × 1 band: 20 / 22.
        assert!((rect(10.0, 1.0).mean_width_mm() - 20.0 / 22.0).abs() < 1e-12);
        // A 10 mm long triangle 3 nm high, as a boolean leaves between near-coincident edges.
        let sliver = Polygon::new(vec![
            Point2::new(0, 0),
            Point2::new(10_000_000, 0),
            Point2::new(5_000_000, 3),
        ]);
        assert!(sliver.mean_width_mm() < 1e-5);
        assert_eq!(
            Polygon::new(vec![Point2::new(0, 0), Point2::new(5, 5)]).mean_width_mm(),
            0.0
        );
        assert_eq!(Polygon::default().mean_width_mm(), 0.0);
    }
}
