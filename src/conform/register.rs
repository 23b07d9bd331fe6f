//! Registration: the rigid transform from the scan frame to the machine frame, from reference
//! points measured in both.
//!
//! Place in the pipeline: step 2, between reading the surface and laying the design on it.
//!
//! - Three points ([`three_point`]): G = t(P2)·R2(v2, θ2)·R1(v1, θ1)·t(−S2). The scan is moved
//!   so S2 sits at the origin, R1 turns the direction S2→S1 onto P2→P1 (about their common
//!   normal v1), R2 turns about that aligned axis by the angle θ2 that brings the plane of
//!   S2→S3 onto the plane of P2→P3, and t(P2) moves the origin to P2.
//! - More points ([`least_squares`]): Kabsch/Umeyama without scale — centroids, the SVD of the
//!   cross-covariance, a sign fix so the result is a rotation and not a reflection.
//!
//! Both report per-point residuals |G·Sᵢ − Pᵢ|.

use crate::geom::{Point3, Vector3};
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, Unit, UnitQuaternion};
use serde::Serialize;

/// Why registration failed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RegisterError {
    /// The two point lists differ in length, or have fewer than three points.
    ///
    /// How to fix: give the same reference points, in the same order, in both frames.
    #[error(
        "registration needs the same number (at least 3) of scan and machine points; got {scan} and {machine}"
    )]
    Count {
        /// Scan points given.
        scan: usize,
        /// Machine points given.
        machine: usize,
    },
    /// The points are (nearly) on one line, which fixes no rotation about that line.
    ///
    /// How to fix: pick reference points that span a triangle.
    #[error("the reference points are collinear or coincident")]
    Degenerate,
}

/// A registration result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Registration {
    /// `"identity"`, `"three-point"` or `"least-squares"`.
    pub method: &'static str,
    /// Rotation as a 3×3 matrix, row by row.
    pub rotation: [[f64; 3]; 3],
    /// Translation, mm.
    pub translation: [f64; 3],
    /// |G·Sᵢ − Pᵢ| per reference point, mm.
    pub residuals: Vec<f64>,
    /// Root mean square of the residuals, mm.
    pub rms: f64,
    /// The transform.
    #[serde(skip)]
    pub transform: Isometry3<f64>,
}

impl Registration {
    /// The identity: the scan is already in the machine frame.
    pub fn identity() -> Self {
        Self::new("identity", Isometry3::identity(), &[], &[])
    }

