//! Supports and brims end to end, on an overhang probe: a 10 mm post whose left side leans out
//! at 30° from the vertical (needs no support), then at 60° (needs it), with a horizontal arm
//! 10 mm long on its right at 8 mm. Sliced by the binary without and with support; the G-code
//! replayed with `conduit_gcode` and checked by `conduit check`.

use std::path::Path;

use conduit::geom::Point3;
use conduit_gcode::{Firmware, moves, parse};
use serde_json::Value;

use crate::support::{conduit, root, slice_with_report, temp_dir, write_stl};

/// The probe's profile in the XZ plane, counter-clockwise; it is extruded 20 mm along Y.
fn profile() -> Vec<[f64; 2]> {
    let t30 = 4.0 * 30f64.to_radians().tan();
    let t60 = 6.0 * 60f64.to_radians().tan();
    vec![
        [0.0, 0.0],
        [10.0, 0.0],
        [10.0, 8.0],
        [20.0, 8.0],
        [20.0, 10.0],
        [-t30 - t60, 10.0],
        [-t30, 4.0],
    ]
}

/// The probe's triangles: the profile's caps (a fan from the arm's inner corner, from which
/// the whole profile is visible) and its sides, normals outwards.
fn probe() -> Vec<[Point3; 3]> {
    let p = profile();
    let at = |q: [f64; 2], y: f64| Point3::new(q[0], y, q[1]);
    let mut tris = Vec::new();
    let hub = 2;
    for i in 0..p.len() {
        let (a, b) = ((hub + 1 + i) % p.len(), (hub + 2 + i) % p.len());
        if a == hub || b == hub {
            continue;
        }
        tris.push([at(p[hub], 0.0), at(p[a], 0.0), at(p[b], 0.0)]);
        tris.push([at(p[hub], 20.0), at(p[b], 20.0), at(p[a], 20.0)]);
    }
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        tris.push([at(a, 0.0), at(b, 20.0), at(b, 0.0)]);
        tris.push([at(a, 0.0), at(a, 20.0), at(b, 20.0)]);
    }
    tris
}

/// Slices `stl` with `extra` arguments; the G-code and the shift from model to bed X.
fn slice(dir: &Path, stl: &Path, extra: &[&str]) -> (String, f64) {
    let (text, min) = slice_with_report(dir, stl, extra);
    let model_min = profile().iter().map(|q| q[0]).fold(f64::MAX, f64::min);
    (text, min[0] - model_min)
}

/// `conduit check --json` of `gcode`: the number of extrusion_into_air findings.
fn air_findings(dir: &Path, gcode: &str) -> usize {
    let path = dir.join("check.gcode");
    std::fs::write(&path, gcode).expect("write");
    let o = conduit(["check", path.to_str().expect("utf-8"), "--json"]);
    let r: Value = serde_json::from_slice(&o.stdout).expect("check JSON");
    r["counts"]["extrusion_into_air"].as_u64().unwrap_or(0) as usize
}

/// Extruding moves of one role: (x, z) of both ends, model X.
fn role_moves(gcode: &str, shift: f64, role: &str) -> Vec<([f64; 2], [f64; 2])> {
    let parsed = parse(gcode.as_bytes()).expect("G-code parses");
    moves(&parsed, Firmware::Marlin)
        .moves
        .into_iter()
        .filter(|m| m.extruding && m.role.as_deref() == Some(role))
        .filter_map(|m| {
            let (a, b) = ((m.from[0]?, m.from[2]?), (m.to[0]?, m.to[2]?));
            Some(([a.0 - shift, a.1], [b.0 - shift, b.1]))
        })
        .collect()
}

