//! The scaffold: planar layers of lines under the shell, stopped below its bottom surface.
//!
//! Place in the pipeline: step 3 of [`super::plan`], after the outline and before the buffer
//! and curved layers (whose lowest layer's thickness is measured down to the scaffold's top,
//! [`Scaffold::top_at`]).
//!
//! # Method
//!
//! Layer `j` (top at `first_layer_height + j·layer_height`) is a family of parallel lines along
//! `curved.scaffold_vectors[j mod n]`, `curved.scaffold_spacing` apart on a lattice anchored at
//! the origin, clipped to the scaffold area ([`crate::region::infill::lines::fill_family`]).
//! Each line carries reference points: one every `curved.step` and one wherever it crosses an
//! edge of the bottom surface's triangles, so the surface is one plane between two neighbours.
//! A reference point is allowed when the layer's top is at most the [`Limit`] there: the
//! bottom surface minus the buffer height minus `curved.scaffold_clearance` (outside the
//! outline, the surface height of the nearest rim point). A line is cut into the runs of
//! allowed points; where a run ends, the crossing with the limit is found by bisection between
//! the last allowed and the first refused point and becomes the run's end, so a line under the
//! surface is shortened, and one that passes under a low point is split in two. Runs shorter
//! than [`MIN_PIECE_WIDTHS`] line widths are dropped. The scaffold rises layer by layer until
//! a layer keeps no run; the lines of a layer are ordered by nearest neighbour (either end
//! first) from where the previous layer ended.

use super::densify::densify;
use super::lift::bisect;
use super::outline::Rim;
use super::shell::Shell;
use crate::geom::{ExPolygon, Point3};
use crate::region::infill::lines::{LineFamily, fill_family};

/// Shortest scaffold line kept, in line widths.
pub const MIN_PIECE_WIDTHS: f64 = 2.0;

/// Most scaffold layers (a guard against a limit that never stops the scaffold).
const MAX_LAYERS: usize = 100_000;

/// The highest a scaffold layer's top may be at a point (see the module docs).
#[derive(Debug, Clone, Copy)]
pub struct Limit<'a> {
    /// The shell.
    pub shell: &'a Shell,
    /// The outline's rim heights, for points outside the outline.
    pub rim: &'a Rim,
    /// How far below the bottom surface the limit is: buffer height + clearance, mm.
    pub below: f64,
}

impl Limit<'_> {
    /// The limit at (x, y), mm; `None` when the shell has no surface at all.
    pub fn at(&self, x: f64, y: f64) -> Option<f64> {
        self.shell
            .bottom(x, y)
            .or_else(|| self.rim.nearest_height(x, y))
            .map(|s| s - self.below)
    }
}

/// How the scaffold is built.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaffoldParams {
    /// Top of the first layer, mm.
    pub first_top: f64,
    /// Layer height above the first, mm.
    pub layer_height: f64,
    /// Line directions, one per layer, cycled.
    pub vectors: Vec<[f64; 2]>,
    /// Distance between lines, mm.
    pub spacing: f64,
    /// Reference point spacing, mm.
    pub step: f64,
    /// Line width, mm.
    pub width: f64,
}

/// One planar scaffold layer.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaffoldLayer {
    /// Top of the layer (where the nozzle is), mm.
    pub z: f64,
    /// Thickness, mm.
    pub height: f64,
    /// The lines in print order, each with its reference points.
    pub lines: Vec<Vec<Point3>>,
}

/// The whole scaffold.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scaffold {
    /// Layers, bottom to top.
    pub layers: Vec<ScaffoldLayer>,
    /// Places where a line was cut at the limit (shortened ends and splits).
    pub cuts: usize,
}

impl Scaffold {
    /// The top of the highest scaffold layer allowed at (x, y) by `limit`, mm: what the
    /// lowest curved layer stands on there; 0 (the bed) without scaffold.
    pub fn top_at(&self, limit: &Limit<'_>, x: f64, y: f64) -> f64 {
        let Some(l) = limit.at(x, y) else { return 0.0 };
        self.layers
            .iter()
            .rev()
            .find(|layer| layer.z <= l)
            .map_or(0.0, |layer| layer.z)
    }

    /// The top of the highest layer, mm (0 without scaffold).
    pub fn max_z(&self) -> f64 {
        self.layers.last().map_or(0.0, |l| l.z)
    }
}

/// Builds the scaffold over `area` (see the module docs); the first layer's lines are ordered
/// from `start` (xy, mm).
pub fn build(
    area: &[ExPolygon],
    limit: &Limit<'_>,
    p: &ScaffoldParams,
    start: (f64, f64),
) -> Scaffold {
    let mut out = Scaffold::default();
    if area.is_empty() || p.vectors.is_empty() {
        return out;
    }
    let mut at = start;
    for j in 0..MAX_LAYERS {
        let z = p.first_top + j as f64 * p.layer_height;
        let v = p.vectors[j % p.vectors.len()];
        let family = LineFamily {
            angle_rad: v[1].atan2(v[0]),
            spacing_mm: p.spacing,
            phase: 0.5,
        };
        let mut pieces = Vec::new();
        for line in fill_family(area, family, false) {
            let xy: Vec<(f64, f64)> = line.points.iter().map(|q| q.to_mm()).collect();
            let dense = densify(limit.shell, &xy, false, p.step);
            let (runs, cuts) = cut_at_limit(&dense, z, limit);
            out.cuts += cuts;
            pieces.extend(
                runs.into_iter()
                    .filter(|r| length(r) >= MIN_PIECE_WIDTHS * p.width),
            );
        }
        if pieces.is_empty() {
            break;
        }
        let ordered = nearest_neighbour(pieces, at);
        if let Some(end) = ordered.last().and_then(|l| l.last()) {
            at = *end;
        }
        out.layers.push(ScaffoldLayer {
            z,
            height: if j == 0 { p.first_top } else { p.layer_height },
            lines: ordered
                .into_iter()
                .map(|l| l.into_iter().map(|(x, y)| Point3::new(x, y, z)).collect())
                .collect(),
        });
    }
    out
}

