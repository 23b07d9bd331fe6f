//! The documentation's examples run as written: every ```` ```sh ```` block of `README.md`,
//! `samples/README.md` and every page of the user guide (`docs/src/*.md`, in the order of
//! `docs/src/SUMMARY.md`), in order, from a folder that looks like the repository root (its
//! `samples/` linked in, `docs/` copied), with `conduit` on the `PATH` as the binary under test.
//! Each document starts from a fresh folder, so a page may only use the samples and the files
//! its own earlier blocks make (in `out/`).
//!
//! `cargo run --release --` is read as `conduit` (the same program, without a second build);
//! `cargo test`, `cargo install` and `cargo build` lines are skipped (they build or are this
//! test). Synopses with placeholders are written in ```` ```text ```` blocks and are not run.
//!
//! Two marks for blocks that need more than this machine may have:
//! - a first line `# needs: PROGRAM...` (e.g. `# needs: prusa-slicer`): the block runs when every
//!   named program is on the `PATH`, and is skipped with a message otherwise;
//! - ```` ```sh,no-run ````: shown as shell, never run (a command that needs a printer).

use std::path::Path;
use std::process::Command;

use crate::support::{root, temp_dir};

/// One ```` ```sh ```` block of a document.
#[derive(Debug)]
struct Block {
    /// The block's lines.
    lines: Vec<String>,
    /// Marked ```` ```sh,no-run ````: never run.
    no_run: bool,
}

impl Block {
    /// The programs named on a first line `# needs: A B`.
    fn needs(&self) -> Vec<String> {
        self.lines
            .first()
            .and_then(|l| l.trim_start().strip_prefix("# needs:"))
            .map(|rest| rest.split_whitespace().map(str::to_owned).collect())
            .unwrap_or_default()
    }
}

/// The ```` ```sh ```` blocks of a Markdown text (also ```` ```sh,no-run ````).
fn sh_blocks(markdown: &str) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut current: Option<Block> = None;
    for line in markdown.lines() {
        let trimmed = line.trim_start();
        match &mut current {
            None => {
                if let Some(info) = trimmed.strip_prefix("```") {
                    let mut words = info.split(',').map(str::trim);
                    if words.next() == Some("sh") {
                        let no_run = words.any(|w| w == "no-run");
                        current = Some(Block {
                            lines: Vec::new(),
                            no_run,
                        });
                    }
                }
            }
            Some(block) => {
                if trimmed == "```" {
                    blocks.extend(current.take());
                } else {
                    block.lines.push(line.to_owned());
                }
            }
        }
    }
    blocks
}

