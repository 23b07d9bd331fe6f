//! Unit tests on hand-written files in the syntax of KiCad 7, 8 and 9.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::{KicadError, PadKind, PadShape};

/// A KiCad 8 board: a resistor turned 90° on top, a part on the bottom, a custom pad, an
/// outline rectangle.
const PCB8: &str = r#"(kicad_pcb
	(version 20240108)
	(generator "pcbnew")
	(generator_version "8.0")
	(net 0 "")
	(net 1 "GND")
	(net 2 "SIG")
	(footprint "Resistor_SMD:R_0805_2012Metric"
		(layer "F.Cu")
		(uuid "6f0c7c2e-0000-4000-8000-000000000001")
		(at 100 50 90)
		(property "Reference" "R1" (at 0 -1.65 90) (layer "F.SilkS") (uuid "6f0c7c2e-0000-4000-8000-000000000002"))
		(property "Value" "10k" (at 0 1.65 90) (layer "F.Fab") (hide yes))
		(pad "1" smd roundrect (at -1 0 90) (size 1.2 1.4) (layers "F.Cu" "F.Paste" "F.Mask")
			(roundrect_rratio 0.2083) (net 2 "SIG") (pintype "passive") (uuid "6f0c7c2e-0000-4000-8000-000000000003"))
		(pad "2" smd roundrect (at 1 0 90) (size 1.2 1.4) (layers "F.Cu" "F.Paste" "F.Mask")
			(roundrect_rratio 0.2083) (net 1 "GND") (pintype "passive"))
	)
	(footprint "Connector:Pad_Custom"
		(layer "B.Cu")
		(at 110 60)
		(property "Reference" "J1" (at 0 0 0) (layer "B.SilkS"))
		(property "Value" "ANT" (at 0 0 0) (layer "B.Fab"))
		(pad "1" thru_hole circle (at 2 1) (size 1.7 1.7) (drill 1) (layers "*.Cu" "*.Mask") (net 2 "SIG"))
		(pad "2" smd custom (at -2 0) (size 1 1) (layers "B.Cu")
			(options (clearance outline) (anchor circle))
			(primitives
				(gr_poly (pts (xy 0 0) (xy 3 0) (xy 3 -2)) (width 0.2) (fill yes))
			)
			(net 1 "GND"))
		(pad "" np_thru_hole oval (at 0 -3) (size 1 2) (drill oval 1 2) (layers "*.Cu"))
	)
	(gr_rect (start 90 40) (end 120 70) (stroke (width 0.1) (type default)) (fill none) (layer "Edge.Cuts")
		(uuid "6f0c7c2e-0000-4000-8000-000000000004"))
)
"#;

