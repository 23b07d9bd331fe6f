//! Points along a flat path where the bottom (or top) surface bends, and at most `step` apart.
//!
//! Place in the pipeline: shared by the scaffold (reference points along its lines), the
//! curved layers (points to lift onto the surface) and the sandwich's top skin and core. A
//! path densified here and lifted onto the surface stays on it between its points: each
//! segment lies over one surface triangle.

use super::shell::Shell;
use crate::surface::densify_path;

/// The points of `path` (xy, mm) with its crossings of the bottom surface's triangle edges and
/// subdivisions to at most `step` inserted; a closed path's closing segment is densified too
/// and its first point is not repeated at the end.
pub fn densify(shell: &Shell, path: &[(f64, f64)], closed: bool, step: f64) -> Vec<(f64, f64)> {
    densify_path(path, closed, step, &|a, b| shell.bottom_crossings(a, b))
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
