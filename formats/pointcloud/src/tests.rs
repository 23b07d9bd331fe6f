//! Tests of the PLY and XYZ readers, including a conformance run over the shared corpus.

use super::*;
use crate::ply::Location;

/// The points of the PLY test files: a unit square with normals, colours and one quad face.
const POINTS: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.5, 0.0, -0.25],
    [1.5, 2.0, 1e-3],
    [0.0, 2.0, 1e6],
];
const COLORS: [[u8; 3]; 4] = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [10, 20, 30]];

/// Header shared by the three encodings: extra properties, a list inside `vertex`, an `edge`
/// element between `vertex` and `face`, and `int`-typed face indices with a `uchar` count.
fn header(format: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\ncomment made by conduit tests\nobj_info nothing\n\
         element vertex 4\nproperty float x\nproperty float32 y\nproperty double z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         property uchar red\nproperty uint8 green\nproperty uchar blue\n\
         property list uchar int16 extra\nproperty double confidence\n\
         element edge 1\nproperty int vertex1\nproperty list ushort uint other\n\
         element face 2\nproperty list uchar int vertex_indices\nproperty uchar flags\n\
         end_header\n"
    )
}

fn ascii_ply() -> Vec<u8> {
    let mut text = header("ascii");
    for (i, (p, c)) in POINTS.iter().zip(COLORS).enumerate() {
        text += &format!(
            "{} {} {} 0 0 1 {} {} {} 2 -7 8 0.{i}\n",
            p[0], p[1], p[2], c[0], c[1], c[2]
        );
    }
    text += "2 3 5 6 7\n";
    text += "4 0 1 2 3 9\n0 1\n";
    text.into_bytes()
}

/// Writes the same content as [`ascii_ply`] in binary, with `put` choosing the byte order.
fn binary_ply(format: &str, big_endian: bool) -> Vec<u8> {
    let mut out = header(format).into_bytes();
    let put = |bytes: &mut Vec<u8>, mut le: Vec<u8>| {
        if big_endian {
            le.reverse();
        }
        bytes.extend(le);
    };
    for (i, (p, c)) in POINTS.iter().zip(COLORS).enumerate() {
        put(&mut out, (p[0] as f32).to_le_bytes().to_vec());
        put(&mut out, (p[1] as f32).to_le_bytes().to_vec());
        put(&mut out, p[2].to_le_bytes().to_vec());
        for n in [0.0f32, 0.0, 1.0] {
            put(&mut out, n.to_le_bytes().to_vec());
        }
        out.extend(c);
        out.push(2);
        put(&mut out, (-7i16).to_le_bytes().to_vec());
        put(&mut out, 8i16.to_le_bytes().to_vec());
        put(&mut out, (i as f64 / 10.0).to_le_bytes().to_vec());
    }
    put(&mut out, 2i32.to_le_bytes().to_vec());
    put(&mut out, 3u16.to_le_bytes().to_vec());
    for v in [5u32, 6, 7] {
        put(&mut out, v.to_le_bytes().to_vec());
    }
    out.push(4);
    for v in [0i32, 1, 2, 3] {
        put(&mut out, v.to_le_bytes().to_vec());
    }
    out.push(9);
    out.push(0);
    out.push(1);
    out
}

