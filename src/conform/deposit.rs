//! Expected deposit thickness along the printed path, and its error against the target d.
//!
//! Place in the pipeline: step 9, on the final tip positions; also on the paths of the two
//! controls (no corrections; slope without curvature) so the report compares them.
//!
//! Every d/2 of path length, the nozzle's reference point is the back edge of the tip in the
//! direction of travel — the outer radius behind the axis when the tip moves down, the inner
//! radius otherwise — and the thickness is its distance to the surface along the surface
//! normal (the closest-point distance, negative below the top surface). The error is
//! thickness − d. An error below −`flattening_error` is flattening, above `floating_error`
//! floating.
//!
//! Tool-surface contact is a sample where the whole nozzle ([`crate::surface::ToolSolid::penetration`]) meets the
//! surface, or where the thickness is at or below `contact_thickness`. The reference point
//! alone would miss a nozzle face ploughing into a wall ahead of it; and where the nozzle meets
//! the surface it scrapes the substrate and the paste under it, so a contact sample's
//! thickness counts as 0 (error −d): a path that collides is never scored as a good deposit.

use super::nozzle::Nozzle;
use crate::geom::{Point3, Vector3};
use crate::surface::Surface;
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

/// One sample of the deposit model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Index of the path.
    pub path: usize,
    /// Arc length along the tip path, mm.
    pub s: f64,
    /// Tip position, mm.
    pub tip: Point3,
    /// Expected deposit thickness (reference point to surface along the normal; 0 where the
    /// nozzle meets the surface), mm.
    pub thickness: f64,
    /// Whether the nozzle meets the surface here.
    pub contact: bool,
}

/// The deposit model every d/2 along `paths` (tips, mm) for `nozzle` (inner diameter d,
/// outer diameter d_o).
pub fn profile(
    surface: &Surface,
    paths: &[Vec<Point3>],
    nozzle: &Nozzle,
    thresholds: &Thresholds,
) -> Vec<Sample> {
    let (d, ro) = (nozzle.inner, nozzle.tip_radius());
    let mut out = Vec::new();
    let step = d / 2.0;
    for (index, path) in paths.iter().enumerate() {
        let mut carry = 0.0;
        let mut along = 0.0;
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
            let back = if seg.z < 0.0 { ro } else { d / 2.0 };
            let mut s = carry;
            while s < len {
                let tip = w[0] + seg * (s / len);
                let r = tip - v * back;
                let thickness = surface.signed_distance(&r);
                let contact = thickness <= thresholds.contact_thickness
                    || nozzle.solid.penetration(surface, &tip) > 0.0;
                out.push(Sample {
                    path: index,
                    s: along + s,
                    tip,
                    thickness: if contact { 0.0 } else { thickness },
                    contact,
                });
                s += step;
            }
            carry = s - len;
            along += len;
        }
    }
    out
}

/// Thickness errors of every sample of `paths` (tips, mm) for `nozzle`.
pub fn deposit(
    surface: &Surface,
    paths: &[Vec<Point3>],
    nozzle: &Nozzle,
    thresholds: &Thresholds,
) -> DepositStats {
    stats(
        &profile(surface, paths, nozzle, thresholds),
        nozzle.inner,
        thresholds,
    )
}

/// Statistics of the samples of [`profile`] against the target thickness `d`.
pub fn stats(samples: &[Sample], d: f64, thresholds: &Thresholds) -> DepositStats {
    let mut st = DepositStats {
        min_thickness: f64::INFINITY,
        ..DepositStats::default()
    };
    let mut errors = Vec::with_capacity(samples.len());
    for sample in samples {
        let thickness = sample.thickness;
        st.min_thickness = st.min_thickness.min(thickness);
        let e = thickness - d;
        if sample.contact {
            st.contact += 1;
        } else if e < -thresholds.flattening_error {
            st.flattening += 1;
        } else if e > thresholds.floating_error {
            st.floating += 1;
        }
        errors.push(e);
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

    fn nozzle(d: f64, d_o: f64) -> Nozzle {
        Nozzle::new(d, d_o, 6.0, 30.0, 10.0)
    }

    #[test]
    fn a_flat_path_at_standoff_d_deposits_exactly_d() {
        let s = plane(0.0);
        let path = vec![Point3::new(0.0, 0.0, 0.25), Point3::new(10.0, 0.0, 0.25)];
        let st = deposit(&s, &[path], &nozzle(0.25, 0.5), &T);
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
        let st = deposit(&s, &[path], &nozzle(d, d_o), &T);
        let expected = (d - 0.2 * d_o / 2.0) / (1.0f64 + 0.04).sqrt() - d;
        assert!(
            (st.mean_negative_error - expected).abs() < 1e-9,
            "{st:?} {expected}"
        );
    }

    #[test]
    fn a_nozzle_ploughing_into_a_wall_ahead_is_contact_with_no_deposit() {
        // A floor at z = 0 up to x = 4.9, a wall to z = 1 by x = 4.91. The path stops at
        // x = 4.95 at standoff d: the reference point (behind) stays over the floor, but in the
        // last samples the nozzle face reaches over the wall.
        let q = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        let mut tris = Vec::new();
        for (x0, z0, x1, z1) in [
            (-5.0, 0.0, 4.9, 0.0),
            (4.9, 0.0, 4.91, 1.0),
            (4.91, 1.0, 10.0, 1.0),
        ] {
            tris.push([q(x0, -5.0, z0), q(x1, -5.0, z1), q(x1, 5.0, z1)]);
            tris.push([q(x0, -5.0, z0), q(x1, 5.0, z1), q(x0, 5.0, z0)]);
        }
        let s = match Surface::from_triangles(tris) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        };
        let (d, d_o) = (0.25, 0.5);
        let path = vec![Point3::new(0.0, 0.0, d), Point3::new(4.95, 0.0, d)];
        let samples = profile(&s, std::slice::from_ref(&path), &nozzle(d, d_o), &T);
        assert_eq!(samples.len(), 40);
        let touching: Vec<f64> = samples
            .iter()
            .filter(|s| s.contact)
            .map(|s| s.tip.x)
            .collect();
        // The face reaches x + 0.25: samples at 4.75 and 4.875 are over the wall.
        assert_eq!(touching, vec![4.75, 4.875]);
        let st = deposit(&s, &[path], &nozzle(d, d_o), &T);
        assert_eq!(st.contact, 2);
        assert!((st.mean_abs_error - 2.0 * d / 40.0).abs() < 1e-12, "{st:?}");
        assert_eq!(st.min_thickness, 0.0);
    }
}
