//! Grid infill: lines in two perpendicular directions on every layer.

use super::InfillPattern;
use super::lines::{LineFamily, fill_family};
use crate::geom::{ExPolygon, Polyline};

/// Lines at `angle_deg` and `angle_deg + 90°` on every layer, each family `2 · spacing` apart so
/// the density matches rectilinear's at the same spacing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Direction of the first family, degrees counter-clockwise from +X.
    pub angle_deg: f64,
    /// Join neighbouring lines of a family into zig-zags along the boundary.
    pub connect: bool,
}

impl Grid {
    /// Grid infill based on `angle_deg`, joined into zig-zags.
    pub fn new(angle_deg: f64) -> Self {
        Self {
            angle_deg,
            connect: true,
        }
    }
}

impl InfillPattern for Grid {
    fn name(&self) -> &'static str {
        "grid"
    }

    fn fill(&self, area: &[ExPolygon], spacing_mm: f64, _layer_index: usize) -> Vec<Polyline> {
        [0.0, 90.0]
            .into_iter()
            .flat_map(|turn| {
                let family = LineFamily {
                    angle_rad: (self.angle_deg + turn).to_radians(),
                    spacing_mm: 2.0 * spacing_mm,
                    phase: 0.5,
                };
                fill_family(area, family, self.connect)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::square_island;

    #[test]
    fn both_directions_at_twice_the_spacing() {
        let p = Grid {
            angle_deg: 0.0,
            connect: false,
        };
        let lines = p.fill(&[square_island(0.0, 0.0, 10.0)], 1.0, 3);
        let horizontal = lines
            .iter()
            .filter(|l| l.points[0].y == l.points[1].y)
            .count();
        let vertical = lines
            .iter()
            .filter(|l| l.points[0].x == l.points[1].x)
            .count();
        // Lines at 1, 3, 5, 7, 9 mm in each direction.
        assert_eq!((horizontal, vertical, lines.len()), (5, 5, 10));
        assert_eq!(p.fill(&[square_island(0.0, 0.0, 10.0)], 1.0, 4), lines);
    }
}
