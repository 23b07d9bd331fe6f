//! Skirt: loops around everything printed on the first layer, to prime the nozzle and show the
//! first-layer adhesion before the part starts.
//!
//! The first layer's islands are united with their holes filled (the skirt never goes inside a
//! part), then grown so that the *inner edge* of the innermost loop is exactly `skirt_distance`
//! from the nearest island: loop `j` (0 = innermost) has its centreline at
//! `skirt_distance + perimeter_width / 2 + j · perimeter_spacing`. Growing uses round joins
//! flattened to [`Tolerances::curve_flattening`](crate::geom::Tolerances). Islands closer than
//! about twice that distance share loops.

use super::params::RegionParams;
use super::perimeters::oriented;
use crate::geom::{ExPolygon, FillRule, Join, Polygon, Tolerances, offset, polygons_to_expolygons};

/// Skirt loops around `first_layer` (the first layer's islands) for a first layer `height` mm
/// high, outermost first (the order a printer primes in), each counter-clockwise.
pub fn make_skirt(first_layer: &[ExPolygon], params: &RegionParams, height: f64) -> Vec<Polygon> {
    if params.skirt_loops == 0 || first_layer.is_empty() {
        return Vec::new();
    }
    let contours: Vec<Polygon> = first_layer
        .iter()
        .map(|e| oriented(e.contour.clone(), true))
        .collect();
    let base = polygons_to_expolygons(&contours, FillRule::NonZero);
    let spacing = params.spacings(height).perimeter;
    let join = Join::Round(Tolerances::default().curve_flattening.mm());
    let mut loops: Vec<Polygon> = Vec::new();
    for j in (0..params.skirt_loops).rev() {
        let distance = params.skirt_distance + params.perimeter_width / 2.0 + j as f64 * spacing;
        loops.extend(
            offset(&base, distance, join)
                .into_iter()
                .map(|e| oriented(e.contour, true)),
        );
    }
    loops
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::{bounds, rect, square_island};

    #[test]
    fn skirt_keeps_its_distance_exactly() {
        let params = RegionParams {
            skirt_loops: 2,
            ..Default::default()
        };
        let spacing = params.spacings(0.2).perimeter;
        let skirt = make_skirt(&[square_island(0.0, 0.0, 20.0)], &params, 0.2);
        assert_eq!(skirt.len(), 2);
        // Innermost loop (printed last): straight sides at 6 + 0.225 from the square.
        let d = 6.0 + 0.225;
        let (x0, y0, x1, y1) = bounds(&skirt[1]);
        for (got, want) in [(x0, -d), (y0, -d), (x1, 20.0 + d), (y1, 20.0 + d)] {
            assert!((got - want).abs() < 1e-6, "{got} != {want}");
        }
        // Its inner edge is exactly skirt_distance from the part.
        assert!((-x0 - params.perimeter_width / 2.0 - 6.0).abs() < 1e-6);
        let (ox0, ..) = bounds(&skirt[0]);
        assert!((-ox0 - (d + spacing)).abs() < 1e-6);
        // Rounded corners: the area is the square grown by d with round corners, within the
        // flattening tolerance.
        let a = skirt[1].area_mm2();
        let exact = 400.0 + 4.0 * 20.0 * d + std::f64::consts::PI * d * d;
        assert!(skirt.iter().all(Polygon::is_counter_clockwise));
        assert!(
            a < exact && a > exact - 2.0 * std::f64::consts::PI * d * 0.005,
            "{a} vs {exact}"
        );
    }

    #[test]
    fn skirt_goes_around_holes_not_into_them_and_merges_close_islands() {
        let params = RegionParams {
            skirt_loops: 1,
            skirt_distance: 2.0,
            ..Default::default()
        };
        let mut ring = square_island(0.0, 0.0, 20.0);
        let mut hole = rect(5.0, 5.0, 15.0, 15.0);
        hole.points.reverse();
        ring.holes.push(hole);
        let near = square_island(22.0, 0.0, 5.0);
        let skirt = make_skirt(&[ring, near], &params, 0.2);
        // One loop around both (they are 2 mm apart), none in the 10 mm hole: every point is
        // at least skirt_distance outside the ring's outline.
        assert_eq!(skirt.len(), 1);
        for p in &skirt[0].points {
            let (x, y) = p.to_mm();
            let (dx, dy) = ((-x).max(x - 20.0).max(0.0), (-y).max(y - 20.0).max(0.0));
            let clear = dx.hypot(dy) >= 2.0 + 0.225 - 0.005;
            assert!(
                clear || x > 20.0,
                "skirt point ({x}, {y}) too close to the ring"
            );
        }
        assert!(make_skirt(&[], &params, 0.2).is_empty());
        let none = RegionParams::default();
        assert!(make_skirt(&[square_island(0.0, 0.0, 5.0)], &none, 0.2).is_empty());
    }
}
