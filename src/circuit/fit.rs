//! Whether placed parts fit their object: footprints and bodies inside the solid, parts clear
//! of each other's cavities, and the material left around each cavity.
//!
//! Place in the pipeline: the electronics stage runs [`part_problems`] on each object's layers
//! before it cuts the cavities (a part beside or above the object, or two parts colliding,
//! fail the job); `conduit place` runs [`placement_problems`] on the layout it proposes, which
//! adds the bodies, the cavities and the clearances to the walls and between parts.

use crate::circuit::PlacedPart;
use crate::geom::{ExPolygon, Point2, Polygon, scaled};
use crate::slice::LayerZ;

/// Footprint area beyond the solid (or overlap between two footprints) that is still taken as
/// none, mm²: polygon rounding at the nanometre grid, and pads flush with a wall.
pub const PROBLEM_AREA_MM2: f64 = 0.05;

/// A footprint as a one-polygon region.
fn region(p: &Polygon) -> [ExPolygon; 1] {
    [ExPolygon {
        contour: p.clone(),
        holes: Vec::new(),
    }]
}

/// The layer a part seated at `z` stands on: the highest layer whose top is at or below `z`
/// (the first layer for a part on the bed).
fn seat_layer(zs: &[LayerZ], z: f64) -> usize {
    zs.iter().rposition(|l| l.top <= z + 1e-6).unwrap_or(0)
}

/// What is wrong with where the parts sit, before their cavities are cut: a part above the
/// object, a footprint reaching beyond the solid at its seating plane (the layer under it, or
/// the first layer for a part on the bed), two parts whose footprints overlap at heights both
/// bodies take up (cavities merely touching are one pocket, which is fine). `islands` are the
/// object's layers at `zs`, in the parts' frame.
pub fn part_problems(
    parts: &[&PlacedPart],
    islands: &[Vec<ExPolygon>],
    zs: &[LayerZ],
) -> Vec<String> {
    let mut problems: Vec<String> = parts
        .iter()
        .filter_map(|p| seat_problem(p, islands, zs))
        .collect();
    if !zs.is_empty() {
        problems.extend(collisions(parts).into_iter().map(|(_, _, m)| m));
    }
    problems
}

/// A part above the object, or whose footprint reaches beyond the solid at its seating plane.
fn seat_problem(part: &PlacedPart, islands: &[Vec<ExPolygon>], zs: &[LayerZ]) -> Option<String> {
    let last = zs.last()?;
    let z = part.position.z;
    if z > last.top + 1e-6 {
        return Some(format!(
            "part {} is above the object: its seating plane z {z:.3} mm is {:.3} mm over the \
             object's top ({:.3} mm)",
            part.name,
            z - last.top,
            last.top
        ));
    }
    let layer = seat_layer(zs, z);
    let (beyond, reach) = outside(&part.footprint, &islands[layer])?;
    Some(format!(
        "part {} is not inside the object: {beyond:.1} of its {:.1} mm² footprint lies outside \
         the solid at z {:.3} mm, up to {reach:.2} mm beyond its edge",
        part.name,
        part.footprint.area_mm2().abs(),
        zs[layer].top
    ))
}

/// The pairs of parts (indices into `parts`, the lower first) whose footprints overlap at
/// heights both bodies take up, with the message naming them.
fn collisions(parts: &[&PlacedPart]) -> Vec<(usize, usize, String)> {
    let mut out = Vec::new();
    for (i, a) in parts.iter().enumerate() {
        for (j, b) in parts.iter().enumerate().skip(i + 1) {
            let Some((low, high)) = shared_heights(a, b) else {
                continue;
            };
            let shared: f64 =
                crate::geom::intersection(&region(&a.footprint), &region(&b.footprint))
                    .iter()
                    .map(ExPolygon::area_mm2)
                    .sum();
            if shared > PROBLEM_AREA_MM2 {
                let message = format!(
                    "parts {} and {} collide: their footprints share {shared:.1} mm² between z \
                     {low:.3} and {high:.3} mm",
                    a.name, b.name
                );
                out.push((i, j, message));
            }
        }
    }
    out
}

