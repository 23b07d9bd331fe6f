//! Schematics (`.kicad_sch`): one sheet file read into its symbols (pins placed on the
//! sheet), wires, buses, junctions, labels and sheet symbols, and the hierarchy of sheet
//! instances built from the root file.
//!
//! Second step of the schematic reader, before [`crate::connect`] netlists the instances.
//! Symbol pins come from the file's embedded `lib_symbols`: the library's y axis points up and
//! the sheet's down, so a library pin at `(x, y)` is at `(x, −y)` before the symbol's rotation
//! (counter-clockwise on screen) and mirror (`(mirror x)` flips y, `(mirror y)` flips x) move it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::error::KicadError;
use crate::sexpr::{self, Node};

/// The most sheet instances a hierarchy may expand to.
pub const MAX_SHEET_INSTANCES: usize = 10_000;

/// A point on a sheet in KiCad's schematic units (100 nm), exact so points compare equal.
pub(crate) type Pt = (i64, i64);

/// A millimetre coordinate in schematic units (100 nm); out-of-range values saturate.
pub(crate) fn to_units(mm: f64) -> i64 {
    #[allow(clippy::cast_possible_truncation)]
    let v = (mm * 10_000.0).round() as i64;
    v
}

/// What a label is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LabelKind {
    /// `label`: joins its name within the sheet instance.
    Local,
    /// `global_label`: joins its name across the design.
    Global,
    /// `hierarchical_label`: joins the parent's sheet pin of its name.
    Hierarchical,
}

/// A label.
#[derive(Debug, Clone)]
pub(crate) struct Label {
    pub name: String,
    pub kind: LabelKind,
    pub at: Pt,
}

/// A symbol pin placed on the sheet.
#[derive(Debug, Clone)]
pub(crate) struct PlacedPin {
    /// Pin number, which is the footprint's pad number.
    pub number: String,
    /// Pin name.
    pub name: String,
    pub at: Pt,
    /// A power input (`power_in`).
    pub power_in: bool,
    /// Hidden (`hide`, `(hide yes)`).
    pub hidden: bool,
    /// The unit it belongs to (0: every unit).
    pub unit: i64,
}

/// A symbol placed on a sheet.
#[derive(Debug, Clone)]
pub(crate) struct Symbol {
    pub uuid: String,
    /// The `Reference` property (overridden per sheet instance by the instance tables).
    pub reference: String,
    pub value: String,
    pub footprint: String,
    pub unit: i64,
    /// A power symbol (`(power)` in its library symbol): its pin joins the net named by its value.
    pub power: bool,
    /// `(power local)` (KiCad 9): its net is local to the sheet instance.
    pub local_power: bool,
    pub on_board: bool,
    pub pins: Vec<PlacedPin>,
    /// KiCad 7+ `(instances (project … (path "/root/sheet…" (reference …) (unit …))))`.
    pub instances: Vec<(String, String, i64)>,
}

/// A sheet symbol: a child sheet and its pins.
#[derive(Debug, Clone)]
pub(crate) struct SheetRef {
    pub uuid: String,
    pub name: String,
    pub file: String,
    pub pins: Vec<(String, Pt)>,
}

/// One `.kicad_sch` file.
#[derive(Debug, Clone, Default)]
pub(crate) struct SheetFile {
    pub version: u32,
    pub symbols: Vec<Symbol>,
    pub wires: Vec<(Pt, Pt)>,
    pub buses: Vec<(Pt, Pt)>,
    pub junctions: Vec<Pt>,
    pub labels: Vec<Label>,
    pub sheets: Vec<SheetRef>,
    /// KiCad 6 root `(symbol_instances (path "/sheet…/symbol" (reference …) (unit …)))`.
    pub symbol_instances: BTreeMap<String, (String, i64)>,
}

/// A library pin: number, name, position (library frame, y up), type and hidden flag.
#[derive(Debug, Clone)]
struct LibPin {
    number: String,
    name: String,
    x: f64,
    y: f64,
    power_in: bool,
    hidden: bool,
    unit: i64,
    style: i64,
}

#[derive(Debug, Clone, Default)]
struct LibSymbol {
    power: Option<bool>,
    pins: Vec<LibPin>,
}

fn pt(x: f64, y: f64) -> Pt {
    (to_units(x), to_units(y))
}

