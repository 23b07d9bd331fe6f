//! The circuit planned on the host's layers: the electronics stage of conduit's own pipeline run
//! on the areas the host prints.
//!
//! Place in the pipeline: after [`super::layers`] and [`super::regions`], before
//! [`super::rewrite`]. Each host layer's islands ([`host_islands`]) and its z span stand in for a
//! sliced layer; [`plan_circuit`] places the circuit ([`place_circuit`]) and runs
//! [`object_stage`] on them, exactly as `conduit slice` does, and sorts what comes out by host
//! layer: the areas to cut (cavities and channels), the conductive traces printed at the layer's
//! end, and the part events due there.
//!
//! # Coordinates
//!
//! The host's G-code is in bed coordinates, and so is everything here. A placement with
//! `origin = "model"` gives bed coordinates directly (where the host put the object); with
//! `origin = "bbox_center"`, x and y are measured from the centre of the printed object's
//! bounding box (the union of every layer's islands) and z from the bed (z = 0), so the same
//! placement works wherever the host puts the object. All of a host's objects count as one
//! object (object 0).
//!
//! # Islands
//!
//! The printed region of a layer ([`printed_regions`]) has a hole between every two lines of
//! sparse infill. The electronics stage needs the object's cross-section, so [`host_islands`]
//! fills the holes of the printed region, except where the layer's external perimeter runs
//! around an empty area (a hole in the object). Files without feature comments have no external
//! perimeter to tell, and get every hole filled.

use crate::circuit::PlacedPart;
use crate::circuit::stage::{ObjectCuts, object_stage, place_circuit};
use crate::circuit::{Electronics, ElectronicsParams, ElectronicsReport};
use crate::geom::{BoundingBox, ExPolygon, FillRule, polygons_to_expolygons};
use crate::geom::{difference, intersection, scaled, union};
use crate::program::{Event, LayerExtras, Role, Toolpath};
use crate::region::cavity::Cavity;
use crate::slice::LayerZ;

use super::PostprocessError;
use super::layers::{ExtrusionPath, HostLayer, HostLayers};
use super::regions::{RegionParams, printed_regions};
use rayon::prelude::*;

/// Empty areas inside the external perimeter smaller than this are not holes of the object but
/// gaps between beads, mm².
const MIN_HOLE_AREA: f64 = 0.05;

/// What the circuit does to one host layer.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LayerPlan {
    /// The areas whose extrusion is removed: the cavities overlapping the layer and the layer's
    /// channels, united.
    pub cuts: Vec<ExPolygon>,
    /// The conductive paths printed after the layer's last extrusion, in print order.
    pub traces: Vec<Toolpath>,
    /// The part events after the traces: parts whose cavity is complete once this layer is.
    pub events: Vec<Event>,
}

/// The circuit planned on a host's layers.
#[derive(Debug, Clone, PartialEq)]
pub struct CircuitPlan {
    /// One entry per host layer, in the order of [`super::HostLayers::layers`].
    pub layers: Vec<LayerPlan>,
    /// The host layers' z spans.
    pub zs: Vec<LayerZ>,
    /// The part cavities.
    pub cavities: Vec<Cavity>,
    /// The parts, bed coordinates.
    pub parts: Vec<PlacedPart>,
    /// Parts, wires and routing totals.
    pub report: ElectronicsReport,
    /// The printed object's bounding box: x and y of the islands, z from 0 to the top layer.
    pub bbox: BoundingBox,
}

impl CircuitPlan {
    /// Total length of the conductive paths, mm.
    pub fn trace_length(&self) -> f64 {
        self.layers
            .iter()
            .flat_map(|l| &l.traces)
            .map(Toolpath::length)
            .sum()
    }

    /// Number of conductive paths.
    pub fn trace_count(&self) -> usize {
        self.layers.iter().map(|l| l.traces.len()).sum()
    }

    /// Number of part events.
    pub fn event_count(&self) -> usize {
        self.layers.iter().map(|l| l.events.len()).sum()
    }
}

/// Whether a host extrusion is part of the object: not a skirt, brim, custom start G-code, or a
/// support, or a feature conduit has no role for (wipe tower, ironing). Extrusions without any
/// feature name (files without comments) count.
pub fn is_object_path(path: &ExtrusionPath) -> bool {
    match path.role {
        Some(Role::Skirt | Role::Support | Role::SupportInterface | Role::Custom) => false,
        Some(_) => true,
        None => path.host_role.is_none(),
    }
}

