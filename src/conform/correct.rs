//! The corrections of point-cloud-based path planning: standoff, lateral escape from the
//! surface where the tip disk touches it, and the shift along the travel (the published
//! method's downhill shift scaled by curvature, or the tip placed on the deposit model).
//!
//! Place in the pipeline: step 6, after the local geometry ([`super::spline`]), before the
//! clearance pass and the deposit model.
//!
//! For each point Tᵢ of the zero-standoff path, the tip goes to Tᵢ + d·ẑ. Then, with d_o the
//! outer diameter, Vᵢ the horizontal direction of travel and κᵢ the signed curvature:
//!
//! - Contact: the tip disk meets the surface around the centroid pᵢ of the contact (exactly:
//!   the contact is found where the surface's highest point over the disc reaches the tip, pᵢ
//!   is the centroid of the part of the disc under the surface,
//!   [`crate::surface::clearance::DiscContact`]); the point moves by
//!   Lᵢ = d_o/2 − |Tᵢpᵢ| + tolerance along Qᵢ = pᵢ→Tᵢ (horizontal).
//! - Downhill (t_z < 0): Mᵢ = 0.5·d·(1 + d·κᵢ) for κᵢ ≤ 1/d, Mᵢ = d beyond (never below 0).
//! - Contact and uphill → L·Q; contact and downhill → L·Q + M·V; no contact and downhill →
//!   M'ᵢ·Vᵢ with M'ᵢ = d_o/2 − |Tᵢqᵢ| + Mᵢ, where qᵢ is the first point of the segment
//!   [tip, tip − d·Vᵢ] (at the tip's height, behind the nozzle) inside the surface, or the
//!   segment's end when it stays above the surface.
//!
//! The moves are horizontal: the tip keeps its height Tᵢ.z + d (the deposit modes below set
//! their own standoff first).
//!
//! Those are the published method's formulas (`corrections = "full"`, and `"slope"` with
//! κ = 0). Their standoff is d vertically, d·n_z along the normal, so on any slope the bead
//! comes out thin, and with a shift of at most d the back edge the deposit model reads (d_o/2
//! behind the tip going down) stays over higher ground. The curvature term only moves that
//! error around (measured on the test surfaces: with or without κ the mean error is the same
//! within micrometres). `corrections = "deposit"` (the default) places the tip on the deposit
//! model instead, the model the report scores (the back edge of the tip in the direction of
//! travel, its distance to the surface along the normal):
//!
//! - Shift: the back edge over the design point, Uᵢ = d_o/2 along Vᵢ where the path goes
//!   down (the outer edge trails the paste) and d/2 where it goes up (the inner edge), faded
//!   in over the first 2° of slope along the travel: on the flat the back edge's place does
//!   not change the thickness, the bead stays centred on the design, and a scan's noise does
//!   not flip the shift back and forth.
//! - Standoff: the height hᵢ over Tᵢ at which that point is d from the surface itself
//!   (bisection on the surface's distance, within [0, 2d]). This is the curvature
//!   correction: the point is d·tan(slope) from Tᵢ along the surface, and over that reach a
//!   valley comes closer (thin) and a crest falls away (thick) — on a 2 mm cylinder at 30°,
//!   6 µm thin in the valley and 5 µm thick on the crest with the tangent plane.
//!   `corrections = "deposit-plane"`, its slope-only control, solves on the tangent plane:
//!   hᵢ = d/n_z (at most 2d). An explicit κ (the path spline's, or height differences along
//!   the slope) scored worse than the tangent plane on the test meshes, whose curvature sits
//!   at their edges; the solve on the surface reads the facets as they are.
//! - Uᵢ exceeds the next point's shift by at most half the point spacing, so the shift ramps
//!   down where it shrinks: dropping from Uᵢ to 0 at once would move the tip backwards and
//!   lay paste twice (measured: carrying the shift on instead pushes the nozzle into a rising
//!   surface).
//! - A shift that would bring the whole nozzle within [`CLEARANCE`] of the surface is cut
//!   back to the largest shift that keeps it (the clearance pass handles points already in
//!   contact).
//!
//! # Along the path, never past a corner
//!
//! Every shift along the travel (M·V, M'·V, U) and the share of a lateral escape that lies
//! along the path carry the tip *along the path seen from above* by that distance, not along
//! the straight line of Vᵢ: on a straight stretch the two are the same; where the path
//! turns, a straight shift would run the tip past the corner and back (0.25 mm at every
//! corner of a Hilbert curve, 2 % more path). So the tip:
//!
//! - never passes the next corner (a turn of more than 30°: it stops on the corner's
//!   bisector, the corner itself) nor the path's end; a gentler turn (a curve cut into
//!   segments) it follows, and the path's vertices it went past are tips too;
//! - never goes backwards: not behind its own design point, not behind the tip before it.
//!   Tips held at one place (at a corner, at the end) are one tip, the last.
//!
//! The escape's share across the path stays an offset. So the printed path, seen from above
//! and laid on the surface, is the design on the surface (without the first shift at each
//! path's start), its length the surface path's. The tip's own travel is longer where its
//! height over the surface changes: the deposit modes' shift (d_o/2 ahead going down, d/2 going
//! up) changes at every turn between downhill, level and uphill stretches, and the nozzle climbs
//! or sinks relative to the surface there (on 2 mm Hilbert stretches on 30° slopes, 0.6–0.8 %).

