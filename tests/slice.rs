//! The planar pipeline end to end: small models sliced by the binary, the G-code re-parsed with
//! `conduit_gcode` and replayed here (and by `conduit::check`), then checked for layer heights,
//! closed perimeters inside the part, solid skins, the extrusion formula, holes, tool changes and
//! heating, paste switching, determinism, the bench config against PrusaSlicer, and the config
//! command line.

use std::collections::BTreeMap;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use conduit::check::{FindingKind, check};
use conduit::config::Config;
use conduit::geom::Transform;
use conduit::scene::{LoadOptions, MeshFormat, Scene, load_scene, save};
use serde_json::Value;

use conduit_gcode::{Firmware, Machine};

use crate::support::{
    conduit, corpus, root, sample, stderr, stdout, stl_triangles, temp_dir, write_stl, xyz,
};

/// Tolerance for "the same point" in G-code coordinates, mm (1 µm; XYZ are written to 3
/// decimals, so equal points are written identically).
const SAME_POINT: f64 = 1e-3;

/// How far short of its start a perimeter loop ends by default, mm: `slice.seam_gap` (0.15) of
/// the 0.4 mm nozzle.
const SEAM_GAP: f64 = 0.06;

// ---------------------------------------------------------------------------------------------
// Running the binary
// ---------------------------------------------------------------------------------------------

/// Runs the conduit binary with `args` and extra environment variables.
fn conduit_env(args: &[OsString], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_conduit"));
    cmd.args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("the conduit binary runs")
}

/// The arguments `slice MODELS... -o DIR/NAME.gcode --report DIR/NAME.json EXTRA...`.
fn slice_args(dir: &Path, name: &str, models: &[PathBuf], extra: &[&str]) -> Vec<OsString> {
    let mut args: Vec<OsString> = vec!["slice".into()];
    args.extend(models.iter().map(|m| m.clone().into_os_string()));
    args.extend([
        "-o".into(),
        dir.join(format!("{name}.gcode")).into_os_string(),
        "--report".into(),
        dir.join(format!("{name}.json")).into_os_string(),
    ]);
    args.extend(extra.iter().map(OsString::from));
    args
}

/// A sliced model: the G-code text and the JSON report.
struct Sliced {
    gcode: String,
    report: Value,
}

/// Slices `models` into `dir` (files named after `name`) with `extra` arguments.
fn slice(dir: &Path, name: &str, models: &[PathBuf], extra: &[&str]) -> Sliced {
    slice_with_env(dir, name, models, extra, &[])
}

fn slice_with_env(
    dir: &Path,
    name: &str,
    models: &[PathBuf],
    extra: &[&str],
    env: &[(&str, &str)],
) -> Sliced {
    let o = conduit_env(&slice_args(dir, name, models, extra), env);
    assert!(
        o.status.success(),
        "slicing {models:?} {extra:?} failed: {}",
        stderr(&o)
    );
    let gcode = std::fs::read_to_string(dir.join(format!("{name}.gcode"))).expect("G-code written");
    let report = std::fs::read_to_string(dir.join(format!("{name}.json"))).expect("report");
    let report = serde_json::from_str(&report).expect("report is JSON");
    Sliced { gcode, report }
}

/// `[min_x, min_y, max_x, max_y]` of object `i` in the slice report.
fn report_footprint(report: &Value, i: usize) -> [f64; 4] {
    let bb = &report["objects"][i]["bbox"];
    let f = |v: &Value| v.as_f64().expect("bbox numbers");
    [
        f(&bb["min"][0]),
        f(&bb["min"][1]),
        f(&bb["max"][0]),
        f(&bb["max"][1]),
    ]
}

/// Two 20 mm cubes side by side (10 mm apart along X), named `left` and `right`, saved as a 3MF.
fn two_part_3mf(dir: &Path) -> PathBuf {
    let (scene, _) =
        load_scene(&sample("cube_20mm.stl"), &LoadOptions::default()).expect("cube sample loads");
    let cube = scene
        .objects
        .into_iter()
        .next()
        .expect("the cube sample has one object");
    let mut left = cube.clone();
    left.name = "left".to_owned();
    left.transform = Transform::identity();
    let mut right = cube;
    right.name = "right".to_owned();
    right.transform = Transform::translation(30.0, 0.0, 0.0);
    let path = dir.join("two_parts.3mf");
    save(
        &Scene {
            objects: vec![left, right],
        },
        &path,
        MeshFormat::ThreeMf,
    )
    .expect("the two-part 3MF is written");
    path
}

// ---------------------------------------------------------------------------------------------
// Replaying G-code
// ---------------------------------------------------------------------------------------------

/// One move that changes X or Y, with the state it ran in.
#[derive(Debug, Clone)]
struct Move {
    /// 1-based line number.
    line: usize,
    from: [f64; 3],
    to: [f64; 3],
    /// Change of E (filament); positive extrudes.
    de: f64,
    /// The last `;TYPE:`.
    role: String,
    /// The last `;WIDTH:`.
    width: Option<f64>,
    /// The last `;HEIGHT:`.
    height: Option<f64>,
    /// The active tool.
    tool: usize,
    /// The last `;Z:` (the layer), in µm.
    layer_um: Option<i64>,
    /// Whether a paste tool's flow was switched on (by its `paste_on_gcode`).
    paste_on: bool,
}

impl Move {
    fn extrudes(&self) -> bool {
        self.de > 0.0
    }

    fn xy_len(&self) -> f64 {
        (self.to[0] - self.from[0]).hypot(self.to[1] - self.from[1])
    }

    fn is_perimeter(&self) -> bool {
        self.role == "Perimeter" || self.role == "External perimeter"
    }
}

/// A temperature command seen in the replay.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Heat {
    line: usize,
    tool: usize,
    celsius: f64,
    wait: bool,
}

/// What a G-code file does, as far as these tests need it.
#[derive(Debug, Default)]
struct Replay {
    /// Every XY move in order.
    moves: Vec<Move>,
    /// The `;Z:` values in order, in µm.
    layer_comments_um: Vec<i64>,
    /// `T<n>` commands: (line, tool).
    tool_selects: Vec<(usize, usize)>,
    /// `M104`/`M109` commands.
    heats: Vec<Heat>,
    /// Lines at which a paste tool was switched on (the first line of the snippet).
    paste_on_lines: Vec<usize>,
    /// Text lines, trimmed.
    lines: Vec<String>,
}

/// Millimetres to whole micrometres.
fn um(mm: f64) -> i64 {
    (mm * 1000.0).round() as i64
}

/// Replays `text` on the modal machine (Marlin: positions, modes, `G92`, `T<n>`, `;TYPE:` and
/// `;WIDTH:`), with `M104`/`M109`, PrusaSlicer's `;HEIGHT:`/`;Z:` markers, and the paste
/// snippets `paste_on`/`paste_off` (their first lines) when given.
fn replay_with_paste(text: &str, paste: Option<(&str, &str)>) -> Replay {
    let g = conduit_gcode::parse(text.as_bytes()).expect("G-code parses");
    let mut r = Replay::default();
    let mut machine = Machine::new(Firmware::Marlin, 25.0);
    let mut height = None;
    let mut layer_um = None;
    let mut paste_on = false;
    for line in &g.lines {
        let raw = String::from_utf8_lossy(&line.text).trim().to_owned();
        if let Some((on, off)) = paste {
            if raw == on {
                paste_on = true;
                r.paste_on_lines.push(line.number);
            } else if raw == off {
                paste_on = false;
            }
        }
        r.lines.push(raw);
        if let Some(c) = line.comment_text() {
            let num = |s: &str| s.trim().parse::<f64>().expect("a number after the marker");
            if let Some(h) = c.strip_prefix("HEIGHT:") {
                height = Some(num(h));
            } else if let Some(z) = c.strip_prefix("Z:") {
                layer_um = Some(um(num(z)));
                r.layer_comments_um.push(um(num(z)));
            }
        }
        if let Some((b'M', n @ (104.0 | 109.0))) = line.command() {
            let t = line.get(b'T').map_or(machine.tool(), |t| t as usize);
            r.heats.push(Heat {
                line: line.number,
                tool: t,
                celsius: line.get(b'S').expect("M104/M109 with S"),
                wait: n == 109.0,
            });
        }
        let step = machine.step_with(line, |_, c| {
            if let conduit_gcode::Command::Tool(t) = c {
                r.tool_selects.push((line.number, t));
            }
        });
        let Some(m) = step else { continue };
        let (from, to) = (xyz(m.from), xyz(m.to));
        if to[0] != from[0] || to[1] != from[1] {
            r.moves.push(Move {
                line: line.number,
                from,
                to,
                de: m.e,
                role: m.role.as_deref().unwrap_or_default().to_owned(),
                width: m.width,
                height,
                tool: m.tool,
                layer_um,
                paste_on,
            });
        }
    }
    r
}

