//! `conduit slice`: models → G-code through the planar pipeline, with a progress line per stage.

use super::{Failure, args::SliceArgs, config::resolve_for_model};
use anyhow::Context;
use conduit::circuit::Electronics;
use conduit::circuit::stage::pnp_records;
use conduit::circuit::{Circuit, Placement};
use conduit::pipeline::{Stage, slice_clfff, slice_scene_watched};
use conduit::scene::{OutputSet, Scene, load_scene_and_settings};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;

pub(crate) fn run(args: SliceArgs) -> Result<(), Failure> {
    let (scene, mut cfg) = models_and_config(&args.models, &args.config)?;
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
        return run_clfff(&args, &cfg, &scene, outputs);
    }
    let electronics = match (&args.circuit, &args.placement) {
        (Some(c), Some(p)) => Some(load_electronics(c, p)?),
        _ => None,
    };
    let bar = stage_bar();
    let routing = super::progress::routing_callback(&bar);
    let (gcode, _program, summary) = slice_scene_watched(
        &scene,
        &cfg,
        electronics.as_ref(),
        |stage| show_stage(&bar, stage),
        Some(&routing),
    )
    .with_context(|| format!("slicing {}", args.models[0].display()))?;
    bar.finish_and_clear();
    outputs.add(&args.output, &gcode)?;
    let mut written = vec![args.output.clone()];
    if let Some(e) = &electronics {
        let records = pnp_records(&e.circuit, &summary.parts);
        for (path, bytes) in pick_and_place_files(&args.output, &records)? {
            outputs.add(&path, &bytes)?;
            written.push(path);
        }
    }
    if let Some(report) = &args.report {
        let json = serde_json::to_vec_pretty(&summary).context("serialising the report")?;
        outputs.add(report, &json)?;
    }
    if let Some(r) = &summary.electronics {
        refuse_unbuilt_circuit(r, args.allow_unrouted, &args.output, "nothing was written")?;
    }
    outputs.commit()?;
    written.extend(args.report.clone());
    let total: f64 = summary.gcode.tools.iter().map(|t| t.filament_mm).sum();
    if args.json {
        super::print_json(&serde_json::json!({
            "outputs": super::paths(written.iter().map(|p| p.as_path())),
            "layers": summary.layers,
            "filament_mm": total,
            "estimated_time_s": summary.gcode.estimated_time_s,
            "report": summary,
        }))?;
        model_warnings(&args, &summary);
        if let Some(r) = &summary.electronics {
            routing_warnings(r);
        }
        for r in summary.curved.iter().flat_map(|c| &c.rejections) {
            warnln!("{r}");
        }
        return Ok(());
    }
    infoln!(
        "{}: {} layers, {:.0} mm filament, estimated {:.0} min",
        args.output.display(),
        summary.layers,
        total,
        summary.gcode.estimated_time_s / 60.0
    );
    model_warnings(&args, &summary);
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
        infoln!(
            "curved tops: {} region(s) curved, {} kept planar{slowed}",
            c.regions.len(),
            c.rejections.len()
        );
        for r in &c.rejections {
            warnln!("{r}");
        }
    }
    Ok(())
}

/// The slice's warnings about the models, naming the model when there is one.
fn model_warnings(args: &SliceArgs, summary: &conduit::pipeline::SliceSummary) {
    for w in summary.warnings() {
        match args.models.as_slice() {
            [one] => warnln!("{}: {w}", one.display()),
            _ => warnln!("{w}"),
        }
    }
}

