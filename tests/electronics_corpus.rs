//! Corpus EAGLE boards placed on a grid in a generated block and routed.
//!
//! Each board's schematic is loaded and every part with pads is put in a cell of a grid (the
//! cell is the part's pad extent plus [`CELL_MARGIN_MM`] on each side, at least
//! [`MIN_CELL_MM`]), all at rotation 0 on one seating plane, in a cuboid block sized to the
//! grid; parts swap cells until the nets' rubberbands are as short as swaps make them. The block is sliced with the circuit (through the library, or the CLI for one board),
//! and the report must account for every wire of the nets' spanning trees; the small boards
//! must route completely.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use conduit::circuit::{Circuit, Part, Placement};
use conduit::config::Config;
use conduit::geom::{Point3, Transform};
use conduit::mesh::Mesh;
use conduit::pipeline::{Electronics, slice_scene_with};
use conduit::scene::{MeshFormat, Scene, SceneObject, save};
use serde_json::Value;

use crate::support::{conduit, corpus, eagle_file, stderr, temp_dir};

/// Smallest side of a grid cell, mm.
const MIN_CELL_MM: f64 = 6.0;
/// Space on each side of a part's pad extent within its cell, mm.
const CELL_MARGIN_MM: f64 = 2.0;
/// Material around the grid, mm.
const BLOCK_MARGIN_MM: f64 = 5.0;
/// Height of the block, mm.
const BLOCK_HEIGHT_MM: f64 = 4.0;
/// Seating plane of every part, mm: the top of the fifth 0.2 mm layer.
const SEATING_Z_MM: f64 = 1.0;
/// Body height of every part, mm.
const BODY_HEIGHT_MM: f64 = 1.0;

/// Parts on a grid: the placement and the block it fits in.
struct Grid {
    /// The placement, TOML, model coordinates.
    toml: String,
    /// Names of the placed parts.
    placed: BTreeSet<String>,
    /// Size of the block in x and y, mm; the block stands on z = 0 from the origin.
    size: [f64; 2],
}

