//! Conformance over the shared corpus: `conduit info --json` on every file, in both 3MF reading
//! modes, against the outcome each file's MANIFEST.json entry expects. A panic (exit 101) fails
//! everywhere.
//!
//! **Default mode** (the manifest's `outcome` is this mode's): `load` → exit 0, `reject` → exit 1
//! with one line `error: ...` naming the file, `either` → 0 or 1 (1 with the same one line). The
//! `either` entries whose note says "a harmless defect ... --strict must reject it" that load do
//! so with a `warning: FILE: ...` line on stderr and the warning in the JSON.
//!
//! **Strict mode** (`info --json --strict`, 3MF files): every `reject` entry and every
//! harmless-defect `either` entry is refused. Every `load` entry loads, except one that carries
//! a defect the manifest says strict mode must refuse: the manifest gives the strict verdict by
//! example only (its harmless-defect entries, MUSTFAIL files of the 3MF validation suite whose
//! file names state the defect), so a `load` file with the same defect gets the same verdict.
//! Such a file is recognised without a list of names: the default mode loads it with a warning
//! line naming the file, and its strict error is of the same kind (the message without file,
//! location, quoted names and numbers) as a harmless-defect entry's strict error. The `expect`
//! texts cannot serve, as they do not all document the defect: `dodeca_chain_loop_color.3mf`
//! says only "PASS (materials ext)", yet its model has two `<metadata name="Description">`,
//! which the core specification forbids (3.4.1: "Producers MUST NOT create multiple metadata
//! elements with the same name"), the defect of MUSTFAIL 3.4.1b. Likewise MUSTPASS 3.4.1c is
//! MUSTFAIL 3.4.1a with the undefined metadata name spelled differently, so strict mode refuses
//! both, as lib3mf's strict mode does. The 3MF reader's own corpus test
//! (`formats/threemf/src/corpus_tests.rs`) applies the same rules to the library.

use crate::support::{conduit, corpus, stderr, stdout, temp_dir};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::Output;
use std::sync::Mutex;

/// The note of the manifest's `either` entries whose defect is harmless.
const HARMLESS_NOTE: &str = "a harmless defect";

struct Case {
    path: PathBuf,
    outcome: String,
    /// An `either` entry whose note names a harmless defect.
    harmless: bool,
    is_3mf: bool,
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
            let note = e["note"].as_str().unwrap_or_default();
            let is_3mf = e["format"].as_str() == Some("3MF")
                || staged.to_ascii_lowercase().ends_with(".3mf");
            (outcome != "companion").then(|| Case {
                path: dir.join(staged),
                harmless: outcome == "either" && note.contains(HARMLESS_NOTE),
                outcome,
                is_3mf,
            })
        })
        .collect();
    cases.sort_by(|a, b| a.path.cmp(&b.path));
    Some(cases)
}

/// Runs `f` over `cases` on two threads (the machine's cores are shared).
fn each_case(cases: &[&Case], f: impl Fn(&Case) + Sync) {
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
                    f(case);
                }
            });
        }
    });
}

/// `conduit info --json [--strict] FILE`.
fn info(case: &Case, strict: bool) -> Output {
    let mut args = vec!["info".as_ref(), "--json".as_ref()];
    if strict {
        args.push("--strict".as_ref());
    }
    args.push(case.path.as_os_str());
    conduit(args)
}

/// A problem with a refusal: `None` when stderr is one line `error: ...` naming the file.
fn refusal_problem(out: &Output, name: &str) -> Option<String> {
    let err = stderr(out);
    let lines: Vec<&str> = err.lines().collect();
    (lines.len() != 1 || !lines[0].starts_with("error: ") || !lines[0].contains(name))
        .then(|| format!("message should be one line naming the file, got {err:?}"))
}

