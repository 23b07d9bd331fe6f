//! A board's layout (EAGLE or KiCad) moved into a printed object: where `conduit place
//! --from-brd` / `--from-pcb` puts each part, and the scale that leaves printed traces room
//! between the parts.
//!
//! Place in the pipeline: before everything else of the electronics line, it writes the
//! [`Placement`] a user then edits and slices with. The board's centre (its outline's, or its
//! elements' when it has none) goes to a point of the object, turned and spread about it; top
//! parts sit on one plane, bottom-side (mirrored) parts face up on a second plane below it,
//! where they keep their place as seen from above. A printed part cannot be mirrored, so a
//! bottom part is turned to the quarter turn that puts its pads nearest to where the board's
//! mirrored copper has them (their nets are routed to them wherever they are). A top part whose
//! pads surround another top part (a socket or module standing over parts on the board) goes
//! to the lower plane too, under the parts it covers.

use std::collections::BTreeMap;

use super::placed::place;
use super::placement::{Connection, Origin, PartPlacement, Placement, PlacingMethod};
use super::{Circuit, Part, PlacedPart};
use crate::geom::BoundingBox;

/// An element of a board as the layout reads it, in EAGLE's frame: mm with y up, angles
/// counter-clockwise; a bottom-side element is `mirror`ed as EAGLE's `MR<degrees>` (turned by
/// `degrees`, then x negated) and its part's pads are those of its top side.
#[derive(Debug, Clone, PartialEq)]
pub struct LayoutElement {
    /// The element's name, the circuit part's.
    pub name: String,
    /// Origin x, mm.
    pub x: f64,
    /// Origin y, mm (y up).
    pub y: f64,
    /// Rotation, degrees counter-clockwise.
    pub degrees: f64,
    /// On the bottom side.
    pub mirror: bool,
}

/// A board as the layout reads it: its elements and the points of its outline.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BoardInput {
    /// The elements in file order.
    pub elements: Vec<LayoutElement>,
    /// Points whose bounding box is the outline's (mm, y up); empty when the board has none.
    pub outline: Vec<[f64; 2]>,
}

impl BoardInput {
    /// An EAGLE board: its elements, and the ends of its Dimension wires.
    pub fn from_eagle(board: &conduit_eagle::Board) -> Self {
        BoardInput {
            elements: board
                .elements
                .iter()
                .map(|e| LayoutElement {
                    name: e.name.clone(),
                    x: e.x,
                    y: e.y,
                    degrees: e.rotation.degrees,
                    mirror: e.rotation.mirror,
                })
                .collect(),
            outline: board
                .outline
                .iter()
                .flat_map(|s| [[s.x1, s.y1], [s.x2, s.y2]])
                .collect(),
        }
    }

    /// A KiCad board: its footprints with y turned up, and the points of its `Edge.Cuts`
    /// drawings. A bottom footprint turned by θ holds its top-side pads mirrored in y, then
    /// turned: EAGLE's `MR(180° − θ)`.
    pub fn from_kicad(pcb: &conduit_kicad::Pcb) -> Self {
        BoardInput {
            elements: pcb
                .footprints
                .iter()
                .map(|f| LayoutElement {
                    name: f.reference.clone(),
                    x: f.x,
                    y: -f.y,
                    degrees: if f.bottom {
                        (180.0 - f.rotation).rem_euclid(360.0)
                    } else {
                        f.rotation
                    },
                    mirror: f.bottom,
                })
                .collect(),
            outline: pcb
                .outline
                .iter()
                .flat_map(conduit_kicad::OutlineShape::extent_points)
                .map(|(x, y)| [x, -y])
                .collect(),
        }
    }

    /// The element named `name`.
    pub fn element(&self, name: &str) -> Option<&LayoutElement> {
        self.elements.iter().find(|e| e.name == name)
    }
}

