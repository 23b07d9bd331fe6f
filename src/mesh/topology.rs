//! Mesh validation: edge manifoldness, boundary edges, winding consistency, shells, orientation.
//!
//! Edges are undirected vertex-index pairs, so validation sees the mesh as its indices say; run
//! [`Mesh::repair`] first to weld near-coincident vertices. Triangles with a repeated vertex
//! index have no edges: they count as degenerate and belong to no shell.
//!
//! Facing is judged per closed shell, not by the sign of the total volume alone: an outer skin
//! must have positive signed volume and the wall of a cavity inside it negative, so a hollow part
//! is [`Orientation::Outward`], and two parts of which one is inside out are not. Nesting comes
//! from the generalised winding number of a point of one shell with respect to another. The same
//! rule drives the orientation step of [`Mesh::repair`].

use super::Mesh;
use super::edges::{EdgeTable, UnionFind, is_collapsed, side_vertices};
use crate::geom::{Point3, Tolerances};
use serde::Serialize;

/// Which way a mesh's triangles face.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Orientation {
    /// Consistent winding, closed, and every shell faces the right way: normals point out of the
    /// material (an outer shell has positive volume, a cavity inside it negative volume).
    Outward,
    /// Consistent winding, closed, and every shell faces the wrong way: the mesh is inside out.
    Inward,
    /// Neighbouring triangles disagree on winding, or the mesh is closed and some shells face
    /// out while others face in.
    Inconsistent,
    /// Consistent winding but the mesh is open (boundary or non-manifold edges), so in/out is not
    /// defined.
    Open,
    /// No triangles (or only triangles with repeated vertex indices).
    Empty,
}

/// What validation found in a mesh.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TopologyReport {
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges shared by two triangles that traverse it in the same direction.
    pub inconsistent_edges: usize,
    /// Triangles with repeated vertex indices or an area below `Tolerances::degenerate_area`.
    pub degenerate_triangles: usize,
    /// Connected components (by shared edges), not counting triangles with repeated indices.
    pub shells: usize,
    /// At least one triangle, no boundary and no non-manifold edges.
    pub closed: bool,
    /// Closed shells facing the wrong way (see [`Orientation::Outward`]); 0 unless the mesh is
    /// closed and consistently wound.
    pub inverted_shells: usize,
    /// Winding and facing.
    pub orientation: Orientation,
}

impl Mesh {
    /// Validates the mesh topology with the default [`Tolerances`].
    pub fn topology(&self) -> TopologyReport {
        self.topology_with(&Tolerances::default())
    }

    /// Validates the mesh topology; `tol.degenerate_area` decides which triangles are degenerate.
    ///
    /// Linear in the mesh size apart from the nesting test between closed shells (only run when
    /// there are several), which costs one winding-number sum per pair of shells whose bounding
    /// boxes overlap.
    pub fn topology_with(&self, tol: &Tolerances) -> TopologyReport {
        let min_area = tol.degenerate_area.mm();
        // The edge table and the per-triangle area test are independent: run them side by side.
        let (edges, degenerate_triangles) = rayon::join(
            || EdgeTable::new(&self.triangles),
            || {
                (0..self.triangles.len())
                    .filter(|&i| {
                        is_collapsed(&self.triangles[i]) || area_below(self.corners(i), min_area)
                    })
                    .count()
            },
        );
        let (mut boundary_edges, mut non_manifold_edges, mut inconsistent_edges) = (0, 0, 0);
        for e in 0..edges.len() {
            match edges.sides(e) {
                [_] => boundary_edges += 1,
                [a, b] => {
                    let (a0, a1) = side_vertices(&self.triangles, *a);
                    let (b0, b1) = side_vertices(&self.triangles, *b);
                    if (a0 < a1) == (b0 < b1) {
                        inconsistent_edges += 1;
                    }
                }
                _ => non_manifold_edges += 1,
            }
        }
        let shells = Shells::new(&self.triangles, &edges);
        let closed = shells.count > 0 && boundary_edges == 0 && non_manifold_edges == 0;
        let mut inverted_shells = 0;
        let orientation = if shells.count == 0 {
            Orientation::Empty
        } else if inconsistent_edges > 0 {
            Orientation::Inconsistent
        } else if !closed {
            Orientation::Open
        } else {
            let facing = shell_facing(self, &shells);
            inverted_shells = facing.iter().filter(|&&f| f == Facing::Inverted).count();
            if inverted_shells == 0 {
                Orientation::Outward
            } else if facing.iter().all(|&f| f != Facing::Correct) {
                Orientation::Inward
            } else {
                Orientation::Inconsistent
            }
        };
        TopologyReport {
            boundary_edges,
            non_manifold_edges,
            inconsistent_edges,
            degenerate_triangles,
            shells: shells.count,
            closed,
            inverted_shells,
            orientation,
        }
    }
}

