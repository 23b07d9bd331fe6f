//! Jet paths: chains of straight segments and circular arcs in the XY plane, millimetres.
//!
//! Place in the pipeline: the shape every later stage works on. `fillet` builds them from
//! polylines, `contour` opens closed ones at a gap, `schedule` reverses them, `shutter` writes
//! them as `G1` lines and `G2`/`G3` arcs (or flattened chords).

use std::f64::consts::PI;

/// One piece of a jet path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Seg {
    /// A straight segment from `a` to `b`.
    Line {
        /// Start, mm.
        a: [f64; 2],
        /// End, mm.
        b: [f64; 2],
    },
    /// A circular arc from `a` to `b` about `c`.
    Arc {
        /// Start, mm.
        a: [f64; 2],
        /// End, mm.
        b: [f64; 2],
        /// Centre, mm.
        c: [f64; 2],
        /// Radius, mm.
        r: f64,
        /// Signed sweep from `a` to `b`, radians (positive counter-clockwise, `G3`).
        sweep: f64,
    },
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn norm(v: [f64; 2]) -> f64 {
    v[0].hypot(v[1])
}

impl Seg {
    /// Where the segment starts.
    pub fn start(&self) -> [f64; 2] {
        match *self {
            Seg::Line { a, .. } | Seg::Arc { a, .. } => a,
        }
    }

    /// Where the segment ends.
    pub fn end(&self) -> [f64; 2] {
        match *self {
            Seg::Line { b, .. } | Seg::Arc { b, .. } => b,
        }
    }

    /// Length, mm.
    pub fn length(&self) -> f64 {
        match *self {
            Seg::Line { a, b } => norm(sub(b, a)),
            Seg::Arc { r, sweep, .. } => r * sweep.abs(),
        }
    }

    /// The same segment run the other way.
    pub fn reversed(&self) -> Seg {
        match *self {
            Seg::Line { a, b } => Seg::Line { a: b, b: a },
            Seg::Arc { a, b, c, r, sweep } => Seg::Arc {
                a: b,
                b: a,
                c,
                r,
                sweep: -sweep,
            },
        }
    }

