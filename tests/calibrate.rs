//! Robot calibration (`conduit calibrate tcp` and `conduit calibrate register`): a known tip
//! offset and pivot recovered from noisy flange poses, the same answer from joint angles through
//! a UR5-like arm model as from the equivalent quaternion poses (and the analytic one: turning
//! only the two last joints pivots the flange about the fifth frame's origin), a known random
//! transform recovered from noisy points and from poses with an injected outlier flagged, and
//! the errors users meet (bad lines, too few or barely turned poses).

use std::fmt::Write as _;
use std::path::Path;

use conduit::geom::{Point3, Vector3};
use conduit::robot::frames::{self, Measured, OutlierRule, PairKind};
use conduit::robot::kinematics::Arm;
use conduit::robot::tcp::{self, PoseSource, TcpError};
use conduit_poses::{Pose, write_poses};
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion};
use serde_json::Value;

use crate::support::{conduit, stderr, stdout, temp_dir};

/// A small deterministic generator (64-bit LCG, high bits).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn normal(&mut self) -> f64 {
        let (u, v) = (self.next().max(1e-300), self.next());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
    fn noise(&mut self, sigma: f64) -> Vector3 {
        Vector3::new(self.normal(), self.normal(), self.normal()) * sigma
    }
    fn unit(&mut self) -> Unit<Vector3> {
        loop {
            let v = Vector3::new(self.normal(), self.normal(), self.normal());
            if v.norm() > 1e-3 {
                return Unit::new_normalize(v);
            }
        }
    }
}

const TIP: [f64; 3] = [3.2, -1.7, 145.0];
const PIVOT: [f64; 3] = [512.0, -80.0, 210.0];
/// Noise of the synthetic measurements, mm per axis.
const NOISE: f64 = 0.02;

/// `m` flange poses holding the tip `TIP` on `PIVOT`, tilted 25–45° toward random directions
/// and spun about the tool axis, positions with `NOISE` added.
fn pivot_poses(m: usize, rng: &mut Lcg) -> Vec<Isometry3<f64>> {
    let t = Vector3::from(TIP);
    (0..m)
        .map(|_| {
            let dir = rng.range(0.0, std::f64::consts::TAU);
            let axis = Unit::new_normalize(Vector3::new(dir.cos(), dir.sin(), 0.0));
            let r = UnitQuaternion::from_axis_angle(&axis, rng.range(25.0, 45.0).to_radians())
                * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), rng.range(-3.0, 3.0));
            let p = Vector3::from(PIVOT) - r * t + rng.noise(NOISE);
            Isometry3::from_parts(Translation3::from(p), r)
        })
        .collect()
}

fn pose_csv(poses: &[Isometry3<f64>]) -> String {
    let rows: Vec<Pose> = poses
        .iter()
        .map(|g| {
            let q = g.rotation;
            Pose {
                position: [g.translation.x, g.translation.y, g.translation.z],
                quaternion: [q.w, q.i, q.j, q.k],
                dispense: false,
            }
        })
        .collect();
    let mut out = b"# flange poses, robot base frame\n".to_vec();
    write_poses(&rows, &mut out).expect("poses written");
    String::from_utf8(out).expect("utf-8")
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("written");
    p
}

