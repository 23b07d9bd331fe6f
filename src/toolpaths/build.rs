//! From regions to a [`Program`]: toolpaths with roles, widths, heights and speeds, in print
//! order, with tool changes between tools.
//!
//! # What [`build_program`] does
//!
//! - **Layers.** The layers of all objects are merged by print height (`LayerZ::top`, compared
//!   on the nanometre grid): objects sliced with the same schedule merge layer index by layer
//!   index, and objects with different schedules interleave in z order instead of being printed
//!   at the wrong height. Program layer `k` is the `k`-th distinct height; its `height` is the
//!   largest of its objects' layer heights (each toolpath keeps its own).
//! - **Tools.** On each layer the paths of one tool print together, so a layer has at most one
//!   change per tool used on it: the tool left active by the previous layer goes first, then the
//!   others in ascending order (a two-tool print alternates `T0 T1 | T1 T0 | T0 T1 …`, one
//!   change per layer). An [`Event::ToolChange`] is inserted wherever the tool differs from the
//!   previous path's; the program's first tool is implied ([`Program::first_tool`]), not an
//!   event.
//! - **Order within a tool.** The skirt first (outermost loop first, as the regions stage
//!   gives it), then the islands nearest-first; each island prints its perimeter loops hole by
//!   hole — the loops around one hole (or around the outside) together, in the regions stage's
//!   order (inner to outer by default), the holes nearest-first — and then its solid and sparse
//!   infill in travel order ([`super::order`]). Infill lines belong to the island whose outer loop
//!   contains their first point (the smallest such loop); lines outside every loop (islands too
//!   thin for perimeters) form one more group per object.
//! - **Seams.** A perimeter or skirt loop starts at the vertex chosen by
//!   [`OrderParams::seam`]: by default the vertex nearest to where the nozzle is
//!   ([`SeamRule::Nearest`](super::order::SeamRule::Nearest)); the config's
//!   `slice.seam_position` picks [`SeamRule::Aligned`](super::order::SeamRule::Aligned).
//! - **Seam gap.** Perimeter loops (not the skirt, not a paste tool's traces) end
//!   [`ProgramParams::seam_gap`] short of their start.
//! - **Overhangs.** Perimeter paths are cut where their bead hangs out over the layer below
//!   by another degree, each piece at its degree's speed and role, and runs of bridges and
//!   overhangs get the bridge fan ([`super::overhang`]).
//! - **Travels.** A travel between two paths of an island that stays inside its internal
//!   infill is marked so that the writer does not retract for it ([`super::travel`]).
//! - **Speeds and widths.** Per tool ([`ToolPathParams`]): perimeters keep the width the
//!   regions stage gave each loop; infill and skirt take the tool's widths; every path on the
//!   program's first layer is printed at `first_layer_speed`.
//!
//! The nozzle position carries from one layer to the next, so layers are built one after the
//! other; everything is deterministic (ordered maps, index tie-breaks, no clocks).

use std::collections::BTreeMap;

use super::order::{Group, OrderParams, order_groups};
use super::overhang::{OverhangParams, split_paths, with_fan_events};
use super::travel::{InsideArea, TravelParams, mark_inside_travels};
use crate::geom::{Point2, Point3, Polygon, scaled, segment_distance2, unscaled};
use crate::program::extrusion::BeadShape;
use crate::program::{Event, Layer, LayerExtras, LayerInsert, LayerItem, Program, Role, Toolpath};
use crate::region::gapfill::split_by_width;
use crate::region::{LayerRegions, PerimeterLoop, SolidRole};
use crate::slice::LayerZ;

/// The layers of one object (or one material of an object), printed with one tool.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectLayers {
    /// Tool index.
    pub tool: usize,
    /// Each layer's place in z and its regions, bottom to top.
    pub layers: Vec<(LayerZ, LayerRegions)>,
}

/// Feed rates per role, mm/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoleSpeeds {
    /// External perimeters. Default 25.
    pub external_perimeter: f64,
    /// Inner perimeters. Default 45.
    pub perimeter: f64,
    /// Internal and bottom solid infill. Default 40.
    pub solid_infill: f64,
    /// Top solid infill. Default 30.
    pub top_solid_infill: f64,
    /// Sparse infill, scaffold and buffer. Default 80.
    pub sparse_infill: f64,
    /// Bridge infill. Default 60.
    pub bridge: f64,
    /// Gap fill. Default 20.
    pub gap_fill: f64,
    /// Skirt and brim. Default 30.
    pub skirt: f64,
    /// Support material base. Default 50.
    pub support: f64,
    /// Support material interface. Default 40.
    pub support_interface: f64,
    /// Conductive traces and drops. Default 10.
    pub conductive: f64,
}

impl Default for RoleSpeeds {
    /// The defaults of `[slice]` in the config.
    fn default() -> Self {
        Self {
            external_perimeter: 25.0,
            perimeter: 45.0,
            solid_infill: 40.0,
            top_solid_infill: 30.0,
            sparse_infill: 80.0,
            bridge: 60.0,
            gap_fill: 20.0,
            skirt: 30.0,
            support: 50.0,
            support_interface: 40.0,
            conductive: 10.0,
        }
    }
}

