//! Material already printed as obstacles of the print head: the test of nozzle positions
//! against it, and the replay of written beads.
//!
//! Place in the pipeline: [`super`] runs it on each curved region before it accepts it; a
//! region with a hit stays planar and the hit is reported.
//!
//! The head is the `[curved]` head ([`ToolSolid::fff_head`]): a cone with its apex at the
//! nozzle tip, opening upward at `head_angle` from the vertical up to `head_height`, plus, when
//! `carriage_radius > 0`, a cylinder of that radius around the nozzle axis from
//! `carriage_clearance` above the tip upward. Two obstacles of the replay walk
//! ([`crate::surface::replay`]) hold the material: [`Material`], planar layers (their top z and
//! xy area) and single points (the surface itself), fixed while the nozzles are tested; and
//! the beads printed so far ([`replay`]), indexed in a grid and grown bead by bead.

use crate::geom::{ExPolygon, Point3};
use crate::surface::{
    Hit, Next, Obstacle, PieceShape, Sample, Spacing, Stretch, ToolPart, ToolSolid, walk,
};

/// A shape as float rings (contour first) with its bounding box [x0, y0, x1, y1].
type Shape = (Vec<Vec<(f64, f64)>>, [f64; 4]);

/// One planar layer of printed material, float mm rings with a bounding box.
#[derive(Debug, Clone, PartialEq)]
struct Slab {
    top: f64,
    /// Per ExPolygon: rings (contour first) and bounding box [x0, y0, x1, y1].
    shapes: Vec<Shape>,
}

/// Printed material the head must not enter.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Material {
    slabs: Vec<Slab>,
    points: Vec<Point3>,
}

impl Material {
    /// Adds a planar layer with its top at `top` covering `area`, keeping only the shapes whose
    /// bounding box meets `window` ([x0, y0, x1, y1], mm).
    pub fn add_layer(&mut self, top: f64, area: &[ExPolygon], window: [f64; 4]) {
        let mut shapes = Vec::new();
        for ex in area {
            let rings: Vec<Vec<(f64, f64)>> = std::iter::once(&ex.contour)
                .chain(&ex.holes)
                .map(|r| r.points.iter().map(|p| p.to_mm()).collect())
                .collect();
            let mut bb = [f64::MAX, f64::MAX, f64::MIN, f64::MIN];
            for &(x, y) in rings.first().into_iter().flatten() {
                bb = [bb[0].min(x), bb[1].min(y), bb[2].max(x), bb[3].max(y)];
            }
            if bb[0] <= window[2] && bb[2] >= window[0] && bb[1] <= window[3] && bb[3] >= window[1]
            {
                shapes.push((rings, bb));
            }
        }
        if !shapes.is_empty() {
            self.slabs.push(Slab { top, shapes });
        }
    }

    /// Adds single material points (e.g. the surface's vertices).
    pub fn add_points(&mut self, points: impl IntoIterator<Item = Point3>) {
        self.points.extend(points);
    }
}

impl Material {
    /// The first hit (in the order of `nozzles`) of `head` against the material.
    pub fn first_hit(&self, head: &ToolSolid, nozzles: &[Point3]) -> Option<Hit> {
        let mut first = None;
        self.walk_nozzles(head, nozzles, |hit| {
            first = Some(hit);
            Next::Stop
        });
        first
    }

    /// Every nozzle position of `nozzles` where `head` hits the material, each with its first
    /// hit, in order.
    pub fn hits(&self, head: &ToolSolid, nozzles: &[Point3]) -> Vec<Hit> {
        let mut out = Vec::new();
        self.walk_nozzles(head, nozzles, |hit| {
            out.push(hit);
            Next::Stretch
        });
        out
    }

    /// The replay walk of `nozzles`, each position a stretch of its own, handing every hit to
    /// `visit`.
    fn walk_nozzles(
        &self,
        head: &ToolSolid,
        nozzles: &[Point3],
        mut visit: impl FnMut(Hit) -> Next,
    ) {
        let stretches = nozzles.iter().map(|p| Stretch {
            points: std::slice::from_ref(p),
            closed: false,
            tested: true,
        });
        let mut obstacle = self;
        // One position per stretch: the spacing has nothing to space.
        walk(
            head,
            &mut obstacle,
            stretches,
            Spacing::Steps(1.0),
            |_, _, hit| hit.map_or(Next::Sample, &mut visit),
        );
    }

