//! Cutting a host extrusion move at the boundary of a layer's cuts (cavities and channels).
//!
//! Place in the pipeline: used by [`super::rewrite`] on every extruding move of a layer that has
//! cuts. A move is a polyline (a straight `G1` has two points, an arc the samples of
//! [`conduit_gcode::Move::path`]); [`split_move`] finds the stretches of it inside the cut region
//! and returns the move as [`Piece`]s in order: stretches outside keep extruding, each with the
//! move's E scaled by its share of the move's length (so the E of the kept pieces is exact, up to
//! the 5 decimals of the output); stretches inside become travels.
//!
//! The region is tested in floating point: each segment is intersected with every edge of the
//! region's rings, and each stretch between two crossings is inside when its midpoint is (even-odd
//! rule over all rings, which is the region's own rule since the rings come from a union). Stretches
//! shorter than [`MIN_PIECE`] are merged into their neighbours, outside stretches turning into
//! travel, so a move that only grazes a cut is never split into slivers and never extrudes inside.

use crate::geom::ExPolygon;

/// Stretches shorter than this are merged into their neighbours, mm: 1 µm, the resolution of the
/// written coordinates.
pub const MIN_PIECE: f64 = 0.001;

/// The cut region of one layer, as rings in millimetres with a bounding box for quick rejection.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CutRegion {
    rings: Vec<Vec<[f64; 2]>>,
    min: [f64; 2],
    max: [f64; 2],
}

impl CutRegion {
    /// The region covered by `areas`, which must not overlap (the output of a union).
    pub fn new(areas: &[ExPolygon]) -> Self {
        let mut rings = Vec::new();
        let (mut min, mut max) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for area in areas {
            for ring in std::iter::once(&area.contour).chain(&area.holes) {
                let points: Vec<[f64; 2]> = ring.points_mm();
                if points.len() < 3 {
                    continue;
                }
                for p in &points {
                    for k in 0..2 {
                        min[k] = min[k].min(p[k]);
                        max[k] = max[k].max(p[k]);
                    }
                }
                rings.push(points);
            }
        }
        Self { rings, min, max }
    }

    /// True when the region is empty.
    pub fn is_empty(&self) -> bool {
        self.rings.is_empty()
    }

    /// Whether `p` is inside the region (even-odd over the rings; points on an edge may go
    /// either way).
    pub fn contains(&self, p: [f64; 2]) -> bool {
        if self.is_empty()
            || p[0] < self.min[0]
            || p[0] > self.max[0]
            || p[1] < self.min[1]
            || p[1] > self.max[1]
        {
            return false;
        }
        let mut inside = false;
        for ring in &self.rings {
            let mut j = ring.len() - 1;
            for i in 0..ring.len() {
                let (a, b) = (ring[i], ring[j]);
                if (a[1] > p[1]) != (b[1] > p[1])
                    && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
                {
                    inside = !inside;
                }
                j = i;
            }
        }
        inside
    }