/// A TOML basic string.
fn toml_string(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// Board positions of the elements of the `.brd` beside `sch`, by part name.
fn board_positions(sch: &Path) -> BTreeMap<String, [f64; 2]> {
    let brd = sch.with_extension("brd");
    let bytes = std::fs::read(&brd).unwrap_or_else(|e| panic!("{}: {e}", brd.display()));
    let board = conduit_eagle::read_board(&bytes).unwrap_or_else(|e| panic!("{e}"));
    board
        .elements
        .iter()
        .map(|e| (e.name.clone(), [e.x, e.y]))
        .collect()
}

/// Where parts in `order` go on a square grid (`ceil(sqrt(n))` columns, row by row): each column
/// as wide as its widest cell, each row as deep as its deepest, a part's pads centred in its
/// cell. Returns each part's offset (package origin, model coordinates) and the grid's size.
fn layout(order: &[(&Part, [f64; 4])], margin: f64) -> (Vec<[f64; 2]>, [f64; 2]) {
    let cell = |e: &[f64; 4]| {
        [
            (e[2] - e[0] + 2.0 * margin).max(MIN_CELL_MM),
            (e[3] - e[1] + 2.0 * margin).max(MIN_CELL_MM),
        ]
    };
    let cols = (order.len() as f64).sqrt().ceil().max(1.0) as usize;
    let rows = order.len().div_ceil(cols);
    let mut widths = vec![0.0f64; cols];
    let mut depths = vec![0.0f64; rows];
    for (k, (_, e)) in order.iter().enumerate() {
        let [w, d] = cell(e);
        widths[k % cols] = widths[k % cols].max(w);
        depths[k / cols] = depths[k / cols].max(d);
    }
    let starts = |sizes: &[f64]| -> Vec<f64> {
        sizes
            .iter()
            .scan(BLOCK_MARGIN_MM, |next, s| {
                let start = *next;
                *next += s;
                Some(start)
            })
            .collect()
    };
    let (xs, ys) = (starts(&widths), starts(&depths));
    let offsets = order
        .iter()
        .enumerate()
        .map(|(k, (_, e))| {
            let (col, row) = (k % cols, k / cols);
            [
                xs[col] + widths[col] / 2.0 - (e[0] + e[2]) / 2.0,
                ys[row] + depths[row] / 2.0 - (e[1] + e[3]) / 2.0,
            ]
        })
        .collect();
    let size = [
        widths.iter().sum::<f64>() + 2.0 * BLOCK_MARGIN_MM,
        depths.iter().sum::<f64>() + 2.0 * BLOCK_MARGIN_MM,
    ];
    (offsets, size)
}

/// Total rubberband length of a layout: per net, the minimum spanning tree (Prim) over its
/// pads on the parts in `order` placed at `offsets`.
fn rubberband_length(circuit: &Circuit, order: &[(&Part, [f64; 4])], offsets: &[[f64; 2]]) -> f64 {
    let at: BTreeMap<&str, (&Part, [f64; 2])> = order
        .iter()
        .zip(offsets)
        .map(|((p, _), o)| (p.name.as_str(), (*p, *o)))
        .collect();
    circuit
        .nets
        .iter()
        .map(|net| {
            let pts: Vec<[f64; 2]> = net
                .pins
                .iter()
                .filter_map(|pin| {
                    let (part, o) = at.get(pin.part.as_str())?;
                    let pad = part.pad(&pin.pad)?;
                    Some([o[0] + pad.x, o[1] + pad.y])
                })
                .collect();
            let mut best: Vec<f64> = vec![f64::INFINITY; pts.len()];
            let mut done = vec![false; pts.len()];
            let mut total = 0.0;
            if !pts.is_empty() {
                best[0] = 0.0;
            }
            for _ in 0..pts.len() {
                let Some(i) = (0..pts.len())
                    .filter(|&i| !done[i])
                    .min_by(|&a, &b| best[a].total_cmp(&best[b]))
                else {
                    break;
                };
                done[i] = true;
                total += best[i];
                for j in 0..pts.len() {
                    let d = (pts[i][0] - pts[j][0]).hypot(pts[i][1] - pts[j][1]);
                    if !done[j] && d < best[j] {
                        best[j] = d;
                    }
                }
            }
            total
        })
        .sum()
}

/// Every part with pads in a cell of a square grid (see [`layout`]), at rotation 0 on one
/// seating plane, arranged as a designer would: starting from the board's own arrangement
/// (parts taken by their board y, rows bottom first, and within a row by board x), two parts
/// swap cells while that shortens the nets' rubberbands (first improvement, in a fixed order,
/// until no swap helps), so a crystal ends up beside its microcontroller rather than wherever the
/// board's rows put it.
fn grid_placement(circuit: &Circuit, positions: &BTreeMap<String, [f64; 2]>, margin: f64) -> Grid {
    let at = |p: &Part| positions.get(&p.name).copied().unwrap_or([f64::MAX; 2]);
    let mut parts: Vec<(&Part, [f64; 4])> = circuit
        .parts
        .iter()
        .filter_map(|p| p.pad_extent().map(|e| (p, e)))
        .collect();
    parts.sort_by(|a, b| at(a.0)[1].total_cmp(&at(b.0)[1]));
    let cols = (parts.len() as f64).sqrt().ceil().max(1.0) as usize;
    for row in parts.chunks_mut(cols) {
        row.sort_by(|a, b| at(a.0)[0].total_cmp(&at(b.0)[0]));
    }
    let cost =
        |order: &[(&Part, [f64; 4])]| rubberband_length(circuit, order, &layout(order, margin).0);
    let mut current = cost(&parts);
    let mut improved = true;
    while improved {
        improved = false;
        for i in 0..parts.len() {
            for j in i + 1..parts.len() {
                parts.swap(i, j);
                let c = cost(&parts);
                if c < current - 1e-9 {
                    current = c;
                    improved = true;
                } else {
                    parts.swap(i, j);
                }
            }
        }
    }
    let (offsets, size) = layout(&parts, margin);
    let mut toml = String::from("origin = \"model\"\n");
    for ((part, _), [x, y]) in parts.iter().zip(&offsets) {
        write!(
            toml,
            "\n[[part]]\nname = {}\nx = {x:?}\ny = {y:?}\nz = {SEATING_Z_MM:?}\n\
             rotation = 0.0\nmethod = \"auto\"\nbody_height = {BODY_HEIGHT_MM:?}\n",
            toml_string(&part.name)
        )
        .expect("writing to a String");
    }
    Grid {
        toml,
        placed: parts.iter().map(|(p, _)| p.name.clone()).collect(),
        size,
    }
}

/// The block for a grid, as a one-object scene.
fn block(grid: &Grid) -> Scene {
    let mesh = Mesh::cuboid(
        "block",
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(grid.size[0], grid.size[1], BLOCK_HEIGHT_MM),
    );
    Scene {
        objects: vec![SceneObject {
            name: "block".into(),
            mesh,
            transform: Transform::identity(),
            tool: None,
            negative: None,
        }],
    }
}

/// Wires the router must be given: per net, one fewer than its pins on placed parts (the
/// spanning tree's edges). Counted from the circuit, not from the report.
fn expected_wires(circuit: &Circuit, placed: &BTreeSet<String>) -> usize {
    circuit
        .nets
        .iter()
        .map(|n| {
            let pins: BTreeSet<(&str, &str)> = n
                .pins
                .iter()
                .filter(|p| placed.contains(&p.part))
                .filter_map(|p| {
                    let pad = circuit.part(&p.part)?.pad(&p.pad)?;
                    Some((p.part.as_str(), pad.name.as_str()))
                })
                .collect();
            pins.len().saturating_sub(1)
        })
        .sum()
}

/// A corpus board placed on its grid.
struct Board {
    name: &'static str,
    circuit: Circuit,
    grid: Grid,
    expected: usize,
}

impl Board {
    /// Corpus board `name`, or `None` (after the skip line) without the corpus.
    fn load(name: &'static str) -> Option<Board> {
        let corpus = corpus()?;
        let sch = eagle_file(&corpus, name, "sch");
        let circuit = Circuit::load(&sch).unwrap_or_else(|e| panic!("{e}"));
        let grid = grid_placement(&circuit, &board_positions(&sch), CELL_MARGIN_MM);
        let expected = expected_wires(&circuit, &grid.placed);
        Some(Board {
            name,
            circuit,
            grid,
            expected,
        })
    }

    /// Slices the block with the circuit through the library; the `electronics` report as
    /// JSON.
    fn slice(&self, cfg: &Config) -> Value {
        let placement = Placement::from_toml(&self.grid.toml).unwrap_or_else(|e| panic!("{e}"));
        let e = Electronics {
            circuit: self.circuit.clone(),
            placement,
        };
        let started = Instant::now();
        let (_, _, summary) = slice_scene_with(&block(&self.grid), cfg, Some(&e), |_| {})
            .unwrap_or_else(|e| panic!("{}: {e}", self.name));
        let report = summary.electronics.expect("a report with a circuit");
        let value = serde_json::to_value(&report).expect("the report serialises");
        self.log(&value, started);
        value
    }

    /// Slices through the CLI into `dir`: the `electronics` report, stderr, and the G-code.
    fn slice_cli(&self, dir: &Path, set: &[&str]) -> (Value, String, PathBuf) {
        let (stl, toml) = (dir.join("block.stl"), dir.join("placement.toml"));
        let (out, report) = (dir.join("board.gcode"), dir.join("report.json"));
        save(&block(&self.grid), &stl, MeshFormat::Stl).expect("block written");
        std::fs::write(&toml, &self.grid.toml).expect("placement written");
        let sch = eagle_file(&corpus().expect("corpus"), self.name, "sch");
        let started = Instant::now();
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
            // The tests judge the routing from the report (a wire left unrouted fails the
            // job, exit 1, without this).
            "--allow-unrouted".as_ref(),
        ];
        for kv in set {
            args.extend([std::ffi::OsStr::new("--set"), std::ffi::OsStr::new(kv)]);
        }
        let o = conduit(args);
        assert!(o.status.success(), "{}: {}", self.name, stderr(&o));
        let text = std::fs::read_to_string(&report).expect("report written");
        let mut value: Value = serde_json::from_str(&text).expect("report is JSON");
        let e = value["electronics"].take();
        self.log(&e, started);
        (e, stderr(&o), out)
    }

    fn log(&self, e: &Value, started: Instant) {
        println!(
            "{}: {} parts on a {:.0} × {:.0} mm grid, {} nets, {} wires expected, {} routed, \
             {} unrouted, {:.1} mm of trace for {:.1} mm straight, {:.1} s",
            self.name,
            self.grid.placed.len(),
            self.grid.size[0],
            self.grid.size[1],
            self.circuit.nets.len(),
            self.expected,
            e["routed"],
            e["unrouted"],
            e["total_length"].as_f64().unwrap_or(f64::NAN),
            e["total_lower_bound"].as_f64().unwrap_or(f64::NAN),
            started.elapsed().as_secs_f64()
        );
    }

    /// The report accounts for every wire: one entry each, counts and totals that add up, no
    /// unplaced pins, every part placed, and routed wires that stay inside the material and are
    /// no shorter than the straight line. Returns the unrouted wires' nets.
    fn check_accounted(&self, e: &Value) -> BTreeSet<String> {
        let name = self.name;
        let wires = e["wires"].as_array().expect("wires");
        assert_eq!(wires.len(), self.expected, "{name}: wires in the report");
        let routed = e["routed"].as_u64().expect("routed") as usize;
        let unrouted = e["unrouted"].as_u64().expect("unrouted") as usize;
        assert_eq!(
            routed + unrouted,
            self.expected,
            "{name}: routed + unrouted"
        );
        let number = |w: &Value, k: &str| w[k].as_f64().unwrap_or_else(|| panic!("{name}: {k}"));
        let (mut length, mut bound, mut count) = (0.0, 0.0, 0);
        let mut failed = BTreeSet::new();
        for w in wires {
            let net = w["net"].as_str().expect("net name");
            assert!(self.circuit.net(net).is_some(), "{name}: unknown net {net}");
            if w["routed"] != Value::Bool(true) {
                failed.insert(net.to_owned());
                continue;
            }
            count += 1;
            let (l, b) = (number(w, "length"), number(w, "lower_bound"));
            assert!(
                l >= b - 1e-6,
                "{name}: net {net} is {l} mm, straight {b} mm"
            );
            assert_eq!(
                w["perimeter_crossings"], 0,
                "{name}: net {net} leaves the block"
            );
            length += l;
            bound += b;
        }
        assert_eq!(count, routed, "{name}: routed wires vs the routed count");
        let total = number(e, "total_length");
        let total_bound = number(e, "total_lower_bound");
        assert!(
            (total - length).abs() < 1e-6 * (1.0 + length),
            "{name}: {total} vs {length}"
        );
        assert!(
            (total_bound - bound).abs() < 1e-6 * (1.0 + bound),
            "{name}: {total_bound}"
        );
        assert!(
            total >= total_bound - 1e-6,
            "{name}: {total} < {total_bound}"
        );
        assert_eq!(e["unplaced_pins"], Value::Array(Vec::new()), "{name}");
        let parts = e["parts"].as_array().expect("parts");
        let names: BTreeSet<String> = parts
            .iter()
            .map(|p| p["name"].as_str().expect("part name").to_owned())
            .collect();
        assert_eq!(names, self.grid.placed, "{name}: parts in the report");
        failed
    }

    /// Every wire routed.
    fn check_complete(&self, e: &Value) {
        let failed = self.check_accounted(e);
        assert!(failed.is_empty(), "{}: unrouted nets {failed:?}", self.name);
        assert_eq!(e["unrouted"], 0);
        assert_eq!(e["routed"], self.expected);
    }
}

