//! Geodesic mapping (`mapping = "geodesic"`): the design laid onto the surface keeping its arc
//! length, where a vertical projection stretches it by 1/cos of the slope (a 50 mm line on a 45°
//! ramp becomes 70.7 mm, which detunes an antenna).
//!
//! Place in the pipeline: step 4, instead of [`super::project`]. Each path starts where its
//! first point drops onto the surface; from there it marches along the surface, step by step,
//! in the design's direction seen from above: each 3D step is as long as its 2D step. The
//! horizontal advance `a` of a step of length ℓ in direction u solves
//! `a² + (h(p + a·u) − z)² = ℓ²` (bisection on a ∈ [0, ℓ]; the left side grows with a for a
//! surface that is a function of x, y).
//!
//! The shape seen from above shrinks along slopes (by cos of the slope), so separate paths of
//! one design keep their start points but not their exact relative layout.

use super::design::PlanarPath;
use super::project::Projected;
use super::surface::Surface;
use crate::geom::Point3;

/// Bisection steps of one march step: 2⁻⁴⁰ of the step length.
const BISECTIONS: usize = 40;

/// Lays every path of `paths` onto `surface` keeping arc length (see the module docs).
pub fn map_geodesic(surface: &Surface, paths: &[PlanarPath]) -> Projected {
    let mut out = Projected::default();
    for p in paths {
        let mut run: Vec<Point3> = Vec::new();
        let Some(first) = p.points.first() else {
            continue;
        };
        let Some(z0) = surface.height(first[0], first[1]) else {
            out.off_surface += p.points.len();
            continue;
        };
        let mut cur = Point3::new(first[0], first[1], z0);
        run.push(cur);
        for w in p.points.windows(2) {
            let (dx, dy) = (w[1][0] - w[0][0], w[1][1] - w[0][1]);
            let step = dx.hypot(dy);
            if step <= 0.0 {
                continue;
            }
            let u = [dx / step, dy / step];
            let at = |a: f64| surface.height(cur.x + a * u[0], cur.y + a * u[1]);
            let (mut lo, mut hi) = (0.0, step);
            let mut found = true;
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                let Some(z) = at(mid) else {
                    hi = mid;
                    found = false;
                    continue;
                };
                if mid.hypot(z - cur.z) < step {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let a = 0.5 * (lo + hi);
            match at(a) {
                Some(z) if found || a > 0.0 => {
                    cur = Point3::new(cur.x + a * u[0], cur.y + a * u[1], z);
                    run.push(cur);
                }
                _ => {
                    out.off_surface += 1;
                    break;
                }
            }
        }
        if run.len() >= 2 {
            out.paths.push(run);
        }
    }
    out
}
