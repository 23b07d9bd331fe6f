//! The Program's vocabulary: [`Toolpath`]s with a [`Role`] (straight moves, or planar line and
//! arc [`Segment`]s), [`Event`]s (tool changes, part placements, the tool switched on and off
//! with a lead time, ...), and [`Layer`]s of both in print order, each at its z.

use std::collections::BTreeMap;

use super::segment::{self, Segment};
use crate::geom::{Point3, Vector3};

/// What an extrusion is for. Decides speed, cooling and the `;TYPE:` comment of G-code output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Role {
    /// The outermost loop of an island or hole (the visible wall).
    ExternalPerimeter,
    /// An inner perimeter loop.
    Perimeter,
    /// A stretch of a perimeter loop whose bead lies over air (its centre more than half a
    /// nozzle beyond the layer below): printed as a round thread, like a bridge.
    OverhangPerimeter,
    /// Internal solid infill (solid layers between a surface and sparse infill).
    SolidInfill,
    /// Solid infill of an upward-facing (visible) surface.
    TopSolidInfill,
    /// Solid infill of a downward-facing surface on the bed.
    BottomSolidInfill,
    /// Solid infill over air: round threads spanning from anchor to anchor.
    BridgeInfill,
    /// Variable-width fill of the strips between perimeter loops.
    GapFill,
    /// Sparse infill.
    SparseInfill,
    /// Skirt (or brim) loops around the first layer.
    Skirt,
    /// Support material: the sparse base of a support column.
    Support,
    /// Support material interface: the dense top layers of a support column, under the part.
    SupportInterface,
    /// Planar scaffold under curved layers.
    Scaffold,
    /// Buffer layer between the scaffold and curved layers.
    Buffer,
    /// A conductive trace (paste or ink tool).
    ConductiveTrace,
    /// A conductive drop (a dot of paste on a pad).
    ConductiveDrop,
    /// An aerosol-jet line along an outline (a free-standing micro-wall).
    JetWall,
    /// An aerosol-jet line of a fill (contour-parallel loops or a serpentine).
    JetFill,
    /// The wipe tower: where a tool just selected purges, and the tower's walls and sparse
    /// layers.
    WipeTower,
    /// Anything else (custom G-code, imported paths).
    Custom,
}

impl Role {
    /// Every role, in declaration order.
    pub const ALL: [Role; 20] = [
        Role::ExternalPerimeter,
        Role::Perimeter,
        Role::OverhangPerimeter,
        Role::SolidInfill,
        Role::TopSolidInfill,
        Role::BottomSolidInfill,
        Role::BridgeInfill,
        Role::GapFill,
        Role::SparseInfill,
        Role::Skirt,
        Role::Support,
        Role::SupportInterface,
        Role::Scaffold,
        Role::Buffer,
        Role::ConductiveTrace,
        Role::ConductiveDrop,
        Role::JetWall,
        Role::JetFill,
        Role::WipeTower,
        Role::Custom,
    ];