use super::Corrections;
use super::nozzle::Nozzle;
use super::spline::Local;
use crate::geom::{Point3, Vector3};
use crate::surface::Surface;

/// Rounds of the clearance pass (lifting a point can bring its segments into contact).
const CLEAR_ROUNDS: usize = 32;

/// Steps along [tip, tip − d·V] looking for the surface.
const BEHIND_STEPS: usize = 16;

/// Largest fall of the deposit modes' shift from one point to the next, as a fraction of the
/// point spacing: the tip always advances at least half a spacing.
const RAMP: f64 = 0.5;

/// Slope along the travel (rise per mm) at which the deposit modes' shift is complete (tan 2°).
const FULL_SHIFT_SLOPE: f64 = 0.035;

/// Bisection steps of the deposit mode's standoff over [0, 2d] (0.5 mm / 2²⁰ < 1 nm).
const STANDOFF_STEPS: usize = 20;

/// Clearance from the surface kept by the deposit modes' cut and by the clearance pass
/// ([`clear`]), mm: 5 µm over the G-code's 1 µm rounding.
pub const CLEARANCE: f64 = 0.005;

/// Bisection steps that cut a shift back to the largest one without contact (0.5 mm / 2¹²
/// ≈ 0.1 µm, below the G-code's 1 µm).
const CUT_STEPS: usize = 12;

/// What the corrections did, summed over points.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct CorrectionCounts {
    /// Points moved away from a tip-disk contact (L·Q).
    pub contact: usize,
    /// Points shifted downhill (M·V or M'·V; the deposit modes' d_o/2).
    pub downhill: usize,
    /// Points shifted uphill (the deposit modes' d/2).
    pub uphill: usize,
}

/// One point's correction: the tip after the lateral escape, and the shift along the path
/// still to add.
#[derive(Debug, Clone, Copy)]
struct Move {
    base: Point3,
    along: f64,
}

/// The corrected tip positions of one path: [`place_tips`], then the tips held at one place
/// made one and the path's vertices the tips went past added ([`printed_path`]).
pub fn correct(
    surface: &Surface,
    nozzle: &Nozzle,
    tolerance: f64,
    mode: Corrections,
    t: &[Point3],
    local: &[Local],
    counts: &mut CorrectionCounts,
) -> Vec<Point3> {
    let track = Track::new(t);
    let placed = place_tips(surface, nozzle, tolerance, mode, t, local, counts, &track);
    printed_path(&track, &placed)
}

/// One tip placed along the path: its arc length along the path seen from above, the tip, its
/// offset across the path.
#[derive(Debug, Clone, Copy)]
struct Placed {
    sigma: f64,
    tip: Point3,
    across: Vector3,
}

