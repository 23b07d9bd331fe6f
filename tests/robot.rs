//! Tool orientation and robot / five-axis output of `conduit conform`: every dialect read back
//! by a small parser gives the poses of the motion plan; on a meshed sphere the tool axis stays
//! on the analytic normal; `--max-tilt`, `fixed:` and `vertical` do what they say; bad input
//! fails before anything is written.

use std::path::{Path, PathBuf};
use std::process::Output;

use conduit::config::{ConformSettings, FiveAxis, RobotSettings, RotaryAxes};
use conduit::conform::orient::{self, OrientParams, ToolAxis};
use conduit::conform::{ConformParams, Placement, Surface};
use conduit::emit::robot::motion::{self, MotionParams, Step, Target};
use conduit::emit::robot::{Dialect, RobotJob, write_robot};
use conduit::geom::{Point3, Vector3};
use conduit::program::Program;
use conduit_svg::{Design, DesignPath};
use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion};
use serde_json::Value;

use crate::support::{conduit, stderr, temp_dir, write_stl};

/// Radius of the test sphere, mm.
const R: f64 = 9.0;

/// A UV sphere of radius `r` centred at the origin, `n` rings of latitude and 2n meridians.
fn sphere(r: f64, n: usize) -> Vec<[Point3; 3]> {
    let p = |i: usize, j: usize| {
        let th = std::f64::consts::PI * i as f64 / n as f64;
        let ph = std::f64::consts::PI * j as f64 / n as f64;
        Point3::new(
            r * th.sin() * ph.cos(),
            r * th.sin() * ph.sin(),
            r * th.cos(),
        )
    };
    let mut t = Vec::with_capacity(4 * n * n);
    for i in 0..n {
        for j in 0..2 * n {
            let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
            if i > 0 {
                t.push([a, b, d]);
            }
            if i + 1 < n {
                t.push([b, c, d]);
            }
        }
    }
    t
}

/// Points of a circle of diameter `d` (closed by the design).
fn circle(d: f64, n: usize) -> Vec<[f64; 2]> {
    (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            [0.5 * d * a.cos(), 0.5 * d * a.sin()]
        })
        .collect()
}

/// An SVG (mm) of one closed circle of diameter `d`.
fn circle_svg(dir: &Path, d: f64) -> PathBuf {
    let pts: Vec<String> = circle(d, 96)
        .iter()
        .map(|p| format!("{:.5},{:.5}", p[0] + 5.0, 5.0 - p[1]))
        .collect();
    let path = dir.join("circle.svg");
    std::fs::write(
        &path,
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10mm\" height=\"10mm\" \
             viewBox=\"0 0 10 10\"><path d=\"M {} Z\"/></svg>",
            pts.join(" L ")
        ),
    )
    .expect("svg written");
    path
}

fn place(x: f64, y: f64) -> Placement {
    Placement {
        x,
        y,
        rot_deg: 0.0,
        scale: 1.0,
    }
}

fn surface(t: Vec<[Point3; 3]>) -> Surface {
    Surface::from_triangles(t).expect("surface")
}

fn params() -> ConformParams {
    ConformParams::from_settings(&ConformSettings::default()).expect("params")
}

/// A config file with `extra` appended; the start G-code homes only.
fn config(dir: &Path, extra: &str) -> PathBuf {
    let path = dir.join("robot.toml");
    std::fs::write(
        &path,
        format!("[printer]\nstart_gcode = \"G28\\n\"\nbed_size = [300, 300]\n{extra}"),
    )
    .expect("config written");
    path
}

/// Runs `conduit conform` on `stl` and `svg` with `cfg`, writing `out`, with `args` after.
fn conform_command(stl: &Path, svg: &Path, cfg: &Path, out: &Path, args: &[&str]) -> Output {
    let mut all: Vec<&str> = vec![
        "conform",
        "--surface",
        stl.to_str().unwrap_or_default(),
        "--design",
        svg.to_str().unwrap_or_default(),
        "-c",
        cfg.to_str().unwrap_or_default(),
        "--out",
        out.to_str().unwrap_or_default(),
    ];
    all.extend(args);
    conduit(&all)
}

