//! Curves to polylines, in final (millimetre) coordinates, within a tolerance.
//!
//! - Bézier curves: the control points are mapped to millimetres first (an affine map of a
//!   Bézier curve is the Bézier curve of the mapped control points, exactly), then flattened
//!   with `kurbo::flatten` at the tolerance.
//! - Elliptical arcs, circles and ellipses are sampled analytically. In millimetres an ellipse
//!   (of any transform) is `q(θ) = c + u·cos θ + v·sin θ`, the image of the unit circle under the
//!   linear map `A = [u v]`. A point at distance `d` from the unit circle maps to a point at most
//!   `σ·d` from the ellipse, with `σ` the largest singular value of `A`; so working on the unit
//!   circle with the tolerance `tol / σ` bounds the deviation in millimetres by `tol`.
//!   - An open arc gets vertices on the curve, with its end points exact; the chord sagitta
//!     `1 − cos(Δ/2)` stays within `tol / σ`.
//!   - A whole circle or ellipse has no end points to keep, so its vertices sit slightly outside
//!     the curve, at radius `1 + δ` with `δ = (1 − cos(Δ/2)) / (1 + cos(Δ/2))`: each chord then
//!     dips exactly `δ` inside while each vertex is `δ` outside. The deviation (both ways) is
//!     at most `tol`, with about half the points an inscribed polygon needs, and the enclosed
//!     area is nearly exact (relative error about `(tol/r)²` instead of `(4/3)·tol/r`).

use std::f64::consts::PI;

use kurbo::{Affine, CubicBez, ParamCurve, Point, QuadBez, Vec2};

/// Flattening would exceed the point budget.
#[derive(Debug)]
pub(crate) struct Overflow;

/// Output points of one subpath, with a shared budget for the whole document.
pub(crate) struct Out<'a> {
    pub(crate) points: Vec<Point>,
    pub(crate) budget: &'a mut usize,
}

impl Out<'_> {
    pub(crate) fn push(&mut self, p: Point) -> Result<(), Overflow> {
        if *self.budget == 0 {
            return Err(Overflow);
        }
        *self.budget -= 1;
        self.points.push(p);
        Ok(())
    }

    /// Fails early when about `n` more points would not fit.
    fn reserve(&mut self, n: f64) -> Result<(), Overflow> {
        // NaN or huge estimates count as not fitting.
        if n.is_nan() || n > *self.budget as f64 {
            return Err(Overflow);
        }
        Ok(())
    }
}

/// Appends a cubic Bézier (in final coordinates) to `out`, except its start point; the last
/// point is exactly `c.p3`.
///
/// Adaptive subdivision at `t = 1/2` until a piece is within `tol` of its chord, measured by a
/// bound that holds exactly (not an estimate): when both inner control points project onto the
/// chord, the curve's distance from the chord is at most `3/4·max(|s1|, |s2|)`, with `s1`, `s2`
/// the control points' distances from the chord's line (the Bernstein weights `3t(1−t)²` and
/// `3t²(1−t)` sum to at most 3/4); otherwise the convex hull bound `max(d1, d2)` to the segment
/// applies. The chord is within the same distance of the curve, since the curve's projection
/// covers the chord. (`kurbo::flatten` needs fewer points but its error is an estimate: it
/// overshot by up to 15% near cusps in the test below.)
pub(crate) fn cubic(c: CubicBez, tol: f64, out: &mut Out<'_>) -> Result<(), Overflow> {
    // Uniform subdivision into n chords deviates at most max|B''| / (8 n²) with
    // max|B''| <= 6 max(|p0 - 2p1 + p2|, |p1 - 2p2 + p3|): more than adaptive output needs,
    // so this is an upper bound to check the budget against before starting.
    let dd = (c.p0.to_vec2() - 2.0 * c.p1.to_vec2() + c.p2.to_vec2())
        .hypot()
        .max((c.p1.to_vec2() - 2.0 * c.p2.to_vec2() + c.p3.to_vec2()).hypot());
    out.reserve((0.75 * dd / tol).sqrt() + 2.0)?;
    subdivide(c, tol, out, 0)?;
    snap_end(out, c.p3)
}

/// Deepest subdivision: 2^40 pieces is far beyond the point budget, so this only stops
/// non-finite input from recursing forever.
const MAX_SUBDIVISION: u32 = 40;

fn subdivide(c: CubicBez, tol: f64, out: &mut Out<'_>, depth: u32) -> Result<(), Overflow> {
    if depth >= MAX_SUBDIVISION || deviation_bound(&c) <= tol {
        return out.push(c.p3);
    }
    let (a, b) = c.subdivide();
    subdivide(a, tol, out, depth + 1)?;
    subdivide(b, tol, out, depth + 1)
}

