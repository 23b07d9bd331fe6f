//! The tool solid against a scanned surface: where its tip disc touches, how deep the surface
//! reaches into the whole solid (vertical, or along a tilted tool axis), and the surface as an
//! [`Obstacle`] of the replay walk.
//!
//! Place in the pipeline: vocabulary for conformal printing — its corrections (the tip disc,
//! [`ToolSolid::disc_contact`]), the clearance pass after them ([`ToolSolid::shortfall`]), the
//! report ([`ToolSolid::penetration`], [`ToolSolid::tip_clearance`], and
//! [`ToolSolid::penetration_along`] for tilted tool axes) and the replay of the written G-code
//! ([`super::replay::walk`] with the [`Surface`] as obstacle).
//!
//! A tool coming from above on a 3-axis machine meets the top surface. The vertical check is
//! exact ([`super::clearance`]): each disc or cylinder by the highest point of the surface over
//! its footprint against its floor, each cone by the highest the surface reaches over its
//! annulus against its rising underside. A piece away from the tip is asked only when a coarse
//! bound of the surface's height around it reaches its floor.
//!
//! Along a tilted axis the solid is checked by its cross-sections perpendicular to the axis,
//! each a whole disc checked exactly: the tip, a cylinder every `step` along it (a section
//! above the surface's top ends the search), a cone every half millimetre along it. A section
//! whose lowest point is above a bound of the surface's height around it is skipped.
//!
//! The corrections' [`ToolSolid::disc_contact`] wants a place, not a depth: the centroid of
//! the part of the tip disc under the surface, exact too
//! ([`super::clearance::DiscContact`]): it finds every contact the depth query finds.

use super::mesh::Surface;
use super::replay::{Obstacle, Sample, Stretch};
use super::tool::{PieceShape, ToolSolid};
use crate::geom::{Point3, Vector3};

/// Points on the rim of a tip disc standing on edge.
const DISC_ANGLES: usize = 16;
/// Cross-section spacing along a tilted cone, mm.
const CONE_RING_MM: f64 = 0.5;
/// Points per rim of a cone's cross-section on an axis standing on edge.
const CONE_ANGLES: usize = 24;
/// Points per rim of a cylinder's cross-section on an axis standing on edge.
const CYLINDER_ANGLES: usize = 16;
/// Depth of a tilted check within which the surface touches the tool (rounding of the tilted
/// frame), mm: a nanometre, a thousandth of the G-code's grid.
const TOUCH: f64 = 1e-9;

impl ToolSolid {
    /// Where the tip disc at `tip` meets the surface (surface at or above the tip's height,
    /// exactly): the centroid (x, y) of the part of the disc under the surface (where it only
    /// touches, of the part within [`super::clearance::CONTACT_BAND`] of its highest point),
    /// or `None` without contact.
    pub fn disc_contact(&self, surface: &Surface, tip: &Point3) -> Option<[f64; 2]> {
        surface
            .height_field()
            .contact_in_disc(tip.x, tip.y, self.tip_radius(), tip.z)
            .map(|c| c.centroid)
    }

    /// How far the surface reaches into the whole solid with its tip at `tip` (vertical axis),
    /// mm; ≤ 0: no contact (the clearance, or a lower bound of it where a coarse bound of the
    /// surface's height already shows there is no contact). Exact ([`super::clearance`]): the
    /// tip and every disc or cylinder at the tip by the highest point of the surface over
    /// their footprint, a cone (or a piece higher up, when the surface reaches its floor) by
    /// the highest point over its annulus less its rise there.
    pub fn penetration(&self, surface: &Surface, tip: &Point3) -> f64 {
        if surface
            .max_height_near(tip.x, tip.y, self.widest())
            .is_none()
        {
            return f64::MIN;
        }
        let field = surface.height_field();
        let mut worst = f64::MIN;
        for piece in self.pieces() {
            let base = tip.z + piece.bottom;
            let Some(bound) = surface
                .max_height_near(tip.x, tip.y, piece.widest())
                .map(|h| h - base)
            else {
                continue;
            };
            let at_tip = piece.bottom <= 0.0 && !matches!(piece.shape, PieceShape::Cone { .. });
            if bound < 0.0 && !at_tip {
                worst = worst.max(bound);
                continue;
            }
            match piece.shape {
                PieceShape::Disc { radius } | PieceShape::Cylinder { radius } => {
                    if let Some(h) = field.max_in_disc(tip.x, tip.y, radius) {
                        worst = worst.max(h - base);
                    }
                }
                PieceShape::Cone { radius, tan, .. } => {
                    if radius > 0.0
                        && let Some(h) = field.max_in_disc(tip.x, tip.y, radius)
                    {
                        worst = worst.max(h - base);
                    }
                    if tan <= 0.0 {
                        continue;
                    }
                    // Floor at ρ ≥ radius: base + (ρ − radius)/tan.
                    let k = 1.0 / tan;
                    let lift = base - radius * k;
                    let wide = piece.widest();
                    if let Some(h) =
                        field.max_over_cone(tip.x, tip.y, radius, wide, k, worst + lift)
                    {
                        worst = worst.max(h - lift);
                    }
                }
            }
        }
        worst
    }

