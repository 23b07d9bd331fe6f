//! Replay of written G-code against the surface: every move sampled every quarter of the inner
//! diameter, each sample checked with the whole nozzle ([`super::nozzle`]) — the replay walk of
//! [`crate::surface::replay`] with the scanned surface as obstacle.
//!
//! Place in the pipeline: after emit, on conduit's own output (or any G-code for the same
//! machine frame), as the tests of a slicer re-parse their G-code: what the file would make the
//! machine do is checked, not the planner's intent.

use super::nozzle::Nozzle;
use crate::check::{Machine, moves_on};
use crate::geom::Point3;
use crate::program::machine::Flavor;
use crate::surface::{Next, Spacing, Stretch, Surface, walk};
use serde::Serialize;

/// The 1-based line range of a conduit G-code file's body: from its first `;LAYER_CHANGE` to
/// the `;TYPE:Custom` of the end G-code (the whole file when the markers are missing).
pub fn body_lines(text: &str) -> std::ops::Range<usize> {
    let lines: Vec<&str> = text.lines().collect();
    let start = lines
        .iter()
        .position(|l| l.trim() == ";LAYER_CHANGE")
        .map_or(1, |i| i + 1);
    let end = lines
        .iter()
        .rposition(|l| l.trim() == ";TYPE:Custom")
        .map(|i| i + 1)
        .filter(|&e| e > start)
        .unwrap_or(lines.len() + 1);
    start..end
}

/// Contacts found by the replay.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ReplayContacts {
    /// Samples checked.
    pub samples: usize,
    /// Samples of dispensing moves where the nozzle meets the surface.
    pub printing: usize,
    /// Samples of travels where it does.
    pub travel: usize,
    /// Samples of the printer's start and end G-code (homing, prime line, lift) where it does:
    /// the machine's own moves, which may not know about the part on the bed.
    pub custom: usize,
    /// Deepest penetration found, mm (≤ 0: the smallest clearance).
    pub worst_penetration: f64,
    /// Up to 20 places of contact [x, y, z], mm.
    pub places: Vec<[f64; 3]>,
}

/// Replays `gcode` on `machine` and counts the nozzle-surface contacts of its moves: the
/// replay walk ([`walk`]) of every move with known ends, sampled every quarter of the inner
/// diameter, with the surface as obstacle (moves whose both ends are above the surface's top
/// plus the needle are skipped). Moves at or below the machine's `print_feed` (mm/s) count as
/// dispensing: a pneumatic dispenser's on/off is a snippet the replay does not interpret, so the
/// feed rate tells printing from travel. Moves on lines outside its `body` (1-based line
/// numbers: from the first layer change to the end G-code) are the printer's custom G-code and
/// counted apart. `G28` puts the axes it homes at the machine's `home` (`printer.home`), as the
/// firmware does: the move after it starts there, not at the origin.
pub fn replay(
    gcode: &conduit_gcode::Gcode,
    machine: &ReplayMachine,
    surface: &Surface,
    nozzle: &Nozzle,
) -> ReplayContacts {
    let body = &machine.body;
    let print_feed = machine.print_feed;
    let mut out = ReplayContacts {
        worst_penetration: f64::MIN,
        ..ReplayContacts::default()
    };
    let all = moves_on(
        gcode,
        Machine::new(machine.flavor, 25.0).with_home(machine.home),
    );
    let known_moves: Vec<(&crate::check::Move, [Point3; 2])> = all
        .moves
        .iter()
        .filter_map(|m| Some((m, [known(&m.from)?, known(&m.to)?])))
        .collect();
    let stretches = known_moves.iter().map(|(_, ends)| Stretch {
        points: ends,
        closed: false,
        tested: true,
    });
    let spacing = Spacing::Steps(nozzle.inner / 4.0);
    let mut obstacle = surface;
    walk(
        &nozzle.solid,
        &mut obstacle,
        stretches,
        spacing,
        |i, s, pen| {
            let m = known_moves[i].0;
            let p = s.tip;
            out.samples += 1;
            out.worst_penetration = out.worst_penetration.max(pen);
            if pen > 0.0 {
                if !body.contains(&m.line) {
                    out.custom += 1;
                } else if m.feed <= print_feed + 1e-9 {
                    out.printing += 1;
                } else {
                    out.travel += 1;
                }
                if out.places.len() < 20 {
                    out.places.push([p.x, p.y, p.z]);
                }
            }
            Next::Sample
        },
    );
    out
}

