//! PrusaSlicer's custom G-code by height: `Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml`,
//! the colour changes, pauses and custom G-code a user puts on the layer slider.
//!
//! The part is `<custom_gcodes_per_print_z>` holding one `<code>` per event and a
//! `<mode value>` (`SingleExtruder`, `MultiAsSingle` or `MultiExtruder`: the kind of printer the
//! events were entered for). A code has `print_z` (mm), `type` (PrusaSlicer's
//! `CustomGCode::Type`: 0 colour change, 1 pause, 2 tool change, 3 template, 4 custom),
//! `extruder` (1-based; 0 for the current one), `color` and `extra` (the pause message or the
//! custom G-code). Files written by PrusaSlicer 2.2 and older have no `type` but a `gcode`:
//! `M600` (colour change), `M601` (pause, whose message is then in `color`), `tool_change`, or
//! the custom G-code itself. This is how PrusaSlicer's own importer reads it.

use super::error;
use super::model_config::{attribute, attributes, number};
use crate::error::ThreeMfError;
use crate::xml::{Ev, Xml};

/// PrusaSlicer's part of custom G-code by height.
pub const PRUSA_CUSTOM_GCODE_PART: &str = "/Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml";

/// What a custom G-code event does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CustomGcodeKind {
    /// A filament (colour) change: PrusaSlicer's `color_change_gcode`, `M600` by default.
    ColorChange,
    /// A pause: PrusaSlicer's `pause_print_gcode`, `M601` by default, after `M117 <message>`.
    PausePrint,
    /// A switch to another extruder (a multi-material print entered on one nozzle).
    ToolChange,
    /// PrusaSlicer's `template_custom_gcode`.
    Template,
    /// G-code given in the event itself.
    Custom,
}

impl CustomGcodeKind {
    /// PrusaSlicer's `CustomGCode::Type` number; `None` for `Unknown` and anything else.
    pub fn from_number(n: u32) -> Option<Self> {
        Some(match n {
            0 => Self::ColorChange,
            1 => Self::PausePrint,
            2 => Self::ToolChange,
            3 => Self::Template,
            4 => Self::Custom,
            _ => return None,
        })
    }
}

/// One event on the layer slider.
#[derive(Debug, Clone, PartialEq)]
pub struct CustomGcode {
    /// Height of the layer it comes before, mm (the top of that layer).
    pub print_z: f64,
    /// What it does.
    pub kind: CustomGcodeKind,
    /// The extruder it is for, 1-based; 0 for the one printing.
    pub extruder: u32,
    /// The colour of the new filament (`#RRGGBB`), as written.
    pub color: String,
    /// The pause message or the custom G-code.
    pub extra: String,
    /// 1-based line of its element.
    pub line: usize,
}

/// The events of a project, with the printer kind they were entered for.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CustomGcodes {
    /// The part they were read from.
    pub part: String,
    /// `SingleExtruder`, `MultiAsSingle` or `MultiExtruder`, when stated.
    pub mode: Option<String>,
    /// The events in file order.
    pub codes: Vec<CustomGcode>,
}

/// Reads the part `part`; events of a type this reader does not know are warned about in
/// `warnings` and left out.
pub(super) fn read(
    part: &str,
    bytes: &[u8],
    warnings: &mut Vec<String>,
) -> Result<CustomGcodes, ThreeMfError> {
    let mut x = Xml::new(part, bytes)?;
    let mut out = CustomGcodes {
        part: part.to_owned(),
        ..CustomGcodes::default()
    };
    let mut depth = 0usize;
    loop {
        let (e, empty) = match x.next()? {
            Ev::Start(e) => (e, false),
            Ev::Empty(e) => (e, true),
            Ev::End => {
                depth = depth.saturating_sub(1);
                continue;
            }
            Ev::Text(_) => continue,
            Ev::Eof => break,
        };
        let line = x.loc().line as usize;
        let name = e.local_name().as_ref().to_owned();
        match (name.as_str(), depth) {
            ("custom_gcodes_per_print_z", 0) => {}
            (_, 0) => {
                return Err(error(
                    part,
                    line,
                    "expected <custom_gcodes_per_print_z> as the root element",
                ));
            }
            ("mode", 1) => {
                let attrs = attributes(&x, &e)?;
                out.mode = attribute(&attrs, "value").map(str::to_owned);
            }
            ("code", 1) => {
                let attrs = attributes(&x, &e)?;
                let get = |name: &str| attribute(&attrs, name);
                if let Some(code) = code(part, line, &get, warnings)? {
                    out.codes.push(code);
                }
            }
            _ => {}
        }
        if !empty {
            if depth == 0 {
                depth = 1;
            } else {
                x.skip()?;
            }
        }
    }
    Ok(out)
}

