//! Inputs found by fuzzing that crashed, exhausted memory or hung `conduit slice` and
//! `conduit info` (`../shared/regressions`, README there): each must now be refused with exit 1
//! and one line naming the file, or, where the input is valid, succeed; never a panic, an abort
//! or a hang.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::support::{regressions, root, temp_dir};

/// A hang guard, not a benchmark: every file finishes in well under a second.
const DEADLINE: Duration = Duration::from_secs(20);

/// Runs conduit with `args` from the project root under [`DEADLINE`]; returns the exit code
/// (`None` when killed by a signal) and stderr. Panics if the deadline passes.
fn run_guarded(args: &[&std::ffi::OsStr]) -> (Option<i32>, String) {
    let err_file = tempfile::NamedTempFile::new().expect("a temp file");
    let mut child = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .args(args)
        .current_dir(root())
        .stdout(Stdio::null())
        .stderr(err_file.reopen().expect("the temp file reopens"))
        .spawn()
        .expect("the conduit binary runs");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("the child can be waited for") {
            break status;
        }
        if start.elapsed() > DEADLINE {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{args:?} still running after {DEADLINE:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let stderr = std::fs::read_to_string(err_file.path()).unwrap_or_default();
    (status.code(), stderr)
}

/// The files of `dir/sub` whose names start with `prefix`, sorted.
fn files(dir: &Path, sub: &str, prefix: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir.join(sub))
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.starts_with(prefix))
                })
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Asserts a refusal: exit 1, exactly one stderr line, naming `file`.
fn assert_refused(file: &Path, code: Option<i32>, stderr: &str) {
    let name = file
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    assert_eq!(code, Some(1), "{}: {stderr}", file.display());
    assert_eq!(stderr.lines().count(), 1, "{}: {stderr}", file.display());
    assert!(stderr.contains(name), "{}: {stderr}", file.display());
}

#[test]
fn slice_configs_that_crashed_are_refused_naming_the_file_and_key() {
    let Some(dir) = regressions() else { return };
    let mut configs = Vec::new();
    for sub in ["panic", "oom", "timeout"] {
        configs.extend(files(&dir, sub, "slice-config-"));
    }
    for name in [
        "min_slice_config_capacity.ini",
        "slice_ini_perimeter_width_1e39.ini",
        "slice_ini_skirts_huge.ini",
        "slice_toml_layer_height_1e-9.toml",
    ] {
        configs.push(dir.join("handmade").join(name));
    }
    assert!(configs.len() >= 12, "{configs:?}");
    let out = temp_dir();
    let gcode = out.path().join("out.gcode");
    for config in &configs {
        let (code, stderr) = run_guarded(&[
            "slice".as_ref(),
            "samples/cube_20mm.stl".as_ref(),
            "-c".as_ref(),
            config.as_os_str(),
            "-o".as_ref(),
            gcode.as_os_str(),
        ]);
        assert_refused(config, code, &stderr);
        assert!(
            ["perimeter", "skirt", "layer_height", "width"]
                .iter()
                .any(|k| stderr.contains(k)),
            "{}: no key named: {stderr}",
            config.display()
        );
    }
}

#[test]
fn slice_meshes_of_duplicated_triangles_finish_quickly() {
    let Some(dir) = regressions() else { return };
    let meshes = [
        dir.join("oom/slice-f42e68009e.obj"),
        dir.join("timeout/slice-9d4b168c19.3mf"),
        dir.join("handmade/slice_obj_tri_x3000.obj"),
    ];
    let out = temp_dir();
    let gcode = out.path().join("out.gcode");
    let report = out.path().join("out.json");
    // In both 3MF reading modes.
    for mode in [None, Some("--strict")] {
        for mesh in &meshes {
            let mut args = vec![
                "slice".as_ref(),
                mesh.as_os_str(),
                "-o".as_ref(),
                gcode.as_os_str(),
                "--report".as_ref(),
                report.as_os_str(),
            ];
            args.extend(mode.map(std::ffi::OsStr::new));
            let (code, stderr) = run_guarded(&args);
            match code {
                Some(0) => {}
                _ => assert_refused(mesh, code, &stderr),
            }
        }
    }
}

#[test]
fn info_on_a_3mf_fanning_out_to_many_instances_finishes() {
    let Some(dir) = regressions() else { return };
    let file = dir.join("handmade/3mf_fanout_distinct_2pow18.3mf");
    // In both 3MF reading modes.
    for strict in [false, true] {
        let mut args = vec!["info".as_ref(), file.as_os_str()];
        if strict {
            args.push("--strict".as_ref());
        }
        let (code, stderr) = run_guarded(&args);
        match code {
            Some(0) => {}
            _ => assert_refused(&file, code, &stderr),
        }
    }
}