#[test]
fn lilypad_vibe_board_routes_completely() {
    let Some(board) = Board::load("LilyPad_Vibe_Board") else {
        return;
    };
    board.check_complete(&board.slice(&Config::default()));
}

#[test]
fn lilypad_tri_color_led_routes_completely_through_the_cli() {
    let Some(board) = Board::load("LilyPad_Tri-Color_LED") else {
        return;
    };
    let dir = temp_dir();
    let (e, err, gcode) = board.slice_cli(dir.path(), &[]);
    board.check_complete(&e);
    assert!(!err.contains("could not be routed"), "{err}");
    let check = conduit(["check".as_ref(), gcode.as_os_str()]);
    assert_eq!(check.status.code(), Some(0), "{}", stderr(&check));
    // The circuit rebuilt from the G-code alone: every net connected, nothing else wrong.
    let sch = eagle_file(&corpus().expect("corpus"), board.name, "sch");
    let dir = dir.path();
    let check = conduit([
        "check".as_ref(),
        gcode.as_os_str(),
        "--circuit".as_ref(),
        sch.as_os_str(),
        "--placement".as_ref(),
        dir.join("placement.toml").as_os_str(),
        "--model".as_ref(),
        dir.join("block.stl").as_os_str(),
    ]);
    let out = crate::support::stdout(&check);
    assert_eq!(check.status.code(), Some(0), "{out}{}", stderr(&check));
    assert!(out.contains(" 0 shorts, 0 runs outside the solid"), "{out}");
}

