//! Planar slicing: a placed mesh → one set of islands (ExPolygons) per layer.
//!
//! The method is libslic3r's `TriangleMeshSlicer`:
//!
//! 1. **Bucket** the triangles by the layers whose slicing plane their z-range crosses (two binary
//!    searches per triangle), so each layer only looks at its own triangles.
//! 2. **Cut** each crossing triangle with the plane `z = slice_z` into a directed segment. A vertex
//!    lying exactly on the plane counts as *above* it (symbolic perturbation `z + ε`): every
//!    vertex is then strictly on one side, a crossing triangle cuts exactly two of its edges, no
//!    horizontal face is ever cut and no segment is counted twice. The segment runs from the edge
//!    the triangle's boundary crosses going down to the edge it crosses going up, which for
//!    outward-facing triangles (counter-clockwise seen from outside) leaves the solid on its left:
//!    outer contours come out counter-clockwise, holes clockwise. An edge's crossing point is
//!    computed from its vertices in index order, so both triangles sharing the edge get the same
//!    bits; it is snapped to the nanometre grid here, once, as the contour leaves the mesh.
//! 3. **Chain** the segments into loops by the mesh edges they start and end on (exact, no
//!    coordinates involved), then join what stays open across gaps of up to
//!    [`DEFAULT_MAX_GAP_MM`]: exact coincidences first, then same direction before reversed,
//!    nearest first (the private `chain` module has the details).
//! 4. **Fill**: the loops become ExPolygons with [`FillRule::Positive`]: counter-clockwise loops
//!    add, clockwise loops subtract. This is PrusaSlicer's "union with positive fill after fixing
//!    orientation": overlapping shells of a multi-body file merge, intended cavities stay holes,
//!    and a hole loop that leaks outside its shell (a broken mesh) adds nothing instead of adding
//!    material as `NonZero` would. Orientation is fixed per mesh beforehand: a mesh with negative
//!    signed volume (inside out) is sliced with its segments reversed.
//!
//! Layers are sliced in parallel with rayon; the output is in layer order and each layer's
//! islands are in [`crate::geom`]'s canonical order, so results are identical run to run.

use super::chain::{Segment, chain_segments};
use super::schedule::{LayerZ, SliceParams, layer_schedule};
use crate::geom::{ExPolygon, FillRule, Point2, Point3, polygons_to_expolygons, scaled};
use crate::mesh::Mesh;
use rayon::prelude::*;
use serde::Serialize;

/// Default for the largest gap (mm) an open slice chain is closed across: PrusaSlicer's
/// `max_gap` in `TriangleMeshSlicer::make_loops` (2 mm), about two to five line widths. A mesh
/// hole wider than this in some layer loses that contour (counted in
/// [`SliceReport::open_chains_dropped`]); repair the mesh first.
pub const DEFAULT_MAX_GAP_MM: f64 = 2.0;

/// One sliced layer.
#[derive(Debug, Clone, PartialEq)]
pub struct SlicedLayer {
    /// Where the layer is.
    pub z: LayerZ,
    /// The solid regions of the layer: outer contours counter-clockwise, holes clockwise.
    pub islands: Vec<ExPolygon>,
}

/// What slicing did, summed over all layers.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct SliceReport {
    /// Number of layers produced.
    pub layers: usize,
    /// Open chains (from holes, flipped or non-manifold parts of the mesh) that were joined into
    /// closed contours across a gap of at most the maximum gap. Zero for a watertight,
    /// consistently oriented mesh.
    pub open_chains_closed: usize,
    /// Open chains that could not be closed and were dropped.
    pub open_chains_dropped: usize,
    /// Segments shorter than the nanometre grid (both ends snap to one point) although the
    /// triangle does not touch the plane at a vertex: the triangle only grazes the plane (a vertex
    /// within a nanometre of it, common with `f32` STL coordinates) or is a needle. They keep the
    /// chaining intact and leave no trace in the output; informational only.
    pub degenerate_segments: usize,
}

/// Slices `mesh` (already placed: everything at z ≥ 0 is printed) into the layers of
/// [`layer_schedule`] from z = 0 up to the top of the mesh, closing open chains across gaps of
/// up to [`DEFAULT_MAX_GAP_MM`]. Invalid `params` give no layers (check them with
/// [`SliceParams::validate`] first).
pub fn slice_mesh(mesh: &Mesh, params: &SliceParams) -> (Vec<SlicedLayer>, SliceReport) {
    slice_mesh_with_gap(mesh, params, DEFAULT_MAX_GAP_MM)
}

/// [`slice_mesh`] with an explicit largest gap (mm) across which open chains are closed.
pub fn slice_mesh_with_gap(
    mesh: &Mesh,
    params: &SliceParams,
    max_gap_mm: f64,
) -> (Vec<SlicedLayer>, SliceReport) {
    let Some(bb) = mesh.bounding_box() else {
        return (Vec::new(), SliceReport::default());
    };
    let schedule = layer_schedule(bb.max[2], params);
    let planes: Vec<f64> = schedule.iter().map(|l| l.slice_z).collect();
    let buckets = Buckets::new(mesh, &planes);
    let flip = mesh.signed_volume() < 0.0;
    let max_gap = scaled(max_gap_mm.max(0.0));

    let per_layer: Vec<(SlicedLayer, SliceReport)> = schedule
        .par_iter()
        .map(|&z| {
            let tris = buckets.layer(z.index);
            let (segments, degenerate) = cut_triangles(mesh, tris, z.slice_z, flip);
            let loops = chain_segments(&segments, max_gap);
            let islands = polygons_to_expolygons(&loops.polygons, FillRule::Positive);
            let report = SliceReport {
                layers: 1,
                open_chains_closed: loops.closed,
                open_chains_dropped: loops.dropped,
                degenerate_segments: degenerate,
            };
            (SlicedLayer { z, islands }, report)
        })
        .collect();

    let mut report = SliceReport::default();
    let mut layers = Vec::with_capacity(per_layer.len());
    for (layer, r) in per_layer {
        report.layers += r.layers;
        report.open_chains_closed += r.open_chains_closed;
        report.open_chains_dropped += r.open_chains_dropped;
        report.degenerate_segments += r.degenerate_segments;
        layers.push(layer);
    }
    (layers, report)
}