fn replay(text: &str) -> Replay {
    replay_with_paste(text, None)
}

/// Runs of consecutive extruding moves of one role, tool and layer: the printed paths. A
/// non-extruding XY move, a role change or a layer change ends a run.
fn runs(moves: &[Move]) -> Vec<Vec<&Move>> {
    let mut out: Vec<Vec<&Move>> = Vec::new();
    let mut current: Vec<&Move> = Vec::new();
    for m in moves {
        let continues = current.last().is_some_and(|p| {
            p.role == m.role
                && p.tool == m.tool
                && p.layer_um == m.layer_um
                && (p.to[0] - m.from[0]).abs() < 1e-9
                && (p.to[1] - m.from[1]).abs() < 1e-9
        });
        if (!m.extrudes() || !continues) && !current.is_empty() {
            out.push(std::mem::take(&mut current));
        }
        if m.extrudes() {
            current.push(m);
        }
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

/// The points of a run: its start, then the end of every move.
fn points(run: &[&Move]) -> Vec<[f64; 2]> {
    let mut pts = Vec::with_capacity(run.len() + 1);
    if let Some(first) = run.first() {
        pts.push([first.from[0], first.from[1]]);
    }
    pts.extend(run.iter().map(|m| [m.to[0], m.to[1]]));
    pts
}

/// Whether a run is a loop that ends the seam gap short of its start.
fn ends_at_its_seam(pts: &[[f64; 2]]) -> bool {
    match (pts.first(), pts.last()) {
        (Some(a), Some(b)) => {
            let gap = (a[0] - b[0]).hypot(a[1] - b[1]);
            pts.len() >= 4 && (gap - SEAM_GAP).abs() <= 2.0 * SAME_POINT
        }
        _ => false,
    }
}

/// `[min_x, min_y, max_x, max_y]` of points.
fn bbox(pts: &[[f64; 2]]) -> [f64; 4] {
    pts.iter().fold(
        [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ],
        |b, p| {
            [
                b[0].min(p[0]),
                b[1].min(p[1]),
                b[2].max(p[0]),
                b[3].max(p[1]),
            ]
        },
    )
}

/// Whether the segment `a`–`b` passes through the open box `[x0, x1] × [y0, y1]`
/// (Liang–Barsky clipping; touching the boundary does not count).
fn segment_enters_box(a: [f64; 2], b: [f64; 2], bx: [f64; 4]) -> bool {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d[0], a[0] - bx[0]),
        (d[0], bx[2] - a[0]),
        (-d[1], a[1] - bx[1]),
        (d[1], bx[3] - a[1]),
    ] {
        if p == 0.0 {
            if q <= 0.0 {
                return false;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    t1 - t0 > 1e-9
}

/// Extruding moves grouped by layer (`;Z:` in µm).
fn by_layer(moves: &[Move]) -> BTreeMap<i64, Vec<&Move>> {
    let mut layers: BTreeMap<i64, Vec<&Move>> = BTreeMap::new();
    for m in moves.iter().filter(|m| m.extrudes()) {
        if let Some(z) = m.layer_um {
            layers.entry(z).or_default().push(m);
        }
    }
    layers
}

/// The library's checker on `text` with `config`'s printer.
fn check_text(text: &str, config: &Config) -> conduit::check::CheckReport {
    let g = conduit_gcode::parse(text.as_bytes()).expect("G-code parses");
    check(&g, &config.check_params())
}

/// `conduit check --json FILE [-c CONFIG]`: exit code and the JSON report.
fn check_cli(file: &Path, config: Option<&Path>) -> (Option<i32>, Value) {
    let mut args: Vec<OsString> = vec!["check".into(), "--json".into(), file.into()];
    if let Some(c) = config {
        args.extend(["-c".into(), c.into()]);
    }
    let o = conduit(&args);
    let v = serde_json::from_str(&stdout(&o))
        .unwrap_or_else(|e| panic!("check --json prints JSON ({e}): {}", stderr(&o)));
    (o.status.code(), v)
}

/// Total `filament_mm` over the tools of a `conduit check --json` report.
fn check_filament_mm(v: &Value) -> f64 {
    v["stats"]["tools"]
        .as_array()
        .expect("stats.tools")
        .iter()
        .map(|t| t["filament_mm"].as_f64().expect("filament_mm"))
        .sum()
}

// ---------------------------------------------------------------------------------------------
// 1. The 20 mm cube with default settings
// ---------------------------------------------------------------------------------------------

#[test]
fn cube_layers_are_exactly_every_0_2_mm() {
    let dir = temp_dir();
    let s = slice(dir.path(), "cube", &[sample("cube_20mm.stl")], &[]);
    let r = replay(&s.gcode);
    let expected: Vec<i64> = (1..=100).map(|k| 200 * k).collect();
    assert_eq!(r.layer_comments_um, expected, ";Z: comments");
    // Every `;Z:` value is written exactly (3 decimals at most, no float noise).
    for l in r.lines.iter().filter(|l| l.starts_with(";Z:")) {
        let z: f64 = l[3..].parse().expect(";Z: number");
        assert_eq!(l[3..], conduit_gcode::fmt_xyz(z), "{l}");
    }
    let mut zs: Vec<i64> = r
        .moves
        .iter()
        .filter(|m| m.extrudes())
        .map(|m| um(m.to[2]))
        .collect();
    zs.sort_unstable();
    zs.dedup();
    assert_eq!(zs, expected, "Z of extruding moves");
    for m in r
        .moves
        .iter()
        .filter(|m| m.extrudes() && m.role != "Custom")
    {
        assert_eq!(
            Some(um(m.to[2])),
            m.layer_um,
            "line {}: extrudes at Z {} in layer ;Z:{:?}",
            m.line,
            m.to[2],
            m.layer_um
        );
        assert!(
            (m.to[2] - m.from[2]).abs() < 1e-9,
            "line {}: planar layers do not move Z while extruding",
            m.line
        );
    }
    assert_eq!(s.report["layers"], 100);
}

#[test]
fn cube_perimeters_are_closed_loops_inside_the_footprint() {
    let dir = temp_dir();
    let s = slice(dir.path(), "cube", &[sample("cube_20mm.stl")], &[]);
    let fp = report_footprint(&s.report, 0);
    assert_eq!(
        [fp[2] - fp[0], fp[3] - fp[1]],
        [20.0, 20.0],
        "the report's bbox is the cube's"
    );
    let r = replay(&s.gcode);
    let mut loops_per_layer: BTreeMap<i64, (usize, usize)> = BTreeMap::new();
    for run in runs(&r.moves) {
        let m0 = run[0];
        if !m0.is_perimeter() {
            continue;
        }
        let pts = points(&run);
        assert!(
            ends_at_its_seam(&pts),
            "line {}: {} run does not end the seam gap short of its start: {:?} .. {:?}",
            m0.line,
            m0.role,
            pts.first(),
            pts.last()
        );
        let w = m0.width.expect(";WIDTH: before the first perimeter");
        for p in &pts {
            assert!(
                p[0] >= fp[0] + w / 2.0 - SAME_POINT
                    && p[0] <= fp[2] - w / 2.0 + SAME_POINT
                    && p[1] >= fp[1] + w / 2.0 - SAME_POINT
                    && p[1] <= fp[3] - w / 2.0 + SAME_POINT,
                "line {}: perimeter point {p:?} is less than half a {w} mm line inside {fp:?}",
                m0.line
            );
        }
        let z = m0.layer_um.expect("perimeters are in layers");
        let counts = loops_per_layer.entry(z).or_default();
        if m0.role == "External perimeter" {
            counts.0 += 1;
            // The external centreline is the square shrunk by exactly half a 0.45 mm line.
            let inner = [fp[0] + 0.225, fp[1] + 0.225, fp[2] - 0.225, fp[3] - 0.225];
            let b = bbox(&pts);
            for k in 0..4 {
                assert!(
                    (b[k] - inner[k]).abs() <= SAME_POINT,
                    "line {}: external perimeter spans {b:?}, expected {inner:?}",
                    m0.line
                );
            }
            for p in &pts {
                let on_edge = (p[0] - inner[0]).abs() <= SAME_POINT
                    || (p[0] - inner[2]).abs() <= SAME_POINT
                    || (p[1] - inner[1]).abs() <= SAME_POINT
                    || (p[1] - inner[3]).abs() <= SAME_POINT;
                assert!(
                    on_edge,
                    "line {}: external point {p:?} off the square",
                    m0.line
                );
            }
        } else {
            counts.1 += 1;
        }
    }
    assert_eq!(loops_per_layer.len(), 100, "perimeters on every layer");
    for (z, (ext, inner)) in &loops_per_layer {
        assert_eq!(
            (*ext, *inner),
            (1, 1),
            "layer {z} µm: one external and one inner loop (perimeters = 2)"
        );
    }
}

#[test]
fn cube_bottom_and_top_layers_are_solid() {
    let dir = temp_dir();
    let s = slice(dir.path(), "cube", &[sample("cube_20mm.stl")], &[]);
    let r = replay(&s.gcode);
    let layers = by_layer(&r.moves);
    assert_eq!(layers.len(), 100);
    let roles = |z: i64| -> Vec<String> {
        let mut v: Vec<String> = layers[&z].iter().map(|m| m.role.clone()).collect();
        v.sort();
        v.dedup();
        v
    };
    let solid_roles = [
        "External perimeter",
        "Perimeter",
        "Solid infill",
        "Top solid infill",
        "Bottom solid infill",
        "Bottom",
        "Bridge infill",
    ];
    // Defaults: 3 bottom and 3 top solid layers.
    for k in [1, 2, 3, 98, 99, 100] {
        let rs = roles(200 * k);
        assert!(
            rs.iter().all(|r| solid_roles.contains(&r.as_str())),
            "layer {k} has roles {rs:?}"
        );
        assert!(
            rs.iter()
                .any(|r| r.contains("olid infill") || r == "Bridge infill"),
            "layer {k} is filled solid: {rs:?}"
        );
    }
    assert!(
        roles(200 * 100).contains(&"Top solid infill".to_owned()),
        "the last layer is a top surface: {:?}",
        roles(200 * 100)
    );
    // The first solid layer over the sparse ones bridges the sparse lines.
    assert!(roles(200 * 98).contains(&"Bridge infill".to_owned()));
    for k in 4..=97 {
        let rs = roles(200 * k);
        assert!(
            rs.contains(&"Internal infill".to_owned()),
            "layer {k} has sparse infill: {rs:?}"
        );
    }
}

#[test]
fn cube_extrusion_per_mm_follows_the_bead_formula() {
    let dir = temp_dir();
    let s = slice(dir.path(), "cube", &[sample("cube_20mm.stl")], &[]);
    let r = replay(&s.gcode);
    let filament_area = std::f64::consts::PI * (1.75f64 / 2.0).powi(2);
    // Per layer: (E written, E the formula gives for the written lengths).
    let mut per_layer: BTreeMap<i64, (f64, f64)> = BTreeMap::new();
    let mut checked = 0;
    for m in r
        .moves
        .iter()
        .filter(|m| m.extrudes() && m.role != "Custom")
    {
        let w = m.width.expect(";WIDTH: before extruding");
        let h = m.height.expect(";HEIGHT: before extruding");
        // Flat beads are rounded rectangles; bridges are round threads of diameter w.
        let bead = if m.role == "Bridge infill" {
            std::f64::consts::PI * w * w / 4.0
        } else {
            (w - h) * h + std::f64::consts::PI * (h / 2.0).powi(2)
        };
        let per_mm = bead / filament_area;
        let expected = m.xy_len() * per_mm;
        // What the file's rounding allows: E has 5 decimals, so a difference of two written
        // values is off by up to 1e-5; X and Y have 3, so each end may sit up to
        // 0.5·√2 µm from the point whose length E was computed from.
        let rounding = 1e-5 + per_mm * 2.0 * 0.0005 * std::f64::consts::SQRT_2;
        assert!(
            (m.de - expected).abs() <= 1e-4 * expected + rounding,
            "line {}: E {:.6} over {:.4} mm, expected {expected:.6} (w {w}, h {h})",
            m.line,
            m.de,
            m.xy_len()
        );
        let e = per_layer
            .entry(m.layer_um.expect("in a layer"))
            .or_default();
        e.0 += m.de;
        e.1 += expected;
        checked += 1;
    }
    assert!(checked > 1000, "only {checked} extruding moves");
    // Summed over a layer the rounding errors cancel out: the flow itself is within 1e-4.
    assert_eq!(per_layer.len(), 100);
    for (z, (written, expected)) in &per_layer {
        assert!(
            (written - expected).abs() <= 1e-4 * expected,
            "layer {z} µm: E {written:.5} written, {expected:.5} from the formula"
        );
    }
}

#[test]
fn first_layer_and_top_solid_widths_take_effect() {
    let dir = temp_dir();
    let s = slice(
        dir.path(),
        "widths",
        &[sample("cube_20mm.stl")],
        &[
            "--set",
            "slice.first_layer_width=0.5",
            "--set",
            "slice.top_solid_infill_width=0.4",
        ],
    );
    let fp = report_footprint(&s.report, 0);
    let r = replay(&s.gcode);
    let layers = by_layer(&r.moves);
    for m in &layers[&200] {
        assert_eq!(
            m.width,
            Some(0.5),
            "line {}: first layer {}",
            m.line,
            m.role
        );
    }
    let first_external: Vec<&Move> = layers[&200]
        .iter()
        .copied()
        .filter(|m| m.role == "External perimeter")
        .collect();
    let b = bbox(&points(&first_external));
    assert!(
        (b[0] - (fp[0] + 0.25)).abs() <= SAME_POINT,
        "first-layer external perimeter at {b:?}: not half of 0.5 mm inside {fp:?}"
    );
    let top: Vec<&&Move> = layers[&20_000]
        .iter()
        .filter(|m| m.role == "Top solid infill")
        .collect();
    assert!(!top.is_empty());
    for m in top {
        assert_eq!(m.width, Some(0.4), "line {}: top solid infill", m.line);
    }
}

// ---------------------------------------------------------------------------------------------
// 2. A block with a square through-hole
// ---------------------------------------------------------------------------------------------

/// The ASCII STL of `samples/cube_with_hole.stl`: a 20 × 20 × 10 mm block with a 6 × 6 mm
/// square hole through Z at its centre, 32 triangles, outward normals.
fn cube_with_hole_stl() -> String {
    let outer = [[0, 0], [20, 0], [20, 20], [0, 20]];
    let hole = [[7, 7], [13, 7], [13, 13], [7, 13]];
    let h = 10;
    let mut tris: Vec<[[i64; 3]; 3]> = Vec::new();
    let at = |p: [i64; 2], z: i64| [p[0], p[1], z];
    for i in 0..4 {
        let j = (i + 1) % 4;
        let (o0, o1, i0, i1) = (outer[i], outer[j], hole[i], hole[j]);
        // Top (+Z) and bottom (−Z) rings.
        tris.push([at(o0, h), at(o1, h), at(i1, h)]);
        tris.push([at(o0, h), at(i1, h), at(i0, h)]);
        tris.push([at(o0, 0), at(i1, 0), at(o1, 0)]);
        tris.push([at(o0, 0), at(i0, 0), at(i1, 0)]);
        // Outer walls face away from the block, hole walls face into the hole.
        tris.push([at(o0, 0), at(o1, 0), at(o1, h)]);
        tris.push([at(o0, 0), at(o1, h), at(o0, h)]);
        tris.push([at(i0, 0), at(i1, h), at(i1, 0)]);
        tris.push([at(i0, 0), at(i0, h), at(i1, h)]);
    }
    let mut out = String::from("solid cube_with_hole\n");
    for t in &tris {
        let u = [t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]];
        let v = [t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]];
        // Every facet is axis-aligned, so the unit normal is the sign of the cross product.
        let n = [
            (u[1] * v[2] - u[2] * v[1]).signum(),
            (u[2] * v[0] - u[0] * v[2]).signum(),
            (u[0] * v[1] - u[1] * v[0]).signum(),
        ];
        out += &format!(
            "  facet normal {} {} {}\n    outer loop\n",
            n[0], n[1], n[2]
        );
        for p in t {
            out += &format!("      vertex {} {} {}\n", p[0], p[1], p[2]);
        }
        out += "    endloop\n  endfacet\n";
    }
    out += "endsolid cube_with_hole\n";
    out
}

#[test]
fn cube_with_hole_sample_is_its_generator_s_output_and_a_closed_outward_solid() {
    let path = sample("cube_with_hole.stl");
    let committed = std::fs::read_to_string(&path).expect("samples/cube_with_hole.stl exists");
    assert!(
        committed == cube_with_hole_stl(),
        "samples/cube_with_hole.stl differs from cube_with_hole_stl() in tests/slice.rs; \
         regenerate it from that function"
    );
    assert_eq!(crate::support::stl_triangles(&path).len(), 32);
    let o = conduit(["info".as_ref(), "--json".as_ref(), path.as_os_str()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).expect("JSON");
    let obj = &v[0]["objects"][0];
    assert_eq!(v[0]["volume_mm3"], 20.0 * 20.0 * 10.0 - 6.0 * 6.0 * 10.0);
    assert_eq!(obj["topology"]["closed"], true);
    assert_eq!(obj["topology"]["orientation"], "outward");
    assert_eq!(obj["topology"]["shells"], 1);
}

#[test]
fn cube_with_hole_has_loops_around_the_hole_and_nothing_inside_it() {
    let dir = temp_dir();
    let s = slice(dir.path(), "hole", &[sample("cube_with_hole.stl")], &[]);
    let fp = report_footprint(&s.report, 0);
    assert_eq!([fp[2] - fp[0], fp[3] - fp[1]], [20.0, 20.0]);
    let hole = [fp[0] + 7.0, fp[1] + 7.0, fp[0] + 13.0, fp[1] + 13.0];
    let grown = [hole[0] - 1.0, hole[1] - 1.0, hole[2] + 1.0, hole[3] + 1.0];
    let shrunk = [hole[0] + 0.1, hole[1] + 0.1, hole[2] - 0.1, hole[3] - 0.1];
    let r = replay(&s.gcode);
    let expected: Vec<i64> = (1..=50).map(|k| 200 * k).collect();
    assert_eq!(r.layer_comments_um, expected, "50 layers of 0.2 mm");

    let mut hole_loops: BTreeMap<i64, usize> = BTreeMap::new();
    for run in runs(&r.moves) {
        let m0 = run[0];
        if !m0.is_perimeter() {
            continue;
        }
        let pts = points(&run);
        assert!(
            ends_at_its_seam(&pts),
            "line {}: {} run does not end the seam gap short of its start",
            m0.line,
            m0.role
        );
        let inside_grown = pts
            .iter()
            .all(|p| p[0] >= grown[0] && p[0] <= grown[2] && p[1] >= grown[1] && p[1] <= grown[3]);
        let b = bbox(&pts);
        let surrounds = b[0] <= hole[0] && b[1] <= hole[1] && b[2] >= hole[2] && b[3] >= hole[3];
        if inside_grown && surrounds {
            *hole_loops
                .entry(m0.layer_um.expect("in a layer"))
                .or_default() += 1;
        }
    }
    for z in &expected {
        let n = hole_loops.get(z).copied().unwrap_or(0);
        assert!(n >= 1, "layer {z} µm has no perimeter loop around the hole");
    }
    for m in r.moves.iter().filter(|m| m.extrudes()) {
        assert!(
            !segment_enters_box([m.from[0], m.from[1]], [m.to[0], m.to[1]], shrunk),
            "line {}: {} extrudes through the hole ({:?} -> {:?}, hole {hole:?})",
            m.line,
            m.role,
            m.from,
            m.to
        );
    }
}

#[test]
fn the_hole_test_geometry_catches_a_segment_across_the_hole() {
    // The helper itself must be able to fail: a segment across the box, one along its edge and
    // one outside.
    let b = [122.1, 122.1, 127.9, 127.9];
    assert!(segment_enters_box([120.0, 125.0], [130.0, 125.0], b));
    assert!(segment_enters_box([123.0, 123.0], [124.0, 124.0], b));
    assert!(!segment_enters_box([120.0, 122.1], [130.0, 122.1], b));
    assert!(!segment_enters_box([120.0, 120.0], [130.0, 121.0], b));
    assert!(!segment_enters_box([120.0, 123.0], [123.0, 120.0], b));
}

// ---------------------------------------------------------------------------------------------
// 3. Two objects on two tools
// ---------------------------------------------------------------------------------------------

const TWO_FILAMENT_TOOLS: &str = r#"
[tools.0]
kind = "filament"
name = "PLA"

[tools.1]
kind = "filament"
name = "PETG"
temperature = 235.0
first_layer_temperature = 240.0
"#;

/// Asserts that every extruding move of a filament tool runs after a wait (`M109`) for that
/// tool at no less than its current target (`M104`/`M109`), minus 5 °C, and at 170 °C or more.
fn assert_heated_before_extruding(r: &Replay) {
    let mut events: Vec<(usize, Option<&Heat>, Option<&Move>)> = r
        .heats
        .iter()
        .map(|h| (h.line, Some(h), None))
        .chain(
            r.moves
                .iter()
                .filter(|m| m.extrudes())
                .map(|m| (m.line, None, Some(m))),
        )
        .collect();
    events.sort_by_key(|e| e.0);
    let mut target: BTreeMap<usize, f64> = BTreeMap::new();
    let mut reached: BTreeMap<usize, f64> = BTreeMap::new();
    for (line, heat, mv) in events {
        if let Some(h) = heat {
            target.insert(h.tool, h.celsius);
            let r = reached.entry(h.tool).or_insert(0.0);
            if h.wait || h.celsius < *r {
                *r = h.celsius;
            }
        }
        if let Some(m) = mv {
            let t = target.get(&m.tool).copied().unwrap_or(0.0);
            let got = reached.get(&m.tool).copied().unwrap_or(0.0);
            assert!(
                t >= 170.0 && got >= t - 5.0,
                "line {line}: tool {} extrudes with target {t} °C, waited for {got} °C",
                m.tool
            );
        }
    }
}

#[test]
fn two_objects_on_two_filament_tools_change_and_heat_tools() {
    let dir = temp_dir();
    let scene = two_part_3mf(dir.path());
    let cfg_path = dir.path().join("two_filaments.toml");
    std::fs::write(&cfg_path, TWO_FILAMENT_TOOLS).expect("config written");
    let cfg_arg = cfg_path.to_str().expect("UTF-8 temp path");
    let s = slice(
        dir.path(),
        "two",
        &[scene],
        &["-c", cfg_arg, "--set", "slice.object_tools=[0,1]"],
    );
    let objects = s.report["objects"].as_array().expect("objects");
    assert_eq!(objects.len(), 2);
    assert_eq!(objects[0]["name"], "left");
    assert_eq!(objects[0]["tool"], 0);
    assert_eq!(objects[1]["name"], "right");
    assert_eq!(objects[1]["tool"], 1);
    let left = report_footprint(&s.report, 0);
    let right = report_footprint(&s.report, 1);
    assert!(left[2] < right[0], "side by side: {left:?} {right:?}");

    let r = replay(&s.gcode);
    let selects: Vec<usize> = r.tool_selects.iter().map(|&(_, t)| t).collect();
    assert!(selects.contains(&0) && selects.contains(&1), "{selects:?}");
    let changes = selects.windows(2).filter(|w| w[0] != w[1]).count();
    // Both cubes are 100 layers tall: at least one change per layer.
    assert!(changes >= 99, "{changes} tool changes");

    // Each object is printed by its own tool, inside its own footprint.
    for m in r
        .moves
        .iter()
        .filter(|m| m.extrudes() && m.role != "Custom")
    {
        let fp = if m.tool == 1 { right } else { left };
        assert!(
            m.to[0] >= fp[0] && m.to[0] <= fp[2] && m.to[1] >= fp[1] && m.to[1] <= fp[3],
            "line {}: tool {} extrudes at {:?}, outside its object {fp:?}",
            m.line,
            m.tool,
            m.to
        );
    }
    let first_t1_extrusion = r
        .moves
        .iter()
        .find(|m| m.extrudes() && m.tool == 1)
        .expect("tool 1 extrudes");
    let t1_wait = r
        .heats
        .iter()
        .find(|h| h.tool == 1 && h.wait)
        .expect("an M109 T1 wait");
    assert!(
        t1_wait.line < first_t1_extrusion.line && t1_wait.celsius == 240.0,
        "{t1_wait:?} before the first T1 extrusion at line {}",
        first_t1_extrusion.line
    );
    assert!(
        r.lines.iter().any(|l| l.starts_with("M109 T1 S240")),
        "the first-layer temperature of tool 1 is waited for"
    );
    assert_heated_before_extruding(&r);

    let (cfg, _) = conduit::config::load(&cfg_path).expect("the test config loads");
    let report = check_text(&s.gcode, &cfg);
    assert!(!report.has_errors(), "{report}");
    assert_eq!(report.of_kind(FindingKind::HeatingNotWaited).count(), 0);
    assert_eq!(report.stats.tools.len(), 2, "both tools extrude");
    let (code, _) = check_cli(&dir.path().join("two.gcode"), Some(&cfg_path));
    assert_eq!(code, Some(0));
}

#[test]
fn the_heating_replay_catches_a_tool_that_extrudes_before_its_wait() {
    let text = "M104 T0 S210\nM109 T0 S210\nG92 E0\nG1 X1 Y1 E1\nT1\nM104 T1 S240\n\
                G1 X2 Y2 E2\nM109 T1 S240\n";
    let r = replay(text);
    let caught = std::panic::catch_unwind(|| assert_heated_before_extruding(&r));
    assert!(caught.is_err(), "tool 1 extrudes before M109 T1");
    let ok = replay("M109 T0 S210\nG92 E0\nG1 X1 Y1 E1\nM104 T0 S205\nG1 X2 Y2 E2\n");
    assert_heated_before_extruding(&ok);
}

// ---------------------------------------------------------------------------------------------
// The sample two-tool printer: PLA + conductive paste
// ---------------------------------------------------------------------------------------------

#[test]
fn two_tool_printer_sample_config_checks() {
    let path = sample("two_tool_printer.toml");
    let o = conduit(["config".as_ref(), "--check".as_ref(), path.as_os_str()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (cfg, warnings) = conduit::config::load(&path).expect("the sample loads");
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(cfg.tools.len(), 2);
    assert_eq!(cfg.tools[0].kind, conduit::config::ToolKind::Filament);
    assert_eq!(cfg.tools[1].kind, conduit::config::ToolKind::Paste);
    assert!(!cfg.tools[1].paste_on_gcode.trim().is_empty());
    assert!(!cfg.tools[1].paste_off_gcode.trim().is_empty());
}

#[test]
fn two_tool_printer_sample_prints_one_object_in_paste() {
    let dir = temp_dir();
    let scene = two_part_3mf(dir.path());
    let cfg_path = sample("two_tool_printer.toml");
    let (cfg, _) = conduit::config::load(&cfg_path).expect("the sample loads");
    let cfg_arg = cfg_path.to_str().expect("UTF-8 sample path");
    let s = slice(
        dir.path(),
        "paste",
        &[scene],
        &["-c", cfg_arg, "--set", "slice.object_tools=[0,1]"],
    );
    let first_line = |snippet: &str| snippet.lines().next().unwrap_or_default().trim().to_owned();
    let on = first_line(&cfg.tools[1].paste_on_gcode);
    let off = first_line(&cfg.tools[1].paste_off_gcode);
    let r = replay_with_paste(&s.gcode, Some((&on, &off)));
    assert!(!r.paste_on_lines.is_empty(), "the paste is switched on");

    let left = report_footprint(&s.report, 0);
    let right = report_footprint(&s.report, 1);
    let offset = cfg.tools[1].offset;
    let mut paste_moves = 0;
    let mut paste_layers = std::collections::BTreeSet::new();
    for m in &r.moves {
        if m.tool == 1 {
            assert!(
                m.de == 0.0,
                "line {}: the paste tool moves E ({})",
                m.line,
                r.lines[m.line - 1]
            );
        }
        if m.paste_on {
            assert_eq!(
                m.tool, 1,
                "line {}: paste flows with tool {}",
                m.line, m.tool
            );
            // G-code coordinates of tool 1 are the part's minus the tool's offset.
            let p = [m.to[0] + offset[0], m.to[1] + offset[1]];
            assert!(
                p[0] >= right[0] && p[0] <= right[2] && p[1] >= right[1] && p[1] <= right[3],
                "line {}: paste at {p:?} (offset applied) outside {right:?}",
                m.line
            );
            paste_moves += 1;
            paste_layers.insert(m.layer_um);
        }
        if m.extrudes() && m.role != "Custom" {
            assert_eq!(m.tool, 0, "line {}: only tool 0 extrudes filament", m.line);
            assert!(
                m.to[0] >= left[0] && m.to[0] <= left[2],
                "line {}: PLA at {:?} outside {left:?}",
                m.line,
                m.to
            );
        }
    }
    assert!(paste_moves > 1000, "{paste_moves} paste moves");
    assert_eq!(
        paste_layers.len(),
        100,
        "paste on every layer of the right cube"
    );
    // The valve is closed whenever the tool changes and at the end.
    let mut open = false;
    for (i, l) in r.lines.iter().enumerate() {
        if *l == on {
            open = true;
        } else if *l == off {
            open = false;
        } else if l.starts_with('T') && l[1..].chars().all(|c| c.is_ascii_digit()) {
            assert!(!open, "line {}: tool change with the paste flowing", i + 1);
        }
    }
    assert!(!open, "the paste is still flowing at the end");
    // The paste tool is never heated.
    assert!(r.heats.iter().all(|h| h.tool != 1 || h.celsius == 0.0));
    assert_heated_before_extruding(&replay(&s.gcode));

    let report = check_text(&s.gcode, &cfg);
    assert!(!report.has_errors(), "{report}");
    let (code, _) = check_cli(&dir.path().join("paste.gcode"), Some(&cfg_path));
    assert_eq!(code, Some(0));
}

// ---------------------------------------------------------------------------------------------
// 4. Determinism
// ---------------------------------------------------------------------------------------------

#[test]
fn slicing_is_byte_identical_across_runs_and_thread_counts() {
    let dir = temp_dir();
    let two = two_part_3mf(dir.path());
    let cases: [(&str, Vec<PathBuf>, Vec<&str>); 2] = [
        ("hole", vec![sample("cube_with_hole.stl")], vec![]),
        ("two", vec![two], vec!["--set", "slice.object_tools=[0,1]"]),
    ];
    for (name, models, extra) in &cases {
        let runs: Vec<(String, Vec<(&str, &str)>)> = vec![
            (format!("{name}_a"), vec![]),
            (format!("{name}_b"), vec![]),
            (format!("{name}_t1"), vec![("RAYON_NUM_THREADS", "1")]),
            (format!("{name}_t2"), vec![("RAYON_NUM_THREADS", "2")]),
        ];
        let outputs: Vec<(String, String)> = runs
            .iter()
            .map(|(run, env)| {
                let s = slice_with_env(dir.path(), run, models, extra, env);
                (run.clone(), s.gcode)
            })
            .collect();
        let (first_name, first) = &outputs[0];
        assert!(first.len() > 10_000, "{first_name} is a real print");
        for (run, text) in &outputs[1..] {
            if text != first {
                let at = first
                    .lines()
                    .zip(text.lines())
                    .position(|(a, b)| a != b)
                    .map_or(0, |i| i + 1);
                panic!("{run} differs from {first_name} at line {at}");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 5. The bench config against PrusaSlicer
// ---------------------------------------------------------------------------------------------

#[test]
fn bench_cube_with_prusaslicer_ini_matches_prusaslicer_filament() {
    let Some(corpus) = corpus() else {
        return;
    };
    let model = corpus.join("bench-models/20mm_cube.stl");
    let peer = corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode");
    let ini = root().join("../shared/bench/configs/prusaslicer.ini");
    if !model.is_file() || !peer.is_file() || !ini.is_file() {
        println!("skipped: bench model, PrusaSlicer G-code or prusaslicer.ini missing");
        return;
    }
    let dir = temp_dir();
    let ini_arg = ini.to_str().expect("UTF-8 path");
    slice(dir.path(), "bench", &[model], &["-c", ini_arg]);
    let ours_path = dir.path().join("bench.gcode");
    let (code, ours) = check_cli(&ours_path, Some(&ini));
    assert_eq!(code, Some(0), "{ours}");
    assert_eq!(ours["stats"]["layers"], 100);
    let (_, theirs) = check_cli(&peer, Some(&ini));
    assert_eq!(theirs["stats"]["layers"], 100);

    let peer_text = std::fs::read_to_string(&peer).expect("peer G-code readable");
    let footer: f64 = peer_text
        .lines()
        .find_map(|l| l.strip_prefix("; filament used [mm] ="))
        .expect("PrusaSlicer's footer")
        .trim()
        .parse()
        .expect("a number");
    let ours_mm = check_filament_mm(&ours);
    let theirs_mm = check_filament_mm(&theirs);
    assert!(
        (theirs_mm - footer).abs() <= 0.001 * footer,
        "check counts {theirs_mm} mm in PrusaSlicer's file, its footer says {footer}"
    );
    assert!(
        (ours_mm - theirs_mm).abs() <= 0.05 * theirs_mm,
        "conduit uses {ours_mm:.1} mm, PrusaSlicer {theirs_mm:.1} mm"
    );

    // Role by role (filament on moves with XY motion, so (de)retractions do not count): the
    // same walls, the same skins grown 3 mm into the sparse infill, the same internal bridge
    // over the sparse infill with round-thread flow, and sparse infill within 5 %.
    let ours_text = std::fs::read_to_string(&ours_path).expect("our G-code readable");
    let by_role = |text: &str| -> BTreeMap<String, f64> {
        let mut sums = BTreeMap::new();
        for m in replay(text)
            .moves
            .iter()
            .filter(|m| m.extrudes() && m.xy_len() > 0.0)
        {
            *sums.entry(m.role.clone()).or_insert(0.0) += m.de;
        }
        sums
    };
    let (ours_roles, theirs_roles) = (by_role(&ours_text), by_role(&peer_text));
    for (role, tolerance) in [
        ("External perimeter", 0.01),
        ("Perimeter", 0.01),
        ("Solid infill", 0.01),
        ("Top solid infill", 0.01),
        ("Bridge infill", 0.01),
        ("Internal infill", 0.05),
    ] {
        let (a, b) = (ours_roles.get(role), theirs_roles.get(role));
        let (Some(&a), Some(&b)) = (a, b) else {
            panic!("{role}: conduit {a:?} mm, PrusaSlicer {b:?} mm");
        };
        assert!(
            (a - b).abs() <= tolerance * b,
            "{role}: conduit {a:.1} mm, PrusaSlicer {b:.1} mm"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// 6. Configs on the command line, and `conduit check` exit codes
// ---------------------------------------------------------------------------------------------

#[test]
fn printed_defaults_load_back_and_slice_the_same() {
    let dir = temp_dir();
    let o = conduit(["config", "--defaults"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let defaults = dir.path().join("defaults.toml");
    std::fs::write(&defaults, o.stdout).expect("defaults written");
    let (cfg, warnings) = conduit::config::load(&defaults).expect("the printed defaults load");
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(cfg, Config::default());
    let check = conduit(["config".as_ref(), "--check".as_ref(), defaults.as_os_str()]);
    assert_eq!(check.status.code(), Some(0), "{}", stderr(&check));

    let cube = sample("cube_20mm.stl");
    let plain = slice(dir.path(), "plain", std::slice::from_ref(&cube), &[]);
    let arg = defaults.to_str().expect("UTF-8 path");
    let loaded = slice(dir.path(), "loaded", &[cube], &["-c", arg]);
    assert!(
        plain.gcode == loaded.gcode,
        "slicing with the printed defaults differs from slicing without a config"
    );
}

#[test]
fn unknown_set_key_exits_2_naming_the_key() {
    let dir = temp_dir();
    for key in ["slice.no_such_key", "no_such_section.layer_height"] {
        let set = format!("{key}=1");
        let args = slice_args(
            dir.path(),
            "bad",
            &[sample("cube_20mm.stl")],
            &["--set", &set],
        );
        let o = conduit(&args);
        assert_eq!(o.status.code(), Some(2), "{key}: {}", stderr(&o));
        let err = stderr(&o);
        let last = key.rsplit('.').next().unwrap_or(key);
        assert!(
            err.contains(key) && err.contains(last),
            "{key}: message does not name the key: {err}"
        );
        assert!(
            !dir.path().join("bad.gcode").exists(),
            "{key}: no G-code after a usage error"
        );
    }
}

#[test]
fn check_exits_1_on_cold_extrusion_and_0_on_conduit_output() {
    let dir = temp_dir();
    let cold = dir.path().join("cold.gcode");
    std::fs::write(
        &cold,
        "G21\nG90\nM82\nG28\nG92 E0\nG1 Z0.2 F600\nG1 X50 Y50 F3000\n\
         G1 X70 Y50 E0.7 F1200\nG1 X70 Y70 E1.4\n",
    )
    .expect("written");
    let (code, v) = check_cli(&cold, None);
    assert_eq!(code, Some(1), "{v}");
    assert!(
        v["counts"]["cold_extrusion"].as_u64().unwrap_or(0) >= 1,
        "{v}"
    );
    let plain = conduit(["check".as_ref(), cold.as_os_str()]);
    assert_eq!(plain.status.code(), Some(1));
    assert!(
        stdout(&plain).contains("cold_extrusion"),
        "{}",
        stdout(&plain)
    );

    slice(dir.path(), "cube", &[sample("cube_20mm.stl")], &[]);
    let (code, v) = check_cli(&dir.path().join("cube.gcode"), None);
    assert_eq!(code, Some(0), "{v}");
    assert_eq!(v["errors"], 0);
    assert_eq!(v["warnings"], 0, "{v}");
    assert_eq!(v["stats"]["layers"], 100);
}

/// A 20 mm square island sliced 2 mm high, its regions built into a Program and written: every
/// extrusion re-read from the G-code has the flow of a flat 0.45 × 0.2 bead or of a round
/// 0.4 mm bridge thread (on the internal bridge over the sparse infill, layer 7), and stays
/// inside the island.
#[test]
fn built_program_round_trips_through_the_writer() {
    use conduit::geom::{ExPolygon, Point2, Polygon};
    use conduit::program::e_per_mm;
    use conduit::region::{RegionParams, make_regions};
    use conduit::slice::{SliceParams, layer_schedule};
    use conduit::toolpaths::{ObjectLayers, build_program};
    let island = ExPolygon {
        contour: Polygon::new(vec![
            Point2::from_mm(100.0, 100.0),
            Point2::from_mm(120.0, 100.0),
            Point2::from_mm(120.0, 120.0),
            Point2::from_mm(100.0, 120.0),
        ]),
        holes: vec![],
    };
    let zs = layer_schedule(2.0, &SliceParams::default());
    let regions = make_regions(&vec![vec![island]; zs.len()], &RegionParams::default());
    let obj = ObjectLayers {
        tool: 0,
        layers: zs.into_iter().zip(regions).collect(),
    };
    let mut cfg = Config::default();
    cfg.printer.retract_length = 0.8;
    cfg.printer.retract_before_travel = 2.0;
    cfg.printer.retract_lift = 0.4;
    let program = build_program(&[obj], &Config::default().program_params());
    let mut out = Vec::new();
    let stats = conduit::emit::gcode::write_gcode(&program, &cfg.gcode_params(), &mut out)
        .expect("G-code written");
    let text = String::from_utf8_lossy(&out).into_owned();
    assert_eq!(stats.layers, 10);
    assert_eq!(text.matches(";LAYER_CHANGE\n").count(), 10);
    // Replay the moves after the first layer change (the start G-code's prime line left out).
    let g = conduit_gcode::parse(text.as_bytes()).expect("G-code parses");
    let body = text.lines().position(|l| l == ";LAYER_CHANGE").unwrap_or(0);
    let mut machine = conduit_gcode::Machine::new(conduit_gcode::Firmware::Marlin, 25.0);
    let known = |p: conduit_gcode::Position| p.map(|c| c.unwrap_or(0.0));
    let moves: Vec<(usize, [f64; 3], [f64; 3], f64)> = g
        .lines
        .iter()
        .enumerate()
        .filter_map(|(i, l)| {
            machine
                .step(l)
                .map(|m| (i, known(m.from), known(m.to), m.e))
        })
        .filter(|(i, ..)| *i > body)
        .collect();
    let k = e_per_mm(0.45, 0.2, 1.75);
    let k_bridge = 0.4 * 0.4 / (1.75 * 1.75);
    let mut bridged = 0;
    for (line, from, to, de) in &moves {
        let xy = (to[0] - from[0]).hypot(to[1] - from[1]);
        if *de <= 0.0 || xy <= 0.5 {
            continue;
        }
        let rate = de / xy;
        if (rate - k_bridge).abs() < 1e-4 {
            bridged += 1;
            assert!((to[2] - 1.6).abs() < 1e-9, "line {line}");
        } else {
            assert!((rate - k).abs() < 1e-4, "line {line}");
        }
    }
    assert!(bridged > 10, "{bridged} bridge moves");
    // Everything stays inside the island.
    assert!(
        moves
            .iter()
            .filter(|(_, _, _, de)| *de > 0.0)
            .all(|(_, _, to, _)| (99.9..=120.1).contains(&to[0]))
    );
}

#[test]
fn contours_dropped_from_an_open_mesh_are_a_warning_on_the_terminal() {
    let tmp = temp_dir();
    let dir = tmp.path();
    // The closed 20 mm cube, and beside it a copy without its two x = max triangles: each of
    // the copy's layers is an open chain whose ends are 20 mm apart, too far to close, so it is
    // dropped while the closed cube prints.
    let cube: Vec<[conduit::geom::Point3; 3]> = stl_triangles(&sample("cube_20mm.stl"))
        .iter()
        .map(|t| t.map(|p| conduit::geom::Point3::new(p[0] as f64, p[1] as f64, p[2] as f64)))
        .collect();
    let max_x = cube
        .iter()
        .flat_map(|t| t.iter().map(|p| p.x))
        .fold(f64::MIN, f64::max);
    let shift = conduit::geom::Vector3::new(30.0, 0.0, 0.0);
    let open: Vec<_> = cube
        .iter()
        .filter(|t| !t.iter().all(|p| (p.x - max_x).abs() < 1e-9))
        .map(|t| t.map(|p| p + shift))
        .collect();
    assert_eq!(open.len(), 10, "two facets removed");
    let model = dir.join("open_cube.stl");
    write_stl(&model, &[cube.clone(), open.clone()].concat());
    let out = conduit_env(
        &slice_args(dir, "open", std::slice::from_ref(&model), &[]),
        &[],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let report: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("open.json")).expect("report written"),
    )
    .expect("report is JSON");
    let dropped = report["objects"][0]["slice"]["open_chains_dropped"]
        .as_u64()
        .expect("dropped count in the report");
    assert_eq!(
        dropped, 100,
        "one open chain per 0.2 mm layer of the 20 mm box"
    );
    let err = stderr(&out);
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning: ")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains(&model.display().to_string())
            && warnings[0].contains("100 open contour(s) could not be closed"),
        "{}",
        warnings[0]
    );

    // The open box alone leaves nothing to print: the error says why.
    write_stl(&model, &open);
    let out = conduit_env(
        &slice_args(dir, "open", std::slice::from_ref(&model), &[]),
        &[],
    );
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("nothing to print") && err.contains("100 open contour(s) could not be closed"),
        "{err}"
    );

    // A slab 1 mm thick in y without its x = max face: each layer's chain ends 1 mm apart, so it
    // is closed across that gap and prints, and the terminal says so too.
    let min_y = cube
        .iter()
        .flat_map(|t| t.iter().map(|p| p.y))
        .fold(f64::MAX, f64::min);
    let slab: Vec<[conduit::geom::Point3; 3]> = cube
        .iter()
        .filter(|t| !t.iter().all(|p| (p.x - max_x).abs() < 1e-9))
        .map(|t| t.map(|p| conduit::geom::Point3::new(p.x, p.y.min(min_y + 1.0), p.z)))
        .collect();
    write_stl(&model, &slab);
    let out = conduit_env(
        &slice_args(dir, "slab", std::slice::from_ref(&model), &[]),
        &[],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning: ")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains("100 open contour(s) were closed across a gap of at most 2 mm"),
        "{}",
        warnings[0]
    );
}

/// The header's estimate (`; estimated printing time = … (S s)`) of a file conduit wrote, in s.
fn header_seconds(text: &str) -> f64 {
    let line = text
        .lines()
        .find(|l| l.starts_with("; estimated printing time = "))
        .expect("an estimate in the header");
    let s = line.rsplit('(').next().expect("(S s)");
    s.trim_end_matches(" s)").parse().expect("seconds")
}

#[test]
fn the_header_estimate_is_the_time_check_plans() {
    // One motion model for both, the custom G-code's moves included: the start G-code's homing
    // and prime line, the tool-change snippets' lifts.
    let dir = temp_dir();
    let two_tool = sample("two_tool_printer.toml");
    let two_tool_arg = two_tool.to_string_lossy().into_owned();
    // Name, models, extra arguments, configuration for `check`.
    type Case<'a> = (&'a str, Vec<PathBuf>, Vec<&'a str>, Option<&'a Path>);
    let mut cases: Vec<Case> = vec![
        ("cube", vec![sample("cube_20mm.stl")], vec![], None),
        (
            "bracket",
            vec![sample("l_bracket.obj")],
            vec!["--set", "slice.infill_pattern=grid"],
            None,
        ),
        ("thin", vec![sample("thin_walls.stl")], vec![], None),
        (
            "two_tool",
            vec![sample("l_bracket.obj")],
            vec!["-c", &two_tool_arg],
            Some(&two_tool),
        ),
    ];
    if let Some(corpus) = corpus() {
        let benchy = corpus.join("bench-models/3DBenchy.stl");
        if benchy.exists() {
            cases.push(("benchy", vec![benchy], vec![], None));
        }
    }
    for (name, models, extra, config) in cases {
        let s = slice(dir.path(), name, &models, &extra);
        let header = header_seconds(&s.gcode);
        let (code, v) = check_cli(&dir.path().join(format!("{name}.gcode")), config);
        assert_eq!(code, Some(0), "{name}: {v}");
        let planned = v["stats"]["estimated_time_s"]
            .as_f64()
            .expect("estimated_time_s");
        println!("{name}: header {header} s, check {planned:.1} s");
        // The header rounds to the second.
        assert!(
            (header - planned).abs() <= 1.0,
            "{name}: header {header} s, check {planned} s"
        );
    }
}

/// Per layer (by `;Z:`), the start of every outer-wall loop: the first point of each run of
/// `External perimeter` moves.
fn outer_wall_starts(text: &str) -> BTreeMap<i64, Vec<[f64; 2]>> {
    let r = replay(text);
    let mut starts: BTreeMap<i64, Vec<[f64; 2]>> = BTreeMap::new();
    for run in runs(&r.moves) {
        if run[0].role == "External perimeter" {
            let layer = run[0].layer_um.expect("a layer marker before the walls");
            starts
                .entry(layer)
                .or_default()
                .push([run[0].from[0], run[0].from[1]]);
        }
    }
    starts
}

/// The share of outer-wall starts within 1 mm of an outer-wall start on the layer below.
fn aligned_share(starts: &BTreeMap<i64, Vec<[f64; 2]>>) -> f64 {
    let layers: Vec<&Vec<[f64; 2]>> = starts.values().collect();
    let (mut aligned, mut all) = (0usize, 0usize);
    for pair in layers.windows(2) {
        for p in pair[1] {
            all += 1;
            if pair[0]
                .iter()
                .any(|q| (p[0] - q[0]).hypot(p[1] - q[1]) <= 1.0)
            {
                aligned += 1;
            }
        }
    }
    aligned as f64 / all.max(1) as f64
}

#[test]
fn aligned_seams_line_up_on_every_layer() {
    let dir = temp_dir();
    // The L bracket's outer wall has one inside corner: every layer's seam is there.
    let s = slice(dir.path(), "aligned", &[sample("l_bracket.obj")], &[]);
    let starts = outer_wall_starts(&s.gcode);
    let first = starts.values().next().expect("walls")[0];
    assert!(
        starts.values().all(|l| l.len() == 1 && l[0] == first),
        "{starts:?}"
    );
    assert_eq!(aligned_share(&starts), 1.0);
    // Nearest scatters them; rear lines them up too.
    let nearest = ["--set", "slice.seam_position=nearest"];
    let s = slice(dir.path(), "nearest", &[sample("l_bracket.obj")], &nearest);
    assert!(aligned_share(&outer_wall_starts(&s.gcode)) < 0.9);
    if let Some(corpus) = corpus() {
        let benchy = corpus.join("bench-models/3DBenchy.stl");
        if benchy.exists() {
            let s = slice(dir.path(), "benchy", &[benchy], &[]);
            let share = aligned_share(&outer_wall_starts(&s.gcode));
            println!(
                "3DBenchy: {:.1} % of outer-wall starts aligned",
                share * 100.0
            );
            assert!(share >= 0.85, "{share}");
        }
    }
}

/// Per printed layer, the time `check` plans for its extruding moves, s.
fn extruding_time_per_layer(text: &str) -> Vec<f64> {
    let g = conduit_gcode::parse(text.as_bytes()).expect("G-code parses");
    let report = check(&g, &Config::default().check_params());
    let m = conduit_gcode::moves(&g, Firmware::Marlin);
    let layer_of: BTreeMap<usize, usize> = m
        .moves
        .iter()
        .filter(|mv| mv.extruding)
        .map(|mv| (mv.line, mv.layer))
        .collect();
    let mut per_layer = vec![0.0; m.layer_z.len()];
    for (line, t) in &report.move_times {
        if let Some(&l) = layer_of.get(line) {
            per_layer[l] += t;
        }
    }
    per_layer
}

#[test]
fn short_layers_are_slowed_to_the_minimum_layer_time() {
    // A 6 mm cube: each layer prints in about 2 s at full speed.
    let dir = temp_dir();
    let tris: Vec<[conduit::geom::Point3; 3]> = stl_triangles(&sample("cube_20mm.stl"))
        .iter()
        .map(|t| t.map(|p| conduit::geom::Point3::new(p[0] as f64, p[1] as f64, p[2] as f64)))
        .map(|t| t.map(|p| conduit::geom::Point3::new(p.x * 0.3, p.y * 0.3, p.z * 0.3)))
        .collect();
    let model = dir.path().join("small.stl");
    write_stl(&model, &tris);
    let off = ["--set", "printer.slowdown_below_layer_time=0"];
    let fast = extruding_time_per_layer(
        &slice(dir.path(), "fast", std::slice::from_ref(&model), &off).gcode,
    );
    let slowed = extruding_time_per_layer(&slice(dir.path(), "slow", &[model], &[]).gcode);
    assert_eq!(fast.len(), slowed.len());
    println!("layer times, s: full speed {fast:.2?}, slowed {slowed:.2?}");
    // The first layer (20 mm/s) takes longer than 5 s anyway; the others are quicker.
    assert!(
        fast[0] > 5.0 && fast[1..].iter().all(|&t| t < 4.0),
        "{fast:?}"
    );
    // Those take the 5 s (to within the refinement of the factor), none longer: the slowest
    // moves here (20 mm/s gap fill) stay above min_print_speed when slowed.
    for (l, t) in slowed.iter().enumerate().skip(1) {
        assert!((t - 5.0).abs() < 0.05, "layer {l}: {t} s");
    }
}
