//! KiCad boards, schematics and netlist exports as circuits.
//!
//! Place in the pipeline: beside the EAGLE conversion of [`super::Circuit::load`], it turns the
//! `conduit-kicad` crate's [`conduit_kicad::Pcb`], [`conduit_kicad::Schematic`] and
//! [`conduit_kicad::NetFile`] into a [`Circuit`]. A board has the pads; a schematic or a netlist
//! export only names each part's footprint, so their pad geometry comes from the board of the
//! same name beside them (`X.kicad_pcb` for `X.kicad_sch` or `X.net`).
//!
//! Package frame: KiCad's y points down and conduit's up, so a pad at `(x, y)` of a footprint
//! is at `(x, −y)`, turned by its angle less the footprint's. A bottom-side footprint's pads are
//! stored mirrored (KiCad negates their y and angles when it flips a part); they are mirrored
//! back, so every part is described as seen from its own top side, as EAGLE's packages are.
//! Pad shapes: `circle` is round, `rect` and `trapezoid` rectangles, `oval` an oblong, a
//! `roundrect` a rectangle (an oblong when its corners are rounded to half the shorter side),
//! a `custom` pad the rectangle covering its anchor and primitives. Holes without copper
//! (`np_thru_hole`) are left out. Pads sharing a number (a connector's mounting tabs, a
//! package's exposed pads) are named `N`, `N#2`, … and joined as one pin.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use conduit_kicad::{Document, Footprint, Netlist, PadKind, Pcb};

use super::{Circuit, CircuitError, Net, Pad, PadShape, Part, PinRef};

/// A KiCad pad's copper as a [`PadShape`], and the offset of its centre from the pad's anchor
/// in the pad's own frame (y down; non-zero only for a custom pad drawn off its anchor).
fn pad_shape(p: &conduit_kicad::Pad) -> (PadShape, [f64; 2]) {
    let (w, h) = (p.width, p.height);
    let oblong = |width: f64, height: f64| {
        if width == height {
            PadShape::Round { diameter: width }
        } else {
            PadShape::Oblong { width, height }
        }
    };
    match p.shape {
        conduit_kicad::PadShape::Circle => (PadShape::Round { diameter: w }, [0.0; 2]),
        conduit_kicad::PadShape::Oval => (oblong(w, h), [0.0; 2]),
        conduit_kicad::PadShape::RoundRect { ratio } if ratio >= 0.5 => (oblong(w, h), [0.0; 2]),
        conduit_kicad::PadShape::Rect
        | conduit_kicad::PadShape::Trapezoid
        | conduit_kicad::PadShape::RoundRect { .. } => (
            PadShape::Rect {
                width: w,
                height: h,
            },
            [0.0; 2],
        ),
        conduit_kicad::PadShape::Custom {
            bounds: [x0, y0, x1, y1],
        } => (
            PadShape::Rect {
                width: x1 - x0,
                height: y1 - y0,
            },
            [(x0 + x1) / 2.0, (y0 + y1) / 2.0],
        ),
    }
}

/// The copper pads of a footprint in conduit's package frame (see the module documentation),
/// and the pins that join pads sharing a number.
fn footprint_pads(f: &Footprint) -> (Vec<Pad>, BTreeMap<String, Vec<String>>) {
    let mut pads = Vec::new();
    let mut seen: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for p in f.pads.iter().filter(|p| p.kind != PadKind::NpThroughHole) {
        let (shape, [ox, oy]) = pad_shape(p);
        // The pad's angle within the footprint, on screen (y down).
        let local = p.rotation - f.rotation;
        let (s, c) = local.to_radians().sin_cos();
        // A custom pad's offset turns with the pad (KiCad's counter-clockwise on screen).
        let (x, y) = (p.x + ox * c + oy * s, p.y - ox * s + oy * c);
        // `+ 0.0` writes −0 as 0.
        let (y, rotation_deg) = if f.bottom {
            (y + 0.0, -local)
        } else {
            (-y + 0.0, local)
        };
        let names = seen.entry(p.number.clone()).or_default();
        let name = if names.is_empty() {
            p.number.clone()
        } else {
            format!("{}#{}", p.number, names.len() + 1)
        };
        names.push(name.clone());
        pads.push(Pad {
            name,
            x,
            y,
            rotation_deg: rotation_deg.rem_euclid(360.0),
            shape,
            smd: matches!(p.kind, PadKind::Smd | PadKind::Connect),
        });
    }
    seen.retain(|_, v| v.len() > 1);
    (pads, seen)
}

