//! The host's layers rebuilt from its G-code: where each layer starts and ends in the file, its
//! z and height, the machine state it runs in, and its extrusions as polylines with role and
//! width.
//!
//! Place in the pipeline: after [`super::host`] and the host's settings (which give the run's
//! config, and with it these [`LayerParams`]); its [`HostLayer`]s are
//! what the electronics stages work on in post-processing mode (the printed regions per layer
//! come from [`super::regions`]), and their line ranges tell where to edit the file.
//!
//! # Layers
//!
//! With layer comments ([`super::HostInfo::markers`] not empty), a layer starts at its marker
//! line and runs to the next layer's first line; the last layer runs to the end of the file,
//! and the lines before the first marker are the [`HostLayers::preamble`] (start G-code, purge
//! lines — their extrusions belong to no layer). Two markers of different conventions with no
//! extrusion between them (OrcaSlicer may write `; CHANGE_LAYER` and `;LAYER_CHANGE` together)
//! start one layer.
//!
//! Without layer comments (Slic3r 1.3, hand-written G-code) a layer is a run of extrusions at
//! one Z (to [`Z_TOLERANCE`]) in file order; it starts at the last move that changed Z before
//! its first extrusion (the layer change) when that move comes after the previous layer's last
//! extrusion, otherwise right after that extrusion.
//!
//! A layer's z is its comment's (`;Z:`, `; Z_HEIGHT:`) when there is one, otherwise the Z of its
//! first extrusion (Cura moves to the next layer's Z before its `;LAYER:` comment). Its height is
//! its comment's (`;HEIGHT:`, `; LAYER_HEIGHT:`), otherwise the rise from the layer below (z
//! itself for the first layer).
//!
//! # Extrusions
//!
//! An extruding move names X or Y and increases E (as `conduit check` counts them). Consecutive
//! extruding moves form one [`ExtrusionPath`] while they join end to start and keep the tool,
//! feature and width; travels, retractions and tool changes end a path. Arcs are sampled as in
//! [`conduit_gcode::Move::path`]. A path's width is the latest `;WIDTH:` / `; LINE_WIDTH:`
//! comment when the host writes them; otherwise it is worked out from the flow: the filament
//! volume `E·π·d²/4` over the path length is the bead's cross-section, and the bead model of
//! [`crate::program::extrusion`] (a rounded rectangle of the layer's height; a round thread for
//! bridges) gives the width. Extrusions at an unknown X or Y (before any absolute move or
//! homing) cannot be placed and are only counted ([`HostLayers::unplaced_extrusions`]).

use std::ops::Range;
use std::sync::Arc;

use conduit_gcode::{Gcode, Line, Machine, Move};
use serde::Serialize;

use super::comments::{HostComment, LayerMarker, read_comment};
use super::host::Host;
use super::roles::role_of;
use crate::geom::Point3;
use crate::program::Role;
use crate::program::extrusion::{BeadShape, filament_area};
use crate::program::machine::{Flavor, Printer, Tool, ToolKind};

/// Two extrusion heights closer than this are the same layer (without layer comments), mm.
pub const Z_TOLERANCE: f64 = 0.000_5;

/// Smallest and largest climb of a spiral's layer, mm (see `follow_z`).
const SPIRAL_MIN_STEP: f64 = 0.05;
const SPIRAL_MAX_STEP: f64 = 1.0;

/// Feed rate of the replay before the file's first `F`, mm/s (Marlin's 1500 mm/min).
const DEFAULT_FEEDRATE: f64 = 25.0;

/// What the layer reconstruction needs to know about the printer. Built by the walk from the
/// run's config (`crate::config::Config::host_layer_params`).
#[derive(Debug, Clone, PartialEq)]
pub struct LayerParams {
    /// Firmware dialect, for the effect of `G90`/`G91` on E.
    pub flavor: Flavor,
    /// Filament diameter per tool, mm, for widths worked out from the flow; `None` for tools
    /// that push no filament (paste). Tools past the end use 1.75 mm filament.
    pub filament_diameters: Vec<Option<f64>>,
    /// Width given to extrusions whose width neither a comment nor the flow tells, mm.
    pub fallback_width: f64,
    /// The bead cross-section the host computes E with, for widths worked out from the flow:
    /// a rounded rectangle for PrusaSlicer and its descendants (their `Flow` model), a
    /// rectangle for Cura (`line width × layer height`). Bridges are round threads whatever
    /// this says.
    pub bead: BeadShape,
}

