//! `conduit check --circuit --placement`: the circuit rebuilt from the G-code's conductive beads,
//! on the bundled demo (as sliced, and with an open, a short, a trace outside the block and an
//! early part event planted in its text) and on postprocessed host files.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde_json::Value;

use crate::support::{conduit, corpus, sample, stderr, stdout, temp_dir};

fn demo(f: &str) -> PathBuf {
    sample(&format!("circuit_demo/{f}"))
}

/// The demo sliced with its circuit, once for the module.
fn demo_gcode() -> &'static str {
    static TEXT: OnceLock<String> = OnceLock::new();
    TEXT.get_or_init(|| {
        let dir = temp_dir();
        let (out, _) = crate::electronics::slice_demo(dir.path());
        std::fs::read_to_string(&out).expect("G-code written")
    })
}

/// `conduit check FILE --circuit --placement [--model] --json`: exit code and the `electrical`
/// object.
fn check(gcode: &Path, sch: &Path, placement: &Path, model: Option<&Path>) -> (i32, Value) {
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "check".as_ref(),
        gcode.as_os_str(),
        "--circuit".as_ref(),
        sch.as_os_str(),
        "--placement".as_ref(),
        placement.as_os_str(),
        "--json".as_ref(),
    ];
    if let Some(m) = model {
        args.extend(["--model".as_ref(), m.as_os_str()]);
    }
    let o = conduit(args);
    let report: Value = serde_json::from_str(&stdout(&o))
        .unwrap_or_else(|e| panic!("{e}: {}{}", stdout(&o), stderr(&o)));
    (o.status.code().unwrap_or(-1), report["electrical"].clone())
}

/// The demo's G-code with `edit` applied, checked in the block's frame.
fn check_demo(edit: impl FnOnce(&str) -> String) -> (i32, Value) {
    let dir = temp_dir();
    let path = dir.path().join("demo.gcode");
    std::fs::write(&path, edit(demo_gcode())).expect("G-code written");
    check(
        &path,
        &demo("led_coin.sch"),
        &demo("placement.toml"),
        Some(&demo("block.stl")),
    )
}

fn open_nets(e: &Value) -> Vec<String> {
    e["nets"]
        .as_array()
        .expect("nets")
        .iter()
        .filter(|n| n["connected"] == false)
        .map(|n| n["net"].as_str().expect("name").to_owned())
        .collect()
}

fn count(e: &Value, key: &str) -> u64 {
    e[key].as_u64().unwrap_or_else(|| panic!("{key} in {e}"))
}

/// The first conductive trace of the demo: VCC from R1.1 to the waypoint's trace. Its only
/// extruding line is the one after the first `;DISPENSE:ON`.
const VCC_TRACE: &str = ";DISPENSE:ON\nG1 X109 Y118\n";

#[test]
fn demo_is_connected_without_problems() {
    let (code, e) = check_demo(str::to_owned);
    assert_eq!(code, 0, "{e}");
    let nets = e["nets"].as_array().expect("nets");
    let names: Vec<&str> = nets.iter().filter_map(|n| n["net"].as_str()).collect();
    assert_eq!(names, ["GND", "N1", "VCC"]);
    assert!(nets.iter().all(|n| n["connected"] == true), "{e}");
    // VCC: BAT1.+, R1.1 and the waypoint w1.
    assert_eq!(nets[2]["terminals"], 3);
    for key in ["short_count", "outside_count", "floating_beads"] {
        assert_eq!(count(&e, key), 0, "{key}: {e}");
    }
    assert_eq!(e["events"], Value::Array(Vec::new()));
    assert_eq!(count(&e, "events_found"), 3);
    // Four straight traces, 70.9 mm as the slice report says.
    assert_eq!(count(&e, "beads"), 4);
    let length = e["conductive_length"].as_f64().expect("length");
    assert!((length - 70.9).abs() < 0.1, "{length}");
}

#[test]
fn demo_without_its_model_names_the_frame_problem() {
    // origin = "model" is the block's frame: without --model the pads land elsewhere, the nets
    // are open and the pick-and-place markers disagree with the placement.
    let dir = temp_dir();
    let path = dir.path().join("demo.gcode");
    std::fs::write(&path, demo_gcode()).expect("G-code written");
    let (code, e) = check(&path, &demo("led_coin.sch"), &demo("placement.toml"), None);
    assert_eq!(code, 1);
    assert_eq!(open_nets(&e), ["GND", "N1", "VCC"]);
    let misplaced = e["events"]
        .as_array()
        .expect("events")
        .iter()
        .filter(|p| p["kind"] == "misplaced")
        .count();
    assert_eq!(misplaced, 2, "{e}");
}