    /// The name written after `;TYPE:` in G-code.
    ///
    /// PrusaSlicer's names (`ExtrusionEntity.cpp`, `ExtrusionEntity::role_to_string`) where
    /// PrusaSlicer has the role, so its G-code viewer and post-processors understand the
    /// output: bottom solid infill is `Solid infill` as in PrusaSlicer, which has no separate
    /// role for it. The conduit-only roles use names in the same style: `Scaffold`, `Buffer`,
    /// `Conductive trace`, `Conductive drop`, `Jet wall`, `Jet fill`.
    pub fn type_name(self) -> &'static str {
        match self {
            Role::ExternalPerimeter => "External perimeter",
            Role::Perimeter => "Perimeter",
            Role::OverhangPerimeter => "Overhang perimeter",
            Role::SolidInfill | Role::BottomSolidInfill => "Solid infill",
            Role::TopSolidInfill => "Top solid infill",
            Role::BridgeInfill => "Bridge infill",
            Role::GapFill => "Gap fill",
            Role::SparseInfill => "Internal infill",
            Role::Skirt => "Skirt/Brim",
            Role::Support => "Support material",
            Role::SupportInterface => "Support material interface",
            Role::Scaffold => "Scaffold",
            Role::Buffer => "Buffer",
            Role::ConductiveTrace => "Conductive trace",
            Role::ConductiveDrop => "Conductive drop",
            Role::JetWall => "Jet wall",
            Role::JetFill => "Jet fill",
            Role::WipeTower => "Wipe tower",
            Role::Custom => "Custom",
        }
    }

    /// The role named `name` in a `;TYPE:` comment (the inverse of [`Role::type_name`], with
    /// `Solid infill` read as [`Role::SolidInfill`]); `None` for names conduit has no role for.
    pub fn from_type_name(name: &str) -> Option<Role> {
        Role::ALL
            .into_iter()
            .filter(|r| *r != Role::BottomSolidInfill)
            .find(|r| r.type_name() == name)
    }

    /// The cross-section of this role's beads: bridges are round threads in air, everything
    /// else is pressed onto the layer below (see [`super::extrusion`]).
    pub fn bead_shape(self) -> super::extrusion::BeadShape {
        match self {
            Role::BridgeInfill | Role::OverhangPerimeter => super::extrusion::BeadShape::Round,
            _ => super::extrusion::BeadShape::RoundedRectangle,
        }
    }

    /// Whether the role deposits conductive material.
    pub fn is_conductive(self) -> bool {
        matches!(self, Role::ConductiveTrace | Role::ConductiveDrop)
    }
}

/// One continuous extrusion: the nozzle moves through `points` while depositing.
///
/// Points are always 3D (planar paths keep z constant), in millimetres, in the machine frame
/// *before* per-tool offsets (the writer applies those).
#[derive(Debug, Clone, PartialEq)]
pub struct Toolpath {
    /// The centreline. For a closed path the last point connects back to the first, which is not
    /// repeated.
    pub points: Vec<Point3>,
    /// Whether the path is a loop (the move from the last point back to the first is part of
    /// the extrusion).
    pub closed: bool,
    /// What the extrusion is for.
    pub role: Role,
    /// Tool index (0 = plastic, 1 = conductive paste, ...).
    pub tool: usize,
    /// Extrusion width, mm.
    pub width: f64,
    /// Extrusion height (layer height for planar paths), mm.
    pub height: f64,
    /// Feed rate while extruding, mm/s.
    pub speed: f64,
    /// Tool direction per point (unit vectors, for 5/6-axis output); `None` for 3-axis paths.
    /// When present it has one entry per point.
    pub tool_axis: Option<Vec<Vector3>>,
    /// The moves as planar lines and arcs (in the XY plane at the points' z), for paths with
    /// arcs; `None`: straight moves between the points. When present, segment `i` runs from
    /// `points[i]` to `points[i + 1]` (for a closed path the last one returns to the first
    /// point), with its ends as the stage computed them.
    pub segments: Option<Vec<Segment>>,
}

impl Toolpath {
    /// Length of the extrusion, mm, including the closing segment of a closed path (along the
    /// arcs of a path with [`Toolpath::segments`]).
    pub fn length(&self) -> f64 {
        if let Some(segments) = &self.segments {
            return segment::length_of(segments);
        }
        let open: f64 = self.points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        match (self.closed, self.points.first(), self.points.last()) {
            (true, Some(first), Some(last)) if self.points.len() > 2 => {
                open + (first - last).norm()
            }
            _ => open,
        }
    }

    /// The path through chords of its [`Toolpath::segments`] that stray at most `tolerance` mm
    /// from their arcs: the start, then every chord's end (a closed path ends at its start
    /// again), each segment's at the z of its end; `None` for a path without segments.
    pub fn chords(&self, tolerance: f64) -> Option<Vec<Point3>> {
        let segments = self.segments.as_ref()?;
        let mut out: Vec<Point3> = self.points.first().copied().into_iter().collect();
        for (i, s) in segments.iter().enumerate() {
            let z = self
                .points
                .get(i + 1)
                .or(self.points.first())
                .map_or(0.0, |p| p.z);
            out.extend(
                s.flatten(tolerance)
                    .into_iter()
                    .map(|p| Point3::new(p[0], p[1], z)),
            );
        }
        Some(out)
    }

