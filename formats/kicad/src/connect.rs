//! The schematic's nets: sheet instances connected the way KiCad's connection graph does.
//!
//! Last step of the schematic reader. In each sheet instance, wires join at their ends;
//! a junction, a label, a pin or a sheet pin joins every wire it lies on, and every item at the
//! same point. Across the design, groups join by name: local labels within their sheet
//! instance, global labels and power symbols (by value) everywhere, hidden power-input pins of
//! ordinary symbols by pin name, a hierarchical label with its parent's sheet pin. Buses carry
//! vector members (`D[0..7]` is `D0`…`D7`): every vector name on a connected piece of bus joins
//! its members index by index with the others', and a member joins the labels of its name.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use crate::sch::{Hierarchy, LabelKind, Pt};

/// A net of the schematic.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct SchNet {
    /// Net name: the global label or power value, else the sheet path and local label
    /// (`/sheet/NAME`), else `Net-(REF-PadN)` after its first pad.
    pub name: String,
    /// The pads as `(reference, pin number)`.
    pub pads: BTreeSet<(String, String)>,
}

/// A part of the schematic: all units of one reference.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct SchPart {
    /// Reference designator.
    pub reference: String,
    /// Value.
    pub value: String,
    /// Library footprint (`Lib:Name`), empty when none is assigned.
    pub footprint: String,
    /// Pin numbers of all its placed units (the footprint's pad numbers).
    pub pins: BTreeSet<String>,
}

#[derive(Default)]
struct Dsu(Vec<usize>);

impl Dsu {
    fn add(&mut self) -> usize {
        self.0.push(self.0.len());
        self.0.len() - 1
    }
    fn find(&mut self, mut a: usize) -> usize {
        while self.0[a] != a {
            self.0[a] = self.0[self.0[a]];
            a = self.0[a];
        }
        a
    }
    fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.0[a.max(b)] = a.min(b);
        }
    }
}

/// True when `p` lies on the segment `a`–`b` (ends included).
fn on_segment(p: Pt, a: Pt, b: Pt) -> bool {
    let cross = i128::from(b.0 - a.0) * i128::from(p.1 - a.1)
        - i128::from(b.1 - a.1) * i128::from(p.0 - a.0);
    cross == 0
        && p.0 >= a.0.min(b.0)
        && p.0 <= a.0.max(b.0)
        && p.1 >= a.1.min(b.1)
        && p.1 <= a.1.max(b.1)
}

/// The members of a vector name `PREFIX[a..b]`, or `None` for a plain name.
pub(crate) fn bus_members(name: &str) -> Option<Vec<String>> {
    let (prefix, rest) = name.split_once('[')?;
    let range = rest.strip_suffix(']')?;
    let (a, b) = range.split_once("..")?;
    let (a, b): (i64, i64) = (a.trim().parse().ok()?, b.trim().parse().ok()?);
    if (a - b).abs() > 1024 {
        return None;
    }
    let step = if b >= a { 1 } else { -1 };
    let mut out = Vec::new();
    let mut i = a;
    loop {
        out.push(format!("{prefix}{i}"));
        if i == b {
            return Some(out);
        }
        i += step;
    }
}

/// The first schematic format version of KiCad 7 (power symbols named by their value).
const KICAD7_SCH: u32 = 20_230_121;

/// A pin reached in the design: its group, reference and number.
struct PinHit {
    node: usize,
    reference: String,
    number: String,
}

/// The connection graph being built: groups, the names that join them, and the pins.
#[derive(Default)]
struct Graph {
    dsu: Dsu,
    /// Name key (`global:GND`, `/sheet/NAME`) → its node.
    named: HashMap<String, usize>,
    /// Name node → the names it shows, with their rank (lower wins).
    names: BTreeMap<usize, Vec<(u8, String)>>,
    hits: Vec<PinHit>,
    parts: BTreeMap<String, SchPart>,
    /// Per instance: the node of each sheet pin of its sheets, by (sheet index, pin name).
    sheet_pins: Vec<BTreeMap<(usize, String), usize>>,
}

impl Graph {
    /// The node of a name key, made on first use and shown as `shown` with `rank`.
    fn name(&mut self, key: String, rank: u8, shown: String) -> usize {
        let dsu = &mut self.dsu;
        let k = *self.named.entry(key).or_insert_with(|| dsu.add());
        self.names.entry(k).or_default().push((rank, shown));
        k
    }

    /// Joins `node` to the name key.
    fn join_name(&mut self, node: usize, key: String, rank: u8, shown: String) {
        let k = self.name(key, rank, shown);
        self.dsu.union(node, k);
    }

    /// Joins two name keys when both exist.
    fn join_keys(&mut self, a: &str, b: &str) {
        if let (Some(&x), Some(&y)) = (self.named.get(a), self.named.get(b)) {
            self.dsu.union(x, y);
        }
    }
}

