//! Schematics (`.sch`): parts resolved to packages, nets resolved to pads, modules flattened.

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

use crate::doc::{Doc, Node};
use crate::error::EagleError;
use crate::library::{DeviceSet, Libraries, Library, Package, lookup};
use crate::netlist::{Net, Netlist, to_netlist};

/// A schematic part, resolved through its library to a device and package.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// Part name, e.g. `R1`. Parts inside module instances are named as EAGLE names them on the
    /// board: `INSTANCE:PART` (nested: `OUTER:INNER:PART`), or the part name renumbered by the
    /// instance's `offset` when that is non-zero (`R1` with offset 100 becomes `R101`).
    pub name: String,
    /// Library name.
    pub library: String,
    /// Device set name.
    pub deviceset: String,
    /// Device (package variant) name; often empty.
    pub device: String,
    /// The `value` attribute, if set.
    pub value: Option<String>,
    /// The package; `None` for supply symbols, frames and other package-less devices.
    pub package: Option<Package>,
    /// `gate.pin` (e.g. `G$1.P1`, `A.1`) -> pad names. A pin connected to several pads
    /// (`<connect pad="1 3">`) lists all of them.
    pub pin_pads: BTreeMap<String, Vec<String>>,
    /// The pins of `pin_pads` connected with `route="any"`: their pads are joined inside the
    /// part, so wiring one of them connects the pin.
    pub route_any: BTreeSet<String>,
}

/// A schematic, flattened: all sheets and module instances merged into one part list and one
/// netlist.
#[derive(Debug, Clone, PartialEq)]
pub struct Schematic {
    /// The `version` attribute of `<eagle>`, e.g. `9.1.0`.
    pub version: String,
    /// Parts with a package, in file order (module instance parts after the top level's).
    pub parts: Vec<Part>,
    /// Names of parts without a package (supply symbols, frames, logos drawn as symbols).
    pub dropped_parts: Vec<String>,
    /// Nets resolved to `(part, pad)`, sorted by name. Nets with the same name on several
    /// sheets are one net, as in EAGLE. Pins of parts without a package contribute nothing, so
    /// a net may have fewer than two pads (or none).
    pub nets: Vec<Net>,
}

impl Schematic {
    /// Net name -> pads.
    pub fn netlist(&self) -> Netlist {
        to_netlist(&self.nets)
    }

    /// The part named `name`.
    pub fn part(&self, name: &str) -> Option<&Part> {
        self.parts.iter().find(|p| p.name == name)
    }
}

/// Reads the `<schematic>` element of a parsed document.
pub(crate) fn read(doc: &Doc, version: String, sch: &Node) -> Result<Schematic, EagleError> {
    let libs = Libraries::read(doc, sch)?;
    let classes = sch
        .list("classes", "class")
        .filter_map(|c| Some((c.attr("number")?.to_owned(), c.attr("name")?.to_owned())))
        .collect();
    let modules = sch
        .list("modules", "module")
        .map(|m| Ok((doc.req(m, "name")?.to_owned(), m)))
        .collect::<Result<BTreeMap<_, _>, EagleError>>()?;
    let mut f = Flattener {
        doc,
        libs: &libs,
        classes,
        modules,
        parts: Vec::new(),
        dropped: Vec::new(),
        nets: Vec::new(),
        parent: Vec::new(),
        by_key: HashMap::new(),
        stack: Vec::new(),
        expansions: 0,
    };
    f.scope(sch, &[])?;
    let nets = f.finish();
    Ok(Schematic {
        version,
        parts: f.parts,
        dropped_parts: f.dropped,
        nets,
    })
}

/// One step of a module instance path: instance name and part-number offset.
#[derive(Debug, Clone)]
struct InstStep {
    name: String,
    offset: i64,
}

/// A net of one scope before merging; `depth` is the module nesting level.
#[derive(Debug)]
struct NetNode {
    name: String,
    depth: usize,
    class: Option<String>,
    pads: BTreeSet<(String, String)>,
}

/// `(part, gate, pin)` of the pins that a scope's nets reference.
type Wired = HashSet<(String, String, String)>;

/// A net of the scope being flattened, as its pin references see it.
struct ScopeNet<'n> {
    /// Its node in the union-find.
    id: usize,
    /// Its name in the scope.
    name: &'n str,
    class: Option<String>,
    /// The module nesting level of the scope.
    depth: usize,
}

