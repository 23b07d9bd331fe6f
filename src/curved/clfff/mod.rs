//! Curved-layer FFF (`conduit slice MODEL --curved clfff`, `curved.mode = "clfff"`): a thin
//! doubly-curved shell (a body panel, an insole top, a dish) printed in layers that follow its
//! bottom surface, on a planar scaffold, with an optional buffer layer between them; or, with
//! `curved.sandwich`, a thick part as a curved bottom skin, a planar core and a curved top skin
//! ([`sandwich`], [`core`]).
//!
//! Place in the pipeline: Scene → placed on the bed → **clfff** → Program(s) → G-code. The
//! planar slicer is not used (the sandwich's core goes through the regions and Program
//! stages); [`plan`] takes the placed meshes and returns each section's Program layers and
//! the report:
//!
//! 1. [`place`]: the shell centred on the bed, lowest point at `curved.raise` (room for
//!    scaffold);
//! 2. [`shell`] and [`outline`]: the bottom and top surfaces as height fields, the top-down
//!    outline (union of the projected triangles, holes kept), the scaffold area (convex hull of
//!    the outline grown by `curved.scaffold_margin`);
//! 3. [`scaffold`]: planar layers of lines from `curved.scaffold_vectors`, cut where they
//!    would come closer than `curved.scaffold_clearance` under the curved layers, ordered by
//!    nearest neighbour;
//! 4. [`layers`]: the buffer (`curved.buffer`, nozzle on the bottom surface) and the model's
//!    `curved.layers` layers (nozzle at surface + k·h), each an outline loop then raster lines
//!    at `curved.angles[k mod n]`, lifted onto the surface ([`lift`]) with points at every
//!    triangle edge and every `curved.step`; flow and z speed by [`crate::curved::motion`]; with a
//!    sandwich these are the bottom skin, followed by the planar [`core`] and the top skin's
//!    `curved.top_layers` layers (nozzle at top surface − (n_t − 1 − j)·h);
//! 5. [`travel`]: the curved paths grouped at long travels, each group lifted above the highest
//!    material under its travel plus `curved.travel_clearance`;
//! 6. [`sections`]: scaffold, buffer and model on their own tools in one Program, or one
//!    Program each (`curved.split_sections`);
//! 7. [`collide`]: the head model of `[curved]` replayed over the whole print, for the report.
//!
//! Everything is sequential and ordered, so the output is deterministic.

pub mod collide;
pub mod core;
pub mod densify;
pub mod layers;
pub mod lift;
pub mod outline;
pub mod place;
pub mod report;
pub mod sandwich;
pub mod scaffold;
pub mod sections;
pub mod shell;
#[cfg(test)]
mod test_meshes;
pub mod travel;

pub use report::ClfffReport;
pub use sections::{Section, SectionLayers};

use crate::curved::CurvedParams;
use crate::curved::motion;
use crate::geom::{ExPolygon, Point3};
use crate::mesh::Mesh;
use crate::program::{Event, Layer, LayerItem, Role, Toolpath};
use crate::toolpaths::{ProgramParams, RoleSpeeds};
use collide::Collisions;
use layers::{LayerSpec, LiftedLayer, lift_layer};
use outline::Rim;
use report::{CoreReport, LayerReport, PlacementReport, ScaffoldReport, SectionReport};
use sandwich::{Follows, Sandwich};
use scaffold::{Limit, Scaffold, ScaffoldParams};
use shell::Shell;
use travel::Grouper;

/// The comment that starts each curved layer in the Program (and the G-code), followed by
/// `<section> k <k> offset <offset>`.
pub const LAYER_COMMENT: &str = "clfff layer";

/// The comment that starts each scaffold layer, followed by `z <z>`.
pub const SCAFFOLD_COMMENT: &str = "clfff scaffold";

/// The comment that starts each top-skin layer of a sandwich, followed by
/// `<section> j <j> offset <offset> angle <angle>` (offset ≤ 0, from the top surface).
pub const TOP_COMMENT: &str = "clfff top";

/// The comment that starts each planar core layer of a sandwich, followed by `z <z>`.
pub const CORE_COMMENT: &str = "clfff core";