/// The tip of every point of `t`, one each (module docs): the standoff and lateral escape of
/// [`point_move`], the shift cut back where it would meet the surface and ramped down, carried
/// along `track`, bounded by its corners, never backwards.
#[allow(clippy::too_many_arguments)]
fn place_tips(
    surface: &Surface,
    nozzle: &Nozzle,
    tolerance: f64,
    mode: Corrections,
    t: &[Point3],
    local: &[Local],
    counts: &mut CorrectionCounts,
    track: &Track,
) -> Vec<Placed> {
    let moves: Vec<Move> = t
        .iter()
        .zip(local)
        .map(|(ti, g)| point_move(surface, nozzle, tolerance, mode, ti, g, counts))
        .collect();
    let mut shift: Vec<f64> = moves.iter().map(|m| m.along).collect();
    // The lateral escape split into its share along the path (joined to the shift) and
    // across it (kept as an offset).
    let split: Vec<(f64, Vector3)> = moves
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let dir = track.direction(i);
            let escape = Vector3::new(m.base.x - t[i].x, m.base.y - t[i].y, 0.0);
            let ahead = escape.dot(&dir);
            (ahead, escape - dir * ahead)
        })
        .collect();
    // The tip of point i at arc length `sigma`.
    let tip_at = |i: usize, sigma: f64| {
        let q = track.at(sigma) + split[i].1;
        Point3::new(q.x, q.y, moves[i].base.z)
    };
    if mode.on_deposit_model() {
        for i in 0..moves.len() {
            // A shift that brings the nozzle within the clearance is cut back to the largest
            // that keeps it (from the point's own place: never behind it, never past the next
            // corner).
            let (s, ahead) = (track.s[i], split[i].0);
            let own = |along: f64| tip_at(i, (s + ahead + along).clamp(s, track.limit(i).max(s)));
            let along = shift[i];
            if along > 0.0
                && nozzle.solid.shortfall(surface, &own(along), CLEARANCE) > 0.0
                && nozzle.solid.shortfall(surface, &own(0.0), CLEARANCE) <= 0.0
            {
                let (mut free, mut hit) = (0.0, along);
                for _ in 0..CUT_STEPS {
                    let mid = 0.5 * (free + hit);
                    if nozzle.solid.shortfall(surface, &own(mid), CLEARANCE) > 0.0 {
                        hit = mid;
                    } else {
                        free = mid;
                    }
                }
                shift[i] = free;
            }
        }
        for i in (1..shift.len()).rev() {
            let spacing = (t[i] - t[i - 1]).xy().norm();
            shift[i - 1] = shift[i - 1].min(shift[i] + RAMP * spacing);
        }
    }
    let mut placed: Vec<Placed> = Vec::with_capacity(t.len());
    let mut reached = f64::MIN;
    for (i, along) in shift.iter().enumerate() {
        // Never behind the tip before (a lateral escape may take a tip behind its own
        // design point, away from the surface it met, but the path never runs backwards).
        let lo = if i == 0 { track.s[0] } else { reached };
        let hi = track.limit(i).max(lo);
        let sigma = (track.s[i] + split[i].0 + along).clamp(lo, hi);
        reached = sigma;
        placed.push(Placed {
            sigma,
            tip: tip_at(i, sigma),
            across: split[i].1,
        });
    }
    placed
}

