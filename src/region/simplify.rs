//! Douglas–Peucker simplification of the sliced islands before any offset.
//!
//! Meshes such as 3DBenchy are finely tessellated: their slices carry hundreds of points per
//! millimetre of contour, most of them within a few micrometres of the chord through their
//! neighbours (265 000 points on Benchy, 41 000 left at 5 µm).
//! Every inward offset builds one segment per edge plus a spike back to each inner corner, so the
//! offset's cost grows with the number of edges *and* with the offset distance over the edge
//! length (the spikes cross more and more offset edges). Simplifying the islands once, with
//! PrusaSlicer's default `gcode_resolution` of 0.0125 mm (its `PerimeterGenerator` does the same
//! with `simplify_p(m_scaled_resolution)`), cuts Benchy's 265 000 island points to 30 000 and the
//! regions stage's offsets by more than ten times, while no point moves further than the
//! tolerance.

use crate::geom::{ExPolygon, Point2, Polygon, scaled, segment_distance2, union};

/// Largest distance (mm) a simplified contour may stray from the sliced one: PrusaSlicer's
/// default `gcode_resolution`.
pub const RESOLUTION_MM: f64 = 0.0125;

/// Largest distance (mm) a point dropped by [`cleaned`] lies from its neighbours' chord.
///
/// i_overlay's offsets return every point where its segments were split, rounded to the
/// nanometre, so straight runs come back as chains of nearly collinear points: on Benchy two
/// thirds of an infill area's points lie within 0.2 µm of their neighbours' chord. Feeding those to
/// the next offset made it about ten times slower; dropping them at 1 µm changes no region by a
/// printable amount.
pub const CLEANUP_MM: f64 = 0.001;

/// The points of the open chain `points` that Douglas–Peucker keeps at `tolerance` (nm): both
/// ends, and recursively the point farthest from the chord while it is farther than `tolerance`.
fn douglas_peucker(points: &[Point2], tolerance: f64) -> Vec<Point2> {
    let n = points.len();
    if n < 3 {
        return points.to_vec();
    }
    let mut keep = vec![false; n];
    (keep[0], keep[n - 1]) = (true, true);
    let limit = tolerance * tolerance;
    let mut stack = vec![(0, n - 1)];
    while let Some((a, b)) = stack.pop() {
        let (mut far, mut far_d) = (0, limit);
        for (i, &p) in points.iter().enumerate().take(b).skip(a + 1) {
            let d = segment_distance2(p, points[a], points[b]);
            if d > far_d {
                (far, far_d) = (i, d);
            }
        }
        if far != 0 {
            keep[far] = true;
            stack.push((a, far));
            stack.push((far, b));
        }
    }
    points
        .iter()
        .zip(keep)
        .filter_map(|(&p, k)| k.then_some(p))
        .collect()
}

/// `ring` simplified as a closed chain from its first point back to it; `None` when fewer than
/// three points remain.
fn simplify_ring(ring: &Polygon, tolerance: f64) -> Option<Polygon> {
    let mut closed = Vec::with_capacity(ring.points.len() + 1);
    closed.extend_from_slice(&ring.points);
    closed.push(*ring.points.first()?);
    let mut points = douglas_peucker(&closed, tolerance);
    points.pop();
    (points.len() >= 3).then(|| Polygon::new(points))
}

/// `areas` (results of an offset) with their nearly collinear points dropped, to within
/// [`CLEANUP_MM`]. Unlike [`simplify_islands`] the result is not re-united: at a micrometre the
/// rings cannot cross anything they did not cross before except by that much, and every consumer
/// (offsets, booleans, extrusion loops) copes with that.
pub fn cleaned(areas: Vec<ExPolygon>) -> Vec<ExPolygon> {
    let tolerance = scaled(CLEANUP_MM) as f64;
    areas
        .into_iter()
        .filter_map(|ex| {
            Some(ExPolygon {
                contour: simplify_ring(&ex.contour, tolerance)?,
                holes: ex
                    .holes
                    .iter()
                    .filter_map(|h| simplify_ring(h, tolerance))
                    .collect(),
            })
        })
        .collect()
}

/// `islands` with every ring simplified to within `tolerance_mm`. When a point was dropped the
/// result is re-united, so rings that the simplification made touch or cross stay valid
/// ExPolygons; otherwise the islands are returned as they are.
pub fn simplify_islands(islands: &[ExPolygon], tolerance_mm: f64) -> Vec<ExPolygon> {
    let tolerance = scaled(tolerance_mm) as f64;
    if tolerance.is_nan() || tolerance <= 0.0 {
        return islands.to_vec();
    }
    let mut changed = false;
    let simplified: Vec<ExPolygon> = islands
        .iter()
        .filter_map(|ex| {
            let before =
                ex.contour.points.len() + ex.holes.iter().map(|h| h.points.len()).sum::<usize>();
            let out = simplify_ring(&ex.contour, tolerance).map(|contour| ExPolygon {
                contour,
                holes: ex
                    .holes
                    .iter()
                    .filter_map(|h| simplify_ring(h, tolerance))
                    .collect(),
            });
            let after = out.as_ref().map_or(0, |e| {
                e.contour.points.len() + e.holes.iter().map(|h| h.points.len()).sum::<usize>()
            });
            changed |= after != before;
            out
        })
        .collect();
    if changed {
        union(&simplified)
    } else {
        simplified
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::square_island;

    #[test]
    fn squares_are_left_alone() {
        let islands = vec![square_island(0.0, 0.0, 10.0)];
        assert_eq!(simplify_islands(&islands, RESOLUTION_MM), islands);
    }

    #[test]
    fn near_collinear_points_go_and_corners_stay() {
        // A 10 mm square whose bottom edge wobbles by ±5 µm every 0.1 mm.
        let mut points: Vec<Point2> = (0..100)
            .map(|i| Point2::from_mm(i as f64 * 0.1, if i % 2 == 1 { 0.005 } else { 0.0 }))
            .collect();
        points.extend([
            Point2::from_mm(10.0, 0.0),
            Point2::from_mm(10.0, 10.0),
            Point2::from_mm(0.0, 10.0),
        ]);
        let island = ExPolygon {
            contour: Polygon::new(points),
            holes: vec![],
        };
        let out = simplify_islands(&[island], RESOLUTION_MM);
        assert_eq!(out, vec![square_island(0.0, 0.0, 10.0)]);
        // A wobble larger than the tolerance stays.
        let bump = ExPolygon {
            contour: Polygon::new(vec![
                Point2::from_mm(0.0, 0.0),
                Point2::from_mm(5.0, 0.05),
                Point2::from_mm(10.0, 0.0),
                Point2::from_mm(10.0, 10.0),
                Point2::from_mm(0.0, 10.0),
            ]),
            holes: vec![],
        };
        assert_eq!(
            simplify_islands(std::slice::from_ref(&bump), RESOLUTION_MM)[0]
                .contour
                .points
                .len(),
            5
        );
    }
}
