//! Walls and fills: which lines a design's outlines become.
//!
//! Place in the pipeline: design polylines → **fill** → corners → fillet → contour → schedule →
//! program → emit. Open polylines are always walls. Closed outlines are walls (`jet.fill = "wall"`:
//! the outline itself is the line's centre), or filled: `"contour"` prints the outline inset by
//! half a line width and further insets `fill_spacing × width` apart until nothing is left;
//! `"serpentine"` prints lines `fill_spacing × width` apart at `fill_angle`, inside the outline
//! inset by half a line width, joined end to end where the next line starts within two spacings.
//! The offsets and clipping are the project's exact integer-grid operations ([`crate::geom`]);
//! sharp corners stay sharp (mitred) so the corner rules see them.

use super::JetFill;
use crate::geom::{
    ExPolygon, FillRule, Join, Point2, Polygon, Polyline, clip_polylines, offset,
    polygons_to_expolygons,
};

/// A line to print: its centre as a polyline, mm, and whether it is a closed loop.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// Vertices, mm.
    pub points: Vec<[f64; 2]>,
    /// Closed loop (gets a shutter gap) or open.
    pub closed: bool,
    /// Part of a fill rather than the wall itself.
    pub fill: bool,
}

/// Miter limit of fill offsets: corners down to 2·asin(1/limit) ≈ 11.5° stay sharp.
const MITER_LIMIT: f64 = 10.0;

fn to_region(points: &[[f64; 2]]) -> Vec<ExPolygon> {
    let poly = Polygon::new(points.iter().map(|p| Point2::from_mm(p[0], p[1])).collect());
    polygons_to_expolygons(&[poly], FillRule::EvenOdd)
}

fn ring_mm(poly: &Polygon) -> Vec<[f64; 2]> {
    poly.points
        .iter()
        .map(|p| {
            let (x, y) = p.to_mm();
            [x, y]
        })
        .collect()
}

/// The lines of one outline for `mode`, line width `width` and spacing factor `spacing`.
pub fn lines(
    points: &[[f64; 2]],
    closed: bool,
    mode: JetFill,
    width: f64,
    spacing: f64,
    angle_deg: f64,
) -> Vec<Line> {
    if !closed || mode == JetFill::Wall {
        return vec![Line {
            points: points.to_vec(),
            closed,
            fill: false,
        }];
    }
    let region = to_region(points);
    let step = spacing * width;
    match mode {
        JetFill::Wall => Vec::new(),
        JetFill::Contour => {
            let mut out = Vec::new();
            let mut inset = width / 2.0;
            // Each loop is one step further in; stop when nothing is left (or after a bound
            // that no real outline reaches, so a degenerate offset can never loop forever).
            for _ in 0..100_000 {
                let loops = offset(&region, -inset, Join::Miter(MITER_LIMIT));
                if loops.is_empty() {
                    break;
                }
                for ex in &loops {
                    for ring in std::iter::once(&ex.contour).chain(&ex.holes) {
                        out.push(Line {
                            points: ring_mm(ring),
                            closed: true,
                            fill: true,
                        });
                    }
                }
                inset += step;
            }
            out
        }
        JetFill::Serpentine => serpentine(&region, width, step, angle_deg),
    }
}

fn serpentine(region: &[ExPolygon], width: f64, step: f64, angle_deg: f64) -> Vec<Line> {
    let inner = offset(region, -width / 2.0, Join::Miter(MITER_LIMIT));
    let (s, c) = angle_deg.to_radians().sin_cos();
    // Scan lines along direction (c, s), stacked along (−s, c).
    let pts: Vec<(f64, f64)> = inner
        .iter()
        .flat_map(|e| e.contour.points.iter())
        .map(|p| p.to_mm())
        .collect();
    if pts.is_empty() {
        return Vec::new();
    }
    let along = |p: &(f64, f64)| p.0 * c + p.1 * s;
    let across = |p: &(f64, f64)| -p.0 * s + p.1 * c;
    let (a0, a1) = pts
        .iter()
        .map(along)
        .fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let (b0, b1) = pts
        .iter()
        .map(across)
        .fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let mut scan = Vec::new();
    let mut b = b0;
    while b <= b1 + 1e-9 {
        let at = |a: f64| Point2::from_mm(a * c - b * s, a * s + b * c);
        scan.push(Polyline {
            points: vec![at(a0 - width), at(a1 + width)],
        });
        b += step;
    }
    let pieces = clip_polylines(&scan, &inner);
    let mut out: Vec<Line> = Vec::new();
    let mut forward = true;
    let mut last_b: Option<f64> = None;
    for piece in pieces {
        let mut p: Vec<[f64; 2]> = piece
            .points
            .iter()
            .map(|q| {
                let (x, y) = q.to_mm();
                [x, y]
            })
            .collect();
        let Some(first) = p.first().copied() else {
            continue;
        };
        let here = across(&(first[0], first[1]));
        if last_b.is_some_and(|l| (here - l).abs() > 1e-9) {
            forward = !forward;
        }
        last_b = Some(here);
        if !forward {
            p.reverse();
        }
        let joined = match out.last_mut() {
            Some(prev) => match (prev.points.last(), p.first()) {
                (Some(e), Some(s0)) if (e[0] - s0[0]).hypot(e[1] - s0[1]) <= 2.0 * step => {
                    prev.points.extend_from_slice(&p);
                    true
                }
                _ => false,
            },
            None => false,
        };
        if !joined {
            out.push(Line {
                points: p,
                closed: false,
                fill: true,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

    #[test]
    fn contour_loops_are_insets_a_spacing_apart() {
        let l = lines(&SQUARE, true, JetFill::Contour, 0.1, 1.0, 0.0);
        // Insets 0.05, 0.15, 0.25, 0.35, 0.45: five loops.
        assert_eq!(l.len(), 5);
        let min_x = l[1].points.iter().map(|p| p[0]).fold(f64::MAX, f64::min);
        assert!((min_x - 0.15).abs() < 1e-6);
    }

    #[test]
    fn serpentine_is_one_back_and_forth_line() {
        let l = lines(&SQUARE, true, JetFill::Serpentine, 0.1, 1.0, 0.0);
        assert_eq!(l.len(), 1);
        // Ten scan lines 0.1 apart from y = 0.05 to 0.95, two points each.
        assert_eq!(l[0].points.len(), 20);
        assert!((l[0].points[0][1] - 0.05).abs() < 1e-6);
        assert!((l[0].points[2][0] - 0.95).abs() < 1e-6);
    }
}