/// A part as seen from inside its scope.
struct LocalPart<'l> {
    full: String,
    has_package: bool,
    pin_pads: BTreeMap<String, Vec<String>>,
    lib: &'l Library,
    deviceset: &'l DeviceSet,
}

struct Flattener<'d, 'l> {
    doc: &'d Doc,
    libs: &'l Libraries,
    classes: HashMap<String, String>,
    modules: BTreeMap<String, &'d Node>,
    parts: Vec<Part>,
    dropped: Vec<String>,
    /// Union-find over scope nets.
    nets: Vec<NetNode>,
    parent: Vec<usize>,
    by_key: HashMap<String, usize>,
    /// Modules being expanded, to catch recursion.
    stack: Vec<String>,
    /// Module instances expanded so far (nested instances count once per expansion).
    expansions: usize,
}

/// Most module instances a flattened design may expand to. Real designs use a handful; the cap
/// stops a small file whose modules nest many instances of each other from expanding
/// exponentially.
const MAX_MODULE_INSTANCES: usize = 100_000;

/// Name of a part at the top level, given its name inside the instance path `path`.
fn full_part_name(path: &[InstStep], local: &str) -> String {
    let mut name = local.to_owned();
    for step in path.iter().rev() {
        name = match renumber(&name, step.offset) {
            Some(n) => n,
            None => format!("{}:{}", step.name, name),
        };
    }
    name
}

/// `R1` + 100 -> `R101`; `None` for offset 0 or a name without a trailing number.
fn renumber(name: &str, offset: i64) -> Option<String> {
    if offset == 0 {
        return None;
    }
    let digits = name.len() - name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    if digits == 0 {
        return None;
    }
    let (stem, num) = name.split_at(name.len() - digits);
    let n: i64 = num.parse().ok()?;
    Some(format!("{stem}{}", n.checked_add(offset)?))
}

/// Net name prefix of an instance path: `A:B:`.
fn net_prefix(path: &[InstStep]) -> String {
    path.iter().map(|s| format!("{}:", s.name)).collect()
}

/// EAGLE shows `GND@1` as `GND`; implicit power nets take the part before `@`.
fn pin_net_name(pin: &str) -> &str {
    pin.split('@').next().unwrap_or(pin)
}

impl<'d, 'l> Flattener<'d, 'l> {
    fn node(&mut self, key: String, depth: usize, class: Option<String>) -> usize {
        if let Some(&i) = self.by_key.get(&key) {
            if self.nets[i].class.is_none() {
                self.nets[i].class = class;
            }
            return i;
        }
        let i = self.nets.len();
        self.nets.push(NetNode {
            name: key.clone(),
            depth,
            class,
            pads: BTreeSet::new(),
        });
        self.parent.push(i);
        self.by_key.insert(key, i);
        i
    }

