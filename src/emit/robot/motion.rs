//! The motion plan shared by every robot dialect: targets (tip position, tool axis, tool frame)
//! with their speeds and blends, and dispense switches, in the order the robot runs them.
//!
//! Place in the pipeline: Program → **motion plan** → dialect writers ([`super`]). Per path:
//! from above the first point (lifted by `clearance` along its tool axis, and up to the
//! layer's safe height when that is higher) down to it, dispense on, through the points
//! (a closed path back to its start), dispense off, lift along the last tool axis. Between
//! paths the tool rises to the safe height (the layer's z: for a conform program the surface's
//! top plus `conform.travel_clearance`) when the lifted points are lower, crosses there and
//! comes down over the next path's approach point. Paths without tool axes (3-axis paths) take
//! +z.

use super::RobotError;
use super::frames::tool_rotation;
use crate::geom::{Point3, Vector3};
use crate::program::Program;
use nalgebra::Rotation3;

/// A pose of the tool centre point, in the program frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Target {
    /// Tip position, mm.
    pub position: Point3,
    /// Unit tool axis (tip toward the tool body).
    pub axis: Vector3,
    /// The tool frame (z = −axis).
    pub rotation: Rotation3<f64>,
}

impl Target {
    fn new(position: Point3, axis: Vector3) -> Self {
        Self {
            position,
            axis,
            rotation: tool_rotation(&axis),
        }
    }
}

/// One step of the plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// A straight move of the tool centre point.
    Move {
        /// Where to.
        to: Target,
        /// Speed, mm/s.
        speed: f64,
        /// Whether material is dispensed on the way.
        print: bool,
        /// Blend radius at the target, mm (0 = exact stop).
        blend: f64,
    },
    /// Dispenser on (`true`) or off.
    Dispense(bool),
}

/// Plan parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionParams {
    /// Lift along the tool axis before and after a path, mm.
    pub clearance: f64,
    /// Travel speed, mm/s.
    pub travel_speed: f64,
    /// Largest blend radius between dispensing moves, mm.
    pub blend: f64,
}

/// A blend never reaches past this fraction of the shorter neighbouring segment, so blend
/// zones of successive points do not overlap (URScript refuses overlapping blends).
const BLEND_SHARE: f64 = 0.4;

/// The motion plan of `program` (see the module docs). Fails on a tool axis that is not a
/// finite non-zero vector or does not match its path's points.
pub fn plan(program: &Program, p: &MotionParams) -> Result<Vec<Step>, RobotError> {
    let mut steps = Vec::new();
    let mut last: Option<Target> = None;
    let mut index = 0;
    for layer in &program.layers {
        for path in layer.paths() {
            index += 1;
            let n = path.points.len();
            if n < 2 {
                continue;
            }
            let axes: Vec<Vector3> = match &path.tool_axis {
                None => vec![Vector3::z(); n],
                Some(a) if a.len() == n => a
                    .iter()
                    .map(|v| {
                        v.try_normalize(1e-9)
                            .filter(|u| u.iter().all(|c| c.is_finite()))
                            .ok_or(RobotError::BadAxis { path: index })
                    })
                    .collect::<Result<_, _>>()?,
                Some(a) => {
                    return Err(RobotError::AxisCount {
                        path: index,
                        axes: a.len(),
                        points: n,
                    });
                }
            };
            let mut targets: Vec<Target> = path
                .points
                .iter()
                .zip(&axes)
                .map(|(q, a)| Target::new(*q, *a))
                .collect();
            if path.closed {
                targets.push(targets[0]);
            }
            let first = targets[0];
            let approach = Target::new(first.position + first.axis * p.clearance, first.axis);
            let safe = layer.z;
            let travel = |to: Target| Step::Move {
                to,
                speed: p.travel_speed,
                print: false,
                blend: 0.0,
            };
            match last {
                Some(from) => {
                    let high = safe.max(from.position.z).max(approach.position.z);
                    if from.position.z < high {
                        steps.push(travel(lifted(&from, high)));
                    }
                    if approach.position.z < high {
                        steps.push(travel(lifted(&approach, high)));
                    }
                }
                None if approach.position.z < safe => steps.push(travel(lifted(&approach, safe))),
                None => {}
            }
            steps.push(travel(approach));
            steps.push(travel(first));
            steps.push(Step::Dispense(true));
            let m = targets.len();
            for k in 1..m {
                let blend = if k + 1 < m {
                    let before = (targets[k].position - targets[k - 1].position).norm();
                    let after = (targets[k + 1].position - targets[k].position).norm();
                    p.blend.min(BLEND_SHARE * before.min(after))
                } else {
                    0.0
                };
                steps.push(Step::Move {
                    to: targets[k],
                    speed: path.speed,
                    print: true,
                    blend,
                });
            }
            steps.push(Step::Dispense(false));
            let end = targets[m - 1];
            let retract = Target::new(end.position + end.axis * p.clearance, end.axis);
            steps.push(travel(retract));
            last = Some(retract);
        }
    }
    Ok(steps)
}

/// `t` raised to height `z`, same orientation.
fn lifted(t: &Target, z: f64) -> Target {
    Target {
        position: Point3::new(t.position.x, t.position.y, z),
        ..*t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::{Layer, LayerItem, Role, Toolpath};

    fn program(axis: Option<Vec<Vector3>>) -> Program {
        Program {
            layers: vec![Layer {
                index: 0,
                z: 10.0,
                height: 0.25,
                items: vec![LayerItem::Path(Toolpath {
                    points: vec![Point3::new(0.0, 0.0, 1.0), Point3::new(1.0, 0.0, 1.0)],
                    closed: false,
                    role: Role::ConductiveTrace,
                    tool: 1,
                    width: 0.25,
                    height: 0.25,
                    speed: 5.0,
                    segments: None,
                    tool_axis: axis,
                })],
            }],
        }
    }

    #[test]
    fn a_path_is_approached_along_its_axis_and_left_along_it() -> Result<(), RobotError> {
        let a = Vector3::new(1.0, 0.0, 1.0).normalize();
        let steps = plan(
            &program(Some(vec![a, a])),
            &MotionParams {
                clearance: 2.0,
                travel_speed: 50.0,
                blend: 0.05,
            },
        )?;
        let moves: Vec<Point3> = steps
            .iter()
            .filter_map(|s| match s {
                Step::Move { to, .. } => Some(to.position),
                Step::Dispense(_) => None,
            })
            .collect();
        let r = std::f64::consts::SQRT_2;
        // Up to the safe height over the approach point, the approach point, the path, the lift.
        let want = [
            Point3::new(r, 0.0, 10.0),
            Point3::new(r, 0.0, 1.0 + r),
            Point3::new(0.0, 0.0, 1.0),
            Point3::new(1.0, 0.0, 1.0),
            Point3::new(1.0 + r, 0.0, 1.0 + r),
        ];
        assert_eq!(moves.len(), want.len());
        for (m, w) in moves.iter().zip(&want) {
            assert!((m - w).norm() < 1e-12, "{m} vs {w}");
        }
        assert_eq!(steps[3], Step::Dispense(true));
        assert!(
            plan(
                &program(Some(vec![a])),
                &MotionParams {
                    clearance: 2.0,
                    travel_speed: 50.0,
                    blend: 0.0,
                }
            )
            .is_err()
        );
        Ok(())
    }
}