impl LayerParams {
    /// The parameters of a machine with firmware `flavor` and `tools` (filament diameters of
    /// the filament tools), with `fallback_width` (the perimeter width) for extrusions whose
    /// width nothing tells, and PrusaSlicer's bead model.
    pub fn new(flavor: Flavor, tools: &[Tool], fallback_width: f64) -> Self {
        Self {
            flavor,
            filament_diameters: tools
                .iter()
                .map(|t| (t.kind == ToolKind::Filament).then_some(t.filament_diameter))
                .collect(),
            fallback_width,
            bead: BeadShape::RoundedRectangle,
        }
    }

    /// These parameters with the bead model of `host` (see [`LayerParams::bead`]).
    pub fn for_host(mut self, host: Host) -> Self {
        self.bead = match host {
            Host::Cura => BeadShape::Rectangle,
            _ => BeadShape::RoundedRectangle,
        };
        self
    }

    fn filament_diameter(&self, tool: usize) -> Option<f64> {
        self.filament_diameters
            .get(tool)
            .copied()
            .unwrap_or(Some(1.75))
            .filter(|d| *d > 0.0)
    }
}

impl Default for LayerParams {
    /// The default machine (a Marlin printer with a filament tool and a paste tool) and the
    /// regions stage's default perimeter width: the parameters of the default config.
    fn default() -> Self {
        Self::new(
            Printer::default().flavor,
            &[Tool::filament(), Tool::paste()],
            crate::region::RegionParams::default().perimeter_width,
        )
    }
}

/// How E values are read in a layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum EMode {
    /// Absolute E (`M82`, the firmware default).
    Absolute,
    /// Relative E (`M83`, or `G91` where the flavour makes E follow it).
    Relative,
}

/// How the host retracts filament before travels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum RetractionStyle {
    /// Firmware retraction: `G10` to retract, `G11` to recover; the firmware knows the length.
    Firmware,
    /// E moves without X or Y (`G1 E-0.8 F2100`).
    Extruder {
        /// Filament pulled back, mm.
        length: f64,
        /// Speed of the retraction, mm/s of filament.
        speed: f64,
    },
}

/// Where a layer's z came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum ZSource {
    /// The host's comment (`;Z:`, `; Z_HEIGHT:`, Simplify3D's marker).
    Comment,
    /// The Z of the layer's first extrusion.
    Moves,
    /// Neither: a layer without extrusions takes the z of the layer below (0 for the first).
    Inherited,
}

/// Where an extrusion's width came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum WidthSource {
    /// The host's `;WIDTH:` / `; LINE_WIDTH:` comment.
    Comment,
    /// Worked out from E, the path length, the layer height and the filament diameter.
    Flow,
    /// [`LayerParams::fallback_width`]: no comment, and no filament flow to measure.
    Fallback,
}

/// One extruding move of an [`ExtrusionPath`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathMove {
    /// The move's line: an index into [`Gcode::lines`] (0-based; [`Line::number`] is one more).
    pub line: usize,
    /// Index in [`ExtrusionPath::points`] of the move's end; it starts at the previous move's
    /// end (or at point 0). Arcs take several points.
    pub end: usize,
    /// Filament pushed by the move, mm of E.
    pub e: f64,
    /// Length of the move, mm.
    pub length: f64,
}

/// Consecutive extruding moves with one tool, feature and width: a polyline with a role and a
/// width.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtrusionPath {
    /// The active tool.
    pub tool: usize,
    /// conduit's role for the host's feature ([`super::role_of`]); `None` for features conduit
    /// has no role for (support, wipe tower, ironing) and when the host names none.
    pub role: Option<Role>,
    /// The host's feature name as written (`External perimeter`, `WALL-OUTER`, `infill`).
    pub host_role: Option<Arc<str>>,
    /// Bead width, mm.
    pub width: f64,
    /// Where [`width`](Self::width) came from.
    pub width_source: WidthSource,
    /// The polyline: the first move's start, then the end of every move (arcs sampled), mm.
    pub points: Vec<Point3>,
    /// The moves, in order.
    pub moves: Vec<PathMove>,
}

impl ExtrusionPath {
    /// Length of the path, mm.
    pub fn length(&self) -> f64 {
        self.moves.iter().map(|m| m.length).sum()
    }

    /// Filament pushed along the path, mm of E.
    pub fn e(&self) -> f64 {
        self.moves.iter().map(|m| m.e).sum()
    }

    /// The lines of the path's first and last moves (indices into [`Gcode::lines`]).
    pub fn line_span(&self) -> Option<(usize, usize)> {
        Some((self.moves.first()?.line, self.moves.last()?.line))
    }
}

/// The extrusion width of one host feature in a layer.
#[derive(Debug, Clone, PartialEq)]
pub struct RoleWidth {
    /// The host's feature name as written; `None` for extrusions before any feature comment.
    pub host_role: Option<String>,
    /// conduit's role for it.
    pub role: Option<Role>,
    /// Length-weighted mean width of the feature's paths, mm.
    pub width: f64,
    /// Total length of the feature's paths, mm.
    pub length: f64,
}