#[test]
fn a_deleted_trace_is_an_open_net_with_its_pieces() {
    let (code, e) = check_demo(|g| {
        assert!(g.contains(VCC_TRACE));
        g.replacen(VCC_TRACE, ";DISPENSE:ON\n", 1)
    });
    assert_eq!(code, 1);
    assert_eq!(open_nets(&e), ["VCC"]);
    let vcc = &e["nets"][2];
    assert_eq!(
        vcc["groups"],
        serde_json::json!([["BAT1.+", "VCC:w1"], ["R1.1"]])
    );
    assert_eq!(count(&e, "short_count"), 0);
}

#[test]
fn a_trace_moved_one_layer_up_still_connects_by_stacking_two_layers_up_not() {
    // The VCC trace printed at the end of the layer above (z 4.2 or 4.4) instead of at z 4.
    let moved = |z: &str, layer: &str| {
        let g = demo_gcode().replacen(VCC_TRACE, ";DISPENSE:ON\n", 1);
        let mark = format!(";LAYER_CHANGE\n;Z:{layer}\n");
        assert!(g.contains(&mark));
        let trace = format!(
            "T1\nG1 Z{z}\nG1 X136.05 Y118\n;DISPENSE:ON\nG1 X109 Y118\n;DISPENSE:OFF\nT0\n{mark}"
        );
        g.replacen(&mark, &trace, 1)
    };
    let (code, e) = check_demo(|_| moved("4.2", "4.4"));
    assert_eq!(code, 0, "{e}");
    assert!(open_nets(&e).is_empty());
    let (code, e) = check_demo(|_| moved("4.4", "4.6"));
    assert_eq!(code, 1);
    assert_eq!(open_nets(&e), ["VCC"]);
    assert_eq!(count(&e, "floating_beads"), 1);
}

#[test]
fn a_line_joining_two_nets_is_a_short_where_they_touch() {
    // From a point of the GND trace (120,125)–(137,133) to one of the N1 trace
    // (137,131)–(137.95,118), printed right after the first trace (tool 1, z 4).
    let bridge = ";DISPENSE:OFF\nG1 X130 Y129.706\n;DISPENSE:ON\nG1 X137.438 Y125\n;DISPENSE:OFF\n";
    let (code, e) = check_demo(|g| g.replacen(";DISPENSE:OFF\n", bridge, 1));
    assert_eq!(code, 1);
    assert_eq!(count(&e, "short_count"), 1, "{e}");
    let s = &e["shorts"][0];
    assert_eq!(s["nets"], serde_json::json!(["GND", "N1"]));
    assert_eq!(s["touching"], true);
    assert_eq!(s["gap"], 0.0);
    let at: Vec<f64> = (0..3)
        .map(|k| s["at"][k].as_f64().expect("coordinate"))
        .collect();
    // On the bridge, at the seating plane.
    assert!(
        (128.0..=139.0).contains(&at[0]) && (124.0..=131.0).contains(&at[1]),
        "{at:?}"
    );
    assert!((at[2] - 4.0).abs() < 1e-9);
    // Every net is still connected; the nets merely touch.
    assert!(open_nets(&e).is_empty());
}

#[test]
fn a_trace_closer_to_another_net_than_the_clearance_is_reported_with_its_gap() {
    // A VCC stub from R1.1 (136.05,118) to (137,121) ends 0.729 mm from the centreline of the
    // N1 trace (137,131)–(137.95,118): 0.6 mm traces 0.129 mm apart, under the 0.2 mm of
    // route.channel_extra, without touching.
    let stub = ";DISPENSE:OFF\nG1 X136.05 Y118\n;DISPENSE:ON\nG1 X137 Y121\n;DISPENSE:OFF\n";
    let (code, e) = check_demo(|g| g.replacen(";DISPENSE:OFF\n", stub, 1));
    assert_eq!(code, 1);
    assert_eq!(count(&e, "short_count"), 1, "{e}");
    let s = &e["shorts"][0];
    assert_eq!(s["nets"], serde_json::json!(["N1", "VCC"]));
    assert_eq!(s["touching"], false);
    assert_eq!(s["gap"], 0.129);
    assert!(open_nets(&e).is_empty());
}

