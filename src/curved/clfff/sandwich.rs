//! The sandwich (`curved.sandwich`): a curved bottom skin, a planar core, a curved top skin,
//! for thick doubly-curved parts (an insole, a thick car panel). This module says what lies in
//! the column over each point (x, y) and lifts the skins' flat paths onto their surfaces.
//!
//! Place in the pipeline: inside step 4 of [`super::plan`]; the bottom skin replaces the
//! model's curved layers, [`super::core`] prints the planar core after it, then the top skin.
//!
//! # The column over (x, y)
//!
//! With `B` the bottom surface, `T` the top surface, `D = T − B`, `h` the layer height, `n_b`
//! bottom and `n_t` top skin layers, and nozzle heights at the top of each bead:
//!
//! - **bottom skin** layer `k = 1 … n_b` at `B + k·h`, printed where `B + k·h ≤ T − h/2` (room
//!   is left for the top surface's layer); the lowest one stands on the scaffold (without a
//!   buffer its thickness is measured down to the scaffold's top, as for plain clfff);
//! - **core** layers: planar, on the grid `first_layer_height + i·h`, layer `z` where
//!   `z − h ≥ B + n_b·h` and `z ≤ T − n_t·h` (it lies wholly between the skins); the lowest
//!   core layer over a point is thicker by the gap down to the bottom skin, `z − (B + n_b·h)`
//!   (between h and 2h);
//! - **top skin** layer `j = 0 … n_t − 1` at `T − (n_t − 1 − j)·h`, the last on the top
//!   surface. Its lowest printed layer reaches down to what is under it (the core's top, else
//!   the bottom skin's top): between h and 2h over the core, between h/2 and 3h where the part
//!   is too thin for a core. A top-skin layer that would be thinner than h/2 there is left out
//!   at that point and the next one takes its place, so where the part is thinner than
//!   `(n_b + n_t)·h` the top skin sits directly on the bottom skin.
//!
//! Every bead's bottom is the top of the bead under it, so the column has neither gaps nor
//! overlaps; the extrusion of each point follows its thickness (capped at
//! [`MAX_THICKNESS_FACTOR`]` · h`, counted in the report).
//!
//! # Lifting
//!
//! A flat path is densified ([`super::densify`]) along the surface it follows and each point
//! asked for its [`Lift`]: absent, or a nozzle height, a thickness and a *state* (which layer
//! is the lowest printed there, which core layer is on top). Where presence or state changes
//! between two points, the boundary is found by bisection; a path is cut where it is absent,
//! and where the state changes the boundary point is repeated with each side's thickness, so
//! the extrusion changes exactly there.

use super::layers::{LayerSpec, LiftedLayer, MAX_THICKNESS_FACTOR, flat_paths};
use super::shell::Shell;
use crate::curved::surface::densify_path;
use crate::curved::tops::Projected;
use crate::geom::{ExPolygon, Point3};

/// Bisection steps for a boundary along a segment (the interval shrinks 2⁻⁴⁰ times).
const BISECTION_STEPS: usize = 40;

/// Most boundaries handled on one segment (a guard; a segment of `curved.step` crosses few).
const MAX_BOUNDARIES: usize = 16;

/// Rounding allowance of the grid and count tests, in layer heights.
const EPS: f64 = 1e-9;

/// Which surface a curved layer follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Follows {
    /// The bottom surface: nozzle at bottom + offset.
    Bottom,
    /// The top surface: nozzle at top + offset (offset ≤ 0).
    Top,
}

/// The layer counts and grid of a sandwich.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sandwich {
    /// Layer height, mm.
    pub h: f64,
    /// Bottom skin layers.
    pub bottom_layers: usize,
    /// Top skin layers.
    pub top_layers: usize,
    /// Top of planar layer 0 (`slice.first_layer_height`); core layer `i` has its top at
    /// `first_top + i·h`.
    pub first_top: f64,
    /// Whether a buffer layer lies under the bottom skin (then the bottom skin's lowest layer is
    /// `h` thick).
    pub buffer: bool,
}

/// What lies in the column over one point (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Column {
    /// Bottom surface, mm.
    pub bottom: f64,
    /// Top surface, mm.
    pub top: f64,
    /// Bottom skin layers printed here (`k = 1 … bottom_count`).
    pub bottom_count: usize,
    /// Core layers here: the grid indices of the lowest and highest.
    pub core: Option<(usize, usize)>,
    /// The first top skin layer printed here (`top_layers` when none is).
    pub top_first: usize,
    /// Top of what the top skin stands on (core top, bottom skin top, or the support), mm.
    pub under: f64,
    /// Top of what the lowest printed layer stands on: the buffer's top (the bottom surface)
    /// or the scaffold's.
    pub base: f64,
}

