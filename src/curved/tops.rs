//! Top regions and their projection: which gently sloped top surfaces get curved top layers,
//! what the planar layers under them give up, and flat paths moved onto the surface.
//!
//! Place in the pipeline: after slicing, before the regions stage. [`find_top_regions`] splits
//! the visible upward-facing triangles of the [`HeightField`] into regions no steeper than
//! `curved.max_angle` (connected components of their xy projection) and reports the steeper
//! ones; [`removal`] is what each planar layer loses under a region; [`Projector`] moves a flat
//! 2D path onto the surface at a depth below it.
//!
//! # What is curved
//!
//! A region's area `A` is the xy projection of its triangles. Its `n` curved layers
//! (`n = slice.top_solid_layers`) are complete layers over `A` — perimeter loops around `A`
//! and solid infill inside them (top solid infill for the topmost), made by the regions
//! stage's own perimeter and rectilinear generators — projected so layer `k` (0 = topmost)
//! lies at `surface(x, y) − k·h`. The planar layers give up what those layers replace: planar
//! layer `j` loses `A ∩ island(j) \ island(j + n)` (the part of `A` within `n` layers of the
//! top), so the planar core under `A` ends `n` layers under the top at every xy and its top is
//! printed as a planar top under the curved layers. The planar perimeters inside `A` go with
//! the area; where `A` ends at an outer wall the curved perimeters continue the wall.
//!
//! Layer `k` at xy stands `h` above layer `k + 1`; the lowest (`k = n − 1`) stands on the core,
//! whose top is that of planar layer `T − n`, `T` being the topmost planar layer at xy (the
//! highest whose slicing plane is below the surface). Its thickness varies between about
//! `h/2` and `3h/2`; points where it would be below [`MIN_THICKNESS_FRACTION`]` · h` are
//! dropped (the path is split there).

use super::surface::HeightField;
use crate::geom::{ExPolygon, Point2, Point3, Polygon, difference, intersection, union};
use crate::slice::LayerZ;

/// Thinnest curved layer kept on the planar core, as a fraction of the layer height.
pub const MIN_THICKNESS_FRACTION: f64 = 0.25;

/// Triangles flatter than this (degrees) make a region flat: planar layers already follow it.
pub const FLAT_DEG: f64 = 0.05;

/// Regions and steep parts smaller than this (mm²) are ignored (slivers between triangles).
pub const MIN_REGION_AREA_MM2: f64 = 1.0;

/// Triangles steeper than this (degrees) are walls, not top surfaces.
const WALL_DEG: f64 = 80.0;

/// One top region that can be curved.
#[derive(Debug, Clone, PartialEq)]
pub struct TopRegion {
    /// Its xy area.
    pub area: ExPolygon,
    /// Steepest triangle in it, degrees.
    pub max_slope_deg: f64,
    /// Flattest triangle in it, degrees.
    pub min_slope_deg: f64,
    /// Its highest surface point.
    pub peak: Point3,
    /// Its lowest surface z, mm.
    pub z_min: f64,
}

/// A top surface steeper than `curved.max_angle`, kept planar.
#[derive(Debug, Clone, PartialEq)]
pub struct SteepPart {
    /// Steepest slope, degrees.
    pub slope_deg: f64,
    /// Centroid of its steepest triangle.
    pub position: Point3,
    /// Area, mm².
    pub area_mm2: f64,
}

fn triangle_polygon(c: &[Point3; 3]) -> ExPolygon {
    let mut poly = Polygon::new(c.iter().map(|p| Point2::from_mm(p.x, p.y)).collect());
    if poly.signed_area2() < 0 {
        poly.points.reverse();
    }
    ExPolygon {
        contour: poly,
        holes: Vec::new(),
    }
}