    /// The first hit of `head` against the material with the nozzle at `p`.
    pub fn hit_at(&self, head: &ToolSolid, p: Point3) -> Option<Hit> {
        for slab in &self.slabs {
            let Some((r, part)) = head.radius_at(slab.top - p.z) else {
                continue;
            };
            for (rings, bb) in &slab.shapes {
                if p.x + r < bb[0] || p.x - r > bb[2] || p.y + r < bb[1] || p.y - r > bb[3] {
                    continue;
                }
                if let Some((x, y)) = closest_within(rings, p.x, p.y, r) {
                    return Some(Hit {
                        nozzle: p,
                        material: Point3::new(x, y, slab.top),
                        part,
                    });
                }
            }
        }
        self.points.iter().find_map(|&q| Hit::of_point(head, p, q))
    }
}

/// The material as an obstacle: the contact is its first hit with the tip there; nothing is
/// laid down.
impl Obstacle for &Material {
    type Contact = Option<Hit>;

    fn contact(&self, tool: &ToolSolid, _index: usize, sample: &Sample) -> Option<Hit> {
        self.hit_at(tool, sample.tip)
    }
}

/// One printed bead for [`replay`]: a straight extrusion whose nozzle tip ran from `from` to
/// `to` (the tip is the bead's top), with a rounded-rectangle cross-section `width × height`
/// (the extrusion model of [`crate::program::extrusion`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bead {
    /// Start of the nozzle tip, mm.
    pub from: Point3,
    /// End of the nozzle tip, mm.
    pub to: Point3,
    /// Bead width, mm.
    pub width: f64,
    /// Bead height, mm.
    pub height: f64,
    /// How steeply the bead's top may lean across it, degrees: a bead of a curved layer lies
    /// on the surface and is lower on its downhill side, the side a lower nozzle beside it
    /// faces; 0 for a planar bead.
    pub lean_deg: f64,
}

/// A bead whose nozzle ran into material printed before it, found by [`replay`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReplayHit {
    /// Index of the bead being printed.
    pub bead: usize,
    /// Index of the earlier bead the head touched.
    pub earlier: usize,
    /// Nozzle position, the highest material point in the head and the part of the head.
    pub hit: Hit,
}

/// Settings of [`replay`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReplayTolerances {
    /// Material must stand more than this above the nozzle tip to count, mm: G-code rounds Z
    /// to 0.001 mm, so two beads printed at "the same" height may differ by that much.
    pub rise: f64,
    /// The nozzle is tested every this many mm along each bead (and at both ends), mm.
    pub sample: f64,
}

impl Default for ReplayTolerances {
    fn default() -> Self {
        Self {
            rise: 0.002,
            sample: 0.1,
        }
    }
}

/// Side of the grid cells [`replay`] sorts beads into, mm.
const REPLAY_CELL_MM: f64 = 2.0;

/// Replays `beads[start..]` in order: the nozzle runs along each bead (tested every
/// `tol.sample` mm) and every bead printed before it is material. Returns, per bead with a
/// hit, its first hit.
///
/// # Material model
///
/// A bead is the union, along its centre line, of round "buttons": at horizontal distance `u`
/// from the centre point `c` (tip height `z`) its top is `z` for `u ≤ a = (w − h)/2` and
/// `z − r + √(r² − (u − a)²)` for `a < u ≤ w/2`, `r = h/2` — the rounded rectangle swept
/// along the bead with round ends. The head's cone (half-angle θ) with its apex at the nozzle
/// tip `p` meets a button at horizontal distance `e = |p − c| > w/2` exactly when
/// `e − a − r·cos θ < tan θ · (z − p.z − r·(1 − sin θ))`: the cone's surface is tangent to the
/// rounded edge at `u = a + r·cos θ`. A bead with a `lean` is lower by `u·tan lean` at `u`
/// on the nozzle's side. Within the footprint (`e ≤ w/2`) the bead's top right
/// above the tip counts as well. The carriage takes the same candidate points. The distance to the centre line is convex along a bead and its height linear,
/// so the worst button of a bead is found by a golden-section search.
///
/// The nozzle's own bead continues the bead(s) just before it when they join end to start; the
/// part of that run within one bead width behind the nozzle is the material it is laying down,
/// not an obstacle, and is skipped — as is, while the nozzle is within one bead width of the
/// run's end, the run's first bead width (a loop closing over its own start: the seam).
pub fn replay(
    beads: &[Bead],
    start: usize,
    head: &ToolSolid,
    tol: &ReplayTolerances,
) -> Vec<ReplayHit> {
    let mut printed = PrintedBeads::new(beads, tol.rise);
    let ends: Vec<[Point3; 2]> = beads.iter().map(|b| [b.from, b.to]).collect();
    let stretches = ends.iter().enumerate().map(|(i, e)| Stretch {
        points: e,
        closed: false,
        tested: i >= start,
    });
    let spacing = Spacing::Steps(tol.sample.max(1e-3));
    let mut out = Vec::new();
    walk(
        head,
        &mut printed,
        stretches,
        spacing,
        |i, _, hit| match hit {
            Some((earlier, hit)) => {
                out.push(ReplayHit {
                    bead: i,
                    earlier,
                    hit,
                });
                Next::Stretch
            }
            None => Next::Sample,
        },
    );
    out
}

