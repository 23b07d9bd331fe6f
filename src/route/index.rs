//! Point and segment queries against the rings of a region, bucketed into horizontal bands.
//!
//! Place in the pipeline: a helper of the router (`route`), which asks many "is this point in the
//! material?", "where does this rubberband cross the perimeter traces?" and "does this link cross
//! a channel?" questions per layer. Edges are sorted into 1 mm bands of y, so a query only looks
//! at the edges whose y range overlaps the query's. A map of 0.5 mm cells marks the cells an
//! edge's bounding box touches: a query that touches no marked cell is answered without looking
//! at an edge (no crossing, not near the boundary), and a point in an unmarked cell shares the
//! inside/outside answer of every point of that cell, which is worked out once and kept. The
//! map also lists each cell's edges, so a yes/no query over a few cells (does this grid link
//! cross the boundary, is this point near it) looks only at the edges there, not at a band
//! across the whole layer.
//!
//! Orientation tests are exact (`i128` cross products of nanometre coordinates); only the
//! parameters of intersection points are `f64`.

use crate::geom::{ExPolygon, Point2, segment_distance};
use std::sync::atomic::{AtomicU8, Ordering};

/// Height of one band of edges, in scaled units (1 mm).
const BAND: i64 = 1_000_000;

/// Side of a cell of the cell map, scaled units (0.5 mm); larger for regions that would need
/// more than [`MAX_CELLS`].
const CELL: i64 = 500_000;

/// Most bands in one index: a region taller than `MAX_BANDS` mm gets taller bands, so the
/// band table stays bounded however far apart the rings lie.
const MAX_BANDS: i64 = 1 << 16;

/// Most cells in one cell map.
const MAX_CELLS: i64 = 1 << 22;

/// Most cells a yes/no query (a crossing, a point near the boundary) looks through by the cell
/// map's edge lists; a query over a larger box scans the bands instead. Either way it sees every
/// edge whose box meets its own, so the answer is the same.
const CELL_QUERY: i64 = 16;

/// Inside/outside of the points of an unmarked cell: not yet known.
const UNKNOWN: u8 = 0;
/// ... all inside.
const INSIDE: u8 = 1;
/// ... all outside.
const OUTSIDE: u8 = 2;

/// Which cells of a grid over the edges' bounding box an edge's bounding box touches, and the
/// inside/outside answer of the untouched ones once asked.
#[derive(Debug, Default)]
struct CellMap {
    x0: i64,
    y0: i64,
    size: i64,
    nx: i64,
    ny: i64,
    marked: Vec<bool>,
    /// Atomic so an index can be shared between threads: two threads that both work out a
    /// cell's answer store the same value.
    answer: Vec<AtomicU8>,
    /// The edges whose box touches each cell (indices into the index's edges, in edge order),
    /// cell `k`'s from `starts[k]` to `starts[k + 1]` in `ids`.
    starts: Vec<u32>,
    ids: Vec<u32>,
}

impl Clone for CellMap {
    fn clone(&self) -> Self {
        Self {
            marked: self.marked.clone(),
            answer: self
                .answer
                .iter()
                .map(|a| AtomicU8::new(a.load(Ordering::Relaxed)))
                .collect(),
            starts: self.starts.clone(),
            ids: self.ids.clone(),
            ..*self
        }
    }
}

