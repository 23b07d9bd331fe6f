//! Text mesh and point-cloud readers: OBJ, OFF, PLY, XYZ.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = conduit_obj::read(data, None);
    let _ = conduit_obj::looks_like_obj(data);
    let _ = conduit_off::read(data);
    let _ = conduit_pointcloud::read_ply(data);
    let _ = conduit_pointcloud::read_xyz(data);
});
