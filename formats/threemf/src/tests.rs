//! Unit tests over crafted packages: round trips, units, transforms, limits, rejections.

use std::io::{Cursor, Write};

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

use crate::*;

mod harmless;

const CT: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types"><Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/><Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/><Default Extension="png" ContentType="image/png"/></Types>"#;
const RELS: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>"#;

/// Builds a package from (zip entry name, bytes) pairs.
fn zip_of(entries: &[(&str, &[u8])]) -> Vec<u8> {
    let mut buf = Cursor::new(Vec::new());
    {
        let mut z = ZipWriter::new(&mut buf);
        let opts = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
        for (name, data) in entries {
            z.start_file(*name, opts).expect("start");
            z.write_all(data).expect("write");
        }
        z.finish().expect("finish");
    }
    buf.into_inner()
}

/// A package whose root model is `model`.
fn pkg(model: &str) -> Vec<u8> {
    zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", RELS.as_bytes()),
        ("3D/3dmodel.model", model.as_bytes()),
    ])
}

/// A core model with `resources` and `build` inserted.
fn model_xml(extra_ns: &str, resources: &str, build: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<model unit="millimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02" xmlns:m="http://schemas.microsoft.com/3dmanufacturing/material/2015/02" xmlns:p="http://schemas.microsoft.com/3dmanufacturing/production/2015/06" {extra_ns}>
<resources>{resources}</resources>
<build>{build}</build>
</model>"#
    )
}

const TET: &str = r#"<mesh><vertices><vertex x="0" y="0" z="0"/><vertex x="1" y="0" z="0"/><vertex x="0" y="1" z="0"/><vertex x="0" y="0" z="1"/></vertices>
<triangles><triangle v1="0" v2="2" v3="1"/><triangle v1="0" v2="1" v3="3"/><triangle v1="1" v2="2" v3="3"/><triangle v1="0" v2="3" v3="2"/></triangles></mesh>"#;

fn read_default(bytes: &[u8]) -> Result<Package, ThreeMfError> {
    read(bytes, &Limits::default())
}

fn err_of(bytes: &[u8]) -> String {
    match read_default(bytes) {
        Ok(_) => "Ok".into(),
        Err(e) => e.to_string(),
    }
}

/// The error message of reading `bytes` in strict mode (`"Ok"` when it reads).
fn err_strict(bytes: &[u8]) -> String {
    match read_with(bytes, &Limits::default(), ReadOptions { strict: true }) {
        Ok(_) => "Ok".into(),
        Err(e) => e.to_string(),
    }
}

