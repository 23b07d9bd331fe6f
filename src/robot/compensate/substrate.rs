//! Substrates the gap compensation and the calibration patterns work on: a sphere, a cylinder,
//! a (wavy) plane, or a scanned mesh, with one query — where a ray first meets the surface.
//!
//! Place in the pipeline: the simulation mode of the gap compensation ([`super::simulate`])
//! measures gaps along the tool axis with it, and the patterns ([`crate::robot::pattern`])
//! drop planar points onto it. Analytic surfaces live in their own frame: a sphere `sphere:R`
//! centred at the origin (its top at z = R), a cylinder `cylinder:R` with its axis along y
//! through the origin (its top line at z = R), a plane `plane` at z = 0, optionally wavy
//! (`plane:waviness:A,P`: z = A·sin(2πx/P)). Their normals point out of the solid.

use crate::geom::{Point3, Vector3};
use crate::surface::Surface;
use std::f64::consts::PI;
use std::path::PathBuf;

/// Why a surface description was refused.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SpecError {
    /// The description names no known surface.
    ///
    /// How to fix: write `sphere:R`, `cylinder:R`, `plane`, `plane:waviness:A,P` (mm) or the
    /// path of a mesh file.
    #[error(
        "unknown surface `{0}` (expected sphere:R, cylinder:R, plane, plane:waviness:A,P or a mesh file)"
    )]
    Unknown(String),
    /// A size is not a positive number.
    ///
    /// How to fix: radii and periods are positive millimetres, the amplitude 0 or more.
    #[error("surface `{spec}`: {what} must be a positive number of mm")]
    Size {
        /// The description.
        spec: String,
        /// Which size.
        what: &'static str,
    },
}

/// A surface description from the command line: an analytic surface, or a mesh file to load.
#[derive(Debug, Clone, PartialEq)]
pub enum SurfaceSpec {
    /// An analytic surface.
    Analytic(Analytic),
    /// A mesh or point-cloud file.
    File(PathBuf),
}

/// Waviness of a plane: z = amplitude·sin(2πx/period).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Waviness {
    /// Amplitude, mm.
    pub amplitude: f64,
    /// Period along x, mm.
    pub period: f64,
}

/// An analytic surface in its own frame (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Analytic {
    /// Sphere of this radius (mm) centred at the origin.
    Sphere(f64),
    /// Cylinder of this radius (mm) about the y axis.
    Cylinder(f64),
    /// The plane z = 0, flat or wavy.
    Plane(Option<Waviness>),
}

/// Parses a surface description; anything that is not an analytic surface is a file path,
/// which must exist.
pub fn parse_spec(spec: &str) -> Result<SurfaceSpec, SpecError> {
    let t = spec.trim();
    let size = |text: &str, what| match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(SpecError::Size {
            spec: spec.to_owned(),
            what,
        }),
    };
    if let Some(r) = t.strip_prefix("sphere:") {
        return Ok(SurfaceSpec::Analytic(Analytic::Sphere(size(
            r,
            "the radius",
        )?)));
    }
    if let Some(r) = t.strip_prefix("cylinder:") {
        return Ok(SurfaceSpec::Analytic(Analytic::Cylinder(size(
            r,
            "the radius",
        )?)));
    }
    if t == "plane" {
        return Ok(SurfaceSpec::Analytic(Analytic::Plane(None)));
    }
    if let Some(w) = t.strip_prefix("plane:waviness:") {
        let Some((a, p)) = w.split_once(',') else {
            return Err(SpecError::Unknown(spec.to_owned()));
        };
        let amplitude = match a.trim().parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => v,
            _ => {
                return Err(SpecError::Size {
                    spec: spec.to_owned(),
                    what: "the amplitude",
                });
            }
        };
        let period = size(p, "the period")?;
        return Ok(SurfaceSpec::Analytic(Analytic::Plane(Some(Waviness {
            amplitude,
            period,
        }))));
    }
    let path = PathBuf::from(t);
    if !t.is_empty() && path.is_file() {
        Ok(SurfaceSpec::File(path))
    } else {
        Err(SpecError::Unknown(spec.to_owned()))
    }
}

/// Where a ray meets a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the (unit) ray direction, mm.
    pub t: f64,
    /// Unit surface normal there, facing the ray's origin.
    pub normal: Vector3,
}

/// A surface that rays can be cast at.
pub enum Substrate {
    /// An analytic surface.
    Analytic(Analytic),
    /// A scanned or meshed surface (boxed: its hierarchy is large).
    Mesh(Box<Surface>),
}

impl std::fmt::Debug for Substrate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Substrate::Analytic(a) => f.debug_tuple("Analytic").field(a).finish(),
            Substrate::Mesh(m) => f
                .debug_struct("Mesh")
                .field("triangles", &m.triangles().len())
                .finish(),
        }
    }
}

/// Farthest a ray is followed, mm.
const MAX_RAY: f64 = 1e4;

