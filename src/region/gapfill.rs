//! Gap fill: variable-width centrelines for strips too narrow for another perimeter loop.
//!
//! Place in the pipeline: stage "regions", after [`super::perimeters`] (which leaves the gaps
//! between loops) and before the Program stage (which turns a [`ThickPolyline`] into toolpaths
//! whose width follows the thickness, see [`split_by_width`]).
//!
//! Method: a medial-axis approximation by the *chordal axis transform*. Each gap's rings are
//! resampled and inserted as constraint edges into a constrained Delaunay triangulation (spade,
//! `f64` mm). Triangles inside the gap (even-odd) are kept. Their non-boundary ("internal") edges
//! are chords across the strip, and the axis joins chord midpoints:
//! - 2 internal edges: the segment between their midpoints;
//! - 3 (junction): the centroid to each midpoint;
//! - 1 (terminal): from the internal edge's midpoint straight on, in the direction of the axis
//!   coming in from the neighbour, until it leaves the triangle: a square end is filled up to
//!   the middle of its end edge at the strip's own width, a taper up to its tip. Where that is
//!   ill-defined (no neighbour axis, or an exit closer than half the fallback), the fallback is
//!   the midline to the shorter boundary edge, i.e. halfway to the opposite vertex along the
//!   longer one;
//! - 0 (isolated): the midline between the two shorter edges.
//!
//! Widths preserve area: each triangle's area is shared among its segments (a third each at a
//! junction, all of it otherwise) and thickness = area / length, so Σ thickness·length is the
//! gap area minus the dropped pieces. A midline parallel to an edge gets the triangle's height
//! over that edge, i.e. the local gap width. Segments are chained into maximal polylines between
//! nodes of degree ≠ 2, and at each junction the two that run on most nearly straight through it
//! are joined into one (one travel fewer); midpoints are graph nodes keyed by the CDT edge, never
//! by coordinates.

use crate::geom::{ExPolygon, Point2, Polygon, unscaled};
use spade::Triangulation;
use spade::handles::{FixedFaceHandle, FixedVertexHandle, InnerTag};

/// A spade point in mm.
type Sp = spade::Point2<f64>;
/// A CDT whose undirected-edge data is the parity of how many ring edges cover the edge.
type Cdt = spade::ConstrainedDelaunayTriangulation<Sp, (), bool>;

/// Boundary edges are resampled to at most `max_width` clamped to this range (mm). Chords no
/// more than about a strip width apart stay nearly perpendicular to the strip, so the chordal
/// axis follows the true medial axis through bends and corners; on straight parallel sides any
/// spacing is exact. Below 0.1 mm (8× the region simplification resolution) we would only add
/// triangles; above 0.5 mm curved gaps get a visibly faceted axis.
const EDGE_MM: (f64, f64) = (0.1, 0.5);
/// Segments shorter than this (mm) are skipped: their thickness would be meaningless.
const MIN_SEGMENT_MM: f64 = 1e-6;
/// How far from a junction (mm) a branch's heading is taken when the straightest pair of
/// branches through it is joined: a few strip widths, past the junction's own triangle.
const HEADING_MM: f64 = 1.0;
/// At most this many pieces per resampled edge, so absurd coordinates cannot exhaust memory.
const MAX_PIECES: f64 = 65_536.0;

/// A centreline whose thickness varies along it.
#[derive(Debug, Clone, PartialEq)]
pub struct ThickPolyline {
    /// Points in order (scaled integer coordinates, see [`crate::geom`]). A closed polyline
    /// repeats its first point at the end.
    pub points: Vec<Point2>,
    /// Thickness of the segment from `points[i]` to `points[i + 1]`, mm (so
    /// `widths.len() + 1 == points.len()`). Thickness is the width of the strip of material the
    /// segment stands for, i.e. the extrusion *spacing* in the flow model of
    /// [`super::params`] (extrusion width = thickness + height·(1 − π/4)).
    pub widths: Vec<f64>,
    /// Whether the last point connects back to the first (it then equals the first point, so
    /// there is no extra closing segment and no seam gap to leave).
    pub closed: bool,
}

