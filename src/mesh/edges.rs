//! The undirected edge table shared by validation ([`super::topology`]) and repair
//! ([`super::repair`]): which triangle sides meet at each edge, plus a small union-find.
//!
//! Built without hashing: half-edges are bucketed by their lower vertex index (a counting sort),
//! then each bucket is sorted by the upper index. Buckets hold a handful of entries, so building
//! the table is linear in practice, and the result does not depend on any hash iteration order.

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// A triangle side: triangle index times three plus the side `k`, where side `k` runs from
/// corner `k` to corner `(k + 1) % 3`.
pub(crate) type Side = u32;

/// Marks a side that belongs to no edge (a side of a triangle with a repeated vertex index).
pub(crate) const NO_EDGE: u32 = u32::MAX;

/// The undirected edges of a triangle list.
///
/// Triangles with a repeated vertex index ("collapsed") take no part: their sides map to
/// [`NO_EDGE`].
#[derive(Debug, Clone)]
pub(crate) struct EdgeTable {
    /// Sides grouped by undirected edge; edge `e` owns `sides[starts[e]..starts[e + 1]]`, in
    /// increasing side order.
    sides: Vec<Side>,
    /// Run starts into `sides`, one per edge plus a final sentinel.
    starts: Vec<u32>,
    /// The edge of each side (`3 * triangles.len()` entries), or [`NO_EDGE`].
    edge_of: Vec<u32>,
    /// The higher vertex index of each edge.
    upper: Vec<u32>,
    /// Edges are ordered by their lower vertex index `v`; those of `v` are
    /// `first_edge[v]..first_edge[v + 1]`.
    first_edge: Vec<u32>,
}

/// Whether a triangle repeats a vertex index.
pub(crate) fn is_collapsed(t: &[u32; 3]) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[2] == t[0]
}

/// The directed side `s` of `triangles` as `(from, to)` vertex indices.
pub(crate) fn side_vertices(triangles: &[[u32; 3]], s: Side) -> (u32, u32) {
    let t = &triangles[(s / 3) as usize];
    let k = (s % 3) as usize;
    (t[k], t[(k + 1) % 3])
}

impl EdgeTable {
    /// Builds the table for `triangles`.
    pub(crate) fn new(triangles: &[[u32; 3]]) -> EdgeTable {
        let vertex_count = triangles
            .iter()
            .flat_map(|t| t.iter())
            .max()
            .map_or(0, |&m| m as usize + 1);
        // Counting sort of the sides by their lower vertex.
        let mut bucket = vec![0u32; vertex_count + 1];
        for t in triangles.iter().filter(|t| !is_collapsed(t)) {
            for k in 0..3 {
                bucket[t[k].min(t[(k + 1) % 3]) as usize + 1] += 1;
            }
        }
        for i in 1..bucket.len() {
            bucket[i] += bucket[i - 1];
        }
        let total = bucket[vertex_count] as usize;
        // (upper vertex, side), filled in side order so each bucket starts sorted by side.
        let mut entries = vec![(0u32, 0u32); total];
        let mut fill = bucket.clone();
        for (ti, t) in triangles.iter().enumerate() {
            if is_collapsed(t) {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let slot = &mut fill[a.min(b) as usize];
                entries[*slot as usize] = (a.max(b), ti as u32 * 3 + k as u32);
                *slot += 1;
            }
        }
        let mut edge_of = vec![NO_EDGE; triangles.len() * 3];
        let mut starts = Vec::with_capacity(total / 2 + 1);
        let mut sides = Vec::with_capacity(total);
        let mut upper = Vec::with_capacity(total / 2);
        let mut first_edge = Vec::with_capacity(vertex_count + 1);
        for v in 0..vertex_count {
            first_edge.push(starts.len() as u32);
            let run = &mut entries[bucket[v] as usize..bucket[v + 1] as usize];
            run.sort_unstable();
            let mut prev = None;
            for &(hi, side) in run.iter() {
                if prev != Some(hi) {
                    starts.push(sides.len() as u32);
                    upper.push(hi);
                    prev = Some(hi);
                }
                edge_of[side as usize] = (starts.len() - 1) as u32;
                sides.push(side);
            }
        }
        starts.push(sides.len() as u32);
        first_edge.push(starts.len() as u32 - 1);
        EdgeTable {
            sides,
            starts,
            edge_of,
            upper,
            first_edge,
        }
    }

