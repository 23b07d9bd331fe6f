//! The electronics stage of the pipeline: parts placed in the object, cavities carved for them,
//! wires routed through the layers and carved as channels, traces and part events for the
//! Program, and the pick-and-place records.
//!
//! Place in the pipeline: after slicing, before the regions stage, which then sees the islands
//! with cavities and channels removed (so perimeters run around them and skins close them).

use std::collections::BTreeMap;

use serde::Serialize;

use crate::circuit::{Circuit, PlacedPart, Placement, PlacingMethod, place, rubberbands};
use crate::geom::{BoundingBox, ExPolygon, Point2, Point3, Polygon, scaled};
use crate::program::{Event, LayerExtras, Role, Toolpath};
use crate::region::cavity::{Cavity, carve_cavities, carve_channels};
use crate::route::{
    NearPad, PadCopper, RoundLog, RouteLayer, RouteParams, RouteResult, Unrouted, Wire, WireRoute,
    min_trace_spacing, route,
};
use crate::slice::LayerZ;

/// What the electronics stage is configured with: the `[route]` settings, the widths and speed
/// of the conductive tool's traces and the perimeter width of the layers they run through.
/// Built by the walk from the config (`crate::config::Config::electronics_params`).
#[derive(Debug, Clone, PartialEq)]
pub struct ElectronicsParams {
    /// The router's parameters (`[route]` and the perimeter width of `[slice]`).
    pub route: RouteParams,
    /// Tool that prints the conductive traces and pad drops (`route.conductive_tool`).
    pub conductive_tool: usize,
    /// How many tools the machine has: the conductive tool must be one of them.
    pub tool_count: usize,
    /// Height of a conductive trace, mm; 0 = the layer's height (`route.conductive_height`).
    pub conductive_height: f64,
    /// Feed of the conductive traces, mm/s (`slice.conductive_speed`).
    pub conductive_speed: f64,
    /// How far a part's cavity reaches beyond its pads and body, mm (`route.cavity_offset`).
    pub cavity_offset: f64,
    /// Whether every pad gets a conductive drop (`route.pad_drops`).
    pub pad_drops: bool,
    /// Diameter of the contact pad at a terminal waypoint, mm; 0 for none
    /// (`route.terminal_pad`).
    pub terminal_pad: f64,
}

/// How the reason of a wire stopped by the time limit starts (see [`crate::route::Unrouted::TimeLimit`]).
const TIME_LIMIT_REASON: &str = "time limit reached";

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
    /// The start pin, `PART.PAD` (or `waypoint`).
    pub from: String,
    /// The end pin, `PART.PAD` (or `waypoint`).
    pub to: String,
    /// Whether a route was found.
    pub routed: bool,
    /// Length of the route, mm (0 when not routed).
    pub length: f64,
    /// Straight 3D distance between the route's ends (the two pins, or the pin and the point
    /// where it [`joins`](NetRoute::joins) another trace), mm: no route is shorter.
    pub lower_bound: f64,
    /// Number of layer changes.
    pub layer_changes: usize,
    /// Crossings of the route with the layers' outer perimeters.
    pub perimeter_crossings: usize,
    /// Where the route ends when not on a pad: on the trace of this other wire of its net
    /// (`FROM-TO` pins), as a T joint, since that trace already reaches the pin. `None` when
    /// it runs pin to pin.
    pub joins: Option<String>,
    /// Why the wire was not routed ("no path within the detour limit (route.max_detour)",
    /// "time limit reached (route.time_limit = 180 s)", ...); `None` when it was.
    pub reason: Option<String>,
    /// What stands in the way of a wire not routed: other nets' traces on its best way
    /// (`trace of net GND (U1.3 to U1.5)`) and other nets' pads closer to its own than two
    /// traces can run (`pad U1.7 0.80 mm from U1.6`). Empty when it was routed.
    pub blocked_by: Vec<String>,
    /// What would help a wire not routed: a trace width, more room between the parts, more
    /// layers, a longer detour or time. `None` when it was routed.
    pub help: Option<String>,
}

