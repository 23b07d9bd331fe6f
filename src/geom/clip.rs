//! Polygon booleans, offsets and polyline clipping on scaled-integer geometry.
//!
//! Place in the pipeline: `slice` turns raw contours into regions with
//! [`polygons_to_expolygons`]; `region` (perimeters, infill, cavities, channels) and `route` build
//! on [`union`], [`difference`], [`intersection`], [`offset`] and [`clip_polylines`].
//!
//! All work is done by [`i_overlay`] in its `i64` integer engine, directly on the nanometre
//! coordinates of [`Point2`], so booleans are exact and no float conversion happens here except
//! for the offset distance and join tolerances (converted once with [`scaled`]).
//!
//! # Coordinate range
//!
//! i_overlay's `i64` engine accepts coordinates in `-2^62..2^62` units, i.e. ±4.6·10¹² mm, so
//! every realistic coordinate (and every `i64` a printer could need) fits and nothing is clamped
//! or checked at run time. (The `i32` engine would have limited nanometre coordinates to ±1073 mm,
//! which is why it is not used.)
//!
//! # Determinism
//!
//! Every result is put in canonical order: each ring starts at its lexicographically smallest
//! point (x, then y), holes are sorted by their first point, ExPolygons by the first point of their
//! outer contour; clipped polylines keep the order of the input polylines and, within one
//! polyline, the order along it. Results therefore do not depend on input order of contours, and
//! G-code built from them is byte-identical across runs.

use super::point::{Point2, scaled};
use super::polygon::{ExPolygon, Polygon, Polyline, polyline_length};
use i_overlay::core::fill_rule::FillRule as IFillRule;
use i_overlay::core::overlay::{Overlay, ShapeType};
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::i_float::int::angle::Angle;
use i_overlay::i_float::int::point::IntPoint;
use i_overlay::i_shape::int::shape::{IntContour, IntShapes};
use i_overlay::mesh::int::arc::ArcOptions;
use i_overlay::mesh::int::outline::offset::IntOutlineOffset;
use i_overlay::mesh::int::style::{IntLineJoin, IntOutlineStyle};
use i_overlay::string::clip::{ClipRule, IntClip};

/// Which points count as inside a set of possibly overlapping, self-intersecting contours.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FillRule {
    /// Inside where a ray crosses the contours an odd number of times (orientation ignored).
    EvenOdd,
    /// Inside where the winding number is not zero (either orientation fills).
    NonZero,
    /// Inside where the winding number is positive: counter-clockwise contours add, clockwise
    /// contours subtract (PrusaSlicer's `union` with positive fill after orientation fixing).
    Positive,
}

impl From<FillRule> for IFillRule {
    fn from(rule: FillRule) -> Self {
        match rule {
            FillRule::EvenOdd => IFillRule::EvenOdd,
            FillRule::NonZero => IFillRule::NonZero,
            FillRule::Positive => IFillRule::Positive,
        }
    }
}

/// How [`offset`] builds corners where the offset edges of a convex corner part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Join {
    /// Sharp corners, as Clipper's miter: a corner is kept sharp while its miter length is at most
    /// `limit · |delta|`, i.e. while its interior angle is at least `2·asin(1/limit)`; sharper
    /// corners are clipped. Limits below 1 behave as 1 (every corner clipped flat).
    Miter(f64),
    /// Round corners, approximated by chords that stray at most this far (mm) from the true arc.
    /// Non-positive or NaN values use the coarsest step i_overlay allows (45° per chord).
    Round(f64),
    /// Squared-off corners: corners with an interior angle of at least 90° stay sharp; sharper
    /// corners are cut flat after extending each offset edge by `|delta|` past the corner (a
    /// clipped miter at limit √2). This differs slightly from Clipper's `jtSquare`, which cuts
    /// every corner at distance `|delta|` along the bisector.
    Square,
}

fn to_int(p: Point2) -> IntPoint<i64> {
    IntPoint::new(p.x, p.y)
}

