//! `conduit compensate`: gap compensation of a robot path from measured gaps (`--gaps`) or from
//! gaps simulated on a known surface under a robot error model (`--simulate`), and
//! `conduit compensate pattern`, calibration print patterns on a surface.

use super::args::ConfigSource;
use super::{Failure, config::resolve};
use anyhow::Context;
use conduit::config::{CompensateSettings, Config};
use conduit::conform::scan::load_scan;
use conduit::emit::robot::Dialect;
use conduit::pipeline::compensate as walk;
use conduit::robot::compensate::substrate::{self, Substrate, SurfaceSpec};
use conduit::robot::compensate::{Params, Path as PosePath, gaps};
use conduit::robot::pattern::{self, PatternParams, Shape};
use conduit::scene::OutputSet;
use conduit_poses::Pose;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Micrometres per millimetre.
const UM: f64 = 1000.0;

/// Arguments of `conduit compensate`.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct CompensateArgs {
    /// `pattern`: write a calibration print pattern instead of compensating a path.
    #[command(subcommand)]
    pub command: Option<CompensateCommand>,
    /// The path: a pose table `x,y,z,qw,qx,qy,qz[,dispense]` whose tool frame's z axis points
    /// from the tool into the work.
    #[arg(required = true, value_name = "PATH.csv")]
    pub path: Option<PathBuf>,
    /// Measured gaps: a `reading` column (mm) placed by `index` (pose number from 0) or `s`
    /// (arc length along the path, mm), or one reading per pose.
    #[arg(long, value_name = "MEASURED.csv", conflicts_with = "simulate")]
    pub gaps: Option<PathBuf>,
    /// Simulate the gaps on a known surface: `sphere:R`, `cylinder:R` (axis along y),
    /// `plane`, `plane:waviness:AMPLITUDE,PERIOD` (mm) or a mesh file, moved by the error
    /// model (--shift, --tilt, --z-error) and read with --noise.
    #[arg(long, value_name = "SURFACE")]
    pub simulate: Option<String>,
    /// Angle between the sensor beam and the tool axis, degrees: a reading h is the gap
    /// h·cos(angle) [compensate.sensor_angle].
    #[arg(long = "sensor-angle", value_name = "DEG")]
    pub sensor_angle: Option<f64>,
    /// Gap to aim for, µm [compensate.target].
    #[arg(long, value_name = "UM")]
    pub target: Option<f64>,
    /// Standard deviation of the Gaussian smoothing of the corrections along the path, mm
    /// (0 = none) [compensate.smoothing].
    #[arg(long, value_name = "MM")]
    pub smoothing: Option<f64>,
    /// Simulation: measure → compensate passes [compensate.passes].
    #[arg(requires = "simulate", long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100))]
    pub passes: Option<u32>,
    /// Simulation: shift of the real substrate, mm [compensate.error_shift].
    #[arg(requires = "simulate", long, value_name = "DX,DY,DZ", allow_hyphen_values = true, value_parser = triple)]
    pub shift: Option<[f64; 3]>,
    /// Simulation: orientation error of the substrate about --tilt-axis through the middle of
    /// the path, degrees [compensate.error_tilt].
    #[arg(
        requires = "simulate",
        long,
        value_name = "DEG",
        allow_hyphen_values = true
    )]
    pub tilt: Option<f64>,
    /// Simulation: axis of --tilt [compensate.error_axis].
    #[arg(requires = "simulate", long = "tilt-axis", value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = triple)]
    pub tilt_axis: Option<[f64; 3]>,
    /// Simulation: tool-length error, mm, added to every gap [compensate.error_z].
    #[arg(
        requires = "simulate",
        long = "z-error",
        value_name = "MM",
        allow_hyphen_values = true
    )]
    pub z_error: Option<f64>,
    /// Simulation: standard deviation of the sensor noise, µm [compensate.noise].
    #[arg(requires = "simulate", long, value_name = "UM")]
    pub noise: Option<f64>,
    /// Simulation: seed of the sensor noise [compensate.seed].
    #[arg(requires = "simulate", long, value_name = "N")]
    pub seed: Option<u64>,
    /// Simulation: also write the readings of the first measurement as a gap table
    /// (`index,s,reading`), for `--gaps`.
    #[arg(long = "readings-out", value_name = "GAPS.csv", requires = "simulate")]
    pub readings_out: Option<PathBuf>,
    /// Settings (the `[compensate]` section).
    #[command(flatten)]
    pub config: ConfigSource,
    /// The compensated pose table to write.
    #[arg(short, long, value_name = "OUT.csv", required = true)]
    pub output: Option<PathBuf>,
    /// Also write the compensated path as a robot or five-axis program (dialect from
    /// `--dialect`): the next run on the machine.
    #[arg(long, value_name = "FILE", requires = "dialect")]
    pub program: Option<PathBuf>,
    /// The program's dialect: `urscript`, `krl`, `rapid` or `gcode-5axis` (as `conduit conform
    /// --dialect`; frames, speeds and dispense outputs from `[robot]`).
    #[arg(long, value_name = "DIALECT", requires = "program",
          value_parser = ["urscript", "krl", "rapid", "gcode-5axis"])]
    pub dialect: Option<String>,
    /// Also write a JSON report: gap statistics before, the corrections, and with --simulate
    /// the real gaps after each pass.
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Print one JSON document on stdout summarising what was done (outputs written, counts,
    /// key figures) instead of the text summary on stderr.
    #[arg(long)]
    pub json: bool,
}

