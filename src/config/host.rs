//! The host slicer's settings for the print being post-processed, so the user configures
//! nothing twice, and the post-processing stages' parameters built from a config.
//!
//! Place in the pipeline: the configuration of post-processing (plugin mode). After the host is
//! detected ([`crate::postprocess::detect_host`]), its settings are collected
//! ([`HostSettings::collect`]) and turned into the run's [`Config`]
//! ([`HostSettings::to_config`]); the walk (`crate::pipeline::postprocess`) builds the stages'
//! parameters from that config (or the user's `-c` file): the layer reconstruction's
//! ([`Config::host_layer_params`]: firmware flavour, filament diameters) and everything an edit
//! and its check need ([`Config::postprocess_params`]).
//!
//! # Sources, later ones winning
//!
//! 1. The file's own settings: PrusaSlicer's `; prusaslicer_config = begin` ... `= end` block
//!    (`; key = value` lines), Slic3r's footer and OrcaSlicer / BambuStudio's
//!    `; CONFIG_BLOCK_START` block (all read by [`crate::config::prusa_ini::pairs_from_gcode`]);
//!    Cura's `;Layer height:` header line and its `;SETTING_3` footer (the profile as JSON
//!    holding `key = value` text), with the Cura keys that have a PrusaSlicer equivalent
//!    renamed ([`CURA_KEYS`]).
//! 2. The environment of the call: PrusaSlicer, SuperSlicer and OrcaSlicer run a post-processing
//!    script with every setting as a `SLIC3R_<KEY>` variable (`SLIC3R_LAYER_HEIGHT=0.2`), plus
//!    `SLIC3R_PP_HOST` (`File`, `PrusaLink`...) and `SLIC3R_PP_OUTPUT_NAME` (the name the
//!    G-code will get). The environment is a parameter ([`HostSettings::collect`]), never read
//!    here.
//!
//! Keys are PrusaSlicer's. OrcaSlicer's names for the same settings (`wall_loops`,
//! `line_width`, `initial_layer_print_height`...) are copied to the PrusaSlicer name when that
//! name is not set ([`ORCA_KEYS`]), so one mapping ([`crate::config::prusa_ini`]) serves all.

use std::collections::BTreeMap;

use conduit_gcode::Gcode;
use serde::Serialize;

use super::prusa_ini::{from_prusa_pairs, pairs_from_gcode, unescape};
use super::{Config, ConfigError};
use crate::postprocess::{Host, LayerParams, PostprocessParams};

/// Where a setting's value came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum SettingSource {
    /// A `SLIC3R_<KEY>` environment variable of the post-processing call.
    Environment,
    /// The settings the host wrote into the G-code file.
    Gcode,
}

/// One setting's value as the host wrote it (`0.2`, `20%`, `0.4,0.4`) and its source.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Setting {
    /// The value as written.
    pub value: String,
    /// Where it came from.
    pub source: SettingSource,
}

/// OrcaSlicer / BambuStudio keys and the PrusaSlicer keys of the same settings.
pub const ORCA_KEYS: &[(&str, &str)] = &[
    ("wall_loops", "perimeters"),
    ("line_width", "extrusion_width"),
    (
        "outer_wall_line_width",
        "external_perimeter_extrusion_width",
    ),
    ("inner_wall_line_width", "perimeter_extrusion_width"),
    ("sparse_infill_line_width", "infill_extrusion_width"),
    (
        "internal_solid_infill_line_width",
        "solid_infill_extrusion_width",
    ),
    ("top_surface_line_width", "top_infill_extrusion_width"),
    ("initial_layer_line_width", "first_layer_extrusion_width"),
    ("initial_layer_print_height", "first_layer_height"),
    ("nozzle_temperature", "temperature"),
    (
        "nozzle_temperature_initial_layer",
        "first_layer_temperature",
    ),
    ("sparse_infill_density", "fill_density"),
    ("top_shell_layers", "top_solid_layers"),
    ("bottom_shell_layers", "bottom_solid_layers"),
    ("retraction_length", "retract_length"),
    ("machine_pause_gcode", "pause_print_gcode"),
];

/// Gives each OrcaSlicer key of `values` ([`ORCA_KEYS`]) its PrusaSlicer name when that name
/// is not set; with `rename` the OrcaSlicer key goes, so that it is not reported as ignored.
pub(crate) fn add_prusa_names<V: Clone>(values: &mut BTreeMap<String, V>, rename: bool) {
    for (orca, prusa) in ORCA_KEYS {
        if values.contains_key(*prusa) {
            continue;
        }
        let value = if rename {
            values.remove(*orca)
        } else {
            values.get(*orca).cloned()
        };
        if let Some(value) = value {
            values.insert((*prusa).to_owned(), value);
        }
    }
}