fn expected_square() -> PointCloud {
    PointCloud {
        points: POINTS.to_vec(),
        normals: Some(vec![[0.0, 0.0, 1.0]; 4]),
        colors: Some(COLORS.to_vec()),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

#[test]
fn ply_ascii_le_be_agree() -> Result<(), PlyError> {
    let ascii = read_ply(&ascii_ply())?;
    let le = read_ply(&binary_ply("binary_little_endian", false))?;
    let be = read_ply(&binary_ply("binary_big_endian", true))?;
    assert_eq!(ascii, expected_square());
    assert_eq!(le, ascii);
    assert_eq!(be, ascii);
    Ok(())
}

#[test]
fn ply_crlf_header_and_integer_coordinates() -> Result<(), PlyError> {
    let text = "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty char x\r\n\
                property ushort y\r\nproperty int32 z\r\nelement face 1\r\n\
                property list int uint vertex_index\r\nend_header\r\n\
                -1 2 3\r\n4 65535 -6\r\n7 8 9\r\n3 0 1 2\r\n";
    let cloud = read_ply(text.as_bytes())?;
    assert_eq!(
        cloud.points,
        vec![[-1.0, 2.0, 3.0], [4.0, 65535.0, -6.0], [7.0, 8.0, 9.0]]
    );
    assert_eq!(cloud.triangles, vec![[0, 1, 2]]);
    assert_eq!(cloud.normals, None);
    assert_eq!(cloud.colors, None);
    Ok(())
}

#[test]
fn ply_ascii_is_one_record_per_line() -> Result<(), PlyError> {
    // VCGLIB writes more values than declared; some writers put comments in the body.
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                end_header\n0 0 0 9 9 9\ncomment between records\n\n1 0 0\n0 1 0\n\
                3 0 1 2 6 0.5 0.5 0.5 0.5 0.5 0.5\n";
    let cloud = read_ply(text.as_bytes())?;
    assert_eq!(cloud.points[1], [1.0, 0.0, 0.0]);
    assert_eq!(cloud.triangles, vec![[0, 1, 2]]);
    let short = text.replace("1 0 0\n", "1 0\n");
    assert_eq!(
        read_ply(short.as_bytes()),
        Err(PlyError::ShortRecord {
            location: Location::Line(13),
            element: "vertex".into(),
            record: 1,
            property: "z".into()
        })
    );
    Ok(())
}

#[test]
fn ply_float_colors_are_scaled() -> Result<(), PlyError> {
    let text = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                property float z\nproperty float red\nproperty float green\nproperty float blue\n\
                end_header\n0 0 0 1.0 0.5 0\n";
    assert_eq!(read_ply(text.as_bytes())?.colors, Some(vec![[255, 128, 0]]));
    Ok(())
}

#[test]
fn ply_header_errors() {
    assert_eq!(read_ply(b""), Err(PlyError::NotPly));
    assert_eq!(read_ply(b"solid cube\n"), Err(PlyError::NotPly));
    assert_eq!(
        read_ply(b"ply\nformat ascii 1.0\nend_header\n"),
        Err(PlyError::NoVertexElement)
    );
    assert_eq!(
        read_ply(b"ply\nformat ascii 1.0\nelement vertex 0\n"),
        Err(PlyError::MissingEndHeader)
    );
    assert_eq!(
        read_ply(b"ply\nelement vertex 0\nend_header\n"),
        Err(PlyError::MissingFormat)
    );
    assert!(matches!(
        read_ply(b"ply\nformat binary_middle_endian 1.0\n"),
        Err(PlyError::UnsupportedFormat { line: 2, .. })
    ));
    assert!(matches!(
        read_ply(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n"),
        Err(PlyError::UnknownType { line: 4, .. })
    ));
    assert!(matches!(
        read_ply(b"ply\nformat ascii 1.0\nproperty float x\n"),
        Err(PlyError::InvalidHeaderLine { line: 3, .. })
    ));
    assert_eq!(
        read_ply(
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
              end_header\n1 2\n"
        ),
        Err(PlyError::MissingProperty {
            element: "vertex".into(),
            property: "z"
        })
    );
}

#[test]
fn ply_truncated_bodies_name_what_is_missing() {
    let header_only = b"ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\n\
        property float y\nproperty float z\nend_header\n";
    assert_eq!(
        read_ply(header_only),
        Err(PlyError::Truncated {
            element: "vertex".into(),
            record: 0,
            count: 8,
            property: "x".into()
        })
    );
    for format in ["binary_little_endian", "binary_big_endian"] {
        let full = binary_ply(format, format.ends_with("big_endian"));
        for cut in [header(format).len() + 5, full.len() - 3] {
            let cut = cut.min(full.len() - 1);
            assert!(
                matches!(read_ply(&full[..cut]), Err(PlyError::Truncated { .. })),
                "{format} cut at {cut}: {:?}",
                read_ply(&full[..cut])
            );
        }
    }
    let ascii = ascii_ply();
    let cut = &ascii[..ascii.len() - 2];
    assert!(matches!(
        read_ply(cut),
        Err(PlyError::Truncated { ref element, record: 1, .. }) if element == "face"
    ));
}

#[test]
fn ply_hostile_counts_and_indices() {
    // Huge declared counts with almost no data: must fail fast, not allocate.
    let huge = b"ply\nformat binary_little_endian 1.0\nelement vertex 18446744073709551615\n\
        property float x\nproperty float y\nproperty float z\nend_header\n\0\0\0\0";
    assert!(matches!(
        read_ply(huge),
        Err(PlyError::TooManyVertices { .. })
    ));
    let huge_list = b"ply\nformat binary_big_endian 1.0\nelement vertex 0\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\n\
        property list uint uint vertex_indices\nend_header\n\xff\xff\xff\xff\0\0\0\0";
    assert!(matches!(
        read_ply(huge_list),
        Err(PlyError::IndexOutOfRange { .. })
    ));
    let huge_skip = b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n\
        property float y\nproperty float z\nelement junk 1\n\
        property list uint double data\nend_header\n\xff\xff\xff\xff";
    assert!(matches!(
        read_ply(huge_skip),
        Err(PlyError::Truncated { ref element, .. }) if element == "junk"
    ));
    let zero_size = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n\
        property float y\nproperty float z\nelement nothing 18446744073709551615\nend_header\n\
        1 2 3\n";
    assert!(read_ply(zero_size).is_ok());
    let negative_len = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\n\
        property list char int vertex_indices\nend_header\n1 2 3\n-1 0\n";
    assert!(matches!(
        read_ply(negative_len),
        Err(PlyError::InvalidListLength {
            location: Location::Line(11),
            ..
        })
    ));
    let bad_index = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n";
    assert_eq!(
        read_ply(bad_index),
        Err(PlyError::IndexOutOfRange {
            location: Location::Line(13),
            face: 0,
            index: 3.0,
            vertex_count: 3
        })
    );
    let nan = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
        property float z\nend_header\n1 nan 3\n";
    assert!(matches!(
        read_ply(nan),
        Err(PlyError::InvalidValue {
            location: Location::Line(8),
            ..
        })
    ));
    let word = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
        property float z\nend_header\n1 two 3\n";
    assert!(matches!(
        read_ply(word),
        Err(PlyError::InvalidValue { ref token, .. }) if token == "two"
    ));
}

#[test]
fn ply_adversarial_bytes_never_panic() {
    let seeds = [
        ascii_ply(),
        binary_ply("binary_little_endian", false),
        binary_ply("binary_big_endian", true),
    ];
    // Deterministic xorshift so failures reproduce.
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for seed in &seeds {
        for cut in 0..seed.len() {
            let _ = read_ply(&seed[..cut]);
        }
        for _ in 0..2000 {
            let mut bytes = seed.clone();
            for _ in 0..1 + next() % 4 {
                let at = (next() % bytes.len() as u64) as usize;
                bytes[at] = next() as u8;
            }
            let _ = read_ply(&bytes);
        }
    }
}

#[test]
fn xyz_plain_and_separators() -> Result<(), XyzError> {
    let text = "// CloudCompare style comment\n# hash comment\n\n1 2 3\n4,5,6\n7;8;9\n\
                10\t11  12 extra words\n";
    let cloud = read_xyz(text.as_bytes())?;
    assert_eq!(
        cloud.points,
        vec![
            [1.0, 2.0, 3.0],
            [4.0, 5.0, 6.0],
            [7.0, 8.0, 9.0],
            [10.0, 11.0, 12.0]
        ]
    );
    assert_eq!(cloud.normals, None);
    assert_eq!(cloud.colors, None);
    assert!(cloud.triangles.is_empty());
    Ok(())
}

#[test]
fn xyz_extra_columns() -> Result<(), XyzError> {
    let rgb = read_xyz(b"X Y Z R G B\n1 2 3 255 0 10\n4 5 6 0 1 0\n")?;
    assert_eq!(rgb.colors, Some(vec![[255, 0, 10], [0, 1, 0]]));
    assert_eq!(rgb.normals, None);

    let rgb_float_written = read_xyz(b"1 2 3 117.0 73.0 49.0 255.0\n4 5 6 0.0 1.0 0.0 255.0\n")?;
    assert_eq!(
        rgb_float_written.colors,
        Some(vec![[117, 73, 49], [0, 1, 0]])
    );

    let normals = read_xyz(b"1 2 3 0.0 0.0 1.0\n4 5 6 -0.6 0.8 0\n")?;
    assert_eq!(
        normals.normals,
        Some(vec![[0.0, 0.0, 1.0], [-0.6, 0.8, 0.0]])
    );
    assert_eq!(normals.colors, None);

    let both = read_xyz(b"1,2,3,0,0.6,-0.8,12,34,56\n")?;
    assert_eq!(both.normals, Some(vec![[0.0, 0.6, -0.8]]));
    assert_eq!(both.colors, Some(vec![[12, 34, 56]]));

    let neither = read_xyz(b"1 2 3 300 2 1\n4 5 6 0.5 2.5 0\n")?;
    assert_eq!((neither.normals, neither.colors), (None, None));

    // One point without the extra columns: the triple is not per-point, so it is dropped.
    let ragged = read_xyz(b"1 2 3 255 0 0\n4 5 6\n")?;
    assert_eq!(ragged.colors, None);
    assert_eq!(ragged.points.len(), 2);
    Ok(())
}

#[test]
fn xyz_errors_name_the_line() {
    assert_eq!(
        read_xyz(b"1 2 3\n# c\n4 5\n"),
        Err(XyzError::TooFewColumns { line: 3, found: 2 })
    );
    assert_eq!(
        read_xyz(b"1 2 3\n4 x 6\n"),
        Err(XyzError::InvalidNumber {
            line: 2,
            token: "x".into()
        })
    );
    assert!(matches!(
        read_xyz(b"1 2 3\n4 inf 6\n"),
        Err(XyzError::InvalidNumber { line: 2, .. })
    ));
    assert_eq!(read_xyz(b""), Ok(PointCloud::default()));
    assert_eq!(
        read_xyz(b"\xEF\xBB\xBF1 2 3\n")
            .map(|c| c.points)
            .as_deref(),
        Ok(&[[1.0, 2.0, 3.0]][..])
    );
}

#[test]
fn corpus() {
    let root = std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/corpus"
    ));
    let Ok(manifest) = std::fs::read_to_string(root.join("MANIFEST.json")) else {
        println!("skipped: corpus not found");
        return;
    };
    let entries: Vec<serde_json::Value> =
        serde_json::from_str(&manifest).expect("MANIFEST.json is a JSON array");
    let mut counts = std::collections::BTreeMap::<(String, String), usize>::new();
    for entry in &entries {
        let format = entry["format"].as_str().unwrap_or_default();
        let read: fn(&[u8]) -> Result<PointCloud, String> = match format {
            "PLY" => |b| read_ply(b).map_err(|e| e.to_string()),
            "XYZ" => |b| read_xyz(b).map_err(|e| e.to_string()),
            _ => continue,
        };
        let staged = entry["staged"].as_str().expect("staged is a string");
        let bytes = std::fs::read(root.join(staged)).expect("corpus file readable");
        let result = read(&bytes);
        let outcome = entry["outcome"].as_str().unwrap_or_default();
        match outcome {
            "load" => {
                let cloud = result.unwrap_or_else(|e| panic!("{staged}: {e}"));
                assert!(!cloud.points.is_empty(), "{staged}: no points");
                println!(
                    "{staged}: {} points, {} triangles, normals {}, colors {}",
                    cloud.points.len(),
                    cloud.triangles.len(),
                    cloud.normals.is_some(),
                    cloud.colors.is_some()
                );
            }
            "reject" => {
                let error = result.err().unwrap_or_else(|| panic!("{staged}: loaded"));
                println!("{staged}: rejected: {error}");
            }
            _ => {}
        }
        *counts
            .entry((format.to_owned(), outcome.to_owned()))
            .or_default() += 1;
    }
    println!("point cloud corpus: {counts:?}");
    assert!(counts.values().sum::<usize>() > 0);
}