/// Runs `conduit conform` on `stl` and `svg` with `args`, writing `out` and a report; returns
/// the report.
fn run(stl: &Path, svg: &Path, cfg: &Path, out: &Path, args: &[&str]) -> Value {
    let report = out.with_extension("json");
    let mut all = vec!["--report", report.to_str().unwrap_or_default()];
    all.extend(args);
    let o = conform_command(stl, svg, cfg, out, &all);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_slice(&std::fs::read(&report).expect("report")).expect("JSON")
}

/// A pose read back from a program: tip position in the workpiece frame and the tool frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Read {
    pub(crate) position: Point3,
    pub(crate) rotation: Rotation3<f64>,
}

/// The rotation of a `[x, y, z, rx, ry, rz]` frame, R = Rz(rz)·Ry(ry)·Rx(rx).
fn frame(v: [f64; 6]) -> Isometry3<f64> {
    let r = Rotation3::from_axis_angle(&Vector3::z_axis(), v[5].to_radians())
        * Rotation3::from_axis_angle(&Vector3::y_axis(), v[4].to_radians())
        * Rotation3::from_axis_angle(&Vector3::x_axis(), v[3].to_radians());
    Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::from_rotation_matrix(&r),
    )
}

/// The numbers in `s` separated by commas, spaces or the given letters.
fn numbers(s: &str) -> Vec<f64> {
    s.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'E' || c == 'e'))
        .filter(|t| !t.is_empty() && *t != "E" && *t != "e" && *t != "-")
        .map(|t| t.parse::<f64>().expect("a number"))
        .collect()
}

/// URScript `movel(p[...])` poses, brought from the base frame back to the workpiece frame.
pub(crate) fn read_urscript(text: &str, workpiece: &Isometry3<f64>) -> (Vec<Read>, Vec<bool>) {
    let mut poses = Vec::new();
    let mut switches = Vec::new();
    assert!(text.starts_with("def conduit_program():\n"), "{text}");
    assert!(text.trim_end().ends_with("end"));
    for l in text.lines().map(str::trim) {
        if let Some(rest) = l.strip_prefix("movel(p[") {
            let inside = &rest[..rest.find(']').expect("]")];
            let v = numbers(inside);
            assert_eq!(v.len(), 6, "{l}");
            let r = Rotation3::new(Vector3::new(v[3], v[4], v[5]));
            let base = Isometry3::from_parts(
                Translation3::new(1000.0 * v[0], 1000.0 * v[1], 1000.0 * v[2]),
                UnitQuaternion::from_rotation_matrix(&r),
            );
            let w = workpiece.inverse() * base;
            poses.push(Read {
                position: Point3::from(w.translation.vector),
                rotation: w.rotation.to_rotation_matrix(),
            });
        } else if let Some(rest) = l.strip_prefix("set_digital_out(") {
            if poses.is_empty() {
                continue; // The initial switch-off.
            }
            switches.push(rest.contains("True"));
        }
    }
    (poses, switches)
}

/// KRL `LIN {X,Y,Z,A,B,C}` poses (in $BASE, the workpiece frame).
fn read_krl(text: &str) -> (Vec<Read>, Vec<bool>) {
    let mut poses = Vec::new();
    let mut switches = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines.iter().any(|l| l.starts_with("DEF ")), "{text}");
    assert_eq!(lines.last().copied(), Some("END"));
    for l in lines {
        if let Some(rest) = l.strip_prefix("LIN {") {
            let v = numbers(&rest[..rest.find('}').expect("}")]);
            assert_eq!(v.len(), 6, "{l}");
            let r = Rotation3::from_axis_angle(&Vector3::z_axis(), v[3].to_radians())
                * Rotation3::from_axis_angle(&Vector3::y_axis(), v[4].to_radians())
                * Rotation3::from_axis_angle(&Vector3::x_axis(), v[5].to_radians());
            poses.push(Read {
                position: Point3::new(v[0], v[1], v[2]),
                rotation: r,
            });
        } else if l.starts_with("$OUT[") && !poses.is_empty() {
            switches.push(l.ends_with("TRUE"));
        }
    }
    (poses, switches)
}