/// Subcommands of `conduit compensate`.
#[derive(Debug, clap::Subcommand)]
pub enum CompensateCommand {
    /// A calibration print pattern projected onto a surface: a pose table with the tool along
    /// the surface normal and the tip at the target gap.
    Pattern(Box<PatternArgs>),
}

/// Arguments of `conduit compensate pattern`.
#[derive(Debug, clap::Args)]
pub struct PatternArgs {
    /// The shape.
    #[arg(value_enum)]
    pub shape: Shape,
    /// Diameter of a circle or spiral, side of a serpentine's square, mm.
    #[arg(long, value_name = "MM")]
    pub size: f64,
    /// The surface: `sphere:R` (centred at the origin), `cylinder:R` (axis along y through the
    /// origin), `plane` (z = 0), `plane:waviness:AMPLITUDE,PERIOD` or a mesh file.
    #[arg(long, value_name = "SURFACE")]
    pub surface: String,
    /// Centre of the pattern in the top view, mm.
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true, value_parser = pair, default_value = "0,0")]
    pub at: [f64; 2],
    /// Draw the pattern in the tangent plane of the surface point above --at (and project it
    /// along that plane's normal) instead of the top view.
    #[arg(long)]
    pub tangent: bool,
    /// Distance between neighbouring points, mm [compensate.pattern_spacing].
    #[arg(long, value_name = "MM")]
    pub spacing: Option<f64>,
    /// Distance between serpentine lines or spiral turns, mm [compensate.pattern_pitch].
    #[arg(long, value_name = "MM")]
    pub pitch: Option<f64>,
    /// Tip-to-surface gap along the normal, µm [compensate.target].
    #[arg(long, value_name = "UM")]
    pub target: Option<f64>,
    /// Settings (the `[compensate]` section).
    #[command(flatten)]
    pub config: ConfigSource,
    /// The pose table to write.
    #[arg(short, long, value_name = "PATH.csv")]
    pub output: PathBuf,
    /// Print one JSON document on stdout summarising what was done (outputs written, counts,
    /// key figures) instead of the text summary on stderr.
    #[arg(long)]
    pub json: bool,
}

/// `A,B,C` as three numbers.
fn triple(text: &str) -> Result<[f64; 3], String> {
    numbers::<3>(text)
}

/// `A,B` as two numbers.
fn pair(text: &str) -> Result<[f64; 2], String> {
    numbers::<2>(text)
}

