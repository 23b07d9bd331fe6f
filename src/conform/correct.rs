//! The corrections of point-cloud-based path planning: standoff, lateral escape from the
//! surface where the tip disk touches it, and the downhill shift (the published method's,
//! scaled by curvature, or solved on the deposit model).
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
//!
//! Those are the published method's formulas (`corrections = "full"`, and `"slope"` with
//! κ = 0). With them the downhill shift is at most d, while the back edge the deposit model
//! reads is d_o/2 behind the tip: on a plain slope the back edge stays over higher ground and
//! the bead comes out thin, and the curvature term only moves that error around (measured on
//! the test surfaces: with or without κ the mean error is the same within micrometres).
//! `corrections = "deposit"` (the default) solves the shift on the deposit model instead:
//!
//! - Mᵢ puts the outer back edge at normal distance d from the surface's tangent plane at Tᵢ
//!   (normal n, slope g < 0 along Vᵢ): Mᵢ = d_o/2 + d·(1/n_z − 1)/(−g), within
//!   [0, d_o/2 + d] — at d_o/2 the back edge, where the paste leaves the nozzle, is over the
//!   design point; more than d beyond that would lay the bead off the design. The tangent
//!   plane is enough: solving on the surface itself, curvature and all, gave the same mean
//!   error on the test surfaces.
//! - Mᵢ exceeds the next point's shift by at most half the point spacing, so the shift ramps
//!   down over a slope's last points: dropping from Mᵢ to 0 where the path turns uphill would
//!   move the tip backwards and lay paste twice, and carrying the shift on past the turn
//!   would push the nozzle into the rising surface (measured: more contacts and a larger
//!   error than ramping down before it).
//! - A shift that would bring the whole nozzle into the surface is cut back to the largest
//!   shift without contact (the clearance pass handles points already in contact).
//! - No contact and downhill: the shift is Mᵢ itself; the method's extra d_o/2 − |Tᵢqᵢ| is for
//!   the back edge its Mᵢ does not model.

use super::nozzle::Nozzle;
use super::spline::Local;
use super::surface::Surface;
use crate::config::Corrections;
use crate::geom::{Point3, Vector3};

/// Rounds of the clearance pass (lifting a point can bring its segments into contact).
const CLEAR_ROUNDS: usize = 32;

/// Steps along [tip, tip − d·V] looking for the surface.
const BEHIND_STEPS: usize = 16;

/// Largest fall of the deposit mode's shift from one point to the next, as a fraction of the
/// point spacing: the tip always advances at least half a spacing.
const RAMP: f64 = 0.5;

/// Bisection steps that cut a shift back to the largest one without contact (0.5 mm / 2¹²
/// ≈ 0.1 µm, below the G-code's 1 µm).
const CUT_STEPS: usize = 12;

/// What the corrections did, summed over points.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct CorrectionCounts {
    /// Points moved away from a tip-disk contact (L·Q).
    pub contact: usize,
    /// Points shifted downhill (M·V or M'·V).
    pub downhill: usize,
}

/// One point's correction: the tip after the lateral escape, and the shift along the
/// horizontal direction of travel still to add.
#[derive(Debug, Clone, Copy)]
struct Move {
    base: Point3,
    along: f64,
    travel: Vector3,
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
    let mut moves: Vec<Move> = t
        .iter()
        .zip(local)
        .map(|(ti, g)| point_move(surface, nozzle, tolerance, mode, ti, g, counts))
        .collect();
    if mode != Corrections::Deposit {
        return moves.iter().map(|m| m.base + m.travel * m.along).collect();
    }
    for i in (1..moves.len()).rev() {
        let spacing = (t[i] - t[i - 1]).xy().norm();
        moves[i - 1].along = moves[i - 1].along.min(moves[i].along + RAMP * spacing);
    }
    moves
        .iter()
        .map(|m| {
            let tip = m.base + m.travel * m.along;
            if m.along <= 0.0
                || nozzle.penetration(surface, &tip) <= 0.0
                || nozzle.penetration(surface, &m.base) > 0.0
            {
                return tip;
            }
            let (mut free, mut hit) = (0.0, m.along);
            for _ in 0..CUT_STEPS {
                let mid = 0.5 * (free + hit);
                if nozzle.penetration(surface, &(m.base + m.travel * mid)) > 0.0 {
                    hit = mid;
                } else {
                    free = mid;
                }
            }
            m.base + m.travel * free
        })
        .collect()
}

