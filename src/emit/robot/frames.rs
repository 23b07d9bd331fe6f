//! Frames and rotations of robot programs: `[x, y, z, rx, ry, rz]` frames, the tool frame of a
//! tool axis, and the rotation notations of the dialects (ZYX Euler angles, rotation vector,
//! quaternion), with the fixed-decimal number format they are written in.
//!
//! Place in the pipeline: shared by the robot writers ([`super`]); the motion plan
//! ([`super::motion`]) turns every tool axis into a tool frame here.
//!
//! Conventions: a frame `[x, y, z, rx, ry, rz]` (mm, degrees) is the translation (x, y, z) and
//! the rotation R = Rz(rz)·Ry(ry)·Rx(rx). The tool frame's z axis points out of the tool into
//! the work (−tool axis); its x axis is the program frame's +X projected onto the plane normal
//! to z, or +Y when +X is (nearly) along z; y = z × x.

use crate::geom::{Point3, Vector3};
use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion};

/// The rigid transform of a frame `[x, y, z, rx, ry, rz]` (mm, degrees; see the module docs).
pub fn frame(v: &[f64; 6]) -> Isometry3<f64> {
    let r = Rotation3::from_euler_angles(v[3].to_radians(), v[4].to_radians(), v[5].to_radians());
    Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::from_rotation_matrix(&r),
    )
}

/// The tool frame's rotation for a tool axis `axis` (unit, from the tip toward the tool body):
/// columns x, y, z of the frame with z = −axis (see the module docs).
pub fn tool_rotation(axis: &Vector3) -> Rotation3<f64> {
    // Tool axes are unit vectors by construction; a degenerate one points the tool down.
    crate::geom::tool_frame(&-axis)
        .or_else(|| crate::geom::tool_frame(&-Vector3::z()))
        .unwrap_or_else(Rotation3::identity)
}

/// ZYX Euler angles `[a, b, c]` in degrees of `r` (R = Rz(a)·Ry(b)·Rx(c): KUKA's A, B, C).
pub fn zyx_degrees(r: &Rotation3<f64>) -> [f64; 3] {
    let (roll, pitch, yaw) = r.euler_angles();
    [yaw.to_degrees(), pitch.to_degrees(), roll.to_degrees()]
}

/// The rotation vector (axis × angle, radians) of `r`: URScript's `rx, ry, rz`.
pub fn rotation_vector(r: &Rotation3<f64>) -> Vector3 {
    UnitQuaternion::from_rotation_matrix(r).scaled_axis()
}

/// The unit quaternion `[w, x, y, z]` of `r` with w ≥ 0 (one of the two signs, chosen so the
/// output is deterministic).
pub fn quaternion(r: &Rotation3<f64>) -> [f64; 4] {
    let q = UnitQuaternion::from_rotation_matrix(r);
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    [s * q.w, s * q.i, s * q.j, s * q.k]
}

/// A point moved by a rigid transform.
pub fn apply(g: &Isometry3<f64>, p: &Point3) -> Point3 {
    g.transform_point(p)
}

/// `v` with exactly `decimals` decimals, never `-0.000`.
pub fn fixed(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_owned(),
        _ => s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_vertical_tool_points_down_with_x_along_x() {
        let r = tool_rotation(&Vector3::z());
        assert!((r * Vector3::z() + Vector3::z()).norm() < 1e-12);
        assert!((r * Vector3::x() - Vector3::x()).norm() < 1e-12);
        // Half a turn about x: rotation vector (π, 0, 0), KUKA A 0 B 0 C ±180.
        let v = rotation_vector(&r);
        assert!((v.norm() - std::f64::consts::PI).abs() < 1e-9);
        let [a, b, c] = zyx_degrees(&r);
        assert!(a.abs() < 1e-9 && b.abs() < 1e-9 && (c.abs() - 180.0).abs() < 1e-9);
        // An axis along x takes +Y as its x direction.
        let r = tool_rotation(&Vector3::x());
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-12);
    }

    #[test]
    fn frames_turn_about_x_then_y_then_z() {
        let g = frame(&[1.0, 2.0, 3.0, 90.0, 0.0, 90.0]);
        // x → x → y; y → z → z.
        assert!((g.rotation * Vector3::x() - Vector3::y()).norm() < 1e-12);
        assert!((g.rotation * Vector3::y() - Vector3::z()).norm() < 1e-12);
        let p = apply(&g, &Point3::origin());
        assert!((p - Point3::new(1.0, 2.0, 3.0)).norm() < 1e-12);
        assert_eq!(fixed(-0.00004, 4), "0.0000");
        assert_eq!(fixed(-1.5, 2), "-1.50");
    }
}
