//! The machinery every line pattern shares: a family of parallel lines on a global lattice,
//! clipped to the area, ordered to keep travel short, and joined into zig-zags along the boundary.
//!
//! **Lattice.** Line `k` of a family with direction `θ` and spacing `S` is the set of points `p`
//! with `p · n = (k + phase) · S`, where `n` is `d = (cos θ, sin θ)` turned by +90°. The lattice is
//! anchored at the origin, not at the area, so neighbouring areas (and the same area on other
//! layers) share lines. A phase of ½ keeps lines off edges that sit on multiples of `S`.
//!
//! **Clipping.** The lines are clipped together in one scan-line sweep over the area's edges
//! ([`super::scanline`]), which gives each piece its lattice line.
//!
//! **Connection.** Pieces are joined into zig-zags by links that run *along the area's
//! boundary* between two piece ends that are neighbours on a ring (no other line meets the ring
//! between them), lie on the same or adjacent lattice lines and are at most [`CONNECT_LIMIT`]
//! spacings apart along the ring — PrusaSlicer's rectilinear infill connects its lines the same
//! way (`FillRectilinear.cpp`: links along the contour between consecutive intersections). A
//! chain starts at the free piece on the lowest line and at each end takes the link onward in
//! its direction of travel, else along the same line (over the top of a hole), else back (down
//! the other side of the hole), so one chain sweeps round a hole instead of stopping at it.
//! Links lie on the boundary, where the infill meets the innermost perimeter, never across the
//! area or over a perimeter; they add about half a boundary length per family to the extruded
//! length. A chain's free ends are then *anchored* (after PrusaSlicer's `infill_anchor`): carried
//! along the boundary into a corner within [`ANCHOR_LIMIT`] spacings, where aligned seams end the
//! perimeters, so the nozzle goes on to the infill without a long travel.
//!
//! **Order.** Chains are then ordered greedily: after each, the nearest free end of any other
//! comes next (ties go to the lower index, so output is deterministic).

use super::scanline::{Lattice, clip_lines};
use crate::geom::{ExPolygon, Point2, Polygon, Polyline, scaled, segment_distance, segment_param};

/// Longest connector, in line spacings (a boundary meeting the lines at 20° needs ~2.9).
pub const CONNECT_LIMIT: f64 = 3.0;

/// Longest anchor at a chain's free end, in line spacings: 2.8 mm for 20 % sparse infill of
/// 0.45 mm lines, about PrusaSlicer's default `infill_anchor` (600 % of the width, 2.7 mm).
pub const ANCHOR_LIMIT: f64 = 1.25;

/// Smallest turn of the boundary, degrees, that counts as a corner an anchor may run to (the
/// same threshold as an aligned seam's corner).
pub const ANCHOR_CORNER_DEG: f64 = 50.0;

/// Farthest a clipped line's end may lie from the boundary edge it is placed on (nm): clipping
/// rounds intersections to the nanometre.
const LOCATE_TOLERANCE_NM: f64 = 1000.0;

/// Rounding slack (nm) when deciding whether a connector leaves the area: clipped end points are
/// rounded to the nanometre, so a connector along an edge can stray a few units either side.
pub const INSIDE_TOLERANCE_NM: f64 = 100.0;

/// Most lines one family may have (10 m of area at 0.1 mm spacing); finer spacings over larger
/// areas give no lines rather than exhausting memory.
pub const MAX_LINES: f64 = 1.0e5;

/// One family of parallel lines.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineFamily {
    /// Direction of the lines, radians counter-clockwise from +X.
    pub angle_rad: f64,
    /// Distance between neighbouring lines, mm.
    pub spacing_mm: f64,
    /// Offset of the lattice from the origin, in spacings (0 ≤ phase < 1).
    pub phase: f64,
}

/// A clipped piece and the lattice line it lies on.
struct Piece {
    points: Vec<Point2>,
    line: i64,
}

