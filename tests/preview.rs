//! `conduit preview` on a peer slicer's G-code (one SVG per layer, the contact sheet and the side
//! views) and on conduit's curved tops (curved extrusions drawn where the G-code puts them).

use crate::support::{conduit, corpus, files_in, stderr, stdout, temp_dir};

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
    // every 3rd layer).
    let svg = std::fs::read_to_string(out.join("layer_0050.svg")).expect("SVG readable");
    assert!(svg.contains(r#"data-role="External perimeter""#));
    assert!(svg.contains("<title>layer 50 of 100, Z 10.000 mm</title>"));
    let png = std::fs::read(out.join("contact_sheet.png")).expect("PNG readable");
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    // IHDR: width and height, big-endian, at bytes 16..24.
    assert_eq!(&png[16..24], &[0, 0, 6, 0, 0, 0, 6, 0]);
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
