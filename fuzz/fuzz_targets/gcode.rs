//! G-code tokenizer: whatever parses must round-trip byte for byte.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(g) = conduit_gcode::parse(data) {
        assert_eq!(g.to_bytes(), data);
        let _ = conduit_gcode::summarize(&g);
    }
});