#[test]
fn a_trace_past_the_wall_is_material_outside_the_solid() {
    // The VCC trace runs on to x = 100, 5 mm past the block's wall at x = 105.
    let (code, e) =
        check_demo(|g| g.replacen(VCC_TRACE, ";DISPENSE:ON\nG1 X109 Y118\nG1 X100 Y118\n", 1));
    assert_eq!(code, 1);
    assert_eq!(count(&e, "outside_count"), 1, "{e}");
    let run = &e["outside"][0];
    let length = run["length"].as_f64().expect("length");
    assert!((4.5..=5.2).contains(&length), "{length}");
    assert_eq!(run["above_top"], false);
    assert!(open_nets(&e).is_empty());
}

#[test]
fn a_stray_trace_far_off_the_bed_is_outside_and_checked_quickly() {
    let (code, e) = check_demo(|g| {
        g.replacen(
            VCC_TRACE,
            ";DISPENSE:ON\nG1 X109 Y118\nG1 X900000 Y-900000\n",
            1,
        )
    });
    assert_eq!(code, 1);
    assert_eq!(count(&e, "outside_count"), 1, "{e}");
    let length = e["outside_length"].as_f64().expect("length");
    assert!(length > 1.2e6, "{length}");
}

#[test]
fn a_part_placed_before_its_cavity_is_complete_is_early() {
    // The coin cell (top at z 7.2) placed before the layer at z 4.2.
    let (code, e) = check_demo(|g| {
        let g = g.replacen(";MANUAL_INSERT PART=BAT1\n", "", 1);
        g.replacen(
            ";LAYER_CHANGE\n;Z:4.2\n",
            ";MANUAL_INSERT PART=BAT1\n;LAYER_CHANGE\n;Z:4.2\n",
            1,
        )
    });
    assert_eq!(code, 1);
    let events = e["events"].as_array().expect("events");
    assert_eq!(events.len(), 1, "{e}");
    assert_eq!(events[0]["part"], "BAT1");
    assert_eq!(events[0]["kind"], "early");
    assert!(
        events[0]["message"]
            .as_str()
            .is_some_and(|m| m.contains("z 4.000") && m.contains("7.200")),
        "{e}"
    );
}

#[test]
fn a_removed_event_is_missing() {
    let (code, e) = check_demo(|g| g.replacen(";PICK_AND_PLACE PART=R1 ", "; R1 ", 1));
    assert_eq!(code, 1);
    let events = e["events"].as_array().expect("events");
    assert_eq!(events.len(), 1, "{e}");
    assert_eq!(
        (&events[0]["part"], &events[0]["kind"]),
        (&"R1".into(), &"missing".into())
    );
}

/// Postprocesses `host` (copied into a temp dir) with the cube's circuit and checks the result.
fn postprocess_and_check(host: &Path) -> (i32, Value) {
    let dir = temp_dir();
    let file = dir.path().join("host.gcode");
    std::fs::copy(host, &file).expect("host file copied");
    let (sch, toml) = (
        sample("postprocess/cube_led.sch"),
        sample("postprocess/cube_led.toml"),
    );
    let o = conduit([
        "postprocess".as_ref(),
        file.as_os_str(),
        "--circuit".as_ref(),
        sch.as_os_str(),
        "--placement".as_ref(),
        toml.as_os_str(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    check(&file, &sch, &toml, None)
}

fn assert_cube_ok(code: i32, e: &Value) {
    assert_eq!(code, 0, "{e}");
    assert_eq!(open_nets(e), Vec::<String>::new());
    assert_eq!(e["nets"].as_array().map(Vec::len), Some(3));
    assert_eq!(count(e, "short_count"), 0);
    assert_eq!(count(e, "outside_count"), 0);
    // R1 by hand, LED1 by the machine; J1 is not placed.
    assert_eq!(count(e, "events_found"), 2);
    assert!(count(e, "beads") >= 3);
}

#[test]
fn a_postprocessed_cube_is_connected_without_problems() {
    let dir = temp_dir();
    let cube = dir.path().join("cube.gcode");
    let o = conduit([
        "slice".as_ref(),
        sample("cube_20mm.stl").as_os_str(),
        "-o".as_ref(),
        cube.as_os_str(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (code, e) = postprocess_and_check(&cube);
    assert_cube_ok(code, &e);
}

#[test]
fn postprocessed_peer_slicer_cubes_are_connected_without_problems() {
    let Some(corpus) = corpus() else { return };
    for host in ["prusaslicer-2.5", "curaengine-4.13", "slic3r-1.3"] {
        let file = corpus
            .join("peer-gcode")
            .join(format!("20mm_cube.{host}.gcode"));
        let (code, e) = postprocess_and_check(&file);
        assert_cube_ok(code, &e);
    }
}