/// One sheet instance's items on the graph: wires and buses as nodes, point items joined to
/// the segments they lie on and to each other.
struct Sheet<'a> {
    f: &'a crate::sch::SheetFile,
    base: usize,
    at: HashMap<Pt, Vec<usize>>,
}

impl Sheet<'_> {
    fn wire(&self, i: usize) -> usize {
        self.base + i
    }
    fn bus(&self, i: usize) -> usize {
        self.base + self.f.wires.len() + i
    }

    /// A new node for a point item, joined to the wires (or buses) it lies on.
    fn attach(&mut self, g: &mut Graph, p: Pt, buses: bool) -> usize {
        self.attach_to(g, p, buses, true)
    }

    /// A new node for a point item, joined to the segments it ends (`inner` false) or lies on.
    fn attach_to(&mut self, g: &mut Graph, p: Pt, buses: bool, inner: bool) -> usize {
        let n = g.dsu.add();
        if !inner {
            self.at.entry(p).or_default().push(n);
            return n;
        }
        let segs: &[(Pt, Pt)] = if buses { &self.f.buses } else { &self.f.wires };
        for (i, &(a, b)) in segs.iter().enumerate() {
            if on_segment(p, a, b) {
                g.dsu
                    .union(n, if buses { self.bus(i) } else { self.wire(i) });
            }
        }
        self.at.entry(p).or_default().push(n);
        n
    }
}

/// Netlists the hierarchy: the parts and the nets with at least one pad.
pub(crate) fn netlist(h: &Hierarchy) -> (Vec<SchPart>, Vec<SchNet>) {
    let mut g = Graph::default();
    for inst in &h.instances {
        add_instance(&mut g, h, inst);
    }
    // Hierarchical labels join their parent's sheet pins (vector members by name).
    for inst in &h.instances {
        let Some((parent, si)) = inst.parent else {
            continue;
        };
        let pscope = &h.instances[parent].name_path;
        for l in &h.files[inst.file].labels {
            if l.kind != LabelKind::Hierarchical {
                continue;
            }
            let Some(&pin) = g.sheet_pins[parent].get(&(si, l.name.clone())) else {
                continue;
            };
            match bus_members(&l.name) {
                None => {
                    if let Some(&k) = g.named.get(&format!("{}{}", inst.name_path, l.name)) {
                        g.dsu.union(pin, k);
                    }
                }
                Some(members) => {
                    for m in members {
                        g.join_keys(&format!("{}{m}", inst.name_path), &format!("{pscope}{m}"));
                    }
                }
            }
        }
    }
    let nets = gather(&mut g);
    (std::mem::take(&mut g.parts).into_values().collect(), nets)
}

fn add_instance(g: &mut Graph, h: &Hierarchy, inst: &crate::sch::Instance) {
    let f = &h.files[inst.file];
    let scope = &inst.name_path;
    let mut sh = Sheet {
        f,
        base: g.dsu.0.len(),
        at: HashMap::new(),
    };
    for _ in 0..f.wires.len() + f.buses.len() {
        g.dsu.add();
    }
    for (i, &(a, b)) in f.wires.iter().enumerate() {
        let w = sh.wire(i);
        sh.at.entry(a).or_default().push(w);
        sh.at.entry(b).or_default().push(w);
    }
    for (i, &(a, b)) in f.buses.iter().enumerate() {
        let w = sh.bus(i);
        sh.at.entry(a).or_default().push(w);
        sh.at.entry(b).or_default().push(w);
    }
    for &j in &f.junctions {
        sh.attach(g, j, false);
        sh.attach(g, j, true);
    }
    for l in &f.labels {
        let vector = bus_members(&l.name).is_some();
        let n = sh.attach(g, l.at, vector);
        if !vector {
            let (key, rank, shown) = match l.kind {
                LabelKind::Global => (format!("global:{}", l.name), 0, l.name.clone()),
                LabelKind::Local | LabelKind::Hierarchical => {
                    let k = format!("{scope}{}", l.name);
                    (k.clone(), 1, k)
                }
            };
            g.join_name(n, key, rank, shown);
        }
    }
    let mut pins_here = BTreeMap::new();
    for (si, s) in f.sheets.iter().enumerate() {
        for (name, p) in &s.pins {
            let n = sh.attach(g, *p, bus_members(name).is_some());
            pins_here.insert((si, name.clone()), n);
        }
    }
    g.sheet_pins.push(pins_here);
    for sym in &f.symbols {
        add_symbol(g, h, inst, &mut sh, sym);
    }
    // Everything at one point is one node.
    for nodes in sh.at.values() {
        for w in nodes.windows(2) {
            g.dsu.union(w[0], w[1]);
        }
    }
    add_buses(g, &sh, scope);
}

