//! The `[curved]` section of the configuration: non-planar top surfaces.
//!
//! Place in the pipeline: read with the rest of [`super::Config`]; the pipeline hands it to
//! [`crate::curved`], which runs between slicing and the regions stage and adds the curved
//! layers to the Program.

use serde::{Deserialize, Serialize};

/// Which curved-layer mode a slice uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CurvedMode {
    /// Planar layers only.
    #[default]
    Off,
    /// Planar body; the top solid layers of gently sloped top surfaces follow the surface.
    Tops,
}

/// Non-planar top surfaces (`[curved]`). Lengths in mm, angles in degrees from the horizontal
/// (slopes) or from the vertical (the head cone), speeds in mm/s.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CurvedSettings {
    /// `"off"` or `"tops"` (also set by `conduit slice --curved tops`). Default `"off"`.
    pub mode: CurvedMode,
    /// Steepest surface slope printed curved, degrees from the horizontal; steeper top surfaces
    /// stay planar (the nozzle would plough its own bead). Default 15.
    pub max_angle: f64,
    /// Longest segment of a curved path, mm: paths are split at every triangle edge of the
    /// surface and wherever needed to keep segments this short. Default 0.5.
    pub step: f64,
    /// Half-angle of the print head's cone around the nozzle, degrees from the vertical.
    /// Default 60.
    pub head_angle: f64,
    /// Height of the head's cone above the nozzle tip, mm. Default 5.
    pub head_height: f64,
    /// Radius of the carriage cylinder around the nozzle axis, mm; 0 = not modelled.
    /// Default 0.
    pub carriage_radius: f64,
    /// Height of the carriage cylinder's bottom above the nozzle tip, mm. Default 10.
    pub carriage_clearance: f64,
    /// Fastest z motion while extruding, mm/s: moves that would rise or fall faster are
    /// slowed. Default 10.
    pub max_z_speed: f64,
}

impl Default for CurvedSettings {
    fn default() -> Self {
        Self {
            mode: CurvedMode::Off,
            max_angle: 15.0,
            step: 0.5,
            head_angle: 60.0,
            head_height: 5.0,
            carriage_radius: 0.0,
            carriage_clearance: 10.0,
            max_z_speed: 10.0,
        }
    }
}

impl CurvedSettings {
    /// Every value out of range, as `curved.key ...` messages.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        let ranges = [
            ("max_angle", self.max_angle, 0.0, 89.0),
            ("step", self.step, 0.01, 100.0),
            ("head_angle", self.head_angle, 0.0, 89.0),
            ("head_height", self.head_height, 0.0, 1000.0),
            ("carriage_radius", self.carriage_radius, 0.0, 1000.0),
            ("carriage_clearance", self.carriage_clearance, 0.0, 1000.0),
            ("max_z_speed", self.max_z_speed, 0.01, 10000.0),
        ];
        for (key, v, lo, hi) in ranges {
            if !(v.is_finite() && v >= lo && v <= hi) {
                out.push(format!("curved.{key} must be in {lo}..={hi}, got {v}"));
            }
        }
        out
    }
}