/// Cura keys and the PrusaSlicer keys of the same settings. `infill_sparse_density` (a
/// percentage number in Cura) is written with a `%`.
pub const CURA_KEYS: &[(&str, &str)] = &[
    ("layer_height", "layer_height"),
    ("layer_height_0", "first_layer_height"),
    ("line_width", "extrusion_width"),
    ("wall_line_width_0", "external_perimeter_extrusion_width"),
    ("wall_line_width_x", "perimeter_extrusion_width"),
    ("infill_line_width", "infill_extrusion_width"),
    ("skin_line_width", "solid_infill_extrusion_width"),
    ("wall_line_count", "perimeters"),
    ("infill_sparse_density", "fill_density"),
    ("machine_nozzle_size", "nozzle_diameter"),
    ("material_diameter", "filament_diameter"),
    ("material_print_temperature", "temperature"),
    (
        "material_print_temperature_layer_0",
        "first_layer_temperature",
    ),
    ("material_bed_temperature", "bed_temperature"),
    ("retraction_amount", "retract_length"),
    ("top_layers", "top_solid_layers"),
    ("bottom_layers", "bottom_solid_layers"),
];

/// The host's settings, keyed by PrusaSlicer key (see the [module docs](self)).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct HostSettings {
    values: BTreeMap<String, Setting>,
}

impl HostSettings {
    /// Collects the settings of `gcode` written by `host` and of the post-processing call's
    /// environment `env` (pass `std::env::vars_os()` converted to strings; variables not
    /// starting with `SLIC3R_` are skipped).
    ///
    /// ```
    /// use conduit::config::{HostSettings, SettingSource};
    /// use conduit::postprocess::Host;
    /// let g = conduit_gcode::parse(b"G1 X1\n; layer_height = 0.3\n; perimeters = 3\n")?;
    /// let env = [("SLIC3R_LAYER_HEIGHT".to_owned(), "0.2".to_owned()),
    ///            ("HOME".to_owned(), "/root".to_owned())];
    /// let s = HostSettings::collect(&g, Host::PrusaSlicer, env);
    /// assert_eq!(s.layer_height(), Some(0.2));
    /// assert_eq!(s.get("layer_height").map(|v| v.source), Some(SettingSource::Environment));
    /// assert_eq!(s.perimeters(), Some(3));
    /// # Ok::<(), conduit_gcode::GcodeError>(())
    /// ```
    pub fn collect(
        gcode: &Gcode,
        host: Host,
        env: impl IntoIterator<Item = (String, String)>,
    ) -> Self {
        let mut settings = Self::default();
        let from_file = |key: String, value: String| {
            (
                key,
                Setting {
                    value,
                    source: SettingSource::Gcode,
                },
            )
        };
        if host == Host::Cura {
            settings
                .values
                .extend(cura_pairs(gcode).into_iter().map(|(k, v)| from_file(k, v)));
        } else {
            settings.values.extend(
                pairs_from_gcode(gcode)
                    .into_iter()
                    .map(|(k, v)| from_file(k, v)),
            );
        }
        for (key, value) in env {
            if let Some(name) = key.strip_prefix("SLIC3R_") {
                settings.values.insert(
                    name.to_ascii_lowercase(),
                    Setting {
                        value,
                        source: SettingSource::Environment,
                    },
                );
            }
        }
        add_prusa_names(&mut settings.values, false);
        settings
    }

    /// The setting named `key` (a PrusaSlicer key, lower case), if the host gave it.
    pub fn get(&self, key: &str) -> Option<&Setting> {
        self.values.get(key)
    }