/// Variable-width centrelines filling `gaps` (mm limits): parts thinner than `min_width` are
/// left empty, thicker than `max_width` are clamped.
///
/// Branches from a junction to a free end shorter than the mean thickness of themselves or of a
/// longer chain at the junction are pruned (axis spurs into convex corners and small bumps; their
/// area is lost), then chains shorter than `min_width` are dropped. Degenerate or self-intersecting gaps never panic; they just give fewer lines.
/// The output is deterministic and independent of the thread count.
pub fn gap_fill(gaps: &[ExPolygon], min_width: f64, max_width: f64) -> Vec<ThickPolyline> {
    if !(min_width.is_finite() && max_width.is_finite() && max_width > 0.0) {
        return Vec::new();
    }
    let min_width = min_width.max(0.0);
    let max_edge = max_width.clamp(EDGE_MM.0, EDGE_MM.1);
    let mut out = Vec::new();
    for gap in gaps {
        let rings: Vec<Vec<Sp>> = std::iter::once(&gap.contour)
            .chain(&gap.holes)
            .map(|r| resample(r, max_edge))
            .filter(|r| r.len() >= 3)
            .collect();
        if let Some((cdt, inside)) = triangulate(&rings) {
            let mut g = chordal_axis(&cdt, &inside, min_width, max_width);
            g.prune_spurs();
            let chains = g.joined_at_junctions(g.chains());
            out.extend(chains.into_iter().filter_map(|c| g.polyline(&c, min_width)));
        }
    }
    out
}

/// `line` split into runs of nearly constant thickness: consecutive segments join a run while
/// their thickness stays within `tolerance` mm of the run's length-weighted mean; each run's
/// thickness is that mean, so Σ thickness·length is kept. Returns (points, thickness) per run;
/// runs share their end points.
pub fn split_by_width(line: &ThickPolyline, tolerance: f64) -> Vec<(Vec<Point2>, f64)> {
    let tol = if tolerance >= 0.0 { tolerance } else { 0.0 };
    let n = line.widths.len().min(line.points.len().saturating_sub(1));
    let len = |i: usize| (line.points[i].distance_squared(line.points[i + 1]) as f64).sqrt() / 1e6;
    let mean =
        |(l, tl, lo, hi): (f64, f64, f64, f64)| if l > 0.0 { tl / l } else { (lo + hi) / 2.0 };
    let mut runs = Vec::new();
    let mut i = 0;
    while i < n {
        let w = line.widths[i];
        let mut acc = (len(i), len(i) * w, w, w);
        let mut j = i + 1;
        while j < n {
            let (l, w) = (len(j), line.widths[j]);
            let next = (acc.0 + l, acc.1 + l * w, acc.2.min(w), acc.3.max(w));
            let m = mean(next);
            if next.3 - m > tol || m - next.2 > tol {
                break;
            }
            acc = next;
            j += 1;
        }
        runs.push((line.points[i..=j].to_vec(), mean(acc)));
        i = j;
    }
    runs
}

/// `ring` in mm without repeated points, with no edge longer than `max_edge`.
fn resample(ring: &Polygon, max_edge: f64) -> Vec<Sp> {
    let mut pts: Vec<Sp> = ring
        .points
        .iter()
        .map(|p| Sp::new(unscaled(p.x), unscaled(p.y)))
        .collect();
    pts.dedup();
    while pts.len() > 1 && pts.first() == pts.last() {
        pts.pop();
    }
    let mut out = Vec::with_capacity(pts.len());
    for (i, &a) in pts.iter().enumerate() {
        let b = pts[(i + 1) % pts.len()];
        let pieces = ((a.distance_2(b).sqrt() / max_edge).ceil()).clamp(1.0, MAX_PIECES) as usize;
        out.extend((0..pieces).map(|k| {
            let f = k as f64 / pieces as f64;
            Sp::new(a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f)
        }));
    }
    out
}

/// The CDT of `rings` and, per face index, whether the face is inside (even-odd); `None` when
/// nothing could be triangulated.
fn triangulate(rings: &[Vec<Sp>]) -> Option<(Cdt, Vec<bool>)> {
    let mut cdt = Cdt::new();
    let mut handles: Vec<Vec<FixedVertexHandle>> = Vec::with_capacity(rings.len());
    // All vertices first: inserting a vertex on a constraint edge would split it and lose the
    // parity stored on it.
    for ring in rings {
        handles.push(
            ring.iter()
                .map(|&p| cdt.insert(p))
                .collect::<Result<_, _>>()
                .ok()?,
        );
    }
    let mut crossing = false;
    for hs in &handles {
        for (i, &a) in hs.iter().enumerate() {
            let b = hs[(i + 1) % hs.len()];
            if a == b {
                continue;
            }
            // Never panics: an edge crossing an earlier constraint is refused (empty result).
            let edges = cdt.try_add_constraint(a, b);
            crossing |= edges.is_empty();
            for e in edges {
                let parity = cdt.undirected_edge_data_mut(e.as_undirected()).data_mut();
                *parity = !*parity;
            }
        }
    }
    if cdt.num_inner_faces() == 0 {
        return None;
    }
    let inside = if crossing {
        // A refused edge breaks the parity walk; fall back to testing each centroid (O(faces ×
        // vertices), only for self-intersecting input).
        let mut inside = vec![false; cdt.num_all_faces()];
        for f in cdt.inner_faces() {
            inside[f.fix().index()] = even_odd(rings, f.center());
        }
        inside
    } else {
        parity_fill(&cdt)
    };
    Some((cdt, inside))
}