/// One `<code>` with attributes `get`; `None` (with a warning) for a type not known.
fn code<'a>(
    part: &str,
    line: usize,
    get: &dyn Fn(&str) -> Option<&'a str>,
    warnings: &mut Vec<String>,
) -> Result<Option<CustomGcode>, ThreeMfError> {
    let z = get("print_z").ok_or_else(|| error(part, line, "<code> has no print_z"))?;
    let print_z = z
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| {
            error(
                part,
                line,
                format!("<code> print_z={z:?} is not a height in mm"),
            )
        })?;
    let extruder = match get("extruder") {
        Some(_) => number(part, line, "code", "extruder", get("extruder"))?,
        None => 0,
    };
    let color = get("color").unwrap_or_default().to_owned();
    let (kind, extra) = match get("type") {
        Some(t) => {
            let n = number(part, line, "code", "type", Some(t))?;
            let Some(kind) = CustomGcodeKind::from_number(n) else {
                warnings.push(format!(
                    "{part}:{line}: custom G-code of unknown type {n} at {print_z} mm left out"
                ));
                return Ok(None);
            };
            (kind, get("extra").unwrap_or_default().to_owned())
        }
        None => {
            // PrusaSlicer 2.2 and older: the G-code says what the event is.
            let gcode = get("gcode").unwrap_or_default();
            match gcode {
                "M600" => (CustomGcodeKind::ColorChange, String::new()),
                "M601" => (CustomGcodeKind::PausePrint, color.clone()),
                "tool_change" => (CustomGcodeKind::ToolChange, String::new()),
                g => (CustomGcodeKind::Custom, g.to_owned()),
            }
        }
    };
    Ok(Some(CustomGcode {
        print_z,
        kind,
        extruder,
        color,
        extra,
        line,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    const PART: &str = PRUSA_CUSTOM_GCODE_PART;

    #[test]
    fn events_read_as_prusaslicer_writes_them() -> Result<(), ThreeMfError> {
        let xml = r##"<?xml version="1.0" encoding="utf-8"?>
<custom_gcodes_per_print_z>
<code print_z="2.2" type="0" extruder="1" color="#FF0000" extra="" gcode="M600"/>
<code print_z="3.4" type="1" extruder="1" color="" extra="Insert magnets" gcode="M601"/>
<code print_z="4" type="4" extruder="1" color="" extra="M117 hello" gcode="M117 hello"/>
<code print_z="5" type="9" extruder="1" color="" extra="" gcode=""/>
<mode value="SingleExtruder"/>
</custom_gcodes_per_print_z>
"##;
        let mut warnings = Vec::new();
        let c = read(PART, xml.as_bytes(), &mut warnings)?;
        assert_eq!(c.mode.as_deref(), Some("SingleExtruder"));
        let kinds: Vec<(f64, CustomGcodeKind, &str)> = c
            .codes
            .iter()
            .map(|c| (c.print_z, c.kind, c.extra.as_str()))
            .collect();
        assert_eq!(
            kinds,
            vec![
                (2.2, CustomGcodeKind::ColorChange, ""),
                (3.4, CustomGcodeKind::PausePrint, "Insert magnets"),
                (4.0, CustomGcodeKind::Custom, "M117 hello"),
            ]
        );
        assert_eq!(c.codes[0].color, "#FF0000");
        assert_eq!((c.codes[0].extruder, c.codes[0].line), (1, 3));
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(warnings[0].contains(":6: custom G-code of unknown type 9"));
        Ok(())
    }

    #[test]
    fn old_files_say_what_an_event_is_by_its_gcode() -> Result<(), ThreeMfError> {
        let xml = r##"<custom_gcodes_per_print_z>
<code print_z="1.0" extruder="1" color="Swap now" gcode="M601"/>
<code print_z="2.0" extruder="1" color="#00FF00" gcode="M600"/>
<code print_z="3.0" extruder="0" color="" gcode="G4 S5"/>
</custom_gcodes_per_print_z>"##;
        let c = read(PART, xml.as_bytes(), &mut Vec::new())?;
        let kinds: Vec<(CustomGcodeKind, &str)> =
            c.codes.iter().map(|c| (c.kind, c.extra.as_str())).collect();
        assert_eq!(
            kinds,
            vec![
                (CustomGcodeKind::PausePrint, "Swap now"),
                (CustomGcodeKind::ColorChange, ""),
                (CustomGcodeKind::Custom, "G4 S5"),
            ]
        );
        Ok(())
    }

    #[test]
    fn a_code_without_a_height_is_an_error_naming_its_line() {
        let xml = "<custom_gcodes_per_print_z>\n<code type=\"0\"/>\n</custom_gcodes_per_print_z>";
        let e = read(PART, xml.as_bytes(), &mut Vec::new()).map(|c| c.codes.len());
        let msg = e.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.contains(":2:") && msg.contains("no print_z"), "{msg}");
        let xml = "<custom_gcodes_per_print_z><code print_z=\"high\"/></custom_gcodes_per_print_z>";
        let e = read(PART, xml.as_bytes(), &mut Vec::new()).map(|c| c.codes.len());
        let msg = e.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.contains("print_z=\"high\" is not a height"), "{msg}");
    }
}
