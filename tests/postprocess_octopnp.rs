//! OctoPNP's part description in a host's post-processed G-code: every machine-placed part
//! described with the id of its `M361 P<id>` and its destination where its event places it,
//! inside the rewritten file (before the host's end G-code), named independently of the
//! temporary file a host passes, and a warning when host lines hold text OctoPNP would read too.

use crate::postprocess::check_postprocessed;
use crate::support::{
    conduit, corpus, m361_ids, octopnp_description, sample, stderr, temp_dir, xml_number,
};
use conduit::pipeline::postprocess::{HostPrint, edit_circuit};
use conduit::postprocess::rewrite::{DESCRIPTION_MARK, END_MARK};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `conduit postprocess FILE --circuit SCH --placement TOML --report REPORT` with the
/// extra environment `env`.
fn postprocess(file: &Path, placement: &Path, report: &Path, env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_conduit"));
    cmd.arg("postprocess")
        .arg(file)
        .arg("--circuit")
        .arg(sample("postprocess/cube_led.sch"))
        .arg("--placement")
        .arg(placement)
        .arg("--report")
        .arg(report);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("the conduit binary runs")
}

/// Copies `src` to `dir/name`, as a host hands its temporary file to the script.
fn host_copy(dir: &Path, src: &Path, name: &str) -> PathBuf {
    let file = dir.join(name);
    std::fs::copy(src, &file).expect("copy");
    file
}

/// X, Y and Z of the `;PICK_AND_PLACE PART=<part> X=.. Y=.. Z=..` comment of `part`.
fn event_position(text: &str, part: &str) -> [f64; 3] {
    let line = text
        .lines()
        .find(|l| l.starts_with(&format!(";PICK_AND_PLACE PART={part} ")))
        .unwrap_or_else(|| panic!("no pick-and-place comment for {part}"));
    ["X", "Y", "Z"].map(|k| {
        line.split_whitespace()
            .find_map(|w| w.strip_prefix(&format!("{k}=")))
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{line}: no {k}"))
    })
}

/// The lines of `text` from [`DESCRIPTION_MARK`] to the [`END_MARK`] after it, as a range of
/// line indices.
fn description_lines(text: &str) -> Option<std::ops::Range<usize>> {
    let lines: Vec<&str> = text.lines().collect();
    let start = lines.iter().position(|l| *l == DESCRIPTION_MARK)?;
    let end = (start..lines.len()).find(|&k| lines[k] == END_MARK)?;
    Some(start..end + 1)
}

