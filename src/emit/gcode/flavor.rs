//! What differs between firmware flavours: temperature commands and waits, pauses.
//!
//! | | Marlin | RepRapFirmware | Klipper |
//! |---|---|---|---|
//! | set tool temperature | `M104 T1 S210` | `G10 P1 S210 R170` (active and standby) | `M104 T1 S210` |
//! | wait for tool | `M109 T1 S210` | `M116 P1` | `M109 T1 S210` |
//! | tool goes idle | `M104 T0 S170` (its standby temperature) | automatic: RRF puts a deselected tool at its `R` temperature | `M104 T0 S170` |
//! | bed | `M140 S60` / `M190 S60` | same | same |
//! | fan | `M106 S255` / `M107` | same | same |
//! | firmware retraction | `G10` / `G11` | same | same (needs `[firmware_retraction]`) |
//! | manual insert pause | `M0 message` | `M291 P"message" S2` (blocking message box) | `M117 message`, `PAUSE` (needs the `PAUSE` macro, as in Mainsail/Fluidd configs) |
//!
//! RepRapFirmware's standby temperature is the tool's `R` value, which it applies by itself when
//! the tool is deselected; a tool without a configured standby temperature gets `R` equal to its
//! active temperature, so it stays hot (RRF's own default `R0` would let it cool). Klipper accepts
//! Marlin's `M104`/`M109` with `T` (see Klipper's `G-Codes.md`); `T1` needs a `T1` macro in the
//! printer config, as for every slicer.

use conduit_gcode::fmt_f;

use crate::program::machine::Flavor;

/// Commands of one flavour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Dialect(pub Flavor);

impl Dialect {
    /// Sets a tool's temperature without waiting: tool `tool`'s, or, with `None`, the one
    /// tool of a print that uses tool 0 alone (no `T` word, as PrusaSlicer writes a
    /// single-extruder print). `standby` is used by RepRapFirmware only.
    pub fn set_tool_temperature(self, tool: Option<usize>, temp: f64, standby: f64) -> String {
        match self.0 {
            Flavor::Marlin | Flavor::Klipper => {
                format!("M104{} S{}", t_word(tool), fmt_f(temp))
            }
            Flavor::RepRapFirmware => format!(
                "G10 P{} S{} R{}",
                tool.unwrap_or(0),
                fmt_f(temp),
                fmt_f(standby)
            ),
        }
    }

    /// Heats a tool (already selected; `tool` as in [`Self::set_tool_temperature`]) to `temp`
    /// and waits.
    pub fn wait_tool_temperature(self, tool: Option<usize>, temp: f64) -> String {
        match self.0 {
            Flavor::Marlin | Flavor::Klipper => {
                format!("M109{} S{}", t_word(tool), fmt_f(temp))
            }
            Flavor::RepRapFirmware => format!("M116 P{}", tool.unwrap_or(0)),
        }
    }

    /// Puts the tool that goes idle at its standby temperature, where the firmware does not.
    pub fn standby(self, tool: usize, standby: f64) -> Option<String> {
        match self.0 {
            Flavor::Marlin | Flavor::Klipper => Some(format!("M104 T{tool} S{}", fmt_f(standby))),
            Flavor::RepRapFirmware => None,
        }
    }

    /// Pauses for the operator with `message` (free of `;` and line breaks).
    pub fn pause(self, message: &str) -> Vec<String> {
        match self.0 {
            Flavor::Marlin => vec![format!("M0 {message}")],
            Flavor::RepRapFirmware => vec![format!("M291 P\"{}\" S2", message.replace('"', "'"))],
            Flavor::Klipper => vec![format!("M117 {message}"), "PAUSE".to_owned()],
        }
    }
}

/// Bed temperature without waiting.
pub(super) fn set_bed(temp: f64) -> String {
    format!("M140 S{}", fmt_f(temp))
}

/// Bed temperature, waiting for it.
pub(super) fn wait_bed(temp: f64) -> String {
    format!("M190 S{}", fmt_f(temp))
}

/// Part-cooling fan at `percent` (0 turns it off with `M107`).
pub(super) fn fan(percent: f64) -> String {
    if percent > 0.0 {
        format!("M106 S{}", fmt_f(percent.min(100.0) * 255.0 / 100.0))
    } else {
        "M107".to_owned()
    }
}

/// ` T<tool>`, or nothing for `None`.
fn t_word(tool: Option<usize>) -> String {
    tool.map_or_else(String::new, |t| format!(" T{t}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temperature_commands_per_flavour() {
        let m = Dialect(Flavor::Marlin);
        let r = Dialect(Flavor::RepRapFirmware);
        let k = Dialect(Flavor::Klipper);
        assert_eq!(
            m.set_tool_temperature(Some(1), 210.0, 170.0),
            "M104 T1 S210"
        );
        assert_eq!(
            r.set_tool_temperature(Some(1), 210.0, 170.0),
            "G10 P1 S210 R170"
        );
        assert_eq!(
            k.set_tool_temperature(Some(1), 210.0, 170.0),
            "M104 T1 S210"
        );
        assert_eq!(m.wait_tool_temperature(Some(0), 215.0), "M109 T0 S215");
        assert_eq!(r.wait_tool_temperature(Some(0), 215.0), "M116 P0");
        // A single-extruder print: no T word, but RepRapFirmware's tool is tool 0.
        assert_eq!(m.set_tool_temperature(None, 215.0, 215.0), "M104 S215");
        assert_eq!(m.wait_tool_temperature(None, 215.0), "M109 S215");
        assert_eq!(
            r.set_tool_temperature(None, 215.0, 170.0),
            "G10 P0 S215 R170"
        );
        assert_eq!(m.standby(0, 170.0).as_deref(), Some("M104 T0 S170"));
        assert_eq!(r.standby(0, 170.0), None);
        assert_eq!(fan(100.0), "M106 S255");
        assert_eq!(fan(0.0), "M107");
        assert_eq!(k.pause("insert R1"), vec!["M117 insert R1", "PAUSE"]);
    }
}
