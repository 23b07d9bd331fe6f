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
//! 1. [`perimeters`]: loops by inward offsets of each island, and the infill area inside them;
//! 2. [`skins`]: the infill area split into top, bottom, internal solid and sparse areas by
//!    comparing neighbouring layers;
//! 3. [`infill`]: solid areas filled with [`infill::Rectilinear`] at 100 %, sparse areas with the
//!    configured pattern at `spacing / density`; plus the [`skirt`] on the first layer.
//!
//! Spacings follow the flow model documented in [`params`].

pub mod infill;
pub mod params;
pub mod perimeters;
pub mod simplify;
pub mod skins;
pub mod skirt;
#[cfg(test)]
mod test_util;

pub use params::{InfillPatternKind, ParamError, RegionParams, Spacings, spacing};
pub use perimeters::{PerimeterLoop, Perimeters, make_perimeters};
pub use skins::{SkinAreas, SolidRole, detect_skins};
pub use skirt::make_skirt;

use crate::geom::{ExPolygon, Polygon, Polyline};
use infill::{InfillPattern, Rectilinear};
use rayon::prelude::*;

/// Solid infill lines of one role.
#[derive(Debug, Clone, PartialEq)]
pub struct Fill {
    /// Centrelines, each an open polyline to extrude in order.
    pub lines: Vec<Polyline>,
    /// What the lines are for.
    pub role: SolidRole,
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
    /// Solid infill in print order: bottom, internal, top; roles without area are left out.
    pub solid_infill: Vec<Fill>,
    /// Sparse infill centrelines.
    pub sparse_infill: Vec<Polyline>,
    /// Skirt loops, outermost first; only on layer 0.
    pub skirt: Vec<Polygon>,
    /// Where infill centrelines may go (inside the innermost perimeters), for routing and
    /// cavities.
    pub infill_area: Vec<ExPolygon>,
    /// The infill area split by role.
    pub skins: SkinAreas,
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
        .map(|(islands, &h)| make_perimeters(islands, params, h))
        .collect();
    let infill_areas: Vec<Vec<ExPolygon>> =
        perimeters.iter().map(|p| p.infill_area.clone()).collect();
    let skins = detect_skins(layers, &infill_areas, heights, params);
    let solid_pattern = Rectilinear::new(params.infill_angle_deg);
    let sparse_pattern = infill::pattern(params.infill_pattern, params.infill_angle_deg);
    let skirt = match (layers.first(), heights.first()) {
        (Some(first), Some(&h)) => make_skirt(first, params, h),
        _ => Vec::new(),
    };
    perimeters
        .into_par_iter()
        .zip(skins)
        .zip(heights)
        .enumerate()
        .map(|(index, ((per, skins), &height))| {
            let sp = params.spacings(height);
            let solid_infill = skins
                .solid()
                .into_iter()
                .filter(|(_, area)| !area.is_empty())
                .map(|(role, area)| Fill {
                    lines: solid_pattern.fill(area, sp.solid_infill, index),
                    role,
                })
                .filter(|f| !f.lines.is_empty())
                .collect();
            let density = params.infill_density.min(1.0);
            let sparse_infill = if density > 0.0 && !skins.sparse.is_empty() {
                sparse_pattern.fill(&skins.sparse, sp.infill / density, index)
            } else {
                Vec::new()
            };
            LayerRegions {
                index,
                height,
                perimeters: per.loops,
                solid_infill,
                sparse_infill,
                skirt: if index == 0 {
                    skirt.clone()
                } else {
                    Vec::new()
                },
                infill_area: per.infill_area,
                skins,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::{square_island, total_length};

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
        // Sparse infill at 20 %.
        let sparse = total_length(&regions[5].sparse_infill) * sp / area;
        assert!((sparse - 0.2).abs() < 0.04, "{sparse}");
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
                .any(|f| f.role == SolidRole::Bottom)
        );
        assert!(r[3].solid_infill.iter().any(|f| f.role == SolidRole::Top));
    }
}
