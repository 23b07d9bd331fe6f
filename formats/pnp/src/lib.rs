//! Pick-and-place files: KiCad position files (ASCII and CSV) and OpenPnP board XML.
//!
//! Part of conduit's `formats/` layer, used by the emit stage: beside the G-code, the pipeline
//! writes where each component goes, so that the vacuum nozzle (or an assembly house) can place
//! it. The crate only describes the files and has no dependency on the pipeline.
//!
//! - [`write_kicad_ascii`] / [`read_kicad_ascii`]: KiCad's "Generate Placement Files" ASCII
//!   table (`NAME.pos`), the file OpenPnP's KiCad importer reads; the reader follows that
//!   importer's row pattern.
//! - [`write_kicad_csv`] / [`read_kicad_csv`]: the same in KiCad's CSV layout
//!   (`NAME-pos.csv`, `Ref,Val,Package,PosX,PosY,Rot,Side`).
//! - [`octopnp::read_block`]: OctoPNP's part description in a G-code file's comments.
//! - [`write_openpnp_board`] / [`read_openpnp_board`]: an OpenPnP `NAME.board.xml`
//!   (`<openpnp-board version="1.1">`, placements version 1.4), parts the machine does not
//!   place marked `enabled="false"`, each part's height in a comment.
//!
//! Output is deterministic (same records, same bytes): `\n` line endings, numbers with fixed
//! decimals in millimetres or degrees. Writers refuse NaN and infinite numbers with
//! [`std::io::ErrorKind::InvalidInput`]; readers never panic.
//!
//! ```
//! use conduit_pnp::{PlacementRecord, Side};
//! let r = PlacementRecord {
//!     reference: "R1".into(), value: "10k".into(), package: "R_0603".into(),
//!     x: 12.5, y: -3.0, z: 1.2, rotation_deg: 270.0, side: Side::Top,
//!     enabled: true, height: 0.6,
//! };
//! let mut csv = Vec::new();
//! conduit_pnp::write_kicad_csv(&[r], &mut csv)?;
//! assert_eq!(
//!     String::from_utf8_lossy(&csv),
//!     "Ref,Val,Package,PosX,PosY,Rot,Side\n\
//!      \"R1\",\"10k\",\"R_0603\",12.500000,-3.000000,-90.000000,top\n"
//! );
//! # Ok::<(), std::io::Error>(())
//! ```

mod kicad;
pub mod octopnp;
mod openpnp;
#[cfg(test)]
mod tests;

pub use kicad::{read_kicad_ascii, read_kicad_csv, write_kicad_ascii, write_kicad_csv};
pub use openpnp::{read_openpnp_board, write_openpnp_board};

use std::io;

/// One component placement, in millimetres and degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementRecord {
    /// Reference designator, e.g. `R1`.
    pub reference: String,
    /// Component value, e.g. `10k`.
    pub value: String,
    /// Package (footprint) name, e.g. `R_0603`.
    pub package: String,
    /// X of the component centre, mm.
    pub x: f64,
    /// Y of the component centre, mm (Y up, as in KiCad's placement files).
    pub y: f64,
    /// Z of the seating plane, mm (0 on a flat board; higher inside a printed object).
    pub z: f64,
    /// Rotation about Z, degrees counter-clockwise.
    pub rotation_deg: f64,
    /// Board side the component sits on.
    pub side: Side,
    /// Whether the machine places it: false for parts inserted by hand or not at all, which
    /// the OpenPnP board marks `enabled="false"` and the KiCad files leave out.
    pub enabled: bool,
    /// Height of the part above its seating plane, mm (0 when unknown).
    pub height: f64,
}

impl PlacementRecord {
    /// OpenPnP part id, `PACKAGE-VALUE`, as OpenPnP's own KiCad importer builds it.
    pub fn part_id(&self) -> String {
        format!("{}-{}", self.package, self.value)
    }
}

/// Board side of a placement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    /// Top (front, `F.Cu`) side.
    Top,
    /// Bottom (back, `B.Cu`) side.
    Bottom,
}

