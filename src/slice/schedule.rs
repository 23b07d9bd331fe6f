//! Layer heights: which layers a print of a given height has, and where each one is sliced.

use thiserror::Error;

/// Heights closer than this (mm) are the same height: one step of the nanometre grid.
const SAME_Z_MM: f64 = 1e-6;

/// Planar slicing parameters, in millimetres.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SliceParams {
    /// Height of every layer above the first (mm). Default 0.2.
    pub layer_height: f64,
    /// Height of the first layer (mm). Default 0.2.
    pub first_layer_height: f64,
}

impl Default for SliceParams {
    fn default() -> Self {
        Self {
            layer_height: 0.2,
            first_layer_height: 0.2,
        }
    }
}

/// A [`SliceParams`] value that cannot be sliced with.
///
/// # How to fix
/// Give both heights as finite numbers greater than zero (in millimetres, e.g. `0.2`).
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum SliceParamsError {
    /// `layer_height` is zero, negative or not finite.
    #[error("layer height must be a finite number > 0 mm, got {0}")]
    LayerHeight(f64),
    /// `first_layer_height` is zero, negative or not finite.
    #[error("first layer height must be a finite number > 0 mm, got {0}")]
    FirstLayerHeight(f64),
}

impl SliceParams {
    /// Parameters after checking both heights with [`SliceParams::validate`].
    pub fn new(layer_height: f64, first_layer_height: f64) -> Result<Self, SliceParamsError> {
        let p = Self {
            layer_height,
            first_layer_height,
        };
        p.validate()?;
        Ok(p)
    }

    /// Checks that both heights are finite and greater than zero.
    pub fn validate(&self) -> Result<(), SliceParamsError> {
        let ok = |h: f64| h.is_finite() && h > 0.0;
        if !ok(self.layer_height) {
            return Err(SliceParamsError::LayerHeight(self.layer_height));
        }
        if !ok(self.first_layer_height) {
            return Err(SliceParamsError::FirstLayerHeight(self.first_layer_height));
        }
        Ok(())
    }
}

/// One layer's place in z (mm).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LayerZ {
    /// 0 for the first layer, counting up.
    pub index: usize,
    /// Bottom of the layer: the previous layer's top, 0 for the first layer.
    pub bottom: f64,
    /// Top of the layer: the nozzle height when printing it (PrusaSlicer's `print_z`).
    pub top: f64,
    /// The plane the mesh is cut at: the middle of the layer.
    pub slice_z: f64,
}

impl LayerZ {
    /// The layer's thickness, `top - bottom`.
    pub fn height(&self) -> f64 {
        self.top - self.bottom
    }
}

/// The layers of an object whose top is at `max_z` (bottom at z = 0), as PrusaSlicer's
/// `generate_object_layers` makes them for a fixed layer height:
///
/// - the first layer spans `0..first_layer_height` and is always present when `max_z > 0`;
/// - layer `k ≥ 1` spans `first + (k−1)·h .. first + k·h` and is present while its middle
///   (`slice_z`) lies strictly below `max_z`.
///
/// So a last partial layer is kept, at full height, when the object reaches past its middle, and
/// dropped otherwise (a 20 mm cube at 0.2 mm gets 100 layers; one 20.05 mm tall also 100, one
/// 20.15 mm tall 101). CuraEngine counts the same way for the default "middle" slicing tolerance.
/// Tops are computed as `first + k·h`, not by accumulation, so they carry no drift.
///
/// Invalid parameters (see [`SliceParams::validate`]) or a non-positive / non-finite `max_z` give
/// no layers.
pub fn layer_schedule(max_z: f64, params: &SliceParams) -> Vec<LayerZ> {
    if params.validate().is_err() || !max_z.is_finite() || max_z <= 0.0 {
        return Vec::new();
    }
    let (first, h) = (params.first_layer_height, params.layer_height);
    let mut layers = vec![LayerZ {
        index: 0,
        bottom: 0.0,
        top: first,
        slice_z: first / 2.0,
    }];
    for k in 1.. {
        let bottom = first + (k - 1) as f64 * h;
        let slice_z = bottom + h / 2.0;
        // A middle within a nanometre of the top counts as at the top: the two are equal on the
        // scaled grid, and this keeps rounding (0.3 + 48·0.2 + 0.1 ≠ 10.0) from adding a layer.
        if slice_z >= max_z - SAME_Z_MM {
            break;
        }
        layers.push(LayerZ {
            index: k,
            bottom,
            top: first + k as f64 * h,
            slice_z,
        });
    }
    layers
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twenty_mm_at_point_two_gives_one_hundred_layers() {
        let l = layer_schedule(20.0, &SliceParams::default());
        assert_eq!(l.len(), 100);
        for (k, layer) in l.iter().enumerate() {
            assert_eq!(layer.index, k);
            assert!((layer.top - 0.2 * (k + 1) as f64).abs() < 1e-9);
            assert!((layer.slice_z - (0.2 * k as f64 + 0.1)).abs() < 1e-9);
        }
        assert!((l[99].top - 20.0).abs() < 1e-9);
    }

    #[test]
    fn partial_last_layer_follows_prusaslicer() {
        let p = SliceParams::default();
        assert_eq!(layer_schedule(20.05, &p).len(), 100);
        assert_eq!(layer_schedule(20.15, &p).len(), 101);
        assert_eq!(layer_schedule(0.05, &p).len(), 1);
        assert!(layer_schedule(0.0, &p).is_empty());
    }

    #[test]
    fn thicker_first_layer() {
        let p = SliceParams::new(0.2, 0.3).expect("valid");
        let l = layer_schedule(10.0, &p);
        // 0.3, then 0.5 .. 9.9 (slice 9.8 < 10), then 10.1 (slice 10.0 is not below 10).
        assert_eq!(l.len(), 49);
        assert_eq!(
            l[0],
            LayerZ {
                index: 0,
                bottom: 0.0,
                top: 0.3,
                slice_z: 0.15
            }
        );
        assert!((l[1].bottom - 0.3).abs() < 1e-12 && (l[1].top - 0.5).abs() < 1e-12);
        assert!((l[1].slice_z - 0.4).abs() < 1e-12);
        assert!((l[48].top - 9.9).abs() < 1e-9);
        for w in l.windows(2) {
            assert_eq!(w[0].top, w[1].bottom);
            assert!((w[1].height() - 0.2).abs() < 1e-9);
        }
    }

    #[test]
    fn invalid_params_are_typed_errors() {
        assert_eq!(
            SliceParams::new(0.0, 0.2),
            Err(SliceParamsError::LayerHeight(0.0))
        );
        assert_eq!(
            SliceParams::new(0.2, -1.0),
            Err(SliceParamsError::FirstLayerHeight(-1.0))
        );
        assert!(SliceParams::new(f64::NAN, 0.2).is_err());
        let bad = SliceParams {
            layer_height: 0.0,
            first_layer_height: 0.2,
        };
        assert!(layer_schedule(10.0, &bad).is_empty());
    }
}
