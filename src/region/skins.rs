//! Top, bottom and internal solid areas ("skins") and the sparse rest of each layer's infill area.
//!
//! Layer `i` has islands `I_i` and infill area `A_i` (from [`super::perimeters`]); there are `N_b`
//! bottom and `N_t` top solid layers.
//!
//! - **bottom zone** `A_i − (I_(i−1) ∩ … ∩ I_(i−N_b))`: infill area that is not over material on
//!   *every* one of the `N_b` layers below, i.e. lies within `N_b` layers of a downward-facing
//!   surface. Layers that do not exist count as empty, so layers `0 … N_b−1` are solid entirely.
//! - **top zone** likewise with `I_(i+1) … I_(i+N_t)`, so the last `N_t` layers are solid.
//!
//! Roles: the part of `A_i` outside `I_(i+1)` (exposed to the top) is [`SolidRole::Top`]; the
//! part outside `I_(i−1)` is [`SolidRole::Bridge`] (over air), or [`SolidRole::Bottom`] on the
//! first layer (on the bed); bridges and bottoms win where top also applies (they are printed
//! on nothing and must bridge); the rest of the zones is [`SolidRole::Internal`].
//!
//! **Small sparse areas.** Whatever sparse area is left in pieces smaller than
//! `solid_infill_below_area` becomes internal solid (see [`RegionParams`]).
//!
//! **Internal bridges.** Internal solid infill directly over the sparse infill of the layer below
//! spans the gaps between sparse lines (2 mm at 20 %) like a bridge. Where it is at least six
//! bridge threads wide (PrusaSlicer's rule too), it becomes
//! [`SolidRole::InternalBridge`]: round threads at the bridge spacing, as PrusaSlicer's
//! "bridge over infill", so the first solid layer does not droop between the lines and the top
//! surface above it comes out flat. Its lines keep the layer's own direction, which crosses the
//! rectilinear sparse lines below at 90°.
//!
//! **Why islands, not infill areas, as cover.** Comparing infill areas would also count the ring
//! under the perimeters of the layers above as "uncovered". On a sloped wall that ring is there on
//! every layer (a 0.1 mm/layer slope gave a 0.8 mm solid ring of ~300 short lines on each layer of
//! a 150 mm disc), although the perimeters above already make the shell thick enough. With
//! islands as cover, a wall receding by `δ` per layer gets solid infill only where `N·δ` exceeds
//! the perimeter band, i.e. where the perimeters alone are thinner than `N` layers.
//!
//! **Under a step.** Where a smaller part stands on a larger one, its perimeters stand on the
//! larger part's top layers. Zones are therefore grown by the larger of the perimeter band width
//! ([`super::perimeters::infill_inset`]) and `solid_infill_margin`, so solid infill reaches under
//! the whole perimeter band of the part above and, with the default 3 mm margin, 2 mm beyond it
//! (PrusaSlicer grows its top and bottom surfaces by 3 mm too). Exposed top and bottom surfaces
//! are grown by `solid_infill_margin`. Everything is limited to the infill area.
//!
//! **Slivers.** Each difference is first *opened* by a quarter of the solid infill width, so
//! slivers narrower than half an extrusion give no solid infill. Layers solid throughout (the
//! first `N_b`, the last `N_t`) are taken whole.

use super::params::RegionParams;
use super::perimeters::{infill_inset, offset_cleaned, shrink_opened};
use crate::geom::{ExPolygon, difference, intersection, union};
use rayon::prelude::*;

/// What a solid area is for, which decides its speed and cooling downstream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolidRole {
    /// Visible upward-facing surface.
    Top,
    /// Downward-facing surface on the bed (the first layer).
    Bottom,
    /// Downward-facing surface over air: drawn as threads spanning it, in the direction that
    /// anchors them ([`super::bridge`]).
    Bridge,
    /// Solid layers between a surface and sparse infill.
    Internal,
    /// The internal solid directly over sparse infill, drawn as threads spanning the sparse
    /// lines below.
    InternalBridge,
}

