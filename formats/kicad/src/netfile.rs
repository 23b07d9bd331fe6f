//! KiCad's netlist export (`.net`, `(export (version "E") …)`): components and nets.
//!
//! The file the schematic editor writes for other tools: each component with its reference,
//! value and footprint, each net with its nodes (`reference`, `pin` = pad number). It has no
//! geometry; pads come from the board.

use crate::error::KicadError;
use crate::netlist::Netlist;
use crate::sexpr::Node;

/// A netlist export.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NetFile {
    /// The components in file order.
    pub components: Vec<Component>,
    /// Nets in file order.
    pub nets: Vec<NetEntry>,
}

/// A component of a netlist export.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Component {
    /// Reference designator.
    pub reference: String,
    /// Value.
    pub value: String,
    /// Library footprint (`Lib:Name`), empty when none is assigned.
    pub footprint: String,
}

/// A net of a netlist export.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NetEntry {
    /// Net name.
    pub name: String,
    /// Its nodes as `(reference, pad number)`, in file order.
    pub nodes: Vec<(String, String)>,
}

impl NetFile {
    /// Net name → pads.
    pub fn netlist(&self) -> Netlist {
        let mut out = Netlist::new();
        for n in &self.nets {
            out.entry(n.name.clone())
                .or_default()
                .extend(n.nodes.iter().cloned());
        }
        out
    }
}

/// The text of `(KEYWORD "text")` inside `n`, empty when absent.
fn text(n: Node<'_>, keyword: &str) -> String {
    n.get(keyword)
        .and_then(|t| t.atom(0))
        .unwrap_or_default()
        .to_owned()
}

/// Reads the `(export …)` root.
pub(crate) fn read(root: Node<'_>) -> Result<NetFile, KicadError> {
    let mut out = NetFile::default();
    if let Some(comps) = root.get("components") {
        for c in comps.all("comp") {
            let reference = c.req("ref")?.req_atom(0, "the reference")?.to_owned();
            out.components.push(Component {
                reference,
                value: text(c, "value"),
                footprint: text(c, "footprint"),
            });
        }
    }
    if let Some(nets) = root.get("nets") {
        for n in nets.all("net") {
            let mut entry = NetEntry {
                name: text(n, "name"),
                nodes: Vec::new(),
            };
            for node in n.all("node") {
                let r = node.req("ref")?.req_atom(0, "the reference")?;
                let p = node.req("pin")?.req_atom(0, "the pin")?;
                entry.nodes.push((r.to_owned(), p.to_owned()));
            }
            out.nets.push(entry);
        }
    }
    Ok(out)
}
