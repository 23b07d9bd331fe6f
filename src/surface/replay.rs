//! The one replay walk: the tool run along its moves, every sampled tip position asked against
//! an obstacle — a scanned surface, or material printed so far.
//!
//! Place in the pipeline: vocabulary for the checks after planning. The curved tops check
//! their nozzle positions against the planar layers, the curved-layer replay runs a whole
//! print over a grid of printed material, the bead replay runs written G-code bead by bead,
//! and conform's replay runs the written G-code against the scanned surface; each is [`walk`]
//! with its own [`Obstacle`].
//!
//! A print is a sequence of [`Stretch`]es (a move, a bead, a path). The walk samples each
//! stretch's tip positions ([`Spacing`]), asks the obstacle for its contact with the
//! [`ToolSolid`] at each position, hands the answer to the caller (which may go on, skip to the
//! next stretch or stop), then lets the obstacle lay down what the stretch printed, so later
//! stretches meet it.

use super::tool::{ToolPart, ToolSolid};
use crate::geom::Point3;

/// A point of an obstacle inside the tool: the contact of printed material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// The nozzle tip, mm.
    pub nozzle: Point3,
    /// The material point inside the tool, mm.
    pub material: Point3,
    /// The part of the tool it is in.
    pub part: ToolPart,
}

impl Hit {
    /// The material point `q` as a hit of `tool` with its tip at `nozzle`: when it lies above
    /// the tip, horizontally closer to the axis than the tool's radius at its height.
    pub fn of_point(tool: &ToolSolid, nozzle: Point3, q: Point3) -> Option<Hit> {
        let (radius, part) = tool.radius_at(q.z - nozzle.z)?;
        ((q.x - nozzle.x).hypot(q.y - nozzle.y) < radius).then_some(Hit {
            nozzle,
            material: q,
            part,
        })
    }

    /// Horizontal distance between nozzle and material, mm.
    pub fn radius(&self) -> f64 {
        (self.material.x - self.nozzle.x).hypot(self.material.y - self.nozzle.y)
    }

    /// Height of the material above the nozzle tip, mm.
    pub fn rise(&self) -> f64 {
        self.material.z - self.nozzle.z
    }
}

/// How the walk spaces tip positions along a stretch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spacing {
    /// Each segment a→b in n = ⌈|b − a| / step⌉ ≥ 1 equal steps, both ends included: the
    /// positions a + (b − a)·k/n for k in 0..=n (moves and beads, one segment each).
    Steps(f64),
    /// Each segment a→b in n = ⌈|b − a|ₓᵧ / step⌉ ≥ 1 equal horizontal steps, its end left to
    /// the next segment: a + (b − a)·j/n for j in 0..n; a closed path runs back to its first
    /// point, an open one ends at its last point itself (paths over a grid).
    Horizontal(f64),
}

/// One tip position of a stretch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// The nozzle tip, mm.
    pub tip: Point3,
    /// How far along its segment, 0 to 1.
    pub fraction: f64,
}

impl Spacing {
    /// The tip positions along `points` (back to the first when `closed`); a single point is
    /// its one position.
    pub fn samples(self, points: &[Point3], closed: bool) -> Vec<Sample> {
        match (self, points) {
            (_, [p]) => vec![Sample {
                tip: *p,
                fraction: 0.0,
            }],
            (Spacing::Steps(step), _) => {
                let mut out = Vec::new();
                for w in points.windows(2) {
                    let (a, b) = (w[0], w[1]);
                    let n = (((b - a).norm() / step).ceil() as usize).max(1);
                    for k in 0..=n {
                        let f = k as f64 / n as f64;
                        out.push(Sample {
                            tip: a + (b - a) * f,
                            fraction: f,
                        });
                    }
                }
                out
            }
            (Spacing::Horizontal(step), _) => horizontal(points, closed, step),
        }
    }
}

/// [`Spacing::Horizontal`] positions along `points`.
fn horizontal(points: &[Point3], closed: bool, step: f64) -> Vec<Sample> {
    let mut out = Vec::with_capacity(points.len() * 2);
    let n = points.len();
    let segs = if closed && n > 2 {
        n
    } else {
        n.saturating_sub(1)
    };
    for i in 0..segs {
        let (a, b) = (points[i], points[(i + 1) % n]);
        let k = ((b - a).xy().norm() / step).ceil().max(1.0) as usize;
        for j in 0..k {
            let f = j as f64 / k as f64;
            out.push(Sample {
                tip: a + (b - a) * f,
                fraction: f,
            });
        }
    }
    if let (false, Some(&last)) = (closed && n > 2, points.last()) {
        out.push(Sample {
            tip: last,
            fraction: 1.0,
        });
    }
    out
}

/// One stretch of the tool's motion: a move, a bead or a path of the tip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stretch<'a> {
    /// Its points, in the order the tip runs them, mm.
    pub points: &'a [Point3],
    /// Whether the tip runs back to the first point.
    pub closed: bool,
    /// Whether its positions are tested (false: it only lays material down).
    pub tested: bool,
}