    /// The point at distance `s` from the start (clamped to the segment).
    pub fn point_at(&self, s: f64) -> [f64; 2] {
        let len = self.length();
        let t = if len > 0.0 {
            (s / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        match *self {
            Seg::Line { a, b } => [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t],
            Seg::Arc { a, c, r, sweep, .. } => {
                let a0 = (a[1] - c[1]).atan2(a[0] - c[0]) + sweep * t;
                [c[0] + r * a0.cos(), c[1] + r * a0.sin()]
            }
        }
    }

    /// The segment cut at distance `s` from its start: the part before and the part after.
    pub fn split_at(&self, s: f64) -> (Seg, Seg) {
        let p = self.point_at(s);
        match *self {
            Seg::Line { a, b } => (Seg::Line { a, b: p }, Seg::Line { a: p, b }),
            Seg::Arc { a, b, c, r, sweep } => {
                let t = if self.length() > 0.0 {
                    (s / self.length()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (
                    Seg::Arc {
                        a,
                        b: p,
                        c,
                        r,
                        sweep: sweep * t,
                    },
                    Seg::Arc {
                        a: p,
                        b,
                        c,
                        r,
                        sweep: sweep * (1.0 - t),
                    },
                )
            }
        }
    }

    /// Unit direction of travel at the start.
    pub fn start_direction(&self) -> [f64; 2] {
        match *self {
            Seg::Line { a, b } => {
                let d = sub(b, a);
                let n = norm(d);
                if n > 0.0 {
                    [d[0] / n, d[1] / n]
                } else {
                    [1.0, 0.0]
                }
            }
            Seg::Arc { a, c, sweep, .. } => {
                let (rx, ry) = (a[0] - c[0], a[1] - c[1]);
                let n = rx.hypot(ry).max(f64::MIN_POSITIVE);
                let s = sweep.signum();
                [-ry * s / n, rx * s / n]
            }
        }
    }

    /// Points of the segment without its start, for output as straight moves: the end of a
    /// line; for an arc, chords that stray at most `tolerance` from it (vertices on the arc,
    /// the end exact).
    pub fn flatten(&self, tolerance: f64) -> Vec<[f64; 2]> {
        match *self {
            Seg::Line { b, .. } => vec![b],
            Seg::Arc { r, sweep, b, .. } => {
                let step = if tolerance >= r {
                    PI / 2.0
                } else {
                    (2.0 * (1.0 - tolerance / r).acos()).clamp(1e-4, PI / 2.0)
                };
                let n = ((sweep.abs() / step).ceil() as usize).max(1);
                let len = self.length();
                let mut out: Vec<[f64; 2]> = (1..n)
                    .map(|i| self.point_at(len * i as f64 / n as f64))
                    .collect();
                out.push(b);
                out
            }
        }
    }
}

/// A chain of segments, each starting where the one before ends.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Chain {
    /// The segments in order.
    pub segs: Vec<Seg>,
    /// Whether the chain returns to its start (a closed contour before it is opened).
    pub closed: bool,
}

impl Chain {
    /// Total length, mm.
    pub fn length(&self) -> f64 {
        self.segs.iter().map(Seg::length).sum()
    }

    /// Where the chain starts.
    pub fn start(&self) -> Option<[f64; 2]> {
        self.segs.first().map(Seg::start)
    }

    /// Where the chain ends.
    pub fn end(&self) -> Option<[f64; 2]> {
        self.segs.last().map(Seg::end)
    }

    /// The chain run the other way.
    pub fn reversed(&self) -> Chain {
        Chain {
            segs: self.segs.iter().rev().map(Seg::reversed).collect(),
            closed: self.closed,
        }
    }

    /// The first `len` millimetres of the chain (the whole chain when it is shorter).
    pub fn truncated(&self, len: f64) -> Chain {
        let mut out = Vec::new();
        let mut left = len;
        for s in &self.segs {
            let l = s.length();
            if l <= left {
                out.push(*s);
                left -= l;
            } else {
                if left > 0.0 {
                    out.push(s.split_at(left).0);
                }
                break;
            }
        }
        Chain {
            segs: out,
            closed: false,
        }
    }

    /// The chain cut at distance `s`: the part before and the part after (open chains).
    pub fn split_at(&self, s: f64) -> (Chain, Chain) {
        let mut before = Vec::new();
        let mut after = Vec::new();
        let mut at = 0.0;
        for seg in &self.segs {
            let l = seg.length();
            if at + l <= s {
                before.push(*seg);
            } else if at >= s {
                after.push(*seg);
            } else {
                let (x, y) = seg.split_at(s - at);
                before.push(x);
                after.push(y);
            }
            at += l;
        }
        (
            Chain {
                segs: before,
                closed: false,
            },
            Chain {
                segs: after,
                closed: false,
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_split_flatten_and_reverse() {
        // Quarter circle of radius 1 about the origin, counter-clockwise from (1, 0).
        let arc = Seg::Arc {
            a: [1.0, 0.0],
            b: [0.0, 1.0],
            c: [0.0, 0.0],
            r: 1.0,
            sweep: PI / 2.0,
        };
        assert!((arc.length() - PI / 2.0).abs() < 1e-12);
        let (x, y) = arc.split_at(PI / 4.0);
        let h = 0.5f64.sqrt();
        assert!((x.end()[0] - h).abs() < 1e-12 && (y.start()[1] - h).abs() < 1e-12);
        let d = arc.start_direction();
        assert!(d[0].abs() < 1e-12 && (d[1] - 1.0).abs() < 1e-12);
        let tol = 1e-3;
        let pts = arc.flatten(tol);
        assert_eq!(pts.last(), Some(&[0.0, 1.0]));
        let mut prev = [1.0, 0.0];
        for p in &pts {
            assert!((norm(*p) - 1.0).abs() < 1e-12);
            // Sagitta of each chord within the tolerance.
            let half = norm(sub(*p, prev)) / 2.0;
            assert!(1.0 - (1.0 - half * half).sqrt() <= tol + 1e-12);
            prev = *p;
        }
        let r = arc.reversed();
        assert_eq!(r.start(), [0.0, 1.0]);
        assert!(r.start_direction()[0] > 0.99);
    }
}
