//! Extrusion into air: plastic laid where nothing holds it up, an overhang steeper than 45° with
//! no support beneath.
//!
//! Place in the pipeline: a pass of `conduit check` over the replayed moves
//! ([`conduit_gcode::moves`]), after the machine replay; it reports [`AirLayer`]s that the
//! checker turns into `extrusion_into_air` warnings.
//!
//! # The rule
//!
//! A point of a bead printed at height `z` is *held* when the centreline of a bead printed
//! below it, at `z_k`, passes within `z − z_k` of it (horizontal reach equal to the height
//! difference: a wall leaning out at 45° from the vertical moves its centre out by one layer
//! height per layer, and is exactly held). For the layer just below this says "centre within
//! one layer height of a centre below", whatever the widths: the bead then rests on at least
//! half of the one below. A bead lying along a gap between beads below, with centrelines
//! within [`GAP_SIDE_MM`] on both sides, is held too (a layer over a dense one whose lines run
//! the same way). Layers down to [`SUPPORT_GAP_MAX_MM`] below the bead's own layer
//! count, so the part's first layer over support, a removable gap above its interface, is held
//! by it. The first layer lies on the bed.
//!
//! Points are tested every [`SAMPLE_STEP_MM`] along each extruding move. A stretch of
//! unheld points is cut into straight pieces where its direction turns by more than
//! [`BRIDGE_TURN_MAX_DEG`]; a piece is a **bridge**, and fine, when the points just past both
//! its ends are anchors: held points, or for a path the file names a bridge (`;TYPE:` with
//! "bridge" in it), points within [`GAP_SIDE_MM`] of the layers below or of this layer's
//! beads printed before (threads spanning from anchor to anchor, sparse infill crossing the
//! lines below, interface lines across the base, the zig-zag turns of a bridge along its
//! perimeter). Anything else unheld — a loop hanging over air, a line ending in air — is
//! extrusion into air once a stretch adds up to [`MIN_RUN_MM`].
//!
//! Only filament beads are checked (paste beads hold what lies on them), and only planar layers: a file that extrudes while moving in Z
//! (curved layers, conformal paths) is not checked, since its layers are not stacked planes.

use std::collections::HashMap;
use std::sync::Arc;

use conduit_gcode::{Move, Moves};

use super::CheckParams;
use crate::program::machine::ToolKind;

/// Sampling step along extruding moves, mm.
pub const SAMPLE_STEP_MM: f64 = 0.1;
/// Layers at most this far (mm) below a bead's layer, beyond the layer height, may hold it: the
/// z gap between support and part is at most this in common profiles.
pub const SUPPORT_GAP_MAX_MM: f64 = 0.3;
/// Unheld stretches shorter than this (mm, about three bead widths) are not reported: the
/// bead's own stiffness carries them, and the corners of a wall leaning at 45° reach out `√2`
/// times as far as its sides, over about 0.4 mm of the loop.
pub const MIN_RUN_MM: f64 = 1.5;
/// Largest change of direction along a bridge, degrees.
pub const BRIDGE_TURN_MAX_DEG: f64 = 15.0;
const BRIDGE_TURN_DEG: f64 = BRIDGE_TURN_MAX_DEG * std::f64::consts::PI / 180.0;
/// Slack on the reach, mm: coordinates are written to the micrometre.
const REACH_SLACK_MM: f64 = 0.002;
/// Cell size of the index of the beads below, mm.
const CELL_MM: f64 = 1.0;
/// A bead lying along a gap between beads below, with their centrelines at most this far on
/// either side, is held (a gap of up to twice this between centrelines bridges itself).
pub const GAP_SIDE_MM: f64 = 1.0;

/// Extrusion into air on one layer.
#[derive(Debug, Clone, PartialEq)]
pub struct AirLayer {
    /// Z of the layer, mm.
    pub z: f64,
    /// Total length of the unheld stretches, mm.
    pub length: f64,
    /// The G-code line of the move where the first stretch starts.
    pub line: usize,
    /// Where the first stretch starts, X and Y, mm.
    pub at: [f64; 2],
    /// The feature role of the first stretch's move, as the file names it (`;TYPE:`).
    pub role: Option<String>,
}

/// One planar extruding segment.
#[derive(Clone, Copy)]
struct Segment {
    a: [f64; 2],
    b: [f64; 2],
}

