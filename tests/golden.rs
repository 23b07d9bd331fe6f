//! Byte-level behaviour: `bench/golden.sh` runs the documented sample commands (README, the
//! guide in `docs/`, `samples/`) and hashes each output; the hashes must equal
//! `bench/golden.txt`. A change that alters an output on purpose re-records the file and names
//! the changed outputs and the reason in its commit.

use std::collections::BTreeMap;
use std::process::Command;

use crate::support::{corpus, root};

/// `hash  name` lines as a map from name to hash.
fn hashes(text: &str) -> BTreeMap<String, String> {
    text.lines()
        .filter_map(|line| line.split_once("  "))
        .map(|(hash, name)| (name.to_string(), hash.to_string()))
        .collect()
}

#[test]
fn golden_outputs_are_unchanged() {
    if Command::new("python3").arg("--version").output().is_err() {
        println!("skipped: python3 not found (bench/golden.sh normalises reports with it)");
        return;
    }
    let corpus = corpus();
    let out = Command::new("bash")
        .arg(root().join("bench/golden.sh"))
        .env("CONDUIT", env!("CARGO_BIN_EXE_conduit"))
        .env(
            "CONDUIT_CORPUS",
            corpus
                .clone()
                .unwrap_or_else(|| root().join("no-corpus-here")),
        )
        .output()
        .expect("bash runs bench/golden.sh");
    assert!(
        out.status.success(),
        "bench/golden.sh failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let got = hashes(&String::from_utf8_lossy(&out.stdout));
    let recorded = std::fs::read_to_string(root().join("bench/golden.txt")).expect("golden.txt");
    let mut want = hashes(&recorded);
    if corpus.is_none() {
        want.retain(|name, _| !name.starts_with("corpus:"));
    }
    let mut differences = Vec::new();
    for (name, hash) in &want {
        match got.get(name) {
            None => differences.push(format!("missing: {name}")),
            Some(h) if h != hash => differences.push(format!("changed: {name}")),
            Some(_) => {}
        }
    }
    for name in got.keys().filter(|n| !want.contains_key(*n)) {
        differences.push(format!("new: {name}"));
    }
    assert!(
        differences.is_empty(),
        "outputs differ from bench/golden.txt ({} of {}):\n{}",
        differences.len(),
        want.len(),
        differences.join("\n")
    );
}