/// One lifted point: nozzle height, local thickness, state (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lift {
    /// Nozzle height, mm.
    pub z: f64,
    /// Local thickness, mm.
    pub thickness: f64,
    /// Where this changes between neighbouring points, the extrusion changes abruptly.
    pub state: i64,
}

impl Sandwich {
    /// Top of core layer `i`, mm.
    pub fn grid_z(&self, i: usize) -> f64 {
        self.first_top + i as f64 * self.h
    }

    /// The column over (x, y); `None` outside the outline. `support(x, y)` is the scaffold's
    /// top (used when there is no buffer).
    pub fn column(
        &self,
        shell: &Shell,
        support: &dyn Fn(f64, f64) -> f64,
        x: f64,
        y: f64,
    ) -> Option<Column> {
        let (b, t) = (shell.bottom(x, y)?, shell.top(x, y)?);
        let h = self.h;
        let base = if self.buffer { b } else { support(x, y) };
        let fits = ((t - b - h / 2.0) / h + EPS).floor().max(0.0) as usize;
        let bottom_count = fits.min(self.bottom_layers);
        let core = (bottom_count == self.bottom_layers)
            .then(|| {
                let lo = b + (self.bottom_layers + 1) as f64 * h;
                let hi = t - self.top_layers as f64 * h;
                let i_lo = ((lo - self.first_top) / h - EPS).ceil().max(1.0) as usize;
                let i_hi = ((hi - self.first_top) / h + EPS).floor();
                (i_hi >= i_lo as f64).then_some((i_lo, i_hi as usize))
            })
            .flatten();
        let under = match core {
            Some((_, hi)) => self.grid_z(hi),
            None if bottom_count > 0 => b + bottom_count as f64 * h,
            None => base,
        };
        // The first j with T − (n_t − 1 − j)·h − under ≥ h/2.
        let n_t = self.top_layers as f64;
        let first = ((under + h / 2.0 - t) / h + n_t - 1.0 - EPS)
            .ceil()
            .max(0.0);
        let top_first = if first >= n_t {
            self.top_layers
        } else {
            first as usize
        };
        Some(Column {
            bottom: b,
            top: t,
            bottom_count,
            core,
            top_first,
            under,
            base,
        })
    }

    /// Bottom skin layer `k` (1-based) at a column; `None` where it is not printed.
    pub fn bottom_lift(&self, c: &Column, k: usize) -> Option<Lift> {
        if k == 0 || k > c.bottom_count {
            return None;
        }
        let z = c.bottom + k as f64 * self.h;
        let lowest = k == 1 && !self.buffer;
        let thickness = if lowest {
            (z - c.base).max(self.h)
        } else {
            self.h
        };
        Some(Lift {
            z,
            thickness,
            state: 0,
        })
    }

    /// Top skin layer `j` (0-based) at a column; `None` where it is not printed.
    pub fn top_lift(&self, c: &Column, j: usize) -> Option<Lift> {
        if j < c.top_first || j >= self.top_layers {
            return None;
        }
        let z = c.top - (self.top_layers - 1 - j) as f64 * self.h;
        let thickness = if j == c.top_first {
            z - c.under
        } else {
            self.h
        };
        // The thickness of the lowest top layer jumps where the core's top or the layer that
        // is lowest changes.
        let state = if j == c.top_first {
            let core = c.core.map_or(-1, |(_, hi)| hi as i64);
            1 + (core + 1) * 1024 + c.bottom_count as i64 * 64 + c.top_first as i64
        } else {
            0
        };
        Some(Lift {
            z,
            thickness,
            state,
        })
    }

    /// Core layer `i` at a column, its top at `z`: its thickness and state; the layer is
    /// printed where the regions stage puts it, so a point outside the column's core range
    /// (the edge of a bead) keeps the nominal height.
    pub fn core_lift(&self, c: Option<&Column>, i: usize, z: f64) -> Lift {
        match c.and_then(|c| c.core.map(|(lo, _)| (c, lo))) {
            Some((c, lo)) if lo == i => Lift {
                z,
                thickness: (z - (c.bottom + self.bottom_layers as f64 * self.h)).max(self.h),
                state: 1,
            },
            _ => Lift {
                z,
                thickness: self.h,
                state: 0,
            },
        }
    }
}

