//! Curved-layer FFF (`conduit slice --curved clfff`): the spherical-cap dish shell of
//! `samples/dish_shell.stl` sliced with scaffold, buffer and three curved layers at 0/45/90°
//! on three tools; the G-code re-parsed with conduit's own reader and compared with the
//! analytic sphere (every curved point at surface + k·h), the scaffold checked against the
//! surface minus its clearance, every extrusion replayed against the head model, and the
//! output accepted by `conduit check`.

use std::f64::consts::TAU;
use std::path::Path;
use std::process::Command;

use conduit::check::moves;
use conduit::config::Flavor;
use conduit::curved::clfff::{CORE_COMMENT, LAYER_COMMENT, SCAFFOLD_COMMENT, TOP_COMMENT};
use conduit::surface::ToolSolid;
use serde_json::Value;

use crate::support::{sample, stderr, stdout, temp_dir};

/// Sphere radius of the dish, mm.
const R: f64 = 60.0;
/// Rim radius (top-down), mm.
const RIM: f64 = 20.0;
/// Rings of the polar triangulation (1 mm apart).
const RINGS: usize = 20;
/// Shell thickness along z, mm: three 0.2 mm layers.
const THICKNESS: f64 = 0.6;

/// Height of the dish's bottom surface above its lowest point at distance `r` from its axis.
fn sag(r: f64) -> f64 {
    R - (R * R - r * r).sqrt()
}

/// The binary STL of `samples/dish_shell.stl`: a spherical-cap dish (sphere radius 60 mm,
/// rim radius 20 mm, 3.43 mm deep, 19.5° at the rim) as a closed shell 0.6 mm thick along z.
/// Both sheets are the same polar triangulation — a centre vertex and 20 rings 1 mm apart,
/// ring i with 6·i vertices — every vertex on the sphere (bottom) or 0.6 mm above it (top);
/// a wall of 120 quads closes the rim. Outward normals; 5040 triangles. Between its vertices
/// each triangle is a chord of the sphere, at most about 0.007 mm above it.
fn dish_shell_stl() -> Vec<u8> {
    polar_solid_stl(
        "conduit sample: spherical-cap dish shell (tests/clfff.rs)",
        RIM,
        RINGS,
        &|r| sag(r),
        &|r| sag(r) + THICKNESS,
    )
}

