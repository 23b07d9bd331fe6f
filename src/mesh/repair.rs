//! Mesh repair: merge near vertices, drop degenerate, duplicate and unconnected facets, make the
//! winding consistent and outward, fill simple holes.
//!
//! [`Mesh::repair`] runs the steps in a fixed order, each preparing the next:
//!
//! 1. **Merge vertices** closer than `Tolerances::vertex_merge`. Cracks between facets that
//!    should share a vertex close up, near-duplicate facets become exact duplicates and slivers
//!    collapse to repeated indices, so the next step can see them.
//! 2. **Remove degenerate facets**, **duplicate facets** (same three vertices; copies wound
//!    opposite ways cancel in pairs, as the shared face of two touching bodies is an internal
//!    wall, then the first of the rest is kept) and **unconnected facets** (sharing no edge with
//!    any other, as admesh's `--remove-unconnected`). A facet with a repeated vertex index is
//!    dropped. A facet with an area below `Tolerances::degenerate_area` is, after step 1, a *cap*
//!    whose third vertex lies on its longest edge; caps close T-junctions in real files (admesh's
//!    conveyor has 34, 3DBenchy 19), so the cap goes by splitting its neighbour across the long
//!    edge at the cap's apex, which keeps a closed surface closed. Duplicates and slivers would
//!    otherwise show up as non-manifold edges that stop the winding walk and the hole search.
//! 3. **Make the winding consistent** per shell: a walk across manifold edges flips each
//!    neighbour to agree; each shell keeps the winding most of its facets already had. The hole
//!    walk and the fill's winding in step 4 rely on this.
//! 4. **Fill holes**: boundary loops of at most `Tolerances::max_hole_edges` edges, triangulated by
//!    ear clipping, wound like the facets around them.
//! 5. **Orient closed shells outward** (after filling, because only closed shells have an inside
//!    and filling closes some). A shell gets positive signed volume unless it is nested inside an
//!    odd number of other closed shells, in which case it is the wall of a cavity and gets
//!    negative volume. Nesting is decided by the winding number of a point of the shell; shells
//!    that intersect one another have no well-defined nesting and get what their probe point says.
//! 6. **Drop unreferenced vertices**, last because the earlier steps orphan some.
//!
//! Repair is idempotent (every test here checks it): kept vertices are more than the merge
//! tolerance apart, no step creates anything an earlier step would remove (new triangles are
//! checked against the same degenerate and duplicate tests), and holes refused once are refused
//! again. It never moves a vertex.

use super::Mesh;
use super::edges::{EdgeTable, FastMap, FastSet, is_collapsed, side_vertices};
use super::topology::{Facing, NO_SHELL, Shells, area_below, shell_facing};
use crate::geom::{Point3, Tolerances, Vector3};
use serde::Serialize;

/// What a repair pass changed.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct RepairReport {
    /// Vertices merged into a neighbour within `Tolerances::vertex_merge`.
    pub merged_vertices: usize,
    /// Degenerate triangles removed. A zero-area cap removed by splitting its neighbour counts
    /// here too, though the triangle count then stays the same.
    pub removed_degenerate: usize,
    /// Duplicate triangles removed.
    pub removed_duplicate: usize,
    /// Triangles removed because they share no edge with any other triangle.
    pub removed_unconnected: usize,
    /// Triangles whose winding was flipped.
    pub flipped_triangles: usize,
    /// Holes (boundary loops) filled.
    pub holes_filled: usize,
    /// Triangles added by hole filling.
    pub triangles_added: usize,
    /// Vertices dropped because no triangle used them any more.
    pub removed_vertices: usize,
}

impl RepairReport {
    /// Whether the pass changed anything.
    pub fn changed(&self) -> bool {
        *self != RepairReport::default()
    }
}

impl Mesh {
    /// Repairs the mesh in place and reports what changed. See the [module docs](self) for the
    /// steps and why they run in this order. Running it again on the result changes nothing.
    ///
    /// ```
    /// use conduit::geom::{Point3, Tolerances};
    /// use conduit::mesh::{Mesh, Orientation};
    ///
    /// // A unit tetrahedron missing its slanted face, the other three wound inwards.
    /// let [o, x, y, z] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    ///     .map(|[a, b, c]| Point3::new(a, b, c));
    /// let mut mesh = Mesh::from_triangle_soup("tet", [[o, x, y], [o, z, x], [o, y, z]]);
    /// assert_eq!(mesh.topology().orientation, Orientation::Open);
    ///
    /// let report = mesh.repair(&Tolerances::default());
    /// assert_eq!((report.holes_filled, report.flipped_triangles), (1, 3));
    /// assert_eq!(mesh.topology().orientation, Orientation::Outward);
    /// assert!((mesh.signed_volume() - 1.0 / 6.0).abs() < 1e-15);
    /// assert!(!mesh.repair(&Tolerances::default()).changed());
    /// ```
    pub fn repair(&mut self, tol: &Tolerances) -> RepairReport {
        let mut report = RepairReport {
            merged_vertices: self.merge_near_vertices(tol.vertex_merge.mm()),
            ..RepairReport::default()
        };
        (report.removed_degenerate, report.removed_duplicate) =
            self.remove_degenerate_and_duplicate(tol.degenerate_area.mm());
        report.removed_unconnected = self.remove_unconnected(2);
        let mut flipped = vec![false; self.triangles.len()];
        self.make_winding_consistent(&mut flipped);
        (report.holes_filled, report.triangles_added) = self.fill_holes(tol);
        self.orient_closed_shells(&mut flipped);
        report.flipped_triangles = flipped.iter().filter(|&&f| f).count();
        report.removed_vertices = self.remove_unreferenced_vertices();
        report
    }

    /// Removes every shell (edge-connected set of triangles) with fewer than
    /// `min_shell_triangles` triangles and returns how many triangles went. Triangles with a
    /// repeated vertex index belong to no shell and are kept.
    ///
    /// `remove_unconnected(2)` is admesh's `--remove-unconnected`: it drops facets that share no
    /// edge with another and keeps every larger shell (admesh's reference output for a file with
    /// two cubes and a stray facet keeps both cubes). [`Mesh::repair`] runs it.
    pub fn remove_unconnected(&mut self, min_shell_triangles: usize) -> usize {
        let edges = EdgeTable::new(&self.triangles);
        let shells = Shells::new(&self.triangles, &edges);
        let mut size = vec![0usize; shells.count];
        for &s in shells.of_triangle.iter().filter(|&&s| s != NO_SHELL) {
            size[s as usize] += 1;
        }
        let before = self.triangles.len();
        let mut i = 0;
        self.triangles.retain(|_| {
            let s = shells.of_triangle[i];
            i += 1;
            s == NO_SHELL || size[s as usize] >= min_shell_triangles
        });
        before - self.triangles.len()
    }

