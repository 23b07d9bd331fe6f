//! `conduit info`: what is in each file, as text or JSON.

use super::{Failure, args::InfoArgs};
use conduit::geom::{BoundingBox, Point3, Tolerances};
use conduit::mesh::{Mesh, RepairReport, TopologyReport};
use conduit::scene::{Content, LoadedFile, MeshDetails, Scene, load};
use rayon::prelude::*;
use serde::Serialize;
use serde_json::{Value, json};
use std::io::Write;

/// Facts about one mesh object.
#[derive(Debug, Serialize)]
struct ObjectInfo {
    name: String,
    triangles: usize,
    vertices: usize,
    volume_mm3: f64,
    area_mm2: f64,
    bbox: Option<BoundingBox>,
    topology: TopologyReport,
    #[serde(skip_serializing_if = "Option::is_none")]
    repair: Option<RepairFindings>,
}

/// What a trial repair would change, and the result.
#[derive(Debug, Serialize)]
struct RepairFindings {
    #[serde(flatten)]
    report: RepairReport,
    closed_after: bool,
    volume_after_mm3: f64,
}

pub(crate) fn run(args: InfoArgs) -> Result<(), Failure> {
    let opts = super::load_options();
    let loaded: Vec<Result<(Value, Vec<String>), String>> = args
        .files
        .par_iter()
        .map(|path| {
            load(path, &opts)
                .map(|file| (describe(&file, !args.no_repair), file.warnings))
                .map_err(|e| format!("{e}"))
        })
        .collect();
    // The readers' warnings go to stderr as well, in the order of the files.
    for (r, path) in loaded.iter().zip(&args.files) {
        for w in r.iter().flat_map(|(_, w)| w) {
            warnln!("{}: {w}", path.display());
        }
    }
    let reports: Vec<Result<Value, String>> =
        loaded.into_iter().map(|r| r.map(|(v, _)| v)).collect();
    let failed = reports.iter().filter(|r| r.is_err()).count();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        let array: Vec<Value> = reports
            .iter()
            .zip(&args.files)
            .map(|(r, path)| match r {
                Ok(v) => v.clone(),
                Err(e) => json!({ "file": path.display().to_string(), "error": e }),
            })
            .collect();
        serde_json::to_writer_pretty(&mut out, &array).map_err(|e| Failure::stdout(e.into()))?;
        writeln!(out).map_err(Failure::stdout)?;
    } else {
        for r in reports.iter().flatten() {
            write_text(&mut out, r, 0).map_err(Failure::stdout)?;
            writeln!(out).map_err(Failure::stdout)?;
        }
    }
    out.flush().map_err(Failure::stdout)?;
    for e in reports.iter().filter_map(|r| r.as_ref().err()) {
        errorln!("{e}");
    }
    if failed > 0 {
        Err(Failure::Reported)
    } else {
        Ok(())
    }
}

/// The JSON description of a loaded file.
fn describe(file: &LoadedFile, trial_repair: bool) -> Value {
    let mut v = json!({
        "file": file.path.display().to_string(),
        "format": file.kind,
    });
    let body = match &file.content {
        Content::Mesh { scene, details } => describe_scene(scene, details, trial_repair),
        Content::PointCloud(cloud) => {
            let pts: Vec<Point3> = cloud
                .points
                .iter()
                .map(|p| Point3::new(p[0], p[1], p[2]))
                .collect();
            json!({
                "points": cloud.points.len(),
                "bbox": BoundingBox::from_points(&pts),
                "normals": cloud.normals.is_some(),
                "colors": cloud.colors.is_some(),
            })
        }
        Content::Eagle(doc) => describe_eagle(doc),
        Content::Kicad(doc) => describe_kicad(doc, &file.path),
        Content::Gcode(summary) => json!({ "gcode": summary }),
        Content::Design(design) => json!({
            "width_mm": design.width_mm,
            "height_mm": design.height_mm,
            "paths": design.paths.len(),
            "closed_paths": design.paths.iter().filter(|p| p.closed).count(),
            "points": design.paths.iter().map(|p| p.points.len()).sum::<usize>(),
        }),
    };
    merge(&mut v, body);
    if !file.warnings.is_empty() {
        v["warnings"] = json!(file.warnings);
    }
    v
}

