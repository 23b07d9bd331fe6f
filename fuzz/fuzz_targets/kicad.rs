//! KiCad reader: boards, schematics (sheets refused: no files) and netlist exports, and their
//! netlists.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let mut no_sheets = |_: &std::path::Path| Err(std::io::ErrorKind::NotFound.into());
    match conduit_kicad::read(data, std::path::Path::new("fuzz.kicad_sch"), &mut no_sheets) {
        Ok(conduit_kicad::Document::Pcb(p)) => {
            let _ = p.netlist();
        }
        Ok(conduit_kicad::Document::Schematic(s)) => {
            let _ = s.netlist();
        }
        Ok(conduit_kicad::Document::NetFile(n)) => {
            let _ = n.netlist();
        }
        Err(_) => {}
    }
});
