//! The planar pipeline as one walk: Scene → placed on the bed → slice → (electronics: cavities,
//! routing, channels) → regions → Program → G-code.
//!
//! [`Stage`] names the steps in order (for progress reporting); [`slice_scene`] runs them and
//! returns the G-code bytes with a [`SliceSummary`] for the report; [`slice_scene_with`] adds a
//! circuit ([`electronics`]). The other walks are its submodules: [`conform`], [`jet`],
//! [`compensate`] and [`postprocess`] (another slicer's G-code with a circuit built in).
//!
//! The walks that route a circuit ([`slice_scene_watched`], [`route_scene`],
//! [`postprocess::edit_circuit_watched`]) start the job's routing clock when routing starts:
//! `route.time_limit` bounds the routing of every object together. They hand the router a
//! callback ([`ProgressFn`]) told how far it got, in wires of the whole job.

pub mod compensate;
pub mod conform;
pub mod jet;
pub mod place;
pub mod postprocess;

pub use crate::circuit::stage::{self as electronics, Electronics, ElectronicsReport};
pub use crate::emit::route_svg::RouteViewLayer;
pub use crate::route::{ProgressFn, RouteProgress};

use crate::config::{Config, CurvedMode};
use crate::emit::gcode::{GcodeStats, write_gcode};
use crate::geom::{BoundingBox, ExPolygon, Transform, scaled};
use crate::mesh::Mesh;
use crate::program::{LayerExtras, LayerInsert, Program};
use crate::region::{RegionError, make_regions_with_heights};
use crate::scene::{Scene, placed_meshes};
use crate::slice::{LayerZ, SliceParams, SliceReport, slice_mesh};
use crate::toolpaths::{ObjectLayers, build_program_with};
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// The pipeline's steps, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Objects placed on the bed.
    Place,
    /// Meshes cut into layers of regions with holes.
    Slice,
    /// Parts placed, cavities carved, wires routed (only with a circuit).
    Route,
    /// Perimeters, skins, infill and skirt per layer.
    Regions,
    /// Toolpaths and events ordered into a Program.
    Program,
    /// The Program written as G-code.
    Emit,
}

impl Stage {
    /// Every stage in order.
    pub const ALL: [Stage; 6] = [
        Stage::Place,
        Stage::Slice,
        Stage::Route,
        Stage::Regions,
        Stage::Program,
        Stage::Emit,
    ];

    /// A short human name.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Place => "placing",
            Stage::Slice => "slicing",
            Stage::Route => "routing",
            Stage::Regions => "regions",
            Stage::Program => "toolpaths",
            Stage::Emit => "writing G-code",
        }
    }
}