    /// The number of undirected edges.
    pub(crate) fn len(&self) -> usize {
        self.starts.len() - 1
    }

    /// The sides meeting at edge `e`, in increasing order.
    pub(crate) fn sides(&self, e: usize) -> &[Side] {
        &self.sides[self.starts[e] as usize..self.starts[e + 1] as usize]
    }

    /// The edge of side `s`, or `None` for a side of a collapsed triangle.
    pub(crate) fn edge_of(&self, s: Side) -> Option<usize> {
        let e = self.edge_of[s as usize];
        (e != NO_EDGE).then_some(e as usize)
    }

    /// The edge joining vertices `a` and `b`, if some triangle has it.
    pub(crate) fn find(&self, a: u32, b: u32) -> Option<usize> {
        let (lo, hi) = (a.min(b) as usize, a.max(b));
        if lo + 1 >= self.first_edge.len() {
            return None;
        }
        let range = self.first_edge[lo] as usize..self.first_edge[lo + 1] as usize;
        let i = self.upper[range.clone()].binary_search(&hi).ok()?;
        Some(range.start + i)
    }

    /// The one other side sharing side `s`'s edge, if that edge is manifold (exactly two sides).
    pub(crate) fn twin(&self, s: Side) -> Option<Side> {
        let sides = self.sides(self.edge_of(s)?);
        match sides {
            [a, b] if *a == s => Some(*b),
            [a, b] if *b == s => Some(*a),
            _ => None,
        }
    }
}

/// Union-find over `0..n` with path halving; the root of a set is always its smallest member, so
/// results do not depend on the order of unions.
#[derive(Debug, Clone)]
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` singleton sets.
    pub(crate) fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    /// The smallest member of `x`'s set.
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grand = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grand;
            x = grand;
        }
        x
    }

    /// Joins the sets of `a` and `b`.
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra < rb {
            self.parent[rb as usize] = ra;
        } else if rb < ra {
            self.parent[ra as usize] = rb;
        }
    }
}

/// A fast, deterministic hasher for the small integer keys of mesh code (vertex indices, grid
/// cells): the FxHash mixing step per word plus a final avalanche, so the low bits that pick a
/// bucket depend on every input bit. Not resistant to adversarial keys; mesh keys are not chosen
/// by an adversary and a bad case only costs time.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct FastHasher(u64);

impl FastHasher {
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl Hasher for FastHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.add(u64::from_le_bytes(word));
        }
    }

    fn write_u32(&mut self, n: u32) {
        self.add(n.into());
    }

    fn write_u64(&mut self, n: u64) {
        self.add(n);
    }

    fn write_i64(&mut self, n: i64) {
        self.add(n as u64);
    }

    fn write_usize(&mut self, n: usize) {
        self.add(n as u64);
    }

    fn finish(&self) -> u64 {
        let h = (self.0 ^ (self.0 >> 32)).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        h ^ (h >> 29)
    }
}

/// A `HashMap` with [`FastHasher`]. Never iterated where the order could leak into a result.
pub(crate) type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<FastHasher>>;

/// A `HashSet` with [`FastHasher`].
pub(crate) type FastSet<K> = HashSet<K, BuildHasherDefault<FastHasher>>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_triangles_share_one_manifold_edge() {
        let tris = [[0, 1, 2], [2, 1, 3], [4, 4, 5]];
        let table = EdgeTable::new(&tris);
        assert_eq!(table.len(), 5);
        // Side 0 of triangle 0 runs 1 -> 2; side 0 of triangle 1 runs 2 -> 1.
        assert_eq!(table.twin(1), Some(3));
        assert_eq!(table.twin(3), Some(1));
        assert_eq!(table.twin(0), None);
        assert_eq!(table.edge_of(6), None);
        assert_eq!(side_vertices(&tris, 4), (1, 3));
        assert_eq!(table.find(2, 1), table.edge_of(1));
        assert_eq!(table.find(0, 3), None);
        assert_eq!(table.find(7, 9), None);
        assert!(table.find(5, 4).is_none());
    }

    #[test]
    fn union_find_roots_are_smallest_members() {
        let mut uf = UnionFind::new(5);
        uf.union(4, 3);
        uf.union(3, 1);
        assert_eq!(uf.find(4), 1);
        assert_eq!(uf.find(0), 0);
    }
}
