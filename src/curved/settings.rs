//! The curved stages' settings, the `[curved]` section of the configuration: non-planar top
//! surfaces (`mode = "tops"`) and curved-layer FFF of thin shells (`mode = "clfff"`).
//!
//! Place in the pipeline: read with the rest of the config (`crate::config::Config::curved`);
//! the pipeline hands it to [`crate::curved`], which runs between slicing and the regions stage and adds the curved
//! layers to the Program (tops), or to [`crate::curved::clfff`], which replaces the planar
//! pipeline with scaffold, buffer and curved layers (clfff).

use serde::{Deserialize, Serialize};

use crate::region::RegionParams;
use crate::surface::ToolSolid;
use crate::toolpaths::ProgramParams;

/// Which curved-layer mode a slice uses.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum CurvedMode {
    /// Planar layers only.
    #[default]
    Off,
    /// Planar body; the top solid layers of gently sloped top surfaces follow the surface.
    Tops,
    /// Curved-layer FFF of a thin shell: planar scaffold, optional buffer layer, then layers
    /// that follow the shell's bottom surface offset along z.
    Clfff,
}

/// Non-planar top surfaces (`[curved]`). Lengths in mm, angles in degrees from the horizontal
/// (slopes) or from the vertical (the head cone), speeds in mm/s.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct CurvedSettings {
    /// `"off"`, `"tops"` or `"clfff"` (also set by `conduit slice --curved tops|clfff`).
    /// Default `"off"`.
    pub mode: CurvedMode,
    /// Steepest surface slope printed curved, degrees from the horizontal; steeper top surfaces
    /// stay planar (the nozzle would plough its own bead). Default 15.
    pub max_angle: f64,
    /// Longest segment of a curved path, mm: paths are split at every triangle edge of the
    /// surface and wherever needed to keep segments this short. Default 0.5.
    pub step: f64,
    /// Half-angle of the print head's cone around the nozzle, degrees from the vertical.
    /// Default 60.
    pub head_angle: f64,
    /// Height of the head's cone above the nozzle tip, mm. Default 5.
    pub head_height: f64,
    /// Radius of the carriage cylinder around the nozzle axis, mm; 0 = not modelled.
    /// Default 0.
    pub carriage_radius: f64,
    /// Height of the carriage cylinder's bottom above the nozzle tip, mm. Default 10.
    pub carriage_clearance: f64,
    /// Fastest z motion while extruding, mm/s: moves that would rise or fall faster are
    /// slowed. Default 10.
    pub max_z_speed: f64,
    /// clfff: height of the model's lowest point above the bed, room for scaffold under it, mm
    /// (with a buffer layer, the buffer's lowest point sits there). Default 2.
    pub raise: f64,
    /// clfff: print a planar scaffold under the shell. Default true.
    pub scaffold: bool,
    /// clfff: how far the scaffold area (the convex hull of the shell's top-down outline)
    /// is grown, mm. Default 3.
    pub scaffold_margin: f64,
    /// clfff: directions [x, y] of the scaffold's lines; scaffold layer `j` uses vector
    /// `j mod n`, so two crossing vectors make a grid over two layers. Default
    /// [[1, 0], [0, 1]].
    pub scaffold_vectors: Vec<[f64; 2]>,
    /// clfff: distance between neighbouring scaffold lines, mm. Default 1.
    pub scaffold_spacing: f64,
    /// clfff: tool printing the scaffold (e.g. PLA). Default 0.
    pub scaffold_tool: usize,
    /// clfff: gap between the scaffold's top and the bottom of the lowest curved layer (the
    /// buffer, or the first model layer), mm: no scaffold point is higher than the shell's
    /// bottom surface minus the buffer height minus this. Default 0.2.
    pub scaffold_clearance: f64,
    /// clfff: print one buffer layer (e.g. TPE) following the bottom surface between the
    /// scaffold and the model. Default false.
    pub buffer: bool,
    /// clfff: tool printing the buffer layer. Default 0.
    pub buffer_tool: usize,
    /// clfff: number of curved model layers; 0 = the shell's median thickness divided by the
    /// layer height. Default 3.
    pub layers: usize,
    /// clfff: raster angle of each curved layer, degrees from +X, cycled through the layers.
    /// Default [0, 90].
    pub angles: Vec<f64>,
    /// clfff: how far above the highest material under a travel the nozzle passes, mm.
    /// Default 1.
    pub travel_clearance: f64,
    /// clfff: write the scaffold, buffer and model as separate files (`OUT.scaffold.gcode`,
    /// `OUT.buffer.gcode`, `OUT.model.gcode`) instead of one file with tool changes (also
    /// `conduit slice --split-sections`). Default false.
    pub split_sections: bool,
    /// clfff: print a thick part as a sandwich: `curved.layers` bottom skin layers following
    /// the bottom surface, a planar core (the `[slice]` perimeters and infill, no solid layers
    /// of its own) between the skins, then `curved.top_layers` top skin layers following the
    /// top surface, the last on it. `curved.layers = 0` gives the bottom skin as many layers as
    /// the top. Default false.
    pub sandwich: bool,
    /// clfff sandwich: number of top skin layers (nozzle at top surface − (n − 1 − j)·h,
    /// j = 0 … n − 1). Default 3.
    pub top_layers: usize,
}

