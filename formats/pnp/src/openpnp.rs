//! OpenPnP board file (`*.board.xml`), as OpenPnP's Simple-XML model classes serialise it:
//! `Board` (`@Root(name = "openpnp-board")`, version 1.1) holds `<placements>`, each
//! `Placement` (version 1.4) has the attributes `id`, `side` (`Top`/`Bottom`), `part-id`,
//! `type` (`Placement`/`Fiducial`) and `enabled`, and one `<location units=".." x y z rotation>`.
//!
//! OpenPnP stores no value or package, only a part id. The writer uses `PACKAGE-VALUE`, like
//! OpenPnP's KiCad importer; the reader splits the part id at its last `-`, so a value that
//! itself contains `-` comes back split differently (compare [`PlacementRecord::part_id`]).

use std::io;

use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};

use crate::{Lines, PlacementRecord, PnpError, Side, fixed4, normalized_rotation, parse_finite};

/// Writes an OpenPnP board named `name` holding `records` in the given order, all of type
/// `Placement`, with locations in millimetres: `enabled="false"` for records the machine does
/// not place, and before each placement a comment with the part's height (OpenPnP keeps
/// heights on its parts, not on the board, so the comment is for whoever sets those up).
///
/// # Errors
/// [`io::ErrorKind::InvalidInput`] if a number is NaN or infinite or a string holds a control
/// character XML 1.0 cannot represent (nothing is written then), or any error of `out`.
pub fn write_openpnp_board(
    name: &str,
    records: &[PlacementRecord],
    out: &mut impl io::Write,
) -> io::Result<()> {
    let mut text = format!("<openpnp-board version=\"1.1\" name=\"{}\">\n", attr(name)?);
    text.push_str(
        "   <!-- Locations are in the printer's bed coordinates, mm: put the board at X 0, Y 0, \
         Z 0, rotation 0 in the job. z is each part's seating plane (0 on a flat board, higher \
         inside a printed object). -->\n",
    );
    text.push_str("   <placements>\n");
    for r in records {
        let side = match r.side {
            Side::Top => "Top",
            Side::Bottom => "Bottom",
        };
        text += &format!(
            "      <!-- {}: height {} mm -->\n",
            comment(&r.reference),
            fixed4(r.height)?
        );
        text += &format!(
            "      <placement version=\"1.4\" id=\"{}\" side=\"{side}\" part-id=\"{}\" \
             type=\"Placement\" enabled=\"{}\">\n         <location units=\"Millimeters\" \
             x=\"{}\" y=\"{}\" z=\"{}\" rotation=\"{}\"/>\n      </placement>\n",
            attr(&r.reference)?,
            attr(&r.part_id())?,
            r.enabled,
            fixed4(r.x)?,
            fixed4(r.y)?,
            fixed4(r.z)?,
            fixed4(normalized_rotation(r.rotation_deg))?,
        );
    }
    text.push_str("   </placements>\n</openpnp-board>\n");
    out.write_all(text.as_bytes())
}

/// `s` escaped for a double-quoted attribute value. Tab and line breaks become character
/// references, since an XML reader turns literal ones into spaces.
fn attr(s: &str) -> io::Result<String> {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\t' | '\n' | '\r' => out += &format!("&#{};", u32::from(c)),
            '\0'..='\u{1f}' | '\u{fffe}' | '\u{ffff}' => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!("character {c:?} in {s:?} cannot be written in XML 1.0"),
                ));
            }
            c => out.push(c),
        }
    }
    Ok(out)
}

/// `s` made safe inside an XML comment (no `--`, no control characters).
fn comment(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { '?' } else { c })
        .collect::<String>()
        .replace("--", "- -")
}

/// A `<placement>` whose end tag has not been read yet.
struct Open {
    attrs: Vec<(String, String)>,
    line: usize,
    location: Option<(Vec<(String, String)>, usize)>,
}

