//! Reference markers found in a scan (`--refs-auto`): small drilled holes are small boundary
//! loops of the scanned mesh, and their area centroids are the reference points.
//!
//! Place in the pipeline: step 2, before [`super::register`]: the markers replace
//! `--refs-scan`, and the correspondence with the machine points is the assignment (of every
//! permutation) with the smallest registration residual.
//!
//! A boundary edge is used by one triangle only; boundary edges chain into loops. A loop whose
//! bounding box is at most `max_size` on its longest side is a marker; the outer rim of the
//! scan is far larger. The centroid is that of the loop's polygon area (the vector area's
//! weighting of a fan from the loop's first vertex), which for a round hole is its centre even
//! when its vertices are unevenly spaced.

use crate::geom::{Point3, Vector3};
use crate::mesh::Mesh;
use std::collections::BTreeMap;

/// A marker: a small hole of the scan.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Marker {
    /// Area centroid of the hole's rim, mm.
    pub centroid: [f64; 3],
    /// Longest side of the rim's bounding box, mm.
    pub size: f64,
    /// Vertices on the rim.
    pub vertices: usize,
}

/// The small boundary loops of `mesh` (longest bounding-box side ≤ `max_size`), sorted by x,
/// then y, then z of their centroids.
pub fn find_markers(mesh: &Mesh, max_size: f64) -> Vec<Marker> {
    // Directed edges; a boundary edge has no twin.
    let mut count: BTreeMap<(u32, u32), u32> = BTreeMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut next: BTreeMap<u32, u32> = BTreeMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if count.get(&(a.min(b), a.max(b))) == Some(&1) {
                next.insert(a, b);
            }
        }
    }
    let mut markers = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for &start in next.keys() {
        if seen.contains(&start) {
            continue;
        }
        let mut ring = vec![start];
        seen.insert(start);
        let mut cur = start;
        let closed = loop {
            let Some(&n) = next.get(&cur) else {
                break false;
            };
            if n == start {
                break true;
            }
            if !seen.insert(n) || ring.len() > next.len() {
                break false;
            }
            ring.push(n);
            cur = n;
        };
        if !closed || ring.len() < 3 {
            continue;
        }
        let pts: Vec<Point3> = ring
            .iter()
            .filter_map(|&i| mesh.vertices.get(i as usize).copied())
            .collect();
        if pts.len() != ring.len() {
            continue;
        }
        let (mut lo, mut hi) = (pts[0], pts[0]);
        for p in &pts {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let size = (hi - lo).max();
        if size > max_size {
            continue;
        }
        markers.push(Marker {
            centroid: area_centroid(&pts),
            size,
            vertices: pts.len(),
        });
    }
    markers.sort_by(|a, b| {
        a.centroid
            .partial_cmp(&b.centroid)
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    markers
}

/// Area centroid of a closed 3D polygon: fan triangles from the first vertex, each weighted by
/// its vector area projected on the polygon's mean normal.
fn area_centroid(pts: &[Point3]) -> [f64; 3] {
    let o = pts[0];
    let mut normal = Vector3::zeros();
    for w in pts.windows(2).skip(1) {
        normal += (w[0] - o).cross(&(w[1] - o));
    }
    let n = normal.try_normalize(1e-18).unwrap_or_else(Vector3::z);
    let (mut sum, mut total) = (Vector3::zeros(), 0.0);
    for w in pts.windows(2).skip(1) {
        let a = (w[0] - o).cross(&(w[1] - o)).dot(&n) / 2.0;
        sum += (o.coords + w[0].coords + w[1].coords) / 3.0 * a;
        total += a;
    }
    let c = if total.abs() > 1e-18 {
        sum / total
    } else {
        pts.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / pts.len() as f64
    };
    [c.x, c.y, c.z]
}