/// The beads printed so far as an obstacle of the replay walk: a grid index of them, and per
/// bead its continuous run (so the nozzle's own bead is not an obstacle).
struct PrintedBeads<'a> {
    beads: &'a [Bead],
    index: BeadIndex,
    /// Material must rise more than this above the tip to count, mm.
    rise: f64,
    /// Per bead: the first bead of its continuous run.
    run_of: Vec<usize>,
    /// Per bead: the run's arc length up to the bead's start, mm.
    run_len: Vec<f64>,
    /// Per run (by first bead): its total length, mm.
    run_total: Vec<f64>,
}

impl<'a> PrintedBeads<'a> {
    /// None of `beads` printed yet, with their runs.
    fn new(beads: &'a [Bead], rise: f64) -> Self {
        let joined = |i: usize| i > 0 && (beads[i].from - beads[i - 1].to).norm() < 1e-6;
        let mut run_of = vec![0; beads.len()];
        let mut run_len = vec![0.0; beads.len()];
        let mut run_total = vec![0.0; beads.len()];
        for i in 0..beads.len() {
            if joined(i) {
                run_of[i] = run_of[i - 1];
                run_len[i] = run_len[i - 1] + beads[i - 1].length();
            } else {
                run_of[i] = i;
            }
            run_total[run_of[i]] = run_len[i] + beads[i].length();
        }
        Self {
            beads,
            index: BeadIndex::new(beads),
            rise,
            run_of,
            run_len,
            run_total,
        }
    }
}

impl Obstacle for PrintedBeads<'_> {
    /// The earlier bead hit and the hit.
    type Contact = Option<(usize, Hit)>;

    fn contact(&self, head: &ToolSolid, i: usize, sample: &Sample) -> Option<(usize, Hit)> {
        let beads = self.beads;
        let b = &beads[i];
        let p = sample.tip;
        let arc = self.run_len[i] + sample.fraction * b.length();
        let total = self.run_total[self.run_of[i]];
        for j in self.index.candidates(beads, p, head, self.rise) {
            // Within one bead width behind the nozzle on its own run: its own bead; and a
            // loop's last bead width closing over the run's first one: its seam.
            if self.run_of[j] == self.run_of[i]
                && (arc - (self.run_len[j] + beads[j].length()) < b.width
                    || (self.run_len[j] < b.width && total - arc < b.width))
            {
                continue;
            }
            if let Some(hit) = bead_hit(head, p, &beads[j], self.rise) {
                return Some((j, hit));
            }
        }
        None
    }

    fn lay(&mut self, i: usize, _stretch: &Stretch<'_>, _samples: &[Sample]) {
        self.index.insert(self.beads, i);
    }
}

impl Bead {
    /// Length of the centre line, mm.
    pub fn length(&self) -> f64 {
        (self.to - self.from).norm()
    }

    fn top(&self) -> f64 {
        self.from.z.max(self.to.z)
    }
}