fn close(a: (f64, f64), b: (f64, f64)) -> bool {
    (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9
}

#[test]
fn kicad8_board_footprints_pads_nets_and_outline() {
    let pcb = crate::read_pcb(PCB8.as_bytes()).expect("test data");
    assert_eq!(pcb.version, 20_240_108);
    let r1 = pcb.footprint("R1").expect("test data");
    assert_eq!((r1.value.as_str(), r1.bottom), ("10k", false));
    assert_eq!(r1.name, "Resistor_SMD:R_0805_2012Metric");
    let p1 = r1.pad("1").expect("test data");
    assert_eq!(p1.kind, PadKind::Smd);
    assert_eq!(p1.shape, PadShape::RoundRect { ratio: 0.2083 });
    assert_eq!((p1.width, p1.height, p1.rotation), (1.2, 1.4, 90.0));
    // (-1, 0) turned 90° counter-clockwise on screen (y down) is (0, 1).
    assert!(close(r1.board_position(p1), (100.0, 51.0)));
    assert!(close(
        r1.board_position(r1.pad("2").expect("test data")),
        (100.0, 49.0)
    ));
    let j1 = pcb.footprint("J1").expect("test data");
    assert!(j1.bottom);
    assert_eq!(j1.pads[0].drill, Some((1.0, 1.0)));
    assert!(close(j1.board_position(&j1.pads[0]), (112.0, 61.0)));
    // The custom pad's box: the anchor circle (±0.5) and the polygon (0..3, -2..0) with half
    // its 0.2 line width.
    assert_eq!(
        j1.pads[1].shape,
        PadShape::Custom {
            bounds: [-0.5, -2.1, 3.1, 0.5]
        }
    );
    assert_eq!(j1.pads[2].kind, PadKind::NpThroughHole);
    assert_eq!(j1.pads[2].drill, Some((1.0, 2.0)));
    assert_eq!(j1.pads[2].net, None);
    let nl = pcb.netlist();
    let pads = |v: &[(&str, &str)]| -> BTreeSet<(String, String)> {
        v.iter()
            .map(|(a, b)| ((*a).to_owned(), (*b).to_owned()))
            .collect()
    };
    assert_eq!(nl["GND"], pads(&[("J1", "2"), ("R1", "2")]));
    assert_eq!(nl["SIG"], pads(&[("J1", "1"), ("R1", "1")]));
    assert_eq!(pcb.outline.len(), 1);
    assert_eq!(
        pcb.outline[0].extent_points(),
        [(90.0, 40.0), (120.0, 40.0), (120.0, 70.0), (90.0, 70.0)]
    );
}

/// A root sheet: R1 upright, R2 turned 90°, a local label on a wire's middle and on R2's pin,
/// a power symbol, and one child sheet file instanced twice.
fn root_sheet(kicad8: bool) -> String {
    let (version, sheet_name, sheet_file, hide) = if kicad8 {
        ("20231120", "Sheetname", "Sheetfile", "(hide yes)")
    } else {
        ("20230121", "Sheet name", "Sheet file", "hide")
    };
    format!(
        r##"(kicad_sch (version {version}) (generator "eeschema") (generator_version "8.0")
  (uuid "00000000-0000-4000-8000-0000000000aa")
  (paper "A4")
  (lib_symbols
    (symbol "Device:R" (pin_numbers {hide}) (in_bom yes) (on_board yes)
      (property "Reference" "R" (at 2.032 0 90))
      (symbol "R_0_1" (rectangle (start -1.016 -2.54) (end 1.016 2.54)))
      (symbol "R_1_1"
        (pin passive line (at 0 3.81 270) (length 1.27) (name "~") (number "1"))
        (pin passive line (at 0 -3.81 90) (length 1.27) (name "~") (number "2"))))
    (symbol "power:GND" (power) (pin_names (offset 0)) (in_bom yes) (on_board yes)
      (property "Reference" "#PWR" (at 0 -6.35 0))
      (property "Value" "GND" (at 0 -3.81 0))
      (symbol "GND_1_1"
        (pin power_in line (at 0 0 270) (length 0) {hide} (name "GND") (number "1")))))
  (junction (at 50 60) (diameter 0) (color 0 0 0 0) (uuid "00000000-0000-4000-8000-000000000001"))
  (wire (pts (xy 50 46.19) (xy 40 46.19)) (stroke (width 0) (type default)) (uuid "00000000-0000-4000-8000-000000000002"))
  (wire (pts (xy 50 53.81) (xy 50 60)) (stroke (width 0) (type default)))
  (wire (pts (xy 50 60) (xy 50 65)) (stroke (width 0) (type default)))
  (wire (pts (xy 63.81 50) (xy 90 50)) (stroke (width 0) (type default)))
  (label "SIG" (at 45 46.19 0) (effects (font (size 1.27 1.27))) (uuid "00000000-0000-4000-8000-000000000003"))
  (label "SIG" (at 56.19 50 0) (effects (font (size 1.27 1.27))))
  (no_connect (at 40 46.19) (uuid "00000000-0000-4000-8000-000000000004"))
  (symbol (lib_id "Device:R") (at 50 50 0) (unit 1) (in_bom yes) (on_board yes) (dnp no)
    (uuid "00000000-0000-4000-8000-000000000011")
    (property "Reference" "R1" (at 52 50 0)) (property "Value" "10k" (at 52 52 0))
    (property "Footprint" "Resistor_SMD:R_0805_2012Metric" (at 0 0 0) (effects {hide}))
    (pin "1" (uuid "00000000-0000-4000-8000-000000000012")) (pin "2" (uuid "00000000-0000-4000-8000-000000000013"))
    (instances (project "demo" (path "/00000000-0000-4000-8000-0000000000aa" (reference "R1") (unit 1)))))
  (symbol (lib_id "Device:R") (at 60 50 90) (unit 1) (in_bom yes) (on_board yes)
    (uuid "00000000-0000-4000-8000-000000000021")
    (property "Reference" "R2" (at 0 0 0)) (property "Value" "1k" (at 0 0 0))
    (property "Footprint" "Resistor_SMD:R_0805_2012Metric" (at 0 0 0))
    (instances (project "demo" (path "/00000000-0000-4000-8000-0000000000aa" (reference "R2") (unit 1)))))
  (symbol (lib_id "power:GND") (at 50 65 0) (unit 1) (in_bom yes) (on_board yes)
    (uuid "00000000-0000-4000-8000-000000000031")
    (property "Reference" "#PWR01" (at 0 0 0)) (property "Value" "GND" (at 0 0 0))
    (instances (project "demo" (path "/00000000-0000-4000-8000-0000000000aa" (reference "#PWR01") (unit 1)))))
  (sheet (at 70 40) (size 10 20) (uuid "00000000-0000-4000-8000-0000000000b1")
    (property "{sheet_name}" "left" (at 70 39 0)) (property "{sheet_file}" "child.kicad_sch" (at 70 61 0))
    (pin "OUT" passive (at 70 50 180) (uuid "00000000-0000-4000-8000-000000000041")))
  (sheet (at 90 40) (size 10 20) (uuid "00000000-0000-4000-8000-0000000000b2")
    (property "{sheet_name}" "right" (at 90 39 0)) (property "{sheet_file}" "child.kicad_sch" (at 90 61 0))
    (pin "OUT" passive (at 90 50 180)))
  (sheet_instances (path "/" (page "1")))
)
"##
    )
}