/// Reads the placements of an OpenPnP board file, in file order, converting lengths to mm.
///
/// Fiducials (`type="Fiducial"`) are skipped; placements OpenPnP would not place (the pre-1.4
/// `type="Ignore"`, or `enabled="false"`) are returned with `enabled` false. Heights are 0
/// (the board has none). Other children of the board are ignored.
///
/// # Errors
/// [`PnpError::Xml`] with the line for malformed XML, [`PnpError::NotABoard`], or an error
/// naming the `<placement>` or `<location>` element and its line.
pub fn read_openpnp_board(text: &str) -> Result<Vec<PlacementRecord>, PnpError> {
    let mut reader = quick_xml::Reader::from_str(text);
    let lines = Lines::new(text);
    let mut path: Vec<String> = Vec::new();
    let mut open: Option<Open> = None;
    let mut records = Vec::new();
    let mut saw_root = false;
    loop {
        let before = reader.buffer_position();
        let event = reader.read_event().map_err(|source| PnpError::Xml {
            line: lines.of(reader.error_position()),
            source,
        })?;
        let (start, empty) = match event {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                if path.len() == 3 {
                    finish(open.take(), &mut records)?;
                }
                path.pop();
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let line = lines.of(before);
        let name = start.name().as_ref().to_owned();
        let xml_err = |source| PnpError::Xml { line, source };
        match path.iter().map(String::as_str).collect::<Vec<_>>()[..] {
            [] if name != "openpnp-board" => return Err(PnpError::NotABoard { found: name }),
            [] => saw_root = true,
            ["openpnp-board", "placements"] if name == "placement" => {
                let attrs = attributes(&start).map_err(xml_err)?;
                open = Some(Open {
                    attrs,
                    line,
                    location: None,
                });
            }
            ["openpnp-board", "placements", "placement"] if name == "location" => {
                if let Some(p) = open.as_mut() {
                    p.location = Some((attributes(&start).map_err(xml_err)?, line));
                }
            }
            _ => {}
        }
        if !empty {
            path.push(name);
        } else if path.len() == 2 {
            finish(open.take(), &mut records)?;
        }
    }
    match path.pop() {
        Some(element) => Err(PnpError::UnexpectedEof { element }),
        None if !saw_root => Err(PnpError::NotABoard {
            found: String::new(),
        }),
        None => Ok(records),
    }
}

fn attributes(e: &BytesStart<'_>) -> Result<Vec<(String, String)>, quick_xml::Error> {
    e.attributes()
        .map(|a| {
            let a = a.map_err(quick_xml::Error::InvalidAttr)?;
            let value = a.normalized_value(XmlVersion::Implicit1_0)?.into_owned();
            Ok((a.key.as_ref().to_owned(), value))
        })
        .collect()
}

fn get<'a>(attrs: &'a [(String, String)], key: &str) -> Option<&'a str> {
    attrs
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

/// Turns a finished `<placement>` into a record, unless it is a fiducial.
fn finish(open: Option<Open>, records: &mut Vec<PlacementRecord>) -> Result<(), PnpError> {
    let Some(Open {
        attrs,
        line,
        location,
    }) = open
    else {
        return Ok(());
    };
    let id = get(&attrs, "id").ok_or(PnpError::Missing {
        element: "placement".into(),
        line,
        missing: "attribute `id`",
    })?;
    let element = format!("placement id=\"{id}\"");
    let missing = |missing| PnpError::Missing {
        element: element.clone(),
        line,
        missing,
    };
    let invalid = |attribute, value: &str| PnpError::InvalidAttribute {
        element: element.clone(),
        line,
        attribute,
        value: value.to_owned(),
    };
    let side = match get(&attrs, "side").ok_or_else(|| missing("attribute `side`"))? {
        "Top" => Side::Top,
        "Bottom" => Side::Bottom,
        other => return Err(invalid("side", other)),
    };
    let skipped = get(&attrs, "type") == Some("Fiducial");
    let enabled = get(&attrs, "type") != Some("Ignore")
        && !get(&attrs, "enabled").is_some_and(|v| v.eq_ignore_ascii_case("false"));
    let (loc, loc_line) = location.ok_or_else(|| missing("<location>"))?;
    if skipped {
        return Ok(());
    }
    let element = format!("location of {id}");
    let invalid = |attribute, value: &str| PnpError::InvalidAttribute {
        element: element.clone(),
        line: loc_line,
        attribute,
        value: value.to_owned(),
    };
    let units = get(&loc, "units").ok_or_else(|| PnpError::Missing {
        element: element.clone(),
        line: loc_line,
        missing: "attribute `units`",
    })?;
    // OpenPnP's `LengthUnit` names.
    let mm = match units {
        "Millimeters" => 1.0,
        "Centimeters" => 10.0,
        "Meters" => 1000.0,
        "Inches" => 25.4,
        "Feet" => 304.8,
        other => return Err(invalid("units", other)),
    };
    // Location's numbers are optional and default to 0.
    let num = |key| match get(&loc, key) {
        None => Ok(0.0),
        Some(v) => parse_finite(v).ok_or_else(|| invalid(key, v)),
    };
    let (package, value) = match get(&attrs, "part-id").unwrap_or("").rsplit_once('-') {
        Some((p, v)) => (p.to_owned(), v.to_owned()),
        None => (
            get(&attrs, "part-id").unwrap_or("").to_owned(),
            String::new(),
        ),
    };
    records.push(PlacementRecord {
        reference: id.to_owned(),
        value,
        package,
        x: num("x")? * mm,
        y: num("y")? * mm,
        z: num("z")? * mm,
        rotation_deg: num("rotation")?,
        side,
        enabled,
        height: 0.0,
    });
    Ok(())
}