fn cube(size: f64) -> Mesh {
    let s = size;
    let vertices = vec![
        [0.0, 0.0, 0.0],
        [s, 0.0, 0.0],
        [s, s, 0.0],
        [0.0, s, 0.0],
        [0.0, 0.0, s],
        [s, 0.0, s],
        [s, s, s],
        [0.0, s, s],
    ];
    let tris = [
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    Mesh {
        vertices,
        triangles: tris
            .iter()
            .map(|&v| Triangle {
                v,
                ..Triangle::default()
            })
            .collect(),
    }
}

fn rich_model() -> Model {
    let mut mesh = cube(10.0);
    mesh.triangles[0].pid = Some(3);
    mesh.triangles[0].p = [Some(0), Some(1), Some(2)];
    mesh.vertices[6] = [10.000000000000002, 0.1, 1.0 / 3.0]; // not f32-exact
    Model {
        unit: Unit::Millimeter,
        language: Some("en-US".into()),
        metadata: vec![
            Metadata {
                name: "Title".into(),
                value: "Rich <model> & \"friends\"".into(),
            },
            Metadata {
                name: "Designer".into(),
                value: "conduit".into(),
            },
        ],
        required_extensions: vec![],
        objects: vec![
            Object {
                id: 5,
                name: Some("cube".into()),
                kind: ObjectType::Model,
                pid: Some(1),
                pindex: Some(1),
                content: ObjectContent::Mesh(mesh),
            },
            Object {
                id: 10,
                name: Some("assembly".into()),
                kind: ObjectType::Model,
                pid: None,
                pindex: None,
                content: ObjectContent::Components(vec![
                    Component {
                        object_id: 5,
                        path: None,
                        transform: None,
                    },
                    Component {
                        object_id: 5,
                        path: None,
                        transform: Some([
                            0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 20.5, -3.25, 0.1,
                        ]),
                    },
                ]),
            },
            Object {
                id: 6,
                name: None,
                kind: ObjectType::Support,
                pid: None,
                pindex: None,
                content: ObjectContent::Mesh(cube(1.0)),
            },
        ],
        base_materials: vec![BaseMaterials {
            id: 1,
            materials: vec![
                BaseMaterial {
                    name: "PLA".into(),
                    display_color: [255, 0, 0, 255],
                },
                BaseMaterial {
                    name: "Silver ink".into(),
                    display_color: [192, 192, 192, 128],
                },
            ],
        }],
        color_groups: vec![ColorGroup {
            id: 3,
            colors: vec![[1, 2, 3, 4], [255, 255, 255, 255], [0, 0, 0, 255]],
        }],
        build: vec![
            BuildItem {
                object_id: 10,
                path: None,
                transform: Some([
                    1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 100.0, 50.0, 0.0,
                ]),
                part_number: Some("PN-1".into()),
            },
            BuildItem {
                object_id: 6,
                path: None,
                transform: None,
                part_number: None,
            },
        ],
    }
}

#[test]
fn write_read_round_trip_is_exact() -> Result<(), ThreeMfError> {
    let model = rich_model();
    let mut out = Cursor::new(Vec::new());
    write(&mut out, &model)?;
    let pkg = read_default(out.get_ref())?;
    assert_eq!(pkg.root_path, "/3D/3dmodel.model");
    assert_eq!(pkg.root(), &model);
    assert!(pkg.warnings.is_empty(), "{:?}", pkg.warnings);
    // Objects are written so components come after the objects they use.
    let mut swapped = model.clone();
    swapped.objects.swap(0, 1);
    let mut out2 = Cursor::new(Vec::new());
    write(&mut out2, &swapped)?;
    assert_eq!(out2.get_ref(), out.get_ref());
    // Only the materials extension can be required by the writer's output.
    let mut req = model.clone();
    req.required_extensions = vec![
        "http://schemas.microsoft.com/3dmanufacturing/material/2015/02".into(),
        "http://schemas.microsoft.com/3dmanufacturing/production/2015/06".into(),
    ];
    let mut out3 = Cursor::new(Vec::new());
    write(&mut out3, &req)?;
    assert_eq!(
        read_default(out3.get_ref())?.root().required_extensions,
        vec!["http://schemas.microsoft.com/3dmanufacturing/material/2015/02".to_string()]
    );
    // Deterministic bytes.
    let mut again = Cursor::new(Vec::new());
    write(&mut again, &model)?;
    assert_eq!(out.get_ref(), again.get_ref());
    Ok(())
}

#[test]
fn writer_refuses_invalid_models_and_leaves_sink_untouched() {
    let mut m = rich_model();
    for o in &mut m.objects {
        if let ObjectContent::Mesh(mesh) = &mut o.content {
            mesh.triangles[1].v = [0, 1, 99];
        }
    }
    let mut out = Cursor::new(Vec::new());
    let e = write(&mut out, &m);
    assert!(matches!(e, Err(ThreeMfError::Unwritable { .. })), "{e:?}");
    assert!(out.get_ref().is_empty());

    let mut m = rich_model();
    m.build[0].object_id = 42;
    assert!(write(Cursor::new(Vec::new()), &m).is_err());

    let mut m = rich_model();
    m.objects[0].content = ObjectContent::Components(vec![Component {
        object_id: 10,
        path: None,
        transform: None,
    }]);
    assert!(
        write(Cursor::new(Vec::new()), &m).is_err(),
        "cycle must be refused"
    );
}

#[test]
fn inch_cube_flattens_to_25_4_mm() -> Result<(), ThreeMfError> {
    let model = Model {
        unit: Unit::Inch,
        objects: vec![Object {
            id: 1,
            name: Some("inch cube".into()),
            kind: ObjectType::Model,
            pid: None,
            pindex: None,
            content: ObjectContent::Mesh(cube(1.0)),
        }],
        build: vec![BuildItem {
            object_id: 1,
            path: None,
            transform: None,
            part_number: None,
        }],
        ..Model::default()
    };
    let mut out = Cursor::new(Vec::new());
    write(&mut out, &model)?;
    let flat = read_default(out.get_ref())?.flatten()?;
    assert_eq!(flat.len(), 1);
    let v = &flat[0].vertices;
    for axis in 0..3 {
        let min = v.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
        let max = v.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max);
        assert!((max - min - 25.4).abs() < 1e-12, "edge {}", max - min);
    }
    assert_eq!(flat[0].name, "inch cube");
    for (u, mm) in [
        (Unit::Micron, 0.001),
        (Unit::Millimeter, 1.0),
        (Unit::Centimeter, 10.0),
        (Unit::Inch, 25.4),
        (Unit::Foot, 304.8),
        (Unit::Meter, 1000.0),
    ] {
        assert_eq!(u.to_mm(), mm);
        assert_eq!(Unit::from_attr(u.as_str()), Some(u));
    }
    Ok(())
}