    /// How far `tip` must rise for the whole solid to clear the surface by `margin`, mm; ≤ 0
    /// when it does. Asked at the lowered tip so the answer is exact where it is > 0: where the
    /// surface is far, [`ToolSolid::penetration`] answers with a bound of the clearance, not
    /// the clearance.
    pub fn shortfall(&self, surface: &Surface, tip: &Point3, margin: f64) -> f64 {
        self.penetration(surface, &Point3::new(tip.x, tip.y, tip.z - margin))
    }

    /// How far the tip disc at `tip` (vertical axis) is above the highest point of the surface
    /// under it, exactly, mm (< 0: the surface reaches into it); `None` off the surface.
    pub fn tip_clearance(&self, surface: &Surface, tip: &Point3) -> Option<f64> {
        surface
            .max_height_in_disc(tip.x, tip.y, self.tip_radius())
            .map(|h| tip.z - h)
    }

    /// How far the surface reaches into the solid with its tip at `tip` and its axis (unit,
    /// tip toward the body) `axis`, mm, measured vertically; ≤ 0 or `f64::MIN`: no contact.
    /// The solid is checked by its cross-sections perpendicular to the axis, each a whole disc
    /// checked exactly ([`super::clearance`]): the tip, a cylinder every `step` along the
    /// axis, a cone every half millimetre. An axis within 0.06° of the horizontal (a disc
    /// standing on edge) is sampled on the cross-sections' rims instead.
    pub fn penetration_along(
        &self,
        surface: &Surface,
        tip: &Point3,
        axis: &Vector3,
        step: f64,
    ) -> f64 {
        let u = (Vector3::x() - axis * axis.x)
            .try_normalize(1e-6)
            .or_else(|| (Vector3::y() - axis * axis.y).try_normalize(1e-6))
            .unwrap_or_else(Vector3::x);
        let v = axis.cross(&u);
        let lean = axis.x.hypot(axis.y);
        let top = surface.max().z;
        let field = surface.height_field();
        let on_edge = axis.z.abs() < 1e-3;
        let mut worst = f64::MIN;
        let mut section = |s: f64, r: f64, n: usize| -> bool {
            let c = tip + axis * s;
            let lowest = c.z - r * lean;
            if lowest > top {
                // Higher sections are higher still: nothing above can touch.
                return false;
            }
            match surface.max_height_near(c.x, c.y, r) {
                Some(h) if h >= lowest => {}
                _ => return true,
            }
            if !on_edge {
                if let Some(h) = field.max_above_disc(&c, &u, &v, r) {
                    worst = worst.max(h);
                }
                return true;
            }
            for k in 0..n.max(1) {
                let t = std::f64::consts::TAU * k as f64 / n.max(1) as f64;
                let p = c + (u * t.cos() + v * t.sin()) * r;
                if let Some(h) = surface.height(p.x, p.y) {
                    worst = worst.max(h - p.z);
                }
            }
            true
        };
        for piece in self.pieces() {
            match piece.shape {
                PieceShape::Disc { radius } => {
                    section(piece.bottom, radius, DISC_ANGLES);
                }
                PieceShape::Cylinder { radius } => {
                    let stations = (piece.height / step).ceil() as usize;
                    for k in 1..=stations {
                        let s = (k as f64 * step).min(piece.height);
                        if !section(piece.bottom + s, radius, CYLINDER_ANGLES) {
                            return settle(worst);
                        }
                    }
                }
                PieceShape::Cone { radius, tan, .. } => {
                    let rings = (piece.height / CONE_RING_MM).ceil() as usize;
                    for k in 1..=rings {
                        let h = piece.height * k as f64 / rings as f64;
                        // The cone widens, so a section above the surface does not end the
                        // search.
                        section(piece.bottom + h, radius + h * tan, CONE_ANGLES);
                    }
                }
            }
        }
        settle(worst)
    }
}

