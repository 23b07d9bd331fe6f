//! The fuzz targets: every format crate's top-level reader and the library's own readers (mesh
//! loading by format, configs, placements, designs, circuits), each called in-process on one
//! mutated input. A target returns whether the input was read; it must never panic.
//!
//! `ci_execs` is the count of the CI test (`tests/fuzz_stable.rs`): 20 000 for every target.
//! The library readers that take a path (`scene`, `placement`, `design`, `circuit`) get the
//! input written to a file in an in-memory scratch folder first.

use super::engine::{Input, Seed, Target};

/// Executions per parser in the CI test.
const CI: u64 = 20_000;

fn ext_in(s: &Seed, exts: &[&str]) -> bool {
    exts.contains(&s.ext.as_str())
}

/// An STL that starts like the ASCII form (`solid` then `facet`/`endsolid` early on).
fn ascii_stl(s: &Seed) -> bool {
    let head = &s.bytes[..s.bytes.len().min(512)];
    let text = String::from_utf8_lossy(head);
    text.trim_start().starts_with("solid") && (text.contains("facet") || text.contains("endsolid"))
}

const XML_DICT: &[&str] = &[
    "<a>",
    "</a>",
    "<a/>",
    "<!DOCTYPE x>",
    "<?xml version=\"1.0\"?>",
    "xmlns=\"\"",
    " x=\"1\"",
];

