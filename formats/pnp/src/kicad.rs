//! KiCad position CSV, as pcbnew's "Generate Placement Files" writes it in CSV mode
//! (`pcbnew/exporters/place_file_exporter.cpp`): a `Ref,Val,Package,PosX,PosY,Rot,Side` header,
//! the three text fields in double quotes, bare numbers, and `top` / `bottom`.
//!
//! Differences from KiCad's own output: numbers have 4 decimals (KiCad prints `%f`, 6), the
//! rotation is in `[0, 360)` (KiCad prints -180..180), a trailing `PosZ` column is added, and a
//! `"` inside a text field is doubled as RFC 4180 says (KiCad writes it unescaped).

use std::io;

use crate::{PlacementRecord, PnpError, Side, fixed4, normalized_rotation, parse_finite};

/// KiCad's columns, then conduit's `PosZ`.
const COLUMNS: [&str; 8] = [
    "Ref", "Val", "Package", "PosX", "PosY", "Rot", "Side", "PosZ",
];

/// Writes `records`, in the given order, as a KiCad position CSV with a trailing `PosZ` column.
///
/// # Errors
/// [`io::ErrorKind::InvalidInput`] if a coordinate or rotation is NaN or infinite (nothing is
/// written then), or any error of `out`.
pub fn write_kicad_pos(records: &[PlacementRecord], out: &mut impl io::Write) -> io::Result<()> {
    let mut text = COLUMNS.join(",");
    text.push('\n');
    for r in records {
        let side = match r.side {
            Side::Top => "top",
            Side::Bottom => "bottom",
        };
        text += &format!(
            "{},{},{},{},{},{},{side},{}\n",
            quote(&r.reference),
            quote(&r.value),
            quote(&r.package),
            fixed4(r.x)?,
            fixed4(r.y)?,
            fixed4(normalized_rotation(r.rotation_deg))?,
            fixed4(r.z)?,
        );
    }
    out.write_all(text.as_bytes())
}

/// `"s"` with inner quotes doubled.
fn quote(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "\"\""))
}

/// Reads a KiCad position CSV: conduit's (with `PosZ`) or KiCad's own (`z` is then 0).
///
/// Fields may be quoted or bare; quoted fields may hold `,`, doubled `""` and line breaks.
/// Blank lines are skipped, `\r\n` is accepted. Rotations are returned as written.
///
/// # Errors
/// A [`PnpError`] `Csv*` variant naming the line of the first bad row.
pub fn read_kicad_pos(text: &str) -> Result<Vec<PlacementRecord>, PnpError> {
    let mut rows = split_rows(text.strip_prefix('\u{feff}').unwrap_or(text))?.into_iter();
    let (line, header) = rows.next().unwrap_or((1, Vec::new()));
    let width = header.len();
    if !(width == 7 || width == 8) || header.iter().zip(COLUMNS).any(|(h, c)| h.trim() != c) {
        let found = header.join(",");
        return Err(PnpError::CsvHeader { line, found });
    }
    rows.map(|(line, f)| {
        if f.len() != width {
            return Err(PnpError::CsvFieldCount {
                line,
                expected: width,
                found: f.len(),
            });
        }
        let bad = |i: usize| PnpError::CsvValue {
            line,
            column: COLUMNS[i],
            value: f[i].clone(),
        };
        let num = |i: usize| parse_finite(&f[i]).ok_or_else(|| bad(i));
        let side = match f[6].trim() {
            "top" => Side::Top,
            "bottom" => Side::Bottom,
            _ => return Err(bad(6)),
        };
        Ok(PlacementRecord {
            reference: f[0].clone(),
            value: f[1].clone(),
            package: f[2].clone(),
            x: num(3)?,
            y: num(4)?,
            z: if width == 8 { num(7)? } else { 0.0 },
            rotation_deg: num(5)?,
            side,
        })
    })
    .collect()
}

/// Splits CSV text into rows of unquoted fields, each with the line where it starts.
fn split_rows(text: &str) -> Result<Vec<(usize, Vec<String>)>, PnpError> {
    let mut rows = Vec::new();
    let (mut fields, mut field) = (Vec::new(), String::new());
    let (mut line, mut start, mut quoted) = (1, 1, false);
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            (true, '"') => quoted = false,
            (false, '"') => quoted = true,
            (false, ',') => fields.push(std::mem::take(&mut field)),
            (false, '\r') if chars.peek() == Some(&'\n') => {}
            (false, '\n') => {
                fields.push(std::mem::take(&mut field));
                rows.push((start, std::mem::take(&mut fields)));
                line += 1;
                start = line;
            }
            (_, c) => {
                line += usize::from(c == '\n');
                field.push(c);
            }
        }
    }
    if quoted {
        return Err(PnpError::CsvUnclosedQuote { line: start });
    }
    if !field.is_empty() || !fields.is_empty() {
        fields.push(field);
        rows.push((start, fields));
    }
    rows.retain(|(_, f)| !(f.len() == 1 && f[0].trim().is_empty()));
    Ok(rows)
}
