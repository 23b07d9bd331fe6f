//! What the report says about a wire the router could not route (`blocked_by`, `help`), and
//! the negotiated strategy (`route.strategy = "negotiated"`) through the CLI.

use serde_json::Value;

use crate::electronics::run_demo_slice;
use crate::support::{stderr, temp_dir};

/// The electronics section of the report at `path`.
fn electronics(path: &std::path::Path) -> Value {
    let json: Value = serde_json::from_slice(&std::fs::read(path).expect("report written"))
        .expect("report is JSON");
    json["electronics"].clone()
}

#[test]
fn traces_too_wide_for_the_pads_name_the_pads_and_the_width_that_fits() {
    // 2.5 mm traces do not pass between the demo's pads, 1.9 and 2.0 mm apart.
    let dir = temp_dir();
    let (o, _, report) = run_demo_slice(
        dir.path(),
        &["--set", "route.conductive_width=2.5", "--allow-unrouted"],
    );
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let e = electronics(&report);
    let unrouted: Vec<&Value> = e["wires"]
        .as_array()
        .expect("wires")
        .iter()
        .filter(|w| w["routed"] == Value::Bool(false))
        .collect();
    assert!(!unrouted.is_empty(), "{e}");
    assert_eq!(e["unrouted"], Value::from(unrouted.len()));
    for w in &unrouted {
        let blocked: Vec<&str> = w["blocked_by"]
            .as_array()
            .expect("blocked_by")
            .iter()
            .filter_map(Value::as_str)
            .collect();
        assert!(!blocked.is_empty(), "{w}");
        // Each pad is named with its distance from the wire's pin: R1's pads are 1.90 mm
        // apart, LED1's 2.00.
        let pins = [
            w["from"].as_str().expect("from"),
            w["to"].as_str().expect("to"),
        ];
        for b in &blocked {
            assert!(
                b.starts_with("pad ")
                    && pins.iter().any(|p| {
                        b.ends_with(&format!(" 1.90 mm from {p}"))
                            || b.ends_with(&format!(" 2.00 mm from {p}"))
                    }),
                "{b}"
            );
        }
        let help = w["help"].as_str().expect("help");
        assert!(
            help.contains("closer than two traces can run (2.76 mm)")
                && help.contains("a route.conductive_width of 1.65 mm fits"),
            "{help}"
        );
        // The terminal's line says the same.
        let line = format!(
            "net {} could not be routed ({} to {}): {help}",
            w["net"].as_str().expect("net"),
            w["from"].as_str().expect("from"),
            w["to"].as_str().expect("to")
        );
        assert!(err.contains(&line), "no '{line}' in {err}");
    }
    // The progress lines: the first pass, then rip-up rounds; the last one's counts are the
    // report's.
    let lines = e["routing"]["progress"].as_array().expect("progress");
    assert_eq!(lines[0]["phase"], "first-pass", "{lines:?}");
    assert!(
        lines[1..].iter().all(|l| l["phase"] == "rip-up"),
        "{lines:?}"
    );
    let last = lines.last().expect("a progress line");
    assert_eq!(
        (&last["routed"], &last["unrouted"]),
        (&e["routed"], &e["unrouted"])
    );
    for w in e["wires"].as_array().expect("wires") {
        if w["routed"] == Value::Bool(true) {
            assert_eq!(w["blocked_by"], Value::Array(Vec::new()), "{w}");
            assert_eq!(w["help"], Value::Null, "{w}");
        }
    }
}

#[test]
fn negotiated_routing_routes_the_demo_the_same_way_twice() {
    let dir = temp_dir();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir_all(&a).expect("folder a");
    std::fs::create_dir_all(&b).expect("folder b");
    let set = ["--set", "route.strategy=negotiated"];
    let (oa, ga, ra) = run_demo_slice(&a, &set);
    let (ob, gb, _) = run_demo_slice(&b, &set);
    assert!(oa.status.success(), "{}", stderr(&oa));
    assert!(ob.status.success(), "{}", stderr(&ob));
    assert_eq!(
        std::fs::read(&ga).expect("G-code a"),
        std::fs::read(&gb).expect("G-code b")
    );
    let e = electronics(&ra);
    assert_eq!(e["unrouted"], Value::from(0), "{e}");
    assert!(
        e["routing"]["negotiation_rounds"]
            .as_u64()
            .is_some_and(|n| n >= 1),
        "{e}"
    );
    assert_eq!(e["routing"]["negotiation_conflicts"], Value::from(0), "{e}");
    // The progress lines: negotiation rounds, the last with every wire routed and none in
    // conflict.
    let lines = e["routing"]["progress"].as_array().expect("progress");
    assert!(
        lines
            .iter()
            .all(|l| l["phase"] == "negotiation" && l["object"] == 0),
        "{lines:?}"
    );
    let last = lines.last().expect("a progress line");
    assert_eq!(last["routed"], e["routed"], "{last}");
    assert_eq!(
        (last["unrouted"].as_u64(), last["conflicts"].as_u64()),
        (Some(0), Some(0))
    );
}

#[test]
fn an_unknown_strategy_is_refused() {
    let dir = temp_dir();
    let (o, out, _) = run_demo_slice(dir.path(), &["--set", "route.strategy=fastest"]);
    let err = stderr(&o);
    // A bad --set value is a usage error.
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(r#"route.strategy must be "ordered" or "negotiated", got "fastest""#),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn routing_gives_the_same_bytes_on_one_thread_and_on_two() {
    let demo = |f: &str| crate::support::sample(&format!("circuit_demo/{f}"));
    let dir = temp_dir();
    for strategy in ["ordered", "negotiated"] {
        let mut outputs = Vec::new();
        for threads in ["1", "2"] {
            let out = dir.path().join(format!("{strategy}-{threads}.gcode"));
            let o = std::process::Command::new(env!("CARGO_BIN_EXE_conduit"))
                .env("RAYON_NUM_THREADS", threads)
                .arg("slice")
                .arg(demo("block.stl"))
                .arg("--circuit")
                .arg(demo("led_coin.sch"))
                .arg("--placement")
                .arg(demo("placement.toml"))
                .arg("-o")
                .arg(&out)
                .args(["--set", &format!("route.strategy={strategy}")])
                .output()
                .expect("the conduit binary runs");
            assert!(o.status.success(), "{}", stderr(&o));
            outputs.push(std::fs::read(&out).expect("G-code written"));
        }
        assert!(
            outputs[0] == outputs[1],
            "{strategy}: 1 and 2 threads differ"
        );
    }
}
