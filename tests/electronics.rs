//! `conduit slice --circuit --placement`: the bundled LED + coin-cell demo built into a block.

use conduit_gcode::{Firmware, Machine};

use crate::support::{conduit, octopnp_description, sample, stderr, temp_dir, xyz};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// One extruding move of the replayed G-code.
pub(crate) struct Extrusion {
    pub(crate) tool: usize,
    pub(crate) role: String,
    pub(crate) z: f64,
    pub(crate) from: [f64; 2],
    pub(crate) to: [f64; 2],
}

impl Extrusion {
    /// Points along the move: both ends and three between.
    pub(crate) fn samples(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        (0..=4).map(|k| {
            let t = f64::from(k) / 4.0;
            [
                self.from[0] + t * (self.to[0] - self.from[0]),
                self.from[1] + t * (self.to[1] - self.from[1]),
            ]
        })
    }
}

/// What the demo's G-code holds: extrusions, and (part, z of the layer it was placed in).
pub(crate) struct Replayed {
    pub(crate) extrusions: Vec<Extrusion>,
    pub(crate) events: Vec<(String, f64)>,
}

/// Replays conduit's G-code: the extruding moves (paste moves with the valve open), and the
/// part events.
pub(crate) fn replay(text: &str) -> Replayed {
    let mut out = Replayed {
        extrusions: Vec::new(),
        events: Vec::new(),
    };
    let g = conduit_gcode::parse(text.as_bytes()).expect("G-code parses");
    let mut machine = Machine::new(Firmware::Marlin, 25.0);
    let mut layer_z = 0.0f64;
    // The paste valve (the default paste_on/off snippets end in these comments).
    let mut valve = false;
    for line in &g.lines {
        let text = String::from_utf8_lossy(&line.text);
        if text.ends_with("; paste on") {
            valve = true;
        } else if text.ends_with("; paste off") {
            valve = false;
        }
        if let Some(z) = text.strip_prefix(";Z:") {
            layer_z = z.parse().expect(";Z: number");
        } else if let Some(rest) = text.strip_prefix(";PICK_AND_PLACE PART=") {
            let part = rest.split(' ').next().unwrap_or_default().to_owned();
            out.events.push((part, layer_z));
        } else if let Some(rest) = text.strip_prefix(";MANUAL_INSERT PART=") {
            out.events.push((rest.to_owned(), layer_z));
        }
        let Some(m) = machine.step(line) else {
            continue;
        };
        let (from, to) = (xyz(m.from), xyz(m.to));
        let moves_xy = to[0] != from[0] || to[1] != from[1];
        // Paste tools carry no E: their moves with the valve open are the traces.
        if moves_xy && (m.e > 0.0 || (m.tool == 1 && valve)) {
            out.extrusions.push(Extrusion {
                tool: m.tool,
                role: m.role.as_deref().unwrap_or_default().to_owned(),
                z: to[2],
                from: [from[0], from[1]],
                to: [to[0], to[1]],
            });
        }
    }
    out
}

/// Slices the bundled demo (block, LED and coin cell) into `dir`: `demo.gcode` and its report
/// `demo.json`, whose paths it returns.
pub(crate) fn slice_demo(dir: &Path) -> (PathBuf, PathBuf) {
    let (o, out, report) = run_demo_slice(dir, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    (out, report)
}

/// `conduit slice` of the demo into `dir` (`demo.gcode`, report `demo.json`) with `extra`
/// arguments: the run and the paths of the G-code and the report.
pub(crate) fn run_demo_slice(
    dir: &Path,
    extra: &[&str],
) -> (std::process::Output, PathBuf, PathBuf) {
    let (out, report) = (dir.join("demo.gcode"), dir.join("demo.json"));
    let demo = |f: &str| sample(&format!("circuit_demo/{f}"));
    let (stl, sch, toml) = (
        demo("block.stl"),
        demo("led_coin.sch"),
        demo("placement.toml"),
    );
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "slice".as_ref(),
        stl.as_os_str(),
        "--circuit".as_ref(),
        sch.as_os_str(),
        "--placement".as_ref(),
        toml.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--report".as_ref(),
        report.as_os_str(),
    ];
    args.extend(extra.iter().map(std::ffi::OsStr::new));
    (conduit(args), out, report)
}

