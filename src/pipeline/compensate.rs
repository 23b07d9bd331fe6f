//! The gap-compensation walks (`conduit compensate`): a robot path and its measured gaps (or a
//! substrate to simulate them on) in, the compensated path, its report and optionally the next
//! robot program out, each as one library call.
//!
//! - [`measured`]: one pass over measured gaps ([`crate::robot::compensate::compensate_pass`]).
//! - [`simulated`]: the measure → compensate loop on simulated gaps
//!   ([`crate::robot::compensate::simulate::run`]).
//! - [`program`]: the compensated path's dispensing runs as a robot or five-axis program, with
//!   the same writers and `[robot]` settings as the conform walk.

use serde::Serialize;

use super::conform::{ConformWalkError, robot_program};
use crate::config::Config;
use crate::conform::{self, ConformError, orient};
use crate::emit::robot::Dialect;
use crate::robot::compensate::gaps::{Key, OnPath};
use crate::robot::compensate::simulate::{self, ErrorModel, PassFigures};
use crate::robot::compensate::substrate::Substrate;
use crate::robot::compensate::{
    self as comp, CompensateError, CorrectionStats, GapStats, Params, Path,
};
use conduit_poses::Pose;

/// Micrometres per millimetre.
const UM: f64 = 1000.0;

/// A compensated path: the pose table to write (comment lines, then the poses) and the report.
#[derive(Debug, Clone)]
pub struct Compensated<R> {
    /// `#` lines of the table: the input's own, then one saying what was done.
    pub comments: Vec<String>,
    /// The compensated poses.
    pub poses: Vec<Pose>,
    /// What the pass (or the simulation) found and did.
    pub report: R,
}

/// The report of a pass over measured gaps.
#[derive(Debug, Clone, Serialize)]
pub struct MeasuredReport {
    /// The path table's name.
    pub path: String,
    /// The gap table's name.
    pub gaps: String,
    /// Poses in the path.
    pub poses: usize,
    /// Whether the path ends where it starts (smoothed around its loop).
    pub closed: bool,
    /// Target gap, mm.
    pub target_mm: f64,
    /// Sensor angle from the tool axis, degrees.
    pub sensor_angle_deg: f64,
    /// Smoothing (standard deviation along the path), mm.
    pub smoothing_mm: f64,
    /// How the readings were placed on the path.
    pub placed_by: Key,
    /// Readings in the gap table.
    pub readings: usize,
    /// Poses before the first or after the last reading.
    pub poses_outside_measurement: usize,
    /// The gaps before the pass, mm.
    pub before_mm: GapStats,
    /// The corrections, mm.
    pub correction_mm: CorrectionStats,
}

/// The report of a simulation.
#[derive(Debug, Clone, Serialize)]
pub struct SimulatedReport {
    /// The path table's name.
    pub path: String,
    /// The simulated substrate as given (`sphere:15`, a file name).
    pub surface: String,
    /// The robot error model.
    pub error_model: ErrorModel,
    /// The point the tilt turns about (the middle of the path), mm.
    pub pivot: [f64; 3],
    /// Poses in the path.
    pub poses: usize,
    /// Target gap, mm.
    pub target_mm: f64,
    /// Sensor angle from the tool axis, degrees.
    pub sensor_angle_deg: f64,
    /// Smoothing (standard deviation along the path), mm.
    pub smoothing_mm: f64,
    /// The real gaps of the uncompensated path, mm.
    pub uncompensated_mm: GapStats,
    /// Every pass: readings, corrections and the real gaps after it.
    pub passes: Vec<PassFigures>,
    /// Gap variation (max − min of the real gaps) before and after every pass, µm.
    pub variation_um: Vec<f64>,
}

/// A simulation's outcome: the compensated path and the first pass's simulated readings.
#[derive(Debug, Clone)]
pub struct Simulated {
    /// The compensated path and the report.
    pub path: Compensated<SimulatedReport>,
    /// The first pass's readings: pose index, arc length along the path (mm), simulated gap
    /// reading (mm).
    pub first_readings: Vec<[f64; 3]>,
}

impl Simulated {
    /// The first pass's readings as a gap table (`index,s,reading` rows after a `#` line), the
    /// form `conduit compensate --gaps` reads.
    pub fn readings_table(&self) -> Result<String, CompensateWalkError> {
        let rows: Vec<Vec<f64>> = self.first_readings.iter().map(|r| r.to_vec()).collect();
        let mut buf = Vec::new();
        conduit_poses::write_table(&["index", "s", "reading"], &rows, 6, &mut buf)
            .map_err(CompensateWalkError::Readings)?;
        Ok([
            "# simulated gap readings, mm".to_owned(),
            String::from_utf8_lossy(&buf).into_owned(),
        ]
        .join("\n"))
    }
}