/// Lines of `family` inside `area`, ordered and (when `connect`) joined into zig-zags.
pub fn fill_family(area: &[ExPolygon], family: LineFamily, connect: bool) -> Vec<Polyline> {
    let s = scaled(family.spacing_mm) as f64;
    if area.is_empty() || s.is_nan() || s < 1.0 || !family.angle_rad.is_finite() {
        return Vec::new();
    }
    let (d, n) = {
        let (sin, cos) = family.angle_rad.sin_cos();
        ((cos, sin), (-sin, cos))
    };
    let dot = |p: Point2, v: (f64, f64)| p.x as f64 * v.0 + p.y as f64 * v.1;
    let (mut n_lo, mut n_hi) = (f64::MAX, f64::MIN);
    for p in area.iter().map(|e| &e.contour).flat_map(|c| &c.points) {
        let pn = dot(*p, n);
        (n_lo, n_hi) = (n_lo.min(pn), n_hi.max(pn));
    }
    let k_lo = (n_lo / s - family.phase).ceil();
    let k_hi = (n_hi / s - family.phase).floor();
    if k_hi < k_lo || k_hi - k_lo > MAX_LINES {
        return Vec::new();
    }
    let lattice = Lattice {
        d,
        n,
        spacing: s,
        phase: family.phase,
    };
    let pieces: Vec<Piece> = clip_lines(area, &lattice, k_lo as i64, k_hi as i64)
        .into_iter()
        .map(|span| Piece {
            points: span.points.to_vec(),
            line: span.line,
        })
        .collect();
    let pieces = if connect {
        let lattice = |p: Point2| dot(p, n) / s - family.phase;
        let boundary = Boundary::new(area, lattice, k_lo as i64, k_hi as i64);
        connect_along_boundary(pieces, &boundary, s)
    } else {
        pieces
    };
    order_nearest(pieces)
        .into_iter()
        .map(|p| Polyline { points: p.points })
        .collect()
}

/// Greedy nearest-neighbour chaining of `pieces`, reversing pieces as needed.
fn order_nearest(pieces: Vec<Piece>) -> Vec<Piece> {
    let mut free: Vec<Option<Piece>> = pieces.into_iter().map(Some).collect();
    let mut out: Vec<Piece> = Vec::with_capacity(free.len());
    let Some(first) = free.first_mut().and_then(Option::take) else {
        return out;
    };
    let mut here = first.points[first.points.len() - 1];
    out.push(first);
    while out.len() < free.len() {
        let mut best: Option<(i128, usize, bool)> = None;
        for (i, piece) in free.iter().enumerate() {
            let Some(piece) = piece else { continue };
            let start = here.distance_squared(piece.points[0]);
            let end = here.distance_squared(piece.points[piece.points.len() - 1]);
            let (dist, reverse) = if end < start {
                (end, true)
            } else {
                (start, false)
            };
            if best.is_none_or(|(b, _, _)| dist < b) {
                best = Some((dist, i, reverse));
            }
        }
        let Some((_, i, reverse)) = best else { break };
        let Some(mut piece) = free[i].take() else {
            break;
        };
        if reverse {
            piece.points.reverse();
        }
        here = piece.points[piece.points.len() - 1];
        out.push(piece);
    }
    out
}

/// A piece end placed on the boundary: the ring, the edge it lies on and its arc length from
/// the ring's first vertex (nm).
#[derive(Debug, Clone, Copy)]
struct OnRing {
    ring: usize,
    edge: usize,
    along: f64,
}

/// The boundary rings of an area with their arc lengths, and its edges bucketed by the lattice
/// lines they cross, so a piece end is placed by looking only at the edges that reach its line.
struct Boundary<'a> {
    rings: Vec<&'a [Point2]>,
    /// Per ring, the arc length at each vertex; one more entry than vertices (the perimeter).
    arc: Vec<Vec<f64>>,
    /// Per lattice line `k_lo + i`, the (ring, edge) pairs that reach it.
    buckets: Vec<Vec<(usize, usize)>>,
    k_lo: i64,
}