/// Reads one sheet file's root list.
pub(crate) fn read_file(root: Node<'_>) -> Result<SheetFile, KicadError> {
    let mut lib = BTreeMap::new();
    if let Some(ls) = root.get("lib_symbols") {
        for s in ls.all("symbol") {
            let name = s.req_atom(0, "the library symbol's name")?;
            lib.insert(name.to_owned(), lib_symbol(s)?);
        }
        // `(extends "Base")` (KiCad 7+ keeps derived symbols so): the base's pins.
        for s in ls.all("symbol") {
            if let (Some(name), Some(base)) = (s.atom(0), s.get("extends").and_then(|e| e.atom(0)))
            {
                let prefix = name.rsplit_once(':').map_or("", |(l, _)| l);
                let key = if prefix.is_empty() {
                    base.to_owned()
                } else {
                    format!("{prefix}:{base}")
                };
                if let Some(b) = lib.get(&key).cloned() {
                    if let Some(d) = lib.get_mut(name) {
                        d.pins = b.pins;
                        d.power = d.power.or(b.power);
                    }
                }
            }
        }
    }
    let mut f = SheetFile {
        version: crate::pcb::version(root)?,
        ..SheetFile::default()
    };
    for item in root.lists() {
        match item.keyword() {
            "symbol" => f.symbols.push(symbol(item, &lib)?),
            "wire" | "bus" => {
                let pts = item.req("pts")?;
                let xy: Vec<Node<'_>> = pts.all("xy").collect();
                for w in xy.windows(2) {
                    let a = pt(w[0].num(0, "x, mm")?, w[0].num(1, "y, mm")?);
                    let b = pt(w[1].num(0, "x, mm")?, w[1].num(1, "y, mm")?);
                    if item.keyword() == "wire" {
                        f.wires.push((a, b));
                    } else {
                        f.buses.push((a, b));
                    }
                }
            }
            "junction" => {
                let (x, y, _) = item.at()?;
                f.junctions.push(pt(x, y));
            }
            "label" | "global_label" | "hierarchical_label" => {
                let (x, y, _) = item.at()?;
                f.labels.push(Label {
                    name: item.req_atom(0, "the label's text")?.to_owned(),
                    kind: match item.keyword() {
                        "label" => LabelKind::Local,
                        "global_label" => LabelKind::Global,
                        _ => LabelKind::Hierarchical,
                    },
                    at: pt(x, y),
                });
            }
            "sheet" => f.sheets.push(sheet(item)?),
            "symbol_instances" => {
                for p in item.all("path") {
                    let path = p.req_atom(0, "the instance path")?.to_owned();
                    let reference = p
                        .get("reference")
                        .and_then(|r| r.atom(0))
                        .unwrap_or_default();
                    let unit = p
                        .get("unit")
                        .map(|u| u.num(0, "a unit number"))
                        .transpose()?;
                    f.symbol_instances
                        .insert(path, (reference.to_owned(), unit.map_or(1, round)));
                }
            }
            _ => {}
        }
    }
    Ok(f)
}

#[allow(clippy::cast_possible_truncation)]
fn round(v: f64) -> i64 {
    v.round() as i64
}

fn lib_symbol(s: Node<'_>) -> Result<LibSymbol, KicadError> {
    let mut out = LibSymbol {
        power: s.get("power").map(|p| p.atom(0) == Some("local")),
        pins: Vec::new(),
    };
    let base = s.atom(0).unwrap_or_default();
    let base = base.rsplit_once(':').map_or(base, |(_, n)| n);
    for sub in s.all("symbol") {
        // `NAME_UNIT_STYLE`; unit 0 and style 0 are common to all.
        let name = sub.atom(0).unwrap_or_default();
        let rest = name
            .strip_prefix(base)
            .and_then(|r| r.strip_prefix('_'))
            .unwrap_or(name);
        let mut parts = rest.rsplitn(2, '_');
        let style = parts.next().and_then(|v| v.parse().ok()).unwrap_or(0);
        let unit = parts.next().and_then(|v| v.parse().ok()).unwrap_or(0);
        for p in sub.all("pin") {
            let (x, y, _) = p.at()?;
            out.pins.push(LibPin {
                number: p
                    .get("number")
                    .and_then(|n| n.atom(0))
                    .unwrap_or_default()
                    .to_owned(),
                name: p
                    .get("name")
                    .and_then(|n| n.atom(0))
                    .unwrap_or_default()
                    .to_owned(),
                x,
                y,
                power_in: p.atom(0) == Some("power_in"),
                hidden: p.flag("hide"),
                unit,
                style,
            });
        }
    }
    Ok(out)
}

