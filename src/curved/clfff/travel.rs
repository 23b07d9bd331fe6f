//! Travels between curved paths: retract, lift above the highest material under the travel
//! plus a clearance, move, come down, unretract.
//!
//! Place in the pipeline: step 6 of [`super::plan`], after the curved layers are toolpaths and
//! before the sections become Programs.
//!
//! # How the writer is made to do it
//!
//! The G-code writer starts every Program layer by retracting (when the way to the layer's
//! first path is long) and moving z alone to the layer's z, then travels to the first path,
//! hopping when the travel is long and coming down vertically after it (with the minimum hop
//! of [`super::sections::writer_params`]), and un-retracts. So the curved paths are cut into
//! groups wherever the travel from one path to the next is longer than
//! `printer.retract_before_travel` (3D), and each group becomes a Program layer whose z is the
//! group's safe travel height: the highest material under the straight xy line of the travel
//! into it (sampled every [`SAMPLE_MM`], both ends included), the travel's own end heights,
//! plus `curved.travel_clearance`. Short travels inside a group (between neighbouring raster
//! lines) go straight, as on planar layers; with [`Grouper::check_short`] (the sandwich, whose
//! planar core layers lie below the bottom skin near the rim) a short travel whose straight
//! line would pass more than [`BLOCKED_TOLERANCE_MM`] under the material starts a group too.

use crate::geom::Point3;
use crate::program::{Layer, LayerItem, Toolpath};

/// Spacing of the samples along a travel, mm.
pub const SAMPLE_MM: f64 = 0.5;

/// How far material may stand above the straight line of a short travel before the travel
/// is lifted ([`Grouper::check_short`]), mm: more than the sag of a straight hop between
/// neighbouring raster lines on a curved layer, less than any bead.
pub const BLOCKED_TOLERANCE_MM: f64 = 0.01;

/// Whether the straight 3D line from `from` to `to` passes more than
/// [`BLOCKED_TOLERANCE_MM`] under `material` (sampled every [`SAMPLE_MM`], ends excluded).
pub fn blocked(from: Point3, to: Point3, material: &dyn Fn(f64, f64) -> f64) -> bool {
    let len = (to.x - from.x).hypot(to.y - from.y);
    let n = (len / SAMPLE_MM).ceil().max(1.0) as usize;
    (1..n).any(|i| {
        let t = i as f64 / n as f64;
        let p = from + (to - from) * t;
        material(p.x, p.y) > p.z + BLOCKED_TOLERANCE_MM
    })
}

/// The safe height of a travel from `from` to `to`: the highest of `material` under the xy
/// line between them (every [`SAMPLE_MM`] and at both ends) and the two end heights, plus
/// `clearance`.
pub fn safe_height(
    from: Point3,
    to: Point3,
    material: &dyn Fn(f64, f64) -> f64,
    clearance: f64,
) -> f64 {
    let len = (to.x - from.x).hypot(to.y - from.y);
    let n = (len / SAMPLE_MM).ceil().max(1.0) as usize;
    let mut top = from.z.max(to.z);
    for i in 0..=n {
        let t = i as f64 / n as f64;
        let (x, y) = (from.x + (to.x - from.x) * t, from.y + (to.y - from.y) * t);
        top = top.max(material(x, y));
    }
    top + clearance
}

/// Cuts a stream of curved paths and comments into Program layers at the long travels (see the
/// module docs).
#[derive(Debug, Clone)]
pub struct Grouper {
    /// Travels longer than this (3D, mm) start a new group.
    pub long_travel: f64,
    /// Clearance above the material, mm.
    pub clearance: f64,
    /// Nominal layer height written on the groups' Program layers, mm.
    pub height: f64,
    /// Whether a short travel that would pass under material starts a group ([`blocked`]).
    /// Default false.
    pub check_short: bool,
    pos: Option<Point3>,
    pending: Vec<LayerItem>,
    layers: Vec<Layer>,
}

impl Grouper {
    /// A grouper starting with the nozzle at `pos` (`None`: unknown).
    pub fn new(long_travel: f64, clearance: f64, height: f64, pos: Option<Point3>) -> Self {
        Self {
            long_travel,
            clearance,
            height,
            check_short: false,
            pos,
            pending: Vec::new(),
            layers: Vec::new(),
        }
    }

    /// Adds a comment (or another event) before the next path.
    pub fn event(&mut self, item: LayerItem) {
        self.pending.push(item);
    }

