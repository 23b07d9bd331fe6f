//! `conduit view`: G-code files (with the model and circuit when given) drawn in 3D in one
//! self-contained HTML page.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use super::{Failure, args::ViewArgs, config::resolve};
use anyhow::Context;
use conduit::check::Frame;
use conduit::pipeline::{model_bboxes, place_on_bed_with_offsets};
use conduit::scene::{LoadOptions, load_scene, write_atomically};
use conduit::view::{ViewData, circuit_of, job_of, mesh_views, page};

pub(crate) fn run(args: ViewArgs) -> Result<(), Failure> {
    let cfg = resolve(&args.config)?;
    let params = cfg.check_params();
    let mut jobs = Vec::with_capacity(args.files.len());
    let mut first_gcode = None;
    for file in &args.files {
        let bytes = super::check::read_gcode_file(file)?;
        let gcode = conduit_gcode::parse(&bytes).with_context(|| format!("{}", file.display()))?;
        let job = job_of(&file_name(file), &gcode, &params).ok_or_else(|| {
            anyhow::anyhow!("{}: no move with X or Y: nothing to show", file.display())
        })?;
        jobs.push(job);
        if first_gcode.is_none() {
            first_gcode = Some(gcode);
        }
    }

    let mut models = Vec::new();
    let mut frame = Frame::Printed;
    if let Some(model) = &args.model {
        let (scene, _) = load_scene(model, &LoadOptions::default())
            .with_context(|| format!("{}", model.display()))?;
        let (meshes, offsets) = place_on_bed_with_offsets(&scene, &cfg);
        models = mesh_views(&meshes);
        frame = Frame::Objects {
            bboxes: model_bboxes(&scene),
            offsets,
        };
    }

    let mut circuit = None;
    if let (Some(c), Some(p), Some(gcode)) = (&args.circuit, &args.placement, &first_gcode) {
        let e = super::slice::load_electronics(c, p)?;
        circuit = Some(
            circuit_of(gcode, params.flavor, &e, &frame, &cfg.electronics_params())
                .with_context(|| format!("{}", p.display()))?,
        );
    }

    let data = ViewData {
        jobs,
        models,
        circuit,
        studio: None,
    };
    let title = format!(
        "{} — conduit view",
        data.jobs
            .iter()
            .map(|j| j.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let html = page(&data, &title).context("serialising the view")?;
    let out = output_path(&args);
    write_atomically(&out, |f| f.write_all(html.as_bytes()))
        .with_context(|| format!("{}", out.display()))?;

    let layers: usize = data.jobs.iter().map(|j| j.layers.len()).sum();
    let segments: usize = data
        .jobs
        .iter()
        .flat_map(|j| &j.groups)
        .filter(|g| !g.travel)
        .map(|g| g.segments)
        .sum();
    if args.json {
        super::print_json(&serde_json::json!({
            "output": out.display().to_string(),
            "bytes": html.len(),
            "jobs": data.jobs.iter().map(|j| serde_json::json!({
                "name": j.name,
                "layers": j.layers.len(),
                "extrusion_segments": j.groups.iter().filter(|g| !g.travel).map(|g| g.segments).sum::<usize>(),
                "travel_segments": j.groups.iter().filter(|g| g.travel).map(|g| g.segments).sum::<usize>(),
                "events": j.events.len(),
            })).collect::<Vec<_>>(),
            "model_triangles": data.models.iter().map(|m| m.triangles).sum::<usize>(),
            "unrouted_wires": data.circuit.as_ref().map(|c| c.unrouted.len()),
        }))?;
    } else {
        infoln!(
            "{}: {} file(s), {layers} layers, {segments} extrusion segments, {:.1} MB",
            out.display(),
            data.jobs.len(),
            html.len() as f64 / 1e6
        );
    }
    if args.open {
        open_in_browser(&out);
    }
    Ok(())
}

/// The file name of `path` (the whole path when it has none).
pub(crate) fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// `-o`, else the first file with `.html` for its extension.
fn output_path(args: &ViewArgs) -> PathBuf {
    args.output.clone().unwrap_or_else(|| {
        args.files
            .first()
            .map_or_else(|| PathBuf::from("view.html"), |f| f.with_extension("html"))
    })
}

/// Opens `page` with the desktop's opener; says so when there is none (the page is written).
pub(crate) fn open_in_browser(page: &Path) {
    open_url(&page.to_string_lossy());
}

/// Opens `target` (a path or URL) with the desktop's opener; warns when there is none.
pub(crate) fn open_url(target: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(target_os = "windows") {
        "explorer"
    } else {
        "xdg-open"
    };
    if let Err(e) = std::process::Command::new(opener)
        .arg(target)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
    {
        warnln!("could not open {target} with {opener} ({e}); open it in a browser");
    }
}
