//! Writing conform paths with tool axes as a robot or five-axis program file: shared by
//! `conduit conform --dialect DIALECT` and `conduit compensate --program`.

use anyhow::Context;
use conduit::config::{ConfigError, RobotSettings};
use conduit::emit::gcode::{GcodeParams, UnknownPlaceholder};
use conduit::emit::robot::{Dialect, RobotJob, write_robot};
use conduit::program::Program;
use conduit::scene::write_atomically;
use std::io::Write;
use std::path::Path;

/// Writes `program` in `dialect` to `out` (all or nothing); returns the moves written.
/// `writer` holds the dispensing tool `tool`'s paste snippets (used by `gcode-5axis`), already
/// adjusted by `conduit::conform::pressure_params`.
pub(crate) fn write_robot_file(
    out: &Path,
    dialect: Dialect,
    program: &Program,
    robot: &RobotSettings,
    (writer, tool): (&GcodeParams, usize),
) -> anyhow::Result<usize> {
    let snippet = |key: &str, pick: fn(&conduit::config::Tool) -> &String| {
        let text = writer
            .tools
            .get(tool)
            .map(pick)
            .cloned()
            .unwrap_or_default();
        writer
            .render_template(&text, tool, &[])
            .map_err(|UnknownPlaceholder(placeholder)| ConfigError::Template { placeholder })
            .with_context(|| format!("tools.{tool}.{key}"))
    };
    let on = snippet("paste_on_gcode", |t| &t.paste_on_gcode)?;
    let off = snippet("paste_off_gcode", |t| &t.paste_off_gcode)?;
    let name = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let job = RobotJob {
        settings: robot,
        name: &name,
        dispense_on_gcode: &on,
        dispense_off_gcode: &off,
    };
    let dialect_name = Dialect::NAMES
        .iter()
        .find(|(_, d)| *d == dialect)
        .map_or("robot", |(n, _)| n);
    let mut text = Vec::new();
    let moves = write_robot(program, dialect, &job, &mut text)
        .with_context(|| format!("writing the {dialect_name} program"))?;
    write_atomically(out, |f| f.write_all(&text))
        .with_context(|| format!("{}: cannot write the program", out.display()))?;
    Ok(moves)
}
