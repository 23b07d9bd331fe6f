//! Closed contours get a gap where the shutter opens and closes, and the gap moves every layer.
//!
//! Place in the pipeline: design polylines → corners → fillet → **contour** → schedule → program →
//! emit.
//!
//! The places for the gap are on straight stretches of the filleted contour, at least
//! `margin + gap` from the nearest corner (a fillet arc, or a joint sharper than
//! [`STRAIGHT_DEG`]), so the bump of the shutter never lands on a corner. Up to `positions`
//! places are spread over the stretches: with at least as many stretches as places, place `p`
//! sits in the middle of stretch `⌊p·S/n⌋` (one per stretch: on the 16 edges of an 8-point
//! star, one per edge); with fewer stretches, place `p` goes to stretch `p mod S`, so
//! consecutive layers always use different stretches, spread evenly along it. Layer `k` uses
//! place `k mod n`.

use super::path::{Chain, Seg};

/// Joints between straight segments at least this straight (degrees) do not end a stretch
/// (flattened curves from SVG or DXF are chains of nearly straight joints).
pub const STRAIGHT_DEG: f64 = 175.0;

/// Where a closed contour's gap goes, layer by layer.
#[derive(Debug, Clone, PartialEq)]
pub struct GapPlaces {
    /// Distance of each place from the chain's start, mm, in the order layers use them.
    pub at: Vec<f64>,
    /// No straight stretch was long enough: the places are wherever there was room, possibly
    /// near a corner.
    pub cramped: bool,
}

/// Straight stretches of a closed chain: `(from, to)` distances from its start, mm (possibly
/// past the chain's length for a stretch across its start), shrunk by `keep` at both ends.
fn stretches(chain: &Chain, keep: f64) -> Vec<(f64, f64)> {
    let segs = &chain.segs;
    let n = segs.len();
    if n == 0 {
        return Vec::new();
    }
    // Whether the joint before segment i continues a straight stretch.
    let continues = |i: usize| -> bool {
        let (p, s) = (&segs[(i + n - 1) % n], &segs[i]);
        match (p, s) {
            (Seg::Line { a: pa, b: pb }, Seg::Line { b: sb, .. }) => {
                super::corners::corner_angle(*pa, *pb, *sb) >= STRAIGHT_DEG
            }
            _ => false,
        }
    };
    let mut starts_at = Vec::with_capacity(n);
    let mut s = 0.0;
    for seg in segs {
        starts_at.push(s);
        s += seg.length();
    }
    let total = s;
    // Start the walk at a segment that begins a stretch (or anywhere, if all continue).
    let first = (0..n).find(|&i| !continues(i)).unwrap_or(0);
    let mut out = Vec::new();
    let mut run: Option<(f64, f64)> = None;
    for k in 0..n {
        let i = (first + k) % n;
        let is_line = matches!(segs[i], Seg::Line { .. });
        // Unwrapped distance so stretches crossing the chain's start stay contiguous.
        let from = starts_at[i] + if i < first { total } else { 0.0 };
        let to = from + segs[i].length();
        match (&mut run, is_line && k > 0 && continues(i)) {
            (Some(r), true) => r.1 = to,
            _ => {
                if let Some(r) = run.take() {
                    out.push(r);
                }
                if is_line {
                    run = Some((from, to));
                }
            }
        }
    }
    if let Some(r) = run {
        out.push(r);
    }
    out.into_iter()
        .filter_map(|(a, b)| (b - a > 2.0 * keep).then_some((a + keep, b - keep)))
        .collect()
}

/// The places of the gap of a closed `chain` (see the [module docs](self)): `positions` places
/// at least `margin + gap` from corners.
pub fn gap_places(chain: &Chain, positions: usize, gap: f64, margin: f64) -> GapPlaces {
    let total = chain.length();
    let n = positions.max(1);
    let mut runs = stretches(chain, margin + gap);
    let mut cramped = false;
    if runs.is_empty() {
        cramped = true;
        // The longest straight segment's middle, else the chain's start.
        let mut s = 0.0;
        let mut best: Option<(f64, f64)> = None;
        for seg in &chain.segs {
            let l = seg.length();
            if matches!(seg, Seg::Line { .. }) && best.is_none_or(|b| l > b.1 - b.0) {
                best = Some((s, s + l));
            }
            s += l;
        }
        let mid = best.map_or(0.0, |(a, b)| (a + b) / 2.0);
        runs = vec![(mid, mid)];
    }
    let count = runs.len();
    let at = (0..n)
        .map(|p| {
            let (run, slot, slots) = if count >= n {
                (p * count / n, 0, 1)
            } else {
                let run = p % count;
                let slots = (n - run).div_ceil(count);
                (run, p / count, slots)
            };
            let (a, b) = runs[run];
            let s = a + (b - a) * (slot as f64 + 1.0) / (slots as f64 + 1.0);
            if total > 0.0 { s % total } else { 0.0 }
        })
        .collect();
    GapPlaces { at, cramped }
}

/// The closed `chain` opened at distance `at` from its start: the path starts there, runs
/// once around and stops `gap` short of where it started.
pub fn open_at(chain: &Chain, at: f64, gap: f64) -> Chain {
    let (before, after) = chain.split_at(at);
    let mut segs = after.segs;
    segs.extend(before.segs);
    let rotated = Chain {
        segs,
        closed: false,
    };
    rotated.truncated((rotated.length() - gap).max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(side: f64) -> Chain {
        let p = [[0.0, 0.0], [side, 0.0], [side, side], [0.0, side]];
        Chain {
            segs: (0..4)
                .map(|i| Seg::Line {
                    a: p[i],
                    b: p[(i + 1) % 4],
                })
                .collect(),
            closed: true,
        }
    }

    #[test]
    fn sixteen_places_on_a_square_are_distinct_and_away_from_corners() {
        let sq = square(1.0);
        let g = gap_places(&sq, 16, 0.01, 0.02);
        assert!(!g.cramped);
        assert_eq!(g.at.len(), 16);
        let mut sorted = g.at.clone();
        sorted.sort_by(f64::total_cmp);
        sorted.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        assert_eq!(sorted.len(), 16);
        for (k, s) in g.at.iter().enumerate() {
            let along = s % 1.0;
            assert!((0.03 - 1e-12..=0.97 + 1e-12).contains(&along), "{s}");
            // Consecutive layers are on different edges.
            let next = g.at[(k + 1) % 16];
            assert_ne!((s / 1.0).floor(), (next / 1.0).floor());
        }
    }

    #[test]
    fn opening_leaves_the_gap_on_the_same_edge() {
        let sq = square(1.0);
        let open = open_at(&sq, 2.5, 0.01);
        assert!((open.length() - 3.99).abs() < 1e-12);
        let (s, e) = (open.start(), open.end());
        assert_eq!(s, Some([0.5, 1.0]));
        let e = e.unwrap_or_default();
        assert!((e[0] - 0.51).abs() < 1e-12 && (e[1] - 1.0).abs() < 1e-12);
    }
}