/// Runs `conduit calibrate register` on the tables `a` and `b` written to `dir` as `a.csv` and
/// `b.csv`; asserts success and returns the output and the report's path.
fn register_cli(dir: &Path, a: &str, b: &str) -> (std::process::Output, std::path::PathBuf) {
    let fa = write(dir, "a.csv", a);
    let fb = write(dir, "b.csv", b);
    let report = dir.join("reg.json");
    let o = conduit([
        "calibrate".as_ref(),
        "register".as_ref(),
        fa.as_os_str(),
        fb.as_os_str(),
        "--report".as_ref(),
        report.as_os_str(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    (o, report)
}

fn json(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).expect("report written")).expect("JSON")
}

fn vec3(v: &Value) -> Vector3 {
    let c = |k: usize| v[k].as_f64().expect("number");
    Vector3::new(c(0), c(1), c(2))
}

#[test]
fn pivot_calibration_recovers_the_tip_and_the_pivot_from_noisy_poses() {
    let mut rng = Lcg(7);
    let poses = pivot_poses(12, &mut rng);
    let p = tcp::pivot(&poses, &[], PoseSource::Quaternions).expect("calibrates");
    let tip_err = (Vector3::from(p.tcp) - Vector3::from(TIP)).norm();
    let pivot_err = (Vector3::from(p.pivot) - Vector3::from(PIVOT)).norm();
    assert!(tip_err < 0.05, "tip off by {tip_err} mm: {p:?}");
    assert!(pivot_err < 0.05, "pivot off by {pivot_err} mm: {p:?}");
    // The residuals are at the noise level: |3D noise| ≈ √3·σ, less the 6 fitted unknowns.
    let expected = NOISE * (3.0f64 * (36.0 - 6.0) / 36.0).sqrt();
    assert!(
        p.rms > 0.5 * expected && p.rms < 2.0 * expected,
        "rms {} vs {expected}",
        p.rms
    );
    // The estimated standard errors cover the actual error.
    let sigma = Vector3::from(p.tcp_sigma).norm();
    assert!(tip_err < 3.0 * sigma, "{tip_err} vs sigma {sigma}");
    assert!(p.condition < 10.0, "{}", p.condition);
}

#[test]
fn the_cli_prints_the_tcp_residuals_and_a_deterministic_report() {
    let dir = temp_dir();
    let mut rng = Lcg(11);
    let mut poses = pivot_poses(9, &mut rng);
    // One pose knocked 0.5 mm off the pivot: the worst residual.
    poses[4].translation.vector.x += 0.5;
    let csv = write(dir.path(), "pivot.csv", &pose_csv(&poses));
    let report = dir.path().join("tcp.json");
    let args = [
        "calibrate".as_ref(),
        "tcp".as_ref(),
        csv.as_os_str(),
        "--report".as_ref(),
        report.as_os_str(),
    ];
    let o = conduit(args);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    // Line 1 is the comment, 2 the header: pose 5 is on line 7.
    assert!(out.contains("worst pose 5 (line 7)"), "{out}");
    assert!(out.contains("pose\tline\tresidual_mm"), "{out}");
    assert_eq!(
        out.lines().filter(|l| l.split('\t').count() == 3).count(),
        10,
        "a header and 9 residual rows: {out}"
    );
    assert!(out.contains("tool_frame = ["), "{out}");
    let r = json(&report);
    assert_eq!(r["poses"], 9);
    assert_eq!(r["worst"]["line"], 7);
    assert_eq!(r["residuals"].as_array().map(Vec::len), Some(9));
    // Still within a few tenths of a mm with the knocked pose in: least squares spreads it.
    assert!((vec3(&r["tcp"]) - Vector3::from(TIP)).norm() < 0.5, "{r}");
    let first = std::fs::read(&report).expect("report");
    let again = conduit(args);
    assert_eq!(stdout(&again), out);
    assert_eq!(std::fs::read(&report).expect("report"), first);
}

/// A UR5-like arm (mm, degrees).
const UR5: [[f64; 4]; 6] = [
    [0.0, 90.0, 89.159, 0.0],
    [-425.0, 0.0, 0.0, 0.0],
    [-392.25, 0.0, 0.0, 0.0],
    [0.0, 90.0, 109.15, 0.0],
    [0.0, -90.0, 94.65, 0.0],
    [0.0, 0.0, 82.3, 0.0],
];

#[test]
fn joint_angles_through_the_arm_model_give_the_same_tcp_as_quaternions() {
    let dir = temp_dir();
    // Joints 1–4 fixed, 5 and 6 turned: the axes of joints 5 and 6 meet at the origin of
    // frame 5, so the flange pivots about it and the "tip" is (0, 0, −d6) in the flange frame.
    // With joints 1–4 at 0 that origin is (a2 + a3, −d4, d1 − d5).
    let mut joints = String::from("# UR5-like arm, joint angles in degrees\nj1,j2,j3,j4,j5,j6\n");
    let arm = Arm::from_dh(&UR5).expect("valid arm");
    let mut poses = Vec::new();
    for k in 0..10 {
        let q = [
            0.0,
            0.0,
            0.0,
            0.0,
            -45.0 + 10.0 * f64::from(k),
            -150.0 + 33.0 * f64::from(k),
        ];
        writeln!(joints, "{}", q.map(|v| format!("{v:.6}")).join(",")).expect("text");
        poses.push(arm.forward(&q).expect("fk"));
    }
    let joints_csv = write(dir.path(), "joints.csv", &joints);
    let quat_csv = write(dir.path(), "flange.csv", &pose_csv(&poses));
    let rows: Vec<String> = UR5
        .iter()
        .map(|r| format!("[{}, {}, {}, {}]", r[0], r[1], r[2], r[3]))
        .collect();
    let cfg = write(
        dir.path(),
        "ur5.toml",
        &format!("[robot]\ndh = [{}]\n", rows.join(", ")),
    );
    let run = |csv: &Path, with_cfg: bool, name: &str| -> Value {
        let report = dir.path().join(name);
        let mut args = vec![
            "calibrate".as_ref(),
            "tcp".as_ref(),
            csv.as_os_str(),
            "--report".as_ref(),
            report.as_os_str(),
        ];
        if with_cfg {
            args.extend(["-c".as_ref(), cfg.as_os_str()]);
        }
        let o = conduit(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        json(&report)
    };
    let by_joints = run(&joints_csv, true, "joints.json");
    let by_quats = run(&quat_csv, false, "quats.json");
    assert_eq!(by_joints["source"], "joints");
    assert_eq!(by_quats["source"], "quaternions");
    let (d1, a2, a3, d4, d5, d6) = (89.159, -425.0, -392.25, 109.15, 94.65, 82.3);
    let tip = Vector3::new(0.0, 0.0, -d6);
    let centre = Vector3::new(a2 + a3, -d4, d1 - d5);
    for r in [&by_joints, &by_quats] {
        assert!((vec3(&r["tcp"]) - tip).norm() < 1e-3, "{r}");
        assert!((vec3(&r["pivot"]) - centre).norm() < 1e-3, "{r}");
    }
    // The quaternion table rounds positions to 0.1 µm: the two agree to that level.
    assert!((vec3(&by_joints["tcp"]) - vec3(&by_quats["tcp"])).norm() < 1e-3);
    assert!(
        by_joints["rms"].as_f64().is_some_and(|v| v < 1e-6),
        "{by_joints}"
    );

    // Joint angles without an arm model: a clear error.
    let o = conduit(["calibrate".as_ref(), "tcp".as_ref(), joints_csv.as_os_str()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("joints.csv") && stderr(&o).contains("[robot] dh is empty"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn bad_pose_tables_are_refused_with_the_file_and_line() {
    let dir = temp_dir();
    let mut rng = Lcg(3);
    let good = pose_csv(&pivot_poses(8, &mut rng));
    let report = dir.path().join("r.json");
    let run = |name: &str, text: &str| {
        let csv = write(dir.path(), name, text);
        let o = conduit([
            "calibrate".as_ref(),
            "tcp".as_ref(),
            csv.as_os_str(),
            "--report".as_ref(),
            report.as_os_str(),
        ]);
        assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
        assert!(!report.exists(), "no report after a failure");
        stderr(&o)
    };
    let broken = good.replacen("0.", "zero.", 1);
    let e = run("broken.csv", &broken);
    assert!(e.contains("broken.csv: line 3"), "{e}");
    let two: String = good.lines().take(4).map(|l| format!("{l}\n")).collect();
    let e = run("two.csv", &two);
    assert!(
        e.contains("two.csv") && e.contains("at least 3 poses, got 2"),
        "{e}"
    );
    // Barely turned: 1° of tilt about varying directions.
    let t = Vector3::from(TIP);
    let flat: Vec<Isometry3<f64>> = (0..8)
        .map(|k| {
            let a = f64::from(k);
            let axis = Unit::new_normalize(Vector3::new(a.cos(), a.sin(), 0.0));
            let r = UnitQuaternion::from_axis_angle(&axis, 1f64.to_radians());
            Isometry3::from_parts(Translation3::from(Vector3::from(PIVOT) - r * t), r)
        })
        .collect();
    let e = run("flat.csv", &pose_csv(&flat));
    assert!(
        e.contains("flat.csv") && e.contains("condition number") && e.contains("tilt the tool"),
        "{e}"
    );
    assert!(matches!(
        tcp::pivot(&flat, &[], PoseSource::Quaternions),
        Err(TcpError::Degenerate { condition, .. }) if condition > tcp::MAX_CONDITION
    ));
}

/// A random rigid transform.
fn random_transform(rng: &mut Lcg) -> Isometry3<f64> {
    let axis = rng.unit();
    let angle = rng.range(0.3, 2.8);
    let t = Vector3::new(
        rng.range(-500.0, 500.0),
        rng.range(-500.0, 500.0),
        rng.range(-200.0, 200.0),
    );
    Isometry3::from_parts(
        Translation3::from(t),
        UnitQuaternion::from_axis_angle(&axis, angle),
    )
}

fn point_csv(points: &[Point3]) -> String {
    let mut s = String::from("x,y,z\n");
    for p in points {
        writeln!(s, "{:.6},{:.6},{:.6}", p.x, p.y, p.z).expect("text");
    }
    s
}

#[test]
fn registration_recovers_a_random_transform_and_flags_an_outlier() {
    let mut rng = Lcg(2024);
    let g = random_transform(&mut rng);
    let a: Vec<Point3> = (0..15)
        .map(|_| {
            Point3::new(
                rng.range(0.0, 200.0),
                rng.range(0.0, 200.0),
                rng.range(0.0, 80.0),
            )
        })
        .collect();
    let mut b: Vec<Point3> = a
        .iter()
        .map(|p| g.transform_point(p) + rng.noise(NOISE))
        .collect();
    // Pair 7 measured 1.5 mm off.
    b[6] += Vector3::new(1.0, -1.0, 0.5);
    let m = |p: &[Point3]| -> Vec<Measured> {
        p.iter()
            .enumerate()
            .map(|(i, q)| Measured {
                position: *q,
                rotation: None,
                line: i + 2,
            })
            .collect()
    };
    let f = frames::register_frames(&m(&a), &m(&b), OutlierRule::Median).expect("fits");
    assert_eq!(f.kind, PairKind::Points);
    let flagged: Vec<usize> = f
        .residuals
        .iter()
        .filter(|r| r.outlier)
        .map(|r| r.pair)
        .collect();
    assert_eq!(flagged, vec![7], "{:?}", f.residuals);
    assert_eq!(f.used, 14);
    assert!(f.residuals[6].residual > 1.0);
    // Residual at the noise level: √3·σ less the 6 fitted unknowns of 42 coordinates.
    let expected = NOISE * (3.0f64 * 36.0 / 42.0).sqrt();
    assert!(
        f.rms > 0.5 * expected && f.rms < 2.0 * expected,
        "{} vs {expected}",
        f.rms
    );
    // Rotation error per axis ≈ σ / (r⊥·√n), r⊥ ≈ r·√(2/3) the RMS distance of the points
    // from an axis through their centroid; its norm over three axes about √3 times that.
    let c = a.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / a.len() as f64;
    let r = (a.iter().map(|p| (p.coords - c).norm_squared()).sum::<f64>() / a.len() as f64).sqrt();
    let turn = f.transform.rotation.angle_to(&g.rotation);
    let expected = 3f64.sqrt() * NOISE / (r * (2.0f64 / 3.0).sqrt() * 14f64.sqrt());
    assert!(turn < 3.0 * expected, "{turn} rad vs {expected}");
    for p in &a {
        let d = (f.transform.transform_point(p) - g.transform_point(p)).norm();
        assert!(d < 0.05, "{d}");
    }

    // The same through the CLI, with the residual table and the three forms of the transform.
    let dir = temp_dir();
    let (o, report) = register_cli(dir.path(), &point_csv(&a), &point_csv(&b));
    let out = stdout(&o);
    assert!(out.contains("15 point pairs, 14 used"), "{out}");
    assert!(out.contains("pair\tline_a\tline_b\tresidual_mm"), "{out}");
    assert!(out.contains("\toutlier"), "{out}");
    assert!(out.contains("4x4 matrix") && out.contains("quaternion") && out.contains("ZYX Euler"));
    assert!(stderr(&o).contains("pair 7 (lines 8/8)"), "{}", stderr(&o));
    let r = json(&report);
    assert_eq!(r["residuals"][6]["outlier"], true);
    assert_eq!(r["residuals"][5]["outlier"], false);
    assert!(
        (vec3(&r["translation"]) - g.translation.vector).norm() < 0.05,
        "{r}"
    );
    let h = g.to_homogeneous();
    for i in 0..3 {
        for j in 0..3 {
            let v = r["matrix"][i][j].as_f64().expect("number");
            assert!((v - h[(i, j)]).abs() < 1e-3, "{i},{j}: {v}");
        }
    }
    // A fixed threshold above the outlier keeps every pair.
    let (fa, fb) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
    let o = conduit([
        "calibrate".as_ref(),
        "register".as_ref(),
        fa.as_os_str(),
        fb.as_os_str(),
        "--outlier".as_ref(),
        "5".as_ref(),
    ]);
    assert!(
        stdout(&o).contains("15 point pairs, 15 used"),
        "{}",
        stdout(&o)
    );
}

#[test]
fn pose_pairs_register_with_orientations_and_flag_a_turned_pose() {
    let mut rng = Lcg(99);
    let g = random_transform(&mut rng);
    let mut a = Vec::new();
    let mut b = Vec::new();
    for _ in 0..8 {
        let r = UnitQuaternion::from_axis_angle(&rng.unit(), rng.range(0.0, 3.0));
        let p = Point3::new(
            rng.range(-100.0, 100.0),
            rng.range(-100.0, 100.0),
            rng.range(0.0, 50.0),
        );
        a.push(Isometry3::from_parts(Translation3::from(p.coords), r));
        b.push(g * Isometry3::from_parts(Translation3::from(p.coords + rng.noise(NOISE)), r));
    }
    // Pose 3 of B turned by 2° about its z axis: its position is right, its orientation is not.
    b[2].rotation *= UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 2f64.to_radians());
    let dir = temp_dir();
    let (o, report) = register_cli(dir.path(), &pose_csv(&a), &pose_csv(&b));
    let out = stdout(&o);
    assert!(out.contains("8 pose pairs, 7 used"), "{out}");
    assert!(out.contains("position_mm\tangle_deg"), "{out}");
    let r = json(&report);
    assert_eq!(r["kind"], "poses");
    let pose3 = &r["residuals"][2];
    assert_eq!(pose3["outlier"], true);
    assert!(
        (pose3["angle_deg"].as_f64().expect("angle") - 2.0).abs() < 0.05,
        "{pose3}"
    );
    assert!(
        pose3["position"].as_f64().expect("position") < 0.1,
        "{pose3}"
    );
    assert!(
        (vec3(&r["translation"]) - g.translation.vector).norm() < 0.05,
        "{r}"
    );
    let q = &r["quaternion"];
    let q = nalgebra::Quaternion::new(
        q[0].as_f64().expect("w"),
        q[1].as_f64().expect("x"),
        q[2].as_f64().expect("y"),
        q[3].as_f64().expect("z"),
    );
    let angle = UnitQuaternion::from_quaternion(q).angle_to(&g.rotation);
    assert!(angle < 0.01f64.to_radians(), "{angle}");

    // Rows that do not pair up: both files named.
    let short: String = pose_csv(&b[..5]);
    let fs = write(dir.path(), "short.csv", &short);
    let fa = dir.path().join("a.csv");
    let o = conduit([
        "calibrate".as_ref(),
        "register".as_ref(),
        fa.as_os_str(),
        fs.as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("a.csv and") && e.contains("short.csv") && e.contains("8 row(s)"),
        "{e}"
    );
}
