//! What post-processing found and did: the JSON of `conduit postprocess --report` and the
//! one-line summary on stderr.
//!
//! Place in the pipeline: the last step; it reads the host's layers and what the edit did, and
//! changes neither. Output is deterministic: the same file and settings give the same report,
//! byte for byte.

use std::fmt;

use serde::Serialize;

use super::layers::{EMode, HostLayer, HostLayers, LayerMethod, RetractionStyle, ZSource};
use super::rewrite::RewriteStats;
use super::{Host, HostInfo};
use crate::circuit::ElectronicsReport;

/// How many of the host's settings came from where.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SettingCounts {
    /// Settings read from the environment of the call (`SLIC3R_<KEY>`).
    pub environment: usize,
    /// Settings read from the file.
    pub gcode: usize,
}

/// The report of one post-processing run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PostprocessReport {
    /// The slicer that wrote the file.
    pub host: Host,
    /// The generator as the header names it.
    pub generator: Option<String>,
    /// How layers were found: `comments` or `z heights`.
    pub layer_method: String,
    /// The layer comments used (`;LAYER_CHANGE`, `;LAYER:<n>`...).
    pub layer_markers: Vec<String>,
    /// Layers found.
    pub layer_count: usize,
    /// The count the host announces, when it does.
    pub declared_layer_count: Option<usize>,
    /// Lines before the first layer.
    pub preamble_lines: usize,
    /// Tools that extrude, sorted.
    pub tools: Vec<usize>,
    /// E modes of the layers: `absolute`, `relative` or both.
    pub e_modes: Vec<EMode>,
    /// The first retraction.
    pub retraction: Option<RetractionStyle>,
    /// Extruding moves at an unknown position.
    pub unplaced_extrusions: usize,
    /// Settings read from the environment of the call.
    pub settings_from_environment: usize,
    /// Settings read from the file.
    pub settings_from_gcode: usize,
    /// Whether the file was changed.
    pub changed: bool,
    /// Per layer.
    pub layers: Vec<LayerReport>,
    /// With a circuit: what was cut and inserted.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub edit: Option<RewriteStats>,
    /// With a circuit: its parts, wires (routed or not, lengths, layer changes) and warnings,
    /// as `conduit slice --report` gives them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub electronics: Option<ElectronicsReport>,
}

/// One layer in a [`PostprocessReport`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayerReport {
    /// 0-based layer index.
    pub index: usize,
    /// The host's own layer number.
    pub host_number: Option<i64>,
    /// Print z, mm.
    pub z: f64,
    /// Where z came from.
    pub z_source: ZSource,
    /// Layer height, mm.
    pub height: f64,
    /// First line (1-based, as editors count).
    pub first_line: usize,
    /// Last line (1-based).
    pub last_line: usize,
    /// Extrusion paths.
    pub paths: usize,
    /// Extruding moves.
    pub extruding_moves: usize,
    /// Extruded length, mm.
    pub length: f64,
    /// Filament pushed, mm of E.
    pub filament: f64,
    /// E mode.
    pub e_mode: EMode,
    /// Tools that extrude, in order of first use.
    pub tools: Vec<usize>,
    /// Width per feature.
    pub widths: Vec<FeatureWidth>,
}

/// The width of one feature in a [`LayerReport`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeatureWidth {
    /// The host's feature name, when it names one.
    pub feature: Option<String>,
    /// conduit's role for it (its `;TYPE:` name), when it has one.
    pub role: Option<&'static str>,
    /// Length-weighted mean width, mm.
    pub width: f64,
    /// Extruded length, mm.
    pub length: f64,
}

/// Rounds to 1 µm (lengths and widths) for a readable, stable report.
fn micrometres(mm: f64) -> f64 {
    (mm * 1000.0).round() / 1000.0
}

impl LayerReport {
    fn new(layer: &HostLayer) -> Self {
        let length: f64 = layer.paths.iter().map(|p| p.length()).sum();
        let filament: f64 = layer.paths.iter().map(|p| p.e()).sum();
        Self {
            index: layer.index,
            host_number: layer.host_number,
            z: layer.z,
            z_source: layer.z_source,
            height: layer.height,
            first_line: layer.lines.start + 1,
            last_line: layer.lines.end.max(layer.lines.start + 1),
            paths: layer.paths.len(),
            extruding_moves: layer.paths.iter().map(|p| p.moves.len()).sum(),
            length: micrometres(length),
            filament: (filament * 1e5).round() / 1e5,
            e_mode: layer.e_mode,
            tools: layer.tools.clone(),
            widths: layer
                .widths
                .iter()
                .map(|w| FeatureWidth {
                    feature: w.host_role.clone(),
                    role: w.role.map(|r| r.type_name()),
                    width: micrometres(w.width),
                    length: micrometres(w.length),
                })
                .collect(),
        }
    }
}