impl RoleSpeeds {
    /// The speed of `role`, mm/s ([`Role::Custom`] moves at the perimeter speed).
    pub fn for_role(&self, role: Role) -> f64 {
        match role {
            Role::ExternalPerimeter => self.external_perimeter,
            Role::Perimeter | Role::Custom => self.perimeter,
            Role::SolidInfill | Role::BottomSolidInfill => self.solid_infill,
            Role::BridgeInfill | Role::OverhangPerimeter => self.bridge,
            Role::GapFill => self.gap_fill,
            Role::TopSolidInfill => self.top_solid_infill,
            Role::SparseInfill | Role::Scaffold | Role::Buffer | Role::WipeTower => {
                self.sparse_infill
            }
            Role::Skirt => self.skirt,
            Role::Support => self.support,
            Role::SupportInterface => self.support_interface,
            Role::ConductiveTrace | Role::ConductiveDrop => self.conductive,
            Role::JetWall | Role::JetFill => self.conductive,
        }
    }

    /// Every speed limited to `max` mm/s.
    pub fn clamped(self, max: f64) -> Self {
        Self {
            external_perimeter: self.external_perimeter.min(max),
            perimeter: self.perimeter.min(max),
            solid_infill: self.solid_infill.min(max),
            top_solid_infill: self.top_solid_infill.min(max),
            sparse_infill: self.sparse_infill.min(max),
            bridge: self.bridge.min(max),
            gap_fill: self.gap_fill.min(max),
            skirt: self.skirt.min(max),
            support: self.support.min(max),
            support_interface: self.support_interface.min(max),
            conductive: self.conductive.min(max),
        }
    }
}

/// How one tool's regions become toolpaths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolPathParams {
    /// Speeds per role.
    pub speeds: RoleSpeeds,
    /// Speed of every path on the program's first layer, mm/s. Default 20.
    pub first_layer_speed: f64,
    /// When set, every path of this tool gets this role (e.g. [`Role::ConductiveTrace`] for a
    /// paste tool, whose regions are traces, not walls and infill) and its speed.
    pub role: Option<Role>,
}

impl Default for ToolPathParams {
    /// Default speeds, no role override.
    fn default() -> Self {
        Self {
            speeds: RoleSpeeds::default(),
            first_layer_speed: 20.0,
            role: None,
        }
    }
}

/// Parameters of [`build_program`].
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramParams {
    /// Per tool, indexed by tool number; tools past the end use [`ToolPathParams::default`].
    pub tools: Vec<ToolPathParams>,
    /// Travel ordering and seam placement.
    pub order: OrderParams,
    /// Nozzle position before the first layer (for the first travel), mm. Default the origin.
    pub start: Point3,
    /// Largest deviation (mm) allowed when dropping vertices of region paths
    /// (Douglas–Peucker), PrusaSlicer's `gcode_resolution`: sliced meshes carry vertices far
    /// closer than any printer resolves. 0 keeps every vertex. Default 0.0125.
    pub resolution: f64,
    /// How far short of its start each perimeter loop ends, mm
    /// ([`Toolpath::clip_loop_end`]). Default 0: loops close.
    pub seam_gap: f64,
    /// Perimeters over air and the bridge fan ([`super::overhang`]).
    pub overhang: OverhangParams,
    /// Which travels need no retraction ([`super::travel`]).
    pub travel: TravelParams,
}

impl Default for ProgramParams {
    fn default() -> Self {
        Self {
            tools: Vec::new(),
            order: OrderParams::default(),
            start: Point3::origin(),
            resolution: DEFAULT_RESOLUTION_MM,
            seam_gap: 0.0,
            overhang: OverhangParams::default(),
            travel: TravelParams::default(),
        }
    }
}

/// Default [`ProgramParams::resolution`], mm (PrusaSlicer's default `gcode_resolution`).
pub const DEFAULT_RESOLUTION_MM: f64 = 0.0125;

/// `points` with every vertex dropped that lies within `tolerance` nm of the simplified chain
/// (Douglas–Peucker, iterative, exact integer inputs). A closed ring keeps its first vertex and
/// is simplified as the chain from it back to itself.
pub fn simplify(points: &[Point2], tolerance: i64, closed: bool) -> Vec<Point2> {
    if tolerance <= 0 || points.len() < 3 {
        return points.to_vec();
    }
    let mut chain = points.to_vec();
    if closed {
        chain.push(points[0]);
    }
    let n = chain.len();
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    let tol2 = (tolerance as f64) * (tolerance as f64);
    let mut stack = vec![(0usize, n - 1)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (pa, pb) = (chain[a], chain[b]);
        let mut worst = (a, -1.0f64);
        for (i, &p) in chain.iter().enumerate().take(b).skip(a + 1) {
            let d2 = segment_distance2(p, pa, pb);
            if d2 > worst.1 {
                worst = (i, d2);
            }
        }
        if worst.1 > tol2 {
            keep[worst.0] = true;
            stack.push((a, worst.0));
            stack.push((worst.0, b));
        }
    }
    if closed {
        keep.pop();
        chain.pop();
    }
    let out: Vec<Point2> = chain
        .into_iter()
        .zip(keep)
        .filter_map(|(p, k)| k.then_some(p))
        .collect();
    // A ring needs three vertices to stay a ring.
    if closed && out.len() < 3 {
        points.to_vec()
    } else {
        out
    }
}

