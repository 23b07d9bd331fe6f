//! What a curved-layer print consists of, for the `clfff` section of the `--report` JSON and
//! the summary on stderr.
//!
//! Place in the pipeline: filled by [`super::plan`] (placement, scaffold, layers, collisions)
//! and completed by the pipeline (files written); read by the CLI.

use serde::Serialize;

use super::collide::Collisions;
use super::sandwich::Follows;
use super::sections::Section;

/// The `clfff` section of the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClfffReport {
    /// Where the shell went and what it looks like from above.
    pub placement: PlacementReport,
    /// The scaffold.
    pub scaffold: ScaffoldReport,
    /// Per curved layer (buffer first, then the model's layers bottom up).
    pub layers: Vec<LayerReport>,
    /// The head model replayed over the whole print.
    pub collisions: Collisions,
    /// Moves slowed for `curved.max_z_speed`, all layers.
    pub z_speed_limited: usize,
    /// Per section: tool, Program layers (travel groups), paths and length.
    pub sections: Vec<SectionReport>,
    /// The sandwich's planar core (`curved.sandwich`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub core: Option<CoreReport>,
}

/// The sandwich's planar core.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CoreReport {
    /// Bottom and top skin layers.
    pub skin_layers: [usize; 2],
    /// Planar core layers printed.
    pub layers: usize,
    /// Nozzle height of the lowest and highest core layer, mm (none without a core).
    pub z: Option<[f64; 2]>,
    /// Largest island area of a core layer, mm².
    pub max_area_mm2: f64,
    /// Toolpaths, after the lowest layer's thickness is applied.
    pub paths: usize,
    /// Extruded length, mm.
    pub length_mm: f64,
    /// Region paths whose extrusion was raised over the bottom skin (lowest core layer there).
    pub thickened_paths: usize,
}

/// The placed shell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlacementReport {
    /// How far the shell was raised above the bed after centring (raise plus buffer), mm.
    pub raised_mm: f64,
    /// Lowest and highest z of the bottom surface, mm.
    pub bottom_z: [f64; 2],
    /// Median thickness of the shell (top − bottom), mm.
    pub thickness_mm: f64,
    /// Steepest slope of the bottom surface, degrees.
    pub max_slope_deg: f64,
    /// Area of the top-down outline, mm².
    pub outline_area_mm2: f64,
    /// Holes in the outline.
    pub outline_holes: usize,
    /// Area of the scaffold area (hull plus margin), mm².
    pub scaffold_area_mm2: f64,
}

/// The scaffold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScaffoldReport {
    /// Its tool.
    pub tool: usize,
    /// Planar layers.
    pub layers: usize,
    /// Lines, all layers.
    pub lines: usize,
    /// Extruded length, mm.
    pub length_mm: f64,
    /// Top of the highest layer, mm.
    pub top_z: f64,
    /// Places where a line was cut below the surface (shortened ends and splits).
    pub cuts: usize,
}

/// One curved layer.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayerReport {
    /// Buffer or model.
    pub section: Section,
    /// The surface the layer follows: `bottom`, or `top` for the sandwich's top skin.
    pub follows: Follows,
    /// 0 for the buffer, 1 … n for the model's layers: the nozzle is at surface + k·h; for the
    /// top skin, its layer from 0 (bottom) to n_t − 1 (the top surface).
    pub k: usize,
    /// Height of the nozzle above the surface it follows (below it for the top skin), mm.
    pub offset: f64,
    /// Raster angle, degrees.
    pub angle_deg: f64,
    /// Toolpaths written.
    pub paths: usize,
    /// Points written.
    pub points: usize,
    /// Largest distance of a point or segment midpoint from its target (surface + offset),
    /// mm.
    pub max_deviation: f64,
    /// Steepest slope of the followed surface under the layer's points, degrees.
    pub max_slope_deg: f64,
    /// Cusp height of the equivalent planar print at the same layer height, `h·cos α` for that
    /// slope α, mm (the curved layer's own cusp is its `max_deviation`).
    pub planar_cusp: f64,
    /// Thinnest and thickest local layer, mm.
    pub thickness: Option<(f64, f64)>,
    /// Points whose local thickness was capped.
    pub thickness_capped: usize,
    /// Points dropped where the surface is missing.
    pub points_dropped: usize,
    /// Moves slowed for `curved.max_z_speed`.
    pub z_speed_limited: usize,
}

/// One section.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SectionReport {
    /// Which section.
    pub section: Section,
    /// Its tool.
    pub tool: usize,
    /// Program layers: planar layers for the scaffold, travel groups for curved sections.
    pub program_layers: usize,
    /// Toolpaths.
    pub paths: usize,
    /// Extruded length, mm.
    pub length_mm: f64,
    /// The file it was written to, with `--split-sections`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
}

impl ClfffReport {
    /// One line per finding worth a warning: collisions and capped thickness.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        for c in &self.collisions.listed {
            out.push(format!(
                "clfff: the head's {:?} would touch material at ({:.2}, {:.2}, {:.2}) while \
                 printing {} at ({:.2}, {:.2}, {:.2}) (program layer {})",
                c.part,
                c.material[0],
                c.material[1],
                c.material[2],
                c.role,
                c.nozzle[0],
                c.nozzle[1],
                c.nozzle[2],
                c.layer
            ));
        }
        let more = self
            .collisions
            .count
            .saturating_sub(self.collisions.listed.len());
        if more > 0 {
            out.push(format!("clfff: ... and {more} more collisions"));
        }
        let dropped: usize = self.layers.iter().map(|l| l.points_dropped).sum();
        if dropped > 0 {
            out.push(format!(
                "clfff: {dropped} points dropped where the surface is missing"
            ));
        }
        out
    }
}
