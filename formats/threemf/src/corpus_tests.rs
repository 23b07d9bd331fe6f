//! Conformance run over the shared test corpus (`../shared/corpus`, see its MANIFEST.json), in
//! both reading modes.
//!
//! **Default mode** ([`read`]): every 3MF whose manifest outcome is `load` must read and
//! flatten; every `reject` must fail with a one-line message; `either` must not panic. The
//! `either` entries whose note says "a harmless defect ... --strict must reject it" must, when
//! they load, carry at least one warning.
//!
//! **Strict mode** ([`read_with`] with `strict: true`): every `reject` and every harmless-defect
//! `either` entry must be refused. A `load` entry must load, unless it carries one of the
//! defects that the manifest's harmless-defect entries are refused for: the manifest states the
//! default mode's outcome, and for strict mode it names those defects by example (the
//! validation suite's MUSTFAIL files, "reason in file name"), so a `load` file with the same
//! defect gets the same strict verdict. Such a file must load in the default mode with a
//! warning, and its strict error must be of the same kind (the message without its location,
//! quoted names and numbers) as the strict error of a harmless-defect entry. There is no list
//! of file names: in today's corpus these are `dodeca_chain_loop_color.3mf` (two
//! `<metadata name="Description">` in one model, which the core specification's 3.4.1 forbids:
//! "Producers MUST NOT create multiple metadata elements with the same name", the defect of
//! MUSTFAIL 3.4.1b), MUSTPASS 3.4.1c (byte for byte MUSTFAIL 3.4.1a's undefined metadata name,
//! under another name), and lib3mf's `MetaData_*_Fail` and `Track_093` samples (undefined or
//! undeclared metadata names, for which lib3mf warns, so its strict mode refuses them too).

use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use crate::error_kind as kind;
use crate::{Limits, Model, ObjectContent, ReadOptions, read, read_with, write};

/// The note of the manifest's `either` entries whose defect is harmless.
const HARMLESS_NOTE: &str = "a harmless defect";

