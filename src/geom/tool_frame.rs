//! The tool frame of a tool direction: the one rule every robot stage uses to turn a direction
//! into a full orientation.
//!
//! Place in the pipeline: shared vocabulary; the robot emitters turn each `Toolpath::tool_axis`
//! into a frame with it, and the gap compensation and calibration patterns build their pose
//! tables with it, so a pose written by one reads back the same in the other.
//!
//! The tool frame's z axis points out of the tool into the work; its x axis is the base +X
//! projected onto the plane across z, or +Y where +X lies (nearly) along z; y = z × x.

use super::Vector3;
use nalgebra::{Matrix3, Rotation3};

/// Below this length the projection of +X onto the plane across z is degenerate.
const DEGENERATE: f64 = 1e-6;

/// The tool frame whose z axis is `into_work` (any non-zero length); `None` for a zero or
/// non-finite direction.
pub fn tool_frame(into_work: &Vector3) -> Option<Rotation3<f64>> {
    let z = into_work.try_normalize(1e-12)?;
    if !z.iter().all(|c| c.is_finite()) {
        return None;
    }
    let project = |v: Vector3| (v - z * v.dot(&z)).try_normalize(DEGENERATE);
    let x = project(Vector3::x()).or_else(|| project(Vector3::y()))?;
    let y = z.cross(&x);
    Some(Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        x, y, z,
    ])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_goes_into_the_work_and_x_toward_base_x() {
        let down = tool_frame(&Vector3::new(0.0, 0.0, -2.0)).expect("non-zero");
        assert!((down * Vector3::z() + Vector3::z()).norm() < 1e-12);
        assert!((down * Vector3::x() - Vector3::x()).norm() < 1e-12);
        // Along +X: x falls back to +Y.
        let along = tool_frame(&Vector3::x()).expect("non-zero");
        assert!((along * Vector3::x() - Vector3::y()).norm() < 1e-12);
        assert!(tool_frame(&Vector3::zeros()).is_none());
    }
}