/// Inside flags by walking from the convex hull and toggling across odd-covered edges.
fn parity_fill(cdt: &Cdt) -> Vec<bool> {
    let mut state: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let mut stack: Vec<(FixedFaceHandle<InnerTag>, bool)> = Vec::new();
    for f in cdt.inner_faces() {
        for e in f.adjacent_edges() {
            if e.rev().face().is_outer() {
                stack.push((f.fix(), *e.as_undirected().data().data()));
            }
        }
    }
    while let Some((f, s)) = stack.pop() {
        if state[f.index()].is_some() {
            continue;
        }
        state[f.index()] = Some(s);
        for e in cdt.face(f).adjacent_edges() {
            if let Some(nb) = e.rev().face().as_inner() {
                if state[nb.fix().index()].is_none() {
                    stack.push((nb.fix(), s ^ *e.as_undirected().data().data()));
                }
            }
        }
    }
    state.into_iter().map(|s| s == Some(true)).collect()
}

/// Even-odd point-in-rings test.
fn even_odd(rings: &[Vec<Sp>], p: Sp) -> bool {
    let mut inside = false;
    for r in rings {
        for (i, a) in r.iter().enumerate() {
            let b = r[(i + 1) % r.len()];
            if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (b.x - a.x) * (p.y - a.y) / (b.y - a.y) {
                inside = !inside;
            }
        }
    }
    inside
}

/// A chain of the axis: its nodes and the segments between them.
type Chain = (Vec<usize>, Vec<usize>);

/// One piece of the axis: node indices, length (mm) and thickness (mm, clamped).
#[derive(Debug, Clone, Copy)]
struct Seg {
    ends: [usize; 2],
    len: f64,
    width: f64,
}

/// The axis graph: nodes (mm) and segments, with edge midpoints shared by CDT edge index.
#[derive(Default)]
struct Graph {
    nodes: Vec<Sp>,
    edge_node: Vec<Option<usize>>,
    segs: Vec<Seg>,
    alive: Vec<bool>,
    limits: (f64, f64),
}

impl Graph {
    fn node(&mut self, p: Sp) -> usize {
        self.nodes.push(p);
        self.nodes.len() - 1
    }

    /// The node at the midpoint of CDT edge `e`, created once.
    fn edge_node(&mut self, e: usize, p: Sp) -> usize {
        if let Some(n) = self.edge_node[e] {
            return n;
        }
        let n = self.node(p);
        self.edge_node[e] = Some(n);
        n
    }

    /// Adds the segment `a`–`b` standing for `area` mm², unless it is thinner than the minimum.
    fn add(&mut self, a: usize, b: usize, area: f64) {
        let len = self.nodes[a].distance_2(self.nodes[b]).sqrt();
        let width = area / len;
        if len >= MIN_SEGMENT_MM && width >= self.limits.0 {
            let width = width.min(self.limits.1);
            self.segs.push(Seg {
                ends: [a, b],
                len,
                width,
            });
            self.alive.push(true);
        }
    }

    /// Live segments at each node, in segment order.
    fn adjacency(&self) -> Vec<Vec<usize>> {
        let mut adj = vec![Vec::new(); self.nodes.len()];
        for (i, s) in self.segs.iter().enumerate().filter(|(i, _)| self.alive[*i]) {
            adj[s.ends[0]].push(i);
            adj[s.ends[1]].push(i);
        }
        adj
    }

    /// Maximal chains of live segments as (nodes, segments): first those starting at nodes of
    /// degree ≠ 2, then closed loops (whose last node is their first).
    fn chains(&self) -> Vec<Chain> {
        let adj = self.adjacency();
        let mut used = vec![false; self.segs.len()];
        let mut out = Vec::new();
        for loops in [false, true] {
            for start in (0..adj.len()).filter(|&n| loops || adj[n].len() != 2) {
                while let Some(&first) = adj[start].iter().find(|&&s| !used[s]) {
                    let (mut nodes, mut segs, mut s) = (vec![start], Vec::new(), first);
                    loop {
                        used[s] = true;
                        segs.push(s);
                        let [a, b] = self.segs[s].ends;
                        let cur = if nodes[nodes.len() - 1] == a { b } else { a };
                        nodes.push(cur);
                        if cur == start || adj[cur].len() != 2 {
                            break;
                        }
                        match adj[cur].iter().find(|&&x| !used[x]) {
                            Some(&x) => s = x,
                            None => break,
                        }
                    }
                    out.push((nodes, segs));
                }
            }
        }
        out
    }

