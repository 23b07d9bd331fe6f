//! Automatic part placement: parts packed into a region of an object's cross-section.
//!
//! Place in the pipeline: between [`Circuit::load`] and a [`super::Placement`]. The caller
//! takes a cross-section of the object, shrinks it by the wall clearance and cavity offsets,
//! and asks [`pack`] where each part goes; it then writes the placement. Nothing here reads a
//! mesh or writes a file.
//!
//! A part's *footprint* is the axis-aligned rectangle of its pads in its package frame
//! ([`super::Pad::half_extent`]), turned by the part's quarter turn. Footprints lie inside the
//! region and at least [`PackParams::gap`] apart; among such arrangements the packer looks for
//! short rubberbands ([`rubberband_length`]).
//!
//! # Method
//!
//! Footprint corners sit on a grid of [`PackParams::step`] over the region's bounding box. The
//! region is rasterised once into grid cells that are inside, outside, or crossed by its
//! boundary; a footprint covering only inside cells fits at once, one that covers a crossed
//! cell is tested exactly against the boundary edges of those cells (integer arithmetic). Parts
//! are placed greedily, most connected first, each where it adds the least rubberband to the
//! parts already placed; then parts are taken out and put back where they do best, and pairs
//! swap places, while the total rubberband shrinks (a bounded number of rounds). When the
//! greedy pass leaves parts out, it is retried with those parts placed first (a few times),
//! then largest part first, then packed bottom-left. The search for a position skips rows and
//! columns where a lower bound of the added rubberband (the distance to each net's bounding box)
//! cannot beat the best found, so a large region costs little more than a tight one.
//! Everything is deterministic: fixed orders, ties broken by cost, turn and grid index.

use std::collections::{BTreeMap, BTreeSet};

use super::Circuit;
use crate::geom::{Coord, ExPolygon, Point2, scaled, union, unscaled};

/// The most candidate positions the grid may have (2000 × 2000).
pub const MAX_GRID_POINTS: u64 = 4_000_000;

/// The largest gap or step accepted, mm.
const MAX_PARAM_MM: f64 = 10_000.0;
/// The smallest step accepted, mm.
const MIN_STEP_MM: f64 = 0.001;
/// Greedy passes, most connected first, that put the parts left out before first.
const RETRIES: usize = 3;
/// Improvement rounds (re-insertions and swaps) at most.
const MAX_ROUNDS: usize = 10;
/// Weight of the pull towards the region's centroid, per mm, in the search for a position: it
/// keeps the arrangement compact and decides where unconnected parts go.
const PULL: f64 = 0.05;
/// Positions per part whose exact rubberband is compared when it is put back.
const TOP_K: usize = 4;
/// Rounding allowance of the lower bounds that prune the search, mm.
const SLACK: f64 = 1e-9;
/// An improvement counts when it shortens the rubberbands by more than this, mm.
const EPS: f64 = 1e-9;

/// What the packer is asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PackParams {
    /// Smallest distance between two parts' footprints, mm (the caller adds cavity offsets,
    /// wall clearance and room for traces).
    pub gap: f64,
    /// Try the four quarter turns (0, 90, 180, 270°) per part; only 0 when false.
    pub rotate: bool,
    /// Step of the candidate-position grid, mm (e.g. 0.5).
    pub step: f64,
}

/// One part where the packer put it.
#[derive(Debug, Clone, PartialEq)]
pub struct Packed {
    /// Part name.
    pub name: String,
    /// Package origin x, mm, in the region's frame.
    pub x: f64,
    /// Package origin y, mm, in the region's frame.
    pub y: f64,
    /// Rotation about +z, counter-clockwise, degrees: 0, 90, 180 or 270.
    pub rotation: f64,
}

/// Why parts could not be packed.
///
/// # How to fix
/// [`PackError::NoRoom`]: a larger object, a smaller gap, fewer parts, or rotations allowed.
/// The others name the parameter or part that is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PackError {
    /// Some parts found no place (the others may have).
    #[error(
        "no room for {}: the region has {free_mm2:.1} mm², the parts need about {needed_mm2:.1} mm² with their gaps",
        parts.join(", ")
    )]
    NoRoom {
        /// The parts that did not fit, largest footprint first.
        parts: Vec<String>,
        /// Area of the region, mm².
        free_mm2: f64,
        /// Footprint areas of all the parts asked for, each grown by half the gap on every
        /// side, mm².
        needed_mm2: f64,
    },
    /// A parameter is not a finite number in its range.
    #[error("pack: {key} = {value} is not a number {range}")]
    BadParam {
        /// `gap` or `step`.
        key: &'static str,
        /// The value given.
        value: f64,
        /// The accepted range, in words.
        range: &'static str,
    },
    /// The step is so fine for the region that the grid would be too large.
    #[error(
        "pack: a step of {step} mm makes {points} grid positions over the region (at most {MAX_GRID_POINTS}); use a larger step"
    )]
    GridTooFine {
        /// The step, mm.
        step: f64,
        /// Positions the grid would have.
        points: u64,
    },
    /// A part name that the circuit does not have.
    #[error("pack: the circuit has no part {part}")]
    UnknownPart {
        /// The name.
        part: String,
    },
    /// A part asked for twice.
    #[error("pack: part {part} is listed twice")]
    DuplicatePart {
        /// The name.
        part: String,
    },
    /// A part without pads has no footprint to pack.
    #[error("pack: part {part} has no pads")]
    NoPads {
        /// The name.
        part: String,
    },
    /// A pad whose position or size is not finite or out of bounds ([`super::Pad::bad_number`]).
    #[error("pack: part {part} pad {pad}: {key} = {value} is not a finite number within bounds")]
    BadPad {
        /// The part.
        part: String,
        /// The pad.
        pad: String,
        /// The attribute.
        key: &'static str,
        /// The value.
        value: f64,
    },
}

