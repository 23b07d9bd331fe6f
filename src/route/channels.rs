//! Channels: the regions a routed trace occupies, carved from the plastic and from the islands
//! seen by the wires routed after it.
//!
//! Place in the pipeline: the last step of routing. After a wire is routed, its trace grown by
//! `(conductive_width + channel_extra) / 2` (its channel) becomes a hole in the islands of the
//! following wires of other nets, and its trace grown by twice that (its keep-out) is where their
//! direct connections may not run; the union of all channels per layer goes to the caller.
//!
//! A channel is built as the union of one rectangle per trace segment and one regular 16-gon per
//! trace point. The 16-gons circumscribe the round joints (their sides touch the circle of the
//! half-width), so a channel always covers the true rounded stroke and reaches at most
//! `half / cos(π/16)` (≈ 1.02 · half) from the centreline.

use super::RouteParams;
use super::index::dist;
use crate::geom::{
    ExPolygon, Join, Point2, Point3, Polygon, offset, scaled, segment_distance, union,
};
use std::f64::consts::PI;

/// Sides of the polygons standing for round joints and pads.
const JOINT_SIDES: usize = 16;

/// Trace points closer than this to the chord of their neighbours are dropped before the channel
/// is built (scaled units: 1 µm, far below the printer's resolution).
const SIMPLIFY_NM: f64 = 1_000.0;

/// Extra clearance added to keep-outs (mm), beyond what the polygonal channels need, so that
/// the channels of two nets at the keep-out distance share no area after rounding.
const KEEP_OUT_MARGIN_MM: f64 = 0.005;

/// Farthest a channel of half-width `half` reaches from its centreline, mm.
pub(crate) fn circumscribed(half: f64) -> f64 {
    circumscribed_by(half, JOINT_SIDES)
}

/// Vertex radius of the regular `sides`-gon whose sides touch the circle of radius `radius`.
fn circumscribed_by(radius: f64, sides: usize) -> f64 {
    radius / (PI / sides as f64).cos()
}

/// Radius (mm) around another net's trace in which no trace centre may run: two channels, plus
/// a margin.
pub(crate) fn keep_out_radius(params: &RouteParams) -> f64 {
    2.0 * circumscribed(params.channel_half_width()) + KEEP_OUT_MARGIN_MM
}

/// Chord deviation of the round corners of grown pad outlines, mm; added to their growth so the
/// chords stay outside the true rounded outline.
const PAD_ROUND_MM: f64 = 0.005;

/// Another net's pad seen from a wire: the copper grown by half the channel clearance
/// (`channel_extra / 2`), which the wire's channel may not overlap (a hole in its islands),
/// and that grown by a channel half-width, where the wire's centre may not run (a keep-out).
/// A channel then keeps `channel_extra` clear of foreign copper, as between two traces.
pub(crate) fn pad_obstacle(outline: &Polygon, params: &RouteParams) -> [Vec<ExPolygon>; 2] {
    let copper = [ExPolygon {
        contour: outline.clone(),
        holes: Vec::new(),
    }];
    let grow = |d: f64| offset(&copper, d + PAD_ROUND_MM, Join::Round(PAD_ROUND_MM));
    let clearance = params.channel_extra / 2.0;
    [
        grow(clearance),
        grow(clearance + circumscribed(params.channel_half_width()) + KEEP_OUT_MARGIN_MM),
    ]
}

/// A regular 16-gon around `center` circumscribing the circle of radius `radius_mm`, as one
/// counter-clockwise ExPolygon.
pub(crate) fn disc(center: Point2, radius_mm: f64) -> Vec<ExPolygon> {
    disc_of(center, radius_mm, JOINT_SIDES)
}

/// A regular `sides`-gon around `center` circumscribing the circle of radius `radius_mm`.
fn disc_of(center: Point2, radius_mm: f64, sides: usize) -> Vec<ExPolygon> {
    let r = scaled(circumscribed_by(radius_mm, sides)) as f64;
    if r <= 0.0 {
        return Vec::new();
    }
    let points = (0..sides)
        .map(|k| {
            let a = 2.0 * PI * k as f64 / sides as f64;
            Point2::new(
                center.x + (r * a.cos()).round() as i64,
                center.y + (r * a.sin()).round() as i64,
            )
        })
        .collect();
    vec![ExPolygon {
        contour: Polygon::new(points),
        holes: Vec::new(),
    }]
}