/// Why a curved-layer plan is impossible.
#[derive(Debug, thiserror::Error)]
pub enum ClfffError {
    /// The model has no surface to follow.
    ///
    /// How to fix: give a surface or a thin shell mesh; a model made only of vertical walls
    /// has no bottom surface.
    #[error("the model has no non-vertical triangles: there is no surface for curved layers")]
    NoSurface,
    /// A section is assigned a tool the config does not define.
    ///
    /// How to fix: set the key to an existing tool, or add a `[tools.N]` table.
    #[error("curved.{key} = {tool}, but the config defines {tools} tool(s)")]
    UnknownTool {
        /// `scaffold_tool` or `buffer_tool`.
        key: &'static str,
        /// The tool.
        tool: usize,
        /// How many tools the config has.
        tools: usize,
    },
    /// A sandwich was asked for a model without thickness.
    ///
    /// How to fix: give a closed solid (a bottom and a top surface); an open surface is a
    /// shell for plain curved layers (`curved.sandwich = false`).
    #[error(
        "curved.sandwich needs a solid with a bottom and a top surface; the model has no \
         thickness"
    )]
    SandwichWithoutThickness,
    /// The sandwich's planar core could not be made into regions.
    #[error("sandwich core: {0}")]
    Regions(#[from] crate::region::RegionError),
    /// The model is much thicker than the curved layers asked for, so most of it would not be
    /// printed (a solid given to plain curved layers).
    ///
    /// How to fix: `curved.layers = 0` follows the thickness; a solid part wants
    /// `curved.sandwich = true` (curved skins around a planar core).
    #[error(
        "the model is {thickness:.2} mm thick, but curved.layers = {layers} prints {printed:.2} mm \
         of it: set curved.layers = 0 to follow the thickness, or curved.sandwich = true for a \
         solid part"
    )]
    ThickerThanLayers {
        /// The shell's median thickness, mm.
        thickness: f64,
        /// `curved.layers`.
        layers: usize,
        /// What those layers print, mm.
        printed: f64,
    },
}

/// What [`plan`] produces.
#[derive(Debug, Clone, PartialEq)]
pub struct ClfffPlan {
    /// Scaffold, buffer and model, in print order (a section without paths has no layers).
    pub sections: Vec<SectionLayers>,
    /// The report.
    pub report: ClfffReport,
}

/// Plans a curved-layer print of the placed (and raised, [`place::raise`]) `meshes` with the
/// model on `tool` (see the module docs); `raised` is the lift [`place::raise`] applied.
pub fn plan(
    meshes: &[Mesh],
    tool: usize,
    raised: f64,
    cfg: &CurvedParams,
) -> Result<ClfffPlan, ClfffError> {
    check_tools(cfg)?;
    let shape = Shape::new(meshes, cfg)?;
    let limit = shape.limit(cfg);
    let scaffold = build_scaffold(&shape.area, &limit, cfg);
    let support = |x: f64, y: f64| scaffold.top_at(&limit, x, y);
    let sandwich = sandwich_of(shape.n, cfg);
    let specs = layer_specs(shape.n, sandwich.as_ref(), cfg);
    let lifted = lift_layers(&shape, specs, sandwich.as_ref(), &support, cfg);
    let made = Made {
        shape: &shape,
        scaffold: &scaffold,
        lifted: &lifted,
        sandwich: sandwich.as_ref(),
        support: &support,
    };
    let emitted = emit_sections(&made, tool, cfg)?;
    Ok(assemble_plan(&made, emitted, raised, cfg))
}

/// A support height at (x, y): the scaffold's top under a point, mm.
type Support<'a> = &'a dyn Fn(f64, f64) -> f64;

/// Refuses a scaffold or buffer tool the config does not define.
fn check_tools(cfg: &CurvedParams) -> Result<(), ClfffError> {
    let c = &cfg.curved;
    for (key, t) in [
        ("scaffold_tool", c.scaffold_tool),
        ("buffer_tool", c.buffer_tool),
    ] {
        if t >= cfg.tool_count {
            return Err(ClfffError::UnknownTool {
                key,
                tool: t,
                tools: cfg.tool_count,
            });
        }
    }
    Ok(())
}

