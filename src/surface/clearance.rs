//! Exact clearance: the highest the surface reaches inside a footprint of the tool — a disc
//! (the tip, a needle, a tilted tool's cross-section) or a cone's annulus — computed exactly
//! per triangle, not sampled.
//!
//! Place in the pipeline: vocabulary under [`super::contact`], which asks it for every check
//! of the tool against a scanned surface: conform's clearance pass, its report's contact count
//! and tip-above-surface figures, the replay of written G-code.
//!
//! # Method
//!
//! Over one triangle the surface is a plane, and the height the tool must clear is an affine
//! function of the point. The largest value of an affine function over the convex set
//! triangle ∩ disc lies at one of its extreme points:
//!
//! 1. a corner of the triangle inside the disc;
//! 2. a crossing of a triangle edge with the circle;
//! 3. the point of the circle the function's gradient points to, when it lies in the triangle
//!    (with no gradient, the centre).
//!
//! Taking the largest of these candidates over every triangle near the disc (the uniform grid
//! of the [`HeightField`]) is the exact maximum, to rounding. A tilted disc is the same
//! question in the disc's own coordinates: its xy footprint is an ellipse, the affine map that
//! turns it back into a disc keeps the triangle a triangle and the function affine.
//!
//! A cone (its underside rises `1/tan` per mm from the axis) asks for the largest
//! `h(p) − k·|p − c|` over triangle ∩ annulus. The function is concave on the triangle, so
//! besides the corners and the crossings of the two circles, the candidates are the gradient's
//! points on both circles, the one critical point of each edge (where the plane's rise along the
//! edge equals the cone's) and the axis itself when the annulus reaches it.
//!
//! Sampling the rim (4 rings × 16 angles, 0.1 mm apart on a 0.5 mm disc) misses a crease
//! between two samples by micrometres; this does not.

use super::height_field::HeightField;
use crate::geom::{Point3, Vector3};

/// Barycentric slack of the gradient's point lying in a triangle: points on a shared edge are
/// found by both triangles (and, being on the circle too, as an edge crossing anyway).
const INSIDE_EPS: f64 = 1e-12;

/// Smallest |det| / (|e₁|·|e₂|) of a triangle taken as two-dimensional: thinner ones are their
/// edges (corners and crossings only).
const FLAT_SINE: f64 = 1e-12;

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Parameters in [0, 1] where the segment `a`→`b` crosses the circle of radius `r` about the
/// origin.
fn circle_crossings(a: [f64; 2], b: [f64; 2], r: f64) -> impl Iterator<Item = f64> {
    let d = sub(b, a);
    let dd = dot(d, d);
    let ad = dot(a, d);
    let disc = ad * ad - dd * (dot(a, a) - r * r);
    let roots = if dd > 0.0 && disc >= 0.0 {
        let s = disc.sqrt();
        [(-ad - s) / dd, (-ad + s) / dd]
    } else {
        [f64::NAN; 2]
    };
    roots.into_iter().filter(|t| (0.0..=1.0).contains(t))
}

/// The gradient of an affine function over a triangle and the triangle's frame: its edges
/// from the first corner and their cross product.
type Frame = ([f64; 2], [f64; 2], [f64; 2], f64);

/// An affine function over a triangle: its value at the corners and its gradient.
struct Affine {
    p: [[f64; 2]; 3],
    vals: [f64; 3],
    /// Gradient and the triangle's frame, when the triangle is two-dimensional.
    frame: Option<Frame>,
}

impl Affine {
    fn new(p: [[f64; 2]; 3], vals: [f64; 3]) -> Self {
        let e1 = sub(p[1], p[0]);
        let e2 = sub(p[2], p[0]);
        let det = cross(e1, e2);
        let scale = dot(e1, e1).sqrt() * dot(e2, e2).sqrt();
        let frame = (det.abs() > FLAT_SINE * scale && scale > 0.0).then(|| {
            let (d1, d2) = (vals[1] - vals[0], vals[2] - vals[0]);
            let g = [
                (d1 * e2[1] - e1[1] * d2) / det,
                (e1[0] * d2 - e2[0] * d1) / det,
            ];
            (g, e1, e2, det)
        });
        Self { p, vals, frame }
    }

