//! Electronic Slic3r-style `.3de` placements on a circuit of our own: a ring of LEDs in a
//! ring-shaped part, fed through two terminals. The `.3de` uses what Electronic Slic3r writes:
//! a net with a single pin in the schematic wired to a free waypoint (a terminal), waypoint
//! chains, waypoints where several wires meet (branches), a part with `placed="false"`.

use crate::support::{conduit, stderr, temp_dir, write_stl};
use conduit::geom::Point3;
use serde_json::Value;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// LEDs on the ring, at 60° steps from 60° (R1 sits at 0°).
const LEDS: usize = 5;
/// Radii of the ring part, mm, and its height.
const INNER: f64 = 14.0;
const OUTER: f64 = 26.0;
const HEIGHT: f64 = 6.0;
/// Seating plane of every part, mm.
const SEAT: f64 = 3.0;

/// A closed annulus: `n` segments, outward-facing triangles.
fn ring_part(path: &Path) {
    let n = 96;
    let at = |r: f64, k: usize, z: f64| {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        Point3::new(r * a.cos(), r * a.sin(), z)
    };
    let mut tris = Vec::new();
    for k in 0..n {
        let j = (k + 1) % n;
        let (o0, o1) = (at(OUTER, k, 0.0), at(OUTER, j, 0.0));
        let (i0, i1) = (at(INNER, k, 0.0), at(INNER, j, 0.0));
        let up = |p: Point3| Point3::new(p.x, p.y, HEIGHT);
        // Outer wall (normal out), inner wall (normal in), top (up), bottom (down).
        tris.push([o0, o1, up(o1)]);
        tris.push([o0, up(o1), up(o0)]);
        tris.push([i1, i0, up(i0)]);
        tris.push([i1, up(i0), up(i1)]);
        tris.push([up(i0), up(o0), up(o1)]);
        tris.push([up(i0), up(o1), up(i1)]);
        tris.push([i0, o1, o0]);
        tris.push([i0, i1, o1]);
    }
    write_stl(path, &tris);
}

