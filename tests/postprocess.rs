//! `conduit postprocess`, the slicer plugin mode: host files left byte for byte without a
//! circuit, layers rebuilt from every host's comments (or Z heights), host settings from the
//! environment, binary G-code and bad inputs refused with the file untouched, and the Cura
//! script run against the binary.

use crate::support::{conduit, corpus, root, sample, stderr, stdout, temp_dir};
use conduit::config::SettingSource;
use conduit::pipeline::postprocess::HostPrint;
use conduit::postprocess::{EMode, Host, LayerMethod, RegionParams, ZSource, printed_regions};
use conduit::program::Role;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Every host file the plugin mode is tested on: the peer slicers' 20 mm cubes and the G-code
/// files of gcode-preview (PrusaSlicer 2.7, Slic3r PE, Cura 2.3, FullControl, Mach3).
fn host_files(corpus: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut folders = vec![corpus.join("peer-gcode"), corpus.join("gcode-preview")];
    while let Some(dir) = folders.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                folders.push(path);
            } else if path.extension().is_some_and(|e| e == "gcode") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// Runs `conduit postprocess` with `args` and the extra environment `env`.
fn postprocess(args: &[&std::ffi::OsStr], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_conduit"));
    cmd.arg("postprocess").args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("the conduit binary runs")
}

/// Copies `src` into `dir` and returns the copy's path.
fn copy_into(dir: &Path, src: &Path) -> PathBuf {
    let name = src.file_name().expect("a file name");
    let dst = dir.join(name);
    std::fs::copy(src, &dst).expect("copy into the temp dir");
    dst
}

#[test]
fn without_circuit_every_host_file_is_left_byte_identical() {
    let Some(corpus) = corpus() else { return };
    let files = host_files(&corpus);
    assert!(files.len() >= 10, "{files:?}");
    let dir = temp_dir();
    for src in &files {
        let file = copy_into(dir.path(), src);
        let before = std::fs::read(&file).expect("copy readable");
        let modified = std::fs::metadata(&file).and_then(|m| m.modified()).ok();
        let o = postprocess(&[file.as_os_str()], &[]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}: {}",
            src.display(),
            stderr(&o)
        );
        assert!(stderr(&o).contains("left unchanged"), "{}", stderr(&o));
        assert_eq!(
            std::fs::read(&file).expect("still there"),
            before,
            "{}",
            src.display()
        );
        // Not rewritten at all: the host's file keeps its timestamp.
        let after = std::fs::metadata(&file).and_then(|m| m.modified()).ok();
        assert_eq!(modified, after, "{}", src.display());
    }
}

