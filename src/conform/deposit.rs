//! Expected deposit thickness along the printed path, and its error against the target d.
//!
//! Place in the pipeline: step 9, on the final tip positions; also on the paths of the two
//! controls (no corrections; slope without curvature) so the report compares them.
//!
//! Every d/2 of path length, the nozzle's reference point is the back edge of the tip in the
//! direction of travel — the outer radius behind the axis when the tip moves down, the inner
//! radius otherwise — and the thickness is its distance to the surface along the surface
//! normal (the closest-point distance, negative below the top surface). The error is
//! thickness − d. A thickness at or below `contact_thickness` is tool-surface contact, an error
//! below −`flattening_error` flattening, above `floating_error` floating.

use super::surface::Surface;
use crate::geom::{Point3, Vector3};
use serde::Serialize;

/// Thresholds of the defect counts, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thresholds {
    /// Thickness at or below which the nozzle touches.
    pub contact_thickness: f64,
    /// Error below minus this: flattening.
    pub flattening_error: f64,
    /// Error above this: floating.
    pub floating_error: f64,
}

/// Deposit statistics of one set of paths.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct DepositStats {
    /// Samples (every d/2).
    pub samples: usize,
    /// Mean |thickness − d|, mm.
    pub mean_abs_error: f64,
    /// Mean of the positive errors (too thick), mm.
    pub mean_positive_error: f64,
    /// Mean of the negative errors (too thin), mm.
    pub mean_negative_error: f64,
    /// Thinnest deposit, mm.
    pub min_thickness: f64,
    /// Samples where the tool touches the surface.
    pub contact: usize,
    /// Samples with flattening.
    pub flattening: usize,
    /// Samples floating above the surface.
    pub floating: usize,
}

/// Thickness errors of every sample of `paths` (tips, mm) for a nozzle of inner diameter `d`
/// and outer diameter `d_o`.
pub fn deposit(
    surface: &Surface,
    paths: &[Vec<Point3>],
    d: f64,
    d_o: f64,
    thresholds: &Thresholds,
) -> DepositStats {
    let mut errors = Vec::new();
    let mut st = DepositStats {
        min_thickness: f64::INFINITY,
        ..DepositStats::default()
    };
    let step = d / 2.0;
    for path in paths {
        let mut carry = 0.0;
        for w in path.windows(2) {
            let seg = w[1] - w[0];
            let len = seg.norm();
            if len <= 0.0 {
                continue;
            }
            let horizontal = Vector3::new(seg.x, seg.y, 0.0);
            let v = horizontal
                .try_normalize(1e-12)
                .unwrap_or_else(Vector3::zeros);
            let back = if seg.z < 0.0 { d_o / 2.0 } else { d / 2.0 };
            let mut s = carry;
            while s < len {
                let p = w[0] + seg * (s / len);
                let r = p - v * back;
                let thickness = surface.signed_distance(&r);
                st.min_thickness = st.min_thickness.min(thickness);
                let e = thickness - d;
                if thickness <= thresholds.contact_thickness {
                    st.contact += 1;
                } else if e < -thresholds.flattening_error {
                    st.flattening += 1;
                } else if e > thresholds.floating_error {
                    st.floating += 1;
                }
                errors.push(e);
                s += step;
            }
            carry = s - len;
        }
    }
    st.samples = errors.len();
    if !errors.is_empty() {
        let n = errors.len() as f64;
        st.mean_abs_error = errors.iter().map(|e| e.abs()).sum::<f64>() / n;
        let pos: Vec<f64> = errors.iter().copied().filter(|e| *e > 0.0).collect();
        let neg: Vec<f64> = errors.iter().copied().filter(|e| *e < 0.0).collect();
        if !pos.is_empty() {
            st.mean_positive_error = pos.iter().sum::<f64>() / pos.len() as f64;
        }
        if !neg.is_empty() {
            st.mean_negative_error = neg.iter().sum::<f64>() / neg.len() as f64;
        }
    } else {
        st.min_thickness = 0.0;
    }
    st
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(slope: f64) -> Surface {
        let p = |x: f64, y: f64| Point3::new(x, y, slope * x);
        match Surface::from_triangles(vec![
            [p(-50.0, -50.0), p(50.0, -50.0), p(50.0, 50.0)],
            [p(-50.0, -50.0), p(50.0, 50.0), p(-50.0, 50.0)],
        ]) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        }
    }

    const T: Thresholds = Thresholds {
        contact_thickness: 0.0,
        flattening_error: 0.05,
        floating_error: 0.1,
    };

    #[test]
    fn a_flat_path_at_standoff_d_deposits_exactly_d() {
        let s = plane(0.0);
        let path = vec![Point3::new(0.0, 0.0, 0.25), Point3::new(10.0, 0.0, 0.25)];
        let st = deposit(&s, &[path], 0.25, 0.5, &T);
        assert_eq!(st.samples, 80);
        assert!(st.mean_abs_error < 1e-12, "{st:?}");
    }

    #[test]
    fn going_down_a_ramp_the_back_edge_of_the_outer_diameter_sets_the_thickness() {
        // Down a slope of 0.2 at standoff d: the reference point is d_o/2 behind, where the
        // surface is 0.2·d_o/2 higher; thickness along the normal = (d − 0.05)·cos α.
        let s = plane(-0.2);
        let (d, d_o) = (0.25, 0.5);
        let path = vec![Point3::new(0.0, 0.0, d), Point3::new(10.0, 0.0, d - 2.0)];
        let st = deposit(&s, &[path], d, d_o, &T);
        let expected = (d - 0.2 * d_o / 2.0) / (1.0f64 + 0.04).sqrt() - d;
        assert!(
            (st.mean_negative_error - expected).abs() < 1e-9,
            "{st:?} {expected}"
        );
    }
}