/// Packs `parts` of `circuit` into `region`: every footprint inside the region, at least
/// `params.gap` from every other, the nets' rubberbands short. Returns the parts in the order
/// of `parts`.
///
/// `region` is in scaled coordinates ([`crate::geom::scaled`]) and may have holes and several
/// islands; overlapping ExPolygons are united first.
///
/// # Errors
/// [`PackError::NoRoom`] naming the parts that found no place; the other variants for a bad
/// parameter or part.
pub fn pack(
    circuit: &Circuit,
    parts: &[&str],
    region: &[ExPolygon],
    params: &PackParams,
) -> Result<Vec<Packed>, PackError> {
    check_params(params)?;
    let items = items(circuit, parts, params)?;
    if items.is_empty() {
        return Ok(Vec::new());
    }
    let region = union(region);
    let free_mm2: f64 = region.iter().map(ExPolygon::area_mm2).sum();
    let needed_mm2: f64 = items.iter().map(|it| it.need).sum();
    let Some(grid) = Grid::new(&region, params.step)? else {
        let mut names: Vec<&Item> = items.iter().collect();
        names.sort_by(|a, b| b.area.total_cmp(&a.area).then(a.name.cmp(b.name)));
        return Err(PackError::NoRoom {
            parts: names.iter().map(|it| it.name.to_owned()).collect(),
            free_mm2,
            needed_mm2,
        });
    };
    let packer = Packer::new(circuit, items, grid, &region, params);
    // Most connected first; the parts that found no place go first in the next try (largest
    // first), a few times; then largest first, and at last packed bottom-left.
    let mut attempts: Vec<(Order, Goal)> = vec![(Order::Connected, Goal::Rubberband); RETRIES + 1];
    attempts.extend([
        (Order::Largest, Goal::Rubberband),
        (Order::Largest, Goal::BottomLeft),
    ]);
    let mut best_failure: Option<(f64, Vec<usize>)> = None;
    let mut first: Vec<usize> = Vec::new();
    for (order, goal) in attempts {
        let mut state = vec![None; packer.items.len()];
        let ahead = if matches!(order, Order::Connected) {
            first.as_slice()
        } else {
            &[]
        };
        let left = packer.greedy(&mut state, ahead, order, goal);
        if left.is_empty() {
            packer.improve(&mut state);
            return Ok(packer.output(&state));
        }
        let lost: f64 = left.iter().map(|&p| packer.items[p].need).sum();
        if best_failure.as_ref().is_none_or(|(l, _)| lost < *l) {
            best_failure = Some((lost, left.clone()));
        }
        first.extend(
            left.into_iter()
                .filter(|p| !first.contains(p))
                .collect::<Vec<_>>(),
        );
        first.sort_by(|&a, &b| {
            let (a, b) = (&packer.items[a], &packer.items[b]);
            b.area.total_cmp(&a.area).then(a.name.cmp(b.name))
        });
    }
    let mut left = best_failure.map(|(_, l)| l).unwrap_or_default();
    left.sort_by(|&a, &b| {
        let (a, b) = (&packer.items[a], &packer.items[b]);
        b.area.total_cmp(&a.area).then(a.name.cmp(b.name))
    });
    Err(PackError::NoRoom {
        parts: left
            .iter()
            .map(|&p| packer.items[p].name.to_owned())
            .collect(),
        free_mm2,
        needed_mm2,
    })
}

/// Total rubberband length of `packed`, mm: per net, the minimum spanning tree over the centres
/// of its pads on the packed parts (in the plane; the pads of one `route="any"` pin of a part
/// count as one point, joined inside the part). Parts the circuit does not have are ignored.
pub fn rubberband_length(circuit: &Circuit, packed: &[Packed]) -> f64 {
    let at: BTreeMap<&str, &Packed> = packed.iter().map(|p| (p.name.as_str(), p)).collect();
    circuit
        .nets
        .iter()
        .map(|net| {
            let mut points: Vec<[f64; 2]> = Vec::new();
            let mut keys: Vec<(String, String)> = Vec::new();
            let mut groups: Vec<usize> = Vec::new();
            for pin in &net.pins {
                let (Some(placed), Some(part)) =
                    (at.get(pin.part.as_str()), circuit.part(&pin.part))
                else {
                    continue;
                };
                let Some(pad) = part.pad(&pin.pad) else {
                    continue;
                };
                let key = (pin.part.clone(), pad.name.clone());
                if keys.contains(&key) {
                    continue;
                }
                let (s, c) = placed.rotation.to_radians().sin_cos();
                points.push([
                    placed.x + c * pad.x - s * pad.y,
                    placed.y + s * pad.x + c * pad.y,
                ]);
                let joined = part.joined_pin(&pad.name);
                let group = joined
                    .and_then(|j| {
                        (0..keys.len()).find(|&k| {
                            keys[k].0 == pin.part && part.joined_pin(&keys[k].1) == Some(j)
                        })
                    })
                    .map_or(keys.len(), |k| groups[k]);
                groups.push(group);
                keys.push(key);
            }
            mst_length(&points, &groups)
        })
        .sum()
}

/// Length of the minimum spanning tree over `points` (Prim), where points sharing a `groups`
/// value are joined already.
fn mst_length(points: &[[f64; 2]], groups: &[usize]) -> f64 {
    let n = points.len();
    if n < 2 {
        return 0.0;
    }
    let mut in_tree = vec![false; n];
    let mut best = vec![f64::INFINITY; n];
    let mut total = 0.0;
    let mut next = Some(0);
    while let Some(j) = next {
        total += if best[j].is_finite() {
            best[j].sqrt()
        } else {
            0.0
        };
        for m in (0..n).filter(|&m| groups[m] == groups[j]) {
            in_tree[m] = true;
            for k in 0..n {
                let d =
                    (points[k][0] - points[m][0]).powi(2) + (points[k][1] - points[m][1]).powi(2);
                if !in_tree[k] && d < best[k] {
                    best[k] = d;
                }
            }
        }
        next = (0..n)
            .filter(|&k| !in_tree[k])
            .min_by(|&a, &b| best[a].total_cmp(&best[b]).then(a.cmp(&b)));
    }
    total
}

