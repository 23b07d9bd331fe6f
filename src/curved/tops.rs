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
//! (`n = slice.top_solid_layers`) are complete layers over areas `A_0 ⊇ A_1 ⊇ … ⊇ A_{n−1}`
//! (`A_0 = A`; deeper ones step in from planar material beside the region by [`rim_step`] per
//! layer and are trimmed where the head would hit) — perimeter loops around `A_k` and solid
//! infill inside them (top solid infill for the topmost), made by the regions stage's own
//! perimeter and rectilinear generators — projected so layer `k` (0 = topmost) lies at
//! `surface(x, y) − k·h`. The planar layers give up what those layers replace: where `m`
//! curved layers cover a point the planar core ends `m` layers under the top there, so planar
//! layer `j` loses `⋃ₖ A_k ∩ island(j) \ island(j + k + 1)` ([`removal_stepped`]; [`removal`]
//! is the case of equal areas). The core's top is printed as a planar top under the curved
//! layers; where `A` ends at an outer wall the curved perimeters continue the wall.
//!
//! Layer `k` at xy stands `h` above layer `k + 1`; where it is the lowest (outside `A_{k+1}`)
//! it stands on the core, whose top is that of planar layer `T − k − 1`, `T` being the topmost
//! planar layer at xy (the highest whose slicing plane is below the surface). Its thickness
//! there varies between about `h/2` and `3h/2`; points where it would be below
//! [`MIN_THICKNESS_FRACTION`]` · h` are dropped (the path is split there), and so are points
//! over another surface than the region's (a crack in the mesh) or next to a step in it.

use crate::geom::{ExPolygon, Point2, Point3, Polygon, difference, intersection, union};
use crate::slice::LayerZ;
use crate::surface::{HeightField, densify_path};

/// Thinnest curved layer kept on the planar core, as a fraction of the layer height.
pub const MIN_THICKNESS_FRACTION: f64 = 0.25;

/// Largest gap between a curved segment's midpoint and its target height before the path is
/// split there (a step or crack in the mesh), mm.
pub const SEAM_TOLERANCE: f64 = 0.005;

/// How far the written G-code may move a point in x or y (half its 0.001 mm resolution, and a
/// little more), mm.
pub const XY_ROUNDING: f64 = 0.0006;

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
    /// Its triangles (indices into [`HeightField::triangles`]), ascending.
    pub triangles: Vec<usize>,
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
            triangles: members,
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

/// What planar layer `j` gives up under stepped curved layers: `areas[k]` is the area of curved
/// layer `k` (0 = topmost, each inside the one above), and where `m` curved layers cover a point
/// the core ends `m` layers under the top there:
/// `⋃ₖ areas[k] ∩ islands[j] \ islands[j + k + 1]`, per layer.
pub fn removal_stepped(
    areas: &[Vec<ExPolygon>],
    islands: &[Vec<ExPolygon>],
) -> Vec<Vec<ExPolygon>> {
    (0..islands.len())
        .map(|j| {
            let mut lost: Vec<ExPolygon> = Vec::new();
            for (k, area) in areas.iter().enumerate() {
                if area.is_empty() {
                    continue;
                }
                let here = intersection(area, &islands[j]);
                if here.is_empty() {
                    continue;
                }
                match islands.get(j + k + 1) {
                    Some(above) if !above.is_empty() => lost.extend(difference(&here, above)),
                    _ => lost.extend(here),
                }
            }
            if lost.len() > 1 { union(&lost) } else { lost }
        })
        .collect()
}

/// How far each deeper curved layer's area steps in from the one above, mm, so that the head's
/// cone clears the planar material beside it.
///
/// Where layer `k` ends, the planar column beside it stands one layer (`h`) higher, plus the
/// surface's own rise towards it: at horizontal distance `D` on a slope `α` the column top is
/// `h + D·tan α` above the nozzle. The cone (half-angle θ) clears it when
/// `D > (h + D·tan α)·tan θ`, i.e. `D > h·tan θ / (1 − tan α·tan θ)`. The nozzle runs half an
/// extrusion width inside the area's edge, which is left as margin for the staircase of the
/// planar layers (their tops lie up to `h/2` off the surface). `None` when the cone is flatter
/// than the surface (`tan α·tan θ ≥ 0.9`): no step clears it.
pub fn rim_step(head_angle_deg: f64, layer_height: f64, max_slope_deg: f64) -> Option<f64> {
    let tan_theta = head_angle_deg.to_radians().tan();
    let k = 1.0 - max_slope_deg.to_radians().tan() * tan_theta;
    (k >= 0.1).then(|| layer_height * tan_theta / k)
}

/// Rows of [`AreaIndex`] per ring edge, on average.
const EDGES_PER_ROW: usize = 8;

/// An area prepared for many point-in-area queries: its ring edges sorted into horizontal rows,
/// so a query counts the crossings of a ray through its row only (even-odd, like
/// [`ExPolygon::contains`] up to points on the boundary).
#[derive(Debug, Clone, Default)]
pub struct AreaIndex {
    y0: f64,
    dy: f64,
    rows: Vec<Vec<[f64; 4]>>,
}

