//! Gap compensation (`conduit compensate`) and calibration patterns (`conduit compensate
//! pattern`): simulated measure → compensate loops on a hemisphere, a cylinder and a wavy plane
//! under a robot error model, patterns checked against the analytic surfaces, and a command
//! line round trip with bad inputs refused.
//!
//! "A 30 mm hemisphere" and "a 30 mm cylinder" are read as 30 mm in diameter: `sphere:15` and
//! `cylinder:15`. The circle of 10 mm is 10 mm across.

use std::f64::consts::PI;
use std::path::Path;

use conduit::robot::compensate::frame;
use conduit::robot::compensate::simulate::{self, ErrorModel};
use conduit::robot::compensate::substrate::{Analytic, Substrate, Waviness};
use conduit::robot::compensate::{Params, Path as PosePath};
use conduit::robot::pattern::{self, PatternParams, Shape};
use conduit_poses::{Pose, read_poses};
use serde_json::Value;

use crate::support::{conduit, stderr, temp_dir};

const GAP: f64 = 0.05;
const WAVY: Waviness = Waviness {
    amplitude: 0.04,
    period: 5.0,
};

fn circle(on: &Substrate) -> Vec<Pose> {
    pattern::pattern(
        on,
        &PatternParams {
            shape: Shape::Circle,
            size: 10.0,
            at: [0.0, 0.0],
            spacing: 0.1,
            pitch: 1.0,
            gap: GAP,
            tangent: false,
        },
    )
    .expect("the circle lies on the surface")
}

fn params(smoothing: f64) -> Params {
    Params {
        target: GAP,
        sensor_angle: 0.0,
        smoothing,
    }
}

/// The published error magnitudes: 3 mm / 1.5 mm centre shift, 0.5° orientation error.
fn published(noise: f64) -> ErrorModel {
    ErrorModel {
        shift: [3.0, 1.5, 0.0],
        tilt: 0.5,
        axis: [1.0, 0.0, 0.0],
        z: 0.0,
        noise,
        seed: 7,
    }
}

#[test]
fn two_passes_bring_the_gap_variation_within_40_um_on_three_surfaces() {
    let surfaces = [
        ("hemisphere 30 mm", Analytic::Sphere(15.0)),
        ("cylinder 30 mm", Analytic::Cylinder(15.0)),
        ("plane, 40 µm waviness", Analytic::Plane(Some(WAVY))),
    ];
    for (name, a) in surfaces {
        let s = Substrate::Analytic(a);
        let path = PosePath::from_poses(circle(&s));
        let sim = simulate::run(&path, &s, &published(0.002), &params(0.5), 2).expect("simulates");
        let [u, p1, p2] = [
            sim.uncompensated.variation,
            sim.passes[0].after.variation,
            sim.passes[1].after.variation,
        ]
        .map(|v| v * 1e3);
        println!(
            "{name}: gap variation uncompensated {u:.1} µm, after pass 1 {p1:.1} µm, after pass 2 {p2:.1} µm"
        );
        assert!(u > 100.0, "{name}: the error model should matter ({u} µm)");
        assert!(p2 <= 40.0, "{name}: {p2} µm after two passes");
        assert!(p2 < u / 5.0 && p1 < u / 5.0, "{name}: {u} {p1} {p2}");
        // The mean gap comes to the target too.
        assert!((sim.passes[1].after.mean - GAP).abs() < 0.005);
    }
}

#[test]
fn simulated_gaps_of_a_shifted_sphere_are_the_line_sphere_intersections() {
    // Tip p = (R + g)·n, measured along −n to the sphere of radius R centred at c: with
    // u = R + g − t, u² − 2u(n·c) + |c|² − R² = 0, so u = n·c + √((n·c)² − |c|² + R²).
    let r = 15.0;
    let s = Substrate::Analytic(Analytic::Sphere(r));
    let path = PosePath::from_poses(circle(&s));
    let model = ErrorModel {
        tilt: 0.0,
        z: 0.02,
        ..published(0.0)
    };
    let c = nalgebra::Vector3::from(model.shift);
    let placement = model.placement(&nalgebra::Point3::origin());
    let gaps = simulate::true_gaps(&path, &s, &placement, model.z).expect("hits");
    for (p, g) in path.poses.iter().zip(&gaps) {
        let tip = nalgebra::Vector3::from(p.position);
        let n = tip.normalize();
        let nc = n.dot(&c);
        let u = nc + (nc * nc - c.norm_squared() + r * r).sqrt();
        let want = tip.norm() - u + model.z;
        assert!((g - want).abs() < 1e-9, "{g} vs {want}");
    }
}