fn from_int(p: IntPoint<i64>) -> Point2 {
    Point2::new(p.x, p.y)
}

fn ring_to_int(points: &[Point2]) -> IntContour<i64> {
    points.iter().copied().map(to_int).collect()
}

/// The ring rotated so it starts at its smallest point (x, then y), orientation unchanged.
fn canonical_ring(mut points: Vec<Point2>) -> Polygon {
    if let Some((start, _)) = points.iter().enumerate().min_by_key(|&(_, p)| (p.x, p.y)) {
        points.rotate_left(start);
    }
    Polygon::new(points)
}

/// Converts i_overlay shapes (outer CCW first, then CW holes) into canonical ExPolygons.
fn shapes_to_expolygons(shapes: IntShapes<i64>) -> Vec<ExPolygon> {
    let mut out: Vec<ExPolygon> = shapes
        .into_iter()
        .filter_map(|shape| {
            let mut rings = shape
                .into_iter()
                .filter(|c| c.len() >= 3)
                .map(|c| canonical_ring(c.into_iter().map(from_int).collect()));
            let mut contour = rings.next()?;
            if !contour.is_counter_clockwise() {
                contour.points.reverse();
                contour = canonical_ring(contour.points);
            }
            let mut holes: Vec<Polygon> = rings
                .map(|mut h| {
                    if h.is_counter_clockwise() {
                        h.points.reverse();
                        h = canonical_ring(h.points);
                    }
                    h
                })
                .collect();
            holes.sort_by_key(|h| h.points.first().map(|p| (p.x, p.y)));
            Some(ExPolygon { contour, holes })
        })
        .collect();
    out.sort_by(|a, b| {
        let key = |e: &ExPolygon| e.contour.points.first().map(|p| (p.x, p.y));
        key(a)
            .cmp(&key(b))
            .then_with(|| a.contour.points.cmp(&b.contour.points))
    });
    out
}

/// The rings of `ex` as i_overlay contours, outer forced CCW and holes CW (the [`ExPolygon`]
/// invariant), so positive and non-zero fills treat holes as holes whatever the caller passed.
fn oriented_rings(ex: &ExPolygon) -> impl Iterator<Item = IntContour<i64>> + '_ {
    let outer = {
        let mut c = ring_to_int(&ex.contour.points);
        if ex.contour.signed_area2() < 0 {
            c.reverse();
        }
        c
    };
    std::iter::once(outer).chain(ex.holes.iter().map(|h| {
        let mut c = ring_to_int(&h.points);
        if h.signed_area2() > 0 {
            c.reverse();
        }
        c
    }))
}

fn edge_count(a: &[ExPolygon]) -> usize {
    a.iter()
        .map(|e| e.contour.points.len() + e.holes.iter().map(|h| h.points.len()).sum::<usize>())
        .sum()
}

fn add_expolygons(overlay: &mut Overlay<i64>, a: &[ExPolygon], kind: ShapeType) {
    for ex in a {
        for ring in oriented_rings(ex) {
            overlay.add_contour(&ring, kind);
        }
    }
}

/// Turns raw closed contours (possibly self-intersecting, overlapping or nested, in any
/// orientation) into ExPolygons under `rule`: outer contours counter-clockwise, holes clockwise,
/// in canonical order (see the module docs). Contours with fewer than three points or zero area
/// contribute nothing.
pub fn polygons_to_expolygons(contours: &[Polygon], rule: FillRule) -> Vec<ExPolygon> {
    let cap = contours.iter().map(|c| c.points.len()).sum();
    let mut overlay = Overlay::<i64>::new(cap);
    for c in contours {
        if c.points.len() >= 3 {
            overlay.add_contour(&ring_to_int(&c.points), ShapeType::Subject);
        }
    }
    shapes_to_expolygons(overlay.overlay(OverlayRule::Subject, rule.into()))
}