/// The point between `good` and `bad` nearest to where `same` stops holding, on `good`'s side,
/// and the point just past it.
fn bisect(
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

/// A skin layer of the sandwich lifted onto its surface: `spec.surface` says which, `spec.k`
/// is `k` (bottom, 1-based) or `j` (top, 0-based).
pub fn lift_skin_layer(
    shell: &Shell,
    outline: &[ExPolygon],
    spec: LayerSpec,
    step: f64,
    sandwich: &Sandwich,
    support: &dyn Fn(f64, f64) -> f64,
) -> LiftedLayer {
    let mut layer = LiftedLayer {
        spec,
        pieces: Vec::new(),
        dropped: 0,
        capped: 0,
    };
    let max_t = MAX_THICKNESS_FACTOR * spec.height;
    let lift = |x: f64, y: f64| -> Option<Lift> {
        let c = sandwich.column(shell, support, x, y)?;
        let l = match spec.surface {
            Follows::Bottom => sandwich.bottom_lift(&c, spec.k),
            Follows::Top => sandwich.top_lift(&c, spec.k),
        }?;
        Some(Lift {
            thickness: l.thickness.min(max_t),
            ..l
        })
    };
    for (xy, closed, role, width) in flat_paths(outline, &spec) {
        let dense = match spec.surface {
            Follows::Bottom => {
                densify_path(&xy, closed, step, &|a, b| shell.bottom_crossings(a, b))
            }
            Follows::Top => densify_path(&xy, closed, step, &|a, b| shell.top_crossings(a, b)),
        };
        let (pieces, dropped) = lift_path(&dense, closed, &lift);
        layer.dropped += dropped;
        // Points at the cap (a thickness exactly three layers counts too: rare, and harmless).
        layer.capped += pieces
            .iter()
            .flat_map(|p| &p.thickness)
            .filter(|&&t| t >= max_t - 1e-12)
            .count();
        layer
            .pieces
            .extend(pieces.into_iter().map(|p| (p, role, width)));
    }
    layer
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    /// A closed wedge over [0, 10]²: bottom z = 1 + 0.05·x, top z = 1.1 + 0.25·x (0.1 mm thick
    /// at x = 0, 2.1 mm at x = 10).
    fn wedge() -> Mesh {
        super::super::test_meshes::ramp_sheet("wedge", 10.0, 10.0, [1.0, 0.05], [1.1, 0.25])
    }

    #[test]
    fn every_column_of_a_wedge_is_stacked_without_gaps_or_overlaps() {
        let shell = Shell::from_meshes(&[wedge()]);
        let s = Sandwich {
            h: 0.2,
            bottom_layers: 2,
            top_layers: 3,
            first_top: 0.2,
            buffer: true,
        };
        let support = |_: f64, _: f64| 0.0;
        let mut with_core = 0;
        let mut thin = 0;
        for i in 0..=200 {
            let x = i as f64 * 0.05;
            let c = s
                .column(&shell, &support, x, 5.0)
                .expect("inside the wedge");
            // Beads bottom to top as (nozzle, thickness).
            let mut beads: Vec<(f64, f64)> = Vec::new();
            for k in 1..=s.bottom_layers {
                if let Some(l) = s.bottom_lift(&c, k) {
                    beads.push((l.z, l.thickness));
                }
            }
            if let Some((lo, hi)) = c.core {
                with_core += 1;
                for g in lo..=hi {
                    let l = s.core_lift(Some(&c), g, s.grid_z(g));
                    beads.push((l.z, l.thickness));
                }
            }
            for j in 0..s.top_layers {
                if let Some(l) = s.top_lift(&c, j) {
                    beads.push((l.z, l.thickness));
                }
            }
            let (b, t) = (1.0 + 0.05 * x, 1.1 + 0.25 * x);
            if t - b < (s.bottom_layers + s.top_layers) as f64 * 0.2 {
                thin += 1;
            }
            if t - b < 0.1 {
                continue;
            }
            // The last bead is the top surface; each bead starts where the one under it ends;
            // the first starts on the buffer (the bottom surface).
            let last = beads.last().expect("a bead");
            assert!((last.0 - t).abs() < 1e-9, "x {x}: {beads:?}");
            let mut floor = b;
            for &(z, th) in &beads {
                assert!((z - th - floor).abs() < 1e-9, "x {x}: {beads:?}");
                assert!((0.1 - 1e-9..0.6 + 1e-9).contains(&th), "x {x}: {beads:?}");
                floor = z;
            }
        }
        assert!(with_core > 50 && thin > 50, "{with_core} {thin}");
    }

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