/// How a board's layout is moved into the object (model coordinates, mm and degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoardLayoutParams {
    /// Where the board's centre goes, x and y.
    pub centre: [f64; 2],
    /// Turn of the whole layout about the board's centre, counter-clockwise seen from above.
    pub rotate_deg: f64,
    /// Factor the distances between parts are multiplied by (the parts keep their size).
    pub scale: f64,
    /// Seating plane of the top-side parts.
    pub top_z: f64,
    /// Seating plane of the bottom-side parts; `None` refuses a board that has any.
    pub bottom_z: Option<f64>,
    /// Height given to every part's body (a board file does not know it).
    pub body_height: f64,
}

/// A board's side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Top side: the part keeps its board rotation.
    Top,
    /// Bottom side (mirrored on the board): placed face up on the lower plane.
    Bottom,
    /// A top part whose pads surround another top part (a socket or module that stands over
    /// parts on the board): put on the lower plane, under the parts it covers.
    Under,
}

/// A board layout in the object.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardLayout {
    /// The placement, model coordinates.
    pub placement: Placement,
    /// The side each placed part came from.
    pub sides: BTreeMap<String, Side>,
    /// Board elements left out, with the reason, one line each.
    pub left_out: Vec<String>,
}

/// Why a board cannot be laid out.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BoardLayoutError {
    /// Bottom-side parts on a board laid out with bottom parts refused.
    #[error(
        "{} bottom-side part(s) ({}): a printed part cannot be mirrored; place them face up \
         below the top parts (leave out --bottom refuse, or give --bottom-z)",
        parts.len(),
        parts.join(", ")
    )]
    BottomParts {
        /// Their names.
        parts: Vec<String>,
    },
    /// No element of the board is a circuit part with pads.
    #[error("no element of the board is a part of the circuit with pads")]
    NoParts,
    /// A number that cannot lay out anything.
    #[error("{what} must be {rule}, got {value}")]
    BadNumber {
        /// Which option.
        what: &'static str,
        /// The rule.
        rule: &'static str,
        /// The value.
        value: f64,
    },
}

/// The board's centre, mm: the middle of its outline's bounding box (the straight and curved
/// wires of the Dimension layer), or, when it has none (a round board drawn as a circle), of
/// the origins of the elements that are circuit parts with a pad on a net (a drawing frame
/// or logo far from the board does not count).
pub fn board_centre(board: &BoardInput, circuit: &Circuit) -> [f64; 2] {
    let mut points: Vec<[f64; 2]> = board.outline.clone();
    if points.is_empty() {
        points = board
            .elements
            .iter()
            .filter(|e| {
                circuit
                    .part(&e.name)
                    .is_some_and(|p| has_connected_pads(circuit, p))
            })
            .map(|e| [e.x, e.y])
            .collect();
    }
    match bounds(points) {
        Some((lo, hi)) => [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0],
        None => [0.0; 2],
    }
}

/// The face-up rotation of a bottom-side part whose board rotation is `MR<degrees>`: the
/// quarter turn whose pads come nearest, in the least-squares sense, to where the mirrored
/// package has them (the best rigid fit of the pads, rounded to a quarter turn). A package the
/// fit cannot tell turns by `−degrees`, the rotation that keeps its outline.
pub fn face_up_rotation(part: &Part, degrees: f64) -> f64 {
    let (s, c) = degrees.to_radians().sin_cos();
    let (mut cross, mut dot) = (0.0, 0.0);
    for pad in &part.pads {
        let (x, y) = (pad.x, pad.y);
        // Where EAGLE's MR<degrees> puts the pad: rotated, then x negated.
        let (qx, qy) = (-(x * c - y * s), x * s + y * c);
        cross += x * qy - y * qx;
        dot += x * qx + y * qy;
    }
    let angle = if cross.hypot(dot) < 1e-9 {
        -degrees
    } else {
        cross.atan2(dot).to_degrees()
    };
    let quarter = (angle / 90.0).round() * 90.0;
    quarter.rem_euclid(360.0)
}