#[test]
fn nested_components_compose_child_first() -> Result<(), ThreeMfError> {
    // Object 1: a single tetrahedron. Object 2 places it rotated 90 degrees about z then moved
    // by (10, 0, 0). Object 3 places object 2 scaled by 2 then moved by (0, 0, 5). The build
    // item moves everything by (100, 0, 0) in centimetres.
    // Point (1, 0, 0) of object 1:
    //   rotation (x, y) -> (-y, x): (0, 1, 0); + (10, 0, 0) -> (10, 1, 0)
    //   * 2 -> (20, 2, 0); + (0, 0, 5) -> (20, 2, 5)
    //   + (100, 0, 0) -> (120, 2, 5) cm = (1200, 20, 50) mm.
    let xml = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<model unit="centimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">
<resources>
<object id="1">{TET}</object>
<object id="2"><components><component objectid="1" transform="0 1 0 -1 0 0 0 0 1 10 0 0"/></components></object>
<object id="3"><components><component objectid="2" transform="2 0 0 0 2 0 0 0 2 0 0 5"/></components></object>
</resources>
<build><item objectid="3" transform="1 0 0 0 1 0 0 0 1 100 0 0"/></build>
</model>"#
    );
    let flat = read_default(&pkg(&xml))?.flatten()?;
    assert_eq!(flat.len(), 1);
    let p = flat[0].vertices[1];
    let want = [1200.0, 20.0, 50.0];
    for k in 0..3 {
        assert!((p[k] - want[k]).abs() < 1e-9, "{p:?} vs {want:?}");
    }
    assert!(!flat[0].mirrored);
    // compose() agrees with applying one transform after the other.
    let a = [0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 10.0, 0.0, 0.0];
    let b = [2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 5.0];
    let q = [0.3, -1.7, 2.5];
    let one = apply_transform(&compose_transforms(&a, &b), q);
    let two = apply_transform(&b, apply_transform(&a, q));
    for k in 0..3 {
        assert!((one[k] - two[k]).abs() < 1e-12);
    }
    Ok(())
}