#[test]
fn the_overhang_probe_prints_with_removable_support_and_nothing_over_air() {
    let dir = temp_dir();
    let stl = dir.path().join("probe.stl");
    write_stl(&stl, &probe());
    let sample = root().join("samples/overhangs.stl");
    assert!(
        std::fs::read(&sample).expect("samples/overhangs.stl")
            == std::fs::read(&stl).expect("probe"),
        "samples/overhangs.stl is not the probe this test generates"
    );
    // Without support the arm and the 60° side hang in air, layer after layer.
    let (bare, _) = slice(dir.path(), &stl, &[]);
    let found = air_findings(dir.path(), &bare);
    assert!(found >= 20, "{found} layers over air");
    assert!(role_moves(&bare, 0.0, "Support material").is_empty());

    let (gcode, shift) = slice(dir.path(), &stl, &["--set", "slice.support_material=true"]);
    assert_eq!(air_findings(dir.path(), &gcode), 0);
    let support: Vec<([f64; 2], [f64; 2])> = ["Support material", "Support material interface"]
        .iter()
        .flat_map(|r| role_moves(&gcode, shift, r))
        .collect();
    let ends = || support.iter().flat_map(|(a, b)| [*a, *b]);
    // Under the arm, from the bed up to one empty layer below it (the arm's first layer is
    // 8.0–8.2 mm; support ends with the layer 7.6–7.8, leaving 7.8–8.0 empty)...
    let arm: Vec<[f64; 2]> = ends().filter(|p| p[0] > 10.5).collect();
    assert!(arm.iter().all(|p| p[0] <= 20.0 + 1e-3));
    let top = arm.iter().map(|p| p[1]).fold(f64::MIN, f64::max);
    let bottom = arm.iter().map(|p| p[1]).fold(f64::MAX, f64::min);
    assert!(
        (top - 7.8).abs() < 1e-6 && (bottom - 0.2).abs() < 1e-6,
        "{bottom}–{top}"
    );
    // ... and at least xy_gap + half a bead from the post's wall.
    assert!(
        ends()
            .filter(|p| p[0] > 10.0 && p[1] < 7.9)
            .all(|p| p[0] >= 10.0 + 0.3 + 0.225 - 1e-3)
    );
    // Under the 60° side (left of x = −2.31), up to one empty layer below its top layer.
    let t30 = 4.0 * 30f64.to_radians().tan();
    assert!(ends().any(|p| p[0] < -t30 - 1.0 && p[1] < 4.0));
    assert!(ends().all(|p| p[1] <= 9.6 + 1e-6));
    // The arm's lowest layer lies over the interface, one layer up.
    let arm_plastic = ["External perimeter", "Overhang perimeter"]
        .iter()
        .flat_map(|r| role_moves(&gcode, shift, r))
        .flat_map(|(a, b)| [a, b])
        .filter(|p| p[0] > 12.0)
        .map(|p| p[1])
        .fold(f64::MAX, f64::min);
    assert!((arm_plastic - 8.2).abs() < 1e-6, "{arm_plastic}");
    let interface = role_moves(&gcode, shift, "Support material interface");
    assert!(
        interface
            .iter()
            .any(|(a, _)| a[0] > 10.5 && (a[1] - 7.8).abs() < 1e-6)
    );
}

#[test]
fn a_brim_surrounds_the_first_layer_only() {
    let dir = temp_dir();
    let stl = dir.path().join("probe.stl");
    write_stl(&stl, &probe());
    let (gcode, shift) = slice(dir.path(), &stl, &["--set", "slice.brim_width=4"]);
    let brim = role_moves(&gcode, shift, "Skirt/Brim");
    assert!(!brim.is_empty());
    // On the first layer, outside the post's 10 mm footprint, within the brim's width.
    let xs: Vec<f64> = brim.iter().flat_map(|(a, b)| [a[0], b[0]]).collect();
    assert!(brim.iter().all(|(a, b)| a[1] == 0.2 && b[1] == 0.2));
    let (lo, hi) = xs
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), &x| (l.min(x), h.max(x)));
    // round(4 / 0.407) = 10 loops: the outermost centreline is 0.225 + 9 · 0.407 out.
    // The first layer is cut at z = 0.1, where the 30° side is 0.058 mm out.
    let reach = 0.225 + 9.0 * conduit::region::spacing(0.45, 0.2);
    let left = -0.1 * 30f64.to_radians().tan();
    assert!(
        (lo - left + reach).abs() < 0.01 && (hi - 10.0 - reach).abs() < 0.01,
        "{lo} {hi}"
    );
}

/// Extruding moves with their role, feed (mm/s), model X and Y of both ends and layer z.
struct Stroke {
    role: String,
    speed: f64,
    from: [f64; 2],
    to: [f64; 2],
    z: f64,
}

fn strokes(gcode: &str, shift: f64) -> Vec<Stroke> {
    let parsed = parse(gcode.as_bytes()).expect("G-code parses");
    moves(&parsed, Firmware::Marlin)
        .moves
        .into_iter()
        .filter(|m| m.extruding)
        .filter_map(|m| {
            Some(Stroke {
                role: m.role.as_deref()?.to_owned(),
                speed: m.feed,
                from: [m.from[0]? - shift, m.from[1]?],
                to: [m.to[0]? - shift, m.to[1]?],
                z: m.to[2]?,
            })
        })
        .collect()
}

impl Stroke {
    fn length(&self) -> f64 {
        (self.to[0] - self.from[0]).hypot(self.to[1] - self.from[1])
    }
    /// A move along Y (a side of the probe) longer than `min` mm.
    fn along_y(&self, min: f64) -> bool {
        (self.to[0] - self.from[0]).abs() < 1e-3 && (self.to[1] - self.from[1]).abs() > min
    }
}

