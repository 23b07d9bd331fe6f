//! Offline gap compensation: synthetic gap readings from a known surface and a robot error
//! model, and the measure → compensate loop run on them.
//!
//! Place in the pipeline: `conduit compensate --simulate`, in place of a real measurement
//! before each pass ([`super::compensate_pass`]). The path is planned on the nominal
//! substrate; the real substrate is the nominal one moved by the error model:
//!
//! - a shift (dx, dy, dz) of the part;
//! - an orientation error: a turn by a few tenths of a degree about an axis through the
//!   middle of the path (the centroid of the commanded tips), as a part clamped slightly
//!   askew — about the middle so it does not also shift the printed area far away;
//! - a tool-length (z) error: the real tip stands this far back along the tool axis from the
//!   commanded one, which adds it to every gap.
//!
//! A gap is measured along the tool axis from the commanded tip to the real surface (a ray
//! from 10 mm behind the tip, so a tip inside the part gives a negative gap). The sensor
//! reading is that gap over cos α plus Gaussian noise from a seeded generator, so the same
//! seed gives the same readings byte for byte.

use super::CompensateSettings;
use super::substrate::Substrate;
use super::{CompensateError, CorrectionStats, GapStats, Params, Path, compensate_pass};
use crate::geom::{Point3, Vector3};
use conduit_poses::Pose;
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion};
use serde::Serialize;

/// How far behind the tip the measuring ray starts, mm: gaps down to −10 mm are measured.
const BEHIND: f64 = 10.0;

/// The robot error model of a simulation (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ErrorModel {
    /// Shift of the real substrate, mm.
    pub shift: [f64; 3],
    /// Orientation error, degrees.
    pub tilt: f64,
    /// Axis of the orientation error (unit).
    pub axis: [f64; 3],
    /// Tool-length error, mm (added to every gap).
    pub z: f64,
    /// Standard deviation of the sensor noise, mm.
    pub noise: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl ErrorModel {
    /// The error model of the `[compensate]` settings, checked.
    pub fn from_settings(s: &CompensateSettings) -> Result<Self, CompensateError> {
        let bad = |key, message: String| Err(CompensateError::Setting { key, message });
        let a = Vector3::from(s.error_axis);
        let Some(axis) = a
            .try_normalize(1e-12)
            .filter(|v| v.iter().all(|c| c.is_finite()))
        else {
            return bad(
                "error_axis",
                format!("must be a non-zero direction, got {a:?}"),
            );
        };
        if !s.error_shift.iter().all(|v| v.is_finite()) {
            return bad("error_shift", "must be finite numbers".to_owned());
        }
        if !(s.error_tilt.is_finite() && s.error_z.is_finite()) {
            return bad(
                "error_tilt",
                "error_tilt and error_z must be finite".to_owned(),
            );
        }
        if !(s.noise.is_finite() && s.noise >= 0.0) {
            return bad("noise", format!("must be ≥ 0, got {}", s.noise));
        }
        Ok(Self {
            shift: s.error_shift,
            tilt: s.error_tilt,
            axis: [axis.x, axis.y, axis.z],
            z: s.error_z,
            noise: s.noise,
            seed: s.seed,
        })
    }

    /// Where the real substrate is: nominal points go to pivot + R·(p − pivot) + shift.
    pub fn placement(&self, pivot: &Point3) -> Isometry3<f64> {
        let r = UnitQuaternion::from_axis_angle(
            &Unit::new_normalize(Vector3::from(self.axis)),
            self.tilt.to_radians(),
        );
        let to = Translation3::from(pivot.coords + Vector3::from(self.shift));
        let from = Translation3::from(-pivot.coords);
        to * Isometry3::from_parts(Translation3::identity(), r) * from
    }
}

/// The real gaps of `path` over `substrate` placed by `placement`, plus the tool-length
/// error `z`: one per pose, mm.
pub fn true_gaps(
    path: &Path,
    substrate: &Substrate,
    placement: &Isometry3<f64>,
    z: f64,
) -> Result<Vec<f64>, CompensateError> {
    let inv = placement.inverse();
    path.poses
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let d = super::into_work(p);
            let o = super::tip(p) - d * BEHIND;
            let hit = substrate
                .hit(&inv.transform_point(&o), &inv.transform_vector(&d))
                .ok_or(CompensateError::Miss {
                    index: i,
                    line: path.line(i),
                })?;
            Ok(hit.t - BEHIND + z)
        })
        .collect()
}

/// A small seeded generator of normal deviates (SplitMix64 and Box–Muller), so the simulation
/// needs no dependency and gives the same numbers everywhere.
#[derive(Debug, Clone)]
pub struct Noise {
    state: u64,
}

impl Noise {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1].
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    /// A standard normal deviate.
    pub fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