    fn new(method: &'static str, g: Isometry3<f64>, scan: &[Point3], machine: &[Point3]) -> Self {
        let residuals: Vec<f64> = scan
            .iter()
            .zip(machine)
            .map(|(s, p)| (g.transform_point(s) - p).norm())
            .collect();
        let rms = if residuals.is_empty() {
            0.0
        } else {
            (residuals.iter().map(|r| r * r).sum::<f64>() / residuals.len() as f64).sqrt()
        };
        let m = g.rotation.to_rotation_matrix().into_inner();
        Self {
            method,
            rotation: [
                [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
                [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
                [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
            ],
            translation: [g.translation.x, g.translation.y, g.translation.z],
            residuals,
            rms,
            transform: g,
        }
    }
}

fn check(scan: &[Point3], machine: &[Point3]) -> Result<(), RegisterError> {
    if scan.len() != machine.len() || scan.len() < 3 {
        return Err(RegisterError::Count {
            scan: scan.len(),
            machine: machine.len(),
        });
    }
    let spread = |p: &[Point3]| {
        let (a, b, c) = (p[0], p[1], p[2]);
        let size = (b - a).norm().max((c - a).norm()).max(1e-12);
        (b - a).cross(&(c - a)).norm() / (size * size)
    };
    // Relative area of the first triangle (or, with more points, any triangle through the
    // first two): below 1e-9 the rotation about the line is not defined.
    let fine = |p: &[Point3]| (2..p.len()).any(|k| spread(&[p[0], p[1], p[k]]) > 1e-9);
    if !fine(scan) || !fine(machine) {
        return Err(RegisterError::Degenerate);
    }
    Ok(())
}

/// The rotation taking direction `a` onto direction `b` (both non-zero).
fn align(a: &Vector3, b: &Vector3) -> UnitQuaternion<f64> {
    UnitQuaternion::rotation_between(a, b).unwrap_or_else(|| {
        // Opposite directions: half a turn about any axis perpendicular to `a`.
        let other = if a.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let axis = Unit::new_normalize(a.cross(&other));
        UnitQuaternion::from_axis_angle(&axis, std::f64::consts::PI)
    })
}

/// Three-point registration (see the module docs): scan points S1..S3 onto machine points
/// P1..P3. S2/P2 is the pivot.
pub fn three_point(
    scan: &[Point3; 3],
    machine: &[Point3; 3],
) -> Result<Registration, RegisterError> {
    check(scan, machine)?;
    let [s1, s2, s3] = *scan;
    let [p1, p2, p3] = *machine;
    // R1: S2→S1 onto P2→P1.
    let r1 = align(&(s1 - s2), &(p1 - p2));
    // R2: about the aligned axis, bring the component of R1·(S2→S3) perpendicular to the axis
    // onto that of P2→P3.
    let axis = (p1 - p2).normalize();
    let perp = |v: Vector3| v - axis * axis.dot(&v);
    let a = perp(r1 * (s3 - s2));
    let b = perp(p3 - p2);
    let theta = a.cross(&b).dot(&axis).atan2(a.dot(&b));
    let r2 = UnitQuaternion::from_axis_angle(&Unit::new_normalize(axis), theta);
    let rot = r2 * r1;
    let g = Isometry3::from_parts(Translation3::from(p2.coords - rot * s2.coords), rot);
    Ok(Registration::new("three-point", g, scan, machine))
}

/// Least-squares registration (Kabsch/Umeyama without scale) of any number ≥ 3 of points.
pub fn least_squares(scan: &[Point3], machine: &[Point3]) -> Result<Registration, RegisterError> {
    check(scan, machine)?;
    let n = scan.len() as f64;
    let cs = scan.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n;
    let cm = machine.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n;
    let mut h = Matrix3::zeros();
    for (s, p) in scan.iter().zip(machine) {
        h += (s.coords - cs) * (p.coords - cm).transpose();
    }
    let svd = h.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(RegisterError::Degenerate);
    };
    let v = v_t.transpose();
    // Reflection guard: flip the last axis when det(V·Uᵀ) < 0.
    let d = (v * u.transpose()).determinant().signum();
    let fix = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, if d < 0.0 { -1.0 } else { 1.0 }));
    let r = v * fix * u.transpose();
    let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    let g = Isometry3::from_parts(Translation3::from(cm - rot * cs), rot);
    Ok(Registration::new("least-squares", g, scan, machine))
}

/// Three-point registration for exactly three points, least squares for more.
pub fn register(scan: &[Point3], machine: &[Point3]) -> Result<Registration, RegisterError> {
    match (scan, machine) {
        ([a, b, c], [p, q, r]) => three_point(&[*a, *b, *c], &[*p, *q, *r]),
        _ => least_squares(scan, machine),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn known() -> Isometry3<f64> {
        let axis = Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8));
        Isometry3::from_parts(
            Translation3::new(12.0, -4.0, 3.5),
            UnitQuaternion::from_axis_angle(&axis, 0.7),
        )
    }

    #[test]
    fn three_points_recover_a_rigid_transform_exactly() -> Result<(), RegisterError> {
        let g = known();
        let s = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(40.0, 5.0, 1.0),
            Point3::new(-3.0, 30.0, 2.0),
        ];
        let p = s.map(|q| g.transform_point(&q));
        let r = three_point(&s, &p)?;
        assert!(r.rms < 1e-9, "{r:?}");
        let probe = Point3::new(7.0, -8.0, 9.0);
        assert!((r.transform.transform_point(&probe) - g.transform_point(&probe)).norm() < 1e-9);
        Ok(())
    }

    #[test]
    fn collinear_points_are_refused() {
        let s = [0.0, 1.0, 2.0].map(|t| Point3::new(t, t, t));
        assert_eq!(
            three_point(&s, &s).map(|r| r.rms),
            Err(RegisterError::Degenerate)
        );
    }
}
