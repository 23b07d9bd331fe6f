//! One G-code file as the 3D view draws it: its moves grouped into GPU line buffers, its layers
//! with their times, retraction and z-hop markers, part events and the job's figures.
//!
//! Place in the pipeline: reads what `conduit check` reads (the parsed G-code, its replayed
//! [`Moves`] and the [`CheckReport`]) and hands [`JobView`] to [`super::page`].
//!
//! - A *group* is one feature role (the latest `;TYPE:`/`; FEATURE:` comment) and tool, or the
//!   travels of a tool: one line buffer in the page. Its moves are cut into *runs* of
//!   connected segments of one layer; runs are sorted by layer (stably, so file order stays
//!   within a layer), which lets the page show a layer range as one draw range per buffer.
//! - Every segment carries its feed (0.1 mm/s) and width (µm, 0 when the file gives none), so
//!   the page can colour by speed and width; a layer's time is the sum of the time estimate of
//!   its moves, from the same motion model as `conduit check`'s total.
//! - Positions are the replayed ones at their true Z: curved and conformal paths are not
//!   flattened. Arcs come as the replay samples them (every 10° at most).

use std::collections::HashMap;

use conduit_gcode::{Gcode, Move, Moves};
use serde::Serialize;

use super::encode::{PositionStream, RunStream, varints_base64};
use crate::check::{CheckParams, CheckReport, Machine, Severity, check, moves_on};
use crate::emit::preview::{CUSTOM_ROLE, UNNAMED_ROLE, layered_by_markers, role_colour, tint};
use conduit_gcode::events::{PartEvent, part_events};
use conduit_pnp::octopnp::{OctoPart, read_block};

/// Role name of the travel groups.
pub const TRAVEL_ROLE: &str = "Travel";
/// Feeds are stored in tenths of mm/s.
const FEED_UNITS_PER_MM_S: f64 = 10.0;

/// One line buffer: the segments of one role and tool (or the travels of one tool).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroupView {
    /// Feature role as the file names it, or [`TRAVEL_ROLE`].
    pub role: String,
    /// Tool number.
    pub tool: usize,
    /// Travels (drawn thin, hidden by default).
    pub travel: bool,
    /// Colour by feature, `#rrggbb`: the previews' role colour tinted per tool.
    pub colour: String,
    /// Segments in the buffer.
    pub segments: usize,
    /// Vertices (segments + runs).
    pub vertices: usize,
    /// Vertex positions, µm deltas (see [`super::encode`]).
    pub positions: String,
    /// Runs as varint pairs (layer, vertex count), sorted by layer.
    pub runs: String,
    /// Feed of each segment, 0.1 mm/s, run-length encoded.
    pub feed: String,
    /// Width of each segment, µm (0: not given), run-length encoded.
    pub width: String,
}

/// One printed layer.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayerView {
    /// Layer height, mm.
    pub z: f64,
    /// Estimated time of its moves, s.
    pub time: f64,
}

/// Point markers (retractions, z-hops): positions and the layer of each.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct MarkerView {
    /// How many.
    pub count: usize,
    /// Positions, µm deltas.
    pub positions: String,
    /// Layer of each, varints.
    pub layers: String,
}

/// A part event with the layer it happens in.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventView {
    /// The event as the file gives it.
    #[serde(flatten)]
    pub event: PartEvent,
    /// 0-based layer it is placed before: the layer of the next extruding move.
    pub layer: usize,
}

/// A part of the file's OctoPNP block, as the page draws it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BlockPart {
    /// Part name.
    pub name: String,
    /// Outline on the bed, mm.
    pub outline: Vec<[f64; 2]>,
    /// Seating plane, mm.
    pub z: f64,
    /// Body height, mm.
    pub height: f64,
}

impl BlockPart {
    fn of(p: &OctoPart) -> Self {
        Self {
            name: p.name.clone(),
            outline: p.outline_on_bed(),
            z: p.destination[2],
            height: p.height,
        }
    }
}

/// Tool usage line of the figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ToolFigure {
    /// Tool number.
    pub tool: usize,
    /// Filament (or paste) extruded, mm.
    pub filament_mm: f64,
    /// The same as a volume, mm³.
    pub filament_mm3: f64,
}

/// The job's figures for the side panel, from `conduit check`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Figures {
    /// Lines in the file.
    pub lines: usize,
    /// Printed layers.
    pub layers: usize,
    /// Estimated print time, s.
    pub time_s: f64,
    /// Filament per tool.
    pub tools: Vec<ToolFigure>,
    /// Extrusion path length, mm.
    pub print_mm: f64,
    /// Travel path length, mm.
    pub travel_mm: f64,
    /// Retractions.
    pub retractions: usize,
    /// Tool changes.
    pub tool_changes: usize,
    /// Error-level findings.
    pub errors: usize,
    /// Warning-level findings.
    pub warnings: usize,
}

