//! Aerosol-jet toolpaths (`conduit jet`): the G-code is replayed and checked against the
//! geometry — the shutter is never open on a travel, closed contours keep their gap, the gap
//! visits every place, the direction reverses once per block, every corner meets the rule
//! table — and the accumulation model is checked against a hand calculation.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use conduit::config::JetSettings;
use conduit::jet::{ModelInput, accumulation};
use conduit_gcode::{Firmware, Machine, Move};
use serde_json::Value;

use crate::support::{conduit, sample, stderr, temp_dir};

const OPEN: &str = "M42 P5 S255 ; shutter open";
const CLOSE: &str = "M42 P5 S0 ; shutter close";

/// One shutter-open stretch of the replay: the moves between an open and a close command.
#[derive(Debug, Default)]
struct Run {
    moves: Vec<Move>,
}

impl Run {
    fn start(&self) -> [f64; 2] {
        xy(&self.moves[0].from)
    }
    fn end(&self) -> [f64; 2] {
        xy(&self.moves[self.moves.len() - 1].to)
    }
    fn z(&self) -> f64 {
        self.moves[0].to[2].unwrap_or(f64::NAN)
    }
    /// Signed area enclosed by the run's path (arcs sampled), mm²: positive counter-clockwise.
    fn signed_area(&self) -> f64 {
        let pts: Vec<[f64; 2]> = std::iter::once(self.start())
            .chain(self.moves.iter().flat_map(|m| {
                m.path
                    .iter()
                    .skip(1)
                    .map(|p| [p[0].unwrap_or(0.0), p[1].unwrap_or(0.0)])
            }))
            .collect();
        let n = pts.len();
        (0..n)
            .map(|i| {
                let (a, b) = (pts[i], pts[(i + 1) % n]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum::<f64>()
            / 2.0
    }
}

fn xy(p: &[Option<f64>; 3]) -> [f64; 2] {
    [p[0].unwrap_or(f64::NAN), p[1].unwrap_or(f64::NAN)]
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Replays `gcode`: the shutter-open runs, and every violation of "closed during travel".
///
/// With `on_the_fly` (a shutter lead time), the close command comes before the path's end: the
/// moves after it at the jetting feed, up to the next travel, still belong to the run.
fn replay(gcode: &[u8], travel_speed: f64, on_the_fly: bool) -> (Vec<Run>, Vec<String>) {
    let g = conduit_gcode::parse(gcode).expect("the G-code parses");
    let mut r = Machine::new(Firmware::Marlin, 25.0);
    let mut open = false;
    let mut closing = false;
    let mut runs = Vec::new();
    let mut cur = Run::default();
    let mut problems = Vec::new();
    for line in &g.lines {
        let text = String::from_utf8_lossy(&line.text).trim().to_owned();
        if text == OPEN {
            assert!(!open, "shutter opened twice");
            open = true;
            continue;
        }
        if text == CLOSE {
            if open && !cur.moves.is_empty() {
                if on_the_fly {
                    closing = true;
                } else {
                    runs.push(std::mem::take(&mut cur));
                }
            }
            open = false;
            continue;
        }
        if let Some(m) = r.step(line) {
            if closing && m.has_xy {
                if (m.feed - travel_speed).abs() > 1e-9 {
                    cur.moves.push(m);
                    continue;
                }
                closing = false;
                runs.push(std::mem::take(&mut cur));
            }
            if !m.has_xy {
                if open {
                    problems.push(format!("line {}: Z move with the shutter open", m.line));
                }
                continue;
            }
            if open && (m.feed - travel_speed).abs() < 1e-9 {
                problems.push(format!("line {}: travel with the shutter open", m.line));
            }
            if !open && m.e > 0.0 {
                problems.push(format!("line {}: printing with the shutter closed", m.line));
            }
            if open {
                cur.moves.push(m);
            }
        }
    }
    assert!(!open, "the job ends with the shutter open");
    if closing {
        runs.push(cur);
    }
    (runs, problems)
}

/// The star of `samples/jet/star8.svg`: 8 points on a 1 mm circle about (1.5, 1.5), inner
/// corners at ρ = sin 15° / sin 142.5° (law of sines in the triangle centre–tip–inner corner
/// with angles 22.5°, 15°, 142.5°), which makes the tips 30° and the inner corners 75°.
fn star_vertices() -> Vec<[f64; 2]> {
    let rho = 15f64.to_radians().sin() / 142.5f64.to_radians().sin();
    (0..16)
        .map(|k| {
            let a = (90.0 + 22.5 * k as f64).to_radians();
            let r = if k % 2 == 0 { 1.0 } else { rho };
            [1.5 + r * a.cos(), 1.5 + r * a.sin()]
        })
        .collect()
}

/// Index of the star edge `p` lies on (within `tol`), with its distance from the edge's ends.
fn star_edge(p: [f64; 2], tol: f64) -> Option<(usize, f64)> {
    let v = star_vertices();
    (0..16).find_map(|i| {
        let (a, b) = (v[i], v[(i + 1) % 16]);
        let len = dist(a, b);
        let (ux, uy) = ((b[0] - a[0]) / len, (b[1] - a[1]) / len);
        let t = (p[0] - a[0]) * ux + (p[1] - a[1]) * uy;
        let off = ((p[0] - a[0]) * uy - (p[1] - a[1]) * ux).abs();
        (off < tol && t > 0.0 && t < len).then_some((i, t.min(len - t)))
    })
}

/// Turn at the junction of two moves, degrees: the direction change from the end of `a` to
/// the start of `b` (tangents from the sampled paths).
fn junction_turn(a: &Move, b: &Move) -> f64 {
    let n = a.path.len();
    let (p, q) = (xy(&a.path[n - 2]), xy(&a.path[n - 1]));
    let (r, s) = (xy(&b.path[0]), xy(&b.path[1]));
    let d1 = [q[0] - p[0], q[1] - p[1]];
    let d2 = [s[0] - r[0], s[1] - r[1]];
    (d1[0] * d2[1] - d1[1] * d2[0])
        .abs()
        .atan2(d1[0] * d2[0] + d1[1] * d2[1])
        .to_degrees()
}

/// Radius and sweep (degrees) of an arc move from its sampled path (exact points on the arc
/// the firmware runs): circumradius of its first, middle and last samples.
fn arc_radius_and_sweep(m: &Move) -> (f64, f64) {
    let n = m.path.len();
    let (a, b, c) = (xy(&m.path[0]), xy(&m.path[n / 2]), xy(&m.path[n - 1]));
    let area2 = ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs();
    let r = dist(a, b) * dist(b, c) * dist(c, a) / (2.0 * area2);
    let sweep = (m.length / r).to_degrees();
    (r, sweep)
}

fn run_jet(dir: &Path, designs: &[PathBuf], layers: u32, extra: &[&str]) -> (Vec<u8>, Value) {
    let out = dir.join("out.gcode");
    let report = dir.join("out.json");
    let mut args: Vec<String> = vec!["jet".into()];
    args.extend(designs.iter().map(|d| d.display().to_string()));
    for a in [
        "--width",
        "20",
        "--layers",
        &layers.to_string(),
        "--layer-height",
        "5",
        "-o",
        out.to_str().unwrap_or_default(),
        "--report",
        report.to_str().unwrap_or_default(),
    ] {
        args.push(a.to_owned());
    }
    args.extend(extra.iter().map(|s| (*s).to_owned()));
    let o = conduit(&args);
    assert!(o.status.success(), "conduit jet failed: {}", stderr(&o));
    let gcode = std::fs::read(&out).expect("G-code written");
    let json: Value =
        serde_json::from_slice(&std::fs::read(&report).expect("report written")).expect("JSON");
    (gcode, json)
}

#[test]
fn star_gets_fillets_moving_gaps_one_reversal_and_a_closed_shutter_on_travel() {
    let dir = temp_dir();
    let (gcode, report) = run_jet(dir.path(), &[sample("jet/star8.svg")], 32, &[]);
    let travel = JetSettings::default().travel_speed;
    let (runs, problems) = replay(&gcode, travel, false);
    assert!(problems.is_empty(), "{problems:#?}");
    assert_eq!(runs.len(), 32, "one shutter cycle per layer");
    let w = 0.02;
    let gap = JetSettings::default().gap;
    let mut places = Vec::new();
    for (k, run) in runs.iter().enumerate() {
        assert!((run.z() - 0.005 * (k + 1) as f64).abs() < 1e-9);
        // The gap: start and end 10 µm apart (1 µm output grid) on the same straight edge,
        // at least a line width plus the gap from its corners.
        let (s, e) = (run.start(), run.end());
        assert!(
            (dist(s, e) - gap).abs() < 0.002,
            "layer {k}: gap {}",
            dist(s, e)
        );
        let (es, ds) = star_edge(s, 0.002).expect("start on an edge");
        let (ee, de) = star_edge(e, 0.002).expect("end on an edge");
        assert_eq!(es, ee, "layer {k}: start and end on different edges");
        assert!(ds.min(de) > w, "layer {k}: gap {ds} mm from a corner");
        places.push(es);
        // Corners: no junction is a sharp corner (an unfilleted corner the rules cover has
        // θ < 90°, a turn over 90°; fillets leave kinks of a few degrees from the 1 µm output
        // grid on 10–20 µm radii), every arc meets the rule for the corner it rounds
        // (θ = 180° − sweep).
        for pair in run.moves.windows(2) {
            let turn = junction_turn(&pair[0], &pair[1]);
            assert!(
                turn < 45.0,
                "layer {k} line {}: a {turn:.1}° kink",
                pair[1].line
            );
        }
        let arcs: Vec<(f64, f64)> = run
            .moves
            .iter()
            .filter(|m| m.arc)
            .map(arc_radius_and_sweep)
            .collect();
        assert_eq!(arcs.len(), 16, "layer {k}: one fillet per corner");
        for (r, sweep) in &arcs {
            let theta = 180.0 - sweep;
            let needed = if theta < 45.0 { w } else { w / 2.0 };
            // 1 µm output grid on the arc's ends and centre offset.
            assert!(*r >= needed - 0.0015, "layer {k}: r {r} for θ {theta:.1}°");
        }
        let outer = arcs.iter().filter(|(_, s)| (s - 150.0).abs() < 8.0).count();
        let inner = arcs.iter().filter(|(_, s)| (s - 105.0).abs() < 8.0).count();
        assert_eq!((outer, inner), (8, 8), "layer {k}: {arcs:?}");
    }
    // 16 gap places on 16 different edges, then the same again.
    let mut first: Vec<usize> = places[..16].to_vec();
    first.sort_unstable();
    first.dedup();
    assert_eq!(first.len(), 16, "{places:?}");
    assert_eq!(places[..16], places[16..]);
    // Direction: counter-clockwise or clockwise by block, one reversal.
    let signs: Vec<bool> = runs.iter().map(|r| r.signed_area() > 0.0).collect();
    let reversals = signs.windows(2).filter(|p| p[0] != p[1]).count();
    assert_eq!(reversals, 1);
    assert!(signs[..16].iter().all(|&s| s == signs[0]));
    // The report agrees.
    assert_eq!(report["direction_reversals"], 1);
    let corners = report["structures"][0]["corners"]
        .as_array()
        .expect("corners");
    assert_eq!(corners.len(), 16);
    for c in corners {
        let angle = c["angle_deg"].as_f64().unwrap_or(f64::NAN);
        let r = c["radius_um"].as_f64().unwrap_or(f64::NAN);
        if (angle - 30.0).abs() < 1e-3 {
            assert!(r >= 20.0 - 1e-9, "{c}");
        } else {
            assert!((angle - 75.0).abs() < 1e-3, "{c}");
            assert!(r >= 10.0 - 1e-9, "{c}");
        }
    }
    // conduit check sees 32 printed layers and no problems.
    let path = dir.path().join("out.gcode");
    let o = conduit(["check", path.to_str().unwrap_or_default(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let check: Value = serde_json::from_slice(&o.stdout).expect("check JSON");
    assert_eq!(check["stats"]["layers"], 32, "{check}");
}

#[test]
fn flattened_fillets_and_shutter_lead_time() {
    let dir = temp_dir();
    let (gcode, _) = run_jet(
        dir.path(),
        &[sample("jet/star8.svg")],
        2,
        &[
            "--set",
            "jet.arcs=false",
            "--set",
            "jet.shutter_lead_time=0.01",
        ],
    );
    let text = String::from_utf8_lossy(&gcode);
    assert!(
        !text
            .lines()
            .any(|l| l.starts_with("G2 ") || l.starts_with("G3 "))
    );
    let s = JetSettings::default();
    let (runs, problems) = replay(&gcode, s.travel_speed, true);
    assert!(problems.is_empty(), "{problems:#?}");
    assert_eq!(runs.len(), 2);
    for run in &runs {
        // The shutter opens lead × speed = 0.01 s × 2 mm/s = 20 µm before the start: a first
        // move without E, then the path.
        let lead = &run.moves[0];
        assert_eq!(lead.e, 0.0);
        assert!((lead.length - 0.02).abs() < 0.0015, "{}", lead.length);
        // E is the jetted length; the star's filleted perimeter minus the gap is about 9.2 mm.
        let printed: f64 = run.moves.iter().filter(|m| m.e > 0.0).map(|m| m.e).sum();
        let length: f64 = run
            .moves
            .iter()
            .filter(|m| m.e > 0.0)
            .map(|m| m.length)
            .sum();
        assert!(
            (printed - length).abs() < 0.01 && printed > 9.0,
            "{printed} {length}"
        );
        // Flattened fillets: no kink sharper than the chords of a 0.5 µm-tolerance arc.
        for pair in run.moves[1..].windows(2) {
            assert!(junction_turn(&pair[0], &pair[1]) < 60.0);
        }
    }
}

#[test]
fn dog_outline_reports_the_rule_for_every_corner() {
    let dir = temp_dir();
    let (_, report) = run_jet(dir.path(), &[sample("jet/dog.svg")], 2, &[]);
    let corners = report["structures"][0]["corners"]
        .as_array()
        .expect("corners");
    assert_eq!(corners.len(), 19);
    let angles: Vec<f64> = corners
        .iter()
        .map(|c| c["angle_deg"].as_f64().unwrap_or(f64::NAN))
        .collect();
    let min = angles.iter().copied().fold(f64::MAX, f64::min);
    let max = angles.iter().copied().fold(f64::MIN, f64::max);
    assert!(
        (min - 26.0).abs() < 1e-3 && (max - 175.0).abs() < 1e-3,
        "{min} {max}"
    );
    for c in corners {
        let angle = c["angle_deg"].as_f64().unwrap_or(f64::NAN);
        let (want_action, want_r) = if angle < 15.0 {
            ("split", 0.0)
        } else if angle < 45.0 {
            ("fillet", 20.0)
        } else if angle < 90.0 {
            ("fillet", 10.0)
        } else {
            ("none", 0.0)
        };
        assert_eq!(c["action"], want_action, "{c}");
        assert!((c["required_radius_um"].as_f64().unwrap_or(-1.0) - want_r).abs() < 1e-9);
        let r = c["radius_um"].as_f64().unwrap_or(-1.0);
        let shrunk = c["shrunk"].as_bool().unwrap_or(true);
        assert!(shrunk || r >= want_r - 1e-9, "{c}");
        assert!(c["predicted_difference_um"].is_number() || c["model_error"].is_string());
    }
}

#[test]
fn structures_are_printed_layer_by_layer_in_turn_and_dxf_is_read() {
    let dir = temp_dir();
    // A 1 mm square as a DXF LWPOLYLINE, beside the star.
    let dxf = dir.path().join("square.dxf");
    std::fs::write(
        &dxf,
        "0\nSECTION\n2\nENTITIES\n0\nLWPOLYLINE\n5\nSQ\n90\n4\n70\n1\n\
         10\n4\n20\n1\n10\n5\n20\n1\n10\n5\n20\n2\n10\n4\n20\n2\n0\nENDSEC\n0\nEOF\n",
    )
    .expect("write");
    let (gcode, report) = run_jet(dir.path(), &[sample("jet/star8.svg"), dxf.clone()], 3, &[]);
    let (runs, problems) = replay(&gcode, JetSettings::default().travel_speed, false);
    assert!(problems.is_empty(), "{problems:#?}");
    assert_eq!(runs.len(), 6);
    for (i, run) in runs.iter().enumerate() {
        assert!((run.z() - 0.005 * (i / 2 + 1) as f64).abs() < 1e-9);
        let on_star = star_edge(run.start(), 0.002).is_some();
        assert_eq!(on_star, i % 2 == 0, "run {i} starts at {:?}", run.start());
    }
    let square = &report["structures"][1];
    assert_eq!(square["name"], "square.dxf#SQ");
    assert_eq!(square["corners"].as_array().map(Vec::len), Some(4));
}

#[test]
fn bad_designs_fail_with_the_file_named_and_write_nothing() {
    let dir = temp_dir();
    let bad = dir.path().join("bad.dxf");
    std::fs::write(
        &bad,
        "0\nSECTION\n2\nENTITIES\n0\nLINE\n10\nx\n20\n0\n11\n1\n21\n0\n0\nENDSEC\n0\nEOF\n",
    )
    .expect("write");
    let out = dir.path().join("o.gcode");
    std::fs::write(dir.path().join("x.txt"), "not a design").expect("write");
    for (design, want) in [
        (
            bad.clone(),
            "bad.dxf: line 8: LINE: group 10 must be a number",
        ),
        (dir.path().join("missing.svg"), "missing.svg"),
        (dir.path().join("x.txt"), "unknown design format"),
    ] {
        let o = conduit([
            "jet",
            design.to_str().unwrap_or_default(),
            "--width",
            "20",
            "--layers",
            "2",
            "--layer-height",
            "5",
            "-o",
            out.to_str().unwrap_or_default(),
        ]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains(want), "{}", stderr(&o));
        assert!(!out.exists());
    }
    // A filament tool cannot jet.
    let o = conduit([
        "jet",
        sample("jet/star8.svg").to_str().unwrap_or_default(),
        "--width",
        "20",
        "--layers",
        "2",
        "--layer-height",
        "5",
        "--set",
        "jet.tool=0",
        "-o",
        out.to_str().unwrap_or_default(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("jet.tool = 0"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn accumulation_model_matches_the_hand_calculation() {
    // θ = 30°, r = 0, w = 35 µm, h = 14 µm, l_ROI = 150 µm, 100 strips at the midpoints
    // l = ±(j + ½)·0.35 µm, j = 0..49, so Σ|l| over each half = 0.35·(1225 + 25) = 437.5 µm.
    // Inner strips (l > 0 ≥ r): R = 0, Δ = 150 − 2l/tan 15°
    //   L_in = 50·150 − 2·437.5/0.2679492 = 7500 − 3265.5444 = 4234.4556.
    // Outer strips (l < 0): R = −l, Δ = 150 + |l|·(π − π/6)
    //   L_out = 7500 + 437.5·2.6179939 = 7500 + 1145.3723 = 8645.3723.
    // L_in + L_out = 12879.8279; d_in = 12879.8279 / 8468.9111 = 1.520836,
    // d_out = 12879.8279 / 17290.7446 = 0.744897,
    // h_in − h_out = 14·(1.520836 − 0.744897) = 10.8631 µm.
    let base = ModelInput {
        angle_deg: 30.0,
        radius: 0.0,
        width: 35.0,
        height: 14.0,
        roi: 150.0,
    };
    let m = accumulation(&base).expect("model");
    assert!((m.l_in - 4234.4556).abs() < 1e-3, "{m:?}");
    assert!((m.l_out - 8645.3723).abs() < 1e-3, "{m:?}");
    assert!((m.difference - 10.8631).abs() < 1e-3, "{m:?}");
    // Falls as r grows, and levels off once every strip turns on an arc (r ≥ w/2).
    let at_r = |r: f64| {
        accumulation(&ModelInput { radius: r, ..base })
            .expect("model")
            .difference
    };
    let rs = [0.0, 5.0, 10.0, 15.0, 17.5, 25.0, 35.0];
    for p in rs.windows(2) {
        let (a, b) = (at_r(p[0]), at_r(p[1]));
        if p[1] <= 17.5 {
            assert!(b < a, "r {} → {}: {a} → {b}", p[0], p[1]);
        } else {
            assert!((a - b).abs() < 1e-9, "r {} → {}: {a} vs {b}", p[0], p[1]);
        }
    }
    // Levelled value: L_in,out = 50·l_ROI ∓ Σ|l|·(π − θ).
    let s = 437.5 * (PI - PI / 6.0);
    let want = 14.0 * ((7500.0 + 7500.0) / (2.0 * (7500.0 - s)) - 15000.0 / (2.0 * (7500.0 + s)));
    assert!((at_r(25.0) - want).abs() < 1e-9);
    // Falls as the region of interest grows and as θ opens towards 180°.
    let at = |roi: f64, angle: f64| {
        accumulation(&ModelInput {
            roi,
            angle_deg: angle,
            ..base
        })
        .expect("model")
        .difference
    };
    for p in [150.0, 200.0, 300.0, 600.0].windows(2) {
        assert!(at(p[1], 30.0) < at(p[0], 30.0));
    }
    for p in [30.0, 60.0, 90.0, 135.0, 170.0, 180.0].windows(2) {
        assert!(at(150.0, p[1]) < at(150.0, p[0]));
    }
    assert!(at(150.0, 180.0).abs() < 1e-9);
}

#[test]
fn model_subcommand_prints_the_prediction() {
    let o = conduit([
        "jet", "model", "--angle", "30", "--radius", "0", "--width", "35", "--height", "14",
        "--roi", "150", "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).expect("JSON");
    let d = v[0]["result_um"]["difference"].as_f64().unwrap_or(f64::NAN);
    assert!((d - 10.8631).abs() < 1e-3);
    let p = v[0]["predicted_difference_um"].as_f64().unwrap_or(f64::NAN);
    assert!((p - d * JetSettings::default().leveling_factor).abs() < 1e-12);
    let o = conduit([
        "jet", "model", "--angle", "30", "--width", "35", "--height", "14", "--roi", "150..300",
        "--steps", "3",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(crate::support::stdout(&o).lines().count(), 5);
}