/// RAPID `MoveL [[x,y,z],[q1,q2,q3,q4],...]` poses (in the work object).
fn read_rapid(text: &str) -> (Vec<Read>, Vec<bool>) {
    let mut poses = Vec::new();
    let mut switches = Vec::new();
    assert!(text.starts_with("MODULE "), "{text}");
    assert!(text.trim_end().ends_with("ENDMODULE"));
    for l in text.lines().map(str::trim) {
        if let Some(rest) = l.strip_prefix("MoveL [[") {
            // [x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],[9E9 x 6]],speed,zone,tool\WObj:=wobj;
            let v = numbers(&rest[..rest.find("]],").expect("robtarget")]);
            assert_eq!(v.len(), 17, "{l}");
            let q =
                UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(v[3], v[4], v[5], v[6]));
            poses.push(Read {
                position: Point3::new(v[0], v[1], v[2]),
                rotation: q.to_rotation_matrix(),
            });
        } else if l.starts_with("SetDO ") && !poses.is_empty() {
            switches.push(l.ends_with(",1;"));
        }
    }
    (poses, switches)
}

/// Poses of the CSV (in the workpiece frame); switches from the dispense column.
fn read_csv(text: &str) -> (Vec<Read>, Vec<bool>) {
    assert!(text.starts_with('#'));
    let poses = conduit_poses::read_poses(text).expect("poses parse");
    let mut switches = Vec::new();
    let mut on = false;
    for p in &poses {
        if p.dispense != on {
            switches.push(p.dispense);
            on = p.dispense;
        }
    }
    if on {
        switches.push(false);
    }
    let read = poses
        .iter()
        .map(|p| {
            let [w, x, y, z] = p.quaternion;
            Read {
                position: Point3::new(p.position[0], p.position[1], p.position[2]),
                rotation: UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z))
                    .to_rotation_matrix(),
            }
        })
        .collect();
    (read, switches)
}

/// Tip and tool axis of five-axis G-code moves, for the kinematics of `s`.
fn read_5axis(text: &str, s: &RobotSettings) -> (Vec<(Point3, Vector3)>, Vec<bool>) {
    let mut out = Vec::new();
    let mut switches = Vec::new();
    for l in text.lines() {
        if l == ";DISPENSE:ON" || l == ";DISPENSE:OFF" {
            switches.push(l.ends_with("ON"));
            continue;
        }
        let Some(rest) = l.strip_prefix("G1 ") else {
            continue;
        };
        let word = |c: char| {
            rest.split_whitespace()
                .find_map(|w| w.strip_prefix(c))
                .map(|v| v.parse::<f64>().expect("a number"))
        };
        let p = Point3::new(
            word('X').expect("X"),
            word('Y').expect("Y"),
            word('Z').expect("Z"),
        );
        if s.five_axis == FiveAxis::Ijk {
            let a = Vector3::new(
                word('I').expect("I"),
                word('J').expect("J"),
                word('K').expect("K"),
            );
            out.push((p, a));
            continue;
        }
        let about_x = s.rotary_axes == RotaryAxes::AC;
        let tilt = s.rotary_signs[0] * word(if about_x { 'A' } else { 'B' }).expect("tilt");
        let c = s.rotary_signs[1] * word('C').expect("C");
        let t = if about_x {
            Rotation3::from_axis_angle(&Vector3::x_axis(), tilt.to_radians())
        } else {
            Rotation3::from_axis_angle(&Vector3::y_axis(), tilt.to_radians())
        };
        let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), c.to_radians());
        if s.five_axis == FiveAxis::Head {
            let a = rz * t * Vector3::z();
            out.push((p - a * s.pivot_length, a));
        } else {
            let turn = t * rz;
            let centre = Point3::from(s.table_centre);
            out.push((
                centre + turn.inverse() * (p - centre),
                turn.inverse() * Vector3::z(),
            ));
        }
    }
    (out, switches)
}

