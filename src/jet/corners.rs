//! Corner angles and the rule table: which corners of a design get a fillet, how large at
//! least, and which are split.
//!
//! Place in the pipeline: design polylines → **corners** → fillet → contour → schedule → program →
//! emit.
//! The angle θ of a corner is the angle between its two segments (180° = straight, 0° = the
//! path turns back on itself).

use super::JetSettings;

/// What a corner needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Requirement {
    /// A tangent fillet of at least this radius, mm (0 = none needed).
    Fillet(f64),
    /// Too sharp to fillet: the shutter closes at the corner and the next segment starts fresh.
    Split,
}

/// The rule table of `[jet]`: `corner_rules` sorted by angle, descending, and `split_below`.
#[derive(Debug, Clone, PartialEq)]
pub struct CornerRules {
    /// `(min_angle_deg, radius / line width)`, by angle descending.
    rows: Vec<(f64, f64)>,
    /// Corners below this angle are split, degrees.
    split_below: f64,
}

impl CornerRules {
    /// The rules of `settings`.
    pub fn new(settings: &JetSettings) -> Self {
        let mut rows: Vec<(f64, f64)> =
            settings.corner_rules.iter().map(|r| (r[0], r[1])).collect();
        rows.sort_by(|a, b| b.0.total_cmp(&a.0));
        Self {
            rows,
            split_below: settings.split_below,
        }
    }

    /// What a corner of angle `theta_deg` needs with line width `width` (mm). Angles above
    /// every row's angle, or covered by no row, need no fillet.
    pub fn requirement(&self, theta_deg: f64, width: f64) -> Requirement {
        if theta_deg < self.split_below {
            return Requirement::Split;
        }
        let factor = self
            .rows
            .iter()
            .find(|(angle, _)| theta_deg >= *angle)
            .map_or(0.0, |r| r.1);
        Requirement::Fillet(factor * width)
    }
}

/// The angle between the segments `v→a` and `v→b` at vertex `v`, degrees in `[0, 180]`
/// (180 = straight on). Degenerate segments count as straight.
pub fn corner_angle(a: [f64; 2], v: [f64; 2], b: [f64; 2]) -> f64 {
    let (ux, uy) = (a[0] - v[0], a[1] - v[1]);
    let (wx, wy) = (b[0] - v[0], b[1] - v[1]);
    let (lu, lw) = (ux.hypot(uy), wx.hypot(wy));
    if lu == 0.0 || lw == 0.0 {
        return 180.0;
    }
    // atan2 of cross and dot is accurate near 0° and 180°, where acos of the dot is not.
    (ux * wy - uy * wx)
        .abs()
        .atan2(ux * wx + uy * wy)
        .to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_rule_table_of_the_study() {
        let rules = CornerRules::new(&JetSettings::default());
        let w = 0.02;
        assert_eq!(rules.requirement(180.0, w), Requirement::Fillet(0.0));
        assert_eq!(rules.requirement(90.0, w), Requirement::Fillet(0.0));
        assert_eq!(rules.requirement(89.9, w), Requirement::Fillet(0.01));
        assert_eq!(rules.requirement(45.0, w), Requirement::Fillet(0.01));
        assert_eq!(rules.requirement(44.9, w), Requirement::Fillet(0.02));
        assert_eq!(rules.requirement(15.0, w), Requirement::Fillet(0.02));
        assert_eq!(rules.requirement(14.9, w), Requirement::Split);
    }

    #[test]
    fn angles_between_segments() {
        let v = [0.0, 0.0];
        assert!((corner_angle([-1.0, 0.0], v, [1.0, 0.0]) - 180.0).abs() < 1e-12);
        assert!((corner_angle([1.0, 0.0], v, [0.0, 1.0]) - 90.0).abs() < 1e-12);
        let t = 30f64.to_radians();
        assert!((corner_angle([1.0, 0.0], v, [t.cos(), -t.sin()]) - 30.0).abs() < 1e-12);
    }
}