/// One layer of the host's print.
#[derive(Debug, Clone, PartialEq)]
pub struct HostLayer {
    /// 0-based position among the rebuilt layers, in file order.
    pub index: usize,
    /// The host's own number for the layer (Cura's `;LAYER:n`, Slic3r's and Simplify3D's), when
    /// its marker carries one.
    pub host_number: Option<i64>,
    /// Print z (top of the layer, where the nozzle is), mm.
    pub z: f64,
    /// Where [`z`](Self::z) came from.
    pub z_source: ZSource,
    /// Layer height, mm.
    pub height: f64,
    /// The layer's lines: indices into [`Gcode::lines`] (see the [module docs](self)).
    pub lines: Range<usize>,
    /// The line of the layer's first extruding move.
    pub first_extrusion_line: Option<usize>,
    /// The line of the layer's last extruding move: traces for the layer go after it.
    pub last_extrusion_line: Option<usize>,
    /// E mode at the layer's first extrusion (at its start when it has none).
    pub e_mode: EMode,
    /// The active tool when the layer starts.
    pub tool_at_start: usize,
    /// Tools that extrude in the layer, in order of first use.
    pub tools: Vec<usize>,
    /// The first retraction in the layer.
    pub retraction: Option<RetractionStyle>,
    /// The extrusions, in file order.
    pub paths: Vec<ExtrusionPath>,
    /// The width of each feature, sorted by feature name (extrusions without one first).
    pub widths: Vec<RoleWidth>,
}

impl HostLayer {
    /// The length-weighted mean width of the layer's extrusions of `role`, mm.
    pub fn width_of(&self, role: Role) -> Option<f64> {
        let (mut sum, mut length) = (0.0, 0.0);
        for w in self.widths.iter().filter(|w| w.role == Some(role)) {
            sum += w.width * w.length;
            length += w.length;
        }
        (length > 0.0).then(|| sum / length)
    }
}

/// How the layers were found.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub enum LayerMethod {
    /// From the host's layer comments.
    Comments(Vec<LayerMarker>),
    /// From the Z heights of extrusions (no layer comments).
    ZHeights,
}

/// The host's print as layers.
#[derive(Debug, Clone, PartialEq)]
pub struct HostLayers {
    /// The layers, in file order.
    pub layers: Vec<HostLayer>,
    /// The lines before the first layer (all of them when there is no layer).
    pub preamble: Range<usize>,
    /// How the layers were found.
    pub method: LayerMethod,
    /// The layer count the host announces (`;LAYER_COUNT:`, `; total layer number:`).
    pub declared_layer_count: Option<usize>,
    /// Extruding moves at an unknown X or Y, which belong to no path.
    pub unplaced_extrusions: usize,
}

impl HostLayers {
    /// Every tool that extrudes in a layer, sorted.
    pub fn tools(&self) -> Vec<usize> {
        let mut tools: Vec<usize> = self
            .layers
            .iter()
            .flat_map(|l| l.tools.iter().copied())
            .collect();
        tools.sort_unstable();
        tools.dedup();
        tools
    }

    /// The E modes of the layers with extrusions, sorted, each once (two for a file that
    /// switches).
    pub fn e_modes(&self) -> Vec<EMode> {
        let mut modes = Vec::new();
        for layer in self.layers.iter().filter(|l| !l.paths.is_empty()) {
            if !modes.contains(&layer.e_mode) {
                modes.push(layer.e_mode);
            }
        }
        modes.sort_by_key(|m| *m == EMode::Relative);
        modes
    }

    /// The first retraction of the print.
    pub fn retraction(&self) -> Option<RetractionStyle> {
        self.layers.iter().find_map(|l| l.retraction)
    }
}