/// The cross-section of the object in a layer: the printed region of its object paths
/// ([`is_object_path`]) with the gaps between beads filled, holes of the object kept (see the
/// [module docs](self#islands)).
pub fn host_islands(layer: &HostLayer, params: &RegionParams) -> Vec<ExPolygon> {
    let model: Vec<&ExtrusionPath> = layer.paths.iter().filter(|p| is_object_path(p)).collect();
    let printed = printed_regions(model.iter().copied(), params);
    if printed.is_empty() {
        return printed;
    }
    let contours: Vec<_> = printed.iter().map(|r| r.contour.clone()).collect();
    let filled = polygons_to_expolygons(&contours, FillRule::NonZero);
    let outer: Vec<&ExtrusionPath> = model
        .iter()
        .copied()
        .filter(|p| p.role == Some(Role::ExternalPerimeter))
        .collect();
    if outer.is_empty() {
        return filled;
    }
    let walls = printed_regions(outer, params);
    let mut empty: Vec<ExPolygon> = Vec::new();
    for hole in walls.iter().flat_map(|w| &w.holes) {
        let area = polygons_to_expolygons(std::slice::from_ref(hole), FillRule::NonZero);
        let material = intersection(&area, &printed);
        let inner: Vec<_> = material.iter().map(|m| m.contour.clone()).collect();
        let inner = polygons_to_expolygons(&inner, FillRule::NonZero);
        empty.extend(
            difference(&area, &inner)
                .into_iter()
                .filter(|e| e.area_mm2() >= MIN_HOLE_AREA),
        );
    }
    if empty.is_empty() {
        filled
    } else {
        difference(&filled, &empty)
    }
}

/// Places `electronics` in the host's print (its `layers`) and runs the electronics stage with
/// `params` on them (see the [module docs](self)).
///
/// # Errors
/// [`PostprocessError::NothingPrinted`] when no layer prints anything,
/// [`PostprocessError::LayersNotAscending`] when a layer is not above the one before it
/// (sequential printing of several objects), [`PostprocessError::Electronics`] when the
/// placement does not fit the circuit or the config has no conductive tool.
pub fn plan_circuit(
    layers: &HostLayers,
    electronics: &Electronics,
    params: &ElectronicsParams,
) -> Result<CircuitPlan, PostprocessError> {
    let layers = &layers.layers;
    let mut zs: Vec<LayerZ> = Vec::with_capacity(layers.len());
    for layer in layers {
        let bottom = zs.last().map_or(0.0, |b: &LayerZ| b.top);
        if layer.z <= bottom && layer.index > 0 {
            return Err(PostprocessError::LayersNotAscending {
                layer: layer.index,
                z: layer.z,
                below: bottom,
            });
        }
        // The host's height, unless it reaches below the layer underneath.
        let bottom = (layer.z - layer.height).max(bottom);
        zs.push(LayerZ {
            index: layer.index,
            bottom,
            top: layer.z,
            slice_z: (bottom + layer.z) / 2.0,
        });
    }
    let beads = RegionParams::default();
    let mut islands: Vec<Vec<ExPolygon>> =
        layers.par_iter().map(|l| host_islands(l, &beads)).collect();
    let bbox = islands_bbox(&islands, zs.last().map_or(0.0, |z| z.top))
        .ok_or(PostprocessError::NothingPrinted)?;
    let circuit = place_circuit(electronics, &[bbox], &[[0.0; 3]], params)?;
    let mut extras = LayerExtras::default();
    let mut report = ElectronicsReport::default();
    let ObjectCuts { cavities, channels } = object_stage(
        0,
        &mut islands,
        &zs,
        &circuit,
        params,
        &mut extras,
        &mut report,
    );
    drop(islands);

    let mut plans: Vec<LayerPlan> = zs
        .par_iter()
        .enumerate()
        .map(|(i, z)| {
            let mut cut: Vec<ExPolygon> = cavities
                .iter()
                .filter(|c| c.overlaps(z.bottom, z.top))
                .flat_map(|c| c.outline.iter().cloned())
                .collect();
            if let Some(ch) = channels.get(i) {
                cut.extend(ch.iter().cloned());
            }
            LayerPlan {
                cuts: if cut.is_empty() { cut } else { union(&cut) },
                ..LayerPlan::default()
            }
        })
        .collect();
    // The stage keys its extras by the layer's top on the nanometre grid.
    let layer_at = |key: i64| zs.iter().position(|z| scaled(z.top) == key);
    for (key, paths) in extras.paths_after {
        if let Some(i) = layer_at(key) {
            plans[i].traces.extend(paths);
        }
    }
    for (key, events) in extras.events_after {
        if let Some(i) = layer_at(key) {
            plans[i].events.extend(events);
        }
    }
    // Events at the start of layer i are written at the end of layer i − 1, after its traces.
    for (key, events) in extras.events_before {
        if let Some(i) = layer_at(key) {
            plans[i.saturating_sub(1)].events.extend(events);
        }
    }
    Ok(CircuitPlan {
        layers: plans,
        zs,
        cavities,
        parts: circuit.parts,
        report,
        bbox,
    })
}