impl<'a> Boundary<'a> {
    fn new(area: &'a [ExPolygon], lattice: impl Fn(Point2) -> f64, k_lo: i64, k_hi: i64) -> Self {
        let rings: Vec<&[Point2]> = rings(area)
            .map(|r| r.points.as_slice())
            .filter(|r| r.len() >= 2)
            .collect();
        let lines = usize::try_from(k_hi - k_lo + 1).unwrap_or(0);
        let mut buckets = vec![Vec::new(); lines];
        let mut arc = Vec::with_capacity(rings.len());
        // Slack in spacings so an end rounded onto the far side of a vertex still finds its edge.
        const SLACK: f64 = 1e-3;
        for (r, pts) in rings.iter().enumerate() {
            let mut acc = vec![0.0; pts.len() + 1];
            for i in 0..pts.len() {
                let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                acc[i + 1] = acc[i] + (a.distance_squared(b) as f64).sqrt();
                let (la, lb) = (lattice(a), lattice(b));
                let lo = (la.min(lb) - SLACK).ceil().max(k_lo as f64) as i64;
                let hi = (la.max(lb) + SLACK).floor().min(k_hi as f64) as i64;
                for k in lo..=hi {
                    if let Some(bucket) = usize::try_from(k - k_lo)
                        .ok()
                        .and_then(|i| buckets.get_mut(i))
                    {
                        bucket.push((r, i));
                    }
                }
            }
            arc.push(acc);
        }
        Self {
            rings,
            arc,
            buckets,
            k_lo,
        }
    }

    /// Where `p`, an end of a piece on lattice line `line`, lies on the boundary: the nearest
    /// edge reaching that line, if within [`LOCATE_TOLERANCE_NM`].
    fn locate(&self, p: Point2, line: i64) -> Option<OnRing> {
        let bucket = self.buckets.get(usize::try_from(line - self.k_lo).ok()?)?;
        let mut best: Option<(f64, OnRing)> = None;
        for &(ring, edge) in bucket {
            let pts = self.rings[ring];
            let (a, b) = (pts[edge], pts[(edge + 1) % pts.len()]);
            let d = segment_distance(p, a, b);
            if d <= LOCATE_TOLERANCE_NM && best.is_none_or(|(bd, _)| d < bd) {
                let len = self.arc[ring][edge + 1] - self.arc[ring][edge];
                let along = self.arc[ring][edge] + segment_param(p, a, b) * len;
                best = Some((d, OnRing { ring, edge, along }));
            }
        }
        best.map(|(_, at)| at)
    }

    /// Length of the ring's perimeter, nm.
    fn perimeter(&self, ring: usize) -> f64 {
        self.arc[ring].last().copied().unwrap_or(0.0)
    }

    /// The first corner (a turn of at least [`ANCHOR_CORNER_DEG`]) met walking along the ring
    /// from `from`, forward or backward, within `reach` nm: its distance and the vertices up to
    /// and including it.
    fn corner_within(&self, from: OnRing, reach: f64, forward: bool) -> Option<(f64, Vec<Point2>)> {
        let (pts, arc) = (self.rings[from.ring], &self.arc[from.ring]);
        let n = pts.len();
        if n < 3 || reach <= 0.0 {
            return None;
        }
        let min_turn = ANCHOR_CORNER_DEG.to_radians();
        let turn = |v: usize| {
            let (p, q, r) = (pts[(v + n - 1) % n], pts[v], pts[(v + 1) % n]);
            let (ax, ay) = ((q.x - p.x) as f64, (q.y - p.y) as f64);
            let (bx, by) = ((r.x - q.x) as f64, (r.y - q.y) as f64);
            (ax * by - ay * bx).atan2(ax * bx + ay * by).abs()
        };
        let (mut v, mut dist) = if forward {
            ((from.edge + 1) % n, arc[from.edge + 1] - from.along)
        } else {
            (from.edge, from.along - arc[from.edge])
        };
        let mut out = Vec::new();
        for _ in 0..n {
            if dist > reach {
                return None;
            }
            out.push(pts[v]);
            if turn(v) >= min_turn {
                return Some((dist, out));
            }
            if forward {
                dist += arc[v + 1] - arc[v];
                v = (v + 1) % n;
            } else {
                let u = (v + n - 1) % n;
                dist += arc[u + 1] - arc[u];
                v = u;
            }
        }
        None
    }

    /// The ring's vertices passed when walking forward along it from `from` to `to`.
    fn vertices_between(&self, from: OnRing, to: OnRing) -> Vec<Point2> {
        let pts = self.rings[from.ring];
        let n = pts.len();
        if from.edge == to.edge && to.along >= from.along {
            return Vec::new();
        }
        let mut out = Vec::new();
        let mut v = (from.edge + 1) % n;
        loop {
            out.push(pts[v]);
            if v == to.edge || out.len() > n {
                break;
            }
            v = (v + 1) % n;
        }
        out
    }
}

