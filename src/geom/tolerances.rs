//! Named tolerances: no global epsilon, each comparison says which tolerance it uses and in what unit.

use serde::{Deserialize, Serialize};

/// A length tolerance in millimetres that is always finite and greater than zero.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Serialize, Deserialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Tolerance(f64);

impl Tolerance {
    /// A tolerance, or `None` if `mm` is not finite and positive.
    pub fn new(mm: f64) -> Option<Self> {
        (mm.is_finite() && mm > 0.0).then_some(Self(mm))
    }

    /// The tolerance in millimetres.
    pub fn mm(self) -> f64 {
        self.0
    }
}

impl TryFrom<f64> for Tolerance {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        Self::new(v).ok_or_else(|| format!("tolerance must be finite and > 0, got {v}"))
    }
}

impl From<Tolerance> for f64 {
    fn from(t: Tolerance) -> f64 {
        t.0
    }
}

/// Every tolerance the geometry code uses, with documented units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tolerances {
    /// Vertices closer than this (mm) are merged by mesh repair. Default 1e-4 mm (0.1 µm): below
    /// any printer's resolution, above float32 noise on parts up to a metre.
    pub vertex_merge: Tolerance,
    /// A triangle whose area is below `degenerate_area` (mm²) is degenerate. Default 1e-10 mm².
    pub degenerate_area: Tolerance,
    /// Boundary loops with at most this many edges are filled by repair. Default 64.
    pub max_hole_edges: usize,
    /// Curves are flattened so no point of the chord strays further than this (mm) from the curve.
    /// Default 0.005 mm.
    pub curve_flattening: Tolerance,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            vertex_merge: Tolerance(1e-4),
            degenerate_area: Tolerance(1e-10),
            max_hole_edges: 64,
            curve_flattening: Tolerance(0.005),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerance_rejects_non_positive_and_nan() {
        assert!(Tolerance::new(0.0).is_none());
        assert!(Tolerance::new(-1.0).is_none());
        assert!(Tolerance::new(f64::NAN).is_none());
        assert!(Tolerance::new(f64::INFINITY).is_none());
        assert_eq!(Tolerance::new(0.5).map(Tolerance::mm), Some(0.5));
    }
}
