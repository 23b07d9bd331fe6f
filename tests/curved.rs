//! Curved top surfaces (`conduit slice --curved tops`): generated blocks with a gentle roof are
//! sliced, the G-code re-parsed and every point of the curved layers compared with the mesh's
//! surface; steep and colliding tops are rejected with a reported position; the corpus wing and
//! car slice and pass `conduit check`.

use std::path::{Path, PathBuf};
use std::process::Command;

use conduit::config::Config;
use conduit::curved::{HeightField, LAYER_COMMENT};
use conduit::pipeline::place_on_bed;
use conduit::scene::{LoadOptions, load_scene};
use serde_json::Value;

use crate::support::{corpus, stderr, temp_dir};

type Tri = [[f64; 3]; 3];

/// A closed block over `[x0, x1] × [y0, y1]`, bottom at z = 0, top z = f(x, y) triangulated on
/// an `n × n` grid (walls split to match, so every edge is shared by two triangles).
fn block_with_top(
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
    n: usize,
    f: &dyn Fn(f64, f64) -> f64,
) -> Vec<Tri> {
    let (dx, dy) = ((x1 - x0) / n as f64, (y1 - y0) / n as f64);
    let at = |i: usize, j: usize| (x0 + i as f64 * dx, y0 + j as f64 * dy);
    let top = |i: usize, j: usize| {
        let (x, y) = at(i, j);
        [x, y, f(x, y)]
    };
    let bot = |i: usize, j: usize| {
        let (x, y) = at(i, j);
        [x, y, 0.0]
    };
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..n {
            t.push([top(i, j), top(i + 1, j), top(i + 1, j + 1)]);
            t.push([top(i, j), top(i + 1, j + 1), top(i, j + 1)]);
            t.push([bot(i, j), bot(i + 1, j + 1), bot(i + 1, j)]);
            t.push([bot(i, j), bot(i, j + 1), bot(i + 1, j + 1)]);
        }
    }
    for k in 0..n {
        for (a, b) in [
            ((k, 0), (k + 1, 0)),
            ((n, k), (n, k + 1)),
            ((k + 1, n), (k, n)),
            ((0, k + 1), (0, k)),
        ] {
            let (ta, tb, ba, bb) = (top(a.0, a.1), top(b.0, b.1), bot(a.0, a.1), bot(b.0, b.1));
            t.push([ba, bb, tb]);
            t.push([ba, tb, ta]);
        }
    }
    t
}