impl Segment {
    /// The distance from `p` to the segment and the segment's point nearest to it.
    fn nearest(&self, p: [f64; 2]) -> (f64, [f64; 2]) {
        let (dx, dy) = (self.b[0] - self.a[0], self.b[1] - self.a[1]);
        let len2 = dx * dx + dy * dy;
        let t = if len2 > 0.0 {
            (((p[0] - self.a[0]) * dx + (p[1] - self.a[1]) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [self.a[0] + t * dx, self.a[1] + t * dy];
        ((p[0] - q[0]).hypot(p[1] - q[1]), q)
    }
}

/// The planar extruding segments of one layer, indexed by grid cell.
struct LayerIndex {
    z: f64,
    segments: Vec<Segment>,
    cells: HashMap<(i64, i64), Vec<u32>>,
    /// Segments spanning more than [`MAX_CELLS_PER_SEGMENT`] cells (a stray move far off the
    /// bed), tested by every query instead.
    long: Vec<u32>,
}

/// The most grid cells one segment is entered in.
const MAX_CELLS_PER_SEGMENT: i64 = 4096;
/// The most samples taken along one move.
const MAX_SAMPLES_PER_SEGMENT: f64 = 10_000.0;

impl LayerIndex {
    /// `segments` indexed for queries up to `reach` from them.
    fn new(z: f64, segments: Vec<Segment>, reach: f64) -> Self {
        let mut index = Self {
            z,
            segments: Vec::with_capacity(segments.len()),
            cells: HashMap::new(),
            long: Vec::new(),
        };
        for s in segments {
            index.add(s, reach);
        }
        index
    }

    /// Adds `s` for queries up to `reach` from it.
    fn add(&mut self, s: Segment, reach: f64) {
        let i = self.segments.len() as u32;
        self.segments.push(s);
        let (x0, x1) = (s.a[0].min(s.b[0]) - reach, s.a[0].max(s.b[0]) + reach);
        let (y0, y1) = (s.a[1].min(s.b[1]) - reach, s.a[1].max(s.b[1]) + reach);
        let span = (cell(x1) - cell(x0) + 1).saturating_mul(cell(y1) - cell(y0) + 1);
        if span > MAX_CELLS_PER_SEGMENT {
            self.long.push(i);
            return;
        }
        for cx in cell(x0)..=cell(x1) {
            for cy in cell(y0)..=cell(y1) {
                self.cells.entry((cx, cy)).or_default().push(i);
            }
        }
    }

    /// The segments a query at `p` must test.
    fn candidates(&self, p: [f64; 2]) -> impl Iterator<Item = &Segment> {
        self.cells
            .get(&(cell(p[0]), cell(p[1])))
            .into_iter()
            .flatten()
            .chain(&self.long)
            .map(|&i| &self.segments[i as usize])
    }

    /// Whether a centreline passes within `reach` of `p`.
    fn near(&self, p: [f64; 2], reach: f64) -> bool {
        self.cells
            .get(&(cell(p[0]), cell(p[1])))
            .is_some_and(|ids| {
                ids.iter()
                    .any(|&i| self.segments[i as usize].nearest(p).0 <= reach)
            })
    }

    /// Whether this layer holds a bead at `p` running along `dir` (radians): a centreline
    /// passes within `reach` of `p`, or centrelines pass within [`GAP_SIDE_MM`] on both sides of
    /// it (it lies along a narrow gap between beads).
    fn holds(&self, p: [f64; 2], dir: f64, reach: f64) -> bool {
        let n = [-dir.sin(), dir.cos()];
        let (mut left, mut right) = (false, false);
        for s in self.candidates(p) {
            let (d, q) = s.nearest(p);
            if d <= reach {
                return true;
            }
            if d <= GAP_SIDE_MM {
                let side = (q[0] - p[0]) * n[0] + (q[1] - p[1]) * n[1];
                left |= side > 0.0;
                right |= side < 0.0;
                if left && right {
                    return true;
                }
            }
        }
        false
    }
}

fn cell(v: f64) -> i64 {
    // Saturating: a coordinate past ±9·10¹⁸ mm lands in the last cell.
    (v / CELL_MM).floor() as i64
}

/// A planar extruding move: its layer, whether a filament tool lays it, and the segments of
/// its path.
fn planar_segments(m: &Move, params: &CheckParams) -> Option<(usize, bool, Vec<Segment>)> {
    if !m.extruding || !m.has_xy {
        return None;
    }
    let filament = params.tool(m.tool).kind == ToolKind::Filament;
    m.to[2]?;
    let mut pts = Vec::with_capacity(m.path.len());
    for q in &m.path {
        pts.push([q[0]?, q[1]?]);
    }
    let segments = pts
        .windows(2)
        .map(|w| Segment { a: w[0], b: w[1] })
        .collect();
    Some((m.layer, filament, segments))
}

/// One run of consecutive extruding moves of one kind of tool.
#[derive(Clone, Default)]
struct Path {
    /// Laid by a filament tool (checked); paste beads only hold what lies on them.
    filament: bool,
    /// (G-code line, segment) in print order.
    segments: Vec<(usize, Segment)>,
    /// The feature role of each move, by G-code line, in line order.
    roles: Vec<(usize, Option<Arc<str>>)>,
}

impl Path {
    /// The feature role of the move at `line`.
    fn role_at(&self, line: usize) -> Option<&str> {
        let i = self.roles.binary_search_by_key(&line, |(l, _)| *l).ok()?;
        self.roles[i].1.as_deref()
    }
}

/// Whether any extruding move changes Z (a non-planar file).
fn non_planar(moves: &Moves) -> bool {
    moves.moves.iter().any(|m| {
        m.extruding
            && m.has_xy
            && matches!((m.from[2], m.to[2]), (Some(a), Some(b)) if (a - b).abs() > 1e-6)
    })
}

/// The layers with extrusion into air (see the module docs), bottom to top.
pub fn air_layers(moves: &Moves, params: &CheckParams) -> Vec<AirLayer> {
    if moves.layer_z.len() < 2 || non_planar(moves) {
        return Vec::new();
    }
    // Per layer: its paths (runs of consecutive extruding moves), each a list of (line, segment).
    let n = moves.layer_z.len();
    let mut paths: Vec<Vec<Path>> = vec![Vec::new(); n];
    let mut open = false;
    for m in &moves.moves {
        match planar_segments(m, params) {
            Some((layer, filament, segments)) if layer < n => {
                let same = open && paths[layer].last().is_some_and(|p| p.filament == filament);
                if !same {
                    paths[layer].push(Path {
                        filament,
                        ..Path::default()
                    });
                    open = true;
                }
                if let Some(path) = paths[layer].last_mut() {
                    path.segments
                        .extend(segments.into_iter().map(|s| (m.line, s)));
                    path.roles.push((m.line, m.role.clone()));
                }
            }
            _ => {
                // Anything else (travel, retraction, tool change) ends the path, except a
                // move that does nothing.
                if m.has_xy || m.e != 0.0 {
                    open = false;
                }
            }
        }
    }
    let reach_max = |l: usize| -> f64 {
        let h = moves.layer_z[l] - moves.layer_z[l.saturating_sub(1)];
        h + SUPPORT_GAP_MAX_MM
    };
    let mut indexes: Vec<Option<LayerIndex>> = (0..n).map(|_| None).collect();
    let mut out = Vec::new();
    for l in 1..n {
        let z = moves.layer_z[l];
        let reach = reach_max(l);
        // The layers that may hold this one.
        let below: Vec<usize> = (0..l)
            .rev()
            .take_while(|&k| z - moves.layer_z[k] <= reach + 1e-9)
            .collect();
        for &k in &below {
            if indexes[k].is_none() {
                let segments = paths[k]
                    .iter()
                    .flat_map(|p| &p.segments)
                    .map(|(_, s)| *s)
                    .collect();
                indexes[k] = Some(LayerIndex::new(
                    moves.layer_z[k],
                    segments,
                    reach.max(GAP_SIDE_MM),
                ));
            }
        }
        // Indexes below the lowest layer still needed are not needed again.
        if let Some(&lowest) = below.last() {
            for slot in indexes.iter_mut().take(lowest) {
                *slot = None;
            }
        }
        let held = |p: [f64; 2], dir: f64| {
            below.iter().any(|&k| {
                indexes[k]
                    .as_ref()
                    .is_some_and(|ix| ix.holds(p, dir, z - ix.z + REACH_SLACK_MM))
            })
        };
        let mut layer: Option<AirLayer> = None;
        // The beads of this layer printed so far: anchors for the bridges that follow.
        let mut printed = LayerIndex::new(z, Vec::new(), GAP_SIDE_MM);
        for path in &paths[l] {
            if !path.filament {
                for (_, s) in &path.segments {
                    printed.add(*s, GAP_SIDE_MM);
                }
                continue;
            }
            let bridge_role = path.segments.first().is_some_and(|(line, _)| {
                path.role_at(*line)
                    .is_some_and(|r| r.to_ascii_lowercase().contains("bridge"))
            });
            let anchored = |p: [f64; 2]| {
                bridge_role
                    && (printed.near(p, GAP_SIDE_MM)
                        || below.iter().any(|&k| {
                            indexes[k]
                                .as_ref()
                                .is_some_and(|ix| ix.near(p, GAP_SIDE_MM))
                        }))
            };
            let runs = unheld_runs(&path.segments, &held, &anchored);
            for (_, s) in &path.segments {
                printed.add(*s, GAP_SIDE_MM);
            }
            for (line, at, length) in runs {
                let entry = layer.get_or_insert_with(|| AirLayer {
                    z,
                    length: 0.0,
                    line,
                    at,
                    role: path.role_at(line).map(str::to_owned),
                });
                entry.length += length;
            }
        }
        if let Some(layer) = layer {
            out.push(layer);
        }
    }
    out
}

/// The stretches of `path` that are neither held nor bridges: (line, start, length).
/// `anchored` says whether a point counts as an anchor for a bridge besides the held points
/// (the beads of the same layer printed before, for a path the file calls a bridge).
fn unheld_runs(
    path: &[(usize, Segment)],
    held: &impl Fn([f64; 2], f64) -> bool,
    anchored: &impl Fn([f64; 2]) -> bool,
) -> Vec<(usize, [f64; 2], f64)> {
    // Samples along the path: (line, point, held, direction of its segment).
    let mut samples: Vec<(usize, [f64; 2], bool, f64)> = Vec::new();
    for (line, s) in path {
        let (dx, dy) = (s.b[0] - s.a[0], s.b[1] - s.a[1]);
        let len = dx.hypot(dy);
        if len <= 0.0 {
            continue;
        }
        let dir = dy.atan2(dx);
        let steps = (len / SAMPLE_STEP_MM)
            .ceil()
            .clamp(1.0, MAX_SAMPLES_PER_SEGMENT) as usize;
        let first = usize::from(!samples.is_empty());
        for i in first..=steps {
            let t = i as f64 / steps as f64;
            let p = [s.a[0] + t * dx, s.a[1] + t * dy];
            samples.push((*line, p, held(p, dir), dir));
        }
    }
    let mut out = Vec::new();
    let mut i = 0;
    while i < samples.len() {
        if samples[i].2 {
            i += 1;
            continue;
        }
        let start = i;
        while i < samples.len() && !samples[i].2 {
            i += 1;
        }
        // Unheld samples start..i, cut into straight pieces at every turn; a piece is a bridge
        // when the points just past both its ends are anchors.
        let end = i;
        let mut k = start;
        while k < end {
            let mut m = k + 1;
            while m < end && angle_between(samples[m].3, samples[k].3) <= BRIDGE_TURN_DEG {
                m += 1;
            }
            // The piece covers samples k..m; its anchors are samples k − 1 and m.
            let anchor = |j: Option<usize>| {
                j.and_then(|j| samples.get(j))
                    .is_some_and(|s| s.2 || anchored(s.1))
            };
            let bridge = anchor(k.checked_sub(1)) && anchor(Some(m));
            if !bridge {
                let length: f64 = samples[k..m]
                    .windows(2)
                    .map(|w| (w[1].1[0] - w[0].1[0]).hypot(w[1].1[1] - w[0].1[1]))
                    .sum();
                match out.last_mut() {
                    // Pieces of one stretch count together.
                    Some((_, _, l, s)) if *s == start => *l += length,
                    _ => out.push((samples[k].0, samples[k].1, length, start)),
                }
            }
            k = m;
        }
    }
    out.into_iter()
        .filter(|(_, _, l, _)| *l >= MIN_RUN_MM)
        .map(|(line, at, l, _)| (line, at, l))
        .collect()
}

/// The absolute difference of two directions, radians in [0, π].
fn angle_between(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    d.min(std::f64::consts::TAU - d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use conduit_gcode::{Firmware, moves, parse};

    /// G-code of `layers`, each a list of paths (lists of XY points) at z = 0.2·(i+1).
    fn gcode(layers: &[Vec<Vec<[f64; 2]>>]) -> String {
        let mut g = String::from("G21\nG90\nM83\nM104 S200\nM109 S200\nG28\n");
        for (i, paths) in layers.iter().enumerate() {
            let z = 0.2 * (i + 1) as f64;
            for path in paths {
                g.push_str(&format!(
                    "G1 Z{z:.3} F600\nG0 X{} Y{}\n",
                    path[0][0], path[0][1]
                ));
                for p in &path[1..] {
                    g.push_str(&format!("G1 X{} Y{} E0.05\n", p[0], p[1]));
                }
            }
        }
        g
    }

    fn air(layers: &[Vec<Vec<[f64; 2]>>]) -> Vec<AirLayer> {
        let text = gcode(layers);
        let parsed = parse(text.as_bytes()).expect("parses");
        let m = moves(&parsed, Firmware::Marlin);
        air_layers(&m, &CheckParams::default())
    }

    fn square(x0: f64, y0: f64, side: f64) -> Vec<[f64; 2]> {
        vec![
            [x0, y0],
            [x0 + side, y0],
            [x0 + side, y0 + side],
            [x0, y0 + side],
            [x0, y0],
        ]
    }

    #[test]
    fn walls_leaning_up_to_45_degrees_are_held_and_steeper_ones_are_not() {
        // A square loop growing by `step` per 0.2 mm layer on each side.
        let lean = |step: f64| -> Vec<Vec<Vec<[f64; 2]>>> {
            (0..10)
                .map(|i| {
                    let d = step * i as f64;
                    vec![square(10.0 - d, 10.0 - d, 10.0 + 2.0 * d)]
                })
                .collect()
        };
        assert!(air(&lean(0.0)).is_empty());
        // 45°: 0.2 mm a layer on each side, diagonally 0.28 at the corners: corners are less
        // than MIN_RUN_MM.
        assert!(air(&lean(0.2)).is_empty(), "{:?}", air(&lean(0.2)));
        // 56°: 0.3 mm a layer; every layer above the first hangs over air all round.
        let steep = air(&lean(0.3));
        assert_eq!(steep.len(), 9, "{steep:?}");
        for (i, l) in steep.iter().enumerate() {
            let side = 10.0 + 0.6 * (i + 1) as f64;
            assert!(
                (l.length - 4.0 * side).abs() < 0.5,
                "{} vs {}",
                l.length,
                4.0 * side
            );
            assert!((l.z - 0.2 * (i + 2) as f64).abs() < 1e-9);
        }
    }

    #[test]
    fn bridges_anchored_at_both_ends_are_fine_and_cantilevers_are_not() {
        // Two posts (squares at x 0–5 and 15–20), then a line across.
        let posts = vec![square(0.0, 0.0, 5.0), square(15.0, 0.0, 5.0)];
        let mut layers = vec![posts.clone(), posts.clone()];
        layers.push(vec![vec![[5.0, 2.5], [15.0, 2.5]]]);
        assert!(air(&layers).is_empty());
        // A line from the post's wall out into air, 7.5 mm past it.
        let mut cantilever = vec![posts.clone(), posts.clone()];
        cantilever.push(vec![vec![[5.0, 2.5], [12.5, 2.5]]]);
        let found = air(&cantilever);
        assert_eq!(found.len(), 1);
        // Held up to the post's edge plus the reach of the layer two below (0.4 mm).
        assert!((found[0].length - 7.0).abs() < 0.15, "{}", found[0].length);
        assert_eq!(found[0].at[1], 2.5);
        // A bend in the air is no bridge: out along x, then back along y to the other post.
        let mut bent = vec![posts.clone(), posts];
        bent.push(vec![vec![
            [5.0, 2.5],
            [10.0, 2.5],
            [10.0, 10.0],
            [15.0, 10.0],
            [15.0, 2.5],
        ]]);
        assert_eq!(air(&bent).len(), 1);
    }

    #[test]
    fn a_stray_move_far_off_the_bed_is_reported_without_filling_memory() {
        let posts = vec![square(0.0, 0.0, 5.0)];
        let layers = vec![
            posts.clone(),
            posts.clone(),
            vec![vec![[2.5, 0.0], [900_000.0, -900_000.0]]],
        ];
        let found = air(&layers);
        assert_eq!(found.len(), 1);
        assert!(found[0].length > 1.2e6, "{}", found[0].length);
    }

    #[test]
    fn a_gap_layer_over_support_still_holds() {
        // A pad on layers 1–2, nothing on layer 3, a line over the pad on layer 4 (0.2 mm gap).
        let pad: Vec<Vec<[f64; 2]>> = (0..11)
            .map(|i| {
                let y = i as f64 * 0.5;
                vec![[0.0, y], [5.0, y]]
            })
            .collect();
        let part = vec![vec![[-1.0, 2.0], [6.0, 2.0], [6.0, 4.0]]];
        let layers = vec![
            pad.clone(),
            pad,
            vec![vec![[20.0, 20.0], [22.0, 20.0]]],
            part,
        ];
        let found = air(&layers);
        // Layer 3's lone line, 15 mm away, hangs in air; layer 4 is held across the gap
        // except where it leaves the pad: at its end it runs on along the gap between two pad
        // lines until their ends are more than GAP_SIDE_MM away (x 5.9), then 2 mm into air.
        assert_eq!(found.len(), 2, "{found:?}");
        assert!((found[1].length - 2.05).abs() < 0.1, "{found:?}");
        assert_eq!(found[1].at, [5.9, 2.0]);
    }
}
