//! Parameters of the regions stage and the extrusion spacing model they imply.
//!
//! # Flow model
//!
//! An extrusion of width `w` and height `h` is modelled, as in PrusaSlicer's `Flow`, as a rectangle
//! with two semicircular ends (a rounded rectangle): area `(w − h)·h + π·h²/4`. Two adjacent
//! extrusions touch along their flat sides and overlap only where the rounded ends would leave a
//! void, so the distance between their centrelines (the *spacing*) is
//!
//! ```text
//! spacing = w − h·(1 − π/4)
//! ```
//!
//! For `w = 0.45 mm` and `h = 0.2 mm` this is `0.45 − 0.2·0.2146 = 0.40708 mm`. Every distance
//! between neighbouring loops or lines in this module is such a spacing; the distance from an
//! island's edge to its external loop's centreline is half the external perimeter *width*, so the
//! printed outer surface lands on the sliced contour.

use super::brim::BrimParams;
use super::support::SupportParams;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which infill pattern sparse infill uses (solid infill is always rectilinear at 100 %).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum InfillPatternKind {
    /// Parallel lines, direction alternating by 90° layer by layer.
    #[default]
    Rectilinear,
    /// Lines in both directions on every layer.
    Grid,
    /// Three line families at 60° forming equilateral triangles on every layer.
    Triangles,
}

/// How the perimeter band of an island is laid out (see [`crate::region::perimeters`]).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum PerimeterGenerator {
    /// Loops never run over themselves, and what they leave is filled with beads whose number
    /// and width follow the local thickness (PrusaSlicer's and Cura's Arachne in effect): thin
    /// and tapering walls print at their true thickness. PrusaSlicer's `arachne` maps here.
    #[default]
    Variable,
    /// PrusaSlicer's classic generator: loops of fixed width that may overlap themselves by up to
    /// 40 % in narrow places, single gap-fill lines between them.
    Classic,
}

/// Parameters of perimeter, skin, infill and skirt generation. Lengths in millimetres.
///
/// The config builds it from the `[slice]` keys of the same names, whose documentation gives
/// each one's reasons and default. [`RegionParams::default`] gives PrusaSlicer's values for a
/// 0.4 mm nozzle at 0.2 mm layers.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionParams {
    /// Number of perimeter loops per island, the external one included.
    pub perimeters: usize,
    /// Extrusion width of the external (outermost) loop, mm.
    pub external_perimeter_width: f64,
    /// Extrusion width of the inner loops, mm.
    pub perimeter_width: f64,
    /// Extrusion width of sparse infill lines, mm.
    pub infill_width: f64,
    /// Extrusion width of solid (bottom and internal solid) infill lines, mm.
    pub solid_infill_width: f64,
    /// Extrusion width of top solid infill lines (the visible upper surfaces), mm.
    pub top_solid_infill_width: f64,
    /// Extrusion width of every extrusion on the first layer, mm.
    pub first_layer_width: f64,
    /// Number of solid layers under every upward-facing surface.
    pub top_solid_layers: usize,
    /// Number of solid layers over every downward-facing surface (and at the bed).
    pub bottom_solid_layers: usize,
    /// Density of sparse infill, 0 (none) to 1 (solid).
    pub infill_density: f64,
    /// Pattern of sparse infill.
    pub infill_pattern: InfillPatternKind,
    /// Base direction of infill lines, degrees counter-clockwise from +X.
    pub infill_angle_deg: f64,
    /// How far infill reaches into the innermost perimeter, a fraction of `perimeter_width`.
    pub infill_overlap: f64,
    /// How far solid areas are grown into the neighbouring sparse area, mm.
    pub solid_infill_margin: f64,
    /// Sparse areas smaller than this (mm²) are filled solid instead; 0 = off.
    pub solid_infill_below_area: f64,
    /// Fill the strips between perimeter loops too narrow for another loop
    /// ([`crate::region::gapfill`]).
    pub gap_fill: bool,
    /// Print the external loop of each island first (better dimensional accuracy, worse overhangs).
    pub external_perimeters_first: bool,
    /// How the perimeter band is laid out.
    pub perimeter_generator: PerimeterGenerator,
    /// Print the parts of an island too thin for its external loop as variable-width lines
    /// along their middle, instead of leaving them out.
    pub thin_walls: bool,
    /// Number of skirt loops around the first layer.
    pub skirt_loops: usize,
    /// Clear gap between the first layer's islands and the inner edge of the skirt, mm.
    pub skirt_distance: f64,
    /// Brim on the first layer.
    pub brim: BrimParams,
    /// Support material.
    pub support: SupportParams,
    /// Nozzle diameter, mm.
    pub nozzle_diameter: f64,
    /// Layer height, mm, used in the spacing formula when no per-layer heights are given.
    pub layer_height: f64,
    /// Find where perimeter beads hang out over the layer below
    /// ([`LayerRegions::overhangs`](super::LayerRegions::overhangs)).
    pub overhangs: bool,
}

