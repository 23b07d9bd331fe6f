//! 3MF reader: arbitrary zip bytes (and the models inside) never panic or exceed the limits.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(pkg) = conduit_3mf::read(data, &conduit_3mf::Limits::default()) {
        let _ = pkg.flatten();
    }
});