#[test]
fn smoothing_keeps_sensor_noise_out_of_the_path() {
    // A flat plane and no robot error: whatever the path picks up is the sensor's 5 µm noise.
    let s = Substrate::Analytic(Analytic::Plane(None));
    let path = PosePath::from_poses(circle(&s));
    let model = ErrorModel {
        shift: [0.0; 3],
        tilt: 0.0,
        ..published(0.005)
    };
    let after = |sigma| {
        let sim = simulate::run(&path, &s, &model, &params(sigma), 2).expect("simulates");
        sim.passes[1].after.variation * 1e3
    };
    let (raw, smooth) = (after(0.0), after(0.5));
    println!(
        "5 µm sensor noise: path gap variation {raw:.1} µm unsmoothed, {smooth:.1} µm smoothed (σ 0.5 mm)"
    );
    // Two passes of raw noise: about √2·5 µm standard deviation over 316 points.
    assert!(raw > 20.0 && smooth < raw / 3.0, "{raw} {smooth}");
}

/// The surface point under a pose (tip moved by the gap into the work) and the unit
/// direction into the work.
fn foot(p: &Pose) -> (nalgebra::Vector3<f64>, nalgebra::Vector3<f64>) {
    let d = frame::into_work(p.quaternion);
    (nalgebra::Vector3::from(p.position) + d * GAP, d)
}

/// Checks that every pose sits at the gap above `a` with its tool along the inward normal:
/// the foot on the surface within 1 µm, the direction within `dir_tol`.
fn check_on(a: Analytic, poses: &[Pose], what: &str, dir_tol: f64) {
    assert!(poses.len() > 10, "{what}");
    for (i, p) in poses.iter().enumerate() {
        let (q, d) = foot(p);
        let (off, normal) = match a {
            Analytic::Sphere(r) => (q.norm() - r, q.normalize()),
            Analytic::Cylinder(r) => {
                let xz = nalgebra::Vector3::new(q.x, 0.0, q.z);
                (xz.norm() - r, xz.normalize())
            }
            Analytic::Plane(w) => {
                let w = w.unwrap_or(Waviness {
                    amplitude: 0.0,
                    period: 1.0,
                });
                let k = 2.0 * PI / w.period;
                let h = w.amplitude * (k * q.x).sin();
                let slope = w.amplitude * k * (k * q.x).cos();
                // Vertical offset times the cosine of the slope is the distance to first order.
                let n = nalgebra::Vector3::new(-slope, 0.0, 1.0).normalize();
                ((q.z - h) * n.z, n)
            }
        };
        assert!(off.abs() < 1e-3, "{what} {i}: {off} mm off the surface");
        assert!(
            (d + normal).norm() < dir_tol,
            "{what} {i}: {d:?} vs −{normal:?}"
        );
    }
}