/// Joins `pieces` into zig-zags by links that follow the area's boundary (PrusaSlicer's
/// rectilinear infill connects its lines the same way, along the contour between consecutive
/// intersections, in `FillRectilinear.cpp`). A link joins two piece ends that are neighbours
/// along a ring (no other line meets the ring between them), on the same or adjacent lattice
/// lines, at most `max_len_nm` apart along the ring; each ring arc between two consecutive ends
/// can carry only the link between those two ends, so no connector is printed twice.
///
/// Chains are walked: each starts at the free piece on the lowest lattice line (an extremity of
/// the sweep), and at every piece end continues to the ring neighbour on the next line in the
/// direction of travel, else on the same line (around the top of a hole), else on the line
/// back (turning the sweep round, down the other side of a hole); the shorter link on ties.
fn connect_along_boundary(
    pieces: Vec<Piece>,
    boundary: &Boundary<'_>,
    spacing_nm: f64,
) -> Vec<Piece> {
    let max_len_nm = CONNECT_LIMIT * spacing_nm;
    let n = pieces.len();
    // Piece ends on each ring, in order along it; and where each piece end sits in that order.
    let mut on_ring: Vec<Vec<(f64, usize, usize, OnRing)>> = vec![Vec::new(); boundary.rings.len()];
    for (i, piece) in pieces.iter().enumerate() {
        let ends = [piece.points[0], piece.points[piece.points.len() - 1]];
        for (end, p) in ends.into_iter().enumerate() {
            if let Some(at) = boundary.locate(p, piece.line) {
                on_ring[at.ring].push((at.along, i, end, at));
            }
        }
    }
    let lines: Vec<i64> = pieces.iter().map(|p| p.line).collect();
    let mut slot: Vec<[Option<(usize, usize)>; 2]> = vec![[None, None]; n];
    for (ring, ends) in on_ring.iter_mut().enumerate() {
        ends.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
        for (k, e) in ends.iter().enumerate() {
            slot[e.1][e.2] = Some((ring, k));
        }
    }
    // The links leaving piece `i` at end `e`: (to piece, to end, points between, length, Δline).
    let candidates = |i: usize, e: usize, used: &[bool]| {
        let mut out: Vec<(usize, usize, Vec<Point2>, f64, i64)> = Vec::new();
        let Some((ring, k)) = slot[i][e] else {
            return out;
        };
        let ends = &on_ring[ring];
        let m = ends.len();
        let perimeter = boundary.perimeter(ring).max(1.0);
        if m < 2 {
            return out;
        }
        let here = ends[k];
        for (other, forward) in [(ends[(k + 1) % m], true), (ends[(k + m - 1) % m], false)] {
            let (j, f) = (other.1, other.2);
            let dline = lines[j] - lines[i];
            if j == i || used[j] || dline.abs() > 1 {
                continue;
            }
            let (length, via) = if forward {
                (
                    (other.0 - here.0).rem_euclid(perimeter),
                    boundary.vertices_between(here.3, other.3),
                )
            } else {
                let mut v = boundary.vertices_between(other.3, here.3);
                v.reverse();
                ((here.0 - other.0).rem_euclid(perimeter), v)
            };
            if length <= max_len_nm {
                out.push((j, f, via, length, dline));
            }
        }
        out
    };
    // The anchor of a chain's free end (after PrusaSlicer's `infill_anchor`): the end carried
    // along the boundary into the nearest corner within reach, so a chain can begin or finish
    // where aligned seams put the end of the perimeters. It stops at that corner, at most
    // [`ANCHOR_LIMIT`] spacings away and half a spacing short of the next line end; two
    // anchors on one arc each stop at the first corner they meet, so they never overlap.
    let anchor = |i: usize, e: usize| -> Vec<Point2> {
        let Some((ring, k)) = slot[i][e] else {
            return Vec::new();
        };
        let ends = &on_ring[ring];
        let m = ends.len();
        let perimeter = boundary.perimeter(ring).max(1.0);
        let here = ends[k];
        let arc = |forward: bool| {
            if m < 2 {
                perimeter
            } else if forward {
                (ends[(k + 1) % m].0 - here.0).rem_euclid(perimeter)
            } else {
                (here.0 - ends[(k + m - 1) % m].0).rem_euclid(perimeter)
            }
        };
        [true, false]
            .into_iter()
            .filter_map(|forward| {
                let reach = (ANCHOR_LIMIT * spacing_nm).min(arc(forward) - spacing_nm / 2.0);
                boundary.corner_within(here.3, reach, forward)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, points)| points)
            .unwrap_or_default()
    };
    let mut used = vec![false; n];
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| (lines[i], i));
    let mut slots: Vec<Option<Piece>> = pieces.into_iter().map(Some).collect();
    let mut out = Vec::new();
    for &start in &order {
        if used[start] {
            continue;
        }
        used[start] = true;
        // Leave the first piece by the end that continues up the lattice, if either does.
        let rises = |e: usize, used: &[bool]| {
            candidates(start, e, used)
                .iter()
                .filter(|c| c.4 == 1)
                .map(|c| c.3)
                .fold(f64::INFINITY, f64::min)
        };
        let mut exit = if rises(0, &used) < rises(1, &used) {
            0
        } else {
            1
        };
        let mut head = anchor(start, 1 - exit);
        head.reverse();
        let mut dir = 1;
        let Some(mut chain) = slots[start].take() else {
            continue;
        };
        if exit == 0 {
            chain.points.reverse();
        }
        if !head.is_empty() {
            head.extend(chain.points);
            chain.points = head;
        }
        let mut piece = start;
        loop {
            let cands = candidates(piece, exit, &used);
            let rank = |d: i64| {
                if d == dir {
                    0
                } else if d == 0 {
                    1
                } else {
                    2
                }
            };
            let Some(best) = cands
                .into_iter()
                .min_by(|a, b| rank(a.4).cmp(&rank(b.4)).then(a.3.total_cmp(&b.3)))
            else {
                break;
            };
            let (j, entry, via, _, dline) = best;
            let Some(mut next) = slots[j].take() else {
                break;
            };
            used[j] = true;
            if dline != 0 {
                dir = dline;
            }
            if entry == 1 {
                next.points.reverse();
            }
            for q in via.into_iter().chain(next.points) {
                if chain.points.last() != Some(&q) {
                    chain.points.push(q);
                }
            }
            (piece, exit) = (j, 1 - entry);
        }
        chain.points.extend(anchor(piece, exit));
        out.push(chain);
    }
    out
}

