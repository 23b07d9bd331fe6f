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
//!    every triangle edge and every `curved.step`), and what the planar layers give up. Where
//!    planar material stands beside a region, each deeper layer steps in from it by
//!    [`tops::rim_step`], so the planar columns left beside it rise a layer at most;
//! 3. [`collision`]: every curved layer's nozzle positions against the head model and the
//!    material printed before (the planar layers up to the region's top less what the curved
//!    layers replace, the layer's own surface); where the head hits, that layer and those under
//!    it are trimmed around the material it hits and the region is planned again, so only the
//!    unreachable rim stays planar, reported with the setting that would allow it.
//!    [`collision::replay`] checks written G-code the same way, bead by bead;
//! 4. [`motion`]: flow from the local layer thickness, feed limited by `curved.max_z_speed`.
//!
//! The pipeline removes the planar areas ([`TopsPlan::removals`]) from the islands before the
//! regions stage and appends each region's curved layers, lowest first, after the planar layer
//! holding the region's highest point (a [`CurvedInsert`] the walk hands to the toolpaths stage
//! as a `program::LayerInsert`). Everything is sequential and
//! ordered, so the output is deterministic.

pub mod clfff;
pub mod collision;
pub mod motion;
pub mod report;
pub mod settings;
pub mod tops;

pub use report::{CurvedLayerReport, CurvedReport, RegionReport, Rejection};
pub use settings::{CurvedMode, CurvedParams, CurvedSettings};

