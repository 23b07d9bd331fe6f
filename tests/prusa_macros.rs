//! PrusaSlicer's macro language in real profiles: PrusaSlicer's own test project (an MK4IS
//! profile whose start and end G-code compute the probed area and the purge line from the
//! print, and pick temperatures by material) slices, and its start and end G-code render as
//! PrusaSlicer renders them; a broken macro is an error naming the template, the line and the
//! placeholder.

use crate::support::{conduit, corpus, sample, stderr, temp_dir};

/// The extent of the material of the first layer: every extruding move's ends grown by half
/// the `;WIDTH:` in force, [min x, min y, max x, max y].
fn first_layer_extent(gcode: &str) -> [f64; 4] {
    let mut ext = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    let (mut x, mut y, mut width) = (None::<f64>, None::<f64>, 0.0);
    let mut layers = 0;
    for line in gcode.lines() {
        if line.starts_with(";LAYER_CHANGE") {
            layers += 1;
            if layers == 2 {
                break;
            }
        }
        if let Some(w) = line.strip_prefix(";WIDTH:") {
            width = w.parse().expect("a width");
        }
        let code = line.split(';').next().unwrap_or_default();
        let mut words = code.split_whitespace();
        if !matches!(words.next(), Some("G1" | "G0")) {
            continue;
        }
        let (mut nx, mut ny, mut e) = (x, y, 0.0);
        for w in words {
            let v = w[1..].parse::<f64>().unwrap_or(0.0);
            match &w[..1] {
                "X" => nx = Some(v),
                "Y" => ny = Some(v),
                "E" => e = v,
                _ => {}
            }
        }
        if layers == 1
            && e > 0.0
            && let (Some(ax), Some(ay), Some(bx), Some(by)) = (x, y, nx, ny)
        {
            let r = width / 2.0;
            for (px, py) in [(ax, ay), (bx, by)] {
                ext = [
                    ext[0].min(px - r),
                    ext[1].min(py - r),
                    ext[2].max(px + r),
                    ext[3].max(py + r),
                ];
            }
        }
        (x, y) = (nx, ny);
    }
    ext
}

/// The number after `letter` in a G-code line.
fn word(line: &str, letter: char) -> f64 {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(letter))
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN)
}

