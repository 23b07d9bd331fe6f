//! Unit tests on small synthetic EAGLE files.

use std::collections::BTreeSet;

use crate::*;

/// A library used by all synthetic schematics:
/// - `R`: one gate `G$1` (pins A, B) on package `P3` (pads 1, 2, 3) with `A` on pads `1 3`;
/// - `IC`: gate `A` (pins A, B) and a power gate `P` (pins VCC@1, GND, direction pwr) on
///   package `P4` (pads 1-4);
/// - `GND`: a supply symbol (pin GND, direction sup) without package.
const LIB: &str = r#"<libraries><library name="L">
<packages>
 <package name="P3"><smd name="1" x="-1" y="0" dx="0.5" dy="0.8" layer="1" roundness="25"/>
  <smd name="2" x="1" y="0" dx="0.5" dy="0.8" layer="1" rot="R90"/>
  <smd name="3" x="0" y="1" dx="0.5" dy="0.8" layer="16"/></package>
 <package name="P4"><pad name="1" x="0" y="0" drill="0.8" shape="square"/>
  <pad name="2" x="2.54" y="0" drill="0.8" diameter="1.6"/>
  <pad name="3" x="5.08" y="0" drill="0.8" diameter="0"/>
  <pad name="4" x="7.62" y="0" drill="0.8" rot="R45"/></package>
</packages>
<symbols>
 <symbol name="S2"><pin name="A" x="0" y="0"/><pin name="B" x="0" y="0"/></symbol>
 <symbol name="PWR"><pin name="VCC@1" x="0" y="0" direction="pwr"/><pin name="GND" x="0" y="0" direction="pwr"/></symbol>
 <symbol name="SUP"><pin name="GND" x="0" y="0" direction="sup"/></symbol>
</symbols>
<devicesets>
 <deviceset name="R"><gates><gate name="G$1" symbol="S2" x="0" y="0"/></gates>
  <devices><device name="" package="P3"><connects>
   <connect gate="G$1" pin="A" pad="1 3" route="any"/><connect gate="G$1" pin="B" pad="2"/>
  </connects></device></devices></deviceset>
 <deviceset name="IC"><gates><gate name="A" symbol="S2" x="0" y="0"/>
   <gate name="P" symbol="PWR" x="0" y="0" addlevel="request"/></gates>
  <devices><device name="DIP" package="P4"><connects>
   <connect gate="A" pin="A" pad="1"/><connect gate="A" pin="B" pad="2"/>
   <connect gate="P" pin="VCC@1" pad="3"/><connect gate="P" pin="GND" pad="4"/>
  </connects></device></devices></deviceset>
 <deviceset name="GND"><gates><gate name="1" symbol="SUP" x="0" y="0"/></gates>
  <devices><device name=""/></devices></deviceset>
</devicesets>
</library></libraries>
<classes><class number="0" name="default" width="0" drill="0"/><class number="1" name="power" width="0.4" drill="0"/></classes>"#;

fn schematic(body: &str) -> String {
    format!(
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<!DOCTYPE eagle SYSTEM \"eagle.dtd\">\n\
         <eagle version=\"9.6.2\"><drawing><schematic>\n{LIB}\n{body}\n</schematic></drawing></eagle>\n"
    )
}

