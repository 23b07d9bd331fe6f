//! The fuzzing regressions of `conduit route` (`../shared/regressions`, README there): every
//! placement and schematic that once panicked or exhausted memory is refused with exit 1 and
//! one line on stderr naming the file, and no run is killed.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::support::{regressions, sample, temp_dir};

/// The files of this share: route placements and schematics, in every folder.
fn route_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for sub in ["panic", "oom", "timeout", "handmade"] {
        let entries = std::fs::read_dir(dir.join(sub))
            .into_iter()
            .flatten()
            .flatten();
        for e in entries {
            let name = e.file_name().to_string_lossy().into_owned();
            if ["route-placement-", "route-sch-", "min_route_", "route_sch_"]
                .iter()
                .any(|p| name.starts_with(p))
            {
                out.push(e.path());
            }
        }
    }
    out.sort();
    out
}

/// Runs `conduit route` on `file` as the README says, with a hang guard; returns the exit code
/// (`None` when killed by a signal or the guard) and stderr.
fn run(file: &Path, out: &Path) -> (Option<i32>, String) {
    let name = file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let is_sch = name.starts_with("route-sch-") || name.contains("_sch");
    let (circuit, placement) = if is_sch {
        (file.to_path_buf(), sample("circuit_demo/placement.toml"))
    } else {
        (sample("circuit_demo/led_coin.sch"), file.to_path_buf())
    };
    let mut child = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .arg("route")
        .arg(sample("circuit_demo/block.stl"))
        .arg("--circuit")
        .arg(&circuit)
        .arg("--placement")
        .arg(&placement)
        .arg("--out-dir")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the conduit binary runs");
    let start = Instant::now();
    loop {
        if let Ok(Some(_)) = child.try_wait() {
            break;
        }
        if start.elapsed() > Duration::from_secs(20) {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let output = child.wait_with_output().expect("the run ends");
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

#[test]
fn route_regressions_are_refused_with_one_line_naming_the_file() {
    let Some(dir) = regressions() else { return };
    let files = route_files(&dir);
    assert!(
        !files.is_empty(),
        "no route regressions in {}",
        dir.display()
    );
    let mut failures = Vec::new();
    for file in &files {
        let out = temp_dir();
        let (code, stderr) = run(file, out.path());
        let name = file
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let lines = stderr.lines().count();
        if code != Some(1) || lines != 1 || !stderr.contains(&name) {
            failures.push(format!(
                "{name}: exit {code:?}, {lines} line(s): {stderr:?}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
