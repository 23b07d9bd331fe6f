//! The jet walk (`conduit jet`): design outlines in, aerosol-jet G-code and its report out, as
//! one library call ([`run`]).
//!
//! Steps: **plan** (structures prepared: fills, corners, fillets, gaps; layers scheduled:
//! direction blocks, structures in turn — [`crate::jet::plan`]) → **write** the G-code with the
//! shutter around every path ([`crate::jet::write_jet`]) → **report** every corner, gap place
//! and layer ([`crate::jet::report::report`]).

use crate::config::Config;
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

/// Runs the jet walk on `outlines` (read from the files `design_names`) with the line width,
/// layer height and layer count of `params` and the `[jet]` settings, tools and firmware
/// flavour of `cfg`.
pub fn run(
    outlines: &[Outline],
    design_names: Vec<String>,
    params: &JetParams,
    cfg: &Config,
) -> Result<JetOutput, JetError> {
    let job = jet::plan(outlines, params, &cfg.jet, &cfg.tools)?;
    let mut gcode: Vec<u8> = Vec::new();
    let stats = jet::write_jet(
        &job.layers,
        params.width,
        (&cfg.jet, cfg.printer.flavor),
        &mut gcode,
    );
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