/// The schematic: R1 and LED1..LED5. IN is R1.1 alone (a single-pin net: the battery's plus
/// wire is attached at a terminal), VP joins R1.2 and every anode, GND every cathode.
fn schematic(path: &Path) {
    let mut parts =
        String::from(r#"<part name="R1" library="ring" deviceset="R" device="" value="100R"/>"#);
    let mut gnd = String::new();
    let mut vp = String::from(r#"<pinref part="R1" gate="G$1" pin="2"/>"#);
    for k in 1..=LEDS {
        let _ = write!(
            parts,
            r#"<part name="LED{k}" library="ring" deviceset="LED" device="" value="white"/>"#
        );
        let _ = write!(vp, r#"<pinref part="LED{k}" gate="G$1" pin="A"/>"#);
        let _ = write!(gnd, r#"<pinref part="LED{k}" gate="G$1" pin="C"/>"#);
    }
    let net = |name: &str, pins: &str| {
        format!(r#"<net name="{name}" class="0"><segment>{pins}</segment></net>"#)
    };
    let nets = [
        net("IN", r#"<pinref part="R1" gate="G$1" pin="1"/>"#),
        net("VP", &vp),
        net("GND", &gnd),
    ]
    .concat();
    let text = format!(
        r#"<?xml version="1.0" encoding="utf-8"?>
<eagle version="9.6.2"><drawing><schematic><libraries><library name="ring">
<packages>
<package name="R0805"><smd name="1" x="-0.95" y="0" dx="1" dy="1.3" layer="1"/><smd name="2" x="0.95" y="0" dx="1" dy="1.3" layer="1"/></package>
<package name="LED-0805"><smd name="A" x="-1" y="0" dx="1" dy="1.2" layer="1"/><smd name="C" x="1" y="0" dx="1" dy="1.2" layer="1"/></package>
</packages>
<symbols>
<symbol name="R"><pin name="1" x="-5.08" y="0"/><pin name="2" x="5.08" y="0" rot="R180"/></symbol>
<symbol name="LED"><pin name="A" x="-3.81" y="0"/><pin name="C" x="3.81" y="0" rot="R180"/></symbol>
</symbols>
<devicesets>
<deviceset name="R" prefix="R"><gates><gate name="G$1" symbol="R" x="0" y="0"/></gates><devices><device name="" package="R0805"><connects><connect gate="G$1" pin="1" pad="1"/><connect gate="G$1" pin="2" pad="2"/></connects><technologies><technology name=""/></technologies></device></devices></deviceset>
<deviceset name="LED" prefix="LED"><gates><gate name="G$1" symbol="LED" x="0" y="0"/></gates><devices><device name="" package="LED-0805"><connects><connect gate="G$1" pin="A" pad="A"/><connect gate="G$1" pin="C" pad="C"/></connects><technologies><technology name=""/></technologies></device></devices></deviceset>
</devicesets></library></libraries>
<parts>{parts}</parts>
<sheets><sheet><nets>{nets}</nets></sheet></sheets>
</schematic></drawing></eagle>
"#
    );
    std::fs::write(path, text).expect("schematic written");
}

/// `(x, y)` at radius `r` and angle `deg`.
fn polar(r: f64, deg: f64) -> (f64, f64) {
    let a = deg.to_radians();
    (r * a.cos(), r * a.sin())
}

/// The `.3de` placement (coordinates from the ring's bounding-box centre, which is its axis):
/// R1 at 0° and the LEDs at 60°... radially (anode inward), a terminal for IN inside the ring
/// and one for GND outside it; VP runs as a chain of waypoints inside the LEDs with a branch
/// to each anode, GND as a chain outside them with a branch to each cathode and to its
/// terminal. `extra_part` is one more `<part>` element (or nothing).
fn three_de(path: &Path, extra_part: &str) {
    let mut parts = String::new();
    let mut part = |name: &str, package: &str, deg: f64, placing: &str| {
        let (x, y) = polar(20.0, deg);
        let _ = write!(
            parts,
            r#"<part name="{name}" library="ring" deviceset="X" device="" package="{package}">
<attributes partHeight="0.8" footprintHeight="0.1" placed="1" placingMethod="{placing}" connectionMethod="Layer"/>
<position X="{x:.4}" Y="{y:.4}" Z="{SEAT}"/><rotation X="0" Y="0" Z="{deg}"/></part>
"#
        );
    };
    part("R1", "R0805", 0.0, "Automatic");
    for k in 1..=LEDS {
        part(&format!("LED{k}"), "LED-0805", 60.0 * k as f64, "Automatic");
    }
    parts.push_str(extra_part);
    let waypoint = |key: &str, r: f64, deg: f64| {
        let (x, y) = polar(r, deg);
        format!(r#"<waypoint key="{key}"><position X="{x:.4}" Y="{y:.4}" Z="{SEAT}"/></waypoint>"#)
    };
    let end = |tag: &str, what: &str| {
        if let Some((p, pin)) = what.split_once('.') {
            format!(r#"<{tag} type="part"><part name="{p}" pin="{pin}"/></{tag}>"#)
        } else {
            format!(r#"<{tag} type="waypoint"><waypoint key="{what}"/></{tag}>"#)
        }
    };
    let wire = |a: &str, b: &str| {
        format!(
            "<wire>{}{}</wire>",
            end("endpoint_a", a),
            end("endpoint_b", b)
        )
    };
    // IN: R1.1 (inner pad) to a terminal between the pad and the inner wall.
    let inn = format!(
        r#"<net name="IN"><waypoints>{}</waypoints><wires>{}</wires></net>"#,
        waypoint("T+", 16.0, 0.0),
        wire("R1.1", "T+")
    );
    // VP: R1.2 (outer pad of R1) first to a waypoint beside R1, then a chain at radius 17
    // from 30° to 300° with a branch to each anode (radius 19).
    let mut vp_points = waypoint("V0", 21.5, 20.0);
    let mut vp_wires = wire("R1.2", "V0");
    let mut previous = "V0".to_owned();
    for k in 1..=LEDS {
        let key = format!("V{k}");
        vp_points += &waypoint(&key, 17.0, 60.0 * k as f64 - 10.0);
        vp_wires += &wire(&previous, &key);
        vp_wires += &wire(&key, &format!("LED{k}.A"));
        previous = key;
    }
    let vp = format!(
        r#"<net name="VP"><waypoints>{vp_points}</waypoints><wires>{vp_wires}</wires></net>"#
    );
    // GND: a chain at radius 23.5 from 60° to 300° with a branch to each cathode (radius 21)
    // and one to the terminal at 180° near the outer wall.
    let mut g_points = waypoint("T-", 24.5, 180.0);
    let mut g_wires = String::new();
    for k in 1..=LEDS {
        let key = format!("G{k}");
        g_points += &waypoint(&key, 23.5, 60.0 * k as f64 + 10.0);
        g_wires += &wire(&format!("LED{k}.C"), &key);
        if k > 1 {
            g_wires += &wire(&format!("G{}", k - 1), &key);
        }
    }
    g_wires += &wire("G2", "T-");
    let gnd = format!(
        r#"<net name="GND"><waypoints>{g_points}</waypoints><wires>{g_wires}</wires></net>"#
    );
    let text = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<electronics version="0.1"><filename source="ring.sch"/><parts>
{parts}</parts><nets>{inn}{vp}{gnd}</nets></electronics>
"#
    );
    std::fs::write(path, text).expect(".3de written");
}

struct Job {
    _dir: tempfile::TempDir,
    model: PathBuf,
    sch: PathBuf,
    placement: PathBuf,
    out: PathBuf,
    report: PathBuf,
}

fn job(extra_part: &str) -> Job {
    let dir = temp_dir();
    let d = dir.path().to_path_buf();
    let (model, sch, placement) = (d.join("ring.stl"), d.join("ring.sch"), d.join("ring.3de"));
    ring_part(&model);
    schematic(&sch);
    three_de(&placement, extra_part);
    Job {
        _dir: dir,
        model,
        sch,
        placement,
        out: d.join("ring.gcode"),
        report: d.join("ring.json"),
    }
}

fn slice(job: &Job) -> std::process::Output {
    conduit([
        "slice".as_ref(),
        job.model.as_os_str(),
        "--circuit".as_ref(),
        job.sch.as_os_str(),
        "--placement".as_ref(),
        job.placement.as_os_str(),
        "-o".as_ref(),
        job.out.as_os_str(),
        "--report".as_ref(),
        job.report.as_os_str(),
    ])
}

#[test]
fn a_ring_of_leds_with_terminals_chains_and_branches_routes_completely() {
    let job = job("");
    let o = slice(&job);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&job.report).expect("report")).expect("JSON");
    let e = &report["electronics"];
    // Every wire of the file: IN 1, VP 1 + 2 per LED, GND 2 per LED (chain has one fewer) + 1.
    let expected_wires = 1 + (1 + 2 * LEDS) + (2 * LEDS - 1 + 1);
    assert_eq!(
        e["wires"].as_array().map(Vec::len),
        Some(expected_wires),
        "{e}"
    );
    assert_eq!(e["routed"], expected_wires, "{e}");
    assert_eq!(e["unrouted"], 0);
    assert_eq!(e["part_problems"], Value::Array(Vec::new()));
    // The single-pin net IN is routed, to its terminal.
    assert!(
        e["wires"]
            .as_array()
            .expect("wires")
            .iter()
            .any(|w| w["net"] == "IN" && w["routed"] == true)
    );
    // Two terminals, T+ on IN and T- on GND, where the file puts them (the ring is centred on
    // the bed: the report's part positions give the centre), on the layer top at the seat.
    let terminals = e["terminals"].as_array().expect("terminals");
    let names: Vec<(&str, &str)> = terminals
        .iter()
        .map(|t| {
            (
                t["net"].as_str().unwrap_or(""),
                t["name"].as_str().unwrap_or(""),
            )
        })
        .collect();
    assert_eq!(names, [("IN", "T+"), ("GND", "T-")]);
    let r1 = e["parts"]
        .as_array()
        .expect("parts")
        .iter()
        .find(|p| p["name"] == "R1")
        .expect("R1");
    let centre = (
        r1["position"][0].as_f64().expect("x") - 20.0,
        r1["position"][1].as_f64().expect("y"),
    );
    for (t, (r, deg)) in terminals.iter().zip([(16.0, 0.0), (24.5, 180.0)]) {
        let (x, y) = polar(r, deg);
        let at = |k: usize| t["position"][k].as_f64().expect("coordinate");
        assert!(
            (at(0) - centre.0 - x).abs() < 1e-3 && (at(1) - centre.1 - y).abs() < 1e-3,
            "{t}"
        );
        assert!((at(2) - SEAT).abs() < 1e-6, "{t}");
        assert_eq!(t["pad_diameter"], 2.0);
    }
    // Each terminal's contact pad is printed: on the seat layer, a ring of conductive moves
    // 0.7 mm from its centre (the pad's edge less half a trace), 24 corners all round.
    let gcode = std::fs::read_to_string(&job.out).expect("G-code");
    let replayed = crate::electronics::replay(&gcode);
    for t in terminals {
        let c = [
            t["position"][0].as_f64().unwrap_or(0.0),
            t["position"][1].as_f64().unwrap_or(0.0),
        ];
        let mut corners: Vec<i64> = replayed
            .extrusions
            .iter()
            .filter(|x| x.tool == 1 && (x.z - SEAT).abs() < 1e-6)
            .map(|x| x.to)
            .filter(|p| (((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt() - 0.7).abs() < 2e-3)
            .map(|p| ((p[1] - c[1]).atan2(p[0] - c[0]).to_degrees() / 15.0).round() as i64)
            .collect();
        corners.sort_unstable();
        corners.dedup();
        assert_eq!(corners.len(), 24, "{t}: ring corners {corners:?}");
    }
    // The electrical check, from the G-code alone: every net (terminals included) connected,
    // nothing shorted, nothing outside the ring.
    let check = conduit([
        "check".as_ref(),
        job.out.as_os_str(),
        "--circuit".as_ref(),
        job.sch.as_os_str(),
        "--placement".as_ref(),
        job.placement.as_os_str(),
        "--model".as_ref(),
        job.model.as_os_str(),
        "--json".as_ref(),
    ]);
    assert_eq!(check.status.code(), Some(0), "{}", stderr(&check));
    let v: Value = serde_json::from_slice(&check.stdout).expect("check JSON");
    let el = &v["electrical"];
    let nets = el["nets"].as_array().expect("nets");
    assert_eq!(nets.len(), 3, "{el}");
    assert!(nets.iter().all(|n| n["connected"] == true), "{el}");
}

#[test]
fn a_part_not_placed_is_a_warning_and_a_tilted_part_is_refused_by_name() {
    // R2 is in the .3de but not placed: it is not in the schematic either, as Electronic
    // Slic3r keeps parts it was told about; the file still loads and says so.
    let unplaced = r#"<part name="LED9" library="ring" deviceset="LED" device="" package="LED-0805">
<attributes partHeight="0.8" footprintHeight="0.1" placed="false" placingMethod="Automatic" connectionMethod="Layer"/>
<position X="0" Y="0" Z="0"/><rotation X="0" Y="0" Z="0"/></part>"#;
    let with_unplaced = job(unplaced);
    let o = slice(&with_unplaced);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o)
            .lines()
            .any(|l| l.starts_with("warning: part LED9 is not placed in the object")),
        "{}",
        stderr(&o)
    );

    // LED3 turned onto its side: refused with its name.
    let tilted = job("");
    let text = std::fs::read_to_string(&tilted.placement).expect("placement");
    let text = text.replacen(
        r#"<rotation X="0" Y="0" Z="180"/>"#,
        r#"<rotation X="90" Y="0" Z="180"/>"#,
        1,
    );
    std::fs::write(&tilted.placement, text).expect("written");
    let o = slice(&tilted);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("part \"LED3\" is turned 90° about x and 0° about y")
            && err.contains("ring.3de"),
        "{err}"
    );
    assert!(!tilted.out.exists());
}

#[test]
fn info_lists_the_circuit_parts_pads_and_nets_with_the_single_pin_net() {
    let job = job("");
    let o = conduit(["info".as_ref(), "--json".as_ref(), job.sch.as_os_str()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).expect("JSON");
    let c = &v[0]["circuit"];
    assert_eq!(v[0]["nets"], 3);
    assert_eq!(v[0]["parts"], 1 + LEDS);
    let net = |name: &str| {
        c["nets"]
            .as_array()
            .expect("nets")
            .iter()
            .find(|n| n["name"] == name)
            .map(|n| n["pins"].clone())
    };
    assert_eq!(net("IN"), Some(serde_json::json!(["R1.1"])));
    let anodes: Vec<String> = std::iter::once("R1.2".to_owned())
        .chain((1..=LEDS).map(|k| format!("LED{k}.A")))
        .collect();
    let mut vp: Vec<String> = serde_json::from_value(net("VP").expect("VP")).expect("pins");
    vp.sort();
    let mut want = anodes;
    want.sort();
    assert_eq!(vp, want);
    // R1's pads: 1 × 1.3 mm at ±0.95 mm, together 2.9 × 1.3 mm.
    let r1 = &c["parts"][0];
    assert_eq!(r1["name"], "R1");
    assert_eq!(r1["package"], "R0805");
    assert_eq!(r1["pads_size"], serde_json::json!([2.9, 1.3]));
    assert_eq!(r1["pads"][0]["at"], serde_json::json!([-0.95, 0.0]));
    assert_eq!(r1["pads"][0]["size"], serde_json::json!([1.0, 1.3]));
    assert_eq!(r1["pads"][0]["kind"], "smd");
}
