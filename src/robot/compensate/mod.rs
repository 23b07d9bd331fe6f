//! Gap compensation of a robot path: measured tool-to-surface gaps move every pose along its
//! tool axis so the gap comes back to a target, pass after pass.
//!
//! Place in the pipeline: the end of the robot branch of `conform` (`conduit compensate`). It
//! reads a pose table (the path, [`conduit_poses`]) and a gap table ([`gaps`]), and writes a
//! new pose table; nothing upstream is re-run. Steps of one pass ([`compensate_pass`]):
//!
//! 1. each sensor reading h, taken at the sensor angle α from the tool axis, is the gap
//!    l = h·cos α along the tool axis;
//! 2. the correction l − target of every pose is smoothed along the path ([`smooth`]) so the
//!    sensor's noise does not become path noise;
//! 3. each tip moves by its correction along the tool frame's z axis (out of the tool into
//!    the work); orientations are kept as they are.
//!
//! Measure again on the new path and repeat. [`simulate`] closes the loop offline: a known
//! surface ([`substrate`]) moved by a robot error model gives the readings.

pub mod frame;
pub mod gaps;
pub mod settings;
pub mod simulate;
pub mod smooth;
pub mod substrate;

use crate::geom::{Point3, Vector3};
use conduit_poses::{Pose, TableError};
use serde::Serialize;
pub use settings::CompensateSettings;

/// Why a compensation failed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CompensateError {
    /// A setting is out of range.
    ///
    /// How to fix: correct the named `[compensate]` key or its command-line option.
    #[error("compensate.{key}: {message}")]
    Setting {
        /// The key.
        key: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The path table could not be read.
    #[error(transparent)]
    Path(#[from] TableError),
    /// The path has no poses.
    ///
    /// How to fix: the table needs at least one pose line.
    #[error("the path has no poses")]
    EmptyPath,
    /// The gap table could not be used.
    #[error(transparent)]
    Gaps(#[from] gaps::GapsError),
    /// A pose's tool axis does not meet the surface (simulation).
    ///
    /// How to fix: check that the path lies over the surface and the error model is not so
    /// large that the real surface moves out from under it.
    #[error("line {line}: the tool axis of pose {index} does not meet the surface")]
    Miss {
        /// 0-based pose index.
        index: usize,
        /// 1-based line of the pose in the path table.
        line: usize,
    },
}

/// Validated parameters of a pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Gap aimed for, mm.
    pub target: f64,
    /// Angle between the sensor beam and the tool axis, degrees.
    pub sensor_angle: f64,
    /// Standard deviation of the smoothing Gaussian, mm of arc length (0 = none).
    pub smoothing: f64,
}

impl Params {
    /// Parameters from the `[compensate]` settings, checked.
    pub fn from_settings(s: &CompensateSettings) -> Result<Self, CompensateError> {
        let setting = |key, message: String| Err(CompensateError::Setting { key, message });
        if !(s.target.is_finite() && s.target >= 0.0) {
            return setting("target", format!("must be ≥ 0, got {}", s.target));
        }
        if !(s.smoothing.is_finite() && s.smoothing >= 0.0) {
            return setting("smoothing", format!("must be ≥ 0, got {}", s.smoothing));
        }
        if !(0.0..90.0).contains(&s.sensor_angle) {
            return setting(
                "sensor_angle",
                format!("must be in [0, 90) degrees, got {}", s.sensor_angle),
            );
        }
        Ok(Self {
            target: s.target,
            sensor_angle: s.sensor_angle,
            smoothing: s.smoothing,
        })
    }
}

/// A path read from a pose table, with the line of each pose.
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    /// The poses, in order.
    pub poses: Vec<Pose>,
    /// The 1-based line of each pose in the table.
    pub lines: Vec<usize>,
}

impl Path {
    /// Reads a pose table (`x,y,z,qw,qx,qy,qz[,dispense]`).
    pub fn parse(text: &str) -> Result<Self, CompensateError> {
        let poses = conduit_poses::read_poses(text)?;
        if poses.is_empty() {
            return Err(CompensateError::EmptyPath);
        }
        let lines = conduit_poses::Table::parse(text)?.lines;
        Ok(Self { poses, lines })
    }

