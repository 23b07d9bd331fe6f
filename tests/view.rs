//! `conduit view` in a real browser: the page of the 20 mm cube draws the cube where it is and
//! nothing where it is not, the layer slider shows layer 1's segments, and every G-code file
//! of the corpus and of the sample commands gives a page that loads without console errors.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use conduit::check::{Firmware, moves};
use conduit::emit::preview::layered_by_markers;
use serde_json::Value;

use crate::browser::{Browser, number, rgb};
use crate::support::{conduit, corpus, root, sample, slice_circuit_demo, stderr, temp_dir};

/// Background of the 3D view (`renderer.setClearColor`).
const BACKGROUND: [u8; 3] = [0x26, 0x2a, 0x31];

/// Extruded segments of each layer of a G-code file, replayed as the view replays it.
fn segments_per_layer(gcode: &Path) -> Vec<usize> {
    let bytes = std::fs::read(gcode).expect("the G-code is readable");
    let g = conduit_gcode::parse(&bytes).expect("the G-code parses");
    let m = layered_by_markers(&g, moves(&g, Firmware::Marlin));
    let mut per_layer = vec![0; m.layer_z.len()];
    for mv in m.moves.iter().filter(|m| m.extruding && m.has_xy) {
        if mv.path.iter().all(|p| p[0].is_some() && p[1].is_some()) {
            per_layer[mv.layer] += mv.path.len() - 1;
        }
    }
    per_layer
}

fn view(args: &[&str]) {
    let out = conduit(args);
    assert!(out.status.success(), "conduit {args:?}: {}", stderr(&out));
}

#[test]
fn cube_view_draws_the_cube_and_the_slider_shows_layer_one() {
    let Some(browser) = Browser::start() else {
        return;
    };
    let dir = temp_dir();
    let gcode = dir.path().join("cube.gcode");
    let html = dir.path().join("cube.html");
    let (g, h) = (gcode.to_string_lossy(), html.to_string_lossy());
    let cube = sample("cube_20mm.stl");
    view(&["slice", &cube.to_string_lossy(), "-o", &g]);
    view(&["view", &g, "-o", &h]);
    browser.open_file(&html).expect("the page loads");
    assert_eq!(browser.console_errors(), Vec::<String>::new());

    // From the top, without the grid: the cube's square is drawn, the area around it is not.
    browser.click("#show-grid");
    browser.eval("window.conduitView.setView('top'); return 0;");
    let bounds = browser.eval(
        "const b = window.conduitView.state(); const j = b.job; \
         return document.getElementById('conduit-data') && JSON.parse(document.getElementById('conduit-data').textContent).jobs[j].bounds;",
    );
    let b: Vec<f64> = bounds
        .as_array()
        .expect("bounds")
        .iter()
        .map(number)
        .collect();
    assert!(
        (b[3] - b[0] - 20.0).abs() < 0.6 && (b[4] - b[1] - 20.0).abs() < 0.6,
        "the cube is 20 mm across: {b:?}"
    );
    let img = browser.keep_screenshot("view_cube_top");
    let top = b[5];
    let at = |x: f64, y: f64| -> [u8; 3] {
        let p = browser.eval(&format!(
            "return window.conduitView.project([{x}, {y}, {top}]);"
        ));
        rgb(&img, number(&p[0]), number(&p[1]))
    };
    let (cx, cy) = ((b[0] + b[3]) / 2.0, (b[1] + b[4]) / 2.0);
    for fx in [0.05, 0.25, 0.5, 0.75, 0.95] {
        for fy in [0.05, 0.25, 0.5, 0.75, 0.95] {
            let (x, y) = (b[0] + fx * (b[3] - b[0]), b[1] + fy * (b[4] - b[1]));
            assert_ne!(
                at(x, y),
                BACKGROUND,
                "the cube is drawn at ({x:.1}, {y:.1})"
            );
        }
    }
    for (dx, dy) in [(-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0), (1.0, 1.0)] {
        let (x, y) = (cx + dx * 14.0, cy + dy * 14.0);
        assert_eq!(at(x, y), BACKGROUND, "nothing is drawn at ({x:.1}, {y:.1})");
    }
    // The drawing uses the legend's colours exactly (no gamma shift): the outer walls' orange.
    let outer = browser.eval(
        "return JSON.parse(document.getElementById('conduit-data').textContent).jobs[0].groups \
         .find((g) => g.role === 'External perimeter').colour;",
    );
    let hex = u32::from_str_radix(
        outer.as_str().expect("a colour").trim_start_matches('#'),
        16,
    )
    .expect("hex");
    let want = [(hex >> 16) as u8, (hex >> 8) as u8, hex as u8];
    let exact = (0..img.height())
        .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| rgb(&img, f64::from(x), f64::from(y)) == want)
        .count();
    assert!(exact >= 200, "{exact} pixels of {outer}");

    // The "to" slider moved to its start by the keyboard: layer 1 alone.
    let per_layer = segments_per_layer(&gcode);
    let all: usize = per_layer.iter().sum();
    let state = browser.eval("return window.conduitView.state();");
    assert_eq!(
        state["drawnSegments"], all as u64,
        "every layer is drawn at first"
    );
    assert_eq!(state["layerCount"], per_layer.len() as u64);
    browser.send_keys("#layer-to", "\u{E011}"); // Home
    let state = browser.eval("return window.conduitView.state();");
    assert_eq!(
        (state["from"].clone(), state["to"].clone()),
        (0.into(), 0.into())
    );
    assert_eq!(
        state["drawnSegments"], per_layer[0] as u64,
        "layer 1's segments"
    );
    assert!(per_layer[0] > 0 && per_layer[0] < all);
    let label = browser.eval("return document.getElementById('layer-label').textContent;");
    assert_eq!(
        label,
        format!("layer 1 of {} · z 0.200 mm", per_layer.len()).as_str()
    );
    browser.keep_screenshot("view_cube_layer_1");
    assert_eq!(browser.console_errors(), Vec::<String>::new());
}

