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
//!
//! # Where a disc meets the surface
//!
//! The corrections' escape wants a place, not a depth: the centroid of the part of the disc
//! where the surface reaches a level ([`HeightField::contact_in_disc`]). Over one triangle that
//! part is the triangle cut by the line where its plane crosses the level (a convex polygon)
//! and then by the circle; its area and first moment are exact sums over the polygon's edges
//! (Green's theorem): a piece of an edge inside the circle adds the triangle it spans with the
//! centre, a piece outside adds the circular sector between its ends' directions.

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

/// The part of the convex polygon `poly` (xy) where the affine function taking `vals` at its
/// corners is at least 0: a convex polygon (empty when the function is negative throughout).
fn clip_at_or_above(poly: &[[f64; 2]], vals: &[f64]) -> Vec<[f64; 2]> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for k in 0..poly.len() {
        let j = (k + 1) % poly.len();
        let (a, b, va, vb) = (poly[k], poly[j], vals[k], vals[j]);
        if va >= 0.0 {
            out.push(a);
        }
        if (va >= 0.0) != (vb >= 0.0) {
            let t = va / (va - vb);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    out
}

/// Area and first moment (∫x, ∫y) of the part of the convex polygon `poly` (corners relative
/// to the disc's centre, either winding) inside the disc of radius `r`, exactly (module docs).
pub fn polygon_in_disc(poly: &[[f64; 2]], r: f64) -> (f64, [f64; 2]) {
    let (mut area, mut mx, mut my) = (0.0, 0.0, 0.0);
    let r2 = r * r;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let mut cuts = [0.0, f64::NAN, f64::NAN, 1.0];
        for (slot, t) in circle_crossings(a, b, r).enumerate() {
            cuts[1 + slot] = t;
        }
        let mut ts: Vec<f64> = cuts.into_iter().filter(|t| !t.is_nan()).collect();
        ts.sort_by(f64::total_cmp);
        for w in ts.windows(2) {
            let at = |t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            let (p, q) = (at(w[0]), at(w[1]));
            // Inside when both ends are (crossings are on the circle to rounding); a line
            // grazing the circle, whose crossings rounding loses, is outside: its chord's
            // area is as small as its crossings are close.
            let within = |v: [f64; 2]| dot(v, v) <= r2 * (1.0 + 1e-9);
            if within(p) && within(q) {
                // The triangle (centre, p, q).
                let c = 0.5 * cross(p, q);
                area += c;
                mx += c * (p[0] + q[0]) / 3.0;
                my += c * (p[1] + q[1]) / 3.0;
            } else {
                // The sector from p's direction to q's.
                let t0 = p[1].atan2(p[0]);
                let t1 = t0 + cross(p, q).atan2(dot(p, q));
                area += 0.5 * r2 * (t1 - t0);
                mx += r2 * r / 3.0 * (t1.sin() - t0.sin());
                my += r2 * r / 3.0 * (t0.cos() - t1.cos());
            }
        }
    }
    // A clockwise polygon sums to the negative of both.
    if area < 0.0 {
        (-area, [-mx, -my])
    } else {
        (area, [mx, my])
    }
}

/// Where the surface reaches into a disc ([`HeightField::contact_in_disc`]): the part of the
/// disc under the surface, by its area and centroid, and the highest point of the surface
/// over the disc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscContact {
    /// Area of the part of the disc where the surface is at or above the level, mm².
    pub area: f64,
    /// Its centroid (x, y), mm; where it has no area (the surface touches the level along a
    /// ridge or at a peak), the centroid of the part within [`CONTACT_BAND`] of the highest
    /// point.
    pub centroid: [f64; 2],
    /// The highest the surface reaches over the disc, mm.
    pub highest: f64,
}

/// Depth below the surface's highest point over a disc that stands for a touch, mm (0.1 µm):
/// where the surface only touches the level (a ridge or a peak at the level, no area), the
/// contact's place is the centroid of the part of the disc within this of the highest point.
pub const CONTACT_BAND: f64 = 1e-7;

/// Areas below this are no area (the clipped polygons' rounding), mm².
const NO_AREA: f64 = 1e-18;

impl HeightField {
    /// Area and first moment of the part of the disc of radius `r` about (x, y) where the
    /// surface is at or above `level`, moments relative to (x, y).
    fn region_at_or_above(&self, x: f64, y: f64, r: f64, level: f64) -> (f64, [f64; 2]) {
        let (mut area, mut m) = (0.0, [0.0, 0.0]);
        for i in self.near(x, y, r) {
            let t = &self.triangles()[i];
            let p = t.corners.map(|c| [c.x - x, c.y - y]);
            let vals = t.corners.map(|c| c.z - level);
            if vals.iter().all(|&v| v < 0.0) {
                continue;
            }
            let part = clip_at_or_above(&p, &vals);
            if part.len() < 3 {
                continue;
            }
            let (a, mo) = polygon_in_disc(&part, r);
            area += a;
            m[0] += mo[0];
            m[1] += mo[1];
        }
        (area, m)
    }