/// A closed solid over the disc of radius `rim` as a binary STL: the bottom sheet at
/// `bottom(r)`, the top sheet at `top(r)` (r the distance from the axis), both the same polar
/// triangulation — a centre vertex and `rings` rings, ring i with 6·i vertices — and a wall of
/// quads around the rim. Outward normals.
fn polar_solid_stl(
    header: &str,
    rim: f64,
    rings: usize,
    bottom: &dyn Fn(f64) -> f64,
    top_z: &dyn Fn(f64) -> f64,
) -> Vec<u8> {
    // Each vertex as (bottom point, top point).
    type Pair = ([f64; 3], [f64; 3]);
    let ring = |i: usize| -> Vec<Pair> {
        if i == 0 {
            return vec![([0.0, 0.0, bottom(0.0)], [0.0, 0.0, top_z(0.0)])];
        }
        let r = rim * i as f64 / rings as f64;
        let n = 6 * i;
        (0..n)
            .map(|j| {
                let a = TAU * j as f64 / n as f64;
                let (x, y) = (r * a.cos(), r * a.sin());
                ([x, y, bottom(r)], [x, y, top_z(r)])
            })
            .collect()
    };
    let mut sheet: Vec<[Pair; 3]> = Vec::new();
    for i in 0..rings {
        let (inner, outer) = (ring(i), ring(i + 1));
        let (ni, no) = (inner.len(), outer.len());
        let (mut a, mut b) = (0, 0);
        while a < ni || b < no {
            let next_b = (b + 1) as f64 / no as f64;
            let next_a = (a + 1) as f64 / ni as f64;
            if b < no && (a == ni || next_b <= next_a) {
                sheet.push([inner[a % ni], outer[b % no], outer[(b + 1) % no]]);
                b += 1;
            } else {
                if ni > 1 {
                    sheet.push([inner[a % ni], outer[b % no], inner[(a + 1) % ni]]);
                }
                a += 1;
            }
        }
    }
    let mut tris: Vec<[[f64; 3]; 3]> = Vec::new();
    for t in &sheet {
        tris.push([t[0].1, t[1].1, t[2].1]);
        tris.push([t[0].0, t[2].0, t[1].0]);
    }
    let edge = ring(rings);
    for j in 0..edge.len() {
        let (p0, p1) = (edge[j], edge[(j + 1) % edge.len()]);
        tris.push([p0.0, p1.0, p1.1]);
        tris.push([p0.0, p1.1, p0.1]);
    }
    let mut out = header.as_bytes().to_vec();
    out.resize(80, b' ');
    out.extend((tris.len() as u32).to_le_bytes());
    for t in &tris {
        let n = {
            let (u, v) = (
                [t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]],
                [t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]],
            );
            let c = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt().max(1e-30);
            [c[0] / l, c[1] / l, c[2] / l]
        };
        for c in n {
            out.extend((c as f32).to_le_bytes());
        }
        for p in t {
            for c in p {
                out.extend((*c as f32).to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    out
}

#[test]
fn clfff_sample_dish_matches_its_generator() {
    let path = sample("dish_shell.stl");
    if std::env::var_os("CONDUIT_WRITE_SAMPLES").is_some() {
        std::fs::write(&path, dish_shell_stl()).expect("the sample is written");
    }
    let committed = std::fs::read(&path).expect("samples/dish_shell.stl exists");
    assert!(
        committed == dish_shell_stl(),
        "samples/dish_shell.stl differs from dish_shell_stl() in tests/clfff.rs; regenerate it \
         with CONDUIT_WRITE_SAMPLES=1 cargo test --release --test tests clfff_sample"
    );
    assert_eq!(committed.len(), 84 + 50 * 5040);
}

/// Three filament tools: PLA scaffold (0), TPE buffer (1), model (2).
const THREE_TOOLS: &str = r#"
[tools.0]
name = "PLA"
[tools.1]
name = "TPE"
temperature = 230.0
first_layer_temperature = 230.0
[tools.2]
name = "PETG"
temperature = 240.0
first_layer_temperature = 240.0
[slice]
object_tools = [2]
[curved]
mode = "clfff"
buffer = true
scaffold_tool = 0
buffer_tool = 1
layers = 3
angles = [0.0, 45.0, 90.0]
"#;

struct Run {
    files: Vec<(String, String)>,
    report: Value,
    stderr: String,
}

fn run(dir: &Path, name: &str, extra: &[&str]) -> Run {
    let cfg = dir.join("three_tools.toml");
    std::fs::write(&cfg, THREE_TOOLS).expect("config written");
    let out = dir.join(format!("{name}.gcode"));
    let rep = dir.join(format!("{name}.json"));
    let o = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .arg("slice")
        .arg(sample("dish_shell.stl"))
        .arg("-c")
        .arg(&cfg)
        .args(["--curved", "clfff", "-o"])
        .arg(&out)
        .arg("--report")
        .arg(&rep)
        .args(extra)
        .output()
        .expect("the conduit binary runs");
    assert!(o.status.success(), "slice failed: {}", stderr(&o));
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&rep).expect("report written"))
            .expect("report is JSON");
    let mut files = Vec::new();
    let names: Vec<String> = if extra.contains(&"--split-sections") {
        ["scaffold", "buffer", "model"]
            .iter()
            .map(|s| format!("{name}.{s}.gcode"))
            .collect()
    } else {
        vec![format!("{name}.gcode")]
    };
    for f in names {
        let path = dir.join(&f);
        let check = Command::new(env!("CARGO_BIN_EXE_conduit"))
            .arg("check")
            .arg(&path)
            .arg("-c")
            .arg(&cfg)
            .output()
            .expect("the conduit binary runs");
        assert!(
            check.status.success(),
            "check rejects {f}: {}",
            stdout(&check)
        );
        files.push((
            f,
            std::fs::read_to_string(&path).expect("G-code is written"),
        ));
    }
    Run {
        files,
        report,
        stderr: stderr(&o),
    }
}

