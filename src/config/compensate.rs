//! The `[compensate]` section of the configuration: gap compensation of robot paths from
//! measured tool-to-surface gaps (`conduit compensate`).
//!
//! Place in the pipeline: read with the rest of [`super::Config`]; `conduit compensate` hands
//! it to the gap compensation in [`crate::conform`]. Lengths in mm, angles in degrees.

use serde::{Deserialize, Serialize};

/// Gap compensation settings (`[compensate]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CompensateSettings {
    /// Gap the compensation aims for, mm. Default 0.05.
    pub target: f64,
}

impl Default for CompensateSettings {
    fn default() -> Self {
        Self { target: 0.05 }
    }
}

impl CompensateSettings {
    /// Problems with the values, one line each.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        if !(self.target.is_finite() && self.target >= 0.0) {
            out.push(format!(
                "compensate.target must be ≥ 0, got {}",
                self.target
            ));
        }
        out
    }
}

/// Documentation of the `[compensate]` keys for `conduit config --defaults`.
pub(super) const KEYS: &[super::defaults::KeyDoc] = &[super::defaults::k(
    "compensate",
    "target",
    "Tool-to-surface gap the compensation aims for, mm (--target overrides, in µm).",
)];