impl CellMap {
    fn new(edges: &[Edge]) -> Self {
        let Some((x0, y0, x1, y1)) =
            edges
                .iter()
                .fold(None, |b: Option<(i64, i64, i64, i64)>, e| {
                    let (lx, ly) = (e.a.x.min(e.b.x), e.a.y.min(e.b.y));
                    let (hx, hy) = (e.a.x.max(e.b.x), e.a.y.max(e.b.y));
                    Some(b.map_or((lx, ly, hx, hy), |b| {
                        (b.0.min(lx), b.1.min(ly), b.2.max(hx), b.3.max(hy))
                    }))
                })
        else {
            return Self::default();
        };
        let mut size = CELL;
        // In i128: for a region billions of millimetres wide the product overflows i64.
        while (((x1 - x0) / size + 1) as i128) * (((y1 - y0) / size + 1) as i128)
            > MAX_CELLS as i128
        {
            size *= 2;
        }
        let (nx, ny) = ((x1 - x0) / size + 1, (y1 - y0) / size + 1);
        let cells = (nx * ny) as usize;
        let mut map = Self {
            x0,
            y0,
            size,
            nx,
            ny,
            marked: vec![false; cells],
            answer: (0..cells).map(|_| AtomicU8::new(UNKNOWN)).collect(),
            starts: vec![0; cells + 1],
            ids: Vec::new(),
        };
        let boxes: Vec<(i64, i64, i64, i64)> = edges
            .iter()
            .map(|e| {
                let (cx0, cy0) = map.cell(e.a.x.min(e.b.x), e.a.y.min(e.b.y));
                let (cx1, cy1) = map.cell(e.a.x.max(e.b.x), e.a.y.max(e.b.y));
                (cx0, cy0, cx1, cy1)
            })
            .collect();
        // Counted, then filled: each cell's edges lie together, in edge order.
        for &(cx0, cy0, cx1, cy1) in &boxes {
            for cy in cy0..=cy1 {
                for cx in cx0..=cx1 {
                    let k = (cy * nx + cx) as usize;
                    map.marked[k] = true;
                    map.starts[k + 1] += 1;
                }
            }
        }
        for k in 0..cells {
            map.starts[k + 1] += map.starts[k];
        }
        let mut next: Vec<u32> = map.starts[..cells].to_vec();
        map.ids = vec![0; map.starts[cells] as usize];
        for (i, &(cx0, cy0, cx1, cy1)) in boxes.iter().enumerate() {
            for cy in cy0..=cy1 {
                for cx in cx0..=cx1 {
                    let k = (cy * nx + cx) as usize;
                    map.ids[next[k] as usize] = i as u32;
                    next[k] += 1;
                }
            }
        }
        map
    }

    /// The cell holding `(x, y)`, clamped to the grid.
    fn cell(&self, x: i64, y: i64) -> (i64, i64) {
        (
            ((x - self.x0).div_euclid(self.size)).clamp(0, self.nx - 1),
            ((y - self.y0).div_euclid(self.size)).clamp(0, self.ny - 1),
        )
    }

    /// Whether the box `lo..=hi` reaches past the grid or touches a marked cell: whether an edge
    /// may pass through it.
    fn may_touch(&self, lo: Point2, hi: Point2) -> bool {
        if self.marked.is_empty() {
            return false;
        }
        let (cx0, cy0) = self.cell(lo.x, lo.y);
        let (cx1, cy1) = self.cell(hi.x, hi.y);
        (cy0..=cy1).any(|cy| (cx0..=cx1).any(|cx| self.marked[(cy * self.nx + cx) as usize]))
    }

    /// The edges whose box touches a cell of the box `lo..=hi` (an edge may come more than
    /// once), if that box spans at most `max_cells` cells; `None` for a larger box.
    fn edges_near(
        &self,
        lo: Point2,
        hi: Point2,
        max_cells: i64,
    ) -> Option<impl Iterator<Item = u32> + '_> {
        if self.marked.is_empty() {
            return None;
        }
        let (cx0, cy0) = self.cell(lo.x, lo.y);
        let (cx1, cy1) = self.cell(hi.x, hi.y);
        if (cx1 - cx0 + 1) * (cy1 - cy0 + 1) > max_cells {
            return None;
        }
        Some((cy0..=cy1).flat_map(move |cy| {
            (cx0..=cx1).flat_map(move |cx| {
                let k = (cy * self.nx + cx) as usize;
                self.ids[self.starts[k] as usize..self.starts[k + 1] as usize]
                    .iter()
                    .copied()
            })
        }))
    }

    /// The unmarked cell holding `p`, if `p` is on the grid and its cell is unmarked.
    fn free_cell(&self, p: Point2) -> Option<usize> {
        if self.marked.is_empty()
            || p.x < self.x0
            || p.y < self.y0
            || (p.x - self.x0) / self.size >= self.nx
            || (p.y - self.y0) / self.size >= self.ny
        {
            return None;
        }
        let k = (((p.y - self.y0) / self.size) * self.nx + (p.x - self.x0) / self.size) as usize;
        (!self.marked[k]).then_some(k)
    }

    /// Whether `p` lies outside the box of all edges (and so outside the region).
    fn off_grid(&self, p: Point2) -> bool {
        self.marked.is_empty()
            || p.x < self.x0
            || p.y < self.y0
            || p.x > self.x0 + self.nx * self.size
            || p.y > self.y0 + self.ny * self.size
    }
}