#[test]
fn patterns_sit_at_the_gap_along_the_normal_of_analytic_surfaces() {
    let surfaces = [
        Analytic::Sphere(15.0),
        Analytic::Cylinder(15.0),
        Analytic::Plane(Some(WAVY)),
    ];
    for a in surfaces {
        let s = Substrate::Analytic(a);
        for shape in [Shape::Circle, Shape::Spiral, Shape::Serpentine] {
            for tangent in [false, true] {
                let p = PatternParams {
                    shape,
                    size: 8.0,
                    at: [2.0, 1.0],
                    spacing: 0.2,
                    pitch: 1.0,
                    gap: GAP,
                    tangent,
                };
                let poses = pattern::pattern(&s, &p).expect("on the surface");
                check_on(
                    a,
                    &poses,
                    &format!("{a:?} {shape:?} tangent {tangent}"),
                    1e-9,
                );
                if !tangent && shape == Shape::Circle {
                    // Top view: the feet are the circle's points dropped along −z.
                    for q in poses.iter().map(|p| foot(p).0) {
                        assert!(((q.x - 2.0).hypot(q.y - 1.0) - 4.0).abs() < 1e-9);
                    }
                }
            }
        }
    }
    // In the tangent plane at (8, 0) of the sphere, a circle keeps its radius in that plane.
    let s = Substrate::Analytic(Analytic::Sphere(15.0));
    let p = PatternParams {
        shape: Shape::Circle,
        size: 6.0,
        at: [8.0, 0.0],
        spacing: 0.1,
        pitch: 1.0,
        gap: GAP,
        tangent: true,
    };
    let poses = pattern::pattern(&s, &p).expect("on the sphere");
    let c = nalgebra::Vector3::new(8.0, 0.0, (225.0f64 - 64.0).sqrt());
    let n0 = c.normalize();
    for q in poses.iter().map(|p| foot(p).0) {
        let v = q - c;
        let across = v - n0 * n0.dot(&v);
        assert!((across.norm() - 3.0).abs() < 1e-9, "{}", across.norm());
    }
}

fn run_ok(args: &[&str]) -> String {
    let o = conduit(args);
    assert!(
        o.status.success(),
        "conduit {args:?} failed: {}",
        stderr(&o)
    );
    stderr(&o)
}

fn poses_of(path: &Path) -> Vec<Pose> {
    read_poses(&std::fs::read_to_string(path).expect("written")).expect("a pose table")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap_or_default()
}

