//! Curved top surfaces (`conduit slice --curved tops`): generated blocks with a gentle roof are
//! sliced, the G-code re-parsed and every point of the curved layers compared with the mesh's
//! surface; steep and colliding tops are rejected with a reported position; the corpus wing and
//! car slice and pass `conduit check`.

use std::path::{Path, PathBuf};
use std::process::Command;

use conduit::config::Config;
use conduit::curved::LAYER_COMMENT;
use conduit::curved::collision::{Bead, ReplayHit, ReplayTolerances, replay};
use conduit::geom::Point3;
use conduit::pipeline::place_on_bed;
use conduit::scene::{LoadOptions, load_scene};
use conduit::surface::HeightField;
use conduit_gcode::{Firmware, Machine};
use serde_json::Value;

use crate::support::{corpus, stderr, temp_dir, xyz};

type Tri = [[f64; 3]; 3];

/// A closed block over `[x0, x1] × [y0, y1]`, bottom at z = 0, top z = f(x, y) triangulated on
/// an `n × n` grid (walls split to match, so every edge is shared by two triangles).
pub(crate) fn block_with_top(
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

pub(crate) fn write_stl(path: &Path, tris: &[Tri]) {
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

/// Steps the modal machine (Marlin) over `gcode`: `each` gets every line's text and, when the
/// line moves, its start, end and E change.
fn replay_lines(gcode: &str, mut each: impl FnMut(&str, Option<([f64; 3], [f64; 3], f64)>)) {
    let g = conduit_gcode::parse(gcode.as_bytes()).expect("G-code parses");
    let mut machine = Machine::new(Firmware::Marlin, 25.0);
    for line in &g.lines {
        let mv = machine.step(line).map(|m| (xyz(m.from), xyz(m.to), m.e));
        each(&String::from_utf8_lossy(&line.text), mv);
    }
}

/// Whether a move changes X or Y.
fn moves_xy(from: [f64; 3], to: [f64; 3]) -> bool {
    from[0] != to[0] || from[1] != to[1]
}

/// The end points of every extruding move inside the curved blocks, with their block's depth.
fn curved_points(gcode: &str) -> Vec<([f64; 3], f64)> {
    let mut depth: Option<f64> = None;
    let mut out = Vec::new();
    replay_lines(gcode, |line, mv| {
        if let Some(rest) = line.strip_prefix(&format!("; {LAYER_COMMENT} layer ")) {
            depth = rest.split_whitespace().nth(2).and_then(|d| d.parse().ok());
        } else if line.starts_with(";LAYER_CHANGE") {
            depth = None;
        }
        if let (Some((_, to, de)), Some(d)) = (mv, depth) {
            if de > 0.0 {
                out.push((to, d));
            }
        }
    });
    out
}

/// Every extruding move of `gcode` as a bead (nozzle path, `;WIDTH:`/`;HEIGHT:` in effect),
/// and the index of the first bead of the first curved layer.
fn beads(gcode: &str) -> (Vec<Bead>, Option<usize>) {
    let (mut width, mut height) = (0.45, 0.2);
    let mut out = Vec::new();
    let mut first_curved = None;
    // Beads of curved layers lie on the surface, no steeper than curved.max_angle.
    let mut lean_deg = 0.0;
    let max_angle = Config::default().curved.max_angle;
    replay_lines(gcode, |line, mv| {
        if line.starts_with(&format!("; {LAYER_COMMENT} layer ")) {
            first_curved.get_or_insert(out.len());
            lean_deg = max_angle;
        }
        if line.starts_with(";LAYER_CHANGE") {
            lean_deg = 0.0;
        }
        if let Some(v) = line.strip_prefix(";WIDTH:") {
            width = v.trim().parse().unwrap_or(width);
        }
        if let Some(v) = line.strip_prefix(";HEIGHT:") {
            height = v.trim().parse().unwrap_or(height);
        }
        if let Some((from, to, de)) = mv {
            if de > 0.0 && moves_xy(from, to) {
                out.push(Bead {
                    from: Point3::new(from[0], from[1], from[2]),
                    to: Point3::new(to[0], to[1], to[2]),
                    width,
                    height,
                    lean_deg,
                });
            }
        }
    });
    (out, first_curved)
}

/// Replays every extrusion from the first curved layer on against the default head and all
/// material printed before it: the hits and the number of beads replayed.
fn head_hits(name: &str, gcode: &str) -> (Vec<ReplayHit>, Vec<Bead>, usize) {
    let (beads, first) = beads(gcode);
    let Some(first) = first else {
        panic!("{name}: no curved layer")
    };
    let head = Config::default().curved.head();
    let hits = replay(&beads, first, &head, &ReplayTolerances::default());
    (hits, beads, first)
}

/// [`head_hits`] finds nothing; returns the number of beads replayed.
fn assert_no_head_hits(name: &str, gcode: &str) -> usize {
    let (hits, beads, first) = head_hits(name, gcode);
    assert!(
        hits.is_empty(),
        "{name}: {} of {} beads hit, first {:?} against {:?}",
        hits.len(),
        beads.len() - first,
        hits[0],
        beads[hits[0].earlier]
    );
    beads.len() - first
}

/// The placed mesh's height field (the slice centres the footprint on the bed).
fn placed_surface(model: &Path) -> HeightField {
    let (scene, _) = load_scene(model, &LoadOptions::default()).expect("the model loads");
    let meshes = place_on_bed(&scene, &Config::default());
    HeightField::from_mesh(&meshes[0])
}

pub(crate) fn dome(x: f64, y: f64) -> f64 {
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
    assert_no_head_hits("dome", &run.gcode);
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
fn curved_slope_beside_a_tall_wall_is_trimmed_where_the_head_would_hit() {
    let dir = temp_dir();
    let model = dir.path().join("wall.stl");
    // A roof falling from 10 mm to 5.5 mm towards a 20 mm wall 1 mm away: when the roof's
    // curved layers are printed the wall stands as tall as the roof's top planar layer
    // (z = 9.8 over the slicing plane 9.7) beside its low end.
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
    assert!(!hits.is_empty(), "{c}");
    for hit in &hits {
        assert!(
            hit["reason"]
                .as_str()
                .is_some_and(|s| s.contains("cone") && s.contains("rim")),
            "{hit}"
        );
        assert!(
            hit["setting"]
                .as_str()
                .is_some_and(|s| s.contains("curved.head_angle")),
            "{hit}"
        );
        // Reported at the roof's low end, beside the wall.
        let x = hit["position"][0].as_f64().unwrap_or(0.0) - bed_offset(&model)[0];
        assert!(x > 20.0 && x < 30.0, "{hit}");
    }
    // The rest of the roof is curved. The cone (60°) with its tip at the top layer,
    // z = 10 − 0.15·x, meets the wall's top (x = 31, z = 9.8) where 31 − x = tan 60°·(9.8 − z),
    // i.e. x = 24.87: nothing curved may lie beyond.
    let region = &c["regions"][0];
    let (area, curved) = (
        region["area_mm2"].as_f64().unwrap_or(0.0),
        region["curved_area_mm2"].as_f64().unwrap_or(0.0),
    );
    assert!((area - 600.0).abs() < 1.0, "{region}");
    assert!(
        curved > 0.6 * area && curved < area - 20.0 * 5.0,
        "{region}"
    );
    let off = bed_offset(&model);
    let max_x = curved_segments(&run.gcode)
        .iter()
        .flat_map(|(a, b, _)| [a[0], b[0]])
        .fold(f64::MIN, f64::max)
        - off[0];
    let limit = 31.0 - 60f64.to_radians().tan() * (9.8 - (10.0 - 0.15 * 24.87));
    assert!(max_x > 20.0 && max_x < limit + 1e-6, "{max_x} vs {limit}");
    assert_no_head_hits("wall", &run.gcode);
    // With a narrow head the whole roof is curved.
    let run = slice(
        dir.path(),
        &model,
        "narrow",
        &["--set", "curved.head_angle=5"],
    );
    let region = &run.report["curved"]["regions"][0];
    let curved = region["curved_area_mm2"].as_f64().unwrap_or(0.0);
    assert!((curved - 600.0).abs() < 1.0, "{}", run.report["curved"]);
    // ... and the replay with the real (60°) head finds it running into the wall.
    let (hits, beads, _) = head_hits("narrow", &run.gcode);
    assert!(!hits.is_empty());
    for h in &hits {
        let wall = &beads[h.earlier];
        assert!(wall.from.x - off[0] > 30.5 && h.hit.rise() > 0.2, "{h:?}");
    }
}

/// Where the slice moved the model: placed minus original xy of the first vertex.
fn bed_offset(model: &Path) -> [f64; 2] {
    let (scene, _) = load_scene(model, &LoadOptions::default()).expect("the model loads");
    let placed = place_on_bed(&scene, &Config::default());
    let (a, b) = (scene.objects[0].mesh.vertices[0], placed[0].vertices[0]);
    [b.x - a.x, b.y - a.y]
}

/// Every extruding move inside the curved blocks as (start, end, depth of its block).
pub(crate) fn curved_segments(gcode: &str) -> Vec<([f64; 3], [f64; 3], f64)> {
    let mut out = Vec::new();
    let mut depth: Option<f64> = None;
    let (beads, _) = beads(gcode);
    // Pair each bead with the block it is in by replaying the comments in step.
    let mut it = beads.iter();
    replay_lines(gcode, |line, mv| {
        if let Some(rest) = line.strip_prefix(&format!("; {LAYER_COMMENT} layer ")) {
            depth = rest.split_whitespace().nth(2).and_then(|d| d.parse().ok());
        } else if line.starts_with(";LAYER_CHANGE") {
            depth = None;
        }
        if let Some((from, to, de)) = mv {
            if de > 0.0 && moves_xy(from, to) {
                let b = it.next();
                assert!(b.is_some_and(|b| b.to.x == to[0] && b.to.y == to[1]));
                if let Some(d) = depth {
                    out.push((from, to, d));
                }
            }
        }
    });
    out
}

/// Largest error of the curved points (segment ends) and of the segments' midpoints from
/// surface − depth, with the number of segments, for segments whose `depth` passes `keep`.
fn surface_errors(hf: &HeightField, gcode: &str, keep: impl Fn(f64) -> bool) -> (usize, f64, f64) {
    let (mut n, mut worst_point, mut worst_mid) = (0, 0.0f64, 0.0f64);
    for (a, b, depth) in curved_segments(gcode) {
        if !keep(depth) {
            continue;
        }
        n += 1;
        let off = |p: [f64; 3]| match hf.at(p[0], p[1]) {
            Some(s) => (p[2] - (s.z - depth)).abs(),
            None => panic!("no surface under {p:?}"),
        };
        worst_point = worst_point.max(off(a)).max(off(b));
        let mid = [
            (a[0] + b[0]) / 2.0,
            (a[1] + b[1]) / 2.0,
            (a[2] + b[2]) / 2.0,
        ];
        worst_mid = worst_mid.max(off(mid));
    }
    (n, worst_point, worst_mid)
}

#[test]
fn curved_corpus_wing_and_car_print_curved_tops_on_the_surface_without_head_hits() {
    let Some(corpus) = corpus() else { return };
    let dir = temp_dir();
    // The gently sloped top of the wing is curved whole; on the car the rims beside steeper
    // panels are trimmed (and reported) where the head would hit.
    for (name, min_share) in [("wing", 0.95), ("car_med", 0.6)] {
        let model: PathBuf = corpus.join(format!("curved/curvislicer/{name}.stl"));
        let run = slice(dir.path(), &model, name, &[]);
        let c = &run.report["curved"];
        let regions = c["regions"].as_array().cloned().unwrap_or_default();
        assert!(!regions.is_empty(), "{name}: {c}");
        let sum = |key: &str| -> f64 { regions.iter().filter_map(|r| r[key].as_f64()).sum() };
        let (gentle, curved) = (sum("area_mm2"), sum("curved_area_mm2"));
        assert!(
            curved >= min_share * gentle && curved > 100.0,
            "{name}: {curved} of {gentle} mm² curved"
        );
        for r in c["rejections"].as_array().into_iter().flatten() {
            let pos = r["position"].as_array().map(Vec::len);
            let reason = r["reason"].as_str().unwrap_or("");
            assert!(pos == Some(3) && !reason.is_empty(), "{r}");
        }
        // Every curved point on surface − k·h; the top layer's segments within 0.05 mm of the
        // mesh, where the planar print's cusp at this layer height is ≥ 0.1 mm.
        let hf = placed_surface(&model);
        let (n, worst_point, _) = surface_errors(&hf, &run.gcode, |_| true);
        assert!(n > 1000, "{name}: {n} curved segments");
        assert!(worst_point < 0.01, "{name}: point {worst_point} mm off");
        let (_, _, worst_top) = surface_errors(&hf, &run.gcode, |d| d == 0.0);
        for r in &regions {
            for layer in r["layers"].as_array().into_iter().flatten() {
                let cusp = layer["planar_cusp"].as_f64().unwrap_or(0.0);
                let dev = layer["max_deviation"].as_f64().unwrap_or(1.0);
                assert!(cusp >= 0.1 && dev < 0.05, "{name}: {layer}");
            }
        }
        assert!(
            worst_top < 0.05,
            "{name}: top layer {worst_top} mm off the mesh"
        );
        let replayed = assert_no_head_hits(name, &run.gcode);
        assert!(replayed > 1000, "{name}: {replayed}");
    }
}

/// Extruding moves of the planar layers (outside the curved blocks): (layer, role, from, to).
fn planar_segments(gcode: &str) -> Vec<(usize, String, [f64; 3], [f64; 3])> {
    let (mut layer, mut curved, mut role) = (0usize, false, String::new());
    let mut out = Vec::new();
    replay_lines(gcode, |line, mv| {
        if line.starts_with(";LAYER_CHANGE") {
            layer += 1;
            curved = false;
        }
        if line.starts_with(&format!("; {LAYER_COMMENT} layer ")) {
            curved = true;
        }
        if let Some(r) = line.strip_prefix(";TYPE:") {
            role = r.trim().to_owned();
        }
        if let Some((from, to, de)) = mv {
            if de > 0.0 && !curved && moves_xy(from, to) {
                out.push((layer, role.clone(), from, to));
            }
        }
    });
    out
}

fn distance_to_segment(p: [f64; 2], a: [f64; 3], b: [f64; 3]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a[0] + t * dx - p[0]).hypot(a[1] + t * dy - p[1])
}

#[test]
fn curved_dome_stands_on_solid_planar_layers_and_reports_deviation_beside_the_cusp() {
    let dir = temp_dir();
    let model = dir.path().join("dome.stl");
    write_stl(&model, &block_with_top(0.0, 0.0, 30.0, 30.0, 24, &dome));
    let run = slice(dir.path(), &model, "dome", &[]);
    let off = bed_offset(&model);
    // Under every point of the curved shell, the planar core's top layers are solid: the top
    // three planar layers at a point are printed there, with solid infill or the perimeters
    // where the core steps down, never sparse infill.
    let planar = planar_segments(&run.gcode);
    let mut checked = 0;
    for i in 0..12 {
        for j in 0..12 {
            let p = [
                off[0] + 4.0 + i as f64 * 2.0 + 0.3,
                off[1] + 4.0 + j as f64 * 2.0 + 0.7,
            ];
            let mut covering: Vec<(usize, &str)> = planar
                .iter()
                .filter(|(_, role, a, b)| role != "Custom" && distance_to_segment(p, *a, *b) < 0.3)
                .map(|(l, role, ..)| (*l, role.as_str()))
                .collect();
            covering.sort_unstable();
            covering.dedup();
            // The core's top at p and the two layers under it: solid there, nothing sparse.
            let Some(&(top, _)) = covering.last() else {
                panic!("nothing planar under {p:?}")
            };
            for l in [top, top - 1, top - 2] {
                let roles: Vec<&str> = covering
                    .iter()
                    .filter(|(k, _)| *k == l)
                    .map(|(_, r)| *r)
                    .collect();
                // Where the core's top steps down a layer its layers end in their perimeters.
                let solid = |r: &&str| {
                    matches!(
                        *r,
                        "Solid infill" | "Top solid infill" | "Perimeter" | "External perimeter"
                    )
                };
                assert!(
                    !roles.is_empty() && roles.iter().all(solid),
                    "{p:?}, layer {l}: {roles:?}"
                );
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 144);
    // The report: per curved layer its deviation from the target surface (as measured on the
    // G-code, to its rounding) beside the planar cusp h·cos α of the region's steepest slope;
    // the dome's steepest slope is at its corners, atan(5·15√2/450) = 13.26°, less the chords.
    let hf = placed_surface(&model);
    let region = &run.report["curved"]["regions"][0];
    let slope = region["max_slope_deg"].as_f64().unwrap_or(0.0);
    let analytic = (5.0 * 15.0 * 2f64.sqrt() / 450.0).atan().to_degrees();
    assert!(
        slope < analytic && slope > analytic - 1.0,
        "{slope} vs {analytic}"
    );
    let layers = region["layers"].as_array().cloned().unwrap_or_default();
    assert_eq!(layers.len(), 3);
    for (k, layer) in layers.iter().enumerate() {
        assert_eq!(layer["k"].as_u64(), Some(k as u64));
        let depth = k as f64 * 0.2;
        assert!((layer["depth"].as_f64().unwrap_or(-1.0) - depth).abs() < 1e-9);
        let cusp = layer["planar_cusp"].as_f64().unwrap_or(0.0);
        assert!(
            (cusp - 0.2 * slope.to_radians().cos()).abs() < 1e-9,
            "{layer}"
        );
        let dev = layer["max_deviation"].as_f64().unwrap_or(1.0);
        let (n, _, measured) = surface_errors(&hf, &run.gcode, |d| (d - depth).abs() < 1e-6);
        assert!(n > 300, "layer {k}: {n} segments");
        // The G-code rounds XYZ to 0.001 mm.
        assert!(
            dev <= measured + 1e-3 && measured <= dev + 2e-3,
            "{layer}: {measured}"
        );
        assert!(dev < 0.05 && cusp >= 0.1, "{layer}");
        // The dome has no planar material beside it: every layer covers the whole top.
        let area = layer["area_mm2"].as_f64().unwrap_or(0.0);
        assert!((area - 900.0).abs() < 0.5, "{layer}");
    }
}