/// A tilted check's depth with rounding settled: a tilted disc whose rim rests on the plane it
/// leans to touches it exactly, and the frame's rounding leaves femtometres either way, which
/// are a touch ([`TOUCH`]), not a contact.
fn settle(depth: f64) -> f64 {
    if depth.abs() < TOUCH { 0.0 } else { depth }
}

/// The scanned surface as an obstacle: the contact is [`ToolSolid::penetration`] (> 0: the
/// surface reaches into the tool); a stretch whose ends are both above the surface's top by the
/// tool's shoulder is out of reach.
impl Obstacle for &Surface {
    type Contact = f64;

    fn in_reach(&self, tool: &ToolSolid, _index: usize, stretch: &Stretch<'_>) -> bool {
        let top = self.max().z + tool.shoulder();
        !stretch.points.iter().all(|p| p.z > top)
    }

    fn contact(&self, tool: &ToolSolid, _index: usize, sample: &Sample) -> f64 {
        tool.penetration(self, &sample.tip)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The conform tests' nozzle: d_o = 0.5, a 6 mm needle under a 30° cone 10 mm high.
    fn nozzle() -> ToolSolid {
        ToolSolid::needle_nozzle(0.5, 6.0, 30.0, 10.0)
    }

    /// A V-crease of flanks at `slope_deg` along the direction `angle_deg` from x through the
    /// origin (the crease at z = 0), 8 mm each way, cut in strips 0.05 mm wide.
    fn crease(slope_deg: f64, angle_deg: f64) -> Surface {
        let s = slope_deg.to_radians().tan();
        let (sin, cos) = angle_deg.to_radians().sin_cos();
        // (a, b): a across the crease, b along it.
        let at = |a: f64, b: f64| Point3::new(a * -sin + b * cos, a * cos + b * sin, s * a.abs());
        let n = 320;
        let mut t = Vec::new();
        for i in 0..n {
            let (a0, a1) = (
                -8.0 + 16.0 * i as f64 / n as f64,
                -8.0 + 16.0 * (i + 1) as f64 / n as f64,
            );
            t.push([at(a0, -8.0), at(a1, -8.0), at(a1, 8.0)]);
            t.push([at(a0, -8.0), at(a1, 8.0), at(a0, 8.0)]);
        }
        match Surface::from_triangles(t) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn the_rim_over_a_crease_between_sample_angles_is_found_to_a_tenth_of_a_micrometre() {
        // A fold with 47° flanks, the crease turned half a sample step (11.25°) from the samples'
        // directions. Over the crease the highest point of the disc is on its rim across the
        // crease: r·tan 47° above the crease; the 16 rim samples nearest it are 11.25° off and
        // 5 µm lower.
        let surface = crease(47.0, 90.0 + 11.25);
        let n = nozzle();
        let rim = 0.25 * 47f64.to_radians().tan();
        let tip = Point3::new(0.0, 0.0, rim - 0.002);
        let pen = n.penetration(&surface, &tip);
        assert!((pen - 0.002).abs() < 1e-7, "{pen}");
        let clear = n.tip_clearance(&surface, &tip).unwrap_or(f64::NAN);
        assert!((clear + 0.002).abs() < 1e-7, "{clear}");
        // The samples the checks used to take (the centre and 4 rings of 16): every one clear
        // of the surface.
        let sampled = (1..=4)
            .flat_map(|ring| {
                (0..16).map(move |k| {
                    let t = std::f64::consts::TAU * k as f64 / 16.0;
                    let rr = 0.25 * ring as f64 / 4.0;
                    [rr * t.cos(), rr * t.sin()]
                })
            })
            .chain([[0.0, 0.0]])
            .filter_map(|q| surface.height(tip.x + q[0], tip.y + q[1]))
            .fold(f64::MIN, f64::max);
        assert!(sampled < tip.z - 0.003, "{}", sampled - tip.z);
        // The corrections' contact finds it too: two caps of the rim, one over each flank,
        // their centroid over the crease (at the disc's centre, to rounding).
        let Some(c) = n.disc_contact(&surface, &tip) else {
            panic!("the contact the samples miss is missed");
        };
        assert!(c[0].hypot(c[1]) < 1e-9, "{c:?}");
        // Off the crease by 0.1 mm across it, one flank's cap: its centroid beyond the crease
        // on that side, as the circular segment's.
        let (sin_c, cos_c) = (90f64 + 11.25).to_radians().sin_cos();
        // Across the crease (the crease runs along (cos, sin) of its angle).
        let normal = Vector3::new(-sin_c, cos_c, 0.0);
        let off = tip + normal * 0.1;
        let Some(c) = n.disc_contact(&surface, &off) else {
            panic!("no contact 0.1 mm off the crease");
        };
        // The flank at distance a from the crease is a·tan 47°: the part of the disc at or
        // above the tip is where a ≥ rim / tan 47° − 0.002 / tan 47°.
        let reach = (rim - 0.002) / 47f64.to_radians().tan();
        let ch = reach - 0.1;
        let alpha = (ch / 0.25).acos();
        let (sin, cos) = alpha.sin_cos();
        let along = 2.0 * 0.25 * sin.powi(3) / (3.0 * (alpha - sin * cos));
        let got = (c[0] - off.x) * normal.x + (c[1] - off.y) * normal.y;
        assert!((got - along).abs() < 1e-9, "{got} {along}");
        // A tilted axis 0.1° from the vertical gives the same to rounding of the tilt.
        let axis = Vector3::new(0.0, 0.1f64.to_radians().sin(), 0.1f64.to_radians().cos());
        let along = n.penetration_along(&surface, &tip, &axis, 0.0625);
        assert!((along - 0.002).abs() < 0.0005, "{along}");
    }

    #[test]
    fn the_shortfall_is_exact_near_the_surface_and_none_far_above_it() {
        // A flat plate at z = 0 over [−20, 20]².
        let c = |x: f64, y: f64| Point3::new(x, y, 0.0);
        let plate = Surface::from_triangles(vec![
            [c(-20.0, -20.0), c(20.0, -20.0), c(20.0, 20.0)],
            [c(-20.0, -20.0), c(20.0, 20.0), c(-20.0, 20.0)],
        ]);
        let Ok(plate) = plate else {
            panic!("plate");
        };
        let n = nozzle();
        // 3 µm above the plate, 5 µm wanted: 2 µm short; 1 µm below it: 6 µm short.
        let short = n.shortfall(&plate, &Point3::new(0.0, 0.0, 0.003), 0.005);
        assert!((short - 0.002).abs() < 1e-12, "{short}");
        let short = n.shortfall(&plate, &Point3::new(0.0, 0.0, -0.001), 0.005);
        assert!((short - 0.006).abs() < 1e-12, "{short}");
        // Well above it: clear, whatever bound the coarse check answers with.
        assert!(n.shortfall(&plate, &Point3::new(0.0, 0.0, 0.3), 0.005) <= 0.0);
        assert!(n.shortfall(&plate, &Point3::new(0.0, 0.0, 0.0051), 0.005) <= 0.0);
    }

    #[test]
    fn a_tilted_needle_meets_a_wall_beside_it_and_a_vertical_one_does_not() -> Result<(), String> {
        // A floor at z = 0 for x < 2 and a block 5 mm high for x ≥ 2 (a step).
        let quad = |x0: f64, x1: f64, z: f64| {
            [
                [
                    Point3::new(x0, -10.0, z),
                    Point3::new(x1, -10.0, z),
                    Point3::new(x1, 10.0, z),
                ],
                [
                    Point3::new(x0, -10.0, z),
                    Point3::new(x1, 10.0, z),
                    Point3::new(x0, 10.0, z),
                ],
            ]
        };
        let mut t = quad(-10.0, 2.0, 0.0).to_vec();
        t.extend(quad(2.0, 10.0, 5.0));
        let s = Surface::from_triangles(t).map_err(|e| e.to_string())?;
        let tip = Point3::new(0.0, 0.0, 0.25);
        let n = nozzle();
        // The needle sampled every quarter of a 0.25 mm bore.
        let step = 0.25 / 4.0;
        // Vertical: the needle stays 2 mm from the wall, the cone starts 6 mm up (above it).
        assert!(n.penetration_along(&s, &tip, &Vector3::z(), step) <= 0.0);
        // Leaning 45° toward the wall: the needle at height 5 is 4.75 mm across, inside it.
        let lean = Vector3::new(1.0, 0.0, 1.0).normalize();
        let p = n.penetration_along(&s, &tip, &lean, step);
        assert!(p > 0.0, "{p}");
        // Leaning away from it: clear.
        let away = Vector3::new(-1.0, 0.0, 1.0).normalize();
        assert!(n.penetration_along(&s, &tip, &away, step) <= 0.0);
        Ok(())
    }
}