/// The printed path of tips placed along `track`: tips held at the same place (at a corner, at
/// the path's end) are one tip, the last (whose design point is nearest); the path's vertices
/// a tip went past since the tip before are tips too, so the printed path keeps the design's
/// shape between them.
fn printed_path(track: &Track, placed: &[Placed]) -> Vec<Point3> {
    let mut out: Vec<Placed> = Vec::with_capacity(placed.len());
    for &p in placed {
        if let Some(last) = out.last_mut()
            && (last.tip.xy() - p.tip.xy()).norm() < 1e-9
        {
            *last = p;
            continue;
        }
        if let Some(&Placed {
            sigma: s0,
            tip: p0,
            across: a0,
        }) = out.last()
        {
            for &sv in track.vertices_between(s0, p.sigma) {
                let f = (sv - s0) / (p.sigma - s0);
                let off = a0 + (p.across - a0) * f;
                let q = track.at(sv) + off;
                let z = p0.z + (p.tip.z - p0.z) * f;
                out.push(Placed {
                    sigma: sv,
                    tip: Point3::new(q.x, q.y, z),
                    across: off,
                });
            }
        }
        out.push(p);
    }
    out.into_iter().map(|p| p.tip).collect()
}

/// The vertices of the zero-standoff paths `t` seen from above where they turn, xy in mm:
/// where the printed path must pass. Path ends are left out, and so are the vertices within
/// `skip` mm (along the path) of its start, where a shift along the path starts the first tip.
pub fn corners(t: &[Vec<Point3>], skip: f64) -> Vec<[f64; 2]> {
    t.iter()
        .flat_map(|p| {
            let track = Track::new(p);
            track
                .vertex_index
                .iter()
                .zip(&track.vertex_s)
                .filter(|&(_, &s)| s > skip)
                .filter_map(|(&k, _)| track.points.get(k).copied())
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Turn (radians) above which a vertex of the path is a corner: the shift never carries a tip
/// past it. Gentler turns (a curve cut into segments) are followed.
const CORNER_TURN: f64 = std::f64::consts::FRAC_PI_6;

/// Turn (radians) above which a point of the path is a vertex (the points between a
/// segment's ends are on it to rounding).
const VERTEX_TURN: f64 = 1e-6;

/// The zero-standoff path seen from above, for moving tips along it: arc length at each
/// point, its vertices, and the arc length of the corner each point must not pass.
struct Track {
    points: Vec<[f64; 2]>,
    /// Horizontal arc length at each point, mm.
    s: Vec<f64>,
    /// For each point, the arc length of the first corner at or after it (the path's end
    /// when there is none).
    limits: Vec<f64>,
    /// The points where the path turns (ends left out), ascending.
    vertex_index: Vec<usize>,
    /// Their arc lengths.
    vertex_s: Vec<f64>,
}

impl Track {
    fn new(t: &[Point3]) -> Self {
        let points: Vec<[f64; 2]> = t.iter().map(|p| [p.x, p.y]).collect();
        let mut s = Vec::with_capacity(points.len());
        let mut acc = 0.0;
        for (i, p) in points.iter().enumerate() {
            if i > 0 {
                acc += (p[0] - points[i - 1][0]).hypot(p[1] - points[i - 1][1]);
            }
            s.push(acc);
        }
        let n = points.len();
        let mut limits = vec![acc; n];
        let mut vertex_index = Vec::new();
        let mut next = acc;
        for i in (0..n).rev() {
            if i > 0 && i + 1 < n {
                let a = [
                    points[i][0] - points[i - 1][0],
                    points[i][1] - points[i - 1][1],
                ];
                let b = [
                    points[i + 1][0] - points[i][0],
                    points[i + 1][1] - points[i][1],
                ];
                let turn = (a[0] * b[1] - a[1] * b[0])
                    .atan2(a[0] * b[0] + a[1] * b[1])
                    .abs();
                if turn > CORNER_TURN {
                    next = s[i];
                }
                if turn > VERTEX_TURN {
                    vertex_index.push(i);
                }
            }
            limits[i] = next;
        }
        vertex_index.reverse();
        let vertex_s = vertex_index.iter().map(|&i| s[i]).collect();
        Self {
            points,
            s,
            limits,
            vertex_index,
            vertex_s,
        }
    }

    /// Arc lengths of the vertices strictly between `a` and `b`.
    fn vertices_between(&self, a: f64, b: f64) -> &[f64] {
        let i = self.vertex_s.partition_point(|&x| x <= a);
        let j = self.vertex_s.partition_point(|&x| x < b).max(i);
        &self.vertex_s[i..j]
    }

    /// The arc length point `i` may be carried to.
    fn limit(&self, i: usize) -> f64 {
        self.limits.get(i).copied().unwrap_or(0.0)
    }

    /// The unit direction of the path leaving point `i` (arriving, at the last point).
    fn direction(&self, i: usize) -> Vector3 {
        let n = self.points.len();
        let (a, b) = if i + 1 < n {
            (i, i + 1)
        } else {
            (i.saturating_sub(1), i)
        };
        let (Some(p), Some(q)) = (self.points.get(a), self.points.get(b)) else {
            return Vector3::zeros();
        };
        Vector3::new(q[0] - p[0], q[1] - p[1], 0.0)
            .try_normalize(1e-12)
            .unwrap_or_else(Vector3::zeros)
    }

    /// The point at arc length `sigma` (within the path), z = 0.
    fn at(&self, sigma: f64) -> Vector3 {
        let n = self.points.len();
        let k = self
            .s
            .partition_point(|&x| x <= sigma)
            .clamp(1, n.max(2) - 1);
        let (Some(p), Some(q)) = (self.points.get(k - 1), self.points.get(k)) else {
            return self
                .points
                .first()
                .map_or_else(Vector3::zeros, |p| Vector3::new(p[0], p[1], 0.0));
        };
        let len = self.s[k] - self.s[k - 1];
        let u = if len > 0.0 {
            ((sigma - self.s[k - 1]) / len).clamp(0.0, 1.0)
        } else {
            1.0
        };
        Vector3::new(p[0] + u * (q[0] - p[0]), p[1] + u * (q[1] - p[1]), 0.0)
    }
}

/// The deposit modes' standoff over Tᵢ and shift along the travel (module docs). `trail` is
/// the back edge's distance behind the axis: d_o/2 going down, d/2 going up, 0 on the level.
fn deposit_placement(
    surface: &Surface,
    ti: &Point3,
    g: &Local,
    d: f64,
    trail: f64,
    mode: Corrections,
) -> (f64, f64) {
    let n = g.normal;
    let standoff = if mode == Corrections::Deposit {
        standoff_on_surface(surface, ti, d)
    } else {
        d / n.z.max(0.5)
    };
    let slope = if n.z > 1e-9 {
        (n.x * g.travel.x + n.y * g.travel.y).abs() / n.z
    } else {
        FULL_SHIFT_SLOPE
    };
    (standoff, trail * (slope / FULL_SHIFT_SLOPE).min(1.0))
}

/// The lowest height over `ti` (within [0, 2d]) at which the surface is `d` away.
fn standoff_on_surface(surface: &Surface, ti: &Point3, d: f64) -> f64 {
    let (mut near, mut far) = (0.0, 2.0 * d);
    for _ in 0..STANDOFF_STEPS {
        let mid = 0.5 * (near + far);
        if surface.signed_distance(&Point3::new(ti.x, ti.y, ti.z + mid)) < d {
            near = mid;
        } else {
            far = mid;
        }
    }
    far
}

/// The published method's downhill shift Mᵢ = 0.5·d·(1 + d·κᵢ), d beyond κᵢ = 1/d (κ = 0 for
/// `"slope"`).
fn published_shift(mode: Corrections, g: &Local, d: f64) -> f64 {
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
    let ro = nozzle.tip_radius();
    let v = g.travel;
    // A slope under 0.1 % is level: rounding would otherwise make flat paths "downhill".
    let downhill = g.tangent.z < -1e-3;
    let uphill = g.tangent.z > 1e-3;
    let on_model = mode.on_deposit_model();
    let (standoff, shift) = if on_model {
        let trail = if downhill {
            ro
        } else if uphill {
            d / 2.0
        } else {
            0.0
        };
        deposit_placement(surface, ti, g, d, trail, mode)
    } else {
        (d, published_shift(mode, g, d))
    };
    let tip = Point3::new(ti.x, ti.y, ti.z + standoff);
    let unmoved = Move {
        base: tip,
        along: 0.0,
    };
    if mode == Corrections::None {
        return unmoved;
    }
    let mut count_shift = |along: f64| {
        if along > 0.0 && downhill {
            counts.downhill += 1;
        } else if along > 0.0 && uphill {
            counts.uphill += 1;
        }
        along
    };
    match nozzle.solid.disc_contact(surface, &tip) {
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
            let along = count_shift(if downhill || on_model { shift } else { 0.0 });
            counts.contact += 1;
            Move {
                base: Point3::new(tip.x + l * qx, tip.y + l * qy, tip.z),
                along,
            }
        }
        None if on_model => Move {
            along: count_shift(shift),
            ..unmoved
        },
        None if downhill => {
            let behind = (1..=BEHIND_STEPS)
                .map(|k| d * k as f64 / BEHIND_STEPS as f64)
                .find(|&s| {
                    surface
                        .height(tip.x - s * v.x, tip.y - s * v.y)
                        .is_some_and(|h| h >= tip.z)
                })
                .unwrap_or(d);
            Move {
                along: count_shift((ro - behind + shift).max(0.0)),
                ..unmoved
            }
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

/// Lifts points until the whole nozzle clears the surface by `margin` (mm) at the points and
/// along the segments between them; returns how many points were lifted. Each tip position is
/// checked by the exact query ([`crate::surface::ToolSolid::shortfall`]: the highest point of
/// the surface over every footprint of the solid, per triangle), at the points and every
/// quarter of the inner diameter along the segments — the positions the report and
/// [`super::replay`] check with the same query, so a path this pass leaves clear replays with
/// no contact.
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
            let need = nozzle.solid.shortfall(surface, &path[i], margin);
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
                .map(|k| {
                    nozzle
                        .solid
                        .shortfall(surface, &(a + (b - a) * (k as f64 / n as f64)), margin)
                })
                .fold(f64::MIN, f64::max);
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

    /// The tip of every point of `t` (one each, before tips held at one place are merged).
    fn run(s: &Surface, mode: Corrections, t: &[Point3], local: &[Local]) -> Vec<Point3> {
        let mut counts = CorrectionCounts::default();
        let track = Track::new(t);
        let n = Nozzle::for_tests();
        place_tips(s, &n, 0.1, mode, t, local, &mut counts, &track)
            .iter()
            .map(|p| p.tip)
            .collect()
    }

    /// The back edge `trail` behind `tip` along +x, at the tip's height.
    fn back_edge(tip: &Point3, trail: f64) -> Point3 {
        Point3::new(tip.x - trail, tip.y, tip.z)
    }

    #[test]
    fn on_a_plain_slope_the_deposit_modes_put_the_back_edge_over_the_design_at_d() {
        // 30°: the standoff is d/cos 30° = 0.2887 on the plane and on the surface alike; the
        // shift is d_o/2 going down, d/2 going up, so the back edge is over Tᵢ and d from the
        // plane along its normal.
        let slope = 30f64.to_radians().tan();
        let standoff = 0.25 / 30f64.to_radians().cos();
        for (sign, trail) in [(-1.0, 0.25), (1.0, 0.125)] {
            let s = extruded(-1.0, 21.0, |x| sign * slope * x);
            let (t, local) = along_x(&s, 0.0, 20.0);
            for mode in [Corrections::Deposit, Corrections::DepositPlane] {
                let tips = run(&s, mode, &t, &local);
                for (ti, tip) in t.iter().zip(&tips).skip(4).take(150) {
                    assert!((tip.x - ti.x - trail).abs() < 1e-9, "{mode:?} {ti} {tip}");
                    assert!(
                        (tip.z - ti.z - standoff).abs() < 1e-6,
                        "{mode:?} {ti} {tip}"
                    );
                    let back = back_edge(tip, trail);
                    assert!((s.signed_distance(&back) - 0.25).abs() < 1e-6, "{mode:?}");
                }
            }
            // The published method keeps the standoff d: d·cos 30° = 0.2165 along the normal.
            let published = run(&s, Corrections::Slope, &t, &local);
            assert!((published[40].z - t[40].z - 0.25).abs() < 1e-12);
        }
        // Across the slope (travel along y) there is no shift, only the standoff.
        let s = extruded(-1.0, 21.0, |x| slope * x);
        let t: Vec<Point3> = (0..=40)
            .map(|i| Point3::new(10.0, -2.5 + 0.125 * i as f64, 10.0 * slope))
            .collect();
        let normals = vec![s.top(10.0, 0.0).map_or_else(Vector3::z, |h| h.1); t.len()];
        let local = spline::local_geometry(&t, &normals);
        let tips = run(&s, Corrections::Deposit, &t, &local);
        for (ti, tip) in t.iter().zip(&tips).skip(2).take(36) {
            assert!((tip.xy() - ti.xy()).norm() < 1e-9, "{ti} {tip}");
            assert!((s.signed_distance(tip) - 0.25).abs() < 1e-6, "{ti} {tip}");
        }
    }

    #[test]
    fn in_a_valley_and_on_a_crest_the_standoff_solved_on_the_surface_keeps_d() {
        // Cylinders of radius R = 2 mm, concave (a valley) and convex (a crest), crossed along
        // x. At a slope θ the reference point over Tᵢ at the tangent plane's standoff is
        // d·tan θ from Tᵢ along the surface, so about d ∓ 0.5·(d·tan θ)²/(R ∓ d) from it: at
        // 30°, 6 µm thin in the valley and 5 µm thick on the crest (exactly R − |P − C| and
        // |P − C| − R for the axis C). On the surface, the standoff brings it back to d.
        let (r, d) = (2.0f64, 0.25);
        let valley = extruded(-1.6, 1.6, move |x| r - (r * r - x * x).sqrt());
        let crest = extruded(-1.6, 1.6, move |x| (r * r - x * x).sqrt() - r);
        for (s, concave) in [(valley, true), (crest, false)] {
            // Off the strips' edges, where a point would take one side's facet normal.
            let (t, local) = along_x(&s, -1.2375, 1.2375);
            let on_surface = run(&s, Corrections::Deposit, &t, &local);
            let on_plane = run(&s, Corrections::DepositPlane, &t, &local);
            let mut checked = 0;
            for ((ti, a), b) in t.iter().zip(&on_surface).zip(&on_plane) {
                let sin = ti.x / r;
                let theta = sin.asin().abs();
                if !(25f64.to_radians()..=35f64.to_radians()).contains(&theta) {
                    continue;
                }
                // Going down on the left half of the valley and the right half of the crest.
                let down = (ti.x < 0.0) == concave;
                let trail = if down { 0.25 } else { 0.125 };
                // Where the rising side ahead cuts the shift back, the back edge is elsewhere.
                if (a.x - ti.x - trail).abs() > 1e-9 || (b.x - ti.x - trail).abs() > 1e-9 {
                    continue;
                }
                let (ra, rb) = (back_edge(a, trail), back_edge(b, trail));
                let axis = Point3::new(0.0, rb.y, if concave { r } else { -r });
                let exact = if concave {
                    r - (rb - axis).xz().norm()
                } else {
                    (rb - axis).xz().norm() - r
                };
                let plane = s.signed_distance(&rb);
                assert!((plane - exact).abs() < 5e-4, "{ti}: {plane} {exact}");
                let reach = d * theta.tan();
                let second_order = 0.5 * reach * reach / if concave { r - d } else { r + d };
                let error = if concave { d - plane } else { plane - d };
                // Within half of it: the control reads the facet's normal, not the cylinder's.
                assert!(
                    (error - second_order).abs() < 0.5 * second_order,
                    "{ti}: {plane} {second_order}"
                );
                assert!((s.signed_distance(&ra) - d).abs() < 5e-4, "{ti} {a}");
                checked += 1;
            }
            assert!(checked >= 4, "{checked}");
        }
    }

    #[test]
    fn after_a_slope_the_shift_ramps_down_and_the_tip_never_runs_backwards() {
        // Down 30° to x = 5, then flat: the shift of d_o/2 (two point spacings) ramps down
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
                assert!((shift - 0.25).abs() < 1e-9, "{ti} {tip}");
            } else if ti.x > 0.5 {
                // k spacings before the flat: at most (k + 1) half spacings.
                let k = ((5.0 - ti.x) / 0.125).round();
                assert!(shift <= 0.0625 * (k + 1.0) + 1e-9, "{ti} {tip}");
            }
        }
        // The published method stops its shift at once: the tip waits there (it never runs
        // backwards), and the printed path holds it once.
        let published = run(&s, Corrections::Slope, &t, &local);
        let least = published
            .windows(2)
            .map(|w| w[1].x - w[0].x)
            .fold(f64::MAX, f64::min);
        assert!(least.abs() < 1e-9, "{least}");
        let mut counts = CorrectionCounts::default();
        let n = Nozzle::for_tests();
        let printed = correct(&s, &n, 0.1, Corrections::Slope, &t, &local, &mut counts);
        assert!(printed.len() < published.len());
        for w in printed.windows(2) {
            assert!(w[1].x - w[0].x > 1e-9, "{} {}", w[0], w[1]);
        }
    }

    #[test]
    fn a_shift_stops_at_a_corner_and_the_printed_path_passes_through_it() {
        // Down a 30° slope along +x to a corner at x = 5, then across the slope along +y:
        // going down the tips are d_o/2 ahead of their points, but none passes the corner
        // (a straight shift along the travel would reach x = 5.25 and come back).
        let slope = 30f64.to_radians().tan();
        let s = extruded(-1.0, 11.0, |x| -slope * x);
        let mut t: Vec<Point3> = (0..=40)
            .map(|i| {
                let x = 0.125 * i as f64;
                Point3::new(x, 0.0, -slope * x)
            })
            .collect();
        t.extend((1..=40).map(|i| Point3::new(5.0, 0.125 * i as f64, -slope * 5.0)));
        let normals: Vec<Vector3> = t
            .iter()
            .map(|p| s.top(p.x, p.y).map_or_else(Vector3::z, |h| h.1))
            .collect();
        let local = spline::local_geometry(&t, &normals);
        let mut counts = CorrectionCounts::default();
        let n = Nozzle::for_tests();
        let printed = correct(&s, &n, 0.1, Corrections::Deposit, &t, &local, &mut counts);
        assert!(printed.iter().all(|p| p.x <= 5.0 + 1e-12));
        assert!(
            printed
                .iter()
                .any(|p| (p.x - 5.0).abs() < 1e-12 && p.y.abs() < 1e-12)
        );
        // Seen from above, the printed path is the design less the first shift (d_o/2).
        let len = |p: &[Point3]| p.windows(2).map(|w| (w[1] - w[0]).xy().norm()).sum::<f64>();
        assert!(
            (len(&t) - len(&printed) - 0.25).abs() < 1e-9,
            "{}",
            len(&printed)
        );
        assert!((printed[0].x - 0.25).abs() < 1e-12, "{}", printed[0]);
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
            // The moves are horizontal: the unshifted tip is at the tip's height over Tᵢ.
            let unshifted = Point3::new(ti.x, ti.y, tip.z);
            if n.solid.shortfall(&s, &unshifted, CLEARANCE) <= 0.0 {
                assert!(n.solid.shortfall(&s, tip, CLEARANCE) <= 1e-9, "{ti} {tip}");
            }
            if tip.x - ti.x < 0.25 - 1e-9 && ti.x > 1.0 {
                cut += 1;
            }
        }
        assert!(cut > 0);
        // Uncut, the last point's shift would reach into the wall.
        let (last, tip) = (t[t.len() - 1], tips[tips.len() - 1]);
        let reach = Point3::new(last.x + 0.25, 0.0, tip.z);
        assert!(n.solid.penetration(&s, &reach) > 0.0);
    }
}