/// The motion plan's targets and dispense switches.
fn plan_of(program: &Program, s: &RobotSettings) -> (Vec<Target>, Vec<bool>) {
    let steps = motion::plan(
        program,
        &MotionParams {
            clearance: s.clearance,
            travel_speed: s.travel_speed,
            blend: s.blend,
        },
    )
    .expect("plan");
    let mut targets = Vec::new();
    let mut switches = Vec::new();
    for st in steps {
        match st {
            Step::Move { to, .. } => targets.push(to),
            Step::Dispense(on) => switches.push(on),
        }
    }
    (targets, switches)
}

/// An oriented program on a sphere: a circle and a line, tool along the normal.
fn sphere_program() -> Program {
    let s = surface(sphere(R, 40));
    let design = Design {
        width_mm: None,
        height_mm: None,
        paths: vec![
            DesignPath {
                id: None,
                points: circle(3.0, 48),
                closed: true,
            },
            DesignPath {
                id: None,
                points: vec![[-3.0, 3.0], [3.0, 3.0]],
                closed: false,
            },
        ],
    };
    let o = OrientParams::new(ToolAxis::Normal, 60.0, 0.5).expect("orientation");
    let planned = orient::plan(&s, &design, &place(2.0, 1.0), &params(), &o).expect("planned");
    assert_eq!(planned.paths.len(), 2);
    orient::program(
        &planned.paths,
        &planned.axes,
        &ConformSettings::default(),
        R + 2.0,
    )
}

fn write(program: &Program, dialect: Dialect, s: &RobotSettings) -> String {
    let job = RobotJob {
        settings: s,
        name: "sphere test",
        dispense_on_gcode: "M42 P6 S255",
        dispense_off_gcode: "M42 P6 S0",
    };
    let mut out = Vec::new();
    write_robot(program, dialect, &job, &mut out).expect("written");
    String::from_utf8(out).expect("UTF-8")
}

/// Angle between two rotations, radians (for small angles: ‖A − B‖_F / √2, which stays
/// finite where rounding makes acos of the trace undefined).
fn rotation_error(a: &Rotation3<f64>, b: &Rotation3<f64>) -> f64 {
    (a.matrix() - b.matrix()).norm() / std::f64::consts::SQRT_2
}

