//! `conduit jet`: aerosol-jet toolpaths from SVG/DXF designs, and `conduit jet model`, the
//! corner accumulation model.

use super::args::{JetArgs, JetCommand, JetModelArgs};
use super::{Failure, config::resolve};
use anyhow::Context;
use conduit::jet::{self, JetParams, ModelInput, accumulation};
use conduit::pipeline::jet::{self as walk, JetOutput};
use conduit::scene::OutputSet;

/// Micrometres per millimetre.
const UM: f64 = 1000.0;

pub(crate) fn run(args: JetArgs) -> Result<(), Failure> {
    if let Some(JetCommand::Model(m)) = args.command {
        return model(m);
    }
    let (Some(width), Some(layers), Some(height), Some(output)) = (
        args.width,
        args.layers,
        args.layer_height,
        args.output.clone(),
    ) else {
        return Err(Failure::Usage(
            "--width, --layers, --layer-height and -o are required".to_owned(),
        ));
    };
    let mut outputs = OutputSet::new(args.designs.iter().chain(&args.config.config));
    outputs.check(&output)?;
    let cfg = resolve(&args.config)?;
    let params = JetParams {
        width: width / UM,
        layer_height: height / UM,
        layers: layers as usize,
    };
    jet::validate(&params, &cfg.jet, &cfg.tools).map_err(anyhow::Error::from)?;
    let mut outlines = Vec::new();
    for path in &args.designs {
        let loaded = jet::design::load(path, cfg.jet.arc_tolerance).map_err(anyhow::Error::from)?;
        for w in &loaded.warnings {
            warnln!("{w}");
        }
        outlines.extend(loaded.outlines);
    }
    let names = args
        .designs
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    let JetOutput {
        gcode,
        stats,
        report,
    } = walk::run(&outlines, names, &params, &cfg).map_err(anyhow::Error::from)?;
    outputs.add(&output, &gcode)?;
    if let Some(path) = &args.report {
        let json = serde_json::to_vec_pretty(&report).context("serialising the report")?;
        outputs.add(path, &json)?;
    }
    outputs.commit()?;
    let corners: usize = report.structures.iter().map(|s| s.corners.len()).sum();
    let count = |a| {
        report
            .structures
            .iter()
            .flat_map(|s| &s.corners)
            .filter(|c| c.action == a)
            .count()
    };
    if args.json {
        super::print_json(&serde_json::json!({
            "outputs": super::paths(std::iter::once(output.as_path()).chain(args.report.as_deref())),
            "structures": report.structures.len(),
            "layers": params.layers,
            "paths": stats.paths,
            "jetted_mm": stats.jetted_mm,
            "corners": corners,
            "filleted": count(jet::fillet::CornerAction::Fillet),
            "split": count(jet::fillet::CornerAction::Split),
            "estimated_time_s": stats.estimated_time_s,
            "warnings": report.warnings.len(),
        }))?;
    } else {
        infoln!(
            "{}: {} structure(s), {} layers, {} paths, {:.3} mm jetted, {} corners ({} filleted, {} split), estimated {:.0} s",
            output.display(),
            report.structures.len(),
            params.layers,
            stats.paths,
            stats.jetted_mm,
            corners,
            count(jet::fillet::CornerAction::Fillet),
            count(jet::fillet::CornerAction::Split),
            stats.estimated_time_s
        );
    }
    // Every corner is in the report; the terminal gets the first few.
    const SHOWN: usize = 10;
    for w in report.warnings.iter().take(SHOWN) {
        warnln!("{w}");
    }
    if report.warnings.len() > SHOWN {
        warnln!(
            "... and {} more (see --report)",
            report.warnings.len() - SHOWN
        );
    }
    Ok(())
}

/// `A` or `A..B` (µm).
fn parse_roi(text: &str) -> Result<(f64, Option<f64>), Failure> {
    let num = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|_| Failure::Usage(format!("--roi {text:?}: expected UM or UM..UM")))
    };
    match text.split_once("..") {
        Some((a, b)) => Ok((num(a)?, Some(num(b)?))),
        None => Ok((num(text)?, None)),
    }
}

fn model(args: JetModelArgs) -> Result<(), Failure> {
    let cfg = resolve(&args.config)?;
    let (a, b) = parse_roi(&args.roi)?;
    let rois: Vec<f64> = match b {
        None => vec![a],
        Some(b) => (0..args.steps)
            .map(|i| a + (b - a) * f64::from(i) / f64::from(args.steps - 1))
            .collect(),
    };
    let factor = cfg.jet.leveling_factor;
    let mut rows = Vec::new();
    for roi in rois {
        let input = ModelInput {
            angle_deg: args.angle,
            radius: args.radius,
            width: args.width,
            height: args.height,
            roi,
        };
        let r = accumulation(&input).map_err(|e| Failure::Work(anyhow::Error::from(e)))?;
        rows.push((input, r));
    }
    if args.json {
        let json: Vec<serde_json::Value> = rows
            .iter()
            .map(|(i, r)| {
                serde_json::json!({
                    "input_um": i,
                    "result_um": r,
                    "leveling_factor": factor,
                    "predicted_difference_um": r.difference * factor,
                })
            })
            .collect();
        let text = serde_json::to_string_pretty(&json).context("serialising")?;
        outln!("{text}")?;
        return Ok(());
    }
    outln!(
        "angle {} deg, radius {} um, width {} um, height {} um, leveling factor {factor}",
        args.angle,
        args.radius,
        args.width,
        args.height
    )?;
    outln!("roi_um\tL_in\tL_out\td_in\td_out\th_in-h_out_um\tpredicted_um")?;
    for (i, r) in &rows {
        outln!(
            "{:.3}\t{:.3}\t{:.3}\t{:.5}\t{:.5}\t{:.4}\t{:.4}",
            i.roi,
            r.l_in,
            r.l_out,
            r.d_in,
            r.d_out,
            r.difference,
            r.difference * factor
        )?;
    }
    Ok(())
}
