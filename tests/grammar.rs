//! The command-line grammar shared by every command: `-q/--quiet` and `-v/--verbose`, `--json`
//! summaries, the output flags (`-o/--output`, `--out-dir`, `--dialect`), messages in words
//! (no Rust type names, "did you mean"), one line per error and the grouped warning of ignored
//! PrusaSlicer settings.

use crate::support::{conduit, corpus, sample, stderr, stdout, temp_dir};
use serde_json::Value;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};

/// `args` as the arguments of one run: text and paths mixed.
fn run(args: &[&dyn AsRef<OsStr>]) -> std::process::Output {
    conduit(args.iter().map(|a| a.as_ref().to_os_string()))
}

/// The JSON document a `--json` run printed on stdout, after checking that it succeeded, that
/// stdout holds nothing else and that every output it lists exists.
fn json_of(o: &std::process::Output, what: &str) -> Value {
    assert!(o.status.success(), "{what}: {}", stderr(o));
    let text = stdout(o);
    let v: Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{what}: {e}: {text}"));
    let outputs = v["outputs"]
        .as_array()
        .unwrap_or_else(|| panic!("{what}: {v}"));
    assert!(!outputs.is_empty(), "{what}: no outputs");
    for p in outputs {
        let p = p.as_str().unwrap_or_default();
        assert!(Path::new(p).exists(), "{what}: {p} listed but not written");
    }
    v
}

/// A PrusaSlicer profile with settings conduit reads, three it ignores that change the print
/// only when not off (`raft_layers = 2` and `ironing = 1` do, `spiral_vase = 0` does not) and two
/// that do not change it.
/// A partial profile: five keys conduit ignores, and the four whose PrusaSlicer defaults it
/// prints otherwise (stated, so the only warning is about the ignored ones).
const PROFILE: &str = "layer_height = 0.2\nraft_layers = 2\nironing = 1\nspiral_vase = 0\n\
                       gcode_comments = 0\nwipe = 1\ngcode_flavor = marlin2\n\
                       fill_pattern = rectilinear\ntop_fill_pattern = rectilinear\n\
                       bottom_fill_pattern = rectilinear\n";