/// The shell of the placed meshes and what its geometry gives the later steps.
struct Shape {
    /// The bottom and top surfaces.
    shell: Shell,
    /// The top-down outline (holes kept).
    out: Vec<ExPolygon>,
    /// The shell's median thickness, mm.
    thickness: f64,
    /// Number of bottom (model) layers.
    n: usize,
    /// The outline's rim heights.
    rim: Rim,
    /// The scaffold area: the outline's convex hull grown by `curved.scaffold_margin`.
    area: Vec<ExPolygon>,
}

impl Shape {
    /// Reads the surfaces and outline of `meshes` and counts the model layers (`curved.layers`,
    /// else the top skin's with a sandwich, else the thickness in layers). Errors when there
    /// is no surface, or no thickness for a sandwich.
    fn new(meshes: &[Mesh], cfg: &CurvedParams) -> Result<Self, ClfffError> {
        let c = &cfg.curved;
        let shell = Shell::from_meshes(meshes);
        let out = outline::outline(&shell);
        if shell.is_empty() || out.is_empty() {
            return Err(ClfffError::NoSurface);
        }
        let h = cfg.region.layer_height;
        let thickness = shell.median_thickness();
        if c.sandwich && thickness <= 0.0 {
            return Err(ClfffError::SandwichWithoutThickness);
        }
        let n = if c.layers > 0 {
            c.layers
        } else if c.sandwich {
            c.top_layers.max(1)
        } else {
            ((thickness / h).round() as usize).max(1)
        };
        // Plain curved layers print `n·h` over the bottom surface; a model thicker than that by
        // more than a layer is mostly left out. (A sandwich fills its thickness with the core.)
        let printed = n as f64 * h;
        if !c.sandwich && thickness > printed + h {
            return Err(ClfffError::ThickerThanLayers {
                thickness,
                layers: c.layers,
                printed,
            });
        }
        let rim = Rim::new(&out, &shell);
        let area = outline::scaffold_area(&out, c.scaffold_margin);
        Ok(Self {
            shell,
            out,
            thickness,
            n,
            rim,
            area,
        })
    }

    /// The limit the scaffold stays under: the buffer's height plus `curved.scaffold_clearance`
    /// below the bottom surface.
    fn limit(&self, cfg: &CurvedParams) -> Limit<'_> {
        let c = &cfg.curved;
        let buffer_h = if c.buffer {
            cfg.region.layer_height
        } else {
            0.0
        };
        Limit {
            shell: &self.shell,
            rim: &self.rim,
            below: buffer_h + c.scaffold_clearance,
        }
    }
}

/// The scaffold's planar layers over the scaffold area (none when `curved.scaffold` is off),
/// its first layer ordered from the bed origin.
fn build_scaffold(area: &[ExPolygon], limit: &Limit<'_>, cfg: &CurvedParams) -> Scaffold {
    let c = &cfg.curved;
    if c.scaffold {
        let p = ScaffoldParams {
            first_top: cfg.first_layer_height,
            layer_height: cfg.region.layer_height,
            vectors: c.scaffold_vectors.clone(),
            spacing: c.scaffold_spacing,
            step: c.step,
            width: cfg.region.infill_width,
        };
        scaffold::build(area, limit, &p, (cfg.bed_origin[0], cfg.bed_origin[1]))
    } else {
        Scaffold::default()
    }
}

/// The sandwich of `curved.sandwich` with `n` bottom-skin layers, or none.
fn sandwich_of(n: usize, cfg: &CurvedParams) -> Option<Sandwich> {
    let c = &cfg.curved;
    c.sandwich.then_some(Sandwich {
        h: cfg.region.layer_height,
        bottom_layers: n,
        top_layers: c.top_layers,
        first_top: cfg.first_layer_height,
        buffer: c.buffer,
    })
}

