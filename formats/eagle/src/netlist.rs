//! Nets and netlists shared by schematics and boards.

use std::collections::{BTreeMap, BTreeSet};

/// Net name -> set of `(part or element name, pad name)`.
pub type Netlist = BTreeMap<String, BTreeSet<(String, String)>>;

/// An electrical net, resolved down to package pads.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Net {
    /// Net (schematic) or signal (board) name. Nets local to a module instance are named
    /// `INSTANCE:NET`.
    pub name: String,
    /// Net class name from `<classes>` (e.g. `default`), or the class number when the file does
    /// not define it; `None` when the net has no `class` attribute.
    pub class: Option<String>,
    /// Pads on this net as `(part or element name, pad name)`.
    pub pads: BTreeSet<(String, String)>,
}

/// Builds a [`Netlist`] from nets; nets sharing a name are merged.
pub(crate) fn to_netlist(nets: &[Net]) -> Netlist {
    let mut out = Netlist::new();
    for n in nets {
        out.entry(n.name.clone())
            .or_default()
            .extend(n.pads.iter().cloned());
    }
    out
}

/// How two netlists (typically a schematic's and its board's) compare.
///
/// Only *connected* nets take part: nets with at least two distinct pads. Nets with zero pads
/// (for example nets that only join supply symbols or other parts without a package) and nets
/// with one pad (unconnected pins) are counted in `skipped_*` and otherwise ignored. Net names
/// often differ between a schematic and its board (EAGLE renames `N$12` freely), so nets are
/// matched by their pad sets; `names_matching` counts equal pad sets that also share a name.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct NetlistComparison {
    /// Connected nets on the left side.
    pub left_connected: usize,
    /// Connected nets on the right side.
    pub right_connected: usize,
    /// Left nets skipped because they have fewer than two pads.
    pub skipped_left: usize,
    /// Right nets skipped because they have fewer than two pads.
    pub skipped_right: usize,
    /// Pad sets present on both sides.
    pub equal: usize,
    /// Of the equal pad sets, how many also carry the same net name on both sides.
    pub names_matching: usize,
    /// Connected left nets whose pad set does not occur on the right, by name.
    pub only_left: Vec<(String, BTreeSet<(String, String)>)>,
    /// Connected right nets whose pad set does not occur on the left, by name.
    pub only_right: Vec<(String, BTreeSet<(String, String)>)>,
}

impl NetlistComparison {
    /// Compares two netlists by their connected pad sets.
    pub fn new(left: &Netlist, right: &Netlist) -> Self {
        let connected = |n: &Netlist| -> BTreeMap<BTreeSet<(String, String)>, BTreeSet<String>> {
            let mut m: BTreeMap<_, BTreeSet<String>> = BTreeMap::new();
            for (name, pads) in n.iter().filter(|(_, p)| p.len() >= 2) {
                m.entry(pads.clone()).or_default().insert(name.clone());
            }
            m
        };
        let l = connected(left);
        let r = connected(right);
        let mut cmp = NetlistComparison {
            left_connected: left.values().filter(|p| p.len() >= 2).count(),
            right_connected: right.values().filter(|p| p.len() >= 2).count(),
            skipped_left: left.values().filter(|p| p.len() < 2).count(),
            skipped_right: right.values().filter(|p| p.len() < 2).count(),
            ..Default::default()
        };
        for (pads, names) in &l {
            match r.get(pads) {
                Some(rnames) => {
                    cmp.equal += 1;
                    if !names.is_disjoint(rnames) {
                        cmp.names_matching += 1;
                    }
                }
                None => {
                    for n in names {
                        cmp.only_left.push((n.clone(), pads.clone()));
                    }
                }
            }
        }
        for (pads, names) in &r {
            if !l.contains_key(pads) {
                for n in names {
                    cmp.only_right.push((n.clone(), pads.clone()));
                }
            }
        }
        cmp
    }

    /// True when every connected pad set occurs on both sides.
    pub fn is_equal(&self) -> bool {
        self.only_left.is_empty() && self.only_right.is_empty()
    }
}