/// Triangle indices per layer, in triangle order, stored flat (CSR).
struct Buckets {
    offsets: Vec<usize>,
    triangles: Vec<u32>,
}

impl Buckets {
    /// Buckets every triangle into the layers whose plane lies in `(z_min, z_max]`: exactly those
    /// where, with on-plane vertices counted as above, it has vertices on both sides.
    fn new(mesh: &Mesh, planes: &[f64]) -> Self {
        let ranges: Vec<(u32, u32)> = (0..mesh.triangles.len())
            .map(|t| {
                let Some([a, b, c]) = corners(mesh, t) else {
                    return (0, 0);
                };
                let z_min = a.z.min(b.z).min(c.z);
                let z_max = a.z.max(b.z).max(c.z);
                if !(z_min.is_finite() && z_max.is_finite()) {
                    return (0, 0);
                }
                let lo = planes.partition_point(|&s| s <= z_min);
                let hi = planes.partition_point(|&s| s <= z_max);
                (lo as u32, hi.max(lo) as u32)
            })
            .collect();
        let mut offsets = vec![0usize; planes.len() + 1];
        for &(lo, hi) in &ranges {
            for l in lo..hi {
                offsets[l as usize + 1] += 1;
            }
        }
        for l in 0..planes.len() {
            offsets[l + 1] += offsets[l];
        }
        let mut fill = offsets.clone();
        let mut triangles = vec![0u32; offsets[planes.len()]];
        for (t, &(lo, hi)) in ranges.iter().enumerate() {
            for l in lo..hi {
                triangles[fill[l as usize]] = t as u32;
                fill[l as usize] += 1;
            }
        }
        Self { offsets, triangles }
    }

    fn layer(&self, l: usize) -> &[u32] {
        &self.triangles[self.offsets[l]..self.offsets[l + 1]]
    }
}

/// Triangle `t`'s corners, or `None` if it refers to a vertex that does not exist.
fn corners(mesh: &Mesh, t: usize) -> Option<[Point3; 3]> {
    let [i, j, k] = mesh.triangles[t];
    Some([
        *mesh.vertices.get(i as usize)?,
        *mesh.vertices.get(j as usize)?,
        *mesh.vertices.get(k as usize)?,
    ])
}

/// The key naming the mesh edge between vertices `u` and `v`, independent of direction.
fn edge_key(u: u32, v: u32) -> u64 {
    let (lo, hi) = if u < v { (u, v) } else { (v, u) };
    (u64::from(lo) << 32) | u64::from(hi)
}

/// Where the plane `z` cuts the edge `u`–`v` (one end below, the other at or above), snapped to
/// the grid, and the vertex the point is, if it is exactly one.
fn cut_edge(mesh: &Mesh, u: u32, v: u32, z: f64) -> (Point2, Option<u32>) {
    // Always interpolate from the lower vertex index so both triangles sharing the edge compute
    // bit-identical points.
    let (lo, hi) = if u < v { (u, v) } else { (v, u) };
    let (p, q) = (mesh.vertices[lo as usize], mesh.vertices[hi as usize]);
    if p.z == z {
        return (Point2::from_mm(p.x, p.y), Some(lo));
    }
    if q.z == z {
        return (Point2::from_mm(q.x, q.y), Some(hi));
    }
    let t = (z - p.z) / (q.z - p.z);
    (
        Point2::from_mm(p.x + t * (q.x - p.x), p.y + t * (q.y - p.y)),
        None,
    )
}

/// Cuts the triangles `tris` with the plane `z`; returns the segments and the number of
/// degenerate ones (see [`SliceReport::degenerate_segments`]).
fn cut_triangles(mesh: &Mesh, tris: &[u32], z: f64, flip: bool) -> (Vec<Segment>, usize) {
    let mut segments = Vec::with_capacity(tris.len());
    let mut degenerate = 0;
    for &t in tris {
        let ids = mesh.triangles[t as usize];
        let Some(p) = corners(mesh, t as usize) else {
            continue;
        };
        let above = [p[0].z >= z, p[1].z >= z, p[2].z >= z];
        let (mut down, mut up) = (None, None);
        for k in 0..3 {
            let n = (k + 1) % 3;
            match (above[k], above[n]) {
                (true, false) => down = Some((ids[k], ids[n])),
                (false, true) => up = Some((ids[k], ids[n])),
                _ => {}
            }
        }
        let (Some((d0, d1)), Some((u0, u1))) = (down, up) else {
            continue;
        };
        let (a, a_vertex) = cut_edge(mesh, d0, d1, z);
        let (b, b_vertex) = cut_edge(mesh, u0, u1, z);
        if a == b && (a_vertex.is_none() || a_vertex != b_vertex) {
            degenerate += 1;
        }
        let (a_edge, b_edge) = (edge_key(d0, d1), edge_key(u0, u1));
        segments.push(if flip {
            Segment {
                a: b,
                b: a,
                a_edge: b_edge,
                b_edge: a_edge,
            }
        } else {
            Segment {
                a,
                b,
                a_edge,
                b_edge,
            }
        });
    }
    (segments, degenerate)
}

#[cfg(test)]
#[path = "planar_tests.rs"]
mod tests;
