//! Parse throughput on real G-code.
//!
//! ```text
//! cargo run --release -p conduit-gcode --example gcode_throughput [FILE.gcode]
//! ```
//!
//! Without an argument it uses the largest `*.gcode` under `../shared/corpus`. It parses the file
//! repeatedly for about two seconds and prints MB/s for [`conduit_gcode::parse`], for
//! [`conduit_gcode::Gcode::to_bytes`] and for [`conduit_gcode::summarize`].

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn largest_gcode(dir: &Path, best: &mut Option<(u64, PathBuf)>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            largest_gcode(&path, best);
        } else if path.extension().is_some_and(|e| e == "gcode") {
            let len = entry.metadata().map_or(0, |m| m.len());
            if best.as_ref().is_none_or(|(l, _)| len > *l) {
                *best = Some((len, path));
            }
        }
    }
}

fn rate(bytes: usize, runs: u32, elapsed: Duration) -> f64 {
    bytes as f64 * f64::from(runs) / elapsed.as_secs_f64() / 1e6
}

/// Runs `f` until about `budget` has passed; returns the run count and time taken.
fn time(budget: Duration, mut f: impl FnMut()) -> (u32, Duration) {
    let start = Instant::now();
    let mut runs = 0;
    while runs < 3 || start.elapsed() < budget {
        f();
        runs += 1;
    }
    (runs, start.elapsed())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = match std::env::args_os().nth(1) {
        Some(p) => PathBuf::from(p),
        None => {
            let corpus = Path::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../../shared/corpus"
            ));
            let mut best = None;
            largest_gcode(corpus, &mut best);
            best.ok_or("no FILE given and no *.gcode found under ../shared/corpus")?
                .1
        }
    };
    let bytes = std::fs::read(&path)?;
    let g = conduit_gcode::parse(&bytes)?;
    assert!(g.to_bytes() == bytes, "round trip differs");
    println!(
        "{}: {} bytes, {} lines",
        path.display(),
        bytes.len(),
        g.lines.len()
    );

    let budget = Duration::from_secs(2);
    let (runs, elapsed) = time(budget, || {
        let g = conduit_gcode::parse(std::hint::black_box(&bytes));
        std::hint::black_box(g.map(|g| g.lines.len()).unwrap_or(0));
    });
    println!(
        "parse:     {:8.1} MB/s ({runs} runs)",
        rate(bytes.len(), runs, elapsed)
    );
    let (runs, elapsed) = time(budget, || {
        std::hint::black_box(g.to_bytes());
    });
    println!(
        "to_bytes:  {:8.1} MB/s ({runs} runs)",
        rate(bytes.len(), runs, elapsed)
    );
    let (runs, elapsed) = time(budget, || {
        std::hint::black_box(conduit_gcode::summarize(&g));
    });
    println!(
        "summarize: {:8.1} MB/s ({runs} runs)",
        rate(bytes.len(), runs, elapsed)
    );
    Ok(())
}