#[test]
fn kinds_ignore_locations_names_and_numbers() {
    assert_eq!(
        kind(r#"/3D/3dmodel.model:8:3: duplicated metadata name "Description""#),
        kind(r#"/3D/a.model:4:3: duplicated metadata name "Title""#)
    );
    assert_ne!(
        kind(r#"/3D/3dmodel.model:8:3: duplicated metadata name "Description""#),
        kind(
            "/3D/3dmodel.model:8:3: resource id 3 is already used by another resource in this part"
        )
    );
}

#[test]
fn corpus() {
    let root = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/corpus"
    ));
    let manifest = root.join("MANIFEST.json");
    let Ok(text) = std::fs::read_to_string(&manifest) else {
        println!("skipped: corpus not found");
        return;
    };
    let entries: serde_json::Value = match serde_json::from_str(&text) {
        Ok(v) => v,
        Err(e) => panic!("MANIFEST.json: {e}"),
    };
    let Some(entries) = entries.as_array() else {
        panic!("MANIFEST.json is not an array");
    };
    let (mut loaded, mut rejected, mut either, mut written) = (0, 0, 0, 0);
    let (mut strict_loaded, mut strict_rejected) = (0, 0);
    let mut failures = Vec::new();
    // Strict-mode errors of the harmless-defect entries, by kind; strict-mode errors of `load`
    // entries, checked against them at the end.
    let mut harmless_kinds: BTreeMap<String, String> = BTreeMap::new();
    let mut refused_loads: Vec<(String, String, usize)> = Vec::new();
    for e in entries {
        let staged = e["staged"].as_str().unwrap_or_default();
        let format = e["format"].as_str().unwrap_or_default();
        let outcome = e["outcome"].as_str().unwrap_or_default();
        let harmless = outcome == "either"
            && e["note"]
                .as_str()
                .unwrap_or_default()
                .contains(HARMLESS_NOTE);
        if format != "3MF" && !staged.to_ascii_lowercase().ends_with(".3mf") {
            continue;
        }
        if outcome == "companion" {
            continue;
        }
        let Ok(bytes) = std::fs::read(root.join(staged)) else {
            failures.push(format!("{staged}: cannot read file"));
            continue;
        };
        let result = catch_unwind(AssertUnwindSafe(|| {
            read(&bytes, &Limits::default()).and_then(|p| p.flatten().map(|f| (p, f)))
        }));
        let strict = catch_unwind(AssertUnwindSafe(|| {
            read_with(&bytes, &Limits::default(), ReadOptions { strict: true })
                .and_then(|p| p.flatten().map(|_| p))
        }));
        let (Ok(result), Ok(strict)) = (result, strict) else {
            failures.push(format!("{staged}: PANIC"));
            continue;
        };
        let ok = result.is_ok();
        let agrees = match outcome {
            "load" => ok,
            "reject" => !ok,
            _ => true,
        };
        if let Ok((p, _)) = &result {
            match writer_round_trip(p.root()) {
                RoundTrip::Done => written += 1,
                RoundTrip::NotWritable => {}
                RoundTrip::Failed(why) => {
                    failures.push(format!("{staged}: writer round trip: {why}"))
                }
            }
        }
        match &result {
            Ok((p, f)) => {
                let tris: usize = f.iter().map(|m| m.triangles.len()).sum();
                println!(
                    "ok     [{outcome}] {staged}: {} part(s), {} item(s), {tris} triangles, {} warning(s)",
                    p.models.len(),
                    f.len(),
                    p.warnings.len()
                );
                for w in p.warnings.iter().take(3) {
                    println!("         warning: {w}");
                }
                if harmless && p.warnings.is_empty() {
                    failures.push(format!("{staged}: harmless defect read without a warning"));
                }
            }
            Err(err) => {
                let msg = err.to_string();
                println!("reject [{outcome}] {staged}: {msg}");
                if msg.contains('\n') {
                    failures.push(format!("{staged}: multi-line error message"));
                }
            }
        }
        if ok {
            loaded += 1;
        } else {
            rejected += 1;
        }
        if outcome == "either" {
            either += 1;
        }
        if !agrees {
            failures.push(format!(
                "{staged}: manifest says {outcome}, got {}",
                match &result {
                    Ok(_) => "Ok".to_string(),
                    Err(e) => format!("Err({e})"),
                }
            ));
        }
        match &strict {
            Ok(_) => {
                strict_loaded += 1;
                if outcome == "reject" || harmless {
                    failures.push(format!("{staged}: strict mode loads a file it must refuse"));
                }
            }
            Err(err) => {
                strict_rejected += 1;
                let msg = err.to_string();
                println!("         strict: {msg}");
                if msg.contains('\n') {
                    failures.push(format!("{staged}: multi-line strict error message"));
                }
                if harmless {
                    harmless_kinds.insert(kind(&msg), staged.to_string());
                }
                if outcome == "load" {
                    let warnings = result.as_ref().map_or(0, |(p, _)| p.warnings.len());
                    refused_loads.push((staged.to_string(), msg, warnings));
                }
            }
        }
    }
    for (staged, msg, warnings) in &refused_loads {
        match harmless_kinds.get(&kind(msg)) {
            Some(like) => {
                println!("strict refuses [load] {staged}: the defect of {like}");
                if *warnings == 0 {
                    failures.push(format!(
                        "{staged}: strict mode refuses it ({msg}) but the default mode gives no warning"
                    ));
                }
            }
            None => failures.push(format!(
                "{staged}: strict mode refuses a load file for a defect no harmless-defect entry has: {msg}"
            )),
        }
    }
    println!(
        "corpus 3MF, default mode: {loaded} loaded, {rejected} rejected ({either} 'either'), {written} root models written and read back"
    );
    println!(
        "corpus 3MF, strict mode: {strict_loaded} loaded, {strict_rejected} rejected ({} 'load' files refused for a harmless defect); {} mismatches",
        refused_loads.len(),
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "corpus mismatches:\n{}",
        failures.join("\n")
    );
}

enum RoundTrip {
    Done,
    NotWritable,
    Failed(String),
}

/// Writes a loaded root model back (after dropping what [`Model`] cannot carry: extension
/// requirements and references to texture/composite/multiproperties groups) and checks that
/// reading it gives the same geometry. Models that reference other parts or use metadata
/// names lib3mf's strict mode rejects are not writable by design.
fn writer_round_trip(root: &Model) -> RoundTrip {
    let mut m = root.clone();
    m.required_extensions.clear();
    let groups: Vec<u32> = m
        .base_materials
        .iter()
        .map(|b| b.id)
        .chain(m.color_groups.iter().map(|c| c.id))
        .collect();
    let mut has_paths = m.build.iter().any(|b| b.path.is_some());
    for o in &mut m.objects {
        if o.pid.is_some_and(|p| !groups.contains(&p)) {
            o.pid = None;
            o.pindex = None;
        }
        let opid = o.pid;
        match &mut o.content {
            ObjectContent::Mesh(mesh) => {
                for t in &mut mesh.triangles {
                    if t.pid.or(opid).is_some_and(|p| !groups.contains(&p)) {
                        t.pid = None;
                        t.p = [None; 3];
                    }
                }
            }
            ObjectContent::Components(c) => has_paths |= c.iter().any(|c| c.path.is_some()),
        }
    }
    let odd_metadata = m.metadata.iter().any(|x| {
        !x.name.contains(':') && !crate::read::WELL_KNOWN_METADATA.contains(&x.name.as_str())
    });
    if has_paths || odd_metadata {
        return RoundTrip::NotWritable;
    }
    let mut buf = std::io::Cursor::new(Vec::new());
    if let Err(e) = write(&mut buf, &m) {
        return RoundTrip::Failed(e.to_string());
    }
    let back = match read(buf.get_ref(), &Limits::default()) {
        Ok(p) => p.root().clone(),
        Err(e) => return RoundTrip::Failed(e.to_string()),
    };
    if back.objects.len() != m.objects.len() || back.build != m.build || back.unit != m.unit {
        return RoundTrip::Failed("objects, build or unit differ".into());
    }
    let by_id: std::collections::HashMap<u32, &crate::Object> =
        back.objects.iter().map(|o| (o.id, o)).collect();
    for a in &m.objects {
        let Some(b) = by_id.get(&a.id) else {
            return RoundTrip::Failed(format!("object {} missing", a.id));
        };
        match (&a.content, &b.content) {
            (ObjectContent::Mesh(x), ObjectContent::Mesh(y)) => {
                if x.triangles != y.triangles || x.vertices.len() != y.vertices.len() {
                    return RoundTrip::Failed(format!("object {}: mesh differs", a.id));
                }
                // f32-exact coordinates are written in their shortest f32 spelling, which an
                // f64 reader may read a fraction of an f32 ulp away.
                let close = x.vertices.iter().zip(&y.vertices).all(|(p, q)| {
                    (0..3).all(|k| (p[k] - q[k]).abs() <= 1e-6 * p[k].abs().max(1.0))
                });
                if !close {
                    return RoundTrip::Failed(format!("object {}: vertices differ", a.id));
                }
            }
            (x, y) if x == y => {}
            _ => return RoundTrip::Failed(format!("object {}: content differs", a.id)),
        }
    }
    RoundTrip::Done
}