    /// Step 1: merges each referenced vertex into the lowest-indexed earlier kept vertex within
    /// `tol` mm, and returns how many were merged.
    ///
    /// Vertices are visited in index order and kept vertices go into a hash grid with cells of
    /// side `2 tol`. A match is then, along each axis, in the vertex's own cell or the neighbour
    /// on the side of the nearer cell wall, so 8 cells are probed (rather than the 27 around a
    /// vertex with cells of side `tol`: a third of the lookups). The grid is only probed, never
    /// iterated, so the result does not depend on hash order. Kept vertices keep
    /// their position and end up pairwise more than `tol` apart, so a second pass merges nothing.
    fn merge_near_vertices(&mut self, tol: f64) -> usize {
        let n = self.vertices.len();
        let mut used = vec![false; n];
        for &v in self.triangles.iter().flatten() {
            used[v as usize] = true;
        }
        let scaled = |p: &Point3| [p.x, p.y, p.z].map(|c| c / (2.0 * tol));
        // Kept vertices per cell as linked lists: the first in `head`, the rest through `next`.
        let mut head: FastMap<[i64; 3], u32> = FastMap::default();
        let mut next = vec![u32::MAX; n];
        let mut map: Vec<u32> = (0..n as u32).collect();
        let mut merged = 0;
        for i in (0..n).filter(|&i| used[i]) {
            let p = self.vertices[i];
            let q = scaled(&p);
            let c = q.map(|x| x.floor() as i64);
            // Per axis, the neighbouring cell on the side of the nearer wall.
            let side = [0, 1, 2].map(|k| if q[k] - q[k].floor() < 0.5 { -1 } else { 1 });
            let mut best: Option<u32> = None;
            for d in 0..8 {
                let key = [0, 1, 2].map(|k| {
                    let step = if d >> k & 1 == 1 { side[k] } else { 0 };
                    c[k].saturating_add(step)
                });
                let mut r = head.get(&key).copied().unwrap_or(u32::MAX);
                while r != u32::MAX {
                    if (self.vertices[r as usize] - p).norm() <= tol && best.is_none_or(|b| r < b) {
                        best = Some(r);
                    }
                    r = next[r as usize];
                }
            }
            match best {
                Some(r) => {
                    map[i] = r;
                    merged += 1;
                }
                None => {
                    // Push to the front; the lowest index among matches wins, whatever the order.
                    if let Some(first) = head.insert(c, i as u32) {
                        next[i] = first;
                    }
                }
            }
        }
        if merged > 0 {
            for t in &mut self.triangles {
                *t = t.map(|v| map[v as usize]);
            }
        }
        merged
    }

    /// Step 2: removes degenerate triangles and duplicates. Returns `(degenerate, duplicate)`.
    ///
    /// Duplicates are triangles on the same three vertices. Copies wound opposite ways cancel in
    /// pairs (a face shared by two touching bodies is an internal wall: both copies go, and the
    /// bodies become one solid); of the copies left, the first is kept. A lone copy wound the
    /// wrong way thus removes its twin too, and step 4 fills the resulting hole with the right
    /// winding.
    ///
    /// A triangle with a repeated index is simply dropped: it has no edges. A triangle with three
    /// distinct vertices but an area below `min_area` mm² is, once near vertices are merged, a
    /// *cap*: its third vertex lies on its longest edge. Such caps fill T-junctions in otherwise
    /// closed meshes (admesh's conveyor has 34 of them), so dropping one would open a crack that
    /// no proper triangle can fill. Instead the cap and its neighbour across the longest edge are
    /// replaced by the neighbour split at the cap's apex: the surface stays closed, the triangle
    /// count stays the same, and the neighbour's winding is kept. A cap that cannot be split that
    /// way (its long edge is a boundary or non-manifold edge, the split would give degenerate or
    /// duplicate triangles, or its apex is already joined to the neighbour's far vertex) is
    /// dropped.
    fn remove_degenerate_and_duplicate(&mut self, min_area: f64) -> (usize, usize) {
        let before = self.triangles.len();
        self.triangles.retain(|t| !is_collapsed(t));
        let collapsed = before - self.triangles.len();
        // Facets on the same three vertices wound opposite ways cancel in pairs: two bodies
        // touching along a face, once welded, each bring that face with the other winding. It is
        // an internal wall, and keeping either copy would leave its edges non-manifold. Of what
        // is left after cancelling, the first is kept.
        let mut balance: FastMap<[u32; 3], i32> = FastMap::default();
        balance.reserve(self.triangles.len());
        for &t in &self.triangles {
            *balance.entry(sorted(t)).or_default() += winding_sign(t);
        }
        let mut seen = FastSet::default();
        seen.reserve(self.triangles.len());
        let before = self.triangles.len();
        self.triangles.retain(|&t| {
            let key = sorted(t);
            let net = balance.get(&key).copied().unwrap_or_default();
            net.signum() == winding_sign(t) && seen.insert(key)
        });
        let duplicate = before - self.triangles.len();
        (collapsed + self.remove_caps(min_area, &mut seen), duplicate)
    }