/// What an extruding move belongs to: a scaffold layer or a curved layer (section, k).
#[derive(Debug, Clone, PartialEq)]
enum Part {
    Scaffold,
    Curved(String, usize),
}

/// Every extruding move of `gcode` (replayed by conduit's G-code reader) with its part.
fn extrusions(gcode: &str) -> Vec<(Part, [f64; 3], [f64; 3])> {
    let parsed = conduit_gcode::parse(gcode.as_bytes()).expect("the G-code parses");
    let m = moves(&parsed, Flavor::Marlin);
    let lines: Vec<&str> = gcode.lines().collect();
    // The part of each line, from the comments before it.
    let mut part_of_line = Vec::with_capacity(lines.len());
    let mut part = None;
    for l in &lines {
        if let Some(rest) = l.strip_prefix(&format!("; {LAYER_COMMENT} ")) {
            let w: Vec<&str> = rest.split_whitespace().collect();
            let k = w
                .get(2)
                .and_then(|k| k.parse().ok())
                .expect("k in the comment");
            part = Some(Part::Curved(w[0].to_owned(), k));
        } else if l.starts_with(&format!("; {SCAFFOLD_COMMENT} ")) {
            part = Some(Part::Scaffold);
        }
        part_of_line.push(part.clone());
    }
    // Extrusions before the first layer comment belong to the start G-code (a prime line).
    m.moves
        .iter()
        .filter(|mv| mv.extruding)
        .filter_map(|mv| {
            let p = |q: [Option<f64>; 3]| q.map(|c| c.expect("known position"));
            let part = part_of_line[mv.line - 1].clone()?;
            Some((part, p(mv.from), p(mv.to)))
        })
        .collect()
}

/// The analytic bottom surface of the placed dish: centred on the 250 mm bed, lowest point at
/// `curved.raise` (2) plus one buffer layer (0.2).
fn surface(x: f64, y: f64) -> Option<f64> {
    let r = (x - 125.0).hypot(y - 125.0);
    (r <= RIM).then(|| 2.2 + sag(r))
}

