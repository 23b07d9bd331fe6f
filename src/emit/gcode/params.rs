//! What the G-code writer is told: the machine (printer, tools, part-placement commands) and
//! the further keys its custom G-code templates may name.
//!
//! Place in the pipeline: built by the walk from the config (`Config::gcode_params`) and
//! adjusted by the walk where a job needs it (a conform program's pressure snippets and travel
//! lift, the minimum hop of a curved-layer print); the writer reads nothing else.

use crate::program::machine::{PnpSettings, Printer, Tool};

/// Everything [`write_gcode`](super::write_gcode) and [`write_block`](super::write_block) need.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GcodeParams {
    /// The printer: flavour, bed, custom G-code, retraction, travel, fan.
    pub printer: Printer,
    /// The tools, by tool number.
    pub tools: Vec<Tool>,
    /// What the machine does to place a part.
    pub pnp: PnpSettings,
    /// Keys of the other settings the templates may name (`{layer_height}`,
    /// `{first_layer_height}`: the `[slice]` keys), looked up after the printer's keys and
    /// before the tools'.
    pub template_keys: toml::Table,
}

impl GcodeParams {
    /// Z lift of tool `tool`'s long travels, mm: its own `travel_lift`, or the printer's
    /// `retract_lift`.
    pub fn travel_lift(&self, tool: usize) -> f64 {
        self.tools
            .get(tool)
            .and_then(|t| t.travel_lift)
            .unwrap_or(self.printer.retract_lift)
    }

    /// The retraction length of tool `tool`, mm: its own override or the printer's.
    pub fn retract_length(&self, tool: usize) -> f64 {
        self.tools
            .get(tool)
            .and_then(|t| t.retract_length)
            .unwrap_or(self.printer.retract_length)
    }

    /// Un-retraction speed, mm/s: `deretract_speed`, or `retract_speed` when that is 0.
    pub fn deretract_speed(&self) -> f64 {
        if self.printer.deretract_speed > 0.0 {
            self.printer.deretract_speed
        } else {
            self.printer.retract_speed
        }
    }
}

#[cfg(test)]
impl GcodeParams {
    /// The default two-tool machine (a PLA extruder and a paste dispenser) with the `[slice]`
    /// keys the default start G-code names (`layer_height`, `first_layer_height`, both 0.2).
    pub(crate) fn for_tests() -> Self {
        let mut template_keys = toml::Table::new();
        template_keys.insert("layer_height".to_owned(), toml::Value::Float(0.2));
        template_keys.insert("first_layer_height".to_owned(), toml::Value::Float(0.2));
        Self {
            printer: Printer::default(),
            tools: vec![Tool::filament(), Tool::paste()],
            template_keys,
            ..Self::default()
        }
    }
}