fn boolean(a: &[ExPolygon], b: &[ExPolygon], rule: OverlayRule) -> Vec<ExPolygon> {
    let mut overlay = Overlay::<i64>::new(edge_count(a) + edge_count(b));
    add_expolygons(&mut overlay, a, ShapeType::Subject);
    add_expolygons(&mut overlay, b, ShapeType::Clip);
    shapes_to_expolygons(overlay.overlay(rule, IFillRule::Positive))
}

/// The union of `a` (which may overlap itself), as non-overlapping ExPolygons.
pub fn union(a: &[ExPolygon]) -> Vec<ExPolygon> {
    boolean(a, &[], OverlayRule::Subject)
}

/// The parts of `a` outside `b`.
pub fn difference(a: &[ExPolygon], b: &[ExPolygon]) -> Vec<ExPolygon> {
    boolean(a, b, OverlayRule::Difference)
}

/// The parts of `a` inside `b`.
pub fn intersection(a: &[ExPolygon], b: &[ExPolygon]) -> Vec<ExPolygon> {
    boolean(a, b, OverlayRule::Intersect)
}

/// The i_overlay join for `join` at offset distance `delta` (scaled units, non-zero).
fn int_join(join: Join, delta: i64) -> IntLineJoin {
    let angle = |radians: f64| Angle::from_radians(radians).unwrap_or(Angle::HALF_TURN);
    match join {
        Join::Miter(limit) => {
            let limit = if limit.is_nan() { 1.0 } else { limit.max(1.0) };
            IntLineJoin::Miter(angle(2.0 * (1.0 / limit).asin()))
        }
        Join::Square => IntLineJoin::Miter(Angle::QUARTER_TURN),
        Join::Round(deviation_mm) => {
            // Chord of angle φ on radius r strays r·(1 − cos(φ/2)) from the arc.
            let r = delta.unsigned_abs() as f64;
            let dev = scaled(deviation_mm) as f64;
            let step = if dev > 0.0 && dev < r {
                2.0 * (1.0 - dev / r).acos()
            } else {
                std::f64::consts::FRAC_PI_4
            };
            IntLineJoin::Round(ArcOptions {
                max_step: angle(step),
                ..ArcOptions::default()
            })
        }
    }
}

/// Grows (`delta_mm > 0`) or shrinks (`delta_mm < 0`) the regions by `delta_mm` millimetres,
/// with corners built by `join`. Regions (or parts of them) that vanish when shrinking disappear;
/// regions that meet when growing merge. `delta_mm` is snapped to the nanometre grid; a zero
/// offset returns the union of `a`.
///
/// ```
/// use conduit::geom::{ExPolygon, Join, Point2, Polygon, offset};
/// let square = Polygon::new(vec![
///     Point2::from_mm(0.0, 0.0),
///     Point2::from_mm(10.0, 0.0),
///     Point2::from_mm(10.0, 10.0),
///     Point2::from_mm(0.0, 10.0),
/// ]);
/// let inset = offset(&[ExPolygon { contour: square, holes: vec![] }], -1.0, Join::Miter(2.0));
/// assert_eq!(inset[0].area_mm2(), 64.0);
/// ```
///
/// The inputs should not overlap each other (as every result of this module): overlapping inputs
/// are offset separately and then united, which differs from "unite, then shrink" for negative
/// deltas.
pub fn offset(a: &[ExPolygon], delta_mm: f64, join: Join) -> Vec<ExPolygon> {
    let delta = scaled(delta_mm);
    if delta == 0 {
        return union(a);
    }
    let rings: Vec<IntContour<i64>> = a.iter().flat_map(oriented_rings).collect();
    let style = IntOutlineStyle::<i64>::new(delta).line_join(int_join(join, delta));
    match rings.as_slice().outline(&style) {
        Ok(shapes) => shapes_to_expolygons(shapes),
        // `outline` only fails a coordinate-range check that the i64 engine never reaches for
        // nanometre coordinates (see the module docs); an empty result is the honest answer.
        Err(_) => Vec::new(),
    }
}

