//! The sandwich's planar core: the layers between the bottom and the top skin, printed by the
//! planar regions and Program stages.
//!
//! Place in the pipeline: inside step 4–5 of [`super::plan`], after the bottom skin (whose top
//! the core stands on) and before the top skin (which reaches down to the core's top).
//!
//! # Method
//!
//! Core layer `i` has its top at `z = first_layer_height + i·h` (the planar grid) and is
//! printed over the points where it lies wholly between the skins ([`super::sandwich`]):
//! `B + n_b·h ≤ z − h` and `T − n_t·h ≥ z`. Both surfaces are planes over each mesh triangle,
//! so each condition is a half-plane within each triangle: the triangles are clipped to it
//! and united (the region where the lowest (highest) triangle meets it is the union of where
//! any does). The first region only grows with `z` and the second only shrinks, so each
//! layer's region is the neighbouring layer's plus the triangles the condition crosses now.
//! The core's islands are the intersection of the two.
//!
//! The islands go through [`crate::region::make_regions_with_heights`] and
//! [`crate::toolpaths::build_program`] as a planar object would, with `[slice]` perimeters and
//! infill, but no top or bottom solid layers of their own (the skins are the part's solid
//! faces) and no skirt; an empty layer under the core keeps the first-layer widths and speed
//! off it. The lowest core layer over each point reaches down to the bottom skin's top: its
//! paths are densified ([`super::densify`]) and their extrusion follows that thickness
//! ([`super::sandwich::Sandwich::core_lift`], [`crate::curved::motion`]).

use super::densify::densify;
use super::lift::lift_path;
use super::outline::ccw_region;
use super::sandwich::{Column, Sandwich};
use super::shell::Shell;
use crate::curved::CurvedParams;
use crate::curved::motion;
use crate::geom::{ExPolygon, Point2, Point3, intersection, union};
use crate::program::Toolpath;
use crate::region::{RegionError, make_regions_with_heights};
use crate::slice::LayerZ;
use crate::surface::SurfaceTriangle;
use crate::toolpaths::{ObjectLayers, ProgramParams, build_program};

/// One planar core layer as toolpaths in print order.
#[derive(Debug, Clone, PartialEq)]
pub struct CoreLayer {
    /// Grid index.
    pub index: usize,
    /// Top of the layer (nozzle height), mm.
    pub z: f64,
    /// Area of its islands, mm².
    pub area_mm2: f64,
    /// Toolpaths, lowest-layer thickness applied.
    pub paths: Vec<Toolpath>,
    /// Paths whose extrusion was raised where they lie over the bottom skin's top.
    pub thickened: usize,
}

/// The part of the triangle (xy of `corners`) where the linear function with values `v` at
/// the corners is ≥ 0, as a counter-clockwise polygon; `None` when empty or degenerate.
fn clip(corners: &[Point3; 3], v: [f64; 3]) -> Option<ExPolygon> {
    let mut pts: Vec<(f64, f64)> = Vec::with_capacity(4);
    for k in 0..3 {
        let (a, b) = (corners[k], corners[(k + 1) % 3]);
        let (va, vb) = (v[k], v[(k + 1) % 3]);
        if va >= 0.0 {
            pts.push((a.x, a.y));
        }
        if (va >= 0.0) != (vb >= 0.0) {
            let t = va / (va - vb);
            pts.push((a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t));
        }
    }
    ccw_region(pts.iter().map(|&(x, y)| Point2::from_mm(x, y)).collect())
}

/// The z range of a triangle's corners.
fn z_range(t: &SurfaceTriangle) -> (f64, f64) {
    let zs = t.corners.map(|p| p.z);
    (
        zs.iter().copied().fold(f64::MAX, f64::min),
        zs.iter().copied().fold(f64::MIN, f64::max),
    )
}