#[test]
fn clfff_dish_with_scaffold_buffer_and_three_layers() {
    let dir = temp_dir();
    let run = run(dir.path(), "dish", &[]);
    assert_eq!(run.files.len(), 1);
    let gcode = &run.files[0].1;
    let ex = extrusions(gcode);
    let h = 0.2;
    let clearance = 0.2;

    // Every curved point at surface + k·h (the buffer is k = 0) within 0.01 mm.
    let mut per_k = [0usize; 4];
    let mut worst: f64 = 0.0;
    for (part, _, to) in &ex {
        if let Part::Curved(section, k) = part {
            let s = surface(to[0], to[1]).unwrap_or_else(|| panic!("{to:?} outside the dish"));
            let want = s + *k as f64 * h;
            worst = worst.max((to[2] - want).abs());
            per_k[*k] += 1;
            assert_eq!(section == "buffer", *k == 0, "{section} {k}");
        }
    }
    assert!(worst < 0.01, "worst {worst}");
    assert!(per_k.iter().all(|&n| n > 1000), "{per_k:?}");

    // No scaffold point above the surface minus buffer and clearance; outside the dish, below
    // its rim. The slicer follows the mesh, whose triangles are chords up to 0.007 mm above the
    // sphere: the same 0.01 mm tolerance as for the curved points.
    let rim = 2.2 + sag(RIM);
    let mut scaffold = 0;
    for (part, from, to) in &ex {
        if *part != Part::Scaffold {
            continue;
        }
        scaffold += 1;
        for p in [from, to] {
            let limit = surface(p[0], p[1]).unwrap_or(rim) - h - clearance;
            assert!(p[2] <= limit + 0.01, "scaffold at {p:?} above {limit}");
        }
    }
    assert!(scaffold > 500, "{scaffold} scaffold moves");

    // The head (cone 60°, 5 mm) never touches what was printed before the nozzle got there.
    let head = ToolSolid::fff_head(60.0, 5.0, 0.0, 10.0);
    assert_eq!(replay_hits(&ex, &head, usize::MAX), 0);
    // A much wider head would: the replay does find collisions.
    let wide = ToolSolid::fff_head(80.0, 5.0, 0.0, 10.0);
    assert!(replay_hits(&ex, &wide, 1) > 0);

    // Tools: scaffold T0, buffer T1, model T2, in that order.
    let tools: Vec<&str> = gcode
        .lines()
        .filter(|l| matches!(*l, "T0" | "T1" | "T2"))
        .collect();
    assert_eq!(tools, ["T0", "T1", "T2"], "{tools:?}");

    // The report: layers, deviation, cusp, collisions.
    let c = &run.report["clfff"];
    let layers = c["layers"].as_array().expect("layers");
    assert_eq!(layers.len(), 4, "{c}");
    let angles: Vec<f64> = layers
        .iter()
        .skip(1)
        .filter_map(|l| l["angle_deg"].as_f64())
        .collect();
    assert_eq!(angles, [0.0, 45.0, 90.0]);
    for l in layers {
        let dev = l["max_deviation"].as_f64().unwrap_or(1.0);
        let cusp = l["planar_cusp"].as_f64().unwrap_or(0.0);
        // Slope at most 19.5° (asin(20/60)): the planar cusp is at least 0.2·cos 19.5°.
        assert!(dev < 1e-6 && cusp > 0.188 && cusp < 0.2, "{l}");
    }
    assert_eq!(c["collisions"]["count"], 0, "{c}");
    assert!(
        c["scaffold"]["layers"].as_u64().is_some_and(|n| n > 10),
        "{c}"
    );
    assert!(run.stderr.contains("3 curved layers"), "{}", run.stderr);

    // Same bytes again, on one thread.
    let again = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .env("RAYON_NUM_THREADS", "1")
        .arg("slice")
        .arg(sample("dish_shell.stl"))
        .arg("-c")
        .arg(dir.path().join("three_tools.toml"))
        .arg("-o")
        .arg(dir.path().join("again.gcode"))
        .output()
        .expect("the conduit binary runs");
    assert!(again.status.success(), "{}", stderr(&again));
    let bytes = std::fs::read_to_string(dir.path().join("again.gcode")).unwrap_or_default();
    assert!(bytes == *gcode, "output differs between runs");
}

/// The G-code's coordinate resolution (3 decimals) with a margin for binary rounding, mm.
const GCODE_RESOLUTION: f64 = 0.0011;

