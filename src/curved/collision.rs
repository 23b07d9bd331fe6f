//! The print head as a collision volume, and the test of nozzle positions against material
//! already printed.
//!
//! Place in the pipeline: [`super`] runs it on each curved region before it accepts it; a
//! region with a hit stays planar and the hit is reported.
//!
//! The head is a cone with its apex at the nozzle tip, opening upward at `head_angle` from the
//! vertical up to `head_height`, plus, when `carriage_radius > 0`, a cylinder of that radius
//! around the nozzle axis from `carriage_clearance` above the tip upward. Material is given as
//! planar layers (their top z and xy area) and as single points (the surface itself).

use crate::geom::{ExPolygon, Point3};

/// The head model (`[curved]` head keys).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Head {
    /// Cone half-angle from the vertical, degrees.
    pub angle_deg: f64,
    /// Cone height above the tip, mm.
    pub height: f64,
    /// Carriage cylinder radius, mm (0 = none).
    pub carriage_radius: f64,
    /// Height of the cylinder's bottom above the tip, mm.
    pub carriage_clearance: f64,
}

/// Which part of the head is hit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HeadPart {
    /// The cone around the nozzle.
    Cone,
    /// The carriage cylinder.
    Carriage,
}

/// A collision: material inside the head with the nozzle at `nozzle`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// The nozzle tip, mm.
    pub nozzle: Point3,
    /// The material point inside the head, mm.
    pub material: Point3,
    /// The part of the head it is in.
    pub part: HeadPart,
}

impl Hit {
    /// Horizontal distance between nozzle and material, mm.
    pub fn radius(&self) -> f64 {
        (self.material.x - self.nozzle.x).hypot(self.material.y - self.nozzle.y)
    }

    /// Height of the material above the nozzle tip, mm.
    pub fn rise(&self) -> f64 {
        self.material.z - self.nozzle.z
    }
}

/// A shape as float rings (contour first) with its bounding box [x0, y0, x1, y1].
type Shape = (Vec<Vec<(f64, f64)>>, [f64; 4]);

/// One planar layer of printed material, float mm rings with a bounding box.
#[derive(Debug, Clone, PartialEq)]
struct Slab {
    top: f64,
    /// Per ExPolygon: rings (contour first) and bounding box [x0, y0, x1, y1].
    shapes: Vec<Shape>,
}

/// Printed material the head must not enter.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Material {
    slabs: Vec<Slab>,
    points: Vec<Point3>,
}

impl Material {
    /// Adds a planar layer with its top at `top` covering `area`, keeping only the shapes whose
    /// bounding box meets `window` ([x0, y0, x1, y1], mm).
    pub fn add_layer(&mut self, top: f64, area: &[ExPolygon], window: [f64; 4]) {
        let mut shapes = Vec::new();
        for ex in area {
            let rings: Vec<Vec<(f64, f64)>> = std::iter::once(&ex.contour)
                .chain(&ex.holes)
                .map(|r| r.points.iter().map(|p| p.to_mm()).collect())
                .collect();
            let mut bb = [f64::MAX, f64::MAX, f64::MIN, f64::MIN];
            for &(x, y) in rings.first().into_iter().flatten() {
                bb = [bb[0].min(x), bb[1].min(y), bb[2].max(x), bb[3].max(y)];
            }
            if bb[0] <= window[2] && bb[2] >= window[0] && bb[1] <= window[3] && bb[3] >= window[1]
            {
                shapes.push((rings, bb));
            }
        }
        if !shapes.is_empty() {
            self.slabs.push(Slab { top, shapes });
        }
    }

    /// Adds single material points (e.g. the surface's vertices).
    pub fn add_points(&mut self, points: impl IntoIterator<Item = Point3>) {
        self.points.extend(points);
    }
}

impl Head {
    /// The head's radius at `rise` mm above the tip (0 where it has no extent), and the part.
    pub fn radius_at(&self, rise: f64) -> Option<(f64, HeadPart)> {
        if rise <= 0.0 {
            return None;
        }
        let cone = (rise <= self.height).then(|| rise * self.angle_deg.to_radians().tan());
        let carriage = (self.carriage_radius > 0.0 && rise >= self.carriage_clearance)
            .then_some(self.carriage_radius);
        match (cone, carriage) {
            (Some(c), Some(r)) if r > c => Some((r, HeadPart::Carriage)),
            (Some(c), _) => Some((c, HeadPart::Cone)),
            (None, Some(r)) => Some((r, HeadPart::Carriage)),
            (None, None) => None,
        }
    }