    /// Where the surface meets the disc of radius `r` about (x, y) at `level`: `None` when the
    /// highest point of the surface over the disc is below `level` (exactly, as
    /// [`HeightField::max_in_disc`]), else the part of the disc under the surface by its area
    /// and centroid (module docs). Overlapping triangles (a scan folded over itself) each add
    /// their part.
    pub fn contact_in_disc(&self, x: f64, y: f64, r: f64, level: f64) -> Option<DiscContact> {
        let highest = self.max_in_disc(x, y, r).filter(|&h| h >= level)?;
        let (area, m) = self.region_at_or_above(x, y, r, level);
        let (band, mb) = if area > NO_AREA {
            (area, m)
        } else {
            self.region_at_or_above(x, y, r, highest - CONTACT_BAND)
        };
        let centroid = if band > NO_AREA {
            [x + mb[0] / band, y + mb[1] / band]
        } else {
            // Nothing measurable even within the band (a vertical sliver): the centre.
            [x, y]
        };
        Some(DiscContact {
            area: if area > NO_AREA { area } else { 0.0 },
            centroid,
            highest,
        })
    }

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

    /// A height field of random heights in [0, 0.1) mm on an n × n grid of 0.2 mm cells.
    fn random_surface(rng: &mut Rng, n: usize) -> crate::surface::Surface {
        let h: Vec<f64> = (0..(n + 1) * (n + 1))
            .map(|_| rng.range(0.0, 0.1))
            .collect();
        let p =
            |i: usize, j: usize| Point3::new(0.2 * i as f64, 0.2 * j as f64, h[j * (n + 1) + i]);
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        match crate::surface::Surface::from_triangles(tris) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn on_random_meshes_the_exact_query_matches_dense_sampling_of_the_disc() {
        // Height fields of random heights (slopes up to about 1) on a 0.2 mm grid, discs of
        // d_o = 0.5 mm at random places: 20 101 samples of the disc never find the surface
        // higher than the exact query, and find it as high to within their spacing.
        let mut rng = Rng(7);
        for _ in 0..4 {
            let surface = random_surface(&mut rng, 30);
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
    fn a_plane_cuts_the_disc_in_a_segment_of_exact_area_and_centroid() {
        // z = x over a triangle holding the disc, level c: the part x ≥ c of the disc of
        // radius r is a circular segment of half-angle α = acos(c/r), area r²(α − sin α cos α),
        // centroid at 2r sin³α / (3(α − sin α cos α)) along x.
        let p = [[-5.0, -5.0], [5.0, -5.0], [0.0, 5.0]];
        let r = 0.25;
        for c in [-0.2, -0.05, 0.0, 0.1, 0.24] {
            let vals = p.map(|q| q[0] - c);
            let part = clip_at_or_above(&p, &vals);
            let (area, m) = polygon_in_disc(&part, r);
            let alpha = (c / r).acos();
            let (sin, cos) = alpha.sin_cos();
            let exact = r * r * (alpha - sin * cos);
            let centroid = 2.0 * r * sin.powi(3) / (3.0 * (alpha - sin * cos));
            assert!((area - exact).abs() < 1e-14, "{c}: {area} {exact}");
            assert!((m[0] / area - centroid).abs() < 1e-12, "{c}: {m:?}");
            assert!((m[1] / area).abs() < 1e-12, "{c}: {m:?}");
        }
        // A triangle inside the disc is itself; either winding.
        let small = [[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]];
        for poly in [small.to_vec(), small.iter().rev().copied().collect()] {
            let (area, m) = polygon_in_disc(&poly, r);
            assert!((area - 0.005).abs() < 1e-15, "{area}");
            assert!((m[0] / area - 0.1 / 3.0).abs() < 1e-12, "{m:?}");
        }
        // The whole disc: πr², centroid at the centre.
        let (area, m) = polygon_in_disc(&p, r);
        assert!(
            (area - std::f64::consts::PI * r * r).abs() < 1e-14,
            "{area}"
        );
        assert!(m[0].abs() < 1e-14 && m[1].abs() < 1e-14, "{m:?}");
    }

    #[test]
    fn on_random_meshes_the_contact_region_matches_a_dense_grid_of_the_disc() {
        // Random height fields as above; the part of a 0.5 mm disc within 20 µm of the
        // surface's highest point over it, by the exact region and by a grid of 2.5 µm cells
        // (31 416 points in the disc).
        let mut rng = Rng(11);
        let surface = random_surface(&mut rng, 30);
        let field = surface.height_field();
        let (r, cell) = (0.25, 0.0025);
        for _ in 0..20 {
            let (x, y) = (rng.range(0.5, 5.5), rng.range(0.5, 5.5));
            let top = field.max_in_disc(x, y, r).unwrap_or(f64::NAN);
            let level = top - 0.02;
            let Some(c) = field.contact_in_disc(x, y, r, level) else {
                panic!("({x}, {y}): no contact 20 µm under the top");
            };
            assert_eq!(c.highest, top);
            assert!(field.contact_in_disc(x, y, r, top + 1e-9).is_none());
            let k = (r / cell) as i64;
            let (mut count, mut sx, mut sy) = (0.0, 0.0, 0.0);
            for i in -k..=k {
                for j in -k..=k {
                    let (dx, dy) = (i as f64 * cell, j as f64 * cell);
                    if dx.hypot(dy) <= r
                        && surface.height(x + dx, y + dy).is_some_and(|z| z >= level)
                    {
                        count += 1.0;
                        sx += dx;
                        sy += dy;
                    }
                }
            }
            let area = count * cell * cell;
            assert!(
                (c.area - area).abs() < 0.05 * c.area + 2e-4,
                "{} {area}",
                c.area
            );
            let (gx, gy) = (x + sx / count, y + sy / count);
            let off = (c.centroid[0] - gx).hypot(c.centroid[1] - gy);
            assert!(
                off < 0.005,
                "({x}, {y}): centroid {:?} grid ({gx}, {gy})",
                c.centroid
            );
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