    /// The point where the extrusion starts.
    pub fn start(&self) -> Option<&Point3> {
        self.points.first()
    }

    /// The point where the extrusion ends: the start again for a closed path.
    pub fn end(&self) -> Option<&Point3> {
        if self.closed {
            self.points.first()
        } else {
            self.points.last()
        }
    }

    /// Reverses the direction of travel (points, tool axes and segments together).
    pub fn reverse(&mut self) {
        self.points.reverse();
        if let Some(axis) = &mut self.tool_axis {
            axis.reverse();
        }
        if let Some(segments) = &mut self.segments {
            segments.reverse();
            for s in segments.iter_mut() {
                *s = s.reversed();
            }
            // Segment i of a loop leaves point i: after the reversal the closing segment
            // (last → first) comes first.
            if self.closed {
                segments.rotate_left(1);
            }
        }
    }

    /// Opens a closed planar path at its start and ends it `gap` mm short of it, where the
    /// loop began (PrusaSlicer's loop clipping, OrcaSlicer's `seam_gap`): the bead's round end
    /// then meets its start instead of running over it, which leaves a blob at the seam.
    /// The last move is cut at the point `gap` before the start, along an arc where the path
    /// has arcs. A path with tool axes (non-planar), an open path, or a loop shorter than
    /// [`MIN_CLIPPED_LOOP_GAPS`] gaps is left as it is; so is everything for a `gap` ≤ 0.
    pub fn clip_loop_end(&mut self, gap: f64) {
        let length = self.length();
        if !self.closed
            || self.tool_axis.is_some()
            || self.points.len() < 3
            || gap.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
            || length <= MIN_CLIPPED_LOOP_GAPS * gap
        {
            return;
        }
        let Some(&first) = self.points.first() else {
            return;
        };
        let keep = length - gap;
        if let Some(segments) = &self.segments {
            let (head, _) = segment::split_at(segments, keep);
            let n = head.len();
            let Some(end) = head.last().map(Segment::end) else {
                return;
            };
            let z = self.points.get(n).unwrap_or(&first).z;
            self.points.truncate(n);
            self.points.push(Point3::new(end[0], end[1], z));
            self.segments = Some(head);
        } else {
            let mut ring = std::mem::take(&mut self.points);
            ring.push(first);
            let mut at = 0.0;
            let mut out = Vec::with_capacity(ring.len());
            out.push(first);
            for w in ring.windows(2) {
                let l = (w[1] - w[0]).norm();
                if at + l >= keep {
                    let t = if l > 0.0 { (keep - at) / l } else { 1.0 };
                    out.push(w[0] + (w[1] - w[0]) * t);
                    break;
                }
                out.push(w[1]);
                at += l;
            }
            self.points = out;
        }
        self.closed = false;
    }

    /// Makes a closed path start at its point `index` (points, tool axes and segments rotate
    /// together). Does nothing for an open path or an index out of range.
    pub fn rotate_start(&mut self, index: usize) {
        if !self.closed || index >= self.points.len() {
            return;
        }
        self.points.rotate_left(index);
        if let Some(axis) = &mut self.tool_axis
            && index < axis.len()
        {
            axis.rotate_left(index);
        }
        if let Some(segments) = &mut self.segments
            && index < segments.len()
        {
            segments.rotate_left(index);
        }
    }
}

/// A loop shorter than this many seam gaps is not clipped ([`Toolpath::clip_loop_end`]): on a
/// tiny loop the gap would be a visible hole rather than a hidden seam.
pub const MIN_CLIPPED_LOOP_GAPS: f64 = 10.0;

