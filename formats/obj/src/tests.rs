//! Tests of the OBJ reader and writer, including a conformance run over the shared corpus.

use std::path::Path;

use super::*;

fn read_ok(text: &str) -> Obj {
    read(text.as_bytes(), None).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

#[test]
fn quad_becomes_two_triangles() {
    let obj = read_ok("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    assert_eq!(obj.objects.len(), 1);
    let quad = &obj.objects[0];
    assert_eq!(quad.name, "");
    assert_eq!(
        quad.vertices,
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0]
        ]
    );
    assert_eq!(quad.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert!(obj.warnings.is_empty(), "{:?}", obj.warnings);
}

#[test]
fn pentagon_is_fan_triangulated() {
    let obj = read_ok("v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\nf 1 2 3 4 5\n");
    assert_eq!(
        obj.objects[0].triangles,
        vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]
    );
}

#[test]
fn negative_indices_are_relative() {
    let text = "v 9 9 9\nvt 0 0\nvn 0 0 1\n\
                v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3/-1/-1 -2/-1/-1 -1/-1/-1\n\
                v 5 5 5\nf -4 -2 -1\n";
    let obj = read_ok(text);
    let object = &obj.objects[0];
    // The unused vertex `9 9 9` is not part of the object; first use decides the order.
    assert_eq!(
        object.vertices,
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [5.0, 5.0, 5.0]
        ]
    );
    assert_eq!(object.triangles, vec![[0, 1, 2], [0, 2, 3]]);
}

#[test]
fn forward_references_and_index_forms() {
    let obj = read_ok("f 1/1 2//7 3/1/1\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    assert_eq!(obj.objects[0].triangles, vec![[0, 1, 2]]);
}

#[test]
fn objects_and_groups_are_kept_apart_and_empty_ones_dropped() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
                o empty\ng first group#1 # a comment\nf 1 2 3\n\
                g\ng second\nusemtl red\nf 1 2 4\nusemtl blue\nf 2 3 4\ng\nf 1 3 4\no last\n";
    let obj = read_ok(text);
    let names: Vec<&str> = obj.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["first group#1", "second", ""]);
    assert_eq!(obj.objects[0].triangles, vec![[0, 1, 2]]);
    assert_eq!(
        obj.objects[1].vertices,
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0]
        ]
    );
    assert_eq!(obj.objects[1].triangles, vec![[0, 1, 2], [1, 3, 2]]);
}

#[test]
fn comments_continuations_and_crlf() {
    let text = "# header\r\nv 0 0 0 # inline\r\nv 1 0 0\r\n  v 0 1 0\r\n\r\nf 1 \\\r\n 2 \\\n3\r\n";
    let obj = read_ok(text);
    assert_eq!(obj.objects[0].triangles, vec![[0, 1, 2]]);
    assert_eq!(obj.objects[0].vertices[2], [0.0, 1.0, 0.0]);
    let windows_path = "# exported from C:\\models\\\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert_eq!(read_ok(windows_path).objects[0].vertices.len(), 3);
}

#[test]
fn no_faces_is_ok_and_lines_warn() {
    assert_eq!(read_ok("").objects, vec![]);
    let obj = read_ok("v 0 0 0\nv 1 0 0\nl 1 2\np 1\n");
    assert!(obj.objects.is_empty());
    assert_eq!(obj.warnings.len(), 1, "{:?}", obj.warnings);
    assert!(obj.warnings[0].contains("line 3"), "{:?}", obj.warnings);
    let short = read_ok("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1// 2//\nf 1 2 3\n");
    assert_eq!(short.objects[0].triangles, vec![[0, 1, 2]]);
    assert_eq!(short.warnings, ["line 4: face with 2 vertices ignored"]);
}

#[test]
fn missing_material_library_is_a_warning() {
    let text = "mtllib nowhere.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let without_dir = read_ok(text);
    assert_eq!(without_dir.objects[0].triangles, vec![[0, 1, 2]]);
    assert_eq!(without_dir.warnings.len(), 1);
    assert!(without_dir.warnings[0].contains("not loaded"));

    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let with_dir = read(text.as_bytes(), Some(dir)).expect("geometry loads");
    assert_eq!(with_dir.objects, without_dir.objects);
    assert_eq!(with_dir.warnings.len(), 1, "{:?}", with_dir.warnings);
    assert!(
        with_dir.warnings[0].contains("nowhere.mtl"),
        "{:?}",
        with_dir.warnings
    );
}

