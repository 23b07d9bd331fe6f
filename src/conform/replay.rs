//! Replay of written G-code against the surface: every move sampled every quarter of the inner
//! diameter, each sample checked with the whole nozzle ([`super::nozzle`]) — the replay walk of
//! [`crate::surface::replay`] with the scanned surface as obstacle.
//!
//! Place in the pipeline: after emit, on conduit's own output (or any G-code for the same
//! machine frame), as the tests of a slicer re-parse their G-code: what the file would make the
//! machine do is checked, not the planner's intent.

use super::nozzle::Nozzle;
use crate::check::moves;
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

/// Replays `gcode` and counts the nozzle-surface contacts of its moves: the replay walk
/// ([`walk`]) of every move with known ends, sampled every quarter of the inner diameter, with
/// the surface as obstacle (moves whose both ends are above the surface's top plus the needle
/// are skipped). Moves at or below `print_feed` (mm/s) count as dispensing: a pneumatic
/// dispenser's on/off is a snippet the replay does not interpret, so the feed rate tells
/// printing from travel. Moves on lines outside `body` (1-based line numbers: from the first
/// layer change to the end G-code) are the printer's custom G-code and counted apart.
pub fn replay(
    gcode: &conduit_gcode::Gcode,
    flavor: Flavor,
    surface: &Surface,
    nozzle: &Nozzle,
    print_feed: f64,
    body: std::ops::Range<usize>,
) -> ReplayContacts {
    let mut out = ReplayContacts {
        worst_penetration: f64::MIN,
        ..ReplayContacts::default()
    };
    let all = moves(gcode, flavor);
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
