//! Where a perimeter's bead hangs out over the layer below, and by how much: the overhang
//! zones of one layer.
//!
//! Place in the pipeline: regions stage, after the perimeters; the toolpaths stage cuts each
//! perimeter path where it enters or leaves a zone and gives every piece the speed, fan and role
//! of its overhang degree (`toolpaths::overhang`).
//!
//! A bead of width `w` whose centre lies at signed distance `d` outside the outline of the
//! layer below (negative inside) rests on it over `w/2 − d` of its width: its *overlap* is
//! `(w/2 − d) / w` (PrusaSlicer's measure of its dynamic overhang speeds: 100 % is a bead fully
//! on the layer below, 0 % one in the air). The points whose overlap is below `p` are the
//! points outside the outline below grown by `w (1 − p) − w/2`, so each threshold is one
//! offset of that outline and one difference. Zone `k` holds the bead centres with
//!
//! | zone | overlap below | offset of the outline below |
//! |---|---|---|
//! | 0 | 1 − [`SUPPORTED_TOLERANCE`] | `−w/2 + 0.05 w` |
//! | 1 | 75 % | `−w/4` |
//! | 2 | 50 % | `0` |
//! | 3 | 25 % | `+w/4` |
//! | 4 | (bridging) | `+nozzle/2`, PrusaSlicer's `overhangs` test |
//!
//! so the zones are nested and a point's *degree* is the number of zones it lies in: 0 for a
//! bead on the layer below, 5 for one more than half a nozzle beyond its edge, which
//! PrusaSlicer prints as an "Overhang perimeter" (a round thread at bridge speed, with the
//! bridge fan). The tolerance keeps a vertical wall, whose external bead's face lies exactly on
//! the outline below, out of zone 0 whatever the rounding of offsets and simplification.
//!
//! The zones are cut to where the layer's beads can be (its islands shrunk by half a bead), so
//! a layer that does not grow past the one below has no zones at all, and most layers cost one
//! offset of each and one difference.

use crate::geom::{ExPolygon, Join, difference, offset};

/// How much of a bead's width may hang out and still count as fully on the layer below: 5 %
/// (0.02 mm of a 0.45 mm bead, more than the slicing resolution, less than the lean of a
/// wall sloping 6° from the vertical at 0.2 mm layers).
pub const SUPPORTED_TOLERANCE: f64 = 0.05;

/// The overlap (fraction of the bead's width resting on the layer below) below which a bead
/// centre lies in zones 0 to 3; zone 4 is the bridging test (see the module docs).
pub const OVERLAPS: [f64; 4] = [1.0 - SUPPORTED_TOLERANCE, 0.75, 0.5, 0.25];

/// Number of zones, and so the highest overhang degree.
pub const ZONES: usize = 5;

/// How far inside the islands' half-bead inset a bead centre may lie and still be looked at,
/// mm: covers the rounding of the loops' own offsets, well below `SUPPORTED_TOLERANCE · w`.
const CENTRE_MARGIN_MM: f64 = 0.005;

/// The overhang zones of the beads of one width on one layer.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OverhangZones {
    /// The bead width the zones are for, mm.
    pub width: f64,
    /// Zone `k` (see the module docs), nested: `zones[k + 1]` lies inside `zones[k]`. Empty
    /// when no bead of this width overhangs.
    pub zones: Vec<Vec<ExPolygon>>,
}

impl OverhangZones {
    /// Whether no bead of this width overhangs.
    pub fn is_empty(&self) -> bool {
        self.zones.iter().all(Vec::is_empty)
    }
}

/// The zones of beads `width` mm wide on a layer with `islands` over a layer with `below`
/// (both as the perimeters were made from them), for a `nozzle` mm nozzle. `None` when no bead
/// of that width hangs out (every zone empty).
pub fn overhang_zones(
    islands: &[ExPolygon],
    below: &[ExPolygon],
    width: f64,
    nozzle: f64,
) -> Option<OverhangZones> {
    if islands.is_empty() || width.is_nan() || width <= 0.0 {
        return None;
    }
    let join = Join::Miter(3.0);
    let centres = offset(islands, -width / 2.0 + CENTRE_MARGIN_MM, join);
    if centres.is_empty() {
        return None;
    }
    let mut grow: Vec<f64> = OVERLAPS
        .iter()
        .map(|p| width * (1.0 - p) - width / 2.0)
        .collect();
    // The bridging test is PrusaSlicer's; on a bead wider than two nozzles it would lie inside
    // zone 3, so it is kept outside.
    grow.push((nozzle / 2.0).max(width / 4.0));
    let mut zones = Vec::with_capacity(ZONES);
    for (k, r) in grow.into_iter().enumerate() {
        let zone = difference(&centres, &offset(below, r, join));
        if zone.is_empty() {
            if k == 0 {
                return None;
            }
            zones.resize(ZONES, Vec::new());
            break;
        }
        zones.push(zone);
    }
    Some(OverhangZones { width, zones })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::{rect_island, square_island};

    #[test]
    fn a_wall_on_the_same_outline_has_no_zones() {
        let island = vec![square_island(0.0, 0.0, 20.0)];
        assert_eq!(overhang_zones(&island, &island, 0.45, 0.4), None);
        // Nor a layer inside the one below.
        let smaller = vec![square_island(1.0, 1.0, 18.0)];
        assert_eq!(overhang_zones(&smaller, &island, 0.45, 0.4), None);
    }

    #[test]
    fn a_step_out_gives_nested_zones_at_the_overlap_offsets() -> Result<(), String> {
        // The layer reaches 1 mm further in +x than the one below (x = 10 there).
        let below = vec![rect_island(0.0, 0.0, 10.0, 10.0)];
        let here = vec![rect_island(0.0, 0.0, 11.0, 10.0)];
        let z = overhang_zones(&here, &below, 0.45, 0.4).ok_or("zones expected")?;
        assert_eq!(z.zones.len(), ZONES);
        // Each zone spans x from its offset of the outline below to the bead centres' edge
        // (11 − w/2 + margin).
        let right = 11.0 - 0.225 + CENTRE_MARGIN_MM;
        for (k, left) in [10.0 - 0.2025, 10.0 - 0.1125, 10.0, 10.1125, 10.2]
            .into_iter()
            .enumerate()
        {
            let area: f64 = z.zones[k].iter().map(ExPolygon::area_mm2).sum();
            // Height: the centres' band (10 − 2 · (w/2 − margin)), minus nothing.
            let h = 10.0 - 2.0 * (0.225 - CENTRE_MARGIN_MM);
            let want = (right - left) * h;
            assert!((area - want).abs() < 0.02, "zone {k}: {area} vs {want}");
        }
        Ok(())
    }
}
