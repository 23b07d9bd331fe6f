//! Five-axis G-code: `G1 X Y Z I J K` (tip and tool vector) for a controller with
//! tool-centre-point interpolation, or X Y Z and two rotary axes for a tilting head or a
//! tilting table (`robot.five_axis`, `robot.rotary_axes`).
//!
//! Place in the pipeline: a dialect writer of [`super::write_robot`]. With a = (i, j, k) the
//! unit tool axis, r = √(i² + j²) and φ = atan2(j, i), the tilt is θ = atan2(r, k) (0..180°)
//! and:
//!
//! - `head`, `AC`: a = Rz(C)·Rx(A)·ẑ, so A = θ, C = φ + 90°; `BC`: a = Rz(C)·Ry(B)·ẑ, B = θ,
//!   C = φ. X Y Z is the pivot: the tip plus `pivot_length`·a.
//! - `table`, `AC`: the part turns by Rx(A)·Rz(C) about `table_centre`, which brings a to +z:
//!   A = θ, C = 90° − φ; `BC`: Ry(B)·Rz(C), B = θ, C = 180° − φ. X Y Z is the turned tip.
//!
//! Each written angle is `rotary_signs[k]` times the angle above. Where the axis is vertical C
//! is free and keeps its previous value; C is unwrapped to the value nearest the previous one,
//! so the table or head never spins round for a small change of direction. XYZ with 3
//! decimals, I J K with 6, angles with 4 (trailing zeros trimmed, as every conduit G-code
//! number), F in mm/min when it changes. Dispensing is switched by the tool's paste snippets
//! followed by `;DISPENSE:ON` / `;DISPENSE:OFF`, as the 3-axis writer does.

use super::motion::Step;
use super::{FiveAxis, RotaryAxes};
use super::{RobotError, RobotJob, banner};
use crate::geom::{Point3, Vector3};
use conduit_gcode::{fmt_f, fmt_fixed, fmt_xyz};
use nalgebra::Rotation3;
use std::io::Write;

/// Below this horizontal length of the tool axis, C is left where it was.
const VERTICAL: f64 = 1e-9;

/// The machine words of a target.
struct Machine {
    kind: FiveAxis,
    /// Tilt about x (`AC`) or y (`BC`).
    about_x: bool,
    signs: [f64; 2],
    pivot: f64,
    centre: Point3,
    /// Last C, degrees (machine angle before the sign).
    c: f64,
}

impl Machine {
    /// The words after `G1` for tip `p` and axis `a`.
    fn words(&mut self, p: &Point3, a: &Vector3) -> String {
        if self.kind == FiveAxis::Ijk {
            return format!(
                "X{} Y{} Z{} I{} J{} K{}",
                fmt_xyz(p.x),
                fmt_xyz(p.y),
                fmt_xyz(p.z),
                fmt_fixed(a.x, 6),
                fmt_fixed(a.y, 6),
                fmt_fixed(a.z, 6)
            );
        }
        let r = a.x.hypot(a.y);
        let tilt = r.atan2(a.z).to_degrees();
        if r > VERTICAL {
            let phi = a.y.atan2(a.x).to_degrees();
            let c = match (self.kind, self.about_x) {
                (FiveAxis::Head, true) => phi + 90.0,
                (FiveAxis::Head, false) => phi,
                (_, true) => 90.0 - phi,
                (_, false) => 180.0 - phi,
            };
            // The turn nearest the previous C.
            self.c = c + 360.0 * ((self.c - c) / 360.0).round();
        }
        let tilt_rot = |t: f64| {
            if self.about_x {
                Rotation3::from_axis_angle(&Vector3::x_axis(), t.to_radians())
            } else {
                Rotation3::from_axis_angle(&Vector3::y_axis(), t.to_radians())
            }
        };
        let xyz = match self.kind {
            FiveAxis::Head => p + a * self.pivot,
            _ => {
                let turn = tilt_rot(tilt)
                    * Rotation3::from_axis_angle(&Vector3::z_axis(), self.c.to_radians());
                self.centre + turn * (p - self.centre)
            }
        };
        let letter = if self.about_x { 'A' } else { 'B' };
        format!(
            "X{} Y{} Z{} {letter}{} C{}",
            fmt_xyz(xyz.x),
            fmt_xyz(xyz.y),
            fmt_xyz(xyz.z),
            fmt_fixed(self.signs[0] * tilt, 4),
            fmt_fixed(self.signs[1] * self.c, 4)
        )
    }
}

pub(super) fn write(
    steps: &[Step],
    job: &RobotJob<'_>,
    out: &mut impl Write,
) -> Result<(), RobotError> {
    let s = job.settings;
    let kind = s.five_axis;
    let mut m = Machine {
        kind,
        about_x: s.rotary_axes == RotaryAxes::AC,
        signs: s.rotary_signs,
        pivot: s.pivot_length,
        centre: Point3::new(s.table_centre[0], s.table_centre[1], s.table_centre[2]),
        c: 0.0,
    };
    let what = match kind {
        FiveAxis::Ijk => "five-axis G-code: tip X Y Z, tool vector I J K".to_owned(),
        FiveAxis::Head => format!(
            "five-axis G-code: head {}, pivot X Y Z {} mm up the tool axis",
            s.rotary_axes.name(),
            fmt_xyz(s.pivot_length)
        ),
        FiveAxis::Table => format!(
            "five-axis G-code: table {} about [{}, {}, {}], X Y Z of the turned tip",
            s.rotary_axes.name(),
            fmt_xyz(m.centre.x),
            fmt_xyz(m.centre.y),
            fmt_xyz(m.centre.z)
        ),
    };
    writeln!(out, "{}", banner(";", &what))?;
    writeln!(out, "G21")?;
    writeln!(out, "G90")?;
    let mut feed = None;
    for st in steps {
        match st {
            Step::Move { to, speed, .. } => {
                let mut line = format!("G1 {}", m.words(&to.position, &to.axis));
                let f = fmt_f(speed * 60.0);
                if feed.as_ref() != Some(&f) {
                    line.push_str(" F");
                    line.push_str(&f);
                    feed = Some(f);
                }
                writeln!(out, "{line}")?;
            }
            Step::Dispense(on) => {
                let (snippet, marker) = if *on {
                    (job.dispense_on_gcode, ";DISPENSE:ON")
                } else {
                    (job.dispense_off_gcode, ";DISPENSE:OFF")
                };
                for l in snippet.lines().filter(|l| !l.trim().is_empty()) {
                    writeln!(out, "{l}")?;
                }
                writeln!(out, "{marker}")?;
            }
        }
    }
    Ok(())
}