/// The child sheet: R3 mirrored about x, its pin 1 on a hierarchical label, pin 2 on ground.
const CHILD: &str = r##"(kicad_sch (version 20231120) (generator "eeschema") (generator_version "8.0")
  (uuid "00000000-0000-4000-8000-0000000000cc")
  (lib_symbols
    (symbol "Device:R" (in_bom yes) (on_board yes)
      (symbol "R_1_1"
        (pin passive line (at 0 3.81 270) (length 1.27) (name "~") (number "1"))
        (pin passive line (at 0 -3.81 90) (length 1.27) (name "~") (number "2"))))
    (symbol "power:GND" (power) (in_bom yes) (on_board yes)
      (symbol "GND_1_1" (pin power_in line (at 0 0 270) (length 0) (hide yes) (name "GND") (number "1")))))
  (hierarchical_label "OUT" (shape passive) (at 100 103.81 0))
  (symbol (lib_id "Device:R") (at 100 100 0) (mirror x) (unit 1) (in_bom yes) (on_board yes)
    (uuid "00000000-0000-4000-8000-000000000051")
    (property "Reference" "R?" (at 0 0 0)) (property "Value" "100" (at 0 0 0))
    (property "Footprint" "Resistor_SMD:R_0603_1608Metric" (at 0 0 0))
    (instances (project "demo"
      (path "/00000000-0000-4000-8000-0000000000aa/00000000-0000-4000-8000-0000000000b1" (reference "R3") (unit 1))
      (path "/00000000-0000-4000-8000-0000000000aa/00000000-0000-4000-8000-0000000000b2" (reference "R4") (unit 1)))))
  (symbol (lib_id "power:GND") (at 100 96.19 180) (unit 1) (in_bom yes) (on_board yes)
    (uuid "00000000-0000-4000-8000-000000000061")
    (property "Reference" "#PWR02" (at 0 0 0)) (property "Value" "GND" (at 0 0 0)))
)
"##;

fn loader(files: BTreeMap<PathBuf, String>) -> impl FnMut(&Path) -> std::io::Result<Vec<u8>> {
    move |p| {
        files
            .get(p)
            .map(|s| s.as_bytes().to_vec())
            .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"))
    }
}

fn pads(v: &[(&str, &str)]) -> BTreeSet<(String, String)> {
    v.iter()
        .map(|(a, b)| ((*a).to_owned(), (*b).to_owned()))
        .collect()
}

#[test]
fn kicad7_and_kicad8_schematics_netlist_through_labels_power_and_sheets() {
    for kicad8 in [false, true] {
        let root = root_sheet(kicad8);
        let files = BTreeMap::from([(PathBuf::from("p/child.kicad_sch"), CHILD.to_owned())]);
        let s = crate::read_schematic(
            root.as_bytes(),
            Path::new("p/demo.kicad_sch"),
            &mut loader(files),
        )
        .expect("test data");
        assert_eq!(s.sheet_instances, 3);
        let refs: Vec<_> = s.parts.iter().map(|p| p.reference.as_str()).collect();
        assert_eq!(refs, ["R1", "R2", "R3", "R4"]);
        assert_eq!(
            s.part("R3").expect("test data").footprint,
            "Resistor_SMD:R_0603_1608Metric"
        );
        assert_eq!(s.part("R4").expect("test data").value, "100");
        let nl = s.netlist();
        assert_eq!(nl["/SIG"], pads(&[("R1", "1"), ("R2", "1")]), "{nl:?}");
        assert_eq!(nl["GND"], pads(&[("R1", "2"), ("R3", "2"), ("R4", "2")]));
        let out = nl
            .values()
            .find(|p| p.contains(&("R2".to_owned(), "2".to_owned())))
            .expect("test data");
        assert_eq!(*out, pads(&[("R2", "2"), ("R3", "1"), ("R4", "1")]));
        assert_eq!(nl.len(), 3);
    }
}