/// The specs of every curved layer in print order: the buffer, the `n` model (bottom skin)
/// layers, then a sandwich's top skin; raster angles cycle through `curved.angles`.
fn layer_specs(n: usize, sandwich: Option<&Sandwich>, cfg: &CurvedParams) -> Vec<LayerSpec> {
    let c = &cfg.curved;
    let h = cfg.region.layer_height;
    let region = &cfg.region;
    let mut specs = Vec::new();
    let angle = |i: usize| {
        c.angles
            .get(i % c.angles.len().max(1))
            .copied()
            .unwrap_or(0.0)
    };
    if c.buffer {
        specs.push(LayerSpec {
            section: Section::Buffer,
            k: 0,
            offset: 0.0,
            angle_deg: angle(0) + 90.0,
            height: h,
            loop_role: Role::Buffer,
            fill_role: Role::Buffer,
            loop_width: region.solid_infill_width,
            fill_width: region.solid_infill_width,
            lowest: true,
            surface: Follows::Bottom,
        });
    }
    for k in 1..=n {
        let top = k == n && sandwich.is_none();
        specs.push(model_spec(
            k,
            k as f64 * h,
            angle(k - 1),
            h,
            top,
            k == 1 && !c.buffer,
            Follows::Bottom,
            region,
        ));
    }
    if let Some(s) = sandwich {
        for j in 0..s.top_layers {
            let below = (s.top_layers - 1 - j) as f64 * h;
            let top = j + 1 == s.top_layers;
            specs.push(model_spec(
                j,
                -below,
                angle(n + j),
                h,
                top,
                false,
                Follows::Top,
                region,
            ));
        }
    }
    specs
}

/// Lifts every spec's flat layer onto its surface (a sandwich's skins by its own lift).
fn lift_layers(
    shape: &Shape,
    specs: Vec<LayerSpec>,
    sandwich: Option<&Sandwich>,
    support: Support<'_>,
    cfg: &CurvedParams,
) -> Vec<LiftedLayer> {
    let step = cfg.curved.step;
    specs
        .into_iter()
        .map(|spec| match sandwich {
            Some(s) if spec.section == Section::Model => {
                sandwich::lift_skin_layer(&shape.shell, &shape.out, spec, step, s, support)
            }
            _ => lift_layer(&shape.shell, &shape.out, spec, step, support),
        })
        .collect()
}

/// The sections' Program layers and what their emission reports.
struct Emitted {
    /// Scaffold, buffer and model, in print order.
    sections: Vec<SectionLayers>,
    /// Every curved layer's report, in print order.
    layers: Vec<LayerReport>,
    /// Moves whose feed the z speed limit lowered.
    z_limited: usize,
    /// The sandwich core's report.
    core: Option<CoreReport>,
}

/// The inputs of [`emit_sections`] and [`assemble_plan`] that the earlier steps made.
struct Made<'a> {
    /// The shell's shape.
    shape: &'a Shape,
    /// The scaffold.
    scaffold: &'a Scaffold,
    /// The lifted curved layers, in print order.
    lifted: &'a [LiftedLayer],
    /// The sandwich, if any.
    sandwich: Option<&'a Sandwich>,
    /// The scaffold's top at (x, y).
    support: Support<'a>,
}

/// The sections' Program layers: the scaffold's, then the buffer's and the model's curved
/// layers on their tools (a sandwich's core before its top skin), grouped at long travels.
fn emit_sections(made: &Made<'_>, tool: usize, cfg: &CurvedParams) -> Result<Emitted, ClfffError> {
    let c = &cfg.curved;
    let h = cfg.region.layer_height;
    let params = cfg.program.clone();
    let bottom_max = made.shape.shell.bottom_range().map_or(0.0, |r| r.1);
    let mut layer_reports = Vec::new();
    let mut z_limited = 0;
    let mut core_report = None;
    let mut sections = vec![scaffold_section(
        made.scaffold,
        c.scaffold_tool,
        cfg.region.infill_width,
        &params,
    )];
    for section in [Section::Buffer, Section::Model] {
        let tool_of = match section {
            Section::Buffer => c.buffer_tool,
            _ => tool,
        };
        let ctx = LayerCtx {
            shell: &made.shape.shell,
            sandwich: made.sandwich,
            support: made.support,
            tool: tool_of,
            speeds: params.tool(tool_of).speeds,
            h,
            max_z_speed: c.max_z_speed,
        };
        let mut grouper = Grouper::new(cfg.retract_before_travel, c.travel_clearance, h, None);
        grouper.check_short = made.sandwich.is_some();
        let mut first = true;
        for layer in made.lifted.iter().filter(|l| l.spec.section == section) {
            if let Some(s) = made.sandwich
                && layer.spec.surface == Follows::Top
                && core_report.is_none()
            {
                core_report = Some(emit_core(&ctx, s, cfg, &mut grouper)?);
            }
            let first_z = (first && layer.spec.surface == Follows::Bottom)
                .then(|| made.scaffold.max_z().max(bottom_max + layer.spec.offset));
            let rep = emit_curved(&ctx, layer, section, &mut grouper, first_z);
            first &= rep.paths == 0;
            z_limited += rep.z_speed_limited;
            layer_reports.push(rep);
        }
        sections.push(SectionLayers {
            section,
            tool: tool_of,
            layers: grouper.finish(),
        });
    }
    Ok(Emitted {
        sections,
        layers: layer_reports,
        z_limited,
        core: core_report,
    })
}