/// How the routing of a job went, for the report.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RoutingSummary {
    /// Rip-up and reroute rounds run (the most of any object).
    pub rounds: usize,
    /// Negotiated-congestion rounds run (the most of any object; 0 with `route.strategy =
    /// "ordered"`).
    pub negotiation_rounds: usize,
    /// Wires still in conflict with another net's trace when negotiation stopped, routed again
    /// in order (every object).
    pub negotiation_conflicts: usize,
    /// Wall time spent routing, seconds (every object).
    pub wall_seconds: f64,
    /// Whether `route.time_limit` stopped routing before it was done.
    pub time_limit_reached: bool,
    /// Where routing stood after each pass and round (`first-pass`, `negotiation`, `settle`,
    /// `rip-up`), object by object: wires routed, unrouted and in conflict.
    pub progress: Vec<RoutingLine>,
}

/// One line of [`RoutingSummary::progress`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RoutingLine {
    /// The object (index in the scene) whose wires these are.
    pub object: usize,
    /// Where its routing stood.
    #[serde(flatten)]
    pub at: RoundLog,
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
    /// Design problems found before routing, one line each (pads of different nets closer
    /// than two traces can pass).
    pub warnings: Vec<String>,
    /// Parts that cannot be built in as placed, one line each: a footprint reaching beyond
    /// the solid at its seating plane, a part above the object, two parts' footprints
    /// overlapping. Each makes the job fail (see [`ElectronicsReport::failures`]).
    pub part_problems: Vec<String>,
    /// The terminals: waypoints only one wire of their net reaches, each with a contact pad.
    pub terminals: Vec<TerminalReport>,
    /// Rounds, time and whether the time limit was reached.
    pub routing: RoutingSummary,
}

/// A terminal in the report: where a battery, a connector or a wire is attached.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TerminalReport {
    /// Net name.
    pub net: String,
    /// The waypoint's name.
    pub name: String,
    /// Where it is on the bed, mm: the centre of its contact pad, on the layer top nearest
    /// the waypoint's z.
    pub position: [f64; 3],
    /// Diameter of its contact pad, mm (0: none printed).
    pub pad_diameter: f64,
}

impl ElectronicsReport {
    /// Why the circuit was not built as asked, one line each: the placement places no part,
    /// a part problem, a wire not routed (with the reason when it is the time limit). Empty
    /// when every part sits inside the solid and every wire is routed.
    pub fn failures(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.parts.is_empty() {
            out.push("the placement places no part of the circuit".to_owned());
        }
        out.extend(self.part_problems.iter().cloned());
        out.extend(self.wires.iter().filter(|w| !w.routed).map(|w| {
            let why = w
                .reason
                .as_deref()
                .filter(|r| r.starts_with(TIME_LIMIT_REASON))
                .or(w.help.as_deref())
                .map(|r| format!(": {r}"))
                .unwrap_or_default();
            format!(
                "net {} could not be routed ({} to {}){why}",
                w.net, w.from, w.to
            )
        }));
        out
    }
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
    #[error(transparent)]
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
    /// The wires of every net, bed coordinates.
    pub wires: Vec<CircuitWire>,
    /// Net pins on parts the placement does not list (`net`, `part.pad`).
    pub unplaced: Vec<(String, String)>,
    /// Waypoints only one wire of their net reaches, bed coordinates.
    pub terminals: Vec<Terminal>,
    /// Parts the placement lists but does not place ([`Placement::skipped`]).
    pub skipped: Vec<String>,
}

/// A waypoint only one wire of its net reaches: the trace ends there, in a contact pad.
#[derive(Debug, Clone, PartialEq)]
pub struct Terminal {
    /// Net name.
    pub net: String,
    /// The waypoint's name.
    pub name: String,
    /// Its position, bed coordinates.
    pub at: Point3,
    /// The scene object it is in.
    pub object: usize,
}

/// One wire to route, with the object it runs in and what it joins.
#[derive(Debug, Clone, PartialEq)]
pub struct CircuitWire {
    /// Scene object: the object of its first pin's part (object 0 for waypoint-only wires).
    pub object: usize,
    /// The object of its second pin's part when that is another object: a trace is printed
    /// inside one object, so such a wire is reported unrouted with a warning.
    pub other_object: Option<usize>,
    /// The rubberband, bed coordinates.
    pub wire: Wire,
    /// The start pin as `PART.PAD`, or `waypoint`.
    pub from: String,
    /// The end pin as `PART.PAD`, or `waypoint`.
    pub to: String,
}

