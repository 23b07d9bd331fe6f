//! The model's top surface as a height field: at (x, y), the highest z of the mesh and the slope
//! of the triangle there.
//!
//! Place in the pipeline: built once per object from the placed mesh, before the regions stage;
//! the curved tops (`crate::curved::tops`) find the gently sloped top regions with it and projects the flat top layers
//! onto it.
//!
//! # Method
//!
//! The upward-facing triangles (normal z > 0) are put in a uniform 2D grid over their xy
//! bounding boxes. A query tests the triangles of one cell with barycentric coordinates and
//! evaluates the plane of each triangle that contains the point; the highest wins. This is
//! exact to floating-point rounding on the mesh's own triangles (the plane equation, no
//! interpolation between samples) — what the tests compare paths against — deterministic, and
//! needs no dependency. A downward ray cast (parry3d) would answer the same question but would
//! add a crate for one query type, and [`HeightField::edge_crossings`] needs the triangles'
//! edges anyway.

use crate::geom::Point3;
use crate::mesh::Mesh;

/// One upward-facing triangle, xy corners and plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceTriangle {
    /// Corners, mm.
    pub corners: [Point3; 3],
    /// Unit normal (z > 0).
    pub normal: [f64; 3],
}

impl SurfaceTriangle {
    /// Slope from the horizontal, degrees.
    pub fn slope_deg(&self) -> f64 {
        self.normal[2].clamp(-1.0, 1.0).acos().to_degrees()
    }

    /// The plane's z at (x, y).
    pub fn z_at(&self, x: f64, y: f64) -> f64 {
        let a = self.corners[0];
        let n = self.normal;
        a.z - (n[0] * (x - a.x) + n[1] * (y - a.y)) / n[2]
    }

    /// Whether (x, y) lies in the triangle's xy projection (edges included, with a tolerance
    /// of `eps` in barycentric units).
    fn contains(&self, x: f64, y: f64, eps: f64) -> bool {
        let [a, b, c] = self.corners;
        let d = (b.y - c.y) * (a.x - c.x) + (c.x - b.x) * (a.y - c.y);
        if d == 0.0 {
            return false;
        }
        let l1 = ((b.y - c.y) * (x - c.x) + (c.x - b.x) * (y - c.y)) / d;
        let l2 = ((c.y - a.y) * (x - c.x) + (a.x - c.x) * (y - c.y)) / d;
        let l3 = 1.0 - l1 - l2;
        l1 >= -eps && l2 >= -eps && l3 >= -eps
    }

    /// Centroid, mm.
    pub fn centroid(&self) -> Point3 {
        let [a, b, c] = self.corners;
        Point3::new(
            (a.x + b.x + c.x) / 3.0,
            (a.y + b.y + c.y) / 3.0,
            (a.z + b.z + c.z) / 3.0,
        )
    }
}

/// What [`HeightField::at`] finds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceHit {
    /// Highest mesh z at the point, mm.
    pub z: f64,
    /// Index of the triangle (in [`HeightField::triangles`]) that gives it.
    pub triangle: usize,
    /// Unit normal of that triangle.
    pub normal: [f64; 3],
    /// Its slope from the horizontal, degrees.
    pub slope_deg: f64,
}

/// Barycentric tolerance of the containment test: points on a shared edge are found in both
/// triangles despite rounding (the planes agree there, so either answer is exact).
const EDGE_EPS: f64 = 1e-9;

/// The top surface of one mesh (see the module docs).
#[derive(Debug, Clone)]
pub struct HeightField {
    triangles: Vec<SurfaceTriangle>,
    origin: [f64; 2],
    cell: f64,
    dims: [usize; 2],
    cells: Vec<Vec<u32>>,
}

impl HeightField {
    /// The height field of the upward-facing triangles of `mesh` (degenerate and vertical
    /// triangles and indices out of range are skipped).
    pub fn from_mesh(mesh: &Mesh) -> Self {
        let mut triangles = Vec::new();
        for t in &mesh.triangles {
            let Some(c) = t
                .iter()
                .map(|&i| mesh.vertices.get(i as usize).copied())
                .collect::<Option<Vec<Point3>>>()
            else {
                continue;
            };
            let n = (c[1] - c[0]).cross(&(c[2] - c[0]));
            let len = n.norm();
            if !(len.is_finite() && len > 0.0) || n.z / len < 1e-6 {
                continue;
            }
            triangles.push(SurfaceTriangle {
                corners: [c[0], c[1], c[2]],
                normal: [n.x / len, n.y / len, n.z / len],
            });
        }
        Self::from_triangles(triangles)
    }

