//! Calibration print patterns: a circle, a spiral or a serpentine drawn in a plane and
//! projected orthographically onto a substrate, as a robot path with the tool along the
//! surface normal and the tip at the target gap above the surface.
//!
//! Place in the pipeline: `conduit compensate pattern`, the start of the robot calibration
//! loop — print the pattern, measure its gaps, compensate ([`super::compensate`]). The
//! pattern is drawn around a centre (x, y) and either dropped along −z ("top view", as
//! `conduit conform` projects a design) or laid in the tangent plane of the surface point
//! above the centre and dropped along that plane's normal, which keeps it undistorted on a
//! steep flank. Every point becomes a pose: tip = surface point + gap·normal, tool frame z
//! along −normal ([`super::compensate::frame`]). The first pose is the approach (no
//! dispensing).
//!
//! Shapes (sizes in mm; `spacing` between neighbouring points, `pitch` between lines):
//! - circle: diameter `size`, from +x counter-clockwise, closed (the first point repeats);
//! - spiral: Archimedean, r = pitch·θ/2π from the centre out to diameter `size`;
//! - serpentine: lines along x across a square of side `size`, `pitch` apart, joined at
//!   alternate ends.

use super::compensate::frame;
use super::compensate::substrate::Substrate;
use crate::geom::{Point3, Vector3};
use conduit_poses::Pose;
use std::f64::consts::PI;

/// Why a pattern could not be made.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PatternError {
    /// A size is not a positive number.
    ///
    /// How to fix: give positive millimetres.
    #[error("{what} must be a positive number of mm, got {value}")]
    Size {
        /// Which size.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// A pattern point has no surface under it.
    ///
    /// How to fix: make the pattern smaller or move it (`--at`) over the surface.
    #[error("pattern point {index} ({x:.3}, {y:.3}) is off the surface")]
    OffSurface {
        /// 0-based point index.
        index: usize,
        /// Where the point was drawn (x).
        x: f64,
        /// Where the point was drawn (y).
        y: f64,
    },
    /// Too many points for the size and spacing.
    ///
    /// How to fix: raise the spacing or pitch.
    #[error("the pattern would have more than {0} points")]
    TooLarge(usize),
}

/// Most points a pattern may have.
const MAX_POINTS: usize = 2_000_000;

/// A pattern shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Shape {
    /// A closed circle.
    Circle,
    /// An Archimedean spiral from the centre out.
    Spiral,
    /// Parallel lines joined at alternate ends.
    Serpentine,
}

/// What to draw and where.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatternParams {
    /// The shape.
    pub shape: Shape,
    /// Diameter (circle, spiral) or side (serpentine), mm.
    pub size: f64,
    /// Centre of the pattern in the top view, mm.
    pub at: [f64; 2],
    /// Distance between neighbouring points, mm.
    pub spacing: f64,
    /// Distance between lines or turns, mm.
    pub pitch: f64,
    /// Tip-to-surface gap along the normal, mm.
    pub gap: f64,
    /// Draw in the tangent plane at the centre instead of the top view.
    pub tangent: bool,
}

/// The shape's points in its plane, relative to the centre.
pub fn planar(
    shape: Shape,
    size: f64,
    spacing: f64,
    pitch: f64,
) -> Result<Vec<[f64; 2]>, PatternError> {
    for (what, value) in [("size", size), ("spacing", spacing), ("pitch", pitch)] {
        if !(value.is_finite() && value > 0.0) {
            return Err(PatternError::Size { what, value });
        }
    }
    let r = size / 2.0;
    let guard = |n: f64| {
        if n > MAX_POINTS as f64 {
            Err(PatternError::TooLarge(MAX_POINTS))
        } else {
            Ok(n as usize)
        }
    };
    match shape {
        Shape::Circle => {
            let n = guard((2.0 * PI * r / spacing).ceil().max(3.0))?;
            Ok((0..=n)
                .map(|i| {
                    // The last point is the first one again, exactly.
                    let a = 2.0 * PI * (i % n) as f64 / n as f64;
                    [r * a.cos(), r * a.sin()]
                })
                .collect())
        }
        Shape::Spiral => {
            let b = pitch / (2.0 * PI);
            let end = r / b;
            guard(PI * r * r / (pitch * spacing) + r / spacing)?;
            let mut out = vec![[0.0, 0.0]];
            let mut th: f64 = 0.0;
            while th < end {
                // Arc length ds = √(r² + b²)·dθ, with r taken at the end of a first guess of
                // the step (r only grows), so no step is longer than `spacing`.
                let step = |r: f64| spacing / (r * r + b * b).sqrt();
                let guess = b * (th + step(b * th));
                th = (th + step(guess)).min(end);
                let rr = b * th;
                out.push([rr * th.cos(), rr * th.sin()]);
            }
            Ok(out)
        }
        Shape::Serpentine => {
            let lines = (size / pitch + 1e-9).floor() as usize + 1;
            let per_line = guard((size / spacing).ceil().max(1.0))?;
            guard((lines * (per_line + 1)) as f64)?;
            let y0 = -((lines - 1) as f64) * pitch / 2.0;
            let mut out = Vec::new();
            for k in 0..lines {
                let y = y0 + k as f64 * pitch;
                let (a, b) = if k % 2 == 0 { (-r, r) } else { (r, -r) };
                if k > 0 {
                    // The joint from the previous line's end, at `spacing` steps.
                    let prev = y - pitch;
                    let m = (pitch / spacing).ceil().max(1.0) as usize;
                    out.extend((1..m).map(|j| [a, prev + pitch * j as f64 / m as f64]));
                }
                out.extend((0..=per_line).map(|i| [a + (b - a) * i as f64 / per_line as f64, y]));
            }
            Ok(out)
        }
    }
}

