//! The conform stage's settings, the `[conform]` section of the configuration: conformal
//! printing of 2D designs onto scanned surfaces with a micro-extrusion nozzle
//! (`conduit conform`), and its enums ([`Mapping`], [`Corrections`]).
//!
//! Place in the pipeline: read with the rest of the config (`crate::config::Config::conform`);
//! the walk turns it into [`crate::conform::ConformParams`] before any work runs. Lengths in mm, speeds in mm/s,
//! angles in degrees.

use serde::{Deserialize, Serialize};

/// How the design is laid onto the surface.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Mapping {
    /// Every design point dropped along −z onto the surface (the design's top view is kept;
    /// lengths stretch on slopes by 1/cos of the slope).
    #[default]
    Projection,
    /// The design walked along the surface: each 3D step as long as the 2D step, in the
    /// design's direction seen from above (arc length is kept).
    Geodesic,
}

/// Which corrections of the point-cloud-based path planning method are applied.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Corrections {
    /// The tip placed on the deposit model: the back edge (outer going down, inner going up)
    /// over the design point, at distance d from the surface itself (the standoff solved on
    /// the surface, curvature and all); nozzle contact escape; the shift ramped so the tip
    /// never runs backwards and cut back where it would meet the surface. The default: it
    /// prints the deposit closest to d of all modes.
    #[default]
    Deposit,
    /// As `Deposit` with the standoff solved on the tangent plane (d/n_z): its slope-only
    /// control, without the curvature.
    #[serde(rename = "deposit-plane")]
    DepositPlane,
    /// Standoff d, nozzle contact and curvature-scaled downhill corrections: the published
    /// method's formulas.
    Full,
    /// Standoff and nozzle contact corrections, downhill shift without curvature (κ = 0).
    Slope,
    /// Standoff only: the zero-standoff path lifted by the inner diameter.
    None,
}

impl Corrections {
    /// Every mode, the default first.
    pub const ALL: [Corrections; 5] = [
        Self::Deposit,
        Self::DepositPlane,
        Self::Full,
        Self::Slope,
        Self::None,
    ];

    /// Whether the mode places the tip on the deposit model (`Deposit`, `DepositPlane`)
    /// rather than by the published method's formulas.
    pub fn on_deposit_model(self) -> bool {
        matches!(self, Self::Deposit | Self::DepositPlane)
    }

    /// The mode's name in a config file.
    pub fn name(self) -> &'static str {
        match self {
            Self::Deposit => "deposit",
            Self::DepositPlane => "deposit-plane",
            Self::Full => "full",
            Self::Slope => "slope",
            Self::None => "none",
        }
    }
}

/// Conformal printing settings (`[conform]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct ConformSettings {
    /// Tool that dispenses (a paste tool: its snippets switch the pressure). Default 1.
    pub tool: usize,
    /// Nozzle inner diameter d, mm: the standoff, the bead width and the point spacing (two
    /// points per d). Default 0.25.
    pub inner_diameter: f64,
    /// Nozzle outer diameter d_o, mm: the tip disk of the contact check. Default 0.5.
    pub outer_diameter: f64,
    /// Extra lateral clearance added to every contact correction, mm. Default 0.1.
    pub tolerance: f64,
    /// Feed rate while dispensing, mm/s. Default 5.
    pub feed: f64,
    /// G-code that switches the dispensing pressure on; empty = the tool's `paste_on_gcode`.
    /// Default empty.
    pub pressure_on_gcode: String,
    /// G-code that switches the dispensing pressure off; empty = the tool's `paste_off_gcode`.
    /// Default empty.
    pub pressure_off_gcode: String,
    /// `"projection"` or `"geodesic"` (also `conduit conform --mapping`). Default
    /// `"projection"`.
    pub mapping: Mapping,
    /// `"deposit"`, `"deposit-plane"`, `"full"`, `"slope"` or `"none"`: which corrections are
    /// applied. Default `"deposit"`.
    pub corrections: Corrections,
    /// Length of the straight needle above the tip (outer diameter), mm. Default 6.
    pub needle_length: f64,
    /// Half-angle of the cone above the needle (the dispenser's body), degrees from the
    /// vertical; 0 = no cone, only the needle. Default 30.
    pub cone_angle: f64,
    /// Height of that cone, mm. Default 10.
    pub cone_height: f64,
    /// Deposit thickness at or below which the nozzle touches the surface, mm. Default 0.
    pub contact_thickness: f64,
    /// Thickness error (thickness − d) below the negative of this counts as flattening, mm.
    /// Default 0.05.
    pub flattening_error: f64,
    /// Thickness error above this counts as floating, mm. Default 0.1.
    pub floating_error: f64,
    /// `--refs-auto`: largest size (longest side of the bounding box) of a hole in the scan
    /// taken as a reference marker, mm. Default 5.
    pub marker_max_size: f64,
    /// Point clouds: a cloud folds over itself where points lie more than this far below the
    /// top of their grid cell, mm; only the top points make the surface. Default 1.
    pub fold_gap: f64,
    /// Height above the highest surface point that travels between paths clear, mm.
    /// Default 2.
    pub travel_clearance: f64,
}

impl Default for ConformSettings {
    fn default() -> Self {
        Self {
            tool: 1,
            inner_diameter: 0.25,
            outer_diameter: 0.5,
            tolerance: 0.1,
            feed: 5.0,
            pressure_on_gcode: String::new(),
            pressure_off_gcode: String::new(),
            mapping: Mapping::Projection,
            corrections: Corrections::Deposit,
            needle_length: 6.0,
            cone_angle: 30.0,
            cone_height: 10.0,
            contact_thickness: 0.0,
            flattening_error: 0.05,
            floating_error: 0.1,
            marker_max_size: 5.0,
            fold_gap: 1.0,
            travel_clearance: 2.0,
        }
    }
}