#[test]
fn quiet_silences_summaries_and_warnings_but_not_errors() {
    let dir = temp_dir();
    let ini = dir.path().join("p.ini");
    std::fs::write(&ini, PROFILE).expect("profile written");
    let out = dir.path().join("cube.gcode");
    let cube = sample("cube_20mm.stl");
    let loud = run(&[&"slice", &cube, &"-c", &ini, &"-o", &out]);
    assert!(loud.status.success(), "{}", stderr(&loud));
    let text = stderr(&loud);
    assert!(
        text.contains("warning: ") && text.contains(" layers, "),
        "{text}"
    );
    for flags in [["-q", "slice"], ["slice", "--quiet"]] {
        let o = run(&[&flags[0], &flags[1], &cube, &"-c", &ini, &"-o", &out]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(stderr(&o), "", "{flags:?}");
    }
    // Errors still print.
    let o = run(&[&"-q", &"slice", &dir.path().join("none.stl"), &"-o", &out]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
    assert!(stderr(&o).starts_with("error: "), "{}", stderr(&o));
    // Quiet and verbose at once is a usage error.
    let o = run(&[&"-q", &"-v", &"config", &"--defaults"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn every_command_with_a_summary_prints_it_as_json() {
    let dir = temp_dir();
    let d = dir.path();
    let gcode = d.join("cube.gcode");
    let cube = sample("cube_20mm.stl");

    let v = json_of(&run(&[&"slice", &cube, &"-o", &gcode, &"--json"]), "slice");
    assert_eq!(v["layers"], 100, "{v}");
    assert!(v["filament_mm"].as_f64().unwrap_or_default() > 100.0, "{v}");
    assert_eq!(v["report"]["layers"], 100, "{v}");

    let v = json_of(
        &run(&[&"preview", &gcode, &"--out-dir", &d.join("p/q"), &"--json"]),
        "preview",
    );
    assert_eq!(v["layers"], 100, "{v}");

    let bad = d.join("bad.stl");
    std::fs::write(&bad, "solid x\nfacet\n").expect("written");
    let o = run(&[
        &"convert",
        &bad,
        &cube,
        &"--to",
        &"obj",
        &"--out-dir",
        &d.join("c/d"),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let o2 = run(&[
        &"convert",
        &bad,
        &cube,
        &"--to",
        &"obj",
        &"--out-dir",
        &d.join("c/d"),
        &"--json",
    ]);
    assert_eq!(o2.status.code(), Some(1));
    let v: Value = serde_json::from_str(&stdout(&o2)).expect("convert --json");
    assert_eq!(
        (v["converted"].as_u64(), v["failed"].as_u64()),
        (Some(1), Some(1)),
        "{v}"
    );
    assert_eq!(v["conversions"][1]["triangles"], 12, "{v}");
    // Each failure is one line, with no count line after it.
    for o in [&o, &o2] {
        assert_eq!(stderr(o).lines().count(), 1, "{}", stderr(o));
    }

    let demo = |f: &str| sample(&format!("circuit_demo/{f}"));
    let v = json_of(
        &run(&[
            &"route",
            &demo("block.stl"),
            &"--circuit",
            &demo("led_coin.sch"),
            &"--placement",
            &demo("placement.toml"),
            &"--out-dir",
            &d.join("route/new"),
            &"--json",
        ]),
        "route",
    );
    assert_eq!(
        (v["parts"].as_u64(), v["routed"].as_u64()),
        (Some(3), Some(4)),
        "{v}"
    );

    let v = json_of(
        &run(&[
            &"conform",
            &"--surface",
            &sample("conform/wrinkled_film.xyz"),
            &"--design",
            &sample("conform/monopole.svg"),
            &"--set",
            &"printer.start_gcode=G28",
            &"--output",
            &d.join("m.gcode"),
            &"--json",
        ]),
        "conform",
    );
    assert_eq!(v["dialect"], "gcode", "{v}");
    assert_eq!(v["report"]["paths"], 2, "{v}");

    let v = json_of(
        &run(&[
            &"jet",
            &sample("jet/star8.svg"),
            &"--width",
            &"20",
            &"--layers",
            &"2",
            &"--layer-height",
            &"5",
            &"-o",
            &d.join("jet.gcode"),
            &"--json",
        ]),
        "jet",
    );
    assert_eq!(v["layers"], 2, "{v}");

    let v = json_of(
        &run(&[
            &"calibrate",
            &"tcp",
            &sample("robot/pivot.csv"),
            &"--report",
            &d.join("t.json"),
            &"--json",
        ]),
        "calibrate tcp",
    );
    assert!(v["report"]["tcp"].is_array(), "{v}");
    let v = json_of(
        &run(&[
            &"calibrate",
            &"register",
            &sample("robot/scanner_points.csv"),
            &sample("robot/robot_points.csv"),
            &"--report",
            &d.join("r.json"),
            &"--json",
        ]),
        "calibrate register",
    );
    assert!(v["report"]["matrix"].is_array(), "{v}");

    let circle = d.join("circle.csv");
    let v = json_of(
        &run(&[
            &"compensate",
            &"pattern",
            &"circle",
            &"--size",
            &"10",
            &"--surface",
            &"sphere:15",
            &"-o",
            &circle,
            &"--json",
        ]),
        "compensate pattern",
    );
    assert!(v["poses"].as_u64().unwrap_or_default() > 10, "{v}");
    let v = json_of(
        &run(&[
            &"compensate",
            &circle,
            &"--simulate",
            &"sphere:15",
            &"--shift",
            &"3,1.5,0",
            &"-o",
            &d.join("comp.csv"),
            &"--json",
        ]),
        "compensate",
    );
    assert_eq!(v["poses"], json_of_poses(&circle), "{v}");

    let pp = d.join("pp.gcode");
    std::fs::copy(&gcode, &pp).expect("copied");
    let o = run(&[
        &"postprocess",
        &pp,
        &"--report",
        &d.join("pp.json"),
        &"--json",
    ]);
    let v = json_of(&o, "postprocess");
    assert_eq!(v["changed"], false, "{v}");
    assert!(v["report"].is_object(), "{v}");
}

/// The number of poses in a pose table (rows after the header and `#` lines).
fn json_of_poses(table: &Path) -> Value {
    let text = std::fs::read_to_string(table).expect("table");
    let rows = text
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .count();
    Value::from(rows - 1)
}

#[test]
fn output_flags_are_spelled_alike_and_folders_are_made() {
    let dir = temp_dir();
    let d = dir.path();
    // The same name in two folders: a KRL program is named after its file.
    std::fs::create_dir_all(d.join("old")).expect("folder made");
    let (a, b) = (d.join("m.src"), d.join("old/m.src"));
    // The file is `-o/--output` (`--out` still taken), the language `--dialect`.
    let o = conform(&[&"--output", &a, &"--dialect", &"krl"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    // The old spelling of the dialect beside the file: the same program, with a warning.
    let o = conform(&[&"--out", &b, &"--output", &"krl"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("warning: `--output krl` is now spelled `--dialect krl`"));
    let program = |p: &Path| std::fs::read_to_string(p).unwrap_or_default();
    assert!(program(&a).starts_with("&ACCESS"), "not KRL");
    assert!(
        program(&a) == program(&b),
        "the two spellings wrote different programs"
    );
    // The old spelling alone names no file: a usage error saying what to write.
    let o = conform(&[&"--output", &"krl"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--dialect krl"), "{}", stderr(&o));

    // `--out-dir` makes missing folders, nested ones too, for every command that has it.
    let gcode = d.join("cube.gcode");
    let o = run(&[&"slice", &sample("cube_20mm.stl"), &"-o", &gcode]);
    assert!(o.status.success(), "{}", stderr(&o));
    let demo = |f: &str| sample(&format!("circuit_demo/{f}"));
    for (what, args, dir) in [
        (
            "preview",
            vec!["preview".to_owned(), path(&gcode)],
            d.join("pv/a"),
        ),
        (
            "route",
            vec![
                "route".to_owned(),
                path(&demo("block.stl")),
                "--circuit".to_owned(),
                path(&demo("led_coin.sch")),
                "--placement".to_owned(),
                path(&demo("placement.toml")),
            ],
            d.join("rt/a"),
        ),
        ("man", vec!["man".to_owned()], d.join("man/a")),
        (
            "convert",
            vec![
                "convert".to_owned(),
                path(&sample("cube_20mm.stl")),
                "--to".into(),
                "obj".into(),
            ],
            d.join("cv/a"),
        ),
    ] {
        let mut all = args;
        all.extend(["--out-dir".to_owned(), path(&dir)]);
        let o = conduit(&all);
        assert!(o.status.success(), "{what}: {}", stderr(&o));
        assert!(
            std::fs::read_dir(&dir).map(|r| r.count()).unwrap_or(0) > 0,
            "{what}"
        );
    }
    // The short `-o` of a folder is no longer shown in the help of route and preview.
    let help = stdout(&conduit(["preview", "--help"]));
    assert!(
        help.contains("--out-dir <DIR>") && !help.contains("-o, --out-dir"),
        "{help}"
    );
}

/// Runs `conduit conform` on the monopole sample with a tilted tool and the output flags `out`.
fn conform(out: &[&dyn AsRef<OsStr>]) -> std::process::Output {
    let (surface, design) = (
        sample("conform/wrinkled_film.xyz"),
        sample("conform/monopole.svg"),
    );
    let mut args: Vec<&dyn AsRef<OsStr>> = vec![
        &"conform",
        &"--surface",
        &surface,
        &"--design",
        &design,
        &"--set",
        &"printer.start_gcode=G28",
        &"--tool-axis",
        &"normal",
    ];
    args.extend(out.iter().copied());
    run(&args)
}

/// `p` as text.
fn path(p: &Path) -> String {
    p.display().to_string()
}

#[test]
fn config_errors_say_what_a_value_must_be_in_words() {
    let dir = temp_dir();
    let cfg = dir.path().join("c.toml");
    let out = dir.path().join("x.gcode");
    let cube = sample("cube_20mm.stl");
    for (toml, want) in [
        (
            "[slice]\nlayer_height = \"abc\"\n",
            "c.toml:2: slice.layer_height must be a number in mm, got \"abc\"",
        ),
        (
            "[slice]\nperimeters = 2.5\n",
            "c.toml:2: slice.perimeters must be a whole number ≥ 0, got 2.5",
        ),
        (
            "[printer]\nbed_size = [1]\n",
            "c.toml:2: printer.bed_size must be a list of 2 values `[…]`, got 1 value",
        ),
    ] {
        std::fs::write(&cfg, toml).expect("config written");
        let o = run(&[&"slice", &cube, &"-c", &cfg, &"-o", &out]);
        assert_eq!(o.status.code(), Some(1));
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{err}");
        // The error names the config, not the model.
        assert!(err.ends_with(&format!("{want}\n")), "{err}");
        assert!(
            err.starts_with(&format!("error: {}", cfg.display())),
            "{err}"
        );
    }
    let o = run(&[
        &"slice",
        &cube,
        &"--set",
        &"tools.0.temperature=hot",
        &"-o",
        &out,
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--set tools.0.temperature must be a number in °C, got \"hot\""),
        "{}",
        stderr(&o)
    );
    // clap suggests commands.
    let o = run(&[&"slcie"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("'slice'"), "{}", stderr(&o));
}

#[test]
fn a_config_refused_by_the_command_is_named() {
    let dir = temp_dir();
    let cfg = dir.path().join("conform.toml");
    std::fs::write(&cfg, "[conform]\nfeed = -5\n").expect("config written");
    let o = run(&[
        &"conform",
        &"--surface",
        &sample("conform/wrinkled_film.xyz"),
        &"--design",
        &sample("conform/monopole.svg"),
        &"-c",
        &cfg,
        &"-o",
        &dir.path().join("m.gcode"),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with(&format!(
            "error: {}: invalid config: conform.feed",
            cfg.display()
        )),
        "{err}"
    );
}

#[test]
fn a_placement_naming_unknown_parts_or_pins_suggests_the_closest_and_names_its_file() {
    let dir = temp_dir();
    let demo = |f: &str| sample(&format!("circuit_demo/{f}"));
    let text = std::fs::read_to_string(demo("placement.toml")).expect("placement");
    assert!(text.contains("name = \"R1\""));
    let bad = dir.path().join("typo.toml");
    std::fs::write(&bad, text.replace("name = \"R1\"", "name = \"R7\"")).expect("written");
    let out = dir.path().join("x.gcode");
    let folder = dir.path().join("r");
    for command in ["slice", "route"] {
        let target: [&dyn AsRef<OsStr>; 2] = if command == "slice" {
            [&"-o", &out]
        } else {
            [&"--out-dir", &folder]
        };
        let o = run(&[
            &command,
            &demo("block.stl"),
            &"--circuit",
            &demo("led_coin.sch"),
            &"--placement",
            &bad,
            target[0],
            target[1],
        ]);
        assert_eq!(o.status.code(), Some(1), "{command}");
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{command}: {err}");
        assert!(
            err.starts_with(&format!("error: {}: ", bad.display())),
            "{command}: {err}"
        );
        assert!(
            err.contains("part \"R7\" is not in the circuit; did you mean \"R1\"?"),
            "{command}: {err}"
        );
    }
    // A pin with a mistyped part: the same pad of the closest part.
    let pins = dir.path().join("pins.toml");
    std::fs::write(
        &pins,
        format!("{text}\n[[net]]\nname = \"N1\"\nwires = [[\"RR1.2\", \"LED1.A\"]]\n"),
    )
    .expect("written");
    let o = run(&[
        &"route",
        &demo("block.stl"),
        &"--circuit",
        &demo("led_coin.sch"),
        &"--placement",
        &pins,
        &"--out-dir",
        &dir.path().join("r"),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("net N1: pin RR1.2 does not exist; did you mean \"R1.2\"?"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn errors_quoting_raw_input_stay_one_line() {
    let dir = temp_dir();
    // An SVG number with a line feed, a carriage return, a tab and an escape character in it.
    let svg = dir.path().join("bad.svg");
    std::fs::write(
        &svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10mm\" height=\"10mm\">\
         <path d=\"M 0 0 L&#10;5 x&#13;&#9;5&#27;\"/></svg>",
    )
    .expect("written");
    // An EAGLE pad position with a line feed.
    let sch = std::fs::read_to_string(sample("circuit_demo/led_coin.sch")).expect("schematic");
    let at = sch.find("<smd name=\"+\" x=\"").expect("a pad") + "<smd name=\"+\" x=\"".len();
    let eagle = dir.path().join("bad.sch");
    std::fs::write(&eagle, format!("{}1&#10;2{}", &sch[..at], &sch[at..])).expect("written");
    let jet_out = dir.path().join("j.gcode");
    let cases: [(Vec<&dyn AsRef<OsStr>>, &str); 3] = [
        (vec![&"info", &svg], "L\\n5 x\\r\\t5\\u{1b}"),
        (
            vec![
                &"jet",
                &svg,
                &"--width",
                &"20",
                &"--layers",
                &"1",
                &"--layer-height",
                &"5",
                &"-o",
                &jet_out,
            ],
            "L\\n5 x\\r\\t5\\u{1b}",
        ),
        (vec![&"info", &eagle], "x=\"1\\n2"),
    ];
    for (args, escaped) in cases {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(1));
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(escaped), "{err}");
        assert!(
            !err.trim_end_matches('\n').contains(['\r', '\t', '\u{1b}']),
            "{err:?}"
        );
    }
}

#[test]
fn ignored_prusaslicer_keys_are_one_short_warning_and_all_of_them_with_verbose() {
    let dir = temp_dir();
    let ini = dir.path().join("p.ini");
    std::fs::write(&ini, PROFILE).expect("profile written");
    let o = run(&[&"config", &"--check", &ini]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        stderr(&o),
        format!(
            "warning: {}: 5 PrusaSlicer keys ignored (2 that change the print: ironing, \
             raft_layers); full list with --verbose\n",
            ini.display()
        )
    );
    let o = run(&[&"config", &"--check", &ini, &"--verbose"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains(
            "ignored PrusaSlicer keys: gcode_comments, ironing, raft_layers, spiral_vase, wipe\n"
        ),
        "{err}"
    );
    assert!(!err.contains("--verbose"), "{err}");

    // A whole profile, as PrusaSlicer writes it into its G-code.
    let Some(corpus) = corpus() else { return };
    let gcode = std::fs::read_to_string(corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode"))
        .expect("peer G-code");
    let full: String = gcode
        .lines()
        .filter_map(|l| l.strip_prefix("; "))
        .filter(|l| {
            l.split_once(" = ").is_some_and(|(k, _)| {
                k.bytes()
                    .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_')
            })
        })
        .map(|l| format!("{l}\n"))
        .collect();
    let profile = dir.path().join("full.ini");
    std::fs::write(&profile, full).expect("profile written");
    let out = dir.path().join("cube.gcode");
    let o = run(&[
        &"slice",
        &sample("cube_20mm.stl"),
        &"-c",
        &profile,
        &"-o",
        &out,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let line = err
        .lines()
        .find(|l| l.contains("PrusaSlicer keys ignored"))
        .unwrap_or_else(|| panic!("{err}"));
    assert!(line.len() < 600, "{} characters: {line}", line.len());
    assert!(
        line.contains("thick_bridges") && !line.contains("gcode_comments"),
        "{line}"
    );
    assert!(line.ends_with("; full list with --verbose"), "{line}");
}

#[test]
fn a_folder_that_takes_no_file_is_named_without_a_temporary_file() {
    let dir = temp_dir();
    let cube = sample("cube_20mm.stl");
    let mut targets: Vec<PathBuf> = vec![dir.path().join("missing/x.stl")];
    if cfg!(target_os = "linux") {
        targets.push(PathBuf::from("/proc/conduit-x.stl"));
    }
    for target in targets {
        let o = run(&[&"convert", &cube, &"-o", &target]);
        assert_eq!(o.status.code(), Some(1));
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(&*target.to_string_lossy()), "{err}");
        assert!(
            !err.contains(".conduit-") && !err.contains("at path"),
            "{err}"
        );
    }
}