#[test]
fn present_material_library_loads_without_warning() {
    let dir = std::env::temp_dir().join(format!("conduit-obj-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(dir.join("red paint.mtl"), "newmtl red\nKd 1 0 0\n").expect("write mtl");
    std::fs::write(dir.join("b.mtl"), "newmtl blue\nKd 0 0 1\n").expect("write mtl");
    let one = "mtllib red paint.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let obj = read(one.as_bytes(), Some(&dir)).expect("loads");
    assert!(obj.warnings.is_empty(), "{:?}", obj.warnings);
    // tobj panics on a colour with fewer than three numbers: the reader must not.
    std::fs::write(
        dir.join("short.mtl"),
        "newmtl a\nKd 0.5\nKs 1 0\nKa\nNs x\n",
    )
    .expect("write");
    let short = "mtllib short.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let obj = read(short.as_bytes(), Some(&dir)).expect("loads");
    assert_eq!(obj.objects[0].triangles, vec![[0, 1, 2]]);
    assert_eq!(obj.warnings.len(), 1, "{:?}", obj.warnings);
    std::fs::write(dir.join("grey.mtl"), "newmtl a\nKd 0.5\nKs 1 0\nKa\n").expect("write");
    let grey = "mtllib grey.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let obj = read(grey.as_bytes(), Some(&dir)).expect("loads");
    assert!(obj.warnings.is_empty(), "{:?}", obj.warnings);
    let two = "mtllib b.mtl missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let obj = read(two.as_bytes(), Some(&dir)).expect("loads");
    assert_eq!(obj.warnings.len(), 1, "{:?}", obj.warnings);
    assert!(obj.warnings[0].contains("missing.mtl"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn errors_name_the_line() {
    let base = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let cases: [(&str, ObjError); 7] = [
        (
            "f 1 2 4\n",
            ObjError::IndexOutOfRange {
                line: 4,
                index: 4,
                available: 3,
            },
        ),
        (
            "f -1 -2 -4\n",
            ObjError::IndexOutOfRange {
                line: 4,
                index: -4,
                available: 3,
            },
        ),
        (
            "f 0 1 2\n",
            ObjError::InvalidIndex {
                line: 4,
                token: "0".into(),
            },
        ),
        (
            "f 1 2 x/1\n",
            ObjError::InvalidIndex {
                line: 4,
                token: "x/1".into(),
            },
        ),
        ("v 1 2\n", ObjError::TooFewCoordinates { line: 4, found: 2 }),
        (
            "\n\nv 1 two 3\n",
            ObjError::InvalidNumber {
                line: 6,
                token: "two".into(),
            },
        ),
        (
            "v 1 nan 3\n",
            ObjError::InvalidNumber {
                line: 4,
                token: "nan".into(),
            },
        ),
    ];
    for (tail, expected) in cases {
        let text = format!("{base}{tail}");
        assert_eq!(read(text.as_bytes(), None), Err(expected), "{text}");
    }
    // A forward reference that never gets its vertex is reported on the face's line.
    assert_eq!(
        read(b"f 1 2 3\nv 0 0 0\nv 0 0 0\n", None),
        Err(ObjError::IndexOutOfRange {
            line: 1,
            index: 3,
            available: 2
        })
    );
}

#[test]
fn hostile_indices_do_not_panic() {
    let base = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for face in [
        "f 1 2 -9223372036854775808",
        "f 1 2 9223372036854775807",
        "f 1 2 99999999999999999999999",
        "f 1 2 -0",
        "f /1/1 2 3",
        "f",
        "f 1 2 3/99999999999999999/-9223372036854775808",
    ] {
        let text = format!("{base}{face}\n");
        let _ = read(text.as_bytes(), None);
    }
    let text = format!("{base}f 1 2 3/99999999999999999/-9223372036854775808\n");
    assert!(read(text.as_bytes(), None).is_ok());
}

#[test]
fn adversarial_bytes_never_panic() {
    let seed = b"mtllib a.mtl\no cube\nv 0 0 0\nv 1 0 0\nv 1 1 0 1\nv 0 1 0 0.5 0.5 0.5\nvt 0 0\n\
        vn 0 0 1\ng side\nusemtl x\ns 1\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -1 -2 -3\nl 1 2\n";
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for cut in 0..seed.len() {
        let _ = read(&seed[..cut], None);
        let _ = looks_like_obj(&seed[..cut]);
    }
    let alphabet = b"vfog -/0123456789.e\n\\#";
    for _ in 0..5000 {
        let mut bytes = seed.to_vec();
        for _ in 0..1 + next() % 6 {
            let at = (next() % bytes.len() as u64) as usize;
            bytes[at] = alphabet[(next() % alphabet.len() as u64) as usize];
        }
        let _ = read(&bytes, None);
    }
}

#[test]
fn write_read_round_trip_is_bit_exact() -> Result<(), Box<dyn std::error::Error>> {
    let tricky = [
        0.1,
        -0.0,
        1.0 / 3.0,
        1e-300,
        f64::MIN_POSITIVE / 4.0, // subnormal
        f64::MAX,
        -123_456.789_012_345_67,
        2.5e15,
        1e16,
        std::f64::consts::PI,
        -1e-7,
        0.30000000000000004,
    ];
    let make = |name: &str, offset: usize| ObjObject {
        name: name.to_owned(),
        vertices: (0..4)
            .map(|i| {
                [
                    tricky[(offset + i) % tricky.len()],
                    tricky[(offset + i + 5) % tricky.len()],
                    tricky[(offset + i + 9) % tricky.len()],
                ]
            })
            .collect(),
        triangles: vec![[0, 1, 2], [0, 2, 3], [3, 2, 1]],
    };
    let objects = vec![make("first part", 0), make("second", 4), make("third", 7)];
    let mut out = Vec::new();
    write(&mut out, &objects)?;
    let text = String::from_utf8(out.clone())?;
    assert!(text.contains("o second\n"), "{text}");
    assert!(text.contains("\nf 5 6 7\n"), "global indices: {text}");
    let back = read(&out, None)?;
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    assert_eq!(back.objects.len(), objects.len());
    for (a, b) in objects.iter().zip(&back.objects) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.triangles, b.triangles);
        let bits = |o: &ObjObject| -> Vec<u64> {
            o.vertices.iter().flatten().map(|c| c.to_bits()).collect()
        };
        assert_eq!(bits(a), bits(b), "{}", a.name);
    }
    Ok(())
}

#[test]
fn write_rejects_what_it_cannot_represent() {
    let mut sink = Vec::new();
    let nan = ObjObject {
        name: "bad".into(),
        vertices: vec![[f64::NAN, 0.0, 0.0]],
        triangles: vec![],
    };
    let error = write(&mut sink, &[nan]).expect_err("NaN");
    assert_eq!(error.kind(), std::io::ErrorKind::InvalidInput);
    let past_end = ObjObject {
        name: "bad".into(),
        vertices: vec![[0.0; 3]; 3],
        triangles: vec![[0, 1, 3]],
    };
    let error = write(&mut sink, &[past_end]).expect_err("index 3 of 3");
    assert_eq!(error.kind(), std::io::ErrorKind::InvalidInput);
    let mut out = Vec::new();
    let multiline = ObjObject {
        name: "two\nlines #1".into(),
        vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2]],
    };
    write(&mut out, &[multiline]).expect("writes");
    let back = read(&out, None).expect("reads");
    assert_eq!(back.objects[0].name, "two lines _1");
    let names = ["", "  ", "ends with \\", "#first", "a#b"];
    let objects: Vec<ObjObject> = names
        .iter()
        .map(|name| ObjObject {
            name: (*name).to_owned(),
            vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2]],
        })
        .collect();
    let mut out = Vec::new();
    write(&mut out, &objects).expect("writes");
    let back = read(&out, None).expect("reads");
    let back_names: Vec<&str> = back.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(back_names, ["", "", "ends with _", "_first", "a#b"]);
}

