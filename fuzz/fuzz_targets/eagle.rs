//! EAGLE reader: schematics and boards, and their netlists.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    match conduit_eagle::read(data) {
        Ok(conduit_eagle::Document::Schematic(s)) => {
            let _ = s.netlist();
        }
        Ok(conduit_eagle::Document::Board(b)) => {
            let _ = b.netlist();
        }
        _ => {}
    }
});
