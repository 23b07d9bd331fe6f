//! `conduit check`: replay a G-code file and report problems and figures; exit 1 on errors.

use super::{Failure, args::CheckArgs, config::resolve};
use anyhow::Context;
use conduit::check::check;
use conduit::scene::FileKind;
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
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&report).context("serialising the report")?
        )?;
    } else {
        outln!("{}: {report}", args.file.display())?;
    }
    if report.has_errors() {
        errorln!(
            "{}: {} error-level finding(s)",
            args.file.display(),
            report.errors
        );
        return Err(Failure::Reported);
    }
    Ok(())
}
