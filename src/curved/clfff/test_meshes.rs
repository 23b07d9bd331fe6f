//! Closed test sheets for the curved-layer stages' unit tests: a rectangle whose bottom and top
//! are planes sloping along x.

use crate::geom::Point3;
use crate::mesh::Mesh;

/// A closed sheet over [0, w] × [0, d]: bottom z = b0 + b1·x, top z = t0 + t1·x.
pub(crate) fn ramp_sheet(name: &str, w: f64, d: f64, bottom: [f64; 2], top: [f64; 2]) -> Mesh {
    let b = |x: f64, y: f64| Point3::new(x, y, bottom[0] + bottom[1] * x);
    let t = |x: f64, y: f64| Point3::new(x, y, top[0] + top[1] * x);
    Mesh::from_triangle_soup(
        name,
        [
            [t(0.0, 0.0), t(w, 0.0), t(w, d)],
            [t(0.0, 0.0), t(w, d), t(0.0, d)],
            [b(0.0, 0.0), b(w, d), b(w, 0.0)],
            [b(0.0, 0.0), b(0.0, d), b(w, d)],
        ],
    )
}
