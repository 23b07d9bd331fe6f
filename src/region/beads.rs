//! Beads along a variable-thickness centreline: how many lines, how wide, and where.
//!
//! Place in the pipeline: stage "regions", after [`super::gapfill`] has turned the gaps and thin
//! walls of a layer into [`ThickPolyline`]s, for the variable perimeter generator
//! ([`super::PerimeterGenerator::Variable`]). A strip of thickness `t` is printed as
//! `n = max(1, round(t / spacing))` beads of thickness `t / n` side by side, the rule of the
//! distributed beading strategy in Kuipers et al., "A framework for adaptive width control of
//! dense contour-parallel toolpaths in fused deposition modeling" (Computer-Aided Design 128,
//! 2020; Arachne in Cura and PrusaSlicer): one bead up to 1.5 spacings, then two beads each
//! narrower than the nozzle rather than one bead twice its width, which a nozzle lays down badly.
//! Bead `j` of `n` runs at `(j − (n − 1)/2) · t / n` from the centreline, so the beads tile the
//! strip and `Σ thickness · length` is the strip's area as before. Where the count changes along a
//! line (a tapering wall), the line is cut there and each run gets its own beads: the
//! transitions of the paper, without its smoothing.

use super::gapfill::ThickPolyline;
use crate::geom::{Point2, scaled};

/// Most beads across one strip: gaps and thin walls are at most about two spacings thick, so a
/// larger count only comes from absurd input.
const MAX_BEADS: usize = 8;
/// Longest mitre at a vertex of an offset bead, as a multiple of its offset: a sharp turn of the
/// centreline would otherwise throw the offset point far out.
const MITRE_LIMIT: f64 = 2.0;

/// `line` as beads of at most about `spacing` mm thickness each (see the module docs). Lines
/// thinner than 1.5 spacings everywhere come back unchanged.
pub fn beads(line: &ThickPolyline, spacing: f64) -> Vec<ThickPolyline> {
    let n_seg = line.widths.len().min(line.points.len().saturating_sub(1));
    if n_seg == 0 || !(spacing.is_finite() && spacing > 0.0) {
        return vec![line.clone()];
    }
    let count = |t: f64| ((t / spacing).round() as usize).clamp(1, MAX_BEADS);
    let counts: Vec<usize> = line.widths[..n_seg].iter().map(|&t| count(t)).collect();
    if counts.iter().all(|&c| c == 1) {
        return vec![line.clone()];
    }
    let uniform = counts.iter().all(|&c| c == counts[0]);
    if line.closed && uniform {
        return offsets(&line.points, &line.widths[..n_seg], counts[0], true);
    }
    // Runs of equal count; a closed line is walked from its first segment (the cut there is one
    // more transition).
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=n_seg {
        if i == n_seg || counts[i] != counts[start] {
            let pts = &line.points[start..=i];
            let widths = &line.widths[start..i];
            if counts[start] == 1 {
                out.push(ThickPolyline {
                    points: pts.to_vec(),
                    widths: widths.to_vec(),
                    closed: false,
                });
            } else {
                out.extend(offsets(pts, widths, counts[start], false));
            }
            start = i;
        }
    }
    out
}

/// The `n` beads of the run `points`/`widths` (segment thicknesses), each `1/n` of the thickness,
/// offset sideways from the centreline; the even-numbered ones run the other way so that the
/// nozzle goes up one and back down the next.
fn offsets(points: &[Point2], widths: &[f64], n: usize, closed: bool) -> Vec<ThickPolyline> {
    let p: Vec<[f64; 2]> = points.iter().map(|q| [q.x as f64, q.y as f64]).collect();
    let m = widths.len();
    // Unit left normal of each segment (zero for a degenerate one).
    let normals: Vec<[f64; 2]> = (0..m)
        .map(|i| {
            let (dx, dy) = (p[i + 1][0] - p[i][0], p[i + 1][1] - p[i][1]);
            let l = dx.hypot(dy);
            if l > 0.0 {
                [-dy / l, dx / l]
            } else {
                [0.0, 0.0]
            }
        })
        .collect();
    // Per vertex: the mitred normal (bisector scaled by 1/cos of half the turn, capped) and the
    // thickness there (mean of the segments meeting there).
    let at = |v: usize| -> ([f64; 2], f64) {
        let before = if v > 0 {
            Some(v - 1)
        } else if closed {
            Some(m - 1)
        } else {
            None
        };
        let after = if v < m {
            Some(v)
        } else if closed {
            Some(0)
        } else {
            None
        };
        let (a, b) = match (before, after) {
            (Some(a), Some(b)) => (a, b),
            (Some(a), None) => (a, a),
            (None, Some(b)) => (b, b),
            (None, None) => return ([0.0, 0.0], 0.0),
        };
        let (na, nb) = (normals[a], normals[b]);
        let (sx, sy) = (na[0] + nb[0], na[1] + nb[1]);
        let l = sx.hypot(sy);
        let t = (widths[a] + widths[b]) / 2.0;
        if l < 1e-9 {
            return (nb, t);
        }
        let (bx, by) = (sx / l, sy / l);
        let cos = (bx * nb[0] + by * nb[1]).max(1.0 / MITRE_LIMIT);
        ([bx / cos, by / cos], t)
    };
    let vertex: Vec<([f64; 2], f64)> = (0..p.len()).map(at).collect();
    (0..n)
        .map(|j| {
            let f = (j as f64 - (n as f64 - 1.0) / 2.0) / n as f64;
            let mut pts: Vec<Point2> = p
                .iter()
                .zip(&vertex)
                .map(|(q, (nv, t))| {
                    let d = scaled(f * t) as f64;
                    Point2::new(
                        (q[0] + nv[0] * d).round() as i64,
                        (q[1] + nv[1] * d).round() as i64,
                    )
                })
                .collect();
            let mut w: Vec<f64> = widths.iter().map(|t| t / n as f64).collect();
            if closed {
                // The closing point repeats the first exactly.
                if let Some(&first) = pts.first()
                    && let Some(last) = pts.last_mut()
                {
                    *last = first;
                }
            }
            if j % 2 == 1 && !closed {
                pts.reverse();
                w.reverse();
            }
            ThickPolyline {
                points: pts,
                widths: w,
                closed,
            }
        })
        .collect()
}