/// OpenLog's config: its ATmega328 is a TQFP-32 at 0.8 mm pitch, where two 0.6 mm traces with
/// 0.2 mm of clearance do not fit between neighbouring pads (the report warns and names them);
/// 0.4 mm traces do.
fn openlog_config() -> Config {
    let mut cfg = Config::default();
    cfg.route.conductive_width = 0.4;
    cfg
}

#[test]
fn openlog_routes_completely() {
    let Some(board) = Board::load("OpenLog") else {
        return;
    };
    let e = board.slice(&openlog_config());
    board.check_complete(&e);
    // No pitch warning at this width.
    assert_eq!(e["warnings"], Value::Array(Vec::new()));
}

#[test]
fn redbot_reports_every_wire_and_names_the_unrouted_nets() {
    let Some(board) = Board::load("RedBot") else {
        return;
    };
    // RedBot has 0.65 mm-pitch parts (the report names them at the default width); 0.4 mm
    // traces fit them. One pass, no rip-up rounds: this test is about the report of a large
    // board, and keeps the suite short.
    let dir = temp_dir();
    let set = ["route.conductive_width=0.4", "route.rip_up_rounds=0"];
    let (e, err, _) = board.slice_cli(dir.path(), &set);
    let failed = board.check_accounted(&e);
    for w in e["wires"].as_array().expect("wires") {
        if w["routed"] == Value::Bool(false) {
            let line = format!(
                "net {} could not be routed ({} to {})",
                w["net"].as_str().expect("net"),
                w["from"].as_str().expect("from pin"),
                w["to"].as_str().expect("to pin")
            );
            assert!(err.contains(&line), "RedBot: no '{line}' in {err}");
        }
    }
    assert!(
        !failed.is_empty(),
        "RedBot routes completely: make this test ask for it"
    );
    println!("RedBot: unrouted nets {failed:?}");
}