fn merge(into: &mut Value, from: Value) {
    if let (Value::Object(a), Value::Object(b)) = (into, from) {
        a.extend(b);
    }
}

fn describe_scene(scene: &Scene, details: &MeshDetails, trial_repair: bool) -> Value {
    let objects: Vec<ObjectInfo> = scene
        .objects
        .iter()
        .map(|o| object_info(&o.name, &o.mesh, trial_repair))
        .collect();
    let bbox = objects
        .iter()
        .filter_map(|o| o.bbox)
        .reduce(|a, b| a.union(&b));
    let mut v = json!({
        "triangles": scene.triangle_count(),
        "vertices": scene.objects.iter().map(|o| o.mesh.vertices.len()).sum::<usize>(),
        "volume_mm3": objects.iter().map(|o| o.volume_mm3).sum::<f64>(),
        "bbox": bbox,
        "objects": objects,
    });
    let details = json!(details);
    if !details.is_null() {
        v["details"] = details;
    }
    v
}

fn object_info(name: &str, mesh: &Mesh, trial_repair: bool) -> ObjectInfo {
    let repair = trial_repair.then(|| {
        let mut fixed = mesh.clone();
        let report = fixed.repair(&Tolerances::default());
        RepairFindings {
            report,
            closed_after: fixed.topology().closed,
            volume_after_mm3: fixed.signed_volume(),
        }
    });
    ObjectInfo {
        name: name.to_string(),
        triangles: mesh.triangles.len(),
        vertices: mesh.vertices.len(),
        volume_mm3: mesh.signed_volume(),
        area_mm2: mesh.area(),
        bbox: mesh.bounding_box(),
        topology: mesh.topology(),
        repair,
    }
}

fn describe_eagle(doc: &conduit_eagle::Document) -> Value {
    use conduit_eagle::Document;
    match doc {
        Document::Schematic(s) => {
            let packages: std::collections::BTreeSet<(&str, &str)> = s
                .parts
                .iter()
                .filter_map(|p| {
                    p.package
                        .as_ref()
                        .map(|k| (k.library.as_str(), k.name.as_str()))
                })
                .collect();
            let pins: usize = s.parts.iter().map(|p| p.pin_pads.len()).sum();
            let pin_pads: usize = s
                .parts
                .iter()
                .flat_map(|p| p.pin_pads.values())
                .map(Vec::len)
                .sum();
            let multi: usize = s
                .parts
                .iter()
                .flat_map(|p| p.pin_pads.values())
                .filter(|v| v.len() > 1)
                .count();
            let circuit = conduit::circuit::Circuit::from_schematic(s);
            let dropped: Vec<Value> = s
                .dropped_parts
                .iter()
                .map(|name| {
                    json!({
                        "name": name,
                        "reason": "no package: a supply symbol, frame or other part with \
                                   nothing to place",
                    })
                })
                .collect();
            json!({
                "eagle": "schematic",
                "version": s.version,
                "parts": circuit.parts.len(),
                "dropped_parts": dropped,
                "packages": packages.len(),
                "nets": circuit.nets.len(),
                "connected_pins": pins,
                "pin_pad_connections": pin_pads,
                "pins_on_several_pads": multi,
                "circuit": describe_circuit(&circuit),
            })
        }
        Document::Board(b) => {
            let packages: std::collections::BTreeSet<(&str, &str)> = b
                .elements
                .iter()
                .map(|e| (e.package.library.as_str(), e.package.name.as_str()))
                .collect();
            let circuit = conduit::circuit::Circuit::from_board(b);
            json!({
                "eagle": "board",
                "version": b.version,
                "elements": b.elements.len(),
                "bottom_elements": b.elements.iter().filter(|e| e.rotation.mirror).count(),
                "packages": packages.len(),
                "pads": b.elements.iter().map(|e| e.package.pads.len()).sum::<usize>(),
                "nets": circuit.nets.len(),
                "circuit": describe_circuit(&circuit),
            })
        }
        Document::Library => json!({ "eagle": "library" }),
    }
}

