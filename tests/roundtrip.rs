//! Golden round trips: STL→3MF→STL bit-exact, OBJ→STL, 3MF write→read equal scene, and 3MF output
//! checked by an independent reader (lib3mf) when it is installed.

use crate::support::{conduit, corpus, sample, stderr, stl_triangles, temp_dir};
use conduit::geom::{Point3, Transform};
use conduit::mesh::Mesh;
use conduit::scene::{LoadOptions, MeshFormat, Scene, SceneObject, load_scene, save};
use std::path::Path;

fn bits(tris: &[[[f32; 3]; 3]]) -> Vec<[[u32; 3]; 3]> {
    tris.iter()
        .map(|t| t.map(|v| v.map(f32::to_bits)))
        .collect()
}

fn stl_to_3mf_to_stl_is_bit_exact(input: &Path) {
    let dir = temp_dir();
    let mid = dir.path().join("mid.3mf");
    let back = dir.path().join("back.stl");
    let a = conduit([
        "convert".as_ref(),
        input.as_os_str(),
        "-o".as_ref(),
        mid.as_os_str(),
    ]);
    assert!(a.status.success(), "{}: {}", input.display(), stderr(&a));
    let b = conduit([
        "convert".as_ref(),
        mid.as_os_str(),
        "-o".as_ref(),
        back.as_os_str(),
    ]);
    assert!(b.status.success(), "{}: {}", input.display(), stderr(&b));
    let original = stl_triangles(input);
    let returned = stl_triangles(&back);
    assert_eq!(
        original.len(),
        returned.len(),
        "{}: triangle count",
        input.display()
    );
    assert!(
        bits(&original) == bits(&returned),
        "{}: coordinates changed",
        input.display()
    );
    let vol = |p: &Path| {
        load_scene(p, &LoadOptions::default())
            .expect("loads")
            .0
            .objects[0]
            .mesh
            .signed_volume()
    };
    assert_eq!(vol(input), vol(&back), "{}: volume", input.display());
}

#[test]
fn sample_cube_round_trips_through_3mf_bit_exactly() {
    stl_to_3mf_to_stl_is_bit_exact(&sample("cube_20mm.stl"));
}

#[test]
fn bench_models_round_trip_through_3mf_bit_exactly() {
    let Some(dir) = corpus() else { return };
    for name in [
        "20mm_cube.stl",
        "3DBenchy.stl",
        "voron2_a_drive_frame_lower.stl",
        "voron2_exhaust_filter_housing.stl",
    ] {
        stl_to_3mf_to_stl_is_bit_exact(&dir.join("bench-models").join(name));
    }
}