/// [`place`] and [`rubberbands`] in model coordinates (`bboxes` of the scene's objects), then
/// everything moved by its object's bed offset.
pub fn place_circuit(
    e: &Electronics,
    bboxes: &[BoundingBox],
    offsets: &[[f64; 3]],
    params: &ElectronicsParams,
) -> Result<PlacedCircuit, ElectronicsError> {
    let placement = e.placement.to_model(bboxes)?;
    if params.conductive_tool >= params.tool_count {
        return Err(ElectronicsError::NoConductiveTool {
            tool: params.conductive_tool,
            tools: params.tool_count,
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
            let other_object = object_of(&b.to_pin).filter(|&o| o != object);
            let d = offset(object);
            let shift = |p: Point3| Point3::new(p.x + d[0], p.y + d[1], p.z + d[2]);
            let label = |pin: &Option<crate::circuit::PinRef>| {
                pin.as_ref()
                    .map_or_else(|| "waypoint".to_owned(), ToString::to_string)
            };
            CircuitWire {
                object,
                other_object,
                wire: Wire {
                    net: b.net.clone(),
                    from: shift(b.from),
                    to: shift(b.to),
                },
                from: label(&b.from_pin),
                to: label(&b.to_pin),
            }
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
    let terminals = terminals(&placement, &offset);
    Ok(PlacedCircuit {
        parts,
        wires,
        unplaced,
        terminals,
        skipped: e.placement.skipped.clone(),
    })
}

/// The waypoints of `placement` (model coordinates) that exactly one wire end names, moved by
/// their object's bed offset.
fn terminals(placement: &Placement, offset: &impl Fn(usize) -> [f64; 3]) -> Vec<Terminal> {
    let mut out = Vec::new();
    for net in &placement.nets {
        for w in &net.waypoints {
            let ends = net
                .wires
                .iter()
                .flatten()
                .filter(|e| matches!(e, crate::circuit::placement::Endpoint::Waypoint(n) if *n == w.name))
                .count();
            if ends == 1 {
                let d = offset(w.object);
                out.push(Terminal {
                    net: net.name.clone(),
                    name: w.name.clone(),
                    at: Point3::new(w.x + d[0], w.y + d[1], w.z + d[2]),
                    object: w.object,
                });
            }
        }
    }
    out
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
    params: &ElectronicsParams,
    extras: &mut LayerExtras,
    report: &mut ElectronicsReport,
) -> ObjectCuts {
    let mine: Vec<(usize, &PlacedPart)> = circuit
        .parts
        .iter()
        .enumerate()
        .filter(|(_, p)| p.object == object)
        .collect();
    report.part_problems.extend(super::fit::part_problems(
        &mine.iter().map(|(_, p)| *p).collect::<Vec<_>>(),
        islands,
        zs,
    ));
    let cavities = carve_part_cavities(&mine, islands, zs, params.cavity_offset);
    let (mine_wires, between): (Vec<&CircuitWire>, Vec<&CircuitWire>) = circuit
        .wires
        .iter()
        .filter(|w| w.object == object)
        .partition(|w| w.other_object.is_none());
    report_between_objects(&between, object, report);
    if object == 0 {
        report
            .unplaced_pins
            .extend(circuit.unplaced.iter().cloned());
        report.warnings.extend(circuit.skipped.iter().cloned());
    }
    let terminals: Vec<&Terminal> = circuit
        .terminals
        .iter()
        .filter(|t| t.object == object)
        .collect();
    let terminal_copper: Vec<PadCopper> = terminals
        .iter()
        .filter(|_| params.terminal_pad > 0.0)
        .map(|t| PadCopper::round(Some(&t.net), t.at, params.terminal_pad))
        .collect();
    let (result, pad_names) = route_object(
        &mine,
        &mine_wires,
        &terminal_copper,
        islands,
        zs,
        &params.route,
        report,
    );
    let style = TraceStyle::of(params);
    report
        .routing
        .progress
        .extend(result.log.iter().map(|&at| RoutingLine { object, at }));
    let mut per_layer = trace_paths(
        &result,
        &mine_wires,
        &pad_names,
        &params.route,
        zs,
        style,
        report,
    );
    if params.pad_drops {
        add_pad_drops(&mine, zs, style, &mut per_layer);
    }
    add_terminal_pads(
        &terminals,
        zs,
        style,
        params.terminal_pad,
        &mut per_layer,
        report,
    );
    add_traces(per_layer, zs, extras);
    add_part_events(&mine, zs, extras, report);
    total_up(report);
    ObjectCuts {
        cavities,
        channels: result.channels,
    }
}

/// How the conductive tool prints the traces and the pad drops.
#[derive(Debug, Clone, Copy)]
struct TraceStyle {
    /// The conductive tool.
    tool: usize,
    /// Feed, mm/s.
    speed: f64,
    /// Trace width, mm.
    width: f64,
    /// Trace height, mm; 0 = the layer's height (pad drops are always a layer high).
    height: f64,
}

impl TraceStyle {
    /// The style of the stage's parameters.
    fn of(params: &ElectronicsParams) -> Self {
        Self {
            tool: params.conductive_tool,
            speed: params.conductive_speed,
            width: params.route.conductive_width,
            height: params.conductive_height,
        }
    }
}

/// The cavities of the object's parts (`mine`, with their placement indices), carved from its
/// islands.
fn carve_part_cavities(
    mine: &[(usize, &PlacedPart)],
    islands: &mut [Vec<ExPolygon>],
    zs: &[LayerZ],
    cavity_offset: f64,
) -> Vec<Cavity> {
    let spans: Vec<(f64, f64)> = zs.iter().map(|z| (z.bottom, z.top)).collect();
    let cavities: Vec<Cavity> = mine
        .iter()
        .map(|(_, p)| Cavity::around(&p.footprint, cavity_offset, p.position.z, p.body_height))
        .collect();
    carve_cavities(islands, &spans, &cavities);
    cavities
}

/// Reports the wires between parts on two objects: a wire there has no material to run in, so
/// it gets a warning and an unrouted entry.
fn report_between_objects(between: &[&CircuitWire], object: usize, report: &mut ElectronicsReport) {
    for w in between {
        report.warnings.push(format!(
            "net {} joins {} on object {} and {} on object {}: a trace cannot leave its \
             object, so this wire is not routed (join the objects, or wire it by hand)",
            w.wire.net,
            w.from,
            object,
            w.to,
            w.other_object.unwrap_or(object)
        ));
        report.wires.push(NetRoute {
            net: w.wire.net.clone(),
            from: w.from.clone(),
            to: w.to.clone(),
            routed: false,
            length: 0.0,
            lower_bound: (w.wire.to - w.wire.from).norm(),
            layer_changes: 0,
            perimeter_crossings: 0,
            joins: None,
            reason: Some("a trace cannot leave its object".to_owned()),
            blocked_by: Vec::new(),
            help: Some("join the objects, or wire it by hand".to_owned()),
        });
    }
}

/// Routes the object's wires through its layers (the islands with the cavities carved) around
/// its parts' pads, after warning about pads too close for two traces, and carves the
/// channels from the islands. Returns the routes and the names of the pads routed round
/// (`PART.PAD`, or `terminal of net N`), in the router's order.
fn route_object(
    mine: &[(usize, &PlacedPart)],
    mine_wires: &[&CircuitWire],
    terminal_copper: &[PadCopper],
    islands: &mut [Vec<ExPolygon>],
    zs: &[LayerZ],
    params: &RouteParams,
    report: &mut ElectronicsReport,
) -> (RouteResult, Vec<String>) {
    let wires: Vec<Wire> = mine_wires.iter().map(|w| w.wire.clone()).collect();
    let layers: Vec<RouteLayer> = zs
        .iter()
        .zip(islands.iter())
        .map(|(z, isl)| RouteLayer {
            z: z.top,
            height: z.height(),
            islands: isl.clone(),
        })
        .collect();
    let pads: Vec<PadCopper> = mine
        .iter()
        .flat_map(|(_, p)| &p.pads)
        .map(|pad| PadCopper {
            net: pad.net.clone(),
            z: pad.centre.z,
            outline: pad.outline.clone(),
        })
        .chain(terminal_copper.iter().cloned())
        .collect();
    let pad_names: Vec<String> = mine
        .iter()
        .flat_map(|(_, p)| p.pads.iter().map(|pad| format!("{}.{}", p.name, pad.name)))
        .chain(
            terminal_copper
                .iter()
                .map(|t| format!("terminal of net {}", t.net.as_deref().unwrap_or("-"))),
        )
        .collect();
    report
        .warnings
        .extend(mine.iter().filter_map(|(_, p)| pitch_warning(p, params)));
    let clock = std::time::Instant::now();
    let result = route(&layers, &wires, &pads, params);
    let summary = &mut report.routing;
    summary.rounds = summary.rounds.max(result.rounds);
    summary.negotiation_rounds = summary.negotiation_rounds.max(result.negotiation_rounds);
    summary.negotiation_conflicts += result.negotiation_conflicts;
    summary.wall_seconds += clock.elapsed().as_secs_f64();
    summary.time_limit_reached |= result.time_limit_reached;
    carve_channels(islands, &result.channels);
    (result, pad_names)
}

/// What helps a wire whose way is longer than the detour limit allows.
fn detour_help(params: &RouteParams) -> String {
    format!(
        "its way is longer than route.max_detour = {} allows: raise it, or place its parts \
         closer",
        params.max_detour
    )
}

/// What blocks the unrouted wire `w` (pins `ends`) and what would help: its report entry's
/// `blocked_by` and `help`, from the router's [`Blockage`](crate::route::Blockage) (or, where the
/// deadline left no time to look, from its reason alone).
fn unrouted_explanation(
    w: &WireRoute,
    ends: &CircuitWire,
    result: &RouteResult,
    mine_wires: &[&CircuitWire],
    pad_names: &[String],
    params: &RouteParams,
) -> (Vec<String>, String) {
    if matches!(w.reason, Some(Unrouted::TimeLimit(_))) {
        let help = format!(
            "route.time_limit (now {} s) stopped routing before this wire: raise it",
            params.time_limit
        );
        return (Vec::new(), help);
    }
    let Some(b) = &w.blockage else {
        let help = match w.reason {
            Some(Unrouted::Detour) => detour_help(params),
            Some(Unrouted::NoLayer) => "no layer of the object holds its pads".to_owned(),
            _ => format!(
                "route.time_limit (now {} s) left no time to find out what blocks it: \
                 raise it",
                params.time_limit
            ),
        };
        return (Vec::new(), help);
    };
    let pins = |k: usize| {
        mine_wires
            .get(k)
            .map_or_else(String::new, |w| format!("{} to {}", w.from, w.to))
    };
    let mut blocked_by: Vec<String> = b
        .traces
        .iter()
        .filter_map(|&k| {
            let other = result.wires.get(k)?;
            Some(format!("trace of net {} ({})", other.net, pins(k)))
        })
        .collect();
    let name = |k: usize| pad_names.get(k).map_or("?", String::as_str);
    let end = |near: &NearPad| if near.near_to { &ends.to } else { &ends.from };
    blocked_by.extend(
        b.pads
            .iter()
            .map(|n| format!("pad {} {:.2} mm from {}", name(n.pad), n.distance, end(n))),
    );
    let help = if let Some(near) = b.pads.first() {
        format!(
            "pads {} and {} are {:.2} mm apart, closer than two traces can run ({:.2} mm): \
             a route.conductive_width of {:.2} mm fits, or more room between the pads",
            end(near),
            name(near.pad),
            near.distance,
            min_trace_spacing(params),
            fitting_width(near.distance, params)
        )
    } else if !b.traces.is_empty() {
        let mut nets: Vec<&str> = Vec::new();
        for net in b
            .traces
            .iter()
            .filter_map(|&k| result.wires.get(k).map(|o| o.net.as_str()))
        {
            if !nets.contains(&net) {
                nets.push(net);
            }
        }
        format!(
            "the traces of {} take its way: more room between the parts (conduit place \
             --scale), more layers to pass them (route.layer_span = {}), or \
             route.strategy = \"negotiated\"",
            nets.join(", "),
            params.layer_span + 1
        )
    } else if b.way_without_traces {
        detour_help(params)
    } else {
        "no way through the material even without other traces: the parts are walled off \
         or too far apart (route.max_detour), or the material is too thin for a channel \
         (route.conductive_width, route.perimeters)"
            .to_owned()
    };
    (blocked_by, help)
}

/// Reports every routed (or unrouted) wire and returns the traces: one path per routed wire
/// and layer, by layer index.
fn trace_paths(
    result: &RouteResult,
    mine_wires: &[&CircuitWire],
    pad_names: &[String],
    params: &RouteParams,
    zs: &[LayerZ],
    style: TraceStyle,
    report: &mut ElectronicsReport,
) -> BTreeMap<usize, Vec<Toolpath>> {
    let mut per_layer: BTreeMap<usize, Vec<Toolpath>> = BTreeMap::new();
    for (w, ends) in result.wires.iter().zip(mine_wires) {
        let (blocked_by, help) = if w.routed {
            (Vec::new(), None)
        } else {
            let (blocked_by, help) =
                unrouted_explanation(w, ends, result, mine_wires, pad_names, params);
            (blocked_by, Some(help))
        };
        report.wires.push(NetRoute {
            net: w.net.clone(),
            from: ends.from.clone(),
            to: ends.to.clone(),
            routed: w.routed,
            length: if w.routed { w.length } else { 0.0 },
            lower_bound: w.lower_bound,
            layer_changes: w.layer_changes,
            perimeter_crossings: w.perimeter_crossings,
            joins: w
                .ends_on_wire
                .and_then(|k| mine_wires.get(k))
                .map(|j| format!("{}-{}", j.from, j.to)),
            reason: w.reason.map(|r| r.to_string()),
            blocked_by,
            help,
        });
        if !w.routed {
            continue;
        }
        for (layer, points) in &w.segments {
            let Some(z) = zs.get(*layer) else { continue };
            if points.len() < 2 {
                continue;
            }
            let height = if style.height > 0.0 {
                style.height
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
                tool: style.tool,
                width: style.width,
                height,
                speed: style.speed,
                segments: None,
                tool_axis: None,
            });
        }
    }
    per_layer
}

/// Adds a drop on every pad of the object's parts to the layer at its seating plane.
fn add_pad_drops(
    mine: &[(usize, &PlacedPart)],
    zs: &[LayerZ],
    style: TraceStyle,
    per_layer: &mut BTreeMap<usize, Vec<Toolpath>>,
) {
    for (_, part) in mine {
        for pad in &part.pads {
            let Some(layer) = floor_layer(zs, pad.centre.z) else {
                continue;
            };
            let z = zs[layer].top;
            per_layer.entry(layer).or_default().push(drop_path(
                pad.centre,
                z,
                style.width,
                zs[layer].height(),
                style.tool,
                style.speed,
            ));
        }
    }
}

/// The contact pads of the object's terminals (a disc of `diameter` filled with concentric
/// rings of trace, on the layer whose top is nearest the waypoint), and their report entries.
fn add_terminal_pads(
    terminals: &[&Terminal],
    zs: &[LayerZ],
    style: TraceStyle,
    diameter: f64,
    per_layer: &mut BTreeMap<usize, Vec<Toolpath>>,
    report: &mut ElectronicsReport,
) {
    for t in terminals {
        let layer = floor_layer(zs, t.at.z).or_else(|| {
            zs.iter()
                .enumerate()
                .min_by(|a, b| {
                    (a.1.top - t.at.z)
                        .abs()
                        .total_cmp(&(b.1.top - t.at.z).abs())
                })
                .map(|(i, _)| i)
        });
        let Some(layer) = layer else { continue };
        let z = zs[layer].top;
        report.terminals.push(TerminalReport {
            net: t.net.clone(),
            name: t.name.clone(),
            position: [t.at.x, t.at.y, z],
            pad_diameter: diameter,
        });
        if diameter <= 0.0 {
            continue;
        }
        // Rings one trace width apart, from the outermost (its outer edge on the pad's edge)
        // inward, then a drop in the middle (a circle of one trace width, covering a disc of
        // two).
        let w = style.width;
        let paths = per_layer.entry(layer).or_default();
        let mut radius = diameter / 2.0 - w / 2.0;
        while radius > w + 1e-9 {
            let mut ring = drop_path(t.at, z, w, zs[layer].height(), style.tool, style.speed);
            ring.points = circle(t.at, z, radius, 24);
            paths.push(ring);
            radius -= w;
        }
        paths.push(drop_path(
            t.at,
            z,
            w,
            zs[layer].height(),
            style.tool,
            style.speed,
        ));
    }
}

/// Hands the traces and drops to the extras, printed after their layer, longest first on each
/// layer.
fn add_traces(per_layer: BTreeMap<usize, Vec<Toolpath>>, zs: &[LayerZ], extras: &mut LayerExtras) {
    for (layer, mut paths) in per_layer {
        paths.sort_by(|a, b| b.length().total_cmp(&a.length()));
        extras
            .paths_after
            .entry(scaled(zs[layer].top))
            .or_default()
            .extend(paths);
    }
}

/// The part events, at the start of the first layer above each cavity (parts standing above
/// the last layer are placed after it), and the parts' report entries.
fn add_part_events(
    mine: &[(usize, &PlacedPart)],
    zs: &[LayerZ],
    extras: &mut LayerExtras,
    report: &mut ElectronicsReport,
) {
    for &(index, part) in mine {
        let top = part.position.z + part.body_height;
        let event = part_event(index + 1, part);
        let report_entry = |after: f64| PartReport {
            name: part.name.clone(),
            method: method_name(part.method),
            position: [part.position.x, part.position.y, part.position.z],
            rotation_deg: part.rotation_deg,
            // Layer heights are sums of floats: report the nanometre the layer starts at.
            placed_after_z: (after * 1e6).round() / 1e6,
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
}

/// The report's totals over every wire reported so far.
fn total_up(report: &mut ElectronicsReport) {
    report.routed = report.wires.iter().filter(|w| w.routed).count();
    report.unrouted = report.wires.len() - report.routed;
    report.total_length = report.wires.iter().map(|w| w.length).sum();
    report.total_lower_bound = report
        .wires
        .iter()
        .filter(|w| w.routed)
        .map(|w| w.lower_bound)
        .sum();
}

/// Two pads of different nets on one part closer than two traces of different nets may run
/// ([`min_trace_spacing`]): at the configured width, traces cannot reach both.
#[derive(Debug, Clone, PartialEq)]
pub struct FinePitch {
    /// The part's name.
    pub part: String,
    /// The two pads (pad names), the closest such pair of the part.
    pub pads: [String; 2],
    /// Distance between the pads' centres, mm.
    pub distance: f64,
    /// The spacing two traces need at the configured width, mm.
    pub spacing: f64,
    /// The widest `route.conductive_width`, in 0.05 mm steps, whose traces may run
    /// `distance` apart.
    pub width: f64,
}

impl FinePitch {
    /// `pads U1.3 and U1.4 are 0.80 mm apart, closer than two traces can run`: what the
    /// slice's warning and `conduit place` say first.
    pub fn too_close(&self) -> String {
        format!(
            "pads {p}.{a} and {p}.{b} are {d:.2} mm apart, closer than two traces can run",
            p = self.part,
            a = self.pads[0],
            b = self.pads[1],
            d = self.distance,
        )
    }
}

/// The closest pair of connected pads of different nets on `part` that two traces of
/// different nets cannot both reach at `params`' width, if any.
pub fn fine_pitch(part: &PlacedPart, params: &RouteParams) -> Option<FinePitch> {
    let spacing = min_trace_spacing(params);
    let mut closest: Option<(f64, &str, &str)> = None;
    for (i, a) in part.pads.iter().enumerate() {
        for b in &part.pads[i + 1..] {
            let (Some(na), Some(nb)) = (&a.net, &b.net) else {
                continue;
            };
            if na == nb {
                continue;
            }
            let d = ((a.centre.x - b.centre.x).powi(2) + (a.centre.y - b.centre.y).powi(2)).sqrt();
            if d < spacing && closest.is_none_or(|(c, _, _)| d < c) {
                closest = Some((d, &a.name, &b.name));
            }
        }
    }
    closest.map(|(distance, a, b)| FinePitch {
        part: part.name.clone(),
        pads: [a.to_owned(), b.to_owned()],
        distance,
        spacing,
        width: fitting_width(distance, params),
    })
}

/// A warning naming `part`'s [`fine_pitch`] pads, if any.
fn pitch_warning(part: &PlacedPart, params: &RouteParams) -> Option<String> {
    fine_pitch(part, params).map(|f| {
        format!(
            "{} ({spacing:.2} mm with route.conductive_width {w} and route.channel_extra {x}): \
             their nets cannot both be routed; a conductive_width of {max:.2} mm fits",
            f.too_close(),
            spacing = f.spacing,
            w = params.conductive_width,
            x = params.channel_extra,
            max = f.width,
        )
    })
}

/// The widest conductive width, in 0.05 mm steps, whose traces may run `d` mm apart.
fn fitting_width(d: f64, params: &RouteParams) -> f64 {
    let mut w = (params.conductive_width * 20.0).floor() / 20.0;
    while w > 0.05 {
        let p = RouteParams {
            conductive_width: w,
            ..params.clone()
        };
        if min_trace_spacing(&p) < d {
            break;
        }
        w -= 0.05;
    }
    (w * 100.0).round() / 100.0
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
    Toolpath {
        points: circle(centre, z, width / 2.0, 12),

        closed: true,
        role: Role::ConductiveDrop,
        tool,
        width,
        height,
        speed,
        segments: None,
        tool_axis: None,
    }
}

/// `n` points on the circle of `radius` about `centre`, at height `z`, counter-clockwise.
fn circle(centre: Point3, z: f64, radius: f64, n: u32) -> Vec<Point3> {
    (0..n)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::TAU / f64::from(n);
            Point3::new(centre.x + radius * a.cos(), centre.y + radius * a.sin(), z)
        })
        .collect()
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

/// Pick-and-place records of the placed parts (bed coordinates), for the KiCad position files
/// and the OpenPnP board: enabled for the parts the machine places (`method = "auto"`).
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
                // Only parts the vacuum nozzle places are enabled: a machine must not try to
                // pick a part inserted by hand or one that only gets pads.
                enabled: p.method == PlacingMethod::Auto,
                height: p.body_height,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::circuit::PlacedPad;
    use crate::geom::{Point2, Polygon};

    /// A part with one square 0.5 mm pad per `(name, x, net)`, on the x axis.
    fn row(pads: &[(&str, f64, Option<&str>)]) -> PlacedPart {
        let square = |x: f64| {
            Polygon::new(vec![
                Point2::from_mm(x - 0.25, -0.25),
                Point2::from_mm(x + 0.25, -0.25),
                Point2::from_mm(x + 0.25, 0.25),
                Point2::from_mm(x - 0.25, 0.25),
            ])
        };
        PlacedPart {
            name: "U1".into(),
            method: PlacingMethod::Auto,
            position: Point3::new(0.0, 0.0, 1.0),
            rotation_deg: 0.0,
            mirror: false,
            body_height: 1.0,
            object: 0,
            pads: pads
                .iter()
                .map(|&(name, x, net)| PlacedPad {
                    name: name.into(),
                    centre: Point3::new(x, 0.0, 1.0),
                    outline: square(x),
                    net: net.map(str::to_owned),
                })
                .collect(),
            footprint: square(0.0),
        }
    }

    #[test]
    fn pads_of_two_nets_closer_than_two_traces_are_named() {
        let params = RouteParams::default();
        // Traces of different nets keep (0.6 + 0.2) mm plus the polygon allowance apart.
        let spacing = min_trace_spacing(&params);
        assert!(spacing > 0.8 && spacing < 0.83, "{spacing}");
        let tight = row(&[
            ("1", 0.0, Some("A")),
            ("2", 0.8, Some("B")),
            ("3", 1.6, Some("A")),
        ]);
        let w = pitch_warning(&tight, &params).expect("a warning");
        assert!(w.starts_with("pads U1.1 and U1.2 are 0.80 mm apart"), "{w}");
        assert!(w.ends_with("a conductive_width of 0.55 mm fits"), "{w}");
        // 0.55 mm does fit, 0.6 does not.
        let at = |w: f64| RouteParams {
            conductive_width: w,
            ..params.clone()
        };
        assert!(min_trace_spacing(&at(0.55)) < 0.8 && min_trace_spacing(&at(0.6)) > 0.8);
        // Same net, unconnected pins, or enough room: nothing to say.
        let same = row(&[("1", 0.0, Some("A")), ("2", 0.8, Some("A"))]);
        let free = row(&[("1", 0.0, Some("A")), ("2", 0.8, None)]);
        let wide = row(&[("1", 0.0, Some("A")), ("2", 1.27, Some("B"))]);
        for part in [same, free, wide] {
            assert_eq!(pitch_warning(&part, &params), None);
        }
    }
}