/// The top-side elements whose pads' extent (their package's pad rectangle, turned as the
/// board turns it) holds the centre of a smaller top-side element's pads: on the board they
/// stand over that part, which a print can only do with them on a lower plane.
fn covering_parts(board: &BoardInput, circuit: &Circuit) -> std::collections::BTreeSet<String> {
    struct Extent {
        name: String,
        centre: [f64; 2],
        at: [f64; 2],
        turn: f64,
        lo: [f64; 2],
        hi: [f64; 2],
    }
    let extents: Vec<Extent> = board
        .elements
        .iter()
        .filter(|e| !e.mirror)
        .filter_map(|e| {
            let part = circuit
                .part(&e.name)
                .filter(|p| has_connected_pads(circuit, p))?;
            let [x0, y0, x1, y1] = part.pad_extent()?;
            let (lo, hi) = ([x0, y0], [x1, y1]);
            let (s, c) = e.degrees.to_radians().sin_cos();
            let (mx, my) = ((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0);
            Some(Extent {
                name: e.name.clone(),
                centre: [e.x + mx * c - my * s, e.y + mx * s + my * c],
                at: [e.x, e.y],
                turn: e.degrees,
                lo,
                hi,
            })
        })
        .collect();
    let mut out = std::collections::BTreeSet::new();
    for a in &extents {
        let (s, c) = a.turn.to_radians().sin_cos();
        let holds = |p: [f64; 2]| {
            let (dx, dy) = (p[0] - a.at[0], p[1] - a.at[1]);
            // Into the package frame: the inverse turn.
            let (x, y) = (dx * c + dy * s, -dx * s + dy * c);
            x > a.lo[0] && x < a.hi[0] && y > a.lo[1] && y < a.hi[1]
        };
        let area = |e: &Extent| (e.hi[0] - e.lo[0]) * (e.hi[1] - e.lo[1]);
        // Only the larger of two parts can stand over the other.
        if extents
            .iter()
            .any(|b| b.name != a.name && area(b) < area(a) && holds(b.centre))
        {
            out.insert(a.name.clone());
        }
    }
    out
}

/// Whether a circuit part takes part in the layout: it has pads, one of them on a net.
pub(crate) fn has_connected_pads(circuit: &Circuit, part: &Part) -> bool {
    circuit
        .nets
        .iter()
        .flat_map(|n| &n.pins)
        .any(|pin| pin.part == part.name && part.pad(&pin.pad).is_some())
}

/// Lays the board out in the object (see the module documentation). Elements that are not
/// circuit parts with a pad on a net (frames, logos, fiducials, mounting holes) are left out
/// and listed.
///
/// # Errors
/// [`BoardLayoutError`] for refused bottom parts, a board without parts, or a scale or body
/// height that is not a positive number.
pub fn layout_board(
    board: &BoardInput,
    circuit: &Circuit,
    params: &BoardLayoutParams,
) -> Result<BoardLayout, BoardLayoutError> {
    if !(params.scale.is_finite() && params.scale > 0.0) {
        return Err(BoardLayoutError::BadNumber {
            what: "--scale",
            rule: "a number > 0",
            value: params.scale,
        });
    }
    if !(params.body_height.is_finite() && params.body_height > 0.0) {
        return Err(BoardLayoutError::BadNumber {
            what: "--body-height",
            rule: "a number of mm > 0",
            value: params.body_height,
        });
    }
    let centre = board_centre(board, circuit);
    let (s, c) = params.rotate_deg.to_radians().sin_cos();
    let mut out = BoardLayout {
        placement: Placement {
            origin: Origin::Model,
            ..Placement::default()
        },
        sides: BTreeMap::new(),
        left_out: Vec::new(),
    };
    let mut refused = Vec::new();
    let covering = covering_parts(board, circuit);
    for e in &board.elements {
        let Some(part) = circuit.part(&e.name) else {
            out.left_out
                .push(format!("{}: not a part of the circuit", e.name));
            continue;
        };
        if part.pads.is_empty() {
            out.left_out.push(format!("{}: no pads", e.name));
            continue;
        }
        if !has_connected_pads(circuit, part) {
            out.left_out
                .push(format!("{}: none of its pads is on a net", e.name));
            continue;
        }
        let (side, z, rotation) = if e.mirror {
            let Some(z) = params.bottom_z else {
                refused.push(e.name.clone());
                continue;
            };
            (Side::Bottom, z, face_up_rotation(part, e.degrees))
        } else if let (true, Some(z)) = (covering.contains(&e.name), params.bottom_z) {
            (Side::Under, z, e.degrees)
        } else {
            (Side::Top, params.top_z, e.degrees)
        };
        let (dx, dy) = (
            (e.x - centre[0]) * params.scale,
            (e.y - centre[1]) * params.scale,
        );
        out.placement.parts.push(PartPlacement {
            name: e.name.clone(),
            x: params.centre[0] + dx * c - dy * s,
            y: params.centre[1] + dx * s + dy * c,
            z,
            rotation: (rotation + params.rotate_deg).rem_euclid(360.0),
            tilt: [0.0; 2],
            mirror: false,
            method: PlacingMethod::Auto,
            connection: Connection::None,
            body_height: params.body_height,
            footprint_height: 0.0,
            body_size: None,
            object: 0,
        });
        out.sides.insert(e.name.clone(), side);
    }
    for part in &circuit.parts {
        if board.element(&part.name).is_none() && has_connected_pads(circuit, part) {
            out.left_out.push(format!(
                "{}: in the circuit but not on the board",
                part.name
            ));
        }
    }
    if !refused.is_empty() {
        return Err(BoardLayoutError::BottomParts { parts: refused });
    }
    if out.placement.parts.is_empty() {
        return Err(BoardLayoutError::NoParts);
    }
    Ok(out)
}

/// The bounding box of `points`, `(min, max)` mm; `None` without points.
pub(crate) fn bounds(points: impl IntoIterator<Item = [f64; 2]>) -> Option<([f64; 2], [f64; 2])> {
    points.into_iter().fold(None, |acc, p| {
        let (lo, hi) = acc.unwrap_or((p, p));
        Some((
            [lo[0].min(p[0]), lo[1].min(p[1])],
            [hi[0].max(p[0]), hi[1].max(p[1])],
        ))
    })
}

/// Whether two outlines overlap: a corner of one inside the other.
fn overlap(a: &crate::geom::Polygon, b: &crate::geom::Polygon) -> bool {
    a.points.iter().any(|&p| b.contains(p)) || b.points.iter().any(|&p| a.contains(p))
}

/// The parts of `placement` placed on their own (model coordinates, no object box needed: a
/// layout made here is in model coordinates); `None` when it does not match `circuit`.
pub fn placed_parts(circuit: &Circuit, placement: &Placement) -> Option<Vec<PlacedPart>> {
    let boxes = [BoundingBox {
        min: [0.0; 3],
        max: [0.0; 3],
    }];
    place(circuit, placement, &boxes).ok()
}

/// The smallest gap between two pads of different nets on different `parts` seated on the
/// same plane, mm, with the two pins (`PART.PAD`); `None` without such a pair. Pads that
/// overlap count as 0.
pub fn closest_foreign_pads(parts: &[&PlacedPart]) -> Option<(f64, String, String)> {
    struct Copper<'a> {
        pin: String,
        net: Option<&'a str>,
        part: usize,
        z: f64,
        lo: [f64; 2],
        hi: [f64; 2],
        outline: &'a crate::geom::Polygon,
    }
    let mut pads: Vec<Copper> = Vec::new();
    for (k, part) in parts.iter().enumerate() {
        for pad in &part.pads {
            let Some((lo, hi)) = bounds(pad.outline.points_mm()) else {
                continue;
            };
            pads.push(Copper {
                pin: format!("{}.{}", part.name, pad.name),
                net: pad.net.as_deref(),
                part: k,
                z: pad.centre.z,
                lo,
                hi,
                outline: &pad.outline,
            });
        }
    }
    // Sweep along x: only pads whose boxes come within the best gap so far are measured.
    pads.sort_by(|a, b| a.lo[0].total_cmp(&b.lo[0]));
    let mut best: Option<(f64, String, String)> = None;
    for (i, a) in pads.iter().enumerate() {
        for b in &pads[i + 1..] {
            let limit = best.as_ref().map_or(f64::INFINITY, |b| b.0);
            if b.lo[0] - a.hi[0] > limit {
                break;
            }
            if a.part == b.part || (a.z - b.z).abs() > 1e-6 {
                continue;
            }
            if a.net.is_some() && a.net == b.net {
                continue;
            }
            let box_gap = (b.lo[1] - a.hi[1]).max(a.lo[1] - b.hi[1]);
            if box_gap > limit {
                continue;
            }
            let gap = if overlap(a.outline, b.outline) {
                0.0
            } else {
                super::fit::ring_gap(a.outline, b.outline)
            };
            if gap < limit {
                let (x, y) = if a.pin <= b.pin {
                    (&a.pin, &b.pin)
                } else {
                    (&b.pin, &a.pin)
                };
                best = Some((gap, x.clone(), y.clone()));
            }
        }
    }
    best
}

