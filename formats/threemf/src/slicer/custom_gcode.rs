//! The slicers' custom G-code by height: the colour changes, pauses and custom G-code a user
//! puts on the layer slider, in PrusaSlicer's part or in OrcaSlicer's and BambuStudio's.
//!
//! - **PrusaSlicer**: `Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml` is
//!   `<custom_gcodes_per_print_z>` holding one `<code>` per event and a `<mode value>`
//!   (`SingleExtruder`, `MultiAsSingle` or `MultiExtruder`: the kind of printer the events were
//!   entered for). A code has `print_z` (mm), `type` (PrusaSlicer's `CustomGCode::Type`: 0
//!   colour change, 1 pause, 2 tool change, 3 template, 4 custom), `extruder` (1-based; 0 for the
//!   current one), `color` and `extra` (the pause message or the custom G-code). Files written
//!   by PrusaSlicer 2.2 and older have no `type` but a `gcode`: `M600` (colour change), `M601`
//!   (pause, whose message is then in `color`), `tool_change`, or the custom G-code itself.
//! - **OrcaSlicer / BambuStudio**: `Metadata/custom_gcode_per_layer.xml` is
//!   `<custom_gcodes_per_layer>` holding one `<plate>` per plate of the project, each with a
//!   `<plate_info id>` (1-based), its events as `<layer top_z type extruder color extra>` (the
//!   attributes and numbers of PrusaSlicer's `<code>`, the height named `top_z`) and its
//!   `<mode value>`. A file with no `<plate>` holds the layers and mode of plate 1 directly
//!   under the root; a plate without `<plate_info>` is not read.
//!
//! This is how the slicers' own importers read them. conduit prints a project's objects as one
//! plate: the events of the first plate that has any are read, and the other plates' events
//! are named as left out.

use super::error;
use super::model_config::{attribute, attributes, number};
use crate::error::ThreeMfError;
use crate::xml::{Ev, Xml};

/// PrusaSlicer's part of custom G-code by height.
pub const PRUSA_CUSTOM_GCODE_PART: &str = "/Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml";

/// OrcaSlicer's and BambuStudio's part of custom G-code by height, per plate.
pub const ORCA_CUSTOM_GCODE_PART: &str = "/Metadata/custom_gcode_per_layer.xml";

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
    /// The plate they belong to (1-based; OrcaSlicer's and BambuStudio's part), `None` for
    /// PrusaSlicer's, which has one.
    pub plate: Option<u32>,
    /// `SingleExtruder`, `MultiAsSingle` or `MultiExtruder`, when stated.
    pub mode: Option<String>,
    /// The events in file order.
    pub codes: Vec<CustomGcode>,
}

impl CustomGcodes {
    /// The slicer whose layer slider wrote them: `PrusaSlicer` or `OrcaSlicer` (OrcaSlicer's
    /// part is BambuStudio's too).
    pub fn writer(&self) -> &'static str {
        if self.part == ORCA_CUSTOM_GCODE_PART {
            "OrcaSlicer"
        } else {
            "PrusaSlicer"
        }
    }
}

/// The events and mode of one plate, as read.
#[derive(Debug, Default)]
struct Plate {
    /// Its `<plate_info id>`, when given.
    id: Option<u32>,
    mode: Option<String>,
    codes: Vec<CustomGcode>,
}