#[test]
fn obj_to_stl_keeps_triangles_and_volume() {
    let dir = temp_dir();
    let out = dir.path().join("bracket.stl");
    let input = sample("l_bracket.obj");
    let r = conduit([
        "convert".as_ref(),
        input.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
    let (obj, _) = load_scene(&input, &LoadOptions::default()).expect("obj loads");
    let tris = stl_triangles(&out);
    // 6 quads → 12 triangles, 2 caps of 4 triangles.
    assert_eq!(obj.triangle_count(), 20);
    assert_eq!(tris.len(), 20);
    let (stl, _) = load_scene(&out, &LoadOptions::default()).expect("stl loads");
    // 40·5·20 + 5·25·20 mm³, exact in binary floating point for these integer coordinates.
    assert_eq!(obj.objects[0].mesh.signed_volume(), 6500.0);
    assert_eq!(stl.objects[0].mesh.signed_volume(), 6500.0);
}

fn two_object_scene() -> Scene {
    let cube = |name: &str, s: f64, dx: f64| SceneObject {
        name: name.into(),
        mesh: Mesh::cuboid(name, Point3::new(dx, 0.0, 0.0), Point3::new(dx + s, s, s)),
        transform: Transform::identity(),
        tool: None,
        negative: None,
    };
    Scene {
        objects: vec![cube("small", 0.1, 0.0), cube("large", 12.5, 30.0)],
    }
}

#[test]
fn threemf_write_then_read_gives_the_same_scene() {
    let dir = temp_dir();
    let path = dir.path().join("scene.3mf");
    let scene = two_object_scene();
    save(&scene, &path, MeshFormat::ThreeMf).expect("3MF written");
    let (back, warnings) = load_scene(&path, &LoadOptions::default()).expect("3MF read");
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(back, scene);
    // Same input, same bytes.
    let again = dir.path().join("again.3mf");
    save(&back, &again, MeshFormat::ThreeMf).expect("3MF written");
    assert_eq!(
        std::fs::read(&path).expect("read"),
        std::fs::read(&again).expect("read")
    );
}

#[test]
fn threemf_build_transforms_are_applied_on_read() {
    let dir = temp_dir();
    let path = dir.path().join("moved.3mf");
    let mut scene = two_object_scene();
    scene.objects.truncate(1);
    // Rotate 90° about z, then move by (5, 6, 7).
    scene.objects[0].transform =
        Transform::from_3mf(&[0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 5.0, 6.0, 7.0]);
    save(&scene, &path, MeshFormat::ThreeMf).expect("written");
    let (back, _) = load_scene(&path, &LoadOptions::default()).expect("read");
    let bb = back.objects[0].mesh.bounding_box().expect("not empty");
    let expect_min = [5.0 - 0.1, 6.0, 7.0];
    let expect_max = [5.0, 6.1, 7.1];
    for k in 0..3 {
        assert!((bb.min[k] - expect_min[k]).abs() < 1e-12, "min {k}: {bb:?}");
        assert!((bb.max[k] - expect_max[k]).abs() < 1e-12, "max {k}: {bb:?}");
    }
    assert!((back.objects[0].mesh.signed_volume() - 0.001).abs() < 1e-15);
}

#[test]
fn corpus_3mf_files_survive_write_and_read() {
    let Some(dir) = corpus() else { return };
    let files = [
        "3mf-samples/examples/core/cube_gears.3mf",
        "3mf-samples/examples/core/torus.3mf",
        "lib3mf/Tests/TestFiles/Reader/Globo.3mf",
    ];
    let out = temp_dir();
    for f in files {
        let (scene, _) =
            load_scene(&dir.join(f), &LoadOptions::default()).expect("corpus 3MF loads");
        let path = out.path().join("x.3mf");
        save(&scene, &path, MeshFormat::ThreeMf).expect("written");
        let (back, _) = load_scene(&path, &LoadOptions::default()).expect("read back");
        assert_eq!(back.objects.len(), scene.objects.len(), "{f}");
        for (a, b) in back.objects.iter().zip(&scene.objects) {
            assert_eq!(a.mesh.triangles, b.mesh.triangles, "{f}: {}", a.name);
            assert_eq!(a.mesh.vertices, b.mesh.vertices, "{f}: {}", a.name);
        }
    }
}

/// Every 3MF conduit writes from corpus meshes loads in lib3mf without warnings. Runs only where
/// the Python package `lib3mf` is installed (`.ci/run` installs it).
#[test]
fn written_3mf_loads_in_lib3mf_without_warnings() {
    let Some(dir) = corpus() else { return };
    let has_lib3mf = std::process::Command::new("python3")
        .args(["-c", "import lib3mf"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_lib3mf {
        println!("skipped: python3 module lib3mf not installed");
        return;
    }
    let out = temp_dir();
    let inputs = [
        "bench-models/20mm_cube.stl",
        "bench-models/voron2_a_drive_frame_lower.stl",
        "3mf-samples/examples/core/cube_gears.3mf",
        "trimesh/models/fuze.obj",
        "Online3DViewer/test/testfiles/off/cube.off",
    ];
    let mut written = Vec::new();
    for (i, f) in inputs.iter().enumerate() {
        let target = out.path().join(format!("out{i}.3mf"));
        let r = conduit([
            "convert".as_ref(),
            dir.join(f).as_os_str(),
            "-o".as_ref(),
            target.as_os_str(),
        ]);
        assert!(r.status.success(), "{f}: {}", stderr(&r));
        written.push(target);
    }
    let check = crate::support::root().join("bench/lib3mf_check.py");
    let r = std::process::Command::new("python3")
        .arg(check)
        .args(&written)
        .output()
        .expect("python runs");
    assert!(
        r.status.success(),
        "lib3mf rejected or warned:\n{}{}",
        String::from_utf8_lossy(&r.stdout),
        String::from_utf8_lossy(&r.stderr)
    );
}
