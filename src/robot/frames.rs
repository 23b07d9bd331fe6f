//! Frame registration for robot set-up: the rigid transform between two frames (a scanner and
//! a robot base, a fixture and a machine) from the same points, or the same poses, measured in
//! both, with per-pair residuals and outlier flags.
//!
//! Place in the pipeline: robot set-up (`conduit calibrate register`), before conformal paths
//! are planned in one frame and printed in the other. The fit itself is the least-squares
//! (Kabsch) registration of [`crate::conform::register::least_squares`].
//!
//! - **Points** (`x,y,z` columns, same row order in both tables): the fit of the point pairs.
//! - **Poses** (`x,y,z,qw,qx,qy,qz` in both tables): each pose stands for four points, its
//!   position and the ends of its three axes drawn L long, and the fit runs over all of them.
//!   L is the RMS distance of the positions from their centroid (at least [`MIN_AXIS_LENGTH`]),
//!   so an orientation error of ε radians weighs as much as the position error it causes across
//!   the measured volume. Solving the rotation from the orientations alone would ignore what
//!   the positions say about it (and the other way round); this weighting uses both, and a
//!   single pose pair already fixes the transform.
//!
//! Outliers ([`OutlierRule`]): a pair whose residual is above the threshold is flagged and left
//! out, and the fit is repeated until the set of flagged pairs stops changing (at most
//! [`MAX_ROUNDS`] fits; a fit that would have too few pairs left keeps the previous one). The default threshold is [`MEDIAN_FACTOR`] × the median residual, at
//! least [`THRESHOLD_FLOOR`]: the median is not pulled up by the outliers themselves (the RMS
//! is), and for Gaussian noise of σ per axis the median residual is about 1.54σ, so 3× the
//! median is 4.6σ, which a good pair exceeds with a probability below 10⁻⁴.

use crate::conform::register::{RegisterError, least_squares};
use crate::geom::{Point3, Vector3};
use conduit_poses::{Table, TableError, read_poses};
use nalgebra::{Isometry3, Quaternion, UnitQuaternion};
use serde::Serialize;

/// Default outlier threshold as a multiple of the median residual.
pub const MEDIAN_FACTOR: f64 = 3.0;
/// Smallest default outlier threshold, mm: below what a robot or a scanner measures, so exact
/// data does not flag its rounding noise.
pub const THRESHOLD_FLOOR: f64 = 0.01;
/// Shortest axis length L for pose pairs, mm (poses measured at one spot).
pub const MIN_AXIS_LENGTH: f64 = 50.0;
/// Most fits of the outlier loop.
pub const MAX_ROUNDS: usize = 10;

/// Why a frame registration failed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum FramesError {
    /// A table could not be read.
    #[error(transparent)]
    Table(#[from] TableError),
    /// The two tables hold different numbers of rows.
    ///
    /// How to fix: one row per measured point or pose, in the same order in both files.
    #[error("the first table has {a} row(s), the second {b}; rows are paired in order")]
    Count {
        /// Rows of the first table.
        a: usize,
        /// Rows of the second table.
        b: usize,
    },
    /// The outlier threshold is not a positive number.
    ///
    /// How to fix: give a distance in mm greater than 0.
    #[error("the outlier threshold must be a positive distance in mm, got {0}")]
    Threshold(f64),
    /// The fit failed (too few pairs, or points on one line).
    #[error(transparent)]
    Register(#[from] RegisterError),
}

/// A point, or a pose, measured in one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Position, mm.
    pub position: Point3,
    /// Orientation, when the table has quaternion columns.
    pub rotation: Option<UnitQuaternion<f64>>,
    /// 1-based line in the file.
    pub line: usize,
}