impl PostprocessReport {
    /// The report of a print by `host` read as `layers`, with `settings` of the host;
    /// `changed` says whether the file was rewritten.
    pub fn new(
        host: &HostInfo,
        layers: &HostLayers,
        settings: SettingCounts,
        changed: bool,
    ) -> Self {
        let (layer_method, layer_markers) = match &layers.method {
            LayerMethod::Comments(markers) => (
                "comments".to_owned(),
                markers.iter().map(|m| m.pattern().to_owned()).collect(),
            ),
            LayerMethod::ZHeights => ("z heights".to_owned(), Vec::new()),
        };
        Self {
            host: host.host,
            generator: host.generator.clone(),
            layer_method,
            layer_markers,
            layer_count: layers.layers.len(),
            declared_layer_count: layers.declared_layer_count,
            preamble_lines: layers.preamble.len(),
            tools: layers.tools(),
            e_modes: layers.e_modes(),
            retraction: layers.retraction(),
            unplaced_extrusions: layers.unplaced_extrusions,
            settings_from_environment: settings.environment,
            settings_from_gcode: settings.gcode,
            changed,
            layers: layers.layers.iter().map(LayerReport::new).collect(),
            edit: None,
            electronics: None,
        }
    }

    /// This report with what building a circuit in changed (`stats`) and the electronics
    /// stage's report of it.
    pub fn with_circuit(mut self, stats: &RewriteStats, electronics: &ElectronicsReport) -> Self {
        self.edit = Some(stats.clone());
        self.electronics = Some(electronics.clone());
        self
    }
}

impl fmt::Display for PostprocessReport {
    /// One line: host, layers, z range, tools, E mode, retraction, settings.
    ///
    /// `PrusaSlicer 2.5.0+linux-x64, 100 layers (;LAYER_CHANGE), z 0.2–20 mm, tools T0,
    /// absolute E, retraction 2 mm, 264 settings`
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.generator {
            Some(g) => write!(f, "{g}")?,
            None => write!(f, "{}", self.host.name())?,
        }
        write!(f, ", {} layers", self.layer_count)?;
        if self.layer_markers.is_empty() {
            write!(f, " (from z heights)")?;
        } else {
            write!(f, " ({})", self.layer_markers.join(" "))?;
        }
        if let (Some(first), Some(last)) = (self.layers.first(), self.layers.last()) {
            write!(
                f,
                ", z {}–{} mm",
                conduit_gcode::fmt_xyz(first.z),
                conduit_gcode::fmt_xyz(last.z)
            )?;
        }
        if self.tools.is_empty() {
            write!(f, ", no extrusion")?;
        } else {
            let tools: Vec<String> = self.tools.iter().map(|t| format!("T{t}")).collect();
            write!(f, ", tools {}", tools.join(" "))?;
        }
        let modes: Vec<&str> = self
            .e_modes
            .iter()
            .map(|m| match m {
                EMode::Absolute => "absolute",
                EMode::Relative => "relative",
            })
            .collect();
        if !modes.is_empty() {
            write!(f, ", {} E", modes.join("+"))?;
        }
        match self.retraction {
            Some(RetractionStyle::Firmware) => write!(f, ", firmware retraction")?,
            Some(RetractionStyle::Extruder { length, .. }) => {
                write!(f, ", retraction {} mm", conduit_gcode::fmt_xyz(length))?;
            }
            None => {}
        }
        let settings = self.settings_from_environment + self.settings_from_gcode;
        write!(f, ", {settings} settings")?;
        if self.settings_from_environment > 0 {
            write!(
                f,
                " ({} from the environment)",
                self.settings_from_environment
            )?;
        }
        if self.unplaced_extrusions > 0 {
            write!(
                f,
                ", {} extrusions at unknown positions",
                self.unplaced_extrusions
            )?;
        }
        Ok(())
    }
}