#[test]
fn every_dialect_reads_back_to_the_poses_of_the_motion_plan() {
    let program = sphere_program();
    let settings = RobotSettings {
        workpiece_frame: [400.0, -120.0, 35.0, 5.0, -10.0, 30.0],
        tool_frame: [0.0, 12.0, 150.0, 0.0, 20.0, 0.0],
        ..RobotSettings::default()
    };
    let (targets, switches) = plan_of(&program, &settings);
    assert_eq!(switches, vec![true, false, true, false]);
    let workpiece = frame(settings.workpiece_frame);
    // Written rounding, half a unit of the last decimal per coordinate (√3 of it as a
    // distance): URScript 1 µm and 1e-6 rad, KRL and RAPID 0.001 mm with 1e-4° or 1e-6 of a
    // quaternion, the CSV 1e-4 mm and 1e-9.
    let half = 0.5 * 3f64.sqrt();
    let cases: [(Dialect, f64, f64); 4] = [
        (Dialect::Urscript, half * 1e-3, 5e-6),
        (Dialect::Krl, half * 1e-3, 5e-6),
        (Dialect::Rapid, half * 1e-3, 5e-6),
        (Dialect::PosesCsv, half * 1e-4, 1e-8),
    ];
    for (dialect, tol_mm, tol_rad) in cases {
        let text = write(&program, dialect, &settings);
        let (read, sw) = match dialect {
            Dialect::Urscript => read_urscript(&text, &workpiece),
            Dialect::Krl => read_krl(&text),
            Dialect::Rapid => read_rapid(&text),
            _ => read_csv(&text),
        };
        assert_eq!(read.len(), targets.len(), "{dialect:?}");
        assert_eq!(sw, switches, "{dialect:?}");
        for (r, t) in read.iter().zip(&targets) {
            let dp = (r.position - t.position).norm();
            let dr = rotation_error(&r.rotation, &t.rotation);
            assert!(
                dp <= tol_mm,
                "{dialect:?}: {} vs {}",
                r.position,
                t.position
            );
            assert!(dr <= tol_rad, "{dialect:?}: rotation off by {dr} rad");
            // The tool frame's z runs into the work: against the tool axis.
            assert!((r.rotation * Vector3::z() + t.axis).norm() < 1e-5);
        }
        // The same program gives the same bytes.
        assert_eq!(text, write(&program, dialect, &settings), "{dialect:?}");
    }
    // The frames are declared as written.
    let krl = write(&program, Dialect::Krl, &settings);
    assert!(
        krl.contains("$BASE={FRAME: X 400.000,Y -120.000,Z 35.000,A 30.0000,B -10.0000,C 5.0000}"),
        "{krl}"
    );
    let rapid = write(&program, Dialect::Rapid, &settings);
    let q = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 20f64.to_radians());
    assert!(
        rapid.contains(&format!(
            "PERS tooldata conduit_tool:=[TRUE,[[0.000,12.000,150.000],[{:.6},0.000000,{:.6},0.000000]]",
            q.w, q.j
        )),
        "{rapid}"
    );
    let ur = write(&program, Dialect::Urscript, &settings);
    assert!(
        ur.contains(&format!(
            "set_tcp(p[0.000000, 0.012000, 0.150000, 0.000000, {:.6}, 0.000000])",
            20f64.to_radians()
        )),
        "{ur}"
    );

    // Five-axis G-code: I J K, a head and a table, each in AC and BC with a reversed axis.
    let kinematics = [
        (FiveAxis::Ijk, RotaryAxes::AC, [1.0, 1.0]),
        (FiveAxis::Head, RotaryAxes::AC, [1.0, -1.0]),
        (FiveAxis::Head, RotaryAxes::BC, [-1.0, 1.0]),
        (FiveAxis::Table, RotaryAxes::AC, [1.0, 1.0]),
        (FiveAxis::Table, RotaryAxes::BC, [1.0, -1.0]),
    ];
    for (kind, axes, signs) in kinematics {
        let s = RobotSettings {
            five_axis: kind,
            rotary_axes: axes,
            rotary_signs: signs,
            pivot_length: 80.0,
            table_centre: [10.0, -5.0, -30.0],
            ..RobotSettings::default()
        };
        let text = write(&program, Dialect::Gcode5Axis, &s);
        let (read, sw) = read_5axis(&text, &s);
        assert_eq!(sw, switches, "{kind:?} {axes:?}");
        assert_eq!(read.len(), targets.len(), "{kind:?} {axes:?}");
        // 3 decimals of mm, angles 1e-4° (2e-6 rad: 0.2 µm per 100 mm of lever).
        for ((p, a), t) in read.iter().zip(&targets) {
            assert!(
                (p - t.position).norm() < 2e-3,
                "{kind:?} {axes:?}: {p} vs {}",
                t.position
            );
            assert!(
                (a - t.axis).norm() < 1e-5,
                "{kind:?} {axes:?}: {a} vs {}",
                t.axis
            );
        }
        // The paste snippets switch the dispenser.
        assert_eq!(text.matches("M42 P6 S255\n;DISPENSE:ON").count(), 2);
    }
}

