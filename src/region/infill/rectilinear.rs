//! Rectilinear infill: parallel lines, turned 90° every layer.

use super::InfillPattern;
use super::lines::{LineFamily, fill_family};
use crate::geom::{ExPolygon, Polyline};

/// Parallel lines at `angle_deg` on even layers and `angle_deg + 90°` on odd layers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rectilinear {
    /// Direction of the lines on even layers, degrees counter-clockwise from +X.
    pub angle_deg: f64,
    /// Join neighbouring lines into zig-zags along the boundary.
    pub connect: bool,
}

impl Rectilinear {
    /// Rectilinear infill based on `angle_deg`, joined into zig-zags.
    pub fn new(angle_deg: f64) -> Self {
        Self {
            angle_deg,
            connect: true,
        }
    }
}

impl InfillPattern for Rectilinear {
    fn name(&self) -> &'static str {
        "rectilinear"
    }

    fn fill(&self, area: &[ExPolygon], spacing_mm: f64, layer_index: usize) -> Vec<Polyline> {
        let turn = if layer_index % 2 == 1 { 90.0 } else { 0.0 };
        let family = LineFamily {
            angle_rad: (self.angle_deg + turn).to_radians(),
            spacing_mm,
            phase: 0.5,
        };
        fill_family(area, family, self.connect)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point2;
    use crate::region::test_util::{polyline_length, square_island};

    /// Segments of `lines` at least `min_mm` long, as (start, end).
    fn long_segments(lines: &[Polyline], min_mm: f64) -> Vec<(Point2, Point2)> {
        lines
            .iter()
            .flat_map(|l| l.points.windows(2).map(|w| (w[0], w[1])))
            .filter(|(a, b)| (a.distance_squared(*b) as f64).sqrt() / 1e6 >= min_mm)
            .collect()
    }

    #[test]
    fn solid_fill_of_a_ten_mm_square_alternates_direction() {
        let area = [square_island(0.0, 0.0, 10.0)];
        for s in [0.407_079_6_f64, 0.45, 1.0, 3.3] {
            let expected = (10.0 / s).floor();
            for connect in [false, true] {
                let p = Rectilinear {
                    angle_deg: 0.0,
                    connect,
                };
                for layer in [0, 1] {
                    let lines = p.fill(&area, s, layer);
                    let segs = long_segments(&lines, 9.0);
                    let n = segs.len() as f64;
                    assert!(
                        (n - expected).abs() <= 1.0,
                        "s {s}, layer {layer}: {n} lines"
                    );
                    for (a, b) in &segs {
                        let len = (a.distance_squared(*b) as f64).sqrt() / 1e6;
                        assert!((len - 10.0).abs() < 1e-5, "length {len}");
                        if layer == 0 {
                            assert_eq!(a.y, b.y, "layer 0 lines are horizontal");
                        } else {
                            assert_eq!(a.x, b.x, "layer 1 lines are vertical");
                        }
                    }
                    if connect {
                        // One zig-zag: every other segment is a connector of length s, and an
                        // anchor at each end runs to the corner beside it; the two anchors
                        // and the connectors together make one side of the square.
                        assert_eq!(lines.len(), 1, "s {s}");
                        let total = polyline_length(&lines[0]);
                        assert!((total - (10.0 * n + 10.0)).abs() < 1e-4, "{total}");
                    } else {
                        assert_eq!(lines.len(), segs.len());
                    }
                }
            }
        }
    }

    #[test]
    fn lines_share_a_global_lattice_across_areas() {
        // Two squares side by side get lines at the same heights.
        let p = Rectilinear {
            angle_deg: 0.0,
            connect: false,
        };
        let ys = |x0: f64| {
            let mut v: Vec<i64> = p
                .fill(&[square_island(x0, 0.0, 10.0)], 0.5, 0)
                .iter()
                .map(|l| l.points[0].y)
                .collect();
            v.sort_unstable();
            v
        };
        assert_eq!(ys(0.0), ys(10.0));
        assert_eq!(ys(0.0)[0], crate::geom::scaled(0.25));
    }
}
