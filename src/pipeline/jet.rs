//! The jet walk (`conduit jet`): design outlines in, aerosol-jet G-code and its report out, as
//! one library call ([`run`]).
//!
//! Steps: **plan** (structures prepared: fills, corners, fillets, gaps; layers scheduled:
//! direction blocks, structures in turn — [`crate::jet::plan`]) → **program** (every path a
//! toolpath between shutter switches — [`crate::jet::program`]) → **write** it with the
//! project's G-code writer in its switched-tool style ([`write_gcode`] with
//! [`Config::jet_gcode_params`]) → **report** every corner, gap place and layer
//! ([`crate::jet::report::report`]) with the writer's totals.

use crate::config::Config;
use crate::emit::gcode::{EmitError, GcodeStats, write_gcode};
use crate::jet::{self, JetError, JetParams, JetReport, JetStats, Outline};

/// What [`run`] made.
#[derive(Debug, Clone)]
pub struct JetOutput {
    /// The G-code.
    pub gcode: Vec<u8>,
    /// What the writer wrote: paths, jetted and travel length, time.
    pub stats: JetStats,
    /// The job's report.
    pub report: JetReport,
}

/// Why the jet walk failed.
#[derive(Debug, thiserror::Error)]
pub enum JetWalkError {
    /// The job could not be planned (parameters, the jet tool).
    #[error(transparent)]
    Plan(#[from] JetError),
    /// The G-code could not be written.
    #[error(transparent)]
    Write(#[from] EmitError),
}

/// Runs the jet walk on `outlines` (read from the files `design_names`) with the line width,
/// layer height and layer count of `params` and the `[jet]` settings, tools and firmware
/// flavour of `cfg`.
pub fn run(
    outlines: &[Outline],
    design_names: Vec<String>,
    params: &JetParams,
    cfg: &Config,
) -> Result<JetOutput, JetWalkError> {
    let job = jet::plan(outlines, params, &cfg.jet, &cfg.tools)?;
    let program = jet::program(&job.layers, params.width, &cfg.jet);
    let mut gcode: Vec<u8> = Vec::new();
    let written = write_gcode(&program, &cfg.jet_gcode_params(params.width), &mut gcode)?;
    let stats = jet_stats(&written);
    let report = jet::report::report(
        design_names,
        &job.structures,
        &job.layers,
        params,
        &cfg.jet,
        stats,
    );
    Ok(JetOutput {
        gcode,
        stats,
        report,
    })
}

/// The report's totals from the writer's: shutter cycles, jetted and travel length, time.
fn jet_stats(written: &GcodeStats) -> JetStats {
    let switched = written.switched.unwrap_or_default();
    JetStats {
        paths: switched.paths,
        jetted_mm: switched.printed_mm,
        travel_mm: switched.travel_mm,
        estimated_time_s: switched.time_s,
    }
}