/// The parts of the open `lines` inside `region` (its boundary counts as inside), each kept in
/// its original direction. Pieces come out in input order, then in order along each line.
pub fn clip_polylines(lines: &[Polyline], region: &[ExPolygon]) -> Vec<Polyline> {
    let rings: Vec<IntContour<i64>> = region.iter().flat_map(oriented_rings).collect();
    let rule = ClipRule {
        invert: false,
        boundary_included: true,
    };
    let mut out = Vec::new();
    for line in lines {
        if line.points.len() < 2 || rings.is_empty() {
            continue;
        }
        let path = ring_to_int(&line.points);
        let mut pieces: Vec<Vec<Point2>> = rings
            .as_slice()
            .clip_path(&path, IFillRule::Positive, rule)
            .into_iter()
            .map(|p| p.into_iter().map(from_int).collect())
            .collect();
        // i_overlay walks its own graph; restore the input direction and order by projecting each
        // piece onto the line (arc-length position of its ends along the input polyline).
        let mut keyed: Vec<(f64, Vec<Point2>)> = pieces
            .drain(..)
            .filter(|p: &Vec<Point2>| p.len() >= 2)
            .map(|mut p| {
                let (s0, s1) = (
                    position_along(&line.points, p[0]),
                    position_along(&line.points, p[p.len() - 1]),
                );
                if s1 < s0 {
                    p.reverse();
                }
                (s0.min(s1), p)
            })
            .collect();
        keyed.sort_by(|a, b| a.0.total_cmp(&b.0).then_with(|| a.1.cmp(&b.1)));
        out.extend(keyed.into_iter().map(|(_, points)| Polyline { points }));
    }
    out
}

/// The stretches of the polyline `line` inside `region` (its boundary counts as inside), as
/// intervals of arc length along it, mm from its start, in order. `line` may return to its
/// start (a loop opened at its seam): a stretch through that point is given as two intervals,
/// one at each end.
pub fn clip_intervals(line: &[Point2], region: &[ExPolygon]) -> Vec<(f64, f64)> {
    let total = polyline_length(line);
    // Cut points are rounded to the nanometre grid: a few nm off the line at most.
    let tol = 1e3;
    let (Some(&start), Some(&end)) = (line.first(), line.last()) else {
        return Vec::new();
    };
    let pieces = clip_polylines(
        &[Polyline {
            points: line.to_vec(),
        }],
        region,
    );
    let mut out: Vec<(f64, f64)> = pieces
        .iter()
        .map(|piece| {
            let len = polyline_length(&piece.points);
            let (first, last) = (piece.points[0], piece.points[piece.points.len() - 1]);
            let (a, b) = (position_along(line, first), position_along(line, last));
            // The positions of a loop's start and end are ambiguous (both 0 by projection):
            // the piece's own length says which end it reaches.
            let forward = (b - (a + len)).abs() <= tol
                || (last == end && last == start && (a + len - total).abs() <= tol);
            // A reversed piece's last point is its earliest along the line.
            let from = if forward { a } else { b };
            (from / 1e6, ((from + len).min(total)) / 1e6)
        })
        .collect();
    out.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
    out
}

/// How [`stroke`] closes the two ends of each polyline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cap {
    /// Cut flat at the end points.
    Butt,
    /// Extended by half the width past the end points, cut flat.
    Square,
    /// Half discs, approximated by chords that stray at most this far (mm) from the true arc,
    /// as for [`Join::Round`].
    Round(f64),
}