/// The heights both parts' bodies take up, when they overlap.
fn shared_heights(a: &PlacedPart, b: &PlacedPart) -> Option<(f64, f64)> {
    let low = a.position.z.max(b.position.z);
    let high = (a.position.z + a.body_height).min(b.position.z + b.body_height);
    (low < high - 1e-6).then_some((low, high))
}

/// How much of `footprint` lies outside `islands`: the area (mm²) and the farthest corner's
/// distance beyond the solid (mm), when the area is more than [`PROBLEM_AREA_MM2`].
fn outside(footprint: &Polygon, islands: &[ExPolygon]) -> Option<(f64, f64)> {
    let beyond: f64 = crate::geom::difference(&region(footprint), islands)
        .iter()
        .map(ExPolygon::area_mm2)
        .sum();
    (beyond > PROBLEM_AREA_MM2).then(|| {
        let reach = footprint
            .points
            .iter()
            .map(|&p| distance_outside(p, islands))
            .fold(0.0, f64::max);
        (beyond, reach)
    })
}

/// How far `p` lies outside `islands`, mm: 0 inside, else the distance to the nearest edge.
fn distance_outside(p: Point2, islands: &[ExPolygon]) -> f64 {
    if islands.iter().any(|i| i.contains(p)) {
        return 0.0;
    }
    distance_to_edges(p, islands)
}

/// The distance from `p` to the nearest edge of `islands` (contours and holes), mm.
fn distance_to_edges(p: Point2, islands: &[ExPolygon]) -> f64 {
    islands
        .iter()
        .flat_map(|i| std::iter::once(&i.contour).chain(&i.holes))
        .map(|ring| point_ring_distance(p, ring))
        .fold(f64::INFINITY, f64::min)
}

/// The distance from `p` to the nearest edge of `ring`, mm.
fn point_ring_distance(p: Point2, ring: &Polygon) -> f64 {
    let n = ring.points.len();
    (0..n)
        .map(|k| crate::geom::segment_distance(p, ring.points[k], ring.points[(k + 1) % n]))
        .fold(f64::INFINITY, f64::min)
        / scaled(1.0) as f64
}

/// The distance between the boundaries of two rings, mm: for rings that do not overlap, the
/// gap between them.
pub(crate) fn ring_gap(a: &Polygon, b: &Polygon) -> f64 {
    let one = |a: &Polygon, b: &Polygon| {
        a.points
            .iter()
            .map(|&p| point_ring_distance(p, b))
            .fold(f64::INFINITY, f64::min)
    };
    one(a, b).min(one(b, a))
}

/// What a layout proposed by `conduit place` gets checked for, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitParams {
    /// How far a cavity reaches beyond its part's footprint (`route.cavity_offset`).
    pub cavity_offset: f64,
    /// Material wanted around each cavity (`route.wall_clearance`).
    pub wall_clearance: f64,
}

/// What [`placement_problems`] found: problems a print cannot have, and notes on thin material.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FitFindings {
    /// Parts outside the solid (footprint at the seating plane, or body above it) and parts
    /// reaching into another part's cavity, each naming the part and the distance.
    pub problems: Vec<String>,
    /// Cavities closer than `wall_clearance` to the object's surface or to another cavity.
    pub notes: Vec<String>,
    /// Names of the parts a problem is about, in the order of `parts`.
    pub flagged: Vec<String>,
}