    fn root(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.root(a), self.root(b));
        if ra != rb {
            self.parent[rb] = ra;
        }
    }

    fn class_name(&self, n: &Node) -> Option<String> {
        let c = n.attr("class")?;
        Some(self.classes.get(c).cloned().unwrap_or_else(|| c.to_owned()))
    }

    /// Resolves the parts of one scope (top level or module) and records them.
    fn resolve_parts(
        &mut self,
        scope: &'d Node,
        path: &[InstStep],
    ) -> Result<HashMap<String, LocalPart<'l>>, EagleError> {
        let doc = self.doc;
        let mut local = HashMap::new();
        for p in scope.list("parts", "part") {
            let name = doc.req(p, "name")?;
            let library = doc.req(p, "library")?;
            let deviceset = doc.req(p, "deviceset")?;
            let device = p.attr("device").unwrap_or_default();
            let line = doc.line(p.pos);
            let lib = self
                .libs
                .find(library, p.attr("library_urn"))
                .ok_or_else(|| EagleError::UnknownLibrary {
                    element: "part",
                    name: name.to_owned(),
                    library: library.to_owned(),
                    line,
                })?;
            let unknown_device = || EagleError::UnknownDevice {
                part: name.to_owned(),
                library: library.to_owned(),
                deviceset: deviceset.to_owned(),
                device: device.to_owned(),
                line,
            };
            let ds = lookup(&lib.devicesets, deviceset).ok_or_else(unknown_device)?;
            let dev = lookup(&ds.devices, device).ok_or_else(unknown_device)?;
            let package = match &dev.package {
                None => None,
                Some(pkg) => Some(lookup(&lib.packages, pkg).cloned().ok_or_else(|| {
                    EagleError::UnknownPackage {
                        owner: format!("{deviceset}/{device}"),
                        library: library.to_owned(),
                        package: pkg.clone(),
                        line: doc.line(dev.pos),
                    }
                })?),
            };
            let full = full_part_name(path, name);
            let has_package = package.is_some();
            let pin_pads = if has_package {
                dev.connects.clone()
            } else {
                BTreeMap::new()
            };
            if has_package {
                self.parts.push(Part {
                    name: full.clone(),
                    library: lib.name.clone(),
                    deviceset: deviceset.to_owned(),
                    device: device.to_owned(),
                    value: p.attr("value").map(str::to_owned),
                    package,
                    pin_pads: pin_pads.clone(),
                    route_any: dev.route_any.clone(),
                });
            } else {
                self.dropped.push(full.clone());
            }
            local.insert(
                name.to_owned(),
                LocalPart {
                    full,
                    has_package,
                    pin_pads,
                    lib,
                    deviceset: ds,
                },
            );
        }
        Ok(local)
    }

    /// Direction of `gate`'s symbol pin `pin` (`io` when unknown).
    fn pin_direction<'p>(part: &'p LocalPart<'_>, gate: &str, pin: &str) -> &'p str {
        part.deviceset
            .gates
            .iter()
            .find(|g| g.name == gate)
            .and_then(|g| lookup(&part.lib.symbols, &g.symbol))
            .and_then(|pins| pins.iter().find(|p| p.name == pin))
            .map_or("io", |p| p.direction.as_str())
    }

    /// Flattens one scope: its parts, nets, and (recursively) its module instances.
    fn scope(&mut self, scope: &'d Node, path: &[InstStep]) -> Result<(), EagleError> {
        let local = self.resolve_parts(scope, path)?;
        let insts = self.module_instances(scope, path)?;
        let wired = self.scope_nets(scope, path, &local, &insts)?;
        self.implicit_power(&local, &wired);
        Ok(())
    }

    /// Expands the module instances of a scope, depth-first; returns their names.
    fn module_instances(
        &mut self,
        scope: &'d Node,
        path: &[InstStep],
    ) -> Result<HashSet<String>, EagleError> {
        let doc = self.doc;
        let mut insts = HashSet::new();
        for mi in scope
            .list("sheets", "sheet")
            .flat_map(|s| s.list("moduleinsts", "moduleinst"))
        {
            let name = doc.req(mi, "name")?;
            let module = doc.req(mi, "module")?;
            let def = *lookup(&self.modules, module).ok_or_else(|| EagleError::UnknownModule {
                instance: name.to_owned(),
                module: module.to_owned(),
                line: doc.line(mi.pos),
            })?;
            let def_name = def.attr("name").unwrap_or(module).to_owned();
            if self.stack.contains(&def_name) {
                return Err(EagleError::RecursiveModule { module: def_name });
            }
            insts.insert(name.to_owned());
            self.expansions += 1;
            if self.expansions > MAX_MODULE_INSTANCES {
                return Err(EagleError::TooManyModuleInstances {
                    limit: MAX_MODULE_INSTANCES,
                });
            }
            let mut inner = path.to_vec();
            inner.push(InstStep {
                name: name.to_owned(),
                offset: doc.opt_i64(mi, "offset")?.unwrap_or(0),
            });
            self.stack.push(def_name);
            self.scope(def, &inner)?;
            self.stack.pop();
        }
        Ok(insts)
    }

    /// Records the nets of a scope (same name on several sheets = same net) with the pads of
    /// their pin references, joined to the module instances' port nets; returns the pins
    /// wired to a net.
    fn scope_nets(
        &mut self,
        scope: &'d Node,
        path: &[InstStep],
        local: &HashMap<String, LocalPart<'l>>,
        insts: &HashSet<String>,
    ) -> Result<Wired, EagleError> {
        let doc = self.doc;
        let depth = path.len();
        let prefix = net_prefix(path);
        let mut wired = Wired::new();
        for net in scope
            .list("sheets", "sheet")
            .flat_map(|s| s.list("nets", "net"))
        {
            let name = doc.req(net, "name")?;
            let class = self.class_name(net);
            let id = self.node(format!("{prefix}{name}"), depth, class.clone());
            let at = ScopeNet {
                id,
                name,
                class,
                depth,
            };
            for seg in net.children_named("segment") {
                for r in &seg.children {
                    match r.name.as_str() {
                        "pinref" => self.pinref(r, &at, local, &mut wired)?,
                        "portref" => {
                            let inst = doc.req(r, "moduleinst")?;
                            let port = doc.req(r, "port")?;
                            if !insts.contains(inst) {
                                return Err(EagleError::UnknownReference {
                                    element: "portref",
                                    kind: "module instance",
                                    name: inst.to_owned(),
                                    line: doc.line(r.pos),
                                });
                            }
                            let inner =
                                self.node(format!("{prefix}{inst}:{port}"), depth + 1, None);
                            self.union(id, inner);
                        }
                        _ => {}
                    }
                }
            }
        }
        Ok(wired)
    }

    /// A `<pinref>` of net `at`: the pads of the pin join the net; a supply symbol's pin inside
    /// a module joins the net to the global net of the same name.
    fn pinref(
        &mut self,
        r: &Node,
        at: &ScopeNet<'_>,
        local: &HashMap<String, LocalPart<'l>>,
        wired: &mut Wired,
    ) -> Result<(), EagleError> {
        let doc = self.doc;
        let pname = doc.req(r, "part")?;
        let gate = doc.req(r, "gate")?;
        let pin = doc.req(r, "pin")?;
        let (key, part) = local
            .get_key_value(pname)
            .or_else(|| local.iter().find(|(k, _)| k.eq_ignore_ascii_case(pname)))
            .ok_or_else(|| EagleError::UnknownReference {
                element: "pinref",
                kind: "part",
                name: pname.to_owned(),
                line: doc.line(r.pos),
            })?;
        wired.insert((key.clone(), gate.to_owned(), pin.to_owned()));
        if part.has_package {
            if let Some(pads) = part.pin_pads.get(&format!("{gate}.{pin}")) {
                for pad in pads {
                    self.nets[at.id]
                        .pads
                        .insert((part.full.clone(), pad.clone()));
                }
            }
        } else if at.depth > 0 && Self::pin_direction(part, gate, pin) == "sup" {
            // A supply symbol inside a module: supply nets are global.
            let global = self.node(at.name.to_owned(), 0, at.class.clone());
            self.union(global, at.id);
        }
        Ok(())
    }

    /// Implicit power: `pwr` pins not wired to any net join the (global) net named after
    /// the pin, whether or not their gate is placed on a sheet.
    fn implicit_power(&mut self, local: &HashMap<String, LocalPart<'l>>, wired: &Wired) {
        let mut names: Vec<&String> = local.keys().collect();
        names.sort();
        for pname in names {
            let part = &local[pname];
            if !part.has_package {
                continue;
            }
            for gate in &part.deviceset.gates {
                let Some(pins) = lookup(&part.lib.symbols, &gate.symbol) else {
                    continue;
                };
                for pin in pins.iter().filter(|p| p.direction == "pwr") {
                    if wired.contains(&(pname.clone(), gate.name.clone(), pin.name.clone())) {
                        continue;
                    }
                    let Some(pads) = part.pin_pads.get(&format!("{}.{}", gate.name, pin.name))
                    else {
                        continue;
                    };
                    let id = self.node(pin_net_name(&pin.name).to_owned(), 0, None);
                    for pad in pads {
                        self.nets[id].pads.insert((part.full.clone(), pad.clone()));
                    }
                }
            }
        }
    }

    /// Merges joined scope nets; the outermost (then alphabetically first) name wins.
    fn finish(&mut self) -> Vec<Net> {
        let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for i in 0..self.nets.len() {
            let r = self.root(i);
            groups.entry(r).or_default().push(i);
        }
        let mut out: Vec<Net> = groups
            .into_values()
            .map(|members| {
                let best = members
                    .iter()
                    .copied()
                    .min_by(|&a, &b| {
                        let (na, nb) = (&self.nets[a], &self.nets[b]);
                        (na.depth, &na.name).cmp(&(nb.depth, &nb.name))
                    })
                    .unwrap_or(members[0]);
                let mut net = Net {
                    name: self.nets[best].name.clone(),
                    class: self.nets[best].class.clone(),
                    pads: BTreeSet::new(),
                };
                for &m in &members {
                    net.pads.extend(self.nets[m].pads.iter().cloned());
                    if net.class.is_none() {
                        net.class = self.nets[m].class.clone();
                    }
                }
                net
            })
            .collect();
        out.sort_by(|a, b| a.name.cmp(&b.name));
        out
    }
}
