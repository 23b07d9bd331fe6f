//! Lifting a flat path onto a surface: each point of the densified path is asked for its
//! [`Lift`] (absent, or a nozzle height, a thickness and a state), and the path is cut where
//! it is absent and doubled where its state changes.
//!
//! Place in the pipeline: inside step 4 of [`super::plan`], for every curved layer
//! ([`super::layers`]), the sandwich's skins ([`super::sandwich`]) and its core
//! ([`super::core`]).
//!
//! Where presence or state changes between two points, the boundary is found by bisection; a
//! path is cut where it is absent (so it ends on the surface's edge, not a step short of it),
//! and where the state changes the boundary point is repeated with each side's thickness, so
//! the extrusion changes exactly there. A ring cut somewhere runs its last piece on into its
//! first.

use crate::curved::tops::Projected;
use crate::geom::Point3;

/// Bisection steps for a boundary along a segment (the interval shrinks 2⁻⁴⁰ times).
const BISECTION_STEPS: usize = 40;

/// Most boundaries handled on one segment (a guard; a segment of `curved.step` crosses few).
const MAX_BOUNDARIES: usize = 16;

/// One lifted point: nozzle height, local thickness, state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lift {
    /// Nozzle height, mm.
    pub z: f64,
    /// Local thickness, mm.
    pub thickness: f64,
    /// Where this changes between neighbouring points, the extrusion changes abruptly.
    pub state: i64,
}

/// The point between `good` and `bad` nearest to where `same` stops holding, on `good`'s side,
/// and the point just past it (also where the scaffold's lines meet their limit).
pub fn bisect(
    mut good: (f64, f64),
    mut bad: (f64, f64),
    same: &dyn Fn((f64, f64)) -> bool,
) -> ((f64, f64), (f64, f64)) {
    for _ in 0..BISECTION_STEPS {
        let mid = ((good.0 + bad.0) / 2.0, (good.1 + bad.1) / 2.0);
        if same(mid) {
            good = mid;
        } else {
            bad = mid;
        }
    }
    (good, bad)
}

/// Builds the pieces of one lifted path.
struct Pieces {
    done: Vec<Projected>,
    cur: Projected,
}

impl Pieces {
    fn push(&mut self, p: (f64, f64), l: Lift) {
        self.cur.points.push(Point3::new(p.0, p.1, l.z));
        self.cur.thickness.push(l.thickness);
    }

    fn cut(&mut self) {
        let done = std::mem::replace(
            &mut self.cur,
            Projected {
                points: Vec::new(),
                thickness: Vec::new(),
                closed: false,
            },
        );
        if done.points.len() >= 2 {
            self.done.push(done);
        }
    }
}

/// `dense` (xy, mm; a closed ring without its first point repeated) lifted by `lift` (see the
/// module docs); also how many points were absent.
pub fn lift_path(
    dense: &[(f64, f64)],
    closed: bool,
    lift: &dyn Fn(f64, f64) -> Option<Lift>,
) -> (Vec<Projected>, usize) {
    let Some(&first) = dense.first() else {
        return (Vec::new(), 0);
    };
    let lifts: Vec<Option<Lift>> = dense.iter().map(|&(x, y)| lift(x, y)).collect();
    let dropped = lifts.iter().filter(|l| l.is_none()).count();
    let key = |l: Option<Lift>| l.map(|l| l.state);
    let uniform = lifts.windows(2).all(|w| key(w[0]) == key(w[1]))
        && (!closed || key(lifts[0]) == key(lifts[dense.len() - 1]));
    if uniform && closed && lifts[0].is_some() {
        let points = dense
            .iter()
            .zip(&lifts)
            .filter_map(|(&(x, y), l)| l.map(|l| (Point3::new(x, y, l.z), l.thickness)))
            .unzip();
        let (points, thickness) = points;
        return (
            vec![Projected {
                points,
                thickness,
                closed: true,
            }],
            dropped,
        );
    }
    let mut pts: Vec<((f64, f64), Option<Lift>)> = dense.iter().copied().zip(lifts).collect();
    if closed {
        pts.push((first, pts[0].1));
    }
    let mut out = Pieces {
        done: Vec::new(),
        cur: Projected {
            points: Vec::new(),
            thickness: Vec::new(),
            closed: false,
        },
    };
    if let Some(l) = pts[0].1 {
        out.push(pts[0].0, l);
    }
    for w in pts.windows(2) {
        let (mut a, mut la) = w[0];
        let (b, lb) = w[1];
        for _ in 0..MAX_BOUNDARIES {
            if key(la) == key(lb) {
                break;
            }
            let ka = key(la);
            let (m, next) = bisect(a, b, &|p| key(lift(p.0, p.1)) == ka);
            let lm = lift(m.0, m.1);
            let ln = lift(next.0, next.1);
            match (lm, ln) {
                (Some(l), Some(n)) => {
                    // Same point (the surface is continuous: one z), each side's thickness.
                    out.push(m, l);
                    out.push(m, Lift { z: l.z, ..n });
                }
                (Some(l), None) => {
                    out.push(m, l);
                    out.cut();
                }
                (None, Some(n)) => out.push(next, n),
                (None, None) => {}
            }
            (a, la) = (next, ln);
        }
        match lb {
            Some(l) => out.push(b, l),
            None => out.cut(),
        }
    }
    out.cut();
    let mut pieces = out.done;
    // A ring cut somewhere: its last piece runs on into its first.
    if closed
        && pieces.len() >= 2
        && let (Some(f), Some(l)) = (pieces.first(), pieces.last())
        && f.points.first() == l.points.last()
        && f.points.first().is_some_and(|p| (p.x, p.y) == first)
    {
        let f = pieces.remove(0);
        if let Some(l) = pieces.last_mut() {
            l.points.extend(f.points.into_iter().skip(1));
            l.thickness.extend(f.thickness.into_iter().skip(1));
        }
    }
    (pieces, dropped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_is_cut_where_absent_and_doubled_where_the_state_changes() {
        // Present for x < 3, state 0 below x = 1 and 1 above; thickness 0.2 + state·0.1.
        let lift = |x: f64, _y: f64| {
            (x < 3.0).then(|| {
                let state = i64::from(x >= 1.0);
                Lift {
                    z: 1.0,
                    thickness: 0.2 + 0.1 * state as f64,
                    state,
                }
            })
        };
        let dense: Vec<(f64, f64)> = (0..=8).map(|i| (i as f64 * 0.5, 0.0)).collect();
        let (pieces, dropped) = lift_path(&dense, false, &lift);
        assert_eq!(dropped, 3);
        assert_eq!(pieces.len(), 1);
        let p = &pieces[0];
        let last = p.points.last().expect("points");
        assert!((last.x - 3.0).abs() < 1e-9, "{last:?}");
        let i = p
            .points
            .iter()
            .position(|q| (q.x - 1.0).abs() < 1e-9)
            .expect("the boundary");
        assert!(p.points[i + 1].x == p.points[i].x || (p.points[i].x - 1.0).abs() < 1e-9);
        assert!(p.thickness[..=i].iter().all(|&t| (t - 0.2).abs() < 1e-12));
        assert!(
            p.thickness[i + 1..]
                .iter()
                .all(|&t| (t - 0.3).abs() < 1e-12)
        );
    }
}
