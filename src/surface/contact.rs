//! The tool solid against a scanned surface: where its tip disc touches, how deep the surface
//! reaches into the whole solid (vertical, or along a tilted tool axis), and the surface as an
//! [`Obstacle`] of the replay walk.
//!
//! Place in the pipeline: vocabulary for conformal printing — its corrections (the tip disc,
//! [`ToolSolid::disc_contact`]), the clearance pass after them ([`ToolSolid::shortfall`]), the
//! report ([`ToolSolid::penetration`], and [`ToolSolid::penetration_along`] for tilted tool
//! axes) and the replay of the written G-code ([`super::replay::walk`] with the [`Surface`] as
//! obstacle).
//!
//! A tool coming from above on a 3-axis machine meets the top surface: the vertical check
//! samples the top height on rings around the axis and compares it with the solid's lowest
//! point at that distance from the axis. Samples: a disc on four rings of 16 points plus the
//! centre; a cone on rings every half millimetre of radius (24 points, every other ring turned
//! by half a step), asked only when the surface anywhere reaches the solid's shoulder. A
//! cylinder (the needle) stands on the tip disc and is covered by its samples.
//!
//! Along a tilted axis the rings are perpendicular to it: the disc as above, a cylinder every
//! `step` along it (16 points on its radius; a ring above the surface's top ends the search),
//! a cone every half millimetre along it (24 points). A sample lies in the part when the top
//! surface at its (x, y) is higher than it; the depth is that height difference. A ring whose
//! lowest point is above a bound of the surface's height around it is skipped.

use super::mesh::Surface;
use super::replay::{Obstacle, Sample, Stretch};
use super::tool::{Piece, PieceShape, ToolSolid};
use crate::geom::{Point3, Vector3};

/// Angles per ring of a disc.
const DISC_ANGLES: usize = 16;
/// Rings of a disc (at ¼, ½, ¾ and 1 of its radius).
const DISC_RINGS: usize = 4;
/// Ring spacing on a cone, mm (of radius when vertical, along the axis when tilted).
const CONE_RING_MM: f64 = 0.5;
/// Angles per cone ring.
const CONE_ANGLES: usize = 24;
/// Points per ring of a cylinder along a tilted axis.
const CYLINDER_ANGLES: usize = 16;

/// Unit directions of the disc rings and of the cone rings (even rings, then odd rings turned
/// by half a step), computed once.
static DIRECTIONS: std::sync::LazyLock<[Vec<[f64; 2]>; 3]> = std::sync::LazyLock::new(|| {
    let dirs = |n: usize, offset: f64| -> Vec<[f64; 2]> {
        (0..n)
            .map(|a| {
                let t = std::f64::consts::TAU * (a as f64 + offset) / n as f64;
                [t.cos(), t.sin()]
            })
            .collect()
    };
    [
        dirs(DISC_ANGLES, 0.0),
        dirs(CONE_ANGLES, 0.0),
        dirs(CONE_ANGLES, 0.5),
    ]
});

/// One sample of a vertical check: offset from the axis and the solid's lowest height there.
#[derive(Debug, Clone, Copy)]
struct RingSample {
    dx: f64,
    dy: f64,
    /// Height of the solid's underside above the tip at this offset.
    floor: f64,
    /// Area weight (the ring's radius) for centroids.
    weight: f64,
}

/// A disc piece's samples: the centre and [`DISC_RINGS`] rings.
fn disc_samples(piece: &Piece) -> Vec<RingSample> {
    let ro = piece.bottom_radius();
    let mut s = vec![RingSample {
        dx: 0.0,
        dy: 0.0,
        floor: piece.bottom,
        weight: ro / (2.0 * DISC_RINGS as f64),
    }];
    for k in 1..=DISC_RINGS {
        let r = ro * k as f64 / DISC_RINGS as f64;
        for u in &DIRECTIONS[0] {
            s.push(RingSample {
                dx: r * u[0],
                dy: r * u[1],
                floor: piece.bottom,
                weight: r,
            });
        }
    }
    s
}

/// A cone piece's samples: rings every [`CONE_RING_MM`] of radius out to its widest, each
/// [`CONE_ANGLES`] long.
fn cone_samples(piece: &Piece) -> Vec<RingSample> {
    let PieceShape::Cone {
        radius: ro, tan, ..
    } = piece.shape
    else {
        return Vec::new();
    };
    let reach = piece.height * tan;
    let rings = (reach / CONE_RING_MM).ceil() as usize;
    let mut s = Vec::new();
    for k in 1..=rings {
        let r = ro + reach * k as f64 / rings as f64;
        for u in &DIRECTIONS[1 + k % 2] {
            s.push(RingSample {
                dx: r * u[0],
                dy: r * u[1],
                floor: piece.floor_at(r),
                weight: r,
            });
        }
    }
    s
}