use crate::geom::{
    ExPolygon, Join, Point2, Point3, Polygon, difference, intersection, offset, union,
};
use crate::mesh::Mesh;
use crate::program::{Event, LayerItem, Role, Toolpath};
use crate::region::infill::{InfillPattern, Rectilinear};
use crate::region::make_perimeters;
use crate::slice::LayerZ;
use crate::surface::HeightField;
use crate::surface::{Hit, ToolPart, ToolSolid};
use crate::toolpaths::RoleSpeeds;
use collision::Material;
use tops::{
    AreaIndex, Projector, TopRegion, find_top_regions, removal_stepped, rim_step, top_layer_at,
};

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
pub fn plan_tops(objects: &[CurvedObject<'_>], cfg: &CurvedParams) -> TopsPlan {
    let c = &cfg.curved;
    let head = c.head();
    let mut plan = TopsPlan {
        removals: objects
            .iter()
            .map(|o| vec![Vec::new(); o.islands.len()])
            .collect(),
        ..TopsPlan::default()
    };
    let n = cfg.region.top_solid_layers;
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
            match plan_region(
                objects,
                oi,
                &region,
                &hf,
                &head,
                cfg,
                &mut plan.report.rejections,
            ) {
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

/// Slivers of planar material beside a region thinner than twice this (mm) are left out of the
/// material the deeper layers step away from: where a vertical outer wall bounds the region,
/// the sliced footprint and the region's triangles meet up to rounding.
const SLIVER_MM: f64 = 0.05;

/// The flat paths of curved layer `k` over `area`: perimeter loops around it and solid infill
/// inside them (top solid infill for the topmost), by the regions stage's generators.
fn flat_layer(area: &[ExPolygon], k: usize, cfg: &CurvedParams) -> Vec<FlatPath> {
    let params = cfg.region.for_layer(1);
    let h = params.layer_height;
    let per = make_perimeters(area, &params, h);
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

/// Most rounds of trimming a region's rim where the head hits before the region is rejected.
const MAX_TRIM_ROUNDS: usize = 12;

/// Clearance kept around a material point the head hit, beyond the cone's radius there, mm.
const TRIM_MARGIN_MM: f64 = 0.1;

/// Hits closer than this (mm, on a grid) on one layer are trimmed as one.
const HIT_GRID_MM: f64 = 0.5;

/// The curved layers over `areas` (topmost first), projected, lowest first.
fn project_layers(
    areas: &[Vec<ExPolygon>],
    region: &TopRegion,
    obj: &CurvedObject<'_>,
    hf: &HeightField,
    cfg: &CurvedParams,
) -> Vec<ProjectedLayer> {
    let h = cfg.region.layer_height;
    let mut layers = Vec::new();
    for k in (0..areas.len()).rev() {
        let below = areas
            .get(k + 1)
            .map_or_else(AreaIndex::default, |a| AreaIndex::new(a));
        let proj = Projector {
            surface: hf,
            layers: obj.layers,
            depth: k as f64 * h,
            count: k + 1,
            below: &below,
            height: h,
            step: cfg.curved.step,
            triangles: &region.triangles,
        };
        let mut pieces = Vec::new();
        let mut meta = Vec::new();
        let mut dropped = 0;
        for (pts, closed, role, width) in flat_layer(&areas[k], k, cfg) {
            let (ps, d) = proj.project(&pts, closed);
            dropped += d;
            for p in ps {
                meta.push((role, width));
                pieces.push(p);
            }
        }
        layers.push((k, pieces, meta, dropped));
    }
    layers
}

fn area_of(areas: &[ExPolygon]) -> f64 {
    areas
        .iter()
        .map(ExPolygon::area_mm2)
        .fold(0.0, |a, b| a + b)
}

/// A regular 24-gon of radius `r` around (x, y), mm: the area a trimmed hit takes away.
fn disc(x: f64, y: f64, r: f64) -> ExPolygon {
    let points = (0..24)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 24.0;
            // Circumscribed, so the polygon contains the circle.
            let rr = r / (std::f64::consts::PI / 24.0).cos();
            Point2::from_mm(x + rr * a.cos(), y + rr * a.sin())
        })
        .collect();
    ExPolygon {
        contour: Polygon::new(points),
        holes: Vec::new(),
    }
}

/// The rejection for a head hit: what part of the head, where, and the setting that allows it.
fn collision_rejection(oi: usize, hit: &Hit, what: String) -> Rejection {
    let (r, rise) = (hit.radius(), hit.rise());
    let (part, setting) = match hit.part {
        // The FFF head has a cone and a carriage only.
        ToolPart::Cone | ToolPart::Tip | ToolPart::Needle => (
            "cone",
            format!(
                "curved.head_angle < {:.1} or curved.head_height < {:.2}",
                r.atan2(rise).to_degrees(),
                rise
            ),
        ),
        ToolPart::Carriage => (
            "carriage",
            format!("curved.carriage_radius < {r:.2} or curved.carriage_clearance > {rise:.2}"),
        ),
    };
    Rejection {
        object: oi,
        kind: "head_collision",
        reason: format!(
            "{what}: the head's {part} would touch printed material at ({:.2}, {:.2}, {:.2}), \
             {rise:.2} mm above and {r:.2} mm beside the nozzle",
            hit.material.x, hit.material.y, hit.material.z
        ),
        position: [hit.nozzle.x, hit.nozzle.y, hit.nozzle.z],
        setting,
    }
}

/// Plans one top region: sets it up, steps its layers in from the material beside it, trims
/// them where the head hits until it clears, reports the trimmed rim pieces to `rejections`
/// and turns the layers into toolpaths.
fn plan_region(
    objects: &[CurvedObject<'_>],
    oi: usize,
    region: &TopRegion,
    hf: &HeightField,
    head: &ToolSolid,
    cfg: &CurvedParams,
    rejections: &mut Vec<Rejection>,
) -> Result<RegionPlan, Rejection> {
    let job = RegionJob::new(objects, oi, region, hf, head, cfg)?;
    // Each deeper layer steps in from the one above so the head clears the planar columns
    // beside it ([`tops::rim_step`]); where the head still hits, the layer and those under it
    // are trimmed around the material it hits, and the stack is planned again.
    let mut areas = job.stepped_areas();
    let cleared = job.trim_until_clear(&mut areas)?;
    job.report_trims(&cleared.trims, rejections);
    Ok(job.emit(cleared, &areas))
}

/// One top region being planned: its object, the shared inputs, and what the setup derives
/// from them once for every step.
struct RegionJob<'a> {
    /// Every object (the collision test sees them all).
    objects: &'a [CurvedObject<'a>],
    /// Index of the region's object.
    oi: usize,
    /// The region's object.
    obj: &'a CurvedObject<'a>,
    /// The region.
    region: &'a TopRegion,
    /// The object's top surface.
    hf: &'a HeightField,
    /// The head model.
    head: &'a ToolSolid,
    /// The whole config.
    cfg: &'a CurvedParams,
    /// Number of curved layers (the top solid layers).
    n: usize,
    /// Layer height, mm.
    h: f64,
    /// The planar layer holding the region's highest point.
    after: usize,
    /// That layer's top, mm.
    after_top: f64,
    /// How far each deeper layer steps in ([`tops::rim_step`]).
    step: Option<f64>,
    /// The region's area, as the topmost curved layer covers it.
    top_area: Vec<ExPolygon>,
    /// The window around the region the islands are clipped to: [min x, min y, max x, max y].
    window: [f64; 4],
    /// The object's islands clipped to the window and to the region's height.
    islands: Vec<Vec<ExPolygon>>,
}

/// The trimming loop's outcome: the projected layers that clear the head, the planar areas
/// they replace, every trimmed hit (by layer) and the number of rounds.
struct Cleared {
    /// The curved layers, lowest first.
    layers: Vec<ProjectedLayer>,
    /// Per planar layer, the area the curved layers replace.
    remove: Vec<Vec<ExPolygon>>,
    /// Every hit trimmed, with its layer.
    trims: Vec<(usize, Hit)>,
    /// Rounds of trimming.
    rounds: usize,
}

impl<'a> RegionJob<'a> {
    /// Sets the region up: finds the planar layer it follows (a rejection when it lies below
    /// the first layer), its rim step and the islands near it.
    fn new(
        objects: &'a [CurvedObject<'a>],
        oi: usize,
        region: &'a TopRegion,
        hf: &'a HeightField,
        head: &'a ToolSolid,
        cfg: &'a CurvedParams,
    ) -> Result<Self, Rejection> {
        let obj = &objects[oi];
        let n = cfg.region.top_solid_layers;
        let h = cfg.region.layer_height;
        let Some(after) = top_layer_at(obj.layers, region.peak.z) else {
            return Err(Rejection {
                object: oi,
                kind: "below_first_layer",
                reason: "the surface lies below the first layer's slicing plane".to_owned(),
                position: peak(region),
                setting: "a lower slice.first_layer_height".to_owned(),
            });
        };
        let top_area = vec![region.area.clone()];
        let step = rim_step(cfg.curved.head_angle, h, region.max_slope_deg);
        let window = region_window(region, head, cfg, step);
        let islands = islands_near(obj, region, window, after, n, h);
        Ok(Self {
            objects,
            oi,
            obj,
            region,
            hf,
            head,
            cfg,
            n,
            h,
            after,
            after_top: obj.layers[after].top,
            step,
            top_area,
            window,
            islands,
        })
    }

    /// The area of each curved layer (topmost first) before any trimming: the region, each
    /// deeper layer stepped in a rim step more from the planar material beside it.
    fn stepped_areas(&self) -> Vec<Vec<ExPolygon>> {
        let top_area = &self.top_area;
        // The footprint at the region's height: where planar material stands beside the region
        // when its curved layers are printed. Elsewhere the region's rim is an outer wall.
        // Layer by layer: stacked layers repeat the same edges, which one overlay of all of them
        // handles very slowly.
        let footprint = self.islands[..=self.after]
            .iter()
            .filter(|isl| !isl.is_empty())
            .fold(Vec::new(), |acc: Vec<ExPolygon>, isl| {
                if acc.is_empty() {
                    isl.clone()
                } else {
                    union(&[acc.as_slice(), isl.as_slice()].concat())
                }
            });
        let footprint = footprint.as_slice();
        // Planar material beside the region (slivers along outer walls left out).
        let material = offset(
            &offset(
                &difference(footprint, top_area),
                -SLIVER_MM,
                Join::Miter(2.0),
            ),
            SLIVER_MM,
            Join::Miter(2.0),
        );
        (0..self.n)
            .map(|k| match (k, self.step) {
                (0, _) => top_area.clone(),
                _ if material.is_empty() => top_area.clone(),
                (_, Some(s)) => {
                    difference(top_area, &offset(&material, k as f64 * s, Join::Miter(2.0)))
                }
                (_, None) => Vec::new(),
            })
            .collect()
    }

    /// Projects the layers over `areas` and tests them against the head; while it hits, trims
    /// `areas` around the hits and projects again. A rejection when nothing of the region is
    /// left or the head still hits after [`MAX_TRIM_ROUNDS`] rounds.
    fn trim_until_clear(&self, areas: &mut [Vec<ExPolygon>]) -> Result<Cleared, Rejection> {
        let mut trims: Vec<(usize, Hit)> = Vec::new();
        let mut rounds = 0;
        loop {
            let layers = project_layers(areas, self.region, self.obj, self.hf, self.cfg);
            if layers.iter().all(|(_, pieces, ..)| pieces.is_empty()) {
                return Err(self.nothing_left(&trims));
            }
            let remove = removal_stepped(areas, &self.islands);
            let material = self.material_under(&layers, &remove);
            let found = self.head_hits(&layers, &material);
            if found.is_empty() {
                return Ok(Cleared {
                    layers,
                    remove,
                    trims,
                    rounds,
                });
            }
            rounds += 1;
            if rounds > MAX_TRIM_ROUNDS {
                let (k, hit) = found[0];
                return Err(collision_rejection(
                    self.oi,
                    &hit,
                    format!("curved layer {k} still collides after {MAX_TRIM_ROUNDS} trims"),
                ));
            }
            self.trim(areas, &found);
            trims.extend(found);
        }
    }

    /// The rejection when the layers hold no path: the first trim took it all, or the region
    /// is too small for one.
    fn nothing_left(&self, trims: &[(usize, Hit)]) -> Rejection {
        let region = self.region;
        match trims.first() {
            Some((_, hit)) => collision_rejection(
                self.oi,
                hit,
                format!(
                    "trimming the rim where the head hits leaves nothing of the region \
                     ({:.1} mm²)",
                    region.area.area_mm2()
                ),
            ),
            None => Rejection {
                object: self.oi,
                kind: "too_small",
                reason: format!(
                    "the region ({:.1} mm²) is too small for a perimeter or infill line",
                    region.area.area_mm2()
                ),
                position: peak(region),
                setting: "narrower extrusion widths in [slice]".to_owned(),
            },
        }
    }

    /// The material printed before the curved layers, from the lowest curved point up to the
    /// planar layer they follow: every object's layers, this object's less what `remove`
    /// gives up.
    fn material_under(&self, layers: &[ProjectedLayer], remove: &[Vec<ExPolygon>]) -> Material {
        let z_low = layers
            .iter()
            .flat_map(|(_, pieces, ..)| pieces.iter().flat_map(|p| p.points.iter()))
            .map(|p| p.z)
            .fold(f64::MAX, f64::min);
        let mut material = Material::default();
        for (o, other) in self.objects.iter().enumerate() {
            for (j, lz) in other.layers.iter().enumerate() {
                if lz.top <= z_low || lz.top > self.after_top + 1e-9 {
                    continue;
                }
                let isl = if o == self.oi {
                    self.islands.get(j)
                } else {
                    other.islands.get(j)
                };
                let Some(isl) = isl else {
                    continue;
                };
                if o == self.oi && !remove[j].is_empty() {
                    material.add_layer(lz.top, &difference(isl, &remove[j]), self.window);
                } else {
                    material.add_layer(lz.top, isl, self.window);
                }
            }
        }
        material
    }

    /// Every layer's nozzles against the planar material and the layer's own points (a concave
    /// surface may rise into the head beside the nozzle): the hits, one per layer and
    /// [`HIT_GRID_MM`] square.
    fn head_hits(&self, layers: &[ProjectedLayer], material: &Material) -> Vec<(usize, Hit)> {
        let mut found: Vec<(usize, Hit)> = Vec::new();
        let mut seen = std::collections::BTreeSet::new();
        for (k, pieces, ..) in layers {
            let nozzles = sample_nozzles(pieces.iter().flat_map(|p| p.points.iter().copied()));
            let mut with_own = material.clone();
            with_own.add_points(nozzles.iter().copied());
            for hit in with_own.hits(self.head, &nozzles) {
                let key = (
                    *k,
                    (hit.material.x / HIT_GRID_MM).floor() as i64,
                    (hit.material.y / HIT_GRID_MM).floor() as i64,
                );
                if seen.insert(key) {
                    found.push((*k, hit));
                }
            }
        }
        found
    }

    /// Trims `areas` around the hits: a hit on layer k trims it and every deeper layer, each
    /// deeper one a rim step more (what it trims becomes planar material beside the deeper
    /// layers).
    fn trim(&self, areas: &mut [Vec<ExPolygon>], found: &[(usize, Hit)]) {
        let discs_of = |k: usize| -> Vec<ExPolygon> {
            found
                .iter()
                .filter(|(hk, _)| *hk <= k)
                .map(|(hk, hit)| {
                    let r = self.head.radius_at(hit.rise()).map_or(0.0, |(r, _)| r);
                    let steps = (k - hk) as f64 * self.step.unwrap_or(0.0);
                    disc(hit.material.x, hit.material.y, r + TRIM_MARGIN_MM + steps)
                })
                .collect()
        };
        for (k, area) in areas.iter_mut().enumerate() {
            let discs = discs_of(k);
            if !discs.is_empty() && !area.is_empty() {
                *area = difference(area, &union(&discs));
            }
        }
    }

    /// Reports every trimmed piece to `rejections`: per layer, each connected group of trimmed
    /// hits with the area of the rim it leaves planar.
    fn report_trims(&self, trims: &[(usize, Hit)], rejections: &mut Vec<Rejection>) {
        for k in 0..self.n {
            let hits: Vec<&Hit> = trims
                .iter()
                .filter(|(hk, _)| *hk == k)
                .map(|(_, h)| h)
                .collect();
            if hits.is_empty() {
                continue;
            }
            let discs: Vec<ExPolygon> = hits
                .iter()
                .map(|hit| {
                    let r = self.head.radius_at(hit.rise()).map_or(0.0, |(r, _)| r);
                    disc(hit.material.x, hit.material.y, r + TRIM_MARGIN_MM)
                })
                .collect();
            for group in union(&discs) {
                let Some(hit) = hits
                    .iter()
                    .find(|hit| group.contains(Point2::from_mm(hit.material.x, hit.material.y)))
                else {
                    continue;
                };
                let lost = area_of(&intersection(std::slice::from_ref(&group), &self.top_area));
                rejections.push(collision_rejection(
                    self.oi,
                    hit,
                    format!(
                        "curved layer {k} (depth {:.2} mm) leaves out {lost:.1} mm² of the region's \
                         rim here, printed planar",
                        k as f64 * self.h
                    ),
                ));
            }
        }
    }

    /// The region's plan: the planar removals, the curved layers as toolpaths (lowest first,
    /// each after its comment) and the region's report (layers topmost first).
    fn emit(&self, cleared: Cleared, areas: &[Vec<ExPolygon>]) -> RegionPlan {
        let region = self.region;
        let speeds = self
            .cfg
            .program
            .clone()
            .tools
            .get(self.obj.tool)
            .map(|t| t.speeds)
            .unwrap_or_default();
        let mut items = Vec::new();
        let mut rep = RegionReport {
            object: self.oi,
            area_mm2: region.area.area_mm2(),
            curved_area_mm2: area_of(&areas[0]),
            rim_step_mm: self.step,
            trim_rounds: cleared.rounds,
            min_slope_deg: region.min_slope_deg,
            max_slope_deg: region.max_slope_deg,
            after_layer: self.after,
            layers: Vec::new(),
            points_dropped: 0,
            z_speed_limited: 0,
        };
        let cusp = self.h * region.max_slope_deg.to_radians().cos();
        for layer in cleared.layers {
            let area_mm2 = area_of(&areas[layer.0]);
            let lr = self.emit_layer(layer, area_mm2, cusp, &speeds, &mut rep, &mut items);
            rep.layers.push(lr);
        }
        rep.layers.reverse();
        (
            cleared.remove,
            CurvedInsert {
                after_z: self.after_top,
                tool: self.obj.tool,
                items,
            },
            rep,
        )
    }

    /// One curved layer's comment and toolpaths, appended to `items`; returns its report and
    /// adds its dropped points and z-limited moves to `rep`.
    fn emit_layer(
        &self,
        (k, pieces, meta, dropped): ProjectedLayer,
        area_mm2: f64,
        cusp: f64,
        speeds: &RoleSpeeds,
        rep: &mut RegionReport,
        items: &mut Vec<LayerItem>,
    ) -> CurvedLayerReport {
        let (oi, h) = (self.oi, self.h);
        let depth = k as f64 * h;
        items.push(LayerItem::Event(Event::Comment(format!(
            "{LAYER_COMMENT} layer {k} depth {depth:.3} (object {oi})"
        ))));
        let mut lr = CurvedLayerReport {
            k,
            depth,
            area_mm2,
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
                tool: self.obj.tool,
                width,
                height: h,
                speed: speeds.for_role(role),
                segments: None,
                tool_axis: None,
            };
            let (paths, stats) =
                motion::to_toolpaths(piece, &template, self.cfg.curved.max_z_speed);
            rep.z_speed_limited += stats.z_limited;
            if let Some((lo, hi)) = stats.thickness {
                lr.thickness = Some(match lr.thickness {
                    Some((a, b)) => (a.min(lo), b.max(hi)),
                    None => (lo, hi),
                });
            }
            for p in paths {
                lr.points += p.points.len();
                lr.max_deviation = lr.max_deviation.max(deviation(&p, self.hf, depth));
                items.push(LayerItem::Path(p));
            }
        }
        lr
    }
}