fn numbers<const N: usize>(text: &str) -> Result<[f64; N], String> {
    let v: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected {N} comma-separated numbers, got {text:?}"))?;
    let arr: [f64; N] = v
        .try_into()
        .map_err(|_| format!("expected {N} comma-separated numbers, got {text:?}"))?;
    if arr.iter().all(|x| x.is_finite()) {
        Ok(arr)
    } else {
        Err(format!("{text:?}: numbers must be finite"))
    }
}

pub(crate) fn run(args: CompensateArgs) -> Result<(), Failure> {
    if let Some(CompensateCommand::Pattern(p)) = args.command {
        return run_pattern(*p);
    }
    let (Some(path), Some(output)) = (args.path.clone(), args.output.clone()) else {
        return Err(Failure::Usage("PATH.csv and -o are required".to_owned()));
    };
    let mut cfg = resolve(&args.config)?;
    overrides(&mut cfg.compensate, &args)?;
    let params = Params::from_settings(&cfg.compensate).map_err(anyhow::Error::from)?;
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let poses = PosePath::parse(&text).with_context(|| path.display().to_string())?;
    let job = Job {
        args: &args,
        header: leading_comments(&text),
        cfg,
        params,
        poses,
        path,
        output,
    };
    match (&args.gaps, &args.simulate) {
        (Some(g), None) => measured(&job, g),
        (None, Some(spec)) => simulated(&job, spec),
        _ => Err(Failure::Usage(
            "give the measured gaps (--gaps MEASURED.csv) or a surface to simulate them on \
             (--simulate SURFACE)"
                .to_owned(),
        )),
    }
}

/// A compensation run, its inputs read and checked.
struct Job<'a> {
    args: &'a CompensateArgs,
    cfg: Config,
    params: Params,
    /// The path.
    poses: PosePath,
    /// The `#` lines at the top of the path table.
    header: Vec<String>,
    path: PathBuf,
    output: PathBuf,
}

/// Command-line values over the `[compensate]` settings, checked again.
fn overrides(s: &mut CompensateSettings, a: &CompensateArgs) -> Result<(), Failure> {
    if let Some(v) = a.target {
        s.target = v / UM;
    }
    if let Some(v) = a.sensor_angle {
        s.sensor_angle = v;
    }
    if let Some(v) = a.smoothing {
        s.smoothing = v;
    }
    if let Some(v) = a.passes {
        s.passes = v;
    }
    if let Some(v) = a.shift {
        s.error_shift = v;
    }
    if let Some(v) = a.tilt {
        s.error_tilt = v;
    }
    if let Some(v) = a.tilt_axis {
        s.error_axis = v;
    }
    if let Some(v) = a.z_error {
        s.error_z = v;
    }
    if let Some(v) = a.noise {
        s.noise = v / UM;
    }
    if let Some(v) = a.seed {
        s.seed = v;
    }
    let problems = s.problems();
    if problems.is_empty() {
        Ok(())
    } else {
        Err(Failure::Usage(problems.join("; ")))
    }
}

/// The `#` lines before the header of a table (they state its frame), kept in the output.
fn leading_comments(text: &str) -> Vec<String> {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .take_while(|l| l.starts_with('#'))
        .map(str::to_owned)
        .collect()
}

/// The table of `poses` after the `comments` lines, staged as `path`.
fn add_table(
    outputs: &mut OutputSet,
    path: &Path,
    comments: &[String],
    poses: &[Pose],
) -> Result<(), Failure> {
    let mut buf: Vec<u8> = Vec::new();
    for c in comments {
        writeln!(buf, "{c}").map_err(anyhow::Error::from)?;
    }
    conduit_poses::write_poses(poses, &mut buf)
        .with_context(|| format!("{}: cannot write poses", path.display()))?;
    outputs.add(path, &buf)?;
    Ok(())
}

