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
//! **Thin parts.** Each loop area is *opened* (shrunk by `d_k + r`, grown back by `r`), so a loop
//! that would run over itself is not made. The classic generator takes `r = 0.3 · spacing`
//! (PrusaSlicer's `INSET_OVERLAP_TOLERANCE` of 0.4: a loop may overlap itself by 40 % of a
//! spacing, so a 0.7 mm wall gets a loop whose sides overlap and is over-filled by up to 18 %).
//! The variable generator ([`PerimeterGenerator::Variable`]) takes `r = spacing / 2`: a loop is
//! made only where its two sides lie at least one spacing apart, and the band it leaves is filled
//! with beads sized to its thickness (see below and [`super::gapfill::beads`]).
//!
//! **Thin walls.** With `thin_walls`, the part of an island outside its external loop's bead (the
//! loop's centreline area grown by `d_0`) is kept as [`Perimeters::thin_walls`]: a fin or a wall
//! too thin for a loop, the tip of a sharp corner. The regions stage fills it along its medial
//! axis at its own thickness, at least [`MIN_BEAD_NOZZLES`] nozzle diameters wide and down to
//! features of [`MIN_FEATURE_NOZZLES`] (PrusaSlicer's Arachne defaults), so such walls print
//! instead of vanishing. The classic generator leaves out pieces shorter than a perimeter width
//! (the regions stage's `thick_lines`), as PrusaSlicer's classic thin walls do.
//!
//! **Gaps.** Where a loop is missing or pinched by that opening, a strip between two loops is
//! left without material. Between loop `k−1` (centreline area `C_(k−1)`) and loop `k` at distance
//! `δ` the strip is `C_(k−1) ⊖ δ/2 − C_k ⊕ δ/2`: what loop `k`'s bead should have covered and
//! did not. After the last loop the same is done for a virtual next loop one perimeter spacing
//! further in, so the strip between the perimeters and the infill is found too (PrusaSlicer's
//! classic perimeter generator). Strips are kept between `0.12 · perimeter_width` and twice the
//! perimeter spacing wide ([`GAP_MIN_FRACTION`]); they are filled by [`super::gapfill`] and cut
//! from the infill area.
//!
//! **Infill area.** The area inside the innermost loop where infill *centrelines* may go: the
//! island shrunk by `d_last + (last_spacing + solid_infill_spacing) / 2 − infill_overlap ·
//! perimeter_width`, so infill lines clipped to it sit one spacing inside the innermost loop, less
//! the overlap that bonds them, then opened by `0.3 · solid spacing` so no infill is laid in a
//! sliver the nozzle cannot fill with whole lines (the gap fill takes it). With zero perimeters
//! it is the island shrunk by half a solid infill spacing.

use super::params::{PerimeterGenerator, RegionParams};
use super::simplify::cleaned;
use crate::geom::{ExPolygon, Join, Polygon, difference, offset, scaled, unscaled};

/// How far (mm) the opening that removes too-thin loops reaches, as a fraction of the spacing:
/// `(1 − INSET_OVERLAP_TOLERANCE) / 2` with PrusaSlicer's tolerance of 0.4.
const OPENING_FRACTION: f64 = 0.3;

/// Widest gap or thin wall filled, in perimeter spacings, by generator: the classic generator's
/// loops leave gaps of up to two spacings; the variable generator's up to two spacings plus the
/// narrowest gap (see [`opening_radius`]).
pub fn max_fill_spacings(generator: PerimeterGenerator) -> f64 {
    match generator {
        PerimeterGenerator::Classic => 2.0,
        PerimeterGenerator::Variable => 2.5,
    }
}

/// The radius (mm) of the opening of a loop area whose loops are `spacing` apart. Classic:
/// `0.3 · spacing`. Variable: half a spacing plus half the narrowest gap, so a loop is made only
/// where its two sides' beads are at least a spacing apart *and* leave a gap wide enough to fill
/// between them; a wall just thinner is two beads of half its thickness instead of a loop and an
/// unfilled hairline (which would leave a 0.91 mm wall 11 % short of plastic).
fn opening_radius(params: &RegionParams, spacing: f64) -> f64 {
    match params.perimeter_generator {
        PerimeterGenerator::Classic => OPENING_FRACTION * spacing,
        PerimeterGenerator::Variable => (spacing + GAP_MIN_FRACTION * params.perimeter_width) / 2.0,
    }
}