fn check_params(p: &PackParams) -> Result<(), PackError> {
    if !(p.gap.is_finite() && (0.0..=MAX_PARAM_MM).contains(&p.gap)) {
        return Err(PackError::BadParam {
            key: "gap",
            value: p.gap,
            range: "from 0 to 10000 mm",
        });
    }
    if !(p.step.is_finite() && (MIN_STEP_MM..=MAX_PARAM_MM).contains(&p.step)) {
        return Err(PackError::BadParam {
            key: "step",
            value: p.step,
            range: "from 0.001 to 10000 mm",
        });
    }
    Ok(())
}

/// An axis-aligned rectangle in scaled units: `[x0, y0, x1, y1]`.
type Rect = [Coord; 4];

/// A part in one quarter turn.
struct Turn {
    /// Quarter turns counter-clockwise.
    quarter: u8,
    /// Footprint width and height, scaled units (rounded up to the nanometre, never below
    /// 1 µm).
    size: [Coord; 2],
    /// Grid cells the footprint covers along x and y when its corner is on a grid point.
    cells: [usize; 2],
    /// The package origin relative to the footprint's lower-left corner, mm.
    origin: [f64; 2],
    /// Pad centres relative to the footprint's lower-left corner, mm, in pad order.
    pads: Vec<[f64; 2]>,
    /// Index of the grid positions where this footprint fits the region.
    fit: usize,
}

/// A part to pack.
struct Item<'a> {
    name: &'a str,
    turns: Vec<Turn>,
    /// Footprint area, mm².
    area: f64,
    /// Footprint grown by half the gap on each side, mm².
    need: f64,
}

/// `p` turned by `quarter` quarter turns counter-clockwise (exact).
fn turn(p: [f64; 2], quarter: u8) -> [f64; 2] {
    match quarter % 4 {
        0 => p,
        1 => [-p[1], p[0]],
        2 => [-p[0], -p[1]],
        _ => [p[1], -p[0]],
    }
}

/// The parts to pack, checked, in the order given.
fn items<'a>(
    circuit: &'a Circuit,
    names: &[&'a str],
    params: &PackParams,
) -> Result<Vec<Item<'a>>, PackError> {
    let mut seen = BTreeSet::new();
    let mut out = Vec::with_capacity(names.len());
    for &name in names {
        let part = circuit.part(name).ok_or_else(|| PackError::UnknownPart {
            part: name.to_owned(),
        })?;
        if !seen.insert(name) {
            return Err(PackError::DuplicatePart {
                part: name.to_owned(),
            });
        }
        if let Some((pad, (key, value))) = part
            .pads
            .iter()
            .find_map(|p| p.bad_number().map(|b| (p, b)))
        {
            return Err(PackError::BadPad {
                part: name.to_owned(),
                pad: pad.name.clone(),
                key,
                value,
            });
        }
        let ext = part.pad_extent().ok_or_else(|| PackError::NoPads {
            part: name.to_owned(),
        })?;
        let quarters: &[u8] = if params.rotate { &[0, 1, 2, 3] } else { &[0] };
        let turns = quarters
            .iter()
            .map(|&q| {
                let corners = [turn([ext[0], ext[1]], q), turn([ext[2], ext[3]], q)];
                let lo = [
                    corners[0][0].min(corners[1][0]),
                    corners[0][1].min(corners[1][1]),
                ];
                let hi = [
                    corners[0][0].max(corners[1][0]),
                    corners[0][1].max(corners[1][1]),
                ];
                // Rounded up to the nanometre (a size in whole nanometres stays as it is).
                let side = |d: f64| ((d * 1e6 - 1e-3).ceil() as Coord).max(scaled(MIN_STEP_MM));
                Turn {
                    quarter: q,
                    size: [side(hi[0] - lo[0]), side(hi[1] - lo[1])],
                    cells: [0, 0],
                    origin: [-lo[0], -lo[1]],
                    pads: part
                        .pads
                        .iter()
                        .map(|p| {
                            let t = turn([p.x, p.y], q);
                            [t[0] - lo[0], t[1] - lo[1]]
                        })
                        .collect(),
                    fit: 0,
                }
            })
            .collect();
        let (w, h) = (ext[2] - ext[0], ext[3] - ext[1]);
        out.push(Item {
            name,
            turns,
            area: w * h,
            need: (w + params.gap) * (h + params.gap),
        });
    }
    Ok(out)
}

/// Whether segment `a`–`b` meets the open rectangle `r` (`open`) or the closed one.
fn segment_meets(a: Point2, b: Point2, r: &Rect, open: bool) -> bool {
    let (minx, maxx) = (a.x.min(b.x), a.x.max(b.x));
    let (miny, maxy) = (a.y.min(b.y), a.y.max(b.y));
    let apart = if open {
        maxx <= r[0] || minx >= r[2] || maxy <= r[1] || miny >= r[3]
    } else {
        maxx < r[0] || minx > r[2] || maxy < r[1] || miny > r[3]
    };
    if apart {
        return false;
    }
    let (mut pos, mut neg) = (0, 0);
    for (x, y) in [(r[0], r[1]), (r[2], r[1]), (r[2], r[3]), (r[0], r[3])] {
        let c = a.cross(b, Point2::new(x, y));
        pos += usize::from(c > 0);
        neg += usize::from(c < 0);
    }
    if open {
        // The line has corners strictly on both sides.
        pos > 0 && neg > 0
    } else {
        // Not every corner strictly on one side.
        pos < 4 && neg < 4
    }
}

/// Cell classes of the rasterised region.
const INSIDE: u8 = 0;
const CROSSED: u8 = 1;
const OUTSIDE: u8 = 2;

/// The region rasterised on the candidate grid.
struct Grid {
    /// Lower-left corner of cell (0, 0), scaled.
    x0: Coord,
    y0: Coord,
    /// Cell side, scaled.
    s: Coord,
    nx: usize,
    ny: usize,
    /// Summed-area tables of outside and crossed cells, `(nx + 1) × (ny + 1)`.
    sum_out: Vec<u32>,
    sum_crossed: Vec<u32>,
    /// Crossed cells, row by row (`i` ascending within a row): their `i`.
    crossed_i: Vec<u32>,
    /// Per row, the first index into `crossed_i` (`ny + 1` entries).
    row_start: Vec<u32>,
    /// Per crossed cell, the first index into `cell_edges` (one more entry than cells).
    edge_start: Vec<u32>,
    /// Edges meeting each crossed cell (closed), by index into `edges`.
    cell_edges: Vec<u32>,
    edges: Vec<(Point2, Point2)>,
}