/// Ctrl-C during routing: the job stops within seconds, exits 130 and leaves no output and no
/// temporary file (RedBot routes for far longer than the test waits).
#[test]
fn ctrl_c_stops_routing_and_writes_nothing() {
    let Some(board) = Board::load("RedBot") else {
        return;
    };
    let dir = temp_dir();
    let dir = dir.path();
    let (stl, toml) = (dir.join("block.stl"), dir.join("placement.toml"));
    save(&block(&board.grid), &stl, MeshFormat::Stl).expect("block written");
    std::fs::write(&toml, &board.grid.toml).expect("placement written");
    let sch = eagle_file(&corpus().expect("corpus"), board.name, "sch");
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_conduit"))
        .args([
            "slice".as_ref(),
            stl.as_os_str(),
            "--circuit".as_ref(),
            sch.as_os_str(),
        ])
        .args(["--placement".as_ref(), toml.as_os_str(), "-o".as_ref()])
        .arg(dir.join("board.gcode"))
        .arg("--report")
        .arg(dir.join("report.json"))
        .args(["--set", "route.conductive_width=0.4", "--allow-unrouted"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("conduit runs");
    // Routing starts after slicing (about a second); the first pass alone takes far longer.
    std::thread::sleep(std::time::Duration::from_secs(4));
    let sent = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(sent.success());
    let stopped = Instant::now();
    let out = child.wait_with_output().expect("conduit ends");
    let after = stopped.elapsed().as_secs_f64();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(
        err.contains("interrupted (Ctrl-C): nothing written"),
        "{err}"
    );
    assert!(!err.contains("could not be routed"), "{err}");
    assert!(after < 10.0, "stopped {after:.1} s after Ctrl-C");
    let mut left: Vec<String> = std::fs::read_dir(dir)
        .expect("dir listed")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["block.stl", "placement.toml"]);
    println!("RedBot: Ctrl-C after 4 s, stopped {after:.2} s later, nothing written");
}
