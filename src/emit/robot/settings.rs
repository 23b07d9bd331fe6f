//! The robot writers' settings, the `[robot]` section of the configuration: six-axis arms and
//! five-axis machines that print conformal paths with the tool axis along the surface
//! (`conduit conform --dialect ...`, `conduit calibrate`, `conduit compensate`).
//!
//! Place in the pipeline: read with the rest of the config (`crate::config::Config::robot`);
//! the robot writers ([`super`]) take their frames and dispense commands from here, the walks
//! the arm's kinematics ([`crate::robot::kinematics`]) and the tool orientation's limits.
//! Lengths in mm, angles in degrees.
//!
//! # Frames
//!
//! A frame is `[x, y, z, rx, ry, rz]`: a translation in mm and a rotation in degrees,
//! R = Rz(rz)·Ry(ry)·Rx(rx) (turn about the fixed x axis first, then y, then z; KUKA's
//! A = rz, B = ry, C = rx). `workpiece_frame` places the frame of the conform program (the
//! machine frame of the scan and design) in the robot's base frame; `tool_frame` places the
//! tool centre point (TCP: the nozzle tip, z pointing out of the tool into the work) in the
//! flange frame.

use serde::{Deserialize, Serialize};

/// Robot and multi-axis settings (`[robot]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct RobotSettings {
    /// Denavit–Hartenberg parameters of the arm, one row per joint from the base:
    /// `[a mm, alpha deg, d mm, theta_offset deg]` (standard convention: joint i's transform is
    /// Rot_z(θᵢ + offset)·Trans_z(d)·Trans_x(a)·Rot_x(α)). Empty = no arm model (flange poses
    /// must then be given as positions and quaternions). Default empty.
    pub dh: Vec<[f64; 4]>,
    /// The conform program's frame in the robot base frame, `[x, y, z, rx, ry, rz]` (mm,
    /// degrees; see the module docs). Default all 0.
    pub workpiece_frame: [f64; 6],
    /// The tool centre point in the flange frame, `[x, y, z, rx, ry, rz]`. Default all 0.
    pub tool_frame: [f64; 6],
    /// Largest tilt of the tool axis from the vertical, degrees, in `--tool-axis normal`
    /// (`--max-tilt` overrides). Default 60.
    pub max_tilt: f64,
    /// Length of path over which surface normals are averaged into tool axes, mm (0 = none).
    /// Default 0.5.
    pub axis_smoothing: f64,
    /// Lift along the tool axis before and after every path, mm. Default 5.
    pub clearance: f64,
    /// Speed of travels, approaches and lifts, mm/s. Default 50.
    pub travel_speed: f64,
    /// Tool acceleration of URScript moves, mm/s². Default 500.
    pub acceleration: f64,
    /// Blend (approximation) radius between dispensing moves, mm; 0 = exact stop at every
    /// point. Default 0.05.
    pub blend: f64,
    /// Digital output that switches the dispenser: URScript `set_digital_out(n, ...)`, KRL
    /// `$OUT[n]`. Default 1.
    pub dispense_output: u32,
    /// Digital output signal of the dispenser in RAPID (`SetDO name, 1`). Default
    /// `"doDispense"`.
    pub dispense_signal: String,
    /// Five-axis G-code: `"ijk"` (`G1 X Y Z I J K`: tip and unit tool vector, for a controller
    /// with tool-centre-point interpolation), `"head"` (a tilting and rotating head: the pivot,
    /// `pivot_length` up the tool axis from the tip, and the rotary angles) or `"table"` (a
    /// tilting and rotating table: the part turned so the tool axis is vertical, the turned tip
    /// and the rotary angles). Default `"ijk"`.
    pub five_axis: FiveAxis,
    /// Rotary axes of a head or table: `"AC"` (tilt A about x, then C about z) or `"BC"` (tilt
    /// B about y, then C about z). Default `"AC"`.
    pub rotary_axes: RotaryAxes,
    /// Direction of each rotary axis: 1 when its positive turn is right-handed about +x/+y
    /// (tilt) and +z (C), −1 when reversed. Default [1, 1].
    pub rotary_signs: [f64; 2],
    /// Head: distance from the rotary pivot to the tool tip along the tool axis, mm. Default 0.
    pub pivot_length: f64,
    /// Table: where the rotary axes cross, in the program frame, mm. Default [0, 0, 0].
    pub table_centre: [f64; 3],
}

/// The machine of five-axis G-code (`five_axis`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum FiveAxis {
    /// `G1 X Y Z I J K`: tip and unit tool vector.
    #[default]
    Ijk,
    /// A tilting and rotating head.
    Head,
    /// A tilting and rotating table.
    Table,
}

/// The rotary axes of a five-axis head or table (`rotary_axes`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
pub enum RotaryAxes {
    /// Tilt A about x, then C about z.
    #[default]
    AC,
    /// Tilt B about y, then C about z.
    BC,
}

impl RotaryAxes {
    /// The axes' letters as written in the config and the G-code.
    pub fn name(self) -> &'static str {
        match self {
            RotaryAxes::AC => "AC",
            RotaryAxes::BC => "BC",
        }
    }
}

impl Default for RobotSettings {
    fn default() -> Self {
        Self {
            dh: Vec::new(),
            workpiece_frame: [0.0; 6],
            tool_frame: [0.0; 6],
            max_tilt: 60.0,
            axis_smoothing: 0.5,
            clearance: 5.0,
            travel_speed: 50.0,
            acceleration: 500.0,
            blend: 0.05,
            dispense_output: 1,
            dispense_signal: "doDispense".to_owned(),
            five_axis: FiveAxis::Ijk,
            rotary_axes: RotaryAxes::AC,
            rotary_signs: [1.0, 1.0],
            pivot_length: 0.0,
            table_centre: [0.0; 3],
        }
    }
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
        for (key, frame) in [
            ("workpiece_frame", &self.workpiece_frame),
            ("tool_frame", &self.tool_frame),
        ] {
            if let Some(i) = frame.iter().position(|v| !v.is_finite()) {
                out.push(format!(
                    "robot.{key}[{i}] is not a finite number (a frame is [x, y, z, rx, ry, rz] \
                     in mm and degrees)"
                ));
            }
        }
        if let Some(i) = self.table_centre.iter().position(|v| !v.is_finite()) {
            out.push(format!("robot.table_centre[{i}] is not a finite number"));
        }
        if !(self.max_tilt.is_finite() && (0.0..=90.0).contains(&self.max_tilt)) {
            out.push(format!(
                "robot.max_tilt must be in [0, 90] degrees, got {}",
                self.max_tilt
            ));
        }
        for (key, v) in [
            ("axis_smoothing", self.axis_smoothing),
            ("clearance", self.clearance),
            ("blend", self.blend),
            ("pivot_length", self.pivot_length),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                out.push(format!("robot.{key} must be ≥ 0, got {v}"));
            }
        }
        for (key, v) in [
            ("travel_speed", self.travel_speed),
            ("acceleration", self.acceleration),
        ] {
            if !(v.is_finite() && v > 0.0) {
                out.push(format!("robot.{key} must be > 0, got {v}"));
            }
        }
        let s = &self.dispense_signal;
        let identifier = s.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
            && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !identifier {
            out.push(format!(
                "robot.dispense_signal must be a RAPID signal name (a letter, then letters, \
                 digits or _), got `{s}`"
            ));
        }
        for (i, v) in self.rotary_signs.iter().enumerate() {
            if *v != 1.0 && *v != -1.0 {
                out.push(format!("robot.rotary_signs[{i}] must be 1 or -1, got {v}"));
            }
        }
        out
    }
}
