//! `conduit place --from-brd`: the corpus boards' layouts moved into a block, checked, and
//! sliced; the layout's geometry against the board file; the refusals.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use conduit::geom::{Point3, Transform};
use conduit::mesh::Mesh;
use conduit::scene::{MeshFormat, Scene, SceneObject, save};
use serde_json::Value;

use crate::support::{conduit, corpus, eagle_file, placement_parts, stderr, stdout, temp_dir};

/// A block `size` mm with its bottom centre at the origin, written as STL.
fn block(dir: &Path, name: &str, size: [f64; 3]) -> PathBuf {
    let mesh = Mesh::cuboid(
        name,
        Point3::new(-size[0] / 2.0, -size[1] / 2.0, 0.0),
        Point3::new(size[0] / 2.0, size[1] / 2.0, size[2]),
    );
    let scene = Scene {
        objects: vec![SceneObject {
            name: name.into(),
            mesh,
            transform: Transform::identity(),
            tool: None,
            negative: None,
        }],
    };
    let path = dir.join(format!("{name}.stl"));
    save(&scene, &path, MeshFormat::Stl).expect("block written");
    path
}

/// Runs `conduit place --json` with `args`; the exit code and the summary.
fn place(args: &[&std::ffi::OsStr]) -> (Option<i32>, Value, String) {
    let mut all: Vec<&std::ffi::OsStr> = vec!["place".as_ref(), "--json".as_ref()];
    all.extend_from_slice(args);
    let o = conduit(all);
    let summary = serde_json::from_str(&stdout(&o)).unwrap_or(Value::Null);
    (o.status.code(), summary, stderr(&o))
}

/// `conduit place --json --model MODEL -o OUT` with `rest`; the exit code and the summary.
fn place_into(model: &Path, out: &Path, rest: &[&std::ffi::OsStr]) -> (Option<i32>, Value, String) {
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "--model".as_ref(),
        model.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ];
    args.extend_from_slice(rest);
    place(&args)
}

/// The parts of a placement TOML by name: (x, y, z, rotation).
fn parts(toml_path: &Path) -> BTreeMap<String, [f64; 4]> {
    placement_parts(toml_path).into_iter().collect()
}