/// Why the pipeline failed.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The scene has no triangles.
    #[error("the scene has no triangles to slice")]
    EmptyScene,
    /// An object does not fit the printer.
    #[error(
        "object '{object}' is {size:.1} mm along {axis}, larger than the printer's {limit:.1} mm"
    )]
    TooLarge {
        /// The object's name.
        object: String,
        /// "x", "y" or "z".
        axis: &'static str,
        /// The object's extent in mm.
        size: f64,
        /// The printer's extent in mm.
        limit: f64,
    },
    /// An object is assigned a tool the config does not define.
    #[error("object '{object}' is assigned tool {tool}, but the config defines {tools} tool(s)")]
    UnknownTool {
        /// The object's name.
        object: String,
        /// The tool index.
        tool: usize,
        /// How many tools the config has.
        tools: usize,
    },
    /// The walk cannot subtract an object's negative volumes (only the planar slice does).
    ///
    /// How to fix: slice the model without `--curved clfff`, or remove the negative volumes in
    /// the slicer that made the 3MF.
    #[error("object '{object}' has negative volumes, which {walk} does not subtract")]
    NegativeVolumes {
        /// The object's name.
        object: String,
        /// The walk (`--curved clfff`).
        walk: &'static str,
    },
    /// Slice parameters are unusable.
    #[error(transparent)]
    SliceParams(#[from] crate::slice::SliceParamsError),
    /// Region parameters are unusable.
    #[error(transparent)]
    Regions(#[from] RegionError),
    /// Writing G-code failed.
    #[error(transparent)]
    Emit(#[from] crate::emit::gcode::EmitError),
    /// The circuit's placement does not fit.
    #[error(transparent)]
    Electronics(#[from] electronics::ElectronicsError),
    /// A curved-layer (clfff) print cannot be planned.
    #[error(transparent)]
    Clfff(#[from] crate::curved::clfff::ClfffError),
    /// The wipe tower has no place.
    #[error(transparent)]
    WipeTower(#[from] crate::toolpaths::TowerError),
    /// Slicing left nothing to print: no layer has an extrusion (a mesh without volume, such
    /// as loose or duplicated triangles, or objects thinner than a line).
    ///
    /// How to fix: give a closed solid; `conduit info` shows whether the mesh is closed.
    #[error(
        "nothing to print: no layer has an extrusion (the model has no printable volume){}",
        open_note(*dropped)
    )]
    NothingToPrint {
        /// Open contours that could not be closed and were left out, over all objects.
        dropped: usize,
    },
}

/// The reason an empty print may have, when open contours were dropped.
fn open_note(dropped: usize) -> String {
    if dropped == 0 {
        return String::new();
    }
    format!(
        "; {dropped} open contour(s) could not be closed and were left out: the mesh has \
         holes (`conduit info` shows them, `conduit convert --repair` fills them)"
    )
}

/// What slicing one object found.
#[derive(Debug, Clone, Serialize)]
pub struct ObjectSummary {
    /// The object's name.
    pub name: String,
    /// The tool printing it.
    pub tool: usize,
    /// Where it ended up on the bed.
    pub bbox: Option<BoundingBox>,
    /// Slicer findings (open chains closed or dropped).
    pub slice: SliceReport,
}

/// What a pipeline run produced, for the JSON report.
#[derive(Debug, Clone, Serialize)]
pub struct SliceSummary {
    /// Per object.
    pub objects: Vec<ObjectSummary>,
    /// Layers in the program.
    pub layers: usize,
    /// Filament, time and per-tool figures from the writer.
    pub gcode: GcodeStats,
    /// Wall time per stage in seconds, in stage order.
    pub stage_seconds: Vec<(Stage, f64)>,
    /// Parts, wires and routing totals, when a circuit was given.
    pub electronics: Option<ElectronicsReport>,
    /// Curved top regions and rejections, with `curved.mode = "tops"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curved: Option<crate::curved::CurvedReport>,
    /// The wipe tower, when one was built (`[wipe_tower]`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wipe_tower: Option<crate::toolpaths::TowerSummary>,
    /// The placed parts (bed coordinates), when a circuit was given: what the pick-and-place
    /// files list.
    #[serde(skip)]
    pub parts: Vec<crate::circuit::PlacedPart>,
}

impl SliceSummary {
    /// What the user should hear about on the terminal, one line each: objects whose open
    /// contours could not be closed and were left out of the print, or were closed across a gap
    /// (either way the mesh has holes, and the print differs from a closed mesh's), and custom
    /// G-code by height that no layer reached.
    pub fn warnings(&self) -> Vec<String> {
        let above = &self.gcode.events_above_print;
        let events = (!above.is_empty()).then(|| {
            let at: Vec<String> = above.iter().map(|z| format!("{z} mm")).collect();
            format!(
                "custom G-code by height above the print's last layer is not written (at {})",
                at.join(", ")
            )
        });
        self.objects
            .iter()
            .filter_map(|o| {
                let (dropped, closed) = (o.slice.open_chains_dropped, o.slice.open_chains_closed);
                let what = if dropped > 0 {
                    format!(
                        "{dropped} open contour(s) could not be closed and were left out \
                         ({closed} closed across a gap)"
                    )
                } else if closed > 0 {
                    format!(
                        "{closed} open contour(s) were closed across a gap of at most \
                         {} mm",
                        crate::slice::DEFAULT_MAX_GAP_MM
                    )
                } else {
                    return None;
                };
                Some(format!(
                    "object \"{}\": {what}; the mesh has holes: `conduit info` shows them, \
                     `conduit convert --repair` fills them",
                    o.name
                ))
            })
            .chain(events)
            .collect()
    }
}

/// Places every object of the scene on the bed: the scene's combined footprint is centred on the
/// bed (objects keep their positions relative to each other, as a 3MF build arranges them) and each
/// object is dropped so its lowest point touches the bed.
pub fn place_on_bed(scene: &Scene, cfg: &Config) -> Vec<Mesh> {
    place_on_bed_with_offsets(scene, cfg).0
}

/// [`place_on_bed`], also returning each object's translation from scene (build) coordinates to
/// bed coordinates, mm: what part placements given in model coordinates must be moved by.
pub fn place_on_bed_with_offsets(scene: &Scene, cfg: &Config) -> (Vec<Mesh>, Vec<[f64; 3]>) {
    let mut meshes = placed_meshes(scene);
    let Some(all) = meshes
        .iter()
        .filter_map(Mesh::bounding_box)
        .reduce(|a, b| a.union(&b))
    else {
        let none = vec![[0.0; 3]; meshes.len()];
        return (meshes, none);
    };
    let p = &cfg.printer;
    let dx = p.bed_origin[0] + p.bed_size[0] / 2.0 - (all.min[0] + all.max[0]) / 2.0;
    let dy = p.bed_origin[1] + p.bed_size[1] / 2.0 - (all.min[1] + all.max[1]) / 2.0;
    let mut offsets = Vec::with_capacity(meshes.len());
    for m in &mut meshes {
        let offset = match m.bounding_box() {
            Some(bb) => [dx, dy, -bb.min[2]],
            None => [dx, dy, 0.0],
        };
        m.transform(&Transform::translation(offset[0], offset[1], offset[2]));
        offsets.push(offset);
    }
    (meshes, offsets)
}

/// Each object's model-space bounding box (an empty box at the origin for an empty object): the
/// frame of a placement with `origin = "model"` or `"bbox_center"`, as `conduit slice` uses it.
pub fn model_bboxes(scene: &Scene) -> Vec<BoundingBox> {
    placed_meshes(scene)
        .iter()
        .map(|m| {
            m.bounding_box().unwrap_or(BoundingBox {
                min: [0.0; 3],
                max: [0.0; 3],
            })
        })
        .collect()
}

/// Runs the whole planar pipeline on a scene; `progress` is told when each stage starts.
pub fn slice_scene(
    scene: &Scene,
    cfg: &Config,
    progress: impl FnMut(Stage),
) -> Result<(Vec<u8>, Program, SliceSummary), PipelineError> {
    slice_scene_with(scene, cfg, None, progress)
}

/// Stage timings: each lap records the time since the previous one.
pub(crate) struct Laps<S = Stage> {
    pub(crate) times: Vec<(S, f64)>,
    clock: Instant,
}

impl<S> Laps<S> {
    pub(crate) fn new() -> Self {
        Self {
            times: Vec::new(),
            clock: Instant::now(),
        }
    }

    pub(crate) fn lap(&mut self, stage: S) {
        self.times.push((stage, self.clock.elapsed().as_secs_f64()));
        self.clock = Instant::now();
    }
}

/// The pipeline up to the regions stage: objects on the bed, sliced, and with a circuit the
/// electronics stage run on their islands.
struct Front {
    /// Per object: its layers and slicing report.
    sliced: Vec<(Vec<crate::slice::SlicedLayer>, SliceReport)>,
    /// Per object: name and bed bounding box.
    placed: Vec<(String, Option<BoundingBox>)>,
    extras: LayerExtras,
    report: Option<ElectronicsReport>,
    parts: Vec<crate::circuit::PlacedPart>,
    /// Per object: what the electronics stage cut (empty without a circuit).
    cuts: Vec<electronics::ObjectCuts>,
    /// The placed meshes, kept only when curved tops need them.
    meshes: Vec<Mesh>,
}

/// The electronics stage's parameters for one job: the config's, with the job's routing
/// deadline (`route.time_limit` from now) and the progress callback. Routing starts now.
pub(crate) fn watched_params(
    cfg: &Config,
    routing: Option<&ProgressFn>,
) -> electronics::ElectronicsParams {
    let mut params = cfg.electronics_params();
    params.route.watch.deadline = crate::route::RouteWatch::deadline_in(params.route.time_limit);
    params.route.watch.progress = routing.cloned();
    params
}

/// `routing` for the wires of one object: its counts moved by the wires of the objects before
/// (`done_before` wires, `unrouted_before` of them unrouted) out of the job's `total`.
fn offset_progress(
    routing: Option<&ProgressFn>,
    done_before: usize,
    unrouted_before: usize,
    total: usize,
) -> Option<ProgressFn> {
    let outer = routing?.clone();
    Some(std::sync::Arc::new(move |p: RouteProgress| {
        outer(RouteProgress {
            done: done_before + p.done,
            total,
            unrouted: unrouted_before + p.unrouted,
            ..p
        })
    }))
}

fn front(
    scene: &Scene,
    cfg: &Config,
    circuit: Option<&Electronics>,
    progress: &mut impl FnMut(Stage),
    routing: Option<&ProgressFn>,
    laps: &mut Laps,
) -> Result<Front, PipelineError> {
    if scene.triangle_count() == 0 {
        return Err(PipelineError::EmptyScene);
    }
    progress(Stage::Place);
    let model_boxes = model_bboxes(scene);
    let (meshes, offsets) = place_on_bed_with_offsets(scene, cfg);
    check_fits(&meshes, cfg)?;
    laps.lap(Stage::Place);

    progress(Stage::Slice);
    let params = SliceParams::new(cfg.slice.layer_height, cfg.slice.first_layer_height)?;
    let mut sliced: Vec<_> = meshes.iter().map(|m| slice_mesh(m, &params)).collect();
    subtract_negative_volumes(scene, &offsets, &params, &mut sliced);
    // The meshes are not needed past slicing (unless curved tops follow their surface): keep
    // only what the report says about them.
    let placed: Vec<(String, Option<BoundingBox>)> = meshes
        .iter()
        .map(|m| (m.name.clone(), m.bounding_box()))
        .collect();
    let meshes = if cfg.curved.mode == CurvedMode::Tops {
        meshes
    } else {
        Vec::new()
    };
    laps.lap(Stage::Slice);

    // Electronics: parts on the bed, then per object cavities, routes and channels.
    let mut out = Front {
        sliced: Vec::new(),
        placed,
        extras: LayerExtras::default(),
        report: None,
        parts: Vec::new(),
        cuts: Vec::new(),
        meshes,
    };
    if let Some(e) = circuit {
        progress(Stage::Route);
        let mut params = watched_params(cfg, routing);
        let circuit = electronics::place_circuit(e, &model_boxes, &offsets, &params)?;
        let mut r = ElectronicsReport::default();
        let routed_here = |i: usize| {
            circuit
                .wires
                .iter()
                .filter(|w| w.object == i && w.other_object.is_none())
                .count()
        };
        let total = (0..sliced.len()).map(routed_here).sum();
        let mut done_before = 0;
        for (i, (layers, _)) in sliced.iter_mut().enumerate() {
            let unrouted_before = r.wires.iter().filter(|w| !w.routed).count();
            params.route.watch.progress =
                offset_progress(routing, done_before, unrouted_before, total);
            done_before += routed_here(i);
            let zs: Vec<LayerZ> = layers.iter().map(|l| l.z).collect();
            let mut islands: Vec<Vec<ExPolygon>> = layers
                .iter_mut()
                .map(|l| std::mem::take(&mut l.islands))
                .collect();
            let cuts = electronics::object_stage(
                i,
                &mut islands,
                &zs,
                &circuit,
                &params,
                &mut out.extras,
                &mut r,
            );
            out.cuts.push(cuts);
            for (l, isl) in layers.iter_mut().zip(islands) {
                l.islands = isl;
            }
        }
        out.report = Some(r);
        out.parts = circuit.parts;
        laps.lap(Stage::Route);
    }
    out.sliced = sliced;
    Ok(out)
}

/// Removes each object's negative volumes ([`crate::scene::SceneObject::negative`]) from its
/// sliced layers: the volume is placed as its object was (`offsets`) and sliced on the same
/// layer planes, and each layer's islands lose its cross-section, as PrusaSlicer subtracts
/// negative volumes from the model parts layer by layer.
fn subtract_negative_volumes(
    scene: &Scene,
    offsets: &[[f64; 3]],
    params: &SliceParams,
    sliced: &mut [(Vec<crate::slice::SlicedLayer>, SliceReport)],
) {
    for ((object, offset), (layers, _)) in scene.objects.iter().zip(offsets).zip(sliced) {
        let Some(negative) = &object.negative else {
            continue;
        };
        let mut mesh = negative.clone();
        mesh.transform(&object.transform);
        mesh.transform(&Transform::translation(offset[0], offset[1], offset[2]));
        let (cut, _) = slice_mesh(&mesh, params);
        // Both schedules start at the bed with the same parameters: layer i is at the same
        // height in each.
        for (layer, hole) in layers.iter_mut().zip(&cut) {
            if !hole.islands.is_empty() {
                layer.islands = crate::geom::difference(&layer.islands, &hole.islands);
            }
        }
    }
}

/// What `conduit route` shows: the layers with what the electronics stage made of them.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteView {
    /// Layers bottom to top (objects merged by height).
    pub layers: Vec<RouteViewLayer>,
    /// Parts and wires.
    pub report: ElectronicsReport,
    /// Placed parts, bed coordinates.
    pub parts: Vec<crate::circuit::PlacedPart>,
}

/// The pipeline up to routing, without regions or G-code: for `conduit route`. `routing` is
/// told how far the router got.
pub fn route_scene(
    scene: &Scene,
    cfg: &Config,
    circuit: &Electronics,
    mut progress: impl FnMut(Stage),
    routing: Option<&ProgressFn>,
) -> Result<RouteView, PipelineError> {
    let mut laps = Laps::new();
    let f = front(scene, cfg, Some(circuit), &mut progress, routing, &mut laps)?;
    let mut by_z: BTreeMap<i64, RouteViewLayer> = BTreeMap::new();
    for ((layers, _), cuts) in f.sliced.into_iter().zip(&f.cuts) {
        for (i, l) in layers.into_iter().enumerate() {
            let key = scaled(l.z.top);
            let entry = by_z.entry(key).or_insert_with(|| RouteViewLayer {
                z: l.z.top,
                islands: Vec::new(),
                cavities: Vec::new(),
                channels: Vec::new(),
                traces: Vec::new(),
                pads: Vec::new(),
            });
            entry.islands.extend(l.islands);
            entry.cavities.extend(
                cuts.cavities
                    .iter()
                    .filter(|c| c.overlaps(l.z.bottom, l.z.top))
                    .flat_map(|c| c.outline.iter().cloned()),
            );
            if let Some(ch) = cuts.channels.get(i) {
                entry.channels.extend(ch.iter().cloned());
            }
        }
    }
    for (key, paths) in &f.extras.paths_after {
        if let Some(layer) = by_z.get_mut(key) {
            layer.traces.extend(paths.iter().map(|p| {
                let mut pts = p.points.clone();
                if p.closed
                    && let Some(first) = pts.first().copied()
                {
                    pts.push(first);
                }
                pts
            }));
        }
    }
    for part in &f.parts {
        for pad in &part.pads {
            // The layer whose top the pad sits on, within float noise.
            let key = scaled(pad.centre.z);
            if let Some((_, layer)) = by_z
                .range_mut(key.saturating_sub(1)..=key.saturating_add(1))
                .next()
            {
                layer
                    .pads
                    .push((format!("{}.{}", part.name, pad.name), pad.outline.clone()));
            }
        }
    }
    Ok(RouteView {
        layers: by_z.into_values().collect(),
        report: f.report.unwrap_or_default(),
        parts: f.parts,
    })
}

/// [`slice_scene`] with an optional circuit: its parts get cavities and placement events, its
/// nets are routed as conductive traces in carved channels on `route.conductive_tool`.
pub fn slice_scene_with(
    scene: &Scene,
    cfg: &Config,
    circuit: Option<&Electronics>,
    progress: impl FnMut(Stage),
) -> Result<(Vec<u8>, Program, SliceSummary), PipelineError> {
    slice_scene_watched(scene, cfg, circuit, progress, None)
}

/// [`slice_scene_with`], with `routing` told how far the router got.
pub fn slice_scene_watched(
    scene: &Scene,
    cfg: &Config,
    circuit: Option<&Electronics>,
    mut progress: impl FnMut(Stage),
    routing: Option<&ProgressFn>,
) -> Result<(Vec<u8>, Program, SliceSummary), PipelineError> {
    let mut laps = Laps::new();
    let Front {
        mut sliced,
        placed,
        extras,
        report,
        parts,
        cuts: _,
        meshes,
    } = front(scene, cfg, circuit, &mut progress, routing, &mut laps)?;
    let mut extras = extras;
    // Objects whose planar layers the curved tops cut into.
    let mut cut_by_tops = vec![false; sliced.len()];
    let curved = (cfg.curved.mode == CurvedMode::Tops).then(|| {
        let (inserts, report, cut) = curved_tops(&mut sliced, &meshes, cfg);
        cut_by_tops = cut;
        for ins in inserts {
            extras
                .inserts_after
                .entry(crate::geom::scaled(ins.after_z))
                .or_default()
                .push(LayerInsert {
                    tool: ins.tool,
                    items: ins.items,
                });
        }
        report
    });

    progress(Stage::Regions);
    let mut objects = Vec::with_capacity(sliced.len());
    let mut summaries = Vec::with_capacity(sliced.len());
    for (i, ((layers, report), (name, bbox))) in sliced.into_iter().zip(placed).enumerate() {
        let tool = cfg.tool_for_object(i);
        if tool >= cfg.tools.len() {
            return Err(PipelineError::UnknownTool {
                object: name,
                tool,
                tools: cfg.tools.len(),
            });
        }
        let heights: Vec<f64> = layers.iter().map(|l| l.z.height()).collect();
        let (zs, islands): (Vec<_>, Vec<_>) = layers.into_iter().map(|l| (l.z, l.islands)).unzip();
        let mut params = cfg.region_params();
        if cut_by_tops.get(i).copied().unwrap_or(false) {
            // Where the curved tops cut the planar layers, the cut leaves slivers along its edge
            // that are no wall of the model; printed as thin walls they would stand beside the
            // curved layers' nozzle closer than the planner's collision check allows for (it
            // keeps the head off the sliced islands, and a thin wall's bead reaches past them).
            // Those layers keep the classic generator without thin walls, as the planner
            // assumes.
            params.perimeter_generator = crate::region::PerimeterGenerator::Classic;
            params.thin_walls = false;
        }
        let regions = make_regions_with_heights(&islands, &heights, &params)?;
        drop(islands);
        objects.push(ObjectLayers {
            tool,
            layers: zs.into_iter().zip(regions).collect(),
        });
        summaries.push(ObjectSummary {
            name,
            tool,
            bbox,
            slice: report,
        });
    }
    laps.lap(Stage::Regions);

    progress(Stage::Program);
    let mut program = build_program_with(&objects, &extras, &cfg.program_params());
    drop(objects);
    if program.layers.iter().all(|l| l.paths().next().is_none()) {
        return Err(PipelineError::NothingToPrint {
            dropped: summaries.iter().map(|o| o.slice.open_chains_dropped).sum(),
        });
    }
    let wipe_tower =
        crate::toolpaths::add_wipe_tower(&mut program, &cfg.tower_params(), &cfg.tower_machine())?;
    laps.lap(Stage::Program);

    progress(Stage::Emit);
    let mut gcode = Vec::new();
    let stats = write_gcode(&program, &cfg.gcode_params(), &mut gcode)?;
    if let Some(e) = circuit {
        // What OctoPNP needs to answer the `M361 P<id>` events, after the program.
        let name = scene.objects.first().map_or("object", |o| o.name.as_str());
        let block = crate::circuit::octopnp::octopnp_block(&e.circuit, &parts, name);
        gcode.extend_from_slice(block.as_bytes());
    }
    laps.lap(Stage::Emit);

    let summary = SliceSummary {
        objects: summaries,
        layers: program.layers.len(),
        gcode: stats,
        stage_seconds: laps.times,
        electronics: report,
        curved,
        wipe_tower,
        parts,
    };
    Ok((gcode, program, summary))
}

/// Plans the curved tops of every object and removes what the curved layers replace from the
/// sliced islands; returns the curved layers to insert, the report, and per object whether
/// anything was removed from it.
fn curved_tops(
    sliced: &mut [(Vec<crate::slice::SlicedLayer>, SliceReport)],
    meshes: &[Mesh],
    cfg: &Config,
) -> (
    Vec<crate::curved::CurvedInsert>,
    crate::curved::CurvedReport,
    Vec<bool>,
) {
    let zs: Vec<Vec<LayerZ>> = sliced
        .iter()
        .map(|(layers, _)| layers.iter().map(|l| l.z).collect())
        .collect();
    let islands: Vec<Vec<Vec<ExPolygon>>> = sliced
        .iter()
        .map(|(layers, _)| layers.iter().map(|l| l.islands.clone()).collect())
        .collect();
    let objects: Vec<crate::curved::CurvedObject<'_>> = meshes
        .iter()
        .zip(&zs)
        .zip(&islands)
        .enumerate()
        .map(
            |(i, ((mesh, layers), islands))| crate::curved::CurvedObject {
                mesh,
                layers,
                islands,
                tool: cfg.tool_for_object(i),
            },
        )
        .collect();
    let plan = crate::curved::plan_tops(&objects, &cfg.curved_params());
    let mut cut = vec![false; sliced.len()];
    for (((layers, _), removals), cut) in sliced.iter_mut().zip(&plan.removals).zip(&mut cut) {
        for (layer, remove) in layers.iter_mut().zip(removals) {
            if !remove.is_empty() {
                layer.islands = crate::geom::difference(&layer.islands, remove);
                *cut = true;
            }
        }
    }
    (plan.inserts, plan.report, cut)
}

fn check_fits(meshes: &[Mesh], cfg: &Config) -> Result<(), PipelineError> {
    let p = &cfg.printer;
    let limits = [
        ("x", p.bed_size[0]),
        ("y", p.bed_size[1]),
        ("z", p.max_height),
    ];
    for m in meshes {
        let Some(bb) = m.bounding_box() else { continue };
        let size = bb.size();
        for (k, (axis, limit)) in limits.iter().enumerate() {
            if size[k] > *limit {
                return Err(PipelineError::TooLarge {
                    object: m.name.clone(),
                    axis,
                    size: size[k],
                    limit: *limit,
                });
            }
        }
    }
    Ok(())
}

/// One G-code file of a curved-layer print ([`slice_clfff`]).
#[derive(Debug, Clone)]
pub struct ClfffFile {
    /// The sections in it, in print order.
    pub sections: Vec<crate::curved::clfff::Section>,
    /// The G-code.
    pub gcode: Vec<u8>,
    /// The Program it was written from.
    pub program: Program,
    /// Filament, time and per-tool figures from the writer.
    pub stats: GcodeStats,
}

/// One object of a curved-layer print, for the report.
#[derive(Debug, Clone, Serialize)]
pub struct ClfffObject {
    /// The object's name.
    pub name: String,
    /// Where it ended up on the bed (raised).
    pub bbox: Option<BoundingBox>,
}

/// What a curved-layer run produced, for the JSON report.
#[derive(Debug, Clone, Serialize)]
pub struct ClfffSummary {
    /// The objects (printed together as one shell).
    pub objects: Vec<ClfffObject>,
    /// Program layers per file (planar scaffold layers and curved travel groups).
    pub layers: Vec<usize>,
    /// Writer figures per file.
    pub gcode: Vec<GcodeStats>,
    /// Wall time per stage in seconds, in stage order.
    pub stage_seconds: Vec<(Stage, f64)>,
    /// Scaffold, curved layers, collisions, sections.
    pub clfff: crate::curved::clfff::ClfffReport,
}

/// The curved-layer FFF pipeline (`curved.mode = "clfff"`): the scene centred and raised on the
/// bed, planned by [`crate::curved::clfff::plan`] (every object together as one shell, the
/// model on object 0's tool), and written as one G-code file, or one per section with
/// `curved.split_sections` (in print order: scaffold, buffer, model; with `curved.sandwich`
/// the model section holds the bottom skin, the planar core and the top skin). See
/// [`crate::curved::clfff`].
pub fn slice_clfff(
    scene: &Scene,
    cfg: &Config,
    mut progress: impl FnMut(Stage),
) -> Result<(Vec<ClfffFile>, ClfffSummary), PipelineError> {
    use crate::curved::clfff;
    let mut laps = Laps::new();
    if scene.triangle_count() == 0 {
        return Err(PipelineError::EmptyScene);
    }
    if let Some(o) = scene.objects.iter().find(|o| o.negative.is_some()) {
        return Err(PipelineError::NegativeVolumes {
            object: o.name.clone(),
            walk: "curved-layer slicing (clfff)",
        });
    }
    progress(Stage::Place);
    let mut meshes = place_on_bed(scene, cfg);
    let curved = cfg.curved_params();
    let raised = clfff::place::raise(&mut meshes, &curved);
    check_fits(&meshes, cfg)?;
    for m in &meshes {
        if let Some(bb) = m.bounding_box()
            && bb.max[2] > cfg.printer.max_height
        {
            return Err(PipelineError::TooLarge {
                object: m.name.clone(),
                axis: "z",
                size: bb.max[2],
                limit: cfg.printer.max_height,
            });
        }
    }
    let tool = cfg.tool_for_object(0);
    if tool >= cfg.tools.len() {
        return Err(PipelineError::UnknownTool {
            object: meshes.first().map(|m| m.name.clone()).unwrap_or_default(),
            tool,
            tools: cfg.tools.len(),
        });
    }
    laps.lap(Stage::Place);

    progress(Stage::Slice);
    let plan = clfff::plan(&meshes, tool, raised, &curved)?;
    laps.lap(Stage::Slice);

    progress(Stage::Program);
    let programs = clfff::sections::programs(&plan.sections, cfg.curved.split_sections);
    laps.lap(Stage::Program);

    progress(Stage::Emit);
    let writer = clfff::sections::writer_params(cfg.gcode_params());
    let mut files = Vec::with_capacity(programs.len());
    for (sections, program) in programs {
        let mut gcode = Vec::new();
        let stats = write_gcode(&program, &writer, &mut gcode)?;
        files.push(ClfffFile {
            sections,
            gcode,
            program,
            stats,
        });
    }
    laps.lap(Stage::Emit);

    let summary = ClfffSummary {
        objects: meshes
            .iter()
            .map(|m| ClfffObject {
                name: m.name.clone(),
                bbox: m.bounding_box(),
            })
            .collect(),
        layers: files.iter().map(|f| f.program.layers.len()).collect(),
        gcode: files.iter().map(|f| f.stats.clone()).collect(),
        stage_seconds: laps.times,
        clfff: plan.report,
    };
    Ok((files, summary))
}
