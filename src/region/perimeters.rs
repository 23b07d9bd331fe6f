//! Perimeter loops of one layer's islands, and the infill area they leave.
//!
//! Loop `k` of an island is the boundary of the island shrunk by `d_k`, where
//!
//! - `d_0 = external_perimeter_width / 2` (the outer face of the external extrusion lands on the
//!   sliced contour),
//! - `d_1 = d_0 + (external_spacing + perimeter_spacing) / 2` (PrusaSlicer's rule; this is one
//!   spacing when both widths are equal),
//! - `d_k = d_(k−1) + perimeter_spacing` after that.
//!
//! Each depth is offset from the island itself (not from the previous loop), which is the same
//! geometry for mitred inward offsets without the rounding drift of chained offsets. Every
//! resulting polygon is a loop: contours give counter-clockwise loops, holes give clockwise loops,
//! so the nozzle always has the part on its left.
//!
//! **Thin parts.** Each loop area is *opened* (shrunk by `d_k + r`, grown back by `r`, with
//! `r = 0.3 · spacing`, PrusaSlicer's `INSET_OVERLAP_TOLERANCE` of 0.4), so a loop that would run
//! over itself is not made. Parts too thin for a loop are simply absent: there is no gap fill or
//! thin-wall medial-axis extrusion yet.
//!
//! **Infill area.** The area inside the innermost loop where infill *centrelines* may go: the
//! island shrunk by `d_last + (last_spacing + solid_infill_spacing) / 2 − infill_overlap ·
//! perimeter_width`, so infill lines clipped to it sit one spacing inside the innermost loop, less
//! the overlap that bonds them. With zero perimeters it is the island shrunk by half a solid
//! infill spacing.

use super::params::RegionParams;
use super::simplify::cleaned;
use crate::geom::{ExPolygon, Join, Polygon, offset, scaled, unscaled};

/// How far (mm) the opening that removes too-thin loops reaches, as a fraction of the spacing:
/// `(1 − INSET_OVERLAP_TOLERANCE) / 2` with PrusaSlicer's tolerance of 0.4.
const OPENING_FRACTION: f64 = 0.3;

/// Join used for every perimeter offset: mitred, so straight walls and square corners stay exact.
/// The miter limit (3) is PrusaSlicer's for perimeters.
pub(crate) const PERIMETER_JOIN: Join = Join::Miter(3.0);

/// One closed extrusion loop.
#[derive(Debug, Clone, PartialEq)]
pub struct PerimeterLoop {
    /// The centreline; counter-clockwise around material, clockwise around holes.
    pub polygon: Polygon,
    /// 0 for the external loop, counting inward.
    pub depth: usize,
    /// Extrusion width, mm.
    pub width: f64,
    /// Whether this is an external loop (depth 0, on a contour or a hole).
    pub external: bool,
    /// Whether the loop runs around a hole (clockwise) rather than around material.
    pub is_hole: bool,
    /// Index of the island (in the layer's input) this loop belongs to.
    pub island: usize,
}

/// The perimeters of one layer and the infill area they enclose.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Perimeters {
    /// Loops in print order: island by island, inner to outer (outer to inner when
    /// `external_perimeters_first`).
    pub loops: Vec<PerimeterLoop>,
    /// Where infill centrelines may go, over all islands of the layer.
    pub infill_area: Vec<ExPolygon>,
}

/// Returns `polygon` with its vertices running counter-clockwise when `ccw`, clockwise otherwise.
pub(crate) fn oriented(mut polygon: Polygon, ccw: bool) -> Polygon {
    if polygon.is_counter_clockwise() != ccw {
        polygon.points.reverse();
    }
    polygon
}

/// [`offset`] with [`PERIMETER_JOIN`], its result [`cleaned`] of nearly collinear points so that
/// further offsets of it stay cheap.
pub(crate) fn offset_cleaned(area: &[ExPolygon], delta_mm: f64) -> Vec<ExPolygon> {
    cleaned(offset(area, delta_mm, PERIMETER_JOIN))
}

/// `area` shrunk by `depth` mm with parts thinner than `2·radius` around the result removed
/// (a morphological opening after the offset).
pub(crate) fn shrink_opened(area: &[ExPolygon], depth: f64, radius: f64) -> Vec<ExPolygon> {
    if radius <= 0.0 {
        return offset_cleaned(area, -depth);
    }
    let shrunk = offset_cleaned(area, -(depth + radius));
    if shrunk.is_empty() {
        return shrunk;
    }
    offset_cleaned(&shrunk, radius)
}

