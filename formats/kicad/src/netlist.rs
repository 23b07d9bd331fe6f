//! Netlists: what every KiCad source (board, schematic, netlist export) comes down to.

use std::collections::{BTreeMap, BTreeSet};

/// Net name → set of `(reference, pad number)`.
pub type Netlist = BTreeMap<String, BTreeSet<(String, String)>>;
