//! Clipping a family of parallel lattice lines to an area in one sweep: the pieces of every line
//! inside the area, in the order a serpentine through the lines meets them.
//!
//! Place in the pipeline: regions stage, the first step of every line pattern
//! ([`super::lines::fill_family`]), before the pieces are joined into zig-zags.
//!
//! Each boundary edge is visited once and crossed with the lattice lines its ends span (the
//! classic scan-line fill of a polygon): `O(E + C log C)` for `E` edges and `C` crossings,
//! where a general polyline clip pays for building and splitting a graph of both. A point of a
//! line is inside where the winding number of the rings (contours counter-clockwise, holes
//! clockwise, whatever their stored orientation) is positive, so overlapping areas fill as
//! their union. An edge crosses line `c` when its ends lie on different sides of the half-open
//! split `< c` / `≥ c`, so a vertex on a line counts once and a line grazing a vertex gets no
//! zero-length piece.

use crate::geom::{ExPolygon, Point2, Polygon};

/// Shortest piece kept, nm: the G-code's resolution (1 µm). A line passing a vertex within
/// rounding is cut into a piece of a few nanometres that would print as a dot between a
/// retraction and a prime.
const MIN_SPAN_NM: i128 = 1000;

/// A family's lattice in scaled (nm) coordinates: line `k` is `{p : p·n = (k + phase)·spacing}`,
/// and `p·d` is the position along it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Lattice {
    /// Direction of the lines (unit vector).
    pub d: (f64, f64),
    /// Normal of the lines: `d` turned by +90°.
    pub n: (f64, f64),
    /// Distance between neighbouring lines, nm.
    pub spacing: f64,
    /// Offset of the lattice from the origin, in spacings.
    pub phase: f64,
}

impl Lattice {
    /// `p`'s coordinates across and along the lines: (`p·n`, `p·d`), nm.
    fn project(&self, p: Point2) -> (f64, f64) {
        let (x, y) = (p.x as f64, p.y as f64);
        (x * self.n.0 + y * self.n.1, x * self.d.0 + y * self.d.1)
    }

    /// `p·n` of line `k`, nm.
    fn offset_of(&self, k: i64) -> f64 {
        (k as f64 + self.phase) * self.spacing
    }

    /// The point at `t` nm along line `k`, rounded to the nanometre.
    fn point(&self, k: i64, t: f64) -> Point2 {
        let c = self.offset_of(k);
        Point2::new(
            (c * self.n.0 + t * self.d.0).round() as i64,
            (c * self.n.1 + t * self.d.1).round() as i64,
        )
    }
}

/// A piece of lattice line `line` inside the area, from `points[0]` to `points[1]`.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Span {
    /// The lattice line it lies on.
    pub line: i64,
    /// Its ends, in the serpentine's direction of travel.
    pub points: [Point2; 2],
}

/// The pieces of lattice lines `k_lo..=k_hi` inside `area`, in serpentine order: line by line
/// from `k_lo`, even lines in increasing `p·d`, odd lines in decreasing `p·d`.
pub(super) fn clip_lines(area: &[ExPolygon], lattice: &Lattice, k_lo: i64, k_hi: i64) -> Vec<Span> {
    let Some(count) = usize::try_from(k_hi - k_lo + 1).ok().filter(|&c| c > 0) else {
        return Vec::new();
    };
    // Per line, its crossings: (position along it, change of winding number).
    let mut crossings: Vec<Vec<(f64, i32)>> = vec![Vec::new(); count];
    for ex in area {
        add_ring(&mut crossings, &ex.contour, true, lattice, k_lo);
        for hole in &ex.holes {
            add_ring(&mut crossings, hole, false, lattice, k_lo);
        }
    }
    let mut spans = Vec::new();
    for (i, line) in crossings.iter_mut().enumerate() {
        if line.is_empty() {
            continue;
        }
        let k = k_lo + i as i64;
        // At one position, entries before exits: pieces meeting at a point of the boundary
        // (two rings touching) join into one.
        line.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)));
        let mut inside: Vec<(f64, f64)> = Vec::new();
        let mut winding = 0;
        let mut start = 0.0;
        for &(t, delta) in line.iter() {
            let was_inside = winding > 0;
            winding += delta;
            match (was_inside, winding > 0) {
                (false, true) => start = t,
                (true, false) => inside.push((start, t)),
                _ => {}
            }
        }
        let mut pieces: Vec<Span> = inside
            .into_iter()
            .map(|(a, b)| Span {
                line: k,
                points: [lattice.point(k, a), lattice.point(k, b)],
            })
            .filter(|s| s.points[0].distance_squared(s.points[1]) >= MIN_SPAN_NM * MIN_SPAN_NM)
            .collect();
        if k.rem_euclid(2) == 1 {
            pieces.reverse();
            for p in &mut pieces {
                p.points.reverse();
            }
        }
        spans.extend(pieces);
    }
    spans
}

