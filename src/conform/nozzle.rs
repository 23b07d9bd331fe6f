//! The dispensing nozzle: its bore, which sets the bead, and its solid, which must not meet the
//! surface.
//!
//! Place in the pipeline: built from the `[conform]` nozzle settings with the run's parameters
//! ([`super::ConformParams`]); used by the corrections ([`super::correct`]: the tip disc of
//! diameter d_o), by the clearance pass after them, by the report and by the replay of the
//! written G-code ([`super::replay`]). Beyond the published method, which checks only the tip
//! disc, the whole nozzle is checked: a needle of the outer diameter rising `needle_length`
//! above the tip, then a cone widening at `cone_angle` from the vertical for `cone_height` —
//! a [`ToolSolid`] checked against the surface by [`crate::surface::contact`] (exactly: the
//! highest point of the surface inside each footprint, [`crate::surface::clearance`]).

use crate::surface::ToolSolid;

/// The nozzle (mm).
#[derive(Debug, Clone, PartialEq)]
pub struct Nozzle {
    /// Inner diameter d: the standoff, the bead width and the sample spacing.
    pub inner: f64,
    /// The solid above the tip: tip disc of the outer diameter d_o, needle, cone.
    pub solid: ToolSolid,
}

impl Nozzle {
    /// The nozzle of inner diameter `inner` and outer diameter `outer`, with a needle of
    /// `needle_length` under a cone of half-angle `cone_angle_deg` (0 = none) and height
    /// `cone_height`.
    pub fn new(
        inner: f64,
        outer: f64,
        needle_length: f64,
        cone_angle_deg: f64,
        cone_height: f64,
    ) -> Self {
        Self {
            inner,
            solid: ToolSolid::needle_nozzle(outer, needle_length, cone_angle_deg, cone_height),
        }
    }

    /// Radius of the tip disc, d_o / 2, mm.
    pub fn tip_radius(&self) -> f64 {
        self.solid.tip_radius()
    }
}

#[cfg(test)]
impl Nozzle {
    /// The default nozzle (d = 0.25, d_o = 0.5, a 6 mm needle under a 30° cone 10 mm high) of
    /// the module tests.
    pub(crate) fn for_tests() -> Self {
        Nozzle::new(0.25, 0.5, 6.0, 30.0, 10.0)
    }
}