#[test]
fn a_missing_sheet_file_and_a_bad_value_are_named() {
    let root = root_sheet(true);
    let e = crate::read_schematic(
        root.as_bytes(),
        Path::new("p/demo.kicad_sch"),
        &mut loader(BTreeMap::new()),
    )
    .expect_err("must be refused");
    assert!(
        matches!(&e, KicadError::SheetIo { file, .. } if file == Path::new("p/child.kicad_sch"))
    );
    let bad = CHILD.replace("(at 100 100 0) (mirror x)", "(at 100 1OO 0) (mirror x)");
    let files = BTreeMap::from([(PathBuf::from("p/child.kicad_sch"), bad)]);
    let e = crate::read_schematic(
        root.as_bytes(),
        Path::new("p/demo.kicad_sch"),
        &mut loader(files),
    )
    .expect_err("must be refused");
    assert_eq!(
        e.to_string(),
        "p/child.kicad_sch: kicad_sch/symbol/at, line 11, column 39: \"1OO\" is not y, mm"
    );
    // A sheet that holds itself.
    let selfish = root.replace("child.kicad_sch", "demo.kicad_sch");
    let e = crate::read_schematic(
        selfish.as_bytes(),
        Path::new("p/demo.kicad_sch"),
        &mut loader(BTreeMap::new()),
    )
    .expect_err("must be refused");
    assert!(matches!(e, KicadError::RecursiveSheet { .. }), "{e}");
}

#[test]
fn kicad9_pad_net_by_name_and_unknown_kinds() {
    let pcb = r#"(kicad_pcb (version 20241229) (generator "pcbnew") (generator_version "9.0")
      (net 0 "") (net 1 "VCC")
      (footprint "X" (layer "F.Cu") (at 0 0)
        (property "Reference" "U1")
        (pad "1" smd rect (at 0 0) (size 1 1) (layers "F.Cu") (net 1 "VCC"))
        (pad "2" smd rect (at 1 0) (size 1 1) (layers "F.Cu") (net 1))))"#;
    let p = crate::read_pcb(pcb.as_bytes()).expect("test data");
    assert_eq!(p.footprints[0].pads[0].net.as_deref(), Some("VCC"));
    assert_eq!(p.footprints[0].pads[1].net.as_deref(), Some("VCC"));
    let e = crate::read_pcb(pcb.replace("smd rect", "smd hexagon").as_bytes())
        .expect_err("must be refused");
    assert!(
        e.to_string().starts_with("kicad_pcb/footprint/pad, line 5"),
        "{e}"
    );
    let e = crate::read_pcb(b"(kicad_sch (version 1))").expect_err("must be refused");
    assert!(matches!(
        e,
        KicadError::WrongKind {
            expected: "board",
            found: "schematic"
        }
    ));
    assert_eq!(
        crate::sniff(b"  (kicad_sch (version 1))"),
        Some(crate::Kind::Schematic)
    );
    assert_eq!(
        crate::sniff(b"(export (version \"E\"))"),
        Some(crate::Kind::NetFile)
    );
    assert_eq!(crate::sniff(b"<?xml"), None);
}

#[test]
fn netlist_export_components_and_nets() {
    let net = r#"(export (version "E")
  (design (source "demo.kicad_sch") (tool "Eeschema 8.0.0"))
  (components
    (comp (ref "R1") (value "10k") (footprint "Resistor_SMD:R_0805_2012Metric"))
    (comp (ref "R2") (value "1k") (footprint "Resistor_SMD:R_0805_2012Metric")))
  (nets
    (net (code "1") (name "/SIG") (node (ref "R1") (pin "1") (pintype "passive")) (node (ref "R2") (pin "1")))
    (net (code "2") (name "unconnected-(R2-Pad2)") (node (ref "R2") (pin "2")))))"#;
    let n = crate::read_netfile(net.as_bytes()).expect("test data");
    assert_eq!(n.components.len(), 2);
    assert_eq!(n.components[1].value, "1k");
    assert_eq!(n.netlist()["/SIG"], pads(&[("R1", "1"), ("R2", "1")]));
    let e = crate::read_netfile(br#"(export (nets (net (node (ref "R1")))))"#)
        .expect_err("must be refused");
    assert_eq!(
        e.to_string(),
        "export/nets/net/node, line 1, column 20: (pin …) is missing"
    );
}