    /// Removes branches from a free end to a junction that are shorter than the mean thickness
    /// of themselves or of a longer chain at that junction: the chordal (and true) medial axis
    /// sends such branches into convex corners and bumps, all within about one bead width. A
    /// junction left with one chain gets that chain extended instead (see the body).
    fn prune_spurs(&mut self) {
        let adj = self.adjacency();
        // Per junction, the pruned spurs' free ends and areas (mm²), in a fixed order.
        let mut pruned: std::collections::BTreeMap<usize, Vec<(usize, f64)>> = Default::default();
        let chains = self.chains();
        let mut at = vec![Vec::new(); self.nodes.len()];
        let stats: Vec<(f64, f64)> = chains
            .iter()
            .enumerate()
            .map(|(k, (nodes, segs))| {
                at[nodes[0]].push(k);
                at[nodes[nodes.len() - 1]].push(k);
                let (len, area) = self.measure(segs);
                (len, area / len)
            })
            .collect();
        for ((nodes, segs), &(len, mean)) in chains.iter().zip(&stats) {
            let j = match (adj[nodes[0]].len(), adj[nodes[nodes.len() - 1]].len()) {
                (1, d) if d >= 3 => nodes[nodes.len() - 1],
                (d, 1) if d >= 3 => nodes[0],
                _ => continue,
            };
            let longer = at[j].iter().map(|&c| stats[c]).filter(|&(l, _)| l > len);
            if len < longer.fold(mean, |m, (_, t)| m.max(t)) {
                segs.iter().for_each(|&s| self.alive[s] = false);
                let free = if nodes[0] == j {
                    nodes[nodes.len() - 1]
                } else {
                    nodes[0]
                };
                pruned.entry(j).or_default().push((free, len * mean));
            }
        }
        // Where every spur at a junction but one chain went, the junction is now that chain's
        // end: a fork at the end of a strip, whose spurs run to the two corners of a concave end
        // (where a thin wall meets the rounded end of a loop's bead). The chain goes on to the
        // middle of the spurs' far ends with their area, so that end is filled instead of
        // left bare.
        let adj = self.adjacency();
        for (j, spurs) in pruned {
            if adj[j].len() != 1 || spurs.len() < 2 {
                continue;
            }
            let n = spurs.len() as f64;
            let (x, y) = spurs.iter().fold((0.0, 0.0), |(x, y), &(f, _)| {
                (x + self.nodes[f].x / n, y + self.nodes[f].y / n)
            });
            let area: f64 = spurs.iter().map(|&(_, a)| a).sum();
            // At the chain's own end thickness, as far as that area reaches, but not more than
            // half that thickness past the spurs' ends.
            let (from, target) = (self.nodes[j], Sp::new(x, y));
            let dist = from.distance_2(target).sqrt();
            let Some(&last) = adj[j].first() else {
                continue;
            };
            let thickness = self.segs[last].width;
            if dist < MIN_SEGMENT_MM || thickness <= 0.0 {
                continue;
            }
            let reach = (area / thickness).min(dist + thickness / 2.0);
            let f = reach / dist;
            let end = self.node(Sp::new(
                from.x + (target.x - from.x) * f,
                from.y + (target.y - from.y) * f,
            ));
            self.add(j, end, area);
        }
    }

