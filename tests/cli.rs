//! The command line: help, exit codes, messages that name the file, atomic outputs, batch convert.

use crate::support::{conduit, files_in, sample, stderr, stdout, temp_dir};
use serde_json::Value;

#[test]
fn help_is_available_for_every_command() {
    for args in [
        vec!["--help"],
        vec!["info", "--help"],
        vec!["convert", "--help"],
    ] {
        let o = conduit(&args);
        assert_eq!(o.status.code(), Some(0), "{args:?}");
        assert!(stdout(&o).contains("Usage"), "{args:?}");
    }
}

#[test]
fn usage_errors_exit_2() {
    assert_eq!(conduit(["info"]).status.code(), Some(2));
    assert_eq!(conduit(["frobnicate"]).status.code(), Some(2));
    let cube = sample("cube_20mm.stl");
    let two = conduit([
        "convert".as_ref(),
        cube.as_os_str(),
        cube.as_os_str(),
        "-o".as_ref(),
        "x.stl".as_ref(),
    ]);
    assert_eq!(two.status.code(), Some(2), "{}", stderr(&two));
    let ext = conduit([
        "convert".as_ref(),
        cube.as_os_str(),
        "-o".as_ref(),
        "x.step".as_ref(),
    ]);
    assert_eq!(ext.status.code(), Some(2));
    let no_dir = conduit([
        "convert".as_ref(),
        cube.as_os_str(),
        "--to".as_ref(),
        "3mf".as_ref(),
    ]);
    assert_eq!(no_dir.status.code(), Some(2));
}

