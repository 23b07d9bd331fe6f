//! Tool-centre-point (pivot) calibration: where the nozzle tip sits in the robot's flange frame,
//! from several flange poses that all hold the tip on one fixed point.
//!
//! Place in the pipeline: robot set-up, before any robot program is written (`conduit
//! calibrate tcp`). The flange poses come from a pose table (`x,y,z,qw,qx,qy,qz`, mm) or from
//! joint angles (`j1..jN`, degrees) through the arm's forward kinematics ([`super::kinematics`]).
//!
//! Method: with flange pose i = (Rᵢ, pᵢ), tip offset t (flange frame) and pivot c (base frame),
//! Rᵢ·t + pᵢ = c for every pose. Stacked, [Rᵢ | −I]·[t; c] = −pᵢ is a 3m×6 linear system,
//! solved in the least-squares sense by SVD. Its singular values say how well the poses fix the
//! solution: poses that all turn about one axis (or barely turn) leave t and c inseparable along
//! that axis, which shows as a small singular value; such sets are refused (see
//! [`MAX_CONDITION`]). At least three poses are needed: two give a rank-5 system.

use super::kinematics::{Arm, KinematicsError};
use crate::geom::{Point3, Vector3};
use conduit_poses::{Table, TableError, read_poses};
use nalgebra::{DMatrix, DVector, Isometry3, Quaternion, Translation3, UnitQuaternion};
use serde::Serialize;

/// Largest accepted condition number (largest / smallest singular value) of the pivot system.
///
/// A pose error of e mm moves the result by up to about e/σ_min. For eight poses tilted by one
/// angle toward eight directions the condition number is 181 at 1°, 36 at 5°, 23 at 8° and 7.4
/// at 25°: the limit refuses such sets below about 6°, where σ_min ≈ 0.13 and pose noise is
/// amplified about eightfold.
pub const MAX_CONDITION: f64 = 30.0;

/// Why a pivot calibration failed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TcpError {
    /// The table could not be read.
    #[error(transparent)]
    Table(#[from] TableError),
    /// The table has neither pose nor joint columns.
    ///
    /// How to fix: name the columns `x,y,z,qw,qx,qy,qz` (flange poses) or `j1,j2,...` (joint
    /// angles in degrees, with `[robot] dh`).
    #[error(
        "no flange poses: the table needs columns x,y,z,qw,qx,qy,qz or joint angles j1..jN; it has {0}"
    )]
    NoPoseColumns(String),
    /// Joint angles were given without an arm model.
    ///
    /// How to fix: set `[robot] dh` in the config given with `-c`.
    #[error("the table holds joint angles (j1..j{joints}) but [robot] dh is empty")]
    NoArm {
        /// Joint columns found.
        joints: usize,
    },
    /// The joint columns do not match the arm model.
    ///
    /// How to fix: one column `j1`..`jN` per row of `[robot] dh`.
    #[error(
        "the table has joint columns j1..j{found}, the arm model ([robot] dh) has {expected} joints"
    )]
    JointColumns {
        /// Joints of the arm model.
        expected: usize,
        /// Joint columns in the table.
        found: usize,
    },
    /// The arm model is not usable.
    #[error("arm model: {0}")]
    Arm(KinematicsError),
    /// Forward kinematics failed for a row.
    #[error("line {line}: {source}")]
    Kinematics {
        /// 1-based line number.
        line: usize,
        /// What failed.
        source: KinematicsError,
    },
    /// A flange pose (from forward kinematics) is not finite or lies beyond
    /// [`conduit_poses::MAX_POSITION`].
    ///
    /// How to fix: check the joint angles on the line and the arm model (`[robot] dh`).
    #[error("line {line}: flange position {value:e} mm is not finite or beyond the working extent")]
    PoseOutOfRange {
        /// 1-based line number.
        line: usize,
        /// The offending coordinate, mm.
        value: f64,
    },
    /// The solver did not converge, or its results are not finite numbers.
    ///
    /// How to fix: check the poses for stray rows (positions in mm, unit quaternions).
    #[error("the pivot solution is not a finite number ({what}); check the poses for stray rows")]
    NotFinite {
        /// What was not finite.
        what: &'static str,
    },
    /// Fewer than three poses.
    ///
    /// How to fix: record at least three (better eight or more) poses around the pivot.
    #[error("pivot calibration needs at least 3 poses, got {0}")]
    TooFew(usize),
    /// The poses do not turn the tool enough to separate the tip offset from the pivot.
    ///
    /// How to fix: record poses tilted by 20–40° in at least two different directions around
    /// the pivot (turning only about the tool axis, or about one axis, is not enough).
    #[error(
        "the poses turn the tool too little (or about one axis only) to fix the tip: condition number {condition:.1} (at most {max}), smallest singular value {smallest:.4}; tilt the tool by 20-40 degrees in at least two different directions around the pivot"
    )]
    Degenerate {
        /// Largest over smallest singular value (infinite when the smallest is 0).
        condition: f64,
        /// Smallest singular value of the 3m×6 system.
        smallest: f64,
        /// The limit, [`MAX_CONDITION`].
        max: f64,
    },
}

