//! Slicer projects: a 3MF from PrusaSlicer or OrcaSlicer brings its profile, its objects'
//! settings and its volumes. The projects are written here, laid out as the two slicers write
//! them (`Metadata/Slic3r_PE.config` and `Slic3r_PE_model.config`; `project_settings.config`
//! and `model_settings.config`), and sliced by the binary; PrusaSlicer's own test project from
//! the corpus checks the reading of a real file.

use std::io::Write;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::support::{conduit, corpus, sample, stderr, temp_dir};

/// An axis-aligned box, min and max corners, mm.
type Cuboid = ([f64; 3], [f64; 3]);

/// A volume of a project: its box, its type as PrusaSlicer spells it, its name and settings.
struct Part<'a> {
    cuboid: Cuboid,
    kind: &'a str,
    name: &'a str,
    settings: &'a [(&'a str, &'a str)],
}

const CUBE_10: Cuboid = ([0.0, 0.0, 0.0], [20.0, 20.0, 10.0]);

fn part<'a>(cuboid: Cuboid, kind: &'a str, name: &'a str) -> Part<'a> {
    Part {
        cuboid,
        kind,
        name,
        settings: &[],
    }
}

/// The 8 corners and 12 outward triangles of a box.
fn cuboid_mesh((lo, hi): Cuboid) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let v = (0..8)
        .map(|i| {
            [
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ]
        })
        .collect();
    let t = vec![
        [0, 2, 3],
        [0, 3, 1],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [0, 4, 6],
        [0, 6, 2],
        [1, 3, 7],
        [1, 7, 5],
    ];
    (v, t)
}

/// A mesh object's XML: the boxes' vertices and triangles one after the other.
fn mesh_object(id: u32, boxes: &[Cuboid]) -> String {
    let (mut vertices, mut triangles) = (String::new(), String::new());
    for (i, b) in boxes.iter().enumerate() {
        let (v, t) = cuboid_mesh(*b);
        for p in v {
            vertices += &format!("<vertex x=\"{}\" y=\"{}\" z=\"{}\"/>\n", p[0], p[1], p[2]);
        }
        for [a, b, c] in t {
            let o = 8 * i as u32;
            triangles += &format!(
                "<triangle v1=\"{}\" v2=\"{}\" v3=\"{}\"/>\n",
                a + o,
                b + o,
                c + o
            );
        }
    }
    format!(
        "<object id=\"{id}\" type=\"model\"><mesh><vertices>\n{vertices}</vertices>\
         <triangles>\n{triangles}</triangles></mesh></object>\n"
    )
}

/// A 3MF package of `parts` (name, bytes), with the core's content types and relationships.
fn package(parts: &[(&str, String)]) -> Vec<u8> {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let content_types = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\">\
        <Default Extension=\"rels\" ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/>\
        <Default Extension=\"model\" ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/></Types>";
    let rels = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">\
        <Relationship Target=\"/3D/3dmodel.model\" Id=\"rel-1\" Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/></Relationships>";
    let all = [
        ("[Content_Types].xml", content_types.to_owned()),
        ("_rels/.rels", rels.to_owned()),
    ];
    for (name, text) in all.iter().chain(parts) {
        zip.start_file(*name, zip::write::SimpleFileOptions::default())
            .expect("a zip entry starts");
        zip.write_all(text.as_bytes())
            .expect("a zip entry is written");
    }
    zip.finish().expect("the zip is finished").into_inner()
}

fn model(application: &str, resources: &str, build: &str) -> String {
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"millimeter\" xml:lang=\"en-US\" \
         xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n\
         <metadata name=\"Application\">{application}</metadata>\n<resources>\n{resources}</resources>\n\
         <build>{build}</build>\n</model>\n"
    )
}