impl Default for RegionParams {
    fn default() -> Self {
        Self {
            perimeters: 2,
            external_perimeter_width: 0.45,
            perimeter_width: 0.45,
            infill_width: 0.45,
            solid_infill_width: 0.45,
            top_solid_infill_width: 0.45,
            first_layer_width: 0.45,
            top_solid_layers: 3,
            bottom_solid_layers: 3,
            infill_density: 0.2,
            infill_pattern: InfillPatternKind::Rectilinear,
            infill_angle_deg: 45.0,
            infill_overlap: 0.25,
            solid_infill_margin: 3.0,
            solid_infill_below_area: 70.0,
            gap_fill: true,
            external_perimeters_first: false,
            perimeter_generator: PerimeterGenerator::Variable,
            thin_walls: true,
            skirt_loops: 0,
            skirt_distance: 6.0,
            brim: BrimParams::default(),
            support: SupportParams::default(),
            nozzle_diameter: 0.4,
            layer_height: 0.2,
            overhangs: true,
        }
    }
}

/// Most perimeter loops per island: 100 loops of 0.45 mm make a 45 mm wall, past which any
/// real part is solid; the bound keeps a mistyped count from sizing the loop plan.
pub const MAX_PERIMETERS: usize = 100;
/// Most top or bottom solid layers: 100 layers are 20 mm of solid shell at 0.2 mm (a thicker
/// shell is a solid part, `infill_density = 1`); skin detection keeps a window of this many
/// layers per layer.
pub const MAX_SOLID_LAYERS: usize = 100;
/// Most skirt loops: a skirt primes the nozzle and marks the print area; 100 loops of 0.45 mm
/// are a 45 mm band, more than any print uses.
pub const MAX_SKIRT_LOOPS: usize = 100;
/// Thinnest layer, mm: below 10 µm no FFF machine positions z reliably, and the layer count
/// (print height / layer height) would run into the millions.
pub const MIN_LAYER_HEIGHT: f64 = 0.01;
/// Smallest and largest nozzle diameter, mm: micro nozzles start at 0.05 mm, large-format
/// pellet extruders end around 5 mm.
pub const NOZZLE_RANGE: [f64; 2] = [0.05, 5.0];
/// Widest extrusion, in nozzle diameters (PrusaSlicer's limit): a wider bead is no longer
/// pressed flat under the nozzle's tip.
pub const MAX_WIDTH_NOZZLES: f64 = 3.0;
/// Widest extrusion, mm, whatever the nozzle.
pub const MAX_WIDTH: f64 = 10.0;
/// Largest `solid_infill_margin`, mm: the margin anchors a skin on the infill around it; a few
/// mm do that, and past 100 mm the whole layer is solid anyway.
pub const MAX_SOLID_INFILL_MARGIN: f64 = 100.0;

/// One problem found by [`RegionParams::validate`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// A length that must be finite and positive is not.
    ///
    /// How to fix: give a positive number of millimetres.
    #[error("{field} must be a finite length > 0 mm, got {value}")]
    NotPositive {
        /// The field name.
        field: &'static str,
        /// The value given.
        value: f64,
    },
    /// An extrusion is narrower than the nozzle or not wider than the layer is high, so the flow
    /// model has no meaning.
    ///
    /// How to fix: use widths between the nozzle diameter and about 2× it, and above the layer
    /// height.
    #[error(
        "{field} = {width} mm must be ≥ nozzle_diameter ({nozzle}) and > layer height ({height})"
    )]
    BadWidth {
        /// The field name.
        field: &'static str,
        /// The width given.
        width: f64,
        /// The nozzle diameter.
        nozzle: f64,
        /// The layer height.
        height: f64,
    },
    /// An extrusion is wider than a nozzle can lay down.
    ///
    /// How to fix: use widths up to 3 nozzle diameters (and at most 10 mm); the usual width is
    /// about 1.1 nozzle diameters.
    #[error("{field} must be at most {max} mm (3 × nozzle_diameter, at most 10 mm), got {width}")]
    TooWide {
        /// The field name.
        field: &'static str,
        /// The width given.
        width: f64,
        /// The widest allowed for this nozzle.
        max: f64,
    },
    /// A count is larger than any print uses.
    ///
    /// How to fix: give a count up to the bound named in the message (and in the key's
    /// documentation, `conduit config --defaults`).
    #[error("{field} must be at most {max}, got {value}")]
    TooMany {
        /// The field name.
        field: &'static str,
        /// The count given.
        value: usize,
        /// The largest count allowed.
        max: usize,
    },
    /// A length is outside the range a printer can use.
    ///
    /// How to fix: give a length within the bounds named in the message.
    #[error("{field} must be between {min} and {max} mm, got {value}")]
    OutOfRange {
        /// The field name.
        field: &'static str,
        /// The value given.
        value: f64,
        /// The smallest value allowed.
        min: f64,
        /// The largest value allowed.
        max: f64,
    },
    /// A fraction is outside its range.
    ///
    /// How to fix: `infill_density` is between 0 and 1, `infill_overlap` between 0 and 1.
    #[error("{field} must be between 0 and 1, got {value}")]
    NotAFraction {
        /// The field name.
        field: &'static str,
        /// The value given.
        value: f64,
    },
    /// An angle is infinite or NaN.
    ///
    /// How to fix: give a finite number of degrees.
    #[error("{field} must be finite, got {value}")]
    NotFinite {
        /// The field name.
        field: &'static str,
        /// The value given.
        value: f64,
    },
    /// A length that may be zero is negative or not finite.
    ///
    /// How to fix: give zero or a positive number of millimetres.
    #[error("{field} must be a finite length ≥ 0 mm, got {value}")]
    Negative {
        /// The field name.
        field: &'static str,
        /// The value given.
        value: f64,
    },
    /// A support setting is unusable (the message names it and its range).
    ///
    /// How to fix: correct the named `[support]` key.
    #[error("{0}")]
    Support(String),
}

