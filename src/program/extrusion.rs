//! How much material an extrusion needs: the flow model.
//!
//! # Bead cross-section
//!
//! A bead of width `w` and height `h` (mm) is modelled as PrusaSlicer's `Flow` does: a rectangle
//! with semicircular ends of diameter `h` (a rounded rectangle, "stadium"):
//!
//! ```text
//! A = (w − h)·h + π·(h/2)²        (mm², for w ≥ h)
//! ```
//!
//! For `w = 0.45`, `h = 0.2`: `A = 0.25·0.2 + π·0.01 = 0.05 + 0.0314159 = 0.0814159 mm²`. This is
//! the same model as the regions stage's extrusion spacing (`region::spacing`). A bead narrower than it
//! is high (`w < h`, only for odd inputs) is taken as an ellipse `π·w·h/4`, which meets the
//! rounded rectangle at `w = h`. [`BeadShape::Rectangle`] (`A = w·h`) is there for processes
//! that print square beads (e.g. some paste dispensers with a flat nozzle). A bridge thread hangs
//! in air with nothing to flatten it against, so it is [`BeadShape::Round`], a circle of
//! diameter `w`: `A = π·w²/4`, whatever the layer height.
//!
//! # Filament tools
//!
//! The extruder axis E counts millimetres of filament of diameter `d` pushed into the hot end, so
//! one millimetre of bead needs
//!
//! ```text
//! E per mm = A / (π·d²/4)
//! ```
//!
//! (with `d = 1.75`: `0.0814159 / 2.4052819 = 0.0338488`).
//!
//! # Paste tools
//!
//! Pneumatic and screw paste extruders are time-based: the flow runs while the tool is switched
//! on (by configurable G-code snippets) and the deposit per millimetre is set by the travel
//! speed. Their moves carry no E word; [`Feed::Paste`] has no E per mm.

use std::f64::consts::PI;

/// Shape of a bead's cross-section (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BeadShape {
    /// Rectangle with semicircular ends of diameter `h`: `(w − h)·h + π·h²/4`.
    #[default]
    RoundedRectangle,
    /// Plain rectangle: `w·h`.
    Rectangle,
    /// Circle of diameter `w` (a thread in air, as bridges are drawn): `π·w²/4`.
    Round,
}

impl BeadShape {
    /// Cross-section area (mm²) of a bead `width` mm wide and `height` mm high. Zero when either
    /// is not positive.
    pub fn area(self, width: f64, height: f64) -> f64 {
        if !(width > 0.0 && height > 0.0) {
            return 0.0;
        }
        match self {
            BeadShape::Rectangle => width * height,
            BeadShape::Round => PI * width * width / 4.0,
            BeadShape::RoundedRectangle if width >= height => {
                (width - height) * height + PI * (height / 2.0).powi(2)
            }
            BeadShape::RoundedRectangle => PI * width * height / 4.0,
        }
    }

    /// The width whose bead of height `height` has cross-section `area` (the inverse of
    /// [`BeadShape::area`] in the width); 0 for a non-positive area or height.
    pub fn width_for_area(self, area: f64, height: f64) -> f64 {
        if !(area > 0.0 && height > 0.0) {
            return 0.0;
        }
        match self {
            BeadShape::Rectangle => area / height,
            BeadShape::Round => (4.0 * area / PI).sqrt(),
            BeadShape::RoundedRectangle if area >= PI * height * height / 4.0 => {
                area / height + height * (1.0 - PI / 4.0)
            }
            BeadShape::RoundedRectangle => 4.0 * area / (PI * height),
        }
    }
}

/// Cross-section area (mm²) of a rounded-rectangle bead, the default model:
/// `(width − height)·height + π·(height/2)²`.
pub fn bead_area(width: f64, height: f64) -> f64 {
    BeadShape::RoundedRectangle.area(width, height)
}

/// Cross-section area (mm²) of filament of diameter `diameter` mm: `π·d²/4`.
pub fn filament_area(diameter: f64) -> f64 {
    PI * diameter * diameter / 4.0
}

/// How a tool is fed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Feed {
    /// Filament of the given diameter (mm) pushed by the E axis.
    Filament {
        /// Filament diameter, mm.
        diameter: f64,
    },
    /// Time-based paste flow switched on and off by G-code snippets; no E axis.
    Paste,
}

impl Feed {
    /// Millimetres of E per millimetre of a `width × height` bead of `shape`; `None` for paste
    /// tools (and for a filament diameter that is not positive).
    pub fn e_per_mm(self, shape: BeadShape, width: f64, height: f64) -> Option<f64> {
        match self {
            Feed::Filament { diameter } if diameter > 0.0 => {
                Some(shape.area(width, height) / filament_area(diameter))
            }
            Feed::Filament { .. } | Feed::Paste => None,
        }
    }
}

/// Millimetres of filament of diameter `filament_diameter` per millimetre of a rounded-rectangle
/// bead `width × height` (the default model; see the module docs).
pub fn e_per_mm(width: f64, height: f64, filament_diameter: f64) -> f64 {
    Feed::Filament {
        diameter: filament_diameter,
    }
    .e_per_mm(BeadShape::RoundedRectangle, width, height)
    .unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounded_rectangle_area_for_045_by_02() {
        // (0.45 − 0.2)·0.2 + π·0.1² = 0.05 + 0.031415927
        assert!((bead_area(0.45, 0.2) - 0.081_415_927).abs() < 1e-9);
        // Continuous at w = h with the ellipse below it; a square bead is a circle.
        assert!((bead_area(0.3, 0.3) - PI * 0.09 / 4.0).abs() < 1e-15);
        assert!((bead_area(0.2, 0.4) - PI * 0.08 / 4.0).abs() < 1e-15);
        assert_eq!(BeadShape::Rectangle.area(0.45, 0.2), 0.45 * 0.2);
        assert_eq!(bead_area(0.0, 0.2), 0.0);
        assert_eq!(bead_area(0.45, f64::NAN), 0.0);
        assert!((BeadShape::Round.area(0.4, 0.2) - PI * 0.04).abs() < 1e-15);
    }

    #[test]
    fn width_for_area_inverts_area() {
        for shape in [
            BeadShape::RoundedRectangle,
            BeadShape::Rectangle,
            BeadShape::Round,
        ] {
            for w in [0.05, 0.1, 0.2, 0.45, 0.9] {
                let back = shape.width_for_area(shape.area(w, 0.2), 0.2);
                assert!((back - w).abs() < 1e-12, "{shape:?} {w} {back}");
            }
        }
        assert_eq!(BeadShape::Round.width_for_area(-1.0, 0.2), 0.0);
    }

    #[test]
    fn e_for_a_10_mm_line_on_175_filament() {
        let e = 10.0 * e_per_mm(0.45, 0.2, 1.75);
        let want = 10.0 * 0.081_415_927 / (PI * 1.75 * 1.75 / 4.0);
        assert!((e - want).abs() < 1e-8, "{e} vs {want}");
        assert!((e - 0.338_488).abs() < 1e-6, "{e}");
        assert_eq!(
            Feed::Paste.e_per_mm(BeadShape::RoundedRectangle, 0.45, 0.2),
            None
        );
        assert_eq!(
            Feed::Filament { diameter: 0.0 }.e_per_mm(BeadShape::Rectangle, 0.45, 0.2),
            None
        );
    }
}