/// Every ring of `area` (contours and holes).
fn rings(area: &[ExPolygon]) -> impl Iterator<Item = &Polygon> {
    area.iter()
        .flat_map(|e| std::iter::once(&e.contour).chain(&e.holes))
}

/// Whether `p` is inside `area` (even–odd over all rings) or within [`INSIDE_TOLERANCE_NM`] of
/// its boundary.
pub fn contains(area: &[ExPolygon], p: Point2) -> bool {
    let mut inside = false;
    for ring in rings(area) {
        let pts = &ring.points;
        for i in 0..pts.len() {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            if segment_distance(p, a, b) <= INSIDE_TOLERANCE_NM {
                return true;
            }
            if (a.y > p.y) != (b.y > p.y) {
                // x of the edge at p.y, compared exactly: p is left of the crossing when
                // (p.x − a.x)·(b.y − a.y) < (b.x − a.x)·(p.y − a.y), sign-adjusted for b.y < a.y.
                let lhs = (p.x - a.x) as i128 * (b.y - a.y) as i128;
                let rhs = (b.x - a.x) as i128 * (p.y - a.y) as i128;
                if (lhs < rhs) == (b.y > a.y) {
                    inside = !inside;
                }
            }
        }
    }
    inside
}

/// Signed distance (nm) of `p` from the line through `a` and `b` (positive on the left).
fn side(a: Point2, b: Point2, p: Point2) -> f64 {
    let len = (a.distance_squared(b) as f64).sqrt();
    if len == 0.0 {
        0.0
    } else {
        a.cross(b, p) as f64 / len
    }
}