/// All targets, in report order.
pub fn all() -> Vec<Target> {
    vec![
        Target {
            name: "stl_ascii",
            about: "conduit_stl::read on ASCII STL; what reads writes and reads back",
            accepts: |s| ext_in(s, &["stl"]) && ascii_stl(s),
            dict: &[
                "solid ",
                "endsolid",
                "facet normal ",
                "outer loop",
                "vertex ",
                "endloop",
                "endfacet",
                " 1e39 ",
            ],
            run: stl,
            ci_execs: CI,
        },
        Target {
            name: "stl_binary",
            about: "conduit_stl::read on binary STL; what reads writes and reads back",
            accepts: |s| ext_in(s, &["stl"]) && !ascii_stl(s),
            dict: &["solid"],
            run: stl,
            ci_execs: CI,
        },
        Target {
            name: "threemf",
            about: "conduit_3mf::read and flatten (XML inside the zip mutated and re-zipped)",
            accepts: |s| ext_in(s, &["3mf"]),
            dict: &[
                "<object id=\"1\" type=\"model\">",
                "<component objectid=\"1\"/>",
                "<item objectid=\"1\" transform=\"1 0 0 0 1 0 0 0 1 0 0 0\"/>",
                "<vertex x=\"1\" y=\"1e308\" z=\"NaN\"/>",
                "<triangle v1=\"0\" v2=\"4294967295\" v3=\"2\"/>",
                " p:path=\"/3D/3dmodel.model\"",
                "unit=\"micron\"",
                "<mesh><vertices></vertices><triangles></triangles></mesh>",
            ],
            run: |i| {
                conduit_3mf::read(i.bytes, &conduit_3mf::Limits::default())
                    .is_ok_and(|p| p.flatten().is_ok())
            },
            ci_execs: CI,
        },
        Target {
            name: "obj",
            about: "conduit_obj::read (no material folder) and looks_like_obj",
            accepts: |s| ext_in(s, &["obj"]),
            dict: &[
                "v ",
                "vt ",
                "vn ",
                "f ",
                "f -1 -2 -3",
                "f 1/1/1 2/2/2 3/3/3",
                "o ",
                "g ",
                "s 1",
                "usemtl ",
                "mtllib ",
                "l 1 2",
                "\\\n",
            ],
            run: |i| {
                let _ = conduit_obj::looks_like_obj(i.bytes);
                conduit_obj::read(i.bytes, None).is_ok()
            },
            ci_execs: CI,
        },
        Target {
            name: "off",
            about: "conduit_off::read",
            accepts: |s| ext_in(s, &["off"]),
            dict: &["OFF", "COFF", "NOFF", "4OFF", "3 0 1 2", "2147483647 "],
            run: |i| conduit_off::read(i.bytes).is_ok(),
            ci_execs: CI,
        },
        Target {
            name: "ply",
            about: "conduit_pointcloud::read_ply (ASCII and binary)",
            accepts: |s| ext_in(s, &["ply"]),
            dict: &[
                "element vertex ",
                "element face ",
                "property float x",
                "property double z",
                "property list uchar int vertex_indices",
                "property list uint uint vertex_index",
                "format binary_big_endian 1.0",
                "format binary_little_endian 1.0",
                "format ascii 1.0",
                "end_header\n",
                "comment ",
            ],
            run: |i| conduit_pointcloud::read_ply(i.bytes).is_ok(),
            ci_execs: CI,
        },
        Target {
            name: "xyz",
            about: "conduit_pointcloud::read_xyz",
            accepts: |s| ext_in(s, &["xyz"]),
            dict: &["# ", "1 2 3", "1,2,3", "\t"],
            run: |i| conduit_pointcloud::read_xyz(i.bytes).is_ok(),
            ci_execs: CI,
        },
        Target {
            name: "eagle",
            about: "conduit_eagle::read (.sch, .brd) and the netlist",
            accepts: |s| ext_in(s, &["sch", "brd"]),
            dict: &[
                "<part name=\"X\" library=\"l\" deviceset=\"d\" device=\"\"/>",
                "<pinref part=\"X\" gate=\"G$1\" pin=\"1\"/>",
                "<smd name=\"1\" x=\"0\" y=\"0\" dx=\"1\" dy=\"1\" layer=\"1\"/>",
                "<pad name=\"1\" x=\"0\" y=\"0\" drill=\"1\"/>",
                "rot=\"R90\"",
                "rot=\"MR1e308\"",
                "rot=\"SR-45\"",
                "<wire x1=\"0\" y1=\"0\" x2=\"1\" y2=\"1\" width=\"0.2\" layer=\"1\" curve=\"90\"/>",
                "<contactref element=\"X\" pad=\"1\"/>",
            ],
            run: |i| match conduit_eagle::read(i.bytes) {
                Ok(conduit_eagle::Document::Schematic(s)) => {
                    let _ = s.netlist();
                    true
                }
                Ok(conduit_eagle::Document::Board(b)) => {
                    let _ = b.netlist();
                    true
                }
                Ok(conduit_eagle::Document::Library) => true,
                Err(_) => false,
            },
            ci_execs: CI,
        },
        Target {
            name: "kicad",
            about: "conduit_kicad::read (.kicad_pcb, .kicad_sch, .net) and the netlists",
            accepts: |s| ext_in(s, &["kicad_pcb", "kicad_sch", "net"]),
            dict: &[
                "(pad \"1\" smd roundrect (at 0 0 90) (size 1 1) (layers \"F.Cu\") (net 1 \"A\"))",
                "(pad \"2\" smd custom (at 0 0) (size 1 1) (primitives (gr_poly (pts (xy 0 0) (xy 1e308 1)))))",
                "(wire (pts (xy 0 0) (xy 10 0)))",
                "(label \"D[0..7]\" (at 0 0 0))",
                "(hierarchical_label \"X\" (at 0 0 0))",
                "(global_label \"G\" (at 10 0 0))",
                "(junction (at 0 0))",
                "(at 1e308 -1e308 90)",
                "(mirror x)",
                "(hide yes)",
                "(",
                ")",
                "\"",
            ],
            run: |i| {
                let doc = conduit_kicad::read(
                    i.bytes,
                    std::path::Path::new("fuzz.kicad_sch"),
                    &mut |_| Err(std::io::ErrorKind::NotFound.into()),
                );
                match doc {
                    Ok(conduit_kicad::Document::Pcb(p)) => {
                        let _ = p.netlist();
                        true
                    }
                    Ok(conduit_kicad::Document::Schematic(s)) => {
                        let _ = s.netlist();
                        true
                    }
                    Ok(conduit_kicad::Document::NetFile(n)) => {
                        let _ = n.netlist();
                        true
                    }
                    Err(_) => false,
                }
            },
            ci_execs: CI,
        },
        Target {
            name: "gcode",
            about: "conduit_gcode::parse (byte-for-byte round trip), summarize and moves",
            accepts: |s| ext_in(s, &["gcode", "g", "gco", "nc"]),
            dict: &[
                "G1 ",
                "G0 ",
                "G2 ",
                "G3 ",
                "G28",
                "G90",
                "G91",
                "G92 E0",
                "M82",
                "M83",
                "G20",
                "G21",
                "T1",
                "T255",
                " X",
                " Y",
                " Z",
                " E",
                " F",
                " I",
                " J",
                " R",
                ";LAYER:",
                ";Z:",
                ";TYPE:",
                ";LAYER_CHANGE",
                "M117 ",
                "*",
                "N10 ",
                "(comment)",
            ],
            run: |i| match conduit_gcode::parse(i.bytes) {
                Ok(g) => {
                    assert_eq!(g.to_bytes(), i.bytes, "G-code round trip");
                    let _ = conduit_gcode::summarize(&g);
                    let _ = conduit_gcode::moves(&g, conduit_gcode::Firmware::Marlin);
                    true
                }
                Err(_) => false,
            },
            ci_execs: CI,
        },
        Target {
            name: "svg",
            about: "conduit_svg::read at 0.01 mm flattening",
            accepts: |s| ext_in(s, &["svg"]),
            dict: &[
                "<path d=\"M0 0 L10 10 Z\"/>",
                "<path d=\"M0 0 A1e308 1 0 1 1 10 10\"/>",
                "<circle cx=\"0\" cy=\"0\" r=\"1e-9\"/>",
                "<g transform=\"scale(1e308) rotate(NaN)\">",
                "</g>",
                "<use href=\"#a\"/>",
                "viewBox=\"0 0 0 0\"",
                "width=\"1e308mm\"",
                " d=\"M0 0 C1 1 2 2 3 3 Q 4 4 5 5\"",
                "<polyline points=\"0,0 1,1 2,2\"/>",
            ],
            run: |i| conduit_svg::read(i.bytes, 0.01).is_ok(),
            ci_execs: CI,
        },
        Target {
            name: "dxf",
            about: "conduit_dxf::read at 0.01 mm flattening",
            accepts: |s| ext_in(s, &["dxf"]),
            dict: &[
                "0\nLINE\n",
                "0\nLWPOLYLINE\n",
                "0\nCIRCLE\n",
                "0\nARC\n",
                "0\nPOLYLINE\n",
                "0\nVERTEX\n",
                "0\nSEQEND\n",
                "0\nSECTION\n2\nENTITIES\n",
                "0\nENDSEC\n",
                "0\nEOF\n",
                "42\n1e308\n",
                "40\n1e-9\n",
                "90\n2147483647\n",
                "10\n",
                "20\n",
                "70\n1\n",
            ],
            run: |i| conduit_dxf::read(i.bytes, 0.01).is_ok(),
            ci_execs: CI,
        },
        Target {
            name: "pnp",
            about: "conduit_pnp::read_kicad_pos and read_openpnp_board",
            accepts: |s| ext_in(s, &["pos"]) || s.name.contains("openpnp"),
            dict: &[
                "Ref,Val,Package,PosX,PosY,Rot,Side\n",
                "\"\"",
                ",top,",
                ",bottom,",
                "<placement id=\"X\" side=\"Top\"><location x=\"1\" y=\"2\" z=\"0\" rotation=\"1e308\"/></placement>",
                "units=\"Inches\"",
            ],
            run: |i| {
                let t = i.text();
                let a = conduit_pnp::read_kicad_csv(&t).is_ok();
                let b = conduit_pnp::read_kicad_ascii(&t).is_ok();
                let c = conduit_pnp::read_openpnp_board(&t).is_ok();
                a || b || c
            },
            ci_execs: CI,
        },
        Target {
            name: "poses",
            about: "conduit_poses::read_poses and Table::parse",
            accepts: |s| ext_in(s, &["csv"]),
            dict: &[
                "x,y,z,qw,qx,qy,qz",
                ",dispense",
                "\"",
                "\"\"",
                ",,",
                "0,0,0,0,0,0,0",
            ],
            run: |i| {
                let t = i.text();
                let _ = conduit_poses::Table::parse(&t);
                conduit_poses::read_poses(&t).is_ok()
            },
            ci_execs: CI,
        },
        Target {
            name: "xml",
            about: "conduit_xml::parse with the EAGLE and SVG readers' options",
            accepts: |s| ext_in(s, &["sch", "brd", "svg", "3de", "xml"]),
            dict: XML_DICT,
            run: |i| {
                use conduit_xml::{DepthCheck, Entities, Names, Options};
                let eagle = Options {
                    names: Names::Qualified,
                    entities: Entities::Strict,
                    depth_check: DepthCheck::BeforeAttributes,
                    max_depth: 64,
                };
                let svg = Options {
                    names: Names::Local,
                    entities: Entities::KeepRaw,
                    depth_check: DepthCheck::AfterAttributes,
                    max_depth: 256,
                };
                let a = conduit_xml::parse(i.bytes, &eagle).is_ok();
                let b = conduit_xml::parse(i.bytes, &svg).is_ok();
                a || b
            },
            ci_execs: CI,
        },
        // The library's readers.
        Target {
            name: "scene",
            about: "conduit::scene::load of a file by its extension (every mesh, cloud, EAGLE, KiCad, G-code and SVG format)",
            accepts: |s| {
                ext_in(
                    s,
                    &[
                        "stl",
                        "3mf",
                        "obj",
                        "off",
                        "ply",
                        "xyz",
                        "sch",
                        "brd",
                        "kicad_pcb",
                        "kicad_sch",
                        "net",
                        "gcode",
                        "svg",
                    ],
                )
            },
            dict: &[
                "solid ",
                "v ",
                "f ",
                "OFF",
                "ply",
                "<path d=\"M0 0 L1 1\"/>",
                "G1 X1",
            ],
            run: |i| {
                let p = i.file(None);
                conduit::scene::load(&p, &conduit::scene::LoadOptions::default()).is_ok()
            },
            ci_execs: CI,
        },
        Target {
            name: "config_toml",
            about: "conduit::config::Config::parse (TOML, validated)",
            accepts: |s| ext_in(s, &["toml"]),
            dict: &[
                "[slice]\n",
                "[printer]\n",
                "[tools.1]\n",
                "[[tools]]\n",
                "[route]\n",
                "[electronics]\n",
                "[curved]\n",
                "[jet]\n",
                "[conform]\n",
                "[robot]\n",
                "layer_height = ",
                "perimeters = ",
                "infill_density = ",
                "nozzle_diameter = ",
                "= 1e308\n",
                "= -1\n",
                "= nan\n",
                "= inf\n",
                "= 18446744073709551615\n",
                "= \"\"\n",
                "= []\n",
                "= {}\n",
            ],
            run: |i| conduit::config::Config::parse(&i.text()).is_ok(),
            ci_execs: CI,
        },
        Target {
            name: "config_ini",
            about: "conduit::config::prusa_ini::from_ini_str (PrusaSlicer profiles)",
            accepts: |s| ext_in(s, &["ini"]),
            dict: &[
                "layer_height = ",
                "perimeters = ",
                "fill_density = ",
                "nozzle_diameter = ",
                "extrusion_width = ",
                "skirts = ",
                "% ",
                "= 1e308\n",
                "= -1\n",
                "= nan\n",
                "[print:x]\n",
                ";",
            ],
            run: |i| conduit::config::prusa_ini::from_ini_str(&i.text()).is_ok(),
            ci_execs: CI,
        },
        Target {
            name: "placement",
            about: "conduit::circuit::Placement::load (.toml and .3de, numbers checked)",
            accepts: |s| ext_in(s, &["toml", "3de"]),
            dict: &[
                "[[parts]]\n",
                "[nets.GND]\n",
                "origin = \"model\"\n",
                "origin = \"bbox_center\"\n",
                "position = [0, 0, 1e308]\n",
                "rotation = [NaN, 0, 0]\n",
                "<part name=\"X\"><position X=\"1e308\" Y=\"0\" Z=\"0\"/></part>",
                "<waypoint key=\"18446744073709551616\"/>",
            ],
            run: |i| {
                let ext = if i.ext == "3de" { "3de" } else { "toml" };
                conduit::circuit::Placement::load(&i.file(Some(ext))).is_ok()
            },
            ci_execs: CI,
        },
        Target {
            name: "design",
            about: "conduit::jet::design::load (.svg and .dxf designs)",
            accepts: |s| ext_in(s, &["svg", "dxf"]),
            dict: &[
                "<path d=\"M0 0 L1e308 1\"/>",
                "0\nLINE\n",
                "0\nCIRCLE\n",
                "40\n1e308\n",
            ],
            run: |i| {
                let ext = if i.ext == "dxf" { "dxf" } else { "svg" };
                conduit::jet::design::load(&i.file(Some(ext)), 0.01).is_ok()
            },
            ci_execs: CI,
        },
        Target {
            name: "circuit",
            about: "conduit::circuit::Circuit::load (EAGLE and KiCad into the circuit model, pads checked)",
            accepts: |s| ext_in(s, &["sch", "brd", "kicad_pcb", "kicad_sch", "net"]),
            dict: &[
                "<smd name=\"1\" x=\"0\" y=\"0\" dx=\"1e308\" dy=\"1\" layer=\"1\"/>",
                "<pad name=\"1\" x=\"0\" y=\"0\" drill=\"-1\"/>",
                "rot=\"R1e308\"",
            ],
            run: |i| conduit::circuit::Circuit::load(&i.file(None)).is_ok(),
            ci_execs: CI,
        },
        Target {
            name: "scan",
            about: "conduit::conform::scan::load_scan (a mesh or point cloud as a surface)",
            // No 3MF: a 1 KB package that fans out to a million triangles takes seconds here
            // (`threemf` and `scene` read packages).
            accepts: |s| ext_in(s, &["stl", "obj", "off", "ply", "xyz"]),
            dict: &["1e308 ", "0 0 0\n", "NaN ", "vertex 0 0 0\n"],
            run: |i| {
                conduit::conform::scan::load_scan(
                    &i.file(None),
                    false,
                    1.0,
                    &conduit::scene::LoadOptions::default(),
                )
                .is_ok()
            },
            ci_execs: CI,
        },
        Target {
            name: "robot_csv",
            about: "conduit::robot readers of CSV tables: TCP flange poses, measured frames, gap readings",
            accepts: |s| ext_in(s, &["csv"]),
            dict: &[
                "x,y,z,qw,qx,qy,qz",
                "j1,j2,j3",
                ",reading",
                "reading\n",
                "\"",
                ",,",
                "1e308,",
            ],
            run: |i| {
                let t = i.text();
                let dh = [[0.0, 90.0, 0.1, 0.0], [0.0, 0.0, 0.0, 0.3]];
                let a = conduit::robot::tcp::flange_poses(&t, &dh).is_ok();
                let b = conduit::robot::frames::read_measured(&t).is_ok();
                let c = conduit::robot::compensate::gaps::read(&t, &[0.0, 1.0, 2.5]).is_ok();
                a || b || c
            },
            ci_execs: CI,
        },
    ]
}

/// The STL target: what reads writes as binary and reads back with as many triangles.
fn stl(i: &Input<'_>) -> bool {
    match conduit_stl::read(i.bytes) {
        Ok(stl) => {
            let mut out = Vec::new();
            if conduit_stl::write_binary(&mut out, "fuzz", &stl.triangles).is_ok() {
                let back = conduit_stl::read(&out).map(|s| s.triangles.len());
                assert_eq!(back.ok(), Some(stl.triangles.len()), "STL round trip");
            }
            true
        }
        Err(_) => false,
    }
}