/// Collisions in a replay of the extrusions (stopping after `limit` of them): material is the
/// points of earlier extrusions (their ends and points every 0.5 mm), kept per 0.5 mm cell of
/// the bed as the highest point; each extrusion is tested at its points before it is added.
/// Material at most [`GCODE_RESOLUTION`] above the tip is not above it: two points of a
/// surface a hair apart can round to different z in the file.
fn replay_hits(ex: &[(Part, [f64; 3], [f64; 3])], head: &ToolSolid, limit: usize) -> usize {
    const CELL: f64 = 0.5;
    const N: usize = 500; // 250 mm bed
    let key = |v: f64| ((v / CELL).floor().max(0.0) as usize).min(N - 1);
    let mut cells: Vec<Option<[f64; 3]>> = vec![None; N * N];
    let mut top = f64::MIN;
    let reach = (head.widest() / CELL).ceil() as usize + 1;
    let mut hits = 0;
    for (_, from, to) in ex {
        let len = (to[0] - from[0]).hypot(to[1] - from[1]);
        let n = (len / CELL).ceil().max(1.0) as usize;
        let pts: Vec<[f64; 3]> = (0..=n)
            .map(|i| {
                let t = i as f64 / n as f64;
                [0, 1, 2].map(|c| from[c] + (to[c] - from[c]) * t)
            })
            .collect();
        let hit = pts.iter().any(|p| {
            if p[2] >= top {
                return false;
            }
            let (kx, ky) = (key(p[0]), key(p[1]));
            let xs = kx.saturating_sub(reach)..=(kx + reach).min(N - 1);
            xs.into_iter().any(|cx| {
                let ys = ky.saturating_sub(reach)..=(ky + reach).min(N - 1);
                ys.into_iter().any(|cy| {
                    cells[cy * N + cx].is_some_and(|q| {
                        q[2] - p[2] > GCODE_RESOLUTION
                            && head
                                .radius_at(q[2] - p[2])
                                .is_some_and(|(r, _)| (q[0] - p[0]).hypot(q[1] - p[1]) < r)
                    })
                })
            })
        });
        if hit {
            hits += 1;
            if hits >= limit {
                return hits;
            }
        }
        for p in pts {
            let slot = &mut cells[key(p[1]) * N + key(p[0])];
            if slot.is_none_or(|q| p[2] > q[2]) {
                *slot = Some(p);
            }
            top = top.max(p[2]);
        }
    }
    hits
}

#[test]
fn clfff_split_sections_write_three_checked_files() {
    let dir = temp_dir();
    let run = run(dir.path(), "split", &["--split-sections"]);
    assert_eq!(run.files.len(), 3);
    for (name, gcode) in &run.files {
        let ex = extrusions(gcode);
        assert!(!ex.is_empty(), "{name}");
        let want = if name.ends_with(".scaffold.gcode") {
            Part::Scaffold
        } else if name.ends_with(".buffer.gcode") {
            Part::Curved("buffer".to_owned(), 0)
        } else {
            Part::Curved("model".to_owned(), 1)
        };
        assert_eq!(ex[0].0, want, "{name}");
        // One material per file: no tool change after the start.
        let changes = gcode.lines().filter(|l| l.starts_with('T')).count();
        assert!(changes <= 1, "{name}: {changes} tool selections");
    }
    let files: Vec<&str> = run.report["clfff"]["sections"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|s| s["file"].as_str())
        .collect();
    assert_eq!(files.len(), 3);
}

/// Rim radius of the thick dish (top-down), mm.
const THICK_RIM: f64 = 15.0;
/// Rings of the thick dish's polar triangulation (1 mm apart).
const THICK_RINGS: usize = 15;
/// Sphere radius of the thick dish's bottom surface, mm.
const RB: f64 = 50.0;
/// Sphere radius of the thick dish's top surface, mm.
const RT: f64 = 80.0;
/// Thickness of the thick dish on its axis, mm.
const HT: f64 = 6.0;

/// The thick dish's bottom surface above its lowest point at distance `r` from the axis.
fn thick_bottom(r: f64) -> f64 {
    RB - (RB * RB - r * r).sqrt()
}

/// The thick dish's top surface above the bottom's lowest point.
fn thick_top(r: f64) -> f64 {
    HT + RT - (RT * RT - r * r).sqrt()
}

/// The binary STL of `samples/thick_dish.stl`: a solid dish 15 mm in rim radius between two
/// spherical caps, the bottom of radius 50 mm (2.30 mm deep, 17.5° at the rim), the top of
/// radius 80 mm 6 mm above it on the axis (10.8° at the rim, 5.12 mm thick there); the polar
/// triangulation of [`polar_solid_stl`] with 15 rings 1 mm apart, 2880 triangles.
fn thick_dish_stl() -> Vec<u8> {
    polar_solid_stl(
        "conduit sample: thick two-cap dish (tests/clfff.rs)",
        THICK_RIM,
        THICK_RINGS,
        &thick_bottom,
        &thick_top,
    )
}

