//! `conduit calibrate`: tool-centre-point (pivot) calibration (`tcp`, see
//! [`conduit::robot::tcp`]) and the rigid transform between two frames (`register`, see
//! [`conduit::robot::frames`]). Results and residuals go to stdout, `--report` writes
//! them as JSON.

use super::args::ConfigSource;
use super::{Failure, config::resolve};
use anyhow::{Context, anyhow};
use conduit::robot::frames::{self, FrameFit, OutlierRule, PairKind};
use conduit::robot::tcp::{self, Pivot, PoseSource};
use conduit::scene::OutputSet;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Arguments of `conduit calibrate`.
#[derive(Debug, clap::Args)]
pub struct CalibrateArgs {
    /// The calibration to run.
    #[command(subcommand)]
    pub command: CalibrateCommand,
}

/// The calibrations.
#[derive(Debug, clap::Subcommand)]
pub enum CalibrateCommand {
    /// Pivot calibration: the tool tip's offset in the flange frame (and the fixed point in the
    /// base frame) from flange poses that all hold the tip on one point.
    Tcp(TcpArgs),
    /// The rigid transform from frame A to frame B (b = T·a) from the same points or poses
    /// measured in both, with per-pair residuals and outliers flagged and left out.
    Register(RegisterArgs),
}

/// Arguments of `conduit calibrate tcp`.
#[derive(Debug, clap::Args)]
pub struct TcpArgs {
    /// Flange poses, one per row: columns `x,y,z,qw,qx,qy,qz` (mm, base frame), or joint
    /// angles `j1..jN` (degrees) with the arm model `[robot] dh` of the config (the pose
    /// columns win when both are there). At least 3 poses (8 or more recommended), tilted
    /// 20–40° in several directions.
    #[arg(value_name = "POSES.csv")]
    pub poses: PathBuf,
    /// Settings (`[robot] dh` for joint angles).
    #[command(flatten)]
    pub config: ConfigSource,
    /// Also write the result and the residuals as JSON.
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Print the result as one JSON document on stdout (the report's content and the files
    /// written) instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `conduit calibrate register`.
#[derive(Debug, clap::Args)]
pub struct RegisterArgs {
    /// Points (`x,y,z`) or poses (`x,y,z,qw,qx,qy,qz`) measured in frame A.
    #[arg(value_name = "A.csv")]
    pub a: PathBuf,
    /// The same points or poses, in the same row order, measured in frame B.
    #[arg(value_name = "B.csv")]
    pub b: PathBuf,
    /// Also write the transform and the residuals as JSON.
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Flag pairs whose residual is above this distance (mm) as outliers. Default: 3× the
    /// median residual, at least 0.01 mm.
    #[arg(long, value_name = "MM")]
    pub outlier: Option<f64>,
    /// Print the result as one JSON document on stdout (the report's content and the files
    /// written) instead of text.
    #[arg(long)]
    pub json: bool,
}

pub(crate) fn run(args: CalibrateArgs) -> Result<(), Failure> {
    match args.command {
        CalibrateCommand::Tcp(a) => run_tcp(a),
        CalibrateCommand::Register(a) => run_register(a),
    }
}

/// `v` with `decimals` decimals, without a negative zero.
fn fixed(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_owned(),
        _ => s,
    }
}

/// Values joined by `sep`, each with `decimals` decimals.
fn list(v: &[f64], decimals: usize, sep: &str) -> String {
    v.iter()
        .map(|x| fixed(*x, decimals))
        .collect::<Vec<_>>()
        .join(sep)
}

fn read(path: &Path) -> anyhow::Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display()))
}

/// Writes the JSON report, never over one of the run's `inputs`.
fn write_report(path: &Path, value: &impl Serialize, inputs: &[&PathBuf]) -> Result<(), Failure> {
    let json = serde_json::to_vec_pretty(value).context("serialising the report")?;
    let mut outputs = OutputSet::new(inputs);
    outputs.add(path, &json)?;
    outputs.commit()?;
    Ok(())
}

/// The JSON report of `conduit calibrate tcp`.
#[derive(Serialize)]
struct TcpReport<'a> {
    file: String,
    #[serde(flatten)]
    result: &'a Pivot,
}

