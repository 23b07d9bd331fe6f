//! Reference markers found in a scan (`--refs-auto`): small drilled holes are small boundary
//! loops of the scanned mesh, and their area centroids are the reference points.
//!
//! Place in the pipeline: step 2, before [`super::register`]: the markers replace
//! `--refs-scan`, and the correspondence with the machine points is the assignment (of every
//! permutation) with the smallest registration residual.
//!
//! A boundary edge is used by one triangle only; boundary edges chain into loops, one per hole
//! even where holes touch at a vertex. A loop whose bounding box is at most `max_size` on its
//! longest side is a marker; the outer rim of the scan is far larger. The centroid is that of
//! the loop's polygon area (the vector area's weighting of a fan from the loop's first
//! vertex), which for a round hole is its centre even when its vertices are unevenly spaced.

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
    let mut markers: Vec<Marker> = boundary_loops(mesh)
        .into_iter()
        .filter_map(|ring| {
            let pts: Vec<Point3> = ring
                .iter()
                .filter_map(|&i| mesh.vertices.get(i as usize).copied())
                .collect();
            if pts.len() != ring.len() || pts.len() < 3 {
                return None;
            }
            let (mut lo, mut hi) = (pts[0], pts[0]);
            for p in &pts {
                lo = lo.inf(p);
                hi = hi.sup(p);
            }
            let size = (hi - lo).max();
            (size <= max_size).then(|| Marker {
                centroid: area_centroid(&pts),
                size,
                vertices: pts.len(),
            })
        })
        .collect();
    markers.sort_by(|a, b| {
        a.centroid
            .partial_cmp(&b.centroid)
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    markers
}

/// The closed loops of boundary edges (edges of one triangle only), as vertex indices.
///
/// Each boundary edge is used once, in its triangle's direction, so a hole's rim runs with the
/// hole on its right (seen from the side the triangles face). Where two holes touch at a vertex
/// (or a hole touches the rim), two boundary edges leave it; the loop takes the one turning
/// furthest right, which stays on the rim of the same hole: each hole is traced on its own
/// instead of two being joined into a figure of eight (or one of them lost).
fn boundary_loops(mesh: &Mesh) -> Vec<Vec<u32>> {
    let mut uses: BTreeMap<(u32, u32), u32> = BTreeMap::new();
    // The triangle of each directed edge, for the side the surface faces there.
    let mut owner: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for (ti, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            owner.insert((a, b), ti);
        }
    }
    let mut leaving: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for &(a, b) in owner.keys() {
        if uses.get(&(a.min(b), a.max(b))) == Some(&1) {
            leaving.entry(a).or_default().push(b);
        }
    }
    let at = |i: u32| mesh.vertices.get(i as usize).copied();
    let facing = |edge: (u32, u32)| -> Option<Vector3> {
        let t = mesh.triangles.get(*owner.get(&edge)?)?;
        let (a, b, c) = (at(t[0])?, at(t[1])?, at(t[2])?);
        (b - a).cross(&(c - a)).try_normalize(1e-18)
    };
    // How far the path u → v → w turns left about `n`, radians (negative: right).
    let turn = |u: u32, v: u32, w: u32, n: &Vector3| -> f64 {
        match (at(u), at(v), at(w)) {
            (Some(a), Some(b), Some(c)) => {
                let (i, o) = (b - a, c - b);
                i.cross(&o).dot(n).atan2(i.dot(&o))
            }
            _ => 0.0,
        }
    };
    let mut used = std::collections::BTreeSet::new();
    let mut loops = Vec::new();
    for (&start, outs) in &leaving {
        for &second in outs {
            let first = (start, second);
            if used.contains(&first) {
                continue;
            }
            let mut ring = Vec::new();
            let mut edge = first;
            let closed = loop {
                if !used.insert(edge) {
                    break false;
                }
                ring.push(edge.0);
                let (u, v) = edge;
                let n = facing(edge).unwrap_or_else(Vector3::z);
                let next = leaving
                    .get(&v)
                    .into_iter()
                    .flatten()
                    .copied()
                    .filter(|&w| (v, w) == first || !used.contains(&(v, w)))
                    .min_by(|&a, &b| turn(u, v, a, &n).total_cmp(&turn(u, v, b, &n)));
                match next {
                    Some(w) if (v, w) == first => break true,
                    Some(w) => edge = (v, w),
                    None => break false,
                }
            };
            if closed {
                loops.push(ring);
            }
        }
    }
    loops
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

/// Most markers tried in every assignment to the machine points (8·7·6 = 336 for three).
pub const MAX_MARKERS: usize = 8;

/// Why the markers could not be registered to the machine points.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MarkerError {
    /// Fewer markers than machine points.
    ///
    /// How to fix: raise `conform.marker_max_size` if the holes are larger.
    #[error(
        "found {found} marker hole(s), {needed} needed (raise conform.marker_max_size if the \
         holes are larger)"
    )]
    TooFew {
        /// Markers found.
        found: usize,
        /// Machine points given.
        needed: usize,
    },
    /// More small holes than [`MAX_MARKERS`]: the assignment would take too long.
    ///
    /// How to fix: lower `conform.marker_max_size` or repair the scan's other holes.
    #[error(
        "found {found} small holes, more than {MAX_MARKERS}: lower conform.marker_max_size or \
         repair the scan's other holes"
    )]
    TooMany {
        /// Holes found.
        found: usize,
    },
    /// No choice of markers gives a registration.
    #[error("the markers are collinear")]
    Collinear,
}