    /// `chains` with, at every junction (in node order), the two chains that end there and run
    /// on most nearly straight through it joined into one, and so on while two are left: each
    /// join is one travel (and, past `retract_before_travel`, one retraction) fewer, where
    /// the branches of a junction would otherwise each start or end there apart. The third
    /// branch of a fork still ends at the junction. Closed chains are left as they are.
    fn joined_at_junctions(&self, chains: Vec<Chain>) -> Vec<Chain> {
        let mut chains: Vec<Option<Chain>> = chains.into_iter().map(Some).collect();
        let ends = |c: &Chain| [c.0[0], c.0[c.0.len() - 1]];
        let open = |c: &Chain| c.0.len() >= 2 && c.0[0] != c.0[c.0.len() - 1];
        // Per node, the chains that have (or had: checked again when used) an end there.
        let mut at_node: Vec<Vec<usize>> = vec![Vec::new(); self.nodes.len()];
        for (k, c) in chains.iter().enumerate() {
            if let Some(c) = c.as_ref().filter(|c| open(c)) {
                for e in ends(c) {
                    at_node[e].push(k);
                }
            }
        }
        let junctions: Vec<usize> = (0..self.nodes.len())
            .filter(|&j| at_node[j].len() >= 3)
            .collect();
        for j in junctions {
            loop {
                // The open chains with an end at `j` (a chain with both ends there is a loop
                // through it, left alone), each as the unit direction it leaves `j` in.
                let at: Vec<(usize, Sp)> = at_node[j]
                    .iter()
                    .filter_map(|&k| {
                        let c = chains[k].as_ref().filter(|c| open(c))?;
                        // The way the chain heads a little away from `j`: the junction node
                        // is a triangle's centroid, off the line of the branches, so their
                        // first segments do not show it.
                        let from_j: Vec<usize> = match ends(c) {
                            [a, _] if a == j => c.0.clone(),
                            [_, b] if b == j => c.0.iter().rev().copied().collect(),
                            _ => return None,
                        };
                        let p = self.nodes[j];
                        let next = from_j
                            .iter()
                            .copied()
                            .find(|&n| self.nodes[n].distance_2(p) >= HEADING_MM * HEADING_MM)
                            .unwrap_or(from_j[from_j.len() - 1]);
                        let q = self.nodes[next];
                        let d = (q.x - p.x).hypot(q.y - p.y);
                        (d > 0.0).then(|| (k, Sp::new((q.x - p.x) / d, (q.y - p.y) / d)))
                    })
                    .collect();
                // The straightest pair: directions out of `j` most nearly opposite.
                let mut best: Option<(f64, usize, usize)> = None;
                for (x, &(a, u)) in at.iter().enumerate() {
                    for &(b, v) in &at[x + 1..] {
                        let dot = u.x * v.x + u.y * v.y;
                        if best.is_none_or(|(d, _, _)| dot < d) {
                            best = Some((dot, a, b));
                        }
                    }
                }
                let Some((_, a, b)) = best else {
                    break;
                };
                let (Some(mut first), Some(mut second)) = (chains[a].take(), chains[b].take())
                else {
                    break;
                };
                if first.0[first.0.len() - 1] != j {
                    first.0.reverse();
                    first.1.reverse();
                }
                if second.0[0] != j {
                    second.0.reverse();
                    second.1.reverse();
                }
                first.0.extend_from_slice(&second.0[1..]);
                first.1.extend_from_slice(&second.1);
                if let Some(&far) = first.0.last() {
                    at_node[far].push(a);
                }
                chains[a] = Some(first);
            }
        }
        chains.into_iter().flatten().collect()
    }

    /// Length (mm) and Σ thickness·length (mm²) of segments.
    fn measure(&self, segs: &[usize]) -> (f64, f64) {
        segs.iter()
            .map(|&s| self.segs[s])
            .fold((0.0, 0.0), |(l, a), s| (l + s.len, a + s.len * s.width))
    }

    /// The chain as a polyline, or `None` when it is shorter than `min_len` mm.
    fn polyline(&self, (nodes, segs): &Chain, min_len: f64) -> Option<ThickPolyline> {
        if self.measure(segs).0 < min_len {
            return None;
        }
        Some(ThickPolyline {
            points: nodes
                .iter()
                .map(|&n| Point2::from_mm(self.nodes[n].x, self.nodes[n].y))
                .collect(),
            widths: segs.iter().map(|&s| self.segs[s].width).collect(),
            closed: nodes.len() > 2 && nodes.first() == nodes.last(),
        })
    }
}

/// The chordal axis of the inside faces, with area-preserving thicknesses.
fn chordal_axis(cdt: &Cdt, inside: &[bool], min_width: f64, max_width: f64) -> Graph {
    let mut g = Graph {
        edge_node: vec![None; cdt.num_undirected_edges()],
        limits: (min_width, max_width),
        ..Graph::default()
    };
    let internal = |e: Edge| {
        !e.is_constraint_edge()
            && e.rev()
                .face()
                .as_inner()
                .is_some_and(|n| inside[n.fix().index()])
    };
    for f in cdt.inner_faces().filter(|f| inside[f.fix().index()]) {
        let edges = f.adjacent_edges();
        let [p0, p1, p2] = f.positions();
        let area = ((p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x)).abs() / 2.0;
        let mids = edges.map(|e| mid(e.positions()));
        let lens = edges.map(|e| e.length_2());
        let inner: Vec<usize> = (0..3).filter(|&i| internal(edges[i])).collect();
        let node = |g: &mut Graph, i: usize| match inner.contains(&i) {
            true => g.edge_node(edges[i].as_undirected().fix().index(), mids[i]),
            false => g.node(mids[i]),
        };
        if let [_, _, _] = inner[..] {
            let c = g.node(f.center());
            for i in 0..3 {
                let m = node(&mut g, i);
                g.add(c, m, area / 3.0);
            }
            continue;
        }
        // The midline parallel to the longest edge that is not the entry (2 internal edges:
        // between them; 1: from the internal edge to the shorter boundary edge; 0: between the
        // two shorter edges). Its thickness is the triangle's height over that edge.
        let (from, to) = match inner[..] {
            [i, j] => (i, j),
            [i] => {
                let (k, l) = ((i + 1) % 3, (i + 2) % 3);
                (i, if lens[k] <= lens[l] { k } else { l })
            }
            _ => {
                let long = (0..3).fold(0, |m, i| if lens[i] > lens[m] { i } else { m });
                ((long + 1) % 3, (long + 2) % 3)
            }
        };
        let a = node(&mut g, from);
        // A terminal rather goes on straight until it leaves the triangle (see the module docs),
        // unless that exit is less than half as far as the midline's.
        let exit = match inner[..] {
            [i] => terminal_exit(edges[i], mids[i], &internal)
                .filter(|p| p.distance_2(mids[i]) * 4.0 >= mids[i].distance_2(mids[to])),
            _ => None,
        };
        let b = match exit {
            Some(p) => g.node(p),
            None => node(&mut g, to),
        };
        g.add(a, b, area);
    }
    g
}