#[test]
fn overhanging_walls_slow_down_by_degree_and_the_arm_prints_as_overhang_perimeter() {
    let dir = temp_dir();
    let stl = dir.path().join("probe.stl");
    write_stl(&stl, &probe());
    let no_slowdown = ["--set", "printer.slowdown_below_layer_time=0"];
    let (gcode, shift) = slice(dir.path(), &stl, &no_slowdown);
    let all = strokes(&gcode, shift);
    // The arm's first layer (8.0–8.2 mm) is the only one with perimeters over air: the
    // stretches more than half a nozzle (0.2 mm) beyond the post's wall at x = 10. External
    // loop (centre 0.225 in): the arm's end, 20 − 2 · 0.225 long, and its two sides from
    // x = 10.2 to 19.775; inner loop (centre 0.225 + spacing in): the same at its depth.
    let over: Vec<&Stroke> = all
        .iter()
        .filter(|s| s.role == "Overhang perimeter")
        .collect();
    let odd: Vec<(f64, f64)> = over
        .iter()
        .filter(|s| (s.z - 8.2).abs() > 1e-6 || s.speed != 15.0)
        .map(|s| (s.z, s.speed))
        .collect();
    assert!(!over.is_empty() && odd.is_empty(), "{odd:?}");
    let d1 = 0.225 + conduit::region::spacing(0.45, 0.2);
    let want = (20.0 - 0.45) + 2.0 * (19.775 - 10.2) + (20.0 - 2.0 * d1) + 2.0 * (20.0 - d1 - 10.2);
    let found: f64 = over.iter().map(|s| s.length()).sum();
    assert!((found - want).abs() < 0.1, "{found} mm vs {want} mm");
    // The bridge fan runs around them, and the layer's fan comes back after.
    let lines: Vec<&str> = gcode.lines().collect();
    for (i, l) in lines.iter().enumerate() {
        if *l == ";TYPE:Overhang perimeter" && !lines[i - 1].starts_with(";WIDTH") {
            assert!(lines[..i].iter().rev().find(|l| l.starts_with("M106")) == Some(&"M106 S255"));
        }
    }
    let last_over = lines
        .iter()
        .rposition(|l| *l == ";TYPE:Overhang perimeter")
        .expect("overhang perimeters");
    let after = lines[last_over..]
        .iter()
        .find(|l| l.starts_with("M106"))
        .expect("the fan back to the layer's");
    assert_ne!(*after, "M106 S255");
    // The 60° side leans out 0.2 · tan 60° = 0.346 mm a layer: its external bead rests on
    // 23 % of its width (the 0–25 % band, 15 mm/s); the 30° side leans 0.115 mm, 26 % of the
    // width out (the 50–75 % band, 20 mm/s); the vertical wall at x = 10 keeps the external
    // perimeter's 25 mm/s. Inner perimeters rest on the layer below (45 mm/s).
    let sides = |z0: f64, z1: f64, pick: &dyn Fn(&Stroke) -> bool| -> Vec<f64> {
        all.iter()
            .filter(|s| s.z > z0 && s.z < z1 && s.along_y(15.0) && pick(s))
            .map(|s| s.speed)
            .collect()
    };
    let external = |s: &Stroke| s.role == "External perimeter";
    let left = |s: &Stroke| external(s) && s.from[0] < 0.0;
    let wall = |s: &Stroke| external(s) && (s.from[0] - 9.775).abs() < 1e-3;
    for (z0, z1, speed) in [(4.3, 7.9, 15.0), (0.3, 3.9, 20.0)] {
        let v = sides(z0, z1, &left);
        assert!(
            v.len() > 10 && v.iter().all(|s| *s == speed),
            "{z0}–{z1}: {v:?}"
        );
    }
    let v = sides(0.3, 7.9, &wall);
    assert!(v.len() > 30 && v.iter().all(|s| *s == 25.0), "{v:?}");
    let inner = sides(0.3, 9.9, &|s: &Stroke| s.role == "Perimeter");
    assert!(
        inner.len() > 40 && inner.iter().all(|s| *s == 45.0),
        "{inner:?}"
    );

    // PrusaSlicer 2.5's behaviour (no dynamic speeds): the overhang at the bridge speed, the
    // sides at their own (past the first layer's 20 mm/s).
    let (plain, _) = slice(
        dir.path(),
        &stl,
        &[
            &no_slowdown[..],
            &["--set", "slice.dynamic_overhang_speeds=false"],
        ]
        .concat(),
    );
    let all = strokes(&plain, shift);
    assert!(
        all.iter()
            .filter(|s| s.role == "Overhang perimeter")
            .all(|s| s.speed == 60.0)
    );
    assert!(
        all.iter()
            .filter(|s| s.role == "External perimeter" && s.z > 0.3)
            .all(|s| s.speed == 25.0)
    );
}