#[test]
fn peer_cubes_have_100_layers_every_0_2_mm() {
    let Some(corpus) = corpus() else { return };
    for (name, host, method_is_comments) in [
        ("20mm_cube.prusaslicer-2.5.gcode", Host::PrusaSlicer, true),
        (
            "20mm_cube.prusaslicer-2.5-arachne.gcode",
            Host::PrusaSlicer,
            true,
        ),
        ("20mm_cube.curaengine-4.13.gcode", Host::Cura, true),
        ("20mm_cube.slic3r-1.3.gcode", Host::Slic3r, false),
        (
            "20mm_cube.slic3r-1.3-gcode_comments.gcode",
            Host::Slic3r,
            true,
        ),
    ] {
        let bytes = std::fs::read(corpus.join("peer-gcode").join(name)).expect("corpus file");
        let g = conduit_gcode::parse(&bytes).expect("parses");
        let (print, _config) = HostPrint::read(&g, Vec::new()).expect("settings read");
        assert_eq!(print.host.host, host, "{name}");
        assert_eq!(
            matches!(print.layers.method, LayerMethod::Comments(_)),
            method_is_comments,
            "{name}"
        );
        let layers = &print.layers.layers;
        assert_eq!(layers.len(), 100, "{name}");
        for (k, layer) in layers.iter().enumerate() {
            let z = 0.2 * (k + 1) as f64;
            assert!(
                (layer.z - z).abs() < 1e-6,
                "{name} layer {k}: z {}",
                layer.z
            );
            // PrusaSlicer writes `;HEIGHT:0.200001` on some layers.
            assert!(
                (layer.height - 0.2).abs() < 1e-5,
                "{name} layer {k}: {}",
                layer.height
            );
            assert!(!layer.paths.is_empty(), "{name} layer {k}");
            assert_eq!(layer.tools, vec![0], "{name} layer {k}");
            assert_eq!(layer.e_mode, EMode::Absolute, "{name}");
            // The layer's lines hold its extrusions.
            let (first, last) = (layer.first_extrusion_line, layer.last_extrusion_line);
            assert!(
                first.is_some_and(|f| layer.lines.contains(&f))
                    && last.is_some_and(|l| layer.lines.contains(&l)),
                "{name} layer {k}"
            );
        }
        // Layers follow each other without gaps.
        for pair in layers.windows(2) {
            assert_eq!(pair[0].lines.end, pair[1].lines.start, "{name}");
        }
        assert_eq!(layers[99].lines.end, g.lines.len(), "{name}");
        // The outside of a middle layer is the cube's 20 mm square (the external perimeter's
        // outer edge), and every width is near the profile's 0.45 mm lines.
        let middle = &layers[50];
        let regions = printed_regions(&middle.paths, &RegionParams::default());
        let outer: f64 = regions.iter().map(|r| r.contour.area_mm2().abs()).sum();
        assert!((outer - 400.0).abs() < 4.0, "{name}: {outer}");
        for w in &middle.widths {
            assert!((w.width - 0.45).abs() < 0.03, "{name}: {w:?}");
        }
        if host == Host::Cura {
            assert_eq!(print.layers.declared_layer_count, Some(100));
            assert_eq!(middle.host_number, Some(50));
            assert_eq!(middle.z_source, ZSource::Moves);
        }
        if name == "20mm_cube.prusaslicer-2.5.gcode" {
            assert_eq!(middle.z_source, ZSource::Comment);
            let external = middle.width_of(Role::ExternalPerimeter);
            assert!(
                external.is_some_and(|w| (w - 0.45).abs() < 1e-12),
                "{external:?}"
            );
            assert_eq!(print.settings.layer_height(), Some(0.2));
            assert_eq!(print.settings.perimeters(), Some(2));
            assert_eq!(print.settings.count_from(SettingSource::Gcode), 264);
        }
    }
}

/// A small OrcaSlicer file with the Bambu comment set.
const ORCA: &str = "\
; HEADER_BLOCK_START
; generated by OrcaSlicer 2.1.1 on 2026-01-01 at 10:00:00
; total layer number: 2
; HEADER_BLOCK_END
; CONFIG_BLOCK_START
; layer_height = 0.2
; wall_loops = 3
; CONFIG_BLOCK_END
M83
G28
; CHANGE_LAYER
; Z_HEIGHT: 0.2
; LAYER_HEIGHT: 0.2
G1 X10 Y10 Z0.2 F30000
; FEATURE: Outer wall
; LINE_WIDTH: 0.42
G1 X20 Y10 E.5
G1 X20 Y20 E.5
; FEATURE: Sparse infill
; LINE_WIDTH: 0.45
G1 X10 Y20 E.5
G1 E-.8 F1800
; CHANGE_LAYER
; Z_HEIGHT: 0.4
; LAYER_HEIGHT: 0.2
G1 Z0.4
G1 E.8
; FEATURE: Inner wall
; LINE_WIDTH: 0.45
G1 X10 Y10 E.5
";