/// Reads the part `part` (PrusaSlicer's or OrcaSlicer's layout, by its root element); events of
/// a type this reader does not know, and the events of plates after the first that has any,
/// are warned about in `warnings` and left out.
pub(super) fn read(
    part: &str,
    bytes: &[u8],
    warnings: &mut Vec<String>,
) -> Result<CustomGcodes, ThreeMfError> {
    let mut x = Xml::new(part, bytes)?;
    // The open elements' names, the root first.
    let mut open: Vec<String> = Vec::new();
    let mut orca = false;
    // PrusaSlicer's events, or OrcaSlicer's directly under the root (plate 1's).
    let mut root = Plate {
        id: Some(1),
        ..Plate::default()
    };
    let mut plates: Vec<Plate> = Vec::new();
    loop {
        let (e, empty) = match x.next()? {
            Ev::Start(e) => (e, false),
            Ev::Empty(e) => (e, true),
            Ev::End => {
                open.pop();
                continue;
            }
            Ev::Text(_) => continue,
            Ev::Eof => break,
        };
        let line = x.loc().line as usize;
        let name = e.local_name().as_ref().to_owned();
        // A child of a `<plate>` of OrcaSlicer's part.
        let in_plate = orca && open.len() == 2 && open.last().is_some_and(|p| p == "plate");
        match (name.as_str(), open.len()) {
            ("custom_gcodes_per_print_z", 0) => {}
            ("custom_gcodes_per_layer", 0) => orca = true,
            (_, 0) => {
                return Err(error(
                    part,
                    line,
                    "expected <custom_gcodes_per_print_z> or <custom_gcodes_per_layer> as the \
                     root element",
                ));
            }
            ("plate", 1) if orca => plates.push(Plate::default()),
            ("mode", _) if open.len() == 1 || in_plate => {
                let attrs = attributes(&x, &e)?;
                target(&mut plates, &mut root, in_plate).mode =
                    attribute(&attrs, "value").map(str::to_owned);
            }
            ("plate_info", _) if in_plate => {
                let attrs = attributes(&x, &e)?;
                let id = number(part, line, "plate_info", "id", attribute(&attrs, "id"))?;
                if let Some(plate) = plates.last_mut() {
                    plate.id = Some(id);
                }
            }
            ("code", 1) if !orca => {
                let attrs = attributes(&x, &e)?;
                let get = |name: &str| attribute(&attrs, name);
                root.codes
                    .extend(code(part, line, ("code", "print_z"), &get, warnings)?);
            }
            ("layer", _) if orca && (open.len() == 1 || in_plate) => {
                let attrs = attributes(&x, &e)?;
                let get = |name: &str| attribute(&attrs, name);
                let read = code(part, line, ("layer", "top_z"), &get, warnings)?;
                target(&mut plates, &mut root, in_plate).codes.extend(read);
            }
            _ => {}
        }
        if !empty {
            open.push(name);
        }
    }
    let chosen = if orca && !plates.is_empty() {
        // As OrcaSlicer reads them: plates by their id, the root's own layers unread.
        let mut plates: Vec<Plate> = plates.into_iter().filter(|p| p.id.is_some()).collect();
        plates.sort_by_key(|p| p.id);
        let first = plates.iter().position(|p| !p.codes.is_empty()).unwrap_or(0);
        for p in plates
            .iter()
            .skip(first + 1)
            .filter(|p| !p.codes.is_empty())
        {
            warnings.push(format!(
                "{part}: the {} custom G-code event(s) of plate {} are left out: conduit prints \
                 the project's objects as one plate, with the events of plate {}",
                p.codes.len(),
                p.id.unwrap_or_default(),
                plates[first].id.unwrap_or_default()
            ));
        }
        if plates.is_empty() {
            Plate::default()
        } else {
            plates.swap_remove(first)
        }
    } else {
        root
    };
    Ok(CustomGcodes {
        part: part.to_owned(),
        plate: chosen.id.filter(|_| orca),
        mode: chosen.mode,
        codes: chosen.codes,
    })
}

/// Where an element read belongs: the plate open, when it is inside one, else the root's.
fn target<'a>(plates: &'a mut [Plate], root: &'a mut Plate, in_plate: bool) -> &'a mut Plate {
    match plates.last_mut().filter(|_| in_plate) {
        Some(plate) => plate,
        None => root,
    }
}