/// A layer's infill area split by role. The six parts are disjoint and together make the infill
/// area (up to the margins explained in the module docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SkinAreas {
    /// Solid areas on the bed (first layer only).
    pub bottom: Vec<ExPolygon>,
    /// Solid areas over air.
    pub bridge: Vec<ExPolygon>,
    /// Solid areas with nothing above.
    pub top: Vec<ExPolygon>,
    /// Other solid areas within the top/bottom solid layer counts.
    pub internal_solid: Vec<ExPolygon>,
    /// Internal solid areas over the sparse infill of the layer below.
    pub internal_bridge: Vec<ExPolygon>,
    /// The rest, filled with the sparse pattern.
    pub sparse: Vec<ExPolygon>,
}

impl SkinAreas {
    /// The solid areas with their roles, in print order: bottom, bridge, internal bridge,
    /// internal, top.
    pub fn solid(&self) -> [(SolidRole, &[ExPolygon]); 5] {
        [
            (SolidRole::Bottom, &self.bottom),
            (SolidRole::Bridge, &self.bridge),
            (SolidRole::InternalBridge, &self.internal_bridge),
            (SolidRole::Internal, &self.internal_solid),
            (SolidRole::Top, &self.top),
        ]
    }
}

/// Intersections of runs of consecutive layers, each computed once and shared by the bottom and
/// top windows of every layer (the top window of layer `i` is the bottom window of layer
/// `i + N + 1`).
struct Windows<'a> {
    islands: &'a [Vec<ExPolygon>],
    /// `runs[k - 2][j]` is `islands[j] ∩ … ∩ islands[j + k − 1]` (runs of `k ≥ 2` layers).
    runs: Vec<Vec<Vec<ExPolygon>>>,
}

impl<'a> Windows<'a> {
    /// Runs of up to `longest` layers. Each run is folded left to right from the run one layer
    /// shorter, so it is exactly what intersecting the layers one by one in order gives.
    fn new(islands: &'a [Vec<ExPolygon>], longest: usize) -> Self {
        let mut runs: Vec<Vec<Vec<ExPolygon>>> = Vec::new();
        for k in 2..=longest.min(islands.len()) {
            let shorter: &[Vec<ExPolygon>] = runs.last().map_or(islands, Vec::as_slice);
            let next = (0..=islands.len() - k)
                .into_par_iter()
                .map(|j| {
                    let acc = &shorter[j];
                    if acc.is_empty() {
                        Vec::new()
                    } else {
                        intersection(acc, &islands[j + k - 1])
                    }
                })
                .collect();
            runs.push(next);
        }
        Self { islands, runs }
    }

    /// Intersection of `islands[range]`; empty if the range is empty.
    fn get(&self, range: std::ops::Range<usize>) -> &[ExPolygon] {
        match range.len() {
            0 => &[],
            1 => &self.islands[range.start],
            k => &self.runs[k - 2][range.start],
        }
    }
}

/// Skin areas of every layer. `islands[i]` are layer `i`'s sliced islands, `infill[i]` its
/// infill area and `heights[i]` its height (mm), bottom to top; missing heights count as
/// `params.layer_height`. Layers are independent given these inputs, so they are computed in
/// parallel; the result does not depend on the thread count.
pub fn detect_skins(
    islands: &[Vec<ExPolygon>],
    infill: &[Vec<ExPolygon>],
    heights: &[f64],
    params: &RegionParams,
) -> Vec<SkinAreas> {
    let count = infill.len().min(islands.len());
    let windows = Windows::new(
        &islands[..count],
        params.bottom_solid_layers.max(params.top_solid_layers),
    );
    let mut skins: Vec<SkinAreas> = (0..count)
        .into_par_iter()
        .map(|i| {
            let height = heights.get(i).copied().unwrap_or(params.layer_height);
            layer_skins(i, islands, infill, &windows, height, params)
        })
        .collect();
    if params.infill_density > 0.0 && params.infill_density < 1.0 {
        let split: Vec<Option<(Vec<ExPolygon>, Vec<ExPolygon>)>> = (1..skins.len())
            .into_par_iter()
            .map(|i| internal_bridge(&skins[i].internal_solid, &skins[i - 1].sparse, params))
            .collect();
        for (i, parts) in split.into_iter().enumerate() {
            if let Some((bridge, rest)) = parts {
                skins[i + 1].internal_bridge = bridge;
                skins[i + 1].internal_solid = rest;
            }
        }
    }
    skins
}