#[test]
fn clfff_sample_thick_dish_matches_its_generator() {
    let path = sample("thick_dish.stl");
    if std::env::var_os("CONDUIT_WRITE_SAMPLES").is_some() {
        std::fs::write(&path, thick_dish_stl()).expect("the sample is written");
    }
    let committed = std::fs::read(&path).expect("samples/thick_dish.stl exists");
    assert!(
        committed == thick_dish_stl(),
        "samples/thick_dish.stl differs from thick_dish_stl() in tests/clfff.rs; regenerate \
         it with CONDUIT_WRITE_SAMPLES=1 cargo test --release --test tests clfff_sample"
    );
    assert_eq!(committed.len(), 84 + 50 * 2880);
}

/// A sandwich of three bottom and three top skin layers, one tool, no buffer.
const SANDWICH: &str = r#"
[curved]
mode = "clfff"
sandwich = true
layers = 3
top_layers = 3
angles = [0.0, 90.0]
"#;

/// What an extruding move of a sandwich belongs to.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Layer {
    Scaffold,
    Bottom(usize),
    Core(f64),
    Top(usize),
}

/// An extruding move of a sandwich: (layer, from, to, E, width).
type SandwichMove = (Layer, [f64; 3], [f64; 3], f64, f64);

/// Every extruding move of a sandwich's G-code with its layer.
fn sandwich_moves(gcode: &str) -> Vec<SandwichMove> {
    let parsed = conduit_gcode::parse(gcode.as_bytes()).expect("the G-code parses");
    let m = moves(&parsed, Flavor::Marlin);
    let word = |rest: &str, i: usize| -> f64 {
        rest.split_whitespace()
            .nth(i)
            .and_then(|w| w.parse().ok())
            .expect("a number in the comment")
    };
    let mut layer_of_line = Vec::new();
    let mut layer = None;
    for l in gcode.lines() {
        if let Some(rest) = l.strip_prefix(&format!("; {LAYER_COMMENT} ")) {
            layer = Some(Layer::Bottom(word(rest, 2) as usize));
        } else if let Some(rest) = l.strip_prefix(&format!("; {TOP_COMMENT} ")) {
            layer = Some(Layer::Top(word(rest, 2) as usize));
        } else if let Some(rest) = l.strip_prefix(&format!("; {CORE_COMMENT} ")) {
            layer = Some(Layer::Core(word(rest, 1)));
        } else if l.starts_with(&format!("; {SCAFFOLD_COMMENT} ")) {
            layer = Some(Layer::Scaffold);
        }
        layer_of_line.push(layer);
    }
    m.moves
        .iter()
        .filter(|mv| mv.extruding)
        .filter_map(|mv| {
            let p = |q: [Option<f64>; 3]| q.map(|c| c.expect("known position"));
            let layer = layer_of_line[mv.line - 1]?;
            Some((layer, p(mv.from), p(mv.to), mv.e, mv.width.unwrap_or(0.0)))
        })
        .collect()
}