/// The gently sloped top regions of `hf` (every visible upward-facing triangle no steeper than
/// `max_angle_deg`, grouped into connected areas; flat and tiny ones left out) and the parts
/// steeper than that, in a deterministic order.
pub fn find_top_regions(hf: &HeightField, max_angle_deg: f64) -> (Vec<TopRegion>, Vec<SteepPart>) {
    // Visible: the highest surface at the triangle's centroid is the triangle itself.
    let visible: Vec<usize> = hf
        .triangles()
        .iter()
        .enumerate()
        .filter(|(_, t)| {
            let c = t.centroid();
            hf.at(c.x, c.y)
                .is_some_and(|s| s.z - t.z_at(c.x, c.y) < 1e-6)
        })
        .map(|(i, _)| i)
        .collect();
    let tris = hf.triangles();
    let (gentle, steep): (Vec<usize>, Vec<usize>) = visible
        .into_iter()
        .filter(|&i| tris[i].slope_deg() <= WALL_DEG)
        .partition(|&i| tris[i].slope_deg() <= max_angle_deg);
    let components = |ids: &[usize]| -> Vec<(ExPolygon, Vec<usize>)> {
        let polys: Vec<ExPolygon> = ids
            .iter()
            .map(|&i| triangle_polygon(&tris[i].corners))
            .collect();
        let areas = union(&polys);
        areas
            .into_iter()
            .filter(|a| a.area_mm2() >= MIN_REGION_AREA_MM2)
            .map(|a| {
                let members: Vec<usize> = ids
                    .iter()
                    .copied()
                    .filter(|&i| {
                        let c = tris[i].centroid();
                        a.contains(Point2::from_mm(c.x, c.y))
                    })
                    .collect();
                (a, members)
            })
            .filter(|(_, m)| !m.is_empty())
            .collect()
    };
    let mut regions = Vec::new();
    for (area, members) in components(&gentle) {
        let mut peak = tris[members[0]].corners[0];
        let (mut z_min, mut max_slope, mut min_slope) = (f64::MAX, 0.0f64, f64::MAX);
        for &i in &members {
            let t = &tris[i];
            max_slope = max_slope.max(t.slope_deg());
            min_slope = min_slope.min(t.slope_deg());
            for p in t.corners {
                if p.z > peak.z {
                    peak = p;
                }
                z_min = z_min.min(p.z);
            }
        }
        if max_slope < FLAT_DEG {
            continue;
        }
        regions.push(TopRegion {
            area,
            max_slope_deg: max_slope,
            min_slope_deg: min_slope,
            peak,
            z_min,
        });
    }
    let mut steep_parts = Vec::new();
    for (area, members) in components(&steep) {
        let Some(&worst) = members.iter().max_by(|&&a, &&b| {
            tris[a]
                .slope_deg()
                .total_cmp(&tris[b].slope_deg())
                .then(b.cmp(&a))
        }) else {
            continue;
        };
        steep_parts.push(SteepPart {
            slope_deg: tris[worst].slope_deg(),
            position: tris[worst].centroid(),
            area_mm2: area.area_mm2(),
        });
    }
    (regions, steep_parts)
}

/// The index of the topmost planar layer at a surface height `s`: the highest layer whose
/// slicing plane is below it.
pub fn top_layer_at(zs: &[LayerZ], s: f64) -> Option<usize> {
    zs.iter().rposition(|z| z.slice_z < s)
}

/// What planar layer `j` gives up under `area` when `n` layers are curved:
/// `area ∩ islands[j] \ islands[j + n]`, per layer (empty where nothing is lost).
pub fn removal(area: &ExPolygon, islands: &[Vec<ExPolygon>], n: usize) -> Vec<Vec<ExPolygon>> {
    let area = std::slice::from_ref(area);
    (0..islands.len())
        .map(|j| {
            let here = intersection(area, &islands[j]);
            if here.is_empty() {
                return here;
            }
            match islands.get(j + n) {
                Some(above) if !above.is_empty() => difference(&here, above),
                _ => here,
            }
        })
        .collect()
}

/// Moves flat paths onto the surface at one depth (see the module docs).
pub struct Projector<'a> {
    /// The surface.
    pub surface: &'a HeightField,
    /// The object's layers (for the planar core under the lowest curved layer).
    pub layers: &'a [LayerZ],
    /// Depth below the surface, mm (`k·h`).
    pub depth: f64,
    /// Curved layers in the stack (`n`).
    pub count: usize,
    /// Whether this is the lowest curved layer (`k = n − 1`), which stands on the core.
    pub lowest: bool,
    /// Nominal layer height, mm.
    pub height: f64,
    /// Longest segment, mm.
    pub step: f64,
}

