//! URScript: `def conduit_program(): ... end` with `set_tcp` from the tool frame and one
//! `movel(p[x, y, z, rx, ry, rz], a=..., v=...[, r=...])` per target.
//!
//! Place in the pipeline: a dialect writer of [`super::write_robot`]. URScript has no
//! workpiece register, so targets are written in the base frame (`robot.workpiece_frame`
//! applied): metres with 6 decimals (1 µm) and the rotation vector in radians with 6 decimals.
//! Speeds are m/s, the acceleration m/s², the blend radius m. The dispenser is
//! `set_digital_out(robot.dispense_output, True/False)`; a move before a switch has no blend,
//! so the switch happens at the point.

use super::RobotSettings;
use super::frames::{fixed, frame, rotation_vector};
use super::motion::Step;
use super::{RobotError, banner, frame_text};
use nalgebra::{Isometry3, UnitQuaternion};
use std::io::Write;

/// `p[x, y, z, rx, ry, rz]` of a pose (mm in, m out).
fn pose(g: &Isometry3<f64>) -> String {
    let t = g.translation.vector / 1000.0;
    let r = rotation_vector(&g.rotation.to_rotation_matrix());
    format!(
        "p[{}, {}, {}, {}, {}, {}]",
        fixed(t.x, 6),
        fixed(t.y, 6),
        fixed(t.z, 6),
        fixed(r.x, 6),
        fixed(r.y, 6),
        fixed(r.z, 6)
    )
}

pub(super) fn write(
    steps: &[Step],
    s: &RobotSettings,
    out: &mut impl Write,
) -> Result<(), RobotError> {
    let base = frame(&s.workpiece_frame);
    let n = s.dispense_output;
    writeln!(out, "def conduit_program():")?;
    writeln!(out, "{}", banner("  #", "URScript"))?;
    writeln!(
        out,
        "  # poses in the robot base frame (m, rotation vector rad); workpiece frame {}",
        frame_text(&s.workpiece_frame)
    )?;
    writeln!(out, "  set_tcp({})", pose(&frame(&s.tool_frame)))?;
    writeln!(out, "  set_digital_out({n}, False)")?;
    let a = fixed(s.acceleration / 1000.0, 3);
    for st in steps {
        match st {
            Step::Move {
                to, speed, blend, ..
            } => {
                let g = base
                    * Isometry3::from_parts(
                        to.position.coords.into(),
                        UnitQuaternion::from_rotation_matrix(&to.rotation),
                    );
                let r = if *blend > 0.0 {
                    format!(", r={}", fixed(blend / 1000.0, 6))
                } else {
                    String::new()
                };
                writeln!(
                    out,
                    "  movel({}, a={a}, v={}{r})",
                    pose(&g),
                    fixed(speed / 1000.0, 4)
                )?;
            }
            Step::Dispense(on) => {
                let v = if *on { "True" } else { "False" };
                writeln!(out, "  set_digital_out({n}, {v})")?;
            }
        }
    }
    writeln!(out, "end")?;
    Ok(())
}
