//! Robot and five-axis programs of oriented paths: URScript, KUKA KRL, ABB RAPID, a CSV of
//! poses, and five-axis G-code.
//!
//! Place in the pipeline: Program → **emit** → file, beside the 3-axis G-code writer
//! ([`crate::emit::gcode`]). Every dialect writes the same motion plan ([`motion`]): targets
//! of the tool centre point (tip position and tool frame, from each toolpath's tool axis) with
//! dispense switches between them. Frames and rotation notations are in [`frames`]; the
//! settings come from `[robot]` ([`RobotSettings`]).
//!
//! | dialect | file | positions | rotation | dispense |
//! |---|---|---|---|---|
//! | `urscript` | `def conduit_program(): ... end` | base frame, m | rotation vector, rad | `set_digital_out(n, True/False)` |
//! | `krl` | `.src`: `DEF name( ) ... END` | `$BASE` = workpiece, mm | ZYX Euler A, B, C, deg | `$OUT[n]=TRUE/FALSE` |
//! | `rapid` | `MODULE name ... ENDMODULE` | `wobjdata` = workpiece, mm | quaternion w first | `SetDO name, 1/0` |
//! | `poses-csv` | `x,y,z,qw,qx,qy,qz,dispense` | workpiece frame, mm | quaternion w first | column |
//! | `gcode-5axis` | `G1 X Y Z I J K` or `X Y Z` + rotary axes | program frame, mm | tool vector or angles | the paste snippets |
//!
//! Numbers are written with fixed decimals (G-code through [`conduit_gcode`]'s formatter), so
//! the same program gives the same bytes.

pub mod frames;
mod gcode5;
mod krl;
pub mod motion;
mod poses_csv;
mod rapid;
pub mod settings;
mod urscript;

use crate::program::Program;
use motion::{MotionParams, Step};
pub use settings::{FiveAxis, RobotSettings, RotaryAxes};
use std::io::Write;

/// A program dialect of [`write_robot`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dialect {
    /// Universal Robots URScript.
    Urscript,
    /// KUKA Robot Language (`.src`).
    Krl,
    /// ABB RAPID module.
    Rapid,
    /// A CSV of poses ([`conduit_poses::write_poses`]).
    PosesCsv,
    /// Five-axis G-code (see `robot.five_axis`).
    Gcode5Axis,
}

impl Dialect {
    /// Every dialect with its command-line name.
    pub const NAMES: [(&'static str, Dialect); 5] = [
        ("urscript", Dialect::Urscript),
        ("krl", Dialect::Krl),
        ("rapid", Dialect::Rapid),
        ("poses-csv", Dialect::PosesCsv),
        ("gcode-5axis", Dialect::Gcode5Axis),
    ];

    /// The dialect named `name` on the command line.
    pub fn from_name(name: &str) -> Option<Dialect> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, d)| *d)
    }

    /// The dialect's command-line name.
    pub fn name(self) -> &'static str {
        Self::NAMES
            .iter()
            .find(|(_, d)| *d == self)
            .map_or("robot", |(n, _)| n)
    }
}

/// Why a robot program could not be written.
#[derive(Debug, thiserror::Error)]
pub enum RobotError {
    /// A `[robot]` value the writer cannot use (the problem names the key).
    ///
    /// How to fix: correct the key (`conduit config --defaults` documents it).
    #[error("invalid [robot] settings: {0}")]
    Settings(String),
    /// A toolpath's tool axes do not match its points.
    #[error("path {path}: {axes} tool axes for {points} points")]
    AxisCount {
        /// 1-based path number.
        path: usize,
        /// Axes given.
        axes: usize,
        /// Points.
        points: usize,
    },
    /// A tool axis is zero or not finite.
    #[error("path {path}: a tool axis is zero or not a finite vector")]
    BadAxis {
        /// 1-based path number.
        path: usize,
    },
    /// The program has no path to write.
    ///
    /// How to fix: check that the design lies over the surface.
    #[error("the program has no path with two or more points")]
    Empty,
    /// Writing failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

/// What a robot program is written with besides the Program.
#[derive(Debug, Clone, Copy)]
pub struct RobotJob<'a> {
    /// The `[robot]` settings.
    pub settings: &'a RobotSettings,
    /// Name of the program (KRL `DEF`, RAPID `MODULE`), made a valid identifier by
    /// [`program_name`].
    pub name: &'a str,
    /// G-code lines that switch the dispenser on (`gcode-5axis`).
    pub dispense_on_gcode: &'a str,
    /// G-code lines that switch it off.
    pub dispense_off_gcode: &'a str,
}

/// `name` as a program identifier: letters, digits and `_` (others become `_`), starting with a
/// letter (`p` is put before otherwise), at most 24 characters (KRL's limit).
pub fn program_name(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if !s.chars().next().is_some_and(|c| c.is_ascii_alphabetic()) {
        s.insert(0, 'p');
    }
    s.truncate(24);
    s
}

/// Writes `program` in `dialect` to `out`; returns the number of moves written.
pub fn write_robot(
    program: &Program,
    dialect: Dialect,
    job: &RobotJob<'_>,
    out: &mut impl Write,
) -> Result<usize, RobotError> {
    let s = job.settings;
    if let Some(p) = s.problems().into_iter().next() {
        return Err(RobotError::Settings(p));
    }
    let steps = motion::plan(
        program,
        &MotionParams {
            clearance: s.clearance,
            travel_speed: s.travel_speed,
            blend: s.blend,
        },
    )?;
    if steps.is_empty() {
        return Err(RobotError::Empty);
    }
    let name = program_name(job.name);
    let mut text = Vec::new();
    match dialect {
        Dialect::Urscript => urscript::write(&steps, s, &mut text)?,
        Dialect::Krl => krl::write(&steps, s, &name, &mut text)?,
        Dialect::Rapid => rapid::write(&steps, s, &name, &mut text)?,
        Dialect::PosesCsv => poses_csv::write(&steps, s, &mut text)?,
        Dialect::Gcode5Axis => gcode5::write(&steps, job, &mut text)?,
    }
    out.write_all(&text)?;
    Ok(steps
        .iter()
        .filter(|st| matches!(st, Step::Move { .. }))
        .count())
}

/// The first line of every program: what wrote it (as a comment after `lead`).
fn banner(lead: &str, what: &str) -> String {
    format!("{lead} conduit {} {what}", env!("CARGO_PKG_VERSION"))
}

/// A frame `[x, y, z, rx, ry, rz]` as text, 3 decimals.
fn frame_text(v: &[f64; 6]) -> String {
    let parts: Vec<String> = v.iter().map(|x| frames::fixed(*x, 3)).collect();
    format!("[{}]", parts.join(", "))
}