#[test]
fn demo_circuit_slices_with_cavities_traces_events_and_placement_files() {
    let dir = temp_dir();
    let (out, report) = slice_demo(dir.path());
    let check = conduit(["check".as_ref(), out.as_os_str()]);
    assert_eq!(check.status.code(), Some(0), "{}", stderr(&check));

    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    let e = &report["electronics"];
    assert_eq!(e["routed"], 4, "{e}");
    assert_eq!(e["unrouted"], 0);
    let total = e["total_length"].as_f64().expect("length");
    let bound = e["total_lower_bound"].as_f64().expect("bound");
    assert!(
        total >= bound - 1e-6 && total < 2.0 * bound,
        "{total} vs {bound}"
    );
    let parts = e["parts"].as_array().expect("parts");
    assert_eq!(parts.len(), 3);

    let text = std::fs::read_to_string(&out).expect("G-code");
    let r = replay(&text);
    // Traces: on tool 1, on the seating plane's layer (all parts sit at z = 4).
    let traces: Vec<&Extrusion> = r.extrusions.iter().filter(|x| x.tool == 1).collect();
    // At least one move per routed wire (straight runs are one move each).
    assert!(traces.len() >= 4, "{} trace moves", traces.len());
    assert!(traces.iter().all(|t| t.role == "Conductive trace"));
    assert!(traces.iter().all(|t| (t.z - 4.0).abs() < 1e-9));
    // Plastic stays on tool 0.
    assert!(
        r.extrusions
            .iter()
            .filter(|x| x.tool == 0)
            .all(|x| x.role != "Conductive trace")
    );

    // Each part is placed once, at the start of the first layer above its cavity.
    let heights = [("BAT1", 3.2), ("R1", 0.6), ("LED1", 1.0)];
    assert_eq!(r.events.len(), 3);
    for (name, h) in heights {
        let (_, layer_top) = r
            .events
            .iter()
            .find(|(p, _)| p == name)
            .unwrap_or_else(|| panic!("no event for {name}"));
        let layer_bottom = layer_top - 0.2;
        assert!(
            layer_bottom >= 4.0 + h - 1e-6 && layer_bottom < 4.0 + h + 0.2,
            "{name} placed in the layer up to {layer_top}"
        );
    }
    // The coin cell's cavity (24 × 21 mm body + 0.3 mm) is empty of plastic from the seating
    // plane to its top: no plastic extrusion passes inside it (0.5 mm in from its edge).
    let bat = parts
        .iter()
        .find(|p| p["name"] == "BAT1")
        .expect("BAT1 in the report");
    let (cx, cy) = (
        bat["position"][0].as_f64().expect("x"),
        bat["position"][1].as_f64().expect("y"),
    );
    let inside = |p: [f64; 2]| (p[0] - cx).abs() < 12.3 - 0.5 && (p[1] - cy).abs() < 10.8 - 0.5;
    let in_cavity = r
        .extrusions
        .iter()
        .filter(|x| x.tool == 0 && x.z > 4.0 + 1e-6 && x.z <= 7.2 + 1e-6)
        .filter(|x| x.samples().any(inside))
        .count();
    assert_eq!(in_cavity, 0);
    // Under it (the floor) and over it (the lid) there is plastic.
    for z in [4.0, 7.4] {
        assert!(
            r.extrusions
                .iter()
                .any(|x| x.tool == 0 && (x.z - z).abs() < 1e-9 && x.samples().any(inside)),
            "no plastic at z {z}"
        );
    }

    // The pick-and-place files list the parts where the report puts them. BAT1 is inserted by
    // hand: the OpenPnP board has it disabled, the KiCad files (which cannot mark a row
    // disabled) leave it out. The `.pos` rows are read with OpenPnP's importer pattern.
    let report_part = |name: &str| {
        parts
            .iter()
            .find(|p| p["name"] == name)
            .unwrap_or_else(|| panic!("{name} in the report"))
    };
    let at = |part: &Value, k: usize| part["position"][k].as_f64().expect("coordinate");
    let pos = std::fs::read_to_string(dir.path().join("demo.pos")).expect(".pos written");
    assert!(pos.starts_with("### Footprint positions") && pos.ends_with("## End\n"));
    let ascii = conduit_pnp::read_kicad_ascii(&pos).expect("every .pos row matches the importer");
    let csv = std::fs::read_to_string(dir.path().join("demo-pos.csv")).expect("CSV written");
    let csv = conduit_pnp::read_kicad_csv(&csv).expect("CSV parses");
    for records in [&ascii, &csv] {
        let names: Vec<&str> = records.iter().map(|r| r.reference.as_str()).collect();
        assert_eq!(
            names,
            ["LED1", "R1"],
            "machine-placed parts in KiCad's order"
        );
        for rec in records.iter() {
            let part = report_part(&rec.reference);
            for (k, v) in [rec.x, rec.y].into_iter().enumerate() {
                assert!((v - at(part, k)).abs() < 1e-4, "{}: {v}", rec.reference);
            }
        }
    }
    let xml = std::fs::read_to_string(dir.path().join("demo.board.xml")).expect("board written");
    let board = conduit_pnp::read_openpnp_board(&xml).expect("OpenPnP parses");
    assert_eq!(board.len(), 3);
    for rec in &board {
        let part = report_part(&rec.reference);
        for (k, v) in [rec.x, rec.y, rec.z].into_iter().enumerate() {
            assert!((v - at(part, k)).abs() < 1e-4, "{}: {v}", rec.reference);
        }
        assert_eq!(rec.enabled, part["method"] == "auto", "{}", rec.reference);
    }
    assert_eq!(
        board
            .iter()
            .filter(|r| !r.enabled)
            .map(|r| r.reference.as_str())
            .collect::<Vec<_>>(),
        ["BAT1"]
    );
    assert!(xml.contains("<!-- R1: height 0.6000 mm -->"), "{xml}");
}

