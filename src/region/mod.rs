//! Print regions of each layer: perimeters, solid and sparse infill, skirt.
//!
//! Place in the pipeline (stage "regions" of `design.md`): Scene → slice → **regions** → Program →
//! G-code. Input is one object's sliced islands per layer, bottom to top; output is, per layer,
//! the extrusion centrelines by role, still in scaled integer 2D coordinates. The Program stage
//! turns them into 3D toolpaths with widths, heights, speeds and tools.
//!
//! [`make_regions`] runs three steps, each parallel over layers where the layers are independent
//! (the output does not depend on the thread count), on islands first [`simplify`]-ed to
//! [`simplify::RESOLUTION_MM`]:
//!
//! 1. [`perimeters`]: loops by inward offsets of each island, the strips between them too narrow
//!    for another loop (filled by [`gapfill`]), and the infill area inside them;
//! 2. [`skins`]: the infill area split into top, bottom, bridge, internal solid and sparse areas
//!    by comparing neighbouring layers;
//! 3. [`infill`]: solid areas filled with [`infill::Rectilinear`] at 100 % (bridges in the
//!    direction [`bridge`] picks, at the bridge spacing), sparse areas with the configured
//!    pattern at `spacing / density`; plus the [`skirt`] on the first layer.
//!
//! The first layer is made with every width set to `first_layer_width`
//! ([`RegionParams::for_layer`]).
//!
//! Spacings follow the flow model documented in [`params`].

pub mod beads;
pub mod bridge;
pub mod brim;
pub mod cavity;
pub mod gapfill;
pub mod infill;
pub mod overhang;
pub mod params;
pub mod perimeters;
pub mod simplify;
pub mod skins;
pub mod skirt;
pub mod support;
#[cfg(test)]
pub(crate) mod test_util;

pub use brim::{Brim, BrimParams, BrimType, make_brim};
pub use overhang::{OverhangZones, overhang_zones};
pub use params::{
    InfillPatternKind, MAX_PERIMETERS, MAX_SKIRT_LOOPS, MAX_SOLID_INFILL_MARGIN, MAX_SOLID_LAYERS,
    MAX_WIDTH, MAX_WIDTH_NOZZLES, MIN_LAYER_HEIGHT, NOZZLE_RANGE, ParamError, PerimeterGenerator,
    RegionParams, Spacings, spacing,
};
pub use perimeters::{PerimeterLoop, Perimeters, make_perimeters};
pub use skins::{SkinAreas, SolidRole, detect_skins};
pub use skirt::make_skirt;
pub use support::{SupportLayer, SupportParams, SupportPattern, make_supports};

use crate::geom::{Cap, ExPolygon, Join, Polygon, Polyline, Tolerances, offset, stroke};
use gapfill::ThickPolyline;
use infill::lines::{LineFamily, fill_family};
use infill::{InfillPattern, Rectilinear};
use rayon::prelude::*;

/// Solid infill lines of one role.
#[derive(Debug, Clone, PartialEq)]
pub struct Fill {
    /// Centrelines, each an open polyline to extrude in order.
    pub lines: Vec<Polyline>,
    /// What the lines are for.
    pub role: SolidRole,
    /// Extrusion width the lines are spaced for, mm (for [`SolidRole::Bridge`] the diameter of
    /// the round thread, see [`RegionParams::bridge_flow`]).
    pub width: f64,
}

/// Everything to print on one layer of one object.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerRegions {
    /// Layer index, 0 at the bottom.
    pub index: usize,
    /// Layer height used for the spacings, mm.
    pub height: f64,
    /// Perimeter loops in print order (see [`Perimeters::loops`]).
    pub perimeters: Vec<PerimeterLoop>,
    /// Solid infill in print order: bottom, bridge, internal bridge, internal, top; roles
    /// without area are left out.
    pub solid_infill: Vec<Fill>,
    /// Sparse infill centrelines.
    pub sparse_infill: Vec<Polyline>,
    /// Extrusion width of the sparse infill lines, mm.
    pub sparse_width: f64,
    /// Variable-width centrelines filling the gaps between perimeter loops.
    pub gap_fill: Vec<ThickPolyline>,
    /// Skirt loops, outermost first; only on layer 0.
    pub skirt: Vec<Polygon>,
    /// Brim loops and ears; only on layer 0 (printed with the skirt's width and speed).
    pub brim: Brim,
    /// Support material on this layer.
    pub support: SupportLayer,
    /// Extrusion width of the skirt loops, mm.
    pub skirt_width: f64,
    /// Where infill centrelines may go (inside the innermost perimeters), for routing and
    /// cavities.
    pub infill_area: Vec<ExPolygon>,
    /// The infill area split by role.
    pub skins: SkinAreas,
    /// Where the perimeter beads hang out over the layer below, one entry per loop width that
    /// does ([`overhang`]); empty on the first layer, when nothing overhangs, and without
    /// [`RegionParams::overhangs`].
    pub overhangs: Vec<OverhangZones>,
}