/// For each level `c` of `levels` (ascending), the region where a surface given by `tris`
/// (their z taken as `sign · z`) satisfies `sign·z ≤ c`, built incrementally (see the module
/// docs).
fn below_levels(tris: &[SurfaceTriangle], sign: f64, levels: &[f64]) -> Vec<Vec<ExPolygon>> {
    let tris: Vec<([Point3; 3], f64, f64)> = tris
        .iter()
        .map(|t| {
            let corners = t.corners.map(|p| Point3::new(p.x, p.y, sign * p.z));
            let (lo, hi) = z_range(&SurfaceTriangle {
                corners,
                normal: t.normal,
            });
            (corners, lo, hi)
        })
        .collect();
    let mut out: Vec<Vec<ExPolygon>> = Vec::with_capacity(levels.len());
    let mut prev: Option<f64> = None;
    for &c in levels {
        let mut pieces: Vec<ExPolygon> = out.last().cloned().unwrap_or_default();
        for (corners, lo, hi) in &tris {
            // Whole at the previous level: already in.
            if *lo > c || prev.is_some_and(|p| *hi <= p) {
                continue;
            }
            if let Some(piece) = clip(corners, corners.map(|q| c - q.z)) {
                pieces.push(piece);
            }
        }
        out.push(union(&pieces));
        prev = Some(c);
    }
    out
}

/// The core's islands per grid index, bottom to top (see the module docs); empty when the part
/// is too thin anywhere for a core.
pub fn islands(shell: &Shell, s: &Sandwich) -> Vec<(usize, Vec<ExPolygon>)> {
    let bottom = shell.bottom_triangles();
    let top = shell.top_triangles();
    let (Some((b_lo, _)), Some(t_hi)) = (
        shell.bottom_range(),
        top.iter().map(|t| z_range(t).1).reduce(f64::max),
    ) else {
        return Vec::new();
    };
    let (nb, nt) = (s.bottom_layers as f64, s.top_layers as f64);
    let i_lo = ((b_lo + (nb + 1.0) * s.h - s.first_top) / s.h - 1e-9)
        .ceil()
        .max(1.0) as usize;
    let i_hi = ((t_hi - nt * s.h - s.first_top) / s.h + 1e-9).floor();
    if i_hi < i_lo as f64 {
        return Vec::new();
    }
    let range: Vec<usize> = (i_lo..=i_hi as usize).collect();
    // Bottom: B ≤ z − h − n_b·h (the mirrored triangles hold −B).
    let over: Vec<f64> = range
        .iter()
        .map(|&i| s.grid_z(i) - (nb + 1.0) * s.h)
        .collect();
    let a = below_levels(&bottom, -1.0, &over);
    // Top: T ≥ z + n_t·h, i.e. −T ≤ −(z + n_t·h), levels ascending from the highest layer.
    let under: Vec<f64> = range
        .iter()
        .rev()
        .map(|&i| -(s.grid_z(i) + nt * s.h))
        .collect();
    let mut b = below_levels(&top, -1.0, &under);
    b.reverse();
    range
        .into_iter()
        .zip(a.iter().zip(&b))
        .filter_map(|(i, (a, b))| {
            if a.is_empty() || b.is_empty() {
                return None;
            }
            let core = intersection(a, b);
            (!core.is_empty()).then_some((i, core))
        })
        .collect()
}

/// The planar core layers of the sandwich `s` on `tool`, toolpaths in print order starting
/// from `start` (see the module docs); `support` is the scaffold's top.
pub fn layers(
    shell: &Shell,
    s: &Sandwich,
    cfg: &CurvedParams,
    tool: usize,
    start: Point3,
    support: &dyn Fn(f64, f64) -> f64,
) -> Result<Vec<CoreLayer>, RegionError> {
    let isl = islands(shell, s);
    let Some(&(first, _)) = isl.first() else {
        return Ok(Vec::new());
    };
    let mut region = cfg.region.clone();
    region.top_solid_layers = 0;
    region.bottom_solid_layers = 0;
    region.skirt_loops = 0;
    region.layer_height = s.h;
    // An empty layer first, then every grid layer from the first core layer up (a layer the
    // core skips stays empty).
    let last = isl.last().map_or(first, |l| l.0);
    let mut stack: Vec<Vec<ExPolygon>> = vec![Vec::new(); last - first + 2];
    for (i, ex) in &isl {
        stack[i - first + 1] = ex.clone();
    }
    let heights = vec![s.h; stack.len()];
    let regions = make_regions_with_heights(&stack, &heights, &region)?;
    let zs: Vec<LayerZ> = (0..stack.len())
        .map(|k| {
            let top = s.grid_z(first + k - 1);
            LayerZ {
                index: k,
                bottom: top - s.h,
                top,
                slice_z: top - s.h / 2.0,
            }
        })
        .collect();
    let object = ObjectLayers {
        tool,
        layers: zs.into_iter().zip(regions).collect(),
    };
    let params = ProgramParams {
        start,
        ..cfg.program.clone()
    };
    let program = build_program(std::slice::from_ref(&object), &params);
    let area = |i: usize| -> f64 {
        isl.iter()
            .find(|(j, _)| *j == i)
            .map_or(0.0, |(_, ex)| ex.iter().map(ExPolygon::area_mm2).sum())
    };
    let mut out = Vec::new();
    for layer in program.layers.iter().skip(1) {
        let index = ((layer.z - s.first_top) / s.h).round().max(0.0) as usize;
        let mut paths = Vec::new();
        let mut thickened = 0;
        for p in layer.paths() {
            let (ps, thick) = thicken(p, shell, s, support, index, cfg);
            thickened += usize::from(thick);
            paths.extend(ps);
        }
        if paths.is_empty() {
            continue;
        }
        out.push(CoreLayer {
            index,
            z: layer.z,
            area_mm2: area(index),
            paths,
            thickened,
        });
    }
    Ok(out)
}