/// Most sweeps the singular value decomposition of the pivot system may take: a well-posed
/// 3m×6 system converges in a few dozen; input that does not converge is refused rather than
/// iterated for ever.
pub const MAX_SVD_ITERATIONS: usize = 1000;

/// Where the flange poses of a table came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PoseSource {
    /// Position and quaternion columns.
    Quaternions,
    /// Joint angles through forward kinematics.
    Joints,
}

/// Flange poses read from a table, with the line each came from.
#[derive(Debug, Clone, PartialEq)]
pub struct FlangePoses {
    /// Flange poses in the base frame (mm).
    pub poses: Vec<Isometry3<f64>>,
    /// 1-based line of each pose in the file.
    pub lines: Vec<usize>,
    /// How they were given.
    pub source: PoseSource,
}

/// Number of joint columns `j1`, `j2`, ... (consecutive from `j1`, case-insensitive).
fn joint_columns(t: &Table) -> usize {
    (1..)
        .take_while(|k| t.column(&format!("j{k}")).is_some())
        .count()
}

/// Reads flange poses from CSV `text`: the pose columns `x,y,z,qw,qx,qy,qz` when present,
/// otherwise joint angles `j1..jN` (degrees) through the arm of `dh` (`[robot] dh` rows).
pub fn flange_poses(text: &str, dh: &[[f64; 4]]) -> Result<FlangePoses, TcpError> {
    let table = Table::parse(text)?;
    let has_pose = ["x", "y", "z", "qw", "qx", "qy", "qz"]
        .iter()
        .all(|c| table.column(c).is_some());
    if has_pose {
        let poses = read_poses(text)?
            .iter()
            .map(|p| {
                let [w, x, y, z] = p.quaternion;
                Isometry3::from_parts(
                    Translation3::from(Vector3::from(p.position)),
                    UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
                )
            })
            .collect();
        return Ok(FlangePoses {
            poses,
            lines: table.lines,
            source: PoseSource::Quaternions,
        });
    }
    let joints = joint_columns(&table);
    if joints == 0 {
        return Err(TcpError::NoPoseColumns(table.columns.join(",")));
    }
    if dh.is_empty() {
        return Err(TcpError::NoArm { joints });
    }
    let arm = Arm::from_dh(dh).map_err(TcpError::Arm)?;
    if arm.joints() != joints {
        return Err(TcpError::JointColumns {
            expected: arm.joints(),
            found: joints,
        });
    }
    let cols: Vec<usize> = (1..=joints)
        .filter_map(|k| table.column(&format!("j{k}")))
        .collect();
    let poses = table
        .rows
        .iter()
        .zip(&table.lines)
        .map(|(row, &line)| {
            let q: Vec<f64> = cols.iter().map(|&c| row[c]).collect();
            let pose = arm
                .forward(&q)
                .map_err(|source| TcpError::Kinematics { line, source })?;
            let beyond = pose
                .translation
                .vector
                .iter()
                .copied()
                .find(|v| !v.is_finite() || v.abs() > conduit_poses::MAX_POSITION);
            match beyond {
                Some(value) => Err(TcpError::PoseOutOfRange { line, value }),
                None => Ok(pose),
            }
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(FlangePoses {
        poses,
        lines: table.lines,
        source: PoseSource::Joints,
    })
}

/// One pose's misfit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PoseResidual {
    /// 1-based pose number, in file order.
    pub pose: usize,
    /// 1-based line in the file.
    pub line: usize,
    /// |Rᵢ·t + pᵢ − c|, mm.
    pub residual: f64,
}

/// The result of a pivot calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Pivot {
    /// How the poses were given.
    pub source: PoseSource,
    /// Number of poses.
    pub poses: usize,
    /// Tip offset in the flange frame, mm.
    pub tcp: [f64; 3],
    /// The fixed point in the base frame, mm.
    pub pivot: [f64; 3],
    /// Standard error (1σ) of each tip offset component, mm, from the residuals.
    pub tcp_sigma: [f64; 3],
    /// Standard error (1σ) of each pivot component, mm.
    pub pivot_sigma: [f64; 3],
    /// Root mean square of the residuals, mm.
    pub rms: f64,
    /// The pose with the largest residual (the first of equals).
    pub worst: PoseResidual,
    /// Per-pose residuals, in file order.
    pub residuals: Vec<PoseResidual>,
    /// Singular values of the 3m×6 system, largest first.
    pub singular_values: [f64; 6],
    /// Largest over smallest singular value.
    pub condition: f64,
}

