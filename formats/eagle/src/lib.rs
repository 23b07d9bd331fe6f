//! EAGLE 6-9 schematic (`.sch`) and board (`.brd`) reader.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the
//! pipeline. The pipeline builds its `Circuit` from the [`Schematic`] (parts, packages, pads and
//! nets) and/or the [`Board`] (element positions, signals, outline).
//!
//! What the reader does:
//! - resolves every part through the embedded `<libraries>` to its device and package, keeping
//!   the pin-to-pad map (`<connect pad="1 3">` puts one pin on several pads);
//! - drops parts without a package (supply symbols, frames) into
//!   [`Schematic::dropped_parts`];
//! - resolves schematic nets (`<pinref>`) to `(part, pad)`, merging same-named nets across
//!   sheets and wiring `pwr` pins that no net touches to the net named after the pin, as EAGLE
//!   does;
//! - flattens EAGLE 9 hierarchical designs (`<modules>`, `<moduleinst>`, `<portref>`), naming
//!   module parts `INSTANCE:PART` like EAGLE's board (see [`Part::name`]);
//! - reads board elements with their placement, signals (`<contactref>`) and the outline
//!   (Dimension layer).
//!
//! Units are EAGLE's: EAGLE XML always stores millimetres, and angles in degrees.
//! Binary files from EAGLE 5 and older are recognised and rejected with
//! [`EagleError::BinaryFormat`]. No input makes the reader panic; hostile inputs are bounded
//! (element nesting deeper than 256 levels, or module hierarchies expanding to more than
//! 100 000 instances, are errors).
//!
//! To check a schematic against its board, compare the two netlists with
//! [`NetlistComparison`], which matches connected pad sets and ignores net names.
//!
//! ```
//! let sch = br#"<?xml version="1.0"?>
//! <eagle version="9.6.2"><drawing><schematic>
//!  <libraries><library name="L">
//!   <packages><package name="P"><smd name="1" x="0" y="0" dx="1" dy="1" layer="1"/>
//!    <smd name="2" x="2" y="0" dx="1" dy="1" layer="1"/></package></packages>
//!   <symbols><symbol name="S"><pin name="A" x="0" y="0"/><pin name="B" x="0" y="0"/></symbol></symbols>
//!   <devicesets><deviceset name="R"><gates><gate name="G$1" symbol="S" x="0" y="0"/></gates>
//!    <devices><device name="" package="P"><connects>
//!     <connect gate="G$1" pin="A" pad="1"/><connect gate="G$1" pin="B" pad="2"/>
//!    </connects></device></devices></deviceset></devicesets>
//!  </library></libraries>
//!  <parts><part name="R1" library="L" deviceset="R" device=""/>
//!   <part name="R2" library="L" deviceset="R" device=""/></parts>
//!  <sheets><sheet><nets><net name="N$1" class="0"><segment>
//!   <pinref part="R1" gate="G$1" pin="B"/><pinref part="R2" gate="G$1" pin="A"/>
//!  </segment></net></nets></sheet></sheets>
//! </schematic></drawing></eagle>"#;
//! let s = conduit_eagle::read_schematic(sch)?;
//! assert_eq!(s.parts.len(), 2);
//! let pads: Vec<_> = s.netlist()["N$1"].iter().cloned().collect();
//! assert_eq!(pads, [("R1".to_string(), "2".to_string()), ("R2".to_string(), "1".to_string())]);
//! # Ok::<(), conduit_eagle::EagleError>(())
//! ```

mod board;
mod doc;
mod error;
mod library;
mod netlist;
mod rotation;
mod schematic;

pub use board::{Board, Element, OutlineSegment, SignalWire};
pub use error::EagleError;
pub use library::{LAYER_BOTTOM, LAYER_DIMENSION, LAYER_PADS, LAYER_TOP, Package, Pad, PadShape};
pub use netlist::{Net, Netlist, NetlistComparison};
pub use rotation::Rotation;
pub use schematic::{Part, Schematic};

/// What an EAGLE XML file contains.
#[derive(Debug, Clone, PartialEq)]
pub enum Document {
    /// A schematic (`.sch`).
    Schematic(Schematic),
    /// A board (`.brd`).
    Board(Board),
    /// A library (`.lbr`); its contents are not read.
    Library,
}

/// True when `bytes` look like a binary EAGLE file (EAGLE 5 and older): those start with
/// `0x10` followed by `0x80` (EAGLE 4-5) or `0x00` (older).
pub fn is_binary_eagle(bytes: &[u8]) -> bool {
    matches!(bytes, [0x10, 0x80 | 0x00, ..])
}

/// Reads an EAGLE 6-9 XML schematic or board.
///
/// # Errors
/// [`EagleError::BinaryFormat`] for pre-6.0 binary files, [`EagleError::NotUtf8`],
/// [`EagleError::Xml`] or [`EagleError::NotEagle`] for anything that is not EAGLE XML, and the
/// reference errors of [`EagleError`] for inconsistent files.
pub fn read(bytes: &[u8]) -> Result<Document, EagleError> {
    if is_binary_eagle(bytes) {
        return Err(EagleError::BinaryFormat);
    }
    let doc = doc::parse(bytes)?;
    let root = &doc.root;
    if root.name != "eagle" {
        return Err(EagleError::NotEagle {
            found: root.name.clone(),
        });
    }
    let version = root.attr("version").unwrap_or_default().to_owned();
    let drawing = root.child("drawing").ok_or_else(|| EagleError::NotEagle {
        found: "eagle".to_owned(),
    })?;
    for c in &drawing.children {
        match c.name.as_str() {
            "schematic" => return schematic::read(&doc, version, c).map(Document::Schematic),
            "board" => return board::read(&doc, version, c).map(Document::Board),
            "library" => return Ok(Document::Library),
            _ => {}
        }
    }
    Err(EagleError::NotEagle {
        found: "drawing".to_owned(),
    })
}

fn kind(d: &Document) -> &'static str {
    match d {
        Document::Schematic(_) => "schematic",
        Document::Board(_) => "board",
        Document::Library => "library",
    }
}

/// Reads an EAGLE schematic; any other EAGLE file is [`EagleError::WrongKind`].
pub fn read_schematic(bytes: &[u8]) -> Result<Schematic, EagleError> {
    match read(bytes)? {
        Document::Schematic(s) => Ok(s),
        other => Err(EagleError::WrongKind {
            expected: "schematic",
            found: kind(&other),
        }),
    }
}

/// Reads an EAGLE board; any other EAGLE file is [`EagleError::WrongKind`].
pub fn read_board(bytes: &[u8]) -> Result<Board, EagleError> {
    match read(bytes)? {
        Document::Board(b) => Ok(b),
        other => Err(EagleError::WrongKind {
            expected: "board",
            found: kind(&other),
        }),
    }
}

#[cfg(test)]
mod tests;
