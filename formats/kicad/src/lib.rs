//! KiCad 6-9 board (`.kicad_pcb`), schematic (`.kicad_sch`) and netlist (`.net`) reader.
//!
//! Part of conduit's `formats/` layer: it describes the files and has no dependency on the
//! pipeline. The pipeline builds its `Circuit` from a [`Pcb`] (footprints, pads, nets,
//! outline), a [`Schematic`] (parts and the nets KiCad's connection graph gives) or a
//! [`NetFile`] (the schematic editor's netlist export).
//!
//! The reader works in three steps:
//! 1. [`sexpr`]: the bytes become a tree of lists, each with its line and column; the input is
//!    bounded ([`sexpr::MAX_BYTES`], lists nested at most [`sexpr::MAX_DEPTH`] deep);
//! 2. the tree becomes the file's structs (`pcb`, `netfile`, `sch` — sheet files read through a
//!    loader and instanced, at most [`MAX_SHEET_INSTANCES`]);
//! 3. for a schematic, `connect` netlists the sheet instances.
//!
//! The s-expression reader is this crate's own: KiCad's dialect is small (lists that start with
//! a keyword, bare atoms, quoted strings), and errors must name the line, column and keyword path
//! that general-purpose s-expression crates do not keep. Files from KiCad 6 (`(version 2021…)`)
//! to 9 are read: KiCad 7's quoted uuids and `(instances …)` inside symbols, KiCad 8's
//! `(property "Reference" …)` in footprints, `(hide yes)` and `(generator_version …)`.
//! No input makes the reader panic.
//!
//! ```
//! let pcb = br#"(kicad_pcb (version 20240108) (generator "pcbnew") (generator_version "8.0")
//!   (net 0 "") (net 1 "GND")
//!   (footprint "Resistor_SMD:R_0805" (layer "F.Cu") (at 10 20 90)
//!     (property "Reference" "R1") (property "Value" "10k")
//!     (pad "1" smd roundrect (at -1 0 90) (size 1 1.4) (layers "F.Cu") (roundrect_rratio 0.25)
//!       (net 1 "GND"))
//!     (pad "2" smd roundrect (at 1 0 90) (size 1 1.4) (layers "F.Cu") (roundrect_rratio 0.25))))"#;
//! let pcb = conduit_kicad::read_pcb(pcb)?;
//! let r1 = &pcb.footprints[0];
//! assert_eq!((r1.reference.as_str(), r1.value.as_str()), ("R1", "10k"));
//! // Pad 1 sits 1 mm left of the origin; turned 90° counter-clockwise it is 1 mm below it
//! // (KiCad's y points down).
//! let (x, y) = r1.board_position(&r1.pads[0]);
//! assert!((x - 10.0).abs() < 1e-9 && (y - 21.0).abs() < 1e-9);
//! assert_eq!(pcb.netlist()["GND"].len(), 1);
//! # Ok::<(), conduit_kicad::KicadError>(())
//! ```

mod connect;
mod error;
mod netfile;
mod netlist;
mod pcb;
mod sch;
pub mod sexpr;

use std::path::Path;

pub use connect::{SchNet, SchPart};
pub use error::KicadError;
pub use netfile::{Component, NetEntry, NetFile};
pub use netlist::Netlist;
pub use pcb::{Footprint, OutlineShape, Pad, PadKind, PadShape, Pcb};
pub use sch::MAX_SHEET_INSTANCES;

/// Which KiCad file a text is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `(kicad_pcb …)`.
    Pcb,
    /// `(kicad_sch …)`.
    Schematic,
    /// `(export …)`: a netlist export.
    NetFile,
}

impl Kind {
    fn noun(self) -> &'static str {
        match self {
            Kind::Pcb => "board",
            Kind::Schematic => "schematic",
            Kind::NetFile => "netlist",
        }
    }
}

/// The KiCad file `bytes` start as, from the first keyword after leading white space; `None`
/// for anything else.
pub fn sniff(bytes: &[u8]) -> Option<Kind> {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace())?;
    let rest = bytes[start..].strip_prefix(b"(")?;
    let word: Vec<u8> = rest
        .iter()
        .take_while(|b| b.is_ascii_alphanumeric() || **b == b'_')
        .copied()
        .collect();
    match word.as_slice() {
        b"kicad_pcb" => Some(Kind::Pcb),
        b"kicad_sch" => Some(Kind::Schematic),
        b"export" => Some(Kind::NetFile),
        _ => None,
    }
}