#[test]
fn info_json_reports_analytic_cube_values() {
    let o = conduit([
        "info".as_ref(),
        "--json".as_ref(),
        sample("cube_20mm.stl").as_os_str(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).expect("JSON");
    let f = &v[0];
    assert_eq!(f["format"], "stl");
    assert_eq!(f["triangles"], 12);
    assert_eq!(f["vertices"], 8);
    assert_eq!(f["volume_mm3"], 8000.0);
    assert_eq!(f["bbox"]["max"], serde_json::json!([20.0, 20.0, 20.0]));
    let obj = &f["objects"][0];
    assert_eq!(obj["topology"]["closed"], true);
    assert_eq!(obj["topology"]["orientation"], "outward");
    assert_eq!(obj["topology"]["boundary_edges"], 0);
    assert_eq!(obj["area_mm2"], 2400.0);
    assert_eq!(obj["repair"]["flipped_triangles"], 0);
}

#[test]
fn info_text_lists_each_file() {
    let o = conduit([
        "info".as_ref(),
        sample("cube_20mm.stl").as_os_str(),
        sample("l_bracket.obj").as_os_str(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("cube_20mm.stl") && text.contains("l_bracket.obj"),
        "{text}"
    );
    assert!(text.contains("volume_mm3: 6500"), "{text}");
}

#[test]
fn bad_input_exits_1_naming_the_file_and_good_files_still_report() {
    let dir = temp_dir();
    let bad = dir.path().join("broken.stl");
    // Binary STL claiming 1000 triangles but holding one.
    let mut bytes = vec![0u8; 84 + 50];
    bytes[80..84].copy_from_slice(&1000u32.to_le_bytes());
    std::fs::write(&bad, &bytes).expect("write");
    let o = conduit([
        "info".as_ref(),
        "--json".as_ref(),
        sample("cube_20mm.stl").as_os_str(),
        bad.as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.starts_with("error: ") && err.contains("broken.stl"),
        "{err}"
    );
    let v: Value = serde_json::from_str(&stdout(&o)).expect("JSON");
    assert_eq!(v[0]["triangles"], 12);
    assert!(
        v[1]["error"]
            .as_str()
            .is_some_and(|e| e.contains("broken.stl"))
    );
    let missing = conduit(["info", "/nonexistent/file.stl"]);
    assert_eq!(missing.status.code(), Some(1));
    assert!(stderr(&missing).contains("/nonexistent/file.stl"));
}

#[test]
fn failed_convert_leaves_no_partial_file_and_keeps_the_old_one() {
    let dir = temp_dir();
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nf 1 2 9\n").expect("write");
    let out = dir.path().join("out.stl");
    let o = conduit([
        "convert".as_ref(),
        bad.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("bad.obj"));
    assert_eq!(
        files_in(dir.path()),
        vec![bad.clone()],
        "no output and no temp file left"
    );
    std::fs::write(&out, b"previous").expect("write");
    let o = conduit([
        "convert".as_ref(),
        bad.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(std::fs::read(&out).expect("read"), b"previous");
}

#[test]
fn batch_convert_writes_one_file_per_input_and_refuses_collisions() {
    let dir = temp_dir();
    let inputs = [sample("cube_20mm.stl"), sample("l_bracket.obj")];
    let mut args: Vec<std::ffi::OsString> = vec!["convert".into()];
    args.extend(inputs.iter().map(|p| p.clone().into_os_string()));
    args.extend([
        "--to".into(),
        "obj".into(),
        "--out-dir".into(),
        dir.path().as_os_str().to_owned(),
    ]);
    let o = conduit(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let names: Vec<String> = files_in(dir.path())
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    assert_eq!(names, ["cube_20mm.obj", "l_bracket.obj"]);
    // Same stem twice → usage error before any work.
    let mut args: Vec<std::ffi::OsString> = vec!["convert".into()];
    args.extend([
        sample("cube_20mm.stl").into_os_string(),
        dir.path().join("cube_20mm.obj").into_os_string(),
    ]);
    args.extend([
        "--to".into(),
        "stl".into(),
        "--out-dir".into(),
        dir.path().as_os_str().to_owned(),
    ]);
    assert_eq!(conduit(&args).status.code(), Some(2));
}

#[test]
fn convert_output_is_deterministic() {
    let dir = temp_dir();
    for fmt in ["stl", "3mf", "obj"] {
        let a = dir.path().join(format!("a.{fmt}"));
        let b = dir.path().join(format!("b.{fmt}"));
        for out in [&a, &b] {
            let o = conduit([
                "convert".as_ref(),
                sample("l_bracket.obj").as_os_str(),
                "-o".as_ref(),
                out.as_os_str(),
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
        }
        assert_eq!(
            std::fs::read(&a).expect("read"),
            std::fs::read(&b).expect("read"),
            "{fmt}"
        );
    }
}

#[cfg(unix)]
#[test]
fn outputs_get_ordinary_file_permissions_and_keep_existing_ones() {
    use std::os::unix::fs::PermissionsExt;
    let dir = temp_dir();
    let mode =
        |p: &std::path::Path| std::fs::metadata(p).expect("exists").permissions().mode() & 0o777;
    let control = dir.path().join("control");
    std::fs::File::create(&control).expect("create");
    let out = dir.path().join("out.stl");
    let run = || {
        conduit([
            "convert".as_ref(),
            sample("cube_20mm.stl").as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ])
    };
    assert!(run().status.success());
    assert_eq!(
        mode(&out),
        mode(&control),
        "a new output has the permissions of a new file"
    );
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o640)).expect("chmod");
    assert!(run().status.success());
    assert_eq!(mode(&out), 0o640, "a replaced output keeps its permissions");
}

#[test]
fn missing_config_circuit_and_placement_are_named_with_their_cause_once() {
    let dir = temp_dir();
    let out = dir.path().join("out.gcode");
    let model = sample("l_bracket.obj");
    let circuit = sample("circuit_demo/led_coin.sch");
    let placement = sample("circuit_demo/placement.toml");
    let missing = dir.path().join("missing");
    let cases: [(&str, Vec<&std::ffi::OsStr>); 3] = [
        ("missing/config.toml", vec!["-c".as_ref()]),
        (
            "missing/board.sch",
            vec![
                "--placement".as_ref(),
                placement.as_os_str(),
                "--circuit".as_ref(),
            ],
        ),
        (
            "missing/parts.toml",
            vec![
                "--circuit".as_ref(),
                circuit.as_os_str(),
                "--placement".as_ref(),
            ],
        ),
    ];
    for (name, flags) in cases {
        let path = missing.join(name.trim_start_matches("missing/"));
        let mut args: Vec<&std::ffi::OsStr> = vec!["slice".as_ref(), model.as_os_str()];
        args.extend(flags);
        args.extend([path.as_os_str(), "-o".as_ref(), out.as_os_str()]);
        let o = conduit(args);
        assert_eq!(o.status.code(), Some(1), "{name}");
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        assert!(err.contains(&*path.to_string_lossy()), "{name}: {err}");
        assert_eq!(err.matches("os error").count(), 1, "{name}: {err}");
        assert!(!out.exists());
    }
}

#[test]
fn convert_takes_a_folder_makes_the_output_folder_and_says_what_it_wrote() {
    let dir = temp_dir();
    let input = dir.path().join("in");
    std::fs::create_dir(&input).expect("input folder");
    for name in ["cube_20mm.stl", "l_bracket.obj"] {
        std::fs::copy(sample(name), input.join(name)).expect("sample copied");
    }
    std::fs::write(input.join("notes.txt"), "not a mesh").expect("other file");
    let out_dir = dir.path().join("made/here");
    let o = conduit([
        "convert".as_ref(),
        input.as_os_str(),
        "--to".as_ref(),
        "3mf".as_ref(),
        "--out-dir".as_ref(),
        out_dir.as_os_str(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let names: Vec<String> = files_in(&out_dir)
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    assert_eq!(names, ["cube_20mm.3mf", "l_bracket.3mf"]);
    let said = String::from_utf8_lossy(&o.stdout).into_owned();
    let lines: Vec<&str> = said.lines().collect();
    assert_eq!(lines.len(), 2, "{said}");
    assert!(
        lines[0].ends_with("cube_20mm.3mf: 1 object, 12 triangles"),
        "{said}"
    );
    assert!(
        lines[1].ends_with("l_bracket.3mf: 1 object, 20 triangles"),
        "{said}"
    );
    // One failed conversion: one line naming the file, no batch summary.
    let broken = dir.path().join("broken.stl");
    std::fs::write(&broken, "solid x\nfacet\n").expect("broken file");
    let o = conduit([
        "convert".as_ref(),
        broken.as_os_str(),
        "-o".as_ref(),
        dir.path().join("x.stl").as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("broken.stl"), "{err}");
    // An empty folder is a usage error naming it.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).expect("empty folder");
    let o = conduit([
        "convert".as_ref(),
        empty.as_os_str(),
        "--to".as_ref(),
        "stl".as_ref(),
        "--out-dir".as_ref(),
        out_dir.as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no mesh files"), "{}", stderr(&o));
}

#[test]
fn completions_and_manual_pages_come_from_the_grammar() {
    let o = conduit(["completions", "bash"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let script = String::from_utf8_lossy(&o.stdout).into_owned();
    for word in [
        "conduit",
        "slice",
        "postprocess",
        "--placement",
        "--dialect",
    ] {
        assert!(script.contains(word), "bash completion lacks {word}");
    }
    let dir = temp_dir();
    let path = dir.path().join("conduit.bash");
    std::fs::write(&path, &script).expect("script written");
    let syntax = std::process::Command::new("bash")
        .arg("-n")
        .arg(&path)
        .output()
        .expect("bash runs");
    assert!(
        syntax.status.success(),
        "{}",
        String::from_utf8_lossy(&syntax.stderr)
    );
    let pages = dir.path().join("man");
    let o = conduit(["man".as_ref(), "--out-dir".as_ref(), pages.as_os_str()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let slice = std::fs::read_to_string(pages.join("conduit-slice.1")).expect("slice page");
    assert!(
        slice.starts_with(".ie") || slice.contains(".TH conduit-slice"),
        "{slice}"
    );
    assert!(
        slice.contains("placement"),
        "the slice page documents --placement"
    );
    for page in [
        "conduit.1",
        "conduit-calibrate-tcp.1",
        "conduit-jet-model.1",
    ] {
        assert!(pages.join(page).is_file(), "{page} written");
    }
}