/// The registration of `markers` to the `machine` points in the assignment with the smallest
/// residual (every ordered choice of markers is tried).
pub fn auto_register(
    markers: &[Marker],
    machine: &[Point3],
) -> Result<super::Registration, MarkerError> {
    let n = machine.len();
    if markers.len() < n {
        return Err(MarkerError::TooFew {
            found: markers.len(),
            needed: n,
        });
    }
    if markers.len() > MAX_MARKERS {
        return Err(MarkerError::TooMany {
            found: markers.len(),
        });
    }
    let pts: Vec<Point3> = markers
        .iter()
        .map(|m| Point3::new(m.centroid[0], m.centroid[1], m.centroid[2]))
        .collect();
    let mut best: Option<super::Registration> = None;
    let mut chosen = Vec::with_capacity(n);
    permute(pts.len(), n, &mut chosen, &mut |idx| {
        let scan: Vec<Point3> = idx.iter().map(|&i| pts[i]).collect();
        if let Ok(r) = super::register::least_squares(&scan, machine)
            && best.as_ref().is_none_or(|b| r.rms < b.rms)
        {
            best = Some(r);
        }
    });
    best.ok_or(MarkerError::Collinear)
}

/// Calls `f` with every ordered choice of `k` of `0..n`, in lexicographic order.
fn permute(n: usize, k: usize, chosen: &mut Vec<usize>, f: &mut impl FnMut(&[usize])) {
    if chosen.len() == k {
        f(chosen);
        return;
    }
    for i in 0..n {
        if !chosen.contains(&i) {
            chosen.push(i);
            permute(n, k, chosen, f);
            chosen.pop();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 6 × 6 plate of unit squares (two triangles each) without the squares in `holes`.
    fn plate(holes: &[[usize; 2]]) -> Mesh {
        let p = |i: usize, j: usize| Point3::new(i as f64, j as f64, 0.0);
        let mut tris = Vec::new();
        for j in 0..6 {
            for i in 0..6 {
                if holes.contains(&[i, j]) {
                    continue;
                }
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        Mesh::from_triangle_soup("plate", tris)
    }

    #[test]
    fn two_holes_touching_at_a_corner_are_two_markers() {
        // Squares (2, 2) and (3, 3) share the vertex (3, 3): each is a hole of its own.
        let markers = find_markers(&plate(&[[2, 2], [3, 3]]), 1.5);
        let centres: Vec<[f64; 3]> = markers.iter().map(|m| m.centroid).collect();
        assert_eq!(
            centres,
            vec![[2.5, 2.5, 0.0], [3.5, 3.5, 0.0]],
            "{markers:?}"
        );
        assert!(markers.iter().all(|m| m.vertices == 4 && m.size == 1.0));
    }

    #[test]
    fn a_hole_and_the_rim_are_separate_loops() {
        // One square hole in the middle; the plate's rim is the other, larger loop.
        let mesh = plate(&[[2, 3]]);
        let loops = boundary_loops(&mesh);
        let mut sizes: Vec<usize> = loops.iter().map(Vec::len).collect();
        sizes.sort_unstable();
        assert_eq!(sizes, vec![4, 24]);
        let markers = find_markers(&mesh, 1.5);
        assert_eq!(markers.len(), 1);
        assert_eq!(markers[0].centroid, [2.5, 3.5, 0.0]);
    }
}
