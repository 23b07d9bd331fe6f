//! The checker on the peer slicers' G-code of `shared/corpus/peer-gcode`: no errors, 100 layers
//! each (the corpus README), and the filament the slicers report within 1 % of the replay.

use super::*;

const CORPUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/corpus/peer-gcode");

/// The filament a slicer reports in its own comments, mm: PrusaSlicer's footer
/// `; filament used [mm] = X`, Slic3r's `; filament used = Xmm (Ycm3)`, Cura's header
/// `;Filament used: Xm` (metres; `0m` when the engine ran without the GUI, which fills it in).
fn reported_filament_mm(g: &conduit_gcode::Gcode) -> Option<f64> {
    for line in &g.lines {
        let Some(c) = line.comment_text() else {
            continue;
        };
        if let Some(v) = c.strip_prefix("filament used [mm] =") {
            return v.trim().split(',').next()?.trim().parse().ok();
        }
        if let Some(v) = c.strip_prefix("filament used =") {
            return v.trim().split("mm").next()?.trim().parse().ok();
        }
        if let Some(v) = c.strip_prefix("Filament used:") {
            let m: f64 = v.trim().split('m').next()?.trim().parse().ok()?;
            return (m > 0.0).then_some(m * 1000.0);
        }
    }
    None
}

/// PrusaSlicer's `; estimated printing time (normal mode) = 17m 0s`, in seconds.
fn reported_time_s(g: &conduit_gcode::Gcode) -> Option<f64> {
    let text = g.lines.iter().find_map(|l| {
        l.comment_text()?
            .strip_prefix("estimated printing time (normal mode) =")
    })?;
    let mut total = 0.0;
    for part in text.split_whitespace() {
        let (num, unit) = part.split_at(part.len().checked_sub(1)?);
        let n: f64 = num.parse().ok()?;
        total += n * match unit {
            "d" => 86400.0,
            "h" => 3600.0,
            "m" => 60.0,
            "s" => 1.0,
            _ => return None,
        };
    }
    Some(total)
}

#[test]
fn peer_gcode_replays_without_errors() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::path::Path::new(CORPUS);
    if !dir.is_dir() {
        println!("skipped: corpus not found");
        return Ok(());
    }
    let mut files: Vec<_> = std::fs::read_dir(dir)?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "gcode"))
        .collect();
    files.sort();
    assert!(!files.is_empty());
    let params = CheckParams::default();
    for path in files {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let name = name.unwrap_or_default();
        let g = conduit_gcode::parse(&std::fs::read(&path)?)?;
        let r = check(&g, &params);
        let used = r.stats.tools.first().map_or(0.0, |t| t.filament_mm);
        let reported = reported_filament_mm(&g);
        println!(
            "{name}: {} layers, {:.2} mm filament ({:.2} cm³), slicer says {}, time {:.0} s, \
             {} errors, {} warnings",
            r.stats.layers,
            used,
            r.stats.tools.first().map_or(0.0, |t| t.filament_mm3) / 1000.0,
            reported.map_or("nothing".to_owned(), |v| format!("{v} mm")),
            r.stats.estimated_time_s,
            r.errors,
            r.warnings
        );
        for f in &r.findings {
            println!("  {:?} line {}: {}", f.severity, f.line, f.message);
        }
        assert!(!r.has_errors(), "{name}: {:?}", r.findings);
        assert_eq!(r.stats.layers, 100, "{name}");
        assert_eq!(r.stats.tools.len(), 1, "{name}");
        if let Some(reported) = reported {
            assert!(
                (used - reported).abs() <= 0.01 * reported,
                "{name}: replayed {used} mm, slicer reports {reported} mm"
            );
        } else {
            println!("  (no filament figure in the file to compare with)");
        }
        if let Some(t) = reported_time_s(&g) {
            let est = r.stats.estimated_time_s;
            println!("  time: replayed {est:.0} s, PrusaSlicer estimates {t:.0} s");
            // PrusaSlicer plans with its own machine limits (1500 mm/s², jerk 10, 8 for X/Y
            // silent): within 10 %.
            assert!((est - t).abs() <= 0.1 * t, "{name}: {est} s vs {t} s");
        }
        let b = r.stats.extrusion_bounds.ok_or("no extrusion")?;
        // The 20 mm cube sits in the middle of the 250 mm bed.
        assert!(b.max[2] > 19.9 && b.max[2] < 20.1, "{name}: {b:?}");
        assert!(b.max[0] - b.min[0] < 21.0, "{name}: {b:?}");
    }
    Ok(())
}
