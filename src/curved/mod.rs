//! Non-planar top surfaces (`conduit slice --curved tops`, `curved.mode = "tops"`): the body
//! is sliced planar; the top solid layers over gently sloped top surfaces follow the surface.
//!
//! Place in the pipeline: Scene → slice → **curved tops** → regions → Program (+ curved layers)
//! → G-code. [`plan_tops`] runs after slicing, on the placed meshes and their sliced islands:
//!
//! 1. [`surface`]: the mesh's top surface as an exact height field;
//! 2. [`tops`]: the top regions no steeper than `curved.max_angle` (steeper ones are reported
//!    and stay planar), their curved layers (perimeters and solid infill over the region, made
//!    flat by the regions stage's generators, then projected to `surface − k·h` with points at
//!    every triangle edge and every `curved.step`), and what the planar layers give up;
//! 3. [`collision`]: each region's nozzle positions against the head model and the material
//!    printed before (the planar layers up to the region's top, its own surface); a region with
//!    a hit stays planar and the hit is reported with the setting that would allow it;
//! 4. [`motion`]: flow from the local layer thickness, feed limited by `curved.max_z_speed`.
//!
//! The pipeline removes the planar areas ([`TopsPlan::removals`]) from the islands before the
//! regions stage and appends each region's curved layers, lowest first, after the planar layer
//! holding the region's highest point ([`insert_curved`]). Everything is sequential and
//! ordered, so the output is deterministic.

pub mod collision;
pub mod motion;
pub mod report;
pub mod surface;
pub mod tops;

pub use report::{CurvedLayerReport, CurvedReport, RegionReport, Rejection};
pub use surface::{HeightField, SurfaceHit};

use crate::config::Config;
use crate::geom::{ExPolygon, Point3, difference, scaled, union};
use crate::mesh::Mesh;
use crate::program::{Event, LayerItem, Program, ProgramParams, Role, Toolpath};
use crate::region::infill::{InfillPattern, Rectilinear};
use crate::region::make_perimeters;
use crate::slice::LayerZ;
use collision::{Head, HeadPart, Material};
use tops::{Projector, TopRegion, find_top_regions, removal, top_layer_at};

/// Nozzle positions tested for collisions are thinned to one per square of this side, mm.
const COLLISION_SAMPLE_MM: f64 = 0.5;

/// The comment that starts each curved layer in the Program (and the G-code).
pub const LAYER_COMMENT: &str = "curved top";

/// One object as [`plan_tops`] needs it.
#[derive(Debug, Clone, Copy)]
pub struct CurvedObject<'a> {
    /// The placed mesh (bed coordinates).
    pub mesh: &'a Mesh,
    /// Its layers.
    pub layers: &'a [LayerZ],
    /// Its sliced islands per layer.
    pub islands: &'a [Vec<ExPolygon>],
    /// The tool printing it.
    pub tool: usize,
}

/// Curved layers to print after one planar layer.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvedInsert {
    /// Top of the planar layer they follow, mm.
    pub after_z: f64,
    /// The tool printing them.
    pub tool: usize,
    /// Comments and toolpaths, in print order.
    pub items: Vec<LayerItem>,
}

/// What [`plan_tops`] decided.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TopsPlan {
    /// Per object, per layer: the area the planar layer gives up.
    pub removals: Vec<Vec<Vec<ExPolygon>>>,
    /// The curved layers.
    pub inserts: Vec<CurvedInsert>,
    /// The report.
    pub report: CurvedReport,
}

