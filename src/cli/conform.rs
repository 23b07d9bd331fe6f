//! `conduit conform`: a 2D design laid onto a scanned surface and printed with a
//! micro-extrusion nozzle (see [`conduit::conform`]), as 3-axis G-code or, with a tool axis per
//! point ([`conduit::conform::orient`]), as a robot or five-axis program
//! ([`conduit::emit::robot`]).

use super::{Failure, args::ConformArgs, config::resolve};
use anyhow::{Context, anyhow};
use conduit::config::{Config, Corrections, Mapping};
use conduit::conform::orient::{OrientParams, OrientationReport, ToolAxis};
use conduit::conform::scan::load_scan;
use conduit::conform::{ConformParams, ConformReport, Placement};
use conduit::emit::robot::Dialect;
use conduit::geom::Point3;
use conduit::pipeline::conform::{self as walk, ConformJob, ConformOutput, ConformWalkError, Refs};
use conduit::scene::{Content, OutputSet, load};
use serde::Serialize;

pub(crate) fn run(args: ConformArgs) -> Result<(), Failure> {
    let (file, dialect_name) = output_and_dialect(&args)?;
    let args = ConformArgs {
        output: vec![file],
        ..args
    };
    let mut cfg = resolve(&args.config)?;
    match args.mapping.as_deref() {
        Some("geodesic") => cfg.conform.mapping = Mapping::Geodesic,
        Some(_) => cfg.conform.mapping = Mapping::Projection,
        None => {}
    }
    // The `[conform]` settings are checked here rather than by the config's own validation:
    // the error names the config file when there is one.
    let params =
        ConformParams::from_settings(&cfg.conform).with_context(|| match &args.config.config {
            Some(path) => format!("{}: invalid config", path.display()),
            None => "invalid config".to_owned(),
        })?;
    let dialect = Dialect::from_name(&dialect_name);
    let orient = orientation(&args, &cfg, dialect)?;
    let place = args.place.as_deref().map(parse_place).transpose()?;
    let scan = load_scan(
        &args.surface,
        args.as_cloud,
        cfg.conform.fold_gap,
        &super::load_options(),
    )
    .map_err(anyhow::Error::from)?;
    for w in &scan.warnings {
        warnln!("{}: {w}", args.surface.display());
    }
    let refs = refs(&args)?;
    let design = match load(&args.design, &super::load_options())
        .map_err(anyhow::Error::from)?
        .content
    {
        Content::Design(d) => d,
        _ => {
            return Err(anyhow!("{}: not an SVG design", args.design.display()).into());
        }
    };
    let job = ConformJob {
        scan,
        design: &design,
        place,
        refs,
        params,
        orient,
        dialect,
        program_name: out_path(&args)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
    };
    let out = walk::run(job, &cfg, |_| {}).map_err(|e| located(e, &args))?;
    write_outputs(&args, &out)?;
    if args.json {
        super::print_json(&serde_json::json!({
            "outputs": super::paths(std::iter::once(out_path(&args)).chain(args.report.as_deref())),
            "dialect": dialect_name,
            "moves": out.moves,
            "report": FullReport {
                conform: &out.report,
                orientation: &out.orientation,
            },
        }))?;
        return warnings(&args, &out.report);
    }
    match out.moves {
        Some(moves) => print_program_summary(&args, &dialect_name, &out, moves),
        None => print_gcode_summary(&args, cfg.conform.corrections, &out.report),
    }
    warnings(&args, &out.report)
}

/// The one file to write (after [`output_and_dialect`] left one).
fn out_path(args: &ConformArgs) -> &std::path::Path {
    args.output
        .first()
        .map_or(std::path::Path::new(""), |p| p.as_path())
}

/// The file to write and the output dialect's name.
///
/// `-o/--output FILE` names the file (`--out` is its older spelling), `--dialect` the language.
/// `--output` once named the language (`-o out.src --output krl`); that spelling is still read,
/// with a warning, when one `--output` value is a dialect name, another is the file and
/// `--dialect` is not given: a file literally named `krl` beside another output is not a
/// likely wish, and refusing would break the old command lines for no gain. Any other mix is a
/// usage error that says how to write it.
fn output_and_dialect(args: &ConformArgs) -> Result<(std::path::PathBuf, String), Failure> {
    let is_dialect = |p: &std::path::PathBuf| {
        p.to_str()
            .is_some_and(|s| super::args::DIALECTS.contains(&s))
    };
    match (args.output.as_slice(), &args.dialect) {
        ([file], Some(d)) => Ok((file.clone(), d.clone())),
        ([file], None) if is_dialect(file) => Err(Failure::Usage(format!(
            "--output {0} names the file to write; give the file with -o FILE and the language \
             with --dialect {0}",
            file.display()
        ))),
        ([file], None) => Ok((file.clone(), "gcode".to_owned())),
        ([a, b], None) if is_dialect(a) != is_dialect(b) => {
            let (name, file) = if is_dialect(a) { (a, b) } else { (b, a) };
            let name = name.display().to_string();
            warnln!("`--output {name}` is now spelled `--dialect {name}`");
            Ok((file.clone(), name))
        }
        _ => Err(Failure::Usage(
            "give one output file with -o/--output FILE and the language with --dialect".to_owned(),
        )),
    }
}

