//! Conformance over the real STL files in `shared/corpus`, against the outcomes in its
//! `MANIFEST.json` (`load`: must read; `reject`: must fail cleanly; `either`: must not panic).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::{Encoding, StlError, read};

const CORPUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/corpus");

/// The corpus folder, or `None` (after saying so) when this checkout has none.
fn corpus() -> Option<PathBuf> {
    let dir = PathBuf::from(CORPUS);
    if dir.is_dir() {
        Some(dir)
    } else {
        println!("skipped: corpus not found");
        None
    }
}

/// Every `*.stl` (any case) under `dir`, sorted.
fn stl_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).expect("readable corpus folder") {
            let path = entry.expect("readable entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("stl"))
            {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// `staged` path → (`outcome`, `info`), from MANIFEST.json.
fn manifest(dir: &Path) -> HashMap<String, (String, String)> {
    let text = std::fs::read_to_string(dir.join("MANIFEST.json")).expect("MANIFEST.json");
    let entries: Vec<serde_json::Value> =
        serde_json::from_str(&text).expect("MANIFEST.json is a JSON array");
    entries
        .iter()
        .filter_map(|e| {
            let info = e["info"].as_str().unwrap_or_default().to_owned();
            Some((
                e["staged"].as_str()?.to_owned(),
                (e["outcome"].as_str()?.to_owned(), info),
            ))
        })
        .collect()
}

/// The triangle count an `info` annotation states ("ASCII STL, 12 facets; ...",
/// "binary STL, 12 triangles ..."), if any.
fn annotated_count(info: &str) -> Option<usize> {
    let words: Vec<&str> = info.split([' ', ',', ';']).collect();
    words
        .windows(2)
        .find(|w| w[1] == "facets" || w[1] == "triangles")
        .and_then(|w| w[0].parse().ok())
}

#[test]
fn annotation_counts_are_understood() {
    assert_eq!(
        annotated_count("ASCII STL, 12 facets; mesh: closed"),
        Some(12)
    );
    assert_eq!(
        annotated_count("binary STL, 8700 triangles (header starts with 'solid')"),
        Some(8700)
    );
    assert_eq!(annotated_count("benchmark model"), None);
}

#[test]
fn every_corpus_stl_meets_its_manifest_outcome() {
    let Some(dir) = corpus() else { return };
    let manifest = manifest(&dir);
    let files = stl_files(&dir);
    assert!(
        files.len() >= 70,
        "expected the 70 corpus STLs, found {}",
        files.len()
    );
    let mut failures = Vec::new();
    let (mut loaded, mut rejected) = (0, 0);
    for path in &files {
        let rel = path
            .strip_prefix(&dir)
            .expect("under corpus")
            .to_string_lossy()
            .replace('\\', "/");
        let Some((outcome, info)) = manifest.get(&rel) else {
            failures.push(format!("{rel}: not in MANIFEST.json"));
            continue;
        };
        let bytes = std::fs::read(path).expect("readable file");
        let result = read(&bytes);
        match &result {
            Ok(_) => loaded += 1,
            Err(_) => rejected += 1,
        }
        match (outcome.as_str(), &result) {
            ("load", Err(e)) => failures.push(format!("{rel}: must load, got error: {e}")),
            ("reject", Ok(stl)) => failures.push(format!(
                "{rel}: must be rejected, read {} triangles",
                stl.triangles.len()
            )),
            ("load" | "reject" | "either", _) => {}
            (other, _) => failures.push(format!("{rel}: unknown outcome {other:?}")),
        }
        if let (Ok(stl), Some(count)) = (&result, annotated_count(info)) {
            if stl.triangles.len() != count {
                let n = stl.triangles.len();
                failures.push(format!("{rel}: {n} triangles, MANIFEST.json says {count}"));
            }
        }
        if let Ok(stl) = &result {
            let finite = stl
                .triangles
                .iter()
                .flatten()
                .flatten()
                .all(|c| c.is_finite());
            assert!(finite, "{rel}: non-finite coordinate accepted");
        }
    }
    println!(
        "{} corpus STLs: {loaded} loaded, {rejected} rejected",
        files.len()
    );
    assert!(
        failures.is_empty(),
        "{} mismatches:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn corpus_files_decode_as_annotated() {
    let Some(dir) = corpus() else { return };
    let read_file = |rel: &str| read(&std::fs::read(dir.join(rel)).expect("readable file"));
    // (file, encoding, triangles) as MANIFEST.json's `info` and SOURCES.md describe them.
    let cases = [
        ("trimesh/models/unit_cube.STL", Encoding::Binary, 12),
        ("trimesh/models/torus.STL", Encoding::Binary, 8700),
        (
            "trimesh/models/counter.unitsmm.STL",
            Encoding::Binary,
            83750,
        ),
        ("trimesh/models/multibody.stl", Encoding::Ascii, 32),
        (
            "trimesh/models/two_objects_mixed_case_names.stl",
            Encoding::Ascii,
            24,
        ),
        ("admesh/examples/block.stl", Encoding::Ascii, 12),
        (
            "admesh/test/conveyor/remove-unconnected-bad.stl",
            Encoding::Ascii,
            857,
        ),
        (
            "CuraEngine/tests/integration/resources/cylinder1000.stl",
            Encoding::Ascii,
            3996,
        ),
        (
            "PrusaSlicer/tests/data/test_stl/ASCII/20mmbox-CRLF.stl",
            Encoding::Ascii,
            12,
        ),
        (
            "PrusaSlicer/tests/data/test_stl/ASCII/20mmbox-CR.stl",
            Encoding::Ascii,
            12,
        ),
        (
            "PrusaSlicer/tests/data/test_stl/ASCII/20mmbox-nonstandard.stl",
            Encoding::Ascii,
            12,
        ),
        (
            "Online3DViewer/test/testfiles/stl/single_triangle_with_comments.stl",
            Encoding::Ascii,
            1,
        ),
        (
            "Online3DViewer/test/testfiles/stl/single_triangle_no_normal.stl",
            Encoding::Ascii,
            1,
        ),
        ("bench-models/3DBenchy.stl", Encoding::Binary, 225_154),
    ];
    for (rel, encoding, count) in cases {
        let stl = read_file(rel).unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert_eq!(
            (stl.encoding, stl.triangles.len()),
            (encoding, count),
            "{rel}"
        );
    }
    let names = |rel: &str| read_file(rel).expect("loads").name;
    assert_eq!(
        names("trimesh/models/unit_cube.STL").as_deref(),
        Some("unit_cube")
    );
    assert_eq!(
        names("trimesh/models/multibody.stl").as_deref(),
        Some("bodyB")
    );
    assert_eq!(
        names("admesh/examples/block.stl").as_deref(),
        Some("Untitled1")
    );
    assert!(matches!(
        read_file("trimesh/models/empty.stl"),
        Err(StlError::NoTriangles {
            encoding: Encoding::Ascii
        })
    ));
}

#[test]
fn twenty_mm_cubes_span_zero_to_twenty() {
    let Some(dir) = corpus() else { return };
    for rel in [
        "bench-models/20mm_cube.stl",
        "PrusaSlicer/tests/data/test_stl/ASCII/20mmbox-LF.stl",
        "PrusaSlicer/tests/data/test_stl/ASCII/20mmbox-CRLF.stl",
        "PrusaSlicer/tests/data/test_stl/ASCII/20mmbox-CR.stl",
        "PrusaSlicer/tests/data/test_stl/ASCII/20mmbox-nonstandard.stl",
        "PrusaSlicer/tests/data/test_stl/Geräte/20mmbox-čřšřěá.stl",
    ] {
        let stl = read(&std::fs::read(dir.join(rel)).expect("readable file"))
            .unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert_eq!(stl.triangles.len(), 12, "{rel}");
        let coords = stl.triangles.iter().flatten();
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for v in coords {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        assert_eq!((lo, hi), ([0.0; 3], [20.0; 3]), "{rel}: bounding box");
        // A closed cube: the recomputed normals are axis-aligned units, two per face direction.
        let mut axes = HashMap::<[i8; 3], usize>::new();
        for t in &stl.triangles {
            *axes
                .entry(crate::facet_normal(t).map(|c| c as i8))
                .or_default() += 1;
        }
        assert_eq!(axes.len(), 6, "{rel}: {axes:?}");
        assert!(
            axes.iter()
                .all(|(n, &k)| k == 2 && n.iter().map(|c| c.abs()).sum::<i8>() == 1),
            "{rel}: {axes:?}"
        );
    }
}
