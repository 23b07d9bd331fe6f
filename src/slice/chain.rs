//! Chaining the directed segments of one slicing plane into closed loops.
//!
//! Two stages, after libslic3r's `TriangleMeshSlicer::make_loops`:
//!
//! 1. **Topological**: every segment starts on one mesh edge and ends on another (edges named by
//!    their vertex pair). A segment ending on edge `e` continues with the segment starting on `e`,
//!    which is the neighbouring triangle's. On a closed, consistently oriented mesh this closes
//!    every loop exactly, whatever the coordinates.
//! 2. **Gaps**: chains left open (holes in the mesh, flipped triangles, non-manifold edges) are
//!    joined end to start, nearest endpoints first: exact coincidences before gaps, same direction
//!    before reversed, shorter gaps before longer ones, up to `max_gap`. A chain whose end meets its
//!    own start closes on itself. Chains that still end nowhere are dropped and counted.

use crate::geom::{Coord, Point2, Polygon};

/// A directed slice segment, already on the nanometre grid: the solid lies to its left.
#[derive(Debug, Clone, Copy)]
pub(super) struct Segment {
    /// Start point.
    pub a: Point2,
    /// End point.
    pub b: Point2,
    /// Key of the mesh edge `a` lies on.
    pub a_edge: u64,
    /// Key of the mesh edge `b` lies on.
    pub b_edge: u64,
}

/// The loops of one plane and what it took to close them.
#[derive(Debug, Default)]
pub(super) struct Loops {
    /// Closed contours, in the mesh's orientation (CCW around solid, CW around holes) except
    /// loops patched from reversed pieces, which are made CCW.
    pub polygons: Vec<Polygon>,
    /// Open chains that ended up in a closed loop.
    pub closed: usize,
    /// Open chains dropped because no endpoint lay within `max_gap`.
    pub dropped: usize,
}

/// The first unused segment index with `key` in `sorted` (sorted by key, then index).
fn take_unused(sorted: &[(u64, u32)], key: u64, used: &mut [bool]) -> Option<usize> {
    let from = sorted.partition_point(|&(k, _)| k < key);
    for &(k, i) in &sorted[from..] {
        if k != key {
            break;
        }
        let i = i as usize;
        if !used[i] {
            used[i] = true;
            return Some(i);
        }
    }
    None
}

/// Marks every segment identical to an earlier one (same edges, same points) as used, so only
/// the first copy is chained. Duplicate triangles (a file listing one face thousands of times)
/// cut identical segments; each copy would otherwise be an open chain of its own, and the gap
/// stage pairs every open endpoint with every other at the same point: quadratic in the copies.
/// A closed, manifold mesh has no two such segments (two triangles share at most one edge), so
/// its loops are unchanged. `starts` is the segments sorted by start edge.
fn mark_duplicates(segments: &[Segment], starts: &[(u64, u32)], used: &mut [bool]) {
    let key = |i: u32| {
        let s = &segments[i as usize];
        (s.a_edge, s.b_edge, s.a.x, s.a.y, s.b.x, s.b.y)
    };
    for run in starts.chunk_by(|x, y| x.0 == y.0) {
        if run.len() < 2 {
            continue;
        }
        // Within a run of one start edge, by the rest of the key, then by index.
        let mut ids: Vec<u32> = run.iter().map(|&(_, i)| i).collect();
        ids.sort_unstable_by_key(|&i| (key(i), i));
        for pair in ids.windows(2) {
            if key(pair[0]) == key(pair[1]) {
                used[pair[1] as usize] = true;
            }
        }
    }
}

/// Appends `p` unless it repeats the last point.
fn push_point(points: &mut Vec<Point2>, p: Point2) {
    if points.last() != Some(&p) {
        points.push(p);
    }
}

/// Chains `segments` into loops; see the module docs. `max_gap` is in scaled units.
pub(super) fn chain_segments(segments: &[Segment], max_gap: Coord) -> Loops {
    let n = segments.len();
    let sorted = |f: fn(&Segment) -> u64| {
        let mut v: Vec<(u64, u32)> = segments
            .iter()
            .enumerate()
            .map(|(i, s)| (f(s), i as u32))
            .collect();
        v.sort_unstable();
        v
    };
    let starts = sorted(|s| s.a_edge);
    let ends = sorted(|s| s.b_edge);
    let mut used = vec![false; n];
    mark_duplicates(segments, &starts, &mut used);
    let mut out = Loops::default();
    let mut open: Vec<Vec<Point2>> = Vec::new();
    let mut forward: Vec<usize> = Vec::new();
    let mut backward: Vec<usize> = Vec::new();

    for seed in 0..n {
        if used[seed] {
            continue;
        }
        used[seed] = true;
        forward.clear();
        backward.clear();
        forward.push(seed);
        let start_key = segments[seed].a_edge;
        let mut key = segments[seed].b_edge;
        let mut closed = false;
        loop {
            if key == start_key {
                closed = true;
                break;
            }
            match take_unused(&starts, key, &mut used) {
                Some(j) => {
                    forward.push(j);
                    key = segments[j].b_edge;
                }
                None => break,
            }
        }
        if !closed {
            // The seed may sit in the middle of an open chain: extend it backwards too. (A
            // backward step can never close the loop: the forward walk would have taken it.)
            let mut key = start_key;
            while let Some(j) = take_unused(&ends, key, &mut used) {
                backward.push(j);
                key = segments[j].a_edge;
            }
        }
        let mut points = Vec::with_capacity(forward.len() + backward.len() + 1);
        for &j in backward.iter().rev().chain(forward.iter()) {
            push_point(&mut points, segments[j].a);
        }
        if closed {
            if points.len() > 1 && points.first() == points.last() {
                points.pop();
            }
            if points.len() >= 3 {
                out.polygons.push(Polygon::new(points));
            }
        } else {
            if let Some(&last) = forward.last() {
                push_point(&mut points, segments[last].b);
            }
            open.push(points);
        }
    }
    if !open.is_empty() {
        close_gaps(open, max_gap, &mut out);
    }
    out
}

