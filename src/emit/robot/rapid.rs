//! ABB RAPID: `MODULE name ... ENDMODULE` with `tooldata` and `wobjdata` from the tool and
//! workpiece frames and one inline-target `MoveL` per target.
//!
//! Place in the pipeline: a dialect writer of [`super::write_robot`]. Targets are robtargets
//! in the work object (the workpiece frame): mm with 3 decimals, the quaternion `[q1, q2, q3,
//! q4]` (w first) with 6 decimals, configuration `[0,0,0,0]` (configuration monitoring is
//! switched off with `ConfL\Off`), external axes `9E9`. Each speed is a `speeddata` constant
//! (tool speed mm/s); blended dispensing moves use a `zonedata` of radius `robot.blend`,
//! others `fine`. The dispenser is `SetDO robot.dispense_signal, 1/0`. The tool's load data is
//! a placeholder (1 kg at the flange) to be replaced by the real tool's.

use super::RobotSettings;
use super::frames::{fixed, frame, quaternion};
use super::motion::Step;
use super::{RobotError, banner};
use nalgebra::Rotation3;
use std::io::Write;

/// `[x,y,z],[q1,q2,q3,q4]` of a position and rotation (the inside of a pose aggregate).
fn pose(p: [f64; 3], r: &Rotation3<f64>) -> String {
    let q = quaternion(r);
    format!(
        "[{},{},{}],[{},{},{},{}]",
        fixed(p[0], 3),
        fixed(p[1], 3),
        fixed(p[2], 3),
        fixed(q[0], 6),
        fixed(q[1], 6),
        fixed(q[2], 6),
        fixed(q[3], 6)
    )
}

fn frame_pose(v: &[f64; 6]) -> String {
    format!(
        "[{}]",
        pose([v[0], v[1], v[2]], &frame(v).rotation.to_rotation_matrix())
    )
}

pub(super) fn write(
    steps: &[Step],
    s: &RobotSettings,
    name: &str,
    out: &mut impl Write,
) -> Result<(), RobotError> {
    // Speeds in order of first use, one constant each.
    let mut speeds: Vec<String> = Vec::new();
    for st in steps {
        if let Step::Move { speed, .. } = st {
            let v = fixed(*speed, 3);
            if !speeds.contains(&v) {
                speeds.push(v);
            }
        }
    }
    let b = s.blend;
    writeln!(out, "MODULE {name}")?;
    writeln!(out, "{}", banner("  !", "RAPID"))?;
    writeln!(
        out,
        "  ! robtargets in conduit_wobj (the workpiece frame), mm; quaternions w first"
    )?;
    writeln!(
        out,
        "  PERS tooldata conduit_tool:=[TRUE,{},[1,[0,0,1],[1,0,0,0],0,0,0]];",
        frame_pose(&s.tool_frame)
    )?;
    writeln!(
        out,
        "  PERS wobjdata conduit_wobj:=[FALSE,TRUE,\"\",{},[[0,0,0],[1,0,0,0]]];",
        frame_pose(&s.workpiece_frame)
    )?;
    for (i, v) in speeds.iter().enumerate() {
        writeln!(
            out,
            "  CONST speeddata conduit_speed{}:=[{v},500,5000,1000];",
            i + 1
        )?;
    }
    writeln!(
        out,
        "  CONST zonedata conduit_blend:=[FALSE,{},{},{},{},{},{}];",
        fixed(b, 3),
        fixed(b, 3),
        fixed(b, 3),
        fixed(b / 10.0, 4),
        fixed(b, 3),
        fixed(b / 10.0, 4)
    )?;
    writeln!(out, "  PROC main()")?;
    writeln!(out, "    ConfL\\Off;")?;
    writeln!(out, "    SetDO {},0;", s.dispense_signal)?;
    for st in steps {
        match st {
            Step::Move {
                to, speed, blend, ..
            } => {
                let v = fixed(*speed, 3);
                let k = speeds.iter().position(|x| *x == v).map_or(1, |i| i + 1);
                let zone = if *blend > 0.0 {
                    "conduit_blend"
                } else {
                    "fine"
                };
                let p = to.position;
                writeln!(
                    out,
                    "    MoveL [{},[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]],conduit_speed{k},{zone},conduit_tool\\WObj:=conduit_wobj;",
                    pose([p.x, p.y, p.z], &to.rotation)
                )?;
            }
            Step::Dispense(on) => {
                writeln!(out, "    SetDO {},{};", s.dispense_signal, u8::from(*on))?;
            }
        }
    }
    writeln!(out, "  ENDPROC")?;
    writeln!(out, "ENDMODULE")?;
    Ok(())
}
