//! Fuzzing on the stable toolchain, bounded for CI: every target of `fuzz_stable/targets.rs`
//! runs its `ci_execs` mutated inputs (20 000 per target, the library readers included) from the
//! seeds in `fuzz_stable/seeds/`, `samples/` and, when present, the shared corpus and regression
//! files (seeds of at most 64 KiB). Each test asserts no panic and
//! no execution over 10 s; a failing input is saved under `target/fuzz-findings/`.
//! `bench/fuzz.sh` runs the same engine for millions of executions.
//!
//! `fuzz_regressions_replay_cleanly` replays `tests/regressions/fuzz/` (inputs the fuzzer once
//! crashed on, named `TARGET-…`) through the same targets.

#[allow(dead_code)]
mod engine;
#[allow(dead_code)]
mod targets;

use crate::support::root;
use engine::{Limits, Runner, Seed};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The seeds, read once for all the tests.
fn seeds() -> &'static [Seed] {
    static SEEDS: OnceLock<Vec<Seed>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let (dirs, notes) = engine::seed_dirs(&root());
        for n in notes {
            println!("{n}");
        }
        engine::collect_seeds(&dirs, 64 << 10)
    })
}

/// Runs target `name` for its CI count and asserts that nothing was found.
fn fuzz(name: &str) {
    let all = targets::all();
    let target = all
        .iter()
        .find(|t| t.name == name)
        .unwrap_or_else(|| panic!("no fuzz target {name}"));
    let runner = Runner {
        seeds: seeds().to_vec(),
        seed: 1,
        limits: Limits::default(),
        findings: Some(root().join("target/fuzz-findings")),
    };
    let scratch = engine::scratch_dir().expect("a scratch folder");
    let report = runner.run(target, target.ci_execs, scratch.path());
    println!("{}", report.line());
    assert_eq!(report.execs, target.ci_execs);
    assert!(report.seeds > 0, "{name}: no seeds");
    let found: Vec<String> = report
        .findings
        .iter()
        .map(|f| {
            format!(
                "{} at execution {}: {} ({})",
                f.kind,
                f.exec,
                f.message,
                f.file
                    .as_ref()
                    .map_or_else(String::new, |p| p.display().to_string())
            )
        })
        .collect();
    assert!(found.is_empty(), "{name}:\n{}", found.join("\n"));
    assert!(report.slowest < Duration::from_secs(10));
}

macro_rules! fuzz_tests {
    ($($name:ident),* $(,)?) => {
        $(
            #[test]
            fn $name() {
                fuzz(stringify!($name));
            }
        )*

        /// Every target has its test above.
        #[test]
        fn every_target_is_tested() {
            let tested = [$(stringify!($name)),*];
            for t in targets::all() {
                assert!(tested.contains(&t.name), "fuzz target {} has no test", t.name);
            }
        }
    };
}

fuzz_tests!(
    stl_ascii,
    stl_binary,
    threemf,
    obj,
    off,
    ply,
    xyz,
    eagle,
    kicad,
    gcode,
    svg,
    dxf,
    pnp,
    poses,
    xml,
    scene,
    config_toml,
    config_ini,
    placement,
    design,
    circuit,
    scan,
    robot_csv,
);

/// The same input always comes out of the same seed, target and execution index, so a finding
/// can be rebuilt from the three numbers.
#[test]
fn inputs_are_reproducible() {
    let all = targets::all();
    let t = &all[0];
    let runner = Runner {
        seeds: seeds().to_vec(),
        seed: 7,
        limits: Limits::default(),
        findings: None,
    };
    let pool = runner.pool(t);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    let mut differ = 0;
    for exec in 0..200 {
        runner.input(t, &pool, exec, &mut a);
        runner.input(t, &pool, exec, &mut b);
        assert_eq!(a, b, "execution {exec}");
        runner.input(t, &pool, exec + 1, &mut b);
        differ += usize::from(a != b);
    }
    assert!(
        differ > 150,
        "only {differ} of 200 neighbouring inputs differ"
    );
}

/// A 3MF seed is mutated inside its zip: the result is still a zip whose entries differ from
/// the seed's.
#[test]
fn packages_are_mutated_inside_the_zip() {
    let Some(seed) = seeds().iter().find(|s| s.entries.is_some()) else {
        println!("skipped: no 3MF seed");
        return;
    };
    let mut rng = engine::Rng::new(3);
    let mut out = Vec::new();
    let mut rezipped = 0;
    for _ in 0..50 {
        engine::mutate(&mut rng, seed, &[], &[], &mut out);
        if out.starts_with(b"PK\x03\x04") && out != seed.bytes {
            rezipped += 1;
        }
    }
    assert!(rezipped >= 25, "{rezipped} of 50 mutations were zips");
}

/// Every file of `tests/regressions/fuzz/` (named after its target) reads to `Ok` or `Err`
/// without a panic, in under 10 s.
#[test]
fn fuzz_regressions_replay_cleanly() {
    let dir = root().join("tests/regressions/fuzz");
    let files = crate::support::files_in(&dir);
    assert!(!files.is_empty(), "no files in {}", dir.display());
    let all = targets::all();
    let scratch = engine::scratch_dir().expect("a scratch folder");
    for f in files {
        let name = f.file_name().map(|n| n.to_string_lossy().into_owned());
        let name = name.unwrap_or_default();
        if name == "README.md" || name.starts_with('.') {
            continue;
        }
        let target = all
            .iter()
            .filter(|t| name.starts_with(&format!("{}-", t.name)))
            .max_by_key(|t| t.name.len())
            .unwrap_or_else(|| panic!("{name}: names no fuzz target"));
        let bytes = std::fs::read(&f).expect("regression file readable");
        let ext = f
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        let t0 = Instant::now();
        let result = engine::replay(target, &bytes, &ext, scratch.path());
        if let Err(panic) = result {
            panic!("{name}: {panic}");
        }
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "{name}: {:?}",
            t0.elapsed()
        );
    }
}