/// Where a library point goes on the sheet for a symbol at `(ox, oy)` turned by `angle` and
/// mirrored by `mirror` (`x`, `y` or none).
pub(crate) fn place_point(
    x: f64,
    y: f64,
    ox: f64,
    oy: f64,
    angle: f64,
    mirror: Option<&str>,
) -> Pt {
    // Library y up → sheet y down.
    let (x, y) = (x, -y);
    // Counter-clockwise on screen, where y points down.
    let (s, c) = angle.to_radians().sin_cos();
    let (mut rx, mut ry) = (x * c + y * s, -x * s + y * c);
    match mirror {
        Some("x") => ry = -ry,
        Some("y") => rx = -rx,
        _ => {}
    }
    pt(ox + rx, oy + ry)
}

fn symbol(s: Node<'_>, lib: &BTreeMap<String, LibSymbol>) -> Result<Symbol, KicadError> {
    let lib_id = s.req("lib_id")?.req_atom(0, "the library id")?;
    let lib_name = s.get("lib_name").and_then(|n| n.atom(0)).unwrap_or(lib_id);
    let reference = s.property("Reference").unwrap_or_default().to_owned();
    let Some(ls) = lib.get(lib_name) else {
        return Err(KicadError::UnknownSymbol {
            path: s.path(),
            line: s.line(),
            reference,
            lib_id: lib_name.to_owned(),
        });
    };
    let (ox, oy, angle) = s.at()?;
    let mirror = s.get("mirror").and_then(|m| m.atom(0));
    let unit = s
        .get("unit")
        .map(|u| u.num(0, "a unit number"))
        .transpose()?
        .map_or(1, round);
    let style = s
        .get("convert")
        .or_else(|| s.get("body_style"))
        .map(|u| u.num(0, "a body style"))
        .transpose()?
        .map_or(1, round);
    let power = ls.power.is_some();
    let pins = ls
        .pins
        .iter()
        .filter(|p| p.style == 0 || p.style == style)
        .map(|p| PlacedPin {
            number: p.number.clone(),
            name: p.name.clone(),
            at: place_point(p.x, p.y, ox, oy, angle, mirror),
            power_in: p.power_in,
            hidden: p.hidden,
            unit: p.unit,
        })
        .collect();
    let mut instances = Vec::new();
    if let Some(inst) = s.get("instances") {
        for project in inst.all("project") {
            for p in project.all("path") {
                let reference = p
                    .get("reference")
                    .and_then(|r| r.atom(0))
                    .unwrap_or_default();
                let u = p
                    .get("unit")
                    .map(|u| u.num(0, "a unit number"))
                    .transpose()?;
                instances.push((
                    p.req_atom(0, "the instance path")?.to_owned(),
                    reference.to_owned(),
                    u.map_or(unit, round),
                ));
            }
        }
    }
    Ok(Symbol {
        uuid: s
            .get("uuid")
            .and_then(|u| u.atom(0))
            .unwrap_or_default()
            .to_owned(),
        reference,
        value: s.property("Value").unwrap_or_default().to_owned(),
        footprint: s.property("Footprint").unwrap_or_default().to_owned(),
        unit,
        power,
        local_power: ls.power == Some(true),
        on_board: s.get("on_board").and_then(|o| o.atom(0)) != Some("no"),
        pins,
        instances,
    })
}

fn sheet(s: Node<'_>) -> Result<SheetRef, KicadError> {
    // "Sheetname"/"Sheetfile" (KiCad 8+), "Sheet name"/"Sheet file" (KiCad 6-7), or, in files
    // saved by a translated KiCad 6, the properties with `(id 0)` and `(id 1)`: by name, else by
    // id, else the first and second property.
    let nth = |names: [&str; 2], id: &str, i: usize| {
        names
            .iter()
            .find_map(|n| s.property(n))
            .or_else(|| {
                s.all("property")
                    .find(|p| p.get("id").and_then(|v| v.atom(0)) == Some(id))
                    .and_then(|p| p.atom(1))
            })
            .or_else(|| s.all("property").nth(i).and_then(|p| p.atom(1)))
    };
    let name = nth(["Sheetname", "Sheet name"], "0", 0).unwrap_or_default();
    let file = nth(["Sheetfile", "Sheet file"], "1", 1)
        .ok_or_else(|| s.missing("(property \"Sheetfile\" …)"))?;
    let mut pins = Vec::new();
    for p in s.all("pin") {
        let (x, y, _) = p.at()?;
        pins.push((p.req_atom(0, "the sheet pin's name")?.to_owned(), pt(x, y)));
    }
    Ok(SheetRef {
        uuid: s
            .get("uuid")
            .and_then(|u| u.atom(0))
            .unwrap_or_default()
            .to_owned(),
        name: name.to_owned(),
        file: file.to_owned(),
        pins,
    })
}