    /// Splits away or drops every triangle with area below `min_area` (see
    /// [`Mesh::remove_degenerate_and_duplicate`]); `existing` holds the sorted vertex sets of all
    /// triangles and is kept up to date. Returns how many caps went.
    fn remove_caps(&mut self, min_area: f64, existing: &mut FastSet<[u32; 3]>) -> usize {
        let mut caps: Vec<usize> = (0..self.triangles.len())
            .filter(|&i| area_below(self.corners(i), min_area))
            .collect();
        let handled = caps.len();
        // Set when a round changed nothing: caps waiting for a neighbouring cap would wait
        // forever (two caps back to back), so they are dropped.
        let mut stuck = false;
        // Dropped caps become collapsed triangles, which the edge table ignores, until the end.
        let mut dropped = false;
        while !caps.is_empty() {
            let edges = EdgeTable::new(&self.triangles);
            // Triangles changed this round: the edge table no longer describes them, so a cap
            // next to one waits for the next round.
            let mut touched = vec![false; self.triangles.len()];
            let mut new_edges = FastSet::default();
            let mut waiting = Vec::new();
            for &cap in &caps {
                let tri = self.triangles[cap];
                let corner = |k: usize| self.vertices[tri[k] as usize];
                let length = |k: usize| (corner((k + 1) % 3) - corner(k)).norm_squared();
                let k = (0..3).fold(0, |best, k| if length(k) > length(best) { k } else { best });
                let apex = tri[(k + 2) % 3];
                let split = edges.twin((cap * 3 + k) as u32).and_then(|twin| {
                    let n = (twin / 3) as usize;
                    // Caps come in stacks along one long edge (a fan of collinear points): the
                    // outermost one splits a proper triangle, and the split's half becomes the
                    // proper neighbour of the next cap in the following round.
                    if touched[n] || (!stuck && area_below(self.corners(n), min_area)) {
                        return Some(None);
                    }
                    let (x, y) = side_vertices(&self.triangles, twin);
                    let far = self.triangles[n][(twin % 3 + 2) as usize % 3];
                    let halves = [[x, apex, far], [apex, y, far]];
                    let edge = (apex.min(far), apex.max(far));
                    let ok = apex != far
                        && edges.find(apex, far).is_none()
                        && !new_edges.contains(&edge)
                        && halves.iter().all(|&h| {
                            !area_below(h.map(|v| self.vertices[v as usize]), min_area)
                                && !existing.contains(&sorted(h))
                        });
                    ok.then_some(Some((n, halves, edge)))
                });
                match split {
                    // The neighbour changed this round or is a cap itself: try again later.
                    Some(None) => {
                        waiting.push(cap);
                        continue;
                    }
                    Some(Some((n, halves, edge))) => {
                        existing.remove(&sorted(tri));
                        existing.remove(&sorted(self.triangles[n]));
                        existing.extend(halves.map(sorted));
                        new_edges.insert(edge);
                        self.triangles[n] = halves[0];
                        self.triangles[cap] = halves[1];
                        touched[n] = true;
                    }
                    None => {
                        existing.remove(&sorted(tri));
                        self.triangles[cap] = [tri[0]; 3];
                        dropped = true;
                    }
                }
                touched[cap] = true;
            }
            stuck = waiting.len() == caps.len();
            caps = waiting;
        }
        if dropped {
            self.triangles.retain(|t| !is_collapsed(t));
        }
        handled
    }

    /// Step 3: makes the winding agree across every manifold edge, toggling `flipped[t]` for
    /// each triangle flipped. Each component (connected through manifold edges) is walked from its
    /// lowest triangle; if that would flip more than half of it, the opposite choice is taken.
    fn make_winding_consistent(&mut self, flipped: &mut [bool]) {
        const UNSEEN: u8 = 0;
        const KEEP: u8 = 1;
        const FLIP: u8 = 2;
        let edges = EdgeTable::new(&self.triangles);
        let n = self.triangles.len();
        let mut state = vec![UNSEEN; n];
        let mut component = Vec::new();
        let mut stack = Vec::new();
        for seed in 0..n {
            if state[seed] != UNSEEN || is_collapsed(&self.triangles[seed]) {
                continue;
            }
            state[seed] = KEEP;
            component.clear();
            stack.push(seed);
            while let Some(t) = stack.pop() {
                component.push(t);
                for k in 0..3 {
                    let side = (t * 3 + k) as u32;
                    let Some(other) = edges.twin(side) else {
                        continue;
                    };
                    let u = (other / 3) as usize;
                    if state[u] != UNSEEN {
                        continue;
                    }
                    // Direction of the shared edge in t's final winding, and in u's current one.
                    let (a, b) = side_vertices(&self.triangles, side);
                    let t_up = (a < b) != (state[t] == FLIP);
                    let (c, d) = side_vertices(&self.triangles, other);
                    state[u] = if (c < d) != t_up { KEEP } else { FLIP };
                    stack.push(u);
                }
            }
            let flips = component.iter().filter(|&&t| state[t] == FLIP).count();
            if 2 * flips > component.len() {
                for &t in &component {
                    state[t] = if state[t] == FLIP { KEEP } else { FLIP };
                }
            }
        }
        for (t, tri) in self.triangles.iter_mut().enumerate() {
            if state[t] == FLIP {
                tri.swap(1, 2);
                flipped[t] = !flipped[t];
            }
        }
    }

    /// Step 4: fills boundary loops of 3 to `tol.max_hole_edges` edges. Returns
    /// `(holes filled, triangles added)`.
    ///
    /// Boundary edges are walked against their triangle's direction, so a loop runs the way the
    /// fill must wind to agree with its neighbours. Where a vertex starts several boundary edges
    /// (holes touching at a vertex) the one to the lowest vertex index is taken, and whenever
    /// the walk comes back to a vertex already on it the closed part is cut off as its own loop,
    /// so every loop is simple.
    ///
    /// A fill is refused, and the hole left open, if any of its triangles would be degenerate or
    /// duplicate an existing one, or if one of its diagonals is already an edge of the mesh
    /// (filling would make it non-manifold).
    fn fill_holes(&mut self, tol: &Tolerances) -> (usize, usize) {
        let edges = EdgeTable::new(&self.triangles);
        let mut out: Vec<(u32, u32)> = (0..edges.len())
            .filter_map(|e| match edges.sides(e) {
                [s] => {
                    let (a, b) = side_vertices(&self.triangles, *s);
                    Some((b, a))
                }
                _ => None,
            })
            .collect();
        if out.is_empty() {
            return (0, 0);
        }
        out.sort_unstable();
        let loops = boundary_loops(&out);
        let mut existing: FastSet<[u32; 3]> = self.triangles.iter().map(|&t| sorted(t)).collect();
        let mut new_diagonals: FastSet<(u32, u32)> = FastSet::default();
        let (mut holes, mut added) = (0, 0);
        for lp in loops {
            if lp.len() < 3 || lp.len() > tol.max_hole_edges {
                continue;
            }
            let min_area = tol.degenerate_area.mm();
            let taken = |a: u32, b: u32| {
                edges.find(a, b).is_some() || new_diagonals.contains(&(a.min(b), a.max(b)))
            };
            let fill = ear_clip(&self.vertices, &lp, min_area, taken);
            let ok_triangles = fill.iter().all(|&t| {
                !area_below(t.map(|v| self.vertices[v as usize]), min_area)
                    && !existing.contains(&sorted(t))
            });
            let diagonals: Vec<(u32, u32)> = fill
                .iter()
                .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
                .map(|(a, b)| (a.min(b), a.max(b)))
                .filter(|&(a, b)| !is_loop_edge(&lp, a, b))
                .collect();
            // Each diagonal is shared by two fill triangles: keep one copy for the checks.
            let mut unique = diagonals.clone();
            unique.sort_unstable();
            unique.dedup();
            let ok_diagonals = unique.len() * 2 == diagonals.len()
                && unique
                    .iter()
                    .all(|&(a, b)| edges.find(a, b).is_none() && !new_diagonals.contains(&(a, b)));
            let distinct: FastSet<[u32; 3]> = fill.iter().map(|&t| sorted(t)).collect();
            if !ok_triangles || !ok_diagonals || distinct.len() != fill.len() {
                continue;
            }
            existing.extend(distinct);
            new_diagonals.extend(unique);
            holes += 1;
            added += fill.len();
            self.triangles.extend(fill);
        }
        (holes, added)
    }