/// The area covered by the open `lines` drawn `width_mm` wide (the region a nozzle leaves when
/// it extrudes a bead of that width along each line), united into non-overlapping ExPolygons in
/// canonical order. Corners are built by `join` and the ends by `cap`; points repeated in a row
/// are ignored, and lines with fewer than two distinct points or a width below 2 nm give nothing.
///
/// ```
/// use conduit::geom::{Cap, Join, Point2, Polyline, stroke};
/// let line = Polyline { points: vec![Point2::from_mm(0.0, 0.0), Point2::from_mm(10.0, 0.0)] };
/// let band = stroke(&[line], 0.5, Join::Miter(2.0), Cap::Butt);
/// assert_eq!(band.len(), 1);
/// assert!((band[0].area_mm2() - 5.0).abs() < 1e-9);
/// ```
pub fn stroke(lines: &[Polyline], width_mm: f64, join: Join, cap: Cap) -> Vec<ExPolygon> {
    use i_overlay::mesh::int::stroke::offset::IntStrokeOffset;
    use i_overlay::mesh::int::style::{IntLineCap, IntStrokeStyle};

    let width = scaled(width_mm);
    if width < 2 {
        return Vec::new();
    }
    let paths: Vec<IntContour<i64>> = lines
        .iter()
        .map(|line| {
            let mut path: IntContour<i64> = Vec::with_capacity(line.points.len());
            for p in &line.points {
                if path.last() != Some(&to_int(*p)) {
                    path.push(to_int(*p));
                }
            }
            path
        })
        .filter(|path| path.len() >= 2)
        .collect();
    if paths.is_empty() {
        return Vec::new();
    }
    let half = width / 2;
    let int_cap = match cap {
        Cap::Butt => IntLineCap::Butt,
        Cap::Square => IntLineCap::Square,
        Cap::Round(deviation_mm) => match int_join(Join::Round(deviation_mm), half) {
            IntLineJoin::Round(options) => IntLineCap::Round(options),
            _ => IntLineCap::Round(ArcOptions::default()),
        },
    };
    let style = IntStrokeStyle::<i64>::new(width)
        .line_join(int_join(join, half))
        .start_cap(int_cap.clone())
        .end_cap(int_cap);
    match paths.as_slice().stroke(&style, false) {
        Ok(shapes) => shapes_to_expolygons(shapes),
        // As for `outline` in `offset`: only a coordinate-range check can fail, which nanometre
        // coordinates never reach.
        Err(_) => Vec::new(),
    }
}