    /// Every setting, sorted by key.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &Setting)> {
        self.values.iter().map(|(k, v)| (k.as_str(), v))
    }

    /// Number of settings.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// True when the host gave no settings at all.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Number of settings from `source`.
    pub fn count_from(&self, source: SettingSource) -> usize {
        self.values.values().filter(|s| s.source == source).count()
    }

    /// The first number of the comma-separated value of `key` (per-extruder lists give the first
    /// extruder's); `None` when absent or not a number.
    pub fn number(&self, key: &str) -> Option<f64> {
        let first = self.get(key)?.value.split(',').next()?.trim();
        first.parse::<f64>().ok().filter(|v| v.is_finite())
    }

    /// The numbers of a comma-separated per-extruder value such as `nozzle_diameter = 0.4,0.6`;
    /// empty when absent or when an item is not a number.
    pub fn numbers(&self, key: &str) -> Vec<f64> {
        let Some(setting) = self.get(key) else {
            return Vec::new();
        };
        let parsed: Option<Vec<f64>> = setting
            .value
            .split(',')
            .map(|v| v.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect();
        parsed.unwrap_or_default()
    }

    /// A length that may be given as a percentage of `base` (`150%`), in mm; `None` when
    /// absent, unreadable or 0 (PrusaSlicer's "automatic").
    fn length_or_percent(&self, key: &str, base: Option<f64>) -> Option<f64> {
        let first = self.get(key)?.value.split(',').next()?.trim().to_owned();
        let mm = match first.strip_suffix('%') {
            Some(p) => p.trim().parse::<f64>().ok()? / 100.0 * base?,
            None => first.parse::<f64>().ok()?,
        };
        (mm.is_finite() && mm > 0.0).then_some(mm)
    }

    /// Layer height, mm (`layer_height`).
    pub fn layer_height(&self) -> Option<f64> {
        self.number("layer_height").filter(|h| *h > 0.0)
    }

    /// First layer height, mm (`first_layer_height`, mm or % of the layer height).
    pub fn first_layer_height(&self) -> Option<f64> {
        self.length_or_percent("first_layer_height", self.layer_height())
    }

    /// The first extruder's nozzle diameter, mm (`nozzle_diameter`).
    pub fn nozzle_diameter(&self) -> Option<f64> {
        self.number("nozzle_diameter").filter(|d| *d > 0.0)
    }

    /// The default extrusion width, mm (`extrusion_width`, mm or % of the nozzle diameter);
    /// `None` when absent or automatic (0).
    pub fn extrusion_width(&self) -> Option<f64> {
        self.length_or_percent("extrusion_width", self.nozzle_diameter())
    }

    /// Number of perimeters (`perimeters`).
    pub fn perimeters(&self) -> Option<u32> {
        self.number("perimeters")
            .filter(|n| *n >= 0.0 && n.fract() == 0.0 && *n <= f64::from(u32::MAX))
            .map(|n| n as u32)
    }

    /// Filament diameter per extruder, mm (`filament_diameter`).
    pub fn filament_diameters(&self) -> Vec<f64> {
        self.numbers("filament_diameter")
    }

    /// Print temperature per extruder, °C (`temperature`).
    pub fn temperatures(&self) -> Vec<f64> {
        self.numbers("temperature")
    }

    /// The name the host will give the G-code (`SLIC3R_PP_OUTPUT_NAME`), as opposed to the
    /// temporary file it passes to the script.
    pub fn output_name(&self) -> Option<&str> {
        self.get("pp_output_name").map(|s| s.value.as_str())
    }

    /// A conduit [`Config`] from these settings, through the PrusaSlicer mapping
    /// ([`crate::config::prusa_ini`]); the `pp_` values of the call are not settings and are
    /// left out. Returns the config and the mapping's warnings (settings ignored or adapted).
    ///
    /// # Errors
    /// [`ConfigError::Ini`] naming the key when a value cannot be read.
    pub fn to_config(&self) -> Result<(Config, Vec<String>), ConfigError> {
        from_prusa_pairs(
            self.values
                .iter()
                .filter(|(k, _)| !k.starts_with("pp_"))
                .filter(|(k, _)| !ORCA_KEYS.iter().any(|(orca, _)| orca == k))
                .map(|(k, v)| (k.clone(), v.value.clone())),
        )
    }
}

impl Config {
    /// The layer reconstruction's parameters: the firmware flavour, the tools' filament
    /// diameters and the perimeter width. Give them the host's bead model with
    /// [`LayerParams::for_host`].
    pub fn host_layer_params(&self) -> LayerParams {
        LayerParams::new(self.printer.flavor, &self.tools, self.slice.perimeter_width)
    }

    /// Everything post-processing needs of this config: the layer reconstruction's parameters
    /// ([`Config::host_layer_params`]), the electronics stage's ([`Config::electronics_params`]),
    /// the G-code writer's for the inserted blocks ([`Config::gcode_params`]) and the checker's
    /// for verifying an edited file.
    pub fn postprocess_params(&self) -> PostprocessParams {
        PostprocessParams {
            layers: self.host_layer_params(),
            electronics: self.electronics_params(),
            gcode: self.gcode_params(),
            check: self.check_params(),
        }
    }
}

