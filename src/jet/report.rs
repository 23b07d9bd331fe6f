//! The JSON report of `conduit jet --report`: every corner with its angle, the rule, the fillet
//! and the accumulation model; the gap places; the layer plan; totals and warnings.
//!
//! Place in the pipeline: a side output of the jet stage, after scheduling and writing (the
//! walk hands in the G-code writer's totals as [`JetStats`]).
//! Lengths in the report are micrometres (`_um`) or millimetres (`_mm`) as their names say.

use serde::Serialize;

use super::JetSettings;
use super::fillet::{Corner, CornerAction};
use super::model::{ModelInput, accumulation};
use super::schedule::{JetLayer, JetParams, Structure};

/// What the G-code writer wrote for the job: its totals in the report.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct JetStats {
    /// Paths printed (shutter cycles).
    pub paths: usize,
    /// Jetted length, mm.
    pub jetted_mm: f64,
    /// Travel length, mm (XY).
    pub travel_mm: f64,
    /// Estimated time at the set speeds (no acceleration), s.
    pub estimated_time_s: f64,
}

/// One corner in the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CornerReport {
    /// Index of the line within its structure (0 = the wall or first fill line).
    pub line: usize,
    /// Index of the vertex in the line.
    pub index: usize,
    /// The vertex, mm.
    pub at_mm: [f64; 2],
    /// Angle between the two segments, degrees (180 = straight).
    pub angle_deg: f64,
    /// `none`, `fillet` or `split`.
    pub action: CornerAction,
    /// Radius the rule asks for, µm.
    pub required_radius_um: f64,
    /// Radius of the fillet, µm.
    pub radius_um: f64,
    /// The fillet was shrunk below the rule to fit its segments.
    pub shrunk: bool,
    /// Accumulation model at this corner (applied radius, the line width, the wall's total
    /// height, `jet.model_roi`): the bare `h_in − h_out`, µm.
    pub model_difference_um: Option<f64>,
    /// The same scaled by `jet.leveling_factor`: the predicted inside/outside height
    /// difference of the finished wall, µm.
    pub predicted_difference_um: Option<f64>,
    /// Why the model could not be evaluated here (a corner too sharp for the ROI).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_error: Option<String>,
}

/// One structure in the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StructureReport {
    /// The outline's name (`FILE#id`).
    pub name: String,
    /// Whether the outline is closed.
    pub closed: bool,
    /// Number of lines printed per layer (1 for a wall).
    pub lines: usize,
    /// Every corner of every line.
    pub corners: Vec<CornerReport>,
    /// Gap places of the first closed line, mm, in the order layers use them.
    pub gap_places_mm: Vec<[f64; 2]>,
}

/// One layer in the plan.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayerPlan {
    /// 0-based index.
    pub index: usize,
    /// Nozzle height, mm.
    pub z_mm: f64,
    /// Paths run reversed.
    pub reversed: bool,
    /// Gap place used by closed contours.
    pub gap_place: usize,
    /// Paths (shutter cycles).
    pub paths: usize,
}

/// The whole report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JetReport {
    /// The design files.
    pub designs: Vec<String>,
    /// Line width, µm.
    pub width_um: f64,
    /// Layer height, µm.
    pub layer_height_um: f64,
    /// Number of layers.
    pub layers: usize,
    /// Layers per direction block.
    pub block_layers: usize,
    /// How often the direction reverses over the job.
    pub direction_reversals: usize,
    /// Factor applied to the model's prediction.
    pub leveling_factor: f64,
    /// Per structure.
    pub structures: Vec<StructureReport>,
    /// Per layer.
    pub layer_plan: Vec<LayerPlan>,
    /// What the writer wrote.
    pub totals: JetStats,
    /// Shrunk fillets, cramped gaps.
    pub warnings: Vec<String>,
}

fn corner_report(line: usize, c: &Corner, p: &JetParams, s: &JetSettings) -> CornerReport {
    let um = 1000.0;
    let input = ModelInput {
        angle_deg: c.angle_deg.max(1e-9),
        radius: c.radius * um,
        width: p.width * um,
        height: p.layer_height * p.layers as f64 * um,
        roi: s.model_roi * um,
    };
    let (raw, err) = match accumulation(&input) {
        Ok(m) => (Some(m.difference), None),
        Err(e) => (None, Some(e.to_string())),
    };
    CornerReport {
        line,
        index: c.index,
        at_mm: c.at,
        angle_deg: c.angle_deg,
        action: c.action,
        required_radius_um: c.required_radius * um,
        radius_um: c.radius * um,
        shrunk: c.shrunk,
        model_difference_um: raw,
        predicted_difference_um: raw.map(|d| d * s.leveling_factor),
        model_error: err,
    }
}

/// Builds the report.
pub fn report(
    designs: Vec<String>,
    structures: &[Structure],
    layers: &[JetLayer],
    params: &JetParams,
    s: &JetSettings,
    totals: JetStats,
) -> JetReport {
    let mut warnings = Vec::new();
    let structures: Vec<StructureReport> = structures
        .iter()
        .map(|st| {
            let mut corners = Vec::new();
            for (li, line) in st.lines.iter().enumerate() {
                for c in &line.corners {
                    if c.shrunk {
                        warnings.push(format!(
                            "{}: corner {} ({:.1}°) needs a {:.1} µm fillet but its segments \
                             leave room for {:.1} µm",
                            st.name,
                            c.index,
                            c.angle_deg,
                            c.required_radius * 1000.0,
                            c.radius * 1000.0
                        ));
                    }
                    corners.push(corner_report(li, c, params, s));
                }
                if line.gaps.as_ref().is_some_and(|g| g.cramped) {
                    warnings.push(format!(
                        "{}: no straight stretch is long enough to keep the shutter gap away \
                         from corners",
                        st.name
                    ));
                }
            }
            let gap_places_mm = st
                .lines
                .iter()
                .find_map(|l| {
                    let g = l.gaps.as_ref()?;
                    let c = l.chains.first()?;
                    let len = c.length();
                    Some(
                        g.at.iter()
                            .map(|&a| point_at(c, a % len.max(1e-12)))
                            .collect(),
                    )
                })
                .unwrap_or_default();
            StructureReport {
                name: st.name.clone(),
                closed: st.closed,
                lines: st.lines.len(),
                corners,
                gap_places_mm,
            }
        })
        .collect();
    let block = s.block_layers.max(1);
    JetReport {
        designs,
        width_um: params.width * 1000.0,
        layer_height_um: params.layer_height * 1000.0,
        layers: params.layers,
        block_layers: block,
        direction_reversals: params.layers.saturating_sub(1) / block,
        leveling_factor: s.leveling_factor,
        structures,
        layer_plan: layers
            .iter()
            .map(|l| LayerPlan {
                index: l.index,
                z_mm: l.z,
                reversed: l.reversed,
                gap_place: l.gap_place,
                paths: l.paths.len(),
            })
            .collect(),
        totals,
        warnings,
    }
}

fn point_at(c: &super::path::Chain, s: f64) -> [f64; 2] {
    let (_, after) = c.split_at(s);
    after.start().or(c.start()).unwrap_or([0.0, 0.0])
}