#[test]
fn sniffing() {
    assert!(looks_like_obj(
        b"# Blender\nmtllib x.mtl\no Cube\nv 1 1 1\n"
    ));
    assert!(looks_like_obj(b"v 0 0 0\r\nv 1 0 0\r\n"));
    assert!(looks_like_obj(b"\n\ng group\nf 1 2 3\n"));
    assert!(!looks_like_obj(b""));
    let bom = b"\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert!(looks_like_obj(bom));
    let obj = read(bom, None).expect("reads");
    assert_eq!(obj.objects[0].vertices.len(), 3);
    assert!(obj.warnings.is_empty(), "{:?}", obj.warnings);
    assert!(!looks_like_obj(b"# only a comment\n"));
    assert!(!looks_like_obj(b"solid cube\n  facet normal 0 0 1\n"));
    assert!(!looks_like_obj(b"ply\nformat ascii 1.0\n"));
    assert!(!looks_like_obj(b"OFF\n8 6 0\n"));
    assert!(!looks_like_obj(b"PK\x03\x04\x14\0\0\0"));
    assert!(!looks_like_obj(b"; generated by PrusaSlicer\nG1 X1 Y2\n"));
    assert!(!looks_like_obj(b"v 0 0 0\nvertex 1 2 3\n"));
    assert!(!looks_like_obj(b"v 0 0 0\0\0\0"));
    assert!(!looks_like_obj(b"newmtl red\nKd 1 0 0\nmap_Kd red.png\n"));
    assert!(looks_like_obj(
        b"newmtl red\nKd 1 0 0\nusemtl red\nv 0 0 0\n"
    ));
}

