//! The whole nozzle along a tilted tool axis against the surface: the tip disk, the needle and
//! the cone sampled on rings around the axis and compared with the top surface.
//!
//! Place in the pipeline: used by [`super::plan`] after the standoff, for the report's
//! contacts. [`super::super::nozzle`] checks a vertical nozzle; this check follows the tool
//! axis instead: rings perpendicular to it, every quarter of the inner diameter along the
//! needle (16 points on the outer radius, and on the tip disk also at ¼, ½ and ¾ of it plus
//! the centre), every half millimetre along the cone (24 points). A sample lies in the part
//! when the top surface at its (x, y) is higher than it; the depth is that height difference.
//! A ring whose lowest point is above a bound of the surface's height around it is skipped.

use super::super::nozzle::Nozzle;
use crate::geom::{Point3, Vector3};
use crate::surface::Surface;

/// Points per ring on the needle and the tip disk.
const NEEDLE_ANGLES: usize = 16;
/// Points per ring on the cone.
const CONE_ANGLES: usize = 24;
/// Ring spacing on the cone, mm.
const CONE_STEP: f64 = 0.5;

/// How far the surface reaches into the nozzle with its tip at `tip` and its axis (unit, tip
/// toward the body) `axis`, mm, measured vertically; ≤ 0 or `f64::MIN`: no contact.
pub fn penetration(surface: &Surface, nozzle: &Nozzle, tip: &Point3, axis: &Vector3) -> f64 {
    let ro = nozzle.outer / 2.0;
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
    // The tip disk.
    ring(0.0, 0.0, 1);
    for k in 1..=4 {
        ring(0.0, ro * f64::from(k) / 4.0, NEEDLE_ANGLES);
    }
    // The needle.
    let step = nozzle.inner / 4.0;
    let stations = (nozzle.needle_length / step).ceil() as usize;
    for k in 1..=stations {
        let s = (k as f64 * step).min(nozzle.needle_length);
        if !ring(s, ro, NEEDLE_ANGLES) {
            return worst;
        }
    }
    // The cone.
    let tan = nozzle.cone_angle_deg.to_radians().tan();
    if tan > 0.0 && nozzle.cone_height > 0.0 {
        let rings = (nozzle.cone_height / CONE_STEP).ceil() as usize;
        for k in 1..=rings {
            let h = nozzle.cone_height * k as f64 / rings as f64;
            // The cone widens, so a ring above the surface does not end the search.
            ring(nozzle.needle_length + h, ro + h * tan, CONE_ANGLES);
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let n = Nozzle::for_tests();
        // Vertical: the needle stays 2 mm from the wall, the cone starts 6 mm up (above it).
        assert!(penetration(&s, &n, &tip, &Vector3::z()) <= 0.0);
        // Leaning 45° toward the wall: the needle at height 5 is 4.75 mm across, inside it.
        let lean = Vector3::new(1.0, 0.0, 1.0).normalize();
        let p = penetration(&s, &n, &tip, &lean);
        assert!(p > 0.0, "{p}");
        // Leaning away from it: clear.
        let away = Vector3::new(-1.0, 0.0, 1.0).normalize();
        assert!(penetration(&s, &n, &tip, &away) <= 0.0);
        Ok(())
    }
}
