//! The `conduit place` walk: a placement written for a circuit and a model, from an EAGLE
//! board's layout or packed automatically, and checked against the model's solid.
//!
//! Place in the pipeline: before the electronics line — its result is the `--placement` the
//! other walks read. The model is put on the bed and sliced as `slice` would (so the checks
//! see the layers the print has), the layout is made in model coordinates
//! (`origin = "model"`), written as TOML, read back, placed by
//! [`crate::circuit::stage::place_circuit`] and checked by
//! [`crate::circuit::fit::placement_problems`].

use crate::circuit::board_layout::{
    BoardInput, BoardLayoutError, BoardLayoutParams, Room, Side, closest_foreign_pads,
    layout_board, suggest_scale,
};
use crate::circuit::fit::{FitParams, placement_problems};
use crate::circuit::placement_toml::placement_toml;
use crate::circuit::stage::{FinePitch, fine_pitch, place_circuit};
use crate::circuit::{Circuit, Electronics, Placement, PlacementError};
use crate::config::Config;
use crate::geom::{BoundingBox, ExPolygon};
use crate::scene::Scene;
use crate::slice::{LayerZ, SliceParams, slice_mesh};

use super::{PipelineError, model_bboxes, place_on_bed_with_offsets};

/// Where the top parts' seating plane goes (model coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlaneChoice {
    /// Under the model's top by the body height and `route.wall_clearance` of cover.
    UnderTop,
    /// At this z.
    At(f64),
    /// This far below the model's top.
    FromTop(f64),
}

/// What happens to a board's bottom-side parts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BottomChoice {
    /// Face up on a plane below the top parts: at this z, or (`None`) under the top plane by
    /// the body height and `route.wall_clearance`.
    Below(Option<f64>),
    /// Refused.
    Refuse,
}

/// How `conduit place --from-brd` lays a board out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FromBoard {
    /// Where the board's centre goes (x, y, model coordinates); the model's bounding-box
    /// centre when `None`.
    pub at: Option<[f64; 2]>,
    /// Turn of the layout about the board's centre, degrees counter-clockwise.
    pub rotate_deg: f64,
    /// Spread of the layout (distances between parts multiplied).
    pub scale: f64,
    /// The top parts' plane.
    pub plane: PlaneChoice,
    /// The bottom parts.
    pub bottom: BottomChoice,
    /// Every part's body height, mm.
    pub body_height: f64,
}

/// A placement made by `conduit place`, with what the checks found.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaceOutcome {
    /// The placement as written.
    pub placement: Placement,
    /// Its TOML text.
    pub toml: String,
    /// Problems a print cannot have: parts outside the solid, reaching into another part's
    /// cavity (each names the part and a distance).
    pub problems: Vec<String>,
    /// Thin material between cavities and the surface or each other.
    pub notes: Vec<String>,
    /// Board elements or circuit parts not placed, with the reason.
    pub left_out: Vec<String>,
    /// Width and depth of the parts' footprints together, mm (the model must be larger).
    pub span: [f64; 2],
    /// The seating planes used, model z, top first.
    pub planes: Vec<f64>,
    /// The smallest gap between pads of different nets on different parts, with the pins.
    pub closest_pads: Option<(f64, String, String)>,
    /// The room wanted between pads and between parts.
    pub room: Room,
    /// For a board layout: the smallest scale giving every pad pair and every part pair its
    /// room (at the width of `fine_pitch` when there is one).
    pub suggested_scale: Option<f64>,
    /// The part whose pads of different nets lie closest for the configured trace width, when
    /// two traces cannot reach them both: its pair of pads and the widest trace that fits
    /// (the narrowest such width over all parts).
    pub fine_pitch: Option<FinePitch>,
}

