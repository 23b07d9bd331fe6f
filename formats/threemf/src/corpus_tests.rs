//! Conformance run over the shared test corpus (`../shared/corpus`, see its MANIFEST.json).
//!
//! Every 3MF whose manifest outcome is `load` must read and flatten; every `reject` must fail
//! with a one-line message; `either` must not panic. Cases where the manifest contradicts
//! another must-pass/must-fail case of the same corpus are listed in [`DISPUTED`] with the
//! reason; they are expected to disagree with the manifest, and the test fails if one of them
//! starts to agree (so the list stays honest).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use crate::{Limits, Model, ObjectContent, read, write};

/// (file name, manifest outcome we knowingly do not meet, why).
const DISPUTED: &[(&str, &str, &str)] = &[(
    "dodeca_chain_loop_color.3mf",
    "load",
    "two <metadata name=\"Description\">, the same defect as \
         MUSTFAIL_Chapter3.4.1b_DuplicatedMetadataName (two \"Title\"); conduit rejects \
         duplicated metadata names as the core specification requires",
)];

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
    let (mut loaded, mut rejected, mut either, mut disputed, mut written) = (0, 0, 0, 0, 0);
    let mut failures = Vec::new();
    for e in entries {
        let staged = e["staged"].as_str().unwrap_or_default();
        let format = e["format"].as_str().unwrap_or_default();
        let outcome = e["outcome"].as_str().unwrap_or_default();
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
        let Ok(result) = result else {
            failures.push(format!("{staged}: PANIC"));
            continue;
        };
        let name = staged.rsplit('/').next().unwrap_or(staged);
        let dispute = DISPUTED.iter().find(|d| d.0 == name);
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
        match (dispute, agrees) {
            (Some(d), true) => failures.push(format!(
                "{staged}: listed as disputed ({}) but now agrees with the manifest; update DISPUTED",
                d.1
            )),
            (Some(_), false) => disputed += 1,
            (None, false) => failures.push(format!(
                "{staged}: manifest says {outcome}, got {}",
                match &result {
                    Ok(_) => "Ok".to_string(),
                    Err(e) => format!("Err({e})"),
                }
            )),
            (None, true) => {}
        }
    }
    println!(
        "corpus 3MF: {loaded} loaded, {rejected} rejected ({either} 'either'), {disputed} disputed (see DISPUTED), {written} root models written and read back, {} mismatches",
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