/// One instance of a sheet file in the hierarchy.
#[derive(Debug, Clone)]
pub(crate) struct Instance {
    /// Index into the files.
    pub file: usize,
    /// Sheet uuids from the root (empty for the root).
    pub uuids: Vec<String>,
    /// `/name/name/` path of sheet names, as KiCad names nets.
    pub name_path: String,
    /// The parent instance and the index of this sheet in its file's sheets.
    pub parent: Option<(usize, usize)>,
}

/// Every file of a hierarchy and its instances, root first.
#[derive(Debug, Clone, Default)]
pub(crate) struct Hierarchy {
    pub files: Vec<SheetFile>,
    pub instances: Vec<Instance>,
}

/// Reads a root sheet and, through `load`, every sheet it instances.
pub(crate) fn hierarchy(
    root: &[u8],
    root_name: &Path,
    load: &mut dyn FnMut(&Path) -> std::io::Result<Vec<u8>>,
) -> Result<Hierarchy, KicadError> {
    let tree = sexpr::parse(root)?;
    let r = tree.root();
    if r.keyword() != "kicad_sch" {
        return Err(crate::wrong_kind(r.keyword(), "schematic"));
    }
    let mut h = Hierarchy::default();
    let mut by_path: BTreeMap<PathBuf, usize> = BTreeMap::new();
    h.files.push(read_file(r)?);
    by_path.insert(root_name.to_path_buf(), 0);
    h.instances.push(Instance {
        file: 0,
        uuids: Vec::new(),
        name_path: "/".to_owned(),
        parent: None,
    });
    // Depth-first over instances; `stack` holds the file paths of the current branch.
    let mut todo = vec![(0usize, vec![root_name.to_path_buf()])];
    while let Some((inst, branch)) = todo.pop() {
        let file = h.instances[inst].file;
        let dir = branch
            .last()
            .and_then(|p| p.parent())
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let sheets = h.files[file].sheets.clone();
        for (i, s) in sheets.iter().enumerate() {
            let path = dir.join(&s.file);
            if branch.contains(&path) {
                return Err(KicadError::RecursiveSheet { file: path });
            }
            let idx = match by_path.get(&path) {
                Some(&i) => i,
                None => {
                    let bytes = load(&path).map_err(|error| KicadError::SheetIo {
                        file: path.clone(),
                        error,
                    })?;
                    let wrap = |source| KicadError::Sheet {
                        file: path.clone(),
                        source: Box::new(source),
                    };
                    let t = sexpr::parse(&bytes).map_err(wrap)?;
                    if t.root().keyword() != "kicad_sch" {
                        return Err(wrap(crate::wrong_kind(t.root().keyword(), "schematic")));
                    }
                    h.files.push(read_file(t.root()).map_err(wrap)?);
                    by_path.insert(path.clone(), h.files.len() - 1);
                    h.files.len() - 1
                }
            };
            if h.instances.len() >= MAX_SHEET_INSTANCES {
                return Err(KicadError::TooManySheets {
                    limit: MAX_SHEET_INSTANCES,
                });
            }
            let parent = &h.instances[inst];
            let mut uuids = parent.uuids.clone();
            uuids.push(s.uuid.clone());
            let name_path = format!("{}{}/", parent.name_path, s.name);
            h.instances.push(Instance {
                file: idx,
                uuids,
                name_path,
                parent: Some((inst, i)),
            });
            let mut b = branch.clone();
            b.push(path);
            todo.push((h.instances.len() - 1, b));
        }
    }
    Ok(h)
}

impl Hierarchy {
    /// A symbol's reference and unit in an instance: from the root's KiCad 6 instance table,
    /// the symbol's own KiCad 7+ instance list, or its `Reference` property.
    pub(crate) fn reference(&self, inst: &Instance, sym: &Symbol) -> (String, i64) {
        let mut key = String::new();
        for u in &inst.uuids {
            key.push('/');
            key.push_str(u);
        }
        let sheet_path = key.clone();
        key.push('/');
        key.push_str(&sym.uuid);
        if let Some((r, u)) = self.files[0].symbol_instances.get(&key) {
            return (r.clone(), *u);
        }
        for (path, r, u) in &sym.instances {
            // KiCad 7+ paths start with the root sheet's uuid.
            let rest = path
                .strip_prefix('/')
                .map(|p| p.split_once('/').map_or("", |(_, rest)| rest))
                .unwrap_or_default();
            let rest = if rest.is_empty() {
                String::new()
            } else {
                format!("/{rest}")
            };
            if rest == sheet_path {
                return (r.clone(), *u);
            }
        }
        (sym.reference.clone(), sym.unit)
    }
}
