//! Conformance over the shared corpus (`../shared/corpus`): every text G-code parses and
//! round-trips exactly, binary G-code is refused, adversarial files do not panic, and the
//! peer slicers' 20 mm cubes have the expected layers.

use std::path::{Path, PathBuf};

use crate::{GcodeError, LayerSource, parse, summarize};

const CORPUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/corpus");

fn files_with_extension(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            files_with_extension(&path, ext, out);
        } else if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
        {
            out.push(path);
        }
    }
}

#[test]
fn corpus_gcode_round_trips() {
    let root = Path::new(CORPUS);
    if !root.is_dir() {
        println!("skipped: corpus not found");
        return;
    }
    let mut files = Vec::new();
    files_with_extension(root, "gcode", &mut files);
    assert!(
        files.len() >= 15,
        "expected the corpus G-code files, found {}",
        files.len()
    );
    let mut cubes = 0;
    for path in &files {
        let bytes = std::fs::read(path).expect("corpus file is readable");
        let name = path
            .strip_prefix(root)
            .unwrap_or(path)
            .display()
            .to_string();
        let g = parse(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(g.to_bytes() == bytes, "{name}: round trip differs");
        let s = summarize(&g);
        println!(
            "{name}: {} lines, {} layers ({:?}{}), {} z-levels, max z {:.3}, tools {:?}, {:?}, E {:?}, {:?}",
            s.lines,
            s.layers,
            s.layer_source,
            s.layer_marker
                .as_deref()
                .map(|m| format!(" {m}"))
                .unwrap_or_default(),
            s.extrusion_z_levels,
            s.bounds.map_or(f64::NAN, |b| b.max[2]),
            s.tools,
            s.flavour,
            s.extrusion,
            s.units,
        );
        if name.starts_with("peer-gcode/20mm_cube.") {
            // peer-gcode/README.md: 0.2 mm layers, a 20 mm cube, 100 printed layers.
            const LAYER_HEIGHT: f64 = 0.2;
            let expected = (20.0 / LAYER_HEIGHT).round() as usize;
            assert!(
                s.layers.abs_diff(expected) <= 2,
                "{name}: {} layers",
                s.layers
            );
            let b = s.bounds.expect("a cube has extruding moves");
            assert!((b.max[2] - 20.0).abs() < 0.05, "{name}: max z {}", b.max[2]);
            assert!(
                b.min[2] > 0.0 && b.min[2] <= LAYER_HEIGHT + 1e-9,
                "{name}: min z {}",
                b.min[2]
            );
            // Each side spans 20 mm of extrusion (within a line width).
            for axis in 0..2 {
                let side = b.max[axis] - b.min[axis];
                assert!((side - 20.0).abs() < 0.5, "{name}: side {side}");
            }
            cubes += 1;
        }
        if name == "peer-gcode/20mm_cube.slic3r-1.3.gcode" {
            // No layer comments at all: layers come from Z heights.
            assert_eq!(s.layer_source, LayerSource::ZHeights, "{name}");
        }
    }
    assert_eq!(cubes, 5, "the five peer-gcode cubes");
}

#[test]
fn corpus_bgcode_is_rejected() {
    let root = Path::new(CORPUS);
    if !root.is_dir() {
        println!("skipped: corpus not found");
        return;
    }
    let mut files = Vec::new();
    files_with_extension(root, "bgcode", &mut files);
    assert!(!files.is_empty(), "expected a .bgcode file in the corpus");
    for path in files {
        let bytes = std::fs::read(&path).expect("corpus file is readable");
        let err = parse(&bytes).expect_err("binary G-code is refused");
        assert_eq!(err, GcodeError::BinaryGcode, "{}", path.display());
        println!("{}: {err}", path.display());
    }
}

#[test]
fn corpus_adversarial_files_do_not_panic() {
    let dir = Path::new(CORPUS).join("gcode-preview-chestnut/test-data/fixtures/adversarial");
    if !dir.is_dir() {
        println!("skipped: corpus not found");
        return;
    }
    let mut files = Vec::new();
    files_with_extension(&dir, "gcode", &mut files);
    assert!(files.len() >= 5);
    for path in files {
        let bytes = std::fs::read(&path).expect("corpus file is readable");
        // Also every prefix of each file (truncation anywhere), for small files.
        let step = (bytes.len() / 200).max(1);
        for end in (0..=bytes.len()).step_by(step).chain([bytes.len()]) {
            if let Ok(g) = parse(&bytes[..end]) {
                assert!(g.to_bytes() == bytes[..end], "{}", path.display());
                let _ = summarize(&g);
            }
        }
    }
}
