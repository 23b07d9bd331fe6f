//! `conduit check`: replay a G-code file and report problems and figures; exit 1 on errors.

use super::{Failure, args::CheckArgs, config::resolve};
use anyhow::Context;
use conduit::check::check;

pub(crate) fn run(args: CheckArgs) -> Result<(), Failure> {
    let cfg = resolve(&args.config)?;
    let bytes = std::fs::read(&args.file)
        .with_context(|| format!("{}: cannot read file", args.file.display()))?;
    let gcode = conduit_gcode::parse(&bytes).with_context(|| format!("{}", args.file.display()))?;
    let report = check(&gcode, &cfg.check_params());
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).context("serialising the report")?
        );
    } else {
        println!("{}: {report}", args.file.display());
    }
    if report.has_errors() {
        eprintln!(
            "error: {}: {} error-level finding(s)",
            args.file.display(),
            report.errors
        );
        return Err(Failure::Reported);
    }
    Ok(())
}