/// What [`make_regions_with_heights`] cannot work with.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegionError {
    /// There is not exactly one height per layer.
    ///
    /// How to fix: pass the heights of the same layers as the islands.
    #[error("{layers} layers but {heights} layer heights")]
    HeightCount {
        /// Number of layers given.
        layers: usize,
        /// Number of heights given.
        heights: usize,
    },
    /// A layer height is not a finite positive length.
    ///
    /// How to fix: this is a slicer bug if the heights come from `slice`; please file an issue.
    #[error("layer {index} has height {height} mm; heights must be finite and > 0")]
    BadHeight {
        /// The layer index.
        index: usize,
        /// The height given.
        height: f64,
    },
    /// The parameters are unusable (every problem is listed).
    ///
    /// How to fix: correct the listed fields of the `[slice]` configuration.
    #[error("invalid region parameters: {}", .0.iter().map(ToString::to_string).collect::<Vec<_>>().join("; "))]
    Params(Vec<ParamError>),
}

/// Regions of every layer of one object whose layers are all `params.layer_height` high.
/// `layers[i]` are the islands of layer `i`, bottom to top.
///
/// Parameters are not checked here (see [`RegionParams::validate`] and
/// [`make_regions_with_heights`]); unusable values give empty regions, never a panic.
pub fn make_regions(layers: &[Vec<ExPolygon>], params: &RegionParams) -> Vec<LayerRegions> {
    let heights = vec![params.layer_height; layers.len()];
    regions(layers, &heights, params)
}

/// Regions of every layer of one object, with `heights[i]` (mm) the height of layer `i` (the
/// first layer is often thicker), after checking the heights and parameters.
pub fn make_regions_with_heights(
    layers: &[Vec<ExPolygon>],
    heights: &[f64],
    params: &RegionParams,
) -> Result<Vec<LayerRegions>, RegionError> {
    if heights.len() != layers.len() {
        return Err(RegionError::HeightCount {
            layers: layers.len(),
            heights: heights.len(),
        });
    }
    if let Some((index, &height)) = heights
        .iter()
        .enumerate()
        .find(|(_, h)| !(h.is_finite() && **h > 0.0))
    {
        return Err(RegionError::BadHeight { index, height });
    }
    let problems = params.validate();
    if !problems.is_empty() {
        return Err(RegionError::Params(problems));
    }
    Ok(regions(layers, heights, params))
}

/// The three steps of the module docs; `heights` has one entry per layer.
fn regions(layers: &[Vec<ExPolygon>], heights: &[f64], params: &RegionParams) -> Vec<LayerRegions> {
    let simplified: Vec<Vec<ExPolygon>> = layers
        .par_iter()
        .map(|islands| simplify::simplify_islands(islands, simplify::RESOLUTION_MM))
        .collect();
    let layers = simplified.as_slice();
    let perimeters: Vec<Perimeters> = layers
        .par_iter()
        .zip(heights)
        .enumerate()
        .map(|(index, (islands, &h))| make_perimeters(islands, &params.for_layer(index), h))
        .collect();
    let infill_areas: Vec<Vec<ExPolygon>> =
        perimeters.iter().map(|p| p.infill_area.clone()).collect();
    let skins = detect_skins(layers, &infill_areas, heights, params);
    let widths: Vec<f64> = (0..layers.len())
        .map(|i| params.for_layer(i).perimeter_width)
        .collect();
    let supports = make_supports(layers, heights, &widths, &params.support);
    let first = params.for_layer(0);
    let (skirt, brim) = match (layers.first(), heights.first()) {
        (Some(islands), Some(&h)) => {
            let brim = make_brim(
                islands,
                &params.brim,
                first.perimeter_width,
                first.spacings(h).perimeter,
            );
            // The skirt goes around everything on the first layer: brim and support too.
            let mut around = islands.clone();
            around.extend(printed_area(&brim, &supports[0], first.perimeter_width));
            (make_skirt(&around, &first, h), brim)
        }
        _ => (Vec::new(), Brim::default()),
    };
    perimeters
        .into_par_iter()
        .zip(skins)
        .zip(supports)
        .zip(heights)
        .enumerate()
        .map(|(index, (((per, skins), support), &height))| {
            let lp = params.for_layer(index);
            let below = index
                .checked_sub(1)
                .map_or(&[][..], |i| layers[i].as_slice());
            let gap_fill = thick_lines(&per, &lp, height);
            let overhangs = if params.overhangs && index > 0 {
                layer_overhangs(&layers[index], below, &per.loops, params.nozzle_diameter)
            } else {
                Vec::new()
            };
            LayerRegions {
                index,
                height,
                perimeters: per.loops,
                solid_infill: solid_fills(&skins, below, &lp, index, height),
                sparse_infill: sparse_fill(&skins, &lp, index, height),
                sparse_width: lp.infill_width,
                gap_fill,
                skirt: if index == 0 {
                    skirt.clone()
                } else {
                    Vec::new()
                },
                brim: if index == 0 {
                    brim.clone()
                } else {
                    Brim::default()
                },
                support,
                skirt_width: lp.perimeter_width,
                infill_area: per.infill_area,
                skins,
                overhangs,
            }
        })
        .collect()
}