impl Default for CurvedSettings {
    fn default() -> Self {
        Self {
            mode: CurvedMode::Off,
            max_angle: 15.0,
            step: 0.5,
            head_angle: 60.0,
            head_height: 5.0,
            carriage_radius: 0.0,
            carriage_clearance: 10.0,
            max_z_speed: 10.0,
            raise: 2.0,
            scaffold: true,
            scaffold_margin: 3.0,
            scaffold_vectors: vec![[1.0, 0.0], [0.0, 1.0]],
            scaffold_spacing: 1.0,
            scaffold_tool: 0,
            scaffold_clearance: 0.2,
            buffer: false,
            buffer_tool: 0,
            layers: 3,
            angles: vec![0.0, 90.0],
            travel_clearance: 1.0,
            split_sections: false,
            sandwich: false,
            top_layers: 3,
        }
    }
}

impl CurvedSettings {
    /// Every value out of range, as `curved.key ...` messages.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        let ranges = [
            ("max_angle", self.max_angle, 0.0, 89.0),
            ("step", self.step, 0.01, 100.0),
            ("head_angle", self.head_angle, 0.0, 89.0),
            ("head_height", self.head_height, 0.0, 1000.0),
            ("carriage_radius", self.carriage_radius, 0.0, 1000.0),
            ("carriage_clearance", self.carriage_clearance, 0.0, 1000.0),
            ("max_z_speed", self.max_z_speed, 0.01, 10000.0),
            ("raise", self.raise, 0.0, 1000.0),
            ("scaffold_margin", self.scaffold_margin, 0.0, 1000.0),
            ("scaffold_spacing", self.scaffold_spacing, 0.1, 1000.0),
            ("scaffold_clearance", self.scaffold_clearance, 0.0, 100.0),
            ("travel_clearance", self.travel_clearance, 0.0, 100.0),
        ];
        for (key, v, lo, hi) in ranges {
            if !(v.is_finite() && v >= lo && v <= hi) {
                out.push(format!("curved.{key} must be in {lo}..={hi}, got {v}"));
            }
        }
        if self.scaffold_vectors.is_empty() {
            out.push("curved.scaffold_vectors must list at least one direction".to_owned());
        }
        for v in &self.scaffold_vectors {
            let len = v[0].hypot(v[1]);
            if !(len.is_finite() && len > 0.0) {
                out.push(format!(
                    "curved.scaffold_vectors: [{}, {}] is not a direction",
                    v[0], v[1]
                ));
            }
        }
        if self.angles.is_empty() {
            out.push("curved.angles must list at least one angle".to_owned());
        }
        for a in &self.angles {
            if !a.is_finite() {
                out.push(format!("curved.angles: {a} is not an angle"));
            }
        }
        if !(1..=1000).contains(&self.top_layers) {
            out.push(format!(
                "curved.top_layers must be in 1..=1000, got {}",
                self.top_layers
            ));
        }
        out
    }
}

impl CurvedSettings {
    /// The print head these settings describe: the cone and the carriage cylinder.
    pub fn head(&self) -> ToolSolid {
        ToolSolid::fff_head(
            self.head_angle,
            self.head_height,
            self.carriage_radius,
            self.carriage_clearance,
        )
    }
}

/// What the curved stages read: their own `[curved]` settings and the planar settings they
/// print beside (built by the config, `Config::curved_params`).
#[derive(Debug, Clone, PartialEq)]
pub struct CurvedParams {
    /// The `[curved]` settings.
    pub curved: CurvedSettings,
    /// The regions stage's parameters (layer height, widths, top solid layers, ...).
    pub region: RegionParams,
    /// Height of the first layer, mm.
    pub first_layer_height: f64,
    /// The toolpaths stage's parameters (speeds per role and tool).
    pub program: ProgramParams,
    /// The bed's front-left corner [X, Y], mm.
    pub bed_origin: [f64; 2],
    /// Travels shorter than this do not retract, mm.
    pub retract_before_travel: f64,
    /// How many tools the machine has.
    pub tool_count: usize,
}