fn run_tcp(args: TcpArgs) -> Result<(), Failure> {
    let cfg = resolve(&args.config)?;
    let file = args.poses.display().to_string();
    let text = read(&args.poses)?;
    let named = |e: tcp::TcpError| anyhow!("{file}: {e}");
    let flange = tcp::flange_poses(&text, &cfg.robot.dh).map_err(named)?;
    let p = tcp::pivot(&flange.poses, &flange.lines, flange.source).map_err(named)?;
    if args.json {
        let report = TcpReport { file, result: &p };
        if let Some(path) = &args.report {
            write_report(path, &report, &inputs(&args))?;
        }
        return super::print_json(&serde_json::json!({
            "outputs": super::paths(args.report.as_deref()),
            "report": report,
        }));
    }

    let source = match p.source {
        PoseSource::Quaternions => "positions and quaternions",
        PoseSource::Joints => "joint angles through [robot] dh",
    };
    outln!("{file}: {} flange poses ({source})", p.poses)?;
    outln!(
        "TCP offset in the flange frame: {} mm (1 sigma {} mm)",
        list(&p.tcp, 4, ", "),
        list(&p.tcp_sigma, 4, ", ")
    )?;
    outln!(
        "pivot in the base frame: {} mm (1 sigma {} mm)",
        list(&p.pivot, 4, ", "),
        list(&p.pivot_sigma, 4, ", ")
    )?;
    outln!(
        "residuals: rms {} mm, worst pose {} (line {}) {} mm",
        fixed(p.rms, 4),
        p.worst.pose,
        p.worst.line,
        fixed(p.worst.residual, 4)
    )?;
    outln!("pose\tline\tresidual_mm")?;
    for r in &p.residuals {
        outln!("{}\t{}\t{}", r.pose, r.line, fixed(r.residual, 4))?;
    }
    outln!(
        "condition number {} (singular values {}; refused above {})",
        fixed(p.condition, 2),
        list(&p.singular_values, 4, ", "),
        tcp::MAX_CONDITION
    )?;
    outln!(
        "paste into [robot] (pivot calibration measures the position; the rotation is the \
         configured one):"
    )?;
    outln!(
        "tool_frame = [{}, {}]",
        list(&p.tcp, 4, ", "),
        list(&cfg.robot.tool_frame[3..], 4, ", ")
    )?;
    if let Some(path) = &args.report {
        write_report(path, &TcpReport { file, result: &p }, &inputs(&args))?;
    }
    Ok(())
}

/// The inputs of a `tcp` run, which its report may not overwrite.
fn inputs(args: &TcpArgs) -> Vec<&PathBuf> {
    std::iter::once(&args.poses)
        .chain(&args.config.config)
        .collect()
}

/// The JSON report of `conduit calibrate register`.
#[derive(Serialize)]
struct RegisterReport<'a> {
    a: String,
    b: String,
    #[serde(flatten)]
    result: &'a FrameFit,
}

fn run_register(args: RegisterArgs) -> Result<(), Failure> {
    let rule = outlier_rule(args.outlier)?;
    let (fa, fb) = (args.a.display().to_string(), args.b.display().to_string());
    let a = frames::read_measured(&read(&args.a)?).map_err(|e| anyhow!("{fa}: {e}"))?;
    let b = frames::read_measured(&read(&args.b)?).map_err(|e| anyhow!("{fb}: {e}"))?;
    let f = frames::register_frames(&a, &b, rule).map_err(|e| anyhow!("{fa} and {fb}: {e}"))?;
    if args.json {
        let report = RegisterReport {
            a: fa,
            b: fb,
            result: &f,
        };
        if let Some(path) = &args.report {
            write_report(path, &report, &[&args.a, &args.b])?;
        }
        warn_outliers(&f);
        return super::print_json(&serde_json::json!({
            "outputs": super::paths(args.report.as_deref()),
            "report": report,
        }));
    }
    print_transform(&fa, &fb, &f)?;
    print_residuals(&f)?;
    warn_outliers(&f);
    if let Some(path) = &args.report {
        write_report(
            path,
            &RegisterReport {
                a: fa,
                b: fb,
                result: &f,
            },
            &[&args.a, &args.b],
        )?;
    }
    Ok(())
}