/// The overhang zones of a layer's `loops` over the layer `below`, one per loop width that
/// overhangs, in order of width.
fn layer_overhangs(
    islands: &[ExPolygon],
    below: &[ExPolygon],
    loops: &[PerimeterLoop],
    nozzle: f64,
) -> Vec<OverhangZones> {
    let mut widths: Vec<f64> = loops.iter().map(|l| l.width).collect();
    widths.sort_by(f64::total_cmp);
    widths.dedup();
    widths
        .into_iter()
        .filter_map(|w| overhang_zones(islands, below, w, nozzle))
        .collect()
}

/// The area the brim's beads (`width` wide) and the support cover on the first layer.
fn printed_area(brim: &Brim, support: &SupportLayer, width: f64) -> Vec<ExPolygon> {
    if brim.is_empty() && support.area.is_empty() {
        return Vec::new();
    }
    let join = Join::Round(Tolerances::default().curve_flattening.mm());
    let mut area = stroke(&brim.lines(), width, join, Cap::Round(0.01));
    area.extend(offset(&support.area, width / 2.0, join));
    area
}

/// The variable-width lines of one layer: its gaps' (between `gap_min` and
/// [`perimeters::max_fill_spacings`] thick)
/// and its thin walls' (down to the smallest feature, raised to the narrowest bead, up to 2.5
/// spacings: a wall just too thin for a loop is about 2.1 spacings), then, with the variable
/// generator, each split into as many beads as its thickness holds ([`beads::beads`]).
fn thick_lines(per: &Perimeters, params: &RegionParams, height: f64) -> Vec<ThickPolyline> {
    let sp = params.spacings(height);
    let mut lines = if per.gaps.is_empty() {
        Vec::new()
    } else {
        gapfill::gap_fill(
            &per.gaps,
            perimeters::GAP_MIN_FRACTION * params.perimeter_width,
            perimeters::max_fill_spacings(params.perimeter_generator) * sp.perimeter,
        )
    };
    if !per.thin_walls.is_empty() {
        let nozzle = params.nozzle_diameter;
        let min_bead = spacing(perimeters::MIN_BEAD_NOZZLES * nozzle, height);
        // The classic generator, as PrusaSlicer's, prints no thin wall shorter than a
        // perimeter is wide: such a piece is the tip of a sharp corner past the external loop,
        // a dot of plastic that costs a travel (and on most printers a retraction) of its own.
        let min_length = match params.perimeter_generator {
            PerimeterGenerator::Classic => params.perimeter_width,
            PerimeterGenerator::Variable => 0.0,
        };
        lines.extend(
            gapfill::gap_fill(
                &per.thin_walls,
                perimeters::MIN_FEATURE_NOZZLES * nozzle,
                2.5 * sp.perimeter,
            )
            .into_iter()
            .filter(|l| {
                crate::geom::polyline_length(&l.points) >= crate::geom::scaled(min_length) as f64
            })
            .map(|l| beads::at_least(l, min_bead)),
        );
    }
    match params.perimeter_generator {
        PerimeterGenerator::Classic => lines,
        PerimeterGenerator::Variable => lines
            .iter()
            .flat_map(|l| beads::beads(l, sp.perimeter))
            .collect(),
    }
}