/// Floor division for a positive divisor.
fn floor_div(a: Coord, b: Coord) -> Coord {
    a.div_euclid(b)
}

impl Grid {
    /// The grid of step `step_mm` over `region`, or `None` when the region is empty.
    fn new(region: &[ExPolygon], step_mm: f64) -> Result<Option<Grid>, PackError> {
        let mut edges = Vec::new();
        for ex in region {
            for ring in std::iter::once(&ex.contour).chain(&ex.holes) {
                let n = ring.points.len();
                for k in 0..n {
                    edges.push((ring.points[k], ring.points[(k + 1) % n]));
                }
            }
        }
        let Some(first) = edges.first().map(|e| e.0) else {
            return Ok(None);
        };
        let (mut lo, mut hi) = (first, first);
        for &(a, _) in &edges {
            lo = Point2::new(lo.x.min(a.x), lo.y.min(a.y));
            hi = Point2::new(hi.x.max(a.x), hi.y.max(a.y));
        }
        let s = scaled(step_mm).max(1);
        let count = |l: Coord, h: Coord| ((h as i128 - l as i128) / s as i128 + 1).max(1);
        let points = count(lo.x, hi.x).saturating_mul(count(lo.y, hi.y));
        if points > MAX_GRID_POINTS as i128 {
            return Err(PackError::GridTooFine {
                step: step_mm,
                points: u64::try_from(points).unwrap_or(u64::MAX),
            });
        }
        let (nx, ny) = (count(lo.x, hi.x) as usize, count(lo.y, hi.y) as usize);
        let (x0, y0) = (lo.x, lo.y);
        let cell = |i: usize, j: usize| -> Rect {
            let (x, y) = (x0 + i as Coord * s, y0 + j as Coord * s);
            [x, y, x + s, y + s]
        };
        let range = |l: Coord, h: Coord, o: Coord, n: usize| {
            let a = floor_div(l - o, s).clamp(0, n as Coord - 1) as usize;
            let b = floor_div(h - o, s).clamp(0, n as Coord - 1) as usize;
            a..=b
        };
        // Cells an edge passes through.
        let mut class = vec![INSIDE; nx * ny];
        for &(a, b) in &edges {
            for j in range(a.y.min(b.y), a.y.max(b.y), y0, ny) {
                for i in range(a.x.min(b.x), a.x.max(b.x), x0, nx) {
                    if segment_meets(a, b, &cell(i, j), true) {
                        class[j * nx + i] = CROSSED;
                    }
                }
            }
        }
        // The other cells: inside or outside by their centre (even-odd along the row). Each
        // edge adds its crossing to the rows whose centre line it spans.
        let mut crossings: Vec<Vec<f64>> = vec![Vec::new(); ny];
        for &(a, b) in &edges {
            for j in range(a.y.min(b.y) - s, a.y.max(b.y), y0, ny) {
                let yc = y0 + j as Coord * s + s / 2;
                if (a.y > yc) != (b.y > yc) {
                    let t = (yc - a.y) as f64 / (b.y - a.y) as f64;
                    crossings[j].push(a.x as f64 + t * (b.x - a.x) as f64);
                }
            }
        }
        for (j, xs) in crossings.iter_mut().enumerate() {
            xs.sort_by(f64::total_cmp);
            let mut k = 0;
            for i in 0..nx {
                let xc = (x0 + i as Coord * s + s / 2) as f64;
                while k < xs.len() && xs[k] < xc {
                    k += 1;
                }
                let c = &mut class[j * nx + i];
                if *c != CROSSED {
                    *c = if k % 2 == 1 { INSIDE } else { OUTSIDE };
                }
            }
        }
        let table = |want: u8| {
            let mut t = vec![0u32; (nx + 1) * (ny + 1)];
            for j in 0..ny {
                for i in 0..nx {
                    let v = u32::from(class[j * nx + i] == want);
                    t[(j + 1) * (nx + 1) + i + 1] =
                        v + t[j * (nx + 1) + i + 1] + t[(j + 1) * (nx + 1) + i]
                            - t[j * (nx + 1) + i];
                }
            }
            t
        };
        let (sum_out, sum_crossed) = (table(OUTSIDE), table(CROSSED));
        let mut crossed_i = Vec::new();
        let mut row_start = Vec::with_capacity(ny + 1);
        let mut ordinal = vec![u32::MAX; nx * ny];
        for j in 0..ny {
            row_start.push(crossed_i.len() as u32);
            for i in 0..nx {
                if class[j * nx + i] == CROSSED {
                    ordinal[j * nx + i] = crossed_i.len() as u32;
                    crossed_i.push(i as u32);
                }
            }
        }
        row_start.push(crossed_i.len() as u32);
        // Edges touching each crossed cell (closed: an edge along a grid line is kept).
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (e, &(a, b)) in edges.iter().enumerate() {
            for j in range(a.y.min(b.y) - 1, a.y.max(b.y) + 1, y0, ny) {
                for i in range(a.x.min(b.x) - 1, a.x.max(b.x) + 1, x0, nx) {
                    let k = ordinal[j * nx + i];
                    if k != u32::MAX && segment_meets(a, b, &cell(i, j), false) {
                        pairs.push((k, e as u32));
                    }
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut edge_start = vec![0u32; crossed_i.len() + 1];
        for &(k, _) in &pairs {
            edge_start[k as usize + 1] += 1;
        }
        for k in 0..crossed_i.len() {
            edge_start[k + 1] += edge_start[k];
        }
        Ok(Some(Grid {
            x0,
            y0,
            s,
            nx,
            ny,
            sum_out,
            sum_crossed,
            crossed_i,
            row_start,
            edge_start,
            cell_edges: pairs.into_iter().map(|(_, e)| e).collect(),
            edges,
        }))
    }

    /// Cells counted by `table` in columns `i..i + w`, rows `j..j + h`.
    fn box_sum(&self, table: &[u32], i: usize, j: usize, w: usize, h: usize) -> u32 {
        let r = self.nx + 1;
        table[(j + h) * r + i + w] + table[j * r + i]
            - table[j * r + i + w]
            - table[(j + h) * r + i]
    }

    /// The footprint of `size` with its lower-left corner on grid point `(i, j)`.
    fn rect(&self, i: usize, j: usize, size: [Coord; 2]) -> Rect {
        let (x, y) = (self.x0 + i as Coord * self.s, self.y0 + j as Coord * self.s);
        [x, y, x + size[0], y + size[1]]
    }

    /// Grid positions where a footprint of `size` lies inside `region`, as a bitset over
    /// `j * nx + i`.
    fn fits(&self, size: [Coord; 2], region: &[ExPolygon]) -> Vec<u64> {
        let mut bits = vec![0u64; (self.nx * self.ny).div_ceil(64)];
        let cw = ((size[0] + self.s - 1) / self.s) as usize;
        let ch = ((size[1] + self.s - 1) / self.s) as usize;
        if cw > self.nx || ch > self.ny {
            return bits;
        }
        for j in 0..=self.ny - ch {
            for i in 0..=self.nx - cw {
                if self.box_sum(&self.sum_out, i, j, cw, ch) > 0 {
                    continue;
                }
                let crossed = self.box_sum(&self.sum_crossed, i, j, cw, ch);
                let ok = crossed == 0 || {
                    let r = self.rect(i, j, size);
                    !self.edge_inside(&r, i, j, cw, ch)
                        && ((cw * ch) as u32 > crossed || {
                            let c = Point2::new((r[0] + r[2]) / 2, (r[1] + r[3]) / 2);
                            region.iter().any(|ex| ex.contains(c))
                        })
                };
                if ok {
                    let k = j * self.nx + i;
                    bits[k / 64] |= 1 << (k % 64);
                }
            }
        }
        bits
    }

    /// Whether a boundary edge listed in the crossed cells of columns `i..i + cw`, rows
    /// `j..j + ch` meets the open rectangle `r`.
    fn edge_inside(&self, r: &Rect, i: usize, j: usize, cw: usize, ch: usize) -> bool {
        for row in j..j + ch {
            let cells =
                &self.crossed_i[self.row_start[row] as usize..self.row_start[row + 1] as usize];
            let from = cells.partition_point(|&c| (c as usize) < i);
            let to = cells.partition_point(|&c| (c as usize) < i + cw);
            let base = self.row_start[row] as usize;
            for k in base + from..base + to {
                let es =
                    &self.cell_edges[self.edge_start[k] as usize..self.edge_start[k + 1] as usize];
                if es.iter().any(|&e| {
                    let (a, b) = self.edges[e as usize];
                    segment_meets(a, b, r, true)
                }) {
                    return true;
                }
            }
        }
        false
    }
}

/// The order of the greedy pass.
#[derive(Clone, Copy)]
enum Order {
    /// Most connected to the parts placed so far first.
    Connected,
    /// Largest footprint first.
    Largest,
}

/// What the greedy pass looks for in a position.
#[derive(Clone, Copy, PartialEq)]
enum Goal {
    /// The least rubberband to the parts placed so far.
    Rubberband,
    /// The lowest row, then the leftmost position.
    BottomLeft,
}

/// Where a part is: its turn (index into [`Item::turns`]) and grid point.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pose {
    turn: usize,
    i: usize,
    j: usize,
}

/// A net pin on a packed part: item, pad index, group (pins sharing it are joined).
type NetPin = (usize, usize, usize);

struct Packer<'a> {
    items: Vec<Item<'a>>,
    grid: Grid,
    /// Per [`Turn::fit`], the positions where that footprint fits the region.
    fits: Vec<Vec<u64>>,
    /// Nets with pins on at least two packed parts.
    nets: Vec<Vec<NetPin>>,
    /// Per item, the nets (indices into `nets`) it has pins on.
    item_nets: Vec<Vec<usize>>,
    /// Connection strength between items: per shared net, 1 / (parts on the net − 1).
    strength: Vec<Vec<f64>>,
    gap: Coord,
    step: f64,
    /// The region's centroid, mm.
    centre: [f64; 2],
}

impl<'a> Packer<'a> {
    fn new(
        circuit: &Circuit,
        mut items: Vec<Item<'a>>,
        grid: Grid,
        region: &[ExPolygon],
        params: &PackParams,
    ) -> Self {
        let mut sizes: BTreeMap<[Coord; 2], usize> = BTreeMap::new();
        let mut fits = Vec::new();
        for item in &mut items {
            for t in &mut item.turns {
                t.cells = [
                    ((t.size[0] + grid.s - 1) / grid.s) as usize,
                    ((t.size[1] + grid.s - 1) / grid.s) as usize,
                ];
                t.fit = *sizes.entry(t.size).or_insert_with(|| {
                    fits.push(grid.fits(t.size, region));
                    fits.len() - 1
                });
            }
        }
        let index: BTreeMap<&str, usize> = items
            .iter()
            .enumerate()
            .map(|(k, it)| (it.name, k))
            .collect();
        let n = items.len();
        let mut nets = Vec::new();
        let mut item_nets = vec![Vec::new(); n];
        let mut strength = vec![vec![0.0; n]; n];
        for net in &circuit.nets {
            let mut pins: Vec<NetPin> = Vec::new();
            let mut joined: Vec<Option<(usize, &str)>> = Vec::new();
            for pin in &net.pins {
                let Some(&it) = index.get(pin.part.as_str()) else {
                    continue;
                };
                let Some(part) = circuit.part(&pin.part) else {
                    continue;
                };
                let Some(pad) = part.pad(&pin.pad) else {
                    continue;
                };
                let Some(k) = part.pads.iter().position(|p| p.name == pad.name) else {
                    continue;
                };
                if pins.iter().any(|&(a, b, _)| (a, b) == (it, k)) {
                    continue;
                }
                let key = part.joined_pin(&pad.name).map(|j| (it, j));
                let group = key
                    .and_then(|key| joined.iter().position(|g| *g == Some(key)))
                    .map_or(pins.len(), |g| pins[g].2);
                pins.push((it, k, group));
                joined.push(key);
            }
            let on: BTreeSet<usize> = pins.iter().map(|p| p.0).collect();
            if on.len() < 2 {
                continue;
            }
            let w = 1.0 / (on.len() - 1) as f64;
            for &a in &on {
                item_nets[a].push(nets.len());
                for &b in &on {
                    if a != b {
                        strength[a][b] += w;
                    }
                }
            }
            nets.push(pins);
        }
        let centre = centroid(region);
        Packer {
            items,
            grid,
            fits,
            nets,
            item_nets,
            strength,
            gap: scaled(params.gap),
            step: params.step,
            centre,
        }
    }