/// With `--program`, stages the compensated `poses` (their dispensing runs) as a robot or
/// five-axis program.
fn add_program(outputs: &mut OutputSet, job: &Job, poses: &[Pose]) -> Result<(), Failure> {
    let (Some(out), Some(name)) = (&job.args.program, &job.args.dialect) else {
        return Ok(());
    };
    let Some(dialect) = Dialect::from_name(name) else {
        return Err(Failure::Usage(format!("unknown program dialect {name:?}")));
    };
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let text = walk::program(
        poses,
        &job.path.display().to_string(),
        (dialect, &stem),
        &job.cfg,
    )
    .map_err(anyhow::Error::from)?;
    outputs.add(out, &text)?;
    Ok(())
}

/// Stages a JSON report.
fn add_report(
    outputs: &mut OutputSet,
    path: &Path,
    report: &impl Serialize,
) -> Result<(), Failure> {
    let json = serde_json::to_vec_pretty(report).context("serialising the report")?;
    outputs.add(path, &json)?;
    Ok(())
}

/// The output set of a compensation run: its outputs may not overwrite the path, the gaps, a
/// simulated surface's file or the config.
fn output_set(job: &Job) -> OutputSet {
    let a = job.args;
    let mut set = OutputSet::new([&job.path]);
    for p in [&a.gaps, &a.config.config].into_iter().flatten() {
        set.input(p);
    }
    if let Some(spec) = &a.simulate {
        set.input(Path::new(spec));
    }
    set
}

/// The files a compensation run writes besides `--readings-out`: the table, the program and
/// the report.
fn written<'a>(job: &'a Job) -> impl Iterator<Item = &'a Path> {
    std::iter::once(job.output.as_path())
        .chain(job.args.program.as_deref())
        .chain(job.args.report.as_deref())
}

/// One pass over measured gaps.
fn measured(job: &Job, gaps_path: &Path) -> Result<(), Failure> {
    let Job {
        args,
        params,
        poses,
        header,
        path,
        output,
        ..
    } = job;
    let text = std::fs::read_to_string(gaps_path)
        .with_context(|| format!("{}: cannot read", gaps_path.display()))?;
    let on =
        gaps::read(&text, &poses.arc_lengths()).with_context(|| gaps_path.display().to_string())?;
    if on.outside > 0 {
        warnln!(
            "{}: {} pose(s) lie outside the measured stretch and take the nearest reading",
            gaps_path.display(),
            on.outside
        );
    }
    let done = walk::measured(
        (poses, &path.display().to_string(), header),
        (&on, &gaps_path.display().to_string()),
        params,
    );
    let mut outputs = output_set(job);
    add_table(&mut outputs, output, &done.comments, &done.poses)?;
    add_program(&mut outputs, job, &done.poses)?;
    if let Some(r) = &args.report {
        add_report(&mut outputs, r, &done.report)?;
    }
    outputs.commit()?;
    let (b, c) = (done.report.before_mm, done.report.correction_mm);
    if args.json {
        return super::print_json(&serde_json::json!({
            "outputs": super::paths(written(job)),
            "poses": done.poses.len(),
            "report": done.report,
        }));
    }
    infoln!(
        "{}: {} poses; gap before {:.4}..{:.4} mm (variation {:.1} µm, RMS {:.1} µm about {:.1} µm); \
         correction {:.4}..{:.4} mm",
        output.display(),
        done.poses.len(),
        b.min,
        b.max,
        b.variation * UM,
        b.rms_about_target * UM,
        params.target * UM,
        c.min,
        c.max
    );
    Ok(())
}

