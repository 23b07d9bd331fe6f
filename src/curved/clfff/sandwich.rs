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
//! The skins' flat paths are densified along the surface they follow and lifted by
//! [`super::lift`], each point asked for its [`Lift`] from the column over it: absent, or a
//! nozzle height, a thickness and a *state* (which layer is the lowest printed there, which
//! core layer is on top).

use super::layers::{LayerSpec, LiftedLayer, MAX_THICKNESS_FACTOR, lift_flat_paths};
pub use super::lift::Lift;
use super::shell::Shell;
use crate::geom::ExPolygon;
use crate::surface::densify_path;

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
    let densify = |xy: &[(f64, f64)], closed: bool| match spec.surface {
        Follows::Bottom => densify_path(xy, closed, step, &|a, b| shell.bottom_crossings(a, b)),
        Follows::Top => densify_path(xy, closed, step, &|a, b| shell.top_crossings(a, b)),
    };
    lift_flat_paths(outline, spec, &densify, &lift)
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
}