/// Solid infill of one layer, role by role in print order: bottom and internal solid at the
/// solid spacing, top at the top spacing, internal bridges at the bridge spacing, all turning
/// 90° a layer; each bridge over air in its own direction ([`bridge::bridge_angle`] against the
/// islands `below`), at the bridge spacing.
fn solid_fills(
    skins: &SkinAreas,
    below: &[ExPolygon],
    params: &RegionParams,
    index: usize,
    height: f64,
) -> Vec<Fill> {
    let sp = params.spacings(height);
    let pattern = Rectilinear::new(params.infill_angle_deg);
    let (bridge_width, bridge_spacing) = params.bridge_flow();
    let mut fills = Vec::new();
    for (role, area) in skins.solid() {
        if area.is_empty() {
            continue;
        }
        let (lines, width) = match role {
            SolidRole::Bridge => {
                // The default when nothing anchors: the direction sparse infill would take.
                let turn = if index % 2 == 1 { 90.0 } else { 0.0 };
                let default = params.infill_angle_deg + turn;
                let lines = area
                    .iter()
                    .flat_map(|ex| {
                        let angle =
                            bridge::bridge_angle(ex, below, bridge_spacing).unwrap_or(default);
                        let family = LineFamily {
                            angle_rad: angle.to_radians(),
                            spacing_mm: bridge_spacing,
                            phase: 0.5,
                        };
                        fill_family(std::slice::from_ref(ex), family, true)
                    })
                    .collect();
                (lines, bridge_width)
            }
            SolidRole::Top => (
                pattern.fill(area, sp.top_solid_infill, index),
                params.top_solid_infill_width,
            ),
            SolidRole::InternalBridge => (pattern.fill(area, bridge_spacing, index), bridge_width),
            SolidRole::Bottom | SolidRole::Internal => (
                pattern.fill(area, sp.solid_infill, index),
                params.solid_infill_width,
            ),
        };
        if !lines.is_empty() {
            fills.push(Fill { lines, role, width });
        }
    }
    fills
}