/// The bounding box of every island, z from 0 to `top`; `None` when there are none.
fn islands_bbox(islands: &[Vec<ExPolygon>], top: f64) -> Option<BoundingBox> {
    let (mut min, mut max) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in islands.iter().flatten().flat_map(|r| &r.contour.points) {
        let (x, y) = p.to_mm();
        min = [min[0].min(x), min[1].min(y)];
        max = [max[0].max(x), max[1].max(y)];
    }
    (min[0] <= max[0]).then_some(BoundingBox {
        min: [min[0], min[1], 0.0],
        max: [max[0], max[1], top],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::postprocess::{LayerParams, detect_host, read_layers};

    fn layer(text: &str) -> HostLayer {
        let g = match conduit_gcode::parse(text.as_bytes()) {
            Ok(g) => g,
            Err(e) => panic!("{e}"),
        };
        let mut l = read_layers(&g, &detect_host(&g).markers, &LayerParams::default());
        l.layers.remove(0)
    }

    /// A square ring of two perimeters around `[x0, x1]²` with sparse infill lines inside, and
    /// (when `hole`) a square hole in the middle with its own external perimeter.
    fn ring_with_infill(hole: bool) -> String {
        let mut s =
            String::from(";LAYER_CHANGE\n;Z:0.2\n;HEIGHT:0.2\nG28\nM83\nG1 Z0.2\n;WIDTH:0.45\n");
        let square = |s: &mut String, a: f64, b: f64, role: &str| {
            s.push_str(&format!(";TYPE:{role}\nG1 X{a} Y{a}\n"));
            for (x, y) in [(b, a), (b, b), (a, b), (a, a)] {
                s.push_str(&format!("G1 X{x} Y{y} E1\n"));
            }
        };
        square(&mut s, 0.0, 20.0, "External perimeter");
        square(&mut s, 0.4, 19.6, "Perimeter");
        s.push_str(";TYPE:Internal infill\n");
        for k in 0..8 {
            let x = 2.0 + 2.25 * f64::from(k);
            if hole && (7.0..13.0).contains(&x) {
                for (y0, y1) in [(0.6, 6.6), (13.4, 19.4)] {
                    s.push_str(&format!("G1 X{x} Y{y0}\nG1 X{x} Y{y1} E1\n"));
                }
            } else {
                s.push_str(&format!("G1 X{x} Y0.6\nG1 X{x} Y19.4 E1\n"));
            }
        }
        if hole {
            square(&mut s, 7.0, 13.0, "External perimeter");
        }
        s
    }

    #[test]
    fn islands_fill_infill_gaps_and_keep_holes_of_the_object() {
        let params = RegionParams::default();
        let full = host_islands(&layer(&ring_with_infill(false)), &params);
        assert_eq!(full.len(), 1);
        assert!(full[0].holes.is_empty(), "{:?}", full[0].holes.len());
        // The 20 mm square grown by half a bead, round corners.
        let area = full[0].area_mm2();
        assert!((area - 20.45 * 20.45).abs() < 0.1, "{area}");
        // The printed region itself has a hole between every two infill lines.
        let printed = printed_regions(&layer(&ring_with_infill(false)).paths, &params);
        assert!(printed[0].holes.len() >= 8);

        let holed = host_islands(&layer(&ring_with_infill(true)), &params);
        assert_eq!(holed.len(), 1);
        assert_eq!(holed[0].holes.len(), 1);
        // The hole is the 6 mm square shrunk by half a bead.
        let hole = holed[0].holes[0].area_mm2().abs();
        assert!((hole - 5.55 * 5.55).abs() < 0.05, "{hole}");
    }

    #[test]
    fn skirts_and_unknown_features_are_not_the_object() {
        let l = layer(
            ";LAYER_CHANGE\n;Z:0.2\nG28\nG1 Z0.2\n;WIDTH:0.4\n;TYPE:Skirt/Brim\nG1 X50 E1\n\
             ;TYPE:Support material\nG1 X50 Y10 E2\n;TYPE:Perimeter\nG1 X0 Y10 E3\n",
        );
        let kept: Vec<bool> = l.paths.iter().map(is_object_path).collect();
        assert_eq!(kept, vec![false, false, true]);
    }
}
