//! What the curved-tops stage did, for the `curved` section of the `--report` JSON and the
//! warnings on stderr.
//!
//! Place in the pipeline: filled by [`super::plan_tops`], carried in the pipeline's summary.

use serde::Serialize;

/// The `curved` section of the report.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct CurvedReport {
    /// Regions printed curved.
    pub regions: Vec<RegionReport>,
    /// Top surfaces kept planar, each with its reason.
    pub rejections: Vec<Rejection>,
    /// Moves slowed for `curved.max_z_speed`, all regions.
    pub z_speed_limited: usize,
}

/// One region printed curved.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegionReport {
    /// Object index.
    pub object: usize,
    /// Area of the gently sloped top surface, mm².
    pub area_mm2: f64,
    /// Area printed curved (the topmost curved layer's, after trimming the rim where the head
    /// would hit), mm².
    pub curved_area_mm2: f64,
    /// How far each deeper curved layer steps in from the one above, mm (`None`: the head's
    /// cone is too flat for the slope and only the topmost layer is curved).
    pub rim_step_mm: Option<f64>,
    /// Rounds of trimming the rim where the head hit (0: none needed).
    pub trim_rounds: usize,
    /// Flattest slope, degrees.
    pub min_slope_deg: f64,
    /// Steepest slope, degrees.
    pub max_slope_deg: f64,
    /// The planar layer (index) after which the curved layers are printed.
    pub after_layer: usize,
    /// Per curved layer, topmost first.
    pub layers: Vec<CurvedLayerReport>,
    /// Points dropped where the layer would be too thin or the surface is missing.
    pub points_dropped: usize,
    /// Moves slowed for `curved.max_z_speed`.
    pub z_speed_limited: usize,
}

/// One curved layer of a region.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurvedLayerReport {
    /// 0 for the topmost.
    pub k: usize,
    /// Depth below the surface, mm.
    pub depth: f64,
    /// Area of the layer, mm² (deeper layers step in from the region's rim).
    pub area_mm2: f64,
    /// Points written.
    pub points: usize,
    /// Largest distance of a point or segment midpoint from its target (surface − depth), mm.
    pub max_deviation: f64,
    /// Cusp height of the planar print at the same layer height, `h·cos α` for the region's
    /// steepest slope α, mm.
    pub planar_cusp: f64,
    /// Thinnest and thickest local layer, mm.
    pub thickness: Option<(f64, f64)>,
}

/// A top surface kept planar.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Rejection {
    /// Object index.
    pub object: usize,
    /// `"too_steep"`, `"head_collision"`, `"too_small"`, `"no_top_layers"` or
    /// `"below_first_layer"`.
    pub kind: &'static str,
    /// What is wrong, in words.
    pub reason: String,
    /// Where, mm (the steepest point, or the nozzle position of the collision).
    pub position: [f64; 3],
    /// The setting that would allow it.
    pub setting: String,
}

impl std::fmt::Display for Rejection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [x, y, z] = self.position;
        write!(
            f,
            "curved top of object {} at ({x:.2}, {y:.2}, {z:.2}) kept planar: {}; allowed with {}",
            self.object, self.reason, self.setting
        )
    }
}