/// The smallest gap between the footprints of two `parts` whose bodies share heights, mm (0
/// for footprints that overlap), with the two parts' names; `None` without such a pair. Pairs
/// whose bounding boxes are `limit` or more apart are not measured.
pub fn closest_parts(parts: &[&PlacedPart], limit: f64) -> Option<(f64, String, String)> {
    let boxes: Vec<Option<([f64; 2], [f64; 2])>> = parts
        .iter()
        .map(|p| bounds(p.footprint.points_mm()))
        .collect();
    let mut best: Option<(f64, String, String)> = None;
    for (i, a) in parts.iter().enumerate() {
        for (j, b) in parts.iter().enumerate().skip(i + 1) {
            let low = a.position.z.max(b.position.z);
            let high = (a.position.z + a.body_height).min(b.position.z + b.body_height);
            if low >= high - 1e-6 {
                continue;
            }
            let (Some((la, ha)), Some((lb, hb))) = (boxes[i], boxes[j]) else {
                continue;
            };
            let box_gap = (lb[0] - ha[0])
                .max(la[0] - hb[0])
                .max(lb[1] - ha[1])
                .max(la[1] - hb[1]);
            let bound = best.as_ref().map_or(limit, |b| b.0.min(limit));
            if box_gap >= bound {
                continue;
            }
            let gap = if overlap(&a.footprint, &b.footprint) {
                0.0
            } else {
                super::fit::ring_gap(&a.footprint, &b.footprint)
            };
            if gap < bound {
                best = Some((gap, a.name.clone(), b.name.clone()));
            }
        }
    }
    best
}