/// Everything the page shows of one G-code file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JobView {
    /// File name shown in the page.
    pub name: String,
    /// Printed layers, bottom up.
    pub layers: Vec<LayerView>,
    /// Line buffers, extrusions first (by role order of appearance, then tool), travels last.
    pub groups: Vec<GroupView>,
    /// Retractions (E decreasing without XY motion), at the nozzle.
    pub retractions: MarkerView,
    /// Z-hops: Z-only lifts that come down again before the next extrusion.
    pub zhops: MarkerView,
    /// Part events, in file order.
    pub events: Vec<EventView>,
    /// Parts of the file's OctoPNP block (conduit's G-code with machine-placed parts).
    pub parts: Vec<BlockPart>,
    /// Figures for the side panel.
    pub figures: Figures,
    /// Findings and notes to list: `line N: message` (errors first).
    pub warnings: Vec<String>,
    /// Extent of the extrusions: [min x, min y, min z, max x, max y, max z], mm (start and end
    /// G-code's `Custom` role only when nothing else extrudes).
    pub bounds: [f64; 6],
}

/// Most findings listed in the panel.
const MAX_LISTED: usize = 50;

/// A connected piece of one group inside one layer.
struct Run {
    layer: usize,
    points: Vec<[f64; 3]>,
    feed: Vec<u64>,
    width: Vec<u64>,
}

#[derive(Default)]
struct GroupBuild {
    runs: Vec<Run>,
}

/// The view of `gcode` replayed as `conduit check` replays it with `params` (layers numbered
/// as the previews number them), or `None` when no move has X or Y: nothing to draw.
pub fn job_of(name: &str, gcode: &Gcode, params: &CheckParams) -> Option<JobView> {
    let machine = Machine::new(params.flavor, 25.0).with_home(params.home);
    let replay = layered_by_markers(gcode, moves_on(gcode, machine));
    if replay.moves.iter().all(|m| !m.has_xy) {
        return None;
    }
    Some(job_view(name, gcode, &replay, &check(gcode, params)))
}

