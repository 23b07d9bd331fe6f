//! KUKA KRL: a `.src` program `DEF name( ) ... END` with `$BASE` and `$TOOL` from the
//! workpiece and tool frames and one `LIN {X, Y, Z, A, B, C}` per target.
//!
//! Place in the pipeline: a dialect writer of [`super::write_robot`]. Targets are in the
//! workpiece frame (`$BASE`), mm with 3 decimals, A, B, C the ZYX Euler angles in degrees with
//! 4 decimals. `$VEL.CP` (m/s) is set when the speed changes. Blended dispensing moves end in
//! `C_DIS` with `$APO.CDIS = robot.blend` (and `$ADVANCE = 3`). The dispenser is
//! `$OUT[robot.dispense_output]`, after `WAIT SEC 0` so the advance run does not switch it
//! early. The first motion is a `PTP $AXIS_ACT` (the block-coincidence run KRL needs before a
//! `LIN`).

use super::RobotSettings;
use super::frames::{fixed, zyx_degrees};
use super::motion::Step;
use super::{RobotError, banner};
use nalgebra::Rotation3;
use std::io::Write;

/// `{X x,Y y,Z z,A a,B b,C c}` of a position and rotation (the FRAME/E6POS aggregate).
fn aggregate(kind: &str, p: [f64; 3], r: &Rotation3<f64>) -> String {
    let [a, b, c] = zyx_degrees(r);
    format!(
        "{{{kind}X {},Y {},Z {},A {},B {},C {}}}",
        fixed(p[0], 3),
        fixed(p[1], 3),
        fixed(p[2], 3),
        fixed(a, 4),
        fixed(b, 4),
        fixed(c, 4)
    )
}

/// The aggregate of a `[x, y, z, rx, ry, rz]` frame.
fn frame_aggregate(v: &[f64; 6]) -> String {
    let r = super::frames::frame(v).rotation.to_rotation_matrix();
    aggregate("FRAME: ", [v[0], v[1], v[2]], &r)
}

pub(super) fn write(
    steps: &[Step],
    s: &RobotSettings,
    name: &str,
    out: &mut impl Write,
) -> Result<(), RobotError> {
    let n = s.dispense_output;
    writeln!(out, "&ACCESS RVP")?;
    writeln!(out, "&REL 1")?;
    writeln!(out, "DEF {name}( )")?;
    writeln!(out, "{}", banner(";", "KRL"))?;
    writeln!(
        out,
        "; LIN targets in $BASE (the workpiece frame), mm; A, B, C: ZYX Euler angles, deg"
    )?;
    writeln!(out, "BAS(#INITMOV,0)")?;
    writeln!(out, "$BASE={}", frame_aggregate(&s.workpiece_frame))?;
    writeln!(out, "$TOOL={}", frame_aggregate(&s.tool_frame))?;
    // Blending (C_DIS) needs the advance run to see the next motions.
    writeln!(out, "$ADVANCE=3")?;
    writeln!(out, "$APO.CDIS={}", fixed(s.blend, 3))?;
    writeln!(out, "$OUT[{n}]=FALSE")?;
    writeln!(out, "PTP $AXIS_ACT")?;
    let mut speed = None;
    for st in steps {
        match st {
            Step::Move {
                to,
                speed: v,
                blend,
                ..
            } => {
                let vel = fixed(v / 1000.0, 4);
                if speed.as_ref() != Some(&vel) {
                    writeln!(out, "$VEL.CP={vel}")?;
                    speed = Some(vel);
                }
                let p = to.position;
                let c_dis = if *blend > 0.0 { " C_DIS" } else { "" };
                writeln!(
                    out,
                    "LIN {}{c_dis}",
                    aggregate("", [p.x, p.y, p.z], &to.rotation)
                )?;
            }
            Step::Dispense(on) => {
                writeln!(out, "WAIT SEC 0")?;
                let v = if *on { "TRUE" } else { "FALSE" };
                writeln!(out, "$OUT[{n}]={v}")?;
            }
        }
    }
    writeln!(out, "END")?;
    Ok(())
}
