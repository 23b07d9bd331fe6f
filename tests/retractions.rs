//! Travel and retraction end to end: a plate pierced by a grid of square holes (the kind of part
//! whose infill is cut into many short strips, like the Voron frame of the bench) is sliced by
//! the binary with the default config, the G-code replayed with `conduit_gcode`, and its
//! retractions, its separate infill runs and where the infill (with its connectors along the
//! boundary) lies are checked against the part's own geometry.

use std::path::Path;

use conduit::geom::Point3;
use conduit_gcode::{Firmware, Move, moves};

use crate::support::{slice_with_report, temp_dir, write_stl, xyz};

/// Side of one cell of the plate's grid, mm.
const CELL: f64 = 4.0;
/// Cells along each side: the plate is `CELLS · CELL` = 36 mm square.
const CELLS: usize = 9;
/// Thickness of the plate, mm (20 layers of 0.2 mm).
const THICKNESS: f64 = 4.0;

/// Whether cell (i, j) is material: every cell but those at odd (i, j), which are the 16 holes.
fn solid(i: isize, j: isize) -> bool {
    let n = CELLS as isize;
    (0..n).contains(&i) && (0..n).contains(&j) && !(i % 2 == 1 && j % 2 == 1)
}

/// The plate as a closed, outward-facing triangle mesh: top and bottom quads per solid cell,
/// side walls wherever a solid cell meets a hole or the outside.
fn plate_triangles() -> Vec<[Point3; 3]> {
    let mut tris = Vec::new();
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    let mut quad = |a: Point3, b: Point3, c: Point3, d: Point3| {
        tris.push([a, b, c]);
        tris.push([a, c, d]);
    };
    let h = THICKNESS;
    for i in 0..CELLS as isize {
        for j in 0..CELLS as isize {
            if !solid(i, j) {
                continue;
            }
            let (x0, y0) = (i as f64 * CELL, j as f64 * CELL);
            let (x1, y1) = (x0 + CELL, y0 + CELL);
            quad(p(x0, y0, h), p(x1, y0, h), p(x1, y1, h), p(x0, y1, h));
            quad(
                p(x0, y0, 0.0),
                p(x0, y1, 0.0),
                p(x1, y1, 0.0),
                p(x1, y0, 0.0),
            );
            if !solid(i - 1, j) {
                quad(p(x0, y0, 0.0), p(x0, y0, h), p(x0, y1, h), p(x0, y1, 0.0));
            }
            if !solid(i + 1, j) {
                quad(p(x1, y0, 0.0), p(x1, y1, 0.0), p(x1, y1, h), p(x1, y0, h));
            }
            if !solid(i, j - 1) {
                quad(p(x0, y0, 0.0), p(x1, y0, 0.0), p(x1, y0, h), p(x0, y0, h));
            }
            if !solid(i, j + 1) {
                quad(p(x0, y1, 0.0), p(x0, y1, h), p(x1, y1, h), p(x1, y1, 0.0));
            }
        }
    }
    tris
}

/// Slices the plate with the default config and `extra` arguments; returns the G-code's moves.
fn slice_plate(dir: &Path, extra: &[&str]) -> Vec<Move> {
    let model = dir.join("plate.stl");
    write_stl(&model, &plate_triangles());
    let mut args = vec!["-q"];
    args.extend_from_slice(extra);
    let (text, _) = slice_with_report(dir, &model, &args);
    let g = conduit_gcode::parse(text.as_bytes()).expect("G-code parses");
    moves(&g, Firmware::Marlin).moves
}

/// Retractions: E drawn back without XY motion.
fn retractions(moves: &[Move]) -> usize {
    moves.iter().filter(|m| !m.has_xy && m.e < 0.0).count()
}

fn role(m: &Move) -> &str {
    m.role.as_deref().unwrap_or_default()
}

/// Separate runs of `wanted` on layer `layer`: extruding moves of that role, a run ending at
/// any other move.
fn runs_on_layer(moves: &[Move], layer: usize, wanted: &str) -> usize {
    let mut runs = 0;
    let mut inside = false;
    for m in moves.iter().filter(|m| m.has_xy) {
        let this = m.extruding && m.layer == layer && role(m) == wanted;
        if this && !inside {
            runs += 1;
        }
        inside = this;
    }
    runs
}

