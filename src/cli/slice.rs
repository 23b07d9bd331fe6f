//! `conduit slice`: models → G-code through the planar pipeline, with a progress line per stage.

use super::{Failure, args::SliceArgs, config::resolve};
use anyhow::Context;
use conduit::pipeline::{Stage, slice_scene};
use conduit::scene::{LoadOptions, Scene, load_scene, write_atomically};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::{IsTerminal, Write};

pub(crate) fn run(args: SliceArgs) -> Result<(), Failure> {
    let cfg = resolve(&args.config)?;
    let mut scene = Scene::default();
    for path in &args.models {
        let (s, warnings) =
            load_scene(path, &LoadOptions::default()).map_err(anyhow::Error::from)?;
        for w in warnings {
            eprintln!("warning: {}: {w}", path.display());
        }
        scene.objects.extend(s.objects);
    }
    let bar = stage_bar();
    let (gcode, _program, summary) = slice_scene(&scene, &cfg, |stage| {
        bar.set_position(stage as u64);
        bar.set_message(stage.name());
    })
    .with_context(|| format!("slicing {}", args.models[0].display()))?;
    bar.finish_and_clear();
    write_atomically(&args.output, |f| f.write_all(&gcode))
        .with_context(|| format!("{}: cannot write G-code", args.output.display()))?;
    if let Some(report) = &args.report {
        let json = serde_json::to_vec_pretty(&summary).context("serialising the report")?;
        write_atomically(report, |f| f.write_all(&json))
            .with_context(|| format!("{}: cannot write report", report.display()))?;
    }
    let total: f64 = summary.gcode.tools.iter().map(|t| t.filament_mm).sum();
    eprintln!(
        "{}: {} layers, {:.0} mm filament, estimated {:.0} min",
        args.output.display(),
        summary.layers,
        total,
        summary.gcode.estimated_time_s / 60.0
    );
    Ok(())
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