/// The deposit mode's downhill shift at a point with surface normal `normal` travelling along
/// `travel`: the outer back edge at normal distance d from the tangent plane (module docs).
fn deposit_shift(normal: Vector3, travel: Vector3, d: f64, ro: f64) -> f64 {
    let cap = ro + d;
    if normal.z <= 1e-9 {
        return cap;
    }
    // Height change per mm along the travel; < 0 downhill.
    let g = -(normal.x * travel.x + normal.y * travel.y) / normal.z;
    if g >= 0.0 {
        return 0.0;
    }
    (ro + d * (1.0 / normal.z - 1.0) / -g).clamp(0.0, cap)
}

/// The correction of one point Tᵢ (module docs).
fn point_move(
    surface: &Surface,
    nozzle: &Nozzle,
    tolerance: f64,
    mode: Corrections,
    ti: &Point3,
    g: &Local,
    counts: &mut CorrectionCounts,
) -> Move {
    let d = nozzle.inner;
    let ro = nozzle.outer / 2.0;
    let tip = Point3::new(ti.x, ti.y, ti.z + d);
    let v = g.travel;
    let unmoved = Move {
        base: tip,
        along: 0.0,
        travel: v,
    };
    let m = match mode {
        Corrections::None => return unmoved,
        Corrections::Deposit => deposit_shift(g.normal, v, d, ro),
        Corrections::Full | Corrections::Slope => {
            let kappa = if mode == Corrections::Full {
                g.section_curvature
            } else {
                0.0
            };
            if kappa > 1.0 / d {
                d
            } else {
                (0.5 * d * (1.0 + d * kappa)).max(0.0)
            }
        }
    };
    // A slope under 0.1 % is flat: rounding would otherwise make flat paths "downhill".
    let downhill = g.tangent.z < -1e-3;
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
            counts.contact += 1;
            if downhill {
                counts.downhill += 1;
            }
            Move {
                base: Point3::new(tip.x + l * qx, tip.y + l * qy, tip.z),
                along: if downhill { m } else { 0.0 },
                travel: v,
            }
        }
        None if downhill => {
            counts.downhill += 1;
            let along = if mode == Corrections::Deposit {
                m
            } else {
                let behind = (1..=BEHIND_STEPS)
                    .map(|k| d * k as f64 / BEHIND_STEPS as f64)
                    .find(|&s| {
                        surface
                            .height(tip.x - s * v.x, tip.y - s * v.y)
                            .is_some_and(|h| h >= tip.z)
                    })
                    .unwrap_or(d);
                (ro - behind + m).max(0.0)
            };
            Move { along, ..unmoved }
        }
        None => unmoved,
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conform::spline;

    /// A surface z = profile(x) over x in [x0, x1], y in [−5, 5], strips every 0.05 mm.
    fn extruded(x0: f64, x1: f64, profile: impl Fn(f64) -> f64) -> Surface {
        let n = ((x1 - x0) / 0.05).round() as usize;
        let q = |i: usize, y: f64| {
            let x = x0 + (x1 - x0) * i as f64 / n as f64;
            Point3::new(x, y, profile(x))
        };
        let tris = (0..n)
            .flat_map(|i| {
                [
                    [q(i, -5.0), q(i + 1, -5.0), q(i + 1, 5.0)],
                    [q(i, -5.0), q(i + 1, 5.0), q(i, 5.0)],
                ]
            })
            .collect();
        match Surface::from_triangles(tris) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        }
    }

    /// The zero-standoff path along +x from `x0` to `x1` every d/2 and its local geometry.
    fn along_x(s: &Surface, x0: f64, x1: f64) -> (Vec<Point3>, Vec<Local>) {
        let n = ((x1 - x0) / 0.125).round() as usize;
        let t: Vec<Point3> = (0..=n)
            .filter_map(|i| {
                let x = x0 + 0.125 * i as f64;
                s.height(x, 0.0).map(|z| Point3::new(x, 0.0, z))
            })
            .collect();
        let normals: Vec<Vector3> = t
            .iter()
            .map(|p| s.top(p.x, p.y).map_or_else(Vector3::z, |h| h.1))
            .collect();
        let local = spline::local_geometry(&t, &normals);
        (t, local)
    }

    fn run(s: &Surface, mode: Corrections, t: &[Point3], local: &[Local]) -> Vec<Point3> {
        let mut counts = CorrectionCounts::default();
        correct(s, &Nozzle::for_tests(), 0.1, mode, t, local, &mut counts)
    }

    #[test]
    fn going_down_a_plain_slope_the_deposit_shift_puts_the_back_edge_at_d() {
        // Down 30°: M = d_o/2 + d·(1/cos 30° − 1)/tan 30° = 0.25 + 0.0670 = 0.3170; the back
        // edge d_o/2 behind the shifted tip is d from the plane along its normal.
        let slope = 30f64.to_radians().tan();
        let s = extruded(-1.0, 21.0, |x| -slope * x);
        let (t, local) = along_x(&s, 0.0, 20.0);
        let tips = run(&s, Corrections::Deposit, &t, &local);
        let expected = 0.25 + 0.25 * (1.0 / 30f64.to_radians().cos() - 1.0) / slope;
        assert!((expected - 0.3170).abs() < 1e-4);
        for (ti, tip) in t.iter().zip(&tips).skip(4).take(150) {
            assert!((tip.x - ti.x - expected).abs() < 1e-6, "{ti} {tip}");
            assert!((tip.z - ti.z - 0.25).abs() < 1e-12);
            let back = Point3::new(tip.x - 0.25, 0.0, tip.z);
            assert!((s.signed_distance(&back) - 0.25).abs() < 1e-6);
        }
        // The published method shifts by 0.5·d: its back edge stays d_o/2 − 0.125 behind.
        let published = run(&s, Corrections::Slope, &t, &local);
        assert!((published[40].x - t[40].x - 0.125).abs() < 1e-9);
    }

    #[test]
    fn after_a_slope_the_shift_ramps_down_and_the_tip_never_runs_backwards() {
        // Down 30° to x = 5, then flat: the shift of 0.317 mm (2.5 point spacings) ramps down
        // over the slope's last points, by at most half a spacing per point.
        let slope = 30f64.to_radians().tan();
        let s = extruded(-1.0, 11.0, |x| -slope * x.min(5.0));
        let (t, local) = along_x(&s, 0.0, 10.0);
        let tips = run(&s, Corrections::Deposit, &t, &local);
        for w in tips.windows(2) {
            assert!(w[1].x - w[0].x >= 0.0625 - 1e-9, "{} {}", w[0], w[1]);
        }
        for (ti, tip) in t.iter().zip(&tips) {
            let shift = tip.x - ti.x;
            if ti.x > 5.0 + 1e-9 {
                assert!(shift.abs() < 1e-12, "{ti} {tip}");
            } else if ti.x > 0.5 && ti.x < 5.0 - 6.0 * 0.125 {
                assert!((shift - 0.3170).abs() < 1e-4, "{ti} {tip}");
            } else if ti.x > 0.5 {
                // k spacings before the flat: at most (k + 1) half spacings.
                let k = ((5.0 - ti.x) / 0.125).round();
                assert!(shift <= 0.0625 * (k + 1.0) + 1e-9, "{ti} {tip}");
            }
        }
        // The published method stops its shift at once: the tip stands still there.
        let published = run(&s, Corrections::Slope, &t, &local);
        let least = published
            .windows(2)
            .map(|w| w[1].x - w[0].x)
            .fold(f64::MAX, f64::min);
        assert!(least < 1e-9, "{least}");
    }

    #[test]
    fn a_shift_that_would_meet_a_wall_ahead_is_cut_back_to_clear_it() {
        // Down 30° into a valley at x = 6 whose far side rises at 80°: near the bottom the
        // full shift would put the nozzle into the far wall.
        let (down, up) = (30f64.to_radians().tan(), 80f64.to_radians().tan());
        let wall = move |x: f64| (-down * x).max(up * (x - 6.0) - down * 6.0);
        let s = extruded(-1.0, 7.0, wall);
        let (t, local) = along_x(&s, 0.0, 5.9);
        let tips = run(&s, Corrections::Deposit, &t, &local);
        let n = Nozzle::for_tests();
        let mut cut = 0;
        for (ti, tip) in t.iter().zip(&tips) {
            let unshifted = Point3::new(ti.x, ti.y, ti.z + 0.25);
            if n.penetration(&s, &unshifted) <= 0.0 {
                assert!(n.penetration(&s, tip) <= 0.0, "{ti} {tip}");
            }
            if tip.x - ti.x < 0.3 && ti.x > 1.0 {
                cut += 1;
            }
        }
        assert!(cut > 0);
        // Uncut, the last points' shift would reach into the wall.
        let last = t[t.len() - 1];
        let reach = Point3::new(last.x + 0.317, 0.0, last.z + 0.25);
        assert!(n.penetration(&s, &reach) > 0.0);
    }
}