/// Sparse infill of one layer: the configured pattern at `spacing / density`.
fn sparse_fill(
    skins: &SkinAreas,
    params: &RegionParams,
    index: usize,
    height: f64,
) -> Vec<Polyline> {
    let density = params.infill_density.min(1.0);
    if density <= 0.0 || skins.sparse.is_empty() {
        return Vec::new();
    }
    let pattern = infill::pattern(params.infill_pattern, params.infill_angle_deg);
    pattern.fill(
        &skins.sparse,
        params.spacings(height).infill / density,
        index,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::{points_length, square_island, total_length};

    fn cube_layers() -> Vec<Vec<ExPolygon>> {
        vec![vec![square_island(0.0, 0.0, 20.0)]; 10]
    }

    #[test]
    fn cube_gets_perimeters_solid_ends_sparse_middle_and_a_skirt() {
        let params = RegionParams {
            skirt_loops: 1,
            ..Default::default()
        };
        let regions = make_regions(&cube_layers(), &params);
        assert_eq!(regions.len(), 10);
        for r in &regions {
            assert_eq!(r.perimeters.len(), 2, "layer {}", r.index);
            let solid = (0..=2).contains(&r.index) || (7..=9).contains(&r.index);
            assert_eq!(!r.solid_infill.is_empty(), solid, "layer {}", r.index);
            assert_eq!(r.sparse_infill.is_empty(), solid, "layer {}", r.index);
            assert_eq!(r.skirt.len(), usize::from(r.index == 0));
        }
        assert_eq!(regions[0].solid_infill[0].role, SolidRole::Bottom);
        assert_eq!(regions[9].solid_infill[0].role, SolidRole::Top);
        assert_eq!(regions[5].skins.sparse.len(), 1);
        // Solid infill: length ≈ area / spacing (plus boundary connectors).
        let sp = params.spacings(0.2).solid_infill;
        let area: f64 = regions[0].infill_area.iter().map(ExPolygon::area_mm2).sum();
        let len: f64 = regions[0]
            .solid_infill
            .iter()
            .map(|f| total_length(&f.lines))
            .sum();
        assert!(
            len * sp / area > 0.95 && len * sp / area < 1.1,
            "{}",
            len * sp / area
        );
        // Sparse infill at 20 %, plus its connectors and anchors along the boundary.
        let sparse = total_length(&regions[5].sparse_infill) * sp / area;
        assert!((0.2..0.25).contains(&sparse), "{sparse}");
    }

    /// A thin wall shorter than a perimeter is wide (a sharp corner's tip past the external
    /// loop) is not printed by the classic generator, as PrusaSlicer's; a longer one is, and the
    /// variable generator keeps both.
    #[test]
    fn classic_thin_walls_shorter_than_a_perimeter_width_are_dropped() {
        let wall = |length: f64| Perimeters {
            thin_walls: vec![crate::region::test_util::rect_island(0.0, 0.0, length, 0.3)],
            ..Default::default()
        };
        let lengths = |generator, length| -> Vec<f64> {
            let params = RegionParams {
                perimeter_generator: generator,
                ..Default::default()
            };
            thick_lines(&wall(length), &params, 0.2)
                .iter()
                .map(|l| points_length(&l.points))
                .collect()
        };
        let width = RegionParams::default().perimeter_width;
        // 0.4 mm long: its axis is shorter than the 0.45 mm perimeter width.
        assert_eq!(lengths(PerimeterGenerator::Classic, 0.4), Vec::<f64>::new());
        let kept = lengths(PerimeterGenerator::Variable, 0.4);
        assert!(
            !kept.is_empty() && kept.iter().all(|&l| l < width),
            "{kept:?}"
        );
        let long = lengths(PerimeterGenerator::Classic, 3.0);
        assert!(long.iter().any(|&l| l > 2.5), "{long:?}");
    }

    #[test]
    fn narrow_strip_gets_one_loop_and_a_gap_fill_line_of_the_strip_width() {
        // 1.3 mm: one loop, then a 0.443 mm strip no second loop fits in (see perimeters).
        let params = RegionParams::default();
        let layers = vec![vec![crate::region::test_util::rect_island(0.0, 0.0, 20.0, 1.3)]; 5];
        let r = make_regions(&layers, &params);
        let half = params.spacings(0.2).perimeter / 2.0;
        let thickness = 1.3 - 2.0 * (0.225 + half);
        let gap_area = thickness * (20.0 - 2.0 * (0.225 + half));
        for layer in &r {
            assert_eq!(layer.perimeters.len(), 1);
            assert!(layer.solid_infill.is_empty() && layer.sparse_infill.is_empty());
            let filled: f64 = layer
                .gap_fill
                .iter()
                .flat_map(|g| g.points.windows(2).zip(&g.widths))
                .map(|(w, t)| {
                    let d = ((w[1].x - w[0].x) as f64).hypot((w[1].y - w[0].y) as f64) / 1e6;
                    d * t
                })
                .sum();
            assert!(
                (filled - gap_area).abs() < 0.03 * gap_area,
                "{filled} vs {gap_area}"
            );
            let long: Vec<f64> = layer
                .gap_fill
                .iter()
                .flat_map(|g| g.widths.clone())
                .collect();
            assert!(
                long.iter().any(|t| (t - thickness).abs() < 0.01),
                "{long:?}"
            );
        }
    }

    #[test]
    fn a_slab_over_two_legs_bridges_across_the_gap() {
        // Legs x ∈ [0, 5] and [15, 20] for layers 0–4, a 20 × 20 slab on layers 5–9.
        let mut layers = vec![
            vec![
                crate::region::test_util::rect_island(0.0, 0.0, 5.0, 20.0),
                crate::region::test_util::rect_island(15.0, 0.0, 20.0, 20.0),
            ];
            5
        ];
        layers.extend(vec![vec![square_island(0.0, 0.0, 20.0)]; 5]);
        let r = make_regions(&layers, &RegionParams::default());
        let bridge = r[5]
            .solid_infill
            .iter()
            .find(|f| f.role == SolidRole::Bridge)
            .expect("layer 5 bridges");
        assert_eq!(bridge.width, 0.4);
        // Lines run along x, from leg to leg: every long segment is horizontal.
        let mut spans = 0;
        for line in &bridge.lines {
            for w in line.points.windows(2) {
                let (dx, dy) = ((w[1].x - w[0].x) as f64, (w[1].y - w[0].y) as f64);
                if dx.hypot(dy) > 5e6 {
                    assert!(dy.abs() < 1e-3 * dx.abs(), "{:?}", w);
                    spans += 1;
                }
            }
        }
        // About 20 mm / 0.45 mm lines.
        assert!((35..=50).contains(&spans), "{spans} spans");
        // No bridge anywhere else.
        for (i, layer) in r.iter().enumerate().filter(|(i, _)| *i != 5) {
            assert!(layer.skins.bridge.is_empty(), "layer {i}");
        }
    }

    #[test]
    fn small_sparse_areas_are_filled_solid() {
        // An 8 mm square: its sparse area (≈ 6.2² = 38 mm²) is below 70 mm².
        let layers = vec![vec![square_island(0.0, 0.0, 8.0)]; 10];
        let r = make_regions(&layers, &RegionParams::default());
        assert!(r.iter().all(|l| l.sparse_infill.is_empty()));
        let off = RegionParams {
            solid_infill_below_area: 0.0,
            ..Default::default()
        };
        let r = make_regions(&layers, &off);
        assert!(!r[5].sparse_infill.is_empty());
        assert!(r[5].solid_infill.is_empty());
    }

    #[test]
    fn first_layer_and_top_widths_are_used() {
        let params = RegionParams {
            first_layer_width: 0.6,
            top_solid_infill_width: 0.4,
            skirt_loops: 1,
            ..Default::default()
        };
        let r = make_regions(&cube_layers(), &params);
        assert!(r[0].perimeters.iter().all(|l| l.width == 0.6));
        assert!(r[0].solid_infill.iter().all(|f| f.width == 0.6));
        assert_eq!((r[0].sparse_width, r[0].skirt_width), (0.6, 0.6));
        assert!(r[1].perimeters.iter().all(|l| l.width == 0.45));
        let top = &r[9].solid_infill[0];
        assert_eq!((top.role, top.width), (SolidRole::Top, 0.4));
        // Top lines are spaced for 0.4 mm: length ≈ area / spacing(0.4).
        let area: f64 = r[9].infill_area.iter().map(ExPolygon::area_mm2).sum();
        let ratio = total_length(&top.lines) * spacing(0.4, 0.2) / area;
        assert!(ratio > 0.95 && ratio < 1.1, "{ratio}");
    }

    #[test]
    fn output_does_not_depend_on_the_thread_count() -> Result<(), rayon::ThreadPoolBuildError> {
        let params = RegionParams {
            infill_pattern: InfillPatternKind::Triangles,
            skirt_loops: 1,
            ..Default::default()
        };
        let mut layers = cube_layers();
        layers.extend(vec![vec![square_island(5.0, 5.0, 8.0)]; 5]);
        let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build();
        let one = pool(1)?.install(|| make_regions(&layers, &params));
        let four = pool(4)?.install(|| make_regions(&layers, &params));
        assert_eq!(one, four);
        assert_eq!(one, make_regions(&layers, &params));
        Ok(())
    }

    #[test]
    fn heights_and_params_are_checked() {
        let layers = cube_layers();
        let params = RegionParams::default();
        assert_eq!(
            make_regions_with_heights(&layers, &[0.2; 3], &params),
            Err(RegionError::HeightCount {
                layers: 10,
                heights: 3
            })
        );
        let mut heights = vec![0.2; 10];
        heights[4] = f64::NAN;
        assert!(matches!(
            make_regions_with_heights(&layers, &heights, &params),
            Err(RegionError::BadHeight { index: 4, .. })
        ));
        let bad = RegionParams {
            infill_density: -1.0,
            ..Default::default()
        };
        assert!(matches!(
            make_regions_with_heights(&layers, &[0.2; 10], &bad),
            Err(RegionError::Params(p)) if p.len() == 1
        ));
        heights[4] = 0.2;
        heights[0] = 0.3;
        let ok = make_regions_with_heights(&layers, &heights, &params);
        assert!(matches!(&ok, Ok(r) if r[0].height == 0.3 && r[1].height == 0.2));
    }

    #[test]
    fn empty_input_and_empty_layers_are_fine() {
        let params = RegionParams::default();
        assert!(make_regions(&[], &params).is_empty());
        let mut layers = cube_layers();
        layers[4].clear();
        let r = make_regions(&layers, &params);
        assert!(r[4].perimeters.is_empty() && r[4].sparse_infill.is_empty());
        // Layers next to the gap are solid against it.
        assert!(
            r[5].solid_infill
                .iter()
                .any(|f| f.role == SolidRole::Bridge)
        );
        assert!(r[3].solid_infill.iter().any(|f| f.role == SolidRole::Top));
    }
}