/// `island` shrunk by `depth` mm, starting from `base` (an area already shrunk by `base.0` nm) when
/// it is not deeper than `depth`: inward mitred offsets compose, so this is the same region as
/// shrinking the island itself, at the cost of a shorter (cheaper) offset. The remaining distance
/// is taken in whole nanometres, so the total depth is exactly `scaled(depth)`.
fn shrink_from(
    island: &[ExPolygon],
    base: Option<&(i64, Vec<ExPolygon>)>,
    depth: f64,
) -> Vec<ExPolygon> {
    let target = scaled(depth);
    match base {
        Some((from, area)) if *from <= target => {
            if *from == target || area.is_empty() {
                area.clone()
            } else {
                offset_cleaned(area, -unscaled(target - from))
            }
        }
        _ => offset_cleaned(island, -depth),
    }
}

/// Depth (mm from the island edge to the centreline), width and spacing of loop `k`, for every
/// loop of a layer `height` mm high.
fn loop_plan(params: &RegionParams, height: f64) -> Vec<(f64, f64, f64)> {
    let sp = params.spacings(height);
    let mut depth = 0.0;
    (0..params.perimeters)
        .map(|k| {
            let (step, width, spacing) = match k {
                0 => (
                    params.external_perimeter_width / 2.0,
                    params.external_perimeter_width,
                    sp.external_perimeter,
                ),
                1 => (
                    (sp.external_perimeter + sp.perimeter) / 2.0,
                    params.perimeter_width,
                    sp.perimeter,
                ),
                _ => (sp.perimeter, params.perimeter_width, sp.perimeter),
            };
            depth += step;
            (depth, width, spacing)
        })
        .collect()
}

/// Distance (mm) from an island's edge to the edge of its infill area on a layer `height` mm
/// high: the width of the perimeter band, less the infill overlap (see the module docs).
pub fn infill_inset(params: &RegionParams, height: f64) -> f64 {
    let solid = params.spacings(height).solid_infill;
    match loop_plan(params, height).last() {
        None => solid / 2.0,
        Some(&(depth, _, spacing)) => {
            depth + (spacing + solid) / 2.0 - params.infill_overlap * params.perimeter_width
        }
    }
}

