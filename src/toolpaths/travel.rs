//! Which travels need no retraction: those that stay inside the part's internal infill.
//!
//! Place in the pipeline: the last step of the toolpaths stage, after ordering. The writer
//! retracts before every travel longer than `printer.retract_before_travel`; a travel from one
//! path to the next that runs entirely inside the layer's *internal* infill area (sparse infill,
//! internal solid infill and internal bridges, within the innermost perimeters) is marked with
//! [`Event::TravelInsideInfill`] before the path it leads to, and the writer does not retract
//! for it. This is PrusaSlicer's `only_retract_when_crossing_perimeters`, with a stricter area:
//! PrusaSlicer accepts a travel anywhere inside the internal part of the layer's slice,
//! perimeters included; here the travel must not touch the innermost perimeter at all.
//!
//! Why this area gives the better print: whatever oozes on such a travel lands on infill that
//! the next layers cover, so the retraction it saves (its time, its blob at the un-retraction,
//! its wear of the filament) costs nothing visible. A travel that crosses a perimeter would
//! drag the ooze over a wall or out of the part; one over top or bottom solid infill would
//! leave it on a visible surface, and one over a bridge or a layer without sparse infill
//! would drop it into air: all of those still retract.
//!
//! The test is exact in scaled integers: both ends inside one ExPolygon of the area, grown by
//! [`EDGE_TOLERANCE_MM`], and the straight travel touching none of its edges.

use crate::geom::{ExPolygon, Join, Point2, Point3, Polygon, offset, union};
use crate::program::{Event, LayerItem};
use crate::region::LayerRegions;

/// Infill lines and the links between them end on the edge of the infill area, where a point
/// test may go either way; the area is grown by this much (mm) so that a travel between two
/// such ends counts as inside. The innermost perimeter's centreline lies more than a quarter of
/// a bead beyond that edge, so the grown area still stays clear of it.
pub const EDGE_TOLERANCE_MM: f64 = 0.05;

/// Pieces of the infill area (and holes in it) narrower on average than this (mm) are
/// slivers, not area a travel could use: see [`crate::geom::Polygon::mean_width_mm`].
const SLIVER_WIDTH_MM: f64 = 0.001;

/// Which travels [`mark_inside_travels`] marks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TravelParams {
    /// Mark the travels that stay inside the internal infill, so that the writer retracts only
    /// for travels that cross a perimeter or leave the internal infill (PrusaSlicer's
    /// `only_retract_when_crossing_perimeters`). Default true.
    pub only_retract_when_crossing_perimeters: bool,
    /// Travels this long or shorter (mm) are not examined: the writer does not retract for them
    /// anyway (`printer.retract_before_travel`). Default 2.
    pub min_length: f64,
}

impl Default for TravelParams {
    fn default() -> Self {
        Self {
            only_retract_when_crossing_perimeters: true,
            min_length: 2.0,
        }
    }
}

/// The internal infill area of one tool's objects on one layer, grown by
/// [`EDGE_TOLERANCE_MM`], with each piece's bounding box for a quick first test.
#[derive(Debug, Clone, Default)]
pub struct InsideArea {
    pieces: Vec<(ExPolygon, [i64; 4])>,
}