/// Adds the crossings of `ring`'s edges with the lattice lines to `crossings` (indexed from line
/// `k_lo`). A `contour` winds +1 around what it holds and a hole −1, whatever its orientation.
fn add_ring(
    crossings: &mut [Vec<(f64, i32)>],
    ring: &Polygon,
    contour: bool,
    lattice: &Lattice,
    k_lo: i64,
) {
    let pts = &ring.points;
    if pts.len() < 3 {
        return;
    }
    // +1 when the ring is stored the way it winds (contour counter-clockwise, hole clockwise).
    let sign = if (ring.signed_area2() > 0) == contour {
        1
    } else {
        -1
    };
    let projected: Vec<(f64, f64)> = pts.iter().map(|&p| lattice.project(p)).collect();
    let last = crossings.len() as i64 - 1;
    for i in 0..projected.len() {
        let (a, b) = (projected[i], projected[(i + 1) % projected.len()]);
        if a.0 == b.0 {
            continue;
        }
        let (lo, hi) = if a.0 < b.0 { (a.0, b.0) } else { (b.0, a.0) };
        // Lines with lo ≤ c < hi: the ends lie on different sides of the split at c.
        let first = ((lo / lattice.spacing - lattice.phase).floor() as i64 - k_lo).max(0);
        let end = ((hi / lattice.spacing - lattice.phase).ceil() as i64 - k_lo).min(last);
        // (d, n) is a right-handed frame, so an edge going up (+n) on a counter-clockwise
        // contour has the inside on its left, at −d: a line crossing it in +t leaves the area.
        let delta = if b.0 > a.0 { -sign } else { sign };
        for j in first..=end {
            let c = lattice.offset_of(k_lo + j);
            if !(lo <= c && c < hi) {
                continue;
            }
            let t = a.1 + (c - a.0) / (b.0 - a.0) * (b.1 - a.1);
            if let Some(line) = usize::try_from(j).ok().and_then(|j| crossings.get_mut(j)) {
                line.push((t, delta));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MM: i64 = 1_000_000;

    fn square(x0: i64, y0: i64, side: i64, ccw: bool) -> Polygon {
        let mut pts = vec![
            Point2::new(x0, y0),
            Point2::new(x0 + side, y0),
            Point2::new(x0 + side, y0 + side),
            Point2::new(x0, y0 + side),
        ];
        if !ccw {
            pts.reverse();
        }
        Polygon { points: pts }
    }

    /// Horizontal lines 1 mm apart, half a spacing off the origin.
    fn horizontal() -> Lattice {
        Lattice {
            d: (1.0, 0.0),
            n: (0.0, 1.0),
            spacing: MM as f64,
            phase: 0.5,
        }
    }

    #[test]
    fn a_square_with_a_hole_gives_two_pieces_on_the_lines_through_the_hole() {
        // 10 mm square at the origin with a 4 mm hole at (3, 3); lines at y = 0.5, 1.5, … 9.5.
        let area = vec![ExPolygon {
            contour: square(0, 0, 10 * MM, true),
            holes: vec![square(3 * MM, 3 * MM, 4 * MM, false)],
        }];
        let spans = clip_lines(&area, &horizontal(), 0, 9);
        let on = |k: i64| spans.iter().filter(|s| s.line == k).count();
        assert_eq!(
            (0..10).map(on).collect::<Vec<_>>(),
            [1, 1, 1, 2, 2, 2, 2, 1, 1, 1]
        );
        // Line 3 (y = 3.5) runs backwards: (10 → 7), then (3 → 0).
        let line3: Vec<[Point2; 2]> = spans
            .iter()
            .filter(|s| s.line == 3)
            .map(|s| s.points)
            .collect();
        let y = 3 * MM + MM / 2;
        assert_eq!(
            line3,
            [
                [Point2::new(10 * MM, y), Point2::new(7 * MM, y)],
                [Point2::new(3 * MM, y), Point2::new(0, y)]
            ]
        );
        // Line 0 runs forwards over the whole width.
        assert_eq!(
            spans[0].points,
            [Point2::new(0, MM / 2), Point2::new(10 * MM, MM / 2)]
        );
    }

    #[test]
    fn orientation_of_the_stored_rings_does_not_matter() {
        let wound = vec![ExPolygon {
            contour: square(0, 0, 10 * MM, false),
            holes: vec![square(3 * MM, 3 * MM, 4 * MM, true)],
        }];
        let proper = vec![ExPolygon {
            contour: square(0, 0, 10 * MM, true),
            holes: vec![square(3 * MM, 3 * MM, 4 * MM, false)],
        }];
        assert_eq!(
            clip_lines(&wound, &horizontal(), 0, 9),
            clip_lines(&proper, &horizontal(), 0, 9)
        );
    }

    #[test]
    fn overlapping_areas_fill_as_their_union() {
        let area = vec![
            ExPolygon {
                contour: square(0, 0, 6 * MM, true),
                holes: vec![],
            },
            ExPolygon {
                contour: square(4 * MM, 0, 6 * MM, true),
                holes: vec![],
            },
        ];
        let spans = clip_lines(&area, &horizontal(), 0, 5);
        assert_eq!(spans.len(), 6);
        assert!(
            spans
                .iter()
                .all(|s| (s.points[1].x - s.points[0].x).abs() == 10 * MM)
        );
    }

    #[test]
    fn a_vertex_on_a_line_is_crossed_once() {
        // A diamond whose left and right vertices lie on y = 5.5 (line 5).
        let c = 5 * MM + MM / 2;
        let diamond = Polygon {
            points: vec![
                Point2::new(5 * MM, c - 3 * MM),
                Point2::new(8 * MM, c),
                Point2::new(5 * MM, c + 3 * MM),
                Point2::new(2 * MM, c),
            ],
        };
        let area = vec![ExPolygon {
            contour: diamond,
            holes: vec![],
        }];
        let spans = clip_lines(&area, &horizontal(), 0, 10);
        let line5: Vec<&Span> = spans.iter().filter(|s| s.line == 5).collect();
        assert_eq!(line5.len(), 1);
        // Line 5 is odd: it runs from right to left.
        assert_eq!(
            line5[0].points,
            [Point2::new(8 * MM, c), Point2::new(2 * MM, c)]
        );
        // The top and bottom vertices sit between lines; lines 3..=7 meet the diamond.
        let lines: Vec<i64> = spans.iter().map(|s| s.line).collect();
        assert_eq!(lines, [3, 4, 5, 6, 7]);
    }

    #[test]
    fn a_slanted_lattice_cuts_at_the_exact_positions() {
        // Lines at 45°: p·n = (k + ½)·s with n = (−√½, √½); a 10 mm square.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let lattice = Lattice {
            d: (h, h),
            n: (-h, h),
            spacing: MM as f64,
            phase: 0.5,
        };
        let area = vec![ExPolygon {
            contour: square(0, 0, 10 * MM, true),
            holes: vec![],
        }];
        let spans = clip_lines(&area, &lattice, -8, 7);
        // p·n ranges over ±10/√2 = ±7.07 mm: lines −8 (c = −7.5) and 7 (c = 7.5) miss it.
        assert_eq!(spans.first().map(|s| s.line), Some(-7));
        assert_eq!(spans.last().map(|s| s.line), Some(6));
        for s in &spans {
            // Both ends on the square's boundary, the piece on its line.
            for p in s.points {
                let on_edge = [p.x, p.y]
                    .iter()
                    .any(|&v| v.abs() <= 1 || (v - 10 * MM).abs() <= 1);
                assert!(on_edge, "{p:?}");
                let across = (-(p.x as f64) + p.y as f64) * h;
                assert!((across - (s.line as f64 + 0.5) * MM as f64).abs() < 1.0);
            }
        }
    }
}