/// `conduit slice --curved clfff`: one G-code file, or one per section with
/// `--split-sections` (`OUT.scaffold.gcode`, `OUT.buffer.gcode`, `OUT.model.gcode`).
fn run_clfff(
    args: &SliceArgs,
    cfg: &conduit::config::Config,
    scene: &Scene,
    mut outputs: OutputSet,
) -> Result<(), Failure> {
    let bar = stage_bar();
    let (files, summary) = slice_clfff(scene, cfg, |stage| {
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
    let r = &summary.clfff;
    let model_layers = r
        .layers
        .iter()
        .filter(|l| l.section == conduit::curved::clfff::Section::Model)
        .count();
    if args.json {
        let files: Vec<serde_json::Value> = written
            .iter()
            .map(|(path, file)| {
                serde_json::json!({
                    "file": path.display().to_string(),
                    "sections": file.sections.iter().map(|s| s.name()).collect::<Vec<_>>(),
                    "program_layers": file.program.layers.len(),
                    "filament_mm": file.stats.tools.iter().map(|t| t.filament_mm).sum::<f64>(),
                    "estimated_time_s": file.stats.estimated_time_s,
                })
            })
            .collect();
        super::print_json(&serde_json::json!({
            "outputs": super::paths(
                written.iter().map(|(p, _)| p.as_path()).chain(args.report.as_deref())
            ),
            "files": files,
            "scaffold_layers": r.scaffold.layers,
            "buffer_layers": r.layers.len() - model_layers,
            "curved_layers": model_layers,
            "collisions": r.collisions.count,
            "report": summary,
        }))?;
        for w in r.warnings() {
            warnln!("{w}");
        }
        return Ok(());
    }
    for (path, file) in written {
        let total: f64 = file.stats.tools.iter().map(|t| t.filament_mm).sum();
        let names: Vec<&str> = file.sections.iter().map(|s| s.name()).collect();
        infoln!(
            "{}: {} ({} program layers), {:.0} mm filament, estimated {:.0} min",
            path.display(),
            names.join(" + "),
            file.program.layers.len(),
            total,
            file.stats.estimated_time_s / 60.0
        );
    }
    let slowed = if r.z_speed_limited > 0 {
        format!(
            ", {} moves slowed for curved.max_z_speed",
            r.z_speed_limited
        )
    } else {
        String::new()
    };
    infoln!(
        "clfff: {} scaffold layers, {} buffer layer(s), {} curved layers, {} collision(s){slowed}",
        r.scaffold.layers,
        r.layers.len() - model_layers,
        model_layers,
        r.collisions.count
    );
    for w in r.warnings() {
        warnln!("{w}");
    }
    Ok(())
}

/// The pick-and-place files beside `output` (`OUT.gcode`): `OUT.pos` (KiCad's ASCII table,
/// what OpenPnP's KiCad importer reads), `OUT-pos.csv` (KiCad's CSV) and `OUT.board.xml`
/// (an OpenPnP board), with their bytes.
pub(crate) fn pick_and_place_files(
    output: &std::path::Path,
    records: &[conduit_pnp::PlacementRecord],
) -> anyhow::Result<Vec<(std::path::PathBuf, Vec<u8>)>> {
    let stem = output
        .file_stem()
        .map_or_else(|| "board".to_owned(), |s| s.to_string_lossy().into_owned());
    let beside = |name: String| output.with_file_name(name);
    let mut files = Vec::new();
    let pos = output.with_extension("pos");
    let mut bytes = Vec::new();
    conduit_pnp::write_kicad_ascii(records, &mut bytes)
        .with_context(|| format!("{}: cannot write positions", pos.display()))?;
    files.push((pos, bytes));
    let csv = beside(format!("{stem}-pos.csv"));
    let mut bytes = Vec::new();
    conduit_pnp::write_kicad_csv(records, &mut bytes)
        .with_context(|| format!("{}: cannot write positions", csv.display()))?;
    files.push((csv, bytes));
    let xml = beside(format!("{stem}.board.xml"));
    let mut bytes = Vec::new();
    conduit_pnp::write_openpnp_board(&stem, records, &mut bytes)
        .with_context(|| format!("{}: cannot write OpenPnP board", xml.display()))?;
    files.push((xml, bytes));
    Ok(files)
}

/// The routing summary line (after `lead`) and the report's warnings, on stderr. What was not
/// built as asked is [`refuse_unbuilt_circuit`]'s to say.
pub(crate) fn print_routing(r: &conduit::circuit::ElectronicsReport, lead: &str) {
    infoln!(
        "{lead}{} parts, {} of {} wires routed ({:.1} mm of trace, {:.1} mm straight)",
        r.parts.len(),
        r.routed,
        r.routed + r.unrouted,
        r.total_length,
        r.total_lower_bound
    );
    routing_warnings(r);
}

/// The routing report's warnings and one line per wire that could not be routed, on stderr.
pub(crate) fn routing_warnings(r: &conduit::circuit::ElectronicsReport) {
    for w in &r.warnings {
        warnln!("{w}");
    }
}

/// A circuit job that did not build the circuit as asked (a wire not routed, a part outside
/// the solid or colliding, a placement that places nothing) fails: each problem is printed as
/// an `error:` line and the run exits 1 with `consequence` said about `output`. With
/// `allow` (`--allow-unrouted`) the problems are warnings and the run goes on.
pub(crate) fn refuse_unbuilt_circuit(
    r: &conduit::circuit::ElectronicsReport,
    allow: bool,
    output: &std::path::Path,
    consequence: &str,
) -> Result<(), Failure> {
    if conduit::interrupt::requested() {
        // The wires Ctrl-C left unrouted are no problem of the circuit's.
        return Err(Failure::Work(anyhow::anyhow!(
            "{}: {}",
            output.display(),
            conduit::interrupt::error()
        )));
    }
    let failures = r.failures();
    if failures.is_empty() {
        return Ok(());
    }
    for f in &failures {
        if allow {
            warnln!("{f}");
        } else {
            errorln!("{f}");
        }
    }
    if allow {
        return Ok(());
    }
    errorln!(
        "{}: the circuit was not built as asked ({} problem(s) above); {consequence} \
         (--allow-unrouted accepts it)",
        output.display(),
        failures.len()
    );
    Err(Failure::Reported)
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

/// The circuit and its placement, checked against each other here so that a placement naming
/// parts, nets or pins the circuit lacks is reported against the placement file.
pub(crate) fn load_electronics(
    circuit: &std::path::Path,
    placement: &std::path::Path,
) -> Result<Electronics, Failure> {
    let c = Circuit::load(circuit).map_err(anyhow::Error::from)?;
    let p = Placement::load(placement).map_err(anyhow::Error::from)?;
    p.validate(&c)
        .with_context(|| placement.display().to_string())?;
    Ok(Electronics {
        circuit: c,
        placement: p,
    })
}

/// One scene of every object of `models`, in order; reader warnings go to stderr.
pub(crate) fn load_models(models: &[std::path::PathBuf]) -> Result<Scene, Failure> {
    Ok(load_models_and_settings(models)?.0)
}

/// The scene of `models` and the job's config: `src` (`-c`, `--set`) over the profile a slicer
/// stored in the first model that has one ([`resolve_for_model`]).
pub(crate) fn models_and_config(
    models: &[std::path::PathBuf],
    src: &super::args::ConfigSource,
) -> Result<(Scene, conduit::config::Config), Failure> {
    let (scene, stored) = load_models_and_settings(models)?;
    let cfg = match &stored {
        Some((path, settings)) => resolve_for_model(src, path, settings)?,
        None => super::config::resolve(src)?,
    };
    Ok((scene, cfg))
}

/// [`load_models`], with the settings a slicer stored in the first model that has them (a
/// 3MF's) and that model's path; a later model's stored profile is said to be unused.
fn load_models_and_settings(
    models: &[std::path::PathBuf],
) -> Result<
    (
        Scene,
        Option<(std::path::PathBuf, conduit_3mf::SlicerSettings)>,
    ),
    Failure,
> {
    let mut scene = Scene::default();
    let mut stored: Option<(std::path::PathBuf, conduit_3mf::SlicerSettings)> = None;
    for path in models {
        let (s, warnings, settings) =
            load_scene_and_settings(path, &super::load_options()).map_err(anyhow::Error::from)?;
        for w in warnings {
            warnln!("{}: {w}", path.display());
        }
        scene.objects.extend(s.objects);
        match (&stored, settings.is_empty()) {
            (_, true) => {}
            (None, false) => stored = Some((path.clone(), settings)),
            (Some((first, _)), false) => warnln!(
                "{}: the slicer settings stored in it are not used: {} gives the job's",
                path.display(),
                first.display()
            ),
        }
    }
    Ok((scene, stored))
}

/// A bar over the pipeline's stages, hidden when stderr is not a terminal or with `--quiet`.
fn stage_bar() -> ProgressBar {
    if super::quiet() || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(Stage::ALL.len() as u64);
    stage_style(&bar);
    bar
}

/// Styles `bar` as the stage bar (the router restyles it while it routes).
fn stage_style(bar: &ProgressBar) {
    if let Ok(style) = ProgressStyle::with_template("slicing [{bar:20}] {msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
}

/// Shows `stage` on the stage bar (routing shows the router's bar).
fn show_stage(bar: &ProgressBar, stage: Stage) {
    if stage == Stage::Route {
        // The router's callback moves the bar from here on.
        bar.set_message("");
        super::progress::routing_style(bar);
        bar.update(|state| {
            state.set_len(0);
            state.set_pos(0);
        });
        return;
    }
    stage_style(bar);
    bar.set_length(Stage::ALL.len() as u64);
    bar.set_position(stage as u64);
    bar.set_message(stage.name());
}
