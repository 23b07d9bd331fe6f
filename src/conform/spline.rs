//! Local geometry of the zero-standoff path: a natural cubic spline through T gives the unit
//! tangent tᵢ, the signed curvature κᵢ, the inflection points and the tool trajectory Vᵢ.
//!
//! Place in the pipeline: step 5, after projection and before the corrections
//! ([`super::correct`]).
//!
//! The spline's parameter is the horizontal arc length h along T (the design's own arc length
//! for a vertical projection), one natural cubic spline per coordinate x(h), y(h), z(h). The
//! curvature is that of the path in the vertical plane of travel: with σ = |(x', y')| the
//! horizontal speed, κ = (σ·z'' − z'·σ') / (σ² + z'²)^{3/2}, negative where the path is concave
//! down (over a bump), positive where it is concave up (in a valley). Vᵢ is (x', y')
//! normalised: the direction of travel seen from above.
//!
//! Where the design turns in the plane, z'' also holds the turn times the surface's slope
//! across the path (z'' = ∇S·(x'', y'') + (x', y')ᵀ·H·(x', y')): a spiral on a flat ramp rises
//! and falls, so its path is curved in z though the surface is a plane. The nozzle's back edge
//! looks straight back along −Vᵢ, over the surface's section in the direction of travel, so
//! the downhill correction takes the curvature of that section ([`Local::section_curvature`]):
//! the same formula with the turn's term ∇S·(x'', y'') removed, ∇S from the surface normal at
//! Tᵢ. On a plane it is exactly 0.

use crate::geom::{Point3, Vector3};

/// Local geometry at one point of T.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Local {
    /// Unit tangent in the direction of travel.
    pub tangent: Vector3,
    /// Horizontal direction of travel, unit (x, y, 0).
    pub travel: Vector3,
    /// Signed curvature of the path in the vertical plane of travel, 1/mm.
    pub curvature: f64,
    /// Signed curvature of the surface's vertical section in the direction of travel, 1/mm
    /// (equal to `curvature` when no surface normals are given).
    pub section_curvature: f64,
    /// Whether the curvature changes sign between this point and the next.
    pub inflection: bool,
    /// The surface's upward unit normal at the point (ẑ when no normals are given).
    pub normal: Vector3,
}

