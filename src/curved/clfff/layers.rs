//! The curved layers (the buffer and the model's layers): flat outline loops and raster lines
//! lifted onto the bottom surface, offset along z.
//!
//! Place in the pipeline: step 4–5 of [`super::plan`], after the scaffold (whose top the
//! lowest curved layer stands on) and before the travel planning.
//!
//! # Method
//!
//! Curved layer `k` has its nozzle at `S(x, y) + k·h`, `S` being the shell's bottom surface and
//! `h` the layer height: the buffer is `k = 0` (its bead fills `[S − h, S]`), the model's layers
//! are `k = 1 … n` (layer 1's bead lies on `S`). Offsetting along z keeps the outline the same
//! on every layer, and the vertical thickness of each layer is exactly `h`.
//!
//! Each layer is, in print order: an outline loop (every ring of the outline, holes included,
//! inset by half the loop's width), then raster lines at the layer's angle `spacing` apart
//! (the bead spacing of [`crate::region::spacing`]: neighbouring beads of that width touch)
//! inside the loop, clipped and ordered by
//! [`fill_family`](crate::region::infill::lines::fill_family) and joined into zig-zags along
//! the loop. Every path is densified ([`super::densify`]) and each point lifted to
//! `S(x, y) + k·h` ([`super::lift`]); where the surface is missing the path is cut at its edge.
//!
//! The local thickness of the lowest curved layer is the distance from its nozzle down to the
//! top of the scaffold there ([`crate::curved::clfff::scaffold::Scaffold::top_at`]), so its
//! extrusion fills the steps of the scaffold; it is capped at [`MAX_THICKNESS_FACTOR`]` · h`
//! (the cap is counted in the report). Every other curved layer is `h` thick.

use super::densify::densify;
use super::lift::{Lift, lift_path};
use super::sections::Section;
use super::shell::Shell;
use crate::curved::tops::Projected;
use crate::geom::{ExPolygon, Join, offset};
use crate::program::Role;
use crate::region::infill::lines::{LineFamily, fill_family};

/// Largest local thickness of the lowest curved layer, in layer heights.
pub const MAX_THICKNESS_FACTOR: f64 = 3.0;

/// Miter limit of the loop's inset corners.
const LOOP_MITER: f64 = 3.0;

/// What one curved layer is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerSpec {
    /// Buffer or model.
    pub section: Section,
    /// 0 for the buffer, 1 … n for the model's layers.
    pub k: usize,
    /// Height of the nozzle above the bottom surface, mm (`k·h`).
    pub offset: f64,
    /// Raster angle, degrees from +X.
    pub angle_deg: f64,
    /// Nominal thickness, mm.
    pub height: f64,
    /// Role of the outline loop.
    pub loop_role: Role,
    /// Role of the raster lines.
    pub fill_role: Role,
    /// Width of the outline loop, mm.
    pub loop_width: f64,
    /// Width of the raster lines, mm.
    pub fill_width: f64,
    /// Whether this is the lowest curved layer (standing on the scaffold).
    pub lowest: bool,
    /// The surface it follows: the bottom (buffer, model layers, the sandwich's bottom skin;
    /// `offset` above it) or the top (the sandwich's top skin, `offset` ≤ 0 below it, `k` the
    /// top-skin layer from 0).
    pub surface: super::sandwich::Follows,
}

/// One curved layer lifted onto the surface.
#[derive(Debug, Clone, PartialEq)]
pub struct LiftedLayer {
    /// What it is.
    pub spec: LayerSpec,
    /// Its pieces in print order, each with its role and width.
    pub pieces: Vec<(Projected, Role, f64)>,
    /// Points dropped where the surface is missing.
    pub dropped: usize,
    /// Points whose local thickness was capped at [`MAX_THICKNESS_FACTOR`]` · h`.
    pub capped: usize,
}

/// A flat path of a layer: xy points (mm), closed, role, width.
pub type FlatPath = (Vec<(f64, f64)>, bool, Role, f64);

