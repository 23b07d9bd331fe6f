//! Conformance over the shared corpus: `conduit info --json` on every file, with the outcome each
//! file's MANIFEST.json entry expects (`load` → exit 0, `reject` → exit 1 with a one-line message
//! naming the file, `either` → 0 or 1). A panic (exit 101) fails everywhere, and so does an expected
//! failure that starts passing.
//!
//! [`DEVIATIONS`] lists the few files whose manifest outcome conduit knowingly does not meet: each
//! repeats the defect of another corpus file with the opposite expectation, so no reader can meet
//! both. The test fails if one of them starts to agree with the manifest, so the list stays honest.

use crate::support::{conduit, corpus, stderr};
use serde_json::Value;
use std::path::PathBuf;
use std::sync::Mutex;

/// (file name, manifest outcome conduit does not meet, why). The 3MF reader's corpus test carries
/// the full reasoning (`formats/threemf/src/corpus_tests.rs`).
const DEVIATIONS: &[(&str, &str, &str)] = &[
    (
        "MUSTFAIL_Chapter3.4.1a_MissingMetadataName.3mf",
        "reject",
        "same undefined metadata name as MUSTPASS_Chapter3.4.1c, which must load",
    ),
    (
        "CS-1111_3dmodel-e1r1_other-e1r1.3mf",
        "load",
        "two 3D-model StartParts, the defect of MUSTFAIL_Chapter2.1.2; lib3mf strict rejects it too",
    ),
    (
        "dodeca_chain_loop_color.3mf",
        "load",
        "duplicated metadata name, the defect of MUSTFAIL_Chapter3.4.1b; lib3mf strict rejects it too",
    ),
    (
        "3mfbase1_cube.3mf",
        "load",
        "resource id 3 used twice (MUSTFAIL DuplicatedIdAcrossGroup) and requires the unsupported \
         volumetric extension; lib3mf rejects it in every mode",
    ),
];

fn deviation(
    path: &std::path::Path,
) -> Option<&'static (&'static str, &'static str, &'static str)> {
    let name = path.file_name()?.to_str()?;
    DEVIATIONS.iter().find(|d| d.0 == name)
}

struct Case {
    path: PathBuf,
    outcome: String,
}

fn cases() -> Option<Vec<Case>> {
    let dir = corpus()?;
    let text = std::fs::read_to_string(dir.join("MANIFEST.json")).expect("manifest readable");
    let manifest: Vec<Value> = serde_json::from_str(&text).expect("manifest is JSON");
    let mut cases: Vec<Case> = manifest
        .iter()
        .filter_map(|e| {
            let outcome = e["outcome"].as_str()?.to_string();
            let staged = e["staged"].as_str()?;
            (outcome != "companion").then(|| Case {
                path: dir.join(staged),
                outcome,
            })
        })
        .collect();
    cases.sort_by(|a, b| a.path.cmp(&b.path));
    Some(cases)
}

#[test]
fn info_meets_every_manifest_outcome() {
    let Some(cases) = cases() else { return };
    let failures = Mutex::new(Vec::new());
    let counts = Mutex::new([0usize; 3]);
    let next = Mutex::new(0usize);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                loop {
                    let i = {
                        let mut n = next.lock().expect("lock");
                        *n += 1;
                        *n - 1
                    };
                    let Some(case) = cases.get(i) else { break };
                    let out = conduit(["info".as_ref(), "--json".as_ref(), case.path.as_os_str()]);
                    let code = out.status.code().unwrap_or(-1);
                    let err = stderr(&out);
                    let name = case.path.display().to_string();
                    let expected = match deviation(&case.path) {
                        Some((_, "reject", _)) => "load",
                        Some((_, "load", _)) => "reject",
                        _ => case.outcome.as_str(),
                    };
                    let problem = match (expected, code) {
                        ("load", 0) | ("either", 0) => None,
                        ("reject", 1) | ("either", 1) => {
                            let lines: Vec<&str> = err.lines().collect();
                            if lines.len() != 1
                                || !lines[0].starts_with("error: ")
                                || !lines[0].contains(&name)
                            {
                                Some(format!(
                                    "message should be one line naming the file, got {err:?}"
                                ))
                            } else {
                                None
                            }
                        }
                        (expected, code) => {
                            Some(format!("expected {expected}, exit {code}: {}", err.trim()))
                        }
                    };
                    let slot = match code {
                        0 => 0,
                        1 => 1,
                        _ => 2,
                    };
                    counts.lock().expect("lock")[slot] += 1;
                    if let Some(p) = problem {
                        failures.lock().expect("lock").push(format!("{name}: {p}"));
                    }
                }
            });
        }
    });
    let [loaded, rejected, other] = *counts.lock().expect("lock");
    println!(
        "corpus: {} files, {loaded} loaded, {rejected} rejected, {other} other exits",
        cases.len()
    );
    let failures = failures.into_inner().expect("lock");
    assert!(
        failures.is_empty(),
        "{} corpus files off their expected outcome:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
