//! Corpus EAGLE boards placed as their `.brd` lays them out: every pad conduit places must sit
//! on the board's own copper for the pad's signal.
//!
//! The board's routing is the independent answer: a track of a signal ends on (or runs through)
//! each pad it connects, so a pad placed through its element's position, rotation and mirror
//! must cover a track end point of its signal. A pad counts as checkable when its signal has
//! tracks and no copper pour (a pour may join a pad with no track at all) and some track end
//! point of the signal lies within reach of the element.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use conduit::circuit::{Circuit, Placement, place};
use conduit::geom::{Point2, Polygon, segment_distance};
use conduit_eagle::{Board, SignalWire};

use crate::support::corpus;

/// How far a track end may lie outside the pad outline and still touch it: half the track
/// width plus this, mm (EAGLE snaps track ends to the pad's origin, so a correctly placed pad
/// has them inside).
const TOLERANCE_MM: f64 = 0.05;

fn boards(corpus: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![corpus.join("eagle")];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "brd") {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

/// Whether `p` (mm) lies inside the pad `outline` or within `reach` (mm) of its edges.
fn touches(outline: &Polygon, p: [f64; 2], reach: f64) -> bool {
    let p = Point2::from_mm(p[0], p[1]);
    let pts = &outline.points;
    let reach_nm = reach * 1e6;
    outline.contains(p)
        || (0..pts.len()).any(|i| segment_distance(p, pts[i], pts[(i + 1) % pts.len()]) <= reach_nm)
}

/// Per board: (pads on copper, checkable pads) for top-side and for mirrored elements.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
struct Tally {
    top: [usize; 2],
    bottom: [usize; 2],
}

fn tally(board: &Board) -> Tally {
    let circuit = Circuit::from_board(board);
    let placement = Placement::from_board(board, 0.0, [0.0, 0.0]);
    let placed = match place(&circuit, &placement, &[]) {
        Ok(p) => p,
        Err(e) => panic!("the board's own layout places: {e}"),
    };
    let signal_of: BTreeMap<(&str, &str), &str> = board
        .nets
        .iter()
        .flat_map(|n| {
            n.pads
                .iter()
                .map(move |(e, p)| ((e.as_str(), p.as_str()), n.name.as_str()))
        })
        .collect();
    let mut t = Tally::default();
    for part in &placed {
        let Some(element) = board.element(&part.name) else {
            continue;
        };
        let bottom = element.is_bottom();
        for pad in &part.pads {
            let Some(signal) = signal_of.get(&(part.name.as_str(), pad.name.as_str())) else {
                continue;
            };
            if board.poured_signals.contains(*signal) {
                continue;
            }
            let Some(wires) = board.signal_wires.get(*signal) else {
                continue;
            };
            let ends: Vec<(&SignalWire, [f64; 2])> = wires
                .iter()
                .flat_map(|w| [(w, [w.x1, w.y1]), (w, [w.x2, w.y2])])
                .collect();
            // Checkable: some end of the signal's tracks within the element's reach (its pads'
            // farthest corner from the origin, mirrored or not).
            let reach = part
                .pads
                .iter()
                .flat_map(|p| p.outline.points.iter())
                .map(|q| {
                    let (x, y) = q.to_mm();
                    (x - element.x).hypot(y - element.y)
                })
                .fold(0.0, f64::max)
                + 1.0;
            let near_element = ends
                .iter()
                .any(|(_, e)| (e[0] - element.x).hypot(e[1] - element.y) <= reach);
            if !near_element {
                continue;
            }
            let on = ends
                .iter()
                .any(|(w, e)| touches(&pad.outline, *e, w.width / 2.0 + TOLERANCE_MM));
            if !on && std::env::var_os("BOARD_COPPER_DEBUG").is_some() {
                let c = pad.centre;
                let d = ends
                    .iter()
                    .map(|(_, e)| (e[0] - c.x).hypot(e[1] - c.y))
                    .fold(f64::INFINITY, f64::min);
                println!(
                    "off: {} {} pad {} at ({:.3}, {:.3}), nearest track end {d:.3} mm",
                    part.name, element.rotation, pad.name, c.x, c.y
                );
            }
            let slot = if bottom { &mut t.bottom } else { &mut t.top };
            slot[1] += 1;
            slot[0] += usize::from(on);
        }
    }
    t
}

#[test]
fn corpus_board_pads_land_on_the_boards_own_copper() {
    let Some(corpus) = corpus() else { return };
    let mut all = Tally::default();
    let mut lines = Vec::new();
    for path in boards(&corpus) {
        let bytes = std::fs::read(&path).expect("corpus board readable");
        if conduit_eagle::is_binary_eagle(&bytes) {
            continue; // EAGLE 5's binary format: refused by the reader (tested elsewhere)
        }
        let board = match conduit_eagle::read_board(&bytes) {
            Ok(b) => b,
            Err(e) => panic!("{}: {e}", path.display()),
        };
        let t = tally(&board);
        lines.push(format!(
            "{}: top {}/{}, bottom {}/{}",
            path.file_name()
                .map(|n| n.to_string_lossy())
                .unwrap_or_default(),
            t.top[0],
            t.top[1],
            t.bottom[0],
            t.bottom[1]
        ));
        for k in 0..2 {
            all.top[k] += t.top[k];
            all.bottom[k] += t.bottom[k];
        }
    }
    println!("{}", lines.join("\n"));
    assert!(
        all.bottom[1] > 0,
        "the corpus has mirrored elements with tracks"
    );
    assert_eq!(
        all.top[0],
        all.top[1],
        "top-side pads off copper:\n{}",
        lines.join("\n")
    );
    assert_eq!(
        all.bottom[0],
        all.bottom[1],
        "mirrored pads off copper:\n{}",
        lines.join("\n")
    );
}