    /// Whether the box spanned by `points` can touch the region.
    fn may_touch(&self, points: &[[f64; 2]]) -> bool {
        if self.is_empty() {
            return false;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in points {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        lo[0] <= self.max[0] && hi[0] >= self.min[0] && lo[1] <= self.max[1] && hi[1] >= self.min[1]
    }

    /// Parameters `t` in (0, 1) where the segment `a`–`b` crosses a ring edge.
    fn crossings(&self, a: [f64; 2], b: [f64; 2], out: &mut Vec<f64>) {
        let d = [b[0] - a[0], b[1] - a[1]];
        for ring in &self.rings {
            let mut j = ring.len() - 1;
            for i in 0..ring.len() {
                let (c, e) = (ring[j], ring[i]);
                j = i;
                let f = [e[0] - c[0], e[1] - c[1]];
                let denom = d[0] * f[1] - d[1] * f[0];
                if denom == 0.0 {
                    // Parallel: a collinear overlap has no crossing of its own; the midpoint
                    // tests of the stretches around it decide.
                    continue;
                }
                let w = [c[0] - a[0], c[1] - a[1]];
                let t = (w[0] * f[1] - w[1] * f[0]) / denom;
                let u = (w[0] * d[1] - w[1] * d[0]) / denom;
                if t > 0.0 && t < 1.0 && (0.0..=1.0).contains(&u) {
                    out.push(t);
                }
            }
        }
    }
}

/// One piece of a cut move.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// The points the piece runs through after its start (its start is the previous piece's
    /// end, or the move's start), mm; the last one is the piece's end.
    pub points: Vec<[f64; 2]>,
    /// Length of the piece, mm.
    pub length: f64,
    /// Whether the piece extrudes (it lies outside the cuts).
    pub extrudes: bool,
}

/// The move through `points` (its start first; at least two points) cut by `region`: `None`
/// when no stretch of it longer than [`MIN_PIECE`] lies inside the region (the move stays as
/// it is), otherwise its pieces in order, alternating between extruding and travelling.
///
/// ```
/// use conduit::geom::{ExPolygon, Point2, Polygon};
/// use conduit::postprocess::cut::{CutRegion, split_move};
/// let square = |x0: f64, x1: f64| ExPolygon {
///     contour: Polygon::new(vec![
///         Point2::from_mm(x0, -1.0),
///         Point2::from_mm(x1, -1.0),
///         Point2::from_mm(x1, 1.0),
///         Point2::from_mm(x0, 1.0),
///     ]),
///     holes: vec![],
/// };
/// let region = CutRegion::new(&[square(4.0, 6.0)]);
/// let pieces = split_move(&[[0.0, 0.0], [10.0, 0.0]], &region).expect("crosses the cut");
/// let lengths: Vec<f64> = pieces.iter().map(|p| (p.length * 1e6).round() / 1e6).collect();
/// assert_eq!(lengths, vec![4.0, 2.0, 4.0]);
/// assert_eq!(pieces.iter().map(|p| p.extrudes).collect::<Vec<_>>(), vec![true, false, true]);
/// ```
pub fn split_move(points: &[[f64; 2]], region: &CutRegion) -> Option<Vec<Piece>> {
    if points.len() < 2 || !region.may_touch(points) {
        return None;
    }
    // Stretches as (start point, end point, inside), along the polyline.
    let mut stretches: Vec<([f64; 2], [f64; 2], bool)> = Vec::new();
    let mut ts: Vec<f64> = Vec::new();
    for seg in points.windows(2) {
        let (a, b) = (seg[0], seg[1]);
        ts.clear();
        ts.push(0.0);
        region.crossings(a, b, &mut ts);
        ts.push(1.0);
        ts.sort_by(f64::total_cmp);
        let at = |t: f64| [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
        for w in ts.windows(2) {
            if w[1] <= w[0] {
                continue;
            }
            let inside = region.contains(at((w[0] + w[1]) / 2.0));
            stretches.push((at(w[0]), at(w[1]), inside));
        }
    }
    // Short inside stretches are ignored; short outside ones do not extrude.
    let len = |s: &([f64; 2], [f64; 2], bool)| (s.1[0] - s.0[0]).hypot(s.1[1] - s.0[1]);
    let lengths: Vec<f64> = stretches.iter().map(len).collect();
    let mut states: Vec<bool> = stretches.iter().map(|s| s.2).collect();
    merge_short(&mut states, &lengths);
    if !states.iter().any(|&inside| inside) {
        return None;
    }
    let mut pieces: Vec<Piece> = Vec::new();
    for ((s, inside), length) in stretches.iter().zip(&states).zip(&lengths) {
        let extrudes = !inside;
        match pieces.last_mut() {
            Some(p) if p.extrudes == extrudes => {
                // Same state: the piece runs on (through the polyline's vertex or a crossing).
                if p.points.last() != Some(&s.1) {
                    p.points.push(s.1);
                }
                p.length += length;
            }
            _ => pieces.push(Piece {
                points: vec![s.1],
                length: *length,
                extrudes,
            }),
        }
    }
    Some(pieces)
}

/// Merges runs of one state shorter than [`MIN_PIECE`] into their neighbours: a short inside
/// run becomes outside (it is a graze), then a short outside run becomes inside (a sliver of
/// extrusion between two cut stretches is not worth a move).
fn merge_short(states: &mut [bool], lengths: &[f64]) {
    for pass_inside in [true, false] {
        let mut i = 0;
        while i < states.len() {
            let mut j = i;
            let mut run = 0.0;
            while j < states.len() && states[j] == states[i] {
                run += lengths[j];
                j += 1;
            }
            if states[i] == pass_inside && run < MIN_PIECE {
                for s in &mut states[i..j] {
                    *s = !pass_inside;
                }
            }
            i = j;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Point2, Polygon};

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> ExPolygon {
        ExPolygon {
            contour: Polygon::new(vec![
                Point2::from_mm(x0, y0),
                Point2::from_mm(x1, y0),
                Point2::from_mm(x1, y1),
                Point2::from_mm(x0, y1),
            ]),
            holes: vec![],
        }
    }

    #[test]
    fn a_move_through_a_square_is_cut_at_its_sides() {
        let region = CutRegion::new(&[rect(2.0, 2.0, 4.0, 4.0)]);
        // y = x + 1 enters through the left side at (2, 3) and leaves through the top at (3, 4).
        let pieces = split_move(&[[0.0, 1.0], [6.0, 7.0]], &region).expect("cut");
        assert_eq!(pieces.len(), 3);
        let s2 = 2f64.sqrt();
        let want = [2.0 * s2, s2, 3.0 * s2];
        for (p, w) in pieces.iter().zip(want) {
            assert!((p.length - w).abs() < 1e-9, "{} vs {w}", p.length);
        }
        assert_eq!(pieces[0].points, vec![[2.0, 3.0]]);
        assert!((pieces[1].points[0][0] - 3.0).abs() < 1e-9);
        assert_eq!(pieces[2].points, vec![[6.0, 7.0]]);
        assert!(!pieces[1].extrudes && pieces[0].extrudes && pieces[2].extrudes);
    }

    #[test]
    fn moves_that_miss_or_graze_stay_whole_and_inside_moves_become_travel() {
        let region = CutRegion::new(&[rect(2.0, 2.0, 4.0, 4.0)]);
        assert_eq!(split_move(&[[0.0, 0.0], [10.0, 0.0]], &region), None);
        // Through a corner only.
        assert_eq!(split_move(&[[0.0, 4.0], [4.0, 0.0]], &region), None);
        let inside = split_move(&[[2.5, 3.0], [3.5, 3.0]], &region).expect("inside");
        assert_eq!(inside.len(), 1);
        assert!(!inside[0].extrudes);
        // A polyline (an arc's samples) in and out keeps its vertices in the pieces.
        let pieces =
            split_move(&[[0.0, 3.0], [3.0, 3.0], [3.0, 6.0]], &region).expect("in and out");
        assert_eq!(pieces.len(), 3);
        assert_eq!(pieces[1].points, vec![[3.0, 3.0], [3.0, 4.0]]);
        assert!((pieces[1].length - 2.0).abs() < 1e-9);
    }

    #[test]
    fn holes_of_the_region_are_outside() {
        let mut ring = rect(0.0, 0.0, 10.0, 10.0);
        let hole = rect(3.0, 3.0, 7.0, 7.0).contour;
        ring.holes
            .push(Polygon::new(hole.points.into_iter().rev().collect()));
        let region = CutRegion::new(&[ring]);
        assert!(region.contains([1.0, 1.0]));
        assert!(!region.contains([5.0, 5.0]));
        let pieces = split_move(&[[-1.0, 5.0], [11.0, 5.0]], &region).expect("cut");
        let states: Vec<bool> = pieces.iter().map(|p| p.extrudes).collect();
        assert_eq!(states, vec![true, false, true, false, true]);
    }
}