    fn rect(&self, p: usize, pose: Pose) -> Rect {
        self.grid
            .rect(pose.i, pose.j, self.items[p].turns[pose.turn].size)
    }

    /// The lower-left corner of grid point `(i, j)`, mm.
    fn corner(&self, i: usize, j: usize) -> [f64; 2] {
        [
            unscaled(self.grid.x0 + i as Coord * self.grid.s),
            unscaled(self.grid.y0 + j as Coord * self.grid.s),
        ]
    }

    fn pad_at(&self, p: usize, pose: Pose, pad: usize) -> [f64; 2] {
        let c = self.corner(pose.i, pose.j);
        let o = self.items[p].turns[pose.turn].pads[pad];
        [c[0] + o[0], c[1] + o[1]]
    }

    /// Rubberband of net `n` with the parts where `state` has them.
    fn net_length(&self, n: usize, state: &[Option<Pose>]) -> f64 {
        let mut points = Vec::new();
        let mut groups = Vec::new();
        for &(it, pad, g) in &self.nets[n] {
            if let Some(pose) = state[it] {
                points.push(self.pad_at(it, pose, pad));
                groups.push(g);
            }
        }
        mst_length(&points, &groups)
    }

    /// Rubberband of the nets of items `ps`.
    fn length_of(&self, ps: &[usize], state: &[Option<Pose>]) -> f64 {
        let mut nets: Vec<usize> = ps
            .iter()
            .flat_map(|&p| self.item_nets[p].iter().copied())
            .collect();
        nets.sort_unstable();
        nets.dedup();
        nets.iter().map(|&n| self.net_length(n, state)).sum()
    }

