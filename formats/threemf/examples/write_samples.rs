//! Writes sample packages with `conduit_3mf::write`, for checking with an independent reader
//! (`python3 bench/lib3mf_check.py OUTDIR/*.3mf`).
//!
//! Usage: `cargo run -p conduit-3mf --example write_samples -- OUTDIR [INPUT.3mf ...]`
//!
//! Always writes `rich.3mf` (materials, colours, components, transforms, metadata) and
//! `inch_cube.3mf`; each INPUT is read, and its root model written back as `rt_<name>.3mf`
//! when it fits in one part (inputs that need other parts are reported and skipped).

use std::path::Path;

use conduit_3mf::*;

fn cube(s: f64) -> Mesh {
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

fn rich() -> Model {
    let mut mesh = cube(10.0);
    mesh.vertices[6] = [10.1, 10.000000000000002, 1.0 / 3.0];
    mesh.triangles[0].pid = Some(3);
    mesh.triangles[0].p = [Some(0), Some(1), Some(2)];
    Model {
        unit: Unit::Millimeter,
        language: Some("en-US".into()),
        metadata: vec![
            Metadata {
                name: "Title".into(),
                value: "conduit <sample> & co".into(),
            },
            Metadata {
                name: "Application".into(),
                value: "conduit".into(),
            },
            Metadata {
                name: "conduit:Generator".into(),
                value: "write_samples".into(),
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
                transform: Some([-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 30.0, 0.0, 0.0]),
                part_number: None,
            },
        ],
    }
}

fn save(dir: &Path, name: &str, model: &Model) -> Result<(), Box<dyn std::error::Error>> {
    let path = dir.join(name);
    let mut buf = std::io::Cursor::new(Vec::new());
    write(&mut buf, model)?;
    std::fs::write(&path, buf.into_inner())?;
    println!("wrote {}", path.display());
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let Some(dir) = args.next() else {
        eprintln!("usage: write_samples OUTDIR [INPUT.3mf ...]");
        std::process::exit(2);
    };
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir)?;
    save(dir, "rich.3mf", &rich())?;
    let inch = Model {
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
    save(dir, "inch_cube.3mf", &inch)?;
    if std::env::var_os("WRITE_SAMPLES_REQ").is_some() {
        for (name, ns) in [
            (
                "req_m.3mf",
                "http://schemas.microsoft.com/3dmanufacturing/material/2015/02",
            ),
            (
                "req_p.3mf",
                "http://schemas.microsoft.com/3dmanufacturing/production/2015/06",
            ),
            (
                "req_s.3mf",
                "http://schemas.microsoft.com/3dmanufacturing/slice/2015/07",
            ),
            (
                "req_b.3mf",
                "http://schemas.microsoft.com/3dmanufacturing/beamlattice/2017/02",
            ),
        ] {
            let mut m = rich();
            m.required_extensions = vec![ns.to_string()];
            save(dir, name, &m)?;
        }
    }
    for input in args {
        let bytes = std::fs::read(&input)?;
        let stem = Path::new(&input)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        match read(&bytes, &Limits::default()) {
            Ok(pkg) => {
                let mut model = pkg.root().clone();
                // Extensions the writer does not produce content for are not required again.
                model.required_extensions.clear();
                // Drop property references to groups `Model` does not carry (textures,
                // composites, multiproperties).
                let groups: Vec<u32> = model
                    .base_materials
                    .iter()
                    .map(|b| b.id)
                    .chain(model.color_groups.iter().map(|c| c.id))
                    .collect();
                for o in &mut model.objects {
                    if o.pid.is_some_and(|p| !groups.contains(&p)) {
                        o.pid = None;
                        o.pindex = None;
                    }
                    let opid = o.pid;
                    if let ObjectContent::Mesh(m) = &mut o.content {
                        for t in &mut m.triangles {
                            if t.pid.or(opid).is_some_and(|p| !groups.contains(&p)) {
                                t.pid = None;
                                t.p = [None; 3];
                            }
                        }
                    }
                }
                if let Err(e) = save(dir, &format!("rt_{stem}.3mf"), &model) {
                    println!("skipped {input}: {e}");
                }
            }
            Err(e) => println!("skipped {input}: {e}"),
        }
    }
    Ok(())
}