/// A problem with a harmless defect read in the default mode: `None` when stderr has a
/// `warning: FILE: ...` line and the JSON a warning.
fn warning_problem(out: &Output, name: &str) -> Option<String> {
    let err = stderr(out);
    let prefix = format!("warning: {name}: ");
    if !err.lines().any(|l| l.starts_with(&prefix)) {
        return Some(format!(
            "loaded without a warning line naming the file: {err:?}"
        ));
    }
    let json: Value = serde_json::from_str(&stdout(out)).unwrap_or_default();
    let warnings = json[0]["warnings"].as_array().map_or(0, Vec::len);
    (warnings == 0).then(|| "the JSON has no warnings".to_string())
}

/// The kind of a reader's refusal: the message without `error: FILE: FORMAT: `, then
/// [`conduit_3mf::error_kind`], so the same defect in two files compares equal.
fn kind(line: &str, name: &str) -> String {
    let msg = line
        .trim()
        .strip_prefix("error: ")
        .unwrap_or(line)
        .strip_prefix(name)
        .unwrap_or(line)
        .trim_start_matches(": ")
        .trim_start_matches("3MF: ");
    conduit_3mf::error_kind(msg)
}

#[test]
fn refusal_kinds_ignore_files_locations_names_and_numbers() {
    let a = kind(
        r#"error: a.3mf: 3MF: /3D/3dmodel.model:8:3: duplicated metadata name "Description""#,
        "a.3mf",
    );
    let b = kind(
        r#"error: x/b.3mf: 3MF: /3D/m.model:4:3: duplicated metadata name "Title""#,
        "x/b.3mf",
    );
    assert_eq!(a, r#"duplicated metadata name "_""#);
    assert_eq!(a, b);
    assert_ne!(
        a,
        kind(
            "error: a.3mf: 3MF: /3D/3dmodel.model:35:2: resource id 3 is already used by another resource in this part",
            "a.3mf"
        )
    );
}

#[test]
fn info_meets_every_manifest_outcome() {
    let Some(cases) = cases() else { return };
    let failures = Mutex::new(Vec::new());
    let counts = Mutex::new([0usize; 3]);
    let all: Vec<&Case> = cases.iter().collect();
    each_case(&all, |case| {
        let out = info(case, false);
        let code = out.status.code().unwrap_or(-1);
        let name = case.path.display().to_string();
        let problem = match (case.outcome.as_str(), code) {
            ("load", 0) => None,
            ("either", 0) if case.harmless => warning_problem(&out, &name),
            ("either", 0) => None,
            ("reject", 1) | ("either", 1) => refusal_problem(&out, &name),
            (expected, code) => Some(format!(
                "expected {expected}, exit {code}: {}",
                stderr(&out).trim()
            )),
        };
        counts.lock().expect("lock")[match code {
            0 => 0,
            1 => 1,
            _ => 2,
        }] += 1;
        if let Some(p) = problem {
            failures.lock().expect("lock").push(format!("{name}: {p}"));
        }
    });
    let [loaded, rejected, other] = *counts.lock().expect("lock");
    println!(
        "corpus, default mode: {} files, {loaded} loaded, {rejected} rejected, {other} other exits",
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

/// What strict mode did with one 3MF file.
struct StrictRun {
    name: String,
    outcome: String,
    harmless: bool,
    code: i32,
    /// The refusal's kind (exit 1).
    kind: Option<String>,
    /// For a `load` file strict mode refuses: a problem with its default-mode reading.
    default_problem: Option<String>,
}

#[test]
fn strict_mode_refuses_every_defect_the_manifest_names() {
    let Some(cases) = cases() else { return };
    let threemf: Vec<&Case> = cases.iter().filter(|c| c.is_3mf).collect();
    let runs = Mutex::new(Vec::new());
    let failures = Mutex::new(Vec::new());
    each_case(&threemf, |case| {
        let out = info(case, true);
        let code = out.status.code().unwrap_or(-1);
        let name = case.path.display().to_string();
        let mut run = StrictRun {
            name: name.clone(),
            outcome: case.outcome.clone(),
            harmless: case.harmless,
            code,
            kind: None,
            default_problem: None,
        };
        match code {
            0 => {}
            1 => {
                if let Some(p) = refusal_problem(&out, &name) {
                    failures
                        .lock()
                        .expect("lock")
                        .push(format!("{name}: strict: {p}"));
                }
                run.kind = Some(kind(&stderr(&out), &name));
                if case.outcome == "load" {
                    let default = info(case, false);
                    run.default_problem = match default.status.code() {
                        Some(0) => warning_problem(&default, &name),
                        c => Some(format!("the default mode exits {c:?}")),
                    };
                }
            }
            c => failures
                .lock()
                .expect("lock")
                .push(format!("{name}: strict: exit {c}: {}", stderr(&out).trim())),
        }
        runs.lock().expect("lock").push(run);
    });
    let runs = runs.into_inner().expect("lock");
    let mut failures = failures.into_inner().expect("lock");
    // The defects the manifest says strict mode refuses, by kind, with an entry that has each.
    let named: BTreeMap<&str, &str> = runs
        .iter()
        .filter(|r| r.harmless)
        .filter_map(|r| Some((r.kind.as_deref()?, r.name.as_str())))
        .collect();
    let (mut loaded, mut rejected, mut refused_loads) = (0, 0, 0);
    for r in &runs {
        match (r.outcome.as_str(), r.code) {
            (_, 0) => {
                loaded += 1;
                if r.outcome == "reject" || r.harmless {
                    failures.push(format!("{}: strict mode loads it", r.name));
                }
            }
            ("load", 1) => {
                rejected += 1;
                refused_loads += 1;
                let kind = r.kind.as_deref().unwrap_or_default();
                match named.get(kind) {
                    Some(like) => println!("strict refuses [load] {}: the defect of {like}", r.name),
                    None => failures.push(format!(
                        "{}: strict mode refuses a load file for a defect no harmless-defect entry has ({kind})",
                        r.name
                    )),
                }
                if let Some(p) = &r.default_problem {
                    failures.push(format!("{}: default mode: {p}", r.name));
                }
            }
            _ => rejected += 1,
        }
    }
    println!(
        "corpus 3MF, strict mode: {} files, {loaded} loaded, {rejected} rejected ({refused_loads} 'load' files for a defect of a harmless-defect entry)",
        runs.len()
    );
    assert!(
        failures.is_empty(),
        "{} corpus files off their strict-mode outcome:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// `--strict` is global: `convert` and `slice` read 3MF the way `info` does. Run on the
/// manifest's harmless-defect entries that the default mode loads.
#[test]
fn strict_applies_to_convert_and_slice() {
    let Some(cases) = cases() else { return };
    let dir = temp_dir();
    let stl = dir.path().join("out.stl");
    let gcode = dir.path().join("out.gcode");
    let mut checked = 0;
    for case in cases.iter().filter(|c| c.harmless && c.is_3mf) {
        let name = case.path.display().to_string();
        let file = case.path.as_os_str();
        let convert = |strict: bool| {
            let mut args = vec!["convert".as_ref(), file, "-o".as_ref(), stl.as_os_str()];
            if strict {
                args.push("--strict".as_ref());
            }
            conduit(args)
        };
        let default = convert(false);
        if default.status.code() != Some(0) {
            continue; // an `either` entry the default mode refuses
        }
        assert!(
            stderr(&default).starts_with(&format!("warning: {name}: ")),
            "{name}: convert: {}",
            stderr(&default)
        );
        let strict = convert(true);
        assert_eq!(strict.status.code(), Some(1), "{name}: convert --strict");
        assert_eq!(refusal_problem(&strict, &name), None, "{name}");
        let slice = conduit([
            "slice".as_ref(),
            "--strict".as_ref(),
            file,
            "-o".as_ref(),
            gcode.as_os_str(),
        ]);
        assert_eq!(slice.status.code(), Some(1), "{name}: slice --strict");
        assert_eq!(refusal_problem(&slice, &name), None, "{name}");
        assert!(!gcode.exists(), "{name}: slice --strict wrote G-code");
        checked += 1;
    }
    assert!(
        checked > 0,
        "no harmless-defect entry loads in the default mode"
    );
}