impl InsideArea {
    /// The area of `regions` (one entry per object printed with the tool on the layer): the
    /// internal solid and internal bridge areas, and the sparse area where the layer has sparse
    /// infill lines (at 0 % density the sparse area is air).
    pub fn new<'a>(regions: impl IntoIterator<Item = &'a LayerRegions>) -> Self {
        let mut parts: Vec<ExPolygon> = Vec::new();
        for r in regions {
            parts.extend(r.skins.internal_solid.iter().cloned());
            parts.extend(r.skins.internal_bridge.iter().cloned());
            if !r.sparse_infill.is_empty() {
                parts.extend(r.skins.sparse.iter().cloned());
            }
        }
        if parts.is_empty() {
            return Self::default();
        }
        // Slivers a few nanometres wide, left where two skins' edges almost coincide, hold no
        // travel, and hundreds of them make the offset below take minutes on a layer of a
        // dense circuit; they go before it.
        let merged = union(&parts)
            .into_iter()
            .filter(|e| e.contour.mean_width_mm() >= SLIVER_WIDTH_MM)
            .map(|mut e| {
                e.holes.retain(|h| h.mean_width_mm() >= SLIVER_WIDTH_MM);
                e
            })
            .collect::<Vec<_>>();
        let grown = offset(&merged, EDGE_TOLERANCE_MM, Join::Miter(2.0));
        let pieces = grown
            .into_iter()
            .map(|e| {
                let b = super::bounds(e.contour.points.iter());
                (e, b)
            })
            .collect();
        Self { pieces }
    }

    /// Whether the area is empty (no travel can be inside it).
    pub fn is_empty(&self) -> bool {
        self.pieces.is_empty()
    }

    /// Whether the straight segment `a`–`b` lies inside the area: both ends inside the same
    /// piece and the segment touching none of its edges (a segment that grazes an edge counts
    /// as leaving).
    pub fn contains_segment(&self, a: Point2, b: Point2) -> bool {
        self.pieces.iter().any(|(e, bx)| {
            let within = |p: Point2| p.x >= bx[0] && p.x <= bx[2] && p.y >= bx[1] && p.y <= bx[3];
            within(a)
                && within(b)
                && e.contains(a)
                && e.contains(b)
                && std::iter::once(&e.contour)
                    .chain(&e.holes)
                    .all(|ring| !touches_ring(a, b, ring))
        })
    }
}

/// Sign of the turn `p → q → r`: 1 left, -1 right, 0 collinear (exact).
fn orient(p: Point2, q: Point2, r: Point2) -> i8 {
    p.cross(q, r).signum() as i8
}

/// Whether `p`, collinear with `a`–`b`, lies on that segment.
fn on_segment(p: Point2, a: Point2, b: Point2) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Whether the closed segments `a`–`b` and `c`–`d` share a point.
fn segments_touch(a: Point2, b: Point2, c: Point2, d: Point2) -> bool {
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    (o1 == 0 && on_segment(c, a, b))
        || (o2 == 0 && on_segment(d, a, b))
        || (o3 == 0 && on_segment(a, c, d))
        || (o4 == 0 && on_segment(b, c, d))
}

/// Whether the segment `a`–`b` touches an edge of the closed `ring`.
fn touches_ring(a: Point2, b: Point2, ring: &Polygon) -> bool {
    let pts = &ring.points;
    let (lo_x, hi_x) = (a.x.min(b.x), a.x.max(b.x));
    let (lo_y, hi_y) = (a.y.min(b.y), a.y.max(b.y));
    (0..pts.len()).any(|i| {
        let (c, d) = (pts[i], pts[(i + 1) % pts.len()]);
        // Edges wholly beside the segment's box cannot touch it.
        if c.x.max(d.x) < lo_x || c.x.min(d.x) > hi_x || c.y.max(d.y) < lo_y || c.y.min(d.y) > hi_y
        {
            return false;
        }
        segments_touch(a, b, c, d)
    })
}

fn xy(p: &Point3) -> Point2 {
    Point2::from_mm(p.x, p.y)
}