/// Distance between the centrelines of two adjacent extrusions of width `width` and height
/// `height` (mm): `width − height·(1 − π/4)`, the rounded-rectangle model of the module docs.
pub fn spacing(width: f64, height: f64) -> f64 {
    width - height * (1.0 - PI / 4.0)
}

impl RegionParams {
    /// Every problem with these parameters (empty when they are usable).
    pub fn validate(&self) -> Vec<ParamError> {
        let mut errors = Vec::new();
        for (field, value) in [
            ("nozzle_diameter", self.nozzle_diameter),
            ("layer_height", self.layer_height),
        ] {
            if !(value.is_finite() && value > 0.0) {
                errors.push(ParamError::NotPositive { field, value });
            }
        }
        let nozzle_ok = (NOZZLE_RANGE[0]..=NOZZLE_RANGE[1]).contains(&self.nozzle_diameter);
        if self.nozzle_diameter > 0.0 && !nozzle_ok {
            errors.push(ParamError::OutOfRange {
                field: "nozzle_diameter",
                value: self.nozzle_diameter,
                min: NOZZLE_RANGE[0],
                max: NOZZLE_RANGE[1],
            });
        }
        // A layer higher than the nozzle is wide is not pressed onto the one below.
        let max_height = if nozzle_ok {
            self.nozzle_diameter
        } else {
            NOZZLE_RANGE[1]
        };
        if self.layer_height > 0.0 && !(MIN_LAYER_HEIGHT..=max_height).contains(&self.layer_height)
        {
            errors.push(ParamError::OutOfRange {
                field: "layer_height",
                value: self.layer_height,
                min: MIN_LAYER_HEIGHT,
                max: max_height,
            });
        }
        for (field, value, max) in [
            ("perimeters", self.perimeters, MAX_PERIMETERS),
            ("top_solid_layers", self.top_solid_layers, MAX_SOLID_LAYERS),
            (
                "bottom_solid_layers",
                self.bottom_solid_layers,
                MAX_SOLID_LAYERS,
            ),
            ("skirt_loops", self.skirt_loops, MAX_SKIRT_LOOPS),
        ] {
            if value > max {
                errors.push(ParamError::TooMany { field, value, max });
            }
        }
        for (field, width) in [
            ("external_perimeter_width", self.external_perimeter_width),
            ("perimeter_width", self.perimeter_width),
            ("infill_width", self.infill_width),
            ("solid_infill_width", self.solid_infill_width),
            ("top_solid_infill_width", self.top_solid_infill_width),
            ("first_layer_width", self.first_layer_width),
        ] {
            if !(width.is_finite() && width >= self.nozzle_diameter && width > self.layer_height) {
                errors.push(ParamError::BadWidth {
                    field,
                    width,
                    nozzle: self.nozzle_diameter,
                    height: self.layer_height,
                });
            } else if width > self.max_width() {
                errors.push(ParamError::TooWide {
                    field,
                    width,
                    max: self.max_width(),
                });
            }
        }
        for (field, value) in [
            ("infill_density", self.infill_density),
            ("infill_overlap", self.infill_overlap),
        ] {
            if !(0.0..=1.0).contains(&value) {
                errors.push(ParamError::NotAFraction { field, value });
            }
        }
        for (field, value) in [
            ("solid_infill_margin", self.solid_infill_margin),
            ("solid_infill_below_area", self.solid_infill_below_area),
            ("skirt_distance", self.skirt_distance),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                errors.push(ParamError::Negative { field, value });
            }
        }
        if self.solid_infill_margin > MAX_SOLID_INFILL_MARGIN {
            errors.push(ParamError::OutOfRange {
                field: "solid_infill_margin",
                value: self.solid_infill_margin,
                min: 0.0,
                max: MAX_SOLID_INFILL_MARGIN,
            });
        }
        if !self.infill_angle_deg.is_finite() {
            errors.push(ParamError::NotFinite {
                field: "infill_angle_deg",
                value: self.infill_angle_deg,
            });
        }
        for (field, value) in [
            ("brim_width", self.brim.width),
            ("brim_separation", self.brim.separation),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                errors.push(ParamError::Negative { field, value });
            }
        }
        errors.extend(self.support.problems().into_iter().map(ParamError::Support));
        errors
    }

    /// The widest extrusion allowed (mm): [`MAX_WIDTH_NOZZLES`] nozzle diameters, at most
    /// [`MAX_WIDTH`].
    pub fn max_width(&self) -> f64 {
        // Rounded to a micrometre so 3 × 0.4 reads 1.2 in a message.
        ((MAX_WIDTH_NOZZLES * self.nozzle_diameter).min(MAX_WIDTH) * 1e6).round() / 1e6
    }

    /// Spacings for one layer of height `height` (mm).
    pub fn spacings(&self, height: f64) -> Spacings {
        Spacings {
            external_perimeter: spacing(self.external_perimeter_width, height),
            perimeter: spacing(self.perimeter_width, height),
            infill: spacing(self.infill_width, height),
            solid_infill: spacing(self.solid_infill_width, height),
            top_solid_infill: spacing(self.top_solid_infill_width, height),
        }
    }

    /// The parameters layer `index` is made with: on the first layer every width is
    /// `first_layer_width`; other layers use these parameters unchanged.
    pub fn for_layer(&self, index: usize) -> RegionParams {
        if index > 0 {
            return self.clone();
        }
        let w = self.first_layer_width;
        RegionParams {
            external_perimeter_width: w,
            perimeter_width: w,
            infill_width: w,
            solid_infill_width: w,
            top_solid_infill_width: w,
            ..self.clone()
        }
    }

    /// Width (mm) and centreline spacing of bridge lines: a bridge is drawn in air as a round
    /// thread of the nozzle's diameter (it cannot be squashed flat against anything), and the
    /// threads are laid 0.05 mm further apart than they are thick (PrusaSlicer's
    /// `BRIDGE_EXTRA_SPACING`) so a thread does not land on its neighbour and pull it down.
    pub fn bridge_flow(&self) -> (f64, f64) {
        (self.nozzle_diameter, self.nozzle_diameter + 0.05)
    }
}

