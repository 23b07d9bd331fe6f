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
    depth_by(x, y, f64::hypot)
}

/// [`depth_in_material`] measured square: beside a hole's corner the larger of the distances
/// along X and along Y, as loops and infill edges offset with sharp corners keep it (so a point
/// this deep is beyond every offset of the material's edge by less than its depth).
fn square_depth_in_material(x: f64, y: f64) -> f64 {
    depth_by(x, y, f64::max)
}

/// The depth in the material with `corner(dx, dy)` the distance beside a hole's corner.
fn depth_by(x: f64, y: f64, corner: fn(f64, f64) -> f64) -> f64 {
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
                corner(dx, dy)
            };
            d = d.min(from_hole);
        }
    }
    d
}

/// Where the slicer put the plate: its outer wall's lower-left corner, less half a bead.
fn plate_origin(moves: &[Move]) -> (f64, f64) {
    let half_bead = 0.225;
    let lo = |k: usize| {
        moves
            .iter()
            .filter(|m| m.extruding && role(m) == "External perimeter")
            .flat_map(|m| [xyz(m.from)[k], xyz(m.to)[k]])
            .fold(f64::INFINITY, f64::min)
    };
    (lo(0) - half_bead, lo(1) - half_bead)
}

#[test]
fn a_plate_with_holes_prints_hole_by_hole_with_joined_infill_and_few_retractions() {
    let dir = temp_dir();
    let all = slice_plate(dir.path(), &[]);
    let (ox, oy) = plate_origin(&all);
    let depth = |p: [f64; 3]| depth_in_material(p[0] - ox, p[1] - oy);

    // Before infill was joined along the boundary and loops were printed hole by hole, this
    // plate took 1203 retractions (392 between sparse-infill runs, 640 between the loops of
    // different holes) and 40 sparse-infill runs on a middle layer; then 662 and 17, and 487
    // retractions since travels inside the infill keep the filament primed.
    let count = retractions(&all);
    assert!(count <= 540, "{count} retractions");
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

/// Travels of `moves` that move in XY without extruding, each with whether the filament was
/// retracted when it started (a retraction since the last extrusion, not yet undone). Travels
/// before the part's first extrusion are left out: they start where the start G-code (and its
/// purge line, `;TYPE:Custom`) left the nozzle.
fn travels_with_retraction(moves: &[Move]) -> Vec<(&Move, bool)> {
    let mut retracted = false;
    let mut out = Vec::new();
    let first = moves
        .iter()
        .position(|m| m.extruding && role(m) != "Custom")
        .unwrap_or(moves.len());
    for m in &moves[first..] {
        if !m.has_xy {
            if m.e < 0.0 {
                retracted = true;
            } else if m.e > 0.0 {
                retracted = false;
            }
        } else if m.extruding {
            retracted = false;
        } else {
            out.push((m, retracted));
        }
    }
    out
}

/// Length of a move in XY, mm.
fn xy_length(m: &Move) -> f64 {
    let (a, b) = (xyz(m.from), xyz(m.to));
    (b[0] - a[0]).hypot(b[1] - a[1])
}

#[test]
fn travels_inside_the_infill_do_not_retract_and_travels_across_perimeters_do() {
    let dir = temp_dir();
    let on = slice_plate(dir.path(), &[]);
    let (ox, oy) = plate_origin(&on);
    // Least depth in the material along a travel by `depth`, sampled every 20 µm.
    let least_depth = |m: &Move, depth: fn(f64, f64) -> f64| {
        let (a, b) = (xyz(m.from), xyz(m.to));
        let n = (xy_length(m) / 0.02).ceil().max(1.0) as usize;
        (0..=n)
            .map(|i| {
                let t = i as f64 / n as f64;
                let (x, y) = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
                depth(x - ox, y - oy)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let inner_loop = on
        .iter()
        .filter(|m| m.extruding && role(m) == "Perimeter")
        .flat_map(|m| [xyz(m.from), xyz(m.to)])
        .map(|p| depth_in_material(p[0] - ox, p[1] - oy))
        .fold(f64::INFINITY, f64::min);
    let last = on.iter().map(|m| m.layer).max().unwrap_or(0);
    // 20 layers: the first is bottom skin and the last top skin; the solid layers next to them
    // are internal solid infill (as PrusaSlicer classes them), covered like the sparse infill.
    assert_eq!(last, 19);
    let internal = |layer: usize| (1..last).contains(&layer);
    // The infill area is the plate inset with sharp corners: the least square depth of the
    // infill's ends (lines, links and anchors all end on its edge) is its edge.
    let edge = on
        .iter()
        .filter(|m| m.extruding && internal(m.layer) && role(m).contains("infill"))
        .flat_map(|m| [xyz(m.from), xyz(m.to)])
        .map(|p| square_depth_in_material(p[0] - ox, p[1] - oy))
        .fold(f64::INFINITY, f64::min);
    assert!(
        (inner_loop + 0.1..inner_loop + 0.4).contains(&edge),
        "infill edge at {edge}, inner loop at {inner_loop}"
    );

    let (mut kept, mut crossing) = (0, 0);
    for (m, retracted) in travels_with_retraction(&on) {
        let long = xy_length(m) > 2.0;
        let depth = least_depth(m, depth_in_material);
        if long && depth < inner_loop {
            // Over a perimeter, a hole or out of the plate: always retracted.
            assert!(
                retracted,
                "line {}: travel across a perimeter, {:?} to {:?}, {depth:.3} mm deep",
                m.line,
                xyz(m.from),
                xyz(m.to)
            );
            crossing += 1;
        } else if long && !internal(m.layer) {
            // Over the top or bottom skin: retracted even inside the infill.
            assert!(
                retracted,
                "line {}: travel on solid layer {}",
                m.line, m.layer
            );
        } else if long && least_depth(m, square_depth_in_material) > edge - 0.02 {
            // Inside the infill area (to the G-code's rounding), never nearer the inner loop
            // than the infill itself: not retracted.
            assert!(
                !retracted,
                "line {}: travel inside the infill on layer {}, {:?} to {:?}, {depth:.3} mm deep",
                m.line,
                m.layer,
                xyz(m.from),
                xyz(m.to)
            );
            kept += 1;
        }
    }
    assert!(crossing > 300, "{crossing} travels across perimeters");
    // 433 and 174 when written.
    assert!(kept > 150, "{kept} long travels inside the infill");

    // With the setting off, every long travel retracts, as PrusaSlicer does by default.
    let off = slice_plate(
        dir.path(),
        &[
            "--set",
            "printer.only_retract_when_crossing_perimeters=false",
        ],
    );
    for (m, retracted) in travels_with_retraction(&off) {
        assert_eq!(retracted, xy_length(m) > 2.0, "line {}", m.line);
    }
    let (with, without) = (retractions(&on), retractions(&off));
    assert!(
        with + kept <= without,
        "{with} retractions with the setting, {without} without"
    );
}

/// A closed box `side` × `side` × `height` mm with its corner at the origin.
fn box_triangles(side: f64, height: f64) -> Vec<[Point3; 3]> {
    let p = |x: f64, y: f64, z: f64| Point3::new(x * side, y * side, z * height);
    let quads = [
        [p(0., 0., 0.), p(0., 1., 0.), p(1., 1., 0.), p(1., 0., 0.)],
        [p(0., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(0., 1., 1.)],
        [p(0., 0., 0.), p(1., 0., 0.), p(1., 0., 1.), p(0., 0., 1.)],
        [p(1., 0., 0.), p(1., 1., 0.), p(1., 1., 1.), p(1., 0., 1.)],
        [p(1., 1., 0.), p(0., 1., 0.), p(0., 1., 1.), p(1., 1., 1.)],
        [p(0., 1., 0.), p(0., 0., 0.), p(0., 0., 1.), p(0., 1., 1.)],
    ];
    quads
        .iter()
        .flat_map(|[a, b, c, d]| [[*a, *b, *c], [*a, *c, *d]])
        .collect()
}

#[test]
fn a_square_box_prints_its_infill_in_one_run_per_layer() {
    let dir = temp_dir();
    let model = dir.path().join("box.stl");
    write_stl(&model, &box_triangles(20.0, 3.0));
    let (text, _) = slice_with_report(dir.path(), &model, &["-q"]);
    let g = conduit_gcode::parse(text.as_bytes()).expect("G-code parses");
    let all = moves(&g, Firmware::Marlin).moves;
    let layers = all.iter().map(|m| m.layer).max().unwrap_or(0) + 1;
    assert_eq!(layers, 15);
    for layer in 0..layers {
        // Every infill line of a layer (solid at 100 %, sparse at 20 % or the bridge over the
        // sparse infill) is joined to the next along the square's infill edge: one zig-zag,
        // one run.
        let runs: usize = [
            "Solid infill",
            "Internal infill",
            "Top solid infill",
            "Bridge infill",
        ]
        .iter()
        .map(|r| runs_on_layer(&all, layer, r))
        .sum();
        assert_eq!(runs, 1, "{runs} infill runs on layer {layer}");
    }
    // So a layer retracts only when it leaves its loops for the infill and the infill for the
    // next layer's loops: at most two retractions per layer.
    let count = retractions(&all);
    assert!(
        count <= 2 * layers,
        "{count} retractions on {layers} layers"
    );
}