/// The midpoint of `p`–`q`.
fn mid([p, q]: [Sp; 2]) -> Sp {
    Sp::new((p.x + q.x) / 2.0, (p.y + q.y) / 2.0)
}

/// A directed edge of the triangulation.
type Edge<'a> = spade::handles::DirectedEdgeHandle<'a, Sp, (), spade::CdtEdge<bool>, ()>;

/// Where the axis entering a terminal triangle through `entry` (midpoint `m`) leaves it when
/// continued straight: the direction is that of the neighbour's axis segment ending at `m`.
fn terminal_exit(entry: Edge, m: Sp, internal: &impl Fn(Edge) -> bool) -> Option<Sp> {
    let nb = entry.rev().face().as_inner()?;
    let back = entry.rev().as_undirected().fix();
    let others: Vec<Edge> = nb
        .adjacent_edges()
        .into_iter()
        .filter(|&e| e.as_undirected().fix() != back && internal(e))
        .collect();
    let from = match others[..] {
        [e] => mid(e.positions()),
        [_, _] => nb.center(),
        _ => return None,
    };
    let d = Sp::new(m.x - from.x, m.y - from.y);
    let cross = |a: Sp, b: Sp| a.x * b.y - a.y * b.x;
    let [a, b] = entry.positions();
    let v = entry.opposite_position()?;
    // Ray m + t·d against the sides a–v and v–b: t = (p − m)×e / d×e, u = (p − m)×d / d×e.
    [(a, v), (v, b)].into_iter().find_map(|(p, q)| {
        let (e, w) = (Sp::new(q.x - p.x, q.y - p.y), Sp::new(p.x - m.x, p.y - m.y));
        let den = cross(d, e);
        let (t, u) = (cross(w, e) / den, cross(w, d) / den);
        (den != 0.0 && t > 0.0 && (0.0..=1.0).contains(&u))
            .then(|| Sp::new(m.x + t * d.x, m.y + t * d.y))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::{contains, rect, rect_island, square};

    fn gap(points: &[(f64, f64)]) -> ExPolygon {
        let pts = points.iter().map(|&(x, y)| Point2::from_mm(x, y)).collect();
        ExPolygon {
            contour: Polygon::new(pts),
            holes: vec![],
        }
    }

    fn seg_len(a: Point2, b: Point2) -> f64 {
        (a.distance_squared(b) as f64).sqrt() / 1e6
    }

    /// (total length, Σ thickness·length) of lines.
    fn measure(lines: &[ThickPolyline]) -> (f64, f64) {
        let segs = lines
            .iter()
            .flat_map(|l| l.points.windows(2).zip(&l.widths));
        segs.fold((0.0, 0.0), |(l, a), (w, t)| {
            (l + seg_len(w[0], w[1]), a + seg_len(w[0], w[1]) * t)
        })
    }

    /// (x mid, thickness) of every segment.
    fn profile(l: &ThickPolyline) -> Vec<(f64, f64)> {
        l.points
            .windows(2)
            .zip(&l.widths)
            .map(|(w, &t)| (unscaled(w[0].x + w[1].x) / 2.0, t))
            .collect()
    }

    #[test]
    fn a_strip_ending_in_a_notch_reaches_the_notch_with_the_pruned_area() {
        // 0.6 mm thick, its right end notched 0.25 mm deep (where a thin wall meets the rounded
        // end of a loop's bead): the axis forks into the notch's two corners; the forks are too
        // short to print, and the line goes on to the middle of the corners instead.
        let g = gap(&[
            (0.0, 0.0),
            (10.0, 0.0),
            (9.75, 0.3),
            (10.0, 0.6),
            (0.0, 0.6),
        ]);
        let lines = gap_fill(std::slice::from_ref(&g), 0.05, 0.8);
        assert_eq!(lines.len(), 1, "{lines:?}");
        let ends = [
            lines[0].points[0],
            lines[0].points[lines[0].points.len() - 1],
        ];
        let right = ends.iter().map(|p| unscaled(p.x)).fold(f64::MIN, f64::max);
        assert!(right > 9.65, "the line ends at x = {right}");
        let (_, area) = measure(&lines);
        let whole = g.contour.area_mm2();
        assert!((area - whole).abs() < 0.02 * whole, "{area} of {whole} mm²");
    }

    #[test]
    fn straight_strip_gives_one_centred_line_of_constant_width() {
        let lines = gap_fill(&[rect_island(0.0, 0.0, 10.0, 0.3)], 0.05, 0.5);
        assert_eq!(lines.len(), 1, "{lines:?}");
        let l = &lines[0];
        assert!(!l.closed && l.points.len() == l.widths.len() + 1);
        for p in &l.points[1..l.points.len() - 1] {
            assert!((unscaled(p.y) - 0.15).abs() < 1e-3, "{p:?}");
        }
        let (len, area) = measure(&lines);
        assert!((9.4..=10.0 + 1e-6).contains(&len), "{len}");
        for &w in &l.widths[1..l.widths.len() - 1] {
            assert!((w - 0.3).abs() < 0.02, "{w}");
        }
        assert!((area - 3.0).abs() < 0.03 * 3.0, "{area}");
    }

    #[test]
    fn square_ring_gives_a_closed_loop_even_when_densely_sampled() {
        // Edges split into `n` pieces; dense sampling makes the axis branch into the corners.
        let ring = |n: usize| {
            let dense = |sq: Polygon| {
                let p = &sq.points;
                let pts = (0..4 * n).map(|i| {
                    let (a, b, f) = (p[i / n], p[(i / n + 1) % 4], (i % n) as f64 / n as f64);
                    Point2::new(
                        a.x + ((b.x - a.x) as f64 * f) as i64,
                        a.y + ((b.y - a.y) as f64 * f) as i64,
                    )
                });
                Polygon::new(pts.collect())
            };
            let mut hole = dense(square(0.3, 0.3, 9.4));
            hole.points.reverse();
            ExPolygon {
                contour: dense(square(0.0, 0.0, 10.0)),
                holes: vec![hole],
            }
        };
        for n in [1, 400] {
            let lines = gap_fill(&[ring(n)], 0.05, 0.5);
            let (len, area) = measure(&lines);
            assert!((len - 38.8).abs() < 0.02 * 38.8, "{len} {lines:?}");
            assert!((area - 11.64).abs() < 0.03 * 11.64, "{area}");
            assert!(lines.len() == 1 && lines[0].closed, "{lines:?}");
            let near = lines[0]
                .widths
                .iter()
                .filter(|w| (*w - 0.3).abs() < 0.03)
                .count();
            assert!(near + 8 >= lines[0].widths.len(), "{lines:?}");
        }
    }

    #[test]
    fn tapered_wedge_thickens_along_the_line_and_keeps_its_area() {
        let lines = gap_fill(
            &[gap(&[(0.0, 0.0), (10.0, 0.0), (10.0, 0.5), (0.0, 0.1)])],
            0.05,
            0.6,
        );
        assert_eq!(lines.len(), 1, "{lines:?}");
        let (_, area) = measure(&lines);
        assert!((area - 3.0).abs() < 0.03 * 3.0, "{area}");
        for (x, t) in profile(&lines[0])
            .into_iter()
            .filter(|(x, _)| (0.5..9.5).contains(x))
        {
            assert!((t - (0.1 + 0.04 * x)).abs() < 0.03, "x {x}: {t}");
        }
    }

    #[test]
    fn t_junction_and_l_corner_keep_area_and_stay_inside() {
        let t = [
            (10.0, 0.3),
            (5.15, 0.3),
            (5.15, 3.3),
            (4.85, 3.3),
            (4.85, 0.3),
        ];
        let l = [(10.0, 3.0), (9.7, 3.0), (9.7, 0.3)];
        // (shape, area, axis length, chains): the T has a junction, where its bar runs on
        // through as one chain and the stem ends; the L a corner.
        for (shape, want, length, chains) in [(&t[..], 3.9, 13.15, 2), (&l[..], 3.81, 12.7, 1)] {
            let mut pts = vec![(0.0, 0.0), (10.0, 0.0)];
            pts.extend(shape);
            pts.push((0.0, 0.3));
            let g = [gap(&pts)];
            let lines = gap_fill(&g, 0.05, 0.5);
            let (len, area) = measure(&lines);
            assert!((area - want).abs() < 0.05 * want, "{area} {lines:?}");
            assert!((len - length).abs() < 0.3, "{len}");
            assert_eq!(lines.len(), chains, "{lines:?}");
            for p in lines.iter().flat_map(|l| &l.points) {
                assert!(contains(&g, *p), "{p:?}");
            }
            // One chain spans the whole 10 mm bar (of the T, and of the L's foot).
            let span = |l: &ThickPolyline| {
                let xs = l.points.iter().map(|p| unscaled(p.x));
                xs.clone().fold(f64::MIN, f64::max) - xs.fold(f64::MAX, f64::min)
            };
            assert!(lines.iter().any(|l| span(l) > 9.5), "{lines:?}");
        }
    }

    #[test]
    fn too_thin_empty_and_degenerate_input_give_nothing_or_no_panic() {
        assert!(gap_fill(&[rect_island(0.0, 0.0, 10.0, 0.04)], 0.05, 0.5).is_empty());
        assert!(gap_fill(&[], 0.05, 0.5).is_empty());
        assert!(gap_fill(&[rect_island(0.0, 0.0, 10.0, 0.3)], f64::NAN, 0.5).is_empty());
        for g in [
            gap(&[]),
            gap(&[(0.0, 0.0), (1.0, 0.0)]),
            gap(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]),
            gap(&[(0.0, 0.0), (0.0, 0.0), (0.0, 0.0)]),
        ] {
            assert!(gap_fill(&[g], 0.05, 0.5).is_empty());
        }
        let dup = gap(&[
            (0.0, 0.0),
            (0.0, 0.0),
            (5.0, 0.0),
            (5.0, 0.3),
            (5.0, 0.3),
            (0.0, 0.3),
            (0.0, 0.0),
        ]);
        assert_eq!(gap_fill(&[dup], 0.05, 0.5).len(), 1);
        let bowtie = gap(&[(0.0, 0.0), (10.0, 0.3), (10.0, 0.0), (0.0, 0.3)]);
        let lines = gap_fill(&[bowtie], 0.05, 0.5);
        assert!(measure(&lines).1 <= 1.5 + 1e-9, "{lines:?}");
        // Overlapping holes, holes outside, touching rings and random grid-snapped polygons.
        let mut rng = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = |n: u64| {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng % n) as f64 / 10.0
        };
        for _ in 0..300 {
            let mut ring = || {
                gap(&(0..3 + next(100) as usize)
                    .map(|_| (next(20), next(20)))
                    .collect::<Vec<_>>())
            };
            let mut g = ring();
            g.holes = vec![ring().contour, rect(0.0, 0.0, 1.0, 1.0)];
            let _ = gap_fill(&[g], 0.05, 0.5);
        }
    }

    #[test]
    fn output_is_deterministic() {
        let gaps = [
            gap(&[(0.0, 0.0), (10.0, 0.0), (10.0, 0.5), (0.0, 0.1)]),
            gap(&[
                (0.0, 1.0),
                (6.0, 1.0),
                (6.0, 4.0),
                (5.7, 4.0),
                (5.7, 1.3),
                (0.0, 1.3),
            ]),
        ];
        let a = gap_fill(&gaps, 0.05, 0.5);
        assert!(!a.is_empty());
        assert_eq!(a, gap_fill(&gaps, 0.05, 0.5));
    }

    #[test]
    fn split_by_width_keeps_area_within_tolerance_and_shares_ends() {
        let lines = gap_fill(
            &[gap(&[(0.0, 0.0), (10.0, 0.0), (10.0, 0.5), (0.0, 0.1)])],
            0.05,
            0.6,
        );
        let line = &lines[0];
        let tol = 0.02;
        let runs = split_by_width(line, tol);
        assert!(runs.len() >= 5, "{runs:?}");
        let (mut at, mut area) = (0, 0.0);
        for (pts, t) in &runs {
            assert_eq!(pts[0], line.points[at]);
            for (w, &wt) in pts.windows(2).zip(&line.widths[at..]) {
                assert!((wt - t).abs() <= tol + 1e-12, "{wt} vs {t}");
                area += seg_len(w[0], w[1]) * t;
            }
            at += pts.len() - 1;
        }
        assert_eq!(at, line.widths.len());
        let want = measure(&lines).1;
        assert!((area - want).abs() < 1e-9 * want, "{area} {want}");
        assert!(
            split_by_width(
                &ThickPolyline {
                    points: vec![],
                    widths: vec![],
                    closed: false
                },
                tol
            )
            .is_empty()
        );
    }
}