/// An internal bridge is opened by this many bridge thread widths: parts narrower than twice
/// that stay internal solid.
const INTERNAL_BRIDGE_OPENING: f64 = 3.0;

/// `internal_solid` split into (the part over `sparse_below`, the rest), parts narrower than
/// `2 · INTERNAL_BRIDGE_OPENING` bridge threads left solid; `None` when nothing is over sparse
/// infill.
fn internal_bridge(
    internal_solid: &[ExPolygon],
    sparse_below: &[ExPolygon],
    params: &RegionParams,
) -> Option<(Vec<ExPolygon>, Vec<ExPolygon>)> {
    if internal_solid.is_empty() || sparse_below.is_empty() {
        return None;
    }
    let over = intersection(internal_solid, sparse_below);
    if over.is_empty() {
        return None;
    }
    // Threads spanning the sparse lines below need room to span them: a strip narrower than
    // six bridge threads (the edge of a solid zone creeping over the sparse infill of the layer
    // below, as on every layer of a sloped top) rests on the solid beside it and gains nothing
    // but the bridge's slow speed and fan. PrusaSlicer opens its internal bridges by the same
    // three thread widths.
    let (bridge_width, _) = params.bridge_flow();
    let bridge = shrink_opened(&over, 0.0, INTERNAL_BRIDGE_OPENING * bridge_width);
    if bridge.is_empty() {
        return None;
    }
    let rest = difference(internal_solid, &bridge);
    Some((bridge, rest))
}