/// Errors of the readers. CSV errors carry the 1-based line of the row; XML errors name the
/// element and the 1-based line of its start tag.
///
/// # How to fix
/// The file is not one these writers (or KiCad / OpenPnP) produced, or was edited by hand:
/// correct the named line or element, or export the file again.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PnpError {
    /// The first CSV row is not KiCad's header (with or without `PosZ`).
    #[error(
        "line {line}: expected header `Ref,Val,Package,PosX,PosY,Rot,Side[,PosZ]`, found `{found}`"
    )]
    CsvHeader {
        /// Line of the header row.
        line: usize,
        /// The header as found (fields joined with `,`).
        found: String,
    },
    /// A CSV row has a different number of fields than the header.
    #[error("line {line}: expected {expected} fields, found {found}")]
    CsvFieldCount {
        /// Line where the row starts.
        line: usize,
        /// Number of header columns.
        expected: usize,
        /// Number of fields in the row.
        found: usize,
    },
    /// A quoted CSV field is not closed before the end of the input.
    #[error("line {line}: quoted field is never closed")]
    CsvUnclosedQuote {
        /// Line where the row starts.
        line: usize,
    },
    /// A CSV field has a value that its column does not accept.
    #[error("line {line}: column {column}: invalid value `{value}`")]
    CsvValue {
        /// Line where the row starts.
        line: usize,
        /// Header name of the column.
        column: &'static str,
        /// The field as found.
        value: String,
    },
    /// A row of a KiCad ASCII position file does not match the importer's row pattern.
    #[error(
        "line {line}: not a position row (reference, value, package, x, y, rotation, side): `{found}`"
    )]
    PosRow {
        /// Line of the row.
        line: usize,
        /// The row as found (its first 80 characters).
        found: String,
    },
    /// The row pattern did not build (never expected: it is a constant).
    #[error("internal row pattern: {0}")]
    Pattern(String),
    /// The XML is not well formed.
    #[error("line {line}: XML error: {source}")]
    Xml {
        /// Line where the parser stopped.
        line: usize,
        /// The parser's error.
        #[source]
        source: quick_xml::Error,
    },
    /// The root element is not `<openpnp-board>`.
    #[error("not an OpenPnP board: root element is <{found}>, expected <openpnp-board>")]
    NotABoard {
        /// Name of the root element found (empty if there is none).
        found: String,
    },
    /// The input ends inside an element.
    #[error("unexpected end of file inside <{element}>")]
    UnexpectedEof {
        /// The innermost open element.
        element: String,
    },
    /// An element lacks a required attribute or child.
    #[error("line {line}: <{element}> has no {missing}")]
    Missing {
        /// The element, e.g. `placement id="R1"`.
        element: String,
        /// Line of its start tag.
        line: usize,
        /// What is missing, e.g. `attribute \`side\`` or `<location>`.
        missing: &'static str,
    },
    /// An attribute has a value that OpenPnP does not write.
    #[error("line {line}: <{element}>: attribute `{attribute}` has invalid value `{value}`")]
    InvalidAttribute {
        /// The element, e.g. `location of R1`.
        element: String,
        /// Line of its start tag.
        line: usize,
        /// Attribute name.
        attribute: &'static str,
        /// The value as found.
        value: String,
    },
}

/// Formats a length or angle with the crate's fixed 4 decimals, refusing NaN and infinities.
fn fixed4(v: f64) -> io::Result<String> {
    fixed(v, 4)
}

/// Formats a number with `decimals` decimals, refusing NaN and infinities; a value that
/// rounds to zero is written without a sign.
fn fixed(v: f64, decimals: usize) -> io::Result<String> {
    if !v.is_finite() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("cannot write non-finite number {v} to a placement file"),
        ));
    }
    let s = format!("{v:.decimals$}");
    // Values in (-0.00005, 0] round to "-0.0000"; write them as "0.0000".
    Ok(match s.strip_prefix('-') {
        Some(abs) if abs.bytes().all(|b| b == b'0' || b == b'.') => abs.to_owned(),
        _ => s,
    })
}

/// `deg` in `[0, 360)` after rounding to 4 decimals (so 359.99999 becomes 0, not 360).
fn normalized_rotation(deg: f64) -> f64 {
    let r = deg.rem_euclid(360.0);
    if (r * 1e4).round() >= 360.0 * 1e4 {
        0.0
    } else {
        r
    }
}

/// Parses a finite number (`NaN` and `inf`, which Rust would accept, are refused).
fn parse_finite(s: &str) -> Option<f64> {
    s.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Line numbers of byte offsets in one text: the offsets of its line breaks, found once, so that
/// a reader can ask for the line of every element without counting from the start each time.
struct Lines(Vec<usize>);

impl Lines {
    /// The line breaks of `text`.
    fn new(text: &str) -> Self {
        Lines(
            text.bytes()
                .enumerate()
                .filter(|(_, b)| *b == b'\n')
                .map(|(i, _)| i)
                .collect(),
        )
    }

    /// 1-based line of byte offset `pos` (offsets past the end count as the end).
    fn of(&self, pos: u64) -> usize {
        let pos = usize::try_from(pos).unwrap_or(usize::MAX);
        self.0.partition_point(|&nl| nl < pos) + 1
    }
}