#[test]
fn every_machine_placed_part_is_described_inside_the_host_file() {
    let Some(corpus) = corpus() else { return };
    let dir = temp_dir();
    let (sch, toml) = (
        sample("postprocess/cube_led.sch"),
        sample("postprocess/cube_led.toml"),
    );
    let circuit = conduit::circuit::Circuit::load(&sch).expect("circuit");
    let led_pads = circuit.part("LED1").expect("LED1").pads.len();
    assert_eq!(led_pads, 2);
    // PrusaSlicer passes a temporary `*.gcode.pp` and says the real name in the environment;
    // the others are run on the file itself.
    let cases = [
        (
            "20mm_cube.prusaslicer-2.5.gcode",
            Some("/home/user/cube_0.2mm_PLA_1h.gcode"),
            "cube_0.2mm_PLA_1h",
        ),
        ("20mm_cube.curaengine-4.13.gcode", None, "object"),
        ("20mm_cube.slic3r-1.3.gcode", None, "object"),
    ];
    for (name, output_name, object) in cases {
        let src = corpus.join("peer-gcode").join(name);
        let file = host_copy(dir.path(), &src, "a1b2c3.gcode.pp");
        let report_path = dir.path().join("report.json");
        let env: Vec<(&str, &str)> = output_name
            .map(|n| ("SLIC3R_PP_OUTPUT_NAME", n))
            .into_iter()
            .collect();
        let o = postprocess(&file, &toml, &report_path, &env);
        assert_eq!(o.status.code(), Some(0), "{name}: {}", stderr(&o));
        assert!(!stderr(&o).contains("warning"), "{name}: {}", stderr(&o));
        let text = std::fs::read_to_string(&file).expect("text");
        let original = std::fs::read_to_string(&src).expect("text");

        // OctoPNP reads the block and nothing else: the first text it collects opens it.
        let (xml, root) = octopnp_description(&text);
        assert!(xml.starts_with("<object name=\""), "{name}: {xml}");
        let root = root.unwrap_or_else(|| panic!("{name}: not well-formed: {xml}"));
        assert_eq!(root.name, "object");
        // A stable name: the host's output name, else `object`; never the temporary file's.
        assert_eq!(root.attr("name"), Some(object), "{name}");
        assert!(!xml.contains("a1b2c3") && !xml.contains(".pp"), "{name}");

        // Only LED1 is placed by the machine (R1 is manual, J1 none), with the id its M361
        // carries, its body height, its two pads, and the destination its event places it at.
        let parts: Vec<&conduit_xml::Node> = root.children_named("part").collect();
        let names: Vec<Option<&str>> = parts.iter().map(|p| p.attr("name")).collect();
        assert_eq!(names, [Some("LED1")], "{name}");
        assert_eq!(m361_ids(&text), ["2"], "{name}");
        let led = parts[0];
        assert_eq!(led.attr("id"), Some("2"), "{name}");
        let child = |n: &str| led.child(n).unwrap_or_else(|| panic!("{name}: no <{n}>"));
        assert_eq!(child("position").attr("box"), Some("1"));
        assert_eq!(xml_number(child("size"), "height", name), 1.0);
        assert_eq!(child("pads").children.len(), led_pads, "{name}");
        let destination = child("destination");
        let at = ["x", "y", "z"].map(|k| xml_number(destination, k, name));
        // The cube's centre is (125, 125) on every host's bed; the placement is from it.
        assert_eq!(at, [129.0, 127.0, 10.0], "{name}");
        assert_eq!(at, event_position(&text, "LED1"), "{name}");
        let report: Value =
            serde_json::from_str(&std::fs::read_to_string(&report_path).expect("report"))
                .expect("JSON");
        let reported = report["electronics"]["parts"]
            .as_array()
            .and_then(|p| p.iter().find(|p| p["name"] == "LED1"))
            .expect("LED1 in the report");
        for (k, v) in at.iter().enumerate() {
            assert_eq!(reported["position"][k].as_f64(), Some(*v), "{name}");
        }
        assert_eq!(xml_number(destination, "orientation", name), 0.0);
        assert_eq!(report["edit"]["description_lines"], 19, "{name}");

        // Inside the file: right after the last layer's last extrusion (the cube's top layer
        // has no block of its own), and the host's end G-code and settings after it as the
        // host wrote them.
        let lines: Vec<&str> = text.lines().collect();
        let block = description_lines(&text).expect("a description block");
        assert_eq!(block.len(), 19);
        assert_eq!(text.matches(DESCRIPTION_MARK).count(), 1);
        let host = conduit_gcode::parse(original.as_bytes()).expect("parses");
        let (print, _) = HostPrint::read(&host, Vec::new()).expect("settings");
        let last = print
            .layers
            .layers
            .iter()
            .filter_map(|l| l.last_extrusion_line)
            .max()
            .expect("an extrusion");
        let host_lines: Vec<&str> = original.lines().collect();
        assert_eq!(lines[block.start - 1], host_lines[last], "{name}");
        assert_eq!(lines[block.end..], host_lines[last + 1..], "{name}");
        assert!(
            host_lines.len() - last > 5,
            "{name}: the host's end G-code follows"
        );

        // The rewrite verifier accepts the block and finds the described part.
        let verified = check_postprocessed(&src, &file, &sch, &toml);
        assert_eq!(verified.description_lines, 19, "{name}");
        assert_eq!(verified.described_parts, ["LED1"], "{name}");
    }
}