    /// Step 5: flips every closed shell that faces the wrong way, toggling `flipped[t]` for the
    /// triangles that were there before hole filling.
    fn orient_closed_shells(&mut self, flipped: &mut [bool]) {
        let edges = EdgeTable::new(&self.triangles);
        let shells = Shells::new(&self.triangles, &edges);
        let facing = shell_facing(self, &shells);
        for (t, tri) in self.triangles.iter_mut().enumerate() {
            let s = shells.of_triangle[t];
            if s != NO_SHELL && facing[s as usize] == Facing::Inverted {
                tri.swap(1, 2);
                if let Some(f) = flipped.get_mut(t) {
                    *f = !*f;
                }
            }
        }
    }

    /// Step 6: drops vertices no triangle uses, keeping the order of the rest. Returns how many.
    fn remove_unreferenced_vertices(&mut self) -> usize {
        let mut new_index = vec![u32::MAX; self.vertices.len()];
        for &v in self.triangles.iter().flatten() {
            new_index[v as usize] = 0;
        }
        let mut next = 0u32;
        for slot in new_index.iter_mut().filter(|s| **s == 0) {
            *slot = next;
            next += 1;
        }
        let before = self.vertices.len();
        if next as usize == before {
            return 0;
        }
        let mut i = 0;
        self.vertices.retain(|_| {
            i += 1;
            new_index[i - 1] != u32::MAX
        });
        for t in &mut self.triangles {
            *t = t.map(|v| new_index[v as usize]);
        }
        before - self.vertices.len()
    }
}

/// A triangle's vertex indices in increasing order: the key for "same facet".
fn sorted(mut t: [u32; 3]) -> [u32; 3] {
    t.sort_unstable();
    t
}

/// +1 if the triangle lists its (distinct) vertices in a rotation of increasing order, −1
/// otherwise: two triangles on the same vertices wind the same way exactly when their signs
/// agree. A rotation of increasing order rises twice going round the triangle, its reverse once.
fn winding_sign([a, b, c]: [u32; 3]) -> i32 {
    if u8::from(a < b) + u8::from(b < c) + u8::from(c < a) == 2 {
        1
    } else {
        -1
    }
}

/// Whether `a`–`b` (with `a < b`) joins two consecutive vertices of the closed loop `lp`.
fn is_loop_edge(lp: &[u32], a: u32, b: u32) -> bool {
    (0..lp.len()).any(|i| {
        let (p, q) = (lp[i], lp[(i + 1) % lp.len()]);
        (p.min(q), p.max(q)) == (a, b)
    })
}

/// Splits directed edges `out` (sorted, each used once) into simple closed loops of vertices.
/// Open chains (possible next to non-manifold edges) are dropped.
fn boundary_loops(out: &[(u32, u32)]) -> Vec<Vec<u32>> {
    let mut used = vec![false; out.len()];
    let mut loops = Vec::new();
    let mut path: Vec<u32> = Vec::new();
    let mut on_path: FastMap<u32, usize> = FastMap::default();
    let next_unused = |used: &[bool], v: u32| {
        let start = out.partition_point(|&(a, _)| a < v);
        (start..out.len())
            .take_while(|&i| out[i].0 == v)
            .find(|&i| !used[i])
    };
    for start in 0..out.len() {
        if used[start] {
            continue;
        }
        path.clear();
        on_path.clear();
        let mut v = out[start].0;
        loop {
            if let Some(&p) = on_path.get(&v) {
                loops.push(path[p..].to_vec());
                for w in path.drain(p..) {
                    on_path.remove(&w);
                }
            }
            on_path.insert(v, path.len());
            path.push(v);
            let Some(e) = next_unused(&used, v) else {
                break;
            };
            used[e] = true;
            v = out[e].1;
        }
    }
    loops
}