/// A block as the script to run: `cargo run --release --` as `conduit`, `cargo test`,
/// `cargo install` and `cargo build` left out.
fn script(block: &Block) -> String {
    block
        .lines
        .iter()
        .filter(|l| {
            let t = l.trim_start();
            !(t.starts_with("cargo test")
                || t.starts_with("cargo install")
                || t.starts_with("cargo build"))
        })
        .map(|l| l.replace("cargo run --release --", "conduit"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The pages of the guide in the order of `docs/src/SUMMARY.md` (the targets of its links).
fn guide_pages(summary: &str) -> Vec<String> {
    let mut pages = Vec::new();
    for line in summary.lines() {
        let mut rest = line;
        while let Some(start) = rest.find("](") {
            let after = &rest[start + 2..];
            let Some(end) = after.find(')') else { break };
            let target = &after[..end];
            if target.ends_with(".md") && !pages.iter().any(|p| p == target) {
                pages.push(target.to_owned());
            }
            rest = &after[end..];
        }
    }
    pages
}

/// Whether `program` is a file in one of the `PATH` folders.
fn on_path(program: &str, path: &str) -> bool {
    std::env::split_paths(path).any(|d| d.join(program).is_file())
}

/// What running a document's blocks did.
#[derive(Debug, Default)]
struct Ran {
    /// Blocks run (and passed).
    run: usize,
    /// Blocks skipped: marked `no-run`, or a program they need is missing.
    skipped: usize,
}

/// Runs every `sh` block of `doc` (relative to the repository root) in one fresh folder.
fn run_blocks_of(doc: &str) -> Ran {
    let text = std::fs::read_to_string(root().join(doc)).expect("the document is readable");
    run_blocks(doc, &text)
}

/// Runs every `sh` block of the Markdown `text` (named `doc` in messages) in one fresh folder.
fn run_blocks(doc: &str, text: &str) -> Ran {
    let root = root();
    let blocks = sh_blocks(text);
    assert!(!blocks.is_empty(), "{doc} has sh blocks");
    let tmp = temp_dir();
    let dir = tmp.path();
    link(&root.join("samples"), &dir.join("samples"));
    copy_dir(&root.join("docs"), &dir.join("docs"));
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
    let mut ran = Ran::default();
    for (i, block) in blocks.iter().enumerate() {
        if block.no_run {
            println!("{doc}, sh block {}: marked no-run, not run", i + 1);
            ran.skipped += 1;
            continue;
        }
        let missing: Vec<String> = block
            .needs()
            .into_iter()
            .filter(|p| !on_path(p, &path))
            .collect();
        if !missing.is_empty() {
            println!(
                "skipped {doc}, sh block {}: needs {} (not installed)",
                i + 1,
                missing.join(", ")
            );
            ran.skipped += 1;
            continue;
        }
        let script = script(block);
        let out = Command::new("bash")
            .arg("-euo")
            .arg("pipefail")
            .arg("-c")
            .arg(&script)
            .current_dir(dir)
            .env("PATH", &path)
            .env("NO_COLOR", "1")
            .output()
            .expect("bash runs");
        assert!(
            out.status.success(),
            "{doc}, sh block {} failed ({}):\n{script}\n--- stderr:\n{}",
            i + 1,
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
        ran.run += 1;
    }
    ran
}

#[cfg(unix)]
fn link(target: &Path, at: &Path) {
    if std::fs::symlink_metadata(at).is_err() {
        std::os::unix::fs::symlink(target, at).expect("symlink");
    }
}

/// Copies the files of `from` (recursively, without a built `book/`) to `to`.
fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("folder made");
    for entry in std::fs::read_dir(from).expect("folder readable") {
        let entry = entry.expect("folder entry");
        let path = entry.path();
        if path.is_dir() {
            if entry.file_name() != "book" {
                copy_dir(&path, &to.join(entry.file_name()));
            }
        } else {
            std::fs::copy(&path, to.join(entry.file_name())).expect("file copied");
        }
    }
}

#[test]
fn sh_blocks_are_found_and_cargo_lines_mapped() {
    let md = "x\n```sh\ncargo run --release -- slice a.stl -o b.gcode\ncargo test --workspace\n```\n\
              ```text\nconduit slice MODEL\n```\n```sh\nconduit info a.stl\n```\n\
              ```sh,no-run\nconduit slice a.stl -o /dev/ttyACM0\n```\n\
              ```sh\n# needs: prusa-slicer\ncargo install --path .\nprusa-slicer --help\n```\n";
    let blocks = sh_blocks(md);
    assert_eq!(blocks.len(), 4);
    assert_eq!(script(&blocks[0]), "conduit slice a.stl -o b.gcode");
    assert_eq!(script(&blocks[1]), "conduit info a.stl");
    assert!(!blocks[1].no_run && blocks[2].no_run);
    assert!(blocks[1].needs().is_empty());
    assert_eq!(blocks[3].needs(), ["prusa-slicer"]);
    assert_eq!(
        script(&blocks[3]),
        "# needs: prusa-slicer\nprusa-slicer --help"
    );
}

#[test]
fn marked_blocks_are_skipped_and_the_others_run() {
    let md = "```sh\nmkdir -p out\nconduit info samples/cube_20mm.stl > out/info.txt\n```\n\
              ```sh\n# needs: conduit-no-such-program\nexit 3\n```\n\
              ```sh,no-run\nexit 4\n```\n```sh\n# needs: conduit bash\ntest -s out/info.txt\n```\n";
    let ran = run_blocks("marks.md", md);
    assert_eq!((ran.run, ran.skipped), (2, 2));
}

#[test]
fn guide_pages_follow_the_summary() {
    let summary = "# Summary\n\n[Introduction](introduction.md)\n\n- [Slicing](slice.md)\n  \
                   - [Curved](curved.md)\n- [Slicing again](slice.md)\n";
    assert_eq!(
        guide_pages(summary),
        ["introduction.md", "slice.md", "curved.md"]
    );
}

#[test]
fn readme_examples_run_as_written() {
    run_blocks_of("README.md");
}

#[test]
fn samples_readme_examples_run_as_written() {
    run_blocks_of("samples/README.md");
}

/// Every page of the guide is in its summary, and every page's blocks run, each page from a
/// fresh folder.
#[test]
fn guide_examples_run_as_written() {
    let src = root().join("docs/src");
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).expect("docs/src/SUMMARY.md");
    let pages = guide_pages(&summary);
    let mut on_disk: Vec<String> = std::fs::read_dir(&src)
        .expect("docs/src is a folder")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".md") && n != "SUMMARY.md")
        .collect();
    on_disk.sort();
    let mut listed = pages.clone();
    listed.sort();
    assert_eq!(listed, on_disk, "every page of docs/src is in SUMMARY.md");
    let mut total = Ran::default();
    for page in &pages {
        let ran = run_blocks_of(&format!("docs/src/{page}"));
        total.run += ran.run;
        total.skipped += ran.skipped;
    }
    println!(
        "guide: {} pages, {} sh blocks run, {} skipped",
        pages.len(),
        total.run,
        total.skipped
    );
    assert!(total.run > pages.len(), "{total:?}");
}