fn write_stl(path: &Path, tris: &[Tri]) {
    let mut out = vec![0u8; 80];
    out.extend((tris.len() as u32).to_le_bytes());
    for t in tris {
        out.extend([0u8; 12]);
        for p in t {
            for c in p {
                out.extend((*c as f32).to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    std::fs::write(path, out).expect("the STL is written");
}

struct Run {
    gcode: String,
    report: Value,
    stderr: String,
}

fn slice(dir: &Path, model: &Path, name: &str, extra: &[&str]) -> Run {
    let out = dir.join(format!("{name}.gcode"));
    let rep = dir.join(format!("{name}.json"));
    let o = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .arg("slice")
        .arg(model)
        .args(["--curved", "tops", "-o"])
        .arg(&out)
        .arg("--report")
        .arg(&rep)
        .args(extra)
        .output()
        .expect("the conduit binary runs");
    assert!(o.status.success(), "slice failed: {}", stderr(&o));
    let check = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .arg("check")
        .arg(&out)
        .output()
        .expect("the conduit binary runs");
    assert!(
        check.status.success(),
        "check rejects {name}: {}",
        String::from_utf8_lossy(&check.stdout)
    );
    Run {
        gcode: std::fs::read_to_string(&out).expect("G-code is written"),
        report: serde_json::from_str(&std::fs::read_to_string(&rep).expect("report written"))
            .expect("report is JSON"),
        stderr: stderr(&o),
    }
}

/// The end points of every extruding move inside the curved blocks, with their block's depth.
fn curved_points(gcode: &str) -> Vec<([f64; 3], f64)> {
    let (mut pos, mut e) = ([0.0f64; 3], 0.0f64);
    let mut depth: Option<f64> = None;
    let mut out = Vec::new();
    for line in gcode.lines() {
        if let Some(rest) = line.strip_prefix(&format!("; {LAYER_COMMENT} layer ")) {
            depth = rest.split_whitespace().nth(2).and_then(|d| d.parse().ok());
            continue;
        }
        if line.starts_with(";LAYER_CHANGE") {
            depth = None;
        }
        let code = line.split(';').next().unwrap_or("").trim();
        let mut words = code.split_whitespace();
        let Some(cmd) = words.next() else { continue };
        let mut new_e = None;
        for w in words {
            let (k, v) = w.split_at(1);
            let Ok(v) = v.parse::<f64>() else { continue };
            match (cmd, k) {
                ("G0" | "G1", "X") => pos[0] = v,
                ("G0" | "G1", "Y") => pos[1] = v,
                ("G0" | "G1", "Z") => pos[2] = v,
                ("G0" | "G1", "E") => new_e = Some(v),
                ("G92", "E") => e = v,
                _ => {}
            }
        }
        if let Some(ne) = new_e {
            if let (Some(d), true) = (depth, ne > e) {
                out.push((pos, d));
            }
            e = ne;
        }
    }
    out
}

/// The placed mesh's height field (the slice centres the footprint on the bed).
fn placed_surface(model: &Path) -> HeightField {
    let (scene, _) = load_scene(model, &LoadOptions::default()).expect("the model loads");
    let meshes = place_on_bed(&scene, &Config::default());
    HeightField::from_mesh(&meshes[0])
}

fn dome(x: f64, y: f64) -> f64 {
    8.0 + 2.5 * (1.0 - ((x - 15.0).powi(2) + (y - 15.0).powi(2)) / 450.0)
}

#[test]
fn curved_gentle_dome_follows_the_surface_at_each_depth() {
    let dir = temp_dir();
    let model = dir.path().join("dome.stl");
    write_stl(&model, &block_with_top(0.0, 0.0, 30.0, 30.0, 24, &dome));
    let run = slice(dir.path(), &model, "dome", &[]);
    let hf = placed_surface(&model);
    let pts = curved_points(&run.gcode);
    assert!(pts.len() > 1000, "{} curved points", pts.len());
    let mut worst: f64 = 0.0;
    for (p, depth) in &pts {
        let s = hf.at(p[0], p[1]).map(|h| h.z);
        let Some(s) = s else {
            panic!("no surface under {p:?}")
        };
        worst = worst.max((p[2] - (s - depth)).abs());
    }
    assert!(worst < 0.01, "worst {worst}");
    let c = &run.report["curved"];
    assert_eq!(c["regions"].as_array().map(Vec::len), Some(1), "{c}");
    for layer in c["regions"][0]["layers"].as_array().into_iter().flatten() {
        let dev = layer["max_deviation"].as_f64().unwrap_or(1.0);
        let cusp = layer["planar_cusp"].as_f64().unwrap_or(0.0);
        assert!(cusp >= 0.1 && dev < 0.05, "{layer}");
    }
    // Same bytes on one and two threads.
    let again = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .env("RAYON_NUM_THREADS", "1")
        .arg("slice")
        .arg(&model)
        .args(["--curved", "tops", "-o"])
        .arg(dir.path().join("one.gcode"))
        .output()
        .expect("the conduit binary runs");
    assert!(again.status.success());
    let one = std::fs::read_to_string(dir.path().join("one.gcode")).unwrap_or_default();
    assert!(one == run.gcode, "output differs between thread counts");
}

#[test]
fn curved_steep_roof_is_rejected_with_position_and_setting() {
    let dir = temp_dir();
    let model = dir.path().join("steep.stl");
    // 30° roof.
    write_stl(
        &model,
        &block_with_top(0.0, 0.0, 20.0, 20.0, 4, &|x, _| {
            2.0 + x * 30f64.to_radians().tan()
        }),
    );
    let run = slice(dir.path(), &model, "steep", &[]);
    let c = &run.report["curved"];
    assert_eq!(c["regions"].as_array().map(Vec::len), Some(0), "{c}");
    let r = &c["rejections"][0];
    assert_eq!(r["kind"], "too_steep", "{c}");
    assert!(r["position"].as_array().is_some_and(|p| p.len() == 3));
    assert!(
        r["setting"]
            .as_str()
            .is_some_and(|s| s.contains("curved.max_angle")),
        "{r}"
    );
    assert!(run.stderr.contains("kept planar"), "{}", run.stderr);
}

#[test]
fn curved_slope_beside_a_tall_wall_is_rejected_for_the_head() {
    let dir = temp_dir();
    let model = dir.path().join("wall.stl");
    // A roof falling from 10 mm to 5.5 mm towards a 20 mm wall 1 mm away: when the roof's
    // curved layers are printed the wall already stands 10 mm tall beside its low end.
    let mut tris = block_with_top(0.0, 0.0, 30.0, 20.0, 10, &|x, _| 10.0 - 0.15 * x);
    tris.extend(block_with_top(31.0, 0.0, 34.0, 20.0, 1, &|_, _| 20.0));
    write_stl(&model, &tris);
    let run = slice(dir.path(), &model, "wall", &[]);
    let c = &run.report["curved"];
    let hits: Vec<&Value> = c["rejections"]
        .as_array()
        .into_iter()
        .flatten()
        .filter(|r| r["kind"] == "head_collision")
        .collect();
    assert_eq!(hits.len(), 1, "{c}");
    assert!(
        hits[0]["reason"]
            .as_str()
            .is_some_and(|s| s.contains("cone")),
        "{}",
        hits[0]
    );
    assert!(
        hits[0]["setting"]
            .as_str()
            .is_some_and(|s| s.contains("curved.head_angle"))
    );
    // With a narrow head the same roof is curved.
    let run = slice(
        dir.path(),
        &model,
        "narrow",
        &["--set", "curved.head_angle=5"],
    );
    assert_eq!(
        run.report["curved"]["regions"].as_array().map(Vec::len),
        Some(1),
        "{}",
        run.report["curved"]
    );
}

#[test]
fn curved_corpus_wing_and_car_slice_and_check() {
    let Some(corpus) = corpus() else { return };
    let dir = temp_dir();
    for name in ["wing", "car_med"] {
        let model: PathBuf = corpus.join(format!("curved/curvislicer/{name}.stl"));
        let run = slice(dir.path(), &model, name, &[]);
        assert!(run.report["curved"].is_object(), "{name}");
    }
}