    /// The value at `q` when `q` lies in the triangle.
    fn inside(&self, q: [f64; 2]) -> Option<f64> {
        let (g, e1, e2, det) = self.frame?;
        let w = sub(q, self.p[0]);
        let l1 = cross(w, e2) / det;
        let l2 = cross(e1, w) / det;
        (l1 >= -INSIDE_EPS && l2 >= -INSIDE_EPS && l1 + l2 <= 1.0 + INSIDE_EPS)
            .then(|| self.vals[0] + dot(g, w))
    }

    /// The unit gradient, or `None` on a level triangle (or a flat one).
    fn direction(&self) -> Option<[f64; 2]> {
        let (g, ..) = self.frame?;
        let n = dot(g, g).sqrt();
        (n > 0.0).then(|| [g[0] / n, g[1] / n])
    }

    /// The edges: ends, values at the ends.
    fn edges(&self) -> impl Iterator<Item = ([f64; 2], [f64; 2], f64, f64)> + '_ {
        (0..3).map(|k| {
            let j = (k + 1) % 3;
            (self.p[k], self.p[j], self.vals[k], self.vals[j])
        })
    }
}

/// The largest value, over the part of the triangle `p` (corners relative to the disc's
/// centre) inside the disc of radius `r`, of the affine function taking `vals` at the
/// corners; `None` when the triangle and the disc do not meet (see the module docs).
pub fn max_over_disc(p: [[f64; 2]; 3], vals: [f64; 3], r: f64) -> Option<f64> {
    let f = Affine::new(p, vals);
    let mut best = f64::NEG_INFINITY;
    let r2 = r * r;
    for (k, q) in p.iter().enumerate() {
        if dot(*q, *q) <= r2 {
            best = best.max(vals[k]);
        }
    }
    for (a, b, va, vb) in f.edges() {
        for t in circle_crossings(a, b, r) {
            best = best.max(va + t * (vb - va));
        }
    }
    let q = f.direction().map_or([0.0, 0.0], |u| [r * u[0], r * u[1]]);
    if let Some(v) = f.inside(q) {
        best = best.max(v);
    }
    (best > f64::NEG_INFINITY).then_some(best)
}

/// The largest value of `f(p) − k·|p|` over the part of the triangle `p` (corners relative to
/// the axis) in the annulus `r0 ≤ |p| ≤ r1`, with `f` the affine function taking `vals` at the
/// corners and `k ≥ 0`; `None` when they do not meet (see the module docs).
pub fn max_over_cone(p: [[f64; 2]; 3], vals: [f64; 3], r0: f64, r1: f64, k: f64) -> Option<f64> {
    let f = Affine::new(p, vals);
    let mut best = f64::NEG_INFINITY;
    let within = |q: [f64; 2]| {
        let d = dot(q, q).sqrt();
        (r0..=r1).contains(&d).then_some(d)
    };
    for (i, q) in p.iter().enumerate() {
        if let Some(d) = within(*q) {
            best = best.max(vals[i] - k * d);
        }
    }
    for (a, b, va, vb) in f.edges() {
        for r in [r0, r1] {
            for t in circle_crossings(a, b, r) {
                best = best.max(va + t * (vb - va) - k * r);
            }
        }
        // The edge's critical point: the plane's rise along it equals the cone's.
        let e = sub(b, a);
        let len = dot(e, e).sqrt();
        if len > 0.0 && k > 0.0 {
            let u = [e[0] / len, e[1] / len];
            let t0 = -dot(a, u);
            let perp = cross(a, u).abs();
            let q = (vb - va) / len / k;
            if perp > 0.0 && q.abs() < 1.0 {
                let t = t0 + q * perp / (1.0 - q * q).sqrt();
                if (0.0..=len).contains(&t) {
                    let at = [a[0] + t * u[0], a[1] + t * u[1]];
                    if let Some(d) = within(at) {
                        best = best.max(va + (vb - va) * t / len - k * d);
                    }
                }
            }
        }
    }
    if let Some(u) = f.direction() {
        for r in [r0, r1] {
            if let Some(v) = f.inside([r * u[0], r * u[1]]) {
                best = best.max(v - k * r);
            }
        }
    } else {
        // Level: the inner circle is as high as the annulus gets, anywhere on it; a point of
        // it in the triangle, if any, is a corner or a crossing already — or the whole
        // triangle holds the circle, and its centre then lies inside too.
        if let Some(v) = f
            .inside([r0, 0.0])
            .filter(|_| f.inside([0.0, 0.0]).is_some())
        {
            best = best.max(v - k * r0);
        }
    }
    if r0 <= 0.0
        && let Some(v) = f.inside([0.0, 0.0])
    {
        best = best.max(v);
    }
    (best > f64::NEG_INFINITY).then_some(best)
}