#[test]
fn a_millimetre_circle_on_a_sphere_keeps_the_tool_on_the_normal() {
    let dir = temp_dir();
    let stl = dir.path().join("sphere.stl");
    let tris = sphere(R, 120);
    assert!(tris.len() > 20_000, "{}", tris.len());
    write_stl(&stl, &tris);
    let svg = circle_svg(dir.path(), 1.0);
    let cfg = config(dir.path(), "");
    // At the pole and 35° down the side (x = 9·sin 35° ≈ 5.2 mm).
    let mut checked = 0;
    for (x, y) in [(0.0, 0.0), (4.0, 3.3)] {
        let out = dir.path().join("circle.csv");
        let place = format!("{x},{y}");
        let r = run(
            &stl,
            &svg,
            &cfg,
            &out,
            &[
                "--place",
                &place,
                "--tool-axis",
                "normal",
                "--max-tilt",
                "90",
                "--dialect",
                "poses-csv",
            ],
        );
        let text = std::fs::read_to_string(&out).expect("poses");
        let (read, _) = read_csv(&text);
        let poses = conduit_poses::read_poses(&text).expect("poses");
        let d = ConformSettings::default().inner_diameter;
        let mut worst = 0.0f64;
        for (p, pose) in read.iter().zip(&poses) {
            if !pose.dispense {
                continue;
            }
            let axis = -(p.rotation * Vector3::z());
            // The point on the surface under the tip, and the sphere's normal there.
            let t = p.position - axis * d;
            let n = t.coords.normalize();
            worst = worst.max(axis.angle(&n).to_degrees());
            // The standoff is along the axis: the tip is d off the surface.
            assert!(
                (p.position.coords.norm() - R - d).abs() < 0.01,
                "{}",
                p.position
            );
            checked += 1;
        }
        let tilt = r["orientation"]["max_tilt_deg"].as_f64().expect("tilt");
        println!("circle at ({x}, {y}): largest angle to the normal {worst:.3}°, tilt {tilt:.1}°");
        assert!(worst < 1.0, "{worst}° at ({x}, {y})");
        let reported = r["orientation"]["max_normal_deviation_deg"]
            .as_f64()
            .expect("deviation");
        assert!(reported < 1.0, "{reported}");
        assert_eq!(r["orientation"]["tool_axis"], "normal");
        assert_eq!(r["orientation"]["contacts"], 0, "{}", r["orientation"]);
        if x > 0.0 {
            // 35° down: the circle's axes lean between 30° and 40°.
            assert!(tilt > 30.0 && tilt < 40.0, "{tilt}");
        }
    }
    assert!(checked > 40);
}

#[test]
fn max_tilt_is_respected_and_a_fixed_axis_is_kept_everywhere() {
    let dir = temp_dir();
    let stl = dir.path().join("sphere.stl");
    write_stl(&stl, &sphere(R, 60));
    let svg = circle_svg(dir.path(), 3.0);
    let cfg = config(dir.path(), "");
    let out = dir.path().join("tilt.csv");
    // 40° to 55° down the sphere, limited to 20°.
    let r = run(
        &stl,
        &svg,
        &cfg,
        &out,
        &[
            "--place",
            "6.5,0",
            "--tool-axis",
            "normal",
            "--max-tilt",
            "20",
            "--dialect",
            "poses-csv",
        ],
    );
    let text = std::fs::read_to_string(&out).expect("poses");
    let (read, _) = read_csv(&text);
    let mut tilts = Vec::new();
    for p in &read {
        let axis = -(p.rotation * Vector3::z());
        tilts.push(axis.angle(&Vector3::z()).to_degrees());
    }
    let max = tilts.iter().copied().fold(0.0, f64::max);
    assert!((max - 20.0).abs() < 1e-5, "{max}");
    let o = &r["orientation"];
    assert!(o["limited"].as_u64().expect("limited") > 0, "{o}");
    assert!((o["max_tilt_deg"].as_f64().expect("tilt") - 20.0).abs() < 1e-9);
    // Held at 20° where the surface leans 40° or more: at least 20° off the normal.
    assert!(
        o["max_normal_deviation_deg"].as_f64().expect("dev") > 20.0,
        "{o}"
    );

    // A fixed axis, in the KRL program's angles: every LIN has the same tool frame.
    let out = dir.path().join("fixed.src");
    run(
        &stl,
        &svg,
        &cfg,
        &out,
        &[
            "--place",
            "2,0",
            "--tool-axis",
            "fixed:0,1,2",
            "--max-tilt",
            "30",
            "--dialect",
            "krl",
        ],
    );
    let (read, _) = read_krl(&std::fs::read_to_string(&out).expect("krl"));
    let want = Vector3::new(0.0, 1.0, 2.0).normalize();
    assert!(read.len() > 40);
    for p in &read {
        let axis = -(p.rotation * Vector3::z());
        assert!((axis - want).norm() < 1e-5, "{axis}");
    }
}