/// The measure → compensate loop on simulated gaps.
fn simulated(job: &Job, spec: &str) -> Result<(), Failure> {
    let Job {
        args,
        cfg,
        params,
        poses,
        header,
        path,
        output,
    } = job;
    let substrate = load_substrate(spec, cfg)?;
    let sim = walk::simulated(
        (poses, &path.display().to_string(), header),
        (&substrate, spec),
        params,
        cfg,
    )
    .map_err(anyhow::Error::from)?;
    let done = &sim.path;
    let mut outputs = output_set(job);
    add_table(&mut outputs, output, &done.comments, &done.poses)?;
    add_program(&mut outputs, job, &done.poses)?;
    if let Some(r) = &args.readings_out {
        let table = sim.readings_table().map_err(anyhow::Error::from)?;
        outputs.add(r, table.as_bytes())?;
    }
    if let Some(r) = &args.report {
        add_report(&mut outputs, r, &done.report)?;
    }
    outputs.commit()?;
    if args.json {
        return super::print_json(&serde_json::json!({
            "outputs": super::paths(written(job).chain(args.readings_out.as_deref())),
            "poses": poses.poses.len(),
            "surface": spec,
            "report": done.report,
        }));
    }
    let figures: Vec<String> = done
        .report
        .variation_um
        .iter()
        .enumerate()
        .map(|(k, v)| {
            if k == 0 {
                format!("uncompensated {v:.1} µm")
            } else {
                format!("after pass {k} {v:.1} µm")
            }
        })
        .collect();
    infoln!(
        "{}: {} poses on {spec}; gap variation: {}",
        output.display(),
        poses.poses.len(),
        figures.join(", ")
    );
    Ok(())
}

/// The substrate of a `--simulate` or `--surface` description (a file is loaded as a mesh or
/// a point cloud).
fn load_substrate(spec: &str, cfg: &Config) -> Result<Substrate, Failure> {
    let parsed = substrate::parse_spec(spec).map_err(|e| Failure::Usage(e.to_string()))?;
    let file = match parsed {
        SurfaceSpec::Analytic(a) => return Ok(Substrate::Analytic(a)),
        SurfaceSpec::File(f) => f,
    };
    let scan = load_scan(&file, false, cfg.conform.fold_gap, &super::load_options())
        .map_err(anyhow::Error::from)?;
    for w in &scan.warnings {
        warnln!("{}: {w}", file.display());
    }
    Ok(Substrate::Mesh(Box::new(scan.surface)))
}

fn run_pattern(args: PatternArgs) -> Result<(), Failure> {
    let mut cfg = resolve(&args.config)?;
    let c = &mut cfg.compensate;
    if let Some(v) = args.target {
        c.target = v / UM;
    }
    if let Some(v) = args.spacing {
        c.pattern_spacing = v;
    }
    if let Some(v) = args.pitch {
        c.pattern_pitch = v;
    }
    let problems = c.problems();
    if !problems.is_empty() {
        return Err(Failure::Usage(problems.join("; ")));
    }
    let params = PatternParams {
        shape: args.shape,
        size: args.size,
        at: args.at,
        spacing: c.pattern_spacing,
        pitch: c.pattern_pitch,
        gap: c.target,
        tangent: args.tangent,
    };
    let substrate = load_substrate(&args.surface, &cfg)?;
    let poses = pattern::pattern(&substrate, &params).map_err(anyhow::Error::from)?;
    let frame = format!("the frame of {}", args.surface);
    let shape = format!("{:?}", args.shape).to_lowercase();
    let comments = vec![format!(
        "# conduit compensate pattern {shape}: size {} mm at ({}, {}){}, gap {} mm; positions mm in {frame}; tool z into the work",
        params.size,
        params.at[0],
        params.at[1],
        if params.tangent {
            " in the tangent plane"
        } else {
            ""
        },
        params.gap
    )];
    let mut outputs = OutputSet::new(args.config.config.iter());
    outputs.input(Path::new(&args.surface));
    add_table(&mut outputs, &args.output, &comments, &poses)?;
    outputs.commit()?;
    if args.json {
        return super::print_json(&serde_json::json!({
            "outputs": super::paths([args.output.as_path()]),
            "shape": shape,
            "poses": poses.len(),
            "surface": args.surface,
        }));
    }
    infoln!(
        "{}: {shape}, {} poses on {}",
        args.output.display(),
        poses.len(),
        args.surface
    );
    Ok(())
}
