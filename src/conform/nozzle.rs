//! The nozzle as a solid above its tip, and its contacts with the surface.
//!
//! Place in the pipeline: used by the corrections ([`super::correct`]: the tip disk of
//! diameter d_o), by the clearance pass after them, and by the replay of the written G-code
//! ([`super::replay`]). Beyond the published method, which checks only the tip disk, the whole
//! nozzle is checked: a needle of the outer diameter rising `needle_length` above the tip, then
//! a cone widening at `cone_angle` from the vertical for `cone_height`.
//!
//! The nozzle comes from above on a 3-axis machine, so the surface it can meet is the top
//! surface: the check samples the top height on rings around the axis and compares it with the
//! lowest point of the nozzle at that distance from the axis. Samples: the tip disk on four
//! rings of 16 points plus the centre; the cone on rings every half millimetre, asked only when
//! the surface anywhere reaches the cone's height.

use crate::geom::Point3;
use crate::surface::Surface;

/// The nozzle's shape (mm, degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nozzle {
    /// Inner diameter d.
    pub inner: f64,
    /// Outer diameter d_o.
    pub outer: f64,
    /// Straight needle above the tip.
    pub needle_length: f64,
    /// Half-angle of the cone above the needle, degrees; 0 = none.
    pub cone_angle_deg: f64,
    /// Height of the cone.
    pub cone_height: f64,
}

/// Angles per ring of the tip disk.
const DISK_ANGLES: usize = 16;
/// Rings of the tip disk (at ¼, ½, ¾ and 1 of its radius).
const DISK_RINGS: usize = 4;
/// Ring spacing on the cone, mm.
const CONE_RING_MM: f64 = 0.5;
/// Angles per cone ring.
const CONE_ANGLES: usize = 24;

/// Unit directions of the disk rings and of the cone rings (even rings, then odd rings turned
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
        dirs(DISK_ANGLES, 0.0),
        dirs(CONE_ANGLES, 0.0),
        dirs(CONE_ANGLES, 0.5),
    ]
});

/// One sample of a contact check: offset from the axis and the nozzle's lowest height there.
#[derive(Debug, Clone, Copy)]
struct Sample {
    dx: f64,
    dy: f64,
    /// Height of the nozzle's underside above the tip at this offset.
    floor: f64,
    /// Area weight (the ring's radius) for centroids.
    weight: f64,
}

impl Nozzle {
    fn disk_samples(&self) -> Vec<Sample> {
        let ro = self.outer / 2.0;
        let mut s = vec![Sample {
            dx: 0.0,
            dy: 0.0,
            floor: 0.0,
            weight: ro / (2.0 * DISK_RINGS as f64),
        }];
        for k in 1..=DISK_RINGS {
            let r = ro * k as f64 / DISK_RINGS as f64;
            for u in &DIRECTIONS[0] {
                s.push(Sample {
                    dx: r * u[0],
                    dy: r * u[1],
                    floor: 0.0,
                    weight: r,
                });
            }
        }
        s
    }

    fn cone_samples(&self) -> Vec<Sample> {
        let ro = self.outer / 2.0;
        let tan = self.cone_angle_deg.to_radians().tan();
        if !(tan > 0.0 && self.cone_height > 0.0) {
            return Vec::new();
        }
        let reach = self.cone_height * tan;
        let rings = (reach / CONE_RING_MM).ceil() as usize;
        let mut s = Vec::new();
        for k in 1..=rings {
            let r = ro + reach * k as f64 / rings as f64;
            for u in &DIRECTIONS[1 + k % 2] {
                s.push(Sample {
                    dx: r * u[0],
                    dy: r * u[1],
                    floor: self.needle_length + (r - ro) / tan,
                    weight: r,
                });
            }
        }
        s
    }

    /// Where the tip disk at `tip` meets the surface (surface at or above the tip's height):
    /// the weighted centroid of the touching samples (x, y), or `None` without contact.
    pub fn disk_contact(&self, surface: &Surface, tip: &Point3) -> Option<[f64; 2]> {
        let (mut sx, mut sy, mut w) = (0.0, 0.0, 0.0);
        for s in self.disk_samples() {
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

    /// How far the surface reaches into the whole nozzle with its tip at `tip`, mm; ≤ 0: no
    /// contact (the clearance, or a lower bound of it where a coarse bound of the surface's
    /// height already shows there is no contact).
    pub fn penetration(&self, surface: &Surface, tip: &Point3) -> f64 {
        let ro = self.outer / 2.0;
        let reach = ro + self.cone_height * self.cone_angle_deg.to_radians().tan();
        let Some(near) = surface.max_height_near(tip.x, tip.y, reach) else {
            return f64::MIN;
        };
        let disk_bound = surface
            .max_height_near(tip.x, tip.y, ro)
            .map_or(f64::MIN, |h| h - tip.z);
        if near < tip.z + self.needle_length && disk_bound < 0.0 {
            return disk_bound.max(near - tip.z - self.needle_length);
        }
        let mut worst = f64::MIN;
        let mut check = |samples: Vec<Sample>| {
            for s in samples {
                if let Some(h) = surface.height(tip.x + s.dx, tip.y + s.dy) {
                    worst = worst.max(h - (tip.z + s.floor));
                }
            }
        };
        if disk_bound >= 0.0 {
            check(self.disk_samples());
        }
        if near >= tip.z + self.needle_length {
            // Ring by ring: a ring whose height bound stays under the cone there is skipped.
            let samples = self.cone_samples();
            for ring in samples.chunks(CONE_ANGLES) {
                let Some(s0) = ring.first() else { continue };
                let r = s0.dx.hypot(s0.dy);
                if surface
                    .max_height_near(tip.x, tip.y, r)
                    .is_some_and(|h| h >= tip.z + s0.floor)
                {
                    check(ring.to_vec());
                }
            }
        }
        worst
    }

    /// How far `tip` must rise for the whole nozzle to clear the surface by `margin`, mm; ≤ 0
    /// when it does. Asked at the lowered tip so the answer is exact where it is > 0: where the
    /// surface is far, [`Nozzle::penetration`] answers with a bound of the clearance, not the
    /// clearance.
    pub fn shortfall(&self, surface: &Surface, tip: &Point3, margin: f64) -> f64 {
        self.penetration(surface, &Point3::new(tip.x, tip.y, tip.z - margin))
    }
}

#[cfg(test)]
impl Nozzle {
    /// The default nozzle (d = 0.25, d_o = 0.5, a 6 mm needle under a 30° cone 10 mm high) of
    /// the module tests.
    pub(crate) fn for_tests() -> Self {
        Nozzle {
            inner: 0.25,
            outer: 0.5,
            needle_length: 6.0,
            cone_angle_deg: 30.0,
            cone_height: 10.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let n = Nozzle::for_tests();
        // 3 µm above the plate, 5 µm wanted: 2 µm short; 1 µm below it: 6 µm short.
        let short = n.shortfall(&plate, &Point3::new(0.0, 0.0, 0.003), 0.005);
        assert!((short - 0.002).abs() < 1e-12, "{short}");
        let short = n.shortfall(&plate, &Point3::new(0.0, 0.0, -0.001), 0.005);
        assert!((short - 0.006).abs() < 1e-12, "{short}");
        // Well above it: clear, whatever bound the coarse check answers with.
        assert!(n.shortfall(&plate, &Point3::new(0.0, 0.0, 0.3), 0.005) <= 0.0);
        assert!(n.shortfall(&plate, &Point3::new(0.0, 0.0, 0.0051), 0.005) <= 0.0);
    }
}
