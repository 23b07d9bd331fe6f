//! The electronics stage's parameters built from the configuration: `[route]`
//! ([`RouteSettings`](super::RouteSettings), defined with the stage in [`crate::circuit::settings`]), the conductive
//! speed and perimeter width of `[slice]` and the number of `[tools.N]`.
//!
//! Place in the pipeline: read with the rest of [`super::Config`]; the slice and route walks
//! and post-processing hand [`Config::electronics_params`] to the electronics stage
//! ([`crate::circuit::stage`]), which hands its router part to [`crate::route`].

use super::Config;
use crate::circuit::stage::ElectronicsParams;

impl Config {
    /// The electronics stage's parameters: the router's from `[route]` with the perimeter width
    /// of `[slice]` ([`RouteSettings::router_params`](super::RouteSettings::router_params)), the conductive tool, trace height,
    /// cavity offset, pad drops and terminal pads of `[route]`, the conductive speed of `[slice]`, and how many
    /// tools there are.
    pub fn electronics_params(&self) -> ElectronicsParams {
        let r = &self.route;
        ElectronicsParams {
            route: r.router_params(self.slice.perimeter_width),
            conductive_tool: r.conductive_tool,
            tool_count: self.tools.len(),
            conductive_height: r.conductive_height,
            conductive_speed: self.slice.conductive_speed,
            cavity_offset: r.cavity_offset,
            pad_drops: r.pad_drops,
            terminal_pad: r.terminal_pad,
        }
    }
}
