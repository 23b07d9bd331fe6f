//! Embedded libraries: packages with their pads, device sets with their pin-to-pad connects.

use std::collections::{BTreeMap, BTreeSet};

use crate::doc::{Doc, Node};
use crate::error::EagleError;
use crate::rotation::Rotation;

/// EAGLE layer number of the top copper layer.
pub const LAYER_TOP: u32 = 1;
/// EAGLE layer number of the bottom copper layer.
pub const LAYER_BOTTOM: u32 = 16;
/// EAGLE layer number of the "Pads" layer, used here for through-hole pads (all copper layers).
pub const LAYER_PADS: u32 = 17;
/// EAGLE layer number of the "Dimension" layer (board outline).
pub const LAYER_DIMENSION: u32 = 20;

/// The copper shape of a pad.
#[derive(Debug, Clone, PartialEq)]
pub enum PadShape {
    /// A surface-mount pad (`<smd>`): a rectangle, optionally rounded.
    Smd {
        /// Width in mm (before rotation).
        dx: f64,
        /// Height in mm (before rotation).
        dy: f64,
        /// Corner roundness in percent, 0 (sharp rectangle) to 100 (fully rounded ends).
        roundness: f64,
    },
    /// A through-hole pad (`<pad>`).
    Through {
        /// Drill diameter in mm.
        drill: f64,
        /// Copper diameter in mm; `None` when EAGLE computes it from the design rules
        /// (`diameter` absent or `0`).
        diameter: Option<f64>,
        /// EAGLE pad shape: `round` (the default), `square`, `octagon`, `long` or `offset`.
        shape: String,
    },
}

/// A pad of a package, in the package's own frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Pad {
    /// Pad name, unique within the package (e.g. `1`, `A3`, `GND`).
    pub name: String,
    /// Centre x in mm, package frame.
    pub x: f64,
    /// Centre y in mm, package frame.
    pub y: f64,
    /// Rotation of the pad within the package.
    pub rotation: Rotation,
    /// Copper shape.
    pub shape: PadShape,
    /// EAGLE layer: 1 (top) or 16 (bottom) for SMD pads, [`LAYER_PADS`] (17) for through-hole
    /// pads, which exist on every copper layer.
    pub layer: u32,
}

/// A package (footprint) from an embedded library.
#[derive(Debug, Clone, PartialEq)]
pub struct Package {
    /// Name of the library the package comes from.
    pub library: String,
    /// Package name.
    pub name: String,
    /// Pads (`<smd>` and `<pad>`), in file order.
    pub pads: Vec<Pad>,
}

impl Package {
    /// The pad named `name` (exact match first, then ASCII case-insensitive as EAGLE does).
    pub fn pad(&self, name: &str) -> Option<&Pad> {
        self.pads
            .iter()
            .find(|p| p.name == name)
            .or_else(|| self.pads.iter().find(|p| p.name.eq_ignore_ascii_case(name)))
    }
}

/// A symbol pin with its electrical direction (`pwr` pins are wired implicitly).
#[derive(Debug, Clone)]
pub(crate) struct SymbolPin {
    pub(crate) name: String,
    pub(crate) direction: String,
}

/// A gate of a device set: one symbol instance.
#[derive(Debug, Clone)]
pub(crate) struct Gate {
    pub(crate) name: String,
    pub(crate) symbol: String,
}

/// A device (package variant) of a device set.
#[derive(Debug, Clone)]
pub(crate) struct Device {
    pub(crate) package: Option<String>,
    /// `gate.pin` -> pads, in connect order.
    pub(crate) connects: BTreeMap<String, Vec<String>>,
    /// `gate.pin`s connected with `route="any"`: their pads are joined inside the part.
    pub(crate) route_any: BTreeSet<String>,
    pub(crate) pos: usize,
}

/// A device set: gates plus package variants.
#[derive(Debug, Clone)]
pub(crate) struct DeviceSet {
    pub(crate) gates: Vec<Gate>,
    pub(crate) devices: BTreeMap<String, Device>,
}

/// One embedded `<library>`.
#[derive(Debug, Clone)]
pub(crate) struct Library {
    pub(crate) name: String,
    pub(crate) urn: Option<String>,
    pub(crate) packages: BTreeMap<String, Package>,
    pub(crate) symbols: BTreeMap<String, Vec<SymbolPin>>,
    pub(crate) devicesets: BTreeMap<String, DeviceSet>,
}

/// Looks a name up exactly, then ASCII case-insensitively (EAGLE names are case-insensitive).
pub(crate) fn lookup<'a, V>(map: &'a BTreeMap<String, V>, key: &str) -> Option<&'a V> {
    map.get(key).or_else(|| {
        map.iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(key))
            .map(|(_, v)| v)
    })
}

/// All embedded libraries of a drawing.
#[derive(Debug, Clone, Default)]
pub(crate) struct Libraries {
    pub(crate) list: Vec<Library>,
}

