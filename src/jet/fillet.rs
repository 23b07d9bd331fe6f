//! Tangent fillet arcs at the corners of a polyline, per the rule table, shrunk where the
//! adjacent segments are too short; corners too sharp to fillet split the path.
//!
//! Place in the pipeline: design polylines → corners → **fillet** → contour → schedule → program →
//! emit.
//!
//! A fillet of radius `r` at a corner of angle `θ` starts and ends `t = r / tan(θ/2)` from the
//! vertex on each segment. Two fillets share a segment: when their `t` add up to more than the
//! segment's length, both are scaled down to fit, the radius follows (`r = t·tan(θ/2)`), and
//! the corner is reported as shrunk.

use serde::Serialize;
use std::f64::consts::PI;

use super::corners::{CornerRules, Requirement, corner_angle};
use super::path::{Chain, Seg};

/// What was done at a corner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CornerAction {
    /// Left sharp: the rule asks for no fillet.
    None,
    /// A tangent arc was inserted.
    Fillet,
    /// The path is split at the corner (shutter closes, the next segment starts fresh).
    Split,
}

/// One corner of a design path and what the rules made of it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Corner {
    /// Index of the vertex in the design path.
    pub index: usize,
    /// The vertex, mm.
    pub at: [f64; 2],
    /// Angle between the two segments, degrees (180 = straight).
    pub angle_deg: f64,
    /// What was done.
    pub action: CornerAction,
    /// Radius the rule asks for, mm (0 when none or split).
    pub required_radius: f64,
    /// Radius of the inserted fillet, mm (0 when none or split).
    pub radius: f64,
    /// The fillet was shrunk below the rule to fit the adjacent segments.
    pub shrunk: bool,
}

/// A design path after filleting: one chain, or several where the path was split.
#[derive(Debug, Clone, PartialEq)]
pub struct Filleted {
    /// The chains in path order; a closed path without splits stays one closed chain.
    pub chains: Vec<Chain>,
    /// Every corner (closed paths: every vertex; open paths: every vertex but the ends).
    pub corners: Vec<Corner>,
}

/// Removes consecutive duplicates (and, for closed paths, a repeated first point at the end).
fn clean(points: &[[f64; 2]], closed: bool) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(points.len());
    for p in points {
        if out.last() != Some(p) {
            out.push(*p);
        }
    }
    if closed && out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    out
}

fn unit(from: [f64; 2], to: [f64; 2]) -> [f64; 2] {
    let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
    let n = dx.hypot(dy);
    if n > 0.0 {
        [dx / n, dy / n]
    } else {
        [0.0, 0.0]
    }
}

/// Per vertex: the corner angle, the rules' requirement, the wanted tangent length, and the
/// factor that fits the tangent lengths to the segments they share.
struct Wanted {
    angle: Vec<f64>,
    req: Vec<Requirement>,
    t_want: Vec<f64>,
    factor: Vec<f64>,
}

/// Measures every corner, asks `rules` for its requirement, and fits the wanted tangent lengths
/// to the segments they share.
fn wanted(pts: &[[f64; 2]], closed: bool, width: f64, rules: &CornerRules) -> Wanted {
    let n = pts.len();
    let is_corner = |i: usize| closed || (i > 0 && i + 1 < n);
    let prev = |i: usize| (i + n - 1) % n;
    let next = |i: usize| (i + 1) % n;
    // Angle, requirement and wanted tangent length per vertex.
    let mut angle = vec![180.0; n];
    let mut req = vec![Requirement::Fillet(0.0); n];
    let mut t_want = vec![0.0; n];
    for i in (0..n).filter(|&i| is_corner(i)) {
        angle[i] = corner_angle(pts[prev(i)], pts[i], pts[next(i)]);
        req[i] = rules.requirement(angle[i], width);
        if let Requirement::Fillet(r) = req[i]
            && r > 0.0
            && angle[i] < 180.0
        {
            t_want[i] = r / (angle[i].to_radians() / 2.0).tan();
        }
    }
    // Fit the tangent lengths to the segments they share.
    let mut factor = vec![1.0f64; n];
    let edges = if closed { n } else { n - 1 };
    for e in 0..edges {
        let (i, j) = (e, next(e));
        let len = (pts[j][0] - pts[i][0]).hypot(pts[j][1] - pts[i][1]);
        let sum = t_want[i] + t_want[j];
        if sum > len {
            let f = len / sum;
            factor[i] = factor[i].min(f);
            factor[j] = factor[j].min(f);
        }
    }
    Wanted {
        angle,
        req,
        t_want,
        factor,
    }
}

