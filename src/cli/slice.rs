//! `conduit slice`: models → G-code through the planar pipeline, with a progress line per stage.

use super::{Failure, args::SliceArgs, config::resolve};
use anyhow::Context;
use conduit::circuit::Electronics;
use conduit::circuit::stage::pnp_records;
use conduit::circuit::{Circuit, Placement};
use conduit::pipeline::{Stage, slice_clfff, slice_scene_with};
use conduit::scene::{OutputSet, Scene, load_scene};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;

pub(crate) fn run(args: SliceArgs) -> Result<(), Failure> {
    let mut cfg = resolve(&args.config)?;
    match args.curved.as_deref() {
        Some("tops") => cfg.curved.mode = conduit::config::CurvedMode::Tops,
        Some("clfff") => cfg.curved.mode = conduit::config::CurvedMode::Clfff,
        Some(_) => cfg.curved.mode = conduit::config::CurvedMode::Off,
        None => {}
    }
    if args.split_sections {
        cfg.curved.split_sections = true;
    }
    let mut outputs = inputs(&args);
    outputs.check(&args.output)?;
    if let Some(report) = &args.report {
        outputs.check(report)?;
    }
    if cfg.curved.mode == conduit::config::CurvedMode::Clfff {
        if args.circuit.is_some() {
            return Err(anyhow::anyhow!(
                "--curved clfff prints a shell without a circuit; leave out --circuit"
            )
            .into());
        }
        return run_clfff(&args, &cfg, outputs);
    }
    let scene = load_models(&args.models)?;
    let electronics = match (&args.circuit, &args.placement) {
        (Some(c), Some(p)) => Some(Electronics {
            circuit: Circuit::load(c).map_err(anyhow::Error::from)?,
            placement: Placement::load(p).map_err(anyhow::Error::from)?,
        }),
        _ => None,
    };
    let bar = stage_bar();
    let (gcode, _program, summary) =
        slice_scene_with(&scene, &cfg, electronics.as_ref(), |stage| {
            bar.set_position(stage as u64);
            bar.set_message(stage.name());
        })
        .with_context(|| format!("slicing {}", args.models[0].display()))?;
    bar.finish_and_clear();
    outputs.add(&args.output, &gcode)?;
    if let Some(e) = &electronics {
        let records = pnp_records(&e.circuit, &summary.parts);
        let pos = args.output.with_extension("pos");
        let mut bytes = Vec::new();
        conduit_pnp::write_kicad_pos(&records, &mut bytes)
            .with_context(|| format!("{}: cannot write positions", pos.display()))?;
        outputs.add(&pos, &bytes)?;
        let xml = args.output.with_extension("openpnp.xml");
        let name = args
            .output
            .file_stem()
            .map_or_else(|| "board".to_owned(), |s| s.to_string_lossy().into_owned());
        let mut bytes = Vec::new();
        conduit_pnp::write_openpnp_board(&name, &records, &mut bytes)
            .with_context(|| format!("{}: cannot write OpenPnP board", xml.display()))?;
        outputs.add(&xml, &bytes)?;
    }
    if let Some(report) = &args.report {
        let json = serde_json::to_vec_pretty(&summary).context("serialising the report")?;
        outputs.add(report, &json)?;
    }
    outputs.commit()?;
    let total: f64 = summary.gcode.tools.iter().map(|t| t.filament_mm).sum();
    eprintln!(
        "{}: {} layers, {:.0} mm filament, estimated {:.0} min",
        args.output.display(),
        summary.layers,
        total,
        summary.gcode.estimated_time_s / 60.0
    );
    if let Some(r) = &summary.electronics {
        print_routing(r, "");
    }
    if let Some(c) = &summary.curved {
        let slowed = if c.z_speed_limited > 0 {
            format!(
                ", {} moves slowed for curved.max_z_speed",
                c.z_speed_limited
            )
        } else {
            String::new()
        };
        eprintln!(
            "curved tops: {} region(s) curved, {} kept planar{slowed}",
            c.regions.len(),
            c.rejections.len()
        );
        for r in &c.rejections {
            eprintln!("warning: {r}");
        }
    }
    Ok(())
}