/// What the walk does after handing a contact to the caller.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Next {
    /// Test the stretch's next position.
    Sample,
    /// Leave the stretch's remaining positions untested.
    Stretch,
    /// End the walk.
    Stop,
}

/// What the tool can run into during a [`walk`].
pub trait Obstacle {
    /// The answer for one tip position (a hit or none, a depth, ...).
    type Contact;

    /// Whether the tool can reach the obstacle anywhere along stretch `index`; `false` skips
    /// its tests (not its material).
    fn in_reach(&self, _tool: &ToolSolid, _index: usize, _stretch: &Stretch<'_>) -> bool {
        true
    }

    /// The contact of the tool with its tip at `sample` of stretch `index`.
    fn contact(&self, tool: &ToolSolid, index: usize, sample: &Sample) -> Self::Contact;

    /// Lays down what stretch `index` printed, after its positions were tested.
    fn lay(&mut self, _index: usize, _stretch: &Stretch<'_>, _samples: &[Sample]) {}
}

/// Walks `stretches` in order (see the module docs): each tested stretch's positions per
/// `spacing` against `obstacle`, every contact handed to `visit` with the stretch's index, then
/// the stretch laid down.
pub fn walk<'a, O: Obstacle>(
    tool: &ToolSolid,
    obstacle: &mut O,
    stretches: impl IntoIterator<Item = Stretch<'a>>,
    spacing: Spacing,
    mut visit: impl FnMut(usize, &Sample, O::Contact) -> Next,
) {
    for (index, stretch) in stretches.into_iter().enumerate() {
        let samples = spacing.samples(stretch.points, stretch.closed);
        if stretch.tested && obstacle.in_reach(tool, index, &stretch) {
            for s in &samples {
                match visit(index, s, obstacle.contact(tool, index, s)) {
                    Next::Sample => {}
                    Next::Stretch => break,
                    Next::Stop => return,
                }
            }
        }
        obstacle.lay(index, &stretch, &samples);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points laid down so far; a tip hits one that stands higher within 1 mm.
    #[derive(Default)]
    struct Pile {
        laid: Vec<Point3>,
    }

    impl Obstacle for Pile {
        type Contact = Option<Point3>;

        fn contact(&self, _tool: &ToolSolid, _index: usize, sample: &Sample) -> Option<Point3> {
            let p = sample.tip;
            self.laid
                .iter()
                .copied()
                .find(|q| q.z > p.z && (q.x - p.x).hypot(q.y - p.y) < 1.0)
        }

        fn lay(&mut self, _index: usize, _stretch: &Stretch<'_>, samples: &[Sample]) {
            self.laid.extend(samples.iter().map(|s| s.tip));
        }
    }

    #[test]
    fn spacings_give_both_ends_of_a_move_and_each_vertex_of_a_path_once() {
        let (a, b) = (Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 1.0));
        let steps = Spacing::Steps(0.5).samples(&[a, b], false);
        // 3D length √2: 3 steps, 4 positions.
        assert_eq!(steps.len(), 4);
        assert_eq!(steps[3].fraction, 1.0);
        let square = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
        ];
        let open = Spacing::Horizontal(0.5).samples(&square, false);
        assert_eq!(open.len(), 5);
        assert_eq!(open[4].tip, square[2]);
        // Closed: back to the first point along the diagonal (3 steps), not repeated.
        let closed = Spacing::Horizontal(0.5).samples(&square, true);
        assert_eq!(closed.len(), 7);
        assert_eq!(Spacing::Steps(0.5).samples(&square[..1], false).len(), 1);
    }

    /// The stretches of a walk over a high stretch and two low ones beside it whose
    /// positions met something, the walk going on with `on_hit` after each.
    fn stretches_hit(on_hit: Next) -> Vec<usize> {
        let tool = ToolSolid::fff_head(45.0, 5.0, 0.0, 10.0);
        let high = [Point3::new(0.0, 0.0, 2.0), Point3::new(1.0, 0.0, 2.0)];
        let low = [Point3::new(0.0, 0.5, 1.0), Point3::new(1.0, 0.5, 1.0)];
        let stretch = |points| Stretch {
            points,
            closed: false,
            tested: true,
        };
        let mut seen = Vec::new();
        walk(
            &tool,
            &mut Pile::default(),
            [stretch(&high), stretch(&low), stretch(&low)],
            Spacing::Steps(0.5),
            |i, _, hit| match hit {
                Some(_) => {
                    seen.push(i);
                    on_hit
                }
                None => Next::Sample,
            },
        );
        seen
    }

    #[test]
    fn the_walk_meets_what_earlier_stretches_laid_and_skips_or_stops_as_told() {
        // The first stretch meets nothing; each low one meets the high one, once.
        assert_eq!(stretches_hit(Next::Stretch), [1, 2]);
        assert_eq!(stretches_hit(Next::Stop), [1]);
    }
}