#[test]
fn vertical_is_todays_three_axis_output() {
    let dir = temp_dir();
    let stl = dir.path().join("sphere.stl");
    write_stl(&stl, &sphere(R, 40));
    let svg = circle_svg(dir.path(), 3.0);
    let cfg_path = config(dir.path(), "");
    let plain = dir.path().join("plain.gcode");
    let r = run(&stl, &svg, &cfg_path, &plain, &["--place", "2,1"]);
    let vertical = dir.path().join("vertical.gcode");
    run(
        &stl,
        &svg,
        &cfg_path,
        &vertical,
        &[
            "--place",
            "2,1",
            "--tool-axis",
            "vertical",
            "--dialect",
            "gcode",
        ],
    );
    let bytes = std::fs::read(&plain).expect("G-code");
    assert_eq!(bytes, std::fs::read(&vertical).expect("G-code"));
    // The 3-axis pipeline of the library, as the command ran before tool axes existed.
    let (cfg, _) = conduit::config::load(&cfg_path).expect("config");
    let file = conduit::scene::load(&stl, &conduit::scene::LoadOptions::default()).expect("stl");
    let conduit::scene::Content::Mesh { scene, .. } = file.content else {
        panic!("a mesh");
    };
    let mut mesh = conduit::mesh::Mesh::default();
    for m in conduit::scene::placed_meshes(&scene) {
        mesh.append(&m);
    }
    let s = Surface::from_mesh(&mesh).expect("surface");
    let design = match conduit::scene::load(&svg, &conduit::scene::LoadOptions::default())
        .expect("svg")
        .content
    {
        conduit::scene::Content::Design(d) => d,
        _ => panic!("a design"),
    };
    let p = ConformParams::from_settings(&cfg.conform).expect("params");
    let planned = conduit::conform::plan(&s, &design, &place(2.0, 1.0), &p, |_| {}).expect("plan");
    let lowest = planned
        .paths
        .iter()
        .flatten()
        .map(|q| q.z)
        .fold(f64::MAX, f64::min);
    let program = conduit::conform::program(
        &planned.paths,
        &cfg.conform,
        s.max().z + cfg.conform.travel_clearance,
    );
    let machine = conduit::conform::machine_params(cfg.gcode_params(), &cfg.conform, &s, lowest)
        .expect("machine");
    let mut want = Vec::new();
    conduit::emit::gcode::write_gcode(&program, &machine, &mut want).expect("G-code");
    assert_eq!(bytes, want);
    // The report has the orientation: no tilt, the slope under the tips as the deviation.
    let o = &r["orientation"];
    assert_eq!(o["tool_axis"], "vertical");
    assert_eq!(o["max_tilt_deg"].as_f64(), Some(0.0));
    let dev = o["max_normal_deviation_deg"].as_f64().expect("dev");
    // The circle spans 0.5 to 3.7 mm from the pole: slopes up to asin(3.7/9) ≈ 24°.
    assert!(dev > 20.0 && dev < 26.0, "{dev}");
}