/// An upper bound on the distance between the cubic and its chord (see [`cubic`]).
fn deviation_bound(c: &CubicBez) -> f64 {
    let chord = c.p3 - c.p0;
    let len2 = chord.hypot2();
    let d1 = c.p1 - c.p0;
    let d2 = c.p2 - c.p0;
    if len2 == 0.0 {
        return d1.hypot().max(d2.hypot()).max((c.p3 - c.p0).hypot());
    }
    let (t1, t2) = (d1.dot(chord) / len2, d2.dot(chord) / len2);
    let len = len2.sqrt();
    if (0.0..=1.0).contains(&t1) && (0.0..=1.0).contains(&t2) {
        0.75 * (d1.cross(chord).abs() / len).max(d2.cross(chord).abs() / len)
    } else {
        let to_segment = |d: Vec2, t: f64| (d - chord * t.clamp(0.0, 1.0)).hypot();
        to_segment(d1, t1).max(to_segment(d2, t2))
    }
}

/// Appends a quadratic Bézier (in final coordinates) to `out`, except its start point.
pub(crate) fn quad(q: QuadBez, tol: f64, out: &mut Out<'_>) -> Result<(), Overflow> {
    cubic(q.raise(), tol, out)
}

/// Makes the last point exactly `end` (flattening may round it), adding it if missing.
fn snap_end(out: &mut Out<'_>, end: Point) -> Result<(), Overflow> {
    match out.points.last_mut() {
        Some(last) if (*last - end).hypot() <= 1e-9 * (1.0 + end.to_vec2().hypot()) => {
            *last = end;
            Ok(())
        }
        _ => out.push(end),
    }
}

/// An ellipse in final coordinates: `center + u·cos θ + v·sin θ`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ellipse {
    pub(crate) center: Point,
    pub(crate) u: Vec2,
    pub(crate) v: Vec2,
}

impl Ellipse {
    /// The ellipse with centre `center`, radii `rx`, `ry` and x-axis rotation `x_rotation`
    /// (radians) in user space, mapped by `ctm`.
    pub(crate) fn new(ctm: Affine, center: Point, rx: f64, ry: f64, x_rotation: f64) -> Ellipse {
        let (s, c) = x_rotation.sin_cos();
        let [a, b, cc, d, _, _] = ctm.as_coeffs();
        let lin = |w: Vec2| Vec2::new(a * w.x + cc * w.y, b * w.x + d * w.y);
        Ellipse {
            center: ctm * center,
            u: lin(Vec2::new(c * rx, s * rx)),
            v: lin(Vec2::new(-s * ry, c * ry)),
        }
    }

    fn at(&self, theta: f64, scale: f64) -> Point {
        let (s, c) = theta.sin_cos();
        self.center + scale * (self.u * c + self.v * s)
    }

    /// Largest singular value of `[u v]`: the most a unit distance can grow.
    fn sigma_max(&self) -> f64 {
        let (a, b, c, d) = (self.u.x, self.u.y, self.v.x, self.v.y);
        let sum = a * a + b * b + c * c + d * d;
        let det = a * d - b * c;
        let disc = (sum * sum - 4.0 * det * det).max(0.0).sqrt();
        ((sum + disc) / 2.0).sqrt()
    }
}

/// Largest parameter step whose chord sagitta on the unit circle is at most `dp`, capped so a
/// full turn has at least 3 chords.
fn max_step_inscribed(dp: f64) -> f64 {
    if dp >= 1.0 {
        2.0 * PI / 3.0
    } else {
        (2.0 * (1.0 - dp).acos()).min(2.0 * PI / 3.0)
    }
}

/// Appends an elliptical arc from parameter `theta0` over `sweep` (radians, signed), except its
/// start point; the last point is exactly `end`.
pub(crate) fn arc(
    e: &Ellipse,
    theta0: f64,
    sweep: f64,
    end: Point,
    tol: f64,
    out: &mut Out<'_>,
) -> Result<(), Overflow> {
    let sigma = e.sigma_max();
    if sigma.is_finite() && sigma > 0.0 {
        let n = (sweep.abs() / max_step_inscribed(tol / sigma))
            .ceil()
            .max(1.0);
        out.reserve(n)?;
        let step = sweep / n;
        for k in 1..n as usize {
            out.push(e.at(theta0 + step * k as f64, 1.0))?;
        }
    }
    out.push(end)
}

