//! Triangles infill: three line families at 60° that meet in common points, on every layer.
//!
//! With unit normals `n₀, n₁, n₂` of the families at `θ+90°, θ+150°, θ+210°`, `n₂ = n₁ − n₀`, so
//! if family 0 and 1 lines sit at `(k + ½)·S` and family 2 lines at `m·S`, every crossing of a
//! family-0 and a family-1 line also lies on a family-2 line: the lines form equilateral
//! triangles instead of a mesh of small stars. See the module docs of [`super`] for why this is
//! the third pattern.

use super::InfillPattern;
use super::lines::{LineFamily, fill_family};
use crate::geom::{ExPolygon, Polyline};

/// Lines at `angle_deg`, `+60°` and `+120°` on every layer, each family `3 · spacing` apart so the
/// density matches rectilinear's at the same spacing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triangles {
    /// Direction of the first family, degrees counter-clockwise from +X.
    pub angle_deg: f64,
    /// Join neighbouring lines of a family into zig-zags along the boundary.
    pub connect: bool,
}

impl Triangles {
    /// Triangles infill based on `angle_deg`, joined into zig-zags.
    pub fn new(angle_deg: f64) -> Self {
        Self {
            angle_deg,
            connect: true,
        }
    }
}

impl InfillPattern for Triangles {
    fn name(&self) -> &'static str {
        "triangles"
    }

    fn fill(&self, area: &[ExPolygon], spacing_mm: f64, _layer_index: usize) -> Vec<Polyline> {
        [(0.0, 0.5), (60.0, 0.5), (120.0, 0.0)]
            .into_iter()
            .flat_map(|(turn, phase)| {
                let family = LineFamily {
                    angle_rad: (self.angle_deg + turn).to_radians(),
                    spacing_mm: 3.0 * spacing_mm,
                    phase,
                };
                fill_family(area, family, self.connect)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point2;
    use crate::region::test_util::square_island;

    /// Crossing point of the infinite lines through segments `a` and `b`.
    fn crossing(a: (Point2, Point2), b: (Point2, Point2)) -> Option<(f64, f64)> {
        let f = |p: Point2| (p.x as f64, p.y as f64);
        let ((x1, y1), (x2, y2), (x3, y3), (x4, y4)) = (f(a.0), f(a.1), f(b.0), f(b.1));
        let den = (x1 - x2) * (y3 - y4) - (y1 - y2) * (x3 - x4);
        if den.abs() < 1.0 {
            return None;
        }
        let t = ((x1 - x3) * (y3 - y4) - (y1 - y3) * (x3 - x4)) / den;
        Some((x1 + t * (x2 - x1), y1 + t * (y2 - y1)))
    }

    #[test]
    fn three_families_meet_in_common_points() {
        let p = Triangles {
            angle_deg: 0.0,
            connect: false,
        };
        let lines = p.fill(&[square_island(0.0, 0.0, 30.0)], 1.0, 0);
        let dir = |l: &Polyline| {
            let (a, b) = (l.points[0], l.points[l.points.len() - 1]);
            let deg = ((b.y - a.y) as f64)
                .atan2((b.x - a.x) as f64)
                .to_degrees()
                .rem_euclid(180.0);
            (deg / 60.0).round() as usize % 3
        };
        // Pieces at least 5 mm long, so the nanometre rounding of their ends does not tilt them
        // enough to matter over the 30 mm square.
        let family = |f: usize| -> Vec<(Point2, Point2)> {
            lines
                .iter()
                .filter(|l| {
                    dir(l) == f && l.points[0].distance_squared(l.points[1]) >= 25_000_000_000_000
                })
                .map(|l| (l.points[0], l.points[1]))
                .collect()
        };
        let (f0, f1, f2) = (family(0), family(1), family(2));
        assert!(!f0.is_empty() && !f1.is_empty() && !f2.is_empty());
        // Horizontal lines at (k + ½)·3 mm.
        for (a, _) in &f0 {
            let k = a.y as f64 / 3e6 - 0.5;
            assert!((k - k.round()).abs() < 1e-6, "{a:?}");
        }
        // Every crossing (inside the square) of a family-0 and a family-1 line is within 20 nm of
        // a family-2 line.
        let mut checked = 0;
        let n2 = (210f64.to_radians().cos(), 210f64.to_radians().sin());
        for &a in &f0 {
            for &b in &f1 {
                let Some((x, y)) = crossing(a, b) else {
                    continue;
                };
                if !(0.0..=30e6).contains(&x) || !(0.0..=30e6).contains(&y) {
                    continue;
                }
                checked += 1;
                let c = (x * n2.0 + y * n2.1) / 3e6;
                assert!(
                    (c - c.round()).abs() * 3e6 < 20.0,
                    "crossing ({x}, {y}) of {a:?} {b:?} off the lattice: {c}"
                );
            }
        }
        assert!(checked > 50, "{checked}");
    }
}