impl Libraries {
    /// Reads `<libraries>` under `parent` (a `<schematic>` or `<board>`).
    pub(crate) fn read(doc: &Doc, parent: &Node) -> Result<Self, EagleError> {
        let mut list = Vec::new();
        for lib in parent.list("libraries", "library") {
            list.push(read_library(doc, lib)?);
        }
        Ok(Libraries { list })
    }

    /// Finds a library by name and, when given (EAGLE 9 managed libraries), URN. Two libraries
    /// may share a name and differ in URN; without a URN match the first one named so wins.
    pub(crate) fn find(&self, name: &str, urn: Option<&str>) -> Option<&Library> {
        let named = |l: &&Library| l.name == name;
        let named_ci = |l: &&Library| l.name.eq_ignore_ascii_case(name);
        if let Some(urn) = urn {
            if let Some(l) = self
                .list
                .iter()
                .find(|l| named(l) && l.urn.as_deref() == Some(urn))
            {
                return Some(l);
            }
        }
        self.list
            .iter()
            .find(named)
            .or_else(|| self.list.iter().find(named_ci))
    }
}

fn read_library(doc: &Doc, lib: &Node) -> Result<Library, EagleError> {
    // Libraries inside .sch/.brd always carry a name; a stand-alone .lbr does not.
    let name = lib.attr("name").unwrap_or_default().to_owned();
    let mut packages = BTreeMap::new();
    for p in lib.list("packages", "package") {
        let pkg = read_package(doc, p, &name)?;
        packages.insert(pkg.name.clone(), pkg);
    }
    let mut symbols = BTreeMap::new();
    for s in lib.list("symbols", "symbol") {
        let sname = doc.req(s, "name")?.to_owned();
        let mut pins = Vec::new();
        for pin in s.children_named("pin") {
            pins.push(SymbolPin {
                name: doc.req(pin, "name")?.to_owned(),
                direction: pin.attr("direction").unwrap_or("io").to_owned(),
            });
        }
        symbols.insert(sname, pins);
    }
    let mut devicesets = BTreeMap::new();
    for ds in lib.list("devicesets", "deviceset") {
        let ds_name = doc.req(ds, "name")?.to_owned();
        let mut gates = Vec::new();
        for g in ds.list("gates", "gate") {
            gates.push(Gate {
                name: doc.req(g, "name")?.to_owned(),
                symbol: doc.req(g, "symbol")?.to_owned(),
            });
        }
        let mut devices = BTreeMap::new();
        for d in ds.list("devices", "device") {
            // The unnamed device ("") is the usual single variant.
            let d_name = d.attr("name").unwrap_or_default().to_owned();
            let package = d
                .attr("package")
                .filter(|p| !p.is_empty())
                .map(str::to_owned);
            let mut connects: BTreeMap<String, Vec<String>> = BTreeMap::new();
            let mut route_any = BTreeSet::new();
            for c in d.list("connects", "connect") {
                let gate = doc.req(c, "gate")?;
                let pin = doc.req(c, "pin")?;
                // One pin may sit on several pads: `pad="1 3"` (EAGLE 7+ "multiple pads"),
                // all to be wired (`route="all"`, the default) or joined inside the part so
                // that one wired pad connects the pin (`route="any"`).
                let pads = doc.req(c, "pad")?.split_whitespace().map(str::to_owned);
                let key = format!("{gate}.{pin}");
                if c.attr("route") == Some("any") {
                    route_any.insert(key.clone());
                }
                connects.entry(key).or_default().extend(pads);
            }
            devices.insert(
                d_name,
                Device {
                    package,
                    connects,
                    route_any,
                    pos: d.pos,
                },
            );
        }
        devicesets.insert(ds_name, DeviceSet { gates, devices });
    }
    Ok(Library {
        name,
        urn: lib.attr("urn").map(str::to_owned),
        packages,
        symbols,
        devicesets,
    })
}

fn read_package(doc: &Doc, p: &Node, library: &str) -> Result<Package, EagleError> {
    let name = doc.req(p, "name")?.to_owned();
    let mut pads = Vec::new();
    for c in &p.children {
        let shape = match c.name.as_str() {
            "smd" => PadShape::Smd {
                dx: doc.f64(c, "dx")?,
                dy: doc.f64(c, "dy")?,
                roundness: doc.opt_f64(c, "roundness")?.unwrap_or(0.0),
            },
            "pad" => PadShape::Through {
                drill: doc.f64(c, "drill")?,
                diameter: doc.opt_f64(c, "diameter")?.filter(|d| *d > 0.0),
                shape: c.attr("shape").unwrap_or("round").to_owned(),
            },
            _ => continue,
        };
        let layer = match shape {
            PadShape::Smd { .. } => doc.opt_u32(c, "layer")?.unwrap_or(LAYER_TOP),
            PadShape::Through { .. } => LAYER_PADS,
        };
        pads.push(Pad {
            name: doc.req(c, "name")?.to_owned(),
            x: doc.f64(c, "x")?,
            y: doc.f64(c, "y")?,
            rotation: doc.rot(c)?,
            shape,
            layer,
        });
    }
    Ok(Package {
        library: library.to_owned(),
        name,
        pads,
    })
}