/// Rebuilds the layers of `gcode`. `markers` are the layer-change conventions the file uses
/// ([`super::HostInfo::markers`]); without any, layers come from Z heights (see the
/// [module docs](self)).
///
/// ```
/// use conduit::postprocess::{LayerParams, detect_host, read_layers};
/// let g = conduit_gcode::parse(b"G28\n;LAYER_CHANGE\n;Z:0.2\n;HEIGHT:0.2\nG1 Z0.2\n;TYPE:Perimeter\n;WIDTH:0.45\nG1 X10 E1\nG1 Y10 E2\n")?;
/// let host = detect_host(&g);
/// let layers = read_layers(&g, &host.markers, &LayerParams::default());
/// assert_eq!(layers.layers.len(), 1);
/// let layer = &layers.layers[0];
/// assert_eq!((layer.z, layer.height, layer.lines.clone()), (0.2, 0.2, 1..9));
/// assert_eq!(layer.paths[0].points.len(), 3);
/// assert_eq!(layer.paths[0].width, 0.45);
/// # Ok::<(), conduit_gcode::GcodeError>(())
/// ```
pub fn read_layers(gcode: &Gcode, markers: &[LayerMarker], params: &LayerParams) -> HostLayers {
    let mut walk = Walk {
        by_comments: !markers.is_empty(),
        machine: Machine::new(params.flavor, DEFAULT_FEEDRATE),
        done: Vec::new(),
        current: None,
        feature: None,
        move_feature: None,
        width: None,
        last_z_change: None,
        declared_count: None,
        unplaced: 0,
    };
    for (index, line) in gcode.lines.iter().enumerate() {
        walk.line(index, line);
    }
    let total = gcode.lines.len();
    let mut built: Vec<LayerBuilder> = walk.done;
    built.extend(walk.current.take());
    let preamble = 0..built.first().map_or(total, |b| b.start);
    let ends: Vec<usize> = built
        .iter()
        .skip(1)
        .map(|b| b.start)
        .chain(std::iter::once(total))
        .collect();
    let mut layers: Vec<HostLayer> = Vec::with_capacity(built.len());
    for (index, (builder, end)) in built.into_iter().zip(ends).enumerate() {
        let below = layers.last().map(|l| (l.z, l.height));
        layers.push(builder.finish(index, end, below, params));
    }
    HostLayers {
        layers,
        preamble,
        method: if markers.is_empty() {
            LayerMethod::ZHeights
        } else {
            LayerMethod::Comments(markers.to_vec())
        },
        declared_layer_count: walk.declared_count,
        unplaced_extrusions: walk.unplaced,
    }
}

/// A path being built: its moves' host state, the width comment in force, and the polyline.
struct OpenPath {
    path: ExtrusionPath,
    width_comment: Option<f64>,
}

/// A layer being built.
struct LayerBuilder {
    start: usize,
    markers: Vec<LayerMarker>,
    host_number: Option<i64>,
    declared_z: Option<f64>,
    declared_height: Option<f64>,
    first_extrusion: Option<(usize, Option<f64>)>,
    last_extrusion: Option<usize>,
    e_relative: bool,
    tool_at_start: usize,
    tools: Vec<usize>,
    retraction: Option<RetractionStyle>,
    paths: Vec<OpenPath>,
    open: Option<OpenPath>,
}

impl LayerBuilder {
    fn new(start: usize, machine: &Machine) -> Self {
        Self {
            start,
            markers: Vec::new(),
            host_number: None,
            declared_z: None,
            declared_height: None,
            first_extrusion: None,
            last_extrusion: None,
            e_relative: machine.e_is_relative(),
            tool_at_start: machine.tool(),
            tools: Vec::new(),
            retraction: None,
            paths: Vec::new(),
            open: None,
        }
    }

    fn close_path(&mut self) {
        if let Some(open) = self.open.take() {
            self.paths.push(open);
        }
    }

    /// Appends an extruding move at a known XY to the open path, or starts a new path.
    fn extrude(
        &mut self,
        index: usize,
        mv: &Move,
        host_role: Option<&Arc<str>>,
        width_comment: Option<f64>,
        xy: [f64; 2],
    ) {
        let points: Vec<Point3> = mv
            .path
            .iter()
            .filter_map(|p| match p {
                [Some(x), Some(y), z] => Some(Point3::new(*x, *y, z.unwrap_or(0.0))),
                _ => None,
            })
            .collect();
        let Some(&start) = points.first() else {
            return;
        };
        let joins = self.open.as_ref().is_some_and(|o| {
            let last = o.path.points.last().copied();
            o.path.tool == mv.tool
                && o.path.host_role.as_ref() == host_role
                && o.width_comment == width_comment
                && last.is_some_and(|p| (p - start).norm() < 1e-9)
        });
        if !joins {
            self.close_path();
            self.open = Some(OpenPath {
                path: ExtrusionPath {
                    tool: mv.tool,
                    role: host_role.and_then(|r| role_of(r)),
                    host_role: host_role.cloned(),
                    width: 0.0,
                    width_source: WidthSource::Fallback,
                    points: vec![start],
                    moves: Vec::new(),
                },
                width_comment,
            });
        }
        if let Some(open) = self.open.as_mut() {
            let path = &mut open.path;
            path.points.extend(points.iter().skip(1));
            if points.len() < 2 {
                // A move whose arc could not be sampled still ends somewhere.
                path.points.push(Point3::new(xy[0], xy[1], start.z));
            }
            path.moves.push(PathMove {
                line: index,
                end: path.points.len() - 1,
                e: mv.e,
                length: mv.length,
            });
        }
        if !self.tools.contains(&mv.tool) {
            self.tools.push(mv.tool);
        }
    }