/// Arc-length position (in scaled units, as f64) of the point of `line` nearest to `p`.
fn position_along(line: &[Point2], p: Point2) -> f64 {
    let mut best = (f64::INFINITY, 0.0);
    let mut start = 0.0;
    for w in line.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (dx, dy) = ((b.x - a.x) as f64, (b.y - a.y) as f64);
        let len2 = dx * dx + dy * dy;
        let len = len2.sqrt();
        let t = if len2 > 0.0 {
            (((p.x - a.x) as f64 * dx + (p.y - a.y) as f64 * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (qx, qy) = (a.x as f64 + t * dx, a.y as f64 + t * dy);
        let d2 = (qx - p.x as f64).powi(2) + (qy - p.y as f64).powi(2);
        if d2 < best.0 {
            best = (d2, start + t * len);
        }
        start += len;
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon {
        Polygon::new(vec![
            Point2::from_mm(x0, y0),
            Point2::from_mm(x1, y0),
            Point2::from_mm(x1, y1),
            Point2::from_mm(x0, y1),
        ])
    }

    fn ex(p: Polygon) -> ExPolygon {
        ExPolygon {
            contour: p,
            holes: vec![],
        }
    }

    fn area(a: &[ExPolygon]) -> f64 {
        a.iter().map(ExPolygon::area_mm2).sum()
    }

    fn assert_oriented(a: &[ExPolygon]) {
        for e in a {
            assert!(e.contour.is_counter_clockwise());
            assert!(e.holes.iter().all(|h| !h.is_counter_clockwise()));
        }
    }

    fn length(p: &Polyline) -> f64 {
        p.points
            .windows(2)
            .map(|w| (w[1].distance_squared(w[0]) as f64).sqrt() / 1e6)
            .sum()
    }

    #[test]
    fn union_of_two_overlapping_squares() {
        let u = union(&[ex(rect(0., 0., 10., 10.)), ex(rect(5., 5., 15., 15.))]);
        assert_eq!(u.len(), 1);
        assert_eq!(area(&u), 175.0);
        assert_oriented(&u);
        // Canonical start: the smallest point.
        assert_eq!(u[0].contour.points[0], Point2::from_mm(0., 0.));
    }

    #[test]
    fn coordinates_beyond_the_i32_range_stay_exact() {
        // 3 m from the origin is 3·10⁹ nm, past i32; the i64 engine keeps it exact.
        let far = ex(rect(3000., -3000., 3010., -2990.));
        let o = offset(std::slice::from_ref(&far), -1.0, Join::Miter(2.0));
        assert_eq!(area(&o), 64.0);
        assert_eq!(o[0].contour.points[0], Point2::from_mm(3001., -2999.));
        let d = difference(&[far], &[ex(rect(3000., -3000., 3005., -2990.))]);
        assert_eq!(area(&d), 50.0);
    }

    #[test]
    fn union_is_independent_of_input_order() {
        let a = ex(rect(0., 0., 10., 10.));
        let b = ex(rect(20., 0., 30., 10.));
        let ab = union(&[a.clone(), b.clone()]);
        let ba = union(&[b, a]);
        assert_eq!(ab, ba);
        assert_eq!(ab.len(), 2);
    }

    #[test]
    fn difference_makes_a_hole() {
        let d = difference(&[ex(rect(0., 0., 10., 10.))], &[ex(rect(3., 3., 5., 6.))]);
        assert_eq!(d.len(), 1);
        assert_eq!(d[0].holes.len(), 1);
        assert_eq!(area(&d), 94.0);
        assert_oriented(&d);
    }

    #[test]
    fn intersection_of_overlapping_squares() {
        let i = intersection(&[ex(rect(0., 0., 10., 10.))], &[ex(rect(5., 5., 15., 15.))]);
        assert_eq!(i.len(), 1);
        assert_eq!(area(&i), 25.0);
    }

    #[test]
    fn inward_offset_of_a_square_is_exact() {
        for join in [Join::Miter(3.0), Join::Square, Join::Round(0.001)] {
            let o = offset(&[ex(rect(0., 0., 10., 10.))], -1.0, join);
            assert_eq!(o.len(), 1, "{join:?}");
            assert_eq!(area(&o), 64.0, "{join:?}");
            assert_eq!(o[0].contour.points[0], Point2::from_mm(1., 1.));
        }
    }

    #[test]
    fn outward_miter_offset_keeps_square_corners() {
        let o = offset(&[ex(rect(0., 0., 10., 10.))], 1.0, Join::Miter(2.0));
        assert_eq!(area(&o), 144.0);
    }

    #[test]
    fn outward_round_offset_adds_a_quarter_circle_per_corner() {
        let o = offset(&[ex(rect(0., 0., 10., 10.))], 1.0, Join::Round(0.001));
        assert_eq!(o.len(), 1);
        let expected = 100.0 + 4.0 * 10.0 * 1.0 + std::f64::consts::PI;
        let a = area(&o);
        // Chords lie inside the arc, at most 0.001 mm from it: the deficit is below
        // perimeter·deviation = 2π·0.001.
        assert!(
            a <= expected + 1e-9 && a > expected - 2.0 * std::f64::consts::PI * 0.001,
            "{a}"
        );
    }

    #[test]
    fn offset_removes_vanishing_regions_and_shrinks_holes() {
        let gone = offset(&[ex(rect(0., 0., 1., 1.))], -0.6, Join::Miter(2.0));
        assert!(gone.is_empty());
        let mut hole = rect(4., 4., 6., 6.);
        hole.points.reverse();
        let ring = ExPolygon {
            contour: rect(0., 0., 10., 10.),
            holes: vec![hole],
        };
        let o = offset(&[ring], -1.0, Join::Miter(2.0));
        assert_eq!(o.len(), 1);
        assert_eq!(o[0].holes.len(), 1);
        assert_eq!(area(&o), 64.0 - 16.0);
    }

    #[test]
    fn nested_contours_even_odd_give_a_hole() {
        // Both counter-clockwise: even-odd still makes the inner one a hole.
        let r = polygons_to_expolygons(
            &[rect(0., 0., 10., 10.), rect(2., 2., 4., 4.)],
            FillRule::EvenOdd,
        );
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].holes.len(), 1);
        assert_eq!(area(&r), 96.0);
        assert_oriented(&r);
        // Non-zero fills the same-orientation inner square; positive keeps a clockwise one a hole.
        let nz = polygons_to_expolygons(
            &[rect(0., 0., 10., 10.), rect(2., 2., 4., 4.)],
            FillRule::NonZero,
        );
        assert_eq!(area(&nz), 100.0);
        let mut inner = rect(2., 2., 4., 4.);
        inner.points.reverse();
        let pos = polygons_to_expolygons(&[rect(0., 0., 10., 10.), inner], FillRule::Positive);
        assert_eq!(area(&pos), 96.0);
    }

    #[test]
    fn figure_eight_non_zero_gives_two_lobes() {
        // A bow-tie: one lobe runs counter-clockwise, the other clockwise.
        let bowtie = Polygon::new(vec![
            Point2::from_mm(0., 0.),
            Point2::from_mm(10., 10.),
            Point2::from_mm(10., 0.),
            Point2::from_mm(0., 10.),
        ]);
        let r = polygons_to_expolygons(std::slice::from_ref(&bowtie), FillRule::NonZero);
        assert_eq!(r.len(), 2);
        assert_eq!(area(&r), 50.0);
        assert_oriented(&r);
        // Positive keeps only the counter-clockwise lobe.
        let p = polygons_to_expolygons(&[bowtie], FillRule::Positive);
        assert_eq!(p.len(), 1);
        assert_eq!(area(&p), 25.0);
    }

    #[test]
    fn clip_line_through_square_with_hole_gives_two_pieces() {
        let mut hole = rect(4., 4., 6., 6.);
        hole.points.reverse();
        let region = [ExPolygon {
            contour: rect(0., 0., 10., 10.),
            holes: vec![hole],
        }];
        let line = Polyline {
            points: vec![Point2::from_mm(-5., 5.), Point2::from_mm(15., 5.)],
        };
        let pieces = clip_polylines(&[line], &region);
        assert_eq!(pieces.len(), 2, "{pieces:?}");
        assert_eq!(
            pieces[0].points,
            vec![Point2::from_mm(0., 5.), Point2::from_mm(4., 5.)]
        );
        assert_eq!(
            pieces[1].points,
            vec![Point2::from_mm(6., 5.), Point2::from_mm(10., 5.)]
        );
        assert_eq!(length(&pieces[0]) + length(&pieces[1]), 8.0);
        // Reversed input keeps its direction.
        let back = Polyline {
            points: vec![Point2::from_mm(15., 5.), Point2::from_mm(-5., 5.)],
        };
        let pieces = clip_polylines(&[back], &region);
        assert_eq!(pieces.len(), 2);
        assert_eq!(
            pieces[0].points,
            vec![Point2::from_mm(10., 5.), Point2::from_mm(6., 5.)]
        );
        assert_eq!(
            pieces[1].points,
            vec![Point2::from_mm(4., 5.), Point2::from_mm(0., 5.)]
        );
    }

    #[test]
    fn clip_keeps_boundary_and_bends() {
        let region = [ex(rect(0., 0., 10., 10.))];
        // Runs along the bottom edge (boundary counts as inside), then up and out.
        let line = Polyline {
            points: vec![
                Point2::from_mm(-2., 0.),
                Point2::from_mm(5., 0.),
                Point2::from_mm(5., 12.),
            ],
        };
        let pieces = clip_polylines(&[line], &region);
        assert_eq!(pieces.len(), 1, "{pieces:?}");
        assert_eq!(length(&pieces[0]), 15.0);
        assert_eq!(pieces[0].points[0], Point2::from_mm(0., 0.));
    }
}