/// The plan: the sections and the report (placement, scaffold, every curved layer, the head
/// of `[curved]` replayed over the first Program, the sections, the core).
fn assemble_plan(made: &Made<'_>, emitted: Emitted, raised: f64, cfg: &CurvedParams) -> ClfffPlan {
    let Emitted {
        sections,
        layers,
        z_limited,
        core,
    } = emitted;
    let collisions = replay_head(&sections, cfg);
    let section_reports = section_reports(&sections);
    let report = ClfffReport {
        placement: placement_report(made.shape, raised),
        scaffold: scaffold_report(made.scaffold, cfg.curved.scaffold_tool),
        layers,
        collisions,
        z_speed_limited: z_limited,
        sections: section_reports,
        core,
    };
    ClfffPlan { sections, report }
}

/// The head model of `[curved]` replayed over the sections combined into one Program.
fn replay_head(sections: &[SectionLayers], cfg: &CurvedParams) -> Collisions {
    let c = &cfg.curved;
    let head = c.head();
    let combined = sections::programs(sections, false);
    combined
        .first()
        .map(|(_, p)| collide::replay(p, &head))
        .unwrap_or_default()
}

/// Per section with layers: its tool, Program layers, paths and their length.
fn section_reports(sections: &[SectionLayers]) -> Vec<SectionReport> {
    sections
        .iter()
        .filter(|s| !s.layers.is_empty())
        .map(|s| {
            let paths: Vec<&Toolpath> = s.layers.iter().flat_map(Layer::paths).collect();
            SectionReport {
                section: s.section,
                tool: s.tool,
                program_layers: s.layers.len(),
                paths: paths.len(),
                length_mm: paths.iter().map(|p| p.length()).sum(),
                file: None,
            }
        })
        .collect()
}

/// Where the shell stands: the lift applied, its bottom range, thickness, steepest slope,
/// outline and scaffold areas.
fn placement_report(shape: &Shape, raised: f64) -> PlacementReport {
    PlacementReport {
        raised_mm: raised,
        bottom_z: shape.shell.bottom_range().map_or([0.0; 2], |(a, b)| [a, b]),
        thickness_mm: shape.thickness,
        max_slope_deg: shape.shell.max_slope_deg(),
        outline_area_mm2: shape.out.iter().map(ExPolygon::area_mm2).sum(),
        outline_holes: shape.out.iter().map(|e| e.holes.len()).sum(),
        scaffold_area_mm2: shape.area.iter().map(ExPolygon::area_mm2).sum(),
    }
}

/// The scaffold's layers, lines, their length, its top and its cuts.
fn scaffold_report(scaffold: &Scaffold, tool: usize) -> ScaffoldReport {
    ScaffoldReport {
        tool,
        layers: scaffold.layers.len(),
        lines: scaffold.layers.iter().map(|l| l.lines.len()).sum(),
        length_mm: scaffold
            .layers
            .iter()
            .flat_map(|l| &l.lines)
            .map(|l| l.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>())
            .sum(),
        top_z: scaffold.max_z(),
        cuts: scaffold.cuts,
    }
}