    fn finish(
        mut self,
        index: usize,
        end: usize,
        below: Option<(f64, f64)>,
        params: &LayerParams,
    ) -> HostLayer {
        self.close_path();
        let extrusion_z = self.first_extrusion.and_then(|(_, z)| z);
        let (z, z_source) = match (self.declared_z, extrusion_z) {
            (Some(z), _) => (z, ZSource::Comment),
            (None, Some(z)) => (z, ZSource::Moves),
            (None, None) => (below.map_or(0.0, |b| b.0), ZSource::Inherited),
        };
        let rise = round_micrometres(z - below.map_or(0.0, |b| b.0));
        let height = match self.declared_height {
            Some(h) if h > 0.0 => h,
            _ if rise > 0.0 => rise,
            _ => below.map_or(z, |b| b.1),
        };
        let paths: Vec<ExtrusionPath> = self
            .paths
            .into_iter()
            .map(|open| with_width(open, height, params))
            .collect();
        let widths = role_widths(&paths);
        HostLayer {
            index,
            host_number: self.host_number,
            z,
            z_source,
            height,
            lines: self.start..end.max(self.start),
            first_extrusion_line: self.first_extrusion.map(|(line, _)| line),
            last_extrusion_line: self.last_extrusion,
            e_mode: if self.e_relative {
                EMode::Relative
            } else {
                EMode::Absolute
            },
            tool_at_start: self.tool_at_start,
            tools: self.tools,
            retraction: self.retraction,
            paths,
            widths,
        }
    }
}

/// Rounds to 1 nm so that `0.4 − 0.2` reads as 0.2.
fn round_micrometres(mm: f64) -> f64 {
    (mm * 1e6).round() / 1e6
}

/// Gives a finished path its width: the comment's, else the flow's, else the fallback.
fn with_width(open: OpenPath, height: f64, params: &LayerParams) -> ExtrusionPath {
    let mut path = open.path;
    if let Some(w) = open.width_comment {
        path.width = w;
        path.width_source = WidthSource::Comment;
        return path;
    }
    let (length, e) = (path.length(), path.e());
    let from_flow = params
        .filament_diameter(path.tool)
        .filter(|_| length > 0.0 && e > 0.0)
        .map(|d| {
            let area = e * filament_area(d) / length;
            let shape = match path.role {
                Some(Role::BridgeInfill) => BeadShape::Round,
                _ => params.bead,
            };
            shape.width_for_area(area, height)
        })
        .filter(|w| w.is_finite() && *w > 0.0);
    match from_flow {
        Some(w) => {
            path.width = w;
            path.width_source = WidthSource::Flow;
        }
        None => {
            path.width = params.fallback_width;
            path.width_source = WidthSource::Fallback;
        }
    }
    path
}

/// Length-weighted mean width per host feature, sorted by feature name.
fn role_widths(paths: &[ExtrusionPath]) -> Vec<RoleWidth> {
    let mut out: Vec<RoleWidth> = Vec::new();
    for p in paths {
        let name = p.host_role.as_deref().map(str::to_owned);
        let length = p.length();
        match out.iter_mut().find(|w| w.host_role == name) {
            Some(w) => {
                w.width += p.width * length;
                w.length += length;
            }
            None => out.push(RoleWidth {
                host_role: name,
                role: p.role,
                width: p.width * length,
                length,
            }),
        }
    }
    for w in &mut out {
        w.width = if w.length > 0.0 {
            w.width / w.length
        } else {
            0.0
        };
    }
    out.sort_by(|a, b| a.host_role.cmp(&b.host_role));
    out
}

/// The state of one walk through the file.
struct Walk {
    by_comments: bool,
    machine: Machine,
    done: Vec<LayerBuilder>,
    current: Option<LayerBuilder>,
    /// The feature from the latest `;TYPE:` / `; FEATURE:` comment.
    feature: Option<Arc<str>>,
    /// The latest per-move feature (Slic3r), kept to share one allocation between moves.
    move_feature: Option<Arc<str>>,
    /// The width from the latest `;WIDTH:` / `; LINE_WIDTH:` comment.
    width: Option<f64>,
    /// The latest motion line that changed Z.
    last_z_change: Option<usize>,
    declared_count: Option<usize>,
    unplaced: usize,
}

impl Walk {
    fn open_layer(&mut self, start: usize) {
        if let Some(mut done) = self.current.take() {
            done.close_path();
            self.done.push(done);
        }
        self.current = Some(LayerBuilder::new(start, &self.machine));
    }