/// Loops and infill area of one layer, whose islands are `islands` and whose height is `height`
/// (mm).
pub fn make_perimeters(islands: &[ExPolygon], params: &RegionParams, height: f64) -> Perimeters {
    let plan = loop_plan(params, height);
    let inset = infill_inset(params, height);
    let mut out = Perimeters::default();
    for (island_index, island) in islands.iter().enumerate() {
        let island = std::slice::from_ref(island);
        let mut island_loops: Vec<PerimeterLoop> = Vec::new();
        // The deepest shrunk area so far: (depth in nm, area). Each deeper shrink starts from it.
        let mut base: Option<(i64, Vec<ExPolygon>)> = None;
        for (k, &(depth, width, spacing)) in plan.iter().enumerate() {
            let radius = OPENING_FRACTION * spacing;
            let shrunk = shrink_from(island, base.as_ref(), depth + radius);
            let area = if shrunk.is_empty() || radius <= 0.0 {
                shrunk.clone()
            } else {
                offset_cleaned(&shrunk, radius)
            };
            base = Some((scaled(depth + radius), shrunk));
            for ex in area {
                let make = |polygon: Polygon, is_hole: bool| PerimeterLoop {
                    polygon: oriented(polygon, !is_hole),
                    depth: k,
                    width,
                    external: k == 0,
                    is_hole,
                    island: island_index,
                };
                island_loops.push(make(ex.contour, false));
                island_loops.extend(ex.holes.into_iter().map(|h| make(h, true)));
            }
        }
        // A stable sort keeps contour-before-holes and the offset's order within one depth.
        if params.external_perimeters_first {
            island_loops.sort_by_key(|l| l.depth);
        } else {
            island_loops.sort_by_key(|l| std::cmp::Reverse(l.depth));
        }
        out.loops.extend(island_loops);
        out.infill_area
            .extend(shrink_from(island, base.as_ref(), inset));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Point2, scaled};
    use crate::region::test_util::{assert_square, square};

    fn island_20() -> ExPolygon {
        ExPolygon {
            contour: square(0.0, 0.0, 20.0),
            holes: vec![],
        }
    }

    #[test]
    fn twenty_mm_square_gets_two_loops_inner_first() {
        let params = RegionParams::default();
        let sp = params.spacings(0.2);
        let per = make_perimeters(&[island_20()], &params, 0.2);
        assert_eq!(per.loops.len(), 2);
        // Inner to outer by default.
        assert_eq!(per.loops[0].depth, 1);
        assert_eq!(per.loops[1].depth, 0);
        let ext = &per.loops[1];
        assert!(ext.external && !ext.is_hole && ext.island == 0);
        assert_eq!(ext.width, 0.45);
        // External loop: offset 0.225 → the 19.55 mm square.
        assert_square(&ext.polygon, 0.225, 19.775);
        assert!(ext.polygon.is_counter_clockwise());
        // Second loop one spacing further in.
        let d1 = 0.225 + sp.perimeter;
        assert_square(&per.loops[0].polygon, d1, 20.0 - d1);
        assert!(!per.loops[0].external);
        // Infill area: one spacing inside the second loop less the overlap (0.25 · 0.45).
        let di = d1 + sp.perimeter - 0.25 * 0.45;
        assert_eq!(per.infill_area.len(), 1);
        assert!(per.infill_area[0].holes.is_empty());
        assert_square(&per.infill_area[0].contour, di, 20.0 - di);
    }

    #[test]
    fn external_first_reverses_the_order() {
        let params = RegionParams {
            external_perimeters_first: true,
            perimeters: 3,
            ..Default::default()
        };
        let per = make_perimeters(&[island_20()], &params, 0.2);
        let depths: Vec<usize> = per.loops.iter().map(|l| l.depth).collect();
        assert_eq!(depths, [0, 1, 2]);
    }

    #[test]
    fn square_with_hole_gets_clockwise_loops_around_the_hole() {
        let mut hole = square(8.0, 8.0, 4.0);
        hole.points.reverse();
        let island = ExPolygon {
            contour: square(0.0, 0.0, 20.0),
            holes: vec![hole],
        };
        let params = RegionParams::default();
        let sp = params.spacings(0.2);
        let per = make_perimeters(&[island], &params, 0.2);
        assert_eq!(per.loops.len(), 4);
        let holes: Vec<&PerimeterLoop> = per.loops.iter().filter(|l| l.is_hole).collect();
        assert_eq!(holes.len(), 2);
        for l in &holes {
            assert!(
                !l.polygon.is_counter_clockwise(),
                "hole loop must be clockwise"
            );
            let d = if l.depth == 0 {
                0.225
            } else {
                0.225 + sp.perimeter
            };
            assert_square(&l.polygon, 8.0 - d, 12.0 + d);
        }
        assert!(
            per.loops
                .iter()
                .filter(|l| !l.is_hole)
                .all(|l| l.polygon.is_counter_clockwise())
        );
        // Infill area keeps a (grown) hole.
        assert_eq!(per.infill_area.len(), 1);
        assert_eq!(per.infill_area[0].holes.len(), 1);
    }

    #[test]
    fn thin_parts_get_no_loop_and_islands_keep_their_index() {
        // A 0.5 mm wide strip: the external loop would be a 0.05 mm sliver, narrower than
        // 0.6 spacing, so it is dropped; the square next to it keeps its loops.
        let strip = ExPolygon {
            contour: Polygon::new(vec![
                Point2::from_mm(30.0, 0.0),
                Point2::from_mm(40.0, 0.0),
                Point2::from_mm(40.0, 0.5),
                Point2::from_mm(30.0, 0.5),
            ]),
            holes: vec![],
        };
        let per = make_perimeters(&[strip, island_20()], &RegionParams::default(), 0.2);
        assert_eq!(per.loops.len(), 2);
        assert!(per.loops.iter().all(|l| l.island == 1));
        assert_eq!(per.infill_area.len(), 1);
    }

    #[test]
    fn zero_perimeters_fill_half_a_spacing_inside() {
        let params = RegionParams {
            perimeters: 0,
            ..Default::default()
        };
        let per = make_perimeters(&[island_20()], &params, 0.2);
        assert!(per.loops.is_empty());
        let d = params.spacings(0.2).solid_infill / 2.0;
        assert_square(&per.infill_area[0].contour, d, 20.0 - d);
        assert_eq!(scaled(d), scaled(0.407_079_632_679_489_7 / 2.0));
    }
}