#[test]
fn unknown_part_in_the_placement_is_an_error_naming_it() {
    let dir = temp_dir();
    let placement = dir.path().join("bad.toml");
    std::fs::write(
        &placement,
        "origin = \"model\"\n[[part]]\nname = \"R9\"\nx = 1.0\ny = 1.0\nz = 1.0\n",
    )
    .expect("written");
    let out = dir.path().join("bad.gcode");
    let o = conduit([
        "slice".as_ref(),
        sample("circuit_demo/block.stl").as_os_str(),
        "--circuit".as_ref(),
        sample("circuit_demo/led_coin.sch").as_os_str(),
        "--placement".as_ref(),
        placement.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_ne!(o.status.code(), Some(0));
    assert!(stderr(&o).contains("R9"), "{}", stderr(&o));
    assert!(!out.exists(), "no G-code on failure");
}

#[test]
fn route_command_draws_every_layer_with_traces_cavities_and_a_report() {
    let dir = temp_dir();
    let svgs = dir.path().join("layers");
    let report = dir.path().join("route.json");
    let demo = |f: &str| sample(&format!("circuit_demo/{f}"));
    let o = conduit([
        "route".as_ref(),
        demo("block.stl").as_os_str(),
        "--circuit".as_ref(),
        demo("led_coin.sch").as_os_str(),
        "--placement".as_ref(),
        demo("placement.toml").as_os_str(),
        "--out-dir".as_ref(),
        svgs.as_os_str(),
        "--report".as_ref(),
        report.as_os_str(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // 8 mm in 0.2 mm layers: 40 SVGs.
    let read = |i: usize| {
        std::fs::read_to_string(svgs.join(format!("layer_{i:04}.svg"))).expect("SVG written")
    };
    assert!(!svgs.join("layer_0041.svg").exists());
    for i in 1..=40 {
        let svg = read(i);
        let z = 0.2 * i as f64;
        assert!(
            svg.contains(&format!("<title>z = {z:.3} mm</title>")),
            "layer {i}"
        );
        // Traces only on the seating plane's layer (z = 4), cavities from there to the coin
        // cell's top (7.2 mm).
        assert_eq!(svg.contains("<polyline"), i == 20, "layer {i}");
        assert_eq!(
            svg.contains("stroke-dasharray"),
            (21..=36).contains(&i),
            "layer {i}"
        );
    }
    assert_eq!(read(20).matches("<polyline").count(), 4);
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    assert_eq!(report["routed"], 4);
    assert_eq!(report["wires"].as_array().map(Vec::len), Some(4));
}

#[test]
fn pad_drops_put_one_drop_on_every_pad() {
    let dir = temp_dir();
    let out = dir.path().join("drops.gcode");
    let demo = |f: &str| sample(&format!("circuit_demo/{f}"));
    let o = conduit([
        "slice".as_ref(),
        demo("block.stl").as_os_str(),
        "--circuit".as_ref(),
        demo("led_coin.sch").as_os_str(),
        "--placement".as_ref(),
        demo("placement.toml").as_os_str(),
        "--set".as_ref(),
        "route.pad_drops=true".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).expect("G-code");
    // Six pads (BAT1 +/−, R1 1/2, LED1 A/C): six drops, each a closed ring of 12 moves on
    // tool 1 at the seating plane.
    let r = replay(&text);
    // (The paste valve is not replayed: the travels between drops are the long moves.)
    let chord = 2.0 * 0.3 * (15f64).to_radians().sin();
    let drops: Vec<&Extrusion> = r
        .extrusions
        .iter()
        .filter(|x| x.role == "Conductive drop")
        .filter(|x| ((x.to[0] - x.from[0]).hypot(x.to[1] - x.from[1]) - chord).abs() < 2e-3)
        .collect();
    assert!(
        drops
            .iter()
            .all(|d| d.tool == 1 && (d.z - 4.0).abs() < 1e-9)
    );
    assert_eq!(drops.len(), 6 * 12, "{} drop moves", drops.len());
}

#[test]
fn wires_between_two_objects_are_reported_with_a_warning_and_not_routed() {
    // The demo with LED1 moved into a second block: N1 (R1 to LED1) and GND (LED1 to the
    // coin cell) would have to leave their object, VCC stays in the first.
    let dir = temp_dir();
    let demo = |f: &str| sample(&format!("circuit_demo/{f}"));
    let second = dir.path().join("second.stl");
    std::fs::copy(demo("block.stl"), &second).expect("second block");
    let text = std::fs::read_to_string(demo("placement.toml")).expect("placement");
    let moved = text.replace(
        "name = \"LED1\"\nx = 32.0\ny = 22.0",
        "name = \"LED1\"\nobject = 1\nx = 20.0\ny = 15.0",
    );
    assert_ne!(moved, text);
    let placement = dir.path().join("two.toml");
    std::fs::write(&placement, moved).expect("placement written");
    let report = dir.path().join("route.json");
    let o = conduit([
        "route".as_ref(),
        demo("block.stl").as_os_str(),
        second.as_os_str(),
        "--circuit".as_ref(),
        demo("led_coin.sch").as_os_str(),
        "--placement".as_ref(),
        placement.as_os_str(),
        "--out-dir".as_ref(),
        dir.path().join("layers").as_os_str(),
        "--report".as_ref(),
        report.as_os_str(),
    ]);
    // Two wires are not routed: the job fails, and still leaves the drawings and the report
    // that show where.
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    for net in ["GND", "N1"] {
        assert!(
            stderr(&o)
                .lines()
                .any(|l| l.starts_with(&format!("error: net {net} could not be routed"))),
            "{}",
            stderr(&o)
        );
    }
    let v: Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    let wires = v["wires"].as_array().expect("wires");
    assert_eq!(wires.len(), 4);
    for w in wires {
        let crosses = [&w["from"], &w["to"]]
            .iter()
            .any(|p| p.as_str().is_some_and(|p| p.starts_with("LED1.")));
        assert_eq!(w["routed"], Value::Bool(!crosses), "{w}");
    }
    assert_eq!(v["routed"], 2);
    assert_eq!(v["unrouted"], 2);
    let warnings: Vec<&str> = v["warnings"]
        .as_array()
        .expect("warnings")
        .iter()
        .filter_map(Value::as_str)
        .collect();
    for net in ["N1", "GND"] {
        assert!(
            warnings
                .iter()
                .any(|w| w.starts_with(&format!("net {net} joins")) && w.contains("object 1")),
            "{warnings:?}"
        );
    }
    assert!(
        stderr(&o).contains("cannot leave its object"),
        "{}",
        stderr(&o)
    );
}

/// The demo placement with `edit` applied to its text, written to `dir/name`.
fn demo_placement_with(
    dir: &std::path::Path,
    name: &str,
    edit: impl Fn(&str) -> String,
) -> PathBuf {
    let text = std::fs::read_to_string(sample("circuit_demo/placement.toml")).expect("sample");
    let path = dir.join(name);
    std::fs::write(&path, edit(&text)).expect("placement written");
    path
}

/// Slices the demo block with `placement` and `extra` arguments: exit code, stderr, whether
/// the G-code exists.
fn slice_demo_with(
    dir: &std::path::Path,
    placement: &Path,
    extra: &[&str],
) -> (Option<i32>, String, bool) {
    let out = dir.join("job.gcode");
    let _ = std::fs::remove_file(&out);
    let mut args: Vec<std::ffi::OsString> = vec![
        "slice".into(),
        sample("circuit_demo/block.stl").into(),
        "--circuit".into(),
        sample("circuit_demo/led_coin.sch").into(),
        "--placement".into(),
        placement.into(),
        "-o".into(),
        out.clone().into(),
    ];
    args.extend(extra.iter().map(Into::into));
    let o = conduit(&args);
    (o.status.code(), stderr(&o), out.exists())
}

/// The part section of `name` in the demo placement, for edits.
fn edit_part(text: &str, name: &str, from: &str, to: &str) -> String {
    let at = text
        .find(&format!("name = \"{name}\""))
        .expect("part in the sample");
    let (head, tail) = text.split_at(at);
    format!("{head}{}", tail.replacen(from, to, 1))
}

#[test]
fn a_circuit_not_built_as_asked_fails_with_each_problem_named_and_writes_nothing() {
    let dir = temp_dir();
    let d = dir.path();
    // (placement edit, expected error lines).
    let outside = demo_placement_with(d, "outside.toml", |t| {
        edit_part(t, "R1", "x = 32.0", "x = 132.0")
    });
    let above = demo_placement_with(d, "above.toml", |t| {
        edit_part(t, "LED1", "z = 4.0", "z = 40.0")
    });
    let collide = demo_placement_with(d, "collide.toml", |t| {
        edit_part(t, "LED1", "y = 22.0", "y = 8.0")
    });
    let empty = d.join("empty.toml");
    std::fs::write(&empty, "origin = \"model\"\n").expect("written");
    let cases: [(&Path, &[&str]); 4] = [
        (
            &outside,
            &[
                "error: part R1 is not inside the object: 3.8 of its 3.8 mm² footprint lies \
                 outside the solid at z 4.000 mm",
                "error: net N1 could not be routed (LED1.A to R1.2)",
            ],
        ),
        (
            &above,
            &[
                "error: part LED1 is above the object: its seating plane z 40.000 mm is 32.000 mm \
               over the object's top (8.000 mm)",
            ],
        ),
        (
            &collide,
            &["error: parts R1 and LED1 collide: their footprints share"],
        ),
        (
            &empty,
            &["error: the placement places no part of the circuit"],
        ),
    ];
    for (placement, expected) in cases {
        let (code, err, written) = slice_demo_with(d, placement, &[]);
        assert_eq!(code, Some(1), "{}: {err}", placement.display());
        assert!(
            !written,
            "{}: no G-code for a failed job",
            placement.display()
        );
        for line in expected {
            assert!(
                err.lines().any(|l| l.starts_with(line)),
                "{}: missing {line:?} in\n{err}",
                placement.display()
            );
        }
        let last = err.lines().last().unwrap_or_default();
        assert!(
            last.contains("job.gcode: the circuit was not built as asked")
                && last.contains("nothing was written (--allow-unrouted accepts it)"),
            "{last}"
        );
        // With --allow-unrouted the same problems are warnings and the files are written.
        let (code, err, written) = slice_demo_with(d, placement, &["--allow-unrouted"]);
        assert_eq!(code, Some(0), "{err}");
        assert!(written);
        for line in expected {
            let warning = line.replacen("error: ", "warning: ", 1);
            assert!(err.lines().any(|l| l.starts_with(&warning)), "{err}");
        }
    }
    // The demo itself is built as asked: no problem at all.
    let (code, err, _) = slice_demo_with(d, &sample("circuit_demo/placement.toml"), &[]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("error") && !err.contains("warning"), "{err}");
}

#[test]
fn the_gcode_carries_octopnps_part_description_for_every_machine_placed_part() {
    let dir = temp_dir();
    let (out, report) = slice_demo(dir.path());
    let text = std::fs::read_to_string(&out).expect("G-code");
    // OctoPNP's reader: from every line, the text from its first `<` to its last `>`, joined;
    // wrapped in an <object> unless the first such line opens one.
    let (xml, root) = octopnp_description(&text);
    assert!(
        xml.lines().next().is_some_and(|l| l.starts_with("<object")),
        "{xml}"
    );
    let root = root.expect("well-formed XML with a root element");
    assert_eq!(root.name, "object");
    // Every M361 P<id> has its part, with OctoPNP's required fields as numbers.
    let ids = crate::support::m361_ids(&text);
    assert_eq!(ids, ["2", "3"]);
    let v: Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    let parts = v["electronics"]["parts"].as_array().expect("parts");
    let described: Vec<&conduit_xml::Node> = root.children_named("part").collect();
    assert_eq!(described.len(), ids.len());
    for ((part, id), (box_number, (name, height, size))) in described
        .iter()
        .zip(&ids)
        .zip([(1, ("R1", 0.6, [2.9, 1.3])), (2, ("LED1", 1.0, [3.0, 1.2]))])
    {
        let number = |node: &conduit_xml::Node, key: &str| -> f64 {
            node.attr(key)
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| panic!("{name}: {key} is not a number"))
        };
        assert_eq!(part.attr("id"), Some(id.as_str()));
        assert_eq!(part.attr("name"), Some(name));
        let child = |n: &str| part.child(n).unwrap_or_else(|| panic!("{name}: no <{n}>"));
        assert_eq!(
            child("position").attr("box"),
            Some(box_number.to_string().as_str())
        );
        assert_eq!(number(child("size"), "height"), height);
        // The outline spans the package's pads.
        let xs: Vec<f64> = child("shape")
            .children
            .iter()
            .map(|p| number(p, "x"))
            .collect();
        let ys: Vec<f64> = child("shape")
            .children
            .iter()
            .map(|p| number(p, "y"))
            .collect();
        let span = |v: &[f64]| {
            v.iter().copied().fold(f64::MIN, f64::max) - v.iter().copied().fold(f64::MAX, f64::min)
        };
        assert!((span(&xs) - size[0]).abs() < 1e-9 && (span(&ys) - size[1]).abs() < 1e-9);
        assert_eq!(child("pads").children.len(), 2);
        let report_part = parts
            .iter()
            .find(|p| p["name"] == name)
            .expect("in the report");
        let destination = child("destination");
        for (k, key) in ["x", "y", "z"].into_iter().enumerate() {
            let want = report_part["position"][k].as_f64().expect("coordinate");
            assert!(
                (number(destination, key) - want).abs() < 1e-4,
                "{name} {key}"
            );
        }
        let rotation = report_part["rotation_deg"].as_f64().expect("rotation");
        assert_eq!(number(destination, "orientation"), rotation);
    }
}