/// The flat paths of a layer over `outline`, in print order.
pub fn flat_paths(outline: &[ExPolygon], spec: &LayerSpec) -> Vec<FlatPath> {
    let mut out = Vec::new();
    let loops = offset(outline, -spec.loop_width / 2.0, Join::Miter(LOOP_MITER));
    for ex in &loops {
        for ring in std::iter::once(&ex.contour).chain(&ex.holes) {
            let pts: Vec<(f64, f64)> = ring.points.iter().map(|p| p.to_mm()).collect();
            if pts.len() >= 3 {
                out.push((pts, true, spec.loop_role, spec.loop_width));
            }
        }
    }
    let spacing = crate::region::spacing(spec.fill_width, spec.height);
    let area = offset(
        outline,
        -(spec.loop_width / 2.0 + spacing),
        Join::Miter(LOOP_MITER),
    );
    let family = LineFamily {
        angle_rad: spec.angle_deg.to_radians(),
        spacing_mm: spacing,
        phase: 0.5,
    };
    for line in fill_family(&area, family, true) {
        let pts: Vec<(f64, f64)> = line.points.iter().map(|p| p.to_mm()).collect();
        if pts.len() >= 2 {
            out.push((pts, false, spec.fill_role, spec.fill_width));
        }
    }
    out
}

/// The layer `spec` over `outline` lifted onto `shell` (see the module docs); `support(x, y)`
/// is the top of what the lowest layer stands on, mm.
pub fn lift_layer(
    shell: &Shell,
    outline: &[ExPolygon],
    spec: LayerSpec,
    step: f64,
    support: &dyn Fn(f64, f64) -> f64,
) -> LiftedLayer {
    let max_t = MAX_THICKNESS_FACTOR * spec.height;
    let lift = |x: f64, y: f64| -> Option<Lift> {
        let z = shell.bottom(x, y)? + spec.offset;
        let thickness = if spec.lowest {
            (z - support(x, y)).max(spec.height).min(max_t)
        } else {
            spec.height
        };
        Some(Lift {
            z,
            thickness,
            state: 0,
        })
    };
    let dense = |xy: &[(f64, f64)], closed: bool| densify(shell, xy, closed, step);
    lift_flat_paths(outline, spec, &dense, &lift)
}

/// A path's densification: the flat path (xy, mm) and whether it is closed → its points.
pub type Densify<'a> = dyn Fn(&[(f64, f64)], bool) -> Vec<(f64, f64)> + 'a;

