//! The tool frame of a pose: its direction into the work from the quaternion, and a quaternion
//! from a tool axis.
//!
//! Place in the pipeline: shared by the gap compensation ([`super`]) and the calibration
//! patterns ([`crate::robot::pattern`]). Convention: the tool frame's z axis points out of
//! the tool into the work (the opposite of `Toolpath::tool_axis`); its x axis is the base +X
//! projected onto the plane across z, or +Y where +X is (nearly) along z.

use crate::geom::Vector3;
use nalgebra::{Quaternion, UnitQuaternion};

/// The tool frame's z axis (out of the tool into the work) of the unit quaternion
/// `[w, x, y, z]`.
pub fn into_work(q: [f64; 4]) -> Vector3 {
    let q = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
    q * Vector3::z()
}

/// The tool frame (`[w, x, y, z]`) whose z axis is `into_work` (any non-zero length), with the
/// project's rule for x ([`crate::geom::tool_frame`]). `None` for a zero or non-finite
/// direction.
pub fn quaternion(into_work: &Vector3) -> Option<[f64; 4]> {
    let q = UnitQuaternion::from_rotation_matrix(&crate::geom::tool_frame(into_work)?);
    Some([q.w, q.i, q.j, q.k])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_of_an_axis_turns_z_onto_it_and_x_toward_base_x() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        for d in [
            Vector3::new(0.0, 0.0, -1.0),
            Vector3::new(h, 0.0, -h),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.3, -0.4, 0.5),
        ] {
            let q = quaternion(&d).expect("non-zero");
            let back = into_work(q);
            assert!((back - d.normalize()).norm() < 1e-12, "{d:?} → {back:?}");
            let r = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
            let x = r * Vector3::x();
            // x is +X's projection where there is one, else +Y's.
            let base = if d.normalize().x.abs() > 0.99 {
                Vector3::y()
            } else {
                Vector3::x()
            };
            assert!(x.dot(&base) > 0.0 && x.dot(&d).abs() < 1e-12);
        }
        assert_eq!(quaternion(&Vector3::zeros()), None);
    }
}
