//! Bridge direction: which way infill lines over air should run so both ends are anchored.
//!
//! Place in the pipeline: stage "regions", after [`super::skins`] has found the bottom solid
//! areas; for each bottom area that hangs over air (a *bridge*), [`bridge_angle`] chooses the
//! direction of its infill lines, as PrusaSlicer's `BridgeDetector` does.
//!
//! Method (areas in scaled integer coordinates):
//!
//! 1. **Anchors** are the islands of the layer below inside the bridge grown by one spacing; the
//!    **span** is the unsupported part (bridge − lower), shrunk by a quarter spacing so that a
//!    line running along a support edge does not count as bridging.
//! 2. **Candidates**: every 5° in [0°, 180°), plus the direction of, and the normal to, each of
//!    the [`EDGE_CANDIDATES`] longest edges of the unsupported part's contours; a candidate within
//!    0.5° of an earlier one is dropped.
//! 3. **Score** of a candidate: the lines of the lattice that infill uses
//!    ([`super::infill::lines`], phase ½) are cut by the bridge into pieces; a piece is
//!    *anchored* when both its ends lie in the anchors. The score is the length over the span of
//!    the anchored pieces divided by the length over the span of all pieces (the anchored
//!    fraction of the bridged area), and the *sag* is the longest single stretch of an anchored
//!    piece over the span.
//! 4. **Choice**: among candidates scoring at least 99 % of the best score, the smallest sag
//!    wins (shorter bridges sag less); remaining ties go to the smallest angle. No anchored
//!    length over the span at all (a cantilever, or nothing over air) gives `None`.
//!
//! Cost: the lines are never built as polylines nor clipped with booleans. Each candidate turns
//! the rings of the bridge and the span once into the frame of its lines, then cuts each lattice
//! line that crosses the span by an even–odd scan over the ring edges (O(lines × edges), into
//! reused buffers); only piece ends are tested against the anchors. A 12 × 20 mm bridge takes
//! about half a millisecond in a release build.

use super::infill::lines::{MAX_LINES, contains};
use crate::geom::{ExPolygon, Join, Point2, difference, intersection, offset, scaled};

/// How many of the longest edges of the unsupported area add candidate directions.
pub const EDGE_CANDIDATES: usize = 4;

/// Candidates closer than this (degrees, modulo 180°) to an earlier candidate are dropped.
const DEDUPE_DEG: f64 = 0.5;

/// Direction (degrees counter-clockwise from +X, in [0, 180)) for the infill lines of `bridge`
/// (one connected area over air, already grown a little into its surroundings), given `lower` =
/// the islands of the layer below (where lines can be anchored), and `spacing` (mm) between
/// bridge lines. `None` when no direction anchors any line over air at both ends (e.g. a
/// cantilever, or a bridge that is fully supported), or when the input is degenerate; the caller
/// then keeps its default infill angle. See the module docs for the method.
pub fn bridge_angle(bridge: &ExPolygon, lower: &[ExPolygon], spacing: f64) -> Option<f64> {
    let s = scaled(spacing) as f64;
    if !(spacing.is_finite() && s >= 1.0) || bridge.contour.points.len() < 3 {
        return None;
    }
    let area = std::slice::from_ref(bridge);
    let anchors = intersection(lower, &offset(area, spacing, Join::Miter(2.0)));
    let unsupported = difference(area, lower);
    let span = offset(&unsupported, -spacing / 4.0, Join::Miter(2.0));
    if anchors.is_empty() || span.is_empty() {
        return None;
    }
    // (score, sag, angle) of the candidates that anchor something over the span.
    let scored: Vec<(f64, f64, f64)> = candidates(&unsupported)
        .into_iter()
        .filter_map(|angle| {
            let (covered, total, sag) = score(angle, s, area, &span, &anchors)?;
            (covered > 0.0 && total > 0.0).then_some((covered / total, sag, angle))
        })
        .collect();
    let best = scored.iter().map(|s| s.0).fold(0.0, f64::max);
    scored
        .into_iter()
        .filter(|s| s.0 >= 0.99 * best)
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.2.total_cmp(&b.2)))
        .map(|s| s.2)
}

/// Rings of `area` in the frame `(p·d, p·n)` of lines along `d` (nm).
type Rings = Vec<Vec<(f64, f64)>>;