/// One event: an `element` (`code` or `layer`) whose height is the attribute `height`, with
/// attributes `get`; `None` (with a warning) for a type not known.
fn code<'a>(
    part: &str,
    line: usize,
    (element, height): (&str, &str),
    get: &dyn Fn(&str) -> Option<&'a str>,
    warnings: &mut Vec<String>,
) -> Result<Option<CustomGcode>, ThreeMfError> {
    let z = get(height).ok_or_else(|| error(part, line, format!("<{element}> has no {height}")))?;
    let print_z = z
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| {
            error(
                part,
                line,
                format!("<{element}> {height}={z:?} is not a height in mm"),
            )
        })?;
    let extruder = match get("extruder") {
        Some(_) => number(part, line, element, "extruder", get("extruder"))?,
        None => 0,
    };
    let color = get("color").unwrap_or_default().to_owned();
    let (kind, extra) = match get("type") {
        Some(t) => {
            let n = number(part, line, element, "type", Some(t))?;
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
    fn orcaslicer_events_are_read_from_the_first_plate_that_has_any() -> Result<(), ThreeMfError> {
        let xml = r##"<?xml version="1.0" encoding="utf-8"?>
<custom_gcodes_per_layer>
<plate>
<plate_info id="2"/>
<layer top_z="1.2" type="0" extruder="1" color="#00FF00" extra="" gcode="M600"/>
<mode value="SingleExtruder"/>
</plate>
<plate>
<plate_info id="1"/>
<layer top_z="0.6" type="1" extruder="1" color="" extra="Insert nuts" gcode="M601"/>
<layer top_z="2" type="0" extruder="1" color="#FF0000" extra="" gcode="M600"/>
<layer top_z="3" type="7" extruder="1" color="" extra="" gcode=""/>
<mode value="MultiAsSingle"/>
</plate>
<plate>
<layer top_z="9" type="4" extruder="1" color="" extra="G4 S1"/>
</plate>
<layer top_z="5" type="4" extruder="1" color="" extra="never"/>
</custom_gcodes_per_layer>
"##;
        let mut warnings = Vec::new();
        let c = read(ORCA_CUSTOM_GCODE_PART, xml.as_bytes(), &mut warnings)?;
        assert_eq!(
            (c.plate, c.mode.as_deref()),
            (Some(1), Some("MultiAsSingle"))
        );
        assert_eq!(c.writer(), "OrcaSlicer");
        let kinds: Vec<(f64, CustomGcodeKind, &str, &str, usize)> = c
            .codes
            .iter()
            .map(|c| {
                (
                    c.print_z,
                    c.kind,
                    c.color.as_str(),
                    c.extra.as_str(),
                    c.line,
                )
            })
            .collect();
        assert_eq!(
            kinds,
            vec![
                (0.6, CustomGcodeKind::PausePrint, "", "Insert nuts", 10),
                (2.0, CustomGcodeKind::ColorChange, "#FF0000", "", 11),
            ]
        );
        // The unknown type of plate 1, and plate 2's event; the plate without an id and the
        // root's own layer are not read, as in OrcaSlicer.
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert!(warnings[0].contains(":12: custom G-code of unknown type 7"));
        assert!(
            warnings[1].contains("the 1 custom G-code event(s) of plate 2 are left out")
                && warnings[1].contains("with the events of plate 1"),
            "{warnings:?}"
        );
        Ok(())
    }

    #[test]
    fn orcaslicer_events_without_plates_are_plate_1s() -> Result<(), ThreeMfError> {
        let xml = r##"<custom_gcodes_per_layer>
<layer top_z="1.5" type="3" extruder="1" color="" extra=""/>
<mode value="SingleExtruder"/>
</custom_gcodes_per_layer>"##;
        let c = read(ORCA_CUSTOM_GCODE_PART, xml.as_bytes(), &mut Vec::new())?;
        assert_eq!(
            (c.plate, c.mode.as_deref()),
            (Some(1), Some("SingleExtruder"))
        );
        assert_eq!(c.codes.len(), 1);
        assert_eq!(
            (c.codes[0].print_z, c.codes[0].kind),
            (1.5, CustomGcodeKind::Template)
        );
        let xml = "<custom_gcodes_per_layer><plate><plate_info id=\"x\"/></plate>\
                   </custom_gcodes_per_layer>";
        let e = read(ORCA_CUSTOM_GCODE_PART, xml.as_bytes(), &mut Vec::new());
        let msg = e.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(
            msg.contains("<plate_info> id=\"x\" is not a whole number"),
            "{msg}"
        );
        let xml = "<custom_gcodes_per_layer><plate><plate_info id=\"1\"/>\n<layer type=\"0\"/>\
                   </plate></custom_gcodes_per_layer>";
        let e = read(ORCA_CUSTOM_GCODE_PART, xml.as_bytes(), &mut Vec::new());
        let msg = e.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(
            msg.contains(":2:") && msg.contains("<layer> has no top_z"),
            "{msg}"
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