/// `items` (one tool's paths and events on one layer, in print order) with an
/// [`Event::TravelInsideInfill`] before every path whose travel from the previous path's end
/// is longer than [`TravelParams::min_length`] and lies inside `area`. The first path is not
/// marked: the travel to it comes from another layer or tool.
pub fn mark_inside_travels(
    items: Vec<LayerItem>,
    area: &InsideArea,
    params: &TravelParams,
) -> Vec<LayerItem> {
    if !params.only_retract_when_crossing_perimeters || area.is_empty() {
        return items;
    }
    let mut out = Vec::with_capacity(items.len());
    let mut last_end: Option<Point3> = None;
    for item in items {
        if let LayerItem::Path(p) = &item {
            if let (Some(from), Some(to)) = (last_end, p.points.first())
                && (to - from).xy().norm() > params.min_length
                && area.contains_segment(xy(&from), xy(to))
            {
                out.push(LayerItem::Event(Event::TravelInsideInfill));
            }
            last_end = p.end().copied().or(last_end);
        }
        out.push(item);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::{Role, Toolpath};
    use crate::region::test_util::rect;

    /// A 20 mm square with a 4 mm square hole in the middle, as the area itself (not grown).
    fn holed_square() -> InsideArea {
        let mut hole = rect(8.0, 8.0, 12.0, 12.0);
        hole.points.reverse();
        let e = ExPolygon {
            contour: rect(0.0, 0.0, 20.0, 20.0),
            holes: vec![hole],
        };
        let b = crate::toolpaths::bounds(e.contour.points.iter());
        InsideArea {
            pieces: vec![(e, b)],
        }
    }

    fn p(x: f64, y: f64) -> Point2 {
        Point2::from_mm(x, y)
    }

    #[test]
    fn segments_inside_across_a_hole_and_out_of_the_area() {
        let area = holed_square();
        // Along the bottom strip, and diagonally through a corner region clear of the hole.
        assert!(area.contains_segment(p(1.0, 1.0), p(19.0, 1.0)));
        assert!(area.contains_segment(p(1.0, 5.0), p(5.0, 1.0)));
        // Across the hole: both ends inside, the middle in the hole.
        assert!(!area.contains_segment(p(2.0, 10.0), p(18.0, 10.0)));
        // Grazing the hole's corner exactly counts as leaving.
        assert!(!area.contains_segment(p(6.0, 6.0), p(14.0, 14.0)));
        // One end outside the area.
        assert!(!area.contains_segment(p(1.0, 1.0), p(25.0, 1.0)));
        // Along the outer edge itself: touching it counts as leaving.
        assert!(!area.contains_segment(p(0.0, 1.0), p(0.0, 19.0)));
    }

    #[test]
    fn the_area_is_internal_infill_grown_a_little_and_empty_without_it() {
        let square = ExPolygon {
            contour: rect(0.0, 0.0, 20.0, 20.0),
            holes: Vec::new(),
        };
        let mut r = crate::region::make_regions(
            &vec![vec![square]; 9],
            &crate::region::RegionParams::default(),
        );
        // The middle layer of nine, with the default three top and three bottom layers: sparse
        // only. The bottom layer is bottom skin only: nothing internal.
        let middle = InsideArea::new([&r[4]]);
        assert_eq!(middle.pieces.len(), 1);
        let sparse = &r[4].skins.sparse[0];
        let grown = middle.pieces[0].0.area_mm2() - sparse.area_mm2();
        let b = crate::toolpaths::bounds(sparse.contour.points.iter());
        let perimeter = 2.0 * crate::geom::unscaled(b[2] - b[0] + b[3] - b[1]);
        // A band EDGE_TOLERANCE_MM wide around the sparse area (its corners add a few µm²).
        assert!(
            (grown - perimeter * EDGE_TOLERANCE_MM).abs() < 0.02,
            "grown by {grown} mm² around {perimeter} mm"
        );
        assert!(InsideArea::new([&r[0]]).is_empty());
        // Without sparse lines (0 % density) the sparse area is air.
        r[4].sparse_infill.clear();
        assert!(InsideArea::new([&r[4]]).is_empty());
    }

    fn line(x0: f64, y0: f64, x1: f64, y1: f64) -> LayerItem {
        LayerItem::Path(Toolpath {
            points: vec![Point3::new(x0, y0, 1.0), Point3::new(x1, y1, 1.0)],
            closed: false,
            role: Role::SparseInfill,
            tool: 0,
            width: 0.45,
            height: 0.2,
            speed: 50.0,
            tool_axis: None,
            segments: None,
        })
    }

    #[test]
    fn only_long_travels_inside_the_area_are_marked() {
        let area = holed_square();
        let items = vec![
            line(1.0, 1.0, 5.0, 1.0),
            // 1 mm away: short, not marked.
            line(5.0, 2.0, 1.0, 2.0),
            // 10 mm along the left strip: marked.
            line(1.0, 12.0, 1.0, 15.0),
            // From (1, 15) through the hole's middle: not marked.
            line(19.0, 5.0, 19.0, 3.0),
        ];
        let params = TravelParams::default();
        let out = mark_inside_travels(items.clone(), &area, &params);
        let marks: Vec<usize> = out
            .iter()
            .enumerate()
            .filter(|(_, i)| matches!(i, LayerItem::Event(Event::TravelInsideInfill)))
            .map(|(k, _)| k)
            .collect();
        assert_eq!(marks, vec![2], "{out:?}");
        let off = TravelParams {
            only_retract_when_crossing_perimeters: false,
            ..params
        };
        assert_eq!(mark_inside_travels(items.clone(), &area, &off), items);
    }
}
