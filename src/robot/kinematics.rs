//! Forward kinematics of a serial arm from its Denavit–Hartenberg table: joint angles → the
//! flange pose in the robot's base frame.
//!
//! Place in the pipeline: robot calibration ([`super::tcp`]) turns logged joint angles into
//! flange poses with it, so a pivot calibration can start from what the controller shows. The
//! table comes from `[robot] dh` ([`crate::emit::robot::RobotSettings::dh`]).
//!
//! Standard convention: joint i contributes Aᵢ = Rot_z(θᵢ + offsetᵢ)·Trans_z(dᵢ)·Trans_x(aᵢ)·
//! Rot_x(αᵢ), and the flange pose is A₁·A₂·…·Aₙ (lengths in mm, angles in degrees).

use crate::geom::Vector3;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

/// Why a forward-kinematics call failed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum KinematicsError {
    /// The arm model has no joints.
    ///
    /// How to fix: set `[robot] dh` to one `[a, alpha, d, theta_offset]` row per joint.
    #[error("no arm model: [robot] dh is empty")]
    NoModel,
    /// A DH value is not a finite number.
    ///
    /// How to fix: correct the named row of `[robot] dh`.
    #[error("robot.dh[{row}] has a value that is not a finite number")]
    BadRow {
        /// 0-based row (joint) index.
        row: usize,
    },
    /// The number of joint angles differs from the number of DH rows.
    ///
    /// How to fix: give one angle per row of `[robot] dh`.
    #[error("{found} joint angle(s) given, the arm model has {expected} joints")]
    JointCount {
        /// Joints of the model.
        expected: usize,
        /// Angles given.
        found: usize,
    },
    /// A joint angle is not a finite number.
    ///
    /// How to fix: write the angle in degrees as a decimal number.
    #[error("joint {joint} angle is not a finite number")]
    BadAngle {
        /// 1-based joint number.
        joint: usize,
    },
}

/// One joint's Denavit–Hartenberg parameters (standard convention).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DhRow {
    /// Link length along the new x axis, mm.
    pub a: f64,
    /// Link twist about the new x axis, degrees.
    pub alpha_deg: f64,
    /// Link offset along the previous z axis, mm.
    pub d: f64,
    /// Added to the joint angle, degrees.
    pub theta_offset_deg: f64,
}

impl DhRow {
    /// The row from `[a mm, alpha deg, d mm, theta_offset deg]`, the `[robot] dh` layout.
    pub fn from_array(r: [f64; 4]) -> Self {
        Self {
            a: r[0],
            alpha_deg: r[1],
            d: r[2],
            theta_offset_deg: r[3],
        }
    }

    /// Aᵢ = Rot_z(θ + offset)·Trans_z(d)·Trans_x(a)·Rot_x(α) for the joint angle `theta_deg`.
    pub fn transform(&self, theta_deg: f64) -> Isometry3<f64> {
        let theta = (theta_deg + self.theta_offset_deg).to_radians();
        let rz = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), theta);
        let rx = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), self.alpha_deg.to_radians());
        // Rot_z and Trans_z commute, so Rot_z·Trans_z·Trans_x·Rot_x is a translation of
        // Rot_z·(a, 0, d) followed by the rotation Rot_z·Rot_x.
        let shift = rz * Vector3::new(self.a, 0.0, self.d);
        Isometry3::from_parts(Translation3::from(shift), rz * rx)
    }
}

/// A serial arm: its DH rows from the base to the flange.
#[derive(Debug, Clone, PartialEq)]
pub struct Arm {
    /// One row per joint, from the base.
    pub rows: Vec<DhRow>,
}

impl Arm {
    /// The arm of a `[robot] dh` table, checked (at least one row, finite values).
    pub fn from_dh(dh: &[[f64; 4]]) -> Result<Self, KinematicsError> {
        if dh.is_empty() {
            return Err(KinematicsError::NoModel);
        }
        if let Some(row) = dh.iter().position(|r| r.iter().any(|v| !v.is_finite())) {
            return Err(KinematicsError::BadRow { row });
        }
        Ok(Self {
            rows: dh.iter().map(|r| DhRow::from_array(*r)).collect(),
        })
    }

    /// Number of joints.
    pub fn joints(&self) -> usize {
        self.rows.len()
    }