/// Largest distance (mm) between a bead's rounded end and the chords that stand for it when the
/// external loop's reach is measured: far below the smallest thin-wall feature.
const BEAD_ARC_MM: f64 = 0.005;

/// Narrowest bead printed in a thin wall, in nozzle diameters (PrusaSlicer's Arachne
/// `min_bead_width` of 85 %): a thinner feature is printed this wide rather than not at all.
pub const MIN_BEAD_NOZZLES: f64 = 0.85;

/// Thinnest feature printed as a thin wall, in nozzle diameters (Arachne's `min_feature_size` of
/// 25 %): below it a fin is within the squish of the beads beside it.
pub const MIN_FEATURE_NOZZLES: f64 = 0.25;

/// Narrowest gap filled, as a fraction of `perimeter_width`: PrusaSlicer's
/// `0.2 · width · (1 − INSET_OVERLAP_TOLERANCE)`. Narrower strips are within the beads' own
/// squish and would only be over-filled.
pub const GAP_MIN_FRACTION: f64 = 0.2 * (1.0 - 0.4);

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
    /// Strips between loops too narrow for another loop, to be gap-filled (empty unless
    /// `gap_fill` is on); see the module docs.
    pub gaps: Vec<ExPolygon>,
    /// Parts of the islands outside their external loop's bead, too thin for a loop (empty
    /// unless `thin_walls` is on); see the module docs.
    pub thin_walls: Vec<ExPolygon>,
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
    let solid_spacing = params.spacings(height).solid_infill;
    let mut out = Perimeters::default();
    let mut gaps: Vec<ExPolygon> = Vec::new();
    for (island_index, island) in islands.iter().enumerate() {
        let island = std::slice::from_ref(island);
        let mut island_loops: Vec<PerimeterLoop> = Vec::new();
        // The deepest shrunk area so far: (depth in nm, area). Each deeper shrink starts from it.
        let mut base: Option<(i64, Vec<ExPolygon>)> = None;
        // The previous loop's centreline area and spacing, for the gaps.
        let mut previous: Option<(Vec<ExPolygon>, f64)> = None;
        for (k, &(depth, width, spacing)) in plan.iter().enumerate() {
            let radius = opening_radius(params, spacing);
            let shrunk = shrink_from(island, base.as_ref(), depth + radius);
            let area = if shrunk.is_empty() || radius <= 0.0 {
                shrunk.clone()
            } else {
                offset_cleaned(&shrunk, radius)
            };
            base = Some((scaled(depth + radius), shrunk));
            if k == 0 && params.thin_walls {
                out.thin_walls.extend(if area.is_empty() {
                    island.to_vec()
                } else {
                    // What the loop's bead covers is its centreline swept by a disc: a round
                    // offset. A mitred one would claim up to three times the bead's reach past
                    // the tip of a tapering loop and leave the wall there empty.
                    let bead = cleaned(offset(&area, depth + SAFETY_MM, Join::Round(BEAD_ARC_MM)));
                    difference(island, &bead)
                });
            }
            if params.gap_fill
                && let Some((prev, prev_spacing)) = &previous
            {
                let distance = (prev_spacing + spacing) / 2.0;
                gaps.extend(gap_between(prev, &area, distance));
            }
            previous = Some((area.clone(), spacing));
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
        if params.gap_fill
            && let Some((last, spacing)) = &previous
        {
            // The strip a further loop would have filled, next to the infill: that loop's
            // centreline area would be `last` shrunk by a spacing and opened by `r`, and its
            // bead would cover that grown by half a spacing; both growths are taken at once.
            let expected = offset_cleaned(last, -spacing / 2.0);
            if !expected.is_empty() {
                let r = opening_radius(params, *spacing);
                let core = offset_cleaned(&expected, -(spacing / 2.0 + r));
                if core.is_empty() {
                    gaps.extend(expected);
                } else {
                    let covered = offset_cleaned(&core, r + spacing / 2.0 + SAFETY_MM);
                    gaps.extend(difference(&expected, &covered));
                }
            }
        }
        let radius = OPENING_FRACTION * solid_spacing;
        let shrunk = shrink_from(island, base.as_ref(), inset + radius);
        if !shrunk.is_empty() {
            out.infill_area.extend(offset_cleaned(&shrunk, radius));
        }
    }
    if !gaps.is_empty() {
        let sp = params.spacings(height);
        let min = GAP_MIN_FRACTION * params.perimeter_width;
        let max = max_fill_spacings(params.perimeter_generator) * sp.perimeter;
        // Drop what is thinner than `min` everywhere and what is wider than `max` (an area a
        // loop or infill covers).
        let kept = shrink_opened(&gaps, 0.0, min / 2.0);
        let wide = shrink_opened(&kept, 0.0, max / 2.0);
        out.gaps = if wide.is_empty() {
            kept
        } else {
            difference(&kept, &offset_cleaned(&wide, SAFETY_MM))
        };
        if !out.gaps.is_empty() && !out.infill_area.is_empty() {
            out.infill_area = difference(&out.infill_area, &out.gaps);
        }
    }
    if !out.thin_walls.is_empty() {
        // Slivers thinner than the smallest feature (where the loop's bead meets the contour
        // within rounding) are dropped; what is left is filled along its middle.
        let min = MIN_FEATURE_NOZZLES * params.nozzle_diameter;
        out.thin_walls = shrink_opened(&out.thin_walls, 0.0, min / 2.0);
    }
    out
}