impl HeightField {
    /// The highest the surface reaches over the disc of radius `r` about (x, y), exactly (see
    /// the module docs); `None` when no triangle meets the disc.
    pub fn max_in_disc(&self, x: f64, y: f64, r: f64) -> Option<f64> {
        let mut best: Option<f64> = None;
        for i in self.near(x, y, r) {
            let t = &self.triangles()[i];
            let p = t.corners.map(|c| [c.x - x, c.y - y]);
            if let Some(v) = max_over_disc(p, t.corners.map(|c| c.z), r) {
                best = Some(best.map_or(v, |b| b.max(v)));
            }
        }
        best
    }

    /// How far the surface reaches above the tilted disc of radius `r` about `centre`,
    /// spanned by the orthonormal `u` and `v`, measured vertically: the largest
    /// `h(x, y) − z` over the disc's points (x, y, z); `None` when no triangle lies under it
    /// or the disc stands on edge (`|u × v|` nearly horizontal: its footprint is a segment).
    pub fn max_above_disc(&self, centre: &Point3, u: &Vector3, v: &Vector3, r: f64) -> Option<f64> {
        // (x, y) − centre = M·(α, β), M = [u.xy v.xy]; det M is the axis' z.
        let det = u.x * v.y - v.x * u.y;
        if det.abs() < 1e-3 {
            return None;
        }
        let mut best: Option<f64> = None;
        for i in self.near(centre.x, centre.y, r) {
            let t = &self.triangles()[i];
            let ab = t.corners.map(|c| {
                let (dx, dy) = (c.x - centre.x, c.y - centre.y);
                [(v.y * dx - v.x * dy) / det, (u.x * dy - u.y * dx) / det]
            });
            let vals = [0, 1, 2].map(|k| {
                let [a, b] = ab[k];
                t.corners[k].z - (centre.z + a * u.z + b * v.z)
            });
            if let Some(h) = max_over_disc(ab, vals, r) {
                best = Some(best.map_or(h, |b| b.max(h)));
            }
        }
        best
    }

    /// The largest `h(x, y) − k·ρ` over the annulus `r0 ≤ ρ ≤ r1` about (x, y), ρ the
    /// distance from (x, y): how high the surface reaches above a cone whose underside rises
    /// `k` per mm from its axis, less the cone's height on its axis; `None` when no triangle
    /// meets the annulus. `floor` is a value the answer is only needed above: triangles that
    /// cannot beat it are skipped.
    pub fn max_over_cone(
        &self,
        x: f64,
        y: f64,
        r0: f64,
        r1: f64,
        k: f64,
        floor: f64,
    ) -> Option<f64> {
        let mut best: Option<f64> = None;
        for i in self.near(x, y, r1) {
            let t = &self.triangles()[i];
            let p = t.corners.map(|c| [c.x - x, c.y - y]);
            // Nearest the triangle's box gets to the axis: a bound of how low the cone is.
            let lo = [0, 1].map(|a| p.iter().map(|q| q[a]).fold(f64::MAX, f64::min));
            let hi = [0, 1].map(|a| p.iter().map(|q| q[a]).fold(f64::MIN, f64::max));
            let gap = [0, 1].map(|a| (lo[a].max(0.0) - hi[a].min(0.0)).max(0.0));
            let near = gap[0].hypot(gap[1]).max(r0);
            if near > r1 {
                continue;
            }
            let top = t.corners.iter().map(|c| c.z).fold(f64::MIN, f64::max);
            let bound = top - k * near;
            if bound < floor || best.is_some_and(|b| bound <= b) {
                continue;
            }
            if let Some(v) = max_over_cone(p, t.corners.map(|c| c.z), r0, r1, k) {
                best = Some(best.map_or(v, |b| b.max(v)));
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift64*).
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }

        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
    }

