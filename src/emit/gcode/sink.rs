//! Where the G-code writer's output goes: lines of text, and the machine motions they command.

use crate::geom::Point3;
use crate::program::Role;

/// What a motion does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MotionKind {
    /// A non-printing move (travel, layer change, z-hop).
    Travel,
    /// A printing move (filament E or paste flow on).
    Extrude,
    /// Filament pulled back (an E-only move or firmware `G10`).
    Retract,
    /// Filament pushed forward again (an E-only move or firmware `G11`).
    Unretract,
}

/// One machine motion, reported to [`GcodeSink::motion`] after the line that commands it.
///
/// Positions are machine coordinates, after the tool's XY offset (see
/// [`write_program`](super::write_program)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// What the motion does.
    pub kind: MotionKind,
    /// Active tool, if one is selected.
    pub tool: Option<usize>,
    /// Role of the path being printed ([`MotionKind::Extrude`] only).
    pub role: Option<Role>,
    /// Where the nozzle was; `None` before the first move (position unknown after the start
    /// G-code).
    pub from: Option<Point3>,
    /// Where the nozzle is after the motion.
    pub to: Point3,
    /// Filament moved, mm (positive forward, negative when retracting); 0 for travels and paste
    /// tools.
    pub e: f64,
    /// Feed rate, mm/s (of the nozzle, or of the filament for E-only moves).
    pub feed: f64,
}

/// Receives the G-code writer's output.
///
/// The same writer can feed a file ([`String`], `Vec<u8>`), a preview or a test [`Recorder`].
pub trait GcodeSink {
    /// One line of G-code, without its line terminator.
    fn line(&mut self, line: &str);

    /// The motion commanded by the line just written. Default: ignored.
    fn motion(&mut self, _motion: &Motion) {}
}

impl GcodeSink for String {
    fn line(&mut self, line: &str) {
        self.push_str(line);
        self.push('\n');
    }
}

impl GcodeSink for Vec<u8> {
    fn line(&mut self, line: &str) {
        self.extend_from_slice(line.as_bytes());
        self.push(b'\n');
    }
}

/// A sink that keeps every line and motion, for tests and previews.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Recorder {
    /// The lines, in order.
    pub lines: Vec<String>,
    /// The motions, in order.
    pub motions: Vec<Motion>,
}

impl GcodeSink for Recorder {
    fn line(&mut self, line: &str) {
        self.lines.push(line.to_owned());
    }

    fn motion(&mut self, motion: &Motion) {
        self.motions.push(*motion);
    }
}
