//! The router's time limit (`route.time_limit`), the reason a wire is unrouted, the routing
//! summary of the report, and an interrupted slice leaving no file behind.
//!
//! The limit is tested with one far too short for any search (a microsecond): every wire must
//! come out unrouted for that reason. No test here depends on how fast the machine is (the
//! time a moderate limit takes is measured by `bench/route.sh --time-limit`).

use std::path::PathBuf;

use serde_json::Value;

use crate::electronics::run_demo_slice;
use crate::support::{conduit, corpus, files_in, sample, stderr, temp_dir};

/// A limit no routing search fits in, s.
const TINY: &str = "route.time_limit=0.000001";
/// What a wire stopped by [`TINY`] is reported with.
const TINY_REASON: &str = "time limit reached (route.time_limit = 0.000001 s)";

/// The demo board's inputs: block, schematic, placement.
fn demo() -> [PathBuf; 3] {
    [
        sample("circuit_demo/block.stl"),
        sample("circuit_demo/led_coin.sch"),
        sample("circuit_demo/placement.toml"),
    ]
}

#[test]
fn a_tiny_time_limit_fails_the_job_naming_the_limit() {
    let dir = temp_dir();
    let (o, out, report) = run_demo_slice(dir.path(), &["--set", TINY]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("could not be routed"))
        .collect();
    assert!(!lines.is_empty(), "no unrouted wire named in {err}");
    for l in &lines {
        assert!(
            l.starts_with("error: net ") && l.ends_with(&format!("): {TINY_REASON}")),
            "{l}"
        );
    }
    assert!(!out.exists() && !report.exists(), "nothing is written");
    assert_eq!(files_in(dir.path()), Vec::<PathBuf>::new());
    // Standard error is a pipe here: no progress bar.
    assert!(!err.contains("routing ["), "{err}");
}

#[test]
fn the_defaults_list_the_time_limit() {
    let o = conduit(["config", "--defaults"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = crate::support::stdout(&o);
    assert!(text.contains("\ntime_limit = 180.0\n"), "{text}");
}

#[test]
fn a_tiny_time_limit_reports_every_wire_routed_or_out_of_time() {
    let dir = temp_dir();
    let (o, out, report) = run_demo_slice(dir.path(), &["--set", TINY, "--allow-unrouted"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists(), "the G-code is written with --allow-unrouted");
    let json: Value = serde_json::from_slice(&std::fs::read(&report).expect("report written"))
        .expect("report is JSON");
    let e = &json["electronics"];
    let wires = e["wires"].as_array().expect("wires");
    assert!(wires.len() >= 2, "the demo has wires to route: {e}");
    let mut out_of_time = 0;
    for w in wires {
        match w["routed"].as_bool() {
            Some(true) => assert_eq!(w["reason"], Value::Null, "{w}"),
            Some(false) => {
                assert_eq!(w["reason"], Value::from(TINY_REASON), "{w}");
                out_of_time += 1;
            }
            None => panic!("no routed flag: {w}"),
        }
    }
    assert!(out_of_time > 0, "a microsecond routes nothing: {e}");
    assert_eq!(e["unrouted"], Value::from(out_of_time));
    assert_eq!(e["routing"]["time_limit_reached"], Value::Bool(true));
    assert_eq!(e["routing"]["rounds"], Value::from(0));
    assert!(
        e["routing"]["wall_seconds"]
            .as_f64()
            .is_some_and(|s| s >= 0.0)
    );
}

#[test]
fn a_job_in_time_is_the_same_with_and_without_a_limit() {
    let dir = temp_dir();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir_all(&a).expect("folder a");
    std::fs::create_dir_all(&b).expect("folder b");
    let (oa, ga, ra) = run_demo_slice(&a, &[]);
    let (ob, gb, rb) = run_demo_slice(&b, &["--set", "route.time_limit=0"]);
    assert!(oa.status.success(), "{}", stderr(&oa));
    assert!(ob.status.success(), "{}", stderr(&ob));
    assert_eq!(
        std::fs::read(&ga).expect("G-code a"),
        std::fs::read(&gb).expect("G-code b"),
        "the limit changes nothing of a job that finishes in time"
    );
    for r in [ra, rb] {
        let json: Value =
            serde_json::from_slice(&std::fs::read(&r).expect("report")).expect("report is JSON");
        let e = &json["electronics"];
        assert_eq!(e["unrouted"], Value::from(0), "{e}");
        assert_eq!(e["routing"]["time_limit_reached"], Value::Bool(false));
        for w in e["wires"].as_array().expect("wires") {
            assert_eq!(w["reason"], Value::Null, "{w}");
        }
    }
}

#[test]
fn a_negative_time_limit_is_refused() {
    let dir = temp_dir();
    let (o, out, _) = run_demo_slice(dir.path(), &["--set", "route.time_limit=-1"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("route.time_limit must be ≥ 0, got -1"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn route_and_postprocess_name_the_time_limit_too() {
    let dir = temp_dir();
    let [stl, sch, toml] = demo();
    let views = dir.path().join("views");
    let o = conduit([
        "route".as_ref(),
        stl.as_os_str(),
        "--circuit".as_ref(),
        sch.as_os_str(),
        "--placement".as_ref(),
        toml.as_os_str(),
        "--out-dir".as_ref(),
        views.as_os_str(),
        "--set".as_ref(),
        TINY.as_ref(),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains(&format!("): {TINY_REASON}")), "{err}");

    let host = dir.path().join("cube.gcode");
    let cube = sample("cube_20mm.stl");
    let o = conduit([
        "slice".as_ref(),
        cube.as_os_str(),
        "-o".as_ref(),
        host.as_os_str(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = std::fs::read(&host).expect("host G-code");
    let (pp_sch, pp_toml) = (
        sample("postprocess/cube_led.sch"),
        sample("postprocess/cube_led.toml"),
    );
    let o = conduit([
        "postprocess".as_ref(),
        host.as_os_str(),
        "--circuit".as_ref(),
        pp_sch.as_os_str(),
        "--placement".as_ref(),
        pp_toml.as_os_str(),
        "--set".as_ref(),
        TINY.as_ref(),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains(&format!("): {TINY_REASON}")), "{err}");
    assert_eq!(
        std::fs::read(&host).expect("host G-code"),
        before,
        "the host's file is left as it was"
    );
}

/// SIGINT two seconds into a slice that takes longer (the corpus Benchy at 0.02 mm layers):
/// the run ends, and neither the output nor a temporary file is left in the folder.
#[cfg(unix)]
#[test]
fn an_interrupted_slice_leaves_no_file() {
    let Some(corpus) = corpus() else {
        println!("skipped: corpus not found");
        return;
    };
    let model = corpus.join("3DBenchy/Single-part/3DBenchy.3mf");
    let dir = temp_dir();
    let (out, report) = (
        dir.path().join("benchy.gcode"),
        dir.path().join("benchy.json"),
    );
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_conduit"))
        .args([
            "slice".as_ref(),
            model.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ])
        .args(["--report".as_ref(), report.as_os_str()])
        .args(["--set", "slice.layer_height=0.02"])
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("conduit starts");
    std::thread::sleep(std::time::Duration::from_secs(2));
    assert!(
        child.try_wait().expect("child state").is_none(),
        "the slice should still run after 2 s"
    );
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(kill.success());
    let status = child.wait().expect("conduit ends");
    assert!(!status.success(), "interrupted: {status:?}");
    assert_eq!(
        files_in(dir.path()),
        Vec::<PathBuf>::new(),
        "files left behind"
    );
}