/// The room a layout must leave, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Room {
    /// Between two pads of different nets on different parts: a trace and its clearance on
    /// both sides.
    pub trace: f64,
    /// Between the footprints of two parts at the same heights: both cavities and the wall
    /// between them.
    pub parts: f64,
}

/// The largest scale [`suggest_scale`] tries.
pub const MAX_SUGGESTED_SCALE: f64 = 10.0;

/// The smallest scale, in steps of 0.05 from 1 up to [`MAX_SUGGESTED_SCALE`], at which every
/// pair of pads of different nets on different parts is `room.trace` apart and every pair of
/// parts at the same heights `room.parts`, with the board laid out by `params` otherwise;
/// `None` when even the largest does not do it.
pub fn suggest_scale(
    board: &BoardInput,
    circuit: &Circuit,
    params: &BoardLayoutParams,
    room: Room,
) -> Option<f64> {
    let steps = ((MAX_SUGGESTED_SCALE - 1.0) / 0.05).round() as usize;
    (0..=steps).map(|k| 1.0 + k as f64 * 0.05).find(|&scale| {
        let at = BoardLayoutParams { scale, ..*params };
        let Some(parts) = layout_board(board, circuit, &at)
            .ok()
            .and_then(|l| placed_parts(circuit, &l.placement))
        else {
            return false;
        };
        let parts: Vec<&PlacedPart> = parts.iter().collect();
        closest_foreign_pads(&parts).is_none_or(|(gap, _, _)| gap >= room.trace - 1e-9)
            && closest_parts(&parts, room.parts).is_none_or(|(gap, _, _)| gap >= room.parts - 1e-9)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::circuit::{Pad, PadShape};

    fn part(pads: &[(f64, f64)]) -> Part {
        Part {
            name: "U1".into(),
            value: None,
            package: "P".into(),
            pads: pads
                .iter()
                .enumerate()
                .map(|(k, &(x, y))| Pad {
                    name: format!("{}", k + 1),
                    x,
                    y,
                    shape: PadShape::Round { diameter: 0.5 },
                    rotation_deg: 0.0,
                    smd: true,
                })
                .collect(),
            pins: Default::default(),
            route_any: Default::default(),
        }
    }

    /// The squared distance from each pad turned face up by `turn` to where `MR<degrees>`
    /// puts it.
    fn misfit(p: &Part, degrees: f64, turn: f64) -> f64 {
        let (s, c) = degrees.to_radians().sin_cos();
        let (st, ct) = turn.to_radians().sin_cos();
        p.pads
            .iter()
            .map(|pad| {
                let (qx, qy) = (-(pad.x * c - pad.y * s), pad.x * s + pad.y * c);
                let (tx, ty) = (pad.x * ct - pad.y * st, pad.x * st + pad.y * ct);
                (qx - tx).powi(2) + (qy - ty).powi(2)
            })
            .sum()
    }

    #[test]
    fn a_bottom_part_turns_to_the_quarter_turn_nearest_its_mirrored_pads() {
        let packages = [
            part(&[(-1.0, 0.0), (1.0, 0.0)]),
            part(&[(0.0, 0.0), (2.0, 0.0), (2.0, 1.0)]),
            part(&[
                (-3.0, 1.0),
                (-1.0, 1.0),
                (1.0, 1.0),
                (3.0, -1.0),
                (0.5, -2.0),
            ]),
        ];
        for p in &packages {
            for degrees in [0.0, 90.0, 180.0, 270.0, 45.0] {
                let turn = face_up_rotation(p, degrees);
                assert_eq!(turn % 90.0, 0.0);
                let best = [0.0, 90.0, 180.0, 270.0]
                    .into_iter()
                    .map(|t| misfit(p, degrees, t))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    misfit(p, degrees, turn) <= best + 1e-9,
                    "MR{degrees}: turned {turn}"
                );
            }
        }
        // A two-pad part along x mirrored without a turn: a half turn puts pad 1 where the
        // mirror has it.
        assert_eq!(face_up_rotation(&packages[0], 0.0), 180.0);
    }

    /// A KiCad bottom footprint turned by θ is EAGLE's `MR(180° − θ)` of its top-side pads:
    /// the layout's element puts every pad where the KiCad board has it.
    #[test]
    fn a_kicad_bottom_footprint_is_eagles_mirrored_element() {
        let pcb = conduit_kicad::read_pcb(
            br#"(kicad_pcb (version 20240108)
              (footprint "X" (layer "B.Cu") (at 10 20 30) (property "Reference" "U1")
                (pad "1" smd rect (at 1 2 30) (size 1 1) (layers "B.Cu"))
                (pad "2" smd rect (at -1.5 0.5 30) (size 1 1) (layers "B.Cu")))
              (gr_line (start 0 0) (end 40 -10) (layer "Edge.Cuts")))"#,
        )
        .expect("board");
        let input = BoardInput::from_kicad(&pcb);
        let e = &input.elements[0];
        assert_eq!((e.x, e.y, e.degrees, e.mirror), (10.0, -20.0, 150.0, true));
        assert_eq!(input.outline, [[0.0, 0.0], [40.0, 10.0]]);
        let part = &Circuit::from_kicad_pcb(&pcb).parts[0];
        let f = &pcb.footprints[0];
        let (s, c) = e.degrees.to_radians().sin_cos();
        for (pad, kicad) in part.pads.iter().zip(&f.pads) {
            // EAGLE's MR<degrees>: turned, then x negated; y up.
            let (x, y) = (pad.x, pad.y);
            let eagle = [e.x - (x * c - y * s), e.y + x * s + y * c];
            let (bx, by) = f.board_position(kicad);
            assert!(
                (eagle[0] - bx).abs() < 1e-9 && (eagle[1] + by).abs() < 1e-9,
                "{}: {eagle:?} vs ({bx}, {by})",
                pad.name
            );
        }
    }
}