    fn line(&mut self, index: usize, line: &Line) {
        let mut this_move_feature: Option<Arc<str>> = None;
        if line.comment.is_some() {
            match read_comment(line) {
                Some(HostComment::LayerStart { marker, number, z }) if self.by_comments => {
                    let opens = self
                        .current
                        .as_ref()
                        .is_none_or(|c| c.first_extrusion.is_some() || c.markers.contains(&marker));
                    if opens {
                        self.open_layer(index);
                    }
                    if let Some(layer) = self.current.as_mut() {
                        layer.markers.push(marker);
                        layer.host_number = layer.host_number.or(number);
                        layer.declared_z = layer.declared_z.or(z);
                    }
                }
                Some(HostComment::Z(z)) => {
                    if let Some(layer) = self.current.as_mut() {
                        layer.declared_z = layer.declared_z.or(Some(z));
                    }
                }
                Some(HostComment::Height(h)) => {
                    if let Some(layer) = self.current.as_mut() {
                        layer.declared_height = layer.declared_height.or(Some(h));
                    }
                }
                Some(HostComment::Feature(name)) => {
                    if self.feature.as_deref() != Some(name) {
                        self.feature = Some(Arc::from(name));
                    }
                }
                Some(HostComment::Width(w)) => self.width = Some(w),
                Some(HostComment::LayerCount(n)) => {
                    self.declared_count = self.declared_count.or(Some(n));
                }
                Some(HostComment::MoveRole(name)) => {
                    if self.move_feature.as_deref() != Some(name) {
                        self.move_feature = Some(Arc::from(name));
                    }
                    this_move_feature = self.move_feature.clone();
                }
                Some(HostComment::LayerStart { .. }) | None => {}
            }
        }
        if is_firmware_retraction(line) {
            if let Some(layer) = self.current.as_mut() {
                layer.retraction.get_or_insert(RetractionStyle::Firmware);
                layer.close_path();
            }
        }
        let tool_before = self.machine.tool();
        let Some(mv) = self.machine.step(line) else {
            if self.machine.tool() != tool_before {
                if let Some(layer) = self.current.as_mut() {
                    layer.close_path();
                }
            }
            return;
        };
        if mv.from[2] != mv.to[2] {
            self.last_z_change = Some(index);
        }
        if !mv.extruding {
            if let Some(layer) = self.current.as_mut() {
                layer.close_path();
                if !mv.has_xy && mv.e < 0.0 {
                    layer.retraction.get_or_insert(RetractionStyle::Extruder {
                        length: -mv.e,
                        speed: mv.feed,
                    });
                }
            }
            return;
        }
        if !self.by_comments {
            // An extrusion that climbs while it prints is a spiral (vase mode, FullControl).
            let spiral = matches!((mv.from[2], mv.to[2]), (Some(a), Some(b)) if b > a);
            self.follow_z(index, mv.to[2], spiral);
        }
        let e_relative = self.machine.e_is_relative();
        let feature = this_move_feature.or_else(|| self.feature.clone());
        let width = self.width;
        let Some(layer) = self.current.as_mut() else {
            // Extrusion before the first layer comment: start G-code, purge lines.
            return;
        };
        if layer.first_extrusion.is_none() {
            layer.first_extrusion = Some((index, mv.to[2]));
            layer.e_relative = e_relative;
        }
        layer.last_extrusion = Some(index);
        match (mv.to[0], mv.to[1], mv.from[0], mv.from[1]) {
            (Some(x), Some(y), Some(_), Some(_)) => {
                layer.extrude(index, &mv, feature.as_ref(), width, [x, y]);
            }
            _ => {
                layer.close_path();
                self.unplaced += 1;
            }
        }
    }

    /// Without layer comments: opens a new layer when an extrusion leaves the current one's Z;
    /// on a `spiral`, one that climbs while it prints, only once it has climbed a layer's
    /// thickness (taken as the first layer's Z, within 0.05..=1 mm), so a vase gives one layer
    /// per turn rather than one per move.
    fn follow_z(&mut self, index: usize, z: Option<f64>, spiral: bool) {
        let current_z = self
            .current
            .as_ref()
            .map(|c| c.first_extrusion.and_then(|(_, z)| z));
        let first_z = self
            .done
            .first()
            .or(self.current.as_ref())
            .and_then(|l| l.first_extrusion)
            .and_then(|(_, z)| z);
        let step = first_z.map_or(SPIRAL_MIN_STEP, |z| {
            z.clamp(SPIRAL_MIN_STEP, SPIRAL_MAX_STEP)
        });
        let opens = match (current_z, z) {
            (None, _) => true,
            (Some(Some(a)), Some(b)) if spiral => b - a >= step - Z_TOLERANCE,
            (Some(Some(a)), Some(b)) => (a - b).abs() > Z_TOLERANCE,
            (Some(None), Some(_)) => true,
            (Some(_), None) => false,
        };
        if !opens {
            return;
        }
        let previous_end = self
            .current
            .as_ref()
            .and_then(|c| c.last_extrusion)
            .map(|l| l + 1);
        let start = match (self.last_z_change, previous_end) {
            (Some(change), Some(after)) if change >= after => change,
            (_, Some(after)) => after,
            (Some(change), None) => change,
            (None, None) => index,
        };
        self.open_layer(start.min(index));
    }
}

