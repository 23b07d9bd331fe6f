//! The stable-toolchain fuzzer's long run: `cargo run --release --example fuzz_stable -- [OPTIONS]`
//! (`bench/fuzz.sh` runs it per target under a memory cap and prints the table).
//!
//! Options: `--execs N` per target (default 1 000 000, or `FUZZ_EXECS`), `--target NAME`
//! (repeatable; default every target), `--seed N` (default 1), `--findings DIR` (default
//! `target/fuzz-findings`), `--max-seed-bytes N` (default 65 536), `--list`, and
//! `--save-exec NAME:I` to write the input of execution `I` of a target to the findings folder
//! without running it (for an execution that ended the process). The seeds, mutations and
//! targets are those of the CI test (`tests/fuzz_stable/`). Exit status 1 when anything was
//! found.

#[allow(dead_code)]
#[path = "../tests/fuzz_stable/engine.rs"]
mod engine;
#[path = "../tests/fuzz_stable/targets.rs"]
mod targets;

use engine::{CURRENT_EXEC, HUGE_ALLOC, HUGE_BYTES, Limits, Runner};
use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::Ordering;

/// The system allocator, reporting every request over [`HUGE_BYTES`] as a finding of the
/// execution that made it (and naming it on stderr first, in case the request ends the process).
struct Counting;

/// Notes a request of `size` bytes.
fn note(size: usize) {
    if size > HUGE_BYTES {
        HUGE_ALLOC.fetch_max(size, Ordering::Relaxed);
        // A failed write is ignored: nothing here may unwind.
        let _ = writeln!(
            std::io::stderr(),
            "allocation of {size} bytes requested at execution {}",
            CURRENT_EXEC.load(Ordering::Relaxed)
        );
    }
}

#[allow(unsafe_code)]
// SAFETY: every call is forwarded to `System` unchanged; `note` only updates an atomic and
// writes a line to stderr, ignoring errors, so it never unwinds.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn main() {
    let mut execs: u64 = std::env::var("FUZZ_EXECS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let mut names: Vec<String> = Vec::new();
    let mut seed: u64 = 1;
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut findings = root.join("target/fuzz-findings");
    let mut max_seed_bytes: u64 = 64 << 10;
    let mut save_exec: Option<(String, u64)> = None;
    let mut list = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |what: &str| {
            args.next().unwrap_or_else(|| {
                eprintln!("{a} needs {what}");
                std::process::exit(2)
            })
        };
        let number = |v: String| -> u64 {
            v.replace('_', "").parse().unwrap_or_else(|_| {
                eprintln!("not a number: {v}");
                std::process::exit(2)
            })
        };
        match a.as_str() {
            "--execs" => execs = number(value("a count")),
            "--target" => names.push(value("a target name")),
            "--seed" => seed = number(value("a number")),
            "--findings" => findings = PathBuf::from(value("a folder")),
            "--max-seed-bytes" => max_seed_bytes = number(value("a size")),
            "--save-exec" => {
                let v = value("NAME:INDEX");
                let (n, i) = v.split_once(':').unwrap_or((v.as_str(), ""));
                save_exec = Some((n.to_owned(), number(i.to_owned())));
            }
            "--list" => list = true,
            _ => {
                eprintln!("unknown option {a} (see the doc comment of examples/fuzz_stable.rs)");
                std::process::exit(2)
            }
        }
    }
    let all = targets::all();
    if list {
        for t in &all {
            println!("{:<14} {}", t.name, t.about);
        }
        return;
    }
    if let Some(unknown) = names.iter().find(|n| !all.iter().any(|t| t.name == *n)) {
        eprintln!("unknown target {unknown} (--list names them)");
        std::process::exit(2);
    }
    let (dirs, notes) = engine::seed_dirs(&root);
    for n in notes {
        println!("{n}");
    }
    let runner = Runner {
        seeds: engine::collect_seeds(&dirs, max_seed_bytes),
        seed,
        limits: Limits::default(),
        findings: Some(findings.clone()),
    };
    if let Some((name, exec)) = save_exec {
        let Some(t) = all.iter().find(|t| t.name == name) else {
            eprintln!("unknown target {name}");
            std::process::exit(2)
        };
        let mut buf = Vec::new();
        let ext = runner.input(t, &runner.pool(t), exec, &mut buf);
        match engine::save(&findings, "abort", t.name, &buf, &ext) {
            Some(p) => println!("{}", p.display()),
            None => {
                eprintln!("cannot write into {}", findings.display());
                std::process::exit(1)
            }
        }
        return;
    }
    let scratch = match engine::scratch_dir() {
        Ok(d) => d,
        Err(e) => {
            eprintln!("no scratch folder: {e}");
            std::process::exit(1)
        }
    };
    println!(
        "{} seeds of at most {max_seed_bytes} bytes, seed {seed}, {execs} executions per target",
        runner.seeds.len()
    );
    let mut found = 0;
    for t in all
        .iter()
        .filter(|t| names.is_empty() || names.iter().any(|n| n == t.name))
    {
        let report = runner.run(t, execs, scratch.path());
        println!("{}", report.line());
        let mut seen: Vec<(&str, &str)> = Vec::new();
        for f in &report.findings {
            if seen.contains(&(f.kind, f.message.as_str())) {
                continue;
            }
            seen.push((f.kind, f.message.as_str()));
            let n = report
                .findings
                .iter()
                .filter(|g| g.kind == f.kind && g.message == f.message)
                .count();
            println!(
                "  {} ×{n}: {} (e.g. execution {}, {})",
                f.kind,
                f.message,
                f.exec,
                f.file
                    .as_ref()
                    .map_or_else(|| "not saved".to_owned(), |p| p.display().to_string())
            );
        }
        found += report.findings.len();
    }
    if found > 0 {
        std::process::exit(1);
    }
}
