//! KiCad position files, as pcbnew's "Generate Placement Files" writes them
//! (`pcbnew/exporters/place_file_exporter.cpp`), in its two layouts:
//!
//! - **ASCII** (`NAME.pos`, the layout OpenPnP's "KiCAD .pos" importer reads): `#` header
//!   comments, `## Unit = mm, Angle = deg.`, `## Side : top|bottom|All`, the
//!   `# Ref  Val  Package  PosX  PosY  Rot  Side` header, one row per footprint with the text
//!   columns left-aligned to the longest entry (at least 8, 8 and 16 characters; spaces inside
//!   them become `_`, an empty one `~`), the numbers right-aligned as `%9.4f  %9.4f  %8.4f`, and `## End`.
//! - **CSV** (`NAME-pos.csv`): a `Ref,Val,Package,PosX,PosY,Rot,Side` header, the three text
//!   fields in double quotes, the numbers as `%f` (6 decimals), and `top` / `bottom`.
//!
//! Both list the top side first, then the bottom, each in KiCad's natural order of references
//! (`R2` before `R10`), with rotations in (-180, 180] as KiCad keeps footprint orientations.
//! Records the machine does not place (`enabled` false) are left out, as KiCad leaves out
//! footprints excluded from position files: neither layout can mark a row disabled. Where
//! conduit departs from pcbnew: the first two comment lines name conduit instead of a date and
//! KiCad version (the files are deterministic), and a `"` inside a CSV text field is doubled
//! as RFC 4180 says (KiCad writes it unescaped). Neither layout has a height: the seating
//! plane's z is in the OpenPnP board file and the slice report.

use std::cmp::Ordering;
use std::io;

use crate::{PlacementRecord, PnpError, Side, fixed, parse_finite};

/// KiCad's CSV columns, and conduit's former trailing `PosZ`, which the reader still takes.
const COLUMNS: [&str; 8] = [
    "Ref", "Val", "Package", "PosX", "PosY", "Rot", "Side", "PosZ",
];

/// The records KiCad would list, in its order: enabled ones, top side first, then natural
/// order of references.
fn listed(records: &[PlacementRecord]) -> Vec<&PlacementRecord> {
    let mut list: Vec<&PlacementRecord> = records.iter().filter(|r| r.enabled).collect();
    list.sort_by(|a, b| {
        let side = |r: &PlacementRecord| u8::from(r.side == Side::Bottom);
        side(a)
            .cmp(&side(b))
            .then_with(|| natural_cmp(&a.reference, &b.reference))
    });
    list
}

/// KiCad's `StrNumCmp`: runs of digits compare as numbers, everything else character by
/// character.
fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (mut a, mut b) = (a.chars().peekable(), b.chars().peekable());
    loop {
        match (a.peek().copied(), b.peek().copied()) {
            (None, None) => return Ordering::Equal,
            (None, Some(_)) => return Ordering::Less,
            (Some(_), None) => return Ordering::Greater,
            (Some(x), Some(y)) if x.is_ascii_digit() && y.is_ascii_digit() => {
                let run = |it: &mut std::iter::Peekable<std::str::Chars<'_>>| {
                    let mut digits = String::new();
                    while let Some(c) = it.next_if(char::is_ascii_digit) {
                        digits.push(c);
                    }
                    digits
                };
                let (x, y) = (run(&mut a), run(&mut b));
                let (tx, ty) = (x.trim_start_matches('0'), y.trim_start_matches('0'));
                let by_value = tx.len().cmp(&ty.len()).then_with(|| tx.cmp(ty));
                if by_value != Ordering::Equal {
                    return by_value;
                }
            }
            (Some(x), Some(y)) => {
                if x != y {
                    return x.cmp(&y);
                }
                a.next();
                b.next();
            }
        }
    }
}

/// `deg` in (-180, 180] after rounding to 6 decimals.
fn rotation_180(deg: f64) -> f64 {
    let r = deg.rem_euclid(360.0);
    let r = if (r * 1e6).round() >= 360.0 * 1e6 {
        0.0
    } else {
        r
    };
    if r > 180.0 { r - 360.0 } else { r }
}

/// `top` or `bottom`, KiCad's side names.
fn side_name(side: Side) -> &'static str {
    match side {
        Side::Top => "top",
        Side::Bottom => "bottom",
    }
}

