//! `conduit check`: replay a G-code file and report problems and figures, with `--circuit` the
//! circuit in it too; exit 1 on errors.

use super::{Failure, args::CheckArgs, config::resolve};
use anyhow::Context;
use conduit::check::{ElectricalParams, ElectricalReport, Frame, check, check_electrical};
use conduit::circuit::{Circuit, Electronics, Placement};
use conduit::pipeline::{model_bboxes, place_on_bed_with_offsets};
use conduit::scene::FileKind;
use conduit::scene::{LoadOptions, load_scene};
use std::path::Path;

/// Reads a G-code input, refusing a file that is something else (an STL, a 3MF, …) by its
/// content, or by its extension when the content does not look like G-code either.
pub(crate) fn read_gcode_file(path: &Path) -> anyhow::Result<Vec<u8>> {
    let bytes =
        std::fs::read(path).with_context(|| format!("{}: cannot read file", path.display()))?;
    let other = match FileKind::sniff(&bytes) {
        Some(FileKind::Gcode) => None,
        Some(kind) => Some(kind),
        None => FileKind::from_extension(path).filter(|k| *k != FileKind::Gcode),
    };
    if let Some(kind) = other {
        let name = serde_json::to_value(kind)
            .ok()
            .and_then(|v| v.as_str().map(str::to_uppercase))
            .unwrap_or_default();
        anyhow::bail!("{}: not a G-code file (it reads as {name})", path.display());
    }
    Ok(bytes)
}

pub(crate) fn run(args: CheckArgs) -> Result<(), Failure> {
    let cfg = resolve(&args.config)?;
    let bytes = read_gcode_file(&args.file)?;
    let gcode = conduit_gcode::parse(&bytes).with_context(|| format!("{}", args.file.display()))?;
    let report = check(&gcode, &cfg.check_params());
    let electrical = electrical(&args, &cfg, &gcode)?;
    if args.json {
        let mut value = serde_json::to_value(&report).context("serialising the report")?;
        if let (Some(e), Some(map)) = (&electrical, value.as_object_mut()) {
            map.insert(
                "electrical".to_owned(),
                serde_json::to_value(e).context("serialising the report")?,
            );
        }
        outln!(
            "{}",
            serde_json::to_string_pretty(&value).context("serialising the report")?
        )?;
    } else {
        outln!("{}: {report}", args.file.display())?;
        if let Some(e) = &electrical {
            outln!("{e}")?;
        }
    }
    if report.has_errors() {
        errorln!(
            "{}: {} error-level finding(s)",
            args.file.display(),
            report.errors
        );
    }
    if let Some(e) = electrical.as_ref().filter(|e| !e.is_ok()) {
        eprintln!(
            "error: {}: {} circuit problem(s)",
            args.file.display(),
            e.problems()
        );
    }
    if report.has_errors() || electrical.is_some_and(|e| !e.is_ok()) {
        return Err(Failure::Reported);
    }
    Ok(())
}

/// The electrical check of `--circuit` and `--placement`, in the frame of `--model` when given
/// (as `conduit slice` placed it on the bed), else in the G-code's own coordinates.
fn electrical(
    args: &CheckArgs,
    cfg: &conduit::config::Config,
    gcode: &conduit_gcode::Gcode,
) -> anyhow::Result<Option<ElectricalReport>> {
    let (Some(circuit), Some(placement)) = (&args.circuit, &args.placement) else {
        return Ok(None);
    };
    let e = Electronics {
        circuit: Circuit::load(circuit)?,
        placement: Placement::load(placement)?,
    };
    let frame = match &args.model {
        Some(model) => {
            let (scene, _) = load_scene(model, &LoadOptions::default())?;
            Frame::Objects {
                bboxes: model_bboxes(&scene),
                offsets: place_on_bed_with_offsets(&scene, cfg).1,
            }
        }
        None => Frame::Printed,
    };
    let stage = cfg.electronics_params();
    let report = check_electrical(
        gcode,
        cfg.printer.flavor,
        &e,
        &frame,
        &stage,
        &ElectricalParams::of(&stage),
    )
    .with_context(|| format!("{}", placement.display()))?;
    Ok(Some(report))
}