/// `line` with every thickness raised to at least `min` mm.
pub fn at_least(mut line: ThickPolyline, min: f64) -> ThickPolyline {
    for w in &mut line.widths {
        *w = w.max(min);
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::unscaled;

    fn mm(x: f64, y: f64) -> Point2 {
        Point2::from_mm(x, y)
    }

    fn area(lines: &[ThickPolyline]) -> f64 {
        lines
            .iter()
            .map(|l| {
                l.points
                    .windows(2)
                    .zip(&l.widths)
                    .map(|(s, w)| (s[0].distance_squared(s[1]) as f64).sqrt() * unscaled(1) * w)
                    .sum::<f64>()
            })
            .sum()
    }

    #[test]
    fn a_strip_under_one_and_a_half_spacings_is_one_bead() {
        let line = ThickPolyline {
            points: vec![mm(0.0, 0.0), mm(10.0, 0.0)],
            widths: vec![0.6],
            closed: false,
        };
        assert_eq!(beads(&line, 0.407), vec![line]);
    }

    #[test]
    fn a_strip_of_two_spacings_is_two_beads_either_side_of_the_middle() {
        let line = ThickPolyline {
            points: vec![mm(0.0, 0.0), mm(10.0, 0.0), mm(10.0, 10.0)],
            widths: vec![0.8, 0.8],
            closed: false,
        };
        let b = beads(&line, 0.407);
        assert_eq!(b.len(), 2);
        for l in &b {
            assert_eq!(l.widths, vec![0.4, 0.4]);
        }
        // Bead 0 on the right of the centreline (y = −0.2 along the first leg), bead 1 on the
        // left, run backwards.
        assert_eq!(b[0].points[0], mm(0.0, -0.2));
        assert_eq!(b[0].points[1], mm(10.2, -0.2));
        assert_eq!(b[1].points[2], mm(0.0, 0.2));
        assert_eq!(b[1].points[1], mm(9.8, 0.2));
        // The beads together stand for the strip's area, up to the corner's in- and outside.
        assert!((area(&b) - area(&[line])).abs() < 1e-9);
    }

    #[test]
    fn a_tapering_strip_changes_count_where_its_thickness_crosses_one_and_a_half_spacings() {
        let line = ThickPolyline {
            points: (0..=4).map(|i| mm(f64::from(i), 0.0)).collect(),
            widths: vec![0.3, 0.5, 0.7, 0.8],
            closed: false,
        };
        let b = beads(&line, 0.4);
        assert_eq!(b.len(), 3);
        assert_eq!(b[0].widths, vec![0.3, 0.5]);
        assert_eq!(b[1].widths, vec![0.35, 0.4]);
        assert_eq!(b[1].points[0], mm(2.0, -0.175));
        // The beads follow the taper, so they are a little longer than the centreline.
        let whole = area(std::slice::from_ref(&line));
        assert!((area(&b) - whole).abs() < 2e-4, "{} {whole}", area(&b));
    }

    #[test]
    fn a_closed_ring_of_two_spacings_gives_two_closed_rings() {
        let pts = vec![
            mm(0.0, 0.0),
            mm(10.0, 0.0),
            mm(10.0, 10.0),
            mm(0.0, 10.0),
            mm(0.0, 0.0),
        ];
        let line = ThickPolyline {
            points: pts,
            widths: vec![0.8; 4],
            closed: true,
        };
        let b = beads(&line, 0.4);
        assert_eq!(b.len(), 2);
        assert!(
            b.iter()
                .all(|l| l.closed && l.points.first() == l.points.last())
        );
        // Inside ring (left of a counter-clockwise square) is 0.4 mm shorter per side... times 4
        // sides, the outside ring as much longer: the area is kept.
        assert!((area(&b) - area(&[line])).abs() < 1e-9);
        assert_eq!(b[1].points[0], mm(0.2, 0.2));
    }

    #[test]
    fn thin_lines_are_raised_to_the_narrowest_bead() {
        let line = ThickPolyline {
            points: vec![mm(0.0, 0.0), mm(1.0, 0.0), mm(2.0, 0.0)],
            widths: vec![0.1, 0.5],
            closed: false,
        };
        assert_eq!(at_least(line, 0.3).widths, vec![0.3, 0.5]);
    }
}