#[test]
fn orca_comment_set_and_slic3r_environment_through_the_command() {
    let dir = temp_dir();
    let file = dir.path().join("part.gcode.pp");
    std::fs::write(&file, ORCA).expect("write");
    let report = dir.path().join("report.json");
    let o = postprocess(
        &[
            file.as_os_str(),
            "--report".as_ref(),
            report.as_os_str(),
            "--output-name".as_ref(),
            "part_with_circuit.gcode".as_ref(),
        ],
        &[
            ("SLIC3R_LAYER_HEIGHT", "0.2"),
            ("SLIC3R_NOZZLE_DIAMETER", "0.4"),
            ("SLIC3R_PP_OUTPUT_NAME", "/home/user/part.gcode"),
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&file).expect("readable"), ORCA);
    let line = stderr(&o);
    assert!(
        line.contains("OrcaSlicer 2.1.1, 2 layers (; CHANGE_LAYER)"),
        "{line}"
    );
    assert!(line.contains("relative E, retraction 0.8 mm"), "{line}");
    assert!(line.contains("(3 from the environment)"), "{line}");
    let v: Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    assert_eq!(v["host"], "OrcaSlicer");
    assert_eq!(v["layer_count"], 2);
    assert_eq!(v["declared_layer_count"], 2);
    assert_eq!(v["settings_from_environment"], 3);
    assert_eq!(v["changed"], false);
    let layer0 = &v["layers"][0];
    assert_eq!(layer0["z"], 0.2);
    assert_eq!(layer0["first_line"], 11);
    assert_eq!(layer0["widths"][0]["feature"], "Outer wall");
    assert_eq!(layer0["widths"][0]["role"], "External perimeter");
    assert_eq!(layer0["widths"][0]["width"], 0.42);
    assert_eq!(layer0["widths"][1]["role"], "Internal infill");
    assert_eq!(v["layers"][1]["widths"][0]["role"], "Perimeter");
    let name = std::fs::read_to_string(dir.path().join("part.gcode.pp.output_name"))
        .expect("the output name file");
    assert_eq!(name, "part_with_circuit.gcode\n");
}

#[test]
fn cura_comment_set_from_a_small_file() {
    let file = "\
;FLAVOR:Marlin
;Layer height: 0.2
;Generated with Cura_SteamEngine 5.2.1
M82 ;absolute extrusion mode
G28
G92 E0
;LAYER_COUNT:2
;LAYER:0
;MESH:box.stl
G0 F3600 X10 Y10 Z0.2
;TYPE:WALL-OUTER
G1 F1800 X20 Y10 E0.33258
G1 X20 Y20 E0.66516
;TYPE:FILL
G1 X10 Y20 E0.99774
;MESH:NONMESH
G0 F600 X10 Y20 Z0.4
;LAYER:1
;TYPE:WALL-INNER
;MESH:box.stl
G1 F1800 X10 Y10 E1.33032
;End of Gcode
";
    let g = conduit_gcode::parse(file.as_bytes()).expect("parses");
    let (print, _) = HostPrint::read(&g, Vec::new()).expect("read");
    assert_eq!(print.host.host, Host::Cura);
    assert_eq!(print.settings.layer_height(), Some(0.2));
    let layers = &print.layers.layers;
    assert_eq!(layers.len(), 2);
    assert_eq!(
        (layers[0].z, layers[1].z, layers[1].height),
        (0.2, 0.4, 0.2)
    );
    assert_eq!(layers[0].host_number, Some(0));
    assert_eq!(layers[1].lines, 17..22);
    let roles: Vec<Option<Role>> = layers
        .iter()
        .flat_map(|l| &l.paths)
        .map(|p| p.role)
        .collect();
    assert_eq!(
        roles,
        vec![
            Some(Role::ExternalPerimeter),
            Some(Role::SparseInfill),
            Some(Role::Perimeter)
        ]
    );
    // E per 10 mm is 0.33258 mm of 1.75 mm filament: 0.4 × 0.2 mm in Cura's rectangle model.
    for p in layers.iter().flat_map(|l| &l.paths) {
        assert!((p.width - 0.4).abs() < 1e-4, "{}", p.width);
    }
}