/// Triangulates the closed loop `lp` by ear clipping on its projection onto the plane given by
/// its Newell normal, keeping the loop's winding.
///
/// Ear clipping was chosen over a fan from the centroid: it adds no vertex, handles non-convex
/// loops, and for the long thin cracks that near-miss vertices leave (the usual small hole) a
/// fan would make a row of slivers while ears follow the crack. Among the valid ears (convex,
/// no other loop vertex inside) the best-shaped one is clipped first, which avoids needles where
/// a loop has a choice. If no ear is valid (the projection folds over itself), the best-shaped
/// convex ear, and failing that the best-shaped ear, is clipped so the loop is still closed; the
/// caller refuses the result if a triangle comes out degenerate.
///
/// Before all that, an ear is only usable if it is not degenerate (area below `min_area`) and
/// its new diagonal is not `taken` (already an edge of the mesh, which the fill would make
/// non-manifold); where a crack's best-shaped diagonal already exists, the other one is used.
fn ear_clip(
    vertices: &[Point3],
    lp: &[u32],
    min_area: f64,
    taken: impl Fn(u32, u32) -> bool,
) -> Vec<[u32; 3]> {
    let pts: Vec<Point3> = lp.iter().map(|&v| vertices[v as usize]).collect();
    let mut normal = Vector3::zeros();
    for i in 0..pts.len() {
        let (p, q) = (pts[i], pts[(i + 1) % pts.len()]);
        normal += Vector3::new(
            (p.y - q.y) * (p.z + q.z),
            (p.z - q.z) * (p.x + q.x),
            (p.x - q.x) * (p.y + q.y),
        );
    }
    // A basis (u, w) of the plane with u × w along the normal, so the loop is counter-clockwise.
    let n = normal.try_normalize(0.0).unwrap_or_else(Vector3::z);
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = helper.cross(&n).normalize();
    let w = n.cross(&u);
    let flat: Vec<(f64, f64)> = pts
        .iter()
        .map(|p| (p.coords.dot(&u), p.coords.dot(&w)))
        .collect();
    let cross = |a: usize, b: usize, c: usize| {
        let (ax, ay) = flat[a];
        let (bx, by) = flat[b];
        let (cx, cy) = flat[c];
        (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    };
    let quality = |a: usize, b: usize, c: usize| {
        let (pa, pb, pc) = (pts[a], pts[b], pts[c]);
        let area2 = (pb - pa).cross(&(pc - pa)).norm();
        let edges2 = (pb - pa).norm_squared() + (pc - pb).norm_squared() + (pa - pc).norm_squared();
        // 1 for an equilateral triangle, 0 for a degenerate one.
        if edges2 > 0.0 {
            2.0 * 3f64.sqrt() * area2 / edges2
        } else {
            0.0
        }
    };
    let mut ring: Vec<usize> = (0..lp.len()).collect();
    let mut out = Vec::with_capacity(lp.len() - 2);
    while ring.len() > 3 {
        let m = ring.len();
        // (rank, quality, position): rank 4 and up = usable, then 3 = valid ear, 1 = convex only.
        let mut best: Option<(u8, f64, usize)> = None;
        for i in 0..m {
            let (a, b, c) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
            let convex = cross(a, b, c) > 0.0;
            let empty = convex
                && ring.iter().all(|&p| {
                    p == a
                        || p == b
                        || p == c
                        || flat[p] == flat[a]
                        || flat[p] == flat[b]
                        || flat[p] == flat[c]
                        || cross(a, b, p) < 0.0
                        || cross(b, c, p) < 0.0
                        || cross(c, a, p) < 0.0
                });
            let usable = !taken(lp[a], lp[c]) && !area_below([pts[a], pts[b], pts[c]], min_area);
            let rank = 4 * u8::from(usable) + 2 * u8::from(empty) + u8::from(convex);
            let q = quality(a, b, c);
            if best.is_none_or(|(r, bq, _)| rank > r || (rank == r && q > bq)) {
                best = Some((rank, q, i));
            }
        }
        let i = best.map_or(0, |(_, _, i)| i);
        let (a, b, c) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
        out.push([lp[a], lp[b], lp[c]]);
        ring.remove(i);
    }
    out.push([lp[ring[0]], lp[ring[1]], lp[ring[2]]]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Orientation;
    use crate::mesh::indexed::tests::cube;

    /// `cube(s)` moved by `(d, d, d)`.
    fn cube_at(s: f64, d: f64) -> Mesh {
        let mut m = cube(s);
        for v in &mut m.vertices {
            *v += Vector3::new(d, d, d);
        }
        m
    }

    /// Repairs `m`, checks that a second pass changes nothing, and returns the first report.
    fn repair_twice(m: &mut Mesh) -> RepairReport {
        let report = m.repair(&Tolerances::default());
        let before = m.clone();
        let again = m.repair(&Tolerances::default());
        assert!(!again.changed(), "second repair changed {again:?}");
        assert_eq!(*m, before);
        report
    }

    fn assert_closed_outward(m: &Mesh) {
        let t = m.topology();
        assert_eq!(
            (t.boundary_edges, t.non_manifold_edges, t.inconsistent_edges),
            (0, 0, 0),
            "{t:?}"
        );
        assert!(t.closed);
        assert_eq!(t.orientation, Orientation::Outward, "{t:?}");
    }

    #[test]
    fn clean_cube_is_left_alone() {
        let mut m = cube(20.0);
        let report = repair_twice(&mut m);
        assert!(!report.changed(), "{report:?}");
        assert_eq!(m, cube(20.0));
    }

    #[test]
    fn flipped_triangle_is_turned_back_and_volume_is_exact() {
        let mut m = cube(20.0);
        m.triangles[5].swap(1, 2);
        assert_eq!(m.topology().orientation, Orientation::Inconsistent);
        let report = repair_twice(&mut m);
        assert_eq!(report.flipped_triangles, 1);
        assert_closed_outward(&m);
        assert_eq!(m.signed_volume(), 8000.0);
        assert_eq!(m.triangles[5], cube(20.0).triangles[5]);
    }

    #[test]
    fn flipping_the_seed_triangle_still_flips_only_one() {
        let mut m = cube(20.0);
        m.triangles[0].swap(0, 2);
        let report = repair_twice(&mut m);
        assert_eq!(report.flipped_triangles, 1);
        assert_closed_outward(&m);
    }

    #[test]
    fn inside_out_cube_is_turned_outward() {
        let mut m = cube(20.0);
        for t in &mut m.triangles {
            t.swap(1, 2);
        }
        let report = repair_twice(&mut m);
        assert_eq!(report.flipped_triangles, 12);
        assert_closed_outward(&m);
        assert_eq!(m.signed_volume(), 8000.0);
    }

    #[test]
    fn missing_face_is_filled_with_exact_volume() {
        let mut m = cube(20.0);
        m.triangles.drain(2..4); // the top face
        let t = m.topology();
        assert_eq!((t.boundary_edges, t.orientation), (4, Orientation::Open));
        let report = repair_twice(&mut m);
        assert_eq!((report.holes_filled, report.triangles_added), (1, 2));
        assert_eq!(report.flipped_triangles, 0);
        assert_closed_outward(&m);
        assert_eq!(m.signed_volume(), 8000.0);
        assert_eq!(m.area(), 2400.0);
    }

    #[test]
    fn missing_face_of_inside_out_cube_is_filled_then_turned_outward() {
        let mut m = cube(20.0);
        for t in &mut m.triangles {
            t.swap(1, 2);
        }
        m.triangles.drain(8..10);
        let report = repair_twice(&mut m);
        assert_eq!((report.holes_filled, report.flipped_triangles), (1, 10));
        assert_closed_outward(&m);
        assert_eq!(m.signed_volume(), 8000.0);
    }

    #[test]
    fn near_duplicate_vertices_are_merged() {
        // The soup of one triangle uses a corner moved by 1e-6 mm, so it welds to nine vertices.
        let mut soup: Vec<[Point3; 3]> = cube(20.0).triangle_corners().collect();
        soup[4][0].x += 1e-6;
        let mut m = Mesh::from_triangle_soup("near", soup);
        assert_eq!(m.vertices.len(), 9);
        assert_eq!(m.topology().boundary_edges, 4);
        let report = repair_twice(&mut m);
        assert_eq!((report.merged_vertices, report.removed_vertices), (1, 1));
        assert_eq!(report.holes_filled, 0);
        assert_eq!(m.vertices.len(), 8);
        assert_closed_outward(&m);
        assert_eq!(m.signed_volume(), 8000.0);
    }

    #[test]
    fn merging_is_transitive_free_and_keeps_the_first_position() {
        // 0 and 1 are 0.8 tol apart, 1 and 2 also, 0 and 2 1.6 tol apart: 1 joins 0, 2 stays.
        let tol = Tolerances::default().vertex_merge.mm();
        let mut m = Mesh {
            name: "chain".into(),
            vertices: vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(0.8 * tol, 0.0, 0.0),
                Point3::new(1.6 * tol, 0.0, 0.0),
            ],
            triangles: vec![[0, 1, 2]],
        };
        assert_eq!(m.merge_near_vertices(tol), 1);
        assert_eq!(m.triangles, vec![[0, 0, 2]]);
    }

    #[test]
    fn merging_matches_a_brute_force_search() {
        // Clusters of points straddling grid cell walls in every axis, from a fixed LCG.
        let tol = 1e-4;
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut rand = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut vertices = Vec::new();
        for _ in 0..300 {
            // A centre on a cell wall (cells are 2 tol wide), then points within 1.5 tol.
            let centre = [0; 3].map(|_| (rand() * 50.0).floor() * 2.0 * tol);
            for _ in 0..4 {
                let [x, y, z] = centre.map(|c| c + (rand() - 0.5) * 3.0 * tol);
                vertices.push(Point3::new(x, y, z));
            }
        }
        let n = vertices.len() as u32;
        let triangles: Vec<[u32; 3]> = (0..n)
            .step_by(3)
            .map(|i| [i, (i + 1) % n, (i + 2) % n])
            .collect();
        let mut m = Mesh {
            name: "cloud".into(),
            vertices: vertices.clone(),
            triangles: triangles.clone(),
        };
        let merged = m.merge_near_vertices(tol);
        let mut kept: Vec<usize> = Vec::new();
        let mut map = vec![0u32; vertices.len()];
        for (i, p) in vertices.iter().enumerate() {
            match kept.iter().find(|&&r| (vertices[r] - p).norm() <= tol) {
                Some(&r) => map[i] = r as u32,
                None => {
                    kept.push(i);
                    map[i] = i as u32;
                }
            }
        }
        assert!(merged > 100, "only {merged} merges: the test needs more");
        assert_eq!(merged, vertices.len() - kept.len());
        let expected: Vec<[u32; 3]> = triangles
            .iter()
            .map(|t| t.map(|v| map[v as usize]))
            .collect();
        assert_eq!(m.triangles, expected);
    }

    #[test]
    fn duplicate_facets_are_removed_in_either_orientation() {
        let mut m = cube(20.0);
        let t0 = m.triangles[0];
        m.triangles.push(t0);
        m.triangles.push([t0[2], t0[1], t0[0]]);
        assert_eq!(m.topology().non_manifold_edges, 3);
        let report = repair_twice(&mut m);
        assert_eq!(report.removed_duplicate, 2);
        assert_eq!(m.triangles, cube(20.0).triangles);
        assert_closed_outward(&m);
    }

    #[test]
    fn degenerate_facets_are_removed() {
        let mut m = cube(20.0);
        // The midpoint of edge 0-1 (a diagonal of the bottom face), so [0, 1, 8] has zero area.
        m.vertices.push(Point3::from(
            (m.vertices[0].coords + m.vertices[1].coords) / 2.0,
        ));
        m.triangles.push([0, 1, 8]);
        m.triangles.push([3, 3, 5]);
        assert_eq!(m.topology().degenerate_triangles, 2);
        let report = repair_twice(&mut m);
        assert_eq!((report.removed_degenerate, report.removed_vertices), (2, 1));
        assert_eq!(m, cube(20.0));
    }

    #[test]
    fn stray_facet_is_removed_as_unconnected() {
        let mut m = cube(20.0);
        let base = m.vertices.len() as u32;
        m.vertices.extend([
            Point3::new(50.0, 0.0, 0.0),
            Point3::new(51.0, 0.0, 0.0),
            Point3::new(50.0, 1.0, 0.0),
        ]);
        m.triangles.insert(0, [base, base + 1, base + 2]);
        let report = repair_twice(&mut m);
        assert_eq!(
            (report.removed_unconnected, report.removed_vertices),
            (1, 3)
        );
        assert_eq!(report.holes_filled, 0);
        assert_eq!(m, cube(20.0));
    }

    #[test]
    fn remove_unconnected_drops_small_shells_only() {
        let mut m = cube(10.0);
        m.append(&cube_at(5.0, 30.0));
        assert_eq!(m.clone().remove_unconnected(2), 0);
        assert_eq!(m.remove_unconnected(13), 24);
        assert!(m.triangles.is_empty());
    }

    #[test]
    fn two_disjoint_cubes_with_one_inside_out_are_both_outward() {
        let mut m = cube(10.0);
        let mut other = cube_at(10.0, 30.0);
        for t in &mut other.triangles {
            t.swap(1, 2);
        }
        m.append(&other);
        let t = m.topology();
        assert_eq!((t.shells, t.inverted_shells), (2, 1));
        let report = repair_twice(&mut m);
        assert_eq!(report.flipped_triangles, 12);
        assert_closed_outward(&m);
        assert_eq!(m.topology().shells, 2);
        assert_eq!(m.signed_volume(), 2000.0);
    }

    #[test]
    fn empty_mesh_is_left_alone() {
        let mut empty = Mesh::default();
        assert!(!repair_twice(&mut empty).changed());
    }

    #[test]
    fn cubes_stacked_face_to_face_become_one_solid() {
        // Two cubes, not welded, touching along a face. Welding makes the shared face appear
        // twice with opposite windings: an internal wall, removed entirely.
        let mut m = cube(10.0);
        let mut upper = cube(10.0);
        for v in &mut upper.vertices {
            v.z += 10.0;
        }
        m.append(&upper);
        assert_eq!(m.topology().shells, 2);
        let report = repair_twice(&mut m);
        assert_eq!((report.merged_vertices, report.removed_duplicate), (4, 4));
        assert_eq!((report.removed_vertices, report.flipped_triangles), (4, 0));
        assert_closed_outward(&m);
        assert_eq!((m.topology().shells, m.triangles.len()), (1, 20));
        assert_eq!(m.signed_volume(), 2000.0);
    }

    #[test]
    fn reversed_copy_of_a_facet_is_replaced_by_a_correct_fill() {
        let mut m = cube(20.0);
        let t = m.triangles[7];
        m.triangles.push([t[0], t[2], t[1]]);
        let report = repair_twice(&mut m);
        assert_eq!((report.removed_duplicate, report.holes_filled), (2, 1));
        assert_closed_outward(&m);
        assert_eq!(m.triangles.len(), 12);
        assert_eq!(m.signed_volume(), 8000.0);
    }

    #[test]
    fn cavity_wall_is_turned_to_face_the_cavity() {
        let mut m = cube(30.0);
        m.append(&cube_at(10.0, 10.0)); // facing out of the cavity, into the material: wrong
        let report = repair_twice(&mut m);
        assert_eq!(report.flipped_triangles, 12);
        assert_closed_outward(&m);
        assert_eq!(m.signed_volume(), 26000.0);
    }

    #[test]
    fn crack_from_a_near_miss_vertex_is_filled() {
        // One facet uses a corner 0.5 µm·√3 away from the shared one (admesh's "exact" case):
        // beyond the merge tolerance, so the crack is a four-edge hole.
        let mut soup: Vec<[Point3; 3]> = cube(20.0).triangle_corners().collect();
        soup[2][0] += Vector3::new(5e-4, 5e-4, 5e-4);
        let mut m = Mesh::from_triangle_soup("crack", soup);
        assert_eq!(m.topology().boundary_edges, 4);
        let report = repair_twice(&mut m);
        assert_eq!((report.merged_vertices, report.holes_filled), (0, 1));
        assert_eq!(report.triangles_added, 2);
        assert_closed_outward(&m);
        // The moved corner lifts the top by 5e-4 mm at one corner: a 200 mm² pyramid of that
        // height, 1/30 mm³, is added.
        let expected = 8000.0 + 200.0 * 5e-4 / 3.0;
        assert!(
            (m.signed_volume() - expected).abs() < 1e-9,
            "{}",
            m.signed_volume()
        );
    }

    /// The index of the vertex at `p`.
    fn vertex_at(m: &Mesh, p: [f64; 3]) -> u32 {
        let found = m.vertices.iter().position(|v| *v == Point3::from(p));
        found.map_or(u32::MAX, |i| i as u32)
    }

    #[test]
    fn cap_at_a_t_junction_is_split_away_and_the_mesh_stays_closed() {
        // The front face's lower triangle is split at the midpoint m of the bottom front edge,
        // and a zero-area cap [a, b, m] closes the T-junction, as CAD exports do.
        let mut m = cube(20.0);
        let a = vertex_at(&m, [0.0, 0.0, 0.0]);
        let b = vertex_at(&m, [20.0, 0.0, 0.0]);
        let top = vertex_at(&m, [20.0, 0.0, 20.0]);
        let front = m.triangles.iter().position(|&t| t == [a, b, top]);
        let Some(front) = front else {
            panic!("no front triangle [{a}, {b}, {top}] in {:?}", m.triangles);
        };
        let mid = m.vertices.len() as u32;
        m.vertices.push(Point3::new(10.0, 0.0, 0.0));
        m.triangles[front] = [a, mid, top];
        m.triangles.push([mid, b, top]);
        m.triangles.push([a, b, mid]);
        let t = m.topology();
        assert_eq!((t.closed, t.degenerate_triangles), (true, 1));
        assert_eq!(t.orientation, Orientation::Outward);
        let report = repair_twice(&mut m);
        assert_eq!(report.removed_degenerate, 1);
        assert_eq!(m.triangles.len(), 14);
        assert_closed_outward(&m);
        assert_eq!(m.topology().degenerate_triangles, 0);
        assert_eq!(m.signed_volume(), 8000.0);
        assert_eq!(m.area(), 2400.0);
    }

    #[test]
    fn stacked_caps_along_one_edge_are_all_split_away() {
        // As in admesh's conveyor: several collinear points on one long edge, each cap resting
        // on the next. The bottom front edge a-b carries points at x = 5, 10, 15.
        let mut m = cube(20.0);
        let a = vertex_at(&m, [0.0, 0.0, 0.0]);
        let b = vertex_at(&m, [20.0, 0.0, 0.0]);
        let top = vertex_at(&m, [20.0, 0.0, 20.0]);
        let Some(front) = m.triangles.iter().position(|&t| t == [a, b, top]) else {
            panic!("no front triangle");
        };
        let base = m.vertices.len() as u32;
        m.vertices
            .extend([5.0, 10.0, 15.0].map(|x| Point3::new(x, 0.0, 0.0)));
        let chain = [a, base, base + 1, base + 2, b];
        m.triangles[front] = [chain[0], chain[1], top];
        for w in chain[1..].windows(2) {
            m.triangles.push([w[0], w[1], top]);
        }
        // Caps: [a, b, p10] on the long edge, then [a, p10, p5] and [p10, b, p15] on its sides.
        m.triangles.push([a, b, base + 1]);
        m.triangles.push([a, base + 1, base]);
        m.triangles.push([base + 1, b, base + 2]);
        let t = m.topology();
        assert_eq!((t.closed, t.degenerate_triangles), (true, 3));
        let report = repair_twice(&mut m);
        assert_eq!(report.removed_degenerate, 3);
        assert_closed_outward(&m);
        assert_eq!(m.topology().degenerate_triangles, 0);
        assert_eq!(m.signed_volume(), 8000.0);
    }

    #[test]
    fn holes_touching_at_a_vertex_are_filled_separately() {
        // Remove the top triangle [4, 5, 6] and the front triangle [0, 1, 5] of the cube's
        // corner list: two three-edge holes sharing only the corner (20, 0, 20).
        let mut m = cube(20.0);
        m.triangles.remove(4);
        m.triangles.remove(2);
        let t = m.topology();
        assert_eq!((t.boundary_edges, t.non_manifold_edges), (6, 0));
        let report = repair_twice(&mut m);
        assert_eq!((report.holes_filled, report.triangles_added), (2, 2));
        assert_closed_outward(&m);
        assert_eq!(m.signed_volume(), 8000.0);
    }

    #[test]
    fn hole_larger_than_the_limit_stays_open() {
        let mut m = cube(20.0);
        m.triangles.drain(2..4);
        let tol = Tolerances {
            max_hole_edges: 3,
            ..Tolerances::default()
        };
        let report = m.repair(&tol);
        assert_eq!(report.holes_filled, 0);
        assert_eq!(m.topology().boundary_edges, 4);
        assert!(!m.repair(&tol).changed());
    }

    #[test]
    fn randomly_damaged_meshes_repair_idempotently() {
        // A cube with a cubic cavity (its wall facing the wrong way), damaged by random
        // deletions, flips, duplicates, collapsed and random facets and split vertices; repair
        // must not panic, must leave no degenerate or duplicate facet, and must be idempotent.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut rand = |n: usize| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 33) as usize) % n.max(1)
        };
        let mut outward = 0;
        for case in 0..300 {
            let mut m = cube(30.0);
            m.append(&cube_at(10.0, 10.0));
            for _ in 0..1 + rand(6) {
                let nt = m.triangles.len();
                let nv = m.vertices.len();
                let t = rand(nt);
                match rand(7) {
                    0 => {
                        m.triangles.remove(t);
                    }
                    1 => m.triangles[t].swap(0, 1),
                    2 => {
                        let mut copy = m.triangles[t];
                        if rand(2) == 0 {
                            copy.swap(1, 2);
                        }
                        m.triangles.push(copy);
                    }
                    3 => m
                        .triangles
                        .push([t as u32 % 8, t as u32 % 8, rand(nv) as u32]),
                    4 => m
                        .triangles
                        .push([rand(nv), rand(nv), rand(nv)].map(|v| v as u32)),
                    5 => {
                        // Give one corner of triangle t its own, slightly moved vertex.
                        let k = rand(3);
                        let v = m.vertices[m.triangles[t][k] as usize];
                        let offset = [1e-6, 1e-3][rand(2)];
                        m.vertices.push(v + Vector3::new(offset, 0.0, 0.0));
                        m.triangles[t][k] = nv as u32;
                    }
                    _ => {
                        let t2 = rand(nt);
                        m.triangles.swap(t, t2);
                    }
                }
                if m.triangles.is_empty() {
                    break;
                }
            }
            let mut fixed = m.clone();
            let first = fixed.repair(&Tolerances::default());
            let after = fixed.clone();
            let second = fixed.repair(&Tolerances::default());
            assert!(
                !second.changed() && fixed == after,
                "case {case}: {first:?} then {second:?}\n{m:?}"
            );
            let t = fixed.topology();
            assert_eq!(t.degenerate_triangles, 0, "case {case}");
            let mut keys: Vec<[u32; 3]> = fixed.triangles.iter().map(|&t| sorted(t)).collect();
            keys.sort_unstable();
            keys.dedup();
            assert_eq!(
                keys.len(),
                fixed.triangles.len(),
                "case {case}: duplicates left"
            );
            outward += usize::from(t.orientation == Orientation::Outward);
        }
        // The rest (71 when written) are left open on purpose: random facets hanging on one
        // existing edge (fins: non-manifold, which repair does not cut away) and cracks whose
        // only fills are degenerate or reuse an existing edge (a vertex moved 1e-3 mm along an
        // edge of its own facet).
        assert!(
            outward >= 229,
            "only {outward} of 300 repaired closed and outward"
        );
    }

    /// Reads an STL file into a mesh, or `None` if it is missing.
    fn load_stl(path: &std::path::Path) -> Option<Mesh> {
        let bytes = std::fs::read(path).ok()?;
        let stl = match conduit_stl::read(&bytes) {
            Ok(stl) => stl,
            Err(e) => panic!("{}: {e}", path.display()),
        };
        let soup = stl
            .triangles
            .iter()
            .map(|t| t.map(|[x, y, z]| Point3::new(x.into(), y.into(), z.into())));
        Some(Mesh::from_triangle_soup(path.display().to_string(), soup))
    }

    /// admesh's test pairs: `*-bad.stl` is an input with a known defect, `*-good.stl` is what
    /// admesh's matching repair option wrote. Every repaired input must come out closed and
    /// outward; its volume is compared with the reference where the reference itself is closed
    /// and outward (admesh's outputs are not always: see the printout).
    #[test]
    fn admesh_corpus_pairs_repair_closed_and_outward() {
        let root = std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../shared/corpus/admesh/test"
        ));
        if !root.is_dir() {
            println!("skipped: corpus not found");
            return;
        }
        let mut compared = 0;
        for model in ["block", "conveyor"] {
            let Ok(dir) = std::fs::read_dir(root.join(model)) else {
                println!("skipped: corpus not found");
                return;
            };
            let mut bad: Vec<_> = dir
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.to_string_lossy().ends_with("-bad.stl"))
                .collect();
            bad.sort();
            for bad_path in bad {
                let good_path = bad_path.to_string_lossy().replace("-bad.stl", "-good.stl");
                let (Some(mut mesh), Some(good)) = (
                    load_stl(&bad_path),
                    load_stl(std::path::Path::new(&good_path)),
                ) else {
                    continue;
                };
                let name = bad_path.strip_prefix(root).unwrap_or(&bad_path).display();
                let before = mesh.topology();
                let report = mesh.repair(&Tolerances::default());
                let after = mesh.topology();
                let good_topology = good.topology();
                let (volume, good_volume) = (mesh.signed_volume(), good.signed_volume());
                println!(
                    "{name}: before {:?} boundary {} inconsistent {}; repair {report:?}; \
                     after {:?} volume {volume:.6}; \
                     reference {:?} closed {} volume {good_volume:.6}",
                    before.orientation,
                    before.boundary_edges,
                    before.inconsistent_edges,
                    after.orientation,
                    good_topology.orientation,
                    good_topology.closed,
                );
                assert!(after.closed, "{name}: {after:?}");
                assert_eq!(after.non_manifold_edges, 0, "{name}");
                assert_eq!(after.orientation, Orientation::Outward, "{name}: {after:?}");
                assert!(!mesh.repair(&Tolerances::default()).changed(), "{name}");
                if good_topology.orientation == Orientation::Outward {
                    let diff = (volume - good_volume).abs() / good_volume;
                    println!(
                        "  compared with the reference: relative volume difference {diff:.2e}"
                    );
                    assert!(diff < 0.01, "{name}: {volume} vs {good_volume}");
                    compared += 1;
                } else {
                    // Not a usable reference as it stands; repaired, it shows whether the two
                    // files describe the same solid (printed, not asserted).
                    let mut fixed = good.clone();
                    fixed.repair(&Tolerances::default());
                    let fixed_volume = fixed.signed_volume();
                    println!(
                        "  reference not closed and outward; repaired reference {:?} volume \
                         {fixed_volume:.6}, relative difference {:.2e}",
                        fixed.topology().orientation,
                        (volume - fixed_volume).abs() / fixed_volume.abs()
                    );
                }
            }
        }
        assert!(compared > 0, "no reference was closed and outward");
    }

    #[test]
    fn non_convex_hole_is_ear_clipped_inside_its_outline() {
        // An L-shaped hole in the top of an L-shaped prism: the fill must not cover the notch.
        let outline = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)];
        let n = outline.len() as u32;
        let mut m = Mesh::default();
        for z in [0.0, 1.0] {
            m.vertices
                .extend(outline.iter().map(|&(x, y)| Point3::new(x, y, z)));
        }
        for i in 0..n {
            let j = (i + 1) % n;
            m.triangles.push([i, j, n + j]);
            m.triangles.push([i, n + j, n + i]);
        }
        // Bottom as a fan from vertex 0 (valid for this L), wound downwards.
        for i in 1..n - 1 {
            m.triangles.push([0, i + 1, i]);
        }
        let report = repair_twice(&mut m);
        assert_eq!((report.holes_filled, report.triangles_added), (1, 4));
        assert_closed_outward(&m);
        assert!((m.signed_volume() - 3.0).abs() < 1e-12);
        assert!((m.area() - 14.0).abs() < 1e-12);
    }
}