/// A PrusaSlicer project: one object `name` of `parts` (one mesh, each part a triangle range),
/// with the object's own `object_settings`, and the profile lines `profile` (`key = value`).
fn prusa_project(
    name: &str,
    parts: &[Part],
    object_settings: &[(&str, &str)],
    profile: &str,
) -> Vec<u8> {
    let boxes: Vec<Cuboid> = parts.iter().map(|p| p.cuboid).collect();
    let mut config = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<config>\n <object id=\"1\" instances_count=\"1\">\n  \
         <metadata type=\"object\" key=\"name\" value=\"{name}\"/>\n"
    );
    for (k, v) in object_settings {
        config += &format!("  <metadata type=\"object\" key=\"{k}\" value=\"{v}\"/>\n");
    }
    for (i, p) in parts.iter().enumerate() {
        config += &format!(
            "  <volume firstid=\"{}\" lastid=\"{}\">\n   <metadata type=\"volume\" key=\"name\" value=\"{}\"/>\n   \
             <metadata type=\"volume\" key=\"volume_type\" value=\"{}\"/>\n",
            12 * i,
            12 * i + 11,
            p.name,
            p.kind
        );
        for (k, v) in p.settings {
            config += &format!("   <metadata type=\"volume\" key=\"{k}\" value=\"{v}\"/>\n");
        }
        config += "  </volume>\n";
    }
    config += " </object>\n</config>\n";
    let mut ini =
        "; generated by PrusaSlicer 2.5.0+linux-x64-GTK3 on 2026-01-01 at 10:00:00 UTC\n\n"
            .to_owned();
    for line in profile.lines() {
        ini += &format!("; {line}\n");
    }
    package(&[
        (
            "3D/3dmodel.model",
            model(
                "PrusaSlicer-2.5.0",
                &mesh_object(1, &boxes),
                "<item objectid=\"1\"/>",
            ),
        ),
        ("Metadata/Slic3r_PE.config", ini),
        ("Metadata/Slic3r_PE_model.config", config),
    ])
}

/// An OrcaSlicer project: object 10 made of components, one mesh object per part (ids 1, 2,
/// ...), `model_settings.config` naming each part's subtype, and the profile `profile` (JSON).
fn orca_project(name: &str, parts: &[(Cuboid, &str)], profile: &str) -> Vec<u8> {
    let mut resources = String::new();
    let mut components = String::new();
    let mut config = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<config>\n  <object id=\"10\">\n    \
         <metadata key=\"name\" value=\"{name}\"/>\n"
    );
    for (i, (cuboid, subtype)) in parts.iter().enumerate() {
        let id = i as u32 + 1;
        resources += &mesh_object(id, &[*cuboid]);
        components += &format!("<component objectid=\"{id}\"/>");
        config += &format!(
            "    <part id=\"{id}\" subtype=\"{subtype}\">\n      <metadata key=\"name\" value=\"part {id}\"/>\n    </part>\n"
        );
    }
    resources += &format!(
        "<object id=\"10\" type=\"model\"><components>{components}</components></object>\n"
    );
    config += "  </object>\n  <plate>\n    <metadata key=\"plater_id\" value=\"1\"/>\n  </plate>\n</config>\n";
    package(&[
        (
            "3D/3dmodel.model",
            model("OrcaSlicer-2.1.0", &resources, "<item objectid=\"10\"/>"),
        ),
        ("Metadata/project_settings.config", profile.to_owned()),
        ("Metadata/model_settings.config", config),
    ])
}

/// Writes `bytes` to `dir/name`.
fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("the project is written");
    path
}