    /// Whether `a` and `b` are closer than the gap (or overlap).
    fn too_close(&self, a: &Rect, b: &Rect) -> bool {
        let overlap = a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
        let dx = (a[0] - b[2]).max(b[0] - a[2]).max(0) as i128;
        let dy = (a[1] - b[3]).max(b[1] - a[3]).max(0) as i128;
        let g = self.gap as i128;
        overlap || dx * dx + dy * dy < g * g
    }

    /// Whether item `p` may stand at `pose`: inside the region and clear of every placed part
    /// but those in `skip`.
    fn allowed(&self, p: usize, pose: Pose, state: &[Option<Pose>], skip: &[usize]) -> bool {
        let k = pose.j * self.grid.nx + pose.i;
        let t = &self.items[p].turns[pose.turn];
        if pose.i + t.cells[0] > self.grid.nx
            || pose.j + t.cells[1] > self.grid.ny
            || self.fits[t.fit][k / 64] & (1 << (k % 64)) == 0
        {
            return false;
        }
        let r = self.rect(p, pose);
        state.iter().enumerate().all(|(q, s)| {
            q == p || skip.contains(&q) || s.is_none_or(|o| !self.too_close(&r, &self.rect(q, o)))
        })
    }

    /// The best positions for item `p` among those free with the other parts of `state`
    /// (`p` itself not placed), at most `k`, best first, by `goal`.
    fn candidates(
        &self,
        p: usize,
        state: &[Option<Pose>],
        goal: Goal,
        k: usize,
    ) -> Vec<(f64, Pose)> {
        let g = &self.grid;
        // The k best as (cost, turn, grid index), in that order.
        let mut best: Vec<(f64, usize, usize)> = Vec::with_capacity(k + 1);
        for (ti, t) in self.items[p].turns.iter().enumerate() {
            let mut free = self.fits[t.fit].clone();
            // Clear the positions too close to a placed part.
            for (q, pose) in state.iter().enumerate() {
                let Some(pose) = *pose else { continue };
                if q == p {
                    continue;
                }
                let r = self.rect(q, pose);
                let span = |lo: Coord, hi: Coord, size: Coord, o: Coord, n: usize| {
                    let a = floor_div(lo - self.gap - size - o, g.s) + 1;
                    let b = floor_div(hi + self.gap - o, g.s) + 1;
                    (a.clamp(0, n as Coord) as usize)..(b.clamp(0, n as Coord) as usize)
                };
                for j in span(r[1], r[3], t.size[1], g.y0, g.ny) {
                    for i in span(r[0], r[2], t.size[0], g.x0, g.nx) {
                        let idx = j * g.nx + i;
                        if free[idx / 64] & (1 << (idx % 64)) != 0
                            && self.too_close(&g.rect(i, j, t.size), &r)
                        {
                            free[idx / 64] &= !(1 << (idx % 64));
                        }
                    }
                }
            }
            // Targets per net: where the footprint's corner would put a pad on a placed pin.
            let mut targets: Vec<Vec<[f64; 2]>> = Vec::new();
            if goal == Goal::Rubberband {
                for &n in &self.item_nets[p] {
                    let mut ts = Vec::new();
                    for &(q, qpad, _) in &self.nets[n] {
                        let Some(qpose) = state[q] else { continue };
                        if q == p {
                            continue;
                        }
                        let at = self.pad_at(q, qpose, qpad);
                        for &(r, rpad, _) in &self.nets[n] {
                            if r == p {
                                let o = t.pads[rpad];
                                ts.push([at[0] - o[0], at[1] - o[1]]);
                            }
                        }
                    }
                    if !ts.is_empty() {
                        targets.push(ts);
                    }
                }
            }
            let bit = |i: usize, j: usize| {
                let idx = j * g.nx + i;
                free[idx / 64] & (1 << (idx % 64)) != 0
            };
            if goal == Goal::BottomLeft {
                // Row by row from the bottom, left to right: the first free positions.
                'scan: for (w, &word) in free.iter().enumerate() {
                    let mut bits = word;
                    while bits != 0 {
                        let idx = w * 64 + bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        if best.len() == k && best.last().is_some_and(|l| idx as f64 > l.0) {
                            break 'scan;
                        }
                        offer(&mut best, k, idx as f64, ti, idx);
                    }
                }
                continue;
            }
            let half = [unscaled(t.size[0]) / 2.0, unscaled(t.size[1]) / 2.0];
            let origin = self.corner(0, 0);
            let x_at = |i: usize| origin[0] + i as f64 * self.step;
            let y_at = |j: usize| origin[1] + j as f64 * self.step;
            // Per net, the bounding box of its targets: the distance to it bounds the distance
            // to the nearest target from below.
            let boxes: Vec<[f64; 4]> = targets
                .iter()
                .map(|ts| {
                    ts.iter().fold(
                        [
                            f64::INFINITY,
                            f64::INFINITY,
                            f64::NEG_INFINITY,
                            f64::NEG_INFINITY,
                        ],
                        |b, t| {
                            [
                                b[0].min(t[0]),
                                b[1].min(t[1]),
                                b[2].max(t[0]),
                                b[3].max(t[1]),
                            ]
                        },
                    )
                })
                .collect();
            let outside = |v: f64, lo: f64, hi: f64| (lo - v).max(v - hi).max(0.0);
            // A lower bound of the cost at (x, y), convex in x; with `x = None`, of every
            // position in row y.
            let lower = |x: Option<f64>, y: f64| -> f64 {
                let pull_y = y + half[1] - self.centre[1];
                let pull = match x {
                    Some(x) => (x + half[0] - self.centre[0]).hypot(pull_y),
                    None => pull_y.abs(),
                };
                PULL * pull
                    + boxes
                        .iter()
                        .map(|b| {
                            let dy = outside(y, b[1], b[3]);
                            x.map_or(dy, |x| outside(x, b[0], b[2]).hypot(dy))
                        })
                        .sum::<f64>()
            };
            let bound = |best: &Vec<(f64, usize, usize)>| {
                if best.len() < k {
                    f64::INFINITY
                } else {
                    best[best.len() - 1].0 + SLACK
                }
            };
            // Rows by their bound, most promising first.
            let mut rows: Vec<(f64, usize)> =
                (0..g.ny).map(|j| (lower(None, y_at(j)), j)).collect();
            rows.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for (row_bound, j) in rows {
                if row_bound > bound(&best) {
                    break;
                }
                let y = y_at(j);
                let f = |i: usize| lower(Some(x_at(i)), y);
                // The minimum of the convex bound along the row, then where it stays within
                // the k-th best.
                let (mut lo, mut hi) = (0, g.nx - 1);
                while hi - lo > 2 {
                    let (m1, m2) = (lo + (hi - lo) / 3, hi - (hi - lo) / 3);
                    if f(m1) < f(m2) {
                        hi = m2;
                    } else {
                        lo = m1;
                    }
                }
                let Some(mid) = (lo..=hi).min_by(|&a, &b| f(a).total_cmp(&f(b))) else {
                    continue;
                };
                let limit = bound(&best);
                if f(mid) > limit {
                    continue;
                }
                let (mut a, mut b) = (0, mid);
                while a < b {
                    let m = (a + b) / 2;
                    if f(m) <= limit { b = m } else { a = m + 1 }
                }
                let first = a;
                let (mut a, mut b) = (mid, g.nx - 1);
                while a < b {
                    let m = (a + b).div_ceil(2);
                    if f(m) <= limit { a = m } else { b = m - 1 }
                }
                for i in (first..=a).filter(|&i| bit(i, j)) {
                    let limit = bound(&best);
                    let c = [x_at(i), y];
                    let mut cost = PULL
                        * (c[0] + half[0] - self.centre[0]).hypot(c[1] + half[1] - self.centre[1]);
                    for ts in &targets {
                        if cost > limit {
                            break;
                        }
                        cost += ts
                            .iter()
                            .map(|t| (c[0] - t[0]).powi(2) + (c[1] - t[1]).powi(2))
                            .fold(f64::INFINITY, f64::min)
                            .sqrt();
                    }
                    offer(&mut best, k, cost, ti, j * g.nx + i);
                }
            }
        }
        best.into_iter()
            .map(|(cost, turn, idx)| {
                (
                    cost,
                    Pose {
                        turn,
                        i: idx % g.nx,
                        j: idx / g.nx,
                    },
                )
            })
            .collect()
    }