/// A small extra growth (mm) so that boundaries meeting exactly do not leave hairline slivers in
/// a difference (PrusaSlicer's `ClipperSafetyOffset`, 10 nm, doubled).
const SAFETY_MM: f64 = 2e-5;

/// The part of the strip `outer ⊖ distance/2` not covered by the beads of the loops on the
/// boundary of `inner` (a centreline area `distance` further in) or anything inside them.
fn gap_between(outer: &[ExPolygon], inner: &[ExPolygon], distance: f64) -> Vec<ExPolygon> {
    let expected = offset_cleaned(outer, -distance / 2.0);
    if expected.is_empty() {
        return expected;
    }
    if inner.is_empty() {
        return expected;
    }
    difference(
        &expected,
        &offset_cleaned(inner, distance / 2.0 + SAFETY_MM),
    )
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
    fn a_strip_too_narrow_for_the_second_loop_leaves_a_centred_gap() {
        // 1.3 mm wide: the external loop fits (its centreline area is 0.85 mm wide), the second
        // loop does not (it needs 2 · (0.632 + 0.122) = 1.508 mm).
        let strip = crate::region::test_util::rect_island(0.0, 0.0, 20.0, 1.3);
        let params = RegionParams::default();
        let per = make_perimeters(&[strip], &params, 0.2);
        assert_eq!(per.loops.len(), 1);
        assert!(per.infill_area.is_empty());
        // The gap: the external loop's centreline area shrunk by half the loop distance.
        let half = params.spacings(0.2).perimeter / 2.0;
        let (x0, y0) = (0.225 + half, 0.225 + half);
        assert_eq!(per.gaps.len(), 1);
        assert_square_rect(&per.gaps[0], [x0, y0, 20.0 - x0, 1.3 - y0]);
        // Without gap fill there is no gap.
        let off = RegionParams {
            gap_fill: false,
            ..params.clone()
        };
        assert!(make_perimeters(&[per_strip()], &off, 0.2).gaps.is_empty());
        // A wide square has none either: every loop is whole.
        assert!(
            make_perimeters(&[island_20()], &params, 0.2)
                .gaps
                .is_empty()
        );
    }

    fn per_strip() -> ExPolygon {
        crate::region::test_util::rect_island(0.0, 0.0, 20.0, 1.3)
    }

    /// `ex` is the axis-aligned rectangle `[x0, y0, x1, y1]` (mm) within 1 µm, without holes.
    fn assert_square_rect(ex: &ExPolygon, r: [f64; 4]) {
        assert!(ex.holes.is_empty());
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in &ex.contour.points {
            let (x, y) = (crate::geom::unscaled(p.x), crate::geom::unscaled(p.y));
            lo = [lo[0].min(x), lo[1].min(y)];
            hi = [hi[0].max(x), hi[1].max(y)];
        }
        let got = [lo[0], lo[1], hi[0], hi[1]];
        for (g, w) in got.iter().zip(r) {
            assert!((g - w).abs() < 1e-3, "{got:?} vs {r:?}");
        }
        let area = (r[2] - r[0]) * (r[3] - r[1]);
        assert!(
            (ex.area_mm2() - area).abs() < 1e-3,
            "{} vs {area}",
            ex.area_mm2()
        );
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