/// Reads measured points (`x,y,z`) or poses (`x,y,z,qw,qx,qy,qz`) from CSV `text`; the
/// quaternion is read when all four of its columns are present.
pub fn read_measured(text: &str) -> Result<Vec<Measured>, FramesError> {
    let table = Table::parse(text)?;
    if ["qw", "qx", "qy", "qz"]
        .iter()
        .all(|c| table.column(c).is_some())
    {
        let poses = read_poses(text)?;
        return Ok(poses
            .iter()
            .zip(&table.lines)
            .map(|(p, &line)| {
                let [w, x, y, z] = p.quaternion;
                Measured {
                    position: Point3::from(p.position),
                    rotation: Some(UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z))),
                    line,
                }
            })
            .collect());
    }
    let idx = table.require(&["x", "y", "z"])?;
    Ok(table
        .rows
        .iter()
        .zip(&table.lines)
        .map(|(r, &line)| Measured {
            position: Point3::new(r[idx[0]], r[idx[1]], r[idx[2]]),
            rotation: None,
            line,
        })
        .collect())
}

/// How outliers are told apart.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OutlierRule {
    /// Residual above this distance, mm.
    Fixed(f64),
    /// Residual above [`MEDIAN_FACTOR`] × the median residual of the fitted pairs, at least
    /// [`THRESHOLD_FLOOR`].
    Median,
}

/// What the pairs hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PairKind {
    /// Positions only.
    Points,
    /// Positions and orientations.
    Poses,
}

/// One pair's misfit under the final transform.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PairResidual {
    /// 1-based pair number, in file order.
    pub pair: usize,
    /// Line in the first file.
    pub line_a: usize,
    /// Line in the second file.
    pub line_b: usize,
    /// The residual the fit and the outlier rule use, mm: |T·a − b| for points; for poses the
    /// RMS over the position and the three axis ends.
    pub residual: f64,
    /// |T·a − b| of the positions, mm.
    pub position: f64,
    /// Angle between the transformed orientation and the measured one, degrees (poses).
    pub angle_deg: Option<f64>,
    /// Above the threshold.
    pub outlier: bool,
    /// In the final fit (outliers are left out unless too few pairs would remain).
    pub used: bool,
}

/// The transform from the first frame (A) into the second (B): b = T·a.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameFit {
    /// What the pairs hold.
    pub kind: PairKind,
    /// Pairs given.
    pub pairs: usize,
    /// Pairs the final fit used.
    pub used: usize,
    /// Axis length L of pose pairs, mm.
    pub axis_length: Option<f64>,
    /// The homogeneous 4×4 matrix, row by row.
    pub matrix: [[f64; 4]; 4],
    /// Translation, mm.
    pub translation: [f64; 3],
    /// Rotation as a unit quaternion `[w, x, y, z]`, w ≥ 0.
    pub quaternion: [f64; 4],
    /// Rotation as Euler angles `[a, b, c]` in degrees with R = Rz(a)·Ry(b)·Rx(c) (ZYX, as
    /// KUKA's A, B, C or yaw, pitch, roll).
    pub euler_zyx_deg: [f64; 3],
    /// Root mean square of the residuals of the pairs used, mm.
    pub rms: f64,
    /// The outlier rule.
    pub rule: OutlierRule,
    /// The threshold it gave, mm.
    pub threshold: f64,
    /// Per-pair residuals, in file order.
    pub residuals: Vec<PairResidual>,
    /// The transform.
    #[serde(skip)]
    pub transform: Isometry3<f64>,
}