/// One edge of a ring, with the group it belongs to and its index within its ring.
#[derive(Debug, Clone, Copy)]
struct Edge {
    a: Point2,
    b: Point2,
    group: u32,
    index: u32,
}

/// Where a query segment meets an edge of the index.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Hit {
    /// Parameter along the query segment, 0 at its start, 1 at its end.
    pub t: f64,
    /// Group of the edge hit (ring or island number, as given to [`RegionIndex::new`]).
    pub group: u32,
    /// Index of the edge within its ring (edge `k` runs from point `k` to point `k + 1`).
    pub edge: u32,
    /// Parameter along the edge.
    pub u: f64,
    /// The meeting point, rounded to the nanometre.
    pub point: Point2,
}

/// Edges of a set of closed rings, bucketed by y for point-in-region and crossing queries.
///
/// Containment uses the even-odd rule over all rings, which is the region's interior when the
/// rings are those of non-overlapping [`ExPolygon`]s (contours and holes).
#[derive(Debug, Clone, Default)]
pub(crate) struct RegionIndex {
    edges: Vec<Edge>,
    y0: i64,
    /// Height of one band, scaled units: [`BAND`], or more for a region of more than
    /// [`MAX_BANDS`] bands.
    band: i64,
    /// The edges of each band, copied in edge order (a band's edges lie together in memory,
    /// which the scans of a query run through), each with the band of its lowest point.
    bands: Vec<Vec<(Edge, u32)>>,
    cells: CellMap,
}

fn orient(a: Point2, b: Point2, p: Point2) -> i128 {
    a.cross(b, p)
}

fn sign(v: i128) -> i8 {
    v.signum() as i8
}

/// Whether `a`–`b` and the edge cross at one point interior to both.
fn proper_crossing(a: Point2, b: Point2, e: Edge) -> bool {
    if a.x.max(b.x) < e.a.x.min(e.b.x) || a.x.min(b.x) > e.a.x.max(e.b.x) {
        return false;
    }
    let (d1, d2) = (orient(e.a, e.b, a), orient(e.a, e.b, b));
    let (d3, d4) = (orient(a, b, e.a), orient(a, b, e.b));
    sign(d1) * sign(d2) < 0 && sign(d3) * sign(d4) < 0
}

/// The point at parameter `t` of `a`–`b`, rounded to the nanometre.
pub(crate) fn lerp(a: Point2, b: Point2, t: f64) -> Point2 {
    Point2::new(
        (a.x as f64 + t * (b.x - a.x) as f64).round() as i64,
        (a.y as f64 + t * (b.y - a.y) as f64).round() as i64,
    )
}

/// Euclidean distance between two points, scaled units as `f64`.
pub(crate) fn dist(a: Point2, b: Point2) -> f64 {
    (a.distance_squared(b) as f64).sqrt()
}

/// Every ring of `regions` (contours and holes), grouped by the index of its ExPolygon.
pub(crate) fn expolygon_rings(regions: &[ExPolygon]) -> Vec<(u32, &[Point2])> {
    regions
        .iter()
        .enumerate()
        .flat_map(|(i, ex)| {
            std::iter::once(&ex.contour)
                .chain(ex.holes.iter())
                .map(move |r| (i as u32, r.points.as_slice()))
        })
        .collect()
}

