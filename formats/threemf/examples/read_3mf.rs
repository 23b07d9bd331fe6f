//! Reads 3MF files and prints what `conduit_3mf` sees: parts, objects, build items, flattened
//! triangle counts, warnings, or the error; with timings.
//!
//! Usage: `cargo run --release -p conduit-3mf --example read_3mf -- FILE.3mf [...]`

use std::time::Instant;

use conduit_3mf::{Limits, read};

fn main() {
    let mut failed = false;
    for path in std::env::args().skip(1) {
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) => {
                println!("{path}: {e}");
                failed = true;
                continue;
            }
        };
        let t0 = Instant::now();
        let pkg = match read(&bytes, &Limits::default()) {
            Ok(p) => p,
            Err(e) => {
                println!("{path}: error: {e}");
                failed = true;
                continue;
            }
        };
        let t1 = Instant::now();
        let flat = match pkg.flatten() {
            Ok(f) => f,
            Err(e) => {
                println!("{path}: flatten error: {e}");
                failed = true;
                continue;
            }
        };
        let t2 = Instant::now();
        let tris: usize = flat.iter().map(|f| f.triangles.len()).sum();
        println!(
            "{path}: {} part(s), {} object(s), {} build item(s), {tris} flattened triangles, unit {:?}; read {:.1} ms, flatten {:.1} ms",
            pkg.models.len(),
            pkg.models.values().map(|m| m.objects.len()).sum::<usize>(),
            pkg.root().build.len(),
            pkg.root().unit,
            (t1 - t0).as_secs_f64() * 1e3,
            (t2 - t1).as_secs_f64() * 1e3,
        );
        for w in &pkg.warnings {
            println!("  warning: {w}");
        }
    }
    std::process::exit(i32::from(failed));
}