/// Sensor readings of `gaps` at the sensor angle of `params`, with the model's noise.
pub fn readings(gaps: &[f64], params: &Params, noise_mm: f64, noise: &mut Noise) -> Vec<f64> {
    let cos = params.sensor_angle.to_radians().cos();
    gaps.iter()
        .map(|l| {
            let e = if noise_mm > 0.0 {
                noise_mm * noise.normal()
            } else {
                0.0
            };
            l / cos + e
        })
        .collect()
}

/// Figures of one simulated pass.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PassFigures {
    /// 1-based pass number.
    pub pass: usize,
    /// The gaps read from the (noisy) sensor before the pass.
    pub measured: GapStats,
    /// The corrections applied.
    pub correction: CorrectionStats,
    /// The real gaps after the pass.
    pub after: GapStats,
}

/// The outcome of a simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// The centroid of the commanded tips, the pivot of the orientation error.
    pub pivot: Point3,
    /// The real gaps of the uncompensated path.
    pub uncompensated: GapStats,
    /// Each pass.
    pub passes: Vec<PassFigures>,
    /// The path after the last pass.
    pub poses: Vec<Pose>,
    /// The sensor readings before the first pass, one per pose, mm.
    pub first_readings: Vec<f64>,
}

/// Runs `passes` measure → compensate passes of `path` over `substrate` under `model`.
pub fn run(
    path: &Path,
    substrate: &Substrate,
    model: &ErrorModel,
    params: &Params,
    passes: usize,
) -> Result<Simulation, CompensateError> {
    let n = path.poses.len().max(1) as f64;
    let pivot = Point3::from(
        path.poses
            .iter()
            .map(|p| super::tip(p).coords)
            .sum::<Vector3>()
            / n,
    );
    let placement = model.placement(&pivot);
    let mut noise = Noise::new(model.seed);
    let mut current = path.clone();
    let mut gaps = true_gaps(&current, substrate, &placement, model.z)?;
    let uncompensated = GapStats::of(&gaps, params.target);
    let mut figures = Vec::with_capacity(passes);
    let mut first_readings = Vec::new();
    for k in 1..=passes {
        let r = readings(&gaps, params, model.noise, &mut noise);
        if k == 1 {
            first_readings = r.clone();
        }
        let pass = compensate_pass(&current, &r, params);
        current.poses = pass.poses;
        gaps = true_gaps(&current, substrate, &placement, model.z)?;
        figures.push(PassFigures {
            pass: k,
            measured: pass.before,
            correction: pass.correction,
            after: GapStats::of(&gaps, params.target),
        });
    }
    Ok(Simulation {
        pivot,
        uncompensated,
        passes: figures,
        poses: current.poses,
        first_readings,
    })
}

#[cfg(test)]
mod tests {
    use super::super::substrate::Analytic;
    use super::*;

    #[test]
    fn a_shifted_plane_reads_the_shift_and_a_tilt_about_the_pivot_reads_the_slope() {
        // Tool z straight down over the plane z = 0, tips 1 mm up.
        let pose = |x: f64| Pose {
            position: [x, 0.0, 1.0],
            quaternion: [0.0, 1.0, 0.0, 0.0],
            dispense: true,
        };
        let path = Path::from_poses(vec![pose(-5.0), pose(0.0), pose(5.0)]);
        let plane = Substrate::Analytic(Analytic::Plane(None));
        let model = ErrorModel {
            shift: [0.0, 0.0, 0.2],
            tilt: 1.0,
            axis: [0.0, 1.0, 0.0],
            z: 0.01,
            noise: 0.0,
            seed: 1,
        };
        let pivot = Point3::new(0.0, 0.0, 1.0);
        let g = true_gaps(&path, &plane, &model.placement(&pivot), model.z).expect("hits");
        // R_y(θ) about (0, 0, 1) takes the plane's point (u, 0, 0) to
        // (u cos θ − sin θ, 0, 1 − u sin θ − cos θ), then the shift lifts it by 0.2.
        let th = 1f64.to_radians();
        for (k, x) in [-5.0f64, 0.0, 5.0].into_iter().enumerate() {
            let u = (x + th.sin()) / th.cos();
            let h = 1.0 - u * th.sin() - th.cos() + 0.2;
            let want = 1.0 - h + 0.01;
            assert!((g[k] - want).abs() < 1e-12, "{k}: {} vs {want}", g[k]);
        }
    }

    #[test]
    fn noise_is_seeded_and_roughly_standard() {
        let mut a = Noise::new(7);
        let mut b = Noise::new(7);
        let xs: Vec<f64> = (0..20000).map(|_| a.normal()).collect();
        assert!(xs.iter().all(|x| *x == b.normal()));
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / xs.len() as f64;
        assert!(
            mean.abs() < 0.03 && (var - 1.0).abs() < 0.05,
            "{mean} {var}"
        );
    }
}