/// `path` (of core layer `index`) with its extrusion raised where it is the lowest core layer
/// over the bottom skin; also whether it was.
fn thicken(
    path: &Toolpath,
    shell: &Shell,
    s: &Sandwich,
    support: &dyn Fn(f64, f64) -> f64,
    index: usize,
    cfg: &CurvedParams,
) -> (Vec<Toolpath>, bool) {
    let Some(z) = path.points.first().map(|p| p.z) else {
        return (Vec::new(), false);
    };
    let xy: Vec<(f64, f64)> = path.points.iter().map(|p| (p.x, p.y)).collect();
    let dense = densify(shell, &xy, path.closed, cfg.curved.step);
    let column = |x: f64, y: f64| -> Option<Column> { s.column(shell, support, x, y) };
    let lift = |x: f64, y: f64| Some(s.core_lift(column(x, y).as_ref(), index, z));
    if !dense
        .iter()
        .any(|&(x, y)| lift(x, y).is_some_and(|l| l.state != 0))
    {
        return (vec![path.clone()], false);
    }
    let (pieces, _) = lift_path(&dense, path.closed, &lift);
    let mut out = Vec::new();
    for piece in &pieces {
        let (paths, _) = motion::to_toolpaths(piece, path, cfg.curved.max_z_speed);
        out.extend(paths.into_iter().filter(|p| p.length() > 0.0));
    }
    (out, true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    /// A closed slab over [0, 20] × [0, 10]: bottom z = 1 + 0.1·x, top z = 4 + 0.05·x.
    fn slab() -> Mesh {
        super::super::test_meshes::ramp_sheet("slab", 20.0, 10.0, [1.0, 0.1], [4.0, 0.05])
    }

    #[test]
    fn core_islands_are_the_strips_between_the_skins() {
        let shell = Shell::from_meshes(&[slab()]);
        let s = Sandwich {
            h: 0.2,
            bottom_layers: 2,
            top_layers: 3,
            first_top: 0.2,
            buffer: true,
        };
        let isl = islands(&shell, &s);
        assert!(!isl.is_empty());
        for (i, ex) in &isl {
            let z = s.grid_z(*i);
            // 1 + 0.1·x + 0.4 ≤ z − 0.2 → x ≤ 10·(z − 1.6); 4 + 0.05·x − 0.6 ≥ z →
            // x ≥ 20·(z − 3.4); clipped to [0, 20].
            let x1 = (10.0 * (z - 1.6)).min(20.0);
            let x0 = (20.0 * (z - 3.4)).max(0.0);
            let want = (x1 - x0).max(0.0) * 10.0;
            let got: f64 = ex.iter().map(ExPolygon::area_mm2).sum();
            assert!((got - want).abs() < 1e-3, "z {z}: {got} vs {want}");
        }
        // The first layer: z − 0.2 ≥ 1.4 somewhere (x = 0): z = 1.8 (grid 0.2 + 8·0.2).
        assert_eq!(isl[0].0, 8);
        // The last: z ≤ 5 − 0.6 over x > 16, i.e. 4.2 (4.4 only touches x = 20).
        assert!((s.grid_z(isl[isl.len() - 1].0) - 4.2).abs() < 1e-9);
    }
}