/// Appends a whole ellipse as a closed polygon, starting at parameter 0, with vertices placed
/// so that the deviation is balanced inside and outside (see the module docs).
pub(crate) fn full_ellipse(e: &Ellipse, tol: f64, out: &mut Out<'_>) -> Result<(), Overflow> {
    let sigma = e.sigma_max();
    if !(sigma.is_finite() && sigma > 0.0) {
        return out.push(e.center);
    }
    let dp = tol / sigma;
    // Largest step with a balanced deviation δ = (1 - c) / (1 + c) <= dp, c = cos(step / 2).
    let max_step = if dp >= 1.0 {
        2.0 * PI / 3.0
    } else {
        (2.0 * ((1.0 - dp) / (1.0 + dp)).acos()).min(2.0 * PI / 3.0)
    };
    let n = (2.0 * PI / max_step).ceil().max(3.0);
    out.reserve(n)?;
    let step = 2.0 * PI / n;
    let c = (step / 2.0).cos();
    let scale = 1.0 + (1.0 - c) / (1.0 + c);
    for k in 0..n as usize {
        out.push(e.at(step * k as f64, scale))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance from `p` to segments `range` of the polyline (wrapping when closed).
    fn dist_to_segments(
        p: Point,
        poly: &[Point],
        closed: bool,
        range: std::ops::Range<usize>,
    ) -> (f64, usize) {
        let n = poly.len();
        let segs = if closed { n } else { n - 1 };
        let mut best = (f64::INFINITY, 0);
        for i in range.start..range.end.min(segs) {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let ab = b - a;
            let t = if ab.hypot2() == 0.0 {
                0.0
            } else {
                ((p - a).dot(ab) / ab.hypot2()).clamp(0.0, 1.0)
            };
            let d = (p - (a + ab * t)).hypot();
            if d < best.0 {
                best = (d, i);
            }
        }
        best
    }

    /// Max distance between the curve (dense samples) and the polyline, both ways.
    fn hausdorff(curve: impl Fn(f64) -> Point, poly: &[Point], closed: bool) -> f64 {
        const SAMPLES: u32 = 1500;
        let samples: Vec<Point> = (0..=SAMPLES)
            .map(|i| curve(f64::from(i) / f64::from(SAMPLES)))
            .collect();
        let all = 0..usize::MAX;
        let mut worst: f64 = 0.0;
        for &p in &samples {
            worst = worst.max(dist_to_segments(p, poly, closed, all.clone()).0);
        }
        let n = poly.len();
        let segs = if closed { n } else { n - 1 };
        for i in 0..segs {
            for k in 0..4 {
                let p = poly[i].lerp(poly[(i + 1) % n], f64::from(k) / 4.0 + 0.125);
                worst = worst.max(dist_to_segments(p, &samples, false, all.clone()).0);
            }
        }
        worst
    }

    #[test]
    fn cubics_stay_within_tolerance() {
        // A fixed pseudo-random set of cubics, including cusps and loops.
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 40.0 - 20.0
        };
        for tol in [0.5, 0.05, 0.01] {
            for _ in 0..30 {
                let c = CubicBez::new(
                    (rnd(), rnd()),
                    (rnd(), rnd()),
                    (rnd(), rnd()),
                    (rnd(), rnd()),
                );
                let mut budget = 1_000_000;
                let mut out = Out {
                    points: vec![c.p0],
                    budget: &mut budget,
                };
                cubic(c, tol, &mut out).expect("within budget");
                assert_eq!(*out.points.last().expect("points"), c.p3);
                let d = hausdorff(|t| kurbo::ParamCurve::eval(&c, t), &out.points, false);
                assert!(d <= tol * 1.0001, "tol {tol}: deviation {d} for {c:?}");
            }
        }
    }

    #[test]
    fn transformed_arcs_and_ellipses_stay_within_tolerance() {
        let ctm = Affine::new([0.3, 0.1, -0.4, 0.2, 5.0, 7.0]);
        let e = Ellipse::new(ctm, Point::new(2.0, 3.0), 30.0, 10.0, 0.7);
        for tol in [0.2, 0.01] {
            let mut budget = 1_000_000;
            let end = e.at(2.5, 1.0);
            let mut out = Out {
                points: vec![e.at(0.3, 1.0)],
                budget: &mut budget,
            };
            arc(&e, 0.3, 2.2, end, tol, &mut out).expect("within budget");
            let d = hausdorff(|t| e.at(0.3 + 2.2 * t, 1.0), &out.points, false);
            assert!(d <= tol * 1.0001, "arc: {d} > {tol}");
            let mut budget = 1_000_000;
            let mut out = Out {
                points: Vec::new(),
                budget: &mut budget,
            };
            full_ellipse(&e, tol, &mut out).expect("within budget");
            let d = hausdorff(|t| e.at(2.0 * PI * t, 1.0), &out.points, true);
            assert!(d <= tol * 1.0001, "ellipse: {d} > {tol}");
        }
    }

    #[test]
    fn budget_is_enforced() {
        let mut budget = 10;
        let e = Ellipse::new(Affine::IDENTITY, Point::ORIGIN, 1e6, 1e6, 0.0);
        let mut out = Out {
            points: Vec::new(),
            budget: &mut budget,
        };
        assert!(full_ellipse(&e, 1e-3, &mut out).is_err());
        let mut budget = 10;
        let mut out = Out {
            points: Vec::new(),
            budget: &mut budget,
        };
        let c = CubicBez::new((0.0, 0.0), (1e9, 0.0), (0.0, 1e9), (1.0, 1.0));
        assert!(cubic(c, 1e-3, &mut out).is_err());
    }
}