fn pinref(part: &str, gate: &str, pin: &str) -> String {
    format!(r#"<pinref part="{part}" gate="{gate}" pin="{pin}"/>"#)
}

fn net(name: &str, refs: &[String]) -> String {
    format!(
        r#"<net name="{name}" class="0"><segment>{}</segment></net>"#,
        refs.concat()
    )
}

fn pads(list: &[(&str, &str)]) -> BTreeSet<(String, String)> {
    list.iter()
        .map(|(a, b)| ((*a).to_owned(), (*b).to_owned()))
        .collect()
}

fn read_sch(xml: &str) -> Schematic {
    match read_schematic(xml.as_bytes()) {
        Ok(s) => s,
        Err(e) => panic!("{e}\n{xml}"),
    }
}

#[test]
fn one_pin_on_two_pads_puts_both_pads_on_the_net() {
    let xml = schematic(&format!(
        r#"<parts><part name="R1" library="L" deviceset="R" device="" value="10k"/>
           <part name="R2" library="L" deviceset="R" device=""/></parts>
           <sheets><sheet><nets>{}</nets></sheet></sheets>"#,
        net("N$1", &[pinref("R1", "G$1", "A"), pinref("R2", "G$1", "B")])
    ));
    let s = read_sch(&xml);
    assert_eq!(s.version, "9.6.2");
    assert_eq!(s.parts.len(), 2);
    let r1 = s.part("R1").expect("R1");
    assert_eq!(r1.value.as_deref(), Some("10k"));
    assert_eq!(r1.pin_pads["G$1.A"], ["1", "3"]);
    assert_eq!(r1.pin_pads["G$1.B"], ["2"]);
    assert_eq!(r1.route_any, ["G$1.A".to_owned()].into());
    let pkg = r1.package.as_ref().expect("package");
    assert_eq!(pkg.name, "P3");
    assert_eq!(pkg.library, "L");
    assert_eq!(
        pkg.pads[0].shape,
        PadShape::Smd {
            dx: 0.5,
            dy: 0.8,
            roundness: 25.0
        }
    );
    assert_eq!(pkg.pads[1].rotation.degrees, 90.0);
    assert_eq!(pkg.pads[2].layer, LAYER_BOTTOM);
    assert_eq!(s.nets.len(), 1);
    assert_eq!(s.nets[0].class.as_deref(), Some("default"));
    assert_eq!(
        s.netlist()["N$1"],
        pads(&[("R1", "1"), ("R1", "3"), ("R2", "2")])
    );
}

#[test]
fn through_hole_pads() {
    let xml = schematic(
        r#"<parts><part name="U1" library="L" deviceset="IC" device="DIP"/></parts><sheets><sheet/></sheets>"#,
    );
    let s = read_sch(&xml);
    let pkg = s.parts[0].package.as_ref().expect("package");
    let shapes: Vec<_> = pkg.pads.iter().map(|p| p.shape.clone()).collect();
    let th = |diameter, shape: &str| PadShape::Through {
        drill: 0.8,
        diameter,
        shape: shape.to_owned(),
    };
    assert_eq!(
        shapes,
        [
            th(None, "square"),
            th(Some(1.6), "round"),
            th(None, "round"),
            th(None, "round")
        ]
    );
    assert!(pkg.pads.iter().all(|p| p.layer == LAYER_PADS));
    assert_eq!(pkg.pads[3].rotation.degrees, 45.0);
}

#[test]
fn nets_merge_across_sheets_and_supply_parts_are_dropped() {
    let xml = schematic(&format!(
        r#"<parts><part name="R1" library="L" deviceset="R" device=""/>
           <part name="R2" library="L" deviceset="R" device=""/>
           <part name="GND1" library="L" deviceset="GND" device=""/>
           <part name="GND2" library="L" deviceset="GND" device=""/></parts>
           <sheets><sheet><nets>{}</nets></sheet><sheet><nets>{}{}</nets></sheet></sheets>"#,
        net(
            "GND",
            &[pinref("R1", "G$1", "B"), pinref("GND1", "1", "GND")]
        ),
        net(
            "GND",
            &[pinref("R2", "G$1", "B"), pinref("GND2", "1", "GND")]
        ),
        net("ALONE", &[pinref("R2", "G$1", "A")]),
    ));
    let s = read_sch(&xml);
    assert_eq!(s.dropped_parts, ["GND1", "GND2"]);
    assert_eq!(s.parts.len(), 2);
    let nl = s.netlist();
    assert_eq!(nl["GND"], pads(&[("R1", "2"), ("R2", "2")]));
    assert_eq!(nl["ALONE"], pads(&[("R2", "1"), ("R2", "3")]));
}

#[test]
fn unwired_power_pins_join_the_net_named_after_the_pin() {
    // U1's power gate is never placed: VCC@1 and GND are wired implicitly. U2's GND pin is on
    // an explicit net, so only its VCC@1 joins VCC.
    let xml = schematic(&format!(
        r#"<parts><part name="U1" library="L" deviceset="IC" device="DIP"/>
           <part name="U2" library="L" deviceset="IC" device="DIP"/>
           <part name="R1" library="L" deviceset="R" device=""/></parts>
           <sheets><sheet><instances><instance part="U1" gate="A" x="0" y="0"/>
           <instance part="U2" gate="A" x="0" y="0"/><instance part="U2" gate="P" x="0" y="0"/></instances>
           <nets>{}{}</nets></sheet></sheets>"#,
        net("GND", &[pinref("R1", "G$1", "B")]),
        net(
            "AGND",
            &[pinref("U2", "P", "GND"), pinref("R1", "G$1", "A")]
        ),
    ));
    let nl = read_sch(&xml).netlist();
    assert_eq!(nl["GND"], pads(&[("R1", "2"), ("U1", "4")]));
    assert_eq!(nl["VCC"], pads(&[("U1", "3"), ("U2", "3")]));
    assert_eq!(nl["AGND"], pads(&[("R1", "1"), ("R1", "3"), ("U2", "4")]));
}

/// A module `AMP` (ports IN, OUT; parts R1, R2 in series through local net X) used twice:
/// `M1` without offset (parts `M1:R1`, `M1:R2`) and `M2` with offset 100 (`R101`, `R102`).
fn modular_schematic() -> String {
    let module = format!(
        r#"<modules><module name="AMP" prefix="" dx="20" dy="10">
           <ports><port name="IN" side="left" coord="0" direction="io"/>
            <port name="OUT" side="right" coord="0" direction="io"/></ports>
           <variantdefs/>
           <parts><part name="R1" library="L" deviceset="R" device=""/>
            <part name="R2" library="L" deviceset="R" device=""/>
            <part name="GND1" library="L" deviceset="GND" device=""/></parts>
           <sheets><sheet><nets>{}{}{}{}</nets></sheet></sheets>
           </module></modules>"#,
        net("IN", &[pinref("R1", "G$1", "A")]),
        net("X", &[pinref("R1", "G$1", "B"), pinref("R2", "G$1", "A")]),
        net("OUT", &[pinref("R2", "G$1", "B")]),
        net("GND", &[pinref("GND1", "1", "GND")]),
    );
    let portref =
        |inst: &str, port: &str| format!(r#"<portref moduleinst="{inst}" port="{port}"/>"#);
    format!(
        r#"{module}
        <parts><part name="J1" library="L" deviceset="R" device=""/>
         <part name="R1" library="L" deviceset="R" device=""/></parts>
        <sheets><sheet><moduleinsts><moduleinst name="M1" module="AMP" x="0" y="0"/>
          <moduleinst name="M2" module="AMP" x="50" y="0" offset="100"/></moduleinsts>
         <nets>{}{}</nets></sheet>
         <sheet><nets>{}</nets></sheet></sheets>"#,
        net("SIG", &[pinref("J1", "G$1", "A"), portref("M1", "IN")]),
        net("MID", &[portref("M1", "OUT"), portref("M2", "IN")]),
        net("OUT", &[portref("M2", "OUT"), pinref("R1", "G$1", "A")]),
    )
}

#[test]
fn module_instances_are_flattened() {
    let s = read_sch(&schematic(&modular_schematic()));
    let names: Vec<&str> = s.parts.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["J1", "R1", "M1:R1", "M1:R2", "R101", "R102"]);
    assert_eq!(s.dropped_parts, ["M1:GND1", "GND101"]);
    let nl = s.netlist();
    assert_eq!(
        nl["SIG"],
        pads(&[("J1", "1"), ("J1", "3"), ("M1:R1", "1"), ("M1:R1", "3")])
    );
    assert_eq!(
        nl["MID"],
        pads(&[("M1:R2", "2"), ("R101", "1"), ("R101", "3")])
    );
    assert_eq!(nl["OUT"], pads(&[("R102", "2"), ("R1", "1"), ("R1", "3")]));
    // Local nets keep their instance prefix; port nets take the outer name.
    assert_eq!(
        nl["M1:X"],
        pads(&[("M1:R1", "2"), ("M1:R2", "1"), ("M1:R2", "3")])
    );
    assert_eq!(
        nl["M2:X"],
        pads(&[("R101", "2"), ("R102", "1"), ("R102", "3")])
    );
    assert!(!nl.contains_key("M1:IN") && !nl.contains_key("M2:OUT"));
    // Supply nets inside modules are global.
    assert!(nl.contains_key("GND") && !nl.contains_key("M1:GND"));
    // Every pad is on at most one net.
    let total: usize = nl.values().map(BTreeSet::len).sum();
    let distinct: BTreeSet<_> = nl.values().flatten().collect();
    assert_eq!(total, distinct.len());
}

#[test]
fn recursive_and_unknown_modules_are_errors() {
    let rec = schematic(
        r#"<modules><module name="A"><parts/><sheets><sheet><moduleinsts>
           <moduleinst name="I" module="A" x="0" y="0"/></moduleinsts></sheet></sheets></module></modules>
           <parts/><sheets><sheet><moduleinsts><moduleinst name="TOP" module="A" x="0" y="0"/></moduleinsts></sheet></sheets>"#,
    );
    assert!(matches!(
        read_schematic(rec.as_bytes()),
        Err(EagleError::RecursiveModule { module }) if module == "A"
    ));
    let unknown = schematic(
        r#"<parts/><sheets><sheet><moduleinsts><moduleinst name="TOP" module="NOPE" x="0" y="0"/></moduleinsts></sheet></sheets>"#,
    );
    assert!(matches!(
        read_schematic(unknown.as_bytes()),
        Err(EagleError::UnknownModule { module, .. }) if module == "NOPE"
    ));
}

#[test]
fn binary_eagle_is_rejected_with_the_documented_message() {
    let msg = "binary EAGLE format (before 6.0) is not supported; open and re-save it in EAGLE 6 or later";
    for bytes in [
        &[0x10u8, 0x80, 0x5a, 0x00, 0x0c, 0x07, 0x00, 0x00][..],
        &[0x10, 0x00, 0x01],
    ] {
        let err = read(bytes).expect_err("binary");
        assert!(matches!(err, EagleError::BinaryFormat));
        assert_eq!(err.to_string(), msg);
        assert_eq!(read_schematic(bytes).expect_err("binary").to_string(), msg);
        assert_eq!(read_board(bytes).expect_err("binary").to_string(), msg);
    }
}

#[test]
fn broken_input_is_a_clean_error() {
    let cases: &[&[u8]] = &[
        b"",
        b"   ",
        b"hello",
        b"\xff\xfe<eagle/>",
        b"<eagle>",
        b"<eagle><drawing></eagle>",
        b"<eagle version=\"9\"><drawing/></eagle>",
        b"<eagle version=\"9\"></eagle>",
        b"<svg/>",
        b"<eagle><drawing><schematic><parts><part name=\"X\"/></parts></schematic></drawing></eagle>",
        b"<eagle><drawing><board><elements><element name=\"X\" library=\"L\" package=\"P\" x=\"0\" y=\"0\"/></elements></board></drawing></eagle>",
        b"<eagle><drawing><board><plain><wire x1=\"a\" y1=\"0\" x2=\"0\" y2=\"0\" layer=\"20\"/></plain></board></drawing></eagle>",
        b"<eagle a=\"1\" a=\"2\"><drawing/></eagle>",
        b"<eagle><drawing><schematic/></drawing></eagle",
        b"\x00\x01\x02\x03",
    ];
    for bytes in cases {
        assert!(read(bytes).is_err(), "{:?}", String::from_utf8_lossy(bytes));
    }
    assert!(matches!(
        read(b"<eagle version=\"9\"><drawing><library/></drawing></eagle>"),
        Ok(Document::Library)
    ));
}

#[test]
fn errors_name_the_element_and_line() {
    let xml = schematic(&format!(
        "<parts><part name=\"R1\" library=\"L\" deviceset=\"R\" device=\"\"/></parts>\n\
         <sheets><sheet><nets>\n{}</nets></sheet></sheets>",
        net("N", &[pinref("R9", "G$1", "A")])
    ));
    let line = xml
        .lines()
        .position(|l| l.contains("part=\"R9\""))
        .map(|i| i + 1)
        .expect("line");
    let err = read_schematic(xml.as_bytes()).expect_err("unknown part");
    assert!(
        matches!(&err, EagleError::UnknownReference { element: "pinref", name, line: l, .. } if name == "R9" && *l == line),
        "{err:?}"
    );
    assert!(err.to_string().contains(&format!("line {line}")), "{err}");

    let bad_rot = schematic("<parts/><sheets/>").replace("rot=\"R90\"", "rot=\"Q90\"");
    let err = read_schematic(bad_rot.as_bytes()).expect_err("bad rot");
    assert!(
        matches!(&err, EagleError::InvalidAttribute { element, attribute: "rot", value, .. } if element == "smd" && value == "Q90"),
        "{err:?}"
    );

    let missing_lib = schematic(r#"<parts><part name="R1" library="NOPE" deviceset="R"/></parts>"#);
    assert!(matches!(
        read_schematic(missing_lib.as_bytes()),
        Err(EagleError::UnknownLibrary { library, .. }) if library == "NOPE"
    ));
    let missing_dev =
        schematic(r#"<parts><part name="R1" library="L" deviceset="R" device="X"/></parts>"#);
    assert!(matches!(
        read_schematic(missing_dev.as_bytes()),
        Err(EagleError::UnknownDevice { device, .. }) if device == "X"
    ));

    let xml_err = read(b"<eagle>\n<drawing>\n</eagle>").expect_err("mismatched end");
    assert!(
        matches!(xml_err, EagleError::Xml { line: 3, .. }),
        "{xml_err:?}"
    );
}

#[test]
fn board_elements_signals_and_outline() {
    let brd = format!(
        r#"<?xml version="1.0" encoding="utf-8"?>
<eagle version="7.5.0"><drawing><board>
<plain><wire x1="0" y1="0" x2="50" y2="0" width="0.2" layer="20"/>
<wire x1="50" y1="0" x2="50" y2="30" width="0.2" layer="20" curve="90"/>
<wire x1="0" y1="0" x2="1" y2="1" width="0.2" layer="21"/></plain>
{LIB}
<elements><element name="R1" library="L" package="P3" value="1k" x="10" y="5" rot="MR90"/>
<element name="U1" library="L" package="P4" x="20.5" y="7.25"/>
<element name="LOGO" library="L" package="P3" x="0" y="0"/></elements>
<signals><signal name="N$1" class="1"><contactref element="R1" pad="1"/><contactref element="R1" pad="3"/>
<contactref element="U1" pad="2"/><wire x1="0" y1="0" x2="1" y2="1" width="0.2" layer="1"/></signal>
<signal name="GND"><contactref element="U1" pad="4"/></signal></signals>
</board></drawing></eagle>"#
    );
    let b = match read_board(brd.as_bytes()) {
        Ok(b) => b,
        Err(e) => panic!("{e}"),
    };
    assert_eq!(b.version, "7.5.0");
    assert_eq!(b.elements.len(), 3);
    let r1 = b.element("R1").expect("R1");
    assert!(r1.is_bottom());
    assert_eq!(
        r1.rotation,
        Rotation {
            degrees: 90.0,
            mirror: true,
            spin: false
        }
    );
    assert_eq!((r1.x, r1.y), (10.0, 5.0));
    assert_eq!(r1.package.pads.len(), 3);
    let u1 = b.element("U1").expect("U1");
    assert!(!u1.is_bottom());
    assert_eq!(u1.value, None);
    assert_eq!(b.outline.len(), 2);
    assert_eq!(b.outline[1].curve, 90.0);
    assert_eq!(b.nets[0].class.as_deref(), Some("power"));
    let nl = b.netlist();
    assert_eq!(nl["N$1"], pads(&[("R1", "1"), ("R1", "3"), ("U1", "2")]));
    assert_eq!(nl["GND"].len(), 1);
    assert!(matches!(
        read_schematic(brd.as_bytes()),
        Err(EagleError::WrongKind {
            expected: "schematic",
            found: "board"
        })
    ));
}

#[test]
fn netlist_comparison_matches_pad_sets_not_names() {
    let mut a = Netlist::new();
    let mut b = Netlist::new();
    a.insert("N$1".into(), pads(&[("R1", "1"), ("R2", "1")]));
    b.insert("SIG".into(), pads(&[("R1", "1"), ("R2", "1")]));
    a.insert("GND".into(), pads(&[("R1", "2"), ("R2", "2")]));
    b.insert("GND".into(), pads(&[("R1", "2"), ("R2", "2")]));
    a.insert("NC".into(), pads(&[("R3", "1")]));
    b.insert("SUPPLY".into(), BTreeSet::new());
    let c = NetlistComparison::new(&a, &b);
    assert!(c.is_equal());
    assert_eq!((c.equal, c.names_matching), (2, 1));
    assert_eq!((c.skipped_left, c.skipped_right), (1, 1));
    b.insert("EXTRA".into(), pads(&[("R3", "1"), ("R4", "1")]));
    let c = NetlistComparison::new(&a, &b);
    assert!(!c.is_equal());
    assert_eq!(c.only_right.len(), 1);
}

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    let mut s = String::from("<eagle><drawing>");
    s.push_str(&"<a>".repeat(100_000));
    assert!(matches!(
        read(s.as_bytes()),
        Err(EagleError::TooDeep { limit: 256, .. })
    ));
}

#[test]
fn exponential_module_nesting_is_capped() {
    // Each module holds ten instances of the next: 10^8 leaf instances if expanded.
    let mut modules = String::from("<modules>");
    for level in 0..8 {
        let insts: String = (0..10)
            .map(|i| {
                format!(
                    r#"<moduleinst name="I{i}" module="M{}" x="0" y="0"/>"#,
                    level + 1
                )
            })
            .collect();
        modules.push_str(&format!(
            r#"<module name="M{level}"><parts/><sheets><sheet><moduleinsts>{insts}</moduleinsts></sheet></sheets></module>"#
        ));
    }
    modules.push_str(r#"<module name="M8"><parts/><sheets/></module></modules>"#);
    let xml = schematic(&format!(
        r#"{modules}<parts/><sheets><sheet><moduleinsts><moduleinst name="TOP" module="M0" x="0" y="0"/></moduleinsts></sheet></sheets>"#
    ));
    assert!(matches!(
        read_schematic(xml.as_bytes()),
        Err(EagleError::TooManyModuleInstances { .. })
    ));
}