/// The spec of a model layer: bottom skin layer `k` (`surface` bottom, `offset` k·h) or top
/// skin layer `k` (`surface` top, `offset` ≤ 0); `top` marks the visible top layer.
#[allow(clippy::too_many_arguments)]
fn model_spec(
    k: usize,
    offset: f64,
    angle_deg: f64,
    height: f64,
    top: bool,
    lowest: bool,
    surface: Follows,
    region: &crate::region::RegionParams,
) -> LayerSpec {
    LayerSpec {
        section: Section::Model,
        k,
        offset,
        angle_deg,
        height,
        loop_role: Role::ExternalPerimeter,
        fill_role: if top {
            Role::TopSolidInfill
        } else {
            Role::SolidInfill
        },
        loop_width: region.external_perimeter_width,
        fill_width: if top {
            region.top_solid_infill_width
        } else {
            region.solid_infill_width
        },
        lowest,
        surface,
    }
}

/// What the curved layers of one section share.
struct LayerCtx<'a> {
    shell: &'a Shell,
    sandwich: Option<&'a Sandwich>,
    support: &'a dyn Fn(f64, f64) -> f64,
    tool: usize,
    speeds: RoleSpeeds,
    h: f64,
    max_z_speed: f64,
}

impl LayerCtx<'_> {
    /// The surface `layer` follows at (x, y), mm.
    fn surface(&self, follows: Follows, x: f64, y: f64) -> Option<f64> {
        match follows {
            Follows::Bottom => self.shell.bottom(x, y),
            Follows::Top => self.shell.top(x, y),
        }
    }

    /// The highest material at (x, y) once `spec`'s layer is printed there, mm.
    fn material(&self, spec: &LayerSpec, x: f64, y: f64) -> f64 {
        let support = (self.support)(x, y);
        let here = match (self.sandwich, spec.surface) {
            (Some(s), Follows::Top) => s.column(self.shell, self.support, x, y).map(|c| {
                if spec.k >= c.top_first {
                    c.top + spec.offset
                } else {
                    c.under
                }
            }),
            _ => self.shell.bottom(x, y).map(|b| b + spec.offset),
        };
        here.map_or(0.0, |z| z).max(support)
    }
}

/// Adds one curved layer's paths to `grouper` (after its comment); `first_z` forces a group at
/// least that high for its first path. Returns the layer's report.
fn emit_curved(
    ctx: &LayerCtx<'_>,
    layer: &LiftedLayer,
    section: Section,
    grouper: &mut Grouper,
    mut first_z: Option<f64>,
) -> LayerReport {
    let spec = &layer.spec;
    let o = spec.offset;
    let material = |x: f64, y: f64| ctx.material(spec, x, y);
    let comment = match spec.surface {
        Follows::Bottom => LAYER_COMMENT,
        Follows::Top => TOP_COMMENT,
    };
    let k_name = match spec.surface {
        Follows::Bottom => "k",
        Follows::Top => "j",
    };
    grouper.event(LayerItem::Event(Event::Comment(format!(
        "{comment} {} {k_name} {} offset {:.3} angle {:.1}",
        section.name(),
        spec.k,
        o,
        spec.angle_deg
    ))));
    let mut rep = LayerReport {
        section,
        follows: spec.surface,
        k: spec.k,
        offset: o,
        angle_deg: spec.angle_deg,
        paths: 0,
        points: 0,
        max_deviation: 0.0,
        max_slope_deg: 0.0,
        planar_cusp: 0.0,
        thickness: None,
        thickness_capped: layer.capped,
        points_dropped: layer.dropped,
        z_speed_limited: 0,
    };
    let surface = |x: f64, y: f64| ctx.surface(spec.surface, x, y);
    for (piece, role, width) in &layer.pieces {
        let template = Toolpath {
            points: Vec::new(),
            closed: false,
            role: *role,
            tool: ctx.tool,
            width: *width,
            height: ctx.h,
            speed: ctx.speeds.for_role(*role),
            segments: None,
            tool_axis: None,
        };
        let (paths, stats) = motion::to_toolpaths(piece, &template, ctx.max_z_speed);
        rep.z_speed_limited += stats.z_limited;
        if let Some((lo, hi)) = stats.thickness {
            rep.thickness = Some(match rep.thickness {
                Some((a, b)) => (a.min(lo), b.max(hi)),
                None => (lo, hi),
            });
        }
        // A state change repeats a point: its zero-length piece extrudes nothing.
        for p in paths.into_iter().filter(|p| p.length() > 0.0) {
            rep.paths += 1;
            rep.points += p.points.len();
            rep.max_deviation = rep.max_deviation.max(deviation(&p, &surface, o));
            for q in &p.points {
                let slope = match spec.surface {
                    Follows::Bottom => ctx.shell.bottom_slope_deg(q.x, q.y),
                    Follows::Top => ctx.shell.top_slope_deg(q.x, q.y),
                };
                if let Some(s) = slope {
                    rep.max_slope_deg = rep.max_slope_deg.max(s);
                }
            }
            grouper.path(p, &material, first_z.take());
        }
    }
    rep.planar_cusp = ctx.h * rep.max_slope_deg.to_radians().cos();
    rep
}

