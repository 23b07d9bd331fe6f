//! `conduit place`: a placement TOML for a circuit in a model, from an EAGLE or KiCad board's
//! layout or packed automatically, checked against the model's solid before it is written.

use anyhow::Context;

use super::{Failure, args::PlaceArgs, config::resolve};
use conduit::circuit::Circuit;
use conduit::pipeline::place::{
    Auto, BottomChoice, FromBoard, PlaceOutcome, PlaneChoice, place_auto, place_from_board,
};
use conduit::scene::OutputSet;

pub(crate) fn run(args: PlaceArgs) -> Result<(), Failure> {
    let mut outputs = OutputSet::new(std::slice::from_ref(&args.model));
    for p in [
        &args.from_brd,
        &args.from_pcb,
        &args.circuit,
        &args.config.config,
    ]
    .into_iter()
    .flatten()
    {
        outputs.input(p);
    }
    outputs.check(&args.output)?;
    let cfg = resolve(&args.config)?;
    let scene = super::slice::load_models(std::slice::from_ref(&args.model))?;
    let circuit_path = args
        .circuit
        .clone()
        .or_else(|| args.from_brd.clone())
        .or_else(|| args.from_pcb.clone())
        .context("--circuit is needed with --auto")?;
    let circuit = Circuit::load(&circuit_path).map_err(anyhow::Error::from)?;
    let source = Some(relative_to(&circuit_path, &args.output));
    let plane = match (args.z, args.z_from_top) {
        (Some(z), _) => PlaneChoice::At(z),
        (None, Some(d)) => PlaneChoice::FromTop(d),
        (None, None) => PlaneChoice::UnderTop,
    };
    let (outcome, from) = if let Some(brd) = args.from_brd.as_ref().or(args.from_pcb.as_ref()) {
        let board = read_board(brd, args.from_pcb.is_some())?;
        let how = FromBoard {
            at: args.at,
            rotate_deg: args.rotate,
            scale: args.scale,
            plane,
            bottom: match (args.bottom.as_deref(), args.bottom_z) {
                (Some("refuse"), _) => BottomChoice::Refuse,
                (_, z) => BottomChoice::Below(z),
            },
            body_height: args.body_height,
        };
        let outcome = place_from_board(&scene, &cfg, &circuit, &board, &how, source)
            .with_context(|| format!("placing {} in {}", brd.display(), args.model.display()))?;
        (outcome, format!("from {}", brd.display()))
    } else {
        let how = Auto {
            z_range: args.z_range.or(args.z.map(|z| [z; 2])),
            from_top: args.z_from_top,
            spacing: args.spacing,
            body_height: args.body_height,
        };
        let outcome = place_auto(&scene, &cfg, &circuit, &how, source).with_context(|| {
            format!(
                "packing {} in {}",
                circuit_path.display(),
                args.model.display()
            )
        })?;
        (outcome, "packed".to_owned())
    };
    report(&args, &outcome, &from)?;
    let problems = outcome.problems.len();
    if problems > 0 && !args.force {
        errorln!(
            "{}: {problems} problem(s) above; nothing written (--force writes the placement \
             anyway)",
            args.output.display()
        );
        return Err(Failure::Reported);
    }
    outputs.add(&args.output, outcome.toml.as_bytes())?;
    outputs.commit()?;
    Ok(())
}

/// `path` as the placement file at `output` names it: relative to the placement's folder when
/// both are relative paths, as given otherwise.
fn relative_to(path: &std::path::Path, output: &std::path::Path) -> String {
    let folder = output.parent().unwrap_or(std::path::Path::new(""));
    if path.is_relative() && output.is_relative() {
        let ups = folder.components().count();
        let mut rel = std::path::PathBuf::new();
        for _ in 0..ups {
            rel.push("..");
        }
        rel.push(path);
        return rel.display().to_string();
    }
    path.display().to_string()
}