fn known(p: &crate::check::Position) -> Option<Point3> {
    Some(Point3::new(p[0]?, p[1]?, p[2]?))
}

/// Lowest, middle and highest of a set of values.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Spread {
    /// Smallest value.
    pub min: f64,
    /// Median (the lower middle of an even count).
    pub median: f64,
    /// Largest value.
    pub max: f64,
}

impl Spread {
    /// The spread of `values` (all zero when empty).
    pub fn of(mut values: Vec<f64>) -> Self {
        values.sort_by(f64::total_cmp);
        match (values.first(), values.last()) {
            (Some(&min), Some(&max)) => Spread {
                min,
                median: values[(values.len() - 1) / 2],
                max,
            },
            _ => Spread::default(),
        }
    }
}

/// How closely the written G-code follows the design on the surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Accuracy {
    /// Height of the tip above the highest point of the surface under its disc (d_o), at every
    /// replay sample of the dispensing moves, by the exact query, mm.
    pub tip_above_surface: Spread,
    /// Length of the dispensing moves as written, mm.
    pub printed_length: f64,
    /// Length of the design laid on the surface (the zero-standoff paths), mm.
    pub surface_length: f64,
    /// `printed_length / surface_length`. Above 1 where the tip's height over the surface
    /// changes along the path: the deposit modes hold the tip d_o/2 ahead of its design point
    /// going down (higher over the ground under it) and d/2 going up, so at every turn between
    /// downhill, level and uphill stretches the nozzle climbs or sinks relative to the surface
    /// (on 2 mm Hilbert stretches on 30° slopes, 0.6–0.8 % more travel).
    pub length_ratio: f64,
    /// Length of the printed path laid on the surface: the dispensing moves seen from above,
    /// each end at the surface's height under it, mm. Where the paste goes, independent of the
    /// tip's height over it.
    pub laid_length: f64,
    /// `laid_length / surface_length`: below 1 by the first shift of each path's start.
    pub laid_ratio: f64,
    /// Corners of the design on the surface (vertices where it turns; path ends, and the
    /// stretch of d_o/2 + d at each path's start where the first tip may start ahead, left
    /// out).
    pub corners: usize,
    /// Largest distance, seen from above, from a corner to the dispensing moves, mm.
    pub corner_deviation_max: f64,
}

/// The machine a replay runs on: firmware, where `G28` homes to, the dispensing feed rate (mm/s;
/// slower moves dispense) and the lines of the file's body.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayMachine {
    /// Firmware dialect.
    pub flavor: Flavor,
    /// Where `G28` puts the axes, mm.
    pub home: [f64; 3],
    /// Moves at or below this feed rate dispense, mm/s.
    pub print_feed: f64,
    /// 1-based line numbers of the body ([`body_lines`]).
    pub body: std::ops::Range<usize>,
}