/// Why no placement could be made.
#[derive(Debug, thiserror::Error)]
pub enum PlaceError {
    /// The model could not be put on the bed or sliced.
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
    /// The board cannot be laid out.
    #[error(transparent)]
    Board(#[from] BoardLayoutError),
    /// The placement made does not read back or place (a bug, or a circuit the board does not
    /// match).
    #[error(transparent)]
    Placement(#[from] PlacementError),
    /// No part could be packed (the parts that found no room are named).
    #[error(transparent)]
    Pack(#[from] crate::circuit::pack::PackError),
    /// No layer top in the range asked for the seating plane.
    #[error(
        "no seating plane between z {low:.3} and {high:.3} mm: the model spans z {bottom:.3} to \
         {top:.3} mm, and a part {body:.3} mm tall needs route.wall_clearance of material under \
         and over it"
    )]
    NoPlane {
        /// The range's low end.
        low: f64,
        /// The range's high end.
        high: f64,
        /// The model's bottom.
        bottom: f64,
        /// The model's top.
        top: f64,
        /// The body height.
        body: f64,
    },
    /// A seating plane outside the model's height.
    #[error(
        "the seating plane z {z:.3} mm is outside the model, which spans z {low:.3} to {high:.3} mm"
    )]
    PlaneOutside {
        /// The plane.
        z: f64,
        /// The model's bottom.
        low: f64,
        /// The model's top.
        high: f64,
    },
}

/// The model as the checks see it: object 0 on the bed, sliced.
#[derive(Debug, Clone)]
pub struct Solid {
    /// Model-space bounding box of object 0.
    bbox: BoundingBox,
    /// Object 0's move from model to bed coordinates.
    offset: [f64; 3],
    /// Model-space bounding boxes of every object (the placement frame).
    pub bboxes: Vec<BoundingBox>,
    /// Every object's move to the bed.
    pub offsets: Vec<[f64; 3]>,
    /// Object 0's layers (bed coordinates) and their islands.
    zs: Vec<LayerZ>,
    islands: Vec<Vec<ExPolygon>>,
}

impl Solid {
    /// Object 0 of `scene` put on the bed and sliced as `conduit slice` would with `cfg`.
    ///
    /// # Errors
    /// An empty scene, or layer settings the slicer refuses.
    pub fn of(scene: &Scene, cfg: &Config) -> Result<Self, PipelineError> {
        if scene.triangle_count() == 0 {
            return Err(PipelineError::EmptyScene);
        }
        let bboxes = model_bboxes(scene);
        let (meshes, offsets) = place_on_bed_with_offsets(scene, cfg);
        let params = SliceParams::new(cfg.slice.layer_height, cfg.slice.first_layer_height)?;
        let (layers, _) = slice_mesh(&meshes[0], &params);
        Ok(Self {
            bbox: bboxes[0],
            offset: offsets[0],
            zs: layers.iter().map(|l| l.z).collect(),
            islands: layers.into_iter().map(|l| l.islands).collect(),
            bboxes,
            offsets,
        })
    }

    /// The model z of the top of the layer nearest to `z` (a seating plane sits on a layer's
    /// top), within the model.
    fn snap(&self, z: f64) -> f64 {
        self.zs
            .iter()
            // To the nanometre: a layer top is a sum of layer heights.
            .map(|l| ((l.top - self.offset[2]) * 1e6).round() / 1e6)
            .min_by(|a, b| (a - z).abs().total_cmp(&(b - z).abs()))
            .unwrap_or(z)
    }

    fn check_plane(&self, z: f64) -> Result<(), PlaceError> {
        let (low, high) = (self.bbox.min[2], self.bbox.max[2]);
        if !(z.is_finite() && z >= low - 1e-9 && z <= high + 1e-9) {
            return Err(PlaceError::PlaneOutside { z, low, high });
        }
        Ok(())
    }
}

/// How `conduit place --auto` packs the parts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Auto {
    /// The range of model z the seating plane is chosen in; by default from
    /// `route.wall_clearance` above the model's bottom to under its top by the body height and
    /// `route.wall_clearance`.
    pub z_range: Option<[f64; 2]>,
    /// The seating plane this far under the model's top (instead of a range).
    pub from_top: Option<f64>,
    /// Smallest distance between two parts' footprints, mm; by default both cavities,
    /// `route.wall_clearance` and four traces with their channels.
    pub spacing: Option<f64>,
    /// Every part's body height, mm.
    pub body_height: f64,
}

/// Step of the packer's grid of candidate positions, mm: fine against the smallest parts
/// (0402, 1 mm long) and coarse enough that a model of 100 mm packs in a second.
const PACK_STEP_MM: f64 = 0.5;