#[test]
fn the_description_is_the_only_addition_to_the_rewrite_without_it() {
    let Some(corpus) = corpus() else { return };
    let bytes = std::fs::read(corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode"))
        .expect("corpus file");
    let original = conduit_gcode::parse(&bytes).expect("parses");
    let (print, config) = HostPrint::read(&original, Vec::new()).expect("settings");
    let electronics = conduit::pipeline::Electronics {
        circuit: conduit::circuit::Circuit::load(&sample("postprocess/cube_led.sch"))
            .expect("circuit"),
        placement: conduit::circuit::Placement::load(&sample("postprocess/cube_led.toml"))
            .expect("placement"),
    };
    let edit = edit_circuit(&original, &print, &electronics, &config).expect("edits");
    let (bare, stats) = conduit::postprocess::rewrite(
        &original,
        &print.layers,
        &edit.plan,
        &config.gcode_params(),
        "",
        |_| edit.summary.clone(),
    )
    .expect("rewrites");
    assert_eq!(stats.description_lines, 0);
    assert_eq!(edit.stats.description_lines, 19);
    assert_eq!(
        edit.stats.added_lines,
        stats.added_lines + 19,
        "{:?}",
        edit.stats
    );
    let text = |g: &conduit_gcode::Gcode| {
        let mut out = Vec::new();
        g.write_to(&mut out).expect("written");
        String::from_utf8(out).expect("text")
    };
    let with = text(&edit.gcode);
    let block = description_lines(&with).expect("a description block");
    let stripped: Vec<&str> = with
        .lines()
        .enumerate()
        .filter(|(i, _)| !block.contains(i))
        .map(|(_, l)| l)
        .collect();
    let bare_text = text(&bare);
    assert_eq!(stripped, bare_text.lines().collect::<Vec<_>>());

    // The verifier wants the description, and the destination where the part goes.
    let params = config.postprocess_params();
    let verify = |edited: &conduit_gcode::Gcode| {
        conduit::postprocess::verify(&original, edited, &electronics, &params)
            .expect("plans")
            .problems
    };
    assert_eq!(verify(&edit.gcode), Vec::<String>::new());
    assert_eq!(
        verify(&bare),
        ["0 OctoPNP part descriptions where one is expected (1 parts placed by the machine)"]
    );
    let mut moved = edit.gcode.clone();
    let i = moved
        .lines
        .iter()
        .position(|l| l.text.starts_with(b";  <destination x=\"129\""))
        .expect("LED1's destination");
    moved.lines[i] = conduit_gcode::Line::new(
        ";  <destination x=\"128\" y=\"127\" z=\"10\" orientation=\"0\"/>",
        conduit_gcode::LineEnding::Lf,
    );
    let problems = verify(&moved);
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(
        problems[0].starts_with("OctoPNP's destination of part LED1 is Some([128.0, 127.0, 10.0])"),
        "{problems:?}"
    );
}

#[test]
fn without_machine_placed_parts_there_is_no_description() {
    let Some(corpus) = corpus() else { return };
    let dir = temp_dir();
    let src = corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode");
    let toml = dir.path().join("by_hand.toml");
    let placement = std::fs::read_to_string(sample("postprocess/cube_led.toml"))
        .expect("placement")
        .replace("method = \"auto\"", "method = \"manual\"");
    std::fs::write(&toml, placement).expect("written");
    let file = host_copy(dir.path(), &src, "by_hand.gcode");
    let report = dir.path().join("report.json");
    let o = postprocess(&file, &toml, &report, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&file).expect("text");
    assert!(text.contains("M117 Insert LED1"));
    assert_eq!(m361_ids(&text), Vec::<String>::new());
    assert!(!text.contains(DESCRIPTION_MARK));
    assert!(!text.contains('<') && !text.contains('>'));
    let verified = check_postprocessed(&src, &file, &sample("postprocess/cube_led.sch"), &toml);
    assert_eq!(verified.description_lines, 0);
}

#[test]
fn host_lines_in_angle_brackets_are_named_in_a_warning() {
    let Some(corpus) = corpus() else { return };
    let dir = temp_dir();
    // PrusaSlicer writes its custom G-code templates into the settings at the end of the file;
    // one with a comparison and an arrow is text OctoPNP collects.
    let host = std::fs::read_to_string(corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode"))
        .expect("corpus file");
    let mut lines: Vec<&str> = host.lines().collect();
    let at = lines.len() - 2;
    let template = "; end_gcode = {if max_layer_z < max_print_height}G1 Z{max_layer_z+2}{endif} ; \
                    lift -> park";
    lines.insert(at, template);
    // A lone `<` is not collected: no `>` follows it.
    lines.insert(
        at,
        "; start_gcode = {if first_layer_temperature[0] < 200}M104 S200{endif}",
    );
    let src = dir.path().join("host.gcode");
    std::fs::write(&src, lines.join("\n") + "\n").expect("written");
    let file = host_copy(dir.path(), &src, "edited.gcode");
    let report_path = dir.path().join("report.json");
    let toml = sample("postprocess/cube_led.toml");
    let o = postprocess(&file, &toml, &report_path, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let warning = format!(
        "warning: the host's line {} holds text in angle brackets, which OctoPNP reads with its \
         part description and then cannot parse it",
        at + 2
    );
    let err = stderr(&o);
    assert_eq!(err.matches(&warning).count(), 1, "{err}");
    let text = std::fs::read_to_string(&file).expect("text");
    assert!(
        text.lines()
            .any(|l| l.starts_with(&format!("; conduit postprocess: {warning}"))),
        "the summary names it"
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&report_path).expect("report"))
            .expect("JSON");
    let warnings = report["electronics"]["warnings"].to_string();
    assert!(
        warnings.contains(&warning["warning: ".len()..]),
        "{warnings}"
    );
    // The description is still written, and OctoPNP's reader indeed collects the host's line.
    let (xml, root) = octopnp_description(&text);
    assert!(xml.contains("<object name=\"object\">"));
    assert!(
        xml.ends_with("< max_print_height}G1 Z{max_layer_z+2}{endif} ; lift ->\n"),
        "{xml}"
    );
    assert!(root.is_none(), "{xml}");
    // The edit itself is as without the host's line.
    check_postprocessed(&src, &file, &sample("postprocess/cube_led.sch"), &toml);
    let check = conduit(["check".as_ref(), file.as_os_str()]);
    assert_eq!(check.status.code(), Some(0));
}