/// Writes the records the machine places as KiCad's ASCII position file (`NAME.pos`).
///
/// # Errors
/// [`io::ErrorKind::InvalidInput`] if a coordinate or rotation is NaN or infinite (nothing is
/// written then), or any error of `out`.
pub fn write_kicad_ascii(records: &[PlacementRecord], out: &mut impl io::Write) -> io::Result<()> {
    let list = listed(records);
    // An empty column would shift the importer's columns (its pattern reads the package as the
    // value), so it is written `~`, KiCad's old placeholder for an empty field.
    let column = |r: &&PlacementRecord, f: fn(&PlacementRecord) -> &str| match f(r) {
        "" => "~".to_owned(),
        s => s.replace(char::is_whitespace, "_"),
    };
    let rows: Vec<[String; 3]> = list
        .iter()
        .map(|r| {
            [
                column(r, |r| &r.reference),
                column(r, |r| &r.value),
                column(r, |r| &r.package),
            ]
        })
        .collect();
    let width = |i: usize, min: usize| {
        rows.iter()
            .map(|r| r[i].chars().count())
            .fold(min, usize::max)
    };
    let (wr, wv, wp) = (width(0, 8), width(1, 8), width(2, 16));
    let sides = match (
        list.iter().any(|r| r.side == Side::Top),
        list.iter().any(|r| r.side == Side::Bottom),
    ) {
        (true, true) => "All",
        (false, true) => "bottom",
        _ => "top",
    };
    let mut text = format!(
        "### Footprint positions - created by conduit ###\n\
         ### Printed by conduit version {}\n\
         ## Unit = mm, Angle = deg.\n\
         ## Side : {sides}\n",
        env!("CARGO_PKG_VERSION")
    );
    text += &format!(
        "{:<wr$}  {:<wv$}  {:<wp$}  {:>9}  {:>9}  {:>8}  Side\n",
        "# Ref", "Val", "Package", "PosX", "PosY", "Rot"
    );
    for (r, [reference, value, package]) in list.iter().zip(&rows) {
        text += &format!(
            "{reference:<wr$}  {value:<wv$}  {package:<wp$}  {:>9}  {:>9}  {:>8}  {}\n",
            fixed(r.x, 4)?,
            fixed(r.y, 4)?,
            fixed(rotation_180(r.rotation_deg), 4)?,
            side_name(r.side)
        );
    }
    text.push_str("## End\n");
    out.write_all(text.as_bytes())
}

/// Writes the records the machine places as KiCad's CSV position file (`NAME-pos.csv`).
///
/// # Errors
/// [`io::ErrorKind::InvalidInput`] if a coordinate or rotation is NaN or infinite (nothing is
/// written then), or any error of `out`.
pub fn write_kicad_csv(records: &[PlacementRecord], out: &mut impl io::Write) -> io::Result<()> {
    let mut text = COLUMNS[..7].join(",");
    text.push('\n');
    for r in listed(records) {
        text += &format!(
            "{},{},{},{},{},{},{}\n",
            quote(&r.reference),
            quote(&r.value),
            quote(&r.package),
            fixed(r.x, 6)?,
            fixed(r.y, 6)?,
            fixed(rotation_180(r.rotation_deg), 6)?,
            side_name(r.side)
        );
    }
    out.write_all(text.as_bytes())
}

/// `"s"` with inner quotes doubled.
fn quote(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "\"\""))
}

/// Reads KiCad's ASCII position file row by row as OpenPnP's "KiCAD .pos" importer does:
/// lines that are empty or start with `#` (after trimming) are skipped, and every other line
/// must match, as a whole, `(\S+)\s+(.*?)\s+(.*?)\s+(-?\d+\.\d+)\s+(-?\d+\.\d+)\s+(-?\d+\.\d+)\s(.*?)`
/// (reference, value, package, x, y, rotation, side). The side column must be `top` or
/// `bottom` (KiCad's names; OpenPnP takes the side from which file it was given). `z` is 0,
/// records are enabled, heights 0.
///
/// # Errors
/// [`PnpError::PosRow`] naming the first line that does not match.
pub fn read_kicad_ascii(text: &str) -> Result<Vec<PlacementRecord>, PnpError> {
    // The importer's pattern, anchored because Java's `Matcher.matches` matches the whole line.
    let row = regex::Regex::new(
        r"^(\S+)\s+(.*?)\s+(.*?)\s+(-?\d+\.\d+)\s+(-?\d+\.\d+)\s+(-?\d+\.\d+)\s(.*?)$",
    )
    .map_err(|e| PnpError::Pattern(e.to_string()))?;
    let mut records = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = || PnpError::PosRow {
            line: i + 1,
            found: line.chars().take(80).collect(),
        };
        let caps = row.captures(line).ok_or_else(bad)?;
        let group = |k: usize| caps.get(k).map_or("", |m| m.as_str());
        let num = |k: usize| parse_finite(group(k)).ok_or_else(bad);
        let side = match group(7).trim() {
            "top" => Side::Top,
            "bottom" => Side::Bottom,
            _ => return Err(bad()),
        };
        records.push(PlacementRecord {
            reference: group(1).to_owned(),
            value: group(2).to_owned(),
            package: group(3).to_owned(),
            x: num(4)?,
            y: num(5)?,
            z: 0.0,
            rotation_deg: num(6)?,
            side,
            enabled: true,
            height: 0.0,
        });
    }
    Ok(records)
}

/// Reads a KiCad position CSV: KiCad's own, or conduit's former layout with a trailing `PosZ`
/// column (`z` is 0 without it). Records are enabled, heights 0.
///
/// Fields may be quoted or bare; quoted fields may hold `,`, doubled `""` and line breaks.
/// Blank lines are skipped, `\r\n` is accepted. Rotations are returned as written.
///
/// # Errors
/// A [`PnpError`] `Csv*` variant naming the line of the first bad row.
pub fn read_kicad_csv(text: &str) -> Result<Vec<PlacementRecord>, PnpError> {
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
            enabled: true,
            height: 0.0,
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
