//! Conformance run over the shared EAGLE corpus (`../shared/corpus/eagle`).
//!
//! For every design with both a `.sch` and a `.brd` (same file stem, same folder) the
//! schematic's netlist must equal the board's, compared as sets of connected pad sets (see
//! [`NetlistComparison`]): nets with fewer than two pads are ignored. That covers unconnected
//! pins (one pad) and supply-only nets (nets joining only supply symbols or other package-less
//! parts: zero pads). Net names may differ between the two files, so pad sets are matched and
//! the number of nets whose names also agree is reported.
//!
//! Binary (pre-6.0) files must be rejected with the documented message.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use conduit_eagle::{EagleError, NetlistComparison, is_binary_eagle, read_board, read_schematic};

const CORPUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/corpus/eagle");

const BINARY_MESSAGE: &str =
    "binary EAGLE format (before 6.0) is not supported; open and re-save it in EAGLE 6 or later";

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out);
        } else {
            out.push(p);
        }
    }
}

#[test]
fn corpus_schematic_and_board_netlists_agree() {
    let root = Path::new(CORPUS);
    if !root.is_dir() {
        println!("skipped: corpus not found");
        return;
    }
    let mut files = Vec::new();
    walk(root, &mut files);
    // stem path -> (sch, brd)
    let mut pairs: BTreeMap<PathBuf, (Option<PathBuf>, Option<PathBuf>)> = BTreeMap::new();
    for f in files {
        let ext = f
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let slot = pairs.entry(f.with_extension("")).or_default();
        match ext.as_deref() {
            Some("sch") => slot.0 = Some(f),
            Some("brd") => slot.1 = Some(f),
            _ => {}
        }
    }

    let mut failures = Vec::new();
    let mut compared = 0;
    let mut binaries = 0;
    for (stem, (sch, brd)) in &pairs {
        let (Some(sch), Some(brd)) = (sch, brd) else {
            continue;
        };
        let name = stem
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let (sb, bb) = match (std::fs::read(sch), std::fs::read(brd)) {
            (Ok(s), Ok(b)) => (s, b),
            _ => {
                failures.push(format!("{name}: cannot read files"));
                continue;
            }
        };
        if is_binary_eagle(&sb) || is_binary_eagle(&bb) {
            binaries += 1;
            for (what, bytes) in [("sch", &sb), ("brd", &bb)] {
                let err = match what {
                    "sch" => read_schematic(bytes).err(),
                    _ => read_board(bytes).err(),
                };
                match err {
                    Some(e @ EagleError::BinaryFormat) if e.to_string() == BINARY_MESSAGE => {}
                    other => failures.push(format!(
                        "{name}.{what}: expected binary error, got {other:?}"
                    )),
                }
            }
            println!("{name}: binary pre-6.0 files rejected as expected");
            continue;
        }
        let s = match read_schematic(&sb) {
            Ok(s) => s,
            Err(e) => {
                failures.push(format!("{name}.sch: {e}"));
                continue;
            }
        };
        let b = match read_board(&bb) {
            Ok(b) => b,
            Err(e) => {
                failures.push(format!("{name}.brd: {e}"));
                continue;
            }
        };
        // Every connect must name a pad of the part's package.
        for p in &s.parts {
            let Some(pkg) = &p.package else { continue };
            for (pin, pads) in &p.pin_pads {
                for pad in pads {
                    if pkg.pad(pad).is_none() {
                        failures.push(format!(
                            "{name}: part {} pin {pin} -> pad {pad} not in package {}",
                            p.name, pkg.name
                        ));
                    }
                }
            }
        }
        // Every contactref must name a pad of the element's package.
        for n in &b.nets {
            for (el, pad) in &n.pads {
                let ok = b.element(el).is_some_and(|e| e.package.pad(pad).is_some());
                if !ok {
                    failures.push(format!(
                        "{name}: signal {} -> {el}.{pad} has no such pad",
                        n.name
                    ));
                }
            }
        }
        // A part and its board element use the same package with the same pads.
        for p in &s.parts {
            let (Some(e), Some(pkg)) = (b.element(&p.name), &p.package) else {
                continue;
            };
            let pads = |k: &conduit_eagle::Package| {
                k.pads.iter().map(|p| p.name.clone()).collect::<Vec<_>>()
            };
            if e.package.name != pkg.name || pads(&e.package) != pads(pkg) {
                failures.push(format!(
                    "{name}: part {} package {} differs from board package {}",
                    p.name, pkg.name, e.package.name
                ));
            }
        }
        let cmp = NetlistComparison::new(&s.netlist(), &b.netlist());
        compared += 1;
        println!(
            "{name}: eagle {} / {}: {} parts, {} dropped, {} elements; nets sch {} brd {}; \
             compared {} vs {} (skipped <2 pads: sch {}, brd {}); equal {}, mismatched {} sch / {} brd; \
             names matching {}/{}",
            s.version,
            b.version,
            s.parts.len(),
            s.dropped_parts.len(),
            b.elements.len(),
            s.nets.len(),
            b.nets.len(),
            cmp.left_connected,
            cmp.right_connected,
            cmp.skipped_left,
            cmp.skipped_right,
            cmp.equal,
            cmp.only_left.len(),
            cmp.only_right.len(),
            cmp.names_matching,
            cmp.equal,
        );
        let board_only: Vec<&str> = b
            .elements
            .iter()
            .filter(|e| s.part(&e.name).is_none())
            .map(|e| e.name.as_str())
            .collect();
        let sch_only: Vec<&str> = s
            .parts
            .iter()
            .filter(|p| b.element(&p.name).is_none())
            .map(|p| p.name.as_str())
            .collect();
        println!("    elements not in schematic: {board_only:?}; parts not on board: {sch_only:?}");
        for (n, pads) in &cmp.only_left {
            println!("    only in sch: {n}: {pads:?}");
        }
        for (n, pads) in &cmp.only_right {
            println!("    only in brd: {n}: {pads:?}");
        }
        if !cmp.is_equal() {
            failures.push(format!("{name}: netlists differ"));
        }
    }
    println!("{compared} designs compared, {binaries} binary designs rejected");
    assert!(
        failures.is_empty(),
        "corpus failures:\n{}",
        failures.join("\n")
    );
}

/// Truncated and corrupted copies of real files must give errors (or documents), never panics.
#[test]
fn corrupted_corpus_files_never_panic() {
    let dir = Path::new(CORPUS).join("LilyPad_Vibe_Board/Hardware");
    let Ok(brd) = std::fs::read(dir.join("SparkFun_LilyPad_Vibe_Board.brd")) else {
        println!("skipped: corpus not found");
        return;
    };
    let sch = std::fs::read(dir.join("SparkFun_LilyPad_Vibe_Board.sch")).unwrap_or_default();
    // A small deterministic generator (64-bit LCG) keeps the run reproducible.
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = |n: usize| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        usize::try_from(state >> 33).unwrap_or(0) % n.max(1)
    };
    let mut errors = 0;
    for original in [&brd, &sch] {
        if original.is_empty() {
            continue;
        }
        for _ in 0..40 {
            let cut = next(original.len());
            errors += usize::from(conduit_eagle::read(&original[..cut]).is_err());
        }
        for _ in 0..40 {
            let mut bytes = original.clone();
            for _ in 0..1 + next(8) {
                let at = next(bytes.len());
                bytes[at] = b"<>\"=/ ax0\xff"[next(10)];
            }
            errors += usize::from(conduit_eagle::read(&bytes).is_err());
        }
    }
    println!("{errors} corrupted inputs rejected cleanly");
}