/// The area of triangle `i` in mm².
pub(crate) fn triangle_area(mesh: &Mesh, i: usize) -> f64 {
    let [a, b, c] = mesh.corners(i);
    (b - a).cross(&(c - a)).norm() / 2.0
}

/// Whether the triangle `a b c` has an area below `min_area` mm². Validation and every repair
/// step use this one test (squared, without a root), so a triangle repair keeps or creates is never
/// called degenerate afterwards.
pub(crate) fn area_below([a, b, c]: [Point3; 3], min_area: f64) -> bool {
    (b - a).cross(&(c - a)).norm_squared() < 4.0 * min_area * min_area
}

/// Marks a triangle that belongs to no shell (it repeats a vertex index).
pub(crate) const NO_SHELL: u32 = u32::MAX;

/// The edge-connected components of a triangle list.
#[derive(Debug, Clone)]
pub(crate) struct Shells {
    /// The shell of each triangle, or [`NO_SHELL`]. Shells are numbered in order of their
    /// lowest triangle index.
    pub(crate) of_triangle: Vec<u32>,
    /// The number of shells.
    pub(crate) count: usize,
    /// Whether each shell has only manifold edges (each used by exactly two triangles).
    pub(crate) closed: Vec<bool>,
}

impl Shells {
    /// Groups triangles joined by any shared edge (manifold or not).
    pub(crate) fn new(triangles: &[[u32; 3]], edges: &EdgeTable) -> Shells {
        let mut uf = UnionFind::new(triangles.len());
        for e in 0..edges.len() {
            let sides = edges.sides(e);
            for s in &sides[1..] {
                uf.union(sides[0] / 3, s / 3);
            }
        }
        let mut of_triangle = vec![NO_SHELL; triangles.len()];
        let mut count = 0;
        for (i, t) in triangles.iter().enumerate() {
            if is_collapsed(t) {
                continue;
            }
            let root = uf.find(i as u32) as usize;
            // Roots are smallest members, so a root is always visited before its other members.
            if root == i {
                of_triangle[i] = count;
                count += 1;
            } else {
                of_triangle[i] = of_triangle[root];
            }
        }
        let mut closed = vec![true; count as usize];
        for e in 0..edges.len() {
            let sides = edges.sides(e);
            if sides.len() != 2 {
                closed[of_triangle[(sides[0] / 3) as usize] as usize] = false;
            }
        }
        Shells {
            of_triangle,
            count: count as usize,
            closed,
        }
    }

    /// The triangles of each shell, in increasing order.
    pub(crate) fn members(&self) -> Vec<Vec<u32>> {
        let mut members = vec![Vec::new(); self.count];
        for (i, &s) in self.of_triangle.iter().enumerate() {
            if s != NO_SHELL {
                members[s as usize].push(i as u32);
            }
        }
        members
    }
}

/// How a consistently wound shell faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Facing {
    /// Closed, and its signed volume has the sign its nesting asks for.
    Correct,
    /// Closed, and its signed volume has the other sign.
    Inverted,
    /// Closed with zero signed volume (a flat, doubled-up surface): no way is right.
    Flat,
    /// Not closed: in and out are undefined.
    Open,
}