impl RegionIndex {
    /// An index over closed `rings`, each tagged with a group number.
    pub(crate) fn new(rings: &[(u32, &[Point2])]) -> Self {
        let mut edges = Vec::new();
        for &(group, ring) in rings {
            if ring.len() < 2 {
                continue;
            }
            for k in 0..ring.len() {
                let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
                if a != b {
                    edges.push(Edge {
                        a,
                        b,
                        group,
                        index: k as u32,
                    });
                }
            }
        }
        let Some(y0) = edges.iter().map(|e| e.a.y.min(e.b.y)).min() else {
            return Self::default();
        };
        let y1 = edges.iter().map(|e| e.a.y.max(e.b.y)).max().unwrap_or(y0);
        let band = if (y1 - y0) / BAND < MAX_BANDS {
            BAND
        } else {
            (y1 - y0) / MAX_BANDS + 1
        };
        let count = ((y1 - y0) / band + 1) as usize;
        let mut bands = vec![Vec::new(); count];
        for e in &edges {
            let lo = ((e.a.y.min(e.b.y) - y0) / band) as usize;
            let hi = ((e.a.y.max(e.b.y) - y0) / band) as usize;
            for band in &mut bands[lo..=hi.min(count - 1)] {
                band.push((*e, lo as u32));
            }
        }
        let cells = CellMap::new(&edges);
        Self {
            edges,
            y0,
            band,
            bands,
            cells,
        }
    }

    /// An index over the rings of `regions`, grouped by ExPolygon.
    pub(crate) fn of_regions(regions: &[ExPolygon]) -> Self {
        Self::new(&expolygon_rings(regions))
    }

    /// Whether the index holds no edges (an empty region).
    pub(crate) fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Edges of the bands overlapping `y_lo..=y_hi`, each once (in the first of those bands it
    /// lies in).
    fn edges_between(&self, y_lo: i64, y_hi: i64) -> impl Iterator<Item = Edge> + '_ {
        let last = self.bands.len() as i64 - 1;
        let band = |y: i64| (y - self.y0).div_euclid(self.band.max(1));
        let range = (!self.bands.is_empty() && band(y_hi) >= 0 && band(y_lo) <= last)
            .then(|| (band(y_lo).max(0) as usize, band(y_hi).min(last) as usize));
        range.into_iter().flat_map(move |(lo, hi)| {
            (lo..=hi).flat_map(move |k| {
                self.bands[k]
                    .iter()
                    .filter(move |(_, first)| (*first as usize).max(lo) == k)
                    .map(|(e, _)| *e)
            })
        })
    }

    /// Edges of the band holding `y` (each edge whose y range contains `y` is there).
    fn band_at(&self, y: i64) -> &[(Edge, u32)] {
        if self.bands.is_empty() || y < self.y0 {
            return &[];
        }
        let k = ((y - self.y0) / self.band.max(1)) as usize;
        self.bands.get(k).map_or(&[], Vec::as_slice)
    }

    /// Whether `p` is strictly inside (even-odd over all rings). Points exactly on an edge may go
    /// either way; use [`Self::inside_or_on`] where the boundary matters.
    pub(crate) fn contains(&self, p: Point2) -> bool {
        if self.cells.off_grid(p) {
            return false;
        }
        match self.cells.free_cell(p) {
            Some(k) => self.cell_answer(k, p),
            None => self.row_parity(p),
        }
    }

    /// Whether the points of the unmarked cell `k` are inside (`p` being one of them): worked
    /// out by a ray from `p` once, then kept.
    fn cell_answer(&self, k: usize, p: Point2) -> bool {
        match self.cells.answer[k].load(Ordering::Relaxed) {
            INSIDE => true,
            OUTSIDE => false,
            _ => {
                let inside = self.ray_parity(p);
                self.cells.answer[k]
                    .store(if inside { INSIDE } else { OUTSIDE }, Ordering::Relaxed);
                inside
            }
        }
    }