/// Something that happens between extrusions.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// Switch to another tool; the following paths use it.
    ToolChange {
        /// The new tool's index.
        tool: usize,
    },
    /// Pick part `part` and place it at the given pose (machine frame, before tool offsets).
    PickAndPlace {
        /// 1-based number of the part in placement order (what `M361 P<id>` names).
        id: usize,
        /// Part name (reference designator, e.g. `R1`).
        part: String,
        /// X of the part centre, mm.
        x: f64,
        /// Y of the part centre, mm.
        y: f64,
        /// Z of the part's seating plane, mm.
        z: f64,
        /// Rotation about +Z, degrees counter-clockwise.
        rotation_deg: f64,
    },
    /// Pause so an operator can insert a part by hand.
    ManualInsertPause {
        /// Part name.
        part: String,
        /// Message shown to the operator.
        message: String,
    },
    /// A comment carried into the machine program.
    Comment(String),
    /// Wait in place.
    Dwell {
        /// Duration, seconds.
        seconds: f64,
    },
    /// The part-cooling fan from here on: `Some(p)` runs it at `p` percent or at the layer's
    /// own speed, whichever is higher (bridges and overhanging perimeters); `None` returns it
    /// to the layer's speed. Layers printed with the fan off keep it off.
    PartFan {
        /// The lowest fan speed wanted, percent; `None`: the layer's.
        at_least: Option<f64>,
    },
    /// Switch the active tool's output on or off (an aerosol jet's shutter). An `on` switch
    /// before a path takes effect where the path starts, an `off` switch after a path where it
    /// ends. With a `lead_time` the command is sent that long (at the path's speed) before the
    /// nozzle gets there, while it keeps moving: the writer runs in to the start on the path's
    /// starting tangent, and cuts the path where the command must go.
    Switch {
        /// On (true) or off.
        on: bool,
        /// Seconds between the command and the moment it takes effect; 0: at standstill at the
        /// path's ends.
        lead_time: f64,
    },
    /// The travel to the next path stays inside the part's internal infill, clear of every
    /// perimeter and of top, bottom and bridge surfaces: the writer does not retract for it,
    /// however long (`printer.only_retract_when_crossing_perimeters`; the toolpaths stage
    /// decides, see `toolpaths::travel`). Only the next travel is concerned.
    TravelInsideInfill,
}

/// One entry of a layer, in print order.
#[derive(Debug, Clone, PartialEq)]
pub enum LayerItem {
    /// An extrusion.
    Path(Toolpath),
    /// An event.
    Event(Event),
}

/// One layer of the Program.
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    /// 0 for the first layer, counting up.
    pub index: usize,
    /// Nominal print height (top of the layer, where the nozzle is), mm.
    pub z: f64,
    /// Layer thickness, mm.
    pub height: f64,
    /// Paths and events in print order.
    pub items: Vec<LayerItem>,
}

impl Layer {
    /// The layer's toolpaths in print order.
    pub fn paths(&self) -> impl Iterator<Item = &Toolpath> {
        self.items.iter().filter_map(|i| match i {
            LayerItem::Path(p) => Some(p),
            LayerItem::Event(_) => None,
        })
    }
}

/// Ordered layers of toolpaths and events: what every machine-program writer consumes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Program {
    /// Layers, bottom to top.
    pub layers: Vec<Layer>,
}

impl Program {
    /// Every toolpath in print order.
    pub fn paths(&self) -> impl Iterator<Item = &Toolpath> {
        self.layers.iter().flat_map(Layer::paths)
    }

    /// The tools that extrude, ascending, without repeats.
    pub fn tools_used(&self) -> Vec<usize> {
        let mut tools: Vec<usize> = self.paths().map(|p| p.tool).collect();
        tools.sort_unstable();
        tools.dedup();
        tools
    }

    /// The tool of the first extrusion, if any.
    pub fn first_tool(&self) -> Option<usize> {
        self.paths().next().map(|p| p.tool)
    }
}

