//! Conformance over the shared corpus: `conduit info --json` on every file, with the outcome each
//! file's MANIFEST.json entry expects (`load` → exit 0, `reject` → exit 1 with a one-line message
//! naming the file, `either` → 0 or 1). A panic (exit 101) fails everywhere, and so does an expected
//! failure that starts passing.

use crate::support::{conduit, corpus, stderr};
use serde_json::Value;
use std::path::PathBuf;
use std::sync::Mutex;

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
                    let problem = match (case.outcome.as_str(), code) {
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