/// Distance (mm) from `(x, y)`, in the plate's own coordinates, to the nearest edge of the
/// plate's material: positive inside the material, negative in a hole or outside.
fn depth_in_material(x: f64, y: f64) -> f64 {
    let side = CELL * CELLS as f64;
    let mut d = x.min(y).min(side - x).min(side - y);
    for i in (1..CELLS).step_by(2) {
        for j in (1..CELLS).step_by(2) {
            let (x0, y0) = (i as f64 * CELL, j as f64 * CELL);
            let (x1, y1) = (x0 + CELL, y0 + CELL);
            let (dx, dy) = ((x0 - x).max(x - x1).max(0.0), (y0 - y).max(y - y1).max(0.0));
            let from_hole = if dx == 0.0 && dy == 0.0 {
                -(x - x0).min(x1 - x).min(y - y0).min(y1 - y)
            } else {
                dx.hypot(dy)
            };
            d = d.min(from_hole);
        }
    }
    d
}

#[test]
fn a_plate_with_holes_prints_hole_by_hole_with_joined_infill_and_few_retractions() {
    let dir = temp_dir();
    let all = slice_plate(dir.path(), &[]);
    // Where the slicer put the plate: its outer wall's lower-left corner, less half a bead.
    let ext: Vec<&Move> = all
        .iter()
        .filter(|m| m.extruding && role(m) == "External perimeter")
        .collect();
    let lo = |k: usize| {
        ext.iter()
            .flat_map(|m| [xyz(m.from)[k], xyz(m.to)[k]])
            .fold(f64::INFINITY, f64::min)
    };
    let half_bead = 0.225;
    let (ox, oy) = (lo(0) - half_bead, lo(1) - half_bead);
    let depth = |p: [f64; 3]| depth_in_material(p[0] - ox, p[1] - oy);

    // Before infill was joined along the boundary and loops were printed hole by hole, this
    // plate took 1203 retractions (392 between sparse-infill runs, 640 between the loops of
    // different holes) and 40 sparse-infill runs on a middle layer; now 660 and 17.
    let count = retractions(&all);
    assert!(count <= 720, "{count} retractions");
    let middle = all.iter().map(|m| m.layer).max().unwrap_or(0) / 2;
    let sparse_runs = runs_on_layer(&all, middle, "Internal infill");
    assert!(
        (1..=20).contains(&sparse_runs),
        "{sparse_runs} sparse-infill runs on layer {middle}"
    );

    // The loops of one hole print one after the other: an inner loop ends at its seam and the
    // outer loop of the same hole starts beside it (within two bead widths and a half), never
    // another hole's.
    let mut pairs = 0;
    let mut last_inner: Option<[f64; 3]> = None;
    for m in all.iter().filter(|m| m.extruding && m.layer == middle) {
        match role(m) {
            "Perimeter" => last_inner = Some(xyz(m.to)),
            "External perimeter" => {
                if let Some(inner) = last_inner.take() {
                    let start = xyz(m.from);
                    let gap = (start[0] - inner[0]).hypot(start[1] - inner[1]);
                    assert!(gap < 2.0 * 0.45 + 0.5, "outer loop starts {gap} mm away");
                    pairs += 1;
                }
            }
            _ => last_inner = None,
        }
    }
    assert_eq!(
        pairs, 17,
        "16 holes and the outside, each inner loop then its outer loop"
    );

    // Infill, connectors along the boundary included, stays in the infill area: deeper in the
    // material than the inner loop's centreline by more than a fifth of a millimetre, so no
    // connector runs over a perimeter or across a hole (sampled at both ends and the middle).
    let inner_loop = all
        .iter()
        .filter(|m| m.extruding && role(m) == "Perimeter")
        .flat_map(|m| [depth(xyz(m.from)), depth(xyz(m.to))])
        .fold(f64::INFINITY, f64::min);
    assert!(
        (0.5..0.8).contains(&inner_loop),
        "inner loop at {inner_loop}"
    );
    for m in all
        .iter()
        .filter(|m| m.extruding && role(m).contains("infill"))
    {
        let (a, b) = (xyz(m.from), xyz(m.to));
        let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, a[2]];
        for p in [a, b, mid] {
            assert!(
                depth(p) >= inner_loop + 0.2,
                "{} move at line {} reaches {:.3} mm from the edge",
                role(m),
                m.line,
                depth(p)
            );
        }
    }
}