/// Checks a layout: everything [`part_problems`] checks, then per part its body (the
/// footprint at every layer from the seating plane to the top of the body, which must all be
/// solid before the cavity is cut), and per pair of parts whose bodies share heights the gap
/// between their footprints against the cavity (a problem when one part's footprint reaches
/// into the other's cavity) and against the wall wanted between the cavities (a note). The
/// material between each cavity and the object's surface at the seating plane is noted when it
/// is thinner than `wall_clearance`.
pub fn placement_problems(
    parts: &[&PlacedPart],
    islands: &[Vec<ExPolygon>],
    zs: &[LayerZ],
    params: FitParams,
) -> FitFindings {
    let mut found = FitFindings::default();
    let Some(last) = zs.last() else {
        return found;
    };
    let seated: Vec<Option<String>> = parts.iter().map(|p| seat_problem(p, islands, zs)).collect();
    let collided = collisions(parts);
    found.problems.extend(seated.iter().flatten().cloned());
    found
        .problems
        .extend(collided.iter().map(|(_, _, m)| m.clone()));
    let mut flagged: Vec<bool> = seated.iter().map(Option::is_some).collect();
    for (i, j, _) in &collided {
        flagged[*i] = true;
        flagged[*j] = true;
    }
    for (i, (part, seat)) in parts.iter().zip(&seated).enumerate() {
        if seat.is_some() {
            continue;
        }
        if let Some(problem) = body_problem(part, islands, zs, last) {
            found.problems.push(problem);
            flagged[i] = true;
            continue;
        }
        let layer = seat_layer(zs, part.position.z);
        let wall = part
            .footprint
            .points
            .iter()
            .map(|&p| distance_to_edges(p, &islands[layer]))
            .fold(f64::INFINITY, f64::min)
            - params.cavity_offset;
        if wall < params.wall_clearance - 1e-6 {
            found.notes.push(format!(
                "part {}: {:.2} mm of material between its cavity and the object's surface at \
                 z {:.3} mm (route.wall_clearance asks {:.2} mm)",
                part.name,
                wall.max(0.0),
                zs[layer].top,
                params.wall_clearance
            ));
        }
    }
    for (i, a) in parts.iter().enumerate() {
        for (j, b) in parts.iter().enumerate().skip(i + 1) {
            // A collision is named already.
            if shared_heights(a, b).is_none() || collided.iter().any(|c| (c.0, c.1) == (i, j)) {
                continue;
            }
            let gap = ring_gap(&a.footprint, &b.footprint);
            if gap < params.cavity_offset - 1e-6 {
                flagged[i] = true;
                flagged[j] = true;
                found.problems.push(format!(
                    "parts {} and {} are {gap:.2} mm apart: each reaches into the other's \
                     cavity (route.cavity_offset {:.2} mm)",
                    a.name, b.name, params.cavity_offset
                ));
            } else if gap < 2.0 * params.cavity_offset + params.wall_clearance - 1e-6 {
                found.notes.push(format!(
                    "parts {} and {}: {:.2} mm of material between their cavities \
                     (route.wall_clearance asks {:.2} mm)",
                    a.name,
                    b.name,
                    (gap - 2.0 * params.cavity_offset).max(0.0),
                    params.wall_clearance
                ));
            }
        }
    }
    found.flagged = parts
        .iter()
        .zip(&flagged)
        .filter(|(_, f)| **f)
        .map(|(p, _)| p.name.clone())
        .collect();
    found
}

/// A body that sticks out of the object, or that is not all solid from its seating plane to
/// its top (the first layer where it is not).
fn body_problem(
    part: &PlacedPart,
    islands: &[Vec<ExPolygon>],
    zs: &[LayerZ],
    last: &LayerZ,
) -> Option<String> {
    let (z, top) = (part.position.z, part.position.z + part.body_height);
    if top > last.top + 1e-6 {
        return Some(format!(
            "part {} sticks out of the object: the top of its body (z {top:.3} mm) is {:.3} mm \
             above the object's top ({:.3} mm)",
            part.name,
            top - last.top,
            last.top
        ));
    }
    zs.iter()
        .enumerate()
        .filter(|(_, l)| l.bottom < top - 1e-6 && l.top > z + 1e-6)
        .find_map(|(k, l)| {
            let (beyond, reach) = outside(&part.footprint, &islands[k])?;
            Some(format!(
                "part {}'s body is not inside the object: at z {:.3} mm {beyond:.1} mm² of it \
                 lies outside the solid, up to {reach:.2} mm beyond its edge",
                part.name, l.top
            ))
        })
}
