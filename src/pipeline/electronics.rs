//! The electronics stage of the pipeline: parts placed in the object, cavities carved for them,
//! wires routed through the layers and carved as channels, traces and part events for the
//! Program, and the pick-and-place records.
//!
//! Place in the pipeline: after slicing, before the regions stage, which then sees the islands
//! with cavities and channels removed (so perimeters run around them and skins close them).

use std::collections::BTreeMap;

use serde::Serialize;

use crate::circuit::{Circuit, PlacedPart, Placement, PlacingMethod, place, rubberbands};
use crate::config::Config;
use crate::geom::{BoundingBox, ExPolygon, Point2, Point3, Polygon, scaled};
use crate::program::{Event, LayerExtras, Role, Toolpath};
use crate::region::cavity::{Cavity, carve_cavities, carve_channels};
use crate::route::{RouteLayer, RouteParams, Wire, route};
use crate::slice::LayerZ;

/// A circuit and where its parts go: what `--circuit` and `--placement` give.
#[derive(Debug, Clone, PartialEq)]
pub struct Electronics {
    /// Parts, pads and nets.
    pub circuit: Circuit,
    /// Part poses (model coordinates), methods and net waypoints.
    pub placement: Placement,
}

/// How one wire (a connection of a net) was routed, for the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NetRoute {
    /// Net name.
    pub net: String,
    /// Whether a route was found.
    pub routed: bool,
    /// Length of the route, mm (0 when not routed).
    pub length: f64,
    /// Straight 3D distance between the ends, mm: no route is shorter.
    pub lower_bound: f64,
    /// Number of layer changes.
    pub layer_changes: usize,
    /// Crossings of the route with the layers' outer perimeters.
    pub perimeter_crossings: usize,
}

/// What the electronics stage did, for the report.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ElectronicsReport {
    /// Parts placed, with their bed position and the layer whose start places them.
    pub parts: Vec<PartReport>,
    /// One entry per wire, nets in name order.
    pub wires: Vec<NetRoute>,
    /// Net pins on parts the placement does not list (`net`, `part.pad`).
    pub unplaced_pins: Vec<(String, String)>,
    /// Wires routed.
    pub routed: usize,
    /// Wires not routed.
    pub unrouted: usize,
    /// Total routed length, mm.
    pub total_length: f64,
    /// Sum of the lower bounds of the routed wires, mm.
    pub total_lower_bound: f64,
}

/// One placed part in the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartReport {
    /// Reference designator.
    pub name: String,
    /// `auto`, `manual` or `none`.
    pub method: &'static str,
    /// Seating-plane centre on the bed, mm.
    pub position: [f64; 3],
    /// Rotation about +Z, degrees.
    pub rotation_deg: f64,
    /// Print height after which the part is placed (top of its cavity), mm.
    pub placed_after_z: f64,
}

/// Why the electronics stage failed.
#[derive(Debug, thiserror::Error)]
pub enum ElectronicsError {
    /// The placement does not fit the circuit or the scene.
    #[error("{0}")]
    Placement(#[from] crate::circuit::PlacementError),
    /// `route.conductive_tool` names a tool the config does not define.
    ///
    /// How to fix: add a `[tools.N]` table for the conductive tool (`kind = "paste"` for a
    /// dispenser) or set `route.conductive_tool` to an existing tool.
    #[error("route.conductive_tool = {tool}, but the config defines {tools} tool(s)")]
    NoConductiveTool {
        /// The configured tool.
        tool: usize,
        /// How many tools the config has.
        tools: usize,
    },
}

/// The circuit placed on the bed: its parts and the wires to route, each with the scene object
/// it belongs to.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlacedCircuit {
    /// Parts in placement order, bed coordinates.
    pub parts: Vec<PlacedPart>,
    /// (object, wire): the wires of every net, bed coordinates; a wire belongs to the object of
    /// its first pin's part (object 0 for waypoint-only wires).
    pub wires: Vec<(usize, Wire)>,
    /// Net pins on parts the placement does not list (`net`, `part.pad`).
    pub unplaced: Vec<(String, String)>,
}

/// [`place`] and [`rubberbands`] in model coordinates (`bboxes` of the scene's objects), then
/// everything moved by its object's bed offset.
pub fn place_circuit(
    e: &Electronics,
    bboxes: &[BoundingBox],
    offsets: &[[f64; 3]],
    cfg: &Config,
) -> Result<PlacedCircuit, ElectronicsError> {
    let placement = e.placement.to_model(bboxes)?;
    if cfg.route.conductive_tool >= cfg.tools.len() {
        return Err(ElectronicsError::NoConductiveTool {
            tool: cfg.route.conductive_tool,
            tools: cfg.tools.len(),
        });
    }
    let mut parts = place(&e.circuit, &placement, bboxes)?;
    let bands = rubberbands(&e.circuit, &placement, &parts)?;
    let offset = |object: usize| offsets.get(object).copied().unwrap_or([0.0; 3]);
    let object_of = |pin: &Option<crate::circuit::PinRef>| {
        pin.as_ref()
            .and_then(|pin| parts.iter().find(|p| p.name == pin.part))
            .map(|p| p.object)
    };
    let wires = bands
        .bands
        .iter()
        .map(|b| {
            let object = object_of(&b.from_pin)
                .or_else(|| object_of(&b.to_pin))
                .unwrap_or(0);
            let d = offset(object);
            let shift = |p: Point3| Point3::new(p.x + d[0], p.y + d[1], p.z + d[2]);
            (
                object,
                Wire {
                    net: b.net.clone(),
                    from: shift(b.from),
                    to: shift(b.to),
                },
            )
        })
        .collect();
    for part in &mut parts {
        translate_part(part, offset(part.object));
    }
    let unplaced = bands
        .unplaced
        .iter()
        .map(|(net, pin)| (net.clone(), pin.to_string()))
        .collect();
    Ok(PlacedCircuit {
        parts,
        wires,
        unplaced,
    })
}

