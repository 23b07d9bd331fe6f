//! What the 3D view draws besides toolpaths: the model's mesh and the circuit (parts as
//! labelled boxes at their seating plane, their cavities, the rubberbands of unrouted wires).
//!
//! Place in the pipeline: beside [`super::job`]; built from the placed meshes
//! (`crate::pipeline::place_on_bed_with_offsets`) and the [`PlacedCircuit`] with the
//! [`ElectricalReport`] of the G-code, all in bed coordinates, and handed to [`super::page`].

use serde::Serialize;

use super::encode::{PositionStream, varints_base64, zigzag};
use crate::check::{ElectricalParams, ElectricalReport, Frame, check_electrical};
use crate::circuit::PlacingMethod;
use crate::circuit::stage::PlacedCircuit;
use crate::circuit::stage::{Electronics, ElectronicsError, ElectronicsParams};
use crate::mesh::Mesh;
use crate::program::machine::Flavor;
use crate::region::cavity::Cavity;

/// Triangle meshes, indexed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshView {
    /// Name shown in the page.
    pub name: String,
    /// Vertices.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Vertex positions, µm deltas.
    pub positions: String,
    /// Triangle corners as zigzag varint deltas from the previous index.
    pub indices: String,
}

/// The model's meshes in bed coordinates, one view per object.
pub fn mesh_views(meshes: &[Mesh]) -> Vec<MeshView> {
    meshes
        .iter()
        .map(|m| {
            let mut positions = PositionStream::default();
            for v in &m.vertices {
                positions.push([v.x, v.y, v.z]);
            }
            let mut last = 0i64;
            let indices = varints_base64(m.triangles.iter().flatten().map(|&i| {
                let d = i64::from(i) - last;
                last = i64::from(i);
                zigzag(d)
            }));
            MeshView {
                name: m.name.clone(),
                vertices: m.vertices.len(),
                triangles: m.triangles.len(),
                positions: positions.base64(),
                indices,
            }
        })
        .collect()
}

/// One placed part.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartView {
    /// Part name.
    pub name: String,
    /// `auto` (the machine places it), `manual` (a person does) or `none`.
    pub method: PlacingMethod,
    /// Footprint (pads and body), bed xy, counter-clockwise.
    pub outline: Vec<[f64; 2]>,
    /// Seating plane, mm.
    pub z: f64,
    /// Body height above it, mm.
    pub height: f64,
    /// The cavity's outlines (the footprint grown by `route.cavity_offset`), bed xy.
    pub cavity: Vec<Vec<[f64; 2]>>,
    /// Pads: name, centre and outline.
    pub pads: Vec<PadView>,
}

/// One pad of a placed part.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PadView {
    /// Pad name.
    pub name: String,
    /// Net, when a net uses it.
    pub net: Option<String>,
    /// Outline, bed xy.
    pub outline: Vec<[f64; 2]>,
}

/// A wire the G-code does not connect.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RubberbandView {
    /// Net name.
    pub net: String,
    /// `PART.PAD` (or `waypoint`) at each end.
    pub pins: [String; 2],
    /// Its ends, bed mm.
    pub from: [f64; 3],
    /// See `from`.
    pub to: [f64; 3],
}

/// The circuit as the page draws it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CircuitView {
    /// Placed parts.
    pub parts: Vec<PartView>,
    /// Wires whose two ends the G-code's traces do not join.
    pub unrouted: Vec<RubberbandView>,
    /// Wires in all.
    pub wires: usize,
    /// One line per problem of the electrical check, as `conduit check` prints them.
    pub problems: Vec<String>,
}

/// The circuit view of `placed` (bed coordinates) with the wires `report` finds open. The
/// cavity outlines are the footprints grown by `cavity_offset` (mm).
pub fn circuit_view(
    placed: &PlacedCircuit,
    report: Option<&ElectricalReport>,
    cavity_offset: f64,
) -> CircuitView {
    let parts = placed
        .parts
        .iter()
        .map(|p| PartView {
            name: p.name.clone(),
            method: p.method,
            outline: p.footprint.points_mm(),
            z: p.position.z,
            height: p.body_height,
            cavity: Cavity::around(&p.footprint, cavity_offset, p.position.z, p.body_height)
                .outline
                .iter()
                .map(|e| e.contour.points_mm())
                .collect(),
            pads: p
                .pads
                .iter()
                .map(|pad| PadView {
                    name: pad.name.clone(),
                    net: pad.net.clone(),
                    outline: pad.outline.points_mm(),
                })
                .collect(),
        })
        .collect();
    // A wire is unrouted when its two ends fall in different connected groups of its net.
    let joined = |net: &str, a: &str, b: &str| -> bool {
        let Some(r) = report else { return false };
        let Some(n) = r.nets.iter().find(|n| n.net == net) else {
            return false;
        };
        n.connected
            || n.groups
                .iter()
                .any(|g| g.iter().any(|t| t == a) && g.iter().any(|t| t == b))
    };
    let unrouted = placed
        .wires
        .iter()
        .filter(|w| !joined(&w.wire.net, &w.from, &w.to))
        .map(|w| RubberbandView {
            net: w.wire.net.clone(),
            pins: [w.from.clone(), w.to.clone()],
            from: [w.wire.from.x, w.wire.from.y, w.wire.from.z],
            to: [w.wire.to.x, w.wire.to.y, w.wire.to.z],
        })
        .collect();
    let problems = report
        .map(ElectricalReport::problem_lines)
        .unwrap_or_default();
    CircuitView {
        parts,
        unrouted,
        wires: placed.wires.len(),
        problems,
    }
}

/// The circuit of `e` as `gcode` builds it: placed in `frame` and checked by
/// [`check_electrical`] with `stage`'s settings, drawn with the wires the traces leave open.
///
/// # Errors
/// The placement does not fit the circuit or the frame.
pub fn circuit_of(
    gcode: &conduit_gcode::Gcode,
    flavor: Flavor,
    e: &Electronics,
    frame: &Frame,
    stage: &ElectronicsParams,
) -> Result<CircuitView, ElectronicsError> {
    let report = check_electrical(gcode, flavor, e, frame, stage, &ElectricalParams::of(stage))?;
    Ok(circuit_view(
        &report.placed,
        Some(&report),
        stage.cavity_offset,
    ))
}
