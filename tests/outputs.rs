//! Outputs that never clobber (devices, FIFOs, symbolic links, inputs), multi-file outputs all or
//! nothing, standard output errors without a panic, and G-code commands refusing other files.

use crate::support::{conduit, files_in, sample, stderr, stdout, temp_dir};
use std::path::Path;
use std::process::{Command, Stdio};

fn os(p: &Path) -> &std::ffi::OsStr {
    p.as_os_str()
}

/// Slices the sample cube to `out` (exit status checked by the caller).
fn slice_cube(out: &Path, extra: &[&std::ffi::OsStr]) -> std::process::Output {
    let cube = sample("cube_20mm.stl");
    let mut args: Vec<&std::ffi::OsStr> = vec!["slice".as_ref(), os(&cube), "-o".as_ref(), os(out)];
    args.extend_from_slice(extra);
    conduit(args)
}

/// A G-code file sliced from the sample cube, in `dir`.
fn cube_gcode(dir: &Path) -> std::path::PathBuf {
    let g = dir.join("cube.gcode");
    let o = slice_cube(&g, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    g
}

fn assert_no_panic(o: &std::process::Output) {
    let err = stderr(o);
    assert!(!err.contains("panicked"), "{err}");
    assert_ne!(o.status.code(), Some(101), "{err}");
}

#[cfg(unix)]
#[test]
fn a_symlinked_output_keeps_the_link_and_writes_its_target() {
    let tmp = temp_dir();
    let target = tmp.path().join("real.gcode");
    std::fs::write(&target, "old").expect("write");
    let link = tmp.path().join("link.gcode");
    std::os::unix::fs::symlink("real.gcode", &link).expect("symlink");
    let o = slice_cube(&link, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let meta = std::fs::symlink_metadata(&link).expect("link");
    assert!(meta.file_type().is_symlink(), "the link was replaced");
    let text = std::fs::read_to_string(&target).expect("target");
    assert!(text.contains("G1"), "target not written");

    // A dangling link gets its target created.
    let dangling = tmp.path().join("dangling.stl");
    std::os::unix::fs::symlink("made.stl", &dangling).expect("symlink");
    let c = conduit([
        "convert".as_ref(),
        os(&sample("cube_20mm.stl")),
        "-o".as_ref(),
        os(&dangling),
    ]);
    assert!(c.status.success(), "{}", stderr(&c));
    assert!(
        std::fs::symlink_metadata(&dangling)
            .expect("link")
            .file_type()
            .is_symlink()
    );
    assert!(tmp.path().join("made.stl").is_file());
}

#[cfg(unix)]
#[test]
fn a_fifo_output_is_written_directly() {
    use std::io::Read;
    use std::os::unix::fs::FileTypeExt;
    let tmp = temp_dir();
    let fifo = tmp.path().join("pipe.gcode");
    match Command::new("mkfifo").arg(&fifo).status() {
        Ok(s) if s.success() => {}
        _ => {
            println!("skipped: mkfifo not available");
            return;
        }
    }
    let reader_path = fifo.clone();
    // The reader blocks until conduit opens the FIFO for writing; when conduit replaces the FIFO
    // instead, the thread stays blocked and is left behind (not joined).
    let reader = std::thread::spawn(move || {
        let mut buf = Vec::new();
        std::fs::File::open(&reader_path)
            .and_then(|mut f| f.read_to_end(&mut buf))
            .map(|_| buf)
    });
    let o = slice_cube(&fifo, &[]);
    let still_fifo = std::fs::symlink_metadata(&fifo)
        .expect("fifo")
        .file_type()
        .is_fifo();
    assert!(still_fifo, "the FIFO was replaced by a regular file");
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = reader.join().expect("reader").expect("read");
    assert!(String::from_utf8_lossy(&bytes).contains("G1"));
}

#[test]
fn an_output_that_is_an_input_is_refused_and_the_input_kept() {
    let tmp = temp_dir();
    let stl = tmp.path().join("cube.stl");
    // ASCII, so `convert` to binary would visibly change it.
    let ascii = conduit([
        "convert".as_ref(),
        os(&sample("cube_20mm.stl")),
        "--ascii".as_ref(),
        "-o".as_ref(),
        os(&stl),
    ]);
    assert!(ascii.status.success(), "{}", stderr(&ascii));
    let before = std::fs::read(&stl).expect("stl");

    let c = conduit(["convert".as_ref(), os(&stl), "-o".as_ref(), os(&stl)]);
    assert_eq!(c.status.code(), Some(1), "{}", stderr(&c));
    assert!(
        stderr(&c).contains("refusing to overwrite the input"),
        "{}",
        stderr(&c)
    );

    // Another spelling of the same path.
    let other = tmp.path().join(".").join("cube.stl");
    let s = conduit(["slice".as_ref(), os(&stl), "-o".as_ref(), os(&other)]);
    assert_eq!(s.status.code(), Some(1), "{}", stderr(&s));
    let msg = stderr(&s);
    assert!(
        msg.contains(&*other.to_string_lossy()) && msg.contains(&*stl.to_string_lossy()),
        "{msg}"
    );
    assert_eq!(
        std::fs::read(&stl).expect("stl"),
        before,
        "the input changed"
    );

    // A report over the G-code postprocess reads.
    let g = cube_gcode(tmp.path());
    let gbefore = std::fs::read(&g).expect("gcode");
    let p = conduit(["postprocess".as_ref(), os(&g), "--report".as_ref(), os(&g)]);
    assert_eq!(p.status.code(), Some(1), "{}", stderr(&p));
    assert_eq!(
        std::fs::read(&g).expect("gcode"),
        gbefore,
        "the G-code changed"
    );

    // A batch whose output folder holds the inputs.
    let b = conduit([
        "convert".as_ref(),
        os(&stl),
        "--to".as_ref(),
        "stl".as_ref(),
        "--out-dir".as_ref(),
        os(tmp.path()),
    ]);
    assert_eq!(b.status.code(), Some(1), "{}", stderr(&b));
    assert_eq!(
        std::fs::read(&stl).expect("stl"),
        before,
        "the input changed"
    );
}

#[test]
fn postprocess_without_output_still_rewrites_in_place_and_writes_its_report() {
    let tmp = temp_dir();
    let g = cube_gcode(tmp.path());
    let report = tmp.path().join("r.json");
    let p = conduit([
        "postprocess".as_ref(),
        os(&g),
        "--report".as_ref(),
        os(&report),
    ]);
    assert!(p.status.success(), "{}", stderr(&p));
    assert!(report.is_file());
}

#[test]
fn slice_whose_report_cannot_be_written_leaves_no_gcode() {
    let tmp = temp_dir();
    let g = tmp.path().join("out.gcode");
    let report = tmp.path().join("missing/r.json");
    let o = slice_cube(&g, &["--report".as_ref(), os(&report)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(files_in(tmp.path()), Vec::<std::path::PathBuf>::new());
    // The message names the path given, not a temporary file.
    let msg = stderr(&o);
    assert!(msg.contains(&*report.to_string_lossy()), "{msg}");
    assert!(!msg.contains(".conduit-"), "{msg}");

    // A report path that is a folder: the same.
    let dir = tmp.path().join("r.json");
    std::fs::create_dir(&dir).expect("dir");
    let o = slice_cube(&g, &["--report".as_ref(), os(&dir)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(files_in(tmp.path()), vec![dir]);
}

#[test]
fn missing_output_folder_names_the_output_not_a_temporary_file() {
    let tmp = temp_dir();
    let out = tmp.path().join("nope/x.stl");
    let o = conduit([
        "convert".as_ref(),
        os(&sample("cube_20mm.stl")),
        "-o".as_ref(),
        os(&out),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let msg = stderr(&o);
    assert!(msg.contains(&*out.to_string_lossy()), "{msg}");
    assert!(!msg.contains(".conduit-"), "{msg}");
    assert_eq!(msg.lines().count(), 1, "{msg}");
}

#[test]
fn preview_that_fails_on_a_later_file_leaves_none() {
    let tmp = temp_dir();
    let g = cube_gcode(tmp.path());
    let out = tmp.path().join("preview");
    std::fs::create_dir(&out).expect("dir");
    // A folder where the third layer's SVG goes: that file cannot be written.
    let blocker = out.join("layer_0003.svg");
    std::fs::create_dir(&blocker).expect("dir");
    let o = conduit(["preview".as_ref(), os(&g), "-o".as_ref(), os(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(files_in(&out), vec![blocker]);
}

/// Runs conduit with its stdout a pipe whose reader is closed before conduit writes.
fn with_closed_stdout(args: &[&std::ffi::OsStr]) -> std::process::Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("conduit runs");
    drop(child.stdout.take());
    child.wait_with_output().expect("conduit ends")
}

#[test]
fn a_closed_stdout_ends_quietly() {
    let o = with_closed_stdout(&["config".as_ref(), "--defaults".as_ref()]);
    assert_no_panic(&o);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(stderr(&o), "");

    let tmp = temp_dir();
    let g = cube_gcode(tmp.path());
    let o = with_closed_stdout(&["check".as_ref(), os(&g)]);
    assert_no_panic(&o);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let o = with_closed_stdout(&["info".as_ref(), os(&sample("cube_20mm.stl"))]);
    assert_no_panic(&o);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn a_full_stdout_is_one_error_line_and_exit_1() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        println!("skipped: /dev/full not available");
        return;
    };
    let tmp = temp_dir();
    let g = cube_gcode(tmp.path());
    for args in [
        vec!["check".as_ref(), os(&g)],
        vec!["config".as_ref(), "--defaults".as_ref()],
    ] {
        let out = full.try_clone().expect("clone");
        let o = Command::new(env!("CARGO_BIN_EXE_conduit"))
            .args(&args)
            .stdout(out)
            .output()
            .expect("conduit runs");
        assert_no_panic(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
        assert!(stderr(&o).contains("standard output"), "{}", stderr(&o));
    }
}

#[test]
fn gcode_commands_refuse_other_files() {
    let tmp = temp_dir();
    let ascii = tmp.path().join("ascii.stl");
    let a = conduit([
        "convert".as_ref(),
        os(&sample("cube_20mm.stl")),
        "--ascii".as_ref(),
        "-o".as_ref(),
        os(&ascii),
    ]);
    assert!(a.status.success(), "{}", stderr(&a));
    // A 3MF under a G-code name: refused by its content.
    let threemf = tmp.path().join("x.3mf");
    let t = conduit([
        "convert".as_ref(),
        os(&sample("cube_20mm.stl")),
        "-o".as_ref(),
        os(&threemf),
    ]);
    assert!(t.status.success(), "{}", stderr(&t));
    let disguised = tmp.path().join("x.gcode");
    std::fs::copy(&threemf, &disguised).expect("copy");
    for file in [sample("cube_20mm.stl"), ascii, disguised] {
        for cmd in ["check", "postprocess"] {
            let before = std::fs::read(&file).expect("read");
            let o = conduit([cmd.as_ref(), os(&file)]);
            assert_eq!(
                o.status.code(),
                Some(1),
                "{cmd} {}: {}",
                file.display(),
                stderr(&o)
            );
            assert!(
                stderr(&o).contains(&*file.to_string_lossy()),
                "{}",
                stderr(&o)
            );
            assert!(stdout(&o).is_empty());
            assert_eq!(std::fs::read(&file).expect("read"), before);
        }
    }
}

#[test]
fn jet_conform_calibrate_and_compensate_refuse_to_overwrite_an_input() {
    let tmp = temp_dir();
    let copy = |rel: &str| {
        let to = tmp.path().join(Path::new(rel).file_name().expect("name"));
        std::fs::copy(sample(rel), &to).expect("copy");
        to
    };
    let pivot = copy("robot/pivot.csv");
    let star = copy("jet/star8.svg");
    let spiral = copy("conform/spiral.svg");
    let film = copy("conform/wrinkled_film.xyz");
    let circle = tmp.path().join("circle.csv");
    let p = conduit([
        "compensate".as_ref(),
        "pattern".as_ref(),
        "circle".as_ref(),
        "--size".as_ref(),
        "10".as_ref(),
        "--surface".as_ref(),
        "sphere:15".as_ref(),
        "-o".as_ref(),
        os(&circle),
    ]);
    assert!(p.status.success(), "{}", stderr(&p));
    let runs: Vec<(Vec<&std::ffi::OsStr>, &Path)> = vec![
        (
            vec![
                "calibrate".as_ref(),
                "tcp".as_ref(),
                os(&pivot),
                "--report".as_ref(),
                os(&pivot),
            ],
            &pivot,
        ),
        (
            vec![
                "jet".as_ref(),
                os(&star),
                "--width".as_ref(),
                "20".as_ref(),
                "--layers".as_ref(),
                "2".as_ref(),
                "--layer-height".as_ref(),
                "5".as_ref(),
                "-o".as_ref(),
                os(&star),
            ],
            &star,
        ),
        (
            vec![
                "conform".as_ref(),
                "--surface".as_ref(),
                os(&film),
                "--design".as_ref(),
                os(&spiral),
                "-o".as_ref(),
                os(&spiral),
            ],
            &spiral,
        ),
        (
            vec![
                "compensate".as_ref(),
                os(&circle),
                "--simulate".as_ref(),
                "sphere:15".as_ref(),
                "-o".as_ref(),
                os(&circle),
            ],
            &circle,
        ),
    ];
    for (args, input) in runs {
        let before = std::fs::read(input).expect("read");
        let o = conduit(&args);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("refusing to overwrite the input"),
            "{}",
            stderr(&o)
        );
        assert_eq!(std::fs::read(input).expect("read"), before, "{args:?}");
    }
}

#[test]
fn help_into_a_full_stdout_fails_and_into_a_closed_one_does_not() {
    let o = with_closed_stdout(&["--help".as_ref()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        println!("skipped: /dev/full not available");
        return;
    };
    let o = Command::new(env!("CARGO_BIN_EXE_conduit"))
        .arg("--help")
        .stdout(full)
        .output()
        .expect("conduit runs");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
}