    /// The widest the head gets, mm.
    pub fn max_radius(&self) -> f64 {
        (self.height * self.angle_deg.to_radians().tan()).max(self.carriage_radius)
    }

    /// The first hit (in the order of `nozzles`) of the head against `material`.
    pub fn first_hit(&self, nozzles: &[Point3], material: &Material) -> Option<Hit> {
        for &p in nozzles {
            for slab in &material.slabs {
                let Some((r, part)) = self.radius_at(slab.top - p.z) else {
                    continue;
                };
                for (rings, bb) in &slab.shapes {
                    if p.x + r < bb[0] || p.x - r > bb[2] || p.y + r < bb[1] || p.y - r > bb[3] {
                        continue;
                    }
                    if let Some((x, y)) = closest_within(rings, p.x, p.y, r) {
                        return Some(Hit {
                            nozzle: p,
                            material: Point3::new(x, y, slab.top),
                            part,
                        });
                    }
                }
            }
            for &q in &material.points {
                let Some((r, part)) = self.radius_at(q.z - p.z) else {
                    continue;
                };
                if (q.x - p.x).hypot(q.y - p.y) < r {
                    return Some(Hit {
                        nozzle: p,
                        material: q,
                        part,
                    });
                }
            }
        }
        None
    }
}

/// The point of the shape (rings, contour first, even-odd) nearest to (x, y) when it is closer
/// than `r`: (x, y) itself when inside.
fn closest_within(rings: &[Vec<(f64, f64)>], x: f64, y: f64, r: f64) -> Option<(f64, f64)> {
    let mut inside = false;
    let mut best = (f64::MAX, (x, y));
    for ring in rings {
        let n = ring.len();
        for i in 0..n {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            if (a.1 > y) != (b.1 > y) && x < a.0 + (y - a.1) * (b.0 - a.0) / (b.1 - a.1) {
                inside = !inside;
            }
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let l2 = dx * dx + dy * dy;
            let t = if l2 > 0.0 {
                (((x - a.0) * dx + (y - a.1) * dy) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let c = (a.0 + t * dx, a.1 + t * dy);
            let d = (c.0 - x).hypot(c.1 - y);
            if d < best.0 {
                best = (d, c);
            }
        }
    }
    if inside {
        Some((x, y))
    } else if best.0 < r {
        Some(best.1)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Point2, Polygon};

    fn square(x0: f64, y0: f64, s: f64) -> ExPolygon {
        ExPolygon {
            contour: Polygon::new(vec![
                Point2::from_mm(x0, y0),
                Point2::from_mm(x0 + s, y0),
                Point2::from_mm(x0 + s, y0 + s),
                Point2::from_mm(x0, y0 + s),
            ]),
            holes: Vec::new(),
        }
    }

    #[test]
    fn cone_hits_a_wall_within_its_radius_only() {
        let head = Head {
            angle_deg: 45.0,
            height: 5.0,
            carriage_radius: 0.0,
            carriage_clearance: 10.0,
        };
        let mut m = Material::default();
        m.add_layer(
            3.0,
            &[square(10.0, 0.0, 5.0)],
            [-100.0, -100.0, 100.0, 100.0],
        );
        // 2 mm above the tip the cone is 2 mm wide.
        let near = [Point3::new(8.5, 2.0, 1.0)];
        let far = [Point3::new(7.5, 2.0, 1.0)];
        let hit = head.first_hit(&near, &m).map(|h| (h.part, h.material));
        assert_eq!(hit, Some((HeadPart::Cone, Point3::new(10.0, 2.0, 3.0))));
        assert!(head.first_hit(&far, &m).is_none());
        // Material below the tip never collides.
        assert!(head.first_hit(&[Point3::new(11.0, 2.0, 3.5)], &m).is_none());
        let carriage = Head {
            carriage_radius: 20.0,
            carriage_clearance: 1.5,
            height: 1.0,
            ..head
        };
        let hit = carriage.first_hit(&far, &m).map(|h| h.part);
        assert_eq!(hit, Some(HeadPart::Carriage));
    }
}