#[test]
fn binary_gcode_is_refused_and_left_untouched() {
    let dir = temp_dir();
    let mut files = vec![dir.path().join("made.bgcode")];
    std::fs::write(&files[0], b"GCDE\x01\x00\x00\x00\x01\x00binary blocks").expect("write");
    if let Some(corpus) = corpus() {
        let real = corpus.join("gcode-preview-chestnut/test-data/fixtures/bgcode/prim-cube.bgcode");
        if real.is_file() {
            files.push(copy_into(dir.path(), &real));
        }
    }
    for file in files {
        let before = std::fs::read(&file).expect("readable");
        let o = postprocess(&[file.as_os_str()], &[]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        let message = stderr(&o);
        assert!(message.contains(&file.display().to_string()), "{message}");
        assert!(message.contains("binary G-code"), "{message}");
        assert!(
            message.contains("Printer Settings > General > Firmware > \"Supports binary G-code\""),
            "{message}"
        );
        assert_eq!(std::fs::read(&file).expect("still there"), before);
    }
}

#[test]
fn bad_inputs_fail_naming_the_file_and_leave_it_untouched() {
    let dir = temp_dir();
    let file = dir.path().join("host.gcode");
    std::fs::write(&file, ORCA).expect("write");
    let missing = dir.path().join("nowhere.gcode");
    let o = postprocess(&[missing.as_os_str()], &[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("nowhere.gcode"), "{}", stderr(&o));

    let nul = dir.path().join("nul.gcode");
    std::fs::write(&nul, b"G1 X1\nG1 \0X2\n").expect("write");
    let o = postprocess(&[nul.as_os_str()], &[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("nul.gcode") && stderr(&o).contains("line 2"));

    let no_circuit = dir.path().join("board.sch");
    let o = postprocess(
        &[
            file.as_os_str(),
            "--circuit".as_ref(),
            no_circuit.as_os_str(),
            "--placement".as_ref(),
            sample("circuit_demo/placement.toml").as_os_str(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("board.sch"), "{}", stderr(&o));

    // A valid circuit whose placement names an object the file does not have, and a config
    // without the conductive tool: refused with the reason, file untouched.
    let placement = dir.path().join("elsewhere.toml");
    std::fs::write(
        &placement,
        "origin = \"bbox_center\"\n[[part]]\nname = \"R1\"\nx = 0.0\ny = 0.0\nz = 0.2\nobject = 1\n",
    )
    .expect("write");
    let sch = sample("postprocess/cube_led.sch");
    for (placement, extra, message) in [
        (placement.as_path(), None, "object 1"),
        (
            sample("postprocess/cube_led.toml").as_path(),
            Some("route.conductive_tool=5"),
            "route.conductive_tool = 5",
        ),
    ] {
        let mut args = vec![
            file.as_os_str(),
            "--circuit".as_ref(),
            sch.as_os_str(),
            "--placement".as_ref(),
            placement.as_os_str(),
        ];
        if let Some(set) = extra {
            args.extend([std::ffi::OsStr::new("--set"), std::ffi::OsStr::new(set)]);
        }
        let o = postprocess(&args, &[]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains(message), "{}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"));
        assert_eq!(std::fs::read_to_string(&file).expect("readable"), ORCA);
    }

    let o = conduit([
        "postprocess".as_ref(),
        file.as_os_str(),
        "--circuit".as_ref(),
        "x.sch".as_ref(),
    ]);
    assert_eq!(o.status.code(), Some(2), "--circuit needs --placement");
}

#[test]
fn cura_script_runs_the_binary() {
    let python = Command::new("python3").arg("--version").output();
    if !python.is_ok_and(|o| o.status.success()) {
        println!("skipped: python3 not found");
        return;
    }
    let o = Command::new("python3")
        .arg(root().join("plugins/cura/test_conduit_script.py"))
        .env("CONDUIT_BIN", env!("CARGO_BIN_EXE_conduit"))
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .output()
        .expect("python3 runs");
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        stderr(&o)
    );
}

/// Checks a file edited by `conduit postprocess --circuit CIRCUIT --placement PLACEMENT` against
/// the host's `original` with [`conduit::postprocess::verify`], using the config the command
/// used without `-c` (the host's settings written in the original, or conduit's defaults when
/// they do not make a valid config). Panics with every problem found; returns the report.
///
/// What it asserts (see `src/postprocess/verify.rs`): every original line is in the edited file
/// unchanged and in order, except extruding moves replaced by cut pieces (motion, `G92`,
/// `G10`/`G11` lines); all other added lines are the `; conduit postprocess:` summary or inside
/// `; conduit: traces|parts ... layer` … `; conduit: end` blocks; no host extrusion has a sampled
/// point (every 0.1 mm) inside a layer's cavities or channels shrunk by 0.01 mm; every planned
/// trace point is printed by the conductive tool inside a block, and nothing else extrudes
/// there; every part has exactly one event, after a layer reaching its cavity's top; `check`
/// finds no error. Two host lines may differ, so that `original` can come from a second run of
/// the host without the post-processing script: the first line when both start with
/// `; generated by` (PrusaSlicer's time stamp), and PrusaSlicer's `; post_process = ...` setting.
pub(crate) fn check_postprocessed(
    original: &Path,
    edited: &Path,
    circuit: &Path,
    placement: &Path,
) -> conduit::postprocess::VerifyReport {
    let read = |p: &Path| {
        let bytes = std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        conduit_gcode::parse(&bytes).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
    };
    let (mut original, edited) = (read(original), read(edited));
    let stamp = |g: &conduit_gcode::Gcode| {
        g.lines
            .first()
            .filter(|l| l.text.starts_with(b"; generated by"))
            .cloned()
    };
    if let (Some(_), Some(theirs)) = (stamp(&original), stamp(&edited)) {
        original.lines[0] = theirs;
    }
    // PrusaSlicer writes its post-processing line into the settings at the end.
    let post_process = |g: &conduit_gcode::Gcode| {
        g.lines
            .iter()
            .position(|l| l.text.starts_with(b"; post_process = "))
    };
    if let (Some(i), Some(j)) = (post_process(&original), post_process(&edited)) {
        original.lines[i] = edited.lines[j].clone();
    }
    let (_, config) = HostPrint::read(&original, Vec::new()).expect("host settings read");
    let config = if config.validate().is_ok() {
        config
    } else {
        conduit::config::Config::default()
    };
    let circuit = conduit::circuit::Circuit::load(circuit).expect("circuit loads");
    let placement = conduit::circuit::Placement::load(placement).expect("placement loads");
    let electronics = conduit::pipeline::Electronics { circuit, placement };
    let report = conduit::postprocess::verify(
        &original,
        &edited,
        &electronics,
        &config.postprocess_params(),
    )
    .expect("the circuit plans on the original");
    assert!(
        report.is_ok(),
        "{} problems:\n{}",
        report.problems.len(),
        report.problems.join("\n")
    );
    report
}

/// The peer slicers' cubes the circuit is built into.
const CUBES: [&str; 5] = [
    "20mm_cube.prusaslicer-2.5.gcode",
    "20mm_cube.prusaslicer-2.5-arachne.gcode",
    "20mm_cube.curaengine-4.13.gcode",
    "20mm_cube.slic3r-1.3.gcode",
    "20mm_cube.slic3r-1.3-gcode_comments.gcode",
];

/// Runs `conduit postprocess` with the cube sample circuit on a copy of `src` in `dir` (named
/// `name`), expecting success; returns the edited copy.
fn build_circuit(dir: &Path, src: &Path, name: &str, placement: &Path) -> PathBuf {
    let file = dir.join(name);
    std::fs::copy(src, &file).expect("copy");
    let o = postprocess(
        &[
            file.as_os_str(),
            "--circuit".as_ref(),
            sample("postprocess/cube_led.sch").as_os_str(),
            "--placement".as_ref(),
            placement.as_os_str(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(0), "{name}: {}", stderr(&o));
    assert!(stderr(&o).contains("rewritten"), "{}", stderr(&o));
    file
}

#[test]
fn circuit_is_built_into_every_peer_cube() {
    let Some(corpus) = corpus() else { return };
    let dir = temp_dir();
    let (sch, toml) = (
        sample("postprocess/cube_led.sch"),
        sample("postprocess/cube_led.toml"),
    );
    for name in CUBES {
        let src = corpus.join("peer-gcode").join(name);
        let edited = build_circuit(dir.path(), &src, name, &toml);
        let check = conduit(["check".as_ref(), edited.as_os_str()]);
        assert_eq!(check.status.code(), Some(0), "{name}: {}", stdout(&check));
        let report = check_postprocessed(&src, &edited, &sch, &toml);
        // Three parts: R1 (pause), LED1 (picked), J1 (comment), each once; one block of
        // traces at z 10 and three blocks of part events.
        let mut parts: Vec<&str> = report.events.iter().map(|(n, _)| n.as_str()).collect();
        parts.sort_unstable();
        assert_eq!(parts, vec!["J1", "LED1", "R1"], "{name}");
        assert_eq!(report.blocks, 4, "{name}");
        // OctoPNP's part description: the one part placed by the machine.
        assert_eq!(report.described_parts, ["LED1"], "{name}");
        assert_eq!(report.description_lines, 19, "{name}");
        assert_eq!(report.summary_lines, 5, "{name}");
        assert!(report.replaced_lines.len() >= 15, "{name}: {report:?}");
        assert!(report.moves_tested > 100, "{name}: {report:?}");
        assert!(report.trace_points >= 6, "{name}: {report:?}");
        let text = std::fs::read_to_string(&edited).expect("text");
        assert!(
            text.contains("\nT1\n") && text.contains(";TYPE:Conductive trace"),
            "{name}"
        );
        assert!(
            text.contains("M117 Insert R1") && text.contains("M361 P2"),
            "{name}"
        );
        assert!(
            text.contains("; conduit postprocess: 3 traces (") && text.contains("3 of 3 wires"),
            "{name}"
        );
        // PrusaSlicer's and Slic3r's first line stays first.
        if !name.contains("cura") {
            assert!(text.starts_with("; generated by "), "{name}");
        }
    }
}

#[test]
fn circuit_output_is_deterministic_and_model_origin_is_bed_coordinates() {
    let Some(corpus) = corpus() else { return };
    let dir = temp_dir();
    let src = corpus.join("peer-gcode/20mm_cube.curaengine-4.13.gcode");
    let toml = sample("postprocess/cube_led.toml");
    let a = build_circuit(dir.path(), &src, "a.gcode", &toml);
    let b = build_circuit(dir.path(), &src, "b.gcode", &toml);
    let a = std::fs::read(&a).expect("a");
    assert_eq!(a, std::fs::read(&b).expect("b"), "two runs differ");
    // The same placement in bed coordinates: the cube's centre is (125, 125).
    let text = std::fs::read_to_string(&toml).expect("placement");
    let mut model = String::from("origin = \"model\"\n");
    for line in text.lines().filter(|l| !l.starts_with("origin")) {
        let shifted = match line.split_once(" = ") {
            Some((k @ ("x" | "y"), v)) => {
                let v: f64 = v.parse().expect("a number");
                format!("{k} = {}", v + 125.0)
            }
            _ => line.to_owned(),
        };
        model.push_str(&shifted);
        model.push('\n');
    }
    let model_toml = dir.path().join("model.toml");
    std::fs::write(&model_toml, model).expect("write");
    let c = build_circuit(dir.path(), &src, "c.gcode", &model_toml);
    let c = std::fs::read_to_string(&c).expect("c");
    let a = String::from_utf8(a).expect("text");
    let differ: Vec<(&str, &str)> = a.lines().zip(c.lines()).filter(|(x, y)| x != y).collect();
    // Only the summary's placement line says which origin was used.
    assert_eq!(differ.len(), 1, "{differ:?}");
    assert!(
        differ[0]
            .1
            .contains("placed in bed coordinates (origin model)")
    );
    assert_eq!(a.lines().count(), c.lines().count());
}

#[test]
fn verify_finds_plastic_in_cavities_and_missing_traces_and_events() {
    let Some(corpus) = corpus() else { return };
    let bytes = std::fs::read(corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode"))
        .expect("corpus file");
    let original = conduit_gcode::parse(&bytes).expect("parses");
    let (_, config) = HostPrint::read(&original, Vec::new()).expect("settings");
    let params = config.postprocess_params();
    let electronics = conduit::pipeline::Electronics {
        circuit: conduit::circuit::Circuit::load(&sample("postprocess/cube_led.sch"))
            .expect("circuit"),
        placement: conduit::circuit::Placement::load(&sample("postprocess/cube_led.toml"))
            .expect("placement"),
    };
    // The host's file as it is: every line kept, but plastic fills the cavities and nothing
    // prints the traces or places the parts.
    let report =
        conduit::postprocess::verify(&original, &original, &electronics, &params).expect("plans");
    assert!(!report.is_ok());
    assert_eq!(report.kept_lines, original.lines.len());
    assert!(report.plastic_in_cuts > 0, "{report:?}");
    let text = report.problems.join("\n");
    assert!(
        text.contains("extrudes inside a cavity or channel"),
        "{text}"
    );
    assert!(text.contains("is not printed by tool 1"), "{text}");
    assert!(text.contains("no event places part R1"), "{text}");
    // The edited file passes; with one line of it changed, the line check names it.
    let edit = conduit::pipeline::postprocess::edit_circuit(
        &original,
        &HostPrint::read(&original, Vec::new()).expect("settings").0,
        &electronics,
        &config,
    )
    .expect("edits");
    assert!(
        conduit::postprocess::verify(&original, &edit.gcode, &electronics, &params)
            .expect("plans")
            .is_ok()
    );
    let mut tampered = edit.gcode.clone();
    let i = tampered
        .lines
        .iter()
        .position(|l| l.text.starts_with(b"M107"))
        .expect("a fan line");
    tampered.lines[i] = conduit_gcode::Line::new("M106 S255", conduit_gcode::LineEnding::Lf);
    let report =
        conduit::postprocess::verify(&original, &tampered, &electronics, &params).expect("plans");
    assert!(
        report
            .problems
            .iter()
            .any(|p| p.contains("(M107) is missing or changed")),
        "{:?}",
        report.problems
    );
}

/// The PrusaSlicer 2.5 cube with its comments in OrcaSlicer's (BambuStudio's) set: the same
/// moves, `; CHANGE_LAYER`, `; Z_HEIGHT:`, `; LAYER_HEIGHT:`, `; FEATURE:`, `; LINE_WIDTH:`
/// and an OrcaSlicer header line.
fn orca_cube(prusa: &str) -> String {
    let mut out = String::from("; generated by OrcaSlicer 2.1.1 on 2026-11-25 at 10:00:00\n");
    for line in prusa.lines().skip(1) {
        let orca = if line == ";LAYER_CHANGE" {
            "; CHANGE_LAYER".to_owned()
        } else if let Some(v) = line.strip_prefix(";Z:") {
            format!("; Z_HEIGHT: {v}")
        } else if let Some(v) = line.strip_prefix(";HEIGHT:") {
            format!("; LAYER_HEIGHT: {v}")
        } else if let Some(v) = line.strip_prefix(";TYPE:") {
            let feature = match v {
                "External perimeter" => "Outer wall",
                "Perimeter" => "Inner wall",
                "Internal infill" => "Sparse infill",
                "Solid infill" => "Internal solid infill",
                "Top solid infill" => "Top surface",
                "Bridge infill" => "Bridge",
                other => other,
            };
            format!("; FEATURE: {feature}")
        } else if let Some(v) = line.strip_prefix(";WIDTH:") {
            format!("; LINE_WIDTH: {v}")
        } else {
            line.to_owned()
        };
        out.push_str(&orca);
        out.push('\n');
    }
    out
}

#[test]
fn circuit_is_built_into_an_orcaslicer_file() {
    let Some(corpus) = corpus() else { return };
    let dir = temp_dir();
    let prusa = std::fs::read_to_string(corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode"))
        .expect("cube");
    let src = dir.path().join("orca.gcode");
    std::fs::write(&src, orca_cube(&prusa)).expect("orca cube written");
    let (sch, toml) = (
        sample("postprocess/cube_led.sch"),
        sample("postprocess/cube_led.toml"),
    );
    let edited = build_circuit(dir.path(), &src, "edited.gcode", &toml);
    let report = check_postprocessed(&src, &edited, &sch, &toml);
    assert_eq!(report.events.len(), 3, "{report:?}");
    assert!(report.trace_points >= 6, "{report:?}");
    // The Orca file is read as Orca's: layers from `; CHANGE_LAYER`, features from
    // `; FEATURE:`; cut moves and blocks as in the PrusaSlicer original.
    let text = std::fs::read_to_string(&edited).expect("text");
    assert!(text.starts_with("; generated by OrcaSlicer"));
    let original = build_circuit(
        dir.path(),
        &corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode"),
        "prusa.gcode",
        &toml,
    );
    let prusa_report = check_postprocessed(
        &corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode"),
        &original,
        &sch,
        &toml,
    );
    assert_eq!(report.replaced_lines, prusa_report.replaced_lines);
    assert_eq!(report.blocks, prusa_report.blocks);
}

#[test]
fn the_hosts_tool_change_gcode_switches_to_the_conductive_tool() {
    let Some(corpus) = corpus() else { return };
    let dir = temp_dir();
    let file = copy_into(
        dir.path(),
        &corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode"),
    );
    let (sch, toml) = (
        sample("postprocess/cube_led.sch"),
        sample("postprocess/cube_led.toml"),
    );
    // PrusaSlicer hands its settings to the script as SLIC3R_ variables; its tool-change G-code
    // selects the tool itself.
    let snippet = "G1 Z{layer_z} F600 ; lift\\nT[next_extruder] ; from [previous_extruder]";
    let o = postprocess(
        &[
            file.as_os_str(),
            "--circuit".as_ref(),
            sch.as_os_str(),
            "--placement".as_ref(),
            toml.as_os_str(),
        ],
        &[("SLIC3R_TOOLCHANGE_GCODE", snippet)],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&file).expect("edited");
    assert!(
        text.contains("\nT1 ; from 0\n"),
        "no host-style change to T1"
    );
    assert!(
        text.contains("\nT0 ; from 1\n"),
        "no host-style change back"
    );
    // (A bare `T0` still follows a part event: the active tool is selected again after a
    // placement.)
    let bare = text.lines().filter(|l| *l == "T1").count();
    assert_eq!(bare, 0, "a second T line beside the host's");
    let check = conduit(["check".as_ref(), file.as_os_str()]);
    assert_eq!(check.status.code(), Some(0), "{}", stdout(&check));
}

#[test]
fn the_report_holds_the_edit_and_the_routing() {
    let Some(corpus) = corpus() else { return };
    let dir = temp_dir();
    let file = copy_into(
        dir.path(),
        &corpus.join("peer-gcode/20mm_cube.curaengine-4.13.gcode"),
    );
    let report = dir.path().join("report.json");
    let o = postprocess(
        &[
            file.as_os_str(),
            "--circuit".as_ref(),
            sample("postprocess/cube_led.sch").as_os_str(),
            "--placement".as_ref(),
            sample("postprocess/cube_led.toml").as_os_str(),
            "--report".as_ref(),
            report.as_os_str(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    assert_eq!(v["changed"], true);
    let cut = v["edit"]["cut_moves"].as_u64().expect("cut moves");
    // The same count as the summary at the top of the file.
    let text = std::fs::read_to_string(&file).expect("edited");
    assert!(
        text.contains(&format!("; conduit postprocess: {cut} extrusion moves cut")),
        "{cut}"
    );
    assert_eq!(v["edit"]["blocks"], 4);
    let e = &v["electronics"];
    assert_eq!(
        (e["routed"].as_u64(), e["unrouted"].as_u64()),
        (Some(3), Some(0))
    );
    let total: f64 = e["wires"]
        .as_array()
        .expect("wires")
        .iter()
        .map(|w| w["length"].as_f64().expect("length"))
        .sum();
    assert!((total - e["total_length"].as_f64().expect("total")).abs() < 1e-9);
    assert_eq!(e["parts"].as_array().map(Vec::len), Some(3));
}