/// A part from a footprint, named `name` with `value`.
fn part(name: &str, value: &str, f: &Footprint) -> Part {
    let (pads, joined) = footprint_pads(f);
    Part {
        name: name.to_owned(),
        value: (!value.is_empty()).then(|| value.to_owned()),
        package: f.name.clone(),
        pads,
        route_any: joined.keys().cloned().collect(),
        pins: joined,
    }
}

/// Nets with at least one pad, sorted by name.
fn nets(netlist: &Netlist) -> Vec<Net> {
    netlist
        .iter()
        .filter(|(_, pads)| !pads.is_empty())
        .map(|(name, pads)| Net {
            name: name.clone(),
            pins: pads.iter().map(|(r, p)| PinRef::new(r, p)).collect(),
        })
        .collect()
}

impl Circuit {
    /// The circuit of a KiCad board: every footprint with copper pads (logos and mounting holes
    /// without copper are left out) and the nets of its pads.
    pub fn from_kicad_pcb(pcb: &Pcb) -> Self {
        let parts: Vec<Part> = pcb
            .footprints
            .iter()
            .map(|f| part(&f.reference, &f.value, f))
            .filter(|p| !p.pads.is_empty())
            .collect();
        Circuit {
            parts,
            nets: nets(&pcb.netlist()),
        }
    }

    /// The circuit of a KiCad schematic or netlist export's `parts` (reference, value) and
    /// `netlist`, with each part's pads from the footprint of the same reference on `pcb`.
    ///
    /// # Errors
    /// The references of the parts that have no footprint on `pcb` (all of them when there is
    /// no board), sorted.
    pub fn from_kicad_parts(
        parts: &[(String, String)],
        netlist: &Netlist,
        pcb: Option<&Pcb>,
    ) -> Result<Self, Vec<String>> {
        let mut missing = BTreeSet::new();
        let mut out = Vec::new();
        for (reference, value) in parts {
            match pcb.and_then(|b| b.footprint(reference)) {
                Some(f) => out.push(part(reference, value, f)),
                None => {
                    missing.insert(reference.clone());
                }
            }
        }
        if !missing.is_empty() {
            return Err(missing.into_iter().collect());
        }
        Ok(Circuit {
            parts: out,
            nets: nets(netlist),
        })
    }

    /// The circuit of a KiCad file read from `path`: a board's own, or a schematic's or netlist
    /// export's with the pads of the board beside it ([`Circuit::from_kicad_parts`]).
    ///
    /// # Errors
    /// [`CircuitError::Kicad`] when the board beside cannot be read,
    /// [`CircuitError::KicadPadsMissing`] when parts have no footprint on it or there is none.
    pub fn from_kicad(doc: &Document, path: &Path) -> Result<Self, CircuitError> {
        let (parts, netlist): (Vec<(String, String)>, Netlist) = match doc {
            Document::Pcb(pcb) => return Ok(Self::from_kicad_pcb(pcb)),
            Document::Schematic(s) => (
                s.parts
                    .iter()
                    .map(|p| (p.reference.clone(), p.value.clone()))
                    .collect(),
                s.netlist(),
            ),
            Document::NetFile(n) => (
                n.components
                    .iter()
                    .map(|c| (c.reference.clone(), c.value.clone()))
                    .collect(),
                n.netlist(),
            ),
        };
        let board = board_beside(path);
        let pcb = if board.is_file() {
            let bytes = std::fs::read(&board).map_err(|error| CircuitError::Io {
                path: board.clone(),
                error,
            })?;
            Some(
                conduit_kicad::read_pcb(&bytes).map_err(|error| CircuitError::Kicad {
                    path: board.clone(),
                    error: Box::new(error),
                })?,
            )
        } else {
            None
        };
        Self::from_kicad_parts(&parts, &netlist, pcb.as_ref()).map_err(|parts| {
            CircuitError::KicadPadsMissing {
                path: path.to_path_buf(),
                board: pcb.is_some().then_some(board.clone()),
                expected: board,
                parts,
            }
        })
    }
}

/// The board that goes with a schematic or netlist export: the same name, `.kicad_pcb`.
pub fn board_beside(path: &Path) -> PathBuf {
    path.with_extension("kicad_pcb")
}