/// How each shell faces, assuming each shell is consistently wound.
///
/// A closed shell should have positive signed volume when it is nested inside an even number of
/// other closed shells (an outer skin, or an island inside a cavity) and negative volume when
/// nested inside an odd number (the wall of a cavity). Whether shell A lies inside shell B is
/// decided by the generalised winding number, with respect to B, of a probe point on A (the
/// centroid of one of A's largest triangles): about 1 inside, 0 outside, and robust to the probe
/// lying near one of B's edges. A probe on B's surface (shells touching along a face) is
/// ambiguous, so the next probe is tried. Shells are assumed not to cross one another; where
/// they do, the probe decides.
pub(crate) fn shell_facing(mesh: &Mesh, shells: &Shells) -> Vec<Facing> {
    let members = shells.members();
    let Some(bb) = mesh.bounding_box() else {
        return vec![Facing::Open; shells.count];
    };
    // Volumes relative to the bounding-box centre, as in `Mesh::signed_volume`, for precision.
    let centre = Point3::new(
        (bb.min[0] + bb.max[0]) / 2.0,
        (bb.min[1] + bb.max[1]) / 2.0,
        (bb.min[2] + bb.max[2]) / 2.0,
    );
    let volume = |tris: &[u32]| {
        tris.iter()
            .map(|&t| {
                let [a, b, c] = mesh.corners(t as usize);
                (a - centre).dot(&(b - centre).cross(&(c - centre)))
            })
            .sum::<f64>()
            / 6.0
    };
    let closed: Vec<usize> = (0..shells.count).filter(|&s| shells.closed[s]).collect();
    let mut depth = vec![0usize; shells.count];
    if closed.len() > 1 {
        let boxes: Vec<_> = closed
            .iter()
            .map(|&s| shell_box(mesh, &members[s]))
            .collect();
        let grid = BoxGrid::new(&boxes);
        let mut candidates = Vec::new();
        for &a in &closed {
            let probes = probe_points(mesh, &members[a]);
            let Some(first) = probes.first() else {
                continue;
            };
            // Only a shell whose box holds the first probe can contain `a` (see `inside`).
            grid.candidates(first, &mut candidates);
            for &j in &candidates {
                let b = closed[j];
                if a != b && inside(mesh, &probes, &members[b], &boxes[j]) {
                    depth[a] += 1;
                }
            }
        }
    }
    (0..shells.count)
        .map(|s| {
            if !shells.closed[s] {
                return Facing::Open;
            }
            let v = volume(&members[s]);
            let want_positive = depth[s] % 2 == 0;
            if v == 0.0 {
                Facing::Flat
            } else if (v > 0.0) == want_positive {
                Facing::Correct
            } else {
                Facing::Inverted
            }
        })
        .collect()
}

/// Boxes registered in the cells of a uniform grid they overlap, so the boxes that may hold a
/// point are found without testing every box: testing every shell against every other is
/// quadratic, minutes for a file of 2¹⁸ component instances. Cells are as large as the median
/// box; a box spanning more than [`BoxGrid::MAX_CELLS`] cells is kept in a list tried for every
/// point. The registrations are one sorted list searched by cell, not a map of lists: millions
/// of small per-cell allocations cost more than the search.
struct BoxGrid {
    /// Side of a cell, or `None` when the boxes give no usable size (every box is then tried).
    cell: Option<f64>,
    /// (cell, box) for every cell a box overlaps, sorted.
    cells: Vec<([i64; 3], u32)>,
    /// Boxes tried for every point.
    big: Vec<usize>,
}

impl BoxGrid {
    /// Most cells a box is registered in.
    const MAX_CELLS: i64 = 64;

    fn new(boxes: &[([f64; 3], [f64; 3])]) -> Self {
        let mut extents: Vec<f64> = boxes
            .iter()
            .map(|(lo, hi)| (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max))
            .filter(|e| e.is_finite())
            .collect();
        extents.sort_unstable_by(f64::total_cmp);
        let cell = extents
            .get(extents.len() / 2)
            .copied()
            .filter(|c| c.is_finite() && *c > 0.0);
        let mut grid = BoxGrid {
            cell,
            cells: Vec::new(),
            big: Vec::new(),
        };
        for (j, (lo, hi)) in boxes.iter().enumerate() {
            let range = cell.map(|c| (Self::key(lo, c), Self::key(hi, c)));
            let small = range.filter(|(from, to)| {
                (0..3)
                    .map(|k| to[k].saturating_sub(from[k]).saturating_add(1))
                    .try_fold(1i64, |n, d| n.checked_mul(d))
                    .is_some_and(|n| n <= Self::MAX_CELLS)
            });
            let (Some((from, to)), Ok(index)) = (small, u32::try_from(j)) else {
                grid.big.push(j);
                continue;
            };
            for x in from[0]..=to[0] {
                for y in from[1]..=to[1] {
                    for z in from[2]..=to[2] {
                        grid.cells.push(([x, y, z], index));
                    }
                }
            }
        }
        grid.cells.sort_unstable();
        grid
    }

    fn key(p: &[f64; 3], cell: f64) -> [i64; 3] {
        p.map(|c| (c / cell).floor() as i64)
    }

    /// Indices of the boxes that may hold `p`, in increasing order, into `out` (cleared first).
    fn candidates(&self, p: &Point3, out: &mut Vec<usize>) {
        out.clear();
        out.extend_from_slice(&self.big);
        let Some(cell) = self.cell else {
            return;
        };
        let key = Self::key(&[p.x, p.y, p.z], cell);
        let from = self.cells.partition_point(|(k, _)| *k < key);
        out.extend(
            self.cells[from..]
                .iter()
                .take_while(|(k, _)| *k == key)
                .map(|&(_, j)| j as usize),
        );
        out.sort_unstable();
    }
}