#[test]
fn prusaslicer_mk4_project_renders_its_start_and_end_gcode() {
    let Some(corpus) = corpus() else {
        return;
    };
    let dir = temp_dir();
    let out = dir.path().join("seam.gcode");
    let run = conduit([
        "slice".as_ref(),
        corpus
            .join("PrusaSlicer/tests/data/seam_test_object.3mf")
            .as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(
        !stderr(&run).contains("cannot fill") && !stderr(&run).contains("syntax error"),
        "{}",
        stderr(&run)
    );
    let g = std::fs::read_to_string(&out).expect("the G-code");
    let lines: Vec<&str> = g.lines().collect();
    let has = |l: &str| lines.contains(&l);
    // Lines PrusaSlicer 2.5 writes for the same project, word for word.
    for l in [
        "M862.1 P0.4 ; nozzle diameter check",
        "M862.3 P \"MK4\" ; printer model check",
        "M140 S60 ; set bed temp",
        "M104 T0 S170 ; set extruder temp for bed leveling",
        "M109 T0 R170 ; wait for temp",
        "G1 X42 Y-4 Z5 F4800",
        "G1 E-2 F2400 ; retraction",
        "G29 P9 X10 Y-4 W32 H4",
        "M106 S100",
        "M190 S60 ; wait for bed temp",
        "M104 S230",
        "M109 S230",
        "G1 E2 F2400 ; deretraction after the initial one before nozzle cleaning",
        "G0 X48 Z0.05 F8000 ; wipe, move close to the bed",
        "G0 X51 Z0.2 F8000 ; wipe, move quickly away from the bed",
        "G1 X241 Y170 F3600 ; park",
        "; max_layer_z = 48.05",
    ] {
        assert!(has(l), "missing `{l}`");
    }
    assert!(!g.contains('{'), "an unfilled macro is left");
    assert!(
        !has("G1 E-4 F2400 ; retraction"),
        "the FLEX branch is not taken"
    );
    // The probed area follows the first layer: X its left edge, Y 4 mm before its front edge,
    // W its width, H its depth plus those 4 mm (the bed, 250 mm wide, clips nothing here).
    let m555 = lines
        .iter()
        .find(|l| l.starts_with("M555 "))
        .expect("an M555 line");
    let [x0, y0, x1, y1] = first_layer_extent(&g);
    let close = |a: f64, b: f64| (a - b).abs() < 2e-3;
    assert!(close(word(m555, 'X'), x0), "{m555} vs x {x0}");
    assert!(close(word(m555, 'Y'), y0 - 4.0), "{m555} vs y {y0}");
    assert!(close(word(m555, 'W'), x1 - x0), "{m555} vs x {x0}..{x1}");
    assert!(
        close(word(m555, 'H'), y1 - y0 + 4.0),
        "{m555} vs y {y0}..{y1}"
    );
    // The end G-code lifts from where the nozzle is: 1 mm, then 23 mm above it.
    let lift = |comment_speed: &str| {
        lines
            .iter()
            .find(|l| l.ends_with(comment_speed))
            .map(|l| word(l, 'Z'))
            .unwrap_or(f64::NAN)
    };
    assert!(close(lift("F720 ; Move print head up"), 49.05));
    assert!(close(lift("F300 ; Move print head up"), 71.05));
    // The filament's own G-code, where PrusaSlicer 2.5 writes it: its start after the
    // preamble's `M83` and before the first layer (its pressure advance for the MK4IS's 0.4 mm
    // nozzle), its end after the last retraction and before the printer's end G-code.
    let at = |l: &str| lines.iter().position(|x| *x == l).unwrap_or(usize::MAX);
    let preamble = at("M83 ; use relative distances for extrusion");
    let first_layer = lines
        .iter()
        .position(|l| l.starts_with(";LAYER_CHANGE"))
        .expect("layers");
    for l in [
        "M900 K0.05 ; Filament gcode",
        "M572 S0.036 ; Filament gcode",
        "M142 S36 ; set heatbreak target temp",
    ] {
        assert!(
            at(l) > preamble && at(l) < first_layer,
            "`{l}` at {}",
            at(l)
        );
    }
    let end_filament = at("; Filament-specific end gcode");
    assert!(end_filament > first_layer && end_filament < usize::MAX);
    assert_eq!(
        lines[end_filament + 1],
        "G1 Z49.05 F720 ; Move print head up"
    );
    assert_eq!(lines.iter().filter(|l| l.starts_with("M572 ")).count(), 2);
    // The layer G-code frames every layer change: before the move, the acceleration from the
    // weight printed so far (`interpolate_table(extruded_weight_total, (0,4000), (1400,2500),
    // …)`) and `M74` with that weight; after it, the layer's z.
    let layers = lines.iter().filter(|l| **l == ";LAYER_CHANGE").count();
    let count = |l: &str| lines.iter().filter(|x| **x == l).count();
    assert_eq!(count(";BEFORE_LAYER_CHANGE"), layers);
    assert_eq!(count(";AFTER_LAYER_CHANGE"), layers);
    let numbers = |prefix: &str, letter: char| -> Vec<f64> {
        lines
            .iter()
            .filter(|l| l.starts_with(prefix))
            .map(|l| word(l, letter))
            .collect()
    };
    let (accels, weights) = (numbers("M201 X", 'X'), numbers("M74 W", 'W'));
    assert_eq!((accels.len(), weights.len()), (layers, layers));
    assert!(
        weights.windows(2).all(|w| w[0] <= w[1]),
        "the weight only grows"
    );
    // 12.84 g in all (the filament total of the summary); the last layer's is nearly that.
    let last = weights[layers - 1];
    assert!(last > 12.0 && last < 12.85, "{last}");
    for (a, w) in accels.iter().zip(&weights) {
        let want = if *w < 1400.0 {
            4000.0 - 1500.0 * w / 1400.0
        } else {
            2500.0
        };
        assert!((a - want).abs() < 0.01 + 1e-4 * want, "M201 {a} at {w} g");
    }
}

#[test]
fn a_broken_macro_names_the_template_the_line_and_the_placeholder() {
    let dir = temp_dir();
    let out = dir.path().join("cube.gcode");
    let run = conduit([
        "slice".as_ref(),
        sample("cube_20mm.stl").as_os_str(),
        "--set".as_ref(),
        "printer.start_gcode=G28\nG1 Z{first_layer_height + lift_height}".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(!run.status.success());
    let err = stderr(&run);
    assert!(
        err.contains(
            "printer.start_gcode, line 2: unknown variable `lift_height` in \
             {first_layer_height + lift_height}"
        ),
        "{err}"
    );
    assert!(!out.exists());
}
