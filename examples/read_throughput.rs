//! Read throughput of conduit's loaders: `cargo run --release --example read_throughput -- FILE...`.
//!
//! For each file: the bytes are read once into memory (page cache warm), then the format reader runs
//! repeatedly on them; prints MB/s of the parse alone and of the full load (parse + indexed mesh),
//! and for meshes the time of the topology check and of a repair (on a copy).

use conduit::geom::Tolerances;
use conduit::scene::{FileKind, LoadOptions, load, load_scene};
use std::path::PathBuf;
use std::time::{Duration, Instant};

fn main() {
    let files: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    if files.is_empty() {
        eprintln!("usage: read_throughput FILE...");
        std::process::exit(2);
    }
    for path in files {
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("{}: {e}", path.display());
                std::process::exit(1);
            }
        };
        let mb = bytes.len() as f64 / 1e6;
        let kind = FileKind::detect(&path, &bytes);
        let parse = time(|| match kind {
            Some(FileKind::Stl) => conduit_stl::read(&bytes)
                .map(|s| s.triangles.len())
                .unwrap_or(0),
            Some(FileKind::ThreeMf) => conduit_3mf::read(&bytes, &conduit_3mf::Limits::default())
                .map(|p| p.models.len())
                .unwrap_or(0),
            _ => 0,
        });
        let full = time(|| {
            load(&path, &LoadOptions::default())
                .map(|f| f.warnings.len())
                .unwrap_or(0)
        });
        println!(
            "{}: {:.1} MB, parse {:.0} MB/s, full load (read + parse + index) {:.0} MB/s",
            path.display(),
            mb,
            mb / parse.as_secs_f64(),
            mb / full.as_secs_f64()
        );
        if let Ok((scene, _)) = load_scene(&path, &LoadOptions::default()) {
            for object in &scene.objects {
                let mesh = &object.mesh;
                let topology = time(|| mesh.topology());
                let repair = time(|| mesh.clone().repair(&Tolerances::default()));
                println!(
                    "  {}: {} triangles, topology check {:.1} ms, repair (with a copy) {:.1} ms",
                    object.name,
                    mesh.triangles.len(),
                    topology.as_secs_f64() * 1e3,
                    repair.as_secs_f64() * 1e3
                );
            }
        }
    }
}

/// Median wall time of `f` over enough runs to fill about two seconds (at least 5).
fn time<T>(mut f: impl FnMut() -> T) -> Duration {
    let mut samples = Vec::new();
    let start = Instant::now();
    while samples.len() < 5 || (start.elapsed() < Duration::from_secs(2) && samples.len() < 200) {
        let t = Instant::now();
        std::hint::black_box(f());
        samples.push(t.elapsed());
    }
    samples.sort();
    samples[samples.len() / 2]
}