/// Every `.gcode` below `dir`, sorted.
fn gcode_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "gcode") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Views `file` into `html`; when conduit writes a page, it loads in the browser without errors.
/// Returns whether a page was written.
fn view_and_load(browser: &Browser, file: &Path, html: &Path) -> bool {
    let out = conduit([
        "view".as_ref(),
        file.as_os_str(),
        "-o".as_ref(),
        html.as_os_str(),
    ]);
    if !out.status.success() {
        assert!(
            !html.exists(),
            "{}: a refused file leaves no page",
            file.display()
        );
        assert!(
            stderr(&out).contains(&*file.to_string_lossy()),
            "the refusal names the file: {}",
            stderr(&out)
        );
        return false;
    }
    browser
        .open_file(html)
        .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let errors = browser.console_errors();
    assert!(
        errors.is_empty(),
        "{}: console errors {errors:?}",
        file.display()
    );
    let state = browser.eval("return window.conduitView.state();");
    assert!(
        number(&state["layerCount"]) >= 1.0,
        "{}: {state}",
        file.display()
    );
    true
}

#[test]
fn every_corpus_gcode_and_sample_output_loads_without_console_errors() {
    let Some(browser) = Browser::start() else {
        return;
    };
    let dir = temp_dir();
    // The sample commands' outputs: bench/golden.sh keeps them with GOLDEN_KEEP.
    let kept = dir.path().join("samples");
    let run = Command::new("bash")
        .arg(root().join("bench/golden.sh"))
        .env("CONDUIT", env!("CARGO_BIN_EXE_conduit"))
        .env("CONDUIT_CORPUS", root().join("no-corpus-here"))
        .env("GOLDEN_KEEP", &kept)
        .output()
        .expect("bash runs bench/golden.sh");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let samples = gcode_files(&kept);
    assert!(samples.len() >= 20, "sample outputs: {samples:?}");
    let mut shown = 0;
    for (i, file) in samples.iter().enumerate() {
        let html = dir.path().join(format!("sample_{i}.html"));
        assert!(
            view_and_load(&browser, file, &html),
            "{}: conduit's own output is shown",
            file.display()
        );
        shown += 1;
    }
    println!("{shown} sample outputs shown");

    let Some(corpus) = corpus() else {
        return;
    };
    let manifest: Value = serde_json::from_str(
        &std::fs::read_to_string(corpus.join("MANIFEST.json")).expect("the manifest"),
    )
    .expect("the manifest is JSON");
    let mut counts = [0; 3];
    for entry in manifest.as_array().expect("a list") {
        let staged = entry["staged"].as_str().unwrap_or_default();
        if !(staged.ends_with(".gcode") || staged.ends_with(".bgcode")) {
            continue;
        }
        let file = corpus.join(staged);
        let html = dir.path().join(format!("corpus_{}.html", counts[2]));
        let shown = view_and_load(&browser, &file, &html);
        match entry["outcome"].as_str() {
            Some("load") => assert!(shown, "{staged}: must be shown"),
            Some("reject") => assert!(!shown, "{staged}: must be refused"),
            _ => {}
        }
        counts[usize::from(!shown)] += 1;
        counts[2] += 1;
    }
    println!(
        "corpus G-code: {} shown, {} refused cleanly, of {}",
        counts[0], counts[1], counts[2]
    );
    assert!(counts[0] >= 15, "{counts:?}");
}