impl Substrate {
    /// Where the ray from `o` along the unit direction `d` first meets the surface from outside
    /// (t ≥ 0); `None` if it does not, or starts inside a sphere or cylinder or under a plane.
    pub fn hit(&self, o: &Point3, d: &Vector3) -> Option<Hit> {
        match self {
            Substrate::Analytic(Analytic::Sphere(r)) => {
                let t = entry(o.coords.dot(d), o.coords.norm_squared() - r * r, 1.0)?;
                let p = o + d * t;
                Some(Hit {
                    t,
                    normal: p.coords / *r,
                })
            }
            Substrate::Analytic(Analytic::Cylinder(r)) => {
                // The same in the xz plane.
                let (ox, oz, dx, dz) = (o.x, o.z, d.x, d.z);
                let a = dx * dx + dz * dz;
                let t = entry(ox * dx + oz * dz, ox * ox + oz * oz - r * r, a)?;
                let p = o + d * t;
                Some(Hit {
                    t,
                    normal: Vector3::new(p.x, 0.0, p.z) / *r,
                })
            }
            Substrate::Analytic(Analytic::Plane(w)) => plane_hit(o, d, w.as_ref()),
            Substrate::Mesh(m) => m.cast(o, d, MAX_RAY).map(|(t, normal)| Hit { t, normal }),
        }
    }
}

/// The smaller root t ≥ 0 of a·t² + 2·b·t + c = 0 where the ray enters the solid (c > 0: the
/// origin is outside).
fn entry(b: f64, c: f64, a: f64) -> Option<f64> {
    if c < 0.0 || a <= 0.0 {
        return None;
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    // The root of smaller magnitude without cancellation: c / (−b + √disc).
    let q = -b + disc.sqrt();
    if q <= 0.0 {
        return None;
    }
    Some(c / q)
}

/// The height of a (wavy) plane at x and its slope dz/dx.
fn wave(w: Option<&Waviness>, x: f64) -> (f64, f64) {
    match w {
        None => (0.0, 0.0),
        Some(w) => {
            let k = 2.0 * PI / w.period;
            (w.amplitude * (k * x).sin(), w.amplitude * k * (k * x).cos())
        }
    }
}

/// First crossing of the ray with z = h(x): sphere tracing on g(t) = z(t) − h(x(t)), whose
/// rate of change is at most `lip`, so a step of g/lip never jumps over the surface.
fn plane_hit(o: &Point3, d: &Vector3, w: Option<&Waviness>) -> Option<Hit> {
    let slope = w.map_or(0.0, |w| 2.0 * PI * w.amplitude / w.period);
    let lip = d.z.abs() + slope * d.x.abs();
    let g = |t: f64| o.z + t * d.z - wave(w, o.x + t * d.x).0;
    let mut t = 0.0;
    let mut v = g(t);
    if v < 0.0 || lip <= 0.0 {
        return None;
    }
    let mut steps = 0;
    // 1e-10 mm is far below the writers' 0.1 µm.
    while v > 1e-10 {
        t += v / lip;
        v = g(t);
        steps += 1;
        if t > MAX_RAY || steps > 100_000 {
            return None;
        }
    }
    let (_, s) = wave(w, o.x + t * d.x);
    let n = Vector3::new(-s, 0.0, 1.0).normalize();
    Some(Hit { t, normal: n })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_meet_analytic_surfaces_where_the_algebra_says() {
        let down = -Vector3::z();
        let s = Substrate::Analytic(Analytic::Sphere(15.0));
        let h = s.hit(&Point3::new(3.0, 4.0, 40.0), &down).expect("hits");
        assert!((h.t - (40.0 - 200.0f64.sqrt())).abs() < 1e-12);
        assert!((h.normal - Vector3::new(3.0, 4.0, 200.0f64.sqrt()) / 15.0).norm() < 1e-12);
        assert!(s.hit(&Point3::new(16.0, 0.0, 40.0), &down).is_none());
        let c = Substrate::Analytic(Analytic::Cylinder(10.0));
        let h = c.hit(&Point3::new(6.0, 100.0, 20.0), &down).expect("hits");
        assert!((h.t - 12.0).abs() < 1e-12 && (h.normal.x - 0.6).abs() < 1e-12);
        let w = Waviness {
            amplitude: 0.04,
            period: 5.0,
        };
        let p = Substrate::Analytic(Analytic::Plane(Some(w)));
        let d = Vector3::new(0.3, 0.1, -1.0).normalize();
        let o = Point3::new(1.0, 2.0, 3.0);
        let h = p.hit(&o, &d).expect("hits");
        let q = o + d * h.t;
        assert!((q.z - 0.04 * (2.0 * PI * q.x / 5.0).sin()).abs() < 1e-9);
    }

    #[test]
    fn specs_parse_and_unknown_ones_are_named() {
        assert_eq!(
            parse_spec("sphere:15"),
            Ok(SurfaceSpec::Analytic(Analytic::Sphere(15.0)))
        );
        assert_eq!(
            parse_spec("plane:waviness:0.04,5"),
            Ok(SurfaceSpec::Analytic(Analytic::Plane(Some(Waviness {
                amplitude: 0.04,
                period: 5.0
            }))))
        );
        assert!(matches!(parse_spec("cone:3"), Err(SpecError::Unknown(s)) if s == "cone:3"));
        assert!(matches!(
            parse_spec("sphere:-1"),
            Err(SpecError::Size { .. })
        ));
    }
}
