//! `conduit preview` on a peer slicer's G-code (one SVG per layer, the contact sheet and the side
//! views), on conduit's curved tops (curved extrusions drawn where the G-code puts them), on the
//! circuit demo (parts labelled, traces in their colour) and into a folder of an earlier run
//! (its extra layer views removed, nothing else).

use std::path::Path;

use crate::support::{conduit, corpus, files_in, slice_circuit_demo, stderr, stdout, temp_dir};

#[test]
fn preview_of_a_prusaslicer_cube_writes_100_svgs_and_a_sheet() {
    let Some(corpus) = corpus() else {
        return;
    };
    let gcode = corpus.join("peer-gcode/20mm_cube.prusaslicer-2.5.gcode");
    let tmp = temp_dir();
    let out = tmp.path().join("preview");
    let run = conduit([
        "preview".as_ref(),
        gcode.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(stdout(&run).contains("100 layers"), "{}", stdout(&run));

    let files = files_in(&out);
    let svgs: Vec<_> = files
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "svg"))
        .collect();
    let pngs: Vec<_> = files
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .collect();
    assert_eq!(svgs.len(), 102);
    assert_eq!(pngs.len(), 3);
    assert_eq!(files.len(), 105);
    assert!(out.join("side_xz.svg").is_file() && out.join("side_yz.png").is_file());
    assert!(out.join("layer_0001.svg").is_file());
    assert!(out.join("layer_0100.svg").is_file());

    // Every layer has the cube's outer wall; the sheet is 6 × 6 tiles of 256 px (34 tiles:
    // every 3rd layer), each with a 24 px label strip, over a legend of 6 roles in 3 columns
    // (2 rows of 24 px and a 16 px margin).
    let svg = std::fs::read_to_string(out.join("layer_0050.svg")).expect("SVG readable");
    assert!(svg.contains(r#"data-role="External perimeter""#));
    assert!(svg.contains("<title>layer 50 of 100, Z 10.000 mm</title>"));
    assert!(svg.contains(">Layer 50 of 100, z 10.000 mm</text>"));
    // Sized for a screen (the legend makes it taller than wide), the millimetres kept in the
    // view box, and a 2 mm scale bar for the 19.55 mm cube.
    assert!(
        svg.contains(r#"width="811" height="1000" viewBox="113.225 -137.953 23.550 29.045""#),
        "{svg}"
    );
    assert!(svg.contains(">2 mm</text>"));
    let png = std::fs::read(out.join("contact_sheet.png")).expect("PNG readable");
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    // IHDR: width and height, big-endian, at bytes 16..24.
    let height: u32 = 6 * (256 + 24) + 2 * 24 + 16;
    assert_eq!(&png[16..20], &1536u32.to_be_bytes());
    assert_eq!(&png[20..24], &height.to_be_bytes());
}

#[test]
fn preview_rejects_a_zero_every() {
    let tmp = temp_dir();
    let run = conduit([
        "preview".as_ref(),
        tmp.path().join("missing.gcode").as_os_str(),
        "-o".as_ref(),
        tmp.path().as_os_str(),
        "--every".as_ref(),
        "0".as_ref(),
    ]);
    assert_eq!(run.status.code(), Some(2), "{}", stderr(&run));
}

/// The (across, Z) points of the side view's polylines whose `data-curved` is `curved`.
fn side_points(svg: &str, curved: bool) -> Vec<(f64, f64)> {
    let tag = format!(r#"data-curved="{curved}""#);
    let mut out = Vec::new();
    for line in svg
        .lines()
        .filter(|l| l.starts_with("<polyline") && l.contains(&tag))
    {
        let Some(points) = line
            .split(r#"points=""#)
            .nth(1)
            .and_then(|r| r.split('"').next())
        else {
            panic!("no points in {line}")
        };
        for pair in points.split_whitespace() {
            let mut it = pair.split(',').map(|v| v.parse::<f64>());
            match (it.next(), it.next()) {
                (Some(Ok(a)), Some(Ok(z))) => out.push((a, -z)),
                _ => panic!("bad point {pair} in {line}"),
            }
        }
    }
    out
}

fn key(a: f64, z: f64) -> (i64, i64) {
    ((a * 1000.0).round() as i64, (z * 1000.0).round() as i64)
}

#[test]
fn preview_of_curved_tops_draws_the_curved_layers_at_their_gcode_heights() {
    use crate::curved::{block_with_top, curved_segments, dome, write_stl};
    use std::collections::BTreeSet;
    let tmp = temp_dir();
    let model = tmp.path().join("dome.stl");
    write_stl(&model, &block_with_top(0.0, 0.0, 30.0, 30.0, 24, &dome));
    let gcode = tmp.path().join("dome.gcode");
    let run = conduit([
        "slice".as_ref(),
        model.as_os_str(),
        "--curved".as_ref(),
        "tops".as_ref(),
        "-o".as_ref(),
        gcode.as_os_str(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let text = std::fs::read_to_string(&gcode).expect("G-code written");
    let out = tmp.path().join("preview");
    let run = conduit([
        "preview".as_ref(),
        gcode.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    // One layer view per planar layer: the curved blocks stay in the layer they follow.
    let planar_z: BTreeSet<i64> = text
        .lines()
        .filter_map(|l| l.strip_prefix(";Z:"))
        .filter_map(|z| z.trim().parse::<f64>().ok())
        .map(|z| (z * 1000.0).round() as i64)
        .collect();
    let layers = files_in(&out)
        .iter()
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("layer_"))
        })
        .count();
    assert!(
        layers > 40 && layers <= planar_z.len(),
        "{layers} layer views"
    );
    assert!(
        stdout(&run).contains(&format!("{layers} layers")),
        "{}",
        stdout(&run)
    );
    let segments = curved_segments(&text);
    assert!(segments.len() > 1000);
    for (axis, file) in [(0, "side_xz.svg"), (1, "side_yz.svg")] {
        let svg = std::fs::read_to_string(out.join(file)).expect("side view written");
        // Every curved point of the G-code, and nothing else, is drawn as curved, at its Z.
        let expected: BTreeSet<(i64, i64)> = segments
            .iter()
            .flat_map(|(a, b, _)| [key(a[axis], a[2]), key(b[axis], b[2])])
            .collect();
        let drawn: BTreeSet<(i64, i64)> = side_points(&svg, true)
            .into_iter()
            .map(|(a, z)| key(a, z))
            .collect();
        assert_eq!(drawn, expected, "{file}");
        // Planar extrusions lie on the layers' Z.
        let planar = side_points(&svg, false);
        assert!(planar.len() > 1000);
        for (_, z) in planar {
            assert!(
                planar_z.contains(&((z * 1000.0).round() as i64)),
                "{file}: z {z}"
            );
        }
        let png = std::fs::read(out.join(file.replace(".svg", ".png"))).expect("PNG written");
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        // IHDR width: 4 × the 256 px tile.
        assert_eq!(&png[16..20], &[0, 0, 4, 0]);
    }
}

/// `layers` layers of a 10 mm square, 0.2 mm apart.
fn squares(layers: usize) -> String {
    let mut g = String::from("G28\nG90\nM82\nG92 E0\n");
    let mut e = 0.0;
    for k in 1..=layers {
        g += &format!(
            ";LAYER_CHANGE\n;Z:{:.1}\nG1 Z{:.1}\nG1 X10 Y10\n",
            k as f64 * 0.2,
            k as f64 * 0.2
        );
        g += ";TYPE:External perimeter\n";
        for (x, y) in [(20, 10), (20, 20), (10, 20), (10, 10)] {
            e += 1.0;
            g += &format!("G1 X{x} Y{y} E{e}\n");
        }
    }
    g
}

fn preview(gcode: &Path, out: &Path) -> std::process::Output {
    conduit([
        "preview".as_ref(),
        gcode.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--json".as_ref(),
    ])
}

#[test]
fn preview_removes_the_layer_views_of_an_earlier_longer_run_and_nothing_else() {
    let tmp = temp_dir();
    let out = tmp.path().join("preview");
    let (long, short) = (
        tmp.path().join("long.gcode"),
        tmp.path().join("short.gcode"),
    );
    std::fs::write(&long, squares(12)).expect("written");
    std::fs::write(&short, squares(3)).expect("written");
    let run = preview(&long, &out);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(out.join("layer_0012.svg").is_file());
    // Files that are not this run's layer views, whatever their names look like.
    let kept = [
        "notes.txt",
        "layer_999.svg",
        "layer_0009.svg.bak",
        "layer_0009.png",
        "my_layer_0009.svg",
    ];
    for name in kept {
        std::fs::write(out.join(name), "mine").expect("written");
    }
    std::fs::create_dir(out.join("layer_0013.svg")).expect("a folder");
    std::fs::write(out.join("layer_00042.svg"), "old").expect("written");

    // A failed run leaves everything where it was.
    let travels = tmp.path().join("travels.gcode");
    std::fs::write(&travels, "G28\nG1 X10 Y10\n").expect("written");
    let run = preview(&travels, &out);
    assert!(!run.status.success());
    assert!(
        stderr(&run).contains("nothing to preview"),
        "{}",
        stderr(&run)
    );
    assert!(out.join("layer_0009.svg").is_file());

    let run = preview(&short, &out);
    assert!(run.status.success(), "{}", stderr(&run));
    let summary: serde_json::Value = serde_json::from_str(&stdout(&run)).expect("JSON");
    let removed: Vec<String> = summary["removed"]
        .as_array()
        .expect("a list")
        .iter()
        .filter_map(|v| v.as_str())
        .map(|p| {
            Path::new(p)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default()
        })
        .collect();
    let mut expected: Vec<String> = (4..=12).map(|k| format!("layer_{k:04}.svg")).collect();
    // Sorted by path: `layer_0004.svg` before `layer_00042.svg` ('.' < '2').
    expected.insert(1, "layer_00042.svg".to_owned());
    assert_eq!(removed, expected);
    for k in 1..=12 {
        let path = out.join(format!("layer_{k:04}.svg"));
        assert_eq!(path.is_file(), k <= 3, "{}", path.display());
    }
    assert!(!out.join("layer_00042.svg").exists());
    for name in kept {
        assert_eq!(
            std::fs::read_to_string(out.join(name)).ok().as_deref(),
            Some("mine"),
            "{name}"
        );
    }
    assert!(out.join("layer_0013.svg").is_dir());
    assert!(out.join("contact_sheet.png").is_file() && out.join("side_yz.svg").is_file());
}

#[test]
fn preview_of_the_circuit_demo_labels_its_parts_and_draws_traces_in_their_colour() {
    use conduit::emit::preview::{TRACE_COLOUR, tint};
    let tmp = temp_dir();
    let gcode = tmp.path().join("demo.gcode");
    slice_circuit_demo(&gcode, &[]);
    let out = tmp.path().join("preview");
    let run = preview(&gcode, &out);
    assert!(run.status.success(), "{}", stderr(&run));
    let summary: serde_json::Value = serde_json::from_str(&stdout(&run)).expect("JSON");
    let parts = summary["parts"].as_array().expect("a list");
    let brief: Vec<String> = parts
        .iter()
        .map(|p| {
            format!(
                "{} {} L{} {} {} {} {}",
                p["name"], p["method"], p["layer"], p["x"], p["y"], p["z"], p["rotation"]
            )
        })
        .collect();
    assert_eq!(
        brief,
        [
            r#""R1" "machine" L24 137.0 118.0 4.0 0.0"#,
            r#""LED1" "machine" L26 137.0 132.0 4.0 90.0"#,
            r#""BAT1" "hand" L37 null null null null"#,
        ]
    );
    let layer = |n: usize| {
        std::fs::read_to_string(out.join(format!("layer_{n:04}.svg"))).expect("layer view")
    };
    // Layer 24 (z 4.8) is printed over R1: its 2.9 × 1.3 mm outline about (137, 118).
    let l24 = layer(24);
    assert!(l24.contains(">Layer 24 of 40, z 4.800 mm</text>"), "{l24}");
    assert!(
        l24.contains(
            r#"<polygon data-part="R1" points="135.550,-117.350 138.450,-117.350 138.450,-118.650 135.550,-118.650"/>"#
        ),
        "{l24}"
    );
    assert!(l24.contains(">R1</text>"));
    assert!(!layer(23).contains("data-part"));
    assert!(layer(37).contains(">Inserted by hand before this layer: BAT1</text>"));
    // The traces (tool 1) in the trace colour's tool-1 tint, which no other role has.
    let c = tint(TRACE_COLOUR, 1);
    let colour = format!(r##"stroke="#{:02x}{:02x}{:02x}""##, c[0], c[1], c[2]);
    let trace = format!(r#"data-role="Conductive trace" data-tool="1" {colour}"#);
    let traced = (1..=40).filter(|&n| layer(n).contains(&trace)).count();
    assert!(traced > 0, "no layer strokes {trace}");
    for n in 1..=40 {
        let svg = layer(n);
        let other = svg
            .lines()
            .any(|l| l.contains(&colour) && !l.contains(r#"data-role="Conductive trace""#));
        assert!(!other, "layer {n}: another role in the trace colour");
    }
    // The side views box both machine-placed parts.
    let side = std::fs::read_to_string(out.join("side_yz.svg")).expect("side view");
    assert!(
        side.contains(r#"<rect data-part="R1" data-layer="24""#),
        "{side}"
    );
    assert!(side.contains(r#"<rect data-part="LED1" data-layer="26""#));
}
