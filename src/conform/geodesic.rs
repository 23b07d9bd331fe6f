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
//! Separate paths keep their layout: the design's centre drops onto the surface, and each
//! path's start is reached by marching from there along the design's x, then its y, each leg
//! as long on the surface as in the design (a vertical drop of each start would spread the
//! paths apart on a slope by 1/cos of the slope, as projection does). On a surface that
//! slopes along one axis this is the surface unrolled flat. A path that starts
//! on a point of a path already laid (a feed line and its patch) starts on that point's 3D
//! position, so what is joined in the design stays joined.

use super::design::PlanarPath;
use super::project::Projected;
use crate::geom::Point3;
use crate::surface::Surface;

/// Bisection steps of one march step: 2⁻⁴⁰ of the step length.
const BISECTIONS: usize = 40;

/// Design points closer than this are the same point (a path starting on another), mm.
const JOIN: f64 = 1e-6;

/// Longest step when marching from the design's centre to a path's start, mm.
const APPROACH_STEP: f64 = 0.1;

/// Marches from `start` (on the surface, over `pts[0]`) through the 2D points `pts`, each 3D
/// step as long as its 2D step. Returns the points reached (starting with `start`; a repeated
/// design point is not repeated), the index in `pts` of each, and whether the march left the
/// surface before the end.
fn march(surface: &Surface, start: Point3, pts: &[[f64; 2]]) -> (Vec<Point3>, Vec<usize>, bool) {
    let mut cur = start;
    let mut run = vec![cur];
    let mut index = vec![0];
    for (i, w) in pts.windows(2).enumerate() {
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
                index.push(i + 1);
            }
            _ => return (run, index, true),
        }
    }
    (run, index, false)
}

/// Where the path starting at `first` (2D) starts on the surface: on an earlier path's point
/// when it joins one, else marched from the design's centre `anchor`, else dropped vertically.
fn start_of(
    surface: &Surface,
    first: [f64; 2],
    laid: &[([f64; 2], Point3)],
    anchor: Option<([f64; 2], Point3)>,
) -> Option<Point3> {
    if let Some((_, q)) = laid
        .iter()
        .find(|(a, _)| (a[0] - first[0]).hypot(a[1] - first[1]) <= JOIN)
    {
        return Some(*q);
    }
    if let Some((a2, a3)) = anchor {
        // Along x, then along y: on a surface that slopes along one axis (a ramp, a cylinder)
        // this lays the design flat without distortion; a straight march from the centre would
        // keep each start's distance from the centre but turn the directions between them.
        let corner = [first[0], a2[1]];
        let mut line = Vec::new();
        for (from, to) in [(a2, corner), (corner, first)] {
            let len = (to[0] - from[0]).hypot(to[1] - from[1]);
            let n = ((len / APPROACH_STEP).ceil() as usize).max(1);
            line.extend((0..=n).map(|k| {
                let t = k as f64 / n as f64;
                [
                    from[0] + t * (to[0] - from[0]),
                    from[1] + t * (to[1] - from[1]),
                ]
            }));
        }
        let (run, _, fell_off) = march(surface, a3, &line);
        if !fell_off && let Some(end) = run.last() {
            return Some(*end);
        }
    }
    surface
        .height(first[0], first[1])
        .map(|z| Point3::new(first[0], first[1], z))
}

/// Lays every path of `paths` onto `surface` keeping arc length (see the module docs).
pub fn map_geodesic(surface: &Surface, paths: &[PlanarPath]) -> Projected {
    let mut out = Projected::default();
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for q in paths.iter().flat_map(|p| &p.points) {
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
    let anchor = surface
        .height(centre[0], centre[1])
        .map(|z| (centre, Point3::new(centre[0], centre[1], z)));
    let mut laid: Vec<([f64; 2], Point3)> = Vec::new();
    for p in paths {
        let Some(first) = p.points.first() else {
            continue;
        };
        let Some(start) = start_of(surface, *first, &laid, anchor) else {
            out.off_surface += p.points.len();
            continue;
        };
        let (run, index, fell_off) = march(surface, start, &p.points);
        if fell_off {
            let reached = index.last().map_or(0, |i| i + 1);
            out.off_surface += p.points.len() - reached;
        }
        laid.extend(index.iter().map(|&i| p.points[i]).zip(run.iter().copied()));
        if run.len() >= 2 {
            out.paths.push(run);
        }
    }
    out
}
