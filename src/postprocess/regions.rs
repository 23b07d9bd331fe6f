//! The printed regions of a host layer: the area its extrusions cover, as polygons with holes.
//!
//! Place in the pipeline: after [`super::layers`]; in post-processing mode these regions stand
//! in for the sliced layer regions of conduit's own pipeline, so the electronics stages (cavities,
//! channels, routing on deflated perimeters) can run on another slicer's print.
//!
//! Each [`ExtrusionPath`] is drawn as the bead it lays down seen from above: its polyline
//! stroked at its width with round joins and round ends ([`crate::geom::stroke`]); the beads are
//! united. A closed perimeter loop of side `L` and width `w` thus covers
//! `(L + w)² − (L − w)² − (4 − π)·(w/2)²` (a square ring with rounded outer corners).

use std::collections::BTreeMap;

use super::layers::ExtrusionPath;
use crate::geom::{Cap, ExPolygon, Join, Point2, Polyline, scaled, stroke, union};

/// How beads are drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegionParams {
    /// How far the chords of round joins and ends may stray from the true arc, mm. Default
    /// 0.005 (5 µm, far below a nozzle's resolution).
    pub arc_deviation: f64,
}

impl Default for RegionParams {
    fn default() -> Self {
        Self {
            arc_deviation: 0.005,
        }
    }
}

/// The union of the beads of `paths` (see the [module docs](self)), in canonical order. Pass a
/// layer's paths, or a filtered subset (one tool, one role).
///
/// ```
/// use conduit::postprocess::{LayerParams, RegionParams, detect_host, printed_regions, read_layers};
/// let g = conduit_gcode::parse(b";LAYER_CHANGE\n;Z:0.2\nG28\nG1 Z0.2\n;WIDTH:0.5\nG1 X10 E1\n")?;
/// let layers = read_layers(&g, &detect_host(&g).markers, &LayerParams::default());
/// let regions = printed_regions(&layers.layers[0].paths, &RegionParams::default());
/// let area: f64 = regions.iter().map(|r| r.area_mm2()).sum();
/// // A 10 mm stroke 0.5 mm wide with round ends: 10·0.5 + π·0.25² (less the chords' 0.5 %).
/// assert!((area - (5.0 + std::f64::consts::PI * 0.0625)).abs() < 0.01);
/// # Ok::<(), conduit_gcode::GcodeError>(())
/// ```
pub fn printed_regions<'a>(
    paths: impl IntoIterator<Item = &'a ExtrusionPath>,
    params: &RegionParams,
) -> Vec<ExPolygon> {
    // Paths of one width are stroked together; widths are compared on the nanometre grid.
    let mut by_width: BTreeMap<i64, Vec<Polyline>> = BTreeMap::new();
    for path in paths {
        let polyline = Polyline {
            points: path
                .points
                .iter()
                .map(|p| Point2::from_mm(p.x, p.y))
                .collect(),
        };
        by_width
            .entry(scaled(path.width))
            .or_default()
            .push(polyline);
    }
    let join = Join::Round(params.arc_deviation);
    let cap = Cap::Round(params.arc_deviation);
    let mut beads: Vec<ExPolygon> = Vec::new();
    let groups = by_width.len();
    for (width, lines) in by_width {
        let stroked = stroke(&lines, crate::geom::unscaled(width), join, cap);
        if groups == 1 {
            return stroked;
        }
        beads.extend(stroked);
    }
    union(&beads)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point3;
    use crate::postprocess::WidthSource;
    use std::f64::consts::PI;

    fn path(points: &[(f64, f64)], width: f64) -> ExtrusionPath {
        ExtrusionPath {
            tool: 0,
            role: None,
            host_role: None,
            width,
            width_source: WidthSource::Comment,
            points: points
                .iter()
                .map(|&(x, y)| Point3::new(x, y, 0.2))
                .collect(),
            moves: Vec::new(),
        }
    }

    fn area(regions: &[ExPolygon]) -> f64 {
        regions.iter().map(ExPolygon::area_mm2).sum()
    }

    #[test]
    fn square_perimeter_loop_has_the_analytic_area() {
        let (side, width) = (10.0, 0.45);
        let square = [
            (0.0, 0.0),
            (side, 0.0),
            (side, side),
            (0.0, side),
            (0.0, 0.0),
        ];
        let regions = printed_regions(&[path(&square, width)], &RegionParams::default());
        let r = width / 2.0;
        let expected = (side + width).powi(2) - (side - width).powi(2) - (4.0 - PI) * r * r;
        assert_eq!(regions.len(), 1);
        assert_eq!(regions[0].holes.len(), 1, "a loop encloses a hole");
        // Chords inside the round corners lose at most deviation × arc length.
        let tolerance = 0.005 * 2.0 * PI * r + 1e-9;
        assert!(
            (area(&regions) - expected).abs() <= tolerance,
            "{} vs {expected}",
            area(&regions)
        );
        // The hole is the square inset by half the width.
        let hole = regions[0].holes[0].area_mm2().abs();
        assert!((hole - (side - width).powi(2)).abs() < 1e-9, "{hole}");
    }

    #[test]
    fn beads_of_different_widths_unite() {
        let a = path(&[(0.0, 0.0), (10.0, 0.0)], 0.4);
        let b = path(&[(0.0, 0.0), (0.0, 10.0)], 0.6);
        let far = path(&[(20.0, 20.0), (30.0, 20.0)], 0.5);
        let regions = printed_regions([&a, &b, &far], &RegionParams::default());
        assert_eq!(regions.len(), 2);
        let single = |p: &ExtrusionPath| area(&printed_regions([p], &RegionParams::default()));
        let total = area(&regions);
        assert!(total < single(&a) + single(&b) + single(&far));
        // Round ends of radius 0.25: chords lose at most 0.005 mm × the π·0.5 mm of arc.
        let far_area = area(&regions[1..]);
        assert!(
            (far_area - (5.0 + PI * 0.0625)).abs() <= 0.005 * PI * 0.5,
            "{far_area}"
        );
        assert!(printed_regions(&[], &RegionParams::default()).is_empty());
        assert!(printed_regions(&[path(&[(1.0, 1.0)], 0.4)], &RegionParams::default()).is_empty());
    }
}