/// The bounding box of a shell's triangles as `(min, max)`.
fn shell_box(mesh: &Mesh, tris: &[u32]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &t in tris {
        for v in mesh.triangles[t as usize] {
            let p = mesh.vertices[v as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    (lo, hi)
}

fn contains((lo, hi): &([f64; 3], [f64; 3]), p: &Point3) -> bool {
    (0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k])
}

/// How many probe points [`shell_facing`] tries per shell.
const PROBES: usize = 8;

/// The centroids of the shell's [`PROBES`] largest triangles, largest first (lowest index first
/// among equals).
fn probe_points(mesh: &Mesh, tris: &[u32]) -> Vec<Point3> {
    let mut best: Vec<(f64, u32)> = Vec::with_capacity(PROBES + 1);
    for &t in tris {
        let area = triangle_area(mesh, t as usize);
        if best.len() < PROBES || best.last().is_some_and(|&(a, _)| area > a) {
            let at = best.partition_point(|&(a, _)| a >= area);
            best.insert(at, (area, t));
            best.truncate(PROBES);
        }
    }
    best.iter()
        .map(|&(_, t)| {
            let [a, b, c] = mesh.corners(t as usize);
            Point3::from((a.coords + b.coords + c.coords) / 3.0)
        })
        .collect()
}

/// Whether the shell the `probes` lie on is inside the closed shell `tris` with bounding box
/// `bbox`, judged by the first probe not on that shell's surface.
fn inside(mesh: &Mesh, probes: &[Point3], tris: &[u32], bbox: &([f64; 3], [f64; 3])) -> bool {
    for p in probes {
        if !contains(bbox, p) {
            return false;
        }
        if let Some(w) = winding_number(mesh, tris, p) {
            return w.abs() > 0.5;
        }
    }
    false
}

/// The generalised winding number of `p` with respect to the triangles `tris`: the sum of their
/// signed solid angles seen from `p` over 4π (Van Oosterom and Strackee). About ±1 inside a
/// closed shell, about 0 outside; `None` when `p` lies on one of the triangles, where the sum
/// jumps and its value is down to rounding.
fn winding_number(mesh: &Mesh, tris: &[u32], p: &Point3) -> Option<f64> {
    let mut total = 0.0;
    for &t in tris {
        let [a, b, c] = mesh.corners(t as usize).map(|q| q - p);
        let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
        let det = a.dot(&b.cross(&c));
        let den = la * lb * lc + a.dot(&b) * lc + a.dot(&c) * lb + b.dot(&c) * la;
        // In the triangle's plane (relative to the corner distances) and inside it: on the
        // surface. A zero corner distance means `p` is a corner.
        if la * lb * lc == 0.0 || (det.abs() <= 1e-12 * la * lb * lc && den <= 0.0) {
            return None;
        }
        total += 2.0 * det.atan2(den);
    }
    Some(total / (4.0 * std::f64::consts::PI))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::indexed::tests::cube;

    /// `cube(s)` moved by `(d, d, d)`.
    fn cube_at(s: f64, d: f64) -> Mesh {
        let mut m = cube(s);
        for v in &mut m.vertices {
            *v += Vector3::new(d, d, d);
        }
        m
    }

    use crate::geom::Vector3;

    #[test]
    fn closed_cube_is_outward_with_eighteen_manifold_edges() {
        let r = cube(20.0).topology();
        assert_eq!(
            r,
            TopologyReport {
                boundary_edges: 0,
                non_manifold_edges: 0,
                inconsistent_edges: 0,
                degenerate_triangles: 0,
                shells: 1,
                closed: true,
                inverted_shells: 0,
                orientation: Orientation::Outward,
            }
        );
        assert_eq!(EdgeTable::new(&cube(1.0).triangles).len(), 18);
    }

    #[test]
    fn one_flipped_triangle_makes_three_inconsistent_edges() {
        let mut m = cube(20.0);
        m.triangles[5].swap(1, 2);
        let r = m.topology();
        assert_eq!(r.inconsistent_edges, 3);
        assert!(r.closed);
        assert_eq!(r.orientation, Orientation::Inconsistent);
    }

    #[test]
    fn missing_face_leaves_four_boundary_edges() {
        let mut m = cube(20.0);
        m.triangles.drain(2..4);
        let r = m.topology();
        assert_eq!((r.boundary_edges, r.shells, r.closed), (4, 1, false));
        assert_eq!(r.orientation, Orientation::Open);
    }

    #[test]
    fn inside_out_cube_is_inward_and_empty_mesh_is_empty() {
        let mut m = cube(3.0);
        for t in &mut m.triangles {
            t.swap(0, 1);
        }
        let r = m.topology();
        assert_eq!((r.orientation, r.inverted_shells), (Orientation::Inward, 1));
        let empty = Mesh::default().topology();
        assert_eq!(
            (empty.orientation, empty.closed, empty.shells),
            (Orientation::Empty, false, 0)
        );
    }

    #[test]
    fn fin_on_an_edge_is_non_manifold_and_degenerates_are_counted() {
        let mut m = cube(20.0);
        m.vertices.push(Point3::new(10.0, -10.0, -10.0));
        // The midpoint of edge 0-1 (a diagonal of the bottom face), so [0, 1, 9] has zero area.
        m.vertices.push(Point3::from(
            (m.vertices[0].coords + m.vertices[1].coords) / 2.0,
        ));
        m.triangles.push([0, 1, 8]);
        m.triangles.push([0, 1, 9]);
        m.triangles.push([2, 2, 3]);
        let r = m.topology();
        assert_eq!(r.non_manifold_edges, 1);
        assert_eq!(r.degenerate_triangles, 2);
        assert_eq!(r.shells, 1);
        assert_eq!(r.orientation, Orientation::Open);
    }

    #[test]
    fn two_disjoint_cubes_are_two_shells_and_a_mixed_pair_is_inconsistent() {
        let mut m = cube(10.0);
        let mut other = cube_at(10.0, 30.0);
        m.append(&other);
        assert_eq!(m.topology().shells, 2);
        assert_eq!(m.topology().orientation, Orientation::Outward);
        for t in &mut other.triangles {
            t.swap(1, 2);
        }
        let mut mixed = cube(10.0);
        mixed.append(&other);
        let r = mixed.topology();
        assert_eq!((r.shells, r.inverted_shells), (2, 1));
        assert_eq!(r.orientation, Orientation::Inconsistent);
    }

    #[test]
    fn cavity_wall_facing_into_the_cavity_is_outward() {
        // A 30 mm cube with a 10 mm cavity whose wall faces the cavity (negative volume).
        let mut m = cube(30.0);
        let mut cavity = cube_at(10.0, 10.0);
        for t in &mut cavity.triangles {
            t.swap(1, 2);
        }
        m.append(&cavity);
        let r = m.topology();
        assert_eq!((r.shells, r.inverted_shells), (2, 0));
        assert_eq!(r.orientation, Orientation::Outward);
        assert_eq!(m.signed_volume(), 27000.0 - 1000.0);
        // The same cavity facing the material is wrong.
        let mut wrong = cube(30.0);
        wrong.append(&cube_at(10.0, 10.0));
        assert_eq!(wrong.topology().inverted_shells, 1);
    }

    #[test]
    fn cubes_stacked_face_to_face_are_not_nested() {
        // The lower cube lists its top face first, so its first probes lie on the upper cube's
        // bottom face, where the winding number is undefined.
        let mut m = cube(10.0);
        m.triangles.rotate_left(2);
        let mut upper = cube(10.0);
        for v in &mut upper.vertices {
            v.z += 10.0;
        }
        m.append(&upper);
        let r = m.topology();
        assert_eq!((r.shells, r.inverted_shells), (2, 0));
        assert_eq!(r.orientation, Orientation::Outward);
    }

    #[test]
    fn winding_number_is_one_inside_and_zero_outside() {
        let m = cube(2.0);
        let all: Vec<u32> = (0..12).collect();
        let w = |x: f64, y: f64, z: f64| winding_number(&m, &all, &Point3::new(x, y, z));
        let inside = w(0.5, 1.0, 1.5).unwrap_or(f64::NAN);
        let outside = w(5.0, 1.0, 1.0).unwrap_or(f64::NAN);
        assert!((inside - 1.0).abs() < 1e-12, "{inside}");
        assert!(outside.abs() < 1e-12, "{outside}");
        // On a face, on an edge, at a corner.
        assert_eq!(w(0.5, 1.0, 2.0), None);
        assert_eq!(w(1.0, 0.0, 0.0), None);
        assert_eq!(w(2.0, 2.0, 2.0), None);
    }
}