/// Every corpus board with a readable `.brd`: laid out at the scale the first run suggests in
/// a block the layout fits, the placement passes its checks (exit 0), holds every part with a
/// pad on a net (bottom-side parts on the lower plane, face up), and slices.
#[test]
fn every_corpus_board_is_placed_from_its_board_and_slices() {
    let Some(corpus) = corpus() else {
        return;
    };
    let dir = temp_dir();
    let d = dir.path();
    for name in [
        "LilyPad_Vibe_Board",
        "LilyPad_Tri-Color_LED",
        "OpenLog",
        "Serial7SegmentDisplay",
        "RedBot",
    ] {
        let brd = eagle_file(&corpus, name, "brd");
        let probe = block(d, "probe", [400.0, 400.0, 8.0]);
        let out = d.join(format!("{name}.toml"));
        let (_, first, err) = place_into(&probe, &out, &["--from-brd".as_ref(), brd.as_os_str()]);
        let scale = first["suggested_scale"]
            .as_f64()
            .unwrap_or_else(|| panic!("{name}: no scale suggested: {first} {err}"));
        // The layout at that scale, its span read from a probe run, in a block 6 mm larger.
        let s = format!("{scale}");
        let (_, sized, err) = place_into(
            &probe,
            &out,
            &[
                "--from-brd".as_ref(),
                brd.as_os_str(),
                "--scale".as_ref(),
                s.as_ref(),
                "--at".as_ref(),
                "0,0".as_ref(),
            ],
        );
        let span = [
            sized["span_mm"][0]
                .as_f64()
                .unwrap_or_else(|| panic!("{name}: {sized} {err}")),
            sized["span_mm"][1].as_f64().expect("span"),
        ];
        let model = block(d, name, [span[0] + 12.0, span[1] + 12.0, 8.0]);
        let (code, summary, err) = place_into(
            &model,
            &out,
            &[
                "--from-brd".as_ref(),
                brd.as_os_str(),
                "--scale".as_ref(),
                s.as_ref(),
                "--at".as_ref(),
                "0,0".as_ref(),
            ],
        );
        assert_eq!(code, Some(0), "{name}: {summary} {err}");
        assert_eq!(summary["problems"], Value::Array(Vec::new()), "{name}");
        let placed = parts(&out);
        assert_eq!(
            placed.len() as u64,
            summary["parts"].as_u64().expect("parts"),
            "{name}"
        );
        // Every element left out is one without a pad on a net; every other is placed.
        let board = conduit_eagle::read_board(&std::fs::read(&brd).expect("brd")).expect("brd");
        let left: Vec<&str> = summary["left_out"]
            .as_array()
            .expect("left_out")
            .iter()
            .map(|l| l.as_str().expect("line"))
            .collect();
        for e in &board.elements {
            let listed = left.iter().any(|l| l.starts_with(&format!("{}: ", e.name)));
            assert_ne!(placed.contains_key(&e.name), listed, "{name}: {}", e.name);
        }
        // Two planes when the board has bottom-side parts; those sit on the lower one.
        let planes: Vec<f64> = summary["planes"]
            .as_array()
            .expect("planes")
            .iter()
            .map(|z| z.as_f64().expect("z"))
            .collect();
        for e in board.elements.iter().filter(|e| e.rotation.mirror) {
            if let Some(p) = placed.get(&e.name) {
                assert_eq!(planes.len(), 2, "{name}");
                assert!(
                    (p[2] - planes[1]).abs() < 1e-9,
                    "{name}: {} at {}",
                    e.name,
                    p[2]
                );
            }
        }
        // And it slices: the placement matches the circuit and the block. (A coarse, short
        // search: how well the boards route is the business of `electronics_corpus`.)
        let gcode = d.join(format!("{name}.gcode"));
        let o = conduit([
            "slice".as_ref(),
            model.as_os_str(),
            "--circuit".as_ref(),
            brd.as_os_str(),
            "--placement".as_ref(),
            out.as_os_str(),
            "-o".as_ref(),
            gcode.as_os_str(),
            "--allow-unrouted".as_ref(),
            "--set".as_ref(),
            "route.rip_up_rounds=0".as_ref(),
            "--set".as_ref(),
            "route.conductive_width=0.4".as_ref(),
            "--set".as_ref(),
            "route.grid_step=3".as_ref(),
            "--set".as_ref(),
            "route.max_detour=1.5".as_ref(),
            "--set".as_ref(),
            "route.detour_slack=5".as_ref(),
            "-q".as_ref(),
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        assert!(gcode.exists(), "{name}");
        println!(
            "{name}: {} parts at scale {scale}, {:.0} × {:.0} mm, planes {planes:?}",
            placed.len(),
            span[0],
            span[1]
        );
    }
}

/// OpenLog laid out as its first summary suggests routes every wire: the summary names the
/// TQFP's 0.8 mm pitch and the widest trace that fits between its pins, the scale suggested is
/// the one for that width, and slicing with both leaves no wire unrouted.
#[test]
fn openlog_laid_out_as_the_summary_suggests_routes_every_wire() {
    let Some(corpus) = corpus() else {
        return;
    };
    let dir = temp_dir();
    let d = dir.path();
    let brd = eagle_file(&corpus, "OpenLog", "brd");
    let model = block(d, "block", [150.0, 150.0, 6.0]);
    let out = d.join("openlog.toml");
    let (_, first, err) = place_into(&model, &out, &["--from-brd".as_ref(), brd.as_os_str()]);
    let fine = &first["fine_pitch"];
    assert_eq!(fine["part"], "U1", "{first} {err}");
    let distance = fine["distance_mm"].as_f64().expect("distance");
    assert!((distance - 0.8).abs() < 1e-6, "{fine}");
    assert!(
        fine["spacing_mm"].as_f64().expect("spacing") > distance,
        "{fine}"
    );
    // 0.55 mm traces keep the spacing the default 0.6 mm ones break at this pitch.
    let width = fine["suggested_width_mm"].as_f64().expect("width");
    assert!((width - 0.55).abs() < 1e-9, "{fine}");
    assert!(
        (first["room_mm"]["trace"].as_f64().expect("room") - (width + 2.0 * 0.2)).abs() < 1e-9,
        "{first}"
    );
    let scale = first["suggested_scale"].as_f64().expect("a scale");
    let set_width = format!("route.conductive_width={width}");
    let scale = format!("{scale}");
    let (code, summary, err) = place_into(
        &model,
        &out,
        &[
            "--from-brd".as_ref(),
            brd.as_os_str(),
            "--scale".as_ref(),
            scale.as_ref(),
            "--set".as_ref(),
            set_width.as_ref(),
        ],
    );
    assert_eq!(code, Some(0), "{summary} {err}");
    let report = d.join("report.json");
    let o = conduit([
        "slice".as_ref(),
        model.as_os_str(),
        "--circuit".as_ref(),
        brd.as_os_str(),
        "--placement".as_ref(),
        out.as_os_str(),
        "-o".as_ref(),
        d.join("openlog.gcode").as_os_str(),
        "--report".as_ref(),
        report.as_os_str(),
        "--set".as_ref(),
        set_width.as_ref(),
        "-q".as_ref(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    let e = &report["electronics"];
    assert_eq!(e["unrouted"], 0, "{}", e["wires"]);
    assert_eq!(e["routed"], 46);
    assert_eq!(e["warnings"], Value::Array(Vec::new()));
}

/// The layout is the board's, moved, turned and spread as asked: between any two parts the
/// offset is the board's offset turned by `--rotate` and multiplied by `--scale`, each part
/// turns by `--rotate`, and `--at` moves every part by the same amount.
#[test]
fn a_board_layout_is_moved_turned_and_spread_as_asked() {
    let Some(corpus) = corpus() else {
        return;
    };
    let dir = temp_dir();
    let d = dir.path();
    let brd = eagle_file(&corpus, "LilyPad_Tri-Color_LED", "brd");
    let board = conduit_eagle::read_board(&std::fs::read(&brd).expect("brd")).expect("brd");
    let model = block(d, "big", [200.0, 200.0, 8.0]);
    let run = |at: &str, out: &Path| {
        let (code, summary, err) = place_into(
            &model,
            out,
            &[
                "--from-brd".as_ref(),
                brd.as_os_str(),
                "--rotate".as_ref(),
                "90".as_ref(),
                "--scale".as_ref(),
                "1.5".as_ref(),
                format!("--at={at}").as_ref(),
            ],
        );
        assert_eq!(code, Some(0), "{summary} {err}");
        parts(out)
    };
    let (a, b) = (
        run("5,7", &d.join("a.toml")),
        run("-20,3.5", &d.join("b.toml")),
    );
    assert_eq!(a.len(), 8);
    let names: Vec<&String> = a.keys().collect();
    for (i, p) in names.iter().enumerate() {
        let ep = board.element(p).expect("on the board");
        // `--at` moves every part by the difference.
        assert!((a[*p][0] - b[*p][0] - 25.0).abs() < 1e-3, "{p}");
        assert!((a[*p][1] - b[*p][1] - 3.5).abs() < 1e-3, "{p}");
        assert!(
            ((a[*p][3] - ep.rotation.degrees - 90.0).rem_euclid(360.0)).abs() < 1e-3,
            "{p}: {} vs {}",
            a[*p][3],
            ep.rotation.degrees
        );
        for q in &names[i + 1..] {
            let eq = board.element(q).expect("on the board");
            let (bx, by) = (ep.x - eq.x, ep.y - eq.y);
            // Turned a quarter counter-clockwise: (x, y) → (−y, x), then times 1.5.
            let (wx, wy) = (-by * 1.5, bx * 1.5);
            let (gx, gy) = (a[*p][0] - a[*q][0], a[*p][1] - a[*q][1]);
            assert!((gx - wx).abs() < 1e-3 && (gy - wy).abs() < 1e-3, "{p}-{q}");
        }
    }
}

/// A layout that cannot be printed is refused with each problem naming the parts and a
/// distance, and nothing is written; `--force` writes it with the problems as warnings.
#[test]
fn a_layout_with_parts_in_each_others_cavities_or_outside_is_refused() {
    let Some(corpus) = corpus() else {
        return;
    };
    let dir = temp_dir();
    let d = dir.path();
    let brd = eagle_file(&corpus, "OpenLog", "brd");
    let model = block(d, "big", [200.0, 200.0, 8.0]);
    let out = d.join("p.toml");
    let args = |model: &Path, scale: &'static str, force: bool| {
        let mut v: Vec<std::ffi::OsString> = vec![
            "--model".into(),
            model.into(),
            "--from-brd".into(),
            brd.clone().into(),
            "--scale".into(),
            scale.into(),
            "-o".into(),
            out.clone().into(),
        ];
        if force {
            v.push("--force".into());
        }
        v
    };
    let call = |v: Vec<std::ffi::OsString>| {
        let refs: Vec<&std::ffi::OsStr> = v.iter().map(|s| s.as_os_str()).collect();
        place(&refs)
    };
    // At the board's own scale the parts crowd into each other's cavities.
    let (code, summary, err) = call(args(&model, "1", false));
    assert_eq!(code, Some(1), "{summary}");
    assert!(!out.exists(), "nothing written");
    assert!(
        err.lines().any(|l| l.starts_with("error: parts ")
            && (l.contains(" collide: their footprints share ")
                || l.contains(" mm apart: each reaches into the other's cavity"))),
        "{err}"
    );
    assert!(
        err.contains("nothing written (--force writes the placement anyway)"),
        "{err}"
    );
    let (code, _, err) = call(args(&model, "1", true));
    assert_eq!(code, Some(0), "{err}");
    assert!(out.exists());
    assert!(
        err.lines().any(|l| l.starts_with("warning: parts ")),
        "{err}"
    );
    std::fs::remove_file(&out).expect("removed");
    // A block smaller than the layout: parts outside, each with how far.
    let small = block(d, "small", [10.0, 10.0, 8.0]);
    let (code, _, err) = call(args(&small, "2.15", false));
    assert_eq!(code, Some(1));
    let outside = err
        .lines()
        .filter(|l| l.contains(" is not inside the object: ") && l.contains(" mm beyond its edge"))
        .count();
    assert!(outside >= 4, "{err}");
    assert!(!out.exists());
}

/// Bottom-side parts are refused with `--bottom refuse`, naming them; a plane outside the
/// model and a binary (pre-6) EAGLE board are refused in one line naming what is wrong.
#[test]
fn refusals_name_the_parts_the_plane_and_the_file() {
    let Some(corpus) = corpus() else {
        return;
    };
    let dir = temp_dir();
    let d = dir.path();
    let model = block(d, "big", [200.0, 200.0, 8.0]);
    let out = d.join("p.toml");
    let openlog = eagle_file(&corpus, "OpenLog", "brd");
    let board = conduit_eagle::read_board(&std::fs::read(&openlog).expect("brd")).expect("brd");
    let (code, _, err) = place_into(
        &model,
        &out,
        &[
            "--from-brd".as_ref(),
            openlog.as_os_str(),
            "--bottom".as_ref(),
            "refuse".as_ref(),
        ],
    );
    assert_eq!(code, Some(1));
    assert!(err.contains("bottom-side part(s) ("), "{err}");
    // The bottom-side elements that are parts with a pad on a net (fiducials are left out).
    let circuit = conduit::circuit::Circuit::load(&openlog).expect("circuit");
    let on_a_net = |name: &str| {
        circuit
            .nets
            .iter()
            .flat_map(|n| &n.pins)
            .any(|p| p.part == name)
    };
    let bottom: Vec<&str> = board
        .elements
        .iter()
        .filter(|e| e.rotation.mirror && on_a_net(&e.name))
        .map(|e| e.name.as_str())
        .collect();
    assert!(!bottom.is_empty());
    for name in bottom {
        assert!(err.contains(name), "{name} in {err}");
    }
    let (code, _, err) = place_into(
        &model,
        &out,
        &[
            "--from-brd".as_ref(),
            openlog.as_os_str(),
            "--z".as_ref(),
            "12".as_ref(),
        ],
    );
    assert_eq!(code, Some(1));
    assert!(
        err.contains(
            "the seating plane z 12.000 mm is outside the model, which spans z 0.000 to 8.000 mm"
        ),
        "{err}"
    );
    let wifly = eagle_file(&corpus, "WiFly-Shield", "brd");
    let (code, _, err) = place_into(&model, &out, &["--from-brd".as_ref(), wifly.as_os_str()]);
    assert_eq!(code, Some(1));
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains(&*wifly.display().to_string()), "{err}");
    assert!(!out.exists());
}

/// `--auto` packs LilyPad Vibe, Tri-Color LED and OpenLog into a block; the placement passes
/// its checks, every part sits inside the block `route.cavity_offset` + `route.wall_clearance`
/// from its sides on one plane, the print routes every wire (no `--allow-unrouted`), and the
/// circuit rebuilt from the G-code has every net connected and no short.
#[test]
fn auto_placed_boards_route_every_wire() {
    let Some(corpus) = corpus() else {
        return;
    };
    let dir = temp_dir();
    let d = dir.path();
    let model = block(d, "block", [70.0, 60.0, 6.0]);
    for name in ["LilyPad_Vibe_Board", "LilyPad_Tri-Color_LED", "OpenLog"] {
        let sch = eagle_file(&corpus, name, "sch");
        let out = d.join(format!("{name}.toml"));
        let (code, summary, err) = place_into(
            &model,
            &out,
            &["--auto".as_ref(), "--circuit".as_ref(), sch.as_os_str()],
        );
        assert_eq!(code, Some(0), "{name}: {summary} {err}");
        assert_eq!(summary["problems"], Value::Array(Vec::new()), "{name}");
        let planes = summary["planes"].as_array().expect("planes");
        assert_eq!(planes.len(), 1, "{name}");
        // The default plane: under the 6 mm top by the 1 mm body and 1 mm of cover.
        assert_eq!(planes[0].as_f64(), Some(4.0), "{name}");
        let placed = parts(&out);
        assert!(placed.len() >= 5, "{name}");
        for (part, [x, y, z, rotation]) in &placed {
            assert!(
                x.abs() < 35.0 - 1.3 && y.abs() < 30.0 - 1.3,
                "{name}: {part} at {x}, {y}"
            );
            assert_eq!(*z, 4.0);
            assert_eq!(rotation % 90.0, 0.0, "{name}: {part}");
        }
        let gcode = d.join(format!("{name}.gcode"));
        let o = conduit([
            "slice".as_ref(),
            model.as_os_str(),
            "--circuit".as_ref(),
            sch.as_os_str(),
            "--placement".as_ref(),
            out.as_os_str(),
            "-o".as_ref(),
            gcode.as_os_str(),
            // OpenLog's TQFP-32 at 0.8 mm pitch needs traces narrower than the default.
            "--set".as_ref(),
            "route.conductive_width=0.4".as_ref(),
        ]);
        let said = format!("{}{}", stdout(&o), stderr(&o));
        assert!(o.status.success(), "{name}: {said}");
        assert!(said.contains(" wires routed ("), "{name}: {said}");
        let o = conduit([
            "check".as_ref(),
            gcode.as_os_str(),
            "--circuit".as_ref(),
            sch.as_os_str(),
            "--placement".as_ref(),
            out.as_os_str(),
            "--model".as_ref(),
            model.as_os_str(),
        ]);
        let said = stdout(&o);
        assert_eq!(o.status.code(), Some(0), "{name}: {said}{}", stderr(&o));
        assert!(
            said.contains(" 0 shorts, 0 runs outside the solid"),
            "{name}: {said}"
        );
        println!(
            "{name}: {} parts packed; {}",
            placed.len(),
            said.lines()
                .find(|l| l.starts_with("circuit:"))
                .unwrap_or("")
        );
    }
}

/// Parts that do not fit are named, with the room there is and the room they need.
#[test]
fn auto_placement_names_the_parts_that_find_no_room() {
    let Some(corpus) = corpus() else {
        return;
    };
    let dir = temp_dir();
    let d = dir.path();
    let model = block(d, "small", [14.0, 12.0, 6.0]);
    let sch = eagle_file(&corpus, "OpenLog", "sch");
    let out = d.join("p.toml");
    let (code, _, err) = place_into(
        &model,
        &out,
        &["--auto".as_ref(), "--circuit".as_ref(), sch.as_os_str()],
    );
    assert_eq!(code, Some(1));
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("no room for "), "{err}");
    assert!(err.contains(" mm², the parts need about "), "{err}");
    assert!(!out.exists());
}