/// The points a measurement stands for (see the module docs).
fn expand(m: &Measured, axis: f64) -> Vec<Point3> {
    match m.rotation {
        None => vec![m.position],
        Some(r) => {
            let mut v = vec![m.position];
            v.extend(
                [Vector3::x(), Vector3::y(), Vector3::z()]
                    .iter()
                    .map(|e| m.position + r * (e * axis)),
            );
            v
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => v[n / 2],
        _ => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// The rigid transform taking the measurements `a` (frame A) onto `b` (frame B), pair by pair
/// in order, with outliers flagged by `rule` and left out of the fit.
pub fn register_frames(
    a: &[Measured],
    b: &[Measured],
    rule: OutlierRule,
) -> Result<FrameFit, FramesError> {
    if a.len() != b.len() {
        return Err(FramesError::Count {
            a: a.len(),
            b: b.len(),
        });
    }
    if let OutlierRule::Fixed(t) = rule
        && !(t.is_finite() && t > 0.0)
    {
        return Err(FramesError::Threshold(t));
    }
    let n = a.len();
    let poses = n > 0 && a.iter().chain(b).all(|m| m.rotation.is_some());
    let (kind, axis) = pair_kind(a, poses);
    let groups = Groups::new(a, b, poses, axis, rule);
    let rounds = groups.rounds(n)?;
    Ok(frame_fit(a, b, poses, kind, axis, rule, rounds))
}

/// Whether the pairs are poses or points, and for poses the axis length (the spread of `a`
/// about its centroid, at least [`MIN_AXIS_LENGTH`]).
fn pair_kind(a: &[Measured], poses: bool) -> (PairKind, Option<f64>) {
    if poses {
        let n = a.len();
        let c = a
            .iter()
            .fold(Vector3::zeros(), |s, m| s + m.position.coords)
            / n as f64;
        let spread = (a
            .iter()
            .map(|m| (m.position.coords - c).norm_squared())
            .sum::<f64>()
            / n as f64)
            .sqrt();
        (PairKind::Poses, Some(spread.max(MIN_AXIS_LENGTH)))
    } else {
        (PairKind::Points, None)
    }
}

/// The outcome of the fitting rounds: the transform, each pair's residual, which pairs were
/// used, and the outlier threshold.
struct Rounds {
    g: Isometry3<f64>,
    r: Vec<f64>,
    used: Vec<bool>,
    tau: f64,
}

/// Every pair expanded into its point group in both frames, with the outlier rule.
struct Groups {
    pa: Vec<Vec<Point3>>,
    pb: Vec<Vec<Point3>>,
    rule: OutlierRule,
}

impl Groups {
    /// Expands every measurement into its points (rotations kept only for poses).
    fn new(
        a: &[Measured],
        b: &[Measured],
        poses: bool,
        axis: Option<f64>,
        rule: OutlierRule,
    ) -> Self {
        let strip = |m: &Measured| Measured {
            rotation: if poses { m.rotation } else { None },
            ..*m
        };
        let pa: Vec<Vec<Point3>> = a
            .iter()
            .map(|m| expand(&strip(m), axis.unwrap_or(0.0)))
            .collect();
        let pb: Vec<Vec<Point3>> = b
            .iter()
            .map(|m| expand(&strip(m), axis.unwrap_or(0.0)))
            .collect();
        Self { pa, pb, rule }
    }

    /// The least-squares transform over the used pairs.
    fn fit(&self, used: &[bool]) -> Result<Isometry3<f64>, RegisterError> {
        let pick = |p: &[Vec<Point3>]| -> Vec<Point3> {
            p.iter()
                .zip(used)
                .filter(|(_, u)| **u)
                .flat_map(|(g, _)| g.iter().copied())
                .collect()
        };
        Ok(least_squares(&pick(&self.pa), &pick(&self.pb))?.transform)
    }

    /// Each pair's RMS distance between its transformed `a` points and its `b` points.
    fn residuals(&self, g: &Isometry3<f64>) -> Vec<f64> {
        self.pa
            .iter()
            .zip(&self.pb)
            .map(|(ga, gb)| {
                let ss: f64 = ga
                    .iter()
                    .zip(gb)
                    .map(|(p, q)| (g.transform_point(p) - q).norm_squared())
                    .sum();
                (ss / ga.len() as f64).sqrt()
            })
            .collect()
    }

    /// The outlier threshold given the residuals and the pairs used.
    fn threshold(&self, r: &[f64], used: &[bool]) -> f64 {
        match self.rule {
            OutlierRule::Fixed(t) => t,
            OutlierRule::Median => {
                let kept: Vec<f64> = r
                    .iter()
                    .zip(used)
                    .filter(|(_, u)| **u)
                    .map(|(v, _)| *v)
                    .collect();
                (MEDIAN_FACTOR * median(kept)).max(THRESHOLD_FLOOR)
            }
        }
    }

    /// Fits, drops the outliers and fits again until the used set is stable (at most
    /// [`MAX_ROUNDS`] rounds).
    fn rounds(&self, n: usize) -> Result<Rounds, RegisterError> {
        let mut used = vec![true; n];
        let mut g = self.fit(&used)?;
        let mut r = self.residuals(&g);
        let mut tau = self.threshold(&r, &used);
        for _ in 1..MAX_ROUNDS {
            let next: Vec<bool> = r.iter().map(|v| *v <= tau).collect();
            if next == used {
                break;
            }
            // Too few pairs left, or a degenerate set: keep the last fit.
            let Ok(g2) = self.fit(&next) else { break };
            used = next;
            g = g2;
            r = self.residuals(&g);
            tau = self.threshold(&r, &used);
        }
        Ok(Rounds { g, r, used, tau })
    }
}

/// The report of a fit: the transform in its forms, each pair's residuals, the RMS.
fn frame_fit(
    a: &[Measured],
    b: &[Measured],
    poses: bool,
    kind: PairKind,
    axis: Option<f64>,
    rule: OutlierRule,
    rounds: Rounds,
) -> FrameFit {
    let Rounds { g, r, used, tau } = rounds;
    let n = a.len();
    let rot = g.rotation;
    let q = if rot.w < 0.0 {
        -rot.into_inner()
    } else {
        rot.into_inner()
    };
    let (roll, pitch, yaw) = rot.euler_angles();
    let h = g.to_homogeneous();
    let matrix: [[f64; 4]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| h[(i, j)]));
    let pairs: Vec<PairResidual> = a
        .iter()
        .zip(b)
        .zip(&r)
        .zip(&used)
        .enumerate()
        .map(|(i, (((ma, mb), res), u))| PairResidual {
            pair: i + 1,
            line_a: ma.line,
            line_b: mb.line,
            residual: *res,
            position: (g.transform_point(&ma.position) - mb.position).norm(),
            angle_deg: match (poses, ma.rotation, mb.rotation) {
                (true, Some(ra), Some(rb)) => Some((rot * ra).angle_to(&rb).to_degrees()),
                _ => None,
            },
            outlier: *res > tau,
            used: *u,
        })
        .collect();
    let kept: Vec<f64> = r
        .iter()
        .zip(&used)
        .filter(|(_, u)| **u)
        .map(|(v, _)| v * v)
        .collect();
    let rms = (kept.iter().sum::<f64>() / kept.len().max(1) as f64).sqrt();
    FrameFit {
        kind,
        pairs: n,
        used: kept.len(),
        axis_length: axis,
        matrix,
        translation: [g.translation.x, g.translation.y, g.translation.z],
        quaternion: [q.w, q.i, q.j, q.k],
        euler_zyx_deg: [yaw.to_degrees(), pitch.to_degrees(), roll.to_degrees()],
        rms,
        rule,
        threshold: tau,
        residuals: pairs,
        transform: g,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Translation3, Unit};

    fn known() -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(100.0, -20.0, 5.0),
            UnitQuaternion::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0)), 0.8),
        )
    }

    fn pt(p: Point3, line: usize) -> Measured {
        Measured {
            position: p,
            rotation: None,
            line,
        }
    }

    #[test]
    fn exact_points_give_the_transform_in_every_form() {
        let g = known();
        let a: Vec<Measured> = [
            [0.0, 0.0, 0.0],
            [50.0, 0.0, 0.0],
            [0.0, 40.0, 0.0],
            [0.0, 0.0, 30.0],
        ]
        .iter()
        .enumerate()
        .map(|(i, p)| pt(Point3::from(*p), i + 2))
        .collect();
        let b: Vec<Measured> = a
            .iter()
            .map(|m| pt(g.transform_point(&m.position), m.line))
            .collect();
        let f = register_frames(&a, &b, OutlierRule::Median).expect("fits");
        assert_eq!((f.kind, f.pairs, f.used), (PairKind::Points, 4, 4));
        assert!(f.rms < 1e-9 && f.residuals.iter().all(|r| !r.outlier));
        assert!(
            (g.to_homogeneous() - nalgebra::Matrix4::from_fn(|i, j| f.matrix[i][j])).norm() < 1e-9
        );
        let [a_deg, b_deg, c_deg] = f.euler_zyx_deg.map(f64::to_radians);
        let r = Rotation3::from_axis_angle(&Vector3::z_axis(), a_deg)
            * Rotation3::from_axis_angle(&Vector3::y_axis(), b_deg)
            * Rotation3::from_axis_angle(&Vector3::x_axis(), c_deg);
        assert!((r.into_inner() - g.rotation.to_rotation_matrix().into_inner()).norm() < 1e-9);
        let [w, x, y, z] = f.quaternion;
        assert!(w >= 0.0);
        assert!(
            UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)).angle_to(&g.rotation)
                < 1e-9
        );
        assert_eq!(f.threshold, THRESHOLD_FLOOR);
    }

    #[test]
    fn one_pose_pair_fixes_the_transform() {
        let g = known();
        let r = UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3);
        let a = [Measured {
            position: Point3::new(1.0, 2.0, 3.0),
            rotation: Some(r),
            line: 2,
        }];
        let b = [Measured {
            position: g.transform_point(&a[0].position),
            rotation: Some(g.rotation * r),
            line: 2,
        }];
        let f = register_frames(&a, &b, OutlierRule::Median).expect("fits");
        assert_eq!(f.kind, PairKind::Poses);
        assert_eq!(f.axis_length, Some(MIN_AXIS_LENGTH));
        assert!((f.transform.to_homogeneous() - g.to_homogeneous()).norm() < 1e-9);
        assert!(f.residuals[0].angle_deg.is_some_and(|d| d < 1e-6));
    }

    #[test]
    fn a_threshold_that_flags_every_pair_keeps_them_all_in_the_fit() {
        let a: Vec<Measured> = [
            [0.0, 0.0, 0.0],
            [50.0, 0.0, 0.0],
            [0.0, 40.0, 0.0],
            [9.0, 9.0, 30.0],
        ]
        .iter()
        .map(|p| pt(Point3::from(*p), 1))
        .collect();
        // b = a shifted by 1 in x, with ±0.1 mm disagreements.
        let b: Vec<Measured> = a
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let wobble = if i % 2 == 0 { 0.1 } else { -0.1 };
                pt(m.position + Vector3::new(1.0, 0.0, wobble), 1)
            })
            .collect();
        let f = register_frames(&a, &b, OutlierRule::Fixed(1e-6)).expect("fits");
        assert_eq!(f.used, 4);
        assert!(f.residuals.iter().all(|r| r.outlier && r.used), "{f:?}");
        assert!(f.rms > 0.01);
    }

    #[test]
    fn tables_and_thresholds_are_checked() {
        let a = read_measured("x,y,z\n0,0,0\n1,0,0\n").expect("reads");
        assert_eq!(a.len(), 2);
        assert_eq!(a[1].line, 3);
        assert!(a[0].rotation.is_none());
        let b = read_measured("# B\nx,y,z,qw,qx,qy,qz\n0,0,0,1,0,0,0\n").expect("reads");
        assert!(b[0].rotation.is_some() && b[0].line == 3);
        assert_eq!(
            register_frames(&a, &b, OutlierRule::Median),
            Err(FramesError::Count { a: 2, b: 1 })
        );
        assert_eq!(
            register_frames(&a, &a, OutlierRule::Fixed(0.0)),
            Err(FramesError::Threshold(0.0))
        );
        assert!(matches!(
            register_frames(&a, &a, OutlierRule::Median),
            Err(FramesError::Register(RegisterError::Count { .. }))
        ));
        assert_eq!(
            read_measured("x,y\n1,2\n"),
            Err(FramesError::Table(TableError::MissingColumn("z".into())))
        );
    }
}