#[test]
fn clfff_sandwich_of_a_thick_dish_has_skins_on_its_surfaces_and_a_planar_core_between() {
    let dir = temp_dir();
    let cfg = dir.path().join("sandwich.toml");
    std::fs::write(&cfg, SANDWICH).expect("config written");
    let out = dir.path().join("sandwich.gcode");
    let rep = dir.path().join("sandwich.json");
    let o = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .arg("slice")
        .arg(sample("thick_dish.stl"))
        .arg("-c")
        .arg(&cfg)
        .arg("-o")
        .arg(&out)
        .arg("--report")
        .arg(&rep)
        .output()
        .expect("the conduit binary runs");
    assert!(o.status.success(), "slice failed: {}", stderr(&o));
    let check = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .arg("check")
        .arg(&out)
        .output()
        .expect("the conduit binary runs");
    assert!(check.status.success(), "check rejects: {}", stdout(&check));
    let gcode = std::fs::read_to_string(&out).expect("G-code written");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&rep).expect("report written"))
            .expect("report is JSON");

    let defaults = conduit::config::Config::default();
    let h = defaults.slice.layer_height;
    let first_top = defaults.slice.first_layer_height;
    let filament = defaults.tools[0].filament_diameter;
    let (nb, nt) = (3usize, 3usize);
    // Placed: centred on the 250 mm bed, lowest point at curved.raise (2 mm).
    let r_of = |p: &[f64; 3]| (p[0] - 125.0).hypot(p[1] - 125.0);
    let bottom = |p: &[f64; 3]| 2.0 + thick_bottom(r_of(p).min(THICK_RIM));
    let top = |p: &[f64; 3]| 2.0 + thick_top(r_of(p).min(THICK_RIM));
    let grid = |z: f64| ((z - first_top) / h).round();
    // The top of the core under a point: the highest grid layer at or below T − n_t·h.
    let core_top =
        |p: &[f64; 3]| first_top + ((top(p) - nt as f64 * h - first_top) / h).floor() * h;

    let ex = sandwich_moves(&gcode);
    let mut count = [0usize; 3];
    let mut worst = [0.0f64; 2];
    let mut core_levels = std::collections::BTreeSet::new();
    let mut flow_checked = 0;
    let mut worst_flow: f64 = 0.0;
    for (layer, from, to, e, width) in &ex {
        for p in [from, to] {
            assert!(
                r_of(p) <= THICK_RIM + 0.01 || *layer == Layer::Scaffold,
                "{p:?}"
            );
        }
        match *layer {
            Layer::Bottom(k) => {
                count[0] += 1;
                let want = bottom(to) + k as f64 * h;
                worst[0] = worst[0].max((to[2] - want).abs());
                assert!((1..=nb).contains(&k));
            }
            Layer::Top(j) => {
                count[2] += 1;
                let want = top(to) - (nt - 1 - j) as f64 * h;
                worst[1] = worst[1].max((to[2] - want).abs());
                // The lowest top layer reaches down to the core's top: E follows that
                // thickness (rounded to 0.01 mm), away from the core's steps.
                let len = (0..3)
                    .map(|c| (to[c] - from[c]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let mid = [0, 1, 2].map(|c| (from[c] + to[c]) / 2.0);
                let tops = [from, to, &mid].map(core_top);
                let near_step = [from, to, &mid].iter().any(|p| {
                    let u = (top(p) - nt as f64 * h - first_top) / h;
                    (u - u.round()).abs() * h < 0.01
                });
                if j == 0
                    && len > 0.3
                    && tops.iter().all(|t| (t - tops[0]).abs() < 1e-9)
                    && !near_step
                {
                    let want_t = mid[2] - tops[0];
                    // E = ((w − t)·t + π t²/4)·len / (π d²/4), solved for t.
                    let area = e * std::f64::consts::PI * filament * filament / 4.0 / len;
                    let c = 1.0 - std::f64::consts::PI / 4.0;
                    let t = (width - (width * width - 4.0 * c * area).sqrt()) / (2.0 * c);
                    worst_flow = worst_flow.max((t - want_t).abs());
                    assert!(want_t >= h - 0.01 && want_t < 2.0 * h + 0.01, "{want_t}");
                    flow_checked += 1;
                }
            }
            Layer::Core(z) => {
                count[1] += 1;
                core_levels.insert(grid(z) as i64);
                for p in [from, to] {
                    // Planar, on the grid, wholly between the skins.
                    assert!(
                        (p[2] - z).abs() < 1e-6,
                        "core point {p:?} off its layer {z}"
                    );
                    assert!(((z - first_top) / h - grid(z)).abs() < 1e-6, "{z}");
                    let skin = bottom(p) + nb as f64 * h;
                    assert!(
                        z - h >= skin - 0.01,
                        "core {p:?} below the bottom skin's top {skin}"
                    );
                    let under = top(p) - nt as f64 * h;
                    assert!(
                        z <= under + 0.01,
                        "core {p:?} above the top skin's bottom {under}"
                    );
                }
            }
            Layer::Scaffold => {}
        }
    }
    assert!(worst[0] < 0.01 && worst[1] < 0.01, "worst {worst:?}");
    assert!(count.iter().all(|&n| n > 1000), "{count:?}");
    // The lowest core layer: the first grid layer with z − h above the bottom skin's top at
    // the centre, 2 + 3·h (strictly: at equality it touches one point).
    let want_lo = (((2.0 + (nb + 1) as f64 * h - first_top) / h) + 1e-6).floor() as i64 + 1;
    // The highest: z ≤ T − n_t·h somewhere, i.e. at the rim; its ring r ≥ r(z) is printed
    // when it is wide enough for beads (two widths certainly are).
    let i_hi = ((2.0 + thick_top(THICK_RIM) - nt as f64 * h - first_top) / h + 1e-6).floor() as i64;
    let ring_width = |i: i64| {
        let v = first_top + i as f64 * h + nt as f64 * h - 2.0;
        THICK_RIM - (RT * RT - (RT - v + HT).powi(2)).max(0.0).sqrt()
    };
    let wide = (want_lo..=i_hi)
        .rev()
        .find(|&i| ring_width(i) >= 2.0 * 0.45)
        .expect("a wide core layer");
    let (lo, hi) = (
        core_levels.first().copied().unwrap_or(0),
        core_levels.last().copied().unwrap_or(0),
    );
    assert_eq!(lo, want_lo, "{core_levels:?}");
    assert!(hi >= wide && hi <= i_hi, "{hi} not in {wide}..={i_hi}");
    assert_eq!(core_levels.len() as i64, hi - lo + 1, "{core_levels:?}");
    assert!(
        flow_checked > 200 && worst_flow < 0.012,
        "{flow_checked} {worst_flow}"
    );

    // The head (cone 60°, 5 mm) never touches what was printed before.
    let head = ToolSolid::fff_head(60.0, 5.0, 0.0, 10.0);
    let parts: Vec<(Part, [f64; 3], [f64; 3])> = ex
        .iter()
        .map(|(_, f, t, ..)| (Part::Scaffold, *f, *t))
        .collect();
    assert_eq!(replay_hits(&parts, &head, usize::MAX), 0);

    let c = &report["clfff"];
    assert_eq!(c["collisions"]["count"], 0, "{c}");
    assert_eq!(
        c["core"]["layers"].as_i64(),
        Some(hi - lo + 1),
        "{}",
        c["core"]
    );
    let follows: Vec<&str> = c["layers"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|l| l["follows"].as_str())
        .collect();
    assert_eq!(follows, ["bottom", "bottom", "bottom", "top", "top", "top"]);
    for l in c["layers"].as_array().into_iter().flatten() {
        assert!(l["max_deviation"].as_f64().is_some_and(|d| d < 1e-6), "{l}");
    }
}

#[test]
fn a_solid_given_to_plain_curved_layers_is_refused_not_printed_as_a_plate() {
    let dir = temp_dir();
    let out = dir.path().join("cube.gcode");
    let o = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .args(["slice", "--curved", "clfff", "-o"])
        .arg(&out)
        .arg(sample("cube_20mm.stl"))
        .output()
        .expect("the conduit binary runs");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("20.00 mm thick") && err.contains("curved.layers = 3 prints 0.60 mm"),
        "{err}"
    );
    assert!(
        !out.exists(),
        "no G-code for a job that would leave the model out"
    );
}