/// The hit of `head` with its tip at `p` against `bead` (see [`replay`]): the bead's highest
/// point inside the head, if any rises more than `min_rise` above the tip. The tangent point
/// is the one of the head's cone ([`ToolSolid::cone`]; a head without one is tested as a
/// cylinder).
pub fn bead_hit(head: &ToolSolid, p: Point3, bead: &Bead, min_rise: f64) -> Option<Hit> {
    if bead.top() - p.z <= min_rise {
        return None;
    }
    let (w, h) = (bead.width, bead.height.min(bead.width));
    let (r, a) = (h / 2.0, (w - h) / 2.0);
    let theta = match head.cone().map(|c| c.shape) {
        Some(PieceShape::Cone { angle_deg, .. }) => angle_deg.to_radians(),
        _ => 0.0,
    };
    let (cos, tan) = (theta.cos(), theta.tan());
    let lean = bead.lean_deg.to_radians().tan();
    let at = |t: f64| Point3::from(bead.from.coords + (bead.to.coords - bead.from.coords) * t);
    // Top of a button at horizontal distance u from its centre, relative to the centre.
    let profile = |u: f64| {
        if u <= a {
            0.0
        } else {
            (r * r - (u - a) * (u - a)).max(0.0).sqrt() - r
        }
    };
    // How far the head is from touching the button at t (negative: it touches). Along the
    // line from the nozzle to the centre the head's measure |e − u| − radius(rise(u)) is
    // convex in u towards the centre and grows away from it, so the flat top's edge, the
    // cone's tangent point on the rounded edge (u = a + r·cos θ) and the point under the
    // nozzle are the candidates.
    let gap = |t: f64| {
        let c = at(t);
        let e = (c.x - p.x).hypot(c.y - p.y);
        let mut g = f64::MAX;
        if e > w / 2.0 + head.widest() {
            return g;
        }
        for u in [a.min(e), (a + r * cos).min(e), e.min(w / 2.0)] {
            let rise = c.z + profile(u) - u * lean - p.z;
            if rise <= min_rise {
                continue;
            }
            let dist = e - u;
            if dist <= 0.0 {
                // Material right above the tip.
                g = g.min(-rise);
            } else if let Some((radius, _)) = head.radius_at(rise) {
                g = g.min(dist - radius);
            }
        }
        g
    };
    // The cone's measure without its limits is convex along the bead (distance to a
    // segment minus a linear height): its minimum, the point nearest to the nozzle and the
    // ends cover the cone, the footprint and the carriage.
    let cone = |t: f64| {
        let c = at(t);
        (c.x - p.x).hypot(c.y - p.y) - tan * (c.z - p.z)
    };
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    let golden = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        if (hi - lo) * bead.length() < 1e-5 {
            break;
        }
        let m1 = hi - golden * (hi - lo);
        let m2 = lo + golden * (hi - lo);
        if cone(m1) < cone(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let d = bead.to - bead.from;
    let l2 = d.x * d.x + d.y * d.y;
    let nearest = if l2 > 0.0 {
        (((p.x - bead.from.x) * d.x + (p.y - bead.from.y) * d.y) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let t = [(lo + hi) / 2.0, nearest, 0.0, 1.0]
        .into_iter()
        .map(|t| (gap(t), t))
        .fold((f64::MAX, 0.0), |b, c| if c.0 < b.0 { c } else { b })
        .1;
    (gap(t) < 0.0).then(|| {
        let c = at(t);
        let rise = c.z - p.z;
        let part = head
            .radius_at(rise)
            .map_or(ToolPart::Cone, |(_, part)| part);
        Hit {
            nozzle: p,
            material: c,
            part,
        }
    })
}

/// Beads sorted into [`REPLAY_CELL_MM`] cells by the xy box of their footprint; each cell's
/// list is kept highest first so a query stops at the first bead below the nozzle.
struct BeadIndex {
    origin: [f64; 2],
    dims: [usize; 2],
    /// Per cell: (top z, bead index), highest first.
    cells: Vec<Vec<(f64, usize)>>,
    /// Per cell: the highest top in it.
    tops: Vec<f64>,
    widest: f64,
}

impl BeadIndex {
    fn new(beads: &[Bead]) -> Self {
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        let mut widest: f64 = 0.0;
        for b in beads {
            for q in [b.from, b.to] {
                lo = [lo[0].min(q.x), lo[1].min(q.y)];
                hi = [hi[0].max(q.x), hi[1].max(q.y)];
            }
            widest = widest.max(b.width);
        }
        if beads.is_empty() {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        let dims = [
            (((hi[0] - lo[0]) / REPLAY_CELL_MM).floor() as usize + 1).min(4096),
            (((hi[1] - lo[1]) / REPLAY_CELL_MM).floor() as usize + 1).min(4096),
        ];
        Self {
            origin: lo,
            dims,
            cells: vec![Vec::new(); dims[0] * dims[1]],
            tops: vec![f64::MIN; dims[0] * dims[1]],
            widest,
        }
    }

    fn cell(&self, x: f64, y: f64) -> (usize, usize) {
        let c = |v: f64, o: f64, n: usize| {
            let f = ((v - o) / REPLAY_CELL_MM).floor();
            if f.is_finite() {
                (f.max(0.0) as usize).min(n - 1)
            } else {
                0
            }
        };
        (
            c(x, self.origin[0], self.dims[0]),
            c(y, self.origin[1], self.dims[1]),
        )
    }

    fn insert(&mut self, beads: &[Bead], i: usize) {
        let b = &beads[i];
        let half = b.width / 2.0;
        let (x0, y0) = self.cell(b.from.x.min(b.to.x) - half, b.from.y.min(b.to.y) - half);
        let (x1, y1) = self.cell(b.from.x.max(b.to.x) + half, b.from.y.max(b.to.y) + half);
        let top = b.top();
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                let k = cy * self.dims[0] + cx;
                let list = &mut self.cells[k];
                let at = list.partition_point(|&(z, j)| z > top || (z == top && j < i));
                list.insert(at, (top, i));
                self.tops[k] = self.tops[k].max(top);
            }
        }
    }

    /// Beads that may reach into the head at `p`, in ascending index order without repeats.
    fn candidates(&self, beads: &[Bead], p: Point3, head: &ToolSolid, min_rise: f64) -> Vec<usize> {
        let mut out = Vec::new();
        let reach = |rise: f64| -> f64 { head.widest_up_to(rise) + self.widest / 2.0 };
        let far = reach(f64::MAX / 4.0).min(1e4);
        let (x0, y0) = self.cell(p.x - far, p.y - far);
        let (x1, y1) = self.cell(p.x + far, p.y + far);
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                let k = cy * self.dims[0] + cx;
                let rise = self.tops[k] - p.z;
                if rise <= min_rise {
                    continue;
                }
                // Distance from p to the cell's square.
                let (bx, by) = (
                    self.origin[0] + cx as f64 * REPLAY_CELL_MM,
                    self.origin[1] + cy as f64 * REPLAY_CELL_MM,
                );
                let dx = (bx - p.x).max(p.x - bx - REPLAY_CELL_MM).max(0.0);
                let dy = (by - p.y).max(p.y - by - REPLAY_CELL_MM).max(0.0);
                if dx.hypot(dy) > reach(rise) {
                    continue;
                }
                for &(z, j) in &self.cells[k] {
                    if z - p.z <= min_rise {
                        break;
                    }
                    let b = &beads[j];
                    if segment_distance(p, b.from, b.to) - b.width / 2.0 > reach(z - p.z) {
                        continue;
                    }
                    out.push(j);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Horizontal distance from `p` to the segment from `a` to `b`, mm.
fn segment_distance(p: Point3, a: Point3, b: Point3) -> f64 {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p.x - a.x) * dx + (p.y - a.y) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a.x + t * dx - p.x).hypot(a.y + t * dy - p.y)
}

/// The point of the shape (rings, contour first, even-odd) nearest to (x, y) when it is closer
/// than `r`: (x, y) itself when inside.
fn closest_within(rings: &[Vec<(f64, f64)>], x: f64, y: f64, r: f64) -> Option<(f64, f64)> {
    let mut inside = false;
    let mut best = (f64::MAX, (x, y));
    for ring in rings {
        let n = ring.len();
        for i in 0..n {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            if (a.1 > y) != (b.1 > y) && x < a.0 + (y - a.1) * (b.0 - a.0) / (b.1 - a.1) {
                inside = !inside;
            }
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let l2 = dx * dx + dy * dy;
            let t = if l2 > 0.0 {
                (((x - a.0) * dx + (y - a.1) * dy) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let c = (a.0 + t * dx, a.1 + t * dy);
            let d = (c.0 - x).hypot(c.1 - y);
            if d < best.0 {
                best = (d, c);
            }
        }
    }
    if inside {
        Some((x, y))
    } else if best.0 < r {
        Some(best.1)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Point2, Polygon};

    fn square(x0: f64, y0: f64, s: f64) -> ExPolygon {
        ExPolygon {
            contour: Polygon::new(vec![
                Point2::from_mm(x0, y0),
                Point2::from_mm(x0 + s, y0),
                Point2::from_mm(x0 + s, y0 + s),
                Point2::from_mm(x0, y0 + s),
            ]),
            holes: Vec::new(),
        }
    }

    #[test]
    fn cone_hits_a_wall_within_its_radius_only() {
        let head = ToolSolid::fff_head(45.0, 5.0, 0.0, 10.0);
        let mut m = Material::default();
        m.add_layer(
            3.0,
            &[square(10.0, 0.0, 5.0)],
            [-100.0, -100.0, 100.0, 100.0],
        );
        // 2 mm above the tip the cone is 2 mm wide.
        let near = [Point3::new(8.5, 2.0, 1.0)];
        let far = [Point3::new(7.5, 2.0, 1.0)];
        let hit = m.first_hit(&head, &near).map(|h| (h.part, h.material));
        assert_eq!(hit, Some((ToolPart::Cone, Point3::new(10.0, 2.0, 3.0))));
        assert!(m.first_hit(&head, &far).is_none());
        // Material below the tip never collides.
        assert!(m.first_hit(&head, &[Point3::new(11.0, 2.0, 3.5)]).is_none());
        let carriage = ToolSolid::fff_head(45.0, 1.0, 20.0, 1.5);
        let hit = m.first_hit(&carriage, &far).map(|h| h.part);
        assert_eq!(hit, Some(ToolPart::Carriage));
    }

    #[test]
    fn replay_finds_a_bead_exactly_where_the_cone_meets_its_rounded_edge() {
        let head = ToolSolid::fff_head(60.0, 5.0, 0.0, 10.0);
        let wall = Bead {
            from: Point3::new(0.0, 0.0, 1.3),
            to: Point3::new(10.0, 0.0, 1.3),
            width: 0.45,
            height: 0.2,
            lean_deg: 0.0,
        };
        // Tangent on the rounded edge (a = 0.125, r = 0.1): e < a + r·cos 60° + tan 60°·(0.3 −
        // r·(1 − sin 60°)) = 0.67141.
        let limit = 0.125 + 0.05 + 3f64.sqrt() * (0.3 - 0.1 * (1.0 - 3f64.sqrt() / 2.0));
        let pass = |y: f64| Bead {
            from: Point3::new(2.0, y, 1.0),
            to: Point3::new(8.0, y, 1.0),
            width: 0.45,
            height: 0.2,
            lean_deg: 0.0,
        };
        let tol = ReplayTolerances::default();
        let near = replay(&[wall, pass(limit - 0.01)], 1, &head, &tol);
        assert_eq!(near.len(), 1);
        assert_eq!((near[0].bead, near[0].earlier), (1, 0));
        assert_eq!(near[0].hit.part, ToolPart::Cone);
        assert!((near[0].hit.material.z - 1.3).abs() < 1e-9);
        assert!(replay(&[wall, pass(limit + 0.01)], 1, &head, &tol).is_empty());
        // Before `start` nothing is tested; a bead at the same height never counts.
        assert!(replay(&[wall, pass(limit - 0.01)], 2, &head, &tol).is_empty());
        let level = Bead {
            from: Point3::new(2.0, 0.2, 1.3),
            to: Point3::new(8.0, 0.2, 1.3),
            ..pass(0.0)
        };
        assert!(replay(&[wall, level], 1, &head, &tol).is_empty());
        // Right under the wall's flat top: hit, whatever the angle.
        let under = Bead {
            from: Point3::new(2.0, 0.05, 1.2),
            to: Point3::new(8.0, 0.05, 1.2),
            ..pass(0.0)
        };
        let narrow = ToolSolid::fff_head(0.0, 5.0, 0.0, 10.0);
        assert_eq!(replay(&[wall, under], 1, &narrow, &tol).len(), 1);
    }
}