/// The [`Accuracy`] of `gcode` on `machine` over `surface`: its dispensing moves (in the body,
/// at or below the dispensing feed), sampled as [`replay`] samples them, against the design's
/// `corners` (xy, mm) and the length of the design on the surface, `surface_length`.
pub fn accuracy(
    gcode: &conduit_gcode::Gcode,
    machine: &ReplayMachine,
    surface: &Surface,
    nozzle: &Nozzle,
    corners: &[[f64; 2]],
    surface_length: f64,
) -> Accuracy {
    let all = moves_on(
        gcode,
        Machine::new(machine.flavor, 25.0).with_home(machine.home),
    );
    let printing: Vec<[Point3; 2]> = all
        .moves
        .iter()
        .filter(|m| machine.body.contains(&m.line) && m.feed <= machine.print_feed + 1e-9)
        .filter_map(|m| Some([known(&m.from)?, known(&m.to)?]))
        .collect();
    let printed_length: f64 = printing.iter().map(|s| (s[1] - s[0]).norm()).sum();
    let laid_length: f64 = printing
        .iter()
        .map(|s| {
            // Off the surface, the tip's own height.
            let ground = |q: &Point3| surface.height(q.x, q.y).unwrap_or(q.z);
            (s[1] - s[0])
                .xy()
                .norm()
                .hypot(ground(&s[1]) - ground(&s[0]))
        })
        .sum();
    let ratio = |l: f64| {
        if surface_length > 0.0 {
            l / surface_length
        } else {
            0.0
        }
    };
    let spacing = Spacing::Steps(nozzle.inner / 4.0);
    let above: Vec<f64> = printing
        .iter()
        .flat_map(|s| spacing.samples(s, false))
        .filter_map(|s| nozzle.solid.tip_clearance(surface, &s.tip))
        .collect();
    let segments: Vec<[[f64; 2]; 2]> = printing
        .iter()
        .map(|s| [[s[0].x, s[0].y], [s[1].x, s[1].y]])
        .collect();
    let grid = SegmentGrid::new(&segments);
    let deviation = corners
        .iter()
        .map(|c| grid.distance(*c))
        .fold(0.0, f64::max);
    Accuracy {
        tip_above_surface: Spread::of(above),
        printed_length,
        surface_length,
        length_ratio: ratio(printed_length),
        laid_length,
        laid_ratio: ratio(laid_length),
        corners: corners.len(),
        corner_deviation_max: deviation,
    }
}

/// Distance in the plane from `p` to the nearest of `segments` (infinite when there are none).
fn distance_to(segments: &[[[f64; 2]; 2]], p: [f64; 2]) -> f64 {
    segments
        .iter()
        .map(|s| segment_distance(s, p))
        .fold(f64::INFINITY, f64::min)
}

/// Distance in the plane from `p` to the segment `s`.
fn segment_distance([a, b]: &[[f64; 2]; 2], p: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let w = [p[0] - a[0], p[1] - a[1]];
    let dd = d[0] * d[0] + d[1] * d[1];
    let t = if dd > 0.0 {
        ((w[0] * d[0] + w[1] * d[1]) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (w[0] - t * d[0]).hypot(w[1] - t * d[1])
}

/// Segments filed by the 1 mm grid cells their boxes overlap, for nearest-segment queries.
struct SegmentGrid<'a> {
    segments: &'a [[[f64; 2]; 2]],
    cells: std::collections::HashMap<(i64, i64), Vec<usize>>,
}

/// Cell of the segment grid, mm.
const SEGMENT_CELL: f64 = 1.0;

impl<'a> SegmentGrid<'a> {
    fn new(segments: &'a [[[f64; 2]; 2]]) -> Self {
        let mut cells: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
        for (i, [a, b]) in segments.iter().enumerate() {
            let (i0, j0) = cell(a[0].min(b[0]), a[1].min(b[1]));
            let (i1, j1) = cell(a[0].max(b[0]), a[1].max(b[1]));
            // A segment over more than 64 cells a side is left to the full search.
            if i1 - i0 > 64 || j1 - j0 > 64 {
                continue;
            }
            for ci in i0..=i1 {
                for cj in j0..=j1 {
                    cells.entry((ci, cj)).or_default().push(i);
                }
            }
        }
        Self { segments, cells }
    }

    /// The distance from `p` to the nearest segment: from the 3 × 3 cells around `p` when one
    /// there is within a cell (nothing outside them can be nearer), else from all.
    fn distance(&self, p: [f64; 2]) -> f64 {
        let (ci, cj) = cell(p[0], p[1]);
        let mut best = f64::INFINITY;
        for di in -1..=1 {
            for dj in -1..=1 {
                for &k in self.cells.get(&(ci + di, cj + dj)).into_iter().flatten() {
                    best = best.min(segment_distance(&self.segments[k], p));
                }
            }
        }
        if best <= SEGMENT_CELL {
            best
        } else {
            distance_to(self.segments, p)
        }
    }
}

fn cell(x: f64, y: f64) -> (i64, i64) {
    let c = |v: f64| (v / SEGMENT_CELL).floor().clamp(-1e12, 1e12) as i64;
    (c(x), c(y))
}
