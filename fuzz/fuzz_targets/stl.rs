//! STL reader: any bytes give a result or an error, never a panic; what reads must round-trip.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(stl) = conduit_stl::read(data) {
        let mut out = Vec::new();
        if conduit_stl::write_binary(&mut out, "fuzz", &stl.triangles).is_ok() {
            let back = conduit_stl::read(&out).map(|s| s.triangles.len()).unwrap_or(usize::MAX);
            assert_eq!(back, stl.triangles.len());
        }
    }
});