    /// [`Self::ray_parity`] of `p` (on the grid, in a marked cell) from the cells of its row
    /// alone: the ray is cut at `q`, the first point of the next unmarked cell to the right,
    /// whose answer the cell holds (or past the grid, where nothing lies). Only edges whose
    /// box reaches the row between `p` and `q` can tell `p` from `q` — one lying wholly beyond
    /// `q` has both on its left, one wholly before `p` neither — and those are in the cells
    /// walked; each is counted in the first of them it touches. The answer is the same as the
    /// ray's over the whole band, at a fraction of the edges.
    fn row_parity(&self, p: Point2) -> bool {
        let cells = &self.cells;
        let (cx, cy) = cells.cell(p.x, p.y);
        let row = cy * cells.nx;
        let mut end = cx + 1;
        while end < cells.nx && cells.marked[(row + end) as usize] {
            end += 1;
        }
        let q = Point2::new(cells.x0 + end * cells.size, p.y);
        let mut inside = end < cells.nx && self.cell_answer((row + end) as usize, q);
        for c in cx..end {
            let k = (row + c) as usize;
            for &id in &cells.ids[cells.starts[k] as usize..cells.starts[k + 1] as usize] {
                let e = self.edges[id as usize];
                if (e.a.y > p.y) == (e.b.y > p.y)
                    || cells.cell(e.a.x.min(e.b.x), p.y).0.max(cx) != c
                {
                    continue;
                }
                let (lo, hi) = if e.a.y < e.b.y {
                    (e.a, e.b)
                } else {
                    (e.b, e.a)
                };
                if (orient(lo, hi, p) > 0) != (end < cells.nx && orient(lo, hi, q) > 0) {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// Even-odd parity of the edges a ray from `p` towards +x crosses.
    fn ray_parity(&self, p: Point2) -> bool {
        let mut inside = false;
        for &(e, _) in self.band_at(p.y) {
            if (e.a.y > p.y) != (e.b.y > p.y) && e.a.x.max(e.b.x) >= p.x {
                let (lo, hi) = if e.a.y < e.b.y {
                    (e.a, e.b)
                } else {
                    (e.b, e.a)
                };
                if orient(lo, hi, p) > 0 {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// Whether `p` lies within `tol` (scaled units) of an edge.
    pub(crate) fn near_boundary(&self, p: Point2, tol: i64) -> bool {
        let (lo, hi) = (
            Point2::new(p.x - tol, p.y - tol),
            Point2::new(p.x + tol, p.y + tol),
        );
        if !self.cells.may_touch(lo, hi) {
            return false;
        }
        let near = |e: &Edge| {
            e.a.x.min(e.b.x) - tol <= p.x
                && e.a.x.max(e.b.x) + tol >= p.x
                && segment_distance(p, e.a, e.b) <= tol as f64
        };
        match self.cells.edges_near(lo, hi, CELL_QUERY) {
            Some(mut ids) => ids.any(|i| near(&self.edges[i as usize])),
            None => self.edges_between(p.y - tol, p.y + tol).any(|e| near(&e)),
        }
    }

    /// Whether `p` is inside or within `tol` of the boundary.
    pub(crate) fn inside_or_on(&self, p: Point2, tol: i64) -> bool {
        self.contains(p) || self.near_boundary(p, tol)
    }

    /// Groups whose rings contain `p` (even-odd per group) or pass within `tol` of it, sorted.
    pub(crate) fn groups_at(&self, p: Point2, tol: i64) -> Vec<u32> {
        let mut parity: Vec<(u32, bool)> = Vec::new();
        for &(e, _) in self.band_at(p.y) {
            if (e.a.y > p.y) != (e.b.y > p.y) {
                let (lo, hi) = if e.a.y < e.b.y {
                    (e.a, e.b)
                } else {
                    (e.b, e.a)
                };
                if orient(lo, hi, p) > 0 {
                    match parity.iter_mut().find(|(g, _)| *g == e.group) {
                        Some(entry) => entry.1 = !entry.1,
                        None => parity.push((e.group, true)),
                    }
                }
            }
        }
        let mut groups: Vec<u32> = parity.into_iter().filter(|g| g.1).map(|g| g.0).collect();
        for e in self.edges_between(p.y - tol, p.y + tol) {
            if segment_distance(p, e.a, e.b) <= tol as f64 {
                groups.push(e.group);
            }
        }
        groups.sort_unstable();
        groups.dedup();
        groups
    }

    /// Every point where the segment `a`–`b` meets an edge (crossing or touching; collinear
    /// overlaps are skipped), sorted by the parameter along `a`–`b`, then by group and edge.
    pub(crate) fn hits(&self, a: Point2, b: Point2) -> Vec<Hit> {
        let mut out = Vec::new();
        for e in self.edges_between(a.y.min(b.y), a.y.max(b.y)) {
            if a.x.max(b.x) < e.a.x.min(e.b.x) || a.x.min(b.x) > e.a.x.max(e.b.x) {
                continue;
            }
            let (d1, d2) = (orient(e.a, e.b, a), orient(e.a, e.b, b));
            let (d3, d4) = (orient(a, b, e.a), orient(a, b, e.b));
            if d1 == d2 || d3 == d4 {
                // Parallel (or collinear): no single meeting point.
                continue;
            }
            if sign(d1) * sign(d2) > 0 || sign(d3) * sign(d4) > 0 {
                continue;
            }
            let t = d1 as f64 / (d1 - d2) as f64;
            let u = d3 as f64 / (d3 - d4) as f64;
            out.push(Hit {
                t,
                group: e.group,
                edge: e.index,
                u,
                point: lerp(a, b, t),
            });
        }
        out.sort_by(|x, y| {
            x.t.total_cmp(&y.t)
                .then(x.group.cmp(&y.group))
                .then(x.edge.cmp(&y.edge))
        });
        out
    }

    /// The midpoints of the stretches of the segment `a`–`b` between the points where it meets
    /// an edge: each stretch lies wholly on one side of the boundary (or along it), so its
    /// midpoint tells where all of it runs.
    pub(crate) fn stretch_midpoints(&self, a: Point2, b: Point2) -> Vec<Point2> {
        let mut ts: Vec<f64> = vec![0.0, 1.0];
        ts.extend(self.hits(a, b).iter().map(|h| h.t));
        ts.sort_by(f64::total_cmp);
        ts.windows(2)
            .filter(|t| t[1] > t[0])
            .map(|t| lerp(a, b, (t[0] + t[1]) / 2.0))
            .collect()
    }

    /// The fraction of the segment `a`–`b` that runs inside the region (0 to 1).
    pub(crate) fn inside_fraction(&self, a: Point2, b: Point2) -> f64 {
        if !self.crosses(a, b) {
            return if self.contains(lerp(a, b, 0.5)) {
                1.0
            } else {
                0.0
            };
        }
        let mut ts: Vec<f64> = vec![0.0, 1.0];
        ts.extend(self.hits(a, b).iter().map(|h| h.t));
        ts.sort_by(f64::total_cmp);
        ts.windows(2)
            .filter(|t| t[1] > t[0] && self.contains(lerp(a, b, (t[0] + t[1]) / 2.0)))
            .map(|t| t[1] - t[0])
            .sum()
    }

    /// Whether the segment `a`–`b` properly crosses an edge (touching does not count).
    pub(crate) fn crosses(&self, a: Point2, b: Point2) -> bool {
        let lo = Point2::new(a.x.min(b.x), a.y.min(b.y));
        let hi = Point2::new(a.x.max(b.x), a.y.max(b.y));
        if !self.cells.may_touch(lo, hi) {
            return false;
        }
        match self.cells.edges_near(lo, hi, CELL_QUERY) {
            Some(mut ids) => ids.any(|i| proper_crossing(a, b, self.edges[i as usize])),
            None => self
                .edges_between(a.y.min(b.y), a.y.max(b.y))
                .any(|e| proper_crossing(a, b, e)),
        }
    }

    /// How many times the segment `a`–`b` properly crosses the boundary.
    pub(crate) fn count_crossings(&self, a: Point2, b: Point2) -> usize {
        self.edges_between(a.y.min(b.y), a.y.max(b.y))
            .filter(|e| proper_crossing(a, b, *e))
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Polygon;

    fn square(x0: f64, y0: f64, s: f64) -> Polygon {
        Polygon::new(vec![
            Point2::from_mm(x0, y0),
            Point2::from_mm(x0 + s, y0),
            Point2::from_mm(x0 + s, y0 + s),
            Point2::from_mm(x0, y0 + s),
        ])
    }

    fn annulus() -> ExPolygon {
        let mut hole = square(15.0, 15.0, 30.0);
        hole.points.reverse();
        ExPolygon {
            contour: square(0.0, 0.0, 60.0),
            holes: vec![hole],
        }
    }

    #[test]
    fn containment_respects_holes() {
        let idx = RegionIndex::of_regions(&[annulus()]);
        assert!(idx.contains(Point2::from_mm(5.0, 30.0)));
        assert!(!idx.contains(Point2::from_mm(30.0, 30.0)));
        assert!(!idx.contains(Point2::from_mm(70.0, 30.0)));
        assert!(idx.inside_or_on(Point2::from_mm(15.0, 30.0), 10));
        assert_eq!(idx.groups_at(Point2::from_mm(5.0, 5.0), 10), vec![0]);
    }

    #[test]
    fn a_line_across_the_annulus_meets_four_edges_in_order() {
        let idx = RegionIndex::of_regions(&[annulus()]);
        let (a, b) = (Point2::from_mm(-5.0, 30.0), Point2::from_mm(65.0, 30.0));
        let hits = idx.hits(a, b);
        let xs: Vec<f64> = hits.iter().map(|h| h.point.to_mm().0).collect();
        assert_eq!(xs, vec![0.0, 15.0, 45.0, 60.0]);
        assert_eq!(idx.count_crossings(a, b), 4);
        assert!(idx.crosses(a, b));
        assert!(!idx.crosses(Point2::from_mm(1.0, 1.0), Point2::from_mm(10.0, 2.0)));
    }

    #[test]
    fn a_point_by_the_edges_gets_the_answer_of_a_ray_across_the_whole_band() {
        // A comb of thin teeth and holes, so rows hold many marked cells in a run.
        let mut regions = vec![annulus()];
        for k in 0..40 {
            let x = 70.0 + k as f64 * 0.7;
            regions.push(ExPolygon {
                contour: Polygon::new(vec![
                    Point2::from_mm(x, 0.0),
                    Point2::from_mm(x + 0.3, 0.1 * k as f64),
                    Point2::from_mm(x + 0.35, 40.0),
                    Point2::from_mm(x - 0.05, 39.0 - 0.2 * k as f64),
                ]),
                holes: Vec::new(),
            });
        }
        let idx = RegionIndex::of_regions(&regions);
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = |span: i64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % span as u64) as i64
        };
        let mut walked = 0;
        for _ in 0..20_000 {
            // Points on a 0.05 mm lattice hit vertices and edges exactly now and then.
            let p = Point2::new(
                next(2_000) * 50_000 - 5_000_000,
                next(900) * 50_000 - 2_000_000,
            );
            if idx.cells.off_grid(p) || idx.cells.free_cell(p).is_some() {
                continue;
            }
            walked += 1;
            assert_eq!(idx.row_parity(p), idx.ray_parity(p), "{p:?}");
        }
        assert!(walked > 2_000, "{walked}");
    }

    #[test]
    fn rings_a_billion_millimetres_apart_get_a_bounded_index() {
        // The pads of a part at y = -1e9 mm beside a 60 mm object: before, one 1 mm band per
        // millimetre between them (24 GB).
        let far = square(0.0, -1e9, 2.0);
        let regions = [
            annulus(),
            ExPolygon {
                contour: far,
                holes: Vec::new(),
            },
        ];
        let idx = RegionIndex::of_regions(&regions);
        assert!(
            idx.bands.len() as i64 <= MAX_BANDS + 1,
            "{}",
            idx.bands.len()
        );
        assert!(idx.cells.marked.len() as i64 <= MAX_CELLS);
        assert!(idx.contains(Point2::from_mm(5.0, 30.0)));
        assert!(!idx.contains(Point2::from_mm(30.0, 30.0)));
        assert!(idx.contains(Point2::from_mm(1.0, -1e9 + 1.0)));
        assert_eq!(
            idx.count_crossings(Point2::from_mm(-5.0, 30.0), Point2::from_mm(65.0, 30.0)),
            4
        );
    }
}
