//! The corrections of point-cloud-based path planning: standoff, lateral escape from the
//! surface where the tip disk touches it, and the downhill shift scaled by curvature.
//!
//! Place in the pipeline: step 6, after the local geometry ([`super::spline`]), before the
//! clearance pass and the deposit model.
//!
//! For each point Tᵢ of the zero-standoff path, the tip goes to Tᵢ + d·ẑ. Then, with d_o the
//! outer diameter, Vᵢ the horizontal direction of travel and κᵢ the signed curvature:
//!
//! - Contact: the tip disk meets the surface around the centroid pᵢ of the contact; the point
//!   moves by Lᵢ = d_o/2 − |Tᵢpᵢ| + tolerance along Qᵢ = pᵢ→Tᵢ (horizontal).
//! - Downhill (t_z < 0): Mᵢ = 0.5·d·(1 + d·κᵢ) for κᵢ ≤ 1/d, Mᵢ = d beyond (never below 0).
//! - Contact and uphill → L·Q; contact and downhill → L·Q + M·V; no contact and downhill →
//!   M'ᵢ·Vᵢ with M'ᵢ = d_o/2 − |Tᵢqᵢ| + Mᵢ, where qᵢ is the first point of the segment
//!   [tip, tip − d·Vᵢ] (at the tip's height, behind the nozzle) inside the surface, or the
//!   segment's end when it stays above the surface.
//!
//! The moves are horizontal: the tip keeps its height Tᵢ.z + d.

use super::nozzle::Nozzle;
use super::spline::Local;
use super::surface::Surface;
use crate::config::Corrections;
use crate::geom::Point3;

/// Rounds of the clearance pass (lifting a point can bring its segments into contact).
const CLEAR_ROUNDS: usize = 32;

/// Steps along [tip, tip − d·V] looking for the surface.
const BEHIND_STEPS: usize = 16;

/// What the corrections did, summed over points.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct CorrectionCounts {
    /// Points moved away from a tip-disk contact (L·Q).
    pub contact: usize,
    /// Points shifted downhill (M·V or M'·V).
    pub downhill: usize,
}

/// The corrected tip positions of one path.
pub fn correct(
    surface: &Surface,
    nozzle: &Nozzle,
    tolerance: f64,
    mode: Corrections,
    t: &[Point3],
    local: &[Local],
    counts: &mut CorrectionCounts,
) -> Vec<Point3> {
    let d = nozzle.inner;
    let ro = nozzle.outer / 2.0;
    t.iter()
        .zip(local)
        .map(|(ti, g)| {
            let tip = Point3::new(ti.x, ti.y, ti.z + d);
            if mode == Corrections::None {
                return tip;
            }
            let kappa = if mode == Corrections::Full {
                g.section_curvature
            } else {
                0.0
            };
            let m = if kappa > 1.0 / d {
                d
            } else {
                (0.5 * d * (1.0 + d * kappa)).max(0.0)
            };
            // A slope under 0.1 % is flat: rounding would otherwise make flat paths "downhill".
            let downhill = g.tangent.z < -1e-3;
            let v = g.travel;
            let mut shift = [0.0, 0.0];
            match nozzle.disk_contact(surface, &tip) {
                Some(p) => {
                    let (qx, qy) = (ti.x - p[0], ti.y - p[1]);
                    let dist = qx.hypot(qy);
                    let (qx, qy) = if dist > 1e-9 {
                        (qx / dist, qy / dist)
                    } else {
                        // Contact all around the axis: step back against the travel.
                        (-v.x, -v.y)
                    };
                    let l = (ro - dist + tolerance).max(0.0);
                    shift = [l * qx, l * qy];
                    counts.contact += 1;
                    if downhill {
                        shift = [shift[0] + m * v.x, shift[1] + m * v.y];
                        counts.downhill += 1;
                    }
                }
                None if downhill => {
                    let behind = (1..=BEHIND_STEPS)
                        .map(|k| d * k as f64 / BEHIND_STEPS as f64)
                        .find(|&s| {
                            surface
                                .height(tip.x - s * v.x, tip.y - s * v.y)
                                .is_some_and(|h| h >= tip.z)
                        })
                        .unwrap_or(d);
                    let m2 = (ro - behind + m).max(0.0);
                    shift = [m2 * v.x, m2 * v.y];
                    counts.downhill += 1;
                }
                None => {}
            }
            Point3::new(tip.x + shift[0], tip.y + shift[1], tip.z)
        })
        .collect()
}

/// The G-code's grid: XYZ are written with [`conduit_gcode::XYZ_DECIMALS`] decimals.
fn grid() -> f64 {
    10f64.powi(-(conduit_gcode::XYZ_DECIMALS as i32))
}

/// `p` as the G-code will hold it: x and y rounded to the grid, z rounded up (never closer to
/// the surface).
fn snap(p: Point3) -> Point3 {
    let g = grid();
    Point3::new(
        (p.x / g).round() * g,
        (p.y / g).round() * g,
        (p.z / g - 1e-6).ceil() * g,
    )
}

/// Lifts points until no sample of the whole nozzle, at the points and along the segments
/// between them (every quarter of the inner diameter, as [`super::replay`] samples), meets the
/// surface; returns how many points were lifted. `margin` is the clearance kept, mm.
///
/// Points are first put on the G-code's 1 µm grid and every lift is rounded up to it, so the
/// path checked is the path written: on a steep flank half a micrometre sideways is several
/// micrometres of height.
pub fn clear(surface: &Surface, nozzle: &Nozzle, path: &mut [Point3], margin: f64) -> usize {
    let step = nozzle.inner / 4.0;
    for p in path.iter_mut() {
        *p = snap(*p);
    }
    let mut lifted = vec![false; path.len()];
    for _ in 0..CLEAR_ROUNDS {
        let mut changed = false;
        for i in 0..path.len() {
            let need = nozzle.penetration(surface, &path[i]) + margin;
            if need > 0.0 {
                path[i] = snap(path[i] + crate::geom::Vector3::new(0.0, 0.0, need));
                lifted[i] = true;
                changed = true;
            }
        }
        for i in 0..path.len().saturating_sub(1) {
            let (a, b) = (path[i], path[i + 1]);
            let n = (((b - a).norm() / step).ceil() as usize).max(2);
            let need = (1..n)
                .map(|k| nozzle.penetration(surface, &(a + (b - a) * (k as f64 / n as f64))))
                .fold(f64::MIN, f64::max)
                + margin;
            if need > 0.0 {
                let up = crate::geom::Vector3::new(0.0, 0.0, need);
                path[i] = snap(path[i] + up);
                path[i + 1] = snap(path[i + 1] + up);
                lifted[i] = true;
                lifted[i + 1] = true;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    lifted.iter().filter(|&&l| l).count()
}