/// `points` without repeats and without points within 1 µm of the chord of their neighbours
/// (Douglas–Peucker), so straight runs of supersampled points become one segment.
fn simplify(points: &[Point2]) -> Vec<Point2> {
    let mut pts: Vec<Point2> = Vec::with_capacity(points.len());
    for &p in points {
        if pts.last() != Some(&p) {
            pts.push(p);
        }
    }
    if pts.len() < 3 {
        return pts;
    }
    let mut keep = vec![false; pts.len()];
    keep[0] = true;
    keep[pts.len() - 1] = true;
    let mut stack = vec![(0, pts.len() - 1)];
    while let Some((i, j)) = stack.pop() {
        let mut far = (0.0, 0);
        for (k, &p) in pts.iter().enumerate().take(j).skip(i + 1) {
            let d = segment_distance(p, pts[i], pts[j]);
            if d > far.0 {
                far = (d, k);
            }
        }
        if far.0 > SIMPLIFY_NM {
            keep[far.1] = true;
            stack.push((i, far.1));
            stack.push((far.1, j));
        }
    }
    pts.into_iter()
        .zip(keep)
        .filter_map(|(p, k)| k.then_some(p))
        .collect()
}

/// The polyline `points` grown by `half_mm` on each side, with round (16-gon) joints and ends.
pub(crate) fn polyline_channel(points: &[Point2], half_mm: f64) -> Vec<ExPolygon> {
    polyline_outline(points, half_mm, JOINT_SIDES)
}

/// Sides of the joints of a polyline grown by `radius_mm`: as many as keep the circumscribing
/// polygon within [`GROWN_BULGE_MM`] of the circle, at least [`JOINT_SIDES`].
fn sides_for(radius_mm: f64) -> usize {
    let mut sides = JOINT_SIDES;
    while sides < 256 && circumscribed_by(radius_mm, sides) - radius_mm > GROWN_BULGE_MM {
        sides *= 2;
    }
    sides
}

/// Farthest the joints of a grown polyline ([`polyline_grown`]) reach past the true round
/// outline, mm.
const GROWN_BULGE_MM: f64 = 0.01;

/// The polyline `points` grown by `radius_mm` with joints fine enough to stay within
/// [`GROWN_BULGE_MM`] of the true round outline: a channel grown by a deflation inset.
pub(crate) fn polyline_grown(points: &[Point2], radius_mm: f64) -> Vec<ExPolygon> {
    polyline_outline(points, radius_mm, sides_for(radius_mm))
}

/// The polyline `points` grown by `half_mm` on each side, with round (`sides`-gon) joints.
fn polyline_outline(points: &[Point2], half_mm: f64, sides: usize) -> Vec<ExPolygon> {
    let pts = simplify(points);
    let h = scaled(half_mm) as f64;
    if pts.is_empty() || h <= 0.0 {
        return Vec::new();
    }
    let mut pieces: Vec<ExPolygon> = pts
        .iter()
        .flat_map(|&p| disc_of(p, half_mm, sides))
        .collect();
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = dist(a, b);
        if len <= 0.0 {
            continue;
        }
        // Left normal of a→b, scaled to the half-width.
        let (nx, ny) = (-(b.y - a.y) as f64 / len * h, (b.x - a.x) as f64 / len * h);
        let at = |p: Point2, s: f64| {
            Point2::new(p.x + (s * nx).round() as i64, p.y + (s * ny).round() as i64)
        };
        pieces.push(ExPolygon {
            contour: Polygon::new(vec![at(a, -1.0), at(b, -1.0), at(b, 1.0), at(a, 1.0)]),
            holes: Vec::new(),
        });
    }
    union(&pieces)
}

/// The channel of one trace polyline (the xy of `points`; z is ignored): the trace grown by
/// `half_width` mm on each side with round joints, as carved from the plastic.
///
/// For a [`WireRoute`](super::WireRoute) segment use
/// `trace_channel(&points, params.channel_half_width())`.
pub fn trace_channel(points: &[Point3], half_width: f64) -> Vec<ExPolygon> {
    let xy: Vec<Point2> = points.iter().map(|p| Point2::from_mm(p.x, p.y)).collect();
    polyline_channel(&xy, half_width)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_channel_has_the_stroke_area() {
        let pts: Vec<Point2> = (0..=10).map(|i| Point2::from_mm(i as f64, 0.0)).collect();
        let ch = polyline_channel(&pts, 0.4);
        assert_eq!(ch.len(), 1);
        let area: f64 = ch.iter().map(ExPolygon::area_mm2).sum();
        // 10 × 0.8 rectangle plus two half 16-gons slightly larger than half discs.
        let stroke = 10.0 * 0.8 + PI * 0.16;
        assert!(area >= stroke && area < stroke * 1.01, "{area}");
    }

    #[test]
    fn simplify_merges_collinear_samples() {
        let pts: Vec<Point2> = (0..=10).map(|i| Point2::from_mm(i as f64, 2.0)).collect();
        assert_eq!(simplify(&pts).len(), 2);
    }
}
