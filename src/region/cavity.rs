//! Cavities for parts and channels for wires, cut from the sliced islands.
//!
//! Place in the pipeline: between slicing and the rest of the regions stage. A part's cavity is
//! its footprint grown by `cavity_offset`, removed from every layer that overlaps the part's
//! height span; a wire's channel is removed from the layer it is printed on. Because the skins
//! stage compares each layer's islands with its neighbours', the layer under a cavity gets a
//! top skin (the floor the part sits on) and the layer over it a bridge (the lid), with no
//! special case here.

use crate::geom::{ExPolygon, Join, Polygon, difference, offset};

/// A pocket to cut from the layers.
#[derive(Debug, Clone, PartialEq)]
pub struct Cavity {
    /// What is removed, already grown by the cavity offset.
    pub outline: Vec<ExPolygon>,
    /// Seating plane (bottom of the pocket), mm.
    pub bottom: f64,
    /// Top of the pocket, mm.
    pub top: f64,
}

/// Layers nearer than this (mm) to a cavity's bottom or top do not count as overlapping it, so a
/// layer ending exactly on the seating plane stays whole (it is the floor).
const TOUCH_MM: f64 = 1e-6;

impl Cavity {
    /// The cavity of a part whose footprint (pads and body outline, counter-clockwise) is
    /// `footprint`, grown by `offset_mm`, spanning `bottom` to `bottom + height`.
    pub fn around(footprint: &Polygon, offset_mm: f64, bottom: f64, height: f64) -> Self {
        let base = [ExPolygon {
            contour: footprint.clone(),
            holes: vec![],
        }];
        let outline = if offset_mm > 0.0 {
            offset(&base, offset_mm, Join::Miter(2.0))
        } else {
            base.to_vec()
        };
        Self {
            outline,
            bottom,
            top: bottom + height.max(0.0),
        }
    }

    /// Whether the layer spanning `bottom`–`top` (mm) overlaps the cavity.
    pub fn overlaps(&self, bottom: f64, top: f64) -> bool {
        top > self.bottom + TOUCH_MM && bottom < self.top - TOUCH_MM
    }
}

/// `layers[i]` (islands of the layer spanning `spans[i]` = (bottom, top), mm) with every
/// overlapping cavity removed. Returns how many layers changed.
pub fn carve_cavities(
    layers: &mut [Vec<ExPolygon>],
    spans: &[(f64, f64)],
    cavities: &[Cavity],
) -> usize {
    let mut changed = 0;
    for (islands, &(bottom, top)) in layers.iter_mut().zip(spans) {
        let cut: Vec<ExPolygon> = cavities
            .iter()
            .filter(|c| c.overlaps(bottom, top))
            .flat_map(|c| c.outline.iter().cloned())
            .collect();
        if !cut.is_empty() && !islands.is_empty() {
            *islands = difference(islands, &cut);
            changed += 1;
        }
    }
    changed
}

/// `layers[i]` with `channels[i]` removed (missing entries remove nothing).
pub fn carve_channels(layers: &mut [Vec<ExPolygon>], channels: &[Vec<ExPolygon>]) {
    for (islands, cut) in layers.iter_mut().zip(channels) {
        if !cut.is_empty() && !islands.is_empty() {
            *islands = difference(islands, cut);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::{rect, square_island, total_area};
    use crate::region::{RegionParams, SolidRole, make_regions};

    #[test]
    fn cavity_is_cut_from_the_overlapping_layers_only_and_gets_a_floor_and_a_lid() {
        // 10 layers of 0.2 mm; a 4 × 4 mm part seated at z = 0.8, 0.6 mm high: layers 4–6.
        let mut layers = vec![vec![square_island(0.0, 0.0, 20.0)]; 10];
        let spans: Vec<(f64, f64)> = (0..10)
            .map(|i| (0.2 * i as f64, 0.2 * (i + 1) as f64))
            .collect();
        let cavity = Cavity::around(&rect(8.0, 8.0, 12.0, 12.0), 0.5, 0.8, 0.6);
        assert!((total_area(&cavity.outline) - 25.0).abs() < 1e-6);
        assert_eq!(carve_cavities(&mut layers, &spans, &[cavity]), 3);
        for (i, l) in layers.iter().enumerate() {
            let want = if (4..=6).contains(&i) {
                400.0 - 25.0
            } else {
                400.0
            };
            assert!((total_area(l) - want).abs() < 1e-6, "layer {i}");
        }
        // The regions: the layer under the pocket has a top skin where the pocket is, the
        // layer over it bridges the pocket.
        let params = RegionParams {
            solid_infill_below_area: 0.0,
            ..Default::default()
        };
        let r = make_regions(&layers, &params);
        let centre = crate::geom::Point2::from_mm(10.0, 10.0);
        let at = |area: &[ExPolygon]| crate::region::test_util::contains(area, centre);
        assert!(at(&r[3].skins.top), "floor");
        assert!(at(&r[7].skins.bridge), "lid");
        assert!(r[3].solid_infill.iter().any(|f| f.role == SolidRole::Top));
        assert!(
            r[7].solid_infill
                .iter()
                .any(|f| f.role == SolidRole::Bridge)
        );
        assert!(r[5].infill_area.iter().all(|ex| !ex.holes.is_empty()));
    }

    #[test]
    fn channels_are_cut_from_their_layer() {
        let mut layers = vec![vec![square_island(0.0, 0.0, 20.0)]; 3];
        let channel = vec![ExPolygon {
            contour: rect(2.0, 9.5, 18.0, 10.5),
            holes: vec![],
        }];
        carve_channels(&mut layers, &[vec![], channel]);
        assert!((total_area(&layers[0]) - 400.0).abs() < 1e-6);
        assert!((total_area(&layers[1]) - 384.0).abs() < 1e-6);
        assert!((total_area(&layers[2]) - 400.0).abs() < 1e-6);
    }
}