/// Slices `model` with `extra` arguments: the run's stderr and its JSON report (`Null` when the
/// run failed).
fn slice(dir: &Path, model: &Path, extra: &[&str]) -> (String, Value, bool) {
    let out = dir.join("out.gcode");
    let report = dir.join("out.json");
    let _ = std::fs::remove_file(&report);
    let mut args = vec![
        "slice".to_owned(),
        model.display().to_string(),
        "-o".to_owned(),
        out.display().to_string(),
        "--report".to_owned(),
        report.display().to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    let o = conduit(&args);
    let json = std::fs::read(&report)
        .ok()
        .and_then(|b| serde_json::from_slice(&b).ok())
        .unwrap_or(Value::Null);
    // Paths shortened to the file name, as the assertions spell them.
    let err = stderr(&o).replace(&format!("{}/", dir.display()), "");
    (err, json, o.status.success())
}

/// How many extruding moves of the absolute-E G-code `gcode` pass a point where `inside`
/// holds (checked at 20 points along each move).
fn extrusions_inside(gcode: &str, inside: &dyn Fn(f64, f64) -> bool) -> usize {
    let (mut x, mut y, mut e, mut count) = (0.0, 0.0, 0.0, 0);
    for line in gcode.lines().filter(|l| l.starts_with("G1 ")) {
        let word = |c: char| {
            line.split_whitespace()
                .find_map(|w| w.strip_prefix(c).and_then(|v| v.parse::<f64>().ok()))
        };
        let (nx, ny) = (word('X').unwrap_or(x), word('Y').unwrap_or(y));
        if let Some(next) = word('E') {
            let passes = (0..=20).any(|i| {
                let t = f64::from(i) / 20.0;
                inside(x + t * (nx - x), y + t * (ny - y))
            });
            if next > e && passes {
                count += 1;
            }
            e = next;
        }
        (x, y) = (nx, ny);
    }
    count
}

fn filament(report: &Value) -> f64 {
    report["gcode"]["tools"].as_array().map_or(0.0, |t| {
        t.iter().filter_map(|t| t["filament_mm"].as_f64()).sum()
    })
}

const PROFILE: &str =
    "layer_height = 0.3\nfirst_layer_height = 0.3\nperimeters = 4\nfill_density = 35%\n";

#[test]
fn a_prusaslicer_project_brings_its_profile_and_flags_override_it() {
    let dir = temp_dir();
    let p = write(
        dir.path(),
        "box.3mf",
        &prusa_project("box", &[part(CUBE_10, "ModelPart", "box")], &[], PROFILE),
    );
    let (err, report, ok) = slice(dir.path(), &p, &[]);
    assert!(ok, "{err}");
    assert!(
        err.contains(
            "box.3mf: slicing with the PrusaSlicer 2.5.0+linux-x64-GTK3 profile \
             (Metadata/Slic3r_PE.config, 4 settings) stored in it (--config and --set override it)"
        ),
        "{err}"
    );
    // 10 mm in 0.3 mm layers: the last at 9.9 mm.
    assert_eq!(report["layers"], 33);
    // --set wins over the stored profile.
    let (_, report, _) = slice(dir.path(), &p, &["--set", "slice.layer_height=0.2"]);
    assert_eq!(report["layers"], 49);
    // --config replaces it, and says so.
    let toml = write(
        dir.path(),
        "c.toml",
        b"[slice]\nlayer_height = 0.25\nfirst_layer_height = 0.25\n",
    );
    let (err, report, _) = slice(dir.path(), &p, &["-c", toml.to_str().unwrap_or_default()]);
    assert_eq!(report["layers"], 40);
    assert!(err.contains("box.3mf: the PrusaSlicer 2.5.0+linux-x64-GTK3 profile stored in it is not used: --config"), "{err}");
    // -q keeps the terminal quiet.
    let (err, _, ok) = slice(dir.path(), &p, &["-q"]);
    assert!(ok && err.is_empty(), "{err}");
}

#[test]
fn an_orcaslicer_project_slices_as_the_same_prusaslicer_project() {
    let dir = temp_dir();
    let orca = orca_project(
        "box",
        &[
            (CUBE_10, "normal_part"),
            (([20.0, 0.0, 0.0], [30.0, 10.0, 30.0]), "modifier_part"),
        ],
        r#"{"layer_height": "0.3", "initial_layer_print_height": "0.3", "wall_loops": "4",
            "sparse_infill_density": "35%", "nozzle_diameter": ["0.4"], "from": "project"}"#,
    );
    let orca = write(dir.path(), "orca.3mf", &orca);
    let (err, orca_report, ok) = slice(dir.path(), &orca, &[]);
    assert!(ok, "{err}");
    assert!(err.contains("orca.3mf: slicing with the OrcaSlicer-2.1.0 profile (Metadata/project_settings.config, 6 settings)"), "{err}");
    assert!(
        err.contains("warning: orca.3mf: object \"box\": modifier \"part 2\" not printed"),
        "{err}"
    );
    let prusa = write(
        dir.path(),
        "prusa.3mf",
        &prusa_project("box", &[part(CUBE_10, "ModelPart", "box")], &[], PROFILE),
    );
    let (_, prusa_report, _) = slice(dir.path(), &prusa, &[]);
    // The modifier (30 mm tall) is not printed, and the renamed keys are read as PrusaSlicer's.
    assert_eq!(orca_report["layers"], 33);
    assert_eq!(orca_report["gcode"], prusa_report["gcode"]);
}