/// Skin areas of layer `i` (< both lengths), `height` mm high; see [`detect_skins`].
fn layer_skins(
    i: usize,
    islands: &[Vec<ExPolygon>],
    infill: &[Vec<ExPolygon>],
    windows: &Windows<'_>,
    height: f64,
    params: &RegionParams,
) -> SkinAreas {
    let area = &infill[i];
    if area.is_empty() {
        return SkinAreas::default();
    }
    let last = infill.len().min(islands.len()) - 1;
    let (nb, nt) = (params.bottom_solid_layers, params.top_solid_layers);
    let sliver = params.solid_infill_width / 4.0;
    let margin = params.solid_infill_margin.max(0.0);
    let band = infill_inset(params, height).max(0.0);
    // Opened (unless taken whole), grown by `grow`, limited to the infill area.
    let limit = |raw: Vec<ExPolygon>, whole: bool, grow: f64| -> Vec<ExPolygon> {
        if whole {
            return area.clone();
        }
        let opened = shrink_opened(&raw, 0.0, sliver);
        if opened.is_empty() || grow <= 0.0 {
            return opened;
        }
        intersection(&offset_cleaned(&opened, grow), area)
    };
    let empty = || (Vec::new(), false);

    let (exposed_bottom, bottom_whole) = match (nb, i) {
        (0, _) => empty(),
        (_, 0) => (Vec::new(), true),
        _ => (difference(area, &islands[i - 1]), false),
    };
    let (exposed_top, top_whole) = match nt {
        0 => empty(),
        _ if i == last => (Vec::new(), true),
        _ => (difference(area, &islands[i + 1]), false),
    };
    let (zone_bottom, zone_bottom_whole) = match nb {
        0 => empty(),
        _ if i < nb => (Vec::new(), true),
        _ => (difference(area, windows.get(i - nb..i)), false),
    };
    let (zone_top, zone_top_whole) = match nt {
        0 => empty(),
        _ if i + nt > last => (Vec::new(), true),
        _ => (difference(area, windows.get(i + 1..i + nt + 1)), false),
    };

    let bottom = if bottom_whole || !exposed_bottom.is_empty() {
        limit(exposed_bottom, bottom_whole, margin)
    } else {
        Vec::new()
    };
    let mut top = if top_whole || !exposed_top.is_empty() {
        limit(exposed_top, top_whole, margin)
    } else {
        Vec::new()
    };
    if !top.is_empty() && !bottom.is_empty() {
        top = difference(&top, &bottom);
    }
    let (bottom, bridge) = if i == 0 {
        (bottom, Vec::new())
    } else {
        (Vec::new(), bottom)
    };
    let below: Vec<ExPolygon> = [bottom.as_slice(), bridge.as_slice()].concat();
    let zone_whole = zone_bottom_whole || zone_top_whole;
    let zone = if zone_whole {
        Vec::new()
    } else {
        match (zone_bottom.is_empty(), zone_top.is_empty()) {
            (true, true) => Vec::new(),
            (false, true) => zone_bottom,
            (true, false) => zone_top,
            (false, false) => union(&[zone_bottom, zone_top].concat()),
        }
    };
    let surfaces: Vec<ExPolygon> = [below.as_slice(), top.as_slice()].concat();
    // The zone reaches under the perimeter band of a part standing on this layer, and the
    // margin anchors it: both from the same edge (where the part above begins), so the larger
    // of the two covers both. (Their sum widened the solid ring of every sloped wall by a
    // band on each of its layers.)
    let mut internal_solid = if zone_whole || !zone.is_empty() {
        limit(zone, zone_whole, band.max(margin))
    } else {
        Vec::new()
    };
    if !internal_solid.is_empty() && !surfaces.is_empty() {
        internal_solid = difference(&internal_solid, &surfaces);
    }
    let solid: Vec<ExPolygon> = [surfaces.as_slice(), internal_solid.as_slice()].concat();
    let mut sparse = if solid.is_empty() {
        area.clone()
    } else {
        difference(area, &solid)
    };
    let threshold = params.solid_infill_below_area;
    if threshold > 0.0 && params.infill_density < 1.0 {
        let (small, large): (Vec<ExPolygon>, Vec<ExPolygon>) =
            sparse.into_iter().partition(|ex| ex.area_mm2() < threshold);
        sparse = large;
        if !small.is_empty() {
            internal_solid = if internal_solid.is_empty() {
                small
            } else {
                union(&[internal_solid, small].concat())
            };
        }
    }
    SkinAreas {
        bottom,
        bridge,
        top,
        internal_solid,
        internal_bridge: Vec::new(),
        sparse,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Point2, Polygon};
    use crate::region::perimeters::infill_inset;
    use crate::region::perimeters::make_perimeters;
    use crate::region::test_util::{contains, square_island, total_area};

    /// Infill areas and skins of a stack of layers.
    fn skins_of(stack: &[Vec<ExPolygon>], params: &RegionParams) -> Vec<SkinAreas> {
        let infill: Vec<Vec<ExPolygon>> = stack
            .iter()
            .map(|l| make_perimeters(l, params, 0.2).infill_area)
            .collect();
        detect_skins(stack, &infill, &[], params)
    }

    #[test]
    fn ten_identical_squares_are_solid_three_at_each_end() {
        let params = RegionParams::default();
        let stack = vec![vec![square_island(0.0, 0.0, 20.0)]; 10];
        let skins = skins_of(&stack, &params);
        let infill_area = total_area(&make_perimeters(&stack[0], &params, 0.2).infill_area);
        for (i, s) in skins.iter().enumerate() {
            let solid = total_area(&s.bottom)
                + total_area(&s.top)
                + total_area(&s.internal_solid)
                + total_area(&s.internal_bridge);
            let sparse = total_area(&s.sparse);
            if (3..=6).contains(&i) {
                assert!(
                    solid < 1e-9 && (sparse - infill_area).abs() < 1e-6,
                    "layer {i}: {s:?}"
                );
            } else {
                assert!(
                    sparse < 1e-9 && (solid - infill_area).abs() < 1e-6,
                    "layer {i}: {s:?}"
                );
            }
        }
        assert!((total_area(&skins[0].bottom) - infill_area).abs() < 1e-6);
        assert!((total_area(&skins[9].top) - infill_area).abs() < 1e-6);
        for i in [1, 2, 8] {
            assert!(
                (total_area(&skins[i].internal_solid) - infill_area).abs() < 1e-6,
                "{i}"
            );
        }
        // The first solid layer over the sparse ones bridges the sparse lines.
        assert!((total_area(&skins[7].internal_bridge) - infill_area).abs() < 1e-6);
        assert!(
            skins
                .iter()
                .enumerate()
                .all(|(i, s)| s.internal_bridge.is_empty() == (i != 7))
        );
    }

    #[test]
    fn step_makes_the_top_of_the_big_part_solid_up_to_under_the_step_edge() {
        // A narrow margin and no small-area rule, so the ring's edges are measurable.
        let params = RegionParams {
            solid_infill_margin: 0.5,
            solid_infill_below_area: 0.0,
            ..Default::default()
        };
        // Big 20 mm square for layers 0–5, small 10 mm square (5..15) for layers 6–11.
        let mut stack = vec![vec![square_island(0.0, 0.0, 20.0)]; 6];
        stack.extend(vec![vec![square_island(5.0, 5.0, 10.0)]; 6]);
        let skins = skins_of(&stack, &params);
        let at = |a: &[ExPolygon], x: f64, y: f64| contains(a, Point2::from_mm(x, y));
        let solid = |s: &SkinAreas, x, y| {
            at(&s.top, x, y)
                || at(&s.internal_solid, x, y)
                || at(&s.internal_bridge, x, y)
                || at(&s.bottom, x, y)
        };
        // The last big layer: the uncovered ring is a top surface.
        assert!(at(&skins[5].top, 2.0, 10.0));
        // Under the small part's perimeters (0.8 mm inside its edge, past the top margin): solid, but not top.
        assert!(at(&skins[5].internal_solid, 5.8, 10.0));
        assert!(!at(&skins[5].top, 5.8, 10.0));
        // Layers 3 and 4 are within 3 layers of that top surface.
        for i in [3, 4] {
            assert!(at(&skins[i].internal_solid, 2.0, 10.0), "layer {i}");
            assert!(at(&skins[i].internal_solid, 5.8, 10.0), "layer {i}");
        }
        // The middle of the small part is sparse all the way from layer 3 to layer 8.
        for (i, s) in skins.iter().enumerate().take(9).skip(3) {
            assert!(
                at(&s.sparse, 10.0, 10.0) && !solid(s, 10.0, 10.0),
                "layer {i}"
            );
        }
        // The solid ring stops at the small part's infill area: the band (0.93 mm) is wider
        // than this margin, and covers it.
        assert!(at(&skins[5].sparse, 7.0, 10.0));
        // The small part's first layers stand on the solid ring: not solid themselves.
        assert!(!solid(&skins[6], 10.0, 10.0));
        assert!(at(&skins[11].top, 10.0, 10.0));
    }

    #[test]
    fn internal_bridges_need_six_threads_of_width() {
        // A 20 mm square of internal solid over sparse infill that reaches `w` mm into it: the
        // strip is bridged (exactly, the opening keeps its square corners) when it is at least
        // six 0.4 mm threads wide, and stays solid when it is narrower.
        use crate::region::test_util::rect_island;
        let params = RegionParams::default();
        assert_eq!(params.bridge_flow().0, 0.4);
        let solid = vec![square_island(0.0, 0.0, 20.0)];
        for (w, bridged) in [(2.0, false), (2.3, false), (2.5, true), (6.0, true)] {
            let sparse = vec![rect_island(20.0 - w, -5.0, 30.0, 25.0)];
            match internal_bridge(&solid, &sparse, &params) {
                None => assert!(!bridged, "{w} mm: not bridged"),
                Some((bridge, rest)) => {
                    assert!(bridged, "{w} mm: bridged {bridge:?}");
                    assert!((total_area(&bridge) - 20.0 * w).abs() < 1e-6, "{w} mm");
                    assert!(
                        (total_area(&rest) - 20.0 * (20.0 - w)).abs() < 1e-6,
                        "{w} mm"
                    );
                }
            }
        }
    }

    #[test]
    fn under_a_step_the_solid_reaches_the_margin_past_the_edge_not_margin_plus_band() {
        // The default 3 mm margin is wider than the perimeter band (0.93 mm): the solid zone
        // under the small part ends 3 mm inside its edge (x = 5), where PrusaSlicer's 3 mm
        // growth of the top surface ends too.
        let params = RegionParams {
            solid_infill_below_area: 0.0,
            ..Default::default()
        };
        let band = infill_inset(&params, 0.2);
        assert!(band < params.solid_infill_margin);
        let mut stack = vec![vec![square_island(0.0, 0.0, 20.0)]; 6];
        stack.extend(vec![vec![square_island(5.0, 5.0, 10.0)]; 6]);
        let skins = skins_of(&stack, &params);
        let at = |a: &[ExPolygon], x: f64| contains(a, Point2::from_mm(x, 10.0));
        for i in [3, 4] {
            assert!(at(&skins[i].internal_solid, 7.95), "layer {i}");
            assert!(at(&skins[i].sparse, 8.05), "layer {i}");
            assert!(!at(&skins[i].internal_solid, 8.05), "layer {i}");
        }
    }

    #[test]
    fn zero_solid_layers_leave_everything_sparse_and_single_layer_is_bottom() {
        let none = RegionParams {
            top_solid_layers: 0,
            bottom_solid_layers: 0,
            ..Default::default()
        };
        let stack = vec![vec![square_island(0.0, 0.0, 20.0)]; 4];
        for s in skins_of(&stack, &none) {
            assert!(s.bottom.is_empty() && s.top.is_empty() && s.internal_solid.is_empty());
            assert_eq!(s.sparse.len(), 1);
        }
        let one = skins_of(&stack[..1], &RegionParams::default());
        assert_eq!(one[0].bottom.len(), 1);
        assert!(one[0].top.is_empty() && one[0].sparse.is_empty());
    }

    /// Ten layers of a square pyramid frustum whose walls recede by `step` mm per layer.
    fn frustum(step: f64) -> Vec<Vec<ExPolygon>> {
        (0..10)
            .map(|i| {
                let d = step * i as f64;
                vec![ExPolygon {
                    contour: Polygon::new(vec![
                        Point2::from_mm(d, d),
                        Point2::from_mm(40.0 - d, d),
                        Point2::from_mm(40.0 - d, 40.0 - d),
                        Point2::from_mm(d, 40.0 - d),
                    ]),
                    holes: vec![],
                }]
            })
            .collect()
    }

    #[test]
    fn steep_walls_get_no_solid_but_shallow_slopes_do() {
        let params = RegionParams::default();
        let band = infill_inset(&params, 0.2);
        // 0.02 and 0.1 mm per layer: three layers recede less than the perimeter band (≈ 0.93 mm).
        for step in [0.02, 0.1] {
            assert!(3.0 * step < band);
            let skins = skins_of(&frustum(step), &params);
            for (i, s) in skins.iter().enumerate().take(7).skip(3) {
                let none = s.internal_solid.is_empty() && s.top.is_empty() && s.bottom.is_empty();
                assert!(none, "step {step}, layer {i}: {s:?}");
            }
        }
        // 0.6 mm per layer: the perimeters alone are thinner than three layers, so the rim of
        // each middle layer is solid, its centre sparse.
        let skins = skins_of(&frustum(0.6), &params);
        let at = |a: &[ExPolygon], x: f64, y: f64| contains(a, Point2::from_mm(x, y));
        for (i, s) in skins.iter().enumerate().take(7).skip(3) {
            let rim = 0.6 * i as f64 + band + 0.3;
            assert!(at(&s.internal_solid, rim, 20.0), "layer {i}");
            assert!(at(&s.sparse, 20.0, 20.0), "layer {i}");
        }
    }
}