    /// The affine function's value at `q` when it lies in the triangle (edges included).
    fn value_at(p: [[f64; 2]; 3], vals: [f64; 3], q: [f64; 2]) -> Option<f64> {
        let e1 = sub(p[1], p[0]);
        let e2 = sub(p[2], p[0]);
        let det = cross(e1, e2);
        let w = sub(q, p[0]);
        let l1 = cross(w, e2) / det;
        let l2 = cross(e1, w) / det;
        (l1 >= -1e-12 && l2 >= -1e-12 && l1 + l2 <= 1.0 + 1e-12)
            .then(|| vals[0] + l1 * (vals[1] - vals[0]) + l2 * (vals[2] - vals[0]))
    }

    /// Dense samples of the disc of radius `r`: 100 rings of 200 angles (20 000 points) and
    /// the centre.
    fn disc_points(r0: f64, r: f64) -> Vec<[f64; 2]> {
        let mut out = vec![[0.0, 0.0]];
        for i in 0..=100 {
            let rr = r0 + (r - r0) * i as f64 / 100.0;
            for a in 0..200 {
                let t = std::f64::consts::TAU * a as f64 / 200.0;
                out.push([rr * t.cos(), rr * t.sin()]);
            }
        }
        out
    }

    /// Dense samples of the triangle `p`: a barycentric grid of 200 steps a side (20 301
    /// points).
    fn triangle_points(p: [[f64; 2]; 3]) -> Vec<[f64; 2]> {
        let n = 200;
        let mut out = Vec::new();
        for i in 0..=n {
            for j in 0..=n - i {
                let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
                let c = 1.0 - a - b;
                out.push([
                    a * p[0][0] + b * p[1][0] + c * p[2][0],
                    a * p[0][1] + b * p[1][1] + c * p[2][1],
                ]);
            }
        }
        out
    }