/// The flat paths of `spec` over `outline` ([`flat_paths`]), each densified by `densify` and
/// lifted by `lift` ([`lift_path`]), with the points where the surface is missing and those
/// at the thickness cap ([`MAX_THICKNESS_FACTOR`]` · h`) counted.
pub fn lift_flat_paths(
    outline: &[ExPolygon],
    spec: LayerSpec,
    densify: &Densify<'_>,
    lift: &dyn Fn(f64, f64) -> Option<Lift>,
) -> LiftedLayer {
    let mut layer = LiftedLayer {
        spec,
        pieces: Vec::new(),
        dropped: 0,
        capped: 0,
    };
    let max_t = MAX_THICKNESS_FACTOR * spec.height;
    for (xy, closed, role, width) in flat_paths(outline, &spec) {
        let (pieces, dropped) = lift_path(&densify(&xy, closed), closed, lift);
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
    use crate::curved::clfff::outline::outline;
    use crate::curved::tops::Projected;
    use crate::geom::Point3;
    use crate::mesh::Mesh;

    #[test]
    fn a_tilted_square_layer_sits_k_heights_above_the_surface() {
        let p = |x: f64, y: f64| Point3::new(x, y, 1.0 + 0.2 * x - 0.1 * y);
        let sheet = Mesh::from_triangle_soup(
            "sheet",
            [
                [p(0.0, 0.0), p(10.0, 0.0), p(10.0, 10.0)],
                [p(0.0, 0.0), p(10.0, 10.0), p(0.0, 10.0)],
            ],
        );
        let shell = Shell::from_meshes(&[sheet]);
        let out = outline(&shell);
        let spec = LayerSpec {
            section: Section::Model,
            k: 2,
            offset: 0.4,
            angle_deg: 45.0,
            height: 0.2,
            loop_role: Role::ExternalPerimeter,
            fill_role: Role::SolidInfill,
            loop_width: 0.45,
            fill_width: 0.45,
            lowest: true,
            surface: crate::curved::clfff::sandwich::Follows::Bottom,
        };
        let layer = lift_layer(&shell, &out, spec, 0.5, &|_, _| -5.0);
        assert_eq!(layer.dropped, 0);
        let (first, role, _) = &layer.pieces[0];
        assert!(first.closed && *role == Role::ExternalPerimeter);
        let mut n = 0;
        for (piece, ..) in &layer.pieces {
            for (q, t) in piece.points.iter().zip(&piece.thickness) {
                assert!((q.z - (1.4 + 0.2 * q.x - 0.1 * q.y)).abs() < 1e-9);
                // Far above its support: capped at three layers.
                assert!((t - 0.6).abs() < 1e-12);
                n += 1;
            }
        }
        assert_eq!(layer.capped, n);
        // The raster covers the inside: about area / spacing of line.
        let length: f64 = layer
            .pieces
            .iter()
            .filter(|(_, r, _)| *r == Role::SolidInfill)
            .flat_map(|(p, ..)| p.points.windows(2).map(|w| (w[1] - w[0]).xy().norm()))
            .sum();
        let inner = 10.0 - 2.0 * (0.225 + crate::region::spacing(0.45, 0.2));
        let want = inner * inner / crate::region::spacing(0.45, 0.2);
        assert!((length - want).abs() < 0.1 * want, "{length} vs {want}");
    }

    #[test]
    fn paths_end_on_the_surfaces_edge_and_a_cut_loop_stays_one_piece() {
        // A flat sheet at z = 1 over [0, 10]² of unit squares, without a notch [8, 10]² and a
        // hole [4, 6]², under the whole square's outline: the loop runs through the notch and
        // the raster lines through the hole.
        let p = |x: usize, y: usize| Point3::new(x as f64, y as f64, 1.0);
        let mut tris = Vec::new();
        for j in 0..10 {
            for i in 0..10 {
                if (i >= 8 && j >= 8) || ((4..6).contains(&i) && (4..6).contains(&j)) {
                    continue;
                }
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        let shell = Shell::from_meshes(&[Mesh::from_triangle_soup("sheet", tris)]);
        let corner = |x: f64, y: f64| crate::geom::Point2::from_mm(x, y);
        let square = ExPolygon {
            contour: crate::geom::Polygon::new(vec![
                corner(0.0, 0.0),
                corner(10.0, 0.0),
                corner(10.0, 10.0),
                corner(0.0, 10.0),
            ]),
            holes: Vec::new(),
        };
        let spec = LayerSpec {
            section: Section::Model,
            k: 1,
            offset: 0.2,
            angle_deg: 0.0,
            height: 0.2,
            loop_role: Role::ExternalPerimeter,
            fill_role: Role::SolidInfill,
            loop_width: 0.45,
            fill_width: 0.45,
            lowest: false,
            surface: crate::curved::clfff::sandwich::Follows::Bottom,
        };
        let layer = lift_layer(&shell, &[square], spec, 0.5, &|_, _| 0.0);
        assert!(layer.dropped > 0);
        let loops: Vec<&Projected> = layer
            .pieces
            .iter()
            .filter(|(_, r, _)| *r == Role::ExternalPerimeter)
            .map(|(p, ..)| p)
            .collect();
        // The loop, cut by the notch, is one open piece from one side of it to the other.
        assert_eq!(loops.len(), 1);
        let (a, b) = (
            loops[0].points[0],
            loops[0].points[loops[0].points.len() - 1],
        );
        assert!(!loops[0].closed);
        for q in [a, b] {
            let on_edge = (q.x - 8.0).abs() < 1e-9 || (q.y - 8.0).abs() < 1e-9;
            assert!(on_edge && q.x <= 10.0 && q.y <= 10.0, "{q}");
        }
        // Raster lines crossing the hole stop on its edges, x = 4 and x = 6.
        let mut at_hole = 0;
        for (piece, role, _) in &layer.pieces {
            if *role != Role::SolidInfill {
                continue;
            }
            for w in piece.points.windows(2) {
                let (lo, hi) = (w[0].x.min(w[1].x), w[0].x.max(w[1].x));
                let y = w[0].y;
                assert!(
                    !(lo < 5.0 && hi > 5.0 && y > 4.0 && y < 6.0),
                    "a line crosses the hole at y = {y}"
                );
            }
            for q in [piece.points[0], piece.points[piece.points.len() - 1]] {
                if q.y > 4.0 && q.y < 6.0 && ((q.x - 4.0).abs() < 1e-9 || (q.x - 6.0).abs() < 1e-9)
                {
                    at_hole += 1;
                }
            }
        }
        assert!(at_hole >= 4, "{at_hole}");
    }
}