/// Pivot calibration of `poses` (flange poses in the base frame, mm); `lines` are reported
/// with the residuals (same length as `poses`; missing entries count as 0).
pub fn pivot(
    poses: &[Isometry3<f64>],
    lines: &[usize],
    source: PoseSource,
) -> Result<Pivot, TcpError> {
    let m = poses.len();
    if m < 3 {
        return Err(TcpError::TooFew(m));
    }
    let mut a = DMatrix::<f64>::zeros(3 * m, 6);
    let mut b = DVector::<f64>::zeros(3 * m);
    for (i, pose) in poses.iter().enumerate() {
        let r = pose.rotation.to_rotation_matrix().into_inner();
        let p = pose.translation.vector;
        for row in 0..3 {
            for col in 0..3 {
                a[(3 * i + row, col)] = r[(row, col)];
            }
            a[(3 * i + row, 3 + row)] = -1.0;
            b[3 * i + row] = -p[row];
        }
    }
    let not_finite = |what| TcpError::NotFinite { what };
    let svd = a
        .try_svd(true, true, 5.0 * f64::EPSILON, MAX_SVD_ITERATIONS)
        .ok_or(not_finite("the decomposition did not converge"))?;
    let mut sv: Vec<f64> = svd.singular_values.iter().copied().collect();
    sv.sort_by(|x, y| y.total_cmp(x));
    let (largest, smallest) = (sv[0], sv[5]);
    let condition = if smallest > 0.0 {
        largest / smallest
    } else {
        f64::INFINITY
    };
    if condition.is_nan() || condition > MAX_CONDITION {
        return Err(TcpError::Degenerate {
            condition,
            smallest,
            max: MAX_CONDITION,
        });
    }
    let degenerate = || TcpError::Degenerate {
        condition,
        smallest,
        max: MAX_CONDITION,
    };
    let x = svd.solve(&b, 0.0).map_err(|_| degenerate())?;
    let tcp = Vector3::new(x[0], x[1], x[2]);
    let c = Point3::new(x[3], x[4], x[5]);
    let residuals: Vec<PoseResidual> = poses
        .iter()
        .enumerate()
        .map(|(i, pose)| PoseResidual {
            pose: i + 1,
            line: lines.get(i).copied().unwrap_or(0),
            residual: (pose.rotation * tcp + pose.translation.vector - c.coords).norm(),
        })
        .collect();
    let ss: f64 = residuals.iter().map(|r| r.residual * r.residual).sum();
    let rms = (ss / m as f64).sqrt();
    let worst = residuals
        .iter()
        .copied()
        .reduce(|w, r| if r.residual > w.residual { r } else { w })
        .ok_or(TcpError::TooFew(m))?;
    // Covariance s²·(AᵀA)⁻¹ = s²·V·Σ⁻²·Vᵀ, with s² the residual variance per equation
    // (3m equations, 6 unknowns).
    let s2 = ss / (3 * m - 6) as f64;
    let v_t = svd.v_t.ok_or_else(degenerate)?;
    let variance = |k: usize| {
        (0..6)
            .map(|j| (v_t[(j, k)] / svd.singular_values[j]).powi(2))
            .sum::<f64>()
            * s2
    };
    let sigma = |k0: usize| [0, 1, 2].map(|k| variance(k0 + k).sqrt());
    let (tcp_sigma, pivot_sigma) = (sigma(0), sigma(3));
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    if !finite(&[tcp.x, tcp.y, tcp.z, c.x, c.y, c.z]) {
        return Err(not_finite("the tip offset or the pivot"));
    }
    if !finite(&[rms, worst.residual]) {
        return Err(not_finite("the residuals"));
    }
    if !finite(&tcp_sigma) || !finite(&pivot_sigma) {
        return Err(not_finite("the standard errors"));
    }
    Ok(Pivot {
        source,
        poses: m,
        tcp: [tcp.x, tcp.y, tcp.z],
        pivot: [c.x, c.y, c.z],
        tcp_sigma,
        pivot_sigma,
        rms,
        worst,
        residuals,
        singular_values: [sv[0], sv[1], sv[2], sv[3], sv[4], sv[5]],
        condition,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Unit;

    #[test]
    fn results_that_are_not_finite_are_an_error() {
        let mut p = poses(
            Vector3::new(1.0, 2.0, 150.0),
            Point3::new(500.0, 0.0, 100.0),
            25.0,
        );
        p[3].translation.vector.x = 1e300;
        let e = pivot(&p, &[], PoseSource::Quaternions);
        assert!(matches!(e, Err(TcpError::NotFinite { .. })), "{e:?}");
    }

    #[test]
    fn a_table_with_a_far_or_overflowing_row_is_refused_by_line() {
        let text = "x,y,z,qw,qx,qy,qz\n1,2,3,1,0,0,0\n1,2,3,-0.2,-1e308,0.4,0.1\n";
        let e = flange_poses(text, &[]);
        assert!(
            matches!(
                e,
                Err(TcpError::Table(TableError::QuaternionLength { line: 3 }))
            ),
            "{e:?}"
        );
    }

    /// Flange poses holding the tip `t` on `c`: tilted by `tilt` degrees toward eight
    /// directions, each also turned about the tool axis.
    fn poses(t: Vector3, c: Point3, tilt: f64) -> Vec<Isometry3<f64>> {
        (0..8)
            .map(|k| {
                let dir = f64::from(k) * std::f64::consts::FRAC_PI_4;
                let axis = Unit::new_normalize(Vector3::new(dir.cos(), dir.sin(), 0.0));
                let r = UnitQuaternion::from_axis_angle(&axis, tilt.to_radians())
                    * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.3 * f64::from(k));
                // p = c − R·t puts the tip on c.
                Isometry3::from_parts(Translation3::from(c.coords - r * t), r)
            })
            .collect()
    }

    #[test]
    fn exact_poses_give_the_tip_and_pivot_exactly() {
        let (t, c) = (
            Vector3::new(1.5, -2.0, 120.0),
            Point3::new(400.0, 50.0, 30.0),
        );
        let p = pivot(&poses(t, c, 25.0), &[], PoseSource::Quaternions).expect("calibrates");
        assert!((Vector3::from(p.tcp) - t).norm() < 1e-9, "{p:?}");
        assert!((Point3::from(p.pivot) - c).norm() < 1e-9, "{p:?}");
        assert!(p.rms < 1e-9 && p.tcp_sigma.iter().all(|s| *s < 1e-9));
        assert!(p.condition < 10.0, "{}", p.condition);
    }

    #[test]
    fn too_few_or_barely_turned_poses_are_refused() {
        let (t, c) = (Vector3::new(0.0, 0.0, 100.0), Point3::new(0.0, 0.0, 0.0));
        let all = poses(t, c, 25.0);
        assert_eq!(
            pivot(&all[..2], &[], PoseSource::Quaternions),
            Err(TcpError::TooFew(2))
        );
        // 1° of tilt: condition number 181.
        let e = pivot(&poses(t, c, 1.0), &[], PoseSource::Quaternions);
        assert!(
            matches!(e, Err(TcpError::Degenerate { condition, .. }) if condition > MAX_CONDITION),
            "{e:?}"
        );
        // Turning only about one axis (the tool's) leaves t_z and c_z inseparable.
        let spun: Vec<_> = (0..6)
            .map(|k| {
                let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), f64::from(k));
                Isometry3::from_parts(Translation3::from(c.coords - r * t), r)
            })
            .collect();
        assert!(matches!(
            pivot(&spun, &[], PoseSource::Quaternions),
            Err(TcpError::Degenerate { .. })
        ));
    }

    #[test]
    fn tables_of_poses_and_of_joints_are_read_with_their_lines() {
        let f =
            flange_poses("# flange poses\nx,y,z,qw,qx,qy,qz\n1,2,3,2,0,0,0\n", &[]).expect("reads");
        assert_eq!(f.lines, vec![3]);
        assert_eq!(f.source, PoseSource::Quaternions);
        assert!((f.poses[0].translation.vector - Vector3::new(1.0, 2.0, 3.0)).norm() < 1e-12);
        assert!(f.poses[0].rotation.angle() < 1e-12);

        let dh = [[100.0, 0.0, 0.0, 0.0], [50.0, 0.0, 0.0, 0.0]];
        let f = flange_poses("J2,j1\n-90,90\n", &dh).expect("reads");
        assert_eq!(f.source, PoseSource::Joints);
        assert!((f.poses[0].translation.vector - Vector3::new(50.0, 100.0, 0.0)).norm() < 1e-9);
        assert_eq!(
            flange_poses("j1,j2\n0,0\n", &[]),
            Err(TcpError::NoArm { joints: 2 })
        );
        assert_eq!(
            flange_poses("j1\n0\n", &dh),
            Err(TcpError::JointColumns {
                expected: 2,
                found: 1
            })
        );
        assert!(matches!(
            flange_poses("a,b\n0,0\n", &dh),
            Err(TcpError::NoPoseColumns(_))
        ));
    }
}