    /// A path of poses without a file (lines counted from 2, after a header).
    pub fn from_poses(poses: Vec<Pose>) -> Self {
        let lines = (2..poses.len() + 2).collect();
        Self { poses, lines }
    }

    /// The line of pose `i`.
    pub fn line(&self, i: usize) -> usize {
        self.lines.get(i).copied().unwrap_or(0)
    }

    /// Arc length of each tip from the first, mm.
    pub fn arc_lengths(&self) -> Vec<f64> {
        let mut s = 0.0;
        let mut prev: Option<Point3> = None;
        self.poses
            .iter()
            .map(|p| {
                let q = tip(p);
                if let Some(a) = prev {
                    s += (q - a).norm();
                }
                prev = Some(q);
                s
            })
            .collect()
    }

    /// Whether the path ends where it starts (within 1 µm) and has at least three poses.
    pub fn is_closed(&self) -> bool {
        match (self.poses.first(), self.poses.last()) {
            (Some(a), Some(b)) if self.poses.len() >= 3 => (tip(a) - tip(b)).norm() < 1e-3,
            _ => false,
        }
    }
}

/// The tip of a pose.
pub fn tip(p: &Pose) -> Point3 {
    Point3::new(p.position[0], p.position[1], p.position[2])
}

/// The direction of a pose's tool frame z axis: out of the tool into the work.
pub fn into_work(p: &Pose) -> Vector3 {
    frame::into_work(p.quaternion)
}

/// Statistics of gaps along a path, mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GapStats {
    /// Smallest gap.
    pub min: f64,
    /// Largest gap.
    pub max: f64,
    /// Mean gap.
    pub mean: f64,
    /// max − min.
    pub variation: f64,
    /// Root mean square of gap − target.
    pub rms_about_target: f64,
}

impl GapStats {
    /// The statistics of `gaps` about `target`.
    pub fn of(gaps: &[f64], target: f64) -> Self {
        let n = gaps.len().max(1) as f64;
        let min = gaps.iter().copied().fold(f64::INFINITY, f64::min);
        let max = gaps.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let (min, max) = if gaps.is_empty() {
            (0.0, 0.0)
        } else {
            (min, max)
        };
        Self {
            min,
            max,
            mean: gaps.iter().sum::<f64>() / n,
            variation: max - min,
            rms_about_target: (gaps.iter().map(|g| (g - target).powi(2)).sum::<f64>() / n).sqrt(),
        }
    }
}

/// Statistics of the corrections of a pass, mm (positive: toward the surface).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CorrectionStats {
    /// Smallest correction.
    pub min: f64,
    /// Largest correction.
    pub max: f64,
    /// Mean correction.
    pub mean: f64,
    /// Largest amount the smoothing changed a correction.
    pub max_smoothing_change: f64,
}

/// The result of one pass.
#[derive(Debug, Clone, PartialEq)]
pub struct Pass {
    /// The moved path.
    pub poses: Vec<Pose>,
    /// The gaps along the tool axis read from the sensor, one per pose, mm.
    pub gaps: Vec<f64>,
    /// The (smoothed) correction of each pose, mm toward the surface.
    pub corrections: Vec<f64>,
    /// Statistics of `gaps` about the target.
    pub before: GapStats,
    /// Statistics of `corrections`.
    pub correction: CorrectionStats,
}

/// One compensation pass: `readings` (one sensor reading per pose, mm) move the poses of
/// `path` (module docs, steps 1 to 3).
pub fn compensate_pass(path: &Path, readings: &[f64], params: &Params) -> Pass {
    let cos = params.sensor_angle.to_radians().cos();
    let gaps: Vec<f64> = readings.iter().map(|h| h * cos).collect();
    let raw: Vec<f64> = gaps.iter().map(|l| l - params.target).collect();
    let s = path.arc_lengths();
    let corrections = smooth::gaussian(&raw, &s, params.smoothing, path.is_closed());
    let poses = path
        .poses
        .iter()
        .zip(&corrections)
        .map(|(p, c)| {
            let q = tip(p) + into_work(p) * *c;
            Pose {
                position: [q.x, q.y, q.z],
                ..*p
            }
        })
        .collect();
    let n = corrections.len().max(1) as f64;
    let correction = CorrectionStats {
        min: corrections.iter().copied().fold(f64::INFINITY, f64::min),
        max: corrections
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max),
        mean: corrections.iter().sum::<f64>() / n,
        max_smoothing_change: raw
            .iter()
            .zip(&corrections)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max),
    };
    Pass {
        poses,
        before: GapStats::of(&gaps, params.target),
        gaps,
        corrections,
        correction,
    }
}

