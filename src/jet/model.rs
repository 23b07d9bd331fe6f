//! The accumulation model at a bend: how much higher the inside of a corner grows than the
//! outside, from mass conservation over strips of the line.
//!
//! Place in the pipeline: a side branch: `conduit jet model` evaluates it for given numbers, and
//! the report evaluates it per corner after filleting.
//!
//! # Model
//!
//! The line of width `w` is cut into `n` strips (here [`STRIPS`] = 100) whose centres sit at
//! offsets `l` from `−w/2` to `w/2` (strip midpoints, `l_i = −w/2 + (i + ½)·w/n`); positive `l`
//! lies towards the inside of the bend. A strip's radius through a corner of angle `θ`
//! (180° = straight) and centreline fillet radius `r` is `R = 0` when `l ≥ r` and `l ≥ 0` (the
//! strip turns sharply), otherwise `R = r − l`. Its length inside a region of interest of
//! centreline length `l_ROI` is
//!
//! - `Δ = l_ROI − r(π − θ) − 2(l − r)/tan(θ/2)` when `R = 0`,
//! - `Δ = l_ROI + (R − r)(π − θ)` otherwise.
//!
//! `L_in` and `L_out` sum `Δ` over the inner (`l > 0`) and outer (`l < 0`) strips. Each half of
//! the line receives the same material, so the heights are `h_in = h·d_in` and
//! `h_out = h·d_out` with `d_in = (L_out + L_in)/(2 L_in)`, `d_out = (L_out + L_in)/(2 L_out)`;
//! the model's answer is `h_in − h_out`. Measured walls level out much of this before they dry
//! (the bare model over-predicts by about an order of magnitude), so reports multiply it by
//! `jet.leveling_factor`.

use serde::Serialize;
use std::f64::consts::PI;

/// Number of strips the line is cut into.
pub const STRIPS: usize = 100;

/// Why the model cannot be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// An input is out of range.
    ///
    /// How to fix: angle in (0, 180] degrees, radius ≥ 0, width, height and ROI > 0.
    #[error("{name} must be {expected}, got {value}")]
    Input {
        /// Which input.
        name: &'static str,
        /// Allowed range.
        expected: &'static str,
        /// The value given.
        value: f64,
    },
    /// Some strip has no length left inside the region of interest: the corner (its fillet and
    /// the sharp inner strips' cut-off) is longer than the ROI.
    ///
    /// How to fix: use a longer region of interest.
    #[error(
        "the region of interest ({roi}) is too short for this corner: a strip at offset {offset} has length {length}"
    )]
    RoiTooShort {
        /// The ROI length.
        roi: f64,
        /// Offset of the first strip without length.
        offset: f64,
        /// Its length.
        length: f64,
    },
}

/// The model's inputs, in one length unit (µm or mm, the result is in the same unit).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModelInput {
    /// Corner angle θ between the two segments, degrees (180 = straight).
    pub angle_deg: f64,
    /// Fillet radius of the centreline, `r`.
    pub radius: f64,
    /// Line width `w`.
    pub width: f64,
    /// Nominal height `h` of the line.
    pub height: f64,
    /// Region of interest `l_ROI` along the centreline.
    pub roi: f64,
}

/// The model's result.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModelResult {
    /// Summed strip length of the inner half, `L_in`.
    pub l_in: f64,
    /// Summed strip length of the outer half, `L_out`.
    pub l_out: f64,
    /// Height factor of the inner half, `d_in`.
    pub d_in: f64,
    /// Height factor of the outer half, `d_out`.
    pub d_out: f64,
    /// Inner height `h·d_in`.
    pub h_in: f64,
    /// Outer height `h·d_out`.
    pub h_out: f64,
    /// `h_in − h_out`, the bare model's prediction.
    pub difference: f64,
}

/// Evaluates the model (see the [module docs](self)).
pub fn accumulation(input: &ModelInput) -> Result<ModelResult, ModelError> {
    let ModelInput {
        angle_deg,
        radius: r,
        width: w,
        height: h,
        roi,
    } = *input;
    let check = |name, ok: bool, expected, value| {
        if ok {
            Ok(())
        } else {
            Err(ModelError::Input {
                name,
                expected,
                value,
            })
        }
    };
    check(
        "angle",
        angle_deg.is_finite() && angle_deg > 0.0 && angle_deg <= 180.0,
        "in (0, 180] degrees",
        angle_deg,
    )?;
    check("radius", r.is_finite() && r >= 0.0, "≥ 0", r)?;
    check("width", w.is_finite() && w > 0.0, "> 0", w)?;
    check("height", h.is_finite() && h > 0.0, "> 0", h)?;
    check("roi", roi.is_finite() && roi > 0.0, "> 0", roi)?;
    let theta = angle_deg.to_radians();
    let turn = PI - theta;
    let (mut l_in, mut l_out) = (0.0, 0.0);
    for i in 0..STRIPS {
        let l = -w / 2.0 + (i as f64 + 0.5) * w / STRIPS as f64;
        let sharp = l >= r && l >= 0.0;
        let delta = if sharp {
            roi - r * turn - 2.0 * (l - r) / (theta / 2.0).tan()
        } else {
            let big_r = r - l;
            roi + (big_r - r) * turn
        };
        if delta <= 0.0 {
            return Err(ModelError::RoiTooShort {
                roi,
                offset: l,
                length: delta,
            });
        }
        if l > 0.0 {
            l_in += delta;
        } else {
            l_out += delta;
        }
    }
    let d_in = (l_out + l_in) / (2.0 * l_in);
    let d_out = (l_out + l_in) / (2.0 * l_out);
    Ok(ModelResult {
        l_in,
        l_out,
        d_in,
        d_out,
        h_in: h * d_in,
        h_out: h * d_out,
        difference: h * (d_in - d_out),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_line_has_no_difference_and_bad_inputs_are_errors() -> Result<(), ModelError> {
        let straight = ModelInput {
            angle_deg: 180.0,
            radius: 0.0,
            width: 35.0,
            height: 14.0,
            roi: 150.0,
        };
        let m = accumulation(&straight)?;
        assert!(m.difference.abs() < 1e-9);
        assert!((m.l_in - 50.0 * 150.0).abs() < 1e-9);
        let short = ModelInput {
            angle_deg: 10.0,
            roi: 20.0,
            ..straight
        };
        assert!(matches!(
            accumulation(&short),
            Err(ModelError::RoiTooShort { .. })
        ));
        let bad = ModelInput {
            angle_deg: 0.0,
            ..straight
        };
        assert!(matches!(
            accumulation(&bad),
            Err(ModelError::Input { name: "angle", .. })
        ));
        Ok(())
    }
}