#[test]
fn only_model_parts_are_printed_and_unhonoured_settings_are_named() {
    let dir = temp_dir();
    let dense = Part {
        cuboid: ([5.0, 5.0, 0.0], [15.0, 15.0, 30.0]),
        kind: "ParameterModifier",
        name: "dense",
        settings: &[
            ("top_solid_min_thickness", "1"),
            ("perimeters", "6"),
            ("fill_density", "80%"),
            ("wipe_into_objects", "1"),
        ],
    };
    let parts = [
        part(CUBE_10, "ModelPart", "box"),
        dense,
        part(
            ([25.0, 0.0, 0.0], [30.0, 5.0, 20.0]),
            "SupportEnforcer",
            "here",
        ),
        part(
            ([0.0, 25.0, 0.0], [5.0, 30.0, 20.0]),
            "SupportBlocker",
            "not here",
        ),
    ];
    let p = write(
        dir.path(),
        "mods.3mf",
        &prusa_project("box", &parts, &[], PROFILE),
    );
    let (err, report, ok) = slice(dir.path(), &p, &[]);
    assert!(ok, "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning: ")).collect();
    assert_eq!(
        warnings,
        [
            "warning: mods.3mf: object \"box\": modifier \"dense\" not printed",
            "warning: mods.3mf: object \"box\": support enforcer \"here\" not printed and not \
             honoured: supports follow the [support] settings alone",
            "warning: mods.3mf: object \"box\": support blocker \"not here\" not printed and not \
             honoured: supports follow the [support] settings alone",
            // Keys conduit reads first, then one that changes the print, then the rest.
            "warning: mods.3mf: object \"box\": the settings of modifier \"dense\" are not \
             honoured: fill_density, perimeters, top_solid_min_thickness, wipe_into_objects",
        ]
    );
    // Only the 20 × 20 × 10 box: its layers, its footprint on the bed.
    assert_eq!(report["layers"], 33);
    let bbox = &report["objects"][0]["bbox"];
    let width =
        bbox["max"][0].as_f64().unwrap_or_default() - bbox["min"][0].as_f64().unwrap_or_default();
    assert!((width - 20.0).abs() < 1e-9, "{bbox}");
    let plain = write(
        dir.path(),
        "plain.3mf",
        &prusa_project("box", &[part(CUBE_10, "ModelPart", "box")], &[], PROFILE),
    );
    let (_, plain_report, _) = slice(dir.path(), &plain, &[]);
    assert_eq!(report["gcode"], plain_report["gcode"]);
}

#[test]
fn a_negative_volume_is_subtracted_like_the_same_hole_in_the_mesh() {
    let dir = temp_dir();
    let parts = [
        part(CUBE_10, "ModelPart", "box"),
        part(
            ([7.0, 7.0, -1.0], [13.0, 13.0, 11.0]),
            "NegativeVolume",
            "hole",
        ),
    ];
    let p = write(
        dir.path(),
        "hole.3mf",
        &prusa_project("box", &parts, &[], ""),
    );
    let (err, report, ok) = slice(dir.path(), &p, &[]);
    assert!(ok, "{err}");
    assert!(!err.contains("warning"), "{err}");
    let (_, stl_report, _) = slice(dir.path(), &sample("cube_with_hole.stl"), &[]);
    assert_eq!(report["layers"], stl_report["layers"]);
    let (a, b) = (filament(&report), filament(&stl_report));
    assert!(
        (a - b).abs() < 0.005 * b,
        "{a} mm with the negative volume, {b} mm with the hole"
    );
    // Nothing is extruded inside the hole (7..13 mm of the box, less the half width of a line).
    let gcode = std::fs::read_to_string(dir.path().join("out.gcode")).unwrap_or_default();
    let solid = write(
        dir.path(),
        "solid.3mf",
        &prusa_project("box", &parts[..1], &[], ""),
    );
    let (_, solid, _) = slice(dir.path(), &solid, &[]);
    let min = &report["objects"][0]["bbox"]["min"];
    let (x0, y0) = (
        min[0].as_f64().unwrap_or_default(),
        min[1].as_f64().unwrap_or_default(),
    );
    let inside =
        |x: f64, y: f64| (7.3..12.7).contains(&(x - x0)) && (7.3..12.7).contains(&(y - y0));
    assert_eq!(extrusions_inside(&gcode, &inside), 0);
    let solid_gcode = std::fs::read_to_string(dir.path().join("out.gcode")).unwrap_or_default();
    assert!(
        extrusions_inside(&solid_gcode, &inside) > 100,
        "the solid box is filled there"
    );
    assert_eq!(report["layers"], solid["layers"]);
    // The curved-layer walk does not subtract: it refuses.
    let (err, _, ok) = slice(dir.path(), &p, &["--curved", "clfff"]);
    assert!(!ok);
    assert!(err.contains("object 'box' has negative volumes, which curved-layer slicing (clfff) does not subtract"), "{err}");
}

