//! The documentation's examples run as written: every ```` ```sh ```` block of `README.md` and
//! `samples/README.md`, in order, from a folder that looks like the repository root (its
//! `samples/` linked in), with `conduit` on the `PATH` as the binary under test.
//!
//! `cargo run --release --` is read as `conduit` (the same program, without a second build);
//! `cargo test` lines are skipped (they are this test). Synopses with placeholders are written
//! in ```` ```text ```` blocks and are not run.

use std::path::Path;
use std::process::Command;

use crate::support::{root, temp_dir};

/// The ```` ```sh ```` blocks of a Markdown text, each as its lines.
fn sh_blocks(markdown: &str) -> Vec<Vec<String>> {
    let mut blocks = Vec::new();
    let mut current: Option<Vec<String>> = None;
    for line in markdown.lines() {
        match (&mut current, line.trim_start()) {
            (None, "```sh") => current = Some(Vec::new()),
            (Some(_), "```") => blocks.extend(current.take()),
            (Some(lines), _) => lines.push(line.to_owned()),
            (None, _) => {}
        }
    }
    blocks
}

/// A block as the script to run: `cargo run --release --` as `conduit`, `cargo test` left out.
fn script(block: &[String]) -> String {
    block
        .iter()
        .filter(|l| !l.trim_start().starts_with("cargo test"))
        .map(|l| l.replace("cargo run --release --", "conduit"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Runs every `sh` block of `doc` (relative to the repository root) in one fresh folder.
fn run_blocks_of(doc: &str) {
    let root = root();
    let text = std::fs::read_to_string(root.join(doc)).expect("the document is readable");
    let blocks = sh_blocks(&text);
    assert!(!blocks.is_empty(), "{doc} has sh blocks");
    let tmp = temp_dir();
    let dir = tmp.path();
    link(&root.join("samples"), &dir.join("samples"));
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).expect("bin folder");
    link(
        Path::new(env!("CARGO_BIN_EXE_conduit")),
        &bin.join("conduit"),
    );
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    for (i, block) in blocks.iter().enumerate() {
        let script = script(block);
        let out = Command::new("bash")
            .arg("-euo")
            .arg("pipefail")
            .arg("-c")
            .arg(&script)
            .current_dir(dir)
            .env("PATH", &path)
            .output()
            .expect("bash runs");
        assert!(
            out.status.success(),
            "{doc}, sh block {} failed ({}):\n{script}\n--- stderr:\n{}",
            i + 1,
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[cfg(unix)]
fn link(target: &Path, at: &Path) {
    if std::fs::symlink_metadata(at).is_err() {
        std::os::unix::fs::symlink(target, at).expect("symlink");
    }
}

#[test]
fn sh_blocks_are_found_and_cargo_lines_mapped() {
    let md = "x\n```sh\ncargo run --release -- slice a.stl -o b.gcode\ncargo test --workspace\n```\n\
              ```text\nconduit slice MODEL\n```\n```sh\nconduit info a.stl\n```\n";
    let blocks = sh_blocks(md);
    assert_eq!(blocks.len(), 2);
    assert_eq!(script(&blocks[0]), "conduit slice a.stl -o b.gcode");
    assert_eq!(script(&blocks[1]), "conduit info a.stl");
}

#[test]
fn readme_examples_run_as_written() {
    run_blocks_of("README.md");
}

#[test]
fn samples_readme_examples_run_as_written() {
    run_blocks_of("samples/README.md");
}