/// Adds the sandwich's planar core to `grouper` (each layer after its comment), starting where
/// the grouper's nozzle is. Returns the core's report.
fn emit_core(
    ctx: &LayerCtx<'_>,
    s: &Sandwich,
    cfg: &CurvedParams,
    grouper: &mut Grouper,
) -> Result<CoreReport, ClfffError> {
    let start = grouper
        .position()
        .unwrap_or_else(|| Point3::new(cfg.bed_origin[0], cfg.bed_origin[1], 0.0));
    let layers = core::layers(ctx.shell, s, cfg, ctx.tool, start, ctx.support)?;
    let mut rep = CoreReport {
        skin_layers: [s.bottom_layers, s.top_layers],
        layers: layers.len(),
        z: layers.first().zip(layers.last()).map(|(a, b)| [a.z, b.z]),
        max_area_mm2: layers.iter().map(|l| l.area_mm2).fold(0.0, f64::max),
        paths: 0,
        length_mm: 0.0,
        thickened_paths: 0,
    };
    for layer in layers {
        grouper.event(LayerItem::Event(Event::Comment(format!(
            "{CORE_COMMENT} z {:.3}",
            layer.z
        ))));
        // The bottom skin stands higher than the core layer beside the core's islands.
        let material = |x: f64, y: f64| {
            s.column(ctx.shell, ctx.support, x, y)
                .map_or(0.0, |c| c.bottom + c.bottom_count as f64 * s.h)
                .max(layer.z)
                .max((ctx.support)(x, y))
        };
        rep.thickened_paths += layer.thickened;
        for p in layer.paths {
            rep.paths += 1;
            rep.length_mm += p.length();
            grouper.path(p, &material, None);
        }
    }
    Ok(rep)
}

/// The scaffold's planar layers as Program layers.
fn scaffold_section(
    scaffold: &Scaffold,
    tool: usize,
    width: f64,
    params: &ProgramParams,
) -> SectionLayers {
    let tp = params.tool(tool);
    let layers = scaffold
        .layers
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let mut speed = tp.speeds.for_role(Role::Scaffold);
            if i == 0 {
                speed = speed.min(tp.first_layer_speed);
            }
            let mut items = vec![LayerItem::Event(Event::Comment(format!(
                "{SCAFFOLD_COMMENT} z {:.3}",
                l.z
            )))];
            items.extend(l.lines.iter().map(|pts| {
                LayerItem::Path(Toolpath {
                    points: pts.clone(),
                    closed: false,
                    role: Role::Scaffold,
                    tool,
                    width,
                    height: l.height,
                    speed,
                    segments: None,
                    tool_axis: None,
                })
            }));
            Layer {
                index: i,
                z: l.z,
                height: l.height,
                items,
            }
        })
        .collect();
    SectionLayers {
        section: Section::Scaffold,
        tool,
        layers,
    }
}

/// Largest distance of a path's points and segment midpoints from `surface` + `offset`.
fn deviation(path: &Toolpath, surface: &dyn Fn(f64, f64) -> Option<f64>, offset: f64) -> f64 {
    let off = |p: Point3| surface(p.x, p.y).map_or(0.0, |s| (p.z - (s + offset)).abs());
    let mut worst = path.points.iter().map(|&p| off(p)).fold(0.0, f64::max);
    for w in path.points.windows(2) {
        worst = worst.max(off(Point3::from((w[0].coords + w[1].coords) / 2.0)));
    }
    worst
}
