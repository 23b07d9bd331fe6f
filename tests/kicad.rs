//! KiCad projects as circuits: the sample board placed with `place --from-pcb` as its EAGLE
//! twin is with `--from-brd`, sliced and checked clean against the KiCad schematic; every
//! kicad-demos project loads as a circuit; a schematic without its board is refused naming its
//! parts.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::support::{conduit, placement_parts, sample, stderr, stdout, temp_dir};

fn demo(f: &str) -> PathBuf {
    sample(&format!("circuit_demo/{f}"))
}

fn place(board_flag: &str, board: &Path, out: &Path) {
    let model = demo("block.stl");
    let o = conduit([
        "place".as_ref(),
        "--model".as_ref(),
        model.as_os_str(),
        board_flag.as_ref(),
        board.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_kicad_board_is_placed_sliced_and_checked_clean() {
    let dir = temp_dir();
    let d = dir.path();
    // The KiCad board is the EAGLE sample's twin (y down, 100 mm off): the same layout.
    let (kicad, eagle) = (d.join("kicad.toml"), d.join("eagle.toml"));
    place("--from-pcb", &demo("led_coin.kicad_pcb"), &kicad);
    place("--from-brd", &demo("led_coin.brd"), &eagle);
    let k = placement_parts(&kicad);
    assert_eq!(k, placement_parts(&eagle));
    assert_eq!(
        k,
        [
            ("BAT1".to_owned(), [20.0, 15.0, 6.0, 0.0]),
            ("R1".to_owned(), [29.0, 21.0, 6.0, 90.0]),
            ("LED1".to_owned(), [29.0, 9.0, 6.0, 270.0]),
        ]
    );
    // Sliced with the board as the circuit, checked against the schematic's nets.
    let gcode = d.join("kicad.gcode");
    let (model, pcb, sch) = (
        demo("block.stl"),
        demo("led_coin.kicad_pcb"),
        demo("led_coin.kicad_sch"),
    );
    let o = conduit([
        "slice".as_ref(),
        model.as_os_str(),
        "--circuit".as_ref(),
        pcb.as_os_str(),
        "--placement".as_ref(),
        kicad.as_os_str(),
        "-o".as_ref(),
        gcode.as_os_str(),
        "-q".as_ref(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = conduit([
        "check".as_ref(),
        gcode.as_os_str(),
        "--circuit".as_ref(),
        sch.as_os_str(),
        "--placement".as_ref(),
        kicad.as_os_str(),
        "--model".as_ref(),
        model.as_os_str(),
        "--json".as_ref(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    let report: Value = serde_json::from_str(&stdout(&o)).expect("json");
    let e = &report["electrical"];
    let nets: Vec<(&str, bool)> = e["nets"]
        .as_array()
        .expect("nets")
        .iter()
        .map(|n| (n["net"].as_str().expect("name"), n["connected"] == true))
        .collect();
    assert_eq!(nets, [("/N1", true), ("GND", true), ("VCC", true)]);
    for key in ["short_count", "outside_count", "floating_beads"] {
        assert_eq!(e[key].as_u64(), Some(0), "{key}: {e}");
    }
}

#[test]
fn the_sample_schematic_and_board_are_one_circuit() {
    let mut sch = conduit::circuit::Circuit::load(&demo("led_coin.kicad_sch")).expect("schematic");
    let pcb = conduit::circuit::Circuit::load(&demo("led_coin.kicad_pcb")).expect("board");
    // The schematic's parts come by reference, the board's in file order.
    let order = |name: &str| pcb.parts.iter().position(|p| p.name == name);
    sch.parts.sort_by_key(|p| order(&p.name));
    assert_eq!(sch, pcb);
    // The EAGLE twin's pads, in the same package frame (R1's corners rounded: a rectangle).
    let eagle = conduit::circuit::Circuit::load(&demo("led_coin.brd")).expect("eagle");
    for (k, e) in pcb.parts.iter().zip(&eagle.parts) {
        assert_eq!(k.pads, e.pads, "{}", k.name);
    }
    // Without its board beside it, the schematic names the parts that lack pads.
    let dir = temp_dir();
    let lone = dir.path().join("lone.kicad_sch");
    std::fs::copy(demo("led_coin.kicad_sch"), &lone).expect("copy");
    let e = conduit::circuit::Circuit::load(&lone).expect_err("no board");
    assert!(
        e.to_string()
            .contains("no pad geometry for 3 part(s) (BAT1, LED1, R1): put the KiCad board"),
        "{e}"
    );
}

/// A netlist export takes its pads from the board of its name beside it.
#[test]
fn a_netlist_export_beside_its_board_is_the_circuit() {
    let dir = temp_dir();
    let d = dir.path();
    std::fs::copy(demo("led_coin.kicad_pcb"), d.join("led_coin.kicad_pcb")).expect("copy");
    std::fs::write(
        d.join("led_coin.net"),
        r#"(export (version "E")
  (design (source "led_coin.kicad_sch") (tool "Eeschema 8.0"))
  (components
    (comp (ref "BAT1") (value "CR2032") (footprint "conduit_demo:CR2032-SMD"))
    (comp (ref "R1") (value "220R") (footprint "conduit_demo:R0805"))
    (comp (ref "LED1") (value "red") (footprint "conduit_demo:LED-0805")))
  (nets
    (net (code "1") (name "/N1") (node (ref "LED1") (pin "A")) (node (ref "R1") (pin "2")))
    (net (code "2") (name "GND") (node (ref "BAT1") (pin "-")) (node (ref "LED1") (pin "C")))
    (net (code "3") (name "VCC") (node (ref "BAT1") (pin "+")) (node (ref "R1") (pin "1")))))
"#,
    )
    .expect("net written");
    let net = conduit::circuit::Circuit::load(&d.join("led_coin.net")).expect("netlist");
    let pcb = conduit::circuit::Circuit::load(&demo("led_coin.kicad_pcb")).expect("board");
    assert_eq!(net, pcb);
}

#[test]
fn every_kicad_demo_loads_as_a_circuit() {
    let demos = Path::new("/usr/share/kicad/demos");
    if !demos.is_dir() {
        println!(
            "skipped: {} is missing (apt-get install kicad-demos)",
            demos.display()
        );
        return;
    }
    let mut dirs = vec![demos.to_path_buf()];
    let mut loaded = 0;
    while let Some(d) = dirs.pop() {
        for entry in std::fs::read_dir(&d).expect("demo folder").flatten() {
            let p = entry.path();
            if p.is_dir() {
                dirs.push(p);
                continue;
            }
            let Some(ext) = p.extension().and_then(|e| e.to_str()) else {
                continue;
            };
            let with_board = ext == "kicad_sch" && p.with_extension("kicad_pcb").exists();
            if p.ends_with("microwave/microwave.kicad_pcb") {
                // Its stubs and filters are drawn as footprints whose pads lie up to 136 mm
                // from their origin: beyond what a printed part's pads may span.
                let e = conduit::circuit::Circuit::load(&p).expect_err("pads too far");
                assert!(
                    e.to_string().ends_with(
                        "part POLY pad 2: x = -135.7503 is not a finite number within ±100"
                    ),
                    "{e}"
                );
                continue;
            }
            if ext == "kicad_pcb" || with_board {
                let c = conduit::circuit::Circuit::load(&p)
                    .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
                assert!(!c.parts.is_empty(), "{}", p.display());
                loaded += 1;
            }
        }
    }
    // 13 boards (the 14th is microwave's) and the 13 schematics that have one.
    assert_eq!(loaded, 26);
}