/// `G10` as firmware retraction (not RepRapFirmware's `G10 P<tool>` temperatures and offsets
/// or `G10 L<n>` work coordinates).
fn is_firmware_retraction(line: &Line) -> bool {
    line.is_command(b'G', 10) && line.get(b'P').is_none() && line.get(b'L').is_none()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::postprocess::detect_host;

    fn layers_of(text: &str) -> HostLayers {
        let g = match conduit_gcode::parse(text.as_bytes()) {
            Ok(g) => g,
            Err(e) => panic!("test input parses: {e}"),
        };
        let host = detect_host(&g);
        read_layers(
            &g,
            &host.markers,
            &LayerParams::default().for_host(host.host),
        )
    }

    #[test]
    fn orca_comment_set() {
        let file = "\
; generated by OrcaSlicer 2.1.1 on 2026-01-01 at 10:00:00
; total layer number: 2
M83
G28
; CHANGE_LAYER
; Z_HEIGHT: 0.2
; LAYER_HEIGHT: 0.2
;LAYER_CHANGE
;Z:0.2
G1 E-.8 F1800
G1 X10 Y10 Z0.2 F30000
G1 E.8 F1800
; FEATURE: Outer wall
; LINE_WIDTH: 0.42
G1 X20 Y10 E.5
G1 X20 Y20 E.5
; FEATURE: Sparse infill
; LINE_WIDTH: 0.45
G1 X10 Y20 E.5
; CHANGE_LAYER
; Z_HEIGHT: 0.4
; LAYER_HEIGHT: 0.2
G10
G1 Z0.4
G11
; FEATURE: Inner wall
G1 X10 Y10 E.5
T1
G1 X12 Y10 E.1
";
        let l = layers_of(file);
        assert_eq!(
            l.method,
            LayerMethod::Comments(vec![LayerMarker::LayerChange, LayerMarker::ChangeLayer])
        );
        assert_eq!(l.declared_layer_count, Some(2));
        assert_eq!(l.layers.len(), 2);
        let (a, b) = (&l.layers[0], &l.layers[1]);
        assert_eq!((a.z, a.height, a.z_source), (0.2, 0.2, ZSource::Comment));
        assert_eq!(a.lines, 4..19);
        assert_eq!(b.lines, 19..29);
        assert_eq!(l.preamble, 0..4);
        assert_eq!(a.e_mode, EMode::Relative);
        assert_eq!(
            a.retraction,
            Some(RetractionStyle::Extruder {
                length: 0.8,
                speed: 30.0
            })
        );
        assert_eq!(b.retraction, Some(RetractionStyle::Firmware));
        assert_eq!(a.paths.len(), 2);
        assert_eq!(a.paths[0].role, Some(Role::ExternalPerimeter));
        assert_eq!(a.paths[0].width, 0.42);
        assert_eq!(a.paths[0].points.len(), 3);
        assert_eq!(a.paths[0].line_span(), Some((14, 15)));
        assert_eq!(a.width_of(Role::SparseInfill), Some(0.45));
        assert_eq!(
            a.widths
                .iter()
                .map(|w| w.host_role.as_deref())
                .collect::<Vec<_>>(),
            vec![Some("Outer wall"), Some("Sparse infill")]
        );
        assert_eq!(b.tools, vec![0, 1]);
        assert_eq!(b.paths.len(), 2, "a tool change ends a path");
        assert_eq!(b.paths[1].tool, 1);
        assert_eq!(b.last_extrusion_line, Some(28));
        assert_eq!(l.tools(), vec![0, 1]);
    }

    #[test]
    fn cura_comment_set() {
        let file = "\
;FLAVOR:Marlin
;Layer height: 0.2
;Generated with Cura_SteamEngine 4.13.0
M82 ;absolute extrusion mode
G28
G92 E0
G1 F1500 E-6.5
;LAYER_COUNT:2
;LAYER:0
;MESH:cube.stl
G0 F3600 X10 Y10 Z0.3
;TYPE:WALL-OUTER
G1 F1500 E0
G1 F1800 X20 Y10 E0.4
G1 X20 Y20 E0.8
;TYPE:SKIN
G1 X10 Y20 E1.2
;MESH:NONMESH
G0 F600 X10 Y20 Z0.5
;TIME_ELAPSED:10
;LAYER:1
;TYPE:WALL-INNER
;MESH:cube.stl
G1 F1800 X10 Y10 E1.6
;End of Gcode
";
        let l = layers_of(file);
        assert_eq!(
            l.method,
            LayerMethod::Comments(vec![LayerMarker::LayerNumber])
        );
        assert_eq!(l.declared_layer_count, Some(2));
        assert_eq!(l.layers.len(), 2);
        let (a, b) = (&l.layers[0], &l.layers[1]);
        assert_eq!((a.host_number, b.host_number), (Some(0), Some(1)));
        assert_eq!((a.z, a.height, a.z_source), (0.3, 0.3, ZSource::Moves));
        assert_eq!((b.z, b.height), (0.5, 0.2));
        assert_eq!(a.e_mode, EMode::Absolute);
        assert_eq!(a.paths[0].role, Some(Role::ExternalPerimeter));
        assert_eq!(a.paths[1].role, Some(Role::SolidInfill));
        assert_eq!(b.paths[0].role, Some(Role::Perimeter));
        // 0.4 mm of 1.75 mm filament over 10 mm at 0.3 mm height, Cura's rectangular bead.
        let expected = 0.4 * filament_area(1.75) / 10.0 / 0.3;
        assert!((a.paths[0].width - expected).abs() < 1e-9);
        assert_eq!(a.paths[0].width_source, WidthSource::Flow);
        assert_eq!(a.lines, 8..20);
    }

    #[test]
    fn a_spiral_gives_one_layer_per_turn() {
        // A first layer at z 0.2, then three turns of a square spiral, each climbing 0.2 mm in
        // four moves of 0.05 mm.
        let mut file = String::from("G28\nM83\nG1 Z0.2 F600\nG1 X0 Y0\nG1 X10 Y0 E1\n");
        let corners = [(10.0, 10.0), (0.0, 10.0), (0.0, 0.0), (10.0, 0.0)];
        let mut z = 0.2;
        for _ in 0..3 {
            for (x, y) in corners {
                z += 0.05;
                file.push_str(&format!("G1 X{x} Y{y} Z{z:.2} E0.5\n"));
            }
        }
        let l = layers_of(&file);
        assert_eq!(l.method, LayerMethod::ZHeights);
        let zs: Vec<f64> = l.layers.iter().map(|l| l.z).collect();
        assert_eq!(zs.len(), 4, "{zs:?}");
        // Each turn's layer starts where it has climbed 0.2 mm over the one before.
        for pair in zs.windows(2) {
            assert!((pair[1] - pair[0] - 0.2).abs() < 1e-9, "{zs:?}");
        }
    }

    #[test]
    fn layers_from_z_without_comments() {
        let file = "\
; generated by Slic3r 1.3.0 on 2026-01-01 at 10:00:00
G28
M82
G92 E0
G1 Z0.200 F7800.000
G1 X1 Y1
G1 X2 Y1 E1.0
G1 X2 Y2 E2.0
G1 E1.5 F2400
G1 Z0.800
G1 X3 Y3
G1 Z0.400
G1 E2.0
G1 X4 Y3 E2.5
";
        let l = layers_of(file);
        assert_eq!(l.method, LayerMethod::ZHeights);
        assert_eq!(l.layers.len(), 2);
        let (a, b) = (&l.layers[0], &l.layers[1]);
        assert_eq!(a.lines, 4..11);
        assert_eq!(b.lines, 11..14);
        assert_eq!((a.z, b.z, b.height), (0.2, 0.4, 0.2));
        assert_eq!(a.z_source, ZSource::Moves);
        assert_eq!(
            a.retraction,
            Some(RetractionStyle::Extruder {
                length: 0.5,
                speed: 40.0
            })
        );
        assert_eq!(a.paths.len(), 1);
        assert_eq!(a.paths[0].moves.len(), 2);
        assert_eq!(l.preamble, 0..4);
    }

    #[test]
    fn unknown_positions_and_empty_files_do_not_panic() {
        let l = layers_of("G91\nG1 X1 E1\nG1 X1 E1\n");
        assert_eq!(l.layers.len(), 1);
        assert_eq!(l.unplaced_extrusions, 2);
        assert!(l.layers[0].paths.is_empty());
        let l = layers_of("");
        assert!(l.layers.is_empty());
        assert_eq!(l.preamble, 0..0);
    }
}