/// The dispensing runs of `poses` as tip paths with their tool axes (from the tip up toward
/// the tool, the opposite of the tool frame's z): a pose with `dispense` 0 is reached by a
/// travel and starts a run; runs of fewer than two poses print nothing and are left out.
pub fn runs(poses: &[Pose]) -> (Vec<Vec<Point3>>, Vec<Vec<Vector3>>) {
    let (mut paths, mut axes): (Vec<Vec<Point3>>, Vec<Vec<Vector3>>) = (Vec::new(), Vec::new());
    for (i, p) in poses.iter().enumerate() {
        if i == 0 || !p.dispense {
            paths.push(Vec::new());
            axes.push(Vec::new());
        }
        if let (Some(path), Some(axis)) = (paths.last_mut(), axes.last_mut()) {
            path.push(Point3::new(p.position[0], p.position[1], p.position[2]));
            axis.push(-frame::into_work(p.quaternion));
        }
    }
    paths
        .into_iter()
        .zip(axes)
        .filter(|(p, _)| p.len() >= 2)
        .unzip()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pass_moves_each_tip_along_its_tool_z_by_the_gap_error() {
        // Tool z straight down, then turned 90° about y (tool z along base +x).
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let path = Path::from_poses(vec![
            Pose {
                position: [0.0, 0.0, 1.0],
                quaternion: [0.0, 1.0, 0.0, 0.0],
                dispense: true,
            },
            Pose {
                position: [5.0, 0.0, 1.0],
                quaternion: [h, 0.0, h, 0.0],
                dispense: true,
            },
        ]);
        let params = Params {
            target: 0.05,
            sensor_angle: 60.0,
            smoothing: 0.0,
        };
        // Readings at 60° are twice the gaps.
        let pass = compensate_pass(&path, &[0.5, 0.04], &params);
        assert!((pass.gaps[0] - 0.25).abs() < 1e-12 && (pass.gaps[1] - 0.02).abs() < 1e-12);
        let a = pass.poses[0].position;
        assert!((a[2] - (1.0 - 0.2)).abs() < 1e-12 && a[0].abs() < 1e-12);
        // Tool z of the second pose is +x: a gap 0.03 short moves the tip 0.03 along −x.
        let b = pass.poses[1].position;
        assert!((b[0] - (5.0 - 0.03)).abs() < 1e-12 && (b[2] - 1.0).abs() < 1e-12);
        assert_eq!(pass.poses[1].quaternion, path.poses[1].quaternion);
        assert!((pass.before.variation - 0.23).abs() < 1e-12);
    }

    #[test]
    fn dispense_off_poses_start_new_runs_with_the_tool_axis_up_the_tool() {
        let down = [0.0, 1.0, 0.0, 0.0]; // half turn about x: tool z = −z (into the work)
        let pose = |x: f64, dispense: bool| Pose {
            position: [x, 0.0, 1.0],
            quaternion: down,
            dispense,
        };
        let poses = [
            pose(0.0, false),
            pose(1.0, true),
            pose(2.0, true),
            pose(5.0, false),
            pose(6.0, false),
            pose(7.0, true),
        ];
        let (paths, axes) = runs(&poses);
        assert_eq!(paths.len(), 2);
        assert_eq!(
            paths[0].iter().map(|p| p.x).collect::<Vec<_>>(),
            vec![0.0, 1.0, 2.0]
        );
        assert_eq!(
            paths[1].iter().map(|p| p.x).collect::<Vec<_>>(),
            vec![6.0, 7.0]
        );
        for a in axes.iter().flatten() {
            assert!((a - Vector3::z()).norm() < 1e-12, "{a:?}");
        }
    }
}