    /// The flange pose in the base frame for `joints_deg` (one angle per row, degrees).
    pub fn forward(&self, joints_deg: &[f64]) -> Result<Isometry3<f64>, KinematicsError> {
        if joints_deg.len() != self.rows.len() {
            return Err(KinematicsError::JointCount {
                expected: self.rows.len(),
                found: joints_deg.len(),
            });
        }
        if let Some(k) = joints_deg.iter().position(|v| !v.is_finite()) {
            return Err(KinematicsError::BadAngle { joint: k + 1 });
        }
        Ok(self
            .rows
            .iter()
            .zip(joints_deg)
            .fold(Isometry3::identity(), |t, (row, &q)| t * row.transform(q)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point3;
    use nalgebra::Matrix3;

    fn close(a: &Isometry3<f64>, pos: [f64; 3], rot: Matrix3<f64>) {
        let p = a.translation.vector;
        assert!(
            (p - Vector3::from(pos)).norm() < 1e-9,
            "position {p:?}, expected {pos:?}"
        );
        let r = a.rotation.to_rotation_matrix().into_inner();
        assert!((r - rot).norm() < 1e-9, "rotation {r}, expected {rot}");
    }

    /// A planar two-link arm: links of 100 and 50 mm, no twist.
    fn planar() -> Arm {
        Arm::from_dh(&[[100.0, 0.0, 0.0, 0.0], [50.0, 0.0, 0.0, 0.0]]).expect("valid")
    }

    #[test]
    fn a_planar_arm_reaches_the_hand_computed_points() {
        let arm = planar();
        close(
            &arm.forward(&[0.0, 0.0]).expect("fk"),
            [150.0, 0.0, 0.0],
            Matrix3::identity(),
        );
        // Elbow up: 100 along y, then 50 along x with the orientation turned back.
        close(
            &arm.forward(&[90.0, -90.0]).expect("fk"),
            [50.0, 100.0, 0.0],
            Matrix3::identity(),
        );
        // Folded back: 100 along x, then 50 back along −x, facing −x.
        let half = Matrix3::new(-1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0);
        close(
            &arm.forward(&[0.0, 180.0]).expect("fk"),
            [50.0, 0.0, 0.0],
            half,
        );
    }

    #[test]
    fn offsets_and_twists_follow_the_standard_convention() {
        // One joint, a = 20, α = 90°, d = 10, offset 90°, at θ = 0.
        let arm = Arm::from_dh(&[[20.0, 90.0, 10.0, 90.0]]).expect("valid");
        let t = arm.forward(&[0.0]).expect("fk");
        // Rot_z(90°)·Rot_x(90°): x → y, y → z, z → x.
        let r = Matrix3::new(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
        close(&t, [0.0, 20.0, 10.0], r);
        // A point in the flange frame lands where the matrix product says.
        let p = t.transform_point(&Point3::new(1.0, 2.0, 3.0));
        assert!((p - Point3::new(3.0, 21.0, 12.0)).norm() < 1e-9, "{p}");
    }

    #[test]
    fn a_ur5_like_arm_at_zero_matches_the_hand_computed_pose() {
        // UR5 parameters (mm, degrees).
        let (d1, a2, a3, d4, d5, d6) = (89.159, -425.0, -392.25, 109.15, 94.65, 82.3);
        let arm = Arm::from_dh(&[
            [0.0, 90.0, d1, 0.0],
            [a2, 0.0, 0.0, 0.0],
            [a3, 0.0, 0.0, 0.0],
            [0.0, 90.0, d4, 0.0],
            [0.0, -90.0, d5, 0.0],
            [0.0, 0.0, d6, 0.0],
        ])
        .expect("valid");
        let t = arm.forward(&[0.0; 6]).expect("fk");
        // The arm stretched along −x, the flange facing −y: x stays, y → z, z → −y.
        let r = Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0);
        close(&t, [a2 + a3, -(d4 + d6), d1 - d5], r);
    }

    #[test]
    fn bad_models_and_angles_are_refused() {
        assert_eq!(Arm::from_dh(&[]), Err(KinematicsError::NoModel));
        assert_eq!(
            Arm::from_dh(&[[0.0; 4], [f64::NAN, 0.0, 0.0, 0.0]]),
            Err(KinematicsError::BadRow { row: 1 })
        );
        assert_eq!(
            planar().forward(&[1.0]),
            Err(KinematicsError::JointCount {
                expected: 2,
                found: 1
            })
        );
        assert_eq!(
            planar().forward(&[0.0, f64::INFINITY]),
            Err(KinematicsError::BadAngle { joint: 2 })
        );
    }
}