impl AreaIndex {
    /// The index of `area`.
    pub fn new(area: &[ExPolygon]) -> Self {
        let mut edges = Vec::new();
        for ex in area {
            for ring in std::iter::once(&ex.contour).chain(&ex.holes) {
                let n = ring.points.len();
                for i in 0..n {
                    let (a, b) = (ring.points[i].to_mm(), ring.points[(i + 1) % n].to_mm());
                    edges.push([a.0, a.1, b.0, b.1]);
                }
            }
        }
        if edges.is_empty() {
            return Self::default();
        }
        let (y0, y1) = edges.iter().fold((f64::MAX, f64::MIN), |(lo, hi), e| {
            (lo.min(e[1]).min(e[3]), hi.max(e[1]).max(e[3]))
        });
        let count = (edges.len() / EDGES_PER_ROW).clamp(1, 4096);
        let dy = ((y1 - y0) / count as f64).max(1e-6);
        let mut rows = vec![Vec::new(); count];
        let row = |y: f64| (((y - y0) / dy).floor().max(0.0) as usize).min(count - 1);
        for e in edges {
            let (lo, hi) = (row(e[1].min(e[3])), row(e[1].max(e[3])));
            for r in &mut rows[lo..=hi] {
                r.push(e);
            }
        }
        Self { y0, dy, rows }
    }

    /// Whether (x, y) (mm) lies inside the area.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        if self.rows.is_empty() || !y.is_finite() {
            return false;
        }
        let r = (y - self.y0) / self.dy;
        if r < 0.0 || r >= self.rows.len() as f64 {
            return false;
        }
        let mut inside = false;
        for e in &self.rows[r as usize] {
            if (e[1] > y) != (e[3] > y) && x < e[0] + (y - e[1]) * (e[2] - e[0]) / (e[3] - e[1]) {
                inside = !inside;
            }
        }
        inside
    }
}

/// Moves flat paths onto the surface at one depth (see the module docs).
pub struct Projector<'a> {
    /// The surface.
    pub surface: &'a HeightField,
    /// The object's layers (for the planar core under the lowest curved layer).
    pub layers: &'a [LayerZ],
    /// Depth below the surface, mm (`k·h`).
    pub depth: f64,
    /// Curved layers over the core where this layer is the lowest (`k + 1`).
    pub count: usize,
    /// The area of the curved layer under this one (`k + 1`): outside it this layer is the
    /// lowest and stands on the core; empty for the lowest layer of the stack.
    pub below: &'a AreaIndex,
    /// Nominal layer height, mm.
    pub height: f64,
    /// Longest segment, mm.
    pub step: f64,
    /// The surface triangles the layer may lie on, ascending (empty: any). Points over other
    /// triangles — a crack in the mesh that shows a lower surface, a neighbouring steep face —
    /// are dropped like points where the surface is missing.
    pub triangles: &'a [usize],
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

    /// Whether the straight move from `a` to `b` (projected points) stays on the surface: its
    /// midpoint within [`SEAM_TOLERANCE`] of surface − depth. Consecutive points lie in one
    /// triangle except where the mesh has a step or crack (triangles meeting at different
    /// heights), which a path must not bridge.
    fn continuous(&self, a: Point3, b: Point3) -> bool {
        let (x, y) = ((a.x + b.x) / 2.0, (a.y + b.y) / 2.0);
        self.surface
            .at(x, y)
            .is_some_and(|s| ((a.z + b.z) / 2.0 - (s.z - self.depth)).abs() <= SEAM_TOLERANCE)
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
            let supported = self.below.contains(x, y);
            let point = self.surface.at(x, y).and_then(|hit| {
                if !self.triangles.is_empty()
                    && self.triangles.binary_search(&hit.triangle).is_err()
                {
                    return None;
                }
                // The G-code writes xy to 0.001 mm: a point that close to a step or crack in
                // the mesh could land on its other side, so it is dropped.
                let near_step = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
                    .iter()
                    .any(|&(dx, dy)| {
                        self.surface
                            .at(x + dx * XY_ROUNDING, y + dy * XY_ROUNDING)
                            .is_none_or(|s| (s.z - hit.z).abs() > SEAM_TOLERANCE)
                    });
                if near_step {
                    return None;
                }
                let z = hit.z - self.depth;
                if supported {
                    return Some((z, self.height));
                }
                let core = self.core_top(hit.z)?;
                (z - core >= min).then_some((z, z - core))
            });
            let flush = |cur: &mut Projected, pieces: &mut Vec<Projected>| {
                let piece = std::mem::replace(
                    cur,
                    Projected {
                        points: Vec::new(),
                        thickness: Vec::new(),
                        closed: false,
                    },
                );
                if piece.points.len() >= 2 {
                    pieces.push(piece);
                }
            };
            match point {
                Some((z, t)) => {
                    let p = Point3::new(x, y, z);
                    if cur.points.last().is_some_and(|&q| !self.continuous(q, p)) {
                        all_ok = false;
                        flush(&mut cur, &mut pieces);
                    }
                    cur.points.push(p);
                    cur.thickness.push(t);
                }
                None => {
                    dropped += 1;
                    all_ok = false;
                    flush(&mut cur, &mut pieces);
                }
            }
        }
        if cur.points.len() >= 2 {
            let closes = match (cur.points.first(), cur.points.last()) {
                (Some(&a), Some(&b)) => self.continuous(b, a),
                _ => false,
            };
            cur.closed = closed && all_ok && closes;
            pieces.push(cur);
        }
        (pieces, dropped)
    }

    /// The points of `path` with crossings of surface triangle edges and `step` subdivisions
    /// inserted; a closed path's closing segment is densified too, so the loop ends just before
    /// its first point (a loop split by dropped points loses its closing segment).
    fn densify(&self, path: &[(f64, f64)], closed: bool) -> Vec<(f64, f64)> {
        densify_path(path, closed, self.step, &|a, b| {
            self.surface.edge_crossings(a, b)
        })
    }
}