#[test]
fn bad_input_fails_with_a_clear_message_and_writes_nothing() {
    let dir = temp_dir();
    let stl = dir.path().join("sphere.stl");
    write_stl(&stl, &sphere(R, 20));
    let svg = circle_svg(dir.path(), 3.0);
    let out = dir.path().join("out.prg");
    let good = config(dir.path(), "");
    let run_fail = |cfg: &Path, args: &[&str]| {
        let o = conform_command(&stl, &svg, cfg, &out, args);
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
        (o.status.code(), stderr(&o))
    };
    let (code, err) = run_fail(&good, &["--dialect", "fanuc"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("fanuc") && err.contains("urscript"), "{err}");
    let (code, err) = run_fail(&good, &["--dialect", "krl", "--tool-axis", "fixed:0,0,0"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("fixed:0,0,0") && err.contains("non-zero"),
        "{err}"
    );
    let (code, err) = run_fail(&good, &["--tool-axis", "normal"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("3-axis G-code"), "{err}");
    let (code, err) = run_fail(
        &good,
        &[
            "--dialect",
            "rapid",
            "--tool-axis",
            "normal",
            "--max-tilt",
            "120",
        ],
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("0 to 90"), "{err}");
    let (code, err) = run_fail(
        &good,
        &[
            "--dialect",
            "krl",
            "--tool-axis",
            "fixed:1,0,1",
            "--max-tilt",
            "30",
        ],
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("45.0°"), "{err}");
    // Frames: a short one, a non-finite one.
    let short = config(dir.path(), "[robot]\nworkpiece_frame = [1, 2, 3]\n");
    let (code, err) = run_fail(&short, &["--dialect", "urscript"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("robot.toml:5")
            && err.contains("robot.workpiece_frame must be a list of 6 values"),
        "{err}"
    );
    let nan = config(dir.path(), "[robot]\ntool_frame = [0, 0, 100, 0, nan, 0]\n");
    let (code, err) = run_fail(&nan, &["--dialect", "urscript"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("robot.tool_frame[4]"), "{err}");
}

#[test]
fn the_old_output_spelling_of_the_dialect_still_works_and_warns() {
    let dir = temp_dir();
    let stl = dir.path().join("sphere.stl");
    write_stl(&stl, &sphere(R, 20));
    let svg = circle_svg(dir.path(), 3.0);
    let cfg = config(dir.path(), "");
    let (new, old) = (dir.path().join("new.script"), dir.path().join("old.script"));
    let o = conform_command(&stl, &svg, &cfg, &new, &["--dialect", "urscript"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let o = conform_command(&stl, &svg, &cfg, &old, &["--output", "urscript"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("`--output urscript` is now spelled `--dialect urscript`"),
        "{}",
        stderr(&o)
    );
    let program = std::fs::read(&new).expect("program");
    assert!(program.starts_with(b"def "), "not URScript");
    assert_eq!(program, std::fs::read(&old).expect("program"));
    // Both spellings at once are a usage error.
    let o = conform_command(
        &stl,
        &svg,
        &cfg,
        &old,
        &["--output", "krl", "--dialect", "urscript"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn a_tool_leaning_into_a_wall_is_reported_and_one_leaning_away_is_not() {
    // A floor at z = 0 for x < 3, a block 4 mm high beyond; a line along y 1 mm from the wall.
    let quad = |x0: f64, x1: f64, z: f64| {
        [
            [
                Point3::new(x0, -10.0, z),
                Point3::new(x1, -10.0, z),
                Point3::new(x1, 10.0, z),
            ],
            [
                Point3::new(x0, -10.0, z),
                Point3::new(x1, 10.0, z),
                Point3::new(x0, 10.0, z),
            ],
        ]
    };
    let mut t = quad(-10.0, 3.0, 0.0).to_vec();
    t.extend(quad(3.0, 10.0, 4.0));
    let s = surface(t);
    let design = Design {
        width_mm: None,
        height_mm: None,
        paths: vec![DesignPath {
            id: None,
            points: vec![[0.0, -2.0], [0.0, 2.0]],
            closed: false,
        }],
    };
    let p = params();
    let count = |axis: Vector3| {
        let o = OrientParams::new(ToolAxis::Fixed(axis.normalize()), 60.0, 0.5).expect("params");
        let planned = orient::plan(&s, &design, &place(2.0, 0.0), &p, &o).expect("planned");
        assert_eq!(
            planned.report.remaining_contacts, planned.orientation.contacts,
            "the conform report and the orientation agree"
        );
        planned.orientation
    };
    // 45° toward the wall: the needle (6 mm) reaches x = 2 + 0.25·0.7 + 4 > 3 below z = 4.
    let into = count(Vector3::new(1.0, 0.0, 1.0));
    let points = into.paths[0].points;
    assert_eq!(into.contacts, points, "{into:?}");
    assert!(into.contact_places[0].depth > 0.0);
    // Vertical and leaning away: the needle stays 1 mm from the wall, the cone starts above it.
    assert_eq!(count(Vector3::z()).contacts, 0);
    assert_eq!(count(Vector3::new(-1.0, 0.0, 1.0)).contacts, 0);
}