impl ProgramParams {
    /// The parameters of tool `tool`.
    pub fn tool(&self, tool: usize) -> ToolPathParams {
        self.tools.get(tool).copied().unwrap_or_default()
    }
}

fn point3(p: Point2, z: f64) -> Point3 {
    Point3::new(unscaled(p.x), unscaled(p.y), z)
}

/// Largest thickness difference (mm) within one gap-fill path: a printer changes flow only per
/// move, and PrusaSlicer's `variable_width` splits at about the same step.
const GAP_WIDTH_TOLERANCE_MM: f64 = 0.05;

/// One object's layer, with what is needed to make its toolpaths.
struct Entry<'a> {
    object: usize,
    tool: usize,
    top: f64,
    regions: &'a LayerRegions,
}

/// Makes toolpaths of one role for one object layer.
struct PathMaker {
    /// Simplification tolerance, nm.
    tolerance: i64,
    z: f64,
    height: f64,
    tool: usize,
    params: ToolPathParams,
    first_layer: bool,
}

impl PathMaker {
    fn path(&self, points: Vec<Point3>, closed: bool, role: Role, width: f64) -> Toolpath {
        let role = self.params.role.unwrap_or(role);
        let speed = if self.first_layer {
            self.params.first_layer_speed
        } else {
            self.params.speeds.for_role(role)
        };
        Toolpath {
            points,
            closed,
            role,
            tool: self.tool,
            width,
            height: self.height,
            speed,
            segments: None,
            tool_axis: None,
        }
    }

    fn points(&self, pts: &[Point2], closed: bool) -> Vec<Point3> {
        simplify(pts, self.tolerance, closed)
            .into_iter()
            .map(|p| point3(p, self.z))
            .collect()
    }

    fn closed(&self, polygon: &Polygon, role: Role, width: f64) -> Option<Toolpath> {
        (polygon.points.len() >= 2)
            .then(|| self.path(self.points(&polygon.points, true), true, role, width))
    }

    fn open(&self, pts: &[Point2], role: Role, width: f64) -> Option<Toolpath> {
        (pts.len() >= 2).then(|| self.path(self.points(pts, false), false, role, width))
    }
}

