//! The `[robot]` section of the configuration: six-axis arms and five-axis machines that print
//! conformal paths with the tool axis along the surface (`conduit conform --output ...`,
//! `conduit calibrate`, `conduit compensate`).
//!
//! Place in the pipeline: read with the rest of [`super::Config`]; the robot emitters in
//! [`crate::emit`] and the calibration in [`crate::conform`] take their frames, kinematics and
//! dispense commands from here. Lengths in mm, angles in degrees.

use serde::{Deserialize, Serialize};

/// Robot and multi-axis settings (`[robot]`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RobotSettings {
    /// Denavit–Hartenberg parameters of the arm, one row per joint from the base:
    /// `[a mm, alpha deg, d mm, theta_offset deg]` (standard convention: joint i's transform is
    /// Rot_z(θᵢ + offset)·Trans_z(d)·Trans_x(a)·Rot_x(α)). Empty = no arm model (flange poses
    /// must then be given as positions and quaternions). Default empty.
    pub dh: Vec<[f64; 4]>,
}

impl RobotSettings {
    /// Problems with the values, one line each.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (i, row) in self.dh.iter().enumerate() {
            if row.iter().any(|v| !v.is_finite()) {
                out.push(format!(
                    "robot.dh[{i}] has a value that is not a finite number"
                ));
            }
        }
        out
    }
}

/// Documentation of the `[robot]` keys for `conduit config --defaults`.
pub(super) const KEYS: &[super::defaults::KeyDoc] = &[super::defaults::k(
    "robot",
    "dh",
    "Denavit–Hartenberg rows of the arm from the base, [a mm, alpha deg, d mm, theta_offset deg] \
     (standard convention); empty = no arm model.",
)];