/// Packs the circuit's parts inside object 0 of `scene` ([`crate::circuit::pack`]): on the
/// seating plane in the range where the solid, from the layer under the parts to the cover
/// over their bodies, leaves the most room (the highest of equals: the most layers under the
/// parts for the traces), every footprint `route.cavity_offset` and `route.wall_clearance`
/// inside the solid and `spacing` from the others, turned by quarter turns.
///
/// # Errors
/// [`PlaceError`] when the model cannot be sliced, no plane fits the range, or the parts do
/// not fit ([`crate::circuit::pack::PackError::NoRoom`] names them).
pub fn place_auto(
    scene: &Scene,
    cfg: &Config,
    circuit: &Circuit,
    how: &Auto,
    source: Option<String>,
) -> Result<PlaceOutcome, PlaceError> {
    use crate::circuit::pack::{PackError, PackParams, pack};
    let solid = Solid::of(scene, cfg)?;
    let r = &cfg.route;
    let (bottom, top) = (solid.bbox.min[2], solid.bbox.max[2]);
    let body = how.body_height;
    if !(body.is_finite() && body > 0.0) {
        return Err(BoardLayoutError::BadNumber {
            what: "--body-height",
            rule: "a number of mm > 0",
            value: body,
        }
        .into());
    }
    let [low, high] = match (how.z_range, how.from_top) {
        (Some(range), _) => range,
        (None, Some(d)) => [top - d; 2],
        (None, None) => [bottom + r.wall_clearance, top - body - r.wall_clearance],
    };
    // Candidate planes: the layer tops in the range (model z), highest first.
    let dz = solid.offset[2];
    let candidates: Vec<(usize, f64)> = solid
        .zs
        .iter()
        .enumerate()
        .map(|(k, l)| (k, ((l.top - dz) * 1e6).round() / 1e6))
        .filter(|&(_, z)| z >= low - 1e-9 && z <= high + 1e-9)
        .rev()
        .collect();
    let inset = -(r.cavity_offset + r.wall_clearance);
    let mut best: Option<(f64, f64, Vec<ExPolygon>)> = None;
    for &(seat, z) in &candidates {
        // The solid from the layer the parts stand on up to the cover over their bodies.
        let cover_top = z + dz + body + r.wall_clearance;
        let mut region = solid.islands[seat].clone();
        for (k, l) in solid.zs.iter().enumerate().skip(seat + 1) {
            if l.bottom >= cover_top - 1e-6 {
                break;
            }
            region = crate::geom::intersection(&region, &solid.islands[k]);
        }
        let region = crate::geom::offset(&region, inset, crate::geom::Join::Miter(2.0));
        let area: f64 = region.iter().map(ExPolygon::area_mm2).sum();
        if best.as_ref().is_none_or(|(a, _, _)| area > a * 1.01) {
            best = Some((area, z, region));
        }
    }
    let Some((_, z, region)) = best else {
        return Err(PlaceError::NoPlane {
            low,
            high,
            bottom,
            top,
            body,
        });
    };
    let mut left_out = Vec::new();
    let mut names: Vec<&str> = Vec::new();
    for part in &circuit.parts {
        if part.pads.is_empty() {
            left_out.push(format!("{}: no pads", part.name));
        } else if !crate::circuit::board_layout::has_connected_pads(circuit, part) {
            left_out.push(format!("{}: none of its pads is on a net", part.name));
        } else {
            names.push(&part.name);
        }
    }
    // Room for the traces that fan out of a side of pins between two parts: four traces with
    // their channels (a TQFP-32 at 0.4 mm traces routes completely with four, not always with
    // three), besides both cavities and the wall between them.
    let gap = how.spacing.unwrap_or(
        2.0 * r.cavity_offset + r.wall_clearance + 4.0 * (r.conductive_width + r.channel_extra),
    );
    let mut step = PACK_STEP_MM;
    let packed = loop {
        let params = PackParams {
            gap,
            rotate: true,
            step,
        };
        match pack(circuit, &names, &region, &params) {
            Err(PackError::GridTooFine { .. }) => step *= 2.0,
            other => break other?,
        }
    };
    let mut placement = Placement {
        origin: crate::circuit::Origin::Model,
        source,
        ..Placement::default()
    };
    for p in &packed {
        placement.parts.push(crate::circuit::PartPlacement {
            name: p.name.clone(),
            x: p.x - solid.offset[0],
            y: p.y - solid.offset[1],
            z,
            rotation: p.rotation,
            tilt: [0.0; 2],
            mirror: false,
            method: crate::circuit::PlacingMethod::Auto,
            connection: crate::circuit::Connection::None,
            body_height: body,
            footprint_height: 0.0,
            body_size: None,
            object: 0,
        });
    }
    let header = vec![
        format!(
            "Packed automatically on the plane z {z:.3} mm, parts {} mm apart; edit freely.",
            crate::circuit::placement_toml::toml_number(gap)
        ),
        "z is the seating plane (the bottom of the part, where its pads are); rotation is \
         degrees counter-clockwise seen from above."
            .to_owned(),
        "body_height is a guess: measure your parts.".to_owned(),
    ];
    let describe = |name: &str| Some(describe_part(circuit.part(name)?, "packed"));
    let toml = placement_toml(&placement, &header, describe);
    let mut outcome = check(&solid, cfg, circuit, toml, vec![z])?;
    outcome.left_out = left_out;
    Ok(outcome)
}