#[test]
fn pattern_simulate_compensate_round_trip_on_the_command_line() {
    let dir = temp_dir();
    let d = dir.path();
    let (path, sim, gaps, out, rep, rep2) = (
        d.join("path.csv"),
        d.join("sim.csv"),
        d.join("gaps.csv"),
        d.join("out.csv"),
        d.join("sim.json"),
        d.join("out.json"),
    );
    run_ok(&[
        "compensate",
        "pattern",
        "circle",
        "--size",
        "10",
        "--surface",
        "sphere:15",
        "-o",
        s(&path),
    ]);
    let nominal = poses_of(&path);
    // Positions are written with 4 decimals: the normal from them is good to about 1e-5.
    check_on(Analytic::Sphere(15.0), &nominal, "CLI circle", 2e-5);
    let simulate = |out: &Path, report: &Path| {
        run_ok(&[
            "compensate",
            s(&path),
            "--simulate",
            "sphere:15",
            "--shift",
            "3,1.5,0",
            "--tilt",
            "0.5",
            "--noise",
            "2",
            "--sensor-angle",
            "20",
            "--passes",
            "1",
            "--readings-out",
            s(&gaps),
            "-o",
            s(out),
            "--report",
            s(report),
        ])
    };
    let said = simulate(&sim, &rep);
    assert!(said.contains("after pass 1"), "{said}");
    let first = std::fs::read(&sim).expect("written");
    // Same input, same bytes.
    simulate(&d.join("again.csv"), &d.join("again.json"));
    assert_eq!(first, std::fs::read(d.join("again.csv")).expect("written"));
    let report: Value =
        serde_json::from_slice(&std::fs::read(&rep).expect("report")).expect("JSON");
    let v = report["variation_um"].as_array().expect("variations");
    assert_eq!(v.len(), 2);
    // The measured readings, compensated by hand on the command line, give the same path.
    run_ok(&[
        "compensate",
        s(&path),
        "--gaps",
        s(&gaps),
        "--sensor-angle",
        "20",
        "-o",
        s(&out),
        "--report",
        s(&rep2),
        "--program",
        s(&d.join("out.script")),
        "--dialect",
        "urscript",
    ]);
    let (a, b) = (poses_of(&sim), poses_of(&out));
    // The same path as the next robot program: every compensated pose is a URScript target
    // (within its 1 µm), its tool frame the table's.
    let script = std::fs::read_to_string(d.join("out.script")).expect("program written");
    let (targets, switches) =
        crate::robot::read_urscript(&script, &nalgebra::Isometry3::identity());
    assert_eq!(
        switches,
        vec![true, false],
        "one dispensing run: on, then off"
    );
    for p in &b {
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            p.quaternion[0],
            p.quaternion[1],
            p.quaternion[2],
            p.quaternion[3],
        ));
        let at = conduit::geom::Point3::new(p.position[0], p.position[1], p.position[2]);
        assert!(
            targets.iter().any(|t| (t.position - at).norm() < 2e-3
                && t.rotation.angle_to(&q.to_rotation_matrix()) < 1e-5),
            "{p:?} not in the program"
        );
    }
    assert_eq!(a.len(), nominal.len());
    assert_eq!(a.len(), b.len());
    for ((p, q), n) in a.iter().zip(&b).zip(&nominal) {
        for k in 0..3 {
            assert!((p.position[k] - q.position[k]).abs() <= 1.5e-4);
        }
        // Orientations are kept (up to the 9 decimals of the table).
        assert!((0..4).all(|k| (q.quaternion[k] - n.quaternion[k]).abs() < 1e-8));
        assert_eq!(q.dispense, n.dispense);
    }
    // The report's statistics are those of the readings times cos 20°.
    let text = std::fs::read_to_string(&gaps).expect("gaps");
    let t = conduit_poses::Table::parse(&text).expect("a table");
    let col = t.column("reading").expect("reading column");
    let l: Vec<f64> = t
        .rows
        .iter()
        .map(|r| r[col] * 20f64.to_radians().cos())
        .collect();
    let (lo, hi) = l
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(*x), b.max(*x)));
    let r2: Value = serde_json::from_slice(&std::fs::read(&rep2).expect("report")).expect("JSON");
    let before = &r2["before_mm"];
    assert!((before["variation"].as_f64().unwrap_or(f64::NAN) - (hi - lo)).abs() < 1e-9);
    assert_eq!(r2["placed_by"], "index");
    // The compensated path measures (nearly) flat: simulating it again without noise.
    let o = conduit([
        "compensate",
        s(&out),
        "--simulate",
        "sphere:15",
        "--shift",
        "3,1.5,0",
        "--tilt",
        "0.5",
        "--passes",
        "1",
        "-o",
        s(&d.join("check.csv")),
        "--report",
        s(&d.join("check.json")),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let check: Value =
        serde_json::from_slice(&std::fs::read(d.join("check.json")).expect("report"))
            .expect("JSON");
    // The orientation error turns about the middle of the path it is given, which moved a
    // little: the second run's real surface is not quite the first's, so only roughly flat.
    let after_one = check["variation_um"][0].as_f64().unwrap_or(f64::NAN);
    let before_any = v[0].as_f64().unwrap_or(f64::NAN);
    assert!(after_one < before_any / 10.0, "{after_one} vs {before_any}");
}

#[test]
fn bad_input_names_the_file_and_line_and_writes_nothing() {
    let dir = temp_dir();
    let d = dir.path();
    let path = d.join("path.csv");
    run_ok(&[
        "compensate",
        "pattern",
        "circle",
        "--size",
        "10",
        "--surface",
        "plane",
        "--spacing",
        "1",
        "-o",
        s(&path),
    ]);
    let out = d.join("out.csv");
    std::fs::write(&out, "old\n").expect("writable");
    let cases: [(&str, &str, &str); 4] = [
        ("nocols.csv", "index,gap\n0,0.1\n", "no `reading` column"),
        ("short.csv", "reading\n0.1\n0.2\n", "2 reading(s) for"),
        (
            "index.csv",
            "index,reading\n0,0.1\n5,0.1\n99,0.2\n",
            "line 4: index 99",
        ),
        (
            "text.csv",
            "# gaps\ns,reading\n0,0.1\n1,x\n",
            "line 4, column `reading`",
        ),
    ];
    for (name, body, says) in cases {
        let g = d.join(name);
        std::fs::write(&g, body).expect("writable");
        let o = conduit(["compensate", s(&path), "--gaps", s(&g), "-o", s(&out)]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{name}: {e}");
        assert!(e.contains(name) && e.contains(says), "{name}: {e}");
        assert_eq!(std::fs::read_to_string(&out).expect("kept"), "old\n");
    }
    // A path without its quaternion's last column.
    let bad = d.join("bad_path.csv");
    std::fs::write(&bad, "x,y,z,qw,qx,qy\n0,0,1,0,1,0\n").expect("writable");
    let o = conduit(["compensate", s(&bad), "--simulate", "plane", "-o", s(&out)]);
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("bad_path.csv") && e.contains("`qz`"),
        "{e}"
    );
    // A malformed path line is named.
    std::fs::write(&bad, "x,y,z,qw,qx,qy,qz\n0,0,1,0,1,0,0\n0,0,1,0,1\n").expect("writable");
    let o = conduit(["compensate", s(&bad), "--simulate", "plane", "-o", s(&out)]);
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("bad_path.csv: line 3"),
        "{e}"
    );
    // An unknown surface.
    let o = conduit([
        "compensate",
        s(&path),
        "--simulate",
        "cone:3",
        "-o",
        s(&out),
    ]);
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("unknown surface `cone:3`"),
        "{e}"
    );
    let o = conduit([
        "compensate",
        "pattern",
        "spiral",
        "--size",
        "5",
        "--surface",
        "torus:3",
        "-o",
        s(&out),
    ]);
    assert!(!o.status.success() && stderr(&o).contains("torus:3"));
    assert_eq!(std::fs::read_to_string(&out).expect("kept"), "old\n");
}

