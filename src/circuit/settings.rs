//! The electronics stage's settings, the `[route]` section of the configuration: cavities,
//! channels and trace routing.
//!
//! Place in the pipeline: read with the rest of the config (`crate::config::Config::route`);
//! the walk builds the electronics stage's [`ElectronicsParams`](super::stage::ElectronicsParams)
//! from it (`crate::config::Config::electronics_params`), the router's part through
//! [`RouteSettings::router_params`]. The router's keys take their defaults from
//! [`RouteParams::default`], so each default is written once.

use serde::{Deserialize, Serialize};

use crate::route::{RouteParams, Strategy};

/// Cavities, channels and trace routing (`[route]`). Lengths in mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct RouteSettings {
    /// Tool that prints the conductive traces. Default 1.
    pub conductive_tool: usize,
    /// Width of a conductive trace, mm. Default 0.6.
    pub conductive_width: f64,
    /// Height of a conductive trace, mm (the layer height when 0). Default 0.
    pub conductive_height: f64,
    /// Extra clearance of a channel beyond the trace width (Δ), mm: a channel is the trace grown
    /// by `(conductive_width + channel_extra) / 2` on each side. Default 0.2.
    pub channel_extra: f64,
    /// How far a part's cavity reaches beyond its pads and body, mm. Default 0.3.
    pub cavity_offset: f64,
    /// Number of deflated perimeter traces the router may follow per layer. Default 3.
    pub perimeters: usize,
    /// Cost per mm on the deflated traces, outermost first; decreasing inward so inner traces
    /// are preferred. Default [3, 2, 1].
    pub perimeter_weights: Vec<f64>,
    /// Cost per mm of a straight section inside material. Default 1.
    pub base_weight: f64,
    /// Cost per mm of a straight section outside material or across a hole. Default 100.
    pub outside_weight: f64,
    /// Cost per mm of trace squeezed through a gap the deflated perimeter traces do not reach
    /// (between pad rows, beside earlier traces), where a trace still fits. Default 4.
    pub squeeze_weight: f64,
    /// Step of the grid explored inside the infill area, mm. Default 1.
    pub grid_step: f64,
    /// Overlap of a trace with the one of the next layer where a wire changes layer, mm (the
    /// "staircase" that connects them). Default 2.
    pub interlayer_overlap: f64,
    /// Extra cost of each layer change, in mm of base-weight path. Default 5.
    pub layer_change_penalty: f64,
    /// Layers below the lower pad and above the upper pad a route may use to pass other
    /// traces. Traces of different nets on adjacent layers would touch, so a crossing needs a
    /// layer in between: at least 2 for routes to cross at all. Default 2.
    pub layer_span: usize,
    /// Rounds of rip-up and reroute for wires that could not be routed: the wires in their way
    /// are routed again after them. 0 routes each wire once. Default 3.
    pub rip_up_rounds: usize,
    /// How the wires share the material: `negotiated` routes every wire with the other nets'
    /// traces as a cost that rises, round by round, where traces still touch, until none do
    /// (the wires then still in conflict are routed again in order); `ordered` routes wire
    /// after wire, each around the traces before it. Default ordered.
    pub strategy: Strategy,
    /// Most rounds of negotiation (`strategy = "negotiated"`). From 1 to 1000. Default 12.
    pub negotiation_rounds: usize,
    /// Longest route worth printing, as a multiple of the straight distance between the pads
    /// (plus `detour_slack`): a trace's resistance grows with its length, so a wire that needs a
    /// longer route is reported unrouted. Default 3.
    pub max_detour: f64,
    /// Longest time the routing of a job (every object) may take, seconds; 0 = no limit. At
    /// the limit the router starts no new search and gives up the one running: what is routed
    /// stays routed, and the other wires are reported unrouted with the reason "time limit
    /// reached". A job that finishes in time is not changed by it. Default 180.
    pub time_limit: f64,
    /// Allowance added to the detour limit, mm: room for layer changes and a way round a part on
    /// short wires. Default 30.
    pub detour_slack: f64,
    /// Put a conductive drop (a small disc of trace) on every pad, also on pins no net uses,
    /// so a part's leads sit in paste. Default false.
    pub pad_drops: bool,
    /// Diameter of the contact pad printed at a terminal: a waypoint only one wire of its net
    /// reaches, where a battery, a connector or a wire is attached (the `.3de` files of
    /// Electronic Slic3r wire single-pin nets to such waypoints). 0 prints none. From 0 to
    /// 50 mm. Default 2.
    pub terminal_pad: f64,
    /// Material kept between a part's cavity and the object's outer surface, and between the
    /// cavities of two parts, mm: what `conduit place` keeps when it lays parts out, and what
    /// it warns about when a placement leaves less. About two perimeters. Default 1.
    pub wall_clearance: f64,
}