/// A projected path piece: 3D points and the local layer thickness at each.
#[derive(Debug, Clone, PartialEq)]
pub struct Projected {
    /// Points on the surface at the projector's depth.
    pub points: Vec<Point3>,
    /// Distance down to the layer below at each point, mm.
    pub thickness: Vec<f64>,
    /// Whether the piece is a loop.
    pub closed: bool,
}

impl Projector<'_> {
    /// The top of the planar core under surface height `s`, mm (0 on the bed).
    pub fn core_top(&self, s: f64) -> Option<f64> {
        let t = top_layer_at(self.layers, s)?;
        Some(match t.checked_sub(self.count) {
            Some(j) => self.layers[j].top,
            None => 0.0,
        })
    }

    /// `path` (xy, mm) densified at triangle edges and to `step`, each point moved to its
    /// surface height minus the depth; split where the surface is missing or the layer would be
    /// too thin. Also returns how many points were dropped.
    pub fn project(&self, path: &[(f64, f64)], closed: bool) -> (Vec<Projected>, usize) {
        let dense = self.densify(path, closed);
        let min = MIN_THICKNESS_FRACTION * self.height;
        let mut pieces: Vec<Projected> = Vec::new();
        let mut cur = Projected {
            points: Vec::new(),
            thickness: Vec::new(),
            closed: false,
        };
        let mut dropped = 0;
        let mut all_ok = true;
        for &(x, y) in &dense {
            let point = self.surface.at(x, y).and_then(|hit| {
                let z = hit.z - self.depth;
                let core = self.core_top(hit.z)?;
                let t = if self.lowest { z - core } else { self.height };
                (z - core >= min).then_some((z, t))
            });
            match point {
                Some((z, t)) => {
                    cur.points.push(Point3::new(x, y, z));
                    cur.thickness.push(t);
                }
                None => {
                    dropped += 1;
                    all_ok = false;
                    if cur.points.len() >= 2 {
                        pieces.push(std::mem::replace(
                            &mut cur,
                            Projected {
                                points: Vec::new(),
                                thickness: Vec::new(),
                                closed: false,
                            },
                        ));
                    } else {
                        cur.points.clear();
                        cur.thickness.clear();
                    }
                }
            }
        }
        if cur.points.len() >= 2 {
            cur.closed = closed && all_ok;
            pieces.push(cur);
        }
        (pieces, dropped)
    }

    /// The points of `path` with crossings of surface triangle edges and `step` subdivisions
    /// inserted; a closed path's closing segment is densified too, so the loop ends just before
    /// its first point (a loop split by dropped points loses its closing segment).
    fn densify(&self, path: &[(f64, f64)], closed: bool) -> Vec<(f64, f64)> {
        let mut out = Vec::with_capacity(path.len() * 4);
        let n = path.len();
        if n == 0 {
            return out;
        }
        let segments = if closed { n } else { n - 1 };
        for i in 0..segments {
            let (a, b) = (path[i], path[(i + 1) % n]);
            out.push(a);
            let len = (b.0 - a.0).hypot(b.1 - a.1);
            if !(len.is_finite() && len > 0.0) {
                continue;
            }
            let mut ts = vec![0.0];
            ts.extend(self.surface.edge_crossings(a, b));
            ts.push(1.0);
            for w in ts.windows(2) {
                let pieces = ((w[1] - w[0]) * len / self.step).ceil().max(1.0) as usize;
                for k in 1..=pieces {
                    let t = w[0] + (w[1] - w[0]) * k as f64 / pieces as f64;
                    if k == pieces && w[1] >= 1.0 {
                        break;
                    }
                    out.push((a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t));
                }
            }
        }
        if !closed {
            out.push(path[n - 1]);
        }
        out
    }
}