/// The region's highest point, as a rejection's position.
fn peak(region: &TopRegion) -> [f64; 3] {
    [region.peak.x, region.peak.y, region.peak.z]
}

/// The window around `region` that the head and the loops can reach, [min x, min y, max x,
/// max y], mm: the region's bounding box grown by the larger of the head's radius and the
/// reach of its perimeters and rim steps.
fn region_window(
    region: &TopRegion,
    head: &ToolSolid,
    cfg: &CurvedParams,
    step: Option<f64>,
) -> [f64; 4] {
    let n = cfg.region.top_solid_layers;
    let params = cfg.region.for_layer(1);
    let reach = (params.perimeters + 2) as f64 * params.perimeter_width
        + n as f64 * step.unwrap_or(0.0)
        + 1.0;
    let bb = ring_bbox(&region.area);
    let grow = head.widest().max(reach) + 1.0;
    [bb[0] - grow, bb[1] - grow, bb[2] + grow, bb[3] + grow]
}

/// The object's islands near the region (within `window`) and at its height (from `n + 1`
/// layers under its lowest point up to the layers over its top, `after` being the planar
/// layer holding its peak); other layers are left empty. That is all the removals, the
/// material beside the region and the collision test look at: the rest of each island is far
/// away, and clipping it off keeps the polygon operations small.
fn islands_near(
    obj: &CurvedObject<'_>,
    region: &TopRegion,
    window: [f64; 4],
    after: usize,
    n: usize,
    h: f64,
) -> Vec<Vec<ExPolygon>> {
    let window_area = [ExPolygon {
        contour: Polygon::new(vec![
            Point2::from_mm(window[0], window[1]),
            Point2::from_mm(window[2], window[1]),
            Point2::from_mm(window[2], window[3]),
            Point2::from_mm(window[0], window[3]),
        ]),
        holes: Vec::new(),
    }];
    let z_from = region.z_min - (n + 1) as f64 * h;
    obj.layers
        .iter()
        .zip(obj.islands)
        .enumerate()
        .map(|(j, (lz, isl))| {
            if lz.top >= z_from && j <= after + n + 1 {
                intersection(isl, &window_area)
            } else {
                Vec::new()
            }
        })
        .collect()
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