impl ToolSolid {
    /// The samples of the solid's discs.
    fn disc_samples(&self) -> Vec<RingSample> {
        self.pieces()
            .iter()
            .filter(|p| matches!(p.shape, PieceShape::Disc { .. }))
            .flat_map(disc_samples)
            .collect()
    }

    /// The samples of the solid's cones, ring after ring.
    fn cone_samples(&self) -> Vec<RingSample> {
        self.pieces().iter().flat_map(cone_samples).collect()
    }

    /// Where the tip disc at `tip` meets the surface (surface at or above the tip's height):
    /// the weighted centroid of the touching samples (x, y), or `None` without contact.
    pub fn disc_contact(&self, surface: &Surface, tip: &Point3) -> Option<[f64; 2]> {
        let (mut sx, mut sy, mut w) = (0.0, 0.0, 0.0);
        for s in self.disc_samples() {
            if let Some(h) = surface.height(tip.x + s.dx, tip.y + s.dy)
                && h >= tip.z
            {
                sx += s.weight * (tip.x + s.dx);
                sy += s.weight * (tip.y + s.dy);
                w += s.weight;
            }
        }
        (w > 0.0).then(|| [sx / w, sy / w])
    }

    /// How far the surface reaches into the whole solid with its tip at `tip` (vertical axis),
    /// mm; ≤ 0: no contact (the clearance, or a lower bound of it where a coarse bound of the
    /// surface's height already shows there is no contact).
    pub fn penetration(&self, surface: &Surface, tip: &Point3) -> f64 {
        let ro = self.tip_radius();
        let shoulder = self.shoulder();
        let Some(near) = surface.max_height_near(tip.x, tip.y, self.widest()) else {
            return f64::MIN;
        };
        let disc_bound = surface
            .max_height_near(tip.x, tip.y, ro)
            .map_or(f64::MIN, |h| h - tip.z);
        if near < tip.z + shoulder && disc_bound < 0.0 {
            return disc_bound.max(near - tip.z - shoulder);
        }
        let mut worst = f64::MIN;
        let mut check = |samples: &[RingSample]| {
            for s in samples {
                if let Some(h) = surface.height(tip.x + s.dx, tip.y + s.dy) {
                    worst = worst.max(h - (tip.z + s.floor));
                }
            }
        };
        if disc_bound >= 0.0 {
            check(&self.disc_samples());
        }
        if near >= tip.z + shoulder {
            // Ring by ring: a ring whose height bound stays under the solid there is skipped.
            let samples = self.cone_samples();
            for ring in samples.chunks(CONE_ANGLES) {
                let Some(s0) = ring.first() else { continue };
                let r = s0.dx.hypot(s0.dy);
                if surface
                    .max_height_near(tip.x, tip.y, r)
                    .is_some_and(|h| h >= tip.z + s0.floor)
                {
                    check(ring);
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

    /// How far the surface reaches into the solid with its tip at `tip` and its axis (unit,
    /// tip toward the body) `axis`, mm, measured vertically; cylinders are sampled every
    /// `step` along the axis; ≤ 0 or `f64::MIN`: no contact.
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
        let mut worst = f64::MIN;
        let mut ring = |s: f64, r: f64, n: usize| -> bool {
            let c = tip + axis * s;
            let lowest = c.z - r * lean;
            if lowest > top {
                // Higher rings are higher still: nothing above can touch.
                return false;
            }
            match surface.max_height_near(c.x, c.y, r) {
                Some(h) if h >= lowest => {}
                _ => return true,
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
                    ring(piece.bottom, 0.0, 1);
                    for k in 1..=DISC_RINGS {
                        ring(
                            piece.bottom,
                            radius * k as f64 / DISC_RINGS as f64,
                            DISC_ANGLES,
                        );
                    }
                }
                PieceShape::Cylinder { radius } => {
                    let stations = (piece.height / step).ceil() as usize;
                    for k in 1..=stations {
                        let s = (k as f64 * step).min(piece.height);
                        if !ring(piece.bottom + s, radius, CYLINDER_ANGLES) {
                            return worst;
                        }
                    }
                }
                PieceShape::Cone { radius, tan, .. } => {
                    let rings = (piece.height / CONE_RING_MM).ceil() as usize;
                    for k in 1..=rings {
                        let h = piece.height * k as f64 / rings as f64;
                        // The cone widens, so a ring above the surface does not end the search.
                        ring(piece.bottom + h, radius + h * tan, CONE_ANGLES);
                    }
                }
            }
        }
        worst
    }
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