/// The summary (text or `--json`), the notes as warnings and the problems as errors (warnings
/// with `--force`).
fn report(args: &PlaceArgs, o: &PlaceOutcome, from: &str) -> Result<(), Failure> {
    // Thin material is worth a look, not a screenful: the first few, the rest with -v.
    const SHOWN_NOTES: usize = 8;
    let shown = if super::verbose() {
        o.notes.len()
    } else {
        SHOWN_NOTES
    };
    for line in o.notes.iter().take(shown) {
        warnln!("{line}");
    }
    if o.notes.len() > shown {
        warnln!(
            "{} more cavities with less material than route.wall_clearance (-v lists them)",
            o.notes.len() - shown
        );
    }
    for line in &o.problems {
        if args.force {
            warnln!("{line}");
        } else {
            errorln!("{line}");
        }
    }
    if args.json {
        let closest = o
            .closest_pads
            .as_ref()
            .map(|(gap, a, b)| serde_json::json!({ "gap_mm": gap, "pins": [a, b] }));
        return super::print_json(&serde_json::json!({
            "outputs": if o.problems.is_empty() || args.force {
                super::paths([args.output.as_path()])
            } else {
                Vec::new()
            },
            "parts": o.placement.parts.len(),
            "planes": o.planes,
            "span_mm": o.span,
            "problems": o.problems,
            "notes": o.notes,
            "left_out": o.left_out,
            "closest_pads": closest,
            "room_mm": { "trace": o.room.trace, "parts": o.room.parts },
            "suggested_scale": o.suggested_scale,
            "fine_pitch": o.fine_pitch.as_ref().map(|f| serde_json::json!({
                "part": f.part,
                "pads": f.pads,
                "distance_mm": f.distance,
                "spacing_mm": f.spacing,
                "suggested_width_mm": f.width,
            })),
        }));
    }
    let planes: Vec<String> = o.planes.iter().map(|z| format!("z {z:.3} mm")).collect();
    outln!(
        "{}: {} parts {from}, {:.1} × {:.1} mm, seated on {}",
        args.output.display(),
        o.placement.parts.len(),
        o.span[0],
        o.span[1],
        planes.join(" (top) and ") + if o.planes.len() > 1 { " (lower)" } else { "" }
    )?;
    if let Some((gap, a, b)) = &o.closest_pads {
        let need = o.room.trace;
        let verdict = if *gap >= need - 1e-9 {
            "room for a trace"
        } else {
            "too close for a trace"
        };
        outln!("closest pads of different nets: {gap:.2} mm ({a}, {b}), {verdict} ({need:.2} mm)")?;
    }
    if let Some(f) = &o.fine_pitch {
        outln!(
            "{} ({s:.2} mm): route with --set route.conductive_width={w:.2}, the widest that fits",
            f.too_close(),
            s = f.spacing,
            w = f.width,
        )?;
    }
    if args.from_brd.is_some() || args.from_pcb.is_some() {
        let width = o.fine_pitch.as_ref().map_or(String::new(), |f| {
            format!(" at route.conductive_width {:.2}", f.width)
        });
        let scale = match o.suggested_scale {
            Some(s) if (s - args.scale).abs() < 1e-9 => format!("--scale {s:.2} is the smallest"),
            Some(s) => format!("try --scale {s:.2}, the smallest"),
            None => format!(
                "no scale up to {} is",
                conduit::circuit::board_layout::MAX_SUGGESTED_SCALE
            ),
        };
        outln!(
            "{scale} that leaves {:.2} mm between pads of different nets and {:.2} mm between \
             parts{width} (route.conductive_width, channel_extra, cavity_offset, wall_clearance)",
            o.room.trace,
            o.room.parts
        )?;
    }
    // Grouped by reason: `left out: 7 with no pads (FRAME1, LOGO1, ...); ...`.
    let mut by_reason: std::collections::BTreeMap<&str, Vec<&str>> = Default::default();
    for line in &o.left_out {
        let (name, reason) = line.split_once(": ").unwrap_or((line.as_str(), "left out"));
        by_reason.entry(reason).or_default().push(name);
    }
    if !by_reason.is_empty() {
        let groups: Vec<String> = by_reason
            .iter()
            .map(|(reason, names)| format!("{} ({reason}): {}", names.len(), names.join(", ")))
            .collect();
        outln!("left out: {}", groups.join("; "))?;
    }
    Ok(())
}

/// The layout of an EAGLE board, or of a KiCad board when `kicad`.
pub(crate) fn read_board(
    path: &std::path::Path,
    kicad: bool,
) -> anyhow::Result<conduit::circuit::board_layout::BoardInput> {
    use conduit::circuit::board_layout::BoardInput;
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    Ok(if kicad {
        BoardInput::from_kicad(
            &conduit_kicad::read_pcb(&bytes).with_context(|| path.display().to_string())?,
        )
    } else {
        BoardInput::from_eagle(
            &conduit_eagle::read_board(&bytes).with_context(|| path.display().to_string())?,
        )
    })
}