impl Default for RouteSettings {
    fn default() -> Self {
        let r = RouteParams::default();
        Self {
            conductive_tool: 1,
            conductive_width: r.conductive_width,
            conductive_height: 0.0,
            channel_extra: r.channel_extra,
            cavity_offset: 0.3,
            perimeters: r.perimeters,
            perimeter_weights: r.perimeter_weights,
            base_weight: r.base_weight,
            outside_weight: r.outside_weight,
            squeeze_weight: r.squeeze_weight,
            grid_step: r.grid_step,
            interlayer_overlap: r.interlayer_overlap,
            layer_change_penalty: r.layer_change_penalty,
            layer_span: r.layer_span,
            rip_up_rounds: r.rip_up_rounds,
            strategy: r.strategy,
            negotiation_rounds: r.negotiation_rounds,
            max_detour: r.max_detour,
            time_limit: r.time_limit,
            detour_slack: r.detour_slack,
            pad_drops: false,
            terminal_pad: 2.0,
            wall_clearance: 1.0,
        }
    }
}

impl RouteSettings {
    /// The router's parameters: these settings' routing keys with `perimeter_width`, the
    /// perimeter width of the layers routed through (`[slice]`); the search limits the
    /// configuration does not set keep [`RouteParams::default`]'s values.
    pub fn router_params(&self, perimeter_width: f64) -> RouteParams {
        RouteParams {
            perimeters: self.perimeters,
            perimeter_width,
            conductive_width: self.conductive_width,
            channel_extra: self.channel_extra,
            perimeter_weights: self.perimeter_weights.clone(),
            base_weight: self.base_weight,
            outside_weight: self.outside_weight,
            squeeze_weight: self.squeeze_weight,
            grid_step: self.grid_step,
            interlayer_overlap: self.interlayer_overlap,
            layer_change_penalty: self.layer_change_penalty,
            layer_span: self.layer_span,
            rip_up_rounds: self.rip_up_rounds,
            strategy: self.strategy,
            negotiation_rounds: self.negotiation_rounds,
            max_detour: self.max_detour,
            detour_slack: self.detour_slack,
            time_limit: self.time_limit,
            ..RouteParams::default()
        }
    }

    /// Every problem with these settings, as `route.<key>: ...` lines.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (key, v) in [
            ("conductive_width", self.conductive_width),
            ("grid_step", self.grid_step),
            ("interlayer_overlap", self.interlayer_overlap),
            ("base_weight", self.base_weight),
            ("max_detour", self.max_detour),
            ("outside_weight", self.outside_weight),
            ("squeeze_weight", self.squeeze_weight),
        ] {
            if !(v.is_finite() && v > 0.0) {
                out.push(format!("route.{key} must be > 0, got {v}"));
            }
        }
        for (key, v) in [
            ("conductive_height", self.conductive_height),
            ("channel_extra", self.channel_extra),
            ("cavity_offset", self.cavity_offset),
            ("layer_change_penalty", self.layer_change_penalty),
            ("detour_slack", self.detour_slack),
            ("wall_clearance", self.wall_clearance),
            ("time_limit", self.time_limit),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                out.push(format!("route.{key} must be ≥ 0, got {v}"));
            }
        }
        if !(0.0..=50.0).contains(&self.terminal_pad) {
            out.push(format!(
                "route.terminal_pad must be from 0 to 50 mm, got {}",
                self.terminal_pad
            ));
        }
        if !(1..=1000).contains(&self.negotiation_rounds) {
            out.push(format!(
                "route.negotiation_rounds must be from 1 to 1000, got {}",
                self.negotiation_rounds
            ));
        }
        if self.perimeter_weights.len() < self.perimeters {
            out.push(format!(
                "route.perimeter_weights has {} weights for {} perimeters",
                self.perimeter_weights.len(),
                self.perimeters
            ));
        }
        if let Some(w) = self
            .perimeter_weights
            .iter()
            .find(|w| !(w.is_finite() && **w > 0.0))
        {
            out.push(format!("route.perimeter_weights must all be > 0, got {w}"));
        }
        out
    }
}