    /// Places every item it can, those in `ahead` first, then in `order`, each at its best
    /// position by `goal`; returns the items that found no place.
    fn greedy(
        &self,
        state: &mut [Option<Pose>],
        ahead: &[usize],
        order: Order,
        goal: Goal,
    ) -> Vec<usize> {
        let n = self.items.len();
        let mut done = vec![false; n];
        let mut left = Vec::new();
        let total: Vec<f64> = self.strength.iter().map(|r| r.iter().sum()).collect();
        let by_area = |a: usize, b: usize| {
            let (x, y) = (&self.items[a], &self.items[b]);
            y.area.total_cmp(&x.area).then(x.name.cmp(y.name))
        };
        for _ in 0..n {
            let next = ahead.iter().copied().find(|&p| !done[p]);
            let next = next.or_else(|| {
                (0..n).filter(|&p| !done[p]).min_by(|&a, &b| match order {
                    Order::Largest => by_area(a, b),
                    Order::Connected => {
                        let to_placed = |p: usize| -> f64 {
                            (0..n)
                                .filter(|&q| state[q].is_some())
                                .map(|q| self.strength[p][q])
                                .sum()
                        };
                        to_placed(b)
                            .total_cmp(&to_placed(a))
                            .then(total[b].total_cmp(&total[a]))
                            .then(by_area(a, b))
                    }
                })
            });
            let Some(p) = next else { break };
            done[p] = true;
            match self.candidates(p, state, goal, 1).first() {
                Some(&(_, pose)) => state[p] = Some(pose),
                None => left.push(p),
            }
        }
        left
    }