/// The tool axis options; a tilted axis needs a robot or five-axis `dialect`.
fn orientation(
    args: &ConformArgs,
    cfg: &Config,
    dialect: Option<Dialect>,
) -> Result<OrientParams, Failure> {
    let axis = args
        .tool_axis
        .as_deref()
        .map(ToolAxis::parse)
        .transpose()
        .map_err(|e| Failure::Usage(e.to_string()))?
        .unwrap_or(ToolAxis::Vertical);
    if dialect.is_none() && axis != ToolAxis::Vertical {
        return Err(Failure::Usage(format!(
            "--tool-axis {} tilts the tool, which 3-axis G-code cannot do: choose --dialect \
             urscript, krl, rapid, poses-csv or gcode-5axis",
            args.tool_axis.as_deref().unwrap_or_default()
        )));
    }
    OrientParams::new(
        axis,
        args.max_tilt.unwrap_or(cfg.robot.max_tilt),
        cfg.robot.axis_smoothing,
    )
    .map_err(|e| Failure::Usage(e.to_string()))
}

/// How the scan is registered: `--refs-machine` with `--refs-scan` or `--refs-auto`, or not at
/// all.
fn refs(args: &ConformArgs) -> Result<Refs, Failure> {
    let machine = args
        .refs_machine
        .as_deref()
        .map(|s| parse_points(s, "--refs-machine"))
        .transpose()?;
    Ok(match (&args.refs_scan, args.refs_auto, machine) {
        (Some(scan), _, Some(machine)) => Refs::Points {
            scan: parse_points(scan, "--refs-scan")?,
            machine,
        },
        (None, true, Some(machine)) => Refs::Markers { machine },
        (None, false, Some(_)) => {
            return Err(Failure::Usage(
                "--refs-machine needs --refs-scan (the same points in the scan) or --refs-auto"
                    .to_owned(),
            ));
        }
        _ => Refs::None,
    })
}

/// Writes the program and, when asked for, the JSON report: both or neither, never over an
/// input.
fn write_outputs(args: &ConformArgs, out: &ConformOutput) -> Result<(), Failure> {
    let mut outputs = OutputSet::new(
        [&args.surface, &args.design]
            .into_iter()
            .chain(&args.config.config),
    );
    outputs.add(out_path(args), &out.program)?;
    if let Some(path) = &args.report {
        let full = FullReport {
            conform: &out.report,
            orientation: &out.orientation,
        };
        let json = serde_json::to_vec_pretty(&full).context("serialising the report")?;
        outputs.add(path, &json)?;
    }
    outputs.commit()?;
    Ok(())
}

/// The summary line of a robot or five-axis program of `moves` moves.
fn print_program_summary(
    args: &ConformArgs,
    dialect_name: &str,
    out: &ConformOutput,
    moves: usize,
) {
    let (report, o) = (&out.report, &out.orientation);
    infoln!(
        "{}: {} program, {} path(s), {} points, {moves} moves, {:.1} mm on the surface; tool \
         axis {}: largest tilt {:.1}°, largest angle to the surface normal {:.1}°{}; {} \
         nozzle contact(s)",
        out_path(args).display(),
        dialect_name,
        report.paths,
        report.points,
        report.geometry.length_3d,
        o.tool_axis,
        o.max_tilt_deg,
        o.max_normal_deviation_deg,
        if o.limited > 0 {
            format!(
                " ({} axes held at the {}° limit)",
                o.limited, o.max_tilt_limit_deg
            )
        } else {
            String::new()
        },
        o.contacts
    );
}

