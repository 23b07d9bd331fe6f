//! The fuzzing regressions of `conform`, `calibrate tcp` and `jet` (`../shared/regressions`, its
//! README gives each file's command): each run ends by itself, exits 1 with one line on stderr
//! naming the file (or 0 where the input is valid), and is never killed by a signal.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::support::{regressions, root, sample, temp_dir};

/// A hang guard, not a benchmark: every run takes well under a second once refused.
const DEADLINE: Duration = Duration::from_secs(20);

/// The arguments that ran `file` (by its name's prefix, as in the README), writing into `out`;
/// `None` for a file of another command.
fn command(dir: &Path, file: &Path, out: &Path) -> Option<Vec<String>> {
    let name = file.file_name()?.to_str()?;
    let f = file.display().to_string();
    let gcode = out.join("o.gcode").display().to_string();
    let film = dir.join("film_small.xyz").display().to_string();
    let monopole = sample("conform/monopole.svg").display().to_string();
    let args: Vec<String> =
        if name.starts_with("conform-surface-") || name.starts_with("conform_surface") {
            vec![
                "conform".into(),
                "--surface".into(),
                f,
                "--design".into(),
                monopole,
                "--set".into(),
                "printer.start_gcode=G28".into(),
                "-o".into(),
                gcode,
            ]
        } else if name.starts_with("conform-design-") || name.starts_with("conform_design") {
            vec![
                "conform".into(),
                "--surface".into(),
                film,
                "--design".into(),
                f,
                "-o".into(),
                gcode,
            ]
        } else if name.starts_with("calibrate-tcp-") || name.starts_with("calibrate_tcp") {
            vec!["calibrate".into(), "tcp".into(), f]
        } else if name.starts_with("jet-dxf-") || name.starts_with("jet_dxf") {
            let layers = if name.starts_with("jet_dxf") {
                "2"
            } else {
                "8"
            };
            ["jet", &f, "--width", "20", "--layers", layers]
                .into_iter()
                .chain(["--layer-height", "5", "-o", &gcode])
                .map(str::to_owned)
                .collect()
        } else {
            return None;
        };
    Some(args)
}

/// Runs conduit with `args` from the project root, killing it at [`DEADLINE`]: its exit code
/// (`None` when ended by a signal), its stderr and whether the deadline killed it.
fn run(args: &[String]) -> (Option<i32>, String, bool) {
    let err = temp_dir();
    let err_path = err.path().join("stderr");
    let err_file = std::fs::File::create(&err_path).expect("a stderr file can be made");
    let mut child = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .args(args)
        .current_dir(root())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(err_file)
        .spawn()
        .expect("the conduit binary runs");
    let start = Instant::now();
    let (status, killed) = loop {
        if let Some(s) = child.try_wait().expect("the child can be waited for") {
            break (s, false);
        }
        if start.elapsed() > DEADLINE {
            let _ = child.kill();
            break (child.wait().expect("the killed child is reaped"), true);
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let stderr = std::fs::read_to_string(&err_path).unwrap_or_default();
    (status.code(), stderr, killed)
}

#[test]
fn conform_calibrate_and_jet_regressions_are_refused_in_one_line() {
    let Some(dir) = regressions() else {
        return;
    };
    let mut files: Vec<PathBuf> = ["panic", "oom", "timeout", "handmade"]
        .iter()
        .flat_map(|sub| crate::support::files_in(&dir.join(sub)))
        .collect();
    files.sort();
    let mut ran = 0;
    let mut failures = Vec::new();
    for file in &files {
        let out = temp_dir();
        let Some(args) = command(&dir, file, out.path()) else {
            continue;
        };
        ran += 1;
        let name = file.file_name().and_then(|n| n.to_str()).unwrap_or("");
        let (code, stderr, killed) = run(&args);
        let lines: Vec<&str> = stderr.lines().collect();
        let ok = !killed
            && match code {
                Some(1) => lines.len() == 1 && lines[0].contains(name),
                Some(0) => true,
                _ => false,
            };
        if !ok {
            failures.push(format!(
                "{name}: exit {code:?}, killed {killed}, {} stderr line(s): {}",
                lines.len(),
                lines.first().unwrap_or(&"")
            ));
        }
    }
    assert!(
        ran >= 20,
        "only {ran} regression files of conform, calibrate and jet found"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