fn length(line: &[(f64, f64)]) -> f64 {
    line.windows(2)
        .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
        .sum()
}

/// The runs of `pts` whose reference points allow a layer top at `z`, each ended at its
/// crossing with the limit; also how many crossings were cut.
fn cut_at_limit(pts: &[(f64, f64)], z: f64, limit: &Limit<'_>) -> (Vec<Vec<(f64, f64)>>, usize) {
    let allowed = |p: (f64, f64)| limit.at(p.0, p.1).is_some_and(|l| z <= l);
    let ok: Vec<bool> = pts.iter().map(|&p| allowed(p)).collect();
    let mut runs = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    let mut cuts = 0;
    for i in 0..pts.len() {
        if ok[i] {
            if cur.is_empty() && i > 0 {
                // Entering from a refused point: start at the crossing.
                cur.push(bisect(pts[i], pts[i - 1], &allowed).0);
                cuts += 1;
            }
            cur.push(pts[i]);
            if i + 1 < pts.len() && !ok[i + 1] {
                cur.push(bisect(pts[i], pts[i + 1], &allowed).0);
                cuts += 1;
                runs.push(std::mem::take(&mut cur));
            }
        }
    }
    if !cur.is_empty() {
        runs.push(cur);
    }
    for r in &mut runs {
        r.dedup();
    }
    runs.retain(|r| r.len() >= 2);
    (runs, cuts)
}

/// `pieces` chained greedily: from `from`, the piece with the nearest end comes next (reversed
/// when that end is its last point); ties go to the lower index.
pub fn nearest_neighbour(
    mut pieces: Vec<Vec<(f64, f64)>>,
    from: (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::with_capacity(pieces.len());
    let mut at = from;
    while !pieces.is_empty() {
        let d = |p: &(f64, f64)| (p.0 - at.0).powi(2) + (p.1 - at.1).powi(2);
        let mut best = (f64::MAX, 0, false);
        for (i, piece) in pieces.iter().enumerate() {
            let (Some(first), Some(last)) = (piece.first(), piece.last()) else {
                continue;
            };
            if d(first) < best.0 {
                best = (d(first), i, false);
            }
            if d(last) < best.0 {
                best = (d(last), i, true);
            }
        }
        let mut piece = pieces.remove(best.1);
        if best.2 {
            piece.reverse();
        }
        if let Some(&end) = piece.last() {
            at = end;
        }
        out.push(piece);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curved::clfff::outline::{outline, scaffold_area};
    use crate::mesh::Mesh;

    /// A closed slab over [0, 20] × [0, 10] whose bottom rises 0.1 per mm of x from z = 1.
    fn ramp() -> Mesh {
        let b = |x: f64, y: f64| Point3::new(x, y, 1.0 + 0.1 * x);
        let t = |x: f64, y: f64| Point3::new(x, y, 1.6 + 0.1 * x);
        Mesh::from_triangle_soup(
            "ramp",
            [
                [t(0.0, 0.0), t(20.0, 0.0), t(20.0, 10.0)],
                [t(0.0, 0.0), t(20.0, 10.0), t(0.0, 10.0)],
                [b(0.0, 0.0), b(20.0, 10.0), b(20.0, 0.0)],
                [b(0.0, 0.0), b(0.0, 10.0), b(20.0, 10.0)],
            ],
        )
    }

    #[test]
    fn lines_stop_at_the_limit_and_layers_stop_at_the_top() {
        let shell = Shell::from_meshes(&[ramp()]);
        let out = outline(&shell);
        let rim = Rim::new(&out, &shell);
        let limit = Limit {
            shell: &shell,
            rim: &rim,
            below: 0.2,
        };
        let area = scaffold_area(&out, 0.0);
        let p = ScaffoldParams {
            first_top: 0.2,
            layer_height: 0.2,
            vectors: vec![[1.0, 0.0], [0.0, 1.0]],
            spacing: 1.0,
            step: 0.5,
            width: 0.45,
        };
        let s = build(&area, &limit, &p, (0.0, 0.0));
        // The limit runs from 0.8 (x = 0) to 2.8 (x = 20): layers 0.2 … 2.8 minus the last
        // ones whose allowed strip is shorter than two widths.
        assert!(
            s.layers.len() >= 12 && s.layers.len() <= 14,
            "{}",
            s.layers.len()
        );
        assert!(s.cuts > 0);
        for layer in &s.layers {
            for line in &layer.lines {
                for q in line {
                    let l = 1.0 + 0.1 * q.x - 0.2;
                    assert!(q.z <= l + 1e-9, "{q:?} above {l}");
                }
            }
        }
        // Layer 8 (lines along x) at z = 1.8 reaches down to x = (1.8 + 0.2 − 1)/0.1 = 10.
        let layer = s.layers.get(8).filter(|l| (l.z - 1.8).abs() < 1e-9);
        let min_x = layer
            .into_iter()
            .flat_map(|l| l.lines.iter().flatten())
            .map(|q| q.x)
            .fold(f64::MAX, f64::min);
        assert!((min_x - 10.0).abs() < 1e-6, "{min_x}");
        assert!((s.top_at(&limit, 5.0, 5.0) - 1.2).abs() < 1e-9);
    }
}