/// Centreline spacings (mm) of each extrusion kind for one layer height; see [`spacing`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spacings {
    /// Spacing of external perimeter extrusions.
    pub external_perimeter: f64,
    /// Spacing of inner perimeter extrusions.
    pub perimeter: f64,
    /// Spacing of sparse infill extrusions at 100 % density.
    pub infill: f64,
    /// Spacing of solid infill lines.
    pub solid_infill: f64,
    /// Spacing of top solid infill lines.
    pub top_solid_infill: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spacing_model_is_the_rounded_rectangle_bead() {
        // A gap of thickness t takes t·h: the spacing model's width t + h·(1 − π/4).
        let w = crate::program::BeadShape::RoundedRectangle.width_for_area(0.3 * 0.2, 0.2);
        assert!((w - spacing(w, 0.2) - 0.2 * (1.0 - PI / 4.0)).abs() < 1e-15);
        assert!((spacing(w, 0.2) - 0.3).abs() < 1e-12);
    }

    #[test]
    fn spacing_follows_the_rounded_rectangle_model() {
        // 0.45 − 0.2·(1 − π/4) = 0.45 − 0.0429204 = 0.4070796
        assert!((spacing(0.45, 0.2) - 0.407_079_6).abs() < 1e-7);
        // A square-ish bead (width = height) loses exactly the corner voids.
        assert!((spacing(0.3, 0.3) - 0.3 * PI / 4.0).abs() < 1e-12);
        let s = RegionParams::default().spacings(0.2);
        assert_eq!(s.perimeter, s.external_perimeter);
        assert!((s.solid_infill - 0.407_079_6).abs() < 1e-7);
    }

    #[test]
    fn defaults_validate_and_bad_values_are_all_reported() {
        assert!(RegionParams::default().validate().is_empty());
        let bad = RegionParams {
            perimeter_width: 0.3,
            infill_density: 1.5,
            layer_height: -0.1,
            ..RegionParams::default()
        };
        let errors = bad.validate();
        assert_eq!(errors.len(), 3, "{errors:?}");
        assert!(matches!(
            errors[0],
            ParamError::NotPositive {
                field: "layer_height",
                ..
            }
        ));
    }
}