/// For lines at `angle` (degrees) spaced `s` nm: (anchored length over the span, length over the
/// span, longest anchored stretch over the span), in nm; `None` when there are too many lines.
fn score(
    angle: f64,
    s: f64,
    bridge: &[ExPolygon],
    span: &[ExPolygon],
    anchors: &[ExPolygon],
) -> Option<(f64, f64, f64)> {
    let (sin, cos) = angle.to_radians().sin_cos();
    let (d, n) = ((cos, sin), (-sin, cos));
    let frame = |area: &[ExPolygon]| -> Rings {
        let rings = area
            .iter()
            .flat_map(|e| std::iter::once(&e.contour).chain(&e.holes));
        let dot = |p: &Point2, v: (f64, f64)| p.x as f64 * v.0 + p.y as f64 * v.1;
        rings
            .map(|r| r.points.iter().map(|p| (dot(p, d), dot(p, n))).collect())
            .collect()
    };
    let (bridge, span) = (frame(bridge), frame(span));
    let (lo, hi) = span
        .iter()
        .flatten()
        .fold((f64::MAX, f64::MIN), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
    // Line k lies at p·n = (k + ½)·s, as in `infill::lines`.
    let (k_lo, k_hi) = ((lo / s - 0.5).ceil(), (hi / s - 0.5).floor());
    if k_hi - k_lo > MAX_LINES {
        return None;
    }
    let world = |x: f64, y: f64| {
        Point2::new(
            (x * d.0 + y * n.0).round() as i64,
            (x * d.1 + y * n.1).round() as i64,
        )
    };
    let (mut xs, mut pieces, mut stretches) = (Vec::new(), Vec::new(), Vec::new());
    let (mut covered, mut total, mut sag) = (0.0, 0.0, 0.0_f64);
    for k in k_lo as i64..=k_hi as i64 {
        let y = (k as f64 + 0.5) * s;
        cut(&bridge, y, &mut xs, &mut pieces);
        cut(&span, y, &mut xs, &mut stretches);
        total += stretches.iter().map(|(a, b)| b - a).sum::<f64>();
        for &(a, b) in &pieces {
            let over = |&(c, e): &(f64, f64)| (e.min(b) - c.max(a)).max(0.0);
            if !stretches.iter().any(|st| over(st) > 0.0) {
                continue;
            }
            if contains(anchors, world(a, y)) && contains(anchors, world(b, y)) {
                for st in &stretches {
                    covered += over(st);
                    sag = sag.max(over(st));
                }
            }
        }
    }
    Some((covered, total, sag))
}

/// The inside intervals `(x0, x1)` of the horizontal line at `y` through `rings` (even–odd),
/// sorted, into `out`; `xs` is scratch space.
fn cut(rings: &Rings, y: f64, xs: &mut Vec<f64>, out: &mut Vec<(f64, f64)>) {
    xs.clear();
    out.clear();
    for r in rings {
        for (i, &(ax, ay)) in r.iter().enumerate() {
            let (bx, by) = r[(i + 1) % r.len()];
            if (ay > y) != (by > y) {
                xs.push(ax + (y - ay) * (bx - ax) / (by - ay));
            }
        }
    }
    xs.sort_by(f64::total_cmp);
    out.extend(xs.chunks_exact(2).map(|c| (c[0], c[1])));
}

/// Candidate directions (degrees in [0, 180)): the 5° grid, then the direction of and the normal
/// to the longest contour edges of `unsupported`, skipping near-duplicates.
fn candidates(unsupported: &[ExPolygon]) -> Vec<f64> {
    let mut edges: Vec<(i128, f64)> = unsupported
        .iter()
        .flat_map(|e| {
            let pts = &e.contour.points;
            (0..pts.len()).map(move |i| {
                let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                let dir = ((b.y - a.y) as f64).atan2((b.x - a.x) as f64).to_degrees();
                (a.distance_squared(b), dir)
            })
        })
        .collect();
    // Stable sort: equal lengths keep contour order, so the choice is deterministic.
    edges.sort_by_key(|e| std::cmp::Reverse(e.0));
    let mut out: Vec<f64> = (0..36).map(|i| f64::from(i) * 5.0).collect();
    for (_, dir) in edges.into_iter().take(EDGE_CANDIDATES) {
        for a in [dir, dir + 90.0] {
            let a = normalize(a);
            let near = |b: &f64| {
                let d = (a - b).abs();
                d.min(180.0 - d) < DEDUPE_DEG
            };
            if !out.iter().any(near) {
                out.push(a);
            }
        }
    }
    out
}

/// `deg` folded into [0, 180).
fn normalize(deg: f64) -> f64 {
    let a = deg.rem_euclid(180.0) + 0.0;
    if a >= 180.0 { 0.0 } else { a }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Polygon;
    use crate::region::test_util::{rect, rect_island, square};

    /// `|got − want| ≤ 0.5°`, modulo 180°.
    fn assert_angle(got: Option<f64>, want: f64) {
        let Some(got) = got else {
            panic!("no bridge angle, wanted {want}°")
        };
        assert!((0.0..180.0).contains(&got), "{got}");
        let d = (got - want).abs();
        assert!(d.min(180.0 - d) <= 0.5, "got {got}°, wanted {want}°");
    }

    /// `e` turned by `deg` about the origin.
    fn rotated(e: &ExPolygon, deg: f64) -> ExPolygon {
        let (sin, cos) = deg.to_radians().sin_cos();
        let turn = |p: &Polygon| {
            Polygon::new(
                p.points
                    .iter()
                    .map(|q| {
                        let (x, y) = q.to_mm();
                        Point2::from_mm(x * cos - y * sin, x * sin + y * cos)
                    })
                    .collect(),
            )
        };
        ExPolygon {
            contour: turn(&e.contour),
            holes: e.holes.iter().map(turn).collect(),
        }
    }

    fn supports_left_and_right() -> (ExPolygon, Vec<ExPolygon>) {
        let lower = vec![
            rect_island(0.0, 0.0, 5.0, 20.0),
            rect_island(15.0, 0.0, 20.0, 20.0),
        ];
        (rect_island(4.0, 0.0, 16.0, 20.0), lower)
    }

    #[test]
    fn supports_left_and_right_give_lines_along_x() {
        let (bridge, lower) = supports_left_and_right();
        for spacing in [0.4, 0.45, 0.5] {
            assert_angle(bridge_angle(&bridge, &lower, spacing), 0.0);
        }
    }

    #[test]
    fn supports_below_and_above_give_lines_along_y() {
        let lower = [
            rect_island(0.0, 0.0, 20.0, 5.0),
            rect_island(0.0, 15.0, 20.0, 20.0),
        ];
        let bridge = rect_island(0.0, 4.0, 20.0, 16.0);
        assert_angle(bridge_angle(&bridge, &lower, 0.45), 90.0);
    }

    #[test]
    fn off_grid_supports_are_found_through_edge_directions() {
        let (bridge, lower) = supports_left_and_right();
        let lower: Vec<ExPolygon> = lower.iter().map(|e| rotated(e, 37.0)).collect();
        assert_angle(bridge_angle(&rotated(&bridge, 37.0), &lower, 0.45), 37.0);
    }

    #[test]
    fn hole_surrounded_by_support_is_crossed_along_its_short_side() {
        let mut hole = rect(15.0, 18.0, 25.0, 22.0);
        hole.points.reverse();
        let lower = [ExPolygon {
            contour: square(0.0, 0.0, 40.0),
            holes: vec![hole],
        }];
        let bridge = rect_island(14.0, 17.0, 26.0, 23.0);
        assert_angle(bridge_angle(&bridge, &lower, 0.45), 90.0);
        // Taller than wide: across x.
        let mut hole = rect(18.0, 15.0, 22.0, 25.0);
        hole.points.reverse();
        let lower = [ExPolygon {
            contour: square(0.0, 0.0, 40.0),
            holes: vec![hole],
        }];
        let bridge = rect_island(17.0, 14.0, 23.0, 26.0);
        assert_angle(bridge_angle(&bridge, &lower, 0.45), 0.0);
    }

    #[test]
    fn cantilever_has_no_bridge_angle() {
        let lower = [rect_island(0.0, 0.0, 5.0, 20.0)];
        let bridge = rect_island(4.0, 0.0, 20.0, 20.0);
        // At 0.4 mm a lattice line runs exactly along the support edge x = 5.
        for spacing in [0.4, 0.45, 0.5] {
            assert_eq!(bridge_angle(&bridge, &lower, spacing), None, "{spacing}");
        }
    }

    #[test]
    fn degenerate_input_gives_none() {
        let (bridge, lower) = supports_left_and_right();
        assert_eq!(bridge_angle(&ExPolygon::default(), &lower, 0.45), None);
        assert_eq!(bridge_angle(&bridge, &[], 0.45), None);
        for spacing in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(bridge_angle(&bridge, &lower, spacing), None, "{spacing}");
        }
        // Fully supported: nothing over air.
        let under = [rect_island(0.0, -1.0, 20.0, 21.0)];
        assert_eq!(bridge_angle(&bridge, &under, 0.45), None);
        // Narrower than half a line: no span left.
        let gap = [
            rect_island(0.0, 0.0, 10.0, 20.0),
            rect_island(10.1, 0.0, 20.0, 20.0),
        ];
        assert_eq!(
            bridge_angle(&rect_island(9.0, 0.0, 11.0, 20.0), &gap, 0.45),
            None
        );
    }

    #[test]
    fn result_is_deterministic_and_ignores_island_order() {
        let (bridge, mut lower) = supports_left_and_right();
        let bridge = rotated(&bridge, 23.0);
        lower = lower.iter().map(|e| rotated(e, 23.0)).collect();
        let first = bridge_angle(&bridge, &lower, 0.45);
        assert_angle(first, 23.0);
        assert_eq!(bridge_angle(&bridge, &lower, 0.45), first);
        lower.reverse();
        assert_eq!(bridge_angle(&bridge, &lower, 0.45), first);
    }
}
