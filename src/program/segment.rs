//! Planar line and arc segments: the moves of a toolpath that has arcs (an aerosol jet's
//! filleted corners), with the geometry every consumer needs — length, points along the way,
//! cutting, the starting direction and chords within a tolerance.
//!
//! Place in the pipeline: vocabulary. A stage builds them (the jet's fillets), a
//! [`super::Toolpath`] carries them in [`super::Toolpath::segments`], and the G-code writer
//! writes them as `G2`/`G3` arcs or flattens them into chords.

use std::f64::consts::PI;

/// One planar move of a toolpath: a straight line or a circular arc in the XY plane, with its
/// ends as computed (so consecutive segments meet within rounding).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Segment {
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

impl Segment {
    /// Where the segment starts.
    pub fn start(&self) -> [f64; 2] {
        match *self {
            Segment::Line { a, .. } | Segment::Arc { a, .. } => a,
        }
    }

    /// Where the segment ends.
    pub fn end(&self) -> [f64; 2] {
        match *self {
            Segment::Line { b, .. } | Segment::Arc { b, .. } => b,
        }
    }

    /// Length, mm.
    pub fn length(&self) -> f64 {
        match *self {
            Segment::Line { a, b } => norm(sub(b, a)),
            Segment::Arc { r, sweep, .. } => r * sweep.abs(),
        }
    }

    /// The same segment run the other way.
    pub fn reversed(&self) -> Segment {
        match *self {
            Segment::Line { a, b } => Segment::Line { a: b, b: a },
            Segment::Arc { a, b, c, r, sweep } => Segment::Arc {
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
            Segment::Line { a, b } => [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t],
            Segment::Arc { a, c, r, sweep, .. } => {
                let a0 = (a[1] - c[1]).atan2(a[0] - c[0]) + sweep * t;
                [c[0] + r * a0.cos(), c[1] + r * a0.sin()]
            }
        }
    }

    /// The segment cut at distance `s` from its start: the part before and the part after.
    pub fn split_at(&self, s: f64) -> (Segment, Segment) {
        let p = self.point_at(s);
        match *self {
            Segment::Line { a, b } => (Segment::Line { a, b: p }, Segment::Line { a: p, b }),
            Segment::Arc { a, b, c, r, sweep } => {
                let t = if self.length() > 0.0 {
                    (s / self.length()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (
                    Segment::Arc {
                        a,
                        b: p,
                        c,
                        r,
                        sweep: sweep * t,
                    },
                    Segment::Arc {
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
            Segment::Line { a, b } => {
                let d = sub(b, a);
                let n = norm(d);
                if n > 0.0 {
                    [d[0] / n, d[1] / n]
                } else {
                    [1.0, 0.0]
                }
            }
            Segment::Arc { a, c, sweep, .. } => {
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
            Segment::Line { b, .. } => vec![b],
            Segment::Arc { r, sweep, b, .. } => {
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

/// Total length of `segments`, mm.
pub fn length_of(segments: &[Segment]) -> f64 {
    segments.iter().map(Segment::length).sum()
}

/// `segments` (each starting where the one before ends) cut at distance `s` from the start: the
/// part before and the part after.
pub fn split_at(segments: &[Segment], s: f64) -> (Vec<Segment>, Vec<Segment>) {
    let mut before = Vec::new();
    let mut after = Vec::new();
    let mut at = 0.0;
    for seg in segments {
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
    (before, after)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_split_flatten_and_reverse() {
        // Quarter circle of radius 1 about the origin, counter-clockwise from (1, 0).
        let arc = Segment::Arc {
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