/// Decides each corner's action and returns the corners with the tangent length and radius
/// per vertex.
fn corner_actions(
    pts: &[[f64; 2]],
    closed: bool,
    angle: &[f64],
    req: &[Requirement],
    t_want: &[f64],
    factor: &[f64],
) -> (Vec<Corner>, Vec<f64>, Vec<f64>) {
    let n = pts.len();
    let is_corner = |i: usize| closed || (i > 0 && i + 1 < n);
    let mut corners = Vec::new();
    let mut t = vec![0.0; n];
    let mut radius = vec![0.0; n];
    for i in (0..n).filter(|&i| is_corner(i)) {
        let (action, required) = match req[i] {
            Requirement::Split => (CornerAction::Split, 0.0),
            Requirement::Fillet(r) if t_want[i] > 0.0 => (CornerAction::Fillet, r),
            Requirement::Fillet(_) => (CornerAction::None, 0.0),
        };
        if action == CornerAction::Fillet {
            t[i] = t_want[i] * factor[i];
            radius[i] = t[i] * (angle[i].to_radians() / 2.0).tan();
        }
        corners.push(Corner {
            index: i,
            at: pts[i],
            angle_deg: angle[i],
            action,
            required_radius: required,
            radius: radius[i],
            shrunk: action == CornerAction::Fillet && factor[i] < 1.0 - 1e-6,
        });
    }
    (corners, t, radius)
}

