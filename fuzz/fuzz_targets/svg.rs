//! SVG design reader.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = conduit_svg::read(data, 0.01);
});