/// Reads a KiCad file, its sheets from beside it.
pub(crate) fn read(bytes: &[u8], path: &Path) -> Result<Document, CircuitError> {
    conduit_kicad::read(bytes, path, &mut |p| std::fs::read(p)).map_err(|error| {
        CircuitError::Kicad {
            path: path.to_path_buf(),
            error: Box::new(error),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const BOARD: &str = r#"(kicad_pcb (version 20240108) (generator "pcbnew")
      (footprint "R_0805" (layer "F.Cu") (at 10 20 90)
        (property "Reference" "R1") (property "Value" "1k")
        (pad "1" smd roundrect (at -1 0.5 120) (size 1 1.4) (layers "F.Cu") (roundrect_rratio 0.25) (net 1 "A"))
        (pad "2" thru_hole oval (at 1 0 90) (size 1.5 2) (drill 0.8) (layers "*.Cu") (net 2 "B")))
      (footprint "J" (layer "B.Cu") (at 30 20 30)
        (property "Reference" "J1") (property "Value" "")
        (pad "1" smd roundrect (at 1 2 50) (size 1 1) (layers "B.Cu") (roundrect_rratio 0.5) (net 1 "A"))
        (pad "MP" smd custom (at 0 -2 30) (size 1 1) (layers "B.Cu")
          (primitives (gr_rect (start 0 0) (end 3 1) (width 0))))
        (pad "MP" smd rect (at 0 4 30) (size 2 1) (layers "B.Cu"))
        (pad "" np_thru_hole circle (at 0 0) (size 1 1) (drill 1) (layers "*.Cu")))
      (footprint "Logo" (layer "F.Cu") (at 0 0) (property "Reference" "G1")))"#;

    #[test]
    fn board_pads_in_conduits_package_frame() {
        let pcb = conduit_kicad::read_pcb(BOARD.as_bytes()).expect("board");
        let c = Circuit::from_kicad_pcb(&pcb);
        let names: Vec<_> = c.parts.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["R1", "J1"]);
        let r1 = &c.parts[0];
        assert_eq!(r1.value.as_deref(), Some("1k"));
        // y flipped; the pad's angle less the footprint's 90°.
        let p = &r1.pads[0];
        assert_eq!((p.x, p.y, p.rotation_deg, p.smd), (-1.0, -0.5, 30.0, true));
        assert_eq!(
            p.shape,
            PadShape::Rect {
                width: 1.0,
                height: 1.4
            }
        );
        let p = &r1.pads[1];
        assert_eq!((p.x, p.y, p.rotation_deg, p.smd), (1.0, 0.0, 0.0, false));
        assert_eq!(
            p.shape,
            PadShape::Oblong {
                width: 1.5,
                height: 2.0
            }
        );
        // Bottom side: stored mirrored, mirrored back (y kept, angle negated).
        let j1 = &c.parts[1];
        assert_eq!(j1.value, None);
        let p = &j1.pads[0];
        assert_eq!((p.x, p.y, p.rotation_deg), (1.0, 2.0, 340.0));
        assert_eq!(p.shape, PadShape::Round { diameter: 1.0 });
        // The custom pad covers its anchor (±0.5) and the rectangle (0..3, 0..1): 3.5 × 1.5
        // centred 1.25, 0.25 from the anchor, which turns with the pad (0° in the footprint).
        let p = &j1.pads[1];
        assert_eq!(p.name, "MP");
        assert_eq!(
            p.shape,
            PadShape::Rect {
                width: 3.5,
                height: 1.5
            }
        );
        assert_eq!((p.x, p.y), (1.25, -1.75));
        assert_eq!(j1.pads[2].name, "MP#2");
        assert_eq!(j1.pads.len(), 3);
        assert_eq!(j1.joined_pin("MP#2"), Some("MP"));
        let a = c.net("A").expect("net A");
        assert_eq!(a.pins, [PinRef::new("J1", "1"), PinRef::new("R1", "1")]);
    }

    #[test]
    fn schematic_parts_without_a_board_are_named() {
        let nl = Netlist::new();
        let parts = [
            ("R2".to_owned(), String::new()),
            ("R1".to_owned(), String::new()),
        ];
        assert_eq!(
            Circuit::from_kicad_parts(&parts, &nl, None),
            Err(vec!["R1".to_owned(), "R2".to_owned()])
        );
        let pcb = conduit_kicad::read_pcb(BOARD.as_bytes()).expect("board");
        assert_eq!(
            Circuit::from_kicad_parts(&parts, &nl, Some(&pcb)),
            Err(vec!["R2".to_owned()])
        );
    }
}