/// `conduit slice --curved clfff`: one G-code file, or one per section with
/// `--split-sections` (`OUT.scaffold.gcode`, `OUT.buffer.gcode`, `OUT.model.gcode`).
fn run_clfff(
    args: &SliceArgs,
    cfg: &conduit::config::Config,
    mut outputs: OutputSet,
) -> Result<(), Failure> {
    let scene = load_models(&args.models)?;
    let bar = stage_bar();
    let (files, summary) = slice_clfff(&scene, cfg, |stage| {
        bar.set_position(stage as u64);
        bar.set_message(stage.name());
    })
    .with_context(|| format!("slicing {}", args.models[0].display()))?;
    bar.finish_and_clear();
    let split = cfg.curved.split_sections;
    let mut written = Vec::with_capacity(files.len());
    for file in &files {
        let path = match (split, file.sections.first()) {
            (true, Some(s)) => s.file_name(&args.output),
            _ => args.output.clone(),
        };
        outputs.add(&path, &file.gcode)?;
        written.push((path, file));
    }
    let mut summary = summary;
    if split {
        for s in &mut summary.clfff.sections {
            s.file = Some(s.section.file_name(&args.output).display().to_string());
        }
    }
    if let Some(report) = &args.report {
        let json = serde_json::to_vec_pretty(&summary).context("serialising the report")?;
        outputs.add(report, &json)?;
    }
    outputs.commit()?;
    for (path, file) in written {
        let total: f64 = file.stats.tools.iter().map(|t| t.filament_mm).sum();
        let names: Vec<&str> = file.sections.iter().map(|s| s.name()).collect();
        eprintln!(
            "{}: {} ({} program layers), {:.0} mm filament, estimated {:.0} min",
            path.display(),
            names.join(" + "),
            file.program.layers.len(),
            total,
            file.stats.estimated_time_s / 60.0
        );
    }
    let r = &summary.clfff;
    let model_layers = r
        .layers
        .iter()
        .filter(|l| l.section == conduit::curved::clfff::Section::Model)
        .count();
    let slowed = if r.z_speed_limited > 0 {
        format!(
            ", {} moves slowed for curved.max_z_speed",
            r.z_speed_limited
        )
    } else {
        String::new()
    };
    eprintln!(
        "clfff: {} scaffold layers, {} buffer layer(s), {} curved layers, {} collision(s){slowed}",
        r.scaffold.layers,
        r.layers.len() - model_layers,
        model_layers,
        r.collisions.count
    );
    for w in r.warnings() {
        eprintln!("warning: {w}");
    }
    Ok(())
}

/// The routing summary line (after `lead`), the report's warnings and one line per wire that
/// could not be routed, on stderr.
pub(crate) fn print_routing(r: &conduit::circuit::ElectronicsReport, lead: &str) {
    eprintln!(
        "{lead}{} parts, {} of {} wires routed ({:.1} mm of trace, {:.1} mm straight)",
        r.parts.len(),
        r.routed,
        r.routed + r.unrouted,
        r.total_length,
        r.total_lower_bound
    );
    for w in &r.warnings {
        eprintln!("warning: {w}");
    }
    for w in r.wires.iter().filter(|w| !w.routed) {
        eprintln!(
            "warning: net {} could not be routed ({} to {})",
            w.net, w.from, w.to
        );
    }
}

/// The output set of a slice: none of its outputs may be one of the run's input files.
fn inputs(args: &SliceArgs) -> OutputSet {
    let mut set = OutputSet::new(&args.models);
    for p in [&args.circuit, &args.placement, &args.config.config]
        .into_iter()
        .flatten()
    {
        set.input(p);
    }
    set
}

/// One scene of every object of `models`, in order; reader warnings go to stderr.
pub(crate) fn load_models(models: &[std::path::PathBuf]) -> Result<Scene, Failure> {
    let mut scene = Scene::default();
    for path in models {
        let (s, warnings) =
            load_scene(path, &super::load_options()).map_err(anyhow::Error::from)?;
        for w in warnings {
            eprintln!("warning: {}: {w}", path.display());
        }
        scene.objects.extend(s.objects);
    }
    Ok(scene)
}

/// A bar over the pipeline's stages, hidden when stderr is not a terminal.
fn stage_bar() -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(Stage::ALL.len() as u64);
    if let Ok(style) = ProgressStyle::with_template("slicing [{bar:20}] {msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}