/// Why a compensation walk failed.
#[derive(Debug, thiserror::Error)]
pub enum CompensateWalkError {
    /// The simulation could not run.
    #[error("{path}: {error}")]
    Simulate {
        /// The path table's name.
        path: String,
        /// What went wrong.
        error: CompensateError,
    },
    /// The error model of `[compensate]` is not usable.
    #[error("{0}")]
    Model(CompensateError),
    /// The path has no dispensing run to write as a program.
    #[error("{path}: no dispensing run of two or more poses")]
    NoRuns {
        /// The path table's name.
        path: String,
    },
    /// The dispensing tool of `[conform]` is not usable.
    #[error("[conform]: {0}")]
    Conform(ConformError),
    /// The program could not be written.
    #[error(transparent)]
    Program(#[from] ConformWalkError),
    /// The readings table could not be written.
    #[error("gap readings: {0}")]
    Readings(std::io::Error),
}

/// One pass over the measured gaps `on` (read from `gaps_name`) of `path` (named `path_name`,
/// its table's `#` lines `header`).
pub fn measured(
    (path, path_name, header): (&Path, &str, &[String]),
    (on, gaps_name): (&OnPath, &str),
    params: &Params,
) -> Compensated<MeasuredReport> {
    let pass = comp::compensate_pass(path, &on.readings, params);
    let mut comments = header.to_vec();
    comments.push(format!(
        "# compensated by conduit compensate: gaps {gaps_name}, target {} mm, sensor angle {} deg, smoothing {} mm",
        params.target, params.sensor_angle, params.smoothing
    ));
    let report = MeasuredReport {
        path: path_name.to_owned(),
        gaps: gaps_name.to_owned(),
        poses: path.poses.len(),
        closed: path.is_closed(),
        target_mm: params.target,
        sensor_angle_deg: params.sensor_angle,
        smoothing_mm: params.smoothing,
        placed_by: on.key,
        readings: on.rows,
        poses_outside_measurement: on.outside,
        before_mm: pass.before,
        correction_mm: pass.correction,
    };
    Compensated {
        comments,
        poses: pass.poses,
        report,
    }
}

/// The measure → compensate loop of `path` (named `path_name`, its table's `#` lines
/// `header`) on simulated gaps over `substrate` (given as `spec`), with the error model,
/// passes and parameters of `cfg`'s `[compensate]`.
pub fn simulated(
    (path, path_name, header): (&Path, &str, &[String]),
    (substrate, spec): (&Substrate, &str),
    params: &Params,
    cfg: &Config,
) -> Result<Simulated, CompensateWalkError> {
    let model = ErrorModel::from_settings(&cfg.compensate).map_err(CompensateWalkError::Model)?;
    let passes = cfg.compensate.passes as usize;
    let sim = simulate::run(path, substrate, &model, params, passes).map_err(|error| {
        CompensateWalkError::Simulate {
            path: path_name.to_owned(),
            error,
        }
    })?;
    let mut variation = vec![sim.uncompensated.variation * UM];
    variation.extend(sim.passes.iter().map(|p| p.after.variation * UM));
    let report = SimulatedReport {
        path: path_name.to_owned(),
        surface: spec.to_owned(),
        error_model: model,
        pivot: [sim.pivot.x, sim.pivot.y, sim.pivot.z],
        poses: path.poses.len(),
        target_mm: params.target,
        sensor_angle_deg: params.sensor_angle,
        smoothing_mm: params.smoothing,
        uncompensated_mm: sim.uncompensated,
        passes: sim.passes.clone(),
        variation_um: variation,
    };
    let s = path.arc_lengths();
    let first_readings = sim
        .first_readings
        .iter()
        .zip(s)
        .enumerate()
        .map(|(i, (r, s))| [i as f64, s, *r])
        .collect();
    let mut comments = header.to_vec();
    comments.push(format!(
        "# compensated by conduit compensate: {passes} simulated pass(es) on {spec}, target {} mm",
        params.target
    ));
    Ok(Simulated {
        path: Compensated {
            comments,
            poses: sim.poses,
            report,
        },
        first_readings,
    })
}

/// The dispensing runs of `poses` (of the path named `path_name`) as a robot or five-axis
/// program in `dialect` named `name`; travels clear the highest tip by
/// `conform.travel_clearance`, the dispenser is switched by the conform tool's snippets.
pub fn program(
    poses: &[Pose],
    path_name: &str,
    (dialect, name): (Dialect, &str),
    cfg: &Config,
) -> Result<Vec<u8>, CompensateWalkError> {
    let (paths, axes) = comp::runs(poses);
    if paths.is_empty() {
        return Err(CompensateWalkError::NoRuns {
            path: path_name.to_owned(),
        });
    }
    let top = paths.iter().flatten().map(|p| p.z).fold(f64::MIN, f64::max);
    let program = orient::program(
        &paths,
        &axes,
        &cfg.conform,
        top + cfg.conform.travel_clearance,
    );
    let writer = conform::pressure_params(cfg.gcode_params(), &cfg.conform)
        .map_err(CompensateWalkError::Conform)?;
    let (text, _) = robot_program(&program, dialect, cfg, &writer, name)?;
    Ok(text)
}