    fn from_triangles(triangles: Vec<SurfaceTriangle>) -> Self {
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for t in &triangles {
            for p in t.corners {
                lo = [lo[0].min(p.x), lo[1].min(p.y)];
                hi = [hi[0].max(p.x), hi[1].max(p.y)];
            }
        }
        if triangles.is_empty() {
            return Self {
                triangles,
                origin: [0.0; 2],
                cell: 1.0,
                dims: [0, 0],
                cells: Vec::new(),
            };
        }
        let (w, h) = ((hi[0] - lo[0]).max(1e-6), (hi[1] - lo[1]).max(1e-6));
        // About two triangles per cell, and never more cells than four per triangle.
        let cell = ((w * h) / (triangles.len() as f64 / 2.0)).sqrt().max(0.05);
        let dims = [
            ((w / cell).ceil() as usize).clamp(1, 4096),
            ((h / cell).ceil() as usize).clamp(1, 4096),
        ];
        let cell = (w / dims[0] as f64).max(h / dims[1] as f64);
        let mut field = Self {
            triangles,
            origin: lo,
            cell,
            dims,
            cells: vec![Vec::new(); dims[0] * dims[1]],
        };
        for (i, t) in field.triangles.iter().enumerate() {
            let xs = t.corners.map(|p| p.x);
            let ys = t.corners.map(|p| p.y);
            let (x0, x1) = (
                xs.iter().copied().fold(f64::MAX, f64::min),
                xs.iter().copied().fold(f64::MIN, f64::max),
            );
            let (y0, y1) = (
                ys.iter().copied().fold(f64::MAX, f64::min),
                ys.iter().copied().fold(f64::MIN, f64::max),
            );
            let (cx0, cy0) = field.cell_of(x0, y0);
            let (cx1, cy1) = field.cell_of(x1, y1);
            for cy in cy0..=cy1 {
                for cx in cx0..=cx1 {
                    field.cells[cy * dims[0] + cx].push(i as u32);
                }
            }
        }
        field
    }

    fn cell_of(&self, x: f64, y: f64) -> (usize, usize) {
        let fx = ((x - self.origin[0]) / self.cell).floor();
        let fy = ((y - self.origin[1]) / self.cell).floor();
        let clamp = |f: f64, n: usize| {
            if f.is_finite() {
                (f.max(0.0) as usize).min(n.saturating_sub(1))
            } else {
                0
            }
        };
        (clamp(fx, self.dims[0]), clamp(fy, self.dims[1]))
    }

