//! Boards (`.brd`): placed elements, signals, outline.

use std::collections::{BTreeMap, BTreeSet};

use crate::doc::{Doc, Node};
use crate::error::EagleError;
use crate::library::{LAYER_DIMENSION, Libraries, Package, lookup};
use crate::netlist::{Net, Netlist, to_netlist};
use crate::rotation::Rotation;

/// A part placed on the board.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    /// Element name, matching the schematic part name.
    pub name: String,
    /// Library name.
    pub library: String,
    /// The package, with pads in the package frame.
    pub package: Package,
    /// The `value` attribute, if set.
    pub value: Option<String>,
    /// Origin x in mm, board frame.
    pub x: f64,
    /// Origin y in mm, board frame.
    pub y: f64,
    /// Placement rotation; `mirror` means the element sits on the bottom side.
    pub rotation: Rotation,
}

impl Element {
    /// True when the element is placed on the bottom side (`M` in its rotation).
    pub fn is_bottom(&self) -> bool {
        self.rotation.mirror
    }
}

/// A straight or curved piece of the board outline (a `<wire>` on layer 20, Dimension).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutlineSegment {
    /// Start x in mm.
    pub x1: f64,
    /// Start y in mm.
    pub y1: f64,
    /// End x in mm.
    pub x2: f64,
    /// End y in mm.
    pub y2: f64,
    /// Arc angle in degrees, counter-clockwise from start to end; 0 for a straight segment.
    pub curve: f64,
}

/// A straight copper track of a signal (a `<wire>` inside `<signal>`): where the board's own
/// routing runs, so a reader can check where it puts the pads against it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SignalWire {
    /// Start x in mm.
    pub x1: f64,
    /// Start y in mm.
    pub y1: f64,
    /// End x in mm.
    pub x2: f64,
    /// End y in mm.
    pub y2: f64,
    /// Track width in mm.
    pub width: f64,
    /// EAGLE layer number (1 top copper, 16 bottom copper, 2-15 inner layers; others are
    /// drawings such as airwires on 19).
    pub layer: u32,
}

/// A board: elements, signals resolved to pads, and outline.
#[derive(Debug, Clone, PartialEq)]
pub struct Board {
    /// The `version` attribute of `<eagle>`, e.g. `7.5.0`.
    pub version: String,
    /// Elements in file order.
    pub elements: Vec<Element>,
    /// Signals as nets of `(element, pad)`, from `<signals>/<signal>/<contactref>`, in file
    /// order.
    pub nets: Vec<Net>,
    /// Wires of `<plain>` on layer 20 (Dimension). Outline drawn inside packages is not
    /// included.
    pub outline: Vec<OutlineSegment>,
    /// The copper tracks of each signal, by signal name (signals without tracks are absent).
    pub signal_wires: BTreeMap<String, Vec<SignalWire>>,
    /// Signals with a copper pour (`<polygon>`): their pads may be joined by the pour alone.
    pub poured_signals: BTreeSet<String>,
}

impl Board {
    /// Signal name -> pads.
    pub fn netlist(&self) -> Netlist {
        to_netlist(&self.nets)
    }

    /// The element named `name`.
    pub fn element(&self, name: &str) -> Option<&Element> {
        self.elements.iter().find(|e| e.name == name)
    }
}