/// Lays `board` out in object 0 of `scene` for `circuit` (see
/// [`crate::circuit::board_layout`]), writes the placement and checks it. `source` is the
/// circuit file the placement names.
///
/// # Errors
/// [`PlaceError`] when the model cannot be sliced, a plane is outside the model, or the board
/// cannot be laid out; problems with the layout itself are in the outcome.
pub fn place_from_board(
    scene: &Scene,
    cfg: &Config,
    circuit: &Circuit,
    board: &BoardInput,
    how: &FromBoard,
    source: Option<String>,
) -> Result<PlaceOutcome, PlaceError> {
    let solid = Solid::of(scene, cfg)?;
    let b = &solid.bbox;
    let cover = how.body_height + cfg.route.wall_clearance;
    let top_z = match how.plane {
        PlaneChoice::UnderTop => solid.snap(b.max[2] - cover),
        PlaneChoice::At(z) => z,
        PlaneChoice::FromTop(d) => b.max[2] - d,
    };
    solid.check_plane(top_z)?;
    let bottom_z = match how.bottom {
        BottomChoice::Refuse => None,
        BottomChoice::Below(Some(z)) => Some(z),
        BottomChoice::Below(None) => Some(solid.snap(top_z - cover)),
    };

    let params = BoardLayoutParams {
        centre: how
            .at
            .unwrap_or([(b.min[0] + b.max[0]) / 2.0, (b.min[1] + b.max[1]) / 2.0]),
        rotate_deg: how.rotate_deg,
        scale: how.scale,
        top_z,
        bottom_z,
        body_height: how.body_height,
    };
    let mut layout = layout_board(board, circuit, &params)?;
    if let (true, Some(z)) = (layout.sides.values().any(|s| *s != Side::Top), bottom_z) {
        solid.check_plane(z)?;
    }
    layout.placement.source = source;
    // Traces narrow enough for the finest pitch need less room between parts too: the scale
    // suggested is the one for the width suggested, so that following both routes.
    let fine = layout_fine_pitch(circuit, &layout.placement, cfg);
    let mut narrowed = cfg.clone();
    if let Some(f) = &fine {
        narrowed.route.conductive_width = narrowed.route.conductive_width.min(f.width);
    }
    let suggested_scale = suggest_scale(board, circuit, &params, room(&narrowed));
    let header = vec![
        format!(
            "Board layout: centre at x {:.3}, y {:.3} mm, turned {} deg, scale {}; edit freely.",
            params.centre[0],
            params.centre[1],
            crate::circuit::placement_toml::toml_number(params.rotate_deg),
            crate::circuit::placement_toml::toml_number(params.scale),
        ),
        "z is the seating plane (the bottom of the part, where its pads are); rotation is \
         degrees counter-clockwise seen from above."
            .to_owned(),
        "body_height is a guess (a board file has none): measure your parts.".to_owned(),
    ];
    let sides = layout.sides.clone();
    let describe = |name: &str| {
        let part = circuit.part(name)?;
        let side = match sides.get(name) {
            Some(Side::Bottom) => "bottom side, placed face up below the top parts",
            Some(Side::Under) => "top side, below the parts its pads surround",
            _ => "top side",
        };
        Some(describe_part(part, side))
    };
    let toml = placement_toml(&layout.placement, &header, describe);
    let mut planes = vec![top_z];
    if sides.values().any(|s| *s != Side::Top)
        && let Some(z) = bottom_z
    {
        planes.push(z);
    }
    let mut outcome = check(&solid, cfg, circuit, toml, planes)?;
    outcome.left_out = layout.left_out;
    outcome.suggested_scale = suggested_scale;
    if fine.is_some() {
        outcome.room = room(&narrowed);
    }
    outcome.fine_pitch = fine;
    Ok(outcome)
}