/// The outlier rule of `--outlier MM` (a positive distance), or the median rule.
fn outlier_rule(outlier: Option<f64>) -> Result<OutlierRule, Failure> {
    Ok(match outlier {
        Some(mm) if !(mm.is_finite() && mm > 0.0) => {
            return Err(Failure::Usage(format!(
                "--outlier {mm}: expected a positive distance in mm"
            )));
        }
        Some(mm) => OutlierRule::Fixed(mm),
        None => OutlierRule::Median,
    })
}

/// Prints the transform from frame A (file `fa`) to frame B (file `fb`): the pairs, the 4×4
/// matrix, translation with quaternion and Euler angles, and the `[robot] workpiece_frame`
/// line.
fn print_transform(fa: &str, fb: &str, f: &FrameFit) -> Result<(), Failure> {
    let kind = match f.kind {
        PairKind::Points => "point",
        PairKind::Poses => "pose",
    };
    outln!(
        "{fa} -> {fb}: {} {kind} pairs, {} used; b = T*a (least squares)",
        f.pairs,
        f.used
    )?;
    if let Some(l) = f.axis_length {
        outln!(
            "poses weigh their orientation over axes {} mm long",
            fixed(l, 3)
        )?;
    }
    outln!("4x4 matrix:")?;
    for row in &f.matrix {
        let cells: Vec<String> = row
            .iter()
            .map(|v| format!("{:>15}", fixed(*v, 9)))
            .collect();
        outln!("{}", cells.join(""))?;
    }
    outln!(
        "translation {} mm, quaternion (w, x, y, z) {}",
        list(&f.translation, 4, ", "),
        list(&f.quaternion, 9, ", ")
    )?;
    let [ea, eb, ec] = f.euler_zyx_deg;
    outln!(
        "xyz {} mm, ZYX Euler (about z, y, x) {} deg",
        list(&f.translation, 4, ", "),
        list(&f.euler_zyx_deg, 6, ", ")
    )?;
    outln!(
        "as [robot] workpiece_frame (A = program frame, B = robot base): workpiece_frame = [{}, {}]",
        list(&f.translation, 4, ", "),
        list(&[ec, eb, ea], 6, ", ")
    )?;
    Ok(())
}

/// Prints the residuals: their rms and outlier threshold, then one row per pair.
fn print_residuals(f: &FrameFit) -> Result<(), Failure> {
    let rule = match f.rule {
        OutlierRule::Fixed(_) => "--outlier".to_owned(),
        OutlierRule::Median => format!(
            "{}x the median, at least {} mm",
            frames::MEDIAN_FACTOR,
            frames::THRESHOLD_FLOOR
        ),
    };
    outln!(
        "residuals: rms {} mm over the pairs used; outlier threshold {} mm ({rule})",
        fixed(f.rms, 4),
        fixed(f.threshold, 4)
    )?;
    let poses = f.kind == PairKind::Poses;
    outln!(
        "pair\tline_a\tline_b\tresidual_mm{}",
        if poses {
            "\tposition_mm\tangle_deg"
        } else {
            ""
        }
    )?;
    for r in &f.residuals {
        let extra = match r.angle_deg {
            Some(d) if poses => format!("\t{}\t{}", fixed(r.position, 4), fixed(d, 4)),
            _ => String::new(),
        };
        outln!(
            "{}\t{}\t{}\t{}{extra}{}",
            r.pair,
            r.line_a,
            r.line_b,
            fixed(r.residual, 4),
            if r.outlier { "\toutlier" } else { "" }
        )?;
    }
    Ok(())
}

/// Warns about the outliers left out of the fit and those kept in it.
fn warn_outliers(f: &FrameFit) {
    let named = |used: bool| -> Vec<String> {
        f.residuals
            .iter()
            .filter(|r| r.outlier && r.used == used)
            .map(|r| format!("pair {} (lines {}/{})", r.pair, r.line_a, r.line_b))
            .collect()
    };
    for (used, what) in [
        (false, "left out of the fit"),
        (true, "kept in the fit (too few pairs without them)"),
    ] {
        let pairs = named(used);
        if !pairs.is_empty() {
            warnln!(
                "{} outlier(s) {what}: {}; measure them again or check the row order",
                pairs.len(),
                pairs.join(", ")
            );
        }
    }
}
