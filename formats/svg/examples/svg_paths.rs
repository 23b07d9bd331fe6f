//! Prints what `conduit_svg::read` finds in SVG files: page size, paths, points, extents.
//!
//! ```text
//! cargo run -p conduit-svg --example svg_paths -- FILE.svg... [--tolerance MM] [--dump]
//! ```
//!
//! `--dump` also prints every path as `path <id> <open|closed> x,y x,y ...` (millimetres, y up).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut tolerance = 0.01;
    let mut files = Vec::new();
    let mut dump = false;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        if arg == "--dump" {
            dump = true;
        } else if arg == "--tolerance" {
            tolerance = args.next().ok_or("--tolerance needs a value")?.parse()?;
        } else {
            files.push(arg);
        }
    }
    if files.is_empty() {
        return Err("usage: svg_paths FILE.svg... [--tolerance MM] [--dump]".into());
    }
    let mut failed = false;
    for file in files {
        let bytes = std::fs::read(&file)?;
        let start = std::time::Instant::now();
        match conduit_svg::read(&bytes, tolerance) {
            Ok(d) => {
                let points: usize = d.paths.iter().map(|p| p.points.len()).sum();
                let closed = d.paths.iter().filter(|p| p.closed).count();
                let (mut min, mut max) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
                for p in d.paths.iter().flat_map(|p| &p.points) {
                    for i in 0..2 {
                        min[i] = min[i].min(p[i]);
                        max[i] = max[i].max(p[i]);
                    }
                }
                println!(
                    "{file}: page {:?} x {:?} mm, {} paths ({closed} closed), {points} points, \
                     x {:.3}..{:.3}, y {:.3}..{:.3} mm, {:.1} ms",
                    d.width_mm,
                    d.height_mm,
                    d.paths.len(),
                    min[0],
                    max[0],
                    min[1],
                    max[1],
                    start.elapsed().as_secs_f64() * 1e3
                );
                if dump {
                    for p in &d.paths {
                        let pts: Vec<String> = p
                            .points
                            .iter()
                            .map(|q| format!("{},{}", q[0], q[1]))
                            .collect();
                        let kind = if p.closed { "closed" } else { "open" };
                        let id = p.id.as_deref().unwrap_or("-");
                        println!("path {id} {kind} {}", pts.join(" "));
                    }
                }
            }
            Err(e) => {
                failed = true;
                println!("{file}: error: {e}");
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
    Ok(())
}
