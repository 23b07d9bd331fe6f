//! `conduit preview` on a peer slicer's G-code: one SVG per layer plus the contact sheet.

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
    assert_eq!(svgs.len(), 100);
    assert_eq!(pngs.len(), 1);
    assert_eq!(files.len(), 101);
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