pub(crate) fn wrong_kind(found: &str, expected: &'static str) -> KicadError {
    let found = match found {
        "kicad_pcb" => Kind::Pcb.noun(),
        "kicad_sch" => Kind::Schematic.noun(),
        "export" => Kind::NetFile.noun(),
        other => {
            return KicadError::NotKicad {
                found: other.to_owned(),
            };
        }
    };
    KicadError::WrongKind { expected, found }
}

/// What a KiCad file contains.
#[derive(Debug, Clone, PartialEq)]
pub enum Document {
    /// A board (`.kicad_pcb`).
    Pcb(Pcb),
    /// A schematic (`.kicad_sch`) with its sheets.
    Schematic(Schematic),
    /// A netlist export (`.net`).
    NetFile(NetFile),
}

/// Reads any KiCad file by its content; a schematic's sheets are read through `load`
/// (paths relative to `path`'s folder).
///
/// # Errors
/// [`KicadError::NotKicad`] for anything else, and those of the readers.
pub fn read(
    bytes: &[u8],
    path: &Path,
    load: &mut dyn FnMut(&Path) -> std::io::Result<Vec<u8>>,
) -> Result<Document, KicadError> {
    match sniff(bytes) {
        Some(Kind::Pcb) => read_pcb(bytes).map(Document::Pcb),
        Some(Kind::Schematic) => read_schematic(bytes, path, load).map(Document::Schematic),
        Some(Kind::NetFile) => read_netfile(bytes).map(Document::NetFile),
        None => {
            let tree = sexpr::parse(bytes)?;
            Err(KicadError::NotKicad {
                found: tree.root().keyword().to_owned(),
            })
        }
    }
}

/// Reads a `.kicad_pcb`.
///
/// # Errors
/// [`KicadError`] for anything that is not a KiCad 6+ board.
pub fn read_pcb(bytes: &[u8]) -> Result<Pcb, KicadError> {
    let tree = sexpr::parse(bytes)?;
    let root = tree.root();
    if root.keyword() != "kicad_pcb" {
        return Err(wrong_kind(root.keyword(), "board"));
    }
    pcb::read(root)
}

/// Reads a netlist export (`.net`).
///
/// # Errors
/// [`KicadError`] for anything that is not a KiCad netlist export.
pub fn read_netfile(bytes: &[u8]) -> Result<NetFile, KicadError> {
    let tree = sexpr::parse(bytes)?;
    let root = tree.root();
    if root.keyword() != "export" {
        return Err(wrong_kind(root.keyword(), "netlist"));
    }
    netfile::read(root)
}

/// A schematic, all its sheets instanced and netlisted.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Schematic {
    /// The root file's `(version …)` date code.
    pub version: u32,
    /// Parts on the board (not power symbols, not `#` references, not `(on_board no)`), by
    /// reference.
    pub parts: Vec<SchPart>,
    /// Nets with at least one pad, sorted by name.
    pub nets: Vec<SchNet>,
    /// How many sheet instances the hierarchy has, the root included.
    pub sheet_instances: usize,
}

impl Schematic {
    /// Net name → pads.
    pub fn netlist(&self) -> Netlist {
        self.nets
            .iter()
            .map(|n| (n.name.clone(), n.pads.clone()))
            .collect()
    }

    /// The part whose reference is `reference`.
    pub fn part(&self, reference: &str) -> Option<&SchPart> {
        self.parts.iter().find(|p| p.reference == reference)
    }
}

/// Reads a root schematic; `load` reads the hierarchical sheets it names (paths relative to
/// `path`'s folder).
///
/// # Errors
/// [`KicadError`] for a file that is not a KiCad 6+ schematic, naming the sheet file for
/// errors inside a sheet.
pub fn read_schematic(
    bytes: &[u8],
    path: &Path,
    load: &mut dyn FnMut(&Path) -> std::io::Result<Vec<u8>>,
) -> Result<Schematic, KicadError> {
    let h = sch::hierarchy(bytes, path, load)?;
    let (parts, nets) = connect::netlist(&h);
    Ok(Schematic {
        version: h.files.first().map_or(0, |f| f.version),
        parts,
        nets,
        sheet_instances: h.instances.len(),
    })
}

/// Reads a root schematic and its sheets from disk.
///
/// # Errors
/// [`KicadError::SheetIo`] when a file cannot be read, and those of [`read_schematic`].
pub fn read_schematic_file(path: &Path) -> Result<Schematic, KicadError> {
    let bytes = std::fs::read(path).map_err(|error| KicadError::SheetIo {
        file: path.to_path_buf(),
        error,
    })?;
    read_schematic(&bytes, path, &mut |p| std::fs::read(p))
}

#[cfg(test)]
mod tests;