/// Cura's settings: `;Layer height: <h>` in the header and the `;SETTING_3` lines at the end (a
/// JSON object of profile texts with `[values]` sections of `key = value` lines), renamed by
/// [`CURA_KEYS`]. Formulas (values starting with `=`) are skipped.
fn cura_pairs(gcode: &Gcode) -> Vec<(String, String)> {
    let mut pairs = Vec::new();
    let mut json = String::new();
    for line in &gcode.lines {
        let Some(text) = line.comment.as_ref().and_then(|_| line.comment_text()) else {
            continue;
        };
        if let Some(h) = text.strip_prefix("Layer height:") {
            pairs.push(("layer_height".to_owned(), h.trim().to_owned()));
        } else if let Some(chunk) = text.strip_prefix("SETTING_3") {
            // The payload follows one space; later chunks continue it mid-token.
            let raw = line.text.get(line.comment.clone().unwrap_or_default());
            let payload = raw
                .and_then(|r| std::str::from_utf8(r).ok())
                .and_then(|r| r.strip_prefix(";SETTING_3 "))
                .unwrap_or(chunk);
            json.push_str(payload);
        }
    }
    let Ok(serde_json::Value::Object(profiles)) = serde_json::from_str(&unescape(&json)) else {
        return pairs;
    };
    let texts = profiles.values().flat_map(|v| match v {
        serde_json::Value::String(s) => vec![s.as_str()],
        serde_json::Value::Array(items) => items.iter().filter_map(|i| i.as_str()).collect(),
        _ => Vec::new(),
    });
    for text in texts {
        let mut in_values = false;
        for row in text.lines() {
            let row = row.trim();
            if row.starts_with('[') {
                in_values = row == "[values]";
                continue;
            }
            let Some((key, value)) = row.split_once('=') else {
                continue;
            };
            let (key, value) = (key.trim(), value.trim());
            if !in_values || value.starts_with('=') || value.is_empty() {
                continue;
            }
            if let Some((_, prusa)) = CURA_KEYS.iter().find(|(cura, _)| *cura == key) {
                let value = if *prusa == "fill_density" {
                    format!("{value}%")
                } else {
                    value.to_owned()
                };
                pairs.push(((*prusa).to_owned(), value));
            }
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env(pairs: &[(&str, &str)]) -> Vec<(String, String)> {
        pairs
            .iter()
            .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
            .collect()
    }

    #[test]
    fn environment_overrides_the_file_and_orca_keys_are_renamed()
    -> Result<(), Box<dyn std::error::Error>> {
        let g = conduit_gcode::parse(
            b"; CONFIG_BLOCK_START\n; wall_loops = 3\n; layer_height = 0.28\n\
              ; nozzle_diameter = 0.4,0.6\n; line_width = 110%\n; CONFIG_BLOCK_END\n",
        )?;
        let s = HostSettings::collect(
            &g,
            Host::OrcaSlicer,
            env(&[
                ("SLIC3R_LAYER_HEIGHT", "0.2"),
                ("SLIC3R_PP_OUTPUT_NAME", "/out/part.gcode"),
                ("PATH", "/bin"),
            ]),
        );
        assert_eq!(s.layer_height(), Some(0.2));
        assert_eq!(s.perimeters(), Some(3));
        assert_eq!(s.numbers("nozzle_diameter"), vec![0.4, 0.6]);
        assert!(
            s.extrusion_width()
                .is_some_and(|w| (w - 0.44).abs() < 1e-12)
        );
        assert_eq!(s.output_name(), Some("/out/part.gcode"));
        assert_eq!(s.count_from(SettingSource::Environment), 2);
        assert!(s.get("path").is_none());
        let (cfg, _warnings) = s.to_config()?;
        assert_eq!(cfg.slice.layer_height, 0.2);
        assert_eq!(cfg.slice.perimeters, 3);
        Ok(())
    }

    #[test]
    fn cura_header_and_profile_are_read() -> Result<(), Box<dyn std::error::Error>> {
        let profile = r#"{"global_quality": "[general]\\nversion = 4\\n\\n[values]\\nlayer_height = 0.15\\nwall_line_count = 4\\ninfill_sparse_density = 25\\nspeed_wall = =speed_print / 2\\n\\n", "extruder_quality": ["[values]\\nmaterial_print_temperature = 205\\n"]}"#;
        let mut file = String::from(";FLAVOR:Marlin\n;Layer height: 0.1\nG1 X1\n");
        // Cura cuts the JSON into comment lines of 80 characters.
        for chunk in profile.as_bytes().chunks(60) {
            file.push_str(";SETTING_3 ");
            file.push_str(std::str::from_utf8(chunk)?);
            file.push('\n');
        }
        let g = conduit_gcode::parse(file.as_bytes())?;
        let s = HostSettings::collect(&g, Host::Cura, Vec::new());
        assert_eq!(s.layer_height(), Some(0.15));
        assert_eq!(s.perimeters(), Some(4));
        assert_eq!(s.get("fill_density").map(|v| v.value.as_str()), Some("25%"));
        assert_eq!(s.temperatures(), vec![205.0]);
        assert!(s.get("speed_wall").is_none());
        let (cfg, _) = s.to_config()?;
        assert!((cfg.slice.infill_density - 0.25).abs() < 1e-12);
        Ok(())
    }
}