/// A KiCad file: what it holds, and the circuit conduit makes of it (a schematic's or netlist
/// export's with the pads of the board beside it, or why it has none).
fn describe_kicad(doc: &conduit_kicad::Document, path: &std::path::Path) -> Value {
    use conduit_kicad::Document;
    let mut v = match doc {
        Document::Pcb(b) => {
            let footprints: std::collections::BTreeSet<&str> =
                b.footprints.iter().map(|f| f.name.as_str()).collect();
            json!({
                "kicad": "board",
                "version": b.version,
                "footprints": b.footprints.len(),
                "bottom_footprints": b.footprints.iter().filter(|f| f.bottom).count(),
                "footprint_kinds": footprints.len(),
                "pads": b.footprints.iter().map(|f| f.pads.len()).sum::<usize>(),
                "outline_shapes": b.outline.len(),
            })
        }
        Document::Schematic(s) => json!({
            "kicad": "schematic",
            "version": s.version,
            "sheet_instances": s.sheet_instances,
            "symbols_on_board": s.parts.len(),
            "pins": s.parts.iter().map(|p| p.pins.len()).sum::<usize>(),
            "nets_with_pins": s.nets.len(),
        }),
        Document::NetFile(n) => json!({
            "kicad": "netlist",
            "components": n.components.len(),
            "nets": n.nets.len(),
        }),
    };
    match conduit::circuit::Circuit::from_kicad(doc, path) {
        Ok(circuit) => {
            v["parts"] = json!(circuit.parts.len());
            v["nets"] = json!(circuit.nets.len());
            v["circuit"] = describe_circuit(&circuit);
        }
        Err(e) => v["circuit_error"] = json!(e.to_string()),
    }
    v
}

/// What a circuit holds, as conduit places and routes it: per part its value, package, pads
/// (package frame: centre, rotation, size, SMD or through-hole) and the size of the pads'
/// bounding box; per net its pins (`PART.PAD`). A net with one pin is kept: a placement may wire
/// it to a terminal.
fn describe_circuit(circuit: &conduit::circuit::Circuit) -> Value {
    let parts: Vec<Value> = circuit
        .parts
        .iter()
        .map(|p| {
            let pads: Vec<Value> = p
                .pads
                .iter()
                .map(|pad| {
                    let (w, h) = pad.shape.size();
                    json!({
                        "name": pad.name,
                        "at": [round(pad.x), round(pad.y)],
                        "rotation_deg": round(pad.rotation_deg),
                        "size": [round(w), round(h)],
                        "kind": if pad.smd { "smd" } else { "through-hole" },
                    })
                })
                .collect();
            let size = p.pad_extent().map_or(Value::Null, |[x0, y0, x1, y1]| {
                json!([round(x1 - x0), round(y1 - y0)])
            });
            json!({
                "name": p.name,
                "value": p.value,
                "package": p.package,
                "pads_size": size,
                "pads": pads,
            })
        })
        .collect();
    let nets: Vec<Value> = circuit
        .nets
        .iter()
        .map(|n| {
            json!({
                "name": n.name,
                "pins": n.pins.iter().map(ToString::to_string).collect::<Vec<_>>(),
            })
        })
        .collect();
    json!({ "parts": parts, "nets": nets })
}

/// `v` rounded to the micrometre, for display.
fn round(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0
}

/// Prints a JSON value as indented `key: value` lines.
fn write_text(out: &mut impl Write, v: &Value, indent: usize) -> std::io::Result<()> {
    let pad = "  ".repeat(indent);
    match v {
        Value::Object(map) => {
            for (k, val) in map {
                match val {
                    Value::Object(m) if !m.is_empty() => {
                        writeln!(out, "{pad}{k}:")?;
                        write_text(out, val, indent + 1)?;
                    }
                    Value::Array(a) if a.iter().any(|x| x.is_object()) => {
                        for (i, item) in a.iter().enumerate() {
                            writeln!(out, "{pad}{k}[{i}]:")?;
                            write_text(out, item, indent + 1)?;
                        }
                    }
                    _ => writeln!(out, "{pad}{k}: {}", scalar(val))?,
                }
            }
            Ok(())
        }
        other => writeln!(out, "{pad}{}", scalar(other)),
    }
}

fn scalar(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Number(n) => match n.as_f64() {
            Some(f) if n.is_f64() => format!("{}", (f * 1000.0).round() / 1000.0),
            _ => n.to_string(),
        },
        Value::Array(a) => a.iter().map(scalar).collect::<Vec<_>>().join(", "),
        Value::Null => "-".into(),
        other => other.to_string(),
    }
}
