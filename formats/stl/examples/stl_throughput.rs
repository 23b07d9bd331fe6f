//! Parse throughput of `conduit_stl::read` on one file, excluding disk I/O.
//!
//! ```text
//! cargo run --release -p conduit-stl --example stl_throughput -- PATH [RUNS]
//! ```
//!
//! Reads PATH into memory once, parses it RUNS times (default: enough for about 2 s, at least 5),
//! and prints the MB/s (1 MB = 10^6 bytes) of the parse alone: the first (untimed-for-statistics)
//! run, which also pays for fresh memory pages, then the best and median of the timed runs.

use std::process::ExitCode;
use std::time::{Duration, Instant};

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: stl_throughput PATH [RUNS]");
        return ExitCode::from(2);
    };
    let runs: Option<usize> = match args.next().map(|r| r.parse()) {
        None => None,
        Some(Ok(n)) if n > 0 => Some(n),
        Some(_) => {
            eprintln!("RUNS must be a positive integer");
            return ExitCode::from(2);
        }
    };
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("error: {path}: {e}");
            return ExitCode::from(2);
        }
    };

    // One untimed run to check the file and warm caches; it also sizes the default run count.
    let start = Instant::now();
    let stl = match conduit_stl::read(&bytes) {
        Ok(stl) => stl,
        Err(e) => {
            eprintln!("error: {path}: {e}");
            return ExitCode::FAILURE;
        }
    };
    let first = start.elapsed();
    let runs = runs.unwrap_or_else(|| {
        let per_run = first.max(Duration::from_micros(1)).as_secs_f64();
        ((2.0 / per_run) as usize).clamp(5, 10_000)
    });

    let mut times = Vec::with_capacity(runs);
    let mut triangles = 0;
    for _ in 0..runs {
        let start = Instant::now();
        let parsed = conduit_stl::read(std::hint::black_box(&bytes));
        let elapsed = start.elapsed();
        triangles = std::hint::black_box(parsed)
            .map(|s| s.triangles.len())
            .unwrap_or(0);
        times.push(elapsed);
    }
    times.sort();
    let mb = bytes.len() as f64 / 1e6;
    let rate = |d: Duration| mb / d.as_secs_f64().max(1e-12);
    let best = times.first().copied().unwrap_or_default();
    let median = times.get(times.len() / 2).copied().unwrap_or_default();
    println!(
        "{path}: {:?} STL, {triangles} triangles, {mb:.2} MB, first run {:.1} MB/s; {runs} runs: best {:.1} MB/s ({:.3} ms), median {:.1} MB/s ({:.3} ms)",
        stl.encoding,
        rate(first),
        rate(best),
        best.as_secs_f64() * 1e3,
        rate(median),
        median.as_secs_f64() * 1e3,
    );
    ExitCode::SUCCESS
}
