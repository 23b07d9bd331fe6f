//! Colour changes, pauses and custom G-code by height (`printer.custom_gcode_per_print_z`,
//! PrusaSlicer's layer slider), written at the start of their layer as PrusaSlicer writes them.
//!
//! Place in the pipeline: part of the writer's layer change, after `printer.layer_gcode` and
//! before the layer's first path.
//!
//! - **Which layer**: an event comes before the first layer whose top reaches its `print_z`:
//!   above the previous layer's top (0 before the first layer) by more than half of
//!   PrusaSlicer's `EPSILON` (0.1 µm), and at most the layer's top plus `EPSILON`. This is
//!   PrusaSlicer's `ToolOrdering::assign_custom_gcodes`. Events above the last layer are not
//!   written (PrusaSlicer leaves them out too); their heights are in the totals
//!   ([`GcodeStats::events_above_print`](crate::emit::gcode::GcodeStats)), so the job can say
//!   so. Several events on one layer are all written, lowest first.
//! - **What is written** (PrusaSlicer's `emit_custom_gcode_per_print_z`):
//!   - colour change: `;COLOR_CHANGE,T<tool>,<color>` (the tag PrusaSlicer's G-code viewer and
//!     printers read), then `printer.color_change_gcode` with `{color_change_extruder}`. The
//!     firmware's filament change leaves the nozzle loaded and primed, so a retraction before
//!     it is not undone after it (PrusaSlicer marks the extruder unretracted the same way);
//!     with firmware retraction the `G11` still follows, as the firmware keeps its state.
//!   - pause: `;PAUSE_PRINT`, `M117 <message>` when the pause has one, then
//!     `printer.pause_print_gcode` with `{color_change_extruder}` the tool printing.
//!   - template: `;CUSTOM_GCODE`, then `printer.template_custom_gcode`.
//!   - custom: `;CUSTOM_GCODE`, then the event's own G-code as given.
//!
//! The templates have the layer's variables (`{layer_num}`, `{layer_z}`, ...) and the writer
//! follows what they do to the position and E as for every custom G-code.

use super::{Writer, scalar};
use crate::emit::gcode::EmitError;
use crate::emit::gcode::macros::Var;
use crate::emit::gcode::sink::GcodeSink;
use crate::program::Layer;
use crate::program::machine::{LayerGcode, LayerGcodeKind};

/// PrusaSlicer's `EPSILON` for comparing heights, mm.
const EPSILON_MM: f64 = 1e-4;

/// The events of `events` that come before a layer whose top is `z`, the layer below's top
/// being `below` (0 for the first layer), lowest first.
pub(super) fn events_at(events: &[LayerGcode], below: f64, z: f64) -> Vec<&LayerGcode> {
    let mut at: Vec<&LayerGcode> = events
        .iter()
        .filter(|e| e.print_z > below + 0.5 * EPSILON_MM && e.print_z <= z + EPSILON_MM)
        .collect();
    at.sort_by(|a, b| a.print_z.total_cmp(&b.print_z));
    at
}

impl<S: GcodeSink> Writer<'_, S> {
    /// Writes the events that come before `layer`, with the layer's template variables
    /// `vars`.
    pub(super) fn layer_events(
        &mut self,
        layer: &Layer,
        vars: &[(&str, Var)],
    ) -> Result<(), EmitError> {
        let cfg = self.cfg;
        let below = self.below_z;
        self.below_z = layer.z;
        for event in events_at(&cfg.printer.custom_gcode_per_print_z, below, layer.z) {
            let tool = self.tool.unwrap_or(0);
            match event.kind {
                LayerGcodeKind::ColorChange => {
                    let changed = event.tool.unwrap_or(tool);
                    self.line(&format!(
                        ";COLOR_CHANGE,T{changed},{}",
                        super::one_line(&event.color)
                    ));
                    let lines = self.event_template(
                        "printer.color_change_gcode",
                        &cfg.printer.color_change_gcode,
                        tool,
                        changed,
                        vars,
                    )?;
                    self.lines(&lines);
                    if !cfg.printer.use_firmware_retraction
                        && let Some(state) = self.tools.get_mut(changed)
                    {
                        state.retracted = 0.0;
                    }
                }
                LayerGcodeKind::Pause => {
                    self.line(";PAUSE_PRINT");
                    if !event.extra.trim().is_empty() {
                        self.line(&format!("M117 {}", super::one_line(&event.extra)));
                    }
                    let lines = self.event_template(
                        "printer.pause_print_gcode",
                        &cfg.printer.pause_print_gcode,
                        tool,
                        tool,
                        vars,
                    )?;
                    self.lines(&lines);
                }
                LayerGcodeKind::Template => {
                    self.line(";CUSTOM_GCODE");
                    let lines = self.event_template(
                        "printer.template_custom_gcode",
                        &cfg.printer.template_custom_gcode,
                        tool,
                        tool,
                        vars,
                    )?;
                    self.lines(&lines);
                }
                LayerGcodeKind::Custom => {
                    self.line(";CUSTOM_GCODE");
                    let lines: Vec<String> = event
                        .extra
                        .lines()
                        .map(str::trim_end)
                        .filter(|l| !l.is_empty())
                        .map(str::to_owned)
                        .collect();
                    self.lines(&lines);
                }
            }
        }
        Ok(())
    }

    /// Heights of the events above the last layer written so far, which no layer took.
    pub(super) fn events_above_print(&self) -> Vec<f64> {
        self.cfg
            .printer
            .custom_gcode_per_print_z
            .iter()
            .map(|e| e.print_z)
            .filter(|&z| z > self.below_z + 0.5 * EPSILON_MM)
            .collect()
    }

    /// `template` rendered for an event, with `{color_change_extruder}` = `changed`.
    fn event_template(
        &mut self,
        name: &str,
        template: &str,
        tool: usize,
        changed: usize,
        vars: &[(&str, Var)],
    ) -> Result<Vec<String>, EmitError> {
        let mut vars = vars.to_vec();
        vars.push(("color_change_extruder", scalar(changed)));
        self.render_custom(name, template, tool, &vars)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn event(print_z: f64) -> LayerGcode {
        LayerGcode {
            print_z,
            kind: LayerGcodeKind::Pause,
            tool: None,
            color: String::new(),
            extra: String::new(),
        }
    }

    #[test]
    fn an_event_comes_before_the_first_layer_reaching_its_height() {
        let events = [event(0.6), event(0.5), event(1.05), event(0.2)];
        let z = |below: f64, top: f64| -> Vec<f64> {
            events_at(&events, below, top)
                .iter()
                .map(|e| e.print_z)
                .collect()
        };
        // Layers of 0.2 mm: 0.2 is the first layer's top, 0.5 and 0.6 come before the layer
        // up to 0.6, lowest first; 1.05 before the layer up to 1.2.
        assert_eq!(z(0.0, 0.2), vec![0.2]);
        assert_eq!(z(0.2, 0.4), Vec::<f64>::new());
        assert_eq!(z(0.4, 0.6), vec![0.5, 0.6]);
        assert_eq!(z(1.0, 1.2), vec![1.05]);
        // Within PrusaSlicer's EPSILON of the top still counts; just past the top below does
        // not come again.
        assert_eq!(z(0.4, 0.59995), vec![0.5, 0.6]);
        assert_eq!(z(0.59996, 0.8), Vec::<f64>::new());
    }
}