/// Reads the `<board>` element of a parsed document.
pub(crate) fn read(doc: &Doc, version: String, brd: &Node) -> Result<Board, EagleError> {
    let libs = Libraries::read(doc, brd)?;
    let classes: Vec<(String, String)> = brd
        .list("classes", "class")
        .filter_map(|c| Some((c.attr("number")?.to_owned(), c.attr("name")?.to_owned())))
        .collect();

    let mut elements = Vec::new();
    for e in brd.list("elements", "element") {
        let name = doc.req(e, "name")?;
        let library = doc.req(e, "library")?;
        let package = doc.req(e, "package")?;
        let line = doc.line(e.pos);
        let lib = libs.find(library, e.attr("library_urn")).ok_or_else(|| {
            EagleError::UnknownLibrary {
                element: "element",
                name: name.to_owned(),
                library: library.to_owned(),
                line,
            }
        })?;
        let pkg =
            lookup(&lib.packages, package)
                .cloned()
                .ok_or_else(|| EagleError::UnknownPackage {
                    owner: format!("element {name}"),
                    library: library.to_owned(),
                    package: package.to_owned(),
                    line,
                })?;
        elements.push(Element {
            name: name.to_owned(),
            library: lib.name.clone(),
            package: pkg,
            value: e.attr("value").map(str::to_owned),
            x: doc.f64(e, "x")?,
            y: doc.f64(e, "y")?,
            rotation: doc.rot(e)?,
        });
    }

    let mut nets = Vec::new();
    let mut tracks = BTreeMap::new();
    let mut poured = BTreeSet::new();
    for s in brd.list("signals", "signal") {
        let mut pads = BTreeSet::new();
        for c in s.children_named("contactref") {
            let element = doc.req(c, "element")?;
            let pad = doc.req(c, "pad")?;
            let el = elements
                .iter()
                .find(|e| e.name == element)
                .or_else(|| {
                    elements
                        .iter()
                        .find(|e| e.name.eq_ignore_ascii_case(element))
                })
                .ok_or_else(|| EagleError::UnknownReference {
                    element: "contactref",
                    kind: "element",
                    name: element.to_owned(),
                    line: doc.line(c.pos),
                })?;
            pads.insert((el.name.clone(), pad.to_owned()));
        }
        let class = s.attr("class").map(|c| {
            classes
                .iter()
                .find(|(n, _)| n == c)
                .map_or_else(|| c.to_owned(), |(_, name)| name.clone())
        });
        let name = doc.req(s, "name")?.to_owned();
        let wires = signal_wires(doc, s)?;
        if s.children_named("polygon").next().is_some() {
            poured.insert(name.clone());
        }
        if !wires.is_empty() {
            tracks
                .entry(name.clone())
                .or_insert_with(Vec::new)
                .extend(wires);
        }
        nets.push(Net { name, class, pads });
    }

    let mut outline = Vec::new();
    for w in brd
        .children_named("plain")
        .flat_map(|p| p.children_named("wire"))
    {
        if doc.opt_u32(w, "layer")? != Some(LAYER_DIMENSION) {
            continue;
        }
        let [x1, y1, x2, y2] = wire_ends(doc, w)?;
        outline.push(OutlineSegment {
            x1,
            y1,
            x2,
            y2,
            curve: doc.opt_f64(w, "curve")?.unwrap_or(0.0),
        });
    }

    Ok(Board {
        version,
        elements,
        nets,
        outline,
        signal_wires: tracks,
        poured_signals: poured,
    })
}

/// The copper `<wire>`s of one `<signal>` (layers 1-16).
fn signal_wires(doc: &Doc, signal: &Node) -> Result<Vec<SignalWire>, EagleError> {
    let mut out = Vec::new();
    for w in signal.children_named("wire") {
        let Some(layer) = doc.opt_u32(w, "layer")? else {
            continue;
        };
        if !(1..=16).contains(&layer) {
            continue;
        }
        let [x1, y1, x2, y2] = wire_ends(doc, w)?;
        out.push(SignalWire {
            x1,
            y1,
            x2,
            y2,
            width: doc.opt_f64(w, "width")?.unwrap_or(0.0),
            layer,
        });
    }
    Ok(out)
}

/// A `<wire>`'s end points `[x1, y1, x2, y2]`, mm.
fn wire_ends(doc: &Doc, w: &Node) -> Result<[f64; 4], EagleError> {
    Ok([
        doc.f64(w, "x1")?,
        doc.f64(w, "y1")?,
        doc.f64(w, "x2")?,
        doc.f64(w, "y2")?,
    ])
}