/// Second derivatives of the natural cubic spline through (t, y) (Thomas algorithm).
fn second_derivatives(t: &[f64], y: &[f64]) -> Vec<f64> {
    let n = t.len();
    let mut m = vec![0.0; n];
    if n < 3 {
        return m;
    }
    let (mut c, mut d) = (vec![0.0; n], vec![0.0; n]);
    for i in 1..n - 1 {
        let (h0, h1) = (t[i] - t[i - 1], t[i + 1] - t[i]);
        let a = h0 / 6.0;
        let b = (h0 + h1) / 3.0;
        let cc = h1 / 6.0;
        let r = (y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0;
        let denom = b - a * c[i - 1];
        c[i] = cc / denom;
        d[i] = (r - a * d[i - 1]) / denom;
    }
    for i in (1..n - 1).rev() {
        m[i] = d[i] - c[i] * m[i + 1];
    }
    m
}

/// First derivative of the spline at every knot.
fn first_derivatives(t: &[f64], y: &[f64], m: &[f64]) -> Vec<f64> {
    let n = t.len();
    (0..n)
        .map(|i| {
            if i + 1 < n {
                let h = t[i + 1] - t[i];
                (y[i + 1] - y[i]) / h - h * (2.0 * m[i] + m[i + 1]) / 6.0
            } else {
                let h = t[i] - t[i - 1];
                (y[i] - y[i - 1]) / h + h * (m[i - 1] + 2.0 * m[i]) / 6.0
            }
        })
        .collect()
}

/// Local geometry of every point of `path` (at least two points). `normals` holds the surface's
/// upward unit normal at each point (for [`Local::section_curvature`]); an empty slice leaves
/// the section curvature equal to the path's.
pub fn local_geometry(path: &[Point3], normals: &[Vector3]) -> Vec<Local> {
    let n = path.len();
    if n < 2 {
        return Vec::new();
    }
    // Horizontal arc length; a vertical step still advances a little so the knots increase.
    let mut t = Vec::with_capacity(n);
    let mut s = 0.0;
    for (i, p) in path.iter().enumerate() {
        if i > 0 {
            let q = path[i - 1];
            s += (p.x - q.x).hypot(p.y - q.y).max(1e-6);
        }
        t.push(s);
    }
    let coords: [Vec<f64>; 3] = [
        path.iter().map(|p| p.x).collect(),
        path.iter().map(|p| p.y).collect(),
        path.iter().map(|p| p.z).collect(),
    ];
    let m: Vec<Vec<f64>> = coords.iter().map(|c| second_derivatives(&t, c)).collect();
    let d: Vec<Vec<f64>> = coords
        .iter()
        .zip(&m)
        .map(|(c, m)| first_derivatives(&t, c, m))
        .collect();
    let mut out: Vec<Local> = (0..n)
        .map(|i| {
            let (x1, y1, z1) = (d[0][i], d[1][i], d[2][i]);
            let (x2, y2, z2) = (m[0][i], m[1][i], m[2][i]);
            let sigma = x1.hypot(y1).max(1e-12);
            let sigma1 = (x1 * x2 + y1 * y2) / sigma;
            let bend = (sigma * sigma + z1 * z1).powf(1.5);
            let curvature = (sigma * z2 - z1 * sigma1) / bend;
            let normal = normals.get(i).copied().unwrap_or_else(Vector3::z);
            // The turn's share of z'': ∇S·(x'', y'') with ∇S = −(n_x, n_y)/n_z (0 for ẑ).
            let turn = if normal.z > 1e-6 {
                -(normal.x * x2 + normal.y * y2) / normal.z
            } else {
                0.0
            };
            let section_curvature = (sigma * (z2 - turn) - z1 * sigma1) / bend;
            let tangent = Vector3::new(x1, y1, z1)
                .try_normalize(1e-12)
                .unwrap_or_else(Vector3::x);
            let travel = Vector3::new(x1 / sigma, y1 / sigma, 0.0);
            Local {
                tangent,
                travel,
                curvature,
                section_curvature,
                inflection: false,
                normal,
            }
        })
        .collect();
    for i in 0..n - 1 {
        out[i].inflection = out[i].curvature * out[i + 1].curvature < 0.0;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_circular_arc_has_its_curvature_and_sign() {
        // Over the top of a circle of radius 10 (concave down): κ = −0.1.
        let r = 10.0;
        let path: Vec<Point3> = (0..=200)
            .map(|i| {
                let a = std::f64::consts::PI * (0.25 + 0.5 * i as f64 / 200.0);
                Point3::new(-r * a.cos(), 0.0, r * a.sin())
            })
            .collect();
        let g = local_geometry(&path, &[]);
        let mid = g[100];
        assert!((mid.curvature + 0.1).abs() < 1e-4, "{}", mid.curvature);
        assert!((mid.tangent - Vector3::x()).norm() < 1e-6);
        // A valley: κ = +0.1.
        let flipped: Vec<Point3> = path.iter().map(|p| Point3::new(p.x, p.y, -p.z)).collect();
        assert!((local_geometry(&flipped, &[])[100].curvature - 0.1).abs() < 1e-4);
    }

    #[test]
    fn a_circle_on_a_ramp_is_curved_but_its_surface_section_is_straight() {
        // A circle of radius 5 on the plane z = 0.5·x: the path rises and falls (curved in its
        // vertical plane of travel), the surface under it is a plane.
        let n = Vector3::new(-0.5, 0.0, 1.0).normalize();
        let path: Vec<Point3> = (0..=400)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 400.0;
                let (x, y) = (5.0 * a.cos(), 5.0 * a.sin());
                Point3::new(x, y, 0.5 * x)
            })
            .collect();
        let g = local_geometry(&path, &vec![n; path.len()]);
        // At a = 180° (x = −5, heading −y, level): z'' = 0.5·x'' = 0.5·(1/5), a valley of the
        // path with κ = 0.1 — from the turn alone.
        assert!(
            (g[200].curvature - 0.1).abs() < 1e-4,
            "{}",
            g[200].curvature
        );
        for l in &g[20..380] {
            assert!(l.section_curvature.abs() < 1e-6, "{}", l.section_curvature);
        }
    }
}