/// The summary line of a G-code run, with the deposit error of the `corrections` used and of
/// the other modes on the same path.
fn print_gcode_summary(args: &ConformArgs, corrections: Corrections, report: &ConformReport) {
    let replay = report.replay.as_ref().map_or(0, |r| r.printing + r.travel);
    // The other modes on the same path, for comparison.
    let others: Vec<String> = Corrections::ALL
        .iter()
        .filter(|&&m| m != corrections)
        .map(|&m| format!("{} {:.3}", m.name(), report.comparison.of(m).mean_abs_error))
        .collect();
    infoln!(
        "{}: {} path(s), {} points, {:.1} mm on the surface ({:.1} mm in the plane), Δz {:.2} mm; \
         deposit error {:.3} mm mean with {} corrections ({}); {} nozzle contact(s) in the replay",
        out_path(args).display(),
        report.paths,
        report.points,
        report.geometry.length_3d,
        report.geometry.length_2d,
        report.geometry.delta_z,
        report.comparison.of(corrections).mean_abs_error,
        report.corrections,
        others.join(", "),
        replay
    );
}

/// A walk error with the file names it concerns.
fn located(e: ConformWalkError, args: &ConformArgs) -> Failure {
    let (surface, design) = (args.surface.display(), args.design.display());
    match e {
        ConformWalkError::MarkersNeedMesh
        | ConformWalkError::Markers(_)
        | ConformWalkError::Registered(_) => anyhow!("{surface}: {e}").into(),
        ConformWalkError::Plan(_) => anyhow!("{design} on {surface}: {e}").into(),
        other => anyhow::Error::from(other).into(),
    }
}

/// The conform report with the orientation section.
#[derive(Serialize)]
struct FullReport<'a> {
    #[serde(flatten)]
    conform: &'a ConformReport,
    orientation: &'a OrientationReport,
}

/// Warnings about the run: contacts in the start/end G-code, design points off the surface, a
/// folded point cloud.
fn warnings(args: &ConformArgs, report: &ConformReport) -> Result<(), Failure> {
    if let Some(r) = &report.replay
        && r.custom > 0
    {
        warnln!(
            "the printer's start or end G-code moves the nozzle into the surface ({} \
             sample(s), first at {:?}): check printer.start_gcode (the default homes and primes a \
             line on the bed's front edge) and printer.end_gcode",
            r.custom,
            r.places.first().copied().unwrap_or_default()
        );
    }
    if report.off_surface > 0 {
        warnln!(
            "{} design point(s) have no surface under them and were left out",
            report.off_surface
        );
    }
    if let Some(c) = &report.surface.cloud
        && c.folds
    {
        warnln!(
            "{}: the point cloud folds over itself; a height field holds only its top \
             ({} of {} points below a fold were left out)",
            args.surface.display(),
            c.below_fold,
            c.points
        );
    }
    Ok(())
}

fn parse_numbers(s: &str, what: &str) -> anyhow::Result<Vec<f64>> {
    s.split(',')
        .map(|v| {
            v.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| anyhow!("{what}: `{}` is not a number", v.trim()))
        })
        .collect()
}

fn parse_place(s: &str) -> Result<Placement, Failure> {
    let v = parse_numbers(s, "--place").map_err(|e| Failure::Usage(e.to_string()))?;
    match v.as_slice() {
        [x, y] => Ok(Placement {
            x: *x,
            y: *y,
            rot_deg: 0.0,
            scale: 1.0,
        }),
        [x, y, r] => Ok(Placement {
            x: *x,
            y: *y,
            rot_deg: *r,
            scale: 1.0,
        }),
        [x, y, r, s] if *s > 0.0 => Ok(Placement {
            x: *x,
            y: *y,
            rot_deg: *r,
            scale: *s,
        }),
        _ => Err(Failure::Usage(format!(
            "--place: expected x,y[,rot[,scale]] with a positive scale, got `{s}`"
        ))),
    }
}

fn parse_points(s: &str, what: &str) -> Result<Vec<Point3>, Failure> {
    let pts = s
        .split(';')
        .filter(|p| !p.trim().is_empty())
        .map(|p| match parse_numbers(p, what)?.as_slice() {
            [x, y, z] => Ok(Point3::new(*x, *y, *z)),
            _ => Err(anyhow!("{what}: `{}` is not x,y,z", p.trim())),
        })
        .collect::<anyhow::Result<Vec<Point3>>>()
        .map_err(|e| Failure::Usage(e.to_string()))?;
    if pts.len() < 3 {
        return Err(Failure::Usage(format!(
            "{what}: at least three points `x,y,z;x,y,z;x,y,z` are needed, got {}",
            pts.len()
        )));
    }
    Ok(pts)
}