fn translate_part(part: &mut PlacedPart, d: [f64; 3]) {
    let shift3 = |p: &mut Point3| {
        p.x += d[0];
        p.y += d[1];
        p.z += d[2];
    };
    let (dx, dy) = (scaled(d[0]), scaled(d[1]));
    let shift2 = |poly: &mut Polygon| {
        for p in &mut poly.points {
            *p = Point2::new(p.x + dx, p.y + dy);
        }
    };
    shift3(&mut part.position);
    shift2(&mut part.footprint);
    for pad in &mut part.pads {
        shift3(&mut pad.centre);
        shift2(&mut pad.outline);
    }
}

/// The router's parameters from `[route]` and the perimeter width of `[slice]`.
pub fn route_params(cfg: &Config) -> RouteParams {
    let r = &cfg.route;
    RouteParams {
        perimeters: r.perimeters,
        perimeter_width: cfg.slice.region.perimeter_width,
        conductive_width: r.conductive_width,
        channel_extra: r.channel_extra,
        perimeter_weights: r.perimeter_weights.clone(),
        base_weight: r.base_weight,
        outside_weight: r.outside_weight,
        grid_step: r.grid_step,
        interlayer_overlap: r.interlayer_overlap,
        layer_change_penalty: r.layer_change_penalty,
        ..RouteParams::default()
    }
}

/// What the electronics stage cut from one object's layers.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ObjectCuts {
    /// The part cavities.
    pub cavities: Vec<Cavity>,
    /// Per layer, the wire channels.
    pub channels: Vec<Vec<ExPolygon>>,
}

/// Everything the electronics stage adds to one object: its islands are carved in place; the
/// extras get the traces, drops and part events, the report its entries; the cuts are
/// returned for drawing.
pub fn object_stage(
    object: usize,
    islands: &mut [Vec<ExPolygon>],
    zs: &[LayerZ],
    circuit: &PlacedCircuit,
    cfg: &Config,
    extras: &mut LayerExtras,
    report: &mut ElectronicsReport,
) -> ObjectCuts {
    let parts = &circuit.parts;
    let spans: Vec<(f64, f64)> = zs.iter().map(|z| (z.bottom, z.top)).collect();
    let mine: Vec<(usize, &PlacedPart)> = parts
        .iter()
        .enumerate()
        .filter(|(_, p)| p.object == object)
        .collect();
    let cavities: Vec<Cavity> = mine
        .iter()
        .map(|(_, p)| {
            Cavity::around(
                &p.footprint,
                cfg.route.cavity_offset,
                p.position.z,
                p.body_height,
            )
        })
        .collect();
    carve_cavities(islands, &spans, &cavities);

    let wires: Vec<Wire> = circuit
        .wires
        .iter()
        .filter(|(o, _)| *o == object)
        .map(|(_, w)| w.clone())
        .collect();
    if object == 0 {
        report
            .unplaced_pins
            .extend(circuit.unplaced.iter().cloned());
    }
    let layers: Vec<RouteLayer> = zs
        .iter()
        .zip(islands.iter())
        .map(|(z, isl)| RouteLayer {
            z: z.top,
            height: z.height(),
            islands: isl.clone(),
        })
        .collect();
    let result = route(&layers, &wires, &route_params(cfg));
    carve_channels(islands, &result.channels);

    // Traces: one path per wire and layer, longest first on each layer.
    let tool = cfg.route.conductive_tool;
    let speed = cfg.slice.conductive_speed;
    let width = cfg.route.conductive_width;
    let mut per_layer: BTreeMap<usize, Vec<Toolpath>> = BTreeMap::new();
    for w in &result.wires {
        report.wires.push(NetRoute {
            net: w.net.clone(),
            routed: w.routed,
            length: if w.routed { w.length } else { 0.0 },
            lower_bound: w.lower_bound,
            layer_changes: w.layer_changes,
            perimeter_crossings: w.perimeter_crossings,
        });
        if !w.routed {
            continue;
        }
        for (layer, points) in &w.segments {
            let Some(z) = zs.get(*layer) else { continue };
            if points.len() < 2 {
                continue;
            }
            let height = if cfg.route.conductive_height > 0.0 {
                cfg.route.conductive_height
            } else {
                z.height()
            };
            per_layer.entry(*layer).or_default().push(Toolpath {
                points: points
                    .iter()
                    .map(|p| Point3::new(p.x, p.y, z.top))
                    .collect(),
                closed: false,
                role: Role::ConductiveTrace,
                tool,
                width,
                height,
                speed,
                tool_axis: None,
            });
        }
    }
    if cfg.route.pad_drops {
        for (_, part) in &mine {
            for pad in &part.pads {
                let Some(layer) = floor_layer(zs, pad.centre.z) else {
                    continue;
                };
                let z = zs[layer].top;
                per_layer.entry(layer).or_default().push(drop_path(
                    pad.centre,
                    z,
                    width,
                    zs[layer].height(),
                    tool,
                    speed,
                ));
            }
        }
    }
    for (layer, mut paths) in per_layer {
        paths.sort_by(|a, b| b.length().total_cmp(&a.length()));
        extras
            .paths_after
            .entry(scaled(zs[layer].top))
            .or_default()
            .extend(paths);
    }

    // Part events: at the start of the first layer above the cavity; parts standing above the
    // last layer are placed after it.
    for (index, part) in mine {
        let top = part.position.z + part.body_height;
        let event = part_event(index + 1, part);
        let report_entry = |after: f64| PartReport {
            name: part.name.clone(),
            method: method_name(part.method),
            position: [part.position.x, part.position.y, part.position.z],
            rotation_deg: part.rotation_deg,
            placed_after_z: after,
        };
        match zs.iter().position(|z| z.bottom >= top - 1e-6) {
            Some(layer) => {
                report.parts.push(report_entry(zs[layer].bottom));
                extras
                    .events_before
                    .entry(scaled(zs[layer].top))
                    .or_default()
                    .push(event);
            }
            None => {
                let Some(last) = zs.last() else { continue };
                report.parts.push(report_entry(last.top));
                extras
                    .events_after
                    .entry(scaled(last.top))
                    .or_default()
                    .push(event);
            }
        }
    }
    report.routed = report.wires.iter().filter(|w| w.routed).count();
    report.unrouted = report.wires.len() - report.routed;
    report.total_length = report.wires.iter().map(|w| w.length).sum();
    report.total_lower_bound = report
        .wires
        .iter()
        .filter(|w| w.routed)
        .map(|w| w.lower_bound)
        .sum();
    ObjectCuts {
        cavities,
        channels: result.channels,
    }
}