    /// Indices of the triangles filed in the grid cells the square of half-side `r` about
    /// (x, y) overlaps, ascending, each once (empty when the square is off the grid).
    pub fn near(&self, x: f64, y: f64, r: f64) -> Vec<usize> {
        let ext = [
            self.origin[0] + self.cell * self.dims[0] as f64,
            self.origin[1] + self.cell * self.dims[1] as f64,
        ];
        if self.cells.is_empty()
            || !(x.is_finite() && y.is_finite() && r.is_finite())
            || x + r < self.origin[0]
            || y + r < self.origin[1]
            || x - r > ext[0]
            || y - r > ext[1]
        {
            return Vec::new();
        }
        let (cx0, cy0) = self.cell_of(x - r, y - r);
        let (cx1, cy1) = self.cell_of(x + r, y + r);
        let mut out = Vec::new();
        for cy in cy0..=cy1 {
            for cx in cx0..=cx1 {
                out.extend(
                    self.cells[cy * self.dims[0] + cx]
                        .iter()
                        .map(|&i| i as usize),
                );
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The upward-facing triangles.
    pub fn triangles(&self) -> &[SurfaceTriangle] {
        &self.triangles
    }

    /// The highest mesh point above or below (x, y) and its triangle; `None` where no
    /// upward-facing triangle covers the point.
    pub fn at(&self, x: f64, y: f64) -> Option<SurfaceHit> {
        if self.cells.is_empty() || !x.is_finite() || !y.is_finite() {
            return None;
        }
        let (cx, cy) = self.cell_of(x, y);
        let mut best: Option<SurfaceHit> = None;
        for &i in &self.cells[cy * self.dims[0] + cx] {
            let t = &self.triangles[i as usize];
            if !t.contains(x, y, EDGE_EPS) {
                continue;
            }
            let z = t.z_at(x, y);
            // Ties (shared edges) go to the lower index so the answer does not depend on order.
            if best.is_none_or(|b| z > b.z) {
                best = Some(SurfaceHit {
                    z,
                    triangle: i as usize,
                    normal: t.normal,
                    slope_deg: t.slope_deg(),
                });
            }
        }
        best
    }

    /// Parameters `t` in (0, 1), ascending and without repeats, where the segment from `a` to
    /// `b` (xy, mm) crosses an edge of a surface triangle near it. Between two consecutive
    /// crossings the segment stays inside one triangle, where the surface is a plane.
    pub fn edge_crossings(&self, a: (f64, f64), b: (f64, f64)) -> Vec<f64> {
        let mut ts = Vec::new();
        if self.cells.is_empty() {
            return ts;
        }
        let (cx0, cy0) = self.cell_of(a.0.min(b.0), a.1.min(b.1));
        let (cx1, cy1) = self.cell_of(a.0.max(b.0), a.1.max(b.1));
        let mut seen: Vec<u32> = Vec::new();
        for cy in cy0..=cy1 {
            for cx in cx0..=cx1 {
                seen.extend_from_slice(&self.cells[cy * self.dims[0] + cx]);
            }
        }
        seen.sort_unstable();
        seen.dedup();
        let d = (b.0 - a.0, b.1 - a.1);
        for &i in &seen {
            let c = self.triangles[i as usize].corners;
            for k in 0..3 {
                let (p, q) = (c[k], c[(k + 1) % 3]);
                let e = (q.x - p.x, q.y - p.y);
                let den = d.0 * e.1 - d.1 * e.0;
                if den.abs() < 1e-18 {
                    continue;
                }
                let w = (p.x - a.0, p.y - a.1);
                let t = (w.0 * e.1 - w.1 * e.0) / den;
                let u = (w.0 * d.1 - w.1 * d.0) / den;
                if t > 1e-9 && t < 1.0 - 1e-9 && (-1e-12..=1.0 + 1e-12).contains(&u) {
                    ts.push(t);
                }
            }
        }
        ts.sort_by(f64::total_cmp);
        // Crossings closer than a nanometre along the segment are one point.
        let len = d.0.hypot(d.1).max(1e-12);
        ts.dedup_by(|x, y| (*x - *y) * len < 1e-6);
        ts
    }
}

/// The points of the flat path `path` (xy, mm) with the points where it crosses a surface's
/// triangle edges and subdivisions to at most `step` mm inserted, so that each segment lies over
/// one triangle and a path lifted onto the surface stays on it; `crossings(a, b)` gives the
/// parameters in (0, 1), ascending, where the segment `a`–`b` crosses a triangle edge. A closed
/// path's closing segment is densified too and its first point is not repeated at the end.
pub fn densify_path(
    path: &[(f64, f64)],
    closed: bool,
    step: f64,
    crossings: &dyn Fn((f64, f64), (f64, f64)) -> Vec<f64>,
) -> Vec<(f64, f64)> {
    let n = path.len();
    let mut out = Vec::with_capacity(n * 4);
    if n == 0 {
        return out;
    }
    let segments = if closed { n } else { n - 1 };
    for i in 0..segments {
        let (a, b) = (path[i], path[(i + 1) % n]);
        out.push(a);
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        if !(len.is_finite() && len > 0.0) {
            continue;
        }
        let mut ts = vec![0.0];
        ts.extend(crossings(a, b));
        ts.push(1.0);
        for w in ts.windows(2) {
            let pieces = ((w[1] - w[0]) * len / step).ceil().max(1.0) as usize;
            for k in 1..=pieces {
                if k == pieces && w[1] >= 1.0 {
                    break;
                }
                let t = w[0] + (w[1] - w[0]) * k as f64 / pieces as f64;
                out.push((a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t));
            }
        }
    }
    if !closed {
        out.push(path[n - 1]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of `n × n` cells over `[0, size]²` with z = f(x, y), two triangles per cell,
    /// counter-clockwise from above.
    fn grid_surface(n: usize, size: f64, f: impl Fn(f64, f64) -> f64) -> Mesh {
        let step = size / n as f64;
        let mut tris = Vec::new();
        let p = |i: usize, j: usize| {
            let (x, y) = (i as f64 * step, j as f64 * step);
            Point3::new(x, y, f(x, y))
        };
        for i in 0..n {
            for j in 0..n {
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        Mesh::from_triangle_soup("surface", tris)
    }

    #[test]
    fn tilted_plane_heights_and_slope_are_exact() {
        let f = |x: f64, y: f64| 2.0 + 0.1 * x + 0.05 * y;
        let hf = HeightField::from_mesh(&grid_surface(7, 20.0, f));
        let slope = (0.1f64.hypot(0.05)).atan().to_degrees();
        for &(x, y) in &[
            (0.0, 0.0),
            (3.3, 17.1),
            (10.0, 10.0),
            (19.99, 0.01),
            (20.0, 20.0),
        ] {
            let hit = hit_at(&hf, x, y);
            assert!(
                (hit.z - f(x, y)).abs() < 1e-9,
                "{x} {y}: {} vs {}",
                hit.z,
                f(x, y)
            );
            assert!((hit.slope_deg - slope).abs() < 1e-9);
        }
        assert!(hf.at(-0.5, 3.0).is_none());
    }

    fn hit_at(hf: &HeightField, x: f64, y: f64) -> SurfaceHit {
        match hf.at(x, y) {
            Some(h) => h,
            None => panic!("no surface at {x} {y}"),
        }
    }

    #[test]
    fn sphere_cap_matches_the_sphere_at_vertices_and_the_chord_plane_between() {
        let r: f64 = 40.0;
        let f = |x: f64, y: f64| {
            let (dx, dy) = (x - 10.0, y - 10.0);
            (r * r - dx * dx - dy * dy).sqrt() - r + 5.0
        };
        let n = 16;
        let hf = HeightField::from_mesh(&grid_surface(n, 20.0, f));
        let step = 20.0 / n as f64;
        let mut worst: f64 = 0.0;
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (i as f64 * step, j as f64 * step);
                assert!((hit_at(&hf, x, y).z - f(x, y)).abs() < 1e-9);
            }
        }
        // Between vertices the triangles are chords of the sphere: below it by about the
        // sagitta of a cell diagonal, d²/(8r), measured vertically (up to 1/cos 21° more at the
        // cap's corners, plus higher-order terms).
        for i in 0..40 {
            for j in 0..40 {
                let (x, y) = (0.25 + i as f64 * 0.49, 0.25 + j as f64 * 0.49);
                let d = f(x, y) - hit_at(&hf, x, y).z;
                assert!(d >= -1e-9, "{x} {y}: above the sphere by {}", -d);
                worst = worst.max(d);
            }
        }
        let diag = step * 2f64.sqrt();
        assert!(
            worst > 0.0 && worst <= diag * diag / (8.0 * r) * 1.25,
            "{worst}"
        );
        // The slope at the rim of the cap matches the sphere's tangent to within a cell.
        let hit = hit_at(&hf, 19.5, 10.2);
        let analytic = ((9.5f64).hypot(0.2) / r).asin().to_degrees();
        assert!(
            (hit.slope_deg - analytic).abs() < 1.5,
            "{} vs {analytic}",
            hit.slope_deg
        );
    }

    #[test]
    fn edge_crossings_split_a_segment_into_single_triangle_pieces() {
        let f = |x: f64, y: f64| 0.1 * x * x / 20.0 + 0.02 * y;
        let hf = HeightField::from_mesh(&grid_surface(5, 20.0, f));
        let (a, b) = ((0.3, 1.1), (17.7, 13.4));
        let mut ts = vec![0.0];
        ts.extend(hf.edge_crossings(a, b));
        ts.push(1.0);
        assert!(ts.len() > 8, "{ts:?}");
        for w in ts.windows(2) {
            let mid = (w[0] + w[1]) / 2.0;
            let p = |t: f64| (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
            let (pa, pb, pm) = (p(w[0]), p(w[1]), p(mid));
            let (za, zb, zm) = (
                hit_at(&hf, pa.0, pa.1).z,
                hit_at(&hf, pb.0, pb.1).z,
                hit_at(&hf, pm.0, pm.1).z,
            );
            assert!(
                ((za + zb) / 2.0 - zm).abs() < 1e-9,
                "not planar between {w:?}"
            );
        }
    }
}