/// Builds the view of one file. `moves` are the replayed moves of `gcode` (layered as the
/// previews layer them), `report` its check.
pub fn job_view(name: &str, gcode: &Gcode, moves: &Moves, report: &CheckReport) -> JobView {
    let mut keys: Vec<(Option<String>, usize)> = Vec::new();
    // Extrusion roles in order of first appearance: the index picks a palette colour.
    let mut roles: Vec<String> = Vec::new();
    let mut groups: Vec<GroupBuild> = Vec::new();
    let mut last_group: Option<usize> = None;
    let mut part_box: Option<[f64; 6]> = None;
    let mut custom_box: Option<[f64; 6]> = None;
    for m in &moves.moves {
        let Some(points) = known_path(m, moves) else {
            last_group = None;
            continue;
        };
        let role = m
            .extruding
            .then(|| m.role.as_deref().unwrap_or(UNNAMED_ROLE).to_owned());
        if let Some(r) = &role {
            let frame = if r == CUSTOM_ROLE {
                &mut custom_box
            } else {
                &mut part_box
            };
            for p in &points {
                let b = frame.get_or_insert([p[0], p[1], p[2], p[0], p[1], p[2]]);
                for k in 0..3 {
                    b[k] = b[k].min(p[k]);
                    b[k + 3] = b[k + 3].max(p[k]);
                }
            }
        }
        if let Some(r) = role.as_ref().filter(|r| !roles.contains(r)) {
            roles.push(r.clone());
        }
        let key = (role, m.tool);
        let g = match keys.iter().position(|k| *k == key) {
            Some(i) => i,
            None => {
                keys.push(key);
                groups.push(GroupBuild::default());
                keys.len() - 1
            }
        };
        let feed = (m.feed * FEED_UNITS_PER_MM_S).round().max(0.0) as u64;
        let width = m
            .width
            .filter(|w| m.extruding && w.is_finite() && *w > 0.0)
            .map_or(0, |w| (w * 1000.0).round() as u64);
        let runs = &mut groups[g].runs;
        let continues = last_group == Some(g)
            && runs
                .last()
                .is_some_and(|r| r.layer == m.layer && r.points.last() == points.first());
        if !continues {
            runs.push(Run {
                layer: m.layer,
                points: vec![points[0]],
                feed: Vec::new(),
                width: Vec::new(),
            });
        }
        if let Some(run) = runs.last_mut() {
            for p in &points[1..] {
                run.points.push(*p);
                run.feed.push(feed);
                run.width.push(width);
            }
        }
        last_group = Some(g);
    }
    // Extrusions first in role order of appearance, travels last; then by tool.
    let mut order: Vec<usize> = (0..keys.len()).collect();
    order.sort_by_key(|&i| (keys[i].0.is_none(), i));
    let mut group_views = Vec::with_capacity(keys.len());
    for i in order {
        let (role, tool) = &keys[i];
        let mut runs = std::mem::take(&mut groups[i].runs);
        runs.retain(|r| r.points.len() >= 2);
        if runs.is_empty() {
            continue;
        }
        runs.sort_by_key(|r| r.layer);
        let colour = match role {
            Some(name) => tint(
                role_colour(name, roles.iter().position(|r| r == name).unwrap_or(0)),
                *tool,
            ),
            None => crate::emit::preview::TRAVEL_COLOUR,
        };
        group_views.push(encode_group(
            role.as_deref().unwrap_or(TRAVEL_ROLE),
            *tool,
            role.is_none(),
            colour,
            &runs,
        ));
    }

    let layers = layer_times(moves, report);
    let (retractions, zhops) = markers(moves);
    let events = events(gcode, moves);
    let mut warnings: Vec<String> = Vec::new();
    let parts = match read_block(gcode.lines.iter().map(|l| &l.text[..])) {
        Ok(parts) => parts.iter().map(BlockPart::of).collect(),
        Err(e) => {
            warnings.push(e);
            Vec::new()
        }
    };
    let mut findings: Vec<_> = report.findings.iter().collect();
    findings.sort_by_key(|f| (f.severity != Severity::Error, f.line));
    for f in findings.iter().take(MAX_LISTED) {
        let level = match f.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        warnings.push(format!("{level}: line {}: {}", f.line, f.message));
    }
    if findings.len() > MAX_LISTED {
        warnings.push(format!(
            "… and {} more (conduit check lists them all)",
            findings.len() - MAX_LISTED
        ));
    }
    let s = &report.stats;
    JobView {
        name: name.to_owned(),
        layers,
        groups: group_views,
        retractions,
        zhops,
        events,
        parts,
        figures: Figures {
            lines: s.lines,
            layers: moves.layer_z.len(),
            time_s: s.estimated_time_s,
            tools: s
                .tools
                .iter()
                .map(|t| ToolFigure {
                    tool: t.tool,
                    filament_mm: t.filament_mm,
                    filament_mm3: t.filament_mm3,
                })
                .collect(),
            print_mm: s.print_distance_mm,
            travel_mm: s.travel_distance_mm,
            retractions: s.retractions,
            tool_changes: s.tool_changes,
            errors: report.errors,
            warnings: report.warnings,
        },
        warnings,
        bounds: part_box.or(custom_box).unwrap_or([0.0; 6]),
    }
}

/// The path of a move with X or Y, every coordinate known (Z the layer's where the file leaves
/// it unknown); `None` for a move without X or Y, or when X or Y is unknown somewhere.
fn known_path(m: &Move, moves: &Moves) -> Option<Vec<[f64; 3]>> {
    if !m.has_xy {
        return None;
    }
    let layer_z = moves.layer_z.get(m.layer).copied().unwrap_or(0.0);
    let points: Option<Vec<[f64; 3]>> = m
        .path
        .iter()
        .map(|p| Some([p[0]?, p[1]?, p[2].unwrap_or(layer_z)]))
        .collect();
    points.filter(|p| p.len() >= 2)
}

fn encode_group(role: &str, tool: usize, travel: bool, colour: [u8; 3], runs: &[Run]) -> GroupView {
    let mut positions = PositionStream::default();
    let mut feed = RunStream::default();
    let mut width = RunStream::default();
    let mut segments = 0;
    for r in runs {
        for p in &r.points {
            positions.push(*p);
        }
        for (&f, &w) in r.feed.iter().zip(&r.width) {
            feed.push(f);
            width.push(w);
        }
        segments += r.points.len() - 1;
    }
    GroupView {
        role: role.to_owned(),
        tool,
        travel,
        colour: format!("#{:02x}{:02x}{:02x}", colour[0], colour[1], colour[2]),
        segments,
        vertices: positions.len(),
        positions: positions.base64(),
        runs: varints_base64(
            runs.iter()
                .flat_map(|r| [r.layer as u64, r.points.len() as u64]),
        ),
        feed: feed.base64(),
        width: width.base64(),
    }
}

