//! The jet stage's settings, the `[jet]` section of the configuration: aerosol-jet toolpaths
//! for free-standing micro-walls (corner rule table, shutter gap, layer blocks, shutter
//! snippets, fill, model).
//!
//! Place in the pipeline: read with the rest of the config (`crate::config::Config::jet`);
//! the jet walk hands it to every step of [`crate::jet`].
//!
//! Lengths are millimetres like every other section (the `conduit jet` command line takes
//! micrometres and converts), angles degrees, speeds mm/s, times seconds.

use serde::{Deserialize, Serialize};

/// How closed outlines of a design are printed.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum JetFill {
    /// Every outline is a wall: one line along it.
    #[default]
    Wall,
    /// Closed outlines are filled with contour-parallel loops (the outline, then inward
    /// offsets `fill_spacing × width` apart).
    Contour,
    /// Closed outlines are filled with a serpentine (back-and-forth lines
    /// `fill_spacing × width` apart, joined at their ends).
    Serpentine,
}

/// Aerosol-jet settings (`[jet]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct JetSettings {
    /// Tool that jets: a `kind = "paste"` tool (unheated, switched by the shutter snippets
    /// below; its own paste snippets are not used). Default 1.
    pub tool: usize,
    /// Minimum fillet radius per corner angle θ (the angle between the two segments, 180° =
    /// straight): `[min_angle_deg, radius / line width]` rows; a corner takes the first row
    /// whose `min_angle_deg ≤ θ` after sorting by angle, descending. Default
    /// `[[90, 0], [45, 0.5], [15, 1]]`: θ ≥ 90° no fillet, 45°–90° r ≥ w/2, 15°–45° r ≥ w.
    pub corner_rules: Vec<[f64; 2]>,
    /// Corners sharper than this (degrees) are not filleted but split: the shutter closes and
    /// the next segment starts fresh. Default 15.
    pub split_below: f64,
    /// Write fillets as `G2`/`G3` arcs (Marlin with `ARC_SUPPORT`, RepRapFirmware, Klipper
    /// with `[gcode_arcs]`); false flattens them into `G1` chords. Default true.
    pub arcs: bool,
    /// Largest distance between a flattened fillet and its chords, mm. Default 0.0005.
    pub arc_tolerance: f64,
    /// Gap left between the end and the start of a closed contour, mm: the shutter opens and
    /// closes there. Default 0.01.
    pub gap: f64,
    /// Number of places the gap of a closed contour cycles through, one per layer, on straight
    /// segments away from corners. Default 16.
    pub gap_positions: usize,
    /// The print direction reverses after every block of this many layers. Default 16.
    pub block_layers: usize,
    /// How closed outlines are printed: `"wall"`, `"contour"` or `"serpentine"`. Default
    /// `"wall"`.
    pub fill: JetFill,
    /// Distance between fill lines as a multiple of the line width. Default 1.
    pub fill_spacing: f64,
    /// Direction of serpentine lines, degrees from +X. Default 0.
    pub fill_angle: f64,
    /// Feed while jetting, mm/s. Default 2.
    pub speed: f64,
    /// Feed of travels (shutter closed), mm/s. Default 10.
    pub travel_speed: f64,
    /// G-code that opens the shutter. Default `M42 P5 S255 ; shutter open`.
    pub shutter_open_gcode: String,
    /// G-code that closes the shutter. Default `M42 P5 S0 ; shutter close`.
    pub shutter_close_gcode: String,
    /// Shutter-on-the-fly lead time, s: the open and close commands are written this long
    /// (at the jetting speed) before the nozzle reaches a path's start and end, while it keeps
    /// moving; 0 = open and close standing at the ends. Default 0.
    pub shutter_lead_time: f64,
    /// Written once before the job (after `G21`, `G90`, `M83`). Default `G28 ; home`.
    pub start_gcode: String,
    /// Written once after the job (after the shutter closes). Default `M84 ; motors off`.
    pub end_gcode: String,
    /// Write `E` words (the jetted length: each jetted move's `E` is its length, mm,
    /// relative) so replays such as `conduit check` and `conduit preview` see the jetted lines;
    /// false writes moves without `E`. Default true.
    pub e_words: bool,
    /// Factor on the accumulation model's prediction: the bare mass-conservation model
    /// over-predicts the inside/outside height difference by about an order of magnitude
    /// (material levels out before it dries). Default 0.1.
    pub leveling_factor: f64,
    /// Length of the region of interest around each corner for the model in the report, mm
    /// (measured along the centreline, through the corner). Default 0.15.
    pub model_roi: f64,
}

impl Default for JetSettings {
    fn default() -> Self {
        Self {
            tool: 1,
            corner_rules: vec![[90.0, 0.0], [45.0, 0.5], [15.0, 1.0]],
            split_below: 15.0,
            arcs: true,
            arc_tolerance: 0.0005,
            gap: 0.01,
            gap_positions: 16,
            block_layers: 16,
            fill: JetFill::Wall,
            fill_spacing: 1.0,
            fill_angle: 0.0,
            speed: 2.0,
            travel_speed: 10.0,
            shutter_open_gcode: "M42 P5 S255 ; shutter open".to_owned(),
            shutter_close_gcode: "M42 P5 S0 ; shutter close".to_owned(),
            shutter_lead_time: 0.0,
            start_gcode: "G28 ; home".to_owned(),
            end_gcode: "M84 ; motors off".to_owned(),
            e_words: true,
            leveling_factor: 0.1,
            model_roi: 0.15,
        }
    }
}

impl JetSettings {
    /// Every value out of range, as `jet.key ...` messages.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        let ranges = [
            ("split_below", self.split_below, 0.0, 180.0),
            ("arc_tolerance", self.arc_tolerance, 1e-6, 1.0),
            ("gap", self.gap, 0.0, 100.0),
            ("fill_spacing", self.fill_spacing, 0.1, 100.0),
            ("fill_angle", self.fill_angle, -360.0, 360.0),
            ("speed", self.speed, 1e-3, 10_000.0),
            ("travel_speed", self.travel_speed, 1e-3, 10_000.0),
            ("shutter_lead_time", self.shutter_lead_time, 0.0, 60.0),
            ("leveling_factor", self.leveling_factor, 0.0, 10.0),
            ("model_roi", self.model_roi, 1e-6, 1000.0),
        ];
        for (key, v, lo, hi) in ranges {
            if !(v.is_finite() && v >= lo && v <= hi) {
                out.push(format!("jet.{key} must be in {lo}..={hi}, got {v}"));
            }
        }
        if self.gap_positions == 0 {
            out.push("jet.gap_positions must be at least 1".to_owned());
        }
        if self.block_layers == 0 {
            out.push("jet.block_layers must be at least 1".to_owned());
        }
        for (i, [angle, factor]) in self.corner_rules.iter().enumerate() {
            if !(angle.is_finite() && (0.0..=180.0).contains(angle)) {
                out.push(format!(
                    "jet.corner_rules[{i}]: angle must be in 0..=180 degrees, got {angle}"
                ));
            }
            if !(factor.is_finite() && (0.0..=100.0).contains(factor)) {
                out.push(format!(
                    "jet.corner_rules[{i}]: radius factor must be in 0..=100, got {factor}"
                ));
            }
        }
        out
    }
}