/// Writes `shot` as a guide picture when `CONDUIT_WRITE_PICTURES=1`.
pub fn write_picture(name: &str, png_of: impl FnOnce() -> Vec<u8>) {
    if std::env::var_os("CONDUIT_WRITE_PICTURES").is_some_and(|v| v == "1") {
        let path = root().join("docs/src/images").join(name);
        std::fs::create_dir_all(path.parent().expect("a folder")).expect("the folder is made");
        std::fs::write(&path, png_of()).expect("the picture is written");
        println!("picture: {}", path.display());
    }
}

#[test]
fn demo_view_shows_the_traces_in_their_own_colour_and_the_parts_labelled() {
    let Some(browser) = Browser::start() else {
        return;
    };
    let dir = temp_dir();
    let gcode = dir.path().join("demo.gcode");
    let html = dir.path().join("demo.html");
    let (g, h) = (gcode.to_string_lossy(), html.to_string_lossy());
    let s = |p: &str| sample(p).to_string_lossy().into_owned();
    let (block, sch, placement) = (
        s("circuit_demo/block.stl"),
        s("circuit_demo/led_coin.sch"),
        s("circuit_demo/placement.toml"),
    );
    slice_circuit_demo(&gcode, &[]);
    view(&[
        "view",
        &g,
        "--model",
        &block,
        "--circuit",
        &sch,
        "--placement",
        &placement,
        "-o",
        &h,
    ]);
    // The layers up to the traces, from the top: the traces lie in the open channels.
    let abs = std::fs::canonicalize(&html).expect("the page exists");
    browser
        .open(
            &format!(
                "file://{}#layers=1-21&view=top&hide=grid,model",
                abs.display()
            ),
            Duration::from_secs(60),
        )
        .expect("the page loads");
    assert_eq!(browser.console_errors(), Vec::<String>::new());
    let state = browser.eval("return window.conduitView.state();");
    assert_eq!(
        (state["from"].clone(), state["to"].clone()),
        (0.into(), 20.into())
    );
    let mut labels: Vec<String> = state["labels"]
        .as_array()
        .expect("labels")
        .iter()
        .map(|v| v.as_str().unwrap_or_default().to_owned())
        .collect();
    labels.sort();
    assert_eq!(labels, ["BAT1", "LED1", "R1"], "the parts are labelled");
    // The trace colour is used by no other group, and it is on screen.
    let colours = browser.eval(
        "return JSON.parse(document.getElementById('conduit-data').textContent).jobs[0].groups \
         .map((g) => [g.role, g.colour]);",
    );
    let colours: Vec<(String, String)> = colours
        .as_array()
        .expect("groups")
        .iter()
        .map(|v| {
            (
                v[0].as_str().unwrap_or_default().to_owned(),
                v[1].as_str().unwrap_or_default().to_owned(),
            )
        })
        .collect();
    let trace = colours
        .iter()
        .find(|(r, _)| r == "Conductive trace")
        .map(|(_, c)| c.clone())
        .expect("the demo has traces");
    assert!(
        colours
            .iter()
            .filter(|(r, _)| r != "Conductive trace")
            .all(|(_, c)| *c != trace),
        "{colours:?}"
    );
    let hex = |c: &str| {
        let n = u32::from_str_radix(c.trim_start_matches('#'), 16).expect("hex");
        [(n >> 16) as u8, (n >> 8) as u8, n as u8]
    };
    let want = hex(&trace);
    let img = browser.keep_screenshot("view_demo_traces");
    let near = (0..img.height())
        .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let c = rgb(&img, f64::from(x), f64::from(y));
            (0..3).all(|k| (i32::from(c[k]) - i32::from(want[k])).abs() <= 24)
        })
        .count();
    assert!(near >= 50, "{near} pixels of the trace colour {trace}");
    assert_eq!(browser.console_errors(), Vec::<String>::new());
    // The guide's picture: the same view from the front-left.
    browser.eval("window.conduitView.setView('iso'); return 0;");
    write_picture("view.png", || {
        let img = browser.keep_screenshot("view_demo_iso");
        img.encode_png().expect("encodes")
    });
}
