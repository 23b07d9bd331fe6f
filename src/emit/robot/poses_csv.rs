//! A CSV of poses: one row per target of the motion plan, `x,y,z,qw,qx,qy,qz,dispense`
//! ([`conduit_poses::write_poses`]), after `#` comment lines naming the frame.
//!
//! Place in the pipeline: a dialect writer of [`super::write_robot`]. Positions are the tool
//! centre point in the workpiece frame (the conform program's frame), mm; the quaternion (w
//! first) is the tool frame's (z into the work). `dispense` is 1 on the rows reached while
//! dispensing. `conduit compensate` and any CSV reader take the file as it is.

use super::RobotSettings;
use super::frames::quaternion;
use super::motion::Step;
use super::{RobotError, banner, frame_text};
use conduit_poses::{Pose, write_poses};
use std::io::Write;

pub(super) fn write(
    steps: &[Step],
    s: &RobotSettings,
    out: &mut impl Write,
) -> Result<(), RobotError> {
    writeln!(out, "{}", banner("#", "poses"))?;
    writeln!(
        out,
        "# frame: workpiece (the conform program's frame; robot.workpiece_frame {} places it in \
         the robot base); TCP positions mm, tool-frame quaternion w first, z into the work",
        frame_text(&s.workpiece_frame)
    )?;
    let poses: Vec<Pose> = steps
        .iter()
        .filter_map(|st| match st {
            Step::Move { to, print, .. } => Some(Pose {
                position: [to.position.x, to.position.y, to.position.z],
                quaternion: quaternion(&to.rotation),
                dispense: *print,
            }),
            Step::Dispense(_) => None,
        })
        .collect();
    write_poses(&poses, out)?;
    Ok(())
}
