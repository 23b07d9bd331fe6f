//! Points along a flat path where the bottom (or top) surface bends, and at most `step` apart.
//!
//! Place in the pipeline: shared by the scaffold (reference points along its lines), the
//! curved layers (points to lift onto the surface) and the sandwich's top skin and core. A
//! path densified here and lifted onto the surface stays on it between its points: each
//! segment lies over one surface triangle.

use super::shell::Shell;

/// The points of `path` (xy, mm) with its crossings of the bottom surface's triangle edges and
/// subdivisions to at most `step` inserted; a closed path's closing segment is densified too
/// and its first point is not repeated at the end.
pub fn densify(shell: &Shell, path: &[(f64, f64)], closed: bool, step: f64) -> Vec<(f64, f64)> {
    densify_with(path, closed, step, &|a, b| shell.bottom_crossings(a, b))
}

/// [`densify`] with the crossings of another surface: `crossings(a, b)` gives the parameters
/// in (0, 1), ascending, where the segment `a`–`b` crosses a triangle edge.
pub fn densify_with(
    path: &[(f64, f64)],
    closed: bool,
    step: f64,
    crossings: &dyn Fn((f64, f64), (f64, f64)) -> Vec<f64>,
) -> Vec<(f64, f64)> {
    let n = path.len();
    let mut out = Vec::with_capacity(n * 4);
    if n == 0 {
        return out;
    }
    let segments = if closed { n } else { n - 1 };
    for i in 0..segments {
        let (a, b) = (path[i], path[(i + 1) % n]);
        out.push(a);
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        if !(len.is_finite() && len > 0.0) {
            continue;
        }
        let mut ts = vec![0.0];
        ts.extend(crossings(a, b));
        ts.push(1.0);
        for w in ts.windows(2) {
            let pieces = ((w[1] - w[0]) * len / step).ceil().max(1.0) as usize;
            for k in 1..=pieces {
                if k == pieces && w[1] >= 1.0 {
                    break;
                }
                let t = w[0] + (w[1] - w[0]) * k as f64 / pieces as f64;
                out.push((a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t));
            }
        }
    }
    if !closed {
        out.push(path[n - 1]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point3;
    use crate::mesh::Mesh;

    #[test]
    fn points_fall_on_triangle_edges_and_at_most_step_apart() {
        let p = |x: f64, y: f64| Point3::new(x, y, 0.1 * x * y);
        let sheet = Mesh::from_triangle_soup(
            "sheet",
            [
                [p(0.0, 0.0), p(10.0, 0.0), p(10.0, 10.0)],
                [p(0.0, 0.0), p(10.0, 10.0), p(0.0, 10.0)],
            ],
        );
        let shell = Shell::from_meshes(&[sheet]);
        let pts = densify(&shell, &[(0.0, 5.0), (10.0, 5.0)], false, 1.0);
        // The diagonal x = y is crossed at x = 5.
        assert!(pts.iter().any(|q| (q.0 - 5.0).abs() < 1e-9));
        assert!(pts.windows(2).all(|w| (w[1].0 - w[0].0) <= 1.0 + 1e-9));
        assert_eq!(pts.first(), Some(&(0.0, 5.0)));
        assert_eq!(pts.last(), Some(&(10.0, 5.0)));
        let ring = densify(&shell, &[(1.0, 1.0), (9.0, 1.0), (9.0, 9.0)], true, 2.0);
        assert_ne!(ring.last(), ring.first());
        assert!(ring.len() >= 4 + 4 + 6);
    }
}