    /// Adds a path; `material(x, y)` is the highest material at (x, y) when it is printed, and
    /// `first_z` (when given) forces a new group whose travel height is at least that (for the
    /// first path of a section, whose travel may come from anywhere).
    pub fn path(
        &mut self,
        path: Toolpath,
        material: &dyn Fn(f64, f64) -> f64,
        first_z: Option<f64>,
    ) {
        let Some(&start) = path.points.first() else {
            return;
        };
        let end = path.end().copied().unwrap_or(start);
        let new_group = match (self.pos, first_z, self.layers.is_empty()) {
            (_, Some(_), _) | (None, _, _) | (_, _, true) => true,
            (Some(p), None, false) => {
                (start - p).norm() > self.long_travel
                    || (self.check_short && blocked(p, start, material))
            }
        };
        if new_group {
            let from = self.pos.unwrap_or(start);
            let mut z = safe_height(from, start, material, self.clearance);
            if let Some(f) = first_z {
                z = z.max(f + self.clearance);
            }
            self.layers.push(Layer {
                index: self.layers.len(),
                z,
                height: self.height,
                items: Vec::new(),
            });
        }
        if let Some(layer) = self.layers.last_mut() {
            layer.items.append(&mut self.pending);
            layer.items.push(LayerItem::Path(path));
        }
        self.pos = Some(end);
    }

    /// Where the nozzle is after the last path.
    pub fn position(&self) -> Option<Point3> {
        self.pos
    }

    /// The groups as Program layers (events after the last path are kept in the last one).
    pub fn finish(mut self) -> Vec<Layer> {
        if let Some(layer) = self.layers.last_mut() {
            layer.items.append(&mut self.pending);
        }
        self.layers
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::Role;

    fn line(a: (f64, f64, f64), b: (f64, f64, f64)) -> Toolpath {
        Toolpath {
            points: vec![Point3::new(a.0, a.1, a.2), Point3::new(b.0, b.1, b.2)],
            closed: false,
            role: Role::SolidInfill,
            tool: 0,
            width: 0.45,
            height: 0.2,
            speed: 40.0,
            segments: None,
            tool_axis: None,
        }
    }

    #[test]
    fn a_travel_over_a_peak_lifts_above_the_peak() {
        // A dome peaking at x = 10 (z = 5), flanks at z = 1.
        let dome = |x: f64, _y: f64| 5.0 - 0.4 * (x - 10.0).abs();
        let z = safe_height(
            Point3::new(0.0, 0.0, 1.0),
            Point3::new(20.0, 0.0, 1.0),
            &dome,
            1.0,
        );
        assert!((z - 6.0).abs() < 1e-12, "{z}");
        let mut g = Grouper::new(2.0, 1.0, 0.2, Some(Point3::new(0.0, 0.0, 1.0)));
        g.path(line((0.0, 0.0, 1.0), (1.0, 0.0, 1.4)), &dome, None);
        // Short travel: same group.
        g.path(line((1.0, 0.4, 1.4), (0.0, 0.0, 1.0)), &dome, None);
        // Long travel over the peak: a new group at the peak plus clearance.
        g.path(line((20.0, 0.0, 1.0), (19.0, 0.0, 1.4)), &dome, None);
        let layers = g.finish();
        assert_eq!(layers.len(), 2);
        assert_eq!(layers[0].paths().count(), 2);
        assert!((layers[1].z - 6.0).abs() < 1e-12);
    }

    #[test]
    fn a_short_hop_under_a_wall_is_lifted_when_checked() {
        // Material at z = 2 between x = 0.4 and x = 0.6; both paths at z = 1.
        let wall = |x: f64, _y: f64| if (0.4..=0.6).contains(&x) { 2.0 } else { 1.0 };
        for check in [false, true] {
            let mut g = Grouper::new(2.0, 1.0, 0.2, None);
            g.check_short = check;
            g.path(line((0.0, 0.0, 1.0), (0.0, 1.0, 1.0)), &wall, None);
            g.path(line((1.0, 1.0, 1.0), (1.0, 0.0, 1.0)), &wall, None);
            let layers = g.finish();
            assert_eq!(layers.len(), if check { 2 } else { 1 });
            if check {
                assert!((layers[1].z - 3.0).abs() < 1e-12, "{}", layers[1].z);
            }
        }
        assert!(!blocked(
            Point3::new(0.0, 0.0, 1.0),
            Point3::new(1.0, 0.0, 1.0),
            &|_, _| 1.0
        ));
    }
}