/// The [`FinePitch`] of the parts of `placement` that asks for the narrowest trace (ties: the
/// closest pads, then the part's name), at `cfg`'s route settings.
fn layout_fine_pitch(circuit: &Circuit, placement: &Placement, cfg: &Config) -> Option<FinePitch> {
    let parts = crate::circuit::board_layout::placed_parts(circuit, placement)?;
    let params = cfg.electronics_params().route;
    parts
        .iter()
        .filter_map(|p| fine_pitch(p, &params))
        .min_by(|a, b| {
            a.width
                .total_cmp(&b.width)
                .then(a.distance.total_cmp(&b.distance))
                .then_with(|| a.part.cmp(&b.part))
        })
}

/// The room a trace needs between two pads of different nets (`route.conductive_width` and
/// `route.channel_extra` on each side) and two parts need between their footprints (both
/// `route.cavity_offset`s and `route.wall_clearance`).
fn room(cfg: &Config) -> Room {
    let r = &cfg.route;
    Room {
        trace: r.conductive_width + 2.0 * r.channel_extra,
        parts: 2.0 * r.cavity_offset + r.wall_clearance,
    }
}

/// `R1: 10k, package 0603` and the side.
fn describe_part(part: &crate::circuit::Part, side: &str) -> String {
    let mut s = part.name.clone();
    s.push(':');
    if let Some(v) = part.value.as_deref().filter(|v| !v.is_empty()) {
        s.push_str(&format!(" {v},"));
    }
    s.push_str(&format!(
        " package {}, {} pads, {side}",
        part.package,
        part.pads.len()
    ));
    s
}

/// A placement placed on the bed and checked against the solid.
#[derive(Debug, Clone, PartialEq)]
pub struct Checked {
    /// The parts and wires on the bed.
    pub placed: crate::circuit::stage::PlacedCircuit,
    /// What the checks found (see [`placement_problems`]).
    pub findings: crate::circuit::fit::FitFindings,
}

/// Places `placement` of `circuit` on the bed and checks its parts in object 0 against the
/// solid: what `conduit place` checks before it writes, and what the studio shows as a part
/// is moved.
///
/// # Errors
/// The placement does not fit the circuit or the scene's objects.
pub fn check_placement(
    solid: &Solid,
    cfg: &Config,
    circuit: &Circuit,
    placement: &Placement,
) -> Result<Checked, PlaceError> {
    let electronics = Electronics {
        circuit: circuit.clone(),
        placement: placement.clone(),
    };
    let placed = place_circuit(
        &electronics,
        &solid.bboxes,
        &solid.offsets,
        &cfg.electronics_params(),
    )
    .map_err(|e| match e {
        crate::circuit::ElectronicsError::Placement(p) => PlaceError::Placement(p),
        other => PlaceError::Pipeline(PipelineError::Electronics(other)),
    })?;
    let mine: Vec<&crate::circuit::PlacedPart> =
        placed.parts.iter().filter(|p| p.object == 0).collect();
    let findings = placement_problems(
        &mine,
        &solid.islands,
        &solid.zs,
        FitParams {
            cavity_offset: cfg.route.cavity_offset,
            wall_clearance: cfg.route.wall_clearance,
        },
    );
    Ok(Checked { placed, findings })
}

/// Reads `toml` back, places it and checks it against the solid.
fn check(
    solid: &Solid,
    cfg: &Config,
    circuit: &Circuit,
    toml: String,
    planes: Vec<f64>,
) -> Result<PlaceOutcome, PlaceError> {
    let placement = Placement::from_toml(&toml)?;
    let Checked {
        placed,
        findings: found,
    } = check_placement(solid, cfg, circuit, &placement)?;
    let mine: Vec<&crate::circuit::PlacedPart> =
        placed.parts.iter().filter(|p| p.object == 0).collect();
    let closest_pads = closest_foreign_pads(&mine);
    let span =
        crate::circuit::board_layout::bounds(mine.iter().flat_map(|p| p.footprint.points_mm()))
            .map_or([0.0; 2], |(lo, hi)| [hi[0] - lo[0], hi[1] - lo[1]]);
    Ok(PlaceOutcome {
        placement,
        toml,
        problems: found.problems,
        notes: found.notes,
        left_out: Vec::new(),
        span,
        planes,
        closest_pads,
        room: room(cfg),
        suggested_scale: None,
        fine_pitch: None,
    })
}