/// The loops of one island cut into units that print together: the loops around one hole
/// (a hole's loop at depth `d` lies inside its loop at depth `d + 1`) and the loops around the
/// island's outside (at depth `d + 1` inside the one at depth `d`). Each unit keeps the regions
/// stage's order (inner to outer, or outer to inner), so a hole's loops are laid one after the
/// other instead of every hole being visited once per depth. Returns indices into `loops`, the
/// units in order of their first loop.
fn loop_units(loops: &[(&PerimeterLoop, Toolpath)]) -> Vec<Vec<usize>> {
    let n = loops.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for a in 0..n {
        let la = loops[a].0;
        let Some(&probe) = la.polygon.points.first() else {
            continue;
        };
        // The loop one depth away that encloses `a`: deeper for a hole, shallower outside.
        let encloses = |b: &&PerimeterLoop| {
            b.is_hole == la.is_hole
                && if la.is_hole {
                    b.depth == la.depth + 1
                } else {
                    b.depth + 1 == la.depth
                }
        };
        let owner = (0..n)
            .filter(|&b| encloses(&loops[b].0) && loops[b].0.polygon.contains(probe))
            .min_by_key(|&b| (loops[b].0.polygon.signed_area2().abs(), b));
        if let Some(b) = owner {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            if ra != rb {
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let mut units: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for i in 0..n {
        let r = root(&mut parent, i);
        units.entry(r).or_default().push(i);
    }
    let mut out: Vec<Vec<usize>> = units.into_values().collect();
    out.sort_by_key(|u| u.first().copied());
    out
}

/// The groups of one object layer, in the order they print: skirt loops; brim loops and ears,
/// and the support (which the part's first layer over it needs in place); the islands.
struct ObjectGroups {
    skirt: Vec<Group>,
    beside: Vec<Group>,
    islands: Vec<Group>,
}

/// See [`ObjectGroups`].
fn object_groups(e: &Entry<'_>, maker: &PathMaker) -> ObjectGroups {
    let r = e.regions;
    let single = |path: Toolpath| Group {
        first: vec![path],
        ..Default::default()
    };
    let skirt: Vec<Group> = r
        .skirt
        .iter()
        .filter_map(|s| maker.closed(s, Role::Skirt, r.skirt_width))
        .map(single)
        .collect();
    let mut beside: Vec<Group> = r
        .brim
        .loops
        .iter()
        .filter_map(|s| maker.closed(s, Role::Skirt, r.skirt_width))
        .map(single)
        .collect();
    let ears: Vec<Toolpath> = r
        .brim
        .ears
        .iter()
        .filter_map(|l| maker.open(&l.points, Role::Skirt, r.skirt_width))
        .collect();
    if !ears.is_empty() {
        beside.push(Group {
            rest: ears,
            ..Default::default()
        });
    }
    // The sheath first, then the lines inside it.
    let sheath: Vec<Toolpath> = r
        .support
        .sheath
        .iter()
        .filter_map(|p| maker.closed(p, Role::Support, r.support.width))
        .collect();
    let lines: Vec<Toolpath> = [
        (&r.support.base, Role::Support),
        (&r.support.interface, Role::SupportInterface),
    ]
    .into_iter()
    .flat_map(|(lines, role)| {
        lines
            .iter()
            .filter_map(move |l| maker.open(&l.points, role, r.support.width))
    })
    .collect();
    if !sheath.is_empty() || !lines.is_empty() {
        beside.push(Group {
            first: sheath,
            rest: lines,
            ..Default::default()
        });
    }
    // Islands by index, in index order; their outer loops for infill assignment.
    let mut islands: BTreeMap<usize, Group> = BTreeMap::new();
    let mut outer: Vec<(usize, &Polygon, i128)> = Vec::new();
    let mut island_loops: BTreeMap<usize, Vec<(&PerimeterLoop, Toolpath)>> = BTreeMap::new();
    for lp in &r.perimeters {
        let role = if lp.external {
            Role::ExternalPerimeter
        } else {
            Role::Perimeter
        };
        if let Some(path) = maker.closed(&lp.polygon, role, lp.width) {
            island_loops.entry(lp.island).or_default().push((lp, path));
        }
        if lp.external && !lp.is_hole {
            outer.push((lp.island, &lp.polygon, lp.polygon.signed_area2().abs()));
        }
    }
    for (island, loops) in island_loops {
        let units = loop_units(&loops);
        let mut paths: Vec<Option<Toolpath>> = loops.into_iter().map(|(_, p)| Some(p)).collect();
        let group = islands.entry(island).or_default();
        for unit in units {
            group.units.push(unit.len());
            group
                .first
                .extend(unit.into_iter().filter_map(|i| paths[i].take()));
        }
    }
    let mut loose = Group::default();
    let mut add_line = |pts: &[Point2], role: Role, width: f64| {
        let Some(path) = maker.open(pts, role, width) else {
            return;
        };
        let owner = outer
            .iter()
            .filter(|(_, poly, _)| poly.contains(pts[0]))
            .min_by_key(|(island, _, area)| (*area, *island))
            .map(|(island, _, _)| *island);
        match owner {
            Some(island) => islands.entry(island).or_default().rest.push(path),
            None => loose.rest.push(path),
        }
    };
    for gap in &r.gap_fill {
        // One path per run of nearly constant thickness; the runs of a line share their ends,
        // so the travel ordering strings them together again.
        for (points, thickness) in split_by_width(gap, GAP_WIDTH_TOLERANCE_MM) {
            let width =
                BeadShape::RoundedRectangle.width_for_area(thickness * maker.height, maker.height);
            add_line(&points, Role::GapFill, width);
        }
    }
    for fill in &r.solid_infill {
        let role = match fill.role {
            SolidRole::Top => Role::TopSolidInfill,
            SolidRole::Bottom => Role::BottomSolidInfill,
            SolidRole::Bridge | SolidRole::InternalBridge => Role::BridgeInfill,
            SolidRole::Internal => Role::SolidInfill,
        };
        for line in &fill.lines {
            add_line(&line.points, role, fill.width);
        }
    }
    for line in &r.sparse_infill {
        add_line(&line.points, Role::SparseInfill, r.sparse_width);
    }
    let mut groups: Vec<Group> = islands.into_values().collect();
    if !loose.rest.is_empty() {
        groups.push(loose);
    }
    ObjectGroups {
        skirt,
        beside,
        islands: groups,
    }
}

/// The [`Program`] printing `objects` (see the module docs).
pub fn build_program(objects: &[ObjectLayers], params: &ProgramParams) -> Program {
    build_program_with(objects, &LayerExtras::default(), params)
}

/// [`build_program`] plus `extras`: each layer starts with its events, then prints its objects
/// as [`build_program`] does, then the extra paths. Extra paths come last so that a trace is
/// laid into a channel whose walls are already printed; the next layer's plastic tool is
/// selected again by a tool change as usual.
pub fn build_program_with(
    objects: &[ObjectLayers],
    extras: &LayerExtras,
    params: &ProgramParams,
) -> Program {
    let mut by_z: BTreeMap<i64, Vec<Entry<'_>>> = BTreeMap::new();
    for (object, obj) in objects.iter().enumerate() {
        for (lz, regions) in &obj.layers {
            by_z.entry(scaled(lz.top)).or_default().push(Entry {
                object,
                tool: obj.tool,
                top: lz.top,
                regions,
            });
        }
    }
    let mut pos = params.start;
    let mut current_tool: Option<usize> = None;
    let mut layers = Vec::with_capacity(by_z.len());
    for (index, (z_key, entries)) in by_z.into_iter().enumerate() {
        let z = entries.first().map_or(0.0, |e| e.top);
        let height = entries.iter().map(|e| e.regions.height).fold(0.0, f64::max);
        let mut tools: Vec<usize> = entries.iter().map(|e| e.tool).collect();
        tools.sort_unstable();
        tools.dedup();
        if let Some(cur) = current_tool
            && let Some(i) = tools.iter().position(|&t| t == cur)
        {
            let t = tools.remove(i);
            tools.insert(0, t);
        }
        let mut items: Vec<LayerItem> = extras
            .events_before
            .get(&z_key)
            .into_iter()
            .flatten()
            .cloned()
            .map(LayerItem::Event)
            .collect();
        for tool in tools {
            let tp = params.tool(tool);
            let mut skirts = Vec::new();
            let mut beside = Vec::new();
            let mut islands = Vec::new();
            for e in entries.iter().filter(|e| e.tool == tool) {
                let maker = PathMaker {
                    tolerance: scaled(params.resolution.max(0.0)),
                    z: e.top,
                    height: e.regions.height,
                    tool,
                    params: tp,
                    first_layer: index == 0,
                };
                let groups = object_groups(e, &maker);
                skirts.extend(groups.skirt);
                beside.extend(groups.beside);
                islands.extend(groups.islands);
                debug_assert!(e.object < objects.len());
            }
            let (mut paths, end) = order_groups(skirts, &pos, &params.order);
            let (beside_paths, end) = order_groups(beside, &end, &params.order);
            paths.extend(beside_paths);
            let (island_paths, end) = order_groups(islands, &end, &params.order);
            paths.extend(island_paths);
            if paths.is_empty() {
                continue;
            }
            // Ordered first: the loops' seams are where the ordering started them.
            for path in &mut paths {
                if matches!(path.role, Role::ExternalPerimeter | Role::Perimeter) {
                    path.clip_loop_end(params.seam_gap);
                }
            }
            let zones: Vec<_> = entries
                .iter()
                .filter(|e| e.tool == tool)
                .flat_map(|e| &e.regions.overhangs)
                .collect();
            let paths = split_paths(paths, &zones, &params.overhang, tp.speeds.bridge);
            if current_tool.is_some_and(|c| c != tool) {
                items.push(LayerItem::Event(Event::ToolChange { tool }));
            }
            current_tool = Some(tool);
            pos = end;
            let inside = if params.travel.only_retract_when_crossing_perimeters {
                InsideArea::new(entries.iter().filter(|e| e.tool == tool).map(|e| e.regions))
            } else {
                InsideArea::default()
            };
            items.extend(mark_inside_travels(
                with_fan_events(paths),
                &inside,
                &params.travel,
            ));
        }
        if let Some(extra) = extras.paths_after.get(&z_key) {
            let mut extra_tools: Vec<usize> = extra.iter().map(|p| p.tool).collect();
            extra_tools.sort_unstable();
            extra_tools.dedup();
            for tool in extra_tools {
                if current_tool.is_some_and(|c| c != tool) {
                    items.push(LayerItem::Event(Event::ToolChange { tool }));
                }
                current_tool = Some(tool);
                for path in extra.iter().filter(|p| p.tool == tool) {
                    if let Some(end) = path.end() {
                        pos = *end;
                    }
                    items.push(LayerItem::Path(path.clone()));
                }
            }
        }
        if let Some(events) = extras.events_after.get(&z_key) {
            items.extend(events.iter().cloned().map(LayerItem::Event));
        }
        for insert in extras.inserts_after.get(&z_key).into_iter().flatten() {
            append_insert(&mut items, insert, current_tool);
        }
        layers.push(Layer {
            index,
            z,
            height,
            items,
        });
    }
    Program { layers }
}

/// Appends `insert` to a layer's items, between tool changes to its tool and back to `active`
/// (the tool the layer ends on) when they differ. The builder's position and tool are left as
/// they were: the next layer starts from the layer's planar end, with `active` selected.
fn append_insert(items: &mut Vec<LayerItem>, insert: &LayerInsert, active: Option<usize>) {
    let switch = active.filter(|&t| t != insert.tool);
    if switch.is_some() {
        items.push(LayerItem::Event(Event::ToolChange { tool: insert.tool }));
    }
    items.extend(insert.items.iter().cloned());
    if let Some(tool) = switch {
        items.push(LayerItem::Event(Event::ToolChange { tool }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{ExPolygon, Polyline};
    use crate::region::{RegionParams, make_regions, make_regions_with_heights};
    use crate::slice::{SliceParams, layer_schedule};

    fn square(x0: f64, y0: f64, side: f64) -> ExPolygon {
        ExPolygon {
            contour: Polygon::new(vec![
                Point2::from_mm(x0, y0),
                Point2::from_mm(x0 + side, y0),
                Point2::from_mm(x0 + side, y0 + side),
                Point2::from_mm(x0, y0 + side),
            ]),
            holes: vec![],
        }
    }

    /// A stack of `n` layers of the given islands, 0.2 mm each.
    fn object(
        tool: usize,
        islands: Vec<ExPolygon>,
        n: usize,
        region: &RegionParams,
    ) -> ObjectLayers {
        let zs = layer_schedule(n as f64 * 0.2, &SliceParams::default());
        let layers = vec![islands; zs.len()];
        let regions = make_regions(&layers, region);
        ObjectLayers {
            tool,
            layers: zs.into_iter().zip(regions).collect(),
        }
    }

    fn region() -> RegionParams {
        RegionParams {
            skirt_loops: 1,
            ..Default::default()
        }
    }

    #[test]
    fn cube_layers_have_roles_speeds_and_islands_together() {
        let obj = object(
            0,
            vec![square(0.0, 0.0, 20.0), square(40.0, 0.0, 10.0)],
            10,
            &region(),
        );
        let params = ProgramParams::default();
        let program = build_program(std::slice::from_ref(&obj), &params);
        assert_eq!(program.layers.len(), 10);
        let l0 = &program.layers[0];
        assert!((l0.z - 0.2).abs() < 1e-12 && (l0.height - 0.2).abs() < 1e-12);
        let paths: Vec<&Toolpath> = l0.paths().collect();
        assert_eq!(paths[0].role, Role::Skirt);
        assert!(
            paths
                .iter()
                .all(|p| p.speed == 20.0 && p.tool == 0 && p.points[0].z == 0.2)
        );
        // Every region path appears once.
        let r0 = &obj.layers[0].1;
        let want = r0.skirt.len()
            + r0.perimeters.len()
            + r0.solid_infill.iter().map(|f| f.lines.len()).sum::<usize>()
            + r0.sparse_infill.len();
        assert_eq!(paths.len(), want);
        // Islands are contiguous: once the print leaves an island it never comes back.
        let island_of = |p: &Toolpath| usize::from(p.points[0].x > 30.0);
        let seq: Vec<usize> = paths[1..].iter().map(|p| island_of(p)).collect();
        let changes = seq.windows(2).filter(|w| w[0] != w[1]).count();
        assert_eq!(changes, 1, "{seq:?}");
        // Perimeters before infill within each island; external perimeters marked.
        for island in [0, 1] {
            let roles: Vec<Role> = paths[1..]
                .iter()
                .filter(|p| island_of(p) == island)
                .map(|p| p.role)
                .collect();
            let first_infill = roles.iter().position(|r| *r == Role::BottomSolidInfill);
            let last_loop = roles
                .iter()
                .rposition(|r| matches!(r, Role::Perimeter | Role::ExternalPerimeter));
            assert!(first_infill > last_loop, "{roles:?}");
            assert!(roles.contains(&Role::ExternalPerimeter));
        }
        // Layer 5: sparse infill at its speed; widths from the region parameters.
        let l5: Vec<&Toolpath> = program.layers[5].paths().collect();
        let sparse: Vec<&&Toolpath> = l5.iter().filter(|p| p.role == Role::SparseInfill).collect();
        assert!(!sparse.is_empty());
        assert!(
            sparse
                .iter()
                .all(|p| p.speed == 80.0 && p.width == 0.45 && !p.closed)
        );
        assert!(
            l5.iter()
                .any(|p| p.role == Role::ExternalPerimeter && p.speed == 25.0 && p.closed)
        );
        assert!(
            program.layers[9]
                .paths()
                .any(|p| p.role == Role::TopSolidInfill && p.speed == 30.0)
        );
        // Besides paths, only the bridge fan around the internal bridges under the top.
        for l in &program.layers {
            let mut fan = None;
            for item in &l.items {
                match item {
                    LayerItem::Path(p) => {
                        assert_eq!(
                            fan.is_some(),
                            p.role == Role::BridgeInfill,
                            "layer {}",
                            l.index
                        );
                    }
                    LayerItem::Event(Event::PartFan { at_least }) => fan = *at_least,
                    LayerItem::Event(e) => panic!("unexpected {e:?}"),
                }
            }
            assert_eq!(fan, None);
        }
    }

    #[test]
    fn extras_come_before_and_after_the_layer_with_tool_changes_back_and_forth() {
        let plastic = object(0, vec![square(0.0, 0.0, 20.0)], 3, &RegionParams::default());
        let z1 = plastic.layers[1].0.top;
        let trace = Toolpath {
            points: vec![Point3::new(2.0, 10.0, z1), Point3::new(18.0, 10.0, z1)],
            closed: false,
            role: Role::ConductiveTrace,
            tool: 1,
            width: 0.6,
            height: 0.2,
            speed: 10.0,
            segments: None,
            tool_axis: None,
        };
        let mut extras = LayerExtras::default();
        extras
            .events_before
            .insert(scaled(z1), vec![Event::Comment("before".to_owned())]);
        extras.paths_after.insert(scaled(z1), vec![trace.clone()]);
        extras
            .events_after
            .insert(scaled(z1), vec![Event::Comment("after".to_owned())]);
        // A height no layer has is ignored.
        extras.paths_after.insert(scaled(99.0), vec![trace.clone()]);
        let program = build_program_with(&[plastic], &extras, &ProgramParams::default());
        let items = &program.layers[1].items;
        assert_eq!(
            items.first(),
            Some(&LayerItem::Event(Event::Comment("before".to_owned())))
        );
        let n = items.len();
        assert_eq!(
            items[n - 3..],
            [
                LayerItem::Event(Event::ToolChange { tool: 1 }),
                LayerItem::Path(trace),
                LayerItem::Event(Event::Comment("after".to_owned())),
            ]
        );
        // The next layer goes back to the plastic tool before its first path.
        assert_eq!(
            program.layers[2].items.first(),
            Some(&LayerItem::Event(Event::ToolChange { tool: 0 }))
        );
        assert_eq!(program.tools_used(), vec![0, 1]);
        let changes = program
            .layers
            .iter()
            .flat_map(|l| &l.items)
            .filter(|i| matches!(i, LayerItem::Event(Event::ToolChange { .. })))
            .count();
        assert_eq!(changes, 2);
    }

    #[test]
    fn inserts_end_the_layer_between_tool_changes_and_leave_the_next_layer_as_it_was() {
        let plastic = object(0, vec![square(0.0, 0.0, 20.0)], 3, &RegionParams::default());
        let z1 = plastic.layers[1].0.top;
        let curved = |tool: usize, y: f64| Toolpath {
            points: vec![
                Point3::new(2.0, y, z1 + 0.1),
                Point3::new(18.0, y, z1 + 0.3),
            ],
            closed: false,
            role: Role::TopSolidInfill,
            tool,
            width: 0.45,
            height: 0.2,
            speed: 20.0,
            tool_axis: None,
            segments: None,
        };
        let plain = build_program(std::slice::from_ref(&plastic), &ProgramParams::default());
        let mut extras = LayerExtras::default();
        extras.inserts_after.insert(
            scaled(z1),
            vec![
                LayerInsert {
                    tool: 0,
                    items: vec![LayerItem::Path(curved(0, 5.0))],
                },
                LayerInsert {
                    tool: 1,
                    items: vec![LayerItem::Path(curved(1, 15.0))],
                },
            ],
        );
        let program = build_program_with(&[plastic], &extras, &ProgramParams::default());
        let items = &program.layers[1].items;
        let planar = plain.layers[1].items.len();
        assert_eq!(items[..planar], plain.layers[1].items[..]);
        assert_eq!(
            items[planar..],
            [
                LayerItem::Path(curved(0, 5.0)),
                LayerItem::Event(Event::ToolChange { tool: 1 }),
                LayerItem::Path(curved(1, 15.0)),
                LayerItem::Event(Event::ToolChange { tool: 0 }),
            ]
        );
        // The layers around are untouched: the next starts where the planar layer ended.
        assert_eq!(program.layers[0], plain.layers[0]);
        assert_eq!(program.layers[2], plain.layers[2]);
    }

    #[test]
    fn two_tools_alternate_with_one_change_per_layer() {
        let plastic = object(0, vec![square(0.0, 0.0, 20.0)], 4, &RegionParams::default());
        let paste = object(1, vec![square(30.0, 0.0, 5.0)], 4, &RegionParams::default());
        let params = ProgramParams {
            tools: vec![
                ToolPathParams::default(),
                ToolPathParams {
                    role: Some(Role::ConductiveTrace),
                    ..Default::default()
                },
            ],
            ..Default::default()
        };
        let program = build_program(&[paste, plastic], &params);
        assert_eq!(program.first_tool(), Some(0));
        assert_eq!(program.tools_used(), vec![0, 1]);
        let mut sequence = Vec::new();
        for layer in &program.layers {
            let mut tools = Vec::new();
            for item in &layer.items {
                match item {
                    LayerItem::Event(Event::ToolChange { tool }) => sequence.push(*tool),
                    LayerItem::Path(p) => {
                        if tools.last() != Some(&p.tool) {
                            tools.push(p.tool);
                        }
                        assert_eq!(p.role == Role::ConductiveTrace, p.tool == 1);
                    }
                    LayerItem::Event(_) => {}
                }
            }
            assert_eq!(tools.len(), 2, "each tool's paths together");
        }
        // T0 T1 | T1 T0 | T0 T1 | T1 T0: one change per layer.
        assert_eq!(sequence, vec![1, 0, 1, 0]);
    }

    #[test]
    fn layers_merge_by_height_and_infill_outside_loops_is_kept() {
        // Object B has a thicker first layer: its layers land at 0.3, 0.5 ...; A's at 0.2, 0.4.
        let a = object(0, vec![square(0.0, 0.0, 10.0)], 3, &RegionParams::default());
        let zs = layer_schedule(
            0.7,
            &SliceParams {
                layer_height: 0.2,
                first_layer_height: 0.3,
            },
        );
        let heights: Vec<f64> = zs.iter().map(LayerZ::height).collect();
        let islands = vec![vec![square(20.0, 0.0, 10.0)]; zs.len()];
        let no_perimeters = RegionParams {
            perimeters: 0,
            ..Default::default()
        };
        let regions =
            make_regions_with_heights(&islands, &heights, &no_perimeters).unwrap_or_default();
        let b = ObjectLayers {
            tool: 0,
            layers: zs.into_iter().zip(regions).collect(),
        };
        let program = build_program(&[a, b], &ProgramParams::default());
        let zs: Vec<f64> = program.layers.iter().map(|l| l.z).collect();
        assert_eq!(zs.len(), 6, "{zs:?}");
        for w in zs.windows(2) {
            assert!(w[0] < w[1]);
        }
        assert!(program.layers.iter().enumerate().all(|(i, l)| l.index == i));
        // B has no loops: its infill is printed anyway, as a loose group.
        assert!(
            program.layers[1]
                .paths()
                .any(|p| p.points[0].x > 15.0 && p.height == 0.3)
        );
    }

    #[test]
    fn loops_print_hole_by_hole() {
        // A 30 mm square with three 4 mm square holes in a row, two loops around each.
        let mut island = square(0.0, 0.0, 30.0);
        for x in [4.0, 13.0, 22.0] {
            let mut hole = square(x, 13.0, 4.0).contour;
            hole.points.reverse();
            island.holes.push(hole);
        }
        let obj = object(0, vec![island], 6, &RegionParams::default());
        let program = build_program(&[obj], &ProgramParams::default());
        let loops: Vec<&Toolpath> = program.layers[3].paths().filter(|p| p.closed).collect();
        assert_eq!(loops.len(), 8);
        // Which hole (0, 1, 2) a loop goes round, or 3 for the outside.
        let hole_of = |p: &Toolpath| {
            let (x0, x1) = p
                .points
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), q| (a.min(q.x), b.max(q.x)));
            if x1 - x0 > 20.0 {
                3
            } else {
                ((x0 - 2.0) / 9.0).floor() as usize
            }
        };
        let seq: Vec<usize> = loops.iter().map(|p| hole_of(p)).collect();
        // Each hole's two loops are consecutive, inner (depth 1) then outer (depth 0).
        for pair in seq.chunks(2) {
            assert_eq!(pair[0], pair[1], "{seq:?}");
        }
        for pair in loops.chunks(2) {
            assert_eq!(
                (pair[0].role, pair[1].role),
                (Role::Perimeter, Role::ExternalPerimeter)
            );
        }
        let mut holes = seq.clone();
        holes.dedup();
        assert_eq!(holes.len(), 4, "{seq:?}");
    }

    #[test]
    fn simplify_drops_collinear_and_tiny_deviations_only() {
        let mm = Point2::from_mm;
        let line = [
            mm(0.0, 0.0),
            mm(1.0, 0.0),
            mm(2.0, 0.005),
            mm(3.0, 0.0),
            mm(3.0, 1.0),
        ];
        let tol = scaled(DEFAULT_RESOLUTION_MM);
        assert_eq!(
            simplify(&line, tol, false),
            vec![mm(0.0, 0.0), mm(3.0, 0.0), mm(3.0, 1.0)]
        );
        let bump = [mm(0.0, 0.0), mm(1.0, 0.02), mm(2.0, 0.0)];
        assert_eq!(simplify(&bump, tol, false), bump.to_vec());
        assert_eq!(simplify(&line, 0, false), line.to_vec());
        // A ring with midpoints on its edges keeps its four corners, starting where it did.
        let ring = [
            mm(0.0, 0.0),
            mm(5.0, 0.0),
            mm(10.0, 0.0),
            mm(10.0, 10.0),
            mm(5.0, 10.0),
            mm(0.0, 10.0),
        ];
        assert_eq!(
            simplify(&ring, tol, true),
            vec![mm(0.0, 0.0), mm(10.0, 0.0), mm(10.0, 10.0), mm(0.0, 10.0)]
        );
    }

    #[test]
    fn build_is_deterministic() {
        let objs = vec![
            object(
                0,
                vec![square(0.0, 0.0, 20.0), square(25.0, 25.0, 8.0)],
                6,
                &region(),
            ),
            object(1, vec![square(50.0, 0.0, 6.0)], 6, &RegionParams::default()),
        ];
        let params = ProgramParams::default();
        assert_eq!(build_program(&objs, &params), build_program(&objs, &params));
    }

    #[test]
    fn degenerate_paths_are_dropped() {
        let mut obj = object(0, vec![square(0.0, 0.0, 10.0)], 1, &RegionParams::default());
        obj.layers[0].1.sparse_infill.push(Polyline {
            points: vec![Point2::new(0, 0)],
        });
        let n = obj.layers[0].1.perimeters.len()
            + obj.layers[0]
                .1
                .solid_infill
                .iter()
                .map(|f| f.lines.len())
                .sum::<usize>();
        let program = build_program(&[obj], &ProgramParams::default());
        assert_eq!(program.paths().count(), n);
        assert!(
            build_program(&[], &ProgramParams::default())
                .layers
                .is_empty()
        );
    }
}