    /// Re-inserts and swaps parts while the rubberbands get shorter.
    fn improve(&self, state: &mut [Option<Pose>]) {
        let n = self.items.len();
        for _ in 0..MAX_ROUNDS {
            let mut improved = false;
            for p in 0..n {
                if self.item_nets[p].is_empty() {
                    continue;
                }
                let Some(old) = state[p] else { continue };
                let now = self.length_of(&[p], state);
                state[p] = None;
                let mut best = (now, old);
                for (_, pose) in self.candidates(p, state, Goal::Rubberband, TOP_K) {
                    state[p] = Some(pose);
                    let l = self.length_of(&[p], state);
                    if l < best.0 - EPS {
                        best = (l, pose);
                    }
                }
                state[p] = Some(best.1);
                improved |= best.1 != old;
            }
            for a in 0..n {
                for b in a + 1..n {
                    improved |= self.try_swap(a, b, state);
                }
            }
            if !improved {
                break;
            }
        }
    }

    /// Swaps the places of `a` and `b` (their footprints' centres, any turn) when that
    /// shortens the rubberbands.
    fn try_swap(&self, a: usize, b: usize, state: &mut [Option<Pose>]) -> bool {
        let (Some(pa), Some(pb)) = (state[a], state[b]) else {
            return false;
        };
        if self.item_nets[a].is_empty() && self.item_nets[b].is_empty() {
            return false;
        }
        let centre = |r: Rect| [r[0] + (r[2] - r[0]) / 2, r[1] + (r[3] - r[1]) / 2];
        let (ca, cb) = (centre(self.rect(a, pa)), centre(self.rect(b, pb)));
        let g = &self.grid;
        let at = |p: usize, turn: usize, c: [Coord; 2]| -> Option<Pose> {
            let size = self.items[p].turns[turn].size;
            let snap = |v: Coord, o: Coord| {
                let k = (v - o + g.s / 2).div_euclid(g.s);
                usize::try_from(k).ok()
            };
            Some(Pose {
                turn,
                i: snap(c[0] - size[0] / 2, g.x0)?,
                j: snap(c[1] - size[1] / 2, g.y0)?,
            })
        };
        let now = self.length_of(&[a, b], state);
        let mut best: Option<(f64, Pose, Pose)> = None;
        for ta in 0..self.items[a].turns.len() {
            let Some(na) = at(a, ta, cb) else { continue };
            if !self.allowed(a, na, state, &[b]) {
                continue;
            }
            for tb in 0..self.items[b].turns.len() {
                let Some(nb) = at(b, tb, ca) else { continue };
                if !self.allowed(b, nb, state, &[a])
                    || self.too_close(&self.rect(a, na), &self.rect(b, nb))
                {
                    continue;
                }
                state[a] = Some(na);
                state[b] = Some(nb);
                let l = self.length_of(&[a, b], state);
                if l < best.map_or(now - EPS, |x| x.0 - EPS) {
                    best = Some((l, na, nb));
                }
            }
        }
        match best {
            Some((_, na, nb)) => {
                state[a] = Some(na);
                state[b] = Some(nb);
                true
            }
            None => {
                state[a] = Some(pa);
                state[b] = Some(pb);
                false
            }
        }
    }

    /// The packed parts, in item order.
    fn output(&self, state: &[Option<Pose>]) -> Vec<Packed> {
        self.items
            .iter()
            .zip(state)
            .filter_map(|(item, pose)| {
                let pose = (*pose)?;
                let t = &item.turns[pose.turn];
                let c = self.corner(pose.i, pose.j);
                Some(Packed {
                    name: item.name.to_owned(),
                    x: c[0] + t.origin[0],
                    y: c[1] + t.origin[1],
                    rotation: 90.0 * f64::from(t.quarter),
                })
            })
            .collect()
    }
}

/// Keeps `(cost, turn, idx)` among the `k` best of `best` (sorted by cost, then turn, then
/// index, so the result does not depend on the order positions are offered in).
fn offer(best: &mut Vec<(f64, usize, usize)>, k: usize, cost: f64, turn: usize, idx: usize) {
    let key = (cost, turn, idx);
    let less = |a: &(f64, usize, usize), b: &(f64, usize, usize)| {
        a.0.total_cmp(&b.0)
            .then(a.1.cmp(&b.1))
            .then(a.2.cmp(&b.2))
            .is_lt()
    };
    if best.len() < k || best.last().is_some_and(|last| less(&key, last)) {
        let at = best.partition_point(|b| less(b, &key));
        best.insert(at, key);
        best.truncate(k);
    }
}

/// The area centroid of `region`, mm (the centre of its bounding box when it has no area).
fn centroid(region: &[ExPolygon]) -> [f64; 2] {
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for ex in region {
        for ring in std::iter::once(&ex.contour).chain(&ex.holes) {
            let pts = ring.points_mm();
            for k in 0..pts.len() {
                let (p, q) = (pts[k], pts[(k + 1) % pts.len()]);
                let c = p[0] * q[1] - q[0] * p[1];
                a += c;
                cx += (p[0] + q[0]) * c;
                cy += (p[1] + q[1]) * c;
                lo = [lo[0].min(p[0]), lo[1].min(p[1])];
                hi = [hi[0].max(p[0]), hi[1].max(p[1])];
            }
        }
    }
    if a.abs() > 1e-12 {
        [cx / (3.0 * a), cy / (3.0 * a)]
    } else {
        [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0]
    }
}

#[cfg(test)]
#[path = "pack_tests.rs"]
mod tests;