#[test]
fn mirrored_item_flips_winding() -> Result<(), ThreeMfError> {
    let xml = model_xml(
        "",
        &format!(r#"<object id="1">{TET}</object>"#),
        r#"<item objectid="1" transform="-1 0 0 0 1 0 0 0 1 0 0 0"/>"#,
    );
    let flat = read_default(&pkg(&xml))?.flatten()?;
    assert!(flat[0].mirrored);
    assert_eq!(flat[0].triangles[0], [0, 1, 2]);
    Ok(())
}

#[test]
fn triangle_properties_resolve_from_triangle_or_object() -> Result<(), ThreeMfError> {
    let xml = model_xml(
        "",
        &format!(
            r##"<basematerials id="1"><base name="a" displaycolor="#FF0000"/><base name="b" displaycolor="#00FF00"/></basematerials>
<m:colorgroup id="2"><m:color color="#112233"/></m:colorgroup>
<object id="3" pid="1" pindex="1">{}</object>"##,
            TET.replacen(
                r#"<triangle v1="0" v2="2" v3="1"/>"#,
                r#"<triangle v1="0" v2="2" v3="1" pid="2" p1="0"/>"#,
                1
            )
        ),
        r#"<item objectid="3"/>"#,
    );
    let p = read_default(&pkg(&xml))?;
    let flat = p.flatten()?;
    assert_eq!(flat[0].triangle_properties[0], Some((2, 0)));
    assert_eq!(flat[0].triangle_properties[1], Some((1, 1)));
    assert_eq!(
        p.root().base_materials[0].materials[1].display_color,
        [0, 255, 0, 255]
    );
    assert_eq!(p.root().color_groups[0].colors[0], [0x11, 0x22, 0x33, 255]);
    Ok(())
}

#[test]
fn zip_bomb_is_stopped_while_inflating() {
    // 24 MiB of zeros deflate to ~24 KiB: ratio ~1000, above the default 200.
    let zeros = vec![b' '; 24 << 20];
    let mut model = model_xml("", &format!(r#"<object id="1">{TET}</object>"#), "").into_bytes();
    model.extend_from_slice(&zeros); // trailing whitespace is legal XML
    let bytes = zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", RELS.as_bytes()),
        ("3D/3dmodel.model", &model),
    ]);
    assert!(bytes.len() < 1 << 20);
    let e = read_default(&bytes);
    assert!(
        matches!(e, Err(ThreeMfError::CompressionRatio { .. })),
        "{e:?}"
    );
    // The absolute budget applies too, whatever the ratio.
    let limits = Limits {
        max_uncompressed_bytes: 1 << 20,
        max_compression_ratio: u64::MAX,
        ..Limits::default()
    };
    let e = read(&bytes, &limits);
    assert!(
        matches!(
            e,
            Err(ThreeMfError::LimitExceeded {
                limit: "max_uncompressed_bytes",
                ..
            })
        ),
        "{e:?}"
    );
}

#[test]
fn absurd_counts_hit_limits() {
    let many: String = (0..200)
        .map(|i| format!(r#"<triangle v1="0" v2="1" v3="{}"/>"#, 2 + i % 2))
        .collect();
    let xml = model_xml(
        "",
        &format!(
            r#"<object id="1"><mesh><vertices><vertex x="0" y="0" z="0"/><vertex x="1" y="0" z="0"/><vertex x="0" y="1" z="0"/><vertex x="0" y="0" z="1"/></vertices><triangles>{many}</triangles></mesh></object>"#
        ),
        r#"<item objectid="1"/>"#,
    );
    let limits = Limits {
        max_triangles: 100,
        ..Limits::default()
    };
    let e = read(&pkg(&xml), &limits);
    assert!(
        matches!(
            e,
            Err(ThreeMfError::LimitExceeded {
                limit: "max_triangles",
                found: 101,
                ..
            })
        ),
        "{e:?}"
    );
    // Exponential instancing: 12 levels of 10 components each would be 10^12 copies.
    let mut res = format!(r#"<object id="1">{TET}</object>"#);
    for level in 2..=13 {
        let comps: String = (0..10)
            .map(|_| format!(r#"<component objectid="{}"/>"#, level - 1))
            .collect();
        res.push_str(&format!(
            r#"<object id="{level}"><components>{comps}</components></object>"#
        ));
    }
    let xml = model_xml("", &res, r#"<item objectid="13"/>"#);
    let small = Limits {
        max_vertices: 100_000,
        max_triangles: 100_000,
        ..Limits::default()
    };
    let pkg = read(&pkg(&xml), &small);
    let Ok(pkg) = pkg else { panic!("{pkg:?}") };
    let e = pkg.flatten();
    assert!(
        matches!(e, Err(ThreeMfError::LimitExceeded { .. })),
        "{e:?}"
    );
    // Entry count.
    let limits = Limits {
        max_archive_entries: 2,
        ..Limits::default()
    };
    assert!(matches!(
        read(&pkg_bytes_simple(), &limits),
        Err(ThreeMfError::LimitExceeded {
            limit: "max_archive_entries",
            ..
        })
    ));
}

fn pkg_bytes_simple() -> Vec<u8> {
    pkg(&model_xml(
        "",
        &format!(r#"<object id="1">{TET}</object>"#),
        r#"<item objectid="1"/>"#,
    ))
}

#[test]
fn component_depth_and_cycles_are_rejected() {
    let xml = model_xml(
        "",
        r#"<object id="1"><components><component objectid="2"/></components></object>
<object id="2"><components><component objectid="1"/></components></object>"#,
        r#"<item objectid="1"/>"#,
    );
    let e = read_default(&pkg(&xml));
    assert!(
        matches!(e, Err(ThreeMfError::ComponentCycle { .. })),
        "{e:?}"
    );
    let mut res = format!(r#"<object id="1">{TET}</object>"#);
    for level in 2..=40 {
        res.push_str(&format!(
            r#"<object id="{level}"><components><component objectid="{}"/></components></object>"#,
            level - 1
        ));
    }
    let e = read_default(&pkg(&model_xml("", &res, r#"<item objectid="40"/>"#)));
    assert!(
        matches!(
            e,
            Err(ThreeMfError::LimitExceeded {
                limit: "max_component_depth",
                ..
            })
        ),
        "{e:?}"
    );
}

#[test]
fn spec_violations_are_rejected_with_located_messages() {
    let ok_obj = format!(r#"<object id="1">{TET}</object>"#);
    let item = r#"<item objectid="1"/>"#;
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "comma decimal",
            model_xml("", &ok_obj.replace(r#"x="1""#, r#"x="1,5""#), item),
            "comma decimal separator",
        ),
        (
            "duplicated attribute",
            model_xml("", &ok_obj, r#"<item objectid="1" objectid="1"/>"#),
            "duplicated attribute",
        ),
        (
            "index out of range",
            model_xml("", &ok_obj.replace(r#"v3="3""#, r#"v3="9""#), item),
            "v3=9 is out of range",
        ),
        (
            "repeated vertex",
            model_xml(
                "",
                &ok_obj.replace(r#"v1="1" v2="2""#, r#"v1="2" v2="2""#),
                item,
            ),
            "distinct",
        ),
        (
            "other-type item",
            model_xml(
                "",
                &ok_obj.replace(r#"id="1""#, r#"id="1" type="other""#),
                item,
            ),
            "type \"other\"",
        ),
        (
            "pindex without pid",
            model_xml(
                "",
                &ok_obj.replace(r#"id="1""#, r#"id="1" pindex="0""#),
                item,
            ),
            "pindex is given without a pid",
        ),
        (
            "dangling pid",
            model_xml("", &ok_obj.replace(r#"id="1""#, r#"id="1" pid="7""#), item),
            "pid=7 does not reference",
        ),
        (
            "duplicate id",
            model_xml(
                "",
                &format!(
                    r##"<m:colorgroup id="1"><m:color color="#000000"/></m:colorgroup>{ok_obj}"##
                ),
                item,
            ),
            "resource id 1 is already used",
        ),
        (
            "missing build",
            model_xml("", &ok_obj, item)
                .replace("<build>", "<!--")
                .replace("</build>", "-->"),
            "has no <build>",
        ),
        (
            "unknown unit",
            model_xml("", &ok_obj, item).replace("millimeter", "furlong"),
            "unknown unit",
        ),
        (
            "undeclared required prefix",
            model_xml(r#"requiredextensions="q""#, &ok_obj, item),
            "prefix \"q\" that is not declared",
        ),
        (
            "unsupported required extension",
            model_xml(
                r#"xmlns:q="http://example.com/q" requiredextensions="q""#,
                &ok_obj,
                item,
            ),
            "http://example.com/q is not supported",
        ),
        (
            "unknown 3MF namespace attribute",
            model_xml(
                r#"xmlns:v2="http://schemas.microsoft.com/3dmanufacturing/v2""#,
                &ok_obj.replace("<mesh>", r#"<mesh v2:x="1">"#),
                item,
            ),
            "unknown 3MF namespace",
        ),
        (
            "unbound prefix",
            model_xml("", &format!("<dc:x/>{ok_obj}"), item),
            "undeclared namespace prefix",
        ),
        (
            "DTD",
            model_xml("", &ok_obj, item).replacen("<model", "<!DOCTYPE model []>\n<model", 1),
            "DTD",
        ),
        (
            "second root",
            format!("{}<model/>", model_xml("", &ok_obj, item)),
            "more than one root element",
        ),
        (
            "xml:space",
            model_xml(r#"xml:space="preserve""#, &ok_obj, item),
            "xml:space",
        ),
        (
            "texture content type",
            model_xml(
                "",
                &format!(
                    r#"<m:texture2d id="5" path="/3D/t.png" contenttype="image/gif"/>{ok_obj}"#
                ),
                item,
            ),
            "image/png or image/jpeg",
        ),
        (
            "missing texture part",
            model_xml(
                "",
                &format!(
                    r#"<m:texture2d id="5" path="/3D/none.png" contenttype="image/png"/>{ok_obj}"#
                ),
                item,
            ),
            "texture part does not exist",
        ),
        (
            "nested multiproperties",
            model_xml(
                "",
                &format!(
                    r##"<m:colorgroup id="2"><m:color color="#000000"/></m:colorgroup><m:multiproperties id="3" pids="2"><m:multi pindices="0"/></m:multiproperties><m:multiproperties id="4" pids="3"><m:multi pindices="0"/></m:multiproperties>{ok_obj}"##
                ),
                item,
            ),
            "must not reference multiproperties",
        ),
        (
            "two colour groups in multiproperties",
            model_xml(
                "",
                &format!(
                    r##"<m:colorgroup id="2"><m:color color="#000000"/></m:colorgroup><m:colorgroup id="3"><m:color color="#000000"/></m:colorgroup><m:multiproperties id="4" pids="2 3"><m:multi pindices="0 0"/></m:multiproperties>{ok_obj}"##
                ),
                item,
            ),
            "at most one colorgroup",
        ),
        (
            "composite on a colour group",
            model_xml(
                "",
                &format!(
                    r##"<m:colorgroup id="2"><m:color color="#000000"/></m:colorgroup><m:compositematerials id="3" matid="2" matindices="0"><m:composite values="1"/></m:compositematerials>{ok_obj}"##
                ),
                item,
            ),
            "matid=2 does not reference a basematerials",
        ),
    ];
    for (what, xml, needle) in cases {
        let bytes = zip_of(&[
            ("[Content_Types].xml", CT.as_bytes()),
            ("_rels/.rels", RELS.as_bytes()),
            ("3D/3dmodel.model", xml.as_bytes()),
            ("3D/t.png", b"\x89PNG"),
        ]);
        let msg = err_of(&bytes);
        assert!(
            msg.contains(needle),
            "{what}: expected {needle:?} in {msg:?}"
        );
        assert!(msg.starts_with("/3D/3dmodel.model"), "{what}: {msg}");
        assert!(!msg.contains('\n'), "{what}: multi-line message");
    }
    // The same model without the defect loads.
    assert!(read_default(&pkg(&model_xml("", &ok_obj, item))).is_ok());
}

#[test]
fn package_level_violations_are_rejected() {
    let model = model_xml(
        "",
        &format!(r#"<object id="1">{TET}</object>"#),
        r#"<item objectid="1"/>"#,
    );
    let m = model.as_bytes();
    // No content types.
    let e = err_of(&zip_of(&[
        ("_rels/.rels", RELS.as_bytes()),
        ("3D/3dmodel.model", m),
    ]));
    assert!(e.contains("[Content_Types].xml"), "{e}");
    // StartPart to a missing part.
    let e = err_of(&zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", RELS.as_bytes()),
    ]));
    assert!(e.contains("does not exist"), "{e}");
    // Two StartParts.
    let two = RELS.replace(
        "</Relationships>",
        r#"<Relationship Target="/3D/b.model" Id="rel1" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>"#,
    );
    let e = err_strict(&zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", two.as_bytes()),
        ("3D/3dmodel.model", m),
        ("3D/b.model", m),
    ]));
    assert!(e.contains("2 StartPart"), "{e}");
    // External thumbnail.
    let ext = RELS.replace(
        "</Relationships>",
        r#"<Relationship Target="http://example.com/t.png" TargetMode="External" Id="rel1" Type="http://schemas.openxmlformats.org/package/2006/relationships/metadata/thumbnail"/></Relationships>"#,
    );
    let e = err_of(&zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", ext.as_bytes()),
        ("3D/3dmodel.model", m),
    ]));
    assert!(e.contains("inside the package"), "{e}");
    // UTF-16 model.
    let utf16: Vec<u8> = [0xFF, 0xFE]
        .into_iter()
        .chain(model.encode_utf16().flat_map(u16::to_le_bytes))
        .collect();
    let e = err_of(&zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", RELS.as_bytes()),
        ("3D/3dmodel.model", &utf16),
    ]));
    assert!(e.contains("UTF-8"), "{e}");
    // Declared non-UTF-8 encoding.
    let latin = model.replacen("encoding=\"UTF-8\"", "encoding=\"ISO-8859-1\"", 1);
    let e = err_of(&pkg(&latin));
    assert!(e.contains("ISO-8859-1"), "{e}");
    // Case-insensitive duplicate part names.
    let e = err_of(&zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", RELS.as_bytes()),
        ("3D/3dmodel.model", m),
        ("3d/3DMODEL.model", m),
    ]));
    assert!(e.contains("case-insensitive"), "{e}");
    // Not a zip at all.
    assert!(matches!(
        read_default(b"solid cube"),
        Err(ThreeMfError::Zip { .. })
    ));
    // Garbage never panics.
    let good = pkg_bytes_simple();
    for cut in (0..good.len()).step_by(97) {
        let _ = read_default(&good[..cut]);
    }
}

#[test]
fn production_parts_are_followed() -> Result<(), ThreeMfError> {
    let root = r#"<?xml version="1.0" encoding="UTF-8"?>
<model unit="millimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02" xmlns:p="http://schemas.microsoft.com/3dmanufacturing/production/2015/06" requiredextensions="p">
<resources><object id="2"><components><component objectid="7" p:path="/3D/part.model" transform="1 0 0 0 1 0 0 0 1 0 0 3"/></components></object></resources>
<build><item objectid="2" transform="1 0 0 0 1 0 0 0 1 5 0 0"/><item objectid="7" p:path="/3D/Part.MODEL"/></build>
</model>"#;
    let part = model_xml(
        "",
        &format!(r#"<object id="7" name="far">{TET}</object>"#),
        "",
    );
    let bytes = zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", RELS.as_bytes()),
        ("3D/3dmodel.model", root.as_bytes()),
        ("3D/part.model", part.as_bytes()),
    ]);
    let p = read_default(&bytes)?;
    assert_eq!(p.models.len(), 2);
    let flat = p.flatten()?;
    assert_eq!(flat.len(), 2);
    assert_eq!(flat[0].vertices[3], [5.0, 0.0, 4.0]);
    assert_eq!(flat[1].name, "far");
    // A p:path to a missing part is an error.
    let bytes = zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", RELS.as_bytes()),
        ("3D/3dmodel.model", root.as_bytes()),
    ]);
    assert!(err_of(&bytes).contains("/3D/part.model"));
    Ok(())
}

/// Small deterministic PRNG for the mutation test (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

#[test]
fn mutated_packages_never_panic() {
    let resources = format!(
        r##"<basematerials id="1"><base name="a" displaycolor="#FF0000"/><base name="b" displaycolor="#00FF00"/></basematerials>
<m:colorgroup id="2"><m:color color="#112233"/></m:colorgroup>
<m:multiproperties id="4" pids="1 2"><m:multi pindices="1 0"/></m:multiproperties>
<object id="3" pid="1" pindex="1">{TET}</object>
<object id="5"><components><component objectid="3" transform="1 0 0 0 1 0 0 0 1 1 2 3"/><component objectid="3"/></components></object>"##
    );
    let base = model_xml(
        "",
        &resources,
        r#"<item objectid="5" transform="-1 0 0 0 1 0 0 0 1 0 0 0"/>"#,
    )
    .into_bytes();
    assert!(read_default(&pkg_raw(&base)).is_ok());
    const ALPHABET: &[u8] = b"<>/=\" '&#;:0123456789.,-+eEabcdxyzmp\n";
    // CONDUIT_3MF_FUZZ_ITERS raises the iteration count for a longer local run.
    let iters: usize = std::env::var("CONDUIT_3MF_FUZZ_ITERS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1500);
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for _ in 0..iters {
        let mut m = base.clone();
        for _ in 0..1 + rng.below(4) {
            let len = m.len();
            if len == 0 {
                break;
            }
            match rng.below(4) {
                0 => {
                    let i = rng.below(len);
                    m[i] = ALPHABET[rng.below(ALPHABET.len())];
                }
                1 => {
                    let i = rng.below(len);
                    let j = (i + rng.below(40)).min(len);
                    m.drain(i..j);
                }
                2 => {
                    let i = rng.below(len);
                    let j = (i + rng.below(60)).min(len);
                    let chunk = m[i..j].to_vec();
                    let at = rng.below(len);
                    m.splice(at..at, chunk);
                }
                _ => m.truncate(rng.below(len)),
            }
        }
        if let Ok(p) = read_default(&pkg_raw(&m)) {
            let _ = p.flatten();
        }
    }
    // Container-level damage: flip bytes of the ZIP itself.
    let good = pkg_raw(&base);
    for _ in 0..iters {
        let mut z = good.clone();
        for _ in 0..1 + rng.below(3) {
            let i = rng.below(z.len());
            z[i] = rng.next() as u8;
        }
        if let Ok(p) = read_default(&z) {
            let _ = p.flatten();
        }
    }
}

fn pkg_raw(model: &[u8]) -> Vec<u8> {
    zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", RELS.as_bytes()),
        ("3D/3dmodel.model", model),
    ])
}