#[test]
fn a_mesh_surface_works_like_an_analytic_one() {
    // The plane z = 0.2·x + 1 as two triangles: normal (−0.2, 0, 1)/|…|.
    let dir = temp_dir();
    let d = dir.path();
    let stl = d.join("ramp.stl");
    let z = |x: f64| 0.2 * x + 1.0;
    let v = |x: f64, y: f64| format!("vertex {x} {y} {}", z(x));
    let tri = |a: String, b: String, c: String| {
        format!("facet normal 0 0 1\nouter loop\n{a}\n{b}\n{c}\nendloop\nendfacet\n")
    };
    let text = format!(
        "solid ramp\n{}{}endsolid ramp\n",
        tri(v(-20.0, -20.0), v(20.0, -20.0), v(20.0, 20.0)),
        tri(v(-20.0, -20.0), v(20.0, 20.0), v(-20.0, 20.0)),
    );
    std::fs::write(&stl, text).expect("writable");
    let (path, out, rep) = (d.join("p.csv"), d.join("o.csv"), d.join("r.json"));
    run_ok(&[
        "compensate",
        "pattern",
        "serpentine",
        "--size",
        "6",
        "--pitch",
        "1",
        "--at",
        "2,-1",
        "--surface",
        s(&stl),
        "-o",
        s(&path),
    ]);
    let n = nalgebra::Vector3::new(-0.2, 0.0, 1.0).normalize();
    let poses = poses_of(&path);
    assert!(poses.len() > 60);
    for p in &poses {
        let (q, dir) = foot(p);
        assert!((q.z - z(q.x)).abs() * n.z < 1e-3, "{q:?}");
        assert!((dir + n).norm() < 1e-6, "{dir:?}");
    }
    run_ok(&[
        "compensate",
        s(&path),
        "--simulate",
        s(&stl),
        "--shift",
        "0,0,0.3",
        "--tilt",
        "0.5",
        "--tilt-axis",
        "0,1,0",
        "--passes",
        "2",
        "-o",
        s(&out),
        "--report",
        s(&rep),
    ]);
    let r: Value = serde_json::from_slice(&std::fs::read(&rep).expect("report")).expect("JSON");
    let v: Vec<f64> = r["variation_um"]
        .as_array()
        .expect("variations")
        .iter()
        .map(|x| x.as_f64().unwrap_or(f64::NAN))
        .collect();
    // A 0.5° turn about y across the 6 mm square: about 6·tan 0.5° = 52 µm of gap variation
    // (less the part of it along the normal); two passes take it to the smoothing's residue.
    println!("ramp mesh: gap variation {v:?} µm");
    assert!(v[0] > 40.0 && v[2] <= 10.0, "{v:?}");
    // The 0.3 mm lift is taken out: the mean gap is at the target again.
    let mean = r["passes"][1]["after"]["mean"].as_f64().unwrap_or(f64::NAN);
    assert!((mean - GAP).abs() < 0.002, "{mean}");
}