/// Whether the segment `a`–`b` stays inside `area`, up to [`INSIDE_TOLERANCE_NM`].
pub fn segment_inside(a: Point2, b: Point2, area: &[ExPolygon]) -> bool {
    let tol = INSIDE_TOLERANCE_NM;
    let (lo_x, hi_x) = (a.x.min(b.x) as f64 - tol, a.x.max(b.x) as f64 + tol);
    let (lo_y, hi_y) = (a.y.min(b.y) as f64 - tol, a.y.max(b.y) as f64 + tol);
    for ring in rings(area) {
        let pts = &ring.points;
        for i in 0..pts.len() {
            let (p, q) = (pts[i], pts[(i + 1) % pts.len()]);
            if (p.x.max(q.x) as f64) < lo_x
                || (p.x.min(q.x) as f64) > hi_x
                || (p.y.max(q.y) as f64) < lo_y
                || (p.y.min(q.y) as f64) > hi_y
            {
                continue;
            }
            let (sa, sb) = (side(p, q, a), side(p, q, b));
            let (sp, sq) = (side(a, b, p), side(a, b, q));
            let proper = |u: f64, v: f64| (u > tol && v < -tol) || (u < -tol && v > tol);
            if proper(sa, sb) && proper(sp, sq) {
                return false;
            }
        }
    }
    [0.25, 0.5, 0.75].iter().all(|&t| {
        let m = Point2::new(
            a.x + ((b.x - a.x) as f64 * t).round() as i64,
            a.y + ((b.y - a.y) as f64 * t).round() as i64,
        );
        contains(area, m)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::{polyline_length, rect_island, square_island};

    #[test]
    fn horizontal_family_over_a_square_is_one_zigzag() {
        let area = [square_island(0.0, 0.0, 10.0)];
        let family = LineFamily {
            angle_rad: 0.0,
            spacing_mm: 1.0,
            phase: 0.5,
        };
        let loose = fill_family(&area, family, false);
        assert_eq!(loose.len(), 10);
        for (i, l) in loose.iter().enumerate() {
            assert_eq!(l.points.len(), 2);
            assert_eq!(l.points[0].y, scaled(i as f64 + 0.5));
            assert!((polyline_length(l) - 10.0).abs() < 1e-6);
        }
        // Boustrophedon: every other line runs right to left.
        assert!(loose[0].points[0].x < loose[0].points[1].x);
        assert!(loose[1].points[0].x > loose[1].points[1].x);
        let joined = fill_family(&area, family, true);
        assert_eq!(joined.len(), 1);
        // Ten lines, nine connectors of one spacing, and an anchor of 0.5 mm at each end into
        // the corner the first and the last line end beside.
        assert_eq!(joined[0].points.len(), 22);
        assert!((polyline_length(&joined[0]) - (100.0 + 9.0 + 1.0)).abs() < 1e-5);
        let ends = [joined[0].points[0], joined[0].points[21]];
        let corners = [Point2::from_mm(0.0, 0.0), Point2::from_mm(0.0, 10.0)];
        assert!(ends.iter().all(|e| corners.contains(e)), "{ends:?}");
    }

    /// Every segment of `lines` lies inside `area` (up to rounding) and, when it is not along a
    /// lattice line (a connector or an anchor), on the area's boundary.
    fn assert_on_area_or_boundary(lines: &[Polyline], area: &[ExPolygon], family: LineFamily) {
        let (sin, cos) = family.angle_rad.sin_cos();
        for l in lines {
            for w in l.points.windows(2) {
                assert!(segment_inside(w[0], w[1], area), "{w:?} leaves the area");
                let (dx, dy) = ((w[1].x - w[0].x) as f64, (w[1].y - w[0].y) as f64);
                let along_lattice = (dx * sin - dy * cos).abs() <= 2.0;
                if !along_lattice {
                    let on_ring = rings(area).any(|r| {
                        (0..r.points.len()).any(|i| {
                            let (a, b) = (r.points[i], r.points[(i + 1) % r.points.len()]);
                            segment_distance(w[0], a, b) <= LOCATE_TOLERANCE_NM
                                && segment_distance(w[1], a, b) <= LOCATE_TOLERANCE_NM
                        })
                    });
                    assert!(on_ring, "connector {w:?} is not on the boundary");
                }
            }
        }
    }

    #[test]
    fn lines_around_holes_join_along_the_hole_into_few_chains() {
        // A 40 mm square with four 6 mm square holes: the lines through the holes are cut into
        // three pieces each. Following the boundary, around the holes too, joins them into
        // chains of four pieces or more on average, in every direction.
        let mut area = square_island(0.0, 0.0, 40.0);
        for (x, y) in [(8.0, 8.0), (26.0, 8.0), (8.0, 26.0), (26.0, 26.0)] {
            let mut hole = crate::region::test_util::rect(x, y, x + 6.0, y + 6.0);
            hole.points.reverse();
            area.holes.push(hole);
        }
        let area = [area];
        for angle in [0.0f64, 45.0, 90.0, 30.0] {
            let family = LineFamily {
                angle_rad: angle.to_radians(),
                spacing_mm: 2.0,
                phase: 0.5,
            };
            let loose = fill_family(&area, family, false);
            let joined = fill_family(&area, family, true);
            assert!(
                joined.len() * 4 <= loose.len(),
                "{angle}°: {} chains of {} pieces",
                joined.len(),
                loose.len()
            );
            assert_on_area_or_boundary(&joined, &area, family);
            // Every piece printed once: the joined length is the loose length plus connectors
            // no longer than the limit each.
            let (a, b) = (
                loose.iter().map(polyline_length).sum::<f64>(),
                joined.iter().map(polyline_length).sum::<f64>(),
            );
            let links = loose.len() - joined.len() + 2 * joined.len();
            assert!(
                b >= a && b <= a + links as f64 * CONNECT_LIMIT * 2.0,
                "{angle}°: {a} → {b}"
            );
        }
    }

    #[test]
    fn connectors_do_not_cross_a_notch() {
        // A U shape: lines across both arms must not be joined across the notch.
        let u = crate::geom::ExPolygon {
            contour: Polygon::new(vec![
                Point2::from_mm(0.0, 0.0),
                Point2::from_mm(10.0, 0.0),
                Point2::from_mm(10.0, 10.0),
                Point2::from_mm(6.0, 10.0),
                Point2::from_mm(6.0, 2.0),
                Point2::from_mm(4.0, 2.0),
                Point2::from_mm(4.0, 10.0),
                Point2::from_mm(0.0, 10.0),
            ]),
            holes: vec![],
        };
        let family = LineFamily {
            angle_rad: 0.0,
            spacing_mm: 1.0,
            phase: 0.5,
        };
        let area = [u];
        assert_on_area_or_boundary(&fill_family(&area, family, true), &area, family);
        for l in fill_family(&area, family, true) {
            for w in l.points.windows(2) {
                assert!(segment_inside(w[0], w[1], &area), "{:?} leaves the U", w);
                let (x0, x1) = (w[0].x.min(w[1].x), w[0].x.max(w[1].x));
                let y0 = w[0].y.min(w[1].y);
                // Nothing printed over the notch (4 < x < 6, y > 2).
                assert!(
                    !(x0 < scaled(5.0) && x1 > scaled(5.0) && y0 > scaled(2.0)),
                    "{w:?}"
                );
            }
        }
        assert!(!segment_inside(
            Point2::from_mm(3.0, 5.0),
            Point2::from_mm(7.0, 5.0),
            &area
        ));
        assert!(segment_inside(
            Point2::from_mm(10.0, 3.0),
            Point2::from_mm(10.0, 8.0),
            &area
        ));
    }

    #[test]
    fn tiny_or_invalid_spacing_gives_nothing() {
        let area = [rect_island(0.0, 0.0, 10.0, 1.0)];
        for spacing_mm in [0.0, -1.0, f64::NAN, 1e-7] {
            let f = LineFamily {
                angle_rad: 0.3,
                spacing_mm,
                phase: 0.5,
            };
            assert!(fill_family(&area, f, true).is_empty(), "{spacing_mm}");
        }
        assert!(
            fill_family(
                &[],
                LineFamily {
                    angle_rad: 0.0,
                    spacing_mm: 1.0,
                    phase: 0.5
                },
                true
            )
            .is_empty()
        );
    }
}
