//! The shell seen from above: its outline (with holes), the scaffold area around it, and the
//! outline's rim heights for scaffold outside the shell.
//!
//! Place in the pipeline: step 2 of [`super::plan`], after the shell is placed and before the
//! scaffold and the curved layers, which are clipped to these areas.
//!
//! - [`outline`]: the union of the bottom surface's triangles projected on the bed (i_overlay
//!   through [`crate::geom::union`]); no raster image, holes stay holes.
//! - [`scaffold_area`]: the convex hull of the outline grown by `curved.scaffold_margin`.
//! - [`Rim`]: points along the outline with the bottom surface's height there; outside the
//!   outline the scaffold is limited by the height of the nearest rim point.

use super::shell::Shell;
use crate::geom::{ExPolygon, Join, Point2, Polygon, offset, union};

/// Chord tolerance of the rounded corners of the grown scaffold area, mm.
const ROUND_TOLERANCE_MM: f64 = 0.02;

/// Spacing of the rim samples along the outline, mm.
const RIM_STEP_MM: f64 = 0.5;

/// The polygon through `points` (repeated neighbours dropped), counter-clockwise, as a region
/// without holes; `None` when fewer than three points remain or it has no area.
pub(super) fn ccw_region(points: Vec<Point2>) -> Option<ExPolygon> {
    let mut ring = Polygon::new(points);
    ring.points.dedup();
    if ring.points.len() < 3 {
        return None;
    }
    let a = ring.signed_area2();
    if a == 0 {
        return None;
    }
    if a < 0 {
        ring.points.reverse();
    }
    Some(ExPolygon {
        contour: ring,
        holes: Vec::new(),
    })
}

/// The top-down projection of the shell's bottom surface, as non-overlapping ExPolygons.
pub fn outline(shell: &Shell) -> Vec<ExPolygon> {
    let tris: Vec<ExPolygon> = shell
        .bottom_triangles()
        .iter()
        .filter_map(|t| {
            ccw_region(
                t.corners
                    .iter()
                    .map(|p| Point2::from_mm(p.x, p.y))
                    .collect(),
            )
        })
        .collect();
    union(&tris)
}

/// The scaffold area: the convex hull of the outline grown by `margin_mm` (round corners).
pub fn scaffold_area(outline: &[ExPolygon], margin_mm: f64) -> Vec<ExPolygon> {
    let pts: Vec<Point2> = outline
        .iter()
        .flat_map(|ex| ex.contour.points.iter().copied())
        .collect();
    let hull = Polygon::convex_hull(&pts);
    if hull.points.len() < 3 {
        return Vec::new();
    }
    let ex = ExPolygon {
        contour: hull,
        holes: Vec::new(),
    };
    offset(&[ex], margin_mm, Join::Round(ROUND_TOLERANCE_MM))
}

/// Points along the outline (contours and holes) with the bottom surface's height there.
#[derive(Debug, Clone, Default)]
pub struct Rim {
    points: Vec<[f64; 3]>,
}

impl Rim {
    /// Samples every outline ring every [`RIM_STEP_MM`] (and at its vertices); samples where
    /// the surface is not found (rounding at the very edge) are left out.
    pub fn new(outline: &[ExPolygon], shell: &Shell) -> Self {
        let mut points = Vec::new();
        for ring in outline
            .iter()
            .flat_map(|ex| std::iter::once(&ex.contour).chain(&ex.holes))
        {
            let n = ring.points.len();
            for i in 0..n {
                let a = ring.points[i].to_mm();
                let b = ring.points[(i + 1) % n].to_mm();
                let len = (b.0 - a.0).hypot(b.1 - a.1);
                let steps = (len / RIM_STEP_MM).ceil().max(1.0) as usize;
                for s in 0..steps {
                    let t = s as f64 / steps as f64;
                    let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
                    if let Some(z) = shell.bottom(x, y) {
                        points.push([x, y, z]);
                    }
                }
            }
        }
        Self { points }
    }

    /// The bottom surface's height at the rim point nearest to (x, y) (ties to the first);
    /// `None` without rim points.
    pub fn nearest_height(&self, x: f64, y: f64) -> Option<f64> {
        let mut best: Option<(f64, f64)> = None;
        for p in &self.points {
            let d = (p[0] - x).powi(2) + (p[1] - y).powi(2);
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, p[2]));
            }
        }
        best.map(|(_, z)| z)
    }

    /// Whether there are no rim points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point3;
    use crate::mesh::Mesh;

    #[test]
    fn hull_of_an_l_is_its_five_corners() {
        let p = |x: f64, y: f64| Point2::from_mm(x, y);
        let pts = [
            p(0.0, 0.0),
            p(10.0, 0.0),
            p(10.0, 2.0),
            p(2.0, 2.0),
            p(2.0, 10.0),
            p(0.0, 10.0),
            p(5.0, 0.0),
        ];
        let h = Polygon::convex_hull(&pts);
        assert_eq!(h.points.len(), 5, "{h:?}");
        assert!(h.is_counter_clockwise());
        // (0,0) (10,0) (10,2) (2,10) (0,10): the square less the corner triangle ½·8·8.
        assert!((h.area_mm2() - 68.0).abs() < 1e-9, "{}", h.area_mm2());
    }

    #[test]
    fn outline_of_a_ring_keeps_its_hole_and_the_scaffold_area_fills_it() {
        // A flat square frame: outer 20 mm, hole 10 mm, as triangles of four trapezoids.
        let z = |x: f64, y: f64| Point3::new(x, y, 1.0);
        let (o, i) = (10.0, 5.0);
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        let mut tris = Vec::new();
        for k in 0..4 {
            let (a, b) = (corners[k], corners[(k + 1) % 4]);
            let (oa, ob) = (z(a.0 * o, a.1 * o), z(b.0 * o, b.1 * o));
            let (ia, ib) = (z(a.0 * i, a.1 * i), z(b.0 * i, b.1 * i));
            tris.push([oa, ob, ib]);
            tris.push([oa, ib, ia]);
        }
        let shell = Shell::from_meshes(&[Mesh::from_triangle_soup("frame", tris)]);
        let out = outline(&shell);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].holes.len(), 1);
        assert!(
            (out[0].area_mm2() - 300.0).abs() < 1e-6,
            "{}",
            out[0].area_mm2()
        );
        let area = scaffold_area(&out, 2.0);
        assert_eq!(area.len(), 1);
        assert!(area[0].holes.is_empty());
        // 20² + 4·20·2 + π·2² (rounded corners, chords inside the arc).
        let want = 400.0 + 160.0 + std::f64::consts::PI * 4.0;
        assert!(
            (area[0].area_mm2() - want).abs() < 0.3,
            "{}",
            area[0].area_mm2()
        );
        let rim = Rim::new(&out, &shell);
        assert_eq!(rim.nearest_height(30.0, 0.0), Some(1.0));
    }
}