fn add_symbol(
    g: &mut Graph,
    h: &Hierarchy,
    inst: &crate::sch::Instance,
    sh: &mut Sheet<'_>,
    sym: &crate::sch::Symbol,
) {
    let scope = &inst.name_path;
    let (reference, unit) = h.reference(inst, sym);
    let is_part = !sym.power && sym.on_board && !reference.starts_with('#');
    let pins: Vec<_> = sym
        .pins
        .iter()
        .filter(|p| p.unit == 0 || p.unit == unit)
        .collect();
    for pin in &pins {
        let n = sh.attach_to(g, pin.at, false, false);
        // KiCad's power connection: a power input that is hidden or on a power symbol. A
        // power symbol's net is its value from KiCad 7 on, its pin's name in KiCad 6 files; a
        // hidden pin's net is its name.
        if pin.power_in && (pin.hidden || sym.power) {
            let kicad7 = h.files[inst.file].version >= KICAD7_SCH;
            let name = if sym.power && kicad7 && !sym.value.is_empty() {
                &sym.value
            } else {
                &pin.name
            };
            let (key, shown) = if sym.local_power {
                let k = format!("{scope}{name}");
                (k.clone(), k)
            } else {
                (format!("global:{name}"), name.clone())
            };
            g.join_name(n, key, 0, shown);
        }
        if is_part {
            g.hits.push(PinHit {
                node: n,
                reference: reference.clone(),
                number: pin.number.clone(),
            });
        }
    }
    if is_part {
        let part = g.parts.entry(reference.clone()).or_insert_with(|| SchPart {
            reference,
            value: sym.value.clone(),
            footprint: sym.footprint.clone(),
            pins: BTreeSet::new(),
        });
        if part.footprint.is_empty() {
            part.footprint.clone_from(&sym.footprint);
        }
        part.pins.extend(pins.iter().map(|p| p.number.clone()));
    }
}

/// Bus vectors: every vector name on one piece of bus joins its members index by index with
/// the others', and each member joins the labels of its name.
fn add_buses(g: &mut Graph, sh: &Sheet<'_>, scope: &str) {
    let f = sh.f;
    let mut vectors: BTreeMap<usize, Vec<Vec<String>>> = BTreeMap::new();
    let bus_names = f
        .labels
        .iter()
        .map(|l| (l.name.as_str(), l.at, l.kind))
        .chain(f.sheets.iter().flat_map(|s| {
            s.pins
                .iter()
                .map(|(n, p)| (n.as_str(), *p, LabelKind::Local))
        }));
    for (name, p, kind) in bus_names {
        let Some(members) = bus_members(name) else {
            continue;
        };
        let mut keyed = Vec::new();
        for m in members {
            let (key, shown) = match kind {
                LabelKind::Global => (format!("global:{m}"), m),
                _ => {
                    let k = format!("{scope}{m}");
                    (k.clone(), k)
                }
            };
            g.name(key.clone(), 2, shown);
            keyed.push(key);
        }
        let on_bus = f
            .buses
            .iter()
            .position(|&(a, b)| on_segment(p, a, b))
            .map(|i| sh.bus(i));
        if let Some(seg) = on_bus {
            let root = g.dsu.find(seg);
            vectors.entry(root).or_default().push(keyed);
        }
    }
    for group in vectors.values() {
        for other in group.iter().skip(1) {
            for (a, b) in group[0].iter().zip(other) {
                g.join_keys(a, b);
            }
        }
    }
}

/// The nets with at least one pad, each named by its best name.
fn gather(g: &mut Graph) -> Vec<SchNet> {
    let mut by_root: BTreeMap<usize, SchNet> = BTreeMap::new();
    for hit in &g.hits {
        let r = g.dsu.find(hit.node);
        by_root
            .entry(r)
            .or_default()
            .pads
            .insert((hit.reference.clone(), hit.number.clone()));
    }
    let mut best: BTreeMap<usize, (u8, String)> = BTreeMap::new();
    for (k, list) in &g.names {
        let r = g.dsu.find(*k);
        for (rank, name) in list {
            let e = best.entry(r).or_insert((u8::MAX, String::new()));
            if (*rank, name) < (e.0, &e.1) {
                *e = (*rank, name.clone());
            }
        }
    }
    let mut nets = Vec::new();
    for (r, mut net) in by_root {
        net.name = match best.remove(&r) {
            Some((_, n)) => n,
            None => net
                .pads
                .iter()
                .next()
                .map(|(p, n)| format!("Net-({p}-Pad{n})"))
                .unwrap_or_default(),
        };
        nets.push(net);
    }
    nets.sort_by(|a, b| a.name.cmp(&b.name));
    nets
}
