//! Every project of Debian's `kicad-demos` (KiCad 6.0) read: boards, schematics, and for each
//! project with both, the schematic's nets against the board's.

use std::path::{Path, PathBuf};

use conduit_eagle::NetlistComparison;

const DEMOS: &str = "/usr/share/kicad/demos";

fn files(ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![PathBuf::from(DEMOS)];
    while let Some(d) = dirs.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|e| e == ext) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

fn demos_present() -> bool {
    if Path::new(DEMOS).is_dir() {
        return true;
    }
    println!("skipped: {DEMOS} is missing (apt-get install kicad-demos)");
    false
}

#[test]
fn every_demo_schematic_nets_match_its_board() {
    if !demos_present() {
        return;
    }
    let mut compared = 0;
    for pcb_path in files("kicad_pcb") {
        let bytes = std::fs::read(&pcb_path).expect("test data");
        let pcb = conduit_kicad::read_pcb(&bytes)
            .unwrap_or_else(|e| panic!("{}: {e}", pcb_path.display()));
        let sch_path = pcb_path.with_extension("kicad_sch");
        if !sch_path.exists() {
            println!(
                "{}: {} footprints, no schematic",
                pcb_path.display(),
                pcb.footprints.len()
            );
            continue;
        }
        let sch = conduit_kicad::read_schematic_file(&sch_path)
            .unwrap_or_else(|e| panic!("{}: {e}", sch_path.display()));
        let cmp = NetlistComparison::new(&sch.netlist(), &pcb.netlist());
        println!(
            "{}: {} sheets, {} parts, {} footprints, {} pads; nets connected sch {} pcb {}, equal {}, names equal {}",
            pcb_path.file_stem().expect("test data").to_string_lossy(),
            sch.sheet_instances,
            sch.parts.len(),
            pcb.footprints.len(),
            pcb.footprints.iter().map(|f| f.pads.len()).sum::<usize>(),
            cmp.left_connected,
            cmp.right_connected,
            cmp.equal,
            cmp.names_matching
        );
        for (n, pads) in &cmp.only_left {
            println!("  only sch {n}: {pads:?}");
        }
        for (n, pads) in &cmp.only_right {
            println!("  only pcb {n}: {pads:?}");
        }
        assert!(
            cmp.is_equal(),
            "{}: the schematic's nets differ from the board's",
            pcb_path.display()
        );
        assert_eq!(
            sch.parts.len(),
            pcb.footprints
                .iter()
                .filter(|f| sch.part(&f.reference).is_some())
                .count()
        );
        compared += 1;
    }
    // Every project of kicad-demos 6.0 with both files.
    assert_eq!(compared, 13);
}

#[test]
fn every_demo_schematic_reads() {
    if !demos_present() {
        return;
    }
    for p in files("kicad_sch") {
        let bytes = std::fs::read(&p).expect("test data");
        // Sub-sheets read as roots too (their own sheets, if any, beside them).
        conduit_kicad::read_schematic(&bytes, &p, &mut |q| std::fs::read(q))
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    }
}