#[test]
fn corpus() {
    let root = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/corpus"
    ));
    let Ok(manifest) = std::fs::read_to_string(root.join("MANIFEST.json")) else {
        println!("skipped: corpus not found");
        return;
    };
    let entries: Vec<serde_json::Value> =
        serde_json::from_str(&manifest).expect("MANIFEST.json is a JSON array");
    let mut counts = std::collections::BTreeMap::<&str, usize>::new();
    let mut sniffed_other = 0;
    for entry in &entries {
        let staged = entry["staged"].as_str().expect("staged is a string");
        let format = entry["format"].as_str().unwrap_or_default();
        let outcome = entry["outcome"].as_str().unwrap_or_default();
        let path = root.join(staged);
        let is_obj = format == "OBJ" || staged.ends_with("_noext_obj");
        if !is_obj {
            let sniff_negative = ["STL", "PLY", "OFF", "3MF", "G-code", "GCODE"].contains(&format)
                || format.starts_with("G-code");
            if sniff_negative {
                let bytes = std::fs::read(&path).expect("corpus file readable");
                assert!(!looks_like_obj(&bytes), "{staged} sniffed as OBJ");
                sniffed_other += 1;
            }
            continue;
        }
        let bytes = std::fs::read(&path).expect("corpus file readable");
        let result = read(&bytes, path.parent());
        match outcome {
            "load" => {
                let obj = result.unwrap_or_else(|e| panic!("{staged}: {e}"));
                assert!(looks_like_obj(&bytes), "{staged} not sniffed as OBJ");
                let triangles: usize = obj.objects.iter().map(|o| o.triangles.len()).sum();
                println!(
                    "{staged}: {} objects, {triangles} triangles, warnings {:?}",
                    obj.objects.len(),
                    obj.warnings
                );
            }
            "reject" => {
                let error = result.err().unwrap_or_else(|| panic!("{staged}: loaded"));
                println!("{staged}: rejected: {error}");
            }
            _ => println!("{staged}: {outcome}: ok = {}", result.is_ok()),
        }
        *counts.entry(outcome).or_default() += 1;
    }
    println!("OBJ corpus: {counts:?}; {sniffed_other} non-OBJ files not sniffed as OBJ");
    assert!(counts.get("load").copied().unwrap_or(0) > 0);
}