/// Endpoint ids: `2·chain` is a chain's start, `2·chain + 1` its end.
fn endpoint(chains: &[Vec<Point2>], id: usize) -> Point2 {
    let c = &chains[id / 2];
    if id % 2 == 0 { c[0] } else { c[c.len() - 1] }
}

/// Joins open chains across gaps up to `max_gap` (stage 2 of the module docs).
fn close_gaps(chains: Vec<Vec<Point2>>, max_gap: Coord, out: &mut Loops) {
    let chains: Vec<Vec<Point2>> = chains.into_iter().filter(|c| !c.is_empty()).collect();
    let k = chains.len();
    let max_d2 = (max_gap as i128) * (max_gap as i128);

    // Candidate pairs by a sweep over x.
    let mut ids: Vec<usize> = (0..2 * k).collect();
    ids.sort_by_key(|&id| {
        let p = endpoint(&chains, id);
        (p.x, p.y, id)
    });
    // (exact?, reversed?, distance², p, q): sorting puts exact before gaps, same direction before
    // reversed, near before far, and breaks ties by endpoint id so the result is deterministic.
    let mut candidates: Vec<(bool, bool, i128, usize, usize)> = Vec::new();
    for (n, &p) in ids.iter().enumerate() {
        let pp = endpoint(&chains, p);
        for &q in &ids[n + 1..] {
            let pq = endpoint(&chains, q);
            if (pq.x - pp.x) as i128 > max_gap as i128 {
                break;
            }
            let d2 = pp.distance_squared(pq);
            if d2 > max_d2 {
                continue;
            }
            let same_kind = p % 2 == q % 2;
            if p / 2 == q / 2 && same_kind {
                continue;
            }
            let (lo, hi) = (p.min(q), p.max(q));
            candidates.push((d2 != 0, same_kind, d2, lo, hi));
        }
    }
    candidates.sort_unstable();
    let mut partner: Vec<Option<usize>> = vec![None; 2 * k];
    for &(_, _, _, p, q) in &candidates {
        if partner[p].is_none() && partner[q].is_none() {
            partner[p] = Some(q);
            partner[q] = Some(p);
        }
    }

    let mut visited = vec![false; k];
    // Paths first: they start at an endpoint without partner and are dropped.
    for id in 0..2 * k {
        if partner[id].is_some() || visited[id / 2] {
            continue;
        }
        let mut e = id;
        loop {
            visited[e / 2] = true;
            out.dropped += 1;
            match partner[e ^ 1] {
                Some(f) if !visited[f / 2] => e = f,
                _ => break,
            }
        }
    }
    // What is left are cycles: walk each from its lowest chain, entered at its start.
    for c in 0..k {
        if visited[c] {
            continue;
        }
        let mut points: Vec<Point2> = Vec::new();
        let mut any_reversed = false;
        let mut e = 2 * c;
        loop {
            let chain = &chains[e / 2];
            visited[e / 2] = true;
            out.closed += 1;
            if e % 2 == 0 {
                chain.iter().for_each(|&p| push_point(&mut points, p));
            } else {
                any_reversed = true;
                chain.iter().rev().for_each(|&p| push_point(&mut points, p));
            }
            match partner[e ^ 1] {
                Some(f) if !visited[f / 2] => e = f,
                _ => break,
            }
        }
        if points.len() > 1 && points.first() == points.last() {
            points.pop();
        }
        if points.len() >= 3 {
            let mut polygon = Polygon::new(points);
            // Pieces of mixed orientation: the loop's own orientation means nothing. Make it
            // CCW (solid), as libslic3r does; this may fill a cavity but never loses material.
            if any_reversed && !polygon.is_counter_clockwise() {
                polygon.points.reverse();
            }
            out.polygons.push(polygon);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(a: (i64, i64), b: (i64, i64), ka: u64, kb: u64) -> Segment {
        Segment {
            a: Point2::new(a.0, a.1),
            b: Point2::new(b.0, b.1),
            a_edge: ka,
            b_edge: kb,
        }
    }

    #[test]
    fn square_chains_topologically_in_any_order() {
        let segs = [
            seg((10, 0), (10, 10), 2, 3),
            seg((0, 10), (0, 0), 4, 1),
            seg((0, 0), (10, 0), 1, 2),
            seg((10, 10), (0, 10), 3, 4),
        ];
        let l = chain_segments(&segs, 0);
        assert_eq!(l.polygons.len(), 1);
        assert_eq!(l.polygons[0].signed_area2(), 200);
        assert_eq!((l.closed, l.dropped), (0, 0));
    }

    #[test]
    fn gap_and_reversed_piece_are_joined() {
        // Two halves of a square; the second was produced by flipped triangles (reversed) and
        // there is a 1-unit gap at one junction.
        let segs = [
            seg((0, 0), (10, 0), 1, 2),
            seg((10, 0), (10, 10), 2, 3),
            // reversed half: runs (0,0) -> (0,10) -> (10,10)
            seg((0, 1), (0, 10), 10, 11),
            seg((0, 10), (10, 10), 11, 12),
        ];
        let l = chain_segments(&segs, 5);
        assert_eq!(l.polygons.len(), 1);
        assert!(l.polygons[0].is_counter_clockwise());
        assert_eq!((l.closed, l.dropped), (2, 0));
        let l = chain_segments(&segs, 0);
        assert!(l.polygons.is_empty());
        assert_eq!((l.closed, l.dropped), (0, 2));
    }
}