/// Fillets and splits the corners of `points` for line width `width` (mm) by `rules`.
pub fn fillet(points: &[[f64; 2]], closed: bool, width: f64, rules: &CornerRules) -> Filleted {
    let pts = clean(points, closed);
    let n = pts.len();
    if n < 2 || (closed && n < 3) {
        let segs = pts
            .windows(2)
            .map(|w| Seg::Line { a: w[0], b: w[1] })
            .collect();
        return Filleted {
            chains: vec![Chain {
                segs,
                closed: false,
            }],
            corners: Vec::new(),
        };
    }
    let is_corner = |i: usize| closed || (i > 0 && i + 1 < n);
    let prev = |i: usize| (i + n - 1) % n;
    let next = |i: usize| (i + 1) % n;
    let Wanted {
        angle,
        req,
        t_want,
        factor,
    } = wanted(&pts, closed, width, rules);
    let (corners, t, radius) = corner_actions(&pts, closed, &angle, &req, &t_want, &factor);
    let split = |i: usize| is_corner(i) && req[i] == Requirement::Split;
    // Tangent points and arcs of each filleted vertex.
    let p_in = |i: usize| {
        let u = unit(pts[i], pts[prev(i)]);
        [pts[i][0] + u[0] * t[i], pts[i][1] + u[1] * t[i]]
    };
    let p_out = |i: usize| {
        let u = unit(pts[i], pts[next(i)]);
        [pts[i][0] + u[0] * t[i], pts[i][1] + u[1] * t[i]]
    };
    let arc = |i: usize| -> Option<Seg> {
        if t[i] <= 0.0 {
            return None;
        }
        let (up, un) = (unit(pts[i], pts[prev(i)]), unit(pts[i], pts[next(i)]));
        let bis = unit([0.0, 0.0], [up[0] + un[0], up[1] + un[1]]);
        let half = angle[i].to_radians() / 2.0;
        let d = radius[i] / half.sin();
        let c = [pts[i][0] + bis[0] * d, pts[i][1] + bis[1] * d];
        // Travel turns left (counter-clockwise arc) when (−up) × un > 0.
        let turn = -(up[0] * un[1] - up[1] * un[0]);
        let sweep = (PI - angle[i].to_radians()) * turn.signum();
        Some(Seg::Arc {
            a: p_in(i),
            b: p_out(i),
            c,
            r: radius[i],
            sweep,
        })
    };
    // Walk the vertices: `order` lists them from the walk's first vertex to its last.
    let first_split = (0..n).find(|&i| split(i));
    let (order, wrap): (Vec<usize>, bool) = match (closed, first_split) {
        (true, None) => ((0..n).chain([0]).collect(), true),
        (true, Some(s)) => ((0..=n).map(|k| (s + k) % n).collect(), false),
        (false, _) => ((0..n).collect(), false),
    };
    let mut chains = Vec::new();
    let mut segs: Vec<Seg> = Vec::new();
    let mut cur = if wrap { p_out(order[0]) } else { pts[order[0]] };
    let push_line = |segs: &mut Vec<Seg>, a: [f64; 2], b: [f64; 2]| {
        if a != b {
            segs.push(Seg::Line { a, b });
        }
    };
    for k in 1..order.len() {
        let j = order[k];
        let last = k + 1 == order.len();
        let endpoint = last && !wrap;
        if endpoint || split(j) {
            push_line(&mut segs, cur, pts[j]);
            chains.push(Chain {
                segs: std::mem::take(&mut segs),
                closed: false,
            });
            cur = pts[j];
            continue;
        }
        match arc(j) {
            Some(a) => {
                push_line(&mut segs, cur, p_in(j));
                segs.push(a);
                cur = p_out(j);
            }
            None => {
                push_line(&mut segs, cur, pts[j]);
                cur = pts[j];
            }
        }
    }
    if wrap {
        chains.push(Chain { segs, closed: true });
    }
    chains.retain(|c| !c.segs.is_empty());
    Filleted { chains, corners }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::JetSettings;

    fn rules() -> CornerRules {
        CornerRules::new(&JetSettings::default())
    }

    #[test]
    fn square_is_left_sharp_and_closed() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let f = fillet(&sq, true, 0.02, &rules());
        assert_eq!(f.chains.len(), 1);
        assert!(f.chains[0].closed);
        assert_eq!(f.chains[0].segs.len(), 4);
        assert!((f.chains[0].length() - 4.0).abs() < 1e-12);
        assert!(f.corners.iter().all(|c| c.action == CornerAction::None));
    }

    #[test]
    fn sharp_vee_gets_a_tangent_fillet_and_a_needle_is_split() {
        // A 30° vee: rule r ≥ w. Tangent length t = r / tan(15°).
        let a = 30f64.to_radians();
        let v = [[1.0, 0.0], [0.0, 0.0], [a.cos(), a.sin()]];
        let f = fillet(&v, false, 0.02, &rules());
        let c = &f.corners[0];
        assert_eq!(c.action, CornerAction::Fillet);
        assert!((c.radius - 0.02).abs() < 1e-12 && !c.shrunk);
        let segs = &f.chains[0].segs;
        assert_eq!(segs.len(), 3);
        let t = 0.02 / 15f64.to_radians().tan();
        assert!((segs[0].length() - (1.0 - t)).abs() < 1e-12);
        if let Seg::Arc { c, r, sweep, a, b } = segs[1] {
            // Tangent: the centre is r from both tangent points and from both lines.
            assert!(((a[0] - c[0]).hypot(a[1] - c[1]) - r).abs() < 1e-12);
            assert!(((b[0] - c[0]).hypot(b[1] - c[1]) - r).abs() < 1e-12);
            assert!((c[1] - r).abs() < 1e-12);
            // Travelling −x then turning up-right is a right turn: clockwise, sweep 150°.
            assert!((sweep + 150f64.to_radians()).abs() < 1e-12);
        } else {
            panic!("expected an arc, got {:?}", segs[1]);
        }
        // 10°: split into two chains meeting at the vertex.
        let a = 10f64.to_radians();
        let v = [[1.0, 0.0], [0.0, 0.0], [a.cos(), a.sin()]];
        let f = fillet(&v, false, 0.02, &rules());
        assert_eq!(f.chains.len(), 2);
        assert_eq!(f.corners[0].action, CornerAction::Split);
    }

    #[test]
    fn short_segments_shrink_the_fillet_and_say_so() {
        // 30° vee with 0.05 mm legs: t would be 0.0746 mm, so it shrinks to fit the leg.
        let a = 30f64.to_radians();
        let v = [[0.05, 0.0], [0.0, 0.0], [0.05 * a.cos(), 0.05 * a.sin()]];
        let f = fillet(&v, false, 0.02, &rules());
        let c = &f.corners[0];
        assert!(c.shrunk);
        assert!((c.radius - 0.05 * 15f64.to_radians().tan()).abs() < 1e-12);
    }
}