/// Plans the curved tops of every object (see the module docs).
pub fn plan_tops(objects: &[CurvedObject<'_>], cfg: &Config) -> TopsPlan {
    let c = &cfg.curved;
    let head = Head {
        angle_deg: c.head_angle,
        height: c.head_height,
        carriage_radius: c.carriage_radius,
        carriage_clearance: c.carriage_clearance,
    };
    let mut plan = TopsPlan {
        removals: objects
            .iter()
            .map(|o| vec![Vec::new(); o.islands.len()])
            .collect(),
        ..TopsPlan::default()
    };
    let n = cfg.slice.region.top_solid_layers;
    for (oi, obj) in objects.iter().enumerate() {
        let hf = HeightField::from_mesh(obj.mesh);
        let (regions, steep) = find_top_regions(&hf, c.max_angle);
        for s in steep {
            plan.report.rejections.push(Rejection {
                object: oi,
                kind: "too_steep",
                reason: format!(
                    "slope {:.1}° is steeper than curved.max_angle = {}° ({:.1} mm²)",
                    s.slope_deg, c.max_angle, s.area_mm2
                ),
                position: [s.position.x, s.position.y, s.position.z],
                setting: format!("curved.max_angle = {:.0}", s.slope_deg.ceil()),
            });
        }
        for region in regions {
            if n == 0 {
                plan.report.rejections.push(Rejection {
                    object: oi,
                    kind: "no_top_layers",
                    reason: "slice.top_solid_layers = 0 leaves no top layers to curve".to_owned(),
                    position: [region.peak.x, region.peak.y, region.peak.z],
                    setting: "slice.top_solid_layers = 1".to_owned(),
                });
                continue;
            }
            match plan_region(objects, oi, &region, &hf, &head, cfg) {
                Ok((remove, insert, rep)) => {
                    for (acc, r) in plan.removals[oi].iter_mut().zip(remove) {
                        if !r.is_empty() {
                            acc.extend(r);
                            *acc = union(acc);
                        }
                    }
                    plan.report.z_speed_limited += rep.z_speed_limited;
                    plan.report.regions.push(rep);
                    plan.inserts.push(insert);
                }
                Err(rejection) => plan.report.rejections.push(rejection),
            }
        }
    }
    plan
}

/// One region's flat paths of curved layer `k`: (xy points, closed, role, width).
type FlatPath = (Vec<(f64, f64)>, bool, Role, f64);

fn flat_layer(area: &ExPolygon, k: usize, cfg: &Config) -> Vec<FlatPath> {
    let params = cfg.slice.region.for_layer(1);
    let h = params.layer_height;
    let per = make_perimeters(std::slice::from_ref(area), &params, h);
    let mut out: Vec<FlatPath> = per
        .loops
        .iter()
        .map(|l| {
            let role = if l.external {
                Role::ExternalPerimeter
            } else {
                Role::Perimeter
            };
            (
                l.polygon.points.iter().map(|p| p.to_mm()).collect(),
                true,
                role,
                l.width,
            )
        })
        .collect();
    let sp = params.spacings(h);
    let (role, spacing, width) = if k == 0 {
        (
            Role::TopSolidInfill,
            sp.top_solid_infill,
            params.top_solid_infill_width,
        )
    } else {
        (
            Role::SolidInfill,
            sp.solid_infill,
            params.solid_infill_width,
        )
    };
    let lines = Rectilinear::new(params.infill_angle_deg).fill(&per.infill_area, spacing, k);
    out.extend(lines.into_iter().map(|l| {
        (
            l.points.iter().map(|p| p.to_mm()).collect(),
            false,
            role,
            width,
        )
    }));
    out
}

/// One curved layer before it becomes toolpaths: k, projected pieces, each piece's role and
/// width, points dropped.
type ProjectedLayer = (usize, Vec<tops::Projected>, Vec<(Role, f64)>, usize);

type RegionPlan = (Vec<Vec<ExPolygon>>, CurvedInsert, RegionReport);

fn plan_region(
    objects: &[CurvedObject<'_>],
    oi: usize,
    region: &TopRegion,
    hf: &HeightField,
    head: &Head,
    cfg: &Config,
) -> Result<RegionPlan, Rejection> {
    let obj = &objects[oi];
    let c = &cfg.curved;
    let n = cfg.slice.region.top_solid_layers;
    let h = cfg.slice.region.layer_height;
    let peak = [region.peak.x, region.peak.y, region.peak.z];
    let Some(after) = top_layer_at(obj.layers, region.peak.z) else {
        return Err(Rejection {
            object: oi,
            kind: "below_first_layer",
            reason: "the surface lies below the first layer's slicing plane".to_owned(),
            position: peak,
            setting: "a lower slice.first_layer_height".to_owned(),
        });
    };
    let speeds = ProgramParams::from_config(cfg)
        .tools
        .get(obj.tool)
        .map(|t| t.speeds)
        .unwrap_or_default();
    // Curved layers, lowest first.
    let mut layers: Vec<ProjectedLayer> = Vec::new();
    for k in (0..n).rev() {
        let proj = Projector {
            surface: hf,
            layers: obj.layers,
            depth: k as f64 * h,
            count: n,
            lowest: k + 1 == n,
            height: h,
            step: c.step,
        };
        let mut pieces = Vec::new();
        let mut meta = Vec::new();
        let mut dropped = 0;
        for (pts, closed, role, width) in flat_layer(&region.area, k, cfg) {
            let (ps, d) = proj.project(&pts, closed);
            dropped += d;
            for p in ps {
                meta.push((role, width));
                pieces.push(p);
            }
        }
        layers.push((k, pieces, meta, dropped));
    }
    if layers.iter().all(|(_, pieces, ..)| pieces.is_empty()) {
        return Err(Rejection {
            object: oi,
            kind: "too_small",
            reason: format!(
                "the region ({:.1} mm²) is too small for a perimeter or infill line",
                region.area.area_mm2()
            ),
            position: peak,
            setting: "narrower extrusion widths in [slice]".to_owned(),
        });
    }
    // Collision: the lowest layer's nozzle positions against the planar material, the
    // topmost layer's also against its own surface (what the layers below it leave is
    // the same surface lower down, so this covers them).
    let layer_nozzles = |want: usize| {
        sample_nozzles(
            layers
                .iter()
                .filter(|(k, ..)| *k == want)
                .flat_map(|(_, pieces, ..)| pieces.iter().flat_map(|p| p.points.iter().copied())),
        )
    };
    let nozzles = layer_nozzles(n - 1);
    let top_nozzles = layer_nozzles(0);
    let remove = removal(&region.area, obj.islands, n);
    let after_top = obj.layers[after].top;
    let z_low = nozzles.iter().map(|p| p.z).fold(f64::MAX, f64::min);
    let bb = ring_bbox(&region.area);
    let grow = head.max_radius();
    let window = [bb[0] - grow, bb[1] - grow, bb[2] + grow, bb[3] + grow];
    let mut material = Material::default();
    for (o, other) in objects.iter().enumerate() {
        for (j, lz) in other.layers.iter().enumerate() {
            if lz.top <= z_low || lz.top > after_top + 1e-9 {
                continue;
            }
            let Some(isl) = other.islands.get(j) else {
                continue;
            };
            if o == oi && !remove[j].is_empty() {
                material.add_layer(lz.top, &difference(isl, &remove[j]), window);
            } else {
                material.add_layer(lz.top, isl, window);
            }
        }
    }
    let mut hit = head.first_hit(&nozzles, &material);
    if hit.is_none() {
        material.add_points(top_nozzles.iter().copied());
        hit = head.first_hit(&top_nozzles, &material);
    }
    if let Some(hit) = hit {
        let (r, rise) = (hit.radius(), hit.rise());
        let (part, setting) = match hit.part {
            HeadPart::Cone => (
                "cone",
                format!(
                    "curved.head_angle < {:.1} or curved.head_height < {:.2}",
                    r.atan2(rise).to_degrees(),
                    rise
                ),
            ),
            HeadPart::Carriage => (
                "carriage",
                format!("curved.carriage_radius < {r:.2} or curved.carriage_clearance > {rise:.2}"),
            ),
        };
        return Err(Rejection {
            object: oi,
            kind: "head_collision",
            reason: format!(
                "the head's {part} would touch printed material at ({:.2}, {:.2}, {:.2}), \
                 {rise:.2} mm above and {r:.2} mm beside the nozzle",
                hit.material.x, hit.material.y, hit.material.z
            ),
            position: [hit.nozzle.x, hit.nozzle.y, hit.nozzle.z],
            setting,
        });
    }
    let mut items = Vec::new();
    let mut rep = RegionReport {
        object: oi,
        area_mm2: region.area.area_mm2(),
        min_slope_deg: region.min_slope_deg,
        max_slope_deg: region.max_slope_deg,
        after_layer: after,
        layers: Vec::new(),
        points_dropped: 0,
        z_speed_limited: 0,
    };
    let cusp = h * region.max_slope_deg.to_radians().cos();
    for (k, pieces, meta, dropped) in layers {
        let depth = k as f64 * h;
        items.push(LayerItem::Event(Event::Comment(format!(
            "{LAYER_COMMENT} layer {k} depth {depth:.3} (object {oi})"
        ))));
        let mut lr = CurvedLayerReport {
            k,
            depth,
            points: 0,
            max_deviation: 0.0,
            planar_cusp: cusp,
            thickness: None,
        };
        rep.points_dropped += dropped;
        for (piece, (role, width)) in pieces.iter().zip(meta) {
            let template = Toolpath {
                points: Vec::new(),
                closed: false,
                role,
                tool: obj.tool,
                width,
                height: h,
                speed: speeds.for_role(role),
                tool_axis: None,
            };
            let (paths, stats) = motion::to_toolpaths(piece, &template, c.max_z_speed);
            rep.z_speed_limited += stats.z_limited;
            if let Some((lo, hi)) = stats.thickness {
                lr.thickness = Some(match lr.thickness {
                    Some((a, b)) => (a.min(lo), b.max(hi)),
                    None => (lo, hi),
                });
            }
            for p in paths {
                lr.points += p.points.len();
                lr.max_deviation = lr.max_deviation.max(deviation(&p, hf, depth));
                items.push(LayerItem::Path(p));
            }
        }
        rep.layers.push(lr);
    }
    rep.layers.reverse();
    Ok((
        remove,
        CurvedInsert {
            after_z: after_top,
            tool: obj.tool,
            items,
        },
        rep,
    ))
}

/// Largest distance of a path's points and segment midpoints from surface − depth, mm.
fn deviation(path: &Toolpath, hf: &HeightField, depth: f64) -> f64 {
    let off = |p: Point3| hf.at(p.x, p.y).map_or(0.0, |s| (p.z - (s.z - depth)).abs());
    let mut worst = path.points.iter().map(|&p| off(p)).fold(0.0, f64::max);
    for w in path.points.windows(2) {
        worst = worst.max(off(Point3::from((w[0].coords + w[1].coords) / 2.0)));
    }
    worst
}

/// The points thinned to the first one in each [`COLLISION_SAMPLE_MM`] square (keeping the
/// lowest z of the square's points would be stricter; the squares are small).
fn sample_nozzles(points: impl Iterator<Item = Point3>) -> Vec<Point3> {
    let mut seen = std::collections::BTreeSet::new();
    points
        .filter(|p| {
            let key = (
                (p.x / COLLISION_SAMPLE_MM).floor() as i64,
                (p.y / COLLISION_SAMPLE_MM).floor() as i64,
            );
            seen.insert(key)
        })
        .collect()
}

fn ring_bbox(ex: &ExPolygon) -> [f64; 4] {
    let mut bb = [f64::MAX, f64::MAX, f64::MIN, f64::MIN];
    for p in &ex.contour.points {
        let (x, y) = p.to_mm();
        bb = [bb[0].min(x), bb[1].min(y), bb[2].max(x), bb[3].max(y)];
    }
    bb
}

/// Appends each insert's curved layers to the Program layer whose top is its `after_z`, with
/// tool changes to its tool and back when the layer ended on another tool.
pub fn insert_curved(program: &mut Program, inserts: &[CurvedInsert]) {
    for ins in inserts {
        let key = scaled(ins.after_z);
        let Some(layer) = program.layers.iter_mut().find(|l| scaled(l.z) == key) else {
            continue;
        };
        let last_tool = layer.paths().last().map(|p| p.tool);
        let switch = last_tool.is_some_and(|t| t != ins.tool);
        if switch {
            layer
                .items
                .push(LayerItem::Event(Event::ToolChange { tool: ins.tool }));
        }
        layer.items.extend(ins.items.iter().cloned());
        if let (true, Some(t)) = (switch, last_tool) {
            layer
                .items
                .push(LayerItem::Event(Event::ToolChange { tool: t }));
        }
    }
}
