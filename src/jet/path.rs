//! Jet paths: chains of straight segments and circular arcs in the XY plane, millimetres (the
//! segments are the Program's [`crate::program::Segment`]s).
//!
//! Place in the pipeline: the shape every later stage works on. `fillet` builds them from
//! polylines, `contour` opens closed ones at a gap, `schedule` reverses them, `program` turns
//! them into the Program's toolpaths, which the G-code writer writes as `G1` lines and `G2`/`G3`
//! arcs (or flattened chords).

pub use crate::program::Segment as Seg;

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
        crate::program::segment::length_of(&self.segs)
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
        let (before, after) = crate::program::segment::split_at(&self.segs, s);
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
