//! Helpers shared by the integration tests: running the binary, finding the corpus, temp dirs,
//! positions of replayed moves.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The project root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The shared corpus, or `None` (after printing a skip line) when it is not beside the checkout.
pub fn corpus() -> Option<PathBuf> {
    let dir = root().join("../shared/corpus");
    if dir.join("MANIFEST.json").is_file() {
        Some(dir)
    } else {
        println!("skipped: corpus not found at {}", dir.display());
        None
    }
}

/// The fuzzing regression folder beside the checkout (`../shared/regressions`), or `None`
/// (after printing a skip line) when it is absent.
pub fn regressions() -> Option<PathBuf> {
    let dir = root().join("../shared/regressions");
    if dir.join("README.md").is_file() {
        Some(dir)
    } else {
        println!("skipped: regressions not found at {}", dir.display());
        None
    }
}

/// A file of the project's own samples.
pub fn sample(name: &str) -> PathBuf {
    root().join("samples").join(name)
}

/// Runs the conduit binary with `args`.
pub fn conduit<I, S>(args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    Command::new(env!("CARGO_BIN_EXE_conduit"))
        .args(args)
        .output()
        .expect("the conduit binary runs")
}

/// Slices the circuit demo (block, LED coin circuit, its placement) into `gcode`, with `extra`
/// arguments; panics with conduit's message when it fails.
pub fn slice_circuit_demo(gcode: &Path, extra: &[&str]) {
    let demo = |f: &str| sample(&format!("circuit_demo/{f}"));
    let mut args: Vec<std::ffi::OsString> = vec![
        "slice".into(),
        demo("block.stl").into(),
        "--circuit".into(),
        demo("led_coin.sch").into(),
        "--placement".into(),
        demo("placement.toml").into(),
        "-o".into(),
        gcode.into(),
    ];
    args.extend(extra.iter().map(Into::into));
    let out = conduit(&args);
    assert!(
        out.status.success(),
        "slicing the circuit demo: {}",
        stderr(&out)
    );
}

/// Stdout of a run as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Stderr of a run as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A fresh temporary folder, removed when dropped.
pub fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("a temp dir can be made")
}

/// Files in a folder (not recursive), sorted.
pub fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| rd.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    v.sort();
    v
}

/// Reads the triangles of a binary or ASCII STL with the project's reader.
pub fn stl_triangles(path: &Path) -> Vec<[[f32; 3]; 3]> {
    let bytes = std::fs::read(path).expect("STL readable");
    conduit_stl::read(&bytes).expect("STL parses").triangles
}

/// `conduit slice MODEL -o DIR/out.gcode --report DIR/out.json EXTRA…`, which must succeed:
/// the G-code's text and where the first object's bounding box starts on the bed (X, Y, Z).
pub fn slice_with_report(dir: &Path, model: &Path, extra: &[&str]) -> (String, [f64; 3]) {
    let (gcode, report) = (dir.join("out.gcode"), dir.join("out.json"));
    let mut args = vec![
        "slice".to_owned(),
        model.display().to_string(),
        "-o".into(),
        gcode.display().to_string(),
        "--report".into(),
        report.display().to_string(),
    ];
    args.extend(extra.iter().map(|s| (*s).to_owned()));
    let o = conduit(&args);
    assert!(o.status.success(), "slicing failed: {}", stderr(&o));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    let min = &r["objects"][0]["bbox"]["min"];
    let at = |i: usize| min[i].as_f64().expect("bbox");
    (
        std::fs::read_to_string(&gcode).expect("G-code"),
        [at(0), at(1), at(2)],
    )
}

/// Writes `tris` as a binary STL with their facet normals.
pub fn write_stl(path: &Path, tris: &[[conduit::geom::Point3; 3]]) {
    let mut b = vec![0u8; 80];
    b.extend((tris.len() as u32).to_le_bytes());
    for t in tris {
        let n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
        for v in [n.x, n.y, n.z] {
            b.extend((v as f32).to_le_bytes());
        }
        for p in t {
            for v in [p.x, p.y, p.z] {
                b.extend((v as f32).to_le_bytes());
            }
        }
        b.extend([0, 0]);
    }
    std::fs::write(path, b).expect("STL written");
}

/// A replayed position with unknown axes at 0 (where firmware counts from before homing).
pub fn xyz(p: conduit_gcode::Position) -> [f64; 3] {
    p.map(|c| c.unwrap_or(0.0))
}

/// OctoPNP's part description read from a G-code text the way OctoPNP reads it: from every line,
/// the text from its first `<` to its last `>`, joined with newlines, parsed as XML. Returns the
/// collected text and its root element, or `None` when the text is not well-formed XML with a
/// root.
pub fn octopnp_description(gcode: &str) -> (String, Option<conduit_xml::Node>) {
    let mut xml = String::new();
    for line in gcode.lines() {
        if let (Some(a), Some(b)) = (line.find('<'), line.rfind('>')) {
            if a < b {
                xml.push_str(&line[a..=b]);
                xml.push('\n');
            }
        }
    }
    let options = conduit_xml::Options {
        names: conduit_xml::Names::Qualified,
        entities: conduit_xml::Entities::Strict,
        depth_check: conduit_xml::DepthCheck::BeforeAttributes,
        max_depth: 16,
    };
    let root = conduit_xml::parse(xml.as_bytes(), &options).ok().flatten();
    (xml, root)
}

/// A numeric attribute of an XML element, panicking with `what` when it is missing or not a
/// number.
pub fn xml_number(node: &conduit_xml::Node, key: &str, what: &str) -> f64 {
    node.attr(key)
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{what}: {key} is not a number"))
}

/// The numbers of the `M361 P<id>` lines.
pub fn m361_ids(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| {
            l.split(';')
                .next()?
                .trim()
                .strip_prefix("M361 P")
                .map(str::to_owned)
        })
        .collect()
}

/// The one file with extension `ext` (`sch`, `brd`) of corpus EAGLE board `name`, anywhere
/// under `eagle/<name>/`.
pub fn eagle_file(corpus: &Path, name: &str, ext: &str) -> PathBuf {
    let mut found = Vec::new();
    let mut stack = vec![corpus.join("eagle").join(name)];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).expect("corpus board folder readable") {
            let path = entry.expect("directory entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == ext) {
                found.push(path);
            }
        }
    }
    assert_eq!(found.len(), 1, "one .{ext} under eagle/{name}");
    found.remove(0)
}

/// The parts of a placement TOML: (name, [x, y, z, rotation]), in file order.
pub fn placement_parts(path: &Path) -> Vec<(String, [f64; 4])> {
    let text = std::fs::read_to_string(path).expect("placement written");
    let p = conduit::circuit::Placement::from_toml(&text).expect("placement reads back");
    p.parts
        .iter()
        .map(|q| (q.name.clone(), [q.x, q.y, q.z, q.rotation]))
        .collect()
}