/// What a layer gets besides its objects' regions, from the other stages: the part events that
/// come before it, the paths printed after them (conductive traces, drops), the events after
/// those, and whole inserts at its end (curved layers), keyed by the layer's print height on
/// the nanometre grid (`scaled(z)`). Heights no object layer has are ignored.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LayerExtras {
    /// Events at the start of the layer, in order (e.g. placing a part whose cavity is done).
    pub events_before: BTreeMap<i64, Vec<Event>>,
    /// Paths printed after the objects' paths, tool by tool in ascending order, each tool's in
    /// the order given.
    pub paths_after: BTreeMap<i64, Vec<Toolpath>>,
    /// Events at the end of the layer, after its paths (e.g. placing a part that stands above
    /// the last layer).
    pub events_after: BTreeMap<i64, Vec<Event>>,
    /// Item sequences appended at the very end of the layer, each printed with its own tool
    /// (e.g. the curved layers of a region whose highest point this layer holds), in order.
    pub inserts_after: BTreeMap<i64, Vec<LayerInsert>>,
}

/// A sequence of items a stage appends to a layer as it is (see [`LayerExtras::inserts_after`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LayerInsert {
    /// The tool printing the insert's paths: selected before them when another tool is active,
    /// and the active tool selected again after them.
    pub tool: usize,
    /// Comments and toolpaths, in print order.
    pub items: Vec<LayerItem>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(closed: bool) -> Toolpath {
        Toolpath {
            points: vec![
                Point3::new(0.0, 0.0, 0.2),
                Point3::new(10.0, 0.0, 0.2),
                Point3::new(10.0, 10.0, 0.2),
                Point3::new(0.0, 10.0, 0.2),
            ],
            closed,
            role: Role::Perimeter,
            tool: 0,
            width: 0.45,
            height: 0.2,
            speed: 60.0,
            segments: None,
            tool_axis: Some(
                (0..4)
                    .map(|i| Vector3::new(f64::from(i), 0.0, 1.0))
                    .collect(),
            ),
        }
    }

    #[test]
    fn a_loop_clipped_at_its_seam_ends_the_gap_short_of_its_start() {
        // A 10 mm square, straight and with its last corner rounded by an arc.
        let pts = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        let mut straight = Toolpath {
            points: pts.iter().map(|p| Point3::new(p[0], p[1], 0.2)).collect(),
            closed: true,
            role: Role::ExternalPerimeter,
            tool: 0,
            width: 0.45,
            height: 0.2,
            speed: 25.0,
            tool_axis: None,
            segments: None,
        };
        let mut arced = straight.clone();
        straight.clip_loop_end(0.06);
        assert!(!straight.closed);
        assert_eq!(straight.points.len(), 5);
        assert!(
            (straight.length() - 39.94).abs() < 1e-12,
            "{}",
            straight.length()
        );
        let end = straight.points[4];
        assert!(
            (end.x - 0.0).abs() < 1e-12 && (end.y - 0.06).abs() < 1e-12,
            "{end:?}"
        );
        // The closing side as a half circle bulging out to the left, radius 5 about (0, 5).
        let line = |a: [f64; 2], b: [f64; 2]| Segment::Line { a, b };
        arced.segments = Some(vec![
            line(pts[0], pts[1]),
            line(pts[1], pts[2]),
            line(pts[2], pts[3]),
            Segment::Arc {
                a: pts[3],
                b: pts[0],
                c: [0.0, 5.0],
                r: 5.0,
                sweep: std::f64::consts::PI,
            },
        ]);
        let before = arced.length();
        arced.clip_loop_end(0.5);
        assert!((before - arced.length() - 0.5).abs() < 1e-9);
        assert_eq!(arced.points.len(), 5);
        // 0.5 mm of arc back from (0, 0): 0.1 rad short of the end, on the circle.
        let end = arced.points[4];
        let (ex, ey) = (-5.0 * 0.1f64.sin(), 5.0 - 5.0 * 0.1f64.cos());
        assert!(
            (end.x - ex).abs() < 1e-9 && (end.y - ey).abs() < 1e-9,
            "{end:?}"
        );
        // Tiny loops, open paths and no gap are left alone.
        let mut tiny = Toolpath {
            points: vec![
                Point3::new(0.0, 0.0, 0.2),
                Point3::new(0.1, 0.0, 0.2),
                Point3::new(0.1, 0.1, 0.2),
            ],
            ..straight.clone()
        };
        tiny.closed = true;
        let kept = tiny.clone();
        tiny.clip_loop_end(0.06);
        assert_eq!(tiny, kept);
        let mut open = straight.clone();
        open.clip_loop_end(0.06);
        assert_eq!(open, straight);
    }

    #[test]
    fn length_counts_the_closing_segment_of_loops_only() {
        assert_eq!(square(true).length(), 40.0);
        assert_eq!(square(false).length(), 30.0);
        assert_eq!(square(true).end(), square(true).start());
    }

    #[test]
    fn rotate_and_reverse_keep_tool_axes_with_their_points() {
        let mut p = square(true);
        p.rotate_start(2);
        assert_eq!(p.points[0], Point3::new(10.0, 10.0, 0.2));
        assert_eq!(p.tool_axis.as_ref().map(|a| a[0].x), Some(2.0));
        p.reverse();
        assert_eq!(p.points[0], Point3::new(10.0, 0.0, 0.2));
        assert_eq!(p.tool_axis.as_ref().map(|a| a[0].x), Some(1.0));
        let mut open = square(false);
        open.rotate_start(2);
        assert_eq!(open, square(false));
    }

    #[test]
    fn segments_follow_their_points_when_reversed_rotated_and_flattened() {
        let quarter = |a: [f64; 2], b: [f64; 2], c: [f64; 2], sweep: f64| Segment::Arc {
            a,
            b,
            c,
            r: 1.0,
            sweep,
        };
        let half_pi = std::f64::consts::FRAC_PI_2;
        // A closed "D": a straight edge up the y axis and a half circle back, as two arcs.
        let mut d = Toolpath {
            points: vec![
                Point3::new(0.0, -1.0, 0.2),
                Point3::new(1.0, 0.0, 0.2),
                Point3::new(0.0, 1.0, 0.2),
            ],
            closed: true,
            segments: Some(vec![
                quarter([0.0, -1.0], [1.0, 0.0], [0.0, 0.0], half_pi),
                quarter([1.0, 0.0], [0.0, 1.0], [0.0, 0.0], half_pi),
                Segment::Line {
                    a: [0.0, 1.0],
                    b: [0.0, -1.0],
                },
            ]),
            tool_axis: None,
            ..square(true)
        };
        let length = std::f64::consts::PI + 2.0;
        assert!((d.length() - length).abs() < 1e-12);
        let runs = |p: &Toolpath| {
            let n = p.points.len();
            p.segments.iter().flatten().enumerate().all(|(i, s)| {
                let (a, b) = (p.points[i], p.points[(i + 1) % n]);
                s.start() == [a.x, a.y] && s.end() == [b.x, b.y]
            })
        };
        d.reverse();
        assert!(runs(&d));
        assert!((d.length() - length).abs() < 1e-12);
        d.rotate_start(1);
        assert!(runs(&d));
        let chords = d.chords(1e-3).expect("a path with segments");
        assert_eq!(chords.first(), chords.last(), "a loop returns to its start");
        assert!(chords.len() > 4, "arcs are flattened into several chords");
        assert_eq!(square(true).chords(1e-3), None);
    }

    #[test]
    fn type_names_are_prusaslicer_names_and_round_trip() {
        assert_eq!(Role::SparseInfill.type_name(), "Internal infill");
        assert_eq!(Role::Skirt.type_name(), "Skirt/Brim");
        for role in Role::ALL {
            let back = Role::from_type_name(role.type_name());
            let want = if role == Role::BottomSolidInfill {
                Role::SolidInfill
            } else {
                role
            };
            assert_eq!(back, Some(want));
        }
        assert_eq!(Role::WipeTower.type_name(), "Wipe tower");
        assert_eq!(Role::from_type_name("Ironing"), None);
    }
}
