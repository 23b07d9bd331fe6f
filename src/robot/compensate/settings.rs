//! Gap compensation's settings, the `[compensate]` section of the configuration: the target gap,
//! the smoothing, the sensor, the robot error model of the simulation mode and the calibration
//! print patterns (`conduit compensate`).
//!
//! Place in the pipeline: read with the rest of the config
//! (`crate::config::Config::compensate`); the compensate walk hands it to every pass.
//! Lengths in mm, angles in degrees.

use serde::{Deserialize, Serialize};

/// Gap compensation settings (`[compensate]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct CompensateSettings {
    /// Gap the compensation aims for, mm. Default 0.05.
    pub target: f64,
    /// Standard deviation of the Gaussian that smooths the corrections along the path, mm of
    /// arc length; 0 = no smoothing. Default 0.5.
    pub smoothing: f64,
    /// Angle between the displacement sensor's beam and the tool axis, degrees, in [0, 90):
    /// a reading h is the gap h·cos(angle). Default 0.
    pub sensor_angle: f64,
    /// Measure → compensate passes of the simulation. Default 1.
    pub passes: u32,
    /// Simulation: shift of the real substrate from the nominal one, [dx, dy, dz] mm.
    /// Default [0, 0, 0].
    pub error_shift: [f64; 3],
    /// Simulation: turn of the real substrate about `error_axis` through the middle of the
    /// path, degrees. Default 0.
    pub error_tilt: f64,
    /// Simulation: axis of `error_tilt` (any length but zero). Default [1, 0, 0].
    pub error_axis: [f64; 3],
    /// Simulation: tool-length error, mm: the real tip stands this far further back along the
    /// tool axis than commanded, adding it to every gap. Default 0.
    pub error_z: f64,
    /// Simulation: standard deviation of the sensor noise added to each reading, mm.
    /// Default 0.
    pub noise: f64,
    /// Simulation: seed of the sensor noise (same seed, same readings). Default 1.
    pub seed: u64,
    /// Patterns: distance between neighbouring points along the pattern, mm. Default 0.1.
    pub pattern_spacing: f64,
    /// Patterns: distance between neighbouring lines of a serpentine or turns of a spiral, mm.
    /// Default 1.
    pub pattern_pitch: f64,
}

impl Default for CompensateSettings {
    fn default() -> Self {
        Self {
            target: 0.05,
            smoothing: 0.5,
            sensor_angle: 0.0,
            passes: 1,
            error_shift: [0.0; 3],
            error_tilt: 0.0,
            error_axis: [1.0, 0.0, 0.0],
            error_z: 0.0,
            noise: 0.0,
            seed: 1,
            pattern_spacing: 0.1,
            pattern_pitch: 1.0,
        }
    }
}

impl CompensateSettings {
    /// Problems with the values, one line each.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (key, v) in [
            ("target", self.target),
            ("smoothing", self.smoothing),
            ("noise", self.noise),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                out.push(format!("compensate.{key} must be ≥ 0, got {v}"));
            }
        }
        for (key, v) in [
            ("pattern_spacing", self.pattern_spacing),
            ("pattern_pitch", self.pattern_pitch),
        ] {
            if !(v.is_finite() && v > 0.0) {
                out.push(format!("compensate.{key} must be > 0, got {v}"));
            }
        }
        if !(0.0..90.0).contains(&self.sensor_angle) {
            out.push(format!(
                "compensate.sensor_angle must be in [0, 90), got {}",
                self.sensor_angle
            ));
        }
        if self.passes == 0 {
            out.push("compensate.passes must be at least 1".to_owned());
        }
        let finite = |v: &[f64]| v.iter().all(|c| c.is_finite());
        if !finite(&self.error_shift) || !finite(&[self.error_tilt, self.error_z]) {
            out.push("compensate.error_* values must be finite numbers".to_owned());
        }
        let axis = self.error_axis;
        if !finite(&axis) || axis.iter().map(|c| c * c).sum::<f64>() < 1e-18 {
            out.push(format!(
                "compensate.error_axis must be a non-zero direction, got {axis:?}"
            ));
        }
        out
    }
}