/// Each layer's Z and the summed time estimate of its moves.
fn layer_times(moves: &Moves, report: &CheckReport) -> Vec<LayerView> {
    let mut layers: Vec<LayerView> = moves
        .layer_z
        .iter()
        .map(|&z| LayerView { z, time: 0.0 })
        .collect();
    // A file that never extrudes (a CNC program, travels only) has its moves in layer 0.
    if layers.is_empty() {
        layers.push(LayerView { z: 0.0, time: 0.0 });
    }
    let layer_of: HashMap<usize, usize> = moves.moves.iter().map(|m| (m.line, m.layer)).collect();
    for (line, t) in &report.move_times {
        if let Some(l) = layer_of.get(line).and_then(|&i| layers.get_mut(i)) {
            l.time += t;
        }
    }
    layers
}

/// Retractions and z-hops.
fn markers(moves: &Moves) -> (MarkerView, MarkerView) {
    let mut retract = (PositionStream::default(), Vec::new());
    let mut hop = (PositionStream::default(), Vec::new());
    // A lift waiting to see whether it comes down before the next extrusion.
    let mut lift: Option<([f64; 3], usize)> = None;
    for m in &moves.moves {
        let at = match m.to {
            [Some(x), Some(y), Some(z)] => [x, y, z],
            _ => continue,
        };
        if m.extruding {
            lift = None;
            continue;
        }
        if !m.has_xy && m.e < 0.0 {
            retract.0.push(at);
            retract.1.push(m.layer as u64);
        }
        let dz = match (m.from[2], m.to[2]) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        if !m.has_xy && dz > 1e-4 {
            lift = Some((at, m.layer));
        } else if dz < -1e-4
            && let Some((p, layer)) = lift.take()
        {
            hop.0.push(p);
            hop.1.push(layer as u64);
        }
    }
    let view = |(s, layers): (PositionStream, Vec<u64>)| MarkerView {
        count: s.len(),
        positions: s.base64(),
        layers: varints_base64(layers),
    };
    (view(retract), view(hop))
}

/// Part events with the layer each is placed before: the layer of the next extruding move
/// (the one printed over the part), as the previews place them.
fn events(gcode: &Gcode, moves: &Moves) -> Vec<EventView> {
    part_events(gcode)
        .into_iter()
        .map(|event| EventView {
            layer: moves.next_extruding_layer(event.line),
            event,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::{CheckParams, check};
    use conduit_gcode::{Firmware, moves};

    /// Two layers of a 10 mm square (perimeter, then T1 infill on layer 2), a retraction, a
    /// z-hop that comes back down, and a pick-and-place marker before layer 2.
    const GCODE: &str = "G28\nG90\nM82\nG92 E0\nG1 Z0.2 F600\nG1 X10 Y10 F6000\n\
        ;TYPE:Perimeter\n;WIDTH:0.45\nG1 X20 Y10 E1 F1200\nG1 X20 Y20 E2\nG1 X10 Y20 E3\n\
        G1 E2 F2400\nG1 Z0.6 F600\nG1 X10 Y10 F6000\nG1 Z0.4 F600\n\
        ;PICK_AND_PLACE PART=R1 X=15 Y=15 Z=0.4 ROTATION=90\nT1\nG1 E3 F2400\n\
        ;TYPE:Internal infill\nG1 X20 Y20 E4 F1200\n";

    #[test]
    fn groups_layers_markers_and_events_follow_the_file() {
        let g = conduit_gcode::parse(GCODE.as_bytes()).expect("parses");
        let m = moves(&g, Firmware::Marlin);
        let report = check(&g, &CheckParams::default());
        let job = job_view("t.gcode", &g, &m, &report);
        assert_eq!(
            job.layers.iter().map(|l| l.z).collect::<Vec<_>>(),
            [0.2, 0.4]
        );
        let groups: Vec<(&str, usize, bool, usize)> = job
            .groups
            .iter()
            .map(|g| (g.role.as_str(), g.tool, g.travel, g.segments))
            .collect();
        assert_eq!(
            groups,
            [
                ("Perimeter", 0, false, 3),
                ("Internal infill", 1, false, 1),
                ("Travel", 0, true, 2)
            ]
        );
        assert_eq!(job.groups[0].colour, "#e6b800");
        // Layer times add up to the estimate (no dwells here).
        let sum: f64 = job.layers.iter().map(|l| l.time).sum();
        assert!((sum - report.stats.estimated_time_s).abs() < 1e-9, "{sum}");
        assert!(job.layers.iter().all(|l| l.time > 0.0));
        assert_eq!((job.retractions.count, job.zhops.count), (1, 1));
        assert_eq!(job.events.len(), 1);
        assert_eq!(
            (job.events[0].event.part.as_str(), job.events[0].layer),
            ("R1", 1)
        );
        assert_eq!(job.bounds, [10.0, 10.0, 0.2, 20.0, 20.0, 0.4]);
        assert_eq!(job.figures.layers, 2);
    }
}