    #[test]
    fn the_exact_disc_maximum_bounds_dense_samples_and_is_reached_by_them() {
        // Random triangles under planes of slope at most √2, against 20 101 points of the disc
        // and 20 301 of the triangle: the exact maximum is never below a sample, and above the
        // best one by at most the samples' spacing times the slope.
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let r = 0.25;
        let disc = disc_points(0.0, r);
        let mut met = 0;
        for _ in 0..300 {
            let p = [0; 3].map(|_| [rng.range(-0.6, 0.6), rng.range(-0.6, 0.6)]);
            let (a, b, c) = (
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            let vals = p.map(|q| a * q[0] + b * q[1] + c);
            let exact = max_over_disc(p, vals, r);
            let dense = disc
                .iter()
                .copied()
                .chain(
                    triangle_points(p)
                        .into_iter()
                        .filter(|q| dot(*q, *q) <= r * r),
                )
                .filter_map(|q| value_at(p, vals, q))
                .fold(None, |b: Option<f64>, v| Some(b.map_or(v, |b| b.max(v))));
            match (exact, dense) {
                (Some(e), Some(d)) => {
                    met += 1;
                    assert!(e >= d - 1e-12, "{p:?} {vals:?}: exact {e} < dense {d}");
                    assert!(e - d < 0.01, "{p:?} {vals:?}: exact {e} ≫ dense {d}");
                }
                (Some(_), None) | (None, None) => {}
                (None, Some(d)) => panic!("{p:?} {vals:?}: missed, dense finds {d}"),
            }
        }
        assert!(met > 100, "{met}");
    }

    #[test]
    fn on_random_meshes_the_exact_query_matches_dense_sampling_of_the_disc() {
        // Height fields of random heights (slopes up to about 1) on a 0.2 mm grid, discs of
        // d_o = 0.5 mm at random places: 20 101 samples of the disc never find the surface
        // higher than the exact query, and find it as high to within their spacing.
        let mut rng = Rng(7);
        for _ in 0..4 {
            let n = 30;
            let h: Vec<f64> = (0..(n + 1) * (n + 1))
                .map(|_| rng.range(0.0, 0.1))
                .collect();
            let p = |i: usize, j: usize| {
                Point3::new(0.2 * i as f64, 0.2 * j as f64, h[j * (n + 1) + i])
            };
            let mut tris = Vec::new();
            for j in 0..n {
                for i in 0..n {
                    tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                    tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
                }
            }
            let surface = match crate::surface::Surface::from_triangles(tris) {
                Ok(s) => s,
                Err(e) => panic!("{e}"),
            };
            let field = surface.height_field();
            for _ in 0..25 {
                let (x, y) = (rng.range(0.5, 5.5), rng.range(0.5, 5.5));
                let exact = field.max_in_disc(x, y, 0.25).unwrap_or(f64::NAN);
                let dense = disc_points(0.0, 0.25)
                    .iter()
                    .filter_map(|q| surface.height(x + q[0], y + q[1]))
                    .fold(f64::MIN, f64::max);
                assert!(exact >= dense - 1e-12, "({x}, {y}): {exact} < {dense}");
                assert!(exact - dense < 0.005, "({x}, {y}): {exact} ≫ {dense}");
            }
        }
    }

    #[test]
    fn a_plane_over_a_disc_peaks_where_its_gradient_points() {
        // z = 2x + y over a triangle holding the disc: r·|∇| = 0.25·√5 above the centre.
        let p = [[-5.0, -5.0], [5.0, -5.0], [0.0, 5.0]];
        let vals = p.map(|q| 2.0 * q[0] + q[1]);
        let m = max_over_disc(p, vals, 0.25).unwrap_or(f64::NAN);
        assert!((m - 0.25 * 5f64.sqrt()).abs() < 1e-12, "{m}");
        // A cone rising 3 per mm on the same plane (slope √5 < 3): the inner circle's peak.
        let c = max_over_cone(p, vals, 0.25, 2.0, 3.0).unwrap_or(f64::NAN);
        assert!((c - 0.25 * (5f64.sqrt() - 3.0)).abs() < 1e-12, "{c}");
        // Rising 1 per mm (slower than the plane): the outer circle's.
        let c = max_over_cone(p, vals, 0.25, 2.0, 1.0).unwrap_or(f64::NAN);
        assert!((c - 2.0 * (5f64.sqrt() - 1.0)).abs() < 1e-12, "{c}");
    }

    #[test]
    fn the_exact_cone_maximum_bounds_dense_samples() {
        let mut rng = Rng(42);
        let (r0, r1) = (0.25, 1.5);
        let samples = disc_points(r0, r1);
        // Planes of slope up to √2, cones rising 0 to 3 per mm; the annulus and the triangle
        // sampled densely (the triangle to catch slivers).
        for _ in 0..200 {
            let p = [0; 3].map(|_| [rng.range(-2.0, 2.0), rng.range(-2.0, 2.0)]);
            let (a, b, c) = (
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            let vals = p.map(|q| a * q[0] + b * q[1] + c);
            let k = rng.range(0.0, 3.0);
            let exact = max_over_cone(p, vals, r0, r1, k);
            let dense = samples
                .iter()
                .copied()
                .chain(triangle_points(p))
                .filter(|q| (r0..=r1).contains(&dot(*q, *q).sqrt()))
                .filter_map(|q| value_at(p, vals, q).map(|v| v - k * dot(q, q).sqrt()))
                .fold(None, |b: Option<f64>, v| Some(b.map_or(v, |b| b.max(v))));
            if let Some(d) = dense {
                let e = exact.unwrap_or(f64::NEG_INFINITY);
                assert!(e >= d - 1e-9, "{p:?} {vals:?} {k}: exact {e} < dense {d}");
                assert!(e - d < 0.05, "{p:?} {vals:?} {k}: exact {e} ≫ dense {d}");
            }
        }
    }
}