/// The layer whose top is the seating plane `z` (within half a layer), where pad drops go.
fn floor_layer(zs: &[LayerZ], z: f64) -> Option<usize> {
    zs.iter()
        .enumerate()
        .filter(|(_, l)| (l.top - z).abs() <= l.height() / 2.0 + 1e-9)
        .min_by(|a, b| (a.1.top - z).abs().total_cmp(&(b.1.top - z).abs()))
        .map(|(i, _)| i)
}

/// A drop: a closed circle of one trace width around `centre` at height `z`.
fn drop_path(centre: Point3, z: f64, width: f64, height: f64, tool: usize, speed: f64) -> Toolpath {
    let r = width / 2.0;
    let points = (0..12)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::TAU / 12.0;
            Point3::new(centre.x + r * a.cos(), centre.y + r * a.sin(), z)
        })
        .collect();
    Toolpath {
        points,
        closed: true,
        role: Role::ConductiveDrop,
        tool,
        width,
        height,
        speed,
        tool_axis: None,
    }
}

fn method_name(m: PlacingMethod) -> &'static str {
    match m {
        PlacingMethod::Auto => "auto",
        PlacingMethod::Manual => "manual",
        PlacingMethod::None => "none",
    }
}

/// The event that places `part` (`id` is its 1-based number in placement order).
fn part_event(id: usize, part: &PlacedPart) -> Event {
    match part.method {
        PlacingMethod::Auto => Event::PickAndPlace {
            id,
            part: part.name.clone(),
            x: part.position.x,
            y: part.position.y,
            z: part.position.z,
            rotation_deg: part.rotation_deg,
        },
        PlacingMethod::Manual => Event::ManualInsertPause {
            part: part.name.clone(),
            message: format!("Insert {}", part.name),
        },
        PlacingMethod::None => Event::Comment(format!(
            "part {} is not placed by the machine (method none)",
            part.name
        )),
    }
}

/// Pick-and-place records of the placed parts (bed coordinates), for `.pos` and OpenPnP files.
pub fn pnp_records(circuit: &Circuit, parts: &[PlacedPart]) -> Vec<conduit_pnp::PlacementRecord> {
    parts
        .iter()
        .map(|p| {
            let part = circuit.part(&p.name);
            conduit_pnp::PlacementRecord {
                reference: p.name.clone(),
                value: part.and_then(|c| c.value.clone()).unwrap_or_default(),
                package: part.map(|c| c.package.clone()).unwrap_or_default(),
                x: p.position.x,
                y: p.position.y,
                z: p.position.z,
                rotation_deg: p.rotation_deg,
                side: if p.mirror {
                    conduit_pnp::Side::Bottom
                } else {
                    conduit_pnp::Side::Top
                },
            }
        })
        .collect()
}
