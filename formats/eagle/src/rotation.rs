//! EAGLE rotation strings: `[M][S]R<degrees>`.

use std::fmt;
use std::str::FromStr;

use crate::error::EagleError;

/// A rotation as EAGLE writes it in `rot` attributes: `[M][S]R<degrees>`.
///
/// - `M` mirrors the object about the y axis before rotating. For a board element it means the
///   part sits on the bottom side.
/// - `S` ("spin") keeps texts from being turned upside down; it does not change geometry.
/// - `R<degrees>` is a counter-clockwise rotation. EAGLE's DTD allows `0..359.9`; any finite
///   angle is accepted here and normalised into `[0, 360)`, so `R-90` reads as 270 degrees.
///
/// `M` and `S` may come in either order (`MSR270`, `SMR270`), each at most once, and the `R` is
/// required. An empty attribute is not a rotation; a missing `rot` attribute means [`Rotation::default`]
/// (`R0`).
///
/// ```
/// use conduit_eagle::Rotation;
/// let r: Rotation = "MR90".parse().unwrap();
/// assert_eq!(r, Rotation { degrees: 90.0, mirror: true, spin: false });
/// assert_eq!(r.to_string(), "MR90");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Rotation {
    /// Counter-clockwise angle in degrees, in `[0, 360)`.
    pub degrees: f64,
    /// Mirrored (for board elements: placed on the bottom side).
    pub mirror: bool,
    /// Spin flag (text readability only).
    pub spin: bool,
}

impl Rotation {
    /// Parses an EAGLE rotation string such as `R90`, `MR180`, `SR45.5` or `MSR270`.
    pub fn parse(s: &str) -> Result<Self, EagleError> {
        let bad = || EagleError::InvalidRotation {
            value: s.to_owned(),
        };
        let mut rest = s;
        let mut mirror = false;
        let mut spin = false;
        loop {
            if let Some(r) = rest.strip_prefix('M') {
                if mirror {
                    return Err(bad());
                }
                mirror = true;
                rest = r;
            } else if let Some(r) = rest.strip_prefix('S') {
                if spin {
                    return Err(bad());
                }
                spin = true;
                rest = r;
            } else {
                break;
            }
        }
        let number = rest.strip_prefix('R').ok_or_else(bad)?;
        // `f64::from_str` accepts "inf", "NaN" and "+5"; EAGLE writes plain decimals only.
        let plain = !number.is_empty()
            && number
                .bytes()
                .enumerate()
                .all(|(i, b)| b.is_ascii_digit() || b == b'.' || (i == 0 && b == b'-'));
        if !plain {
            return Err(bad());
        }
        let degrees: f64 = number.parse().map_err(|_| bad())?;
        if !degrees.is_finite() {
            return Err(bad());
        }
        let mut degrees = degrees.rem_euclid(360.0);
        // rem_euclid can round a tiny negative angle up to exactly 360.
        if degrees >= 360.0 {
            degrees = 0.0;
        }
        Ok(Rotation {
            degrees,
            mirror,
            spin,
        })
    }
}

impl FromStr for Rotation {
    type Err = EagleError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Rotation::parse(s)
    }
}

impl fmt::Display for Rotation {
    /// Writes the EAGLE form, e.g. `MSR270`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.mirror {
            f.write_str("M")?;
        }
        if self.spin {
            f.write_str("S")?;
        }
        write!(f, "R{}", self.degrees)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rot(s: &str) -> Rotation {
        match Rotation::parse(s) {
            Ok(r) => r,
            Err(e) => panic!("{s}: {e}"),
        }
    }

    #[test]
    fn parses_eagle_rotations() {
        let r = |degrees, mirror, spin| Rotation {
            degrees,
            mirror,
            spin,
        };
        assert_eq!(rot("R0"), r(0.0, false, false));
        assert_eq!(rot("R90"), r(90.0, false, false));
        assert_eq!(rot("MR180"), r(180.0, true, false));
        assert_eq!(rot("SR45"), r(45.0, false, true));
        assert_eq!(rot("SR45.5"), r(45.5, false, true));
        assert_eq!(rot("MSR270"), r(270.0, true, true));
        assert_eq!(rot("SMR270"), r(270.0, true, true));
        assert_eq!(rot("R359.9"), r(359.9, false, false));
        assert_eq!(rot("R-90"), r(270.0, false, false));
        assert_eq!(rot("R360"), r(0.0, false, false));
        assert_eq!(Rotation::default(), r(0.0, false, false));
    }

    #[test]
    fn rejects_bad_rotations() {
        for s in [
            "", "R", "90", "r90", "X90", "RR90", "MMR90", "SSR90", "MR", "R90M", "R 90", " R90",
            "R9O", "Rinf", "RNaN", "R+90", "R1e3", "M90", "R--90", "R9-0",
        ] {
            assert!(
                matches!(Rotation::parse(s), Err(EagleError::InvalidRotation { .. })),
                "{s:?} should be rejected"
            );
        }
    }

    #[test]
    fn displays_eagle_form() {
        assert_eq!(rot("MSR270").to_string(), "MSR270");
        assert_eq!(rot("SR45.5").to_string(), "SR45.5");
        assert_eq!(rot("R0").to_string(), "R0");
    }
}