/// How far above the surface the projecting rays start, mm, beyond the pattern's size.
const ABOVE: f64 = 1e3;

/// The pattern as poses on `substrate` (module docs).
pub fn pattern(substrate: &Substrate, p: &PatternParams) -> Result<Vec<Pose>, PatternError> {
    if !(p.gap.is_finite() && p.gap >= 0.0) {
        return Err(PatternError::Size {
            what: "gap",
            value: p.gap,
        });
    }
    let pts = planar(p.shape, p.size, p.spacing, p.pitch)?;
    let down = -Vector3::z();
    let drop = |q: Point3, d: &Vector3, index: usize, xy: [f64; 2]| {
        substrate
            .hit(&(q - d * ABOVE), d)
            .map(|h| (q - d * ABOVE + d * h.t, h.normal))
            .ok_or(PatternError::OffSurface {
                index,
                x: xy[0],
                y: xy[1],
            })
    };
    let [cx, cy] = p.at;
    // The drawing plane: the top view, or the tangent plane at the centre.
    let (origin, u, v, d) = if p.tangent {
        let (c, n) = drop(Point3::new(cx, cy, 0.0), &down, 0, p.at)?;
        let Some(q) = frame::quaternion(&-n) else {
            return Err(PatternError::OffSurface {
                index: 0,
                x: cx,
                y: cy,
            });
        };
        let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            q[0], q[1], q[2], q[3],
        ));
        // The tool frame's x and y span the tangent plane (y = z × x with z = −n).
        (c, r * Vector3::x(), r * Vector3::y(), -n)
    } else {
        (Point3::new(cx, cy, 0.0), Vector3::x(), Vector3::y(), down)
    };
    pts.iter()
        .enumerate()
        .map(|(i, xy)| {
            let q = origin + u * xy[0] + v * xy[1];
            let (s, n) = drop(q, &d, i, [q.x, q.y])?;
            let tip = s + n * p.gap;
            let quaternion = frame::quaternion(&-n).ok_or(PatternError::OffSurface {
                index: i,
                x: q.x,
                y: q.y,
            })?;
            Ok(Pose {
                position: [tip.x, tip.y, tip.z],
                quaternion,
                dispense: i > 0,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_have_their_size_and_spacing() {
        let c = planar(Shape::Circle, 10.0, 0.1, 1.0).expect("circle");
        assert_eq!(c.first(), c.last());
        assert!(c.iter().all(|p| (p[0].hypot(p[1]) - 5.0).abs() < 1e-12));
        let s = planar(Shape::Spiral, 10.0, 0.1, 1.0).expect("spiral");
        let last = s[s.len() - 1];
        assert!((last[0].hypot(last[1]) - 5.0).abs() < 1e-12);
        assert!(
            s.windows(2)
                .all(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) < 0.1 + 1e-9)
        );
        let z = planar(Shape::Serpentine, 10.0, 0.5, 2.0).expect("serpentine");
        // Six lines at y = −5, −3, ..., 5, 21 points each, joints of 3 points between them.
        assert_eq!(z.len(), 6 * 21 + 5 * 3);
        assert_eq!(z[0], [-5.0, -5.0]);
        assert_eq!(z[z.len() - 1], [-5.0, 5.0]);
        assert!(
            z.windows(2)
                .all(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) < 0.5 + 1e-9)
        );
    }
}