#[test]
fn object_settings_apply_to_a_single_object_and_are_named_when_objects_differ() {
    let dir = temp_dir();
    let p = write(
        dir.path(),
        "one.3mf",
        &prusa_project(
            "box",
            &[part(CUBE_10, "ModelPart", "box")],
            &[("layer_height", "0.25")],
            PROFILE,
        ),
    );
    let (err, report, _) = slice(dir.path(), &p, &[]);
    assert!(
        err.contains("(Metadata/Slic3r_PE.config, 4 settings) with the objects' own settings"),
        "{err}"
    );
    assert_eq!(report["layers"], 40);
    // Two projects' objects together: the second's profile is not used, and its object's
    // settings are named.
    let q = write(
        dir.path(),
        "two.3mf",
        &prusa_project(
            "other",
            &[part(CUBE_10, "ModelPart", "other")],
            &[("perimeters", "2")],
            PROFILE,
        ),
    );
    let o = conduit([
        "slice".as_ref(),
        p.as_os_str(),
        q.as_os_str(),
        "-o".as_ref(),
        dir.path().join("two.gcode").as_os_str(),
    ]);
    assert!(o.status.success());
    assert!(
        stderr(&o).contains("two.3mf: the slicer settings stored in it are not used:"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_malformed_stored_profile_is_an_error_naming_part_and_line() {
    let dir = temp_dir();
    let cube = [part(CUBE_10, "ModelPart", "box")];
    for (profile, expected) in [
        (
            "layer_height = 0.3\nfill_density = lots\n",
            "error: bad.3mf: Metadata/Slic3r_PE.config:4: fill_density = \"lots\"",
        ),
        (
            "layer_height = 0.3\nperimeters\n",
            "Metadata/Slic3r_PE.config:4: slicer settings: expected `; key = value`",
        ),
    ] {
        let p = write(
            dir.path(),
            "bad.3mf",
            &prusa_project("box", &cube, &[], profile),
        );
        let (err, _, ok) = slice(dir.path(), &p, &[]);
        assert!(!ok);
        assert!(err.contains(expected), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // A volume past the end of the object's mesh.
    let config = "<config>\n<object id=\"1\">\n<volume firstid=\"0\" lastid=\"20\"/>\n</object>\n</config>\n";
    let bytes = package(&[
        (
            "3D/3dmodel.model",
            model("x", &mesh_object(1, &[CUBE_10]), "<item objectid=\"1\"/>"),
        ),
        ("Metadata/Slic3r_PE_model.config", config.to_owned()),
    ]);
    let (err, _, ok) = slice(dir.path(), &write(dir.path(), "range.3mf", &bytes), &[]);
    assert!(!ok);
    assert!(
        err.contains(
            "range.3mf: 3MF: /Metadata/Slic3r_PE_model.config:3: slicer settings: object 1: \
             volume ends at triangle 20, but the object's mesh has 12 triangles"
        ),
        "{err}"
    );
}

#[test]
fn prusaslicers_own_project_reads_as_prusaslicer_wrote_it() {
    let Some(corpus) = corpus() else {
        return;
    };
    let path = corpus.join("PrusaSlicer/tests/data/seam_test_object.3mf");
    let (scene, _, settings) = conduit::scene::load_scene_and_settings(&path, &Default::default())
        .expect("PrusaSlicer's test project reads");
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.objects[0].mesh.triangles.len(), 225_154);
    let profile = settings.profile.as_ref().expect("it carries a profile");
    assert_eq!(profile.writer.as_deref(), Some("PrusaSlicer 2.8.0-alpha3"));
    assert_eq!(profile.settings.len(), 339);
    let e = conduit::config::embedded::from_3mf(&settings)
        .expect("the profile converts")
        .expect("there is one");
    assert_eq!(e.config.slice.layer_height, 0.15);
    assert_eq!(e.config.slice.first_layer_height, 0.2);
    assert_eq!(e.config.slice.perimeters, 2);
    assert_eq!(e.config.slice.infill_density, 0.15);
}

/// `bytes` (a 3MF package) with the part `name` added.
fn with_part(bytes: Vec<u8>, name: &str, text: &str) -> Vec<u8> {
    let mut zip =
        zip::ZipWriter::new_append(std::io::Cursor::new(bytes)).expect("the package reopens");
    zip.start_file(name, zip::write::SimpleFileOptions::default())
        .expect("a zip entry starts");
    zip.write_all(text.as_bytes())
        .expect("a zip entry is written");
    zip.finish().expect("the zip is finished").into_inner()
}

/// The layer-slider events of a PrusaSlicer project (as PrusaSlicer 2.5 writes them), with
/// one above the 10 mm cube's top.
const LAYER_SLIDER: &str = r##"<?xml version="1.0" encoding="utf-8"?>
<custom_gcodes_per_print_z>
<code print_z="2.2" type="0" extruder="1" color="#FF0000" extra="" gcode="M600"/>
<code print_z="4" type="1" extruder="1" color="" extra="Insert magnets" gcode="M601"/>
<code print_z="6.3" type="4" extruder="1" color="" extra="M117 custom here&#10;G4 S1" gcode="M117 custom here"/>
<code print_z="50" type="1" extruder="1" color="" extra="never" gcode="M601"/>
<mode value="SingleExtruder"/>
</custom_gcodes_per_print_z>
"##;

/// The line of the event `tag` in `lines`, asserting that it comes once, followed by `then`,
/// at the start of the layer at `z` (`;Z:` after its `;LAYER_CHANGE`); returns the indices of
/// that `;LAYER_CHANGE` and of the tag.
fn event_line(lines: &[&str], tag: &str, z: &str, then: &[&str]) -> (usize, usize) {
    let at: Vec<usize> = (0..lines.len()).filter(|&i| lines[i] == tag).collect();
    assert_eq!(at.len(), 1, "{tag} once");
    let i = at[0];
    assert_eq!(&lines[i + 1..i + 1 + then.len()], then);
    let layer = lines[..i]
        .iter()
        .rposition(|l| *l == ";LAYER_CHANGE")
        .unwrap_or(0);
    assert_eq!(lines[layer + 1], format!(";Z:{z}"));
    (layer, i)
}

/// PrusaSlicer's colour changes, pauses and custom G-code by height come before the first
/// layer whose top reaches them, right after the move to it (PrusaSlicer 2.5 puts the same
/// project's events on the same layers), with the project's profile or with `--config`; one
/// above the print is named on the terminal; `conduit check` replays the file.
#[test]
fn layer_slider_events_come_where_prusaslicer_puts_them() {
    let dir = temp_dir();
    let bytes = prusa_project("box", &[part(CUBE_10, "ModelPart", "box")], &[], PROFILE);
    let p = write(
        dir.path(),
        "events.3mf",
        &with_part(
            bytes,
            "Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml",
            LAYER_SLIDER,
        ),
    );
    let toml = write(
        dir.path(),
        "c.toml",
        b"[printer]\ncolor_change_gcode = \"M600 ; T{color_change_extruder}\"\n\
          [slice]\nlayer_height = 0.3\nfirst_layer_height = 0.3\n",
    );
    for extra in [&[][..], &["-c", toml.to_str().unwrap_or_default()]] {
        let (err, _, ok) = slice(dir.path(), &p, extra);
        assert!(ok, "{err}");
        assert!(
            err.contains("events.3mf: 4 event(s) of PrusaSlicer's layer slider stored in it"),
            "{err}"
        );
        assert!(
            err.contains(
                "custom G-code by height above the print's last layer is not written (at 50 mm)"
            ),
            "{err}"
        );
        let gcode = std::fs::read_to_string(dir.path().join("out.gcode")).expect("G-code");
        let lines: Vec<&str> = gcode.lines().collect();
        // 0.3 mm layers: 2.2 mm comes before the layer up to 2.4 mm, 4 before 4.2, 6.3 before
        // 6.3 itself.
        let m600 = if extra.is_empty() {
            "M600"
        } else {
            "M600 ; T0"
        };
        for (tag, z, then) in [
            (";COLOR_CHANGE,T0,#FF0000", "2.4", &[m600][..]),
            (";PAUSE_PRINT", "4.2", &["M117 Insert magnets", "M601"]),
            (";CUSTOM_GCODE", "6.3", &["M117 custom here", "G4 S1"]),
        ] {
            let (layer, i) = event_line(&lines, tag, z, then);
            assert!(lines[layer..i].iter().any(|l| l.starts_with("G1 Z")));
            assert!(
                !lines[layer..i]
                    .iter()
                    .any(|l| l.contains(" E") && l.contains(" X"))
            );
        }
        assert!(!gcode.contains("never"));
        let check = conduit([
            "check",
            dir.path().join("out.gcode").to_str().unwrap_or_default(),
        ]);
        assert!(check.status.success(), "{}", stderr(&check));
    }
}

/// An OrcaSlicer project's layer-slider events (plate 1's; plate 2's are named as left out)
/// come where PrusaSlicer's would, its profile's `machine_pause_gcode` as the pause G-code.
#[test]
fn orcaslicer_plate_events_come_before_their_layers() {
    let dir = temp_dir();
    let bytes = orca_project(
        "box",
        &[(CUBE_10, "normal_part")],
        r#"{"layer_height": "0.3", "initial_layer_print_height": "0.3",
            "machine_pause_gcode": "PAUSE ; orca", "nozzle_diameter": ["0.4"]}"#,
    );
    let events = r##"<?xml version="1.0" encoding="utf-8"?>
<custom_gcodes_per_layer>
<plate>
<plate_info id="1"/>
<layer top_z="1" type="1" extruder="1" color="" extra="Insert nuts" gcode="M601"/>
<layer top_z="2.2" type="0" extruder="1" color="#00FF00" extra="" gcode="M600"/>
<mode value="SingleExtruder"/>
</plate>
<plate>
<plate_info id="2"/>
<layer top_z="3" type="1" extruder="1" color="" extra="never" gcode="M601"/>
<mode value="SingleExtruder"/>
</plate>
</custom_gcodes_per_layer>
"##;
    let p = write(
        dir.path(),
        "orca.3mf",
        &with_part(bytes, "Metadata/custom_gcode_per_layer.xml", events),
    );
    let (err, _, ok) = slice(dir.path(), &p, &[]);
    assert!(ok, "{err}");
    assert!(
        err.contains(
            "orca.3mf: 2 event(s) of OrcaSlicer's layer slider stored in it, plate 1 (colour changes"
        ),
        "{err}"
    );
    assert!(
        err.contains("the 1 custom G-code event(s) of plate 2 are left out"),
        "{err}"
    );
    let gcode = std::fs::read_to_string(dir.path().join("out.gcode")).expect("G-code");
    let lines: Vec<&str> = gcode.lines().collect();
    for (tag, z, then) in [
        (
            ";PAUSE_PRINT",
            "1.2",
            &["M117 Insert nuts", "PAUSE ; orca"][..],
        ),
        (";COLOR_CHANGE,T0,#00FF00", "2.4", &["M600"]),
    ] {
        event_line(&lines, tag, z, then);
    }
    assert!(!gcode.contains("never"));
    let check = conduit([
        "check",
        dir.path().join("out.gcode").to_str().unwrap_or_default(),
    ]);
    assert!(check.status.success(), "{}", stderr(&check));
}
