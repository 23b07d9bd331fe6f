//! Import of PrusaSlicer (and Slic3r) settings: a `.ini` profile export, or the `key = value`
//! pairs of the `SLIC3R_<KEY>` environment a post-processing script is called with.
//!
//! Place in the pipeline: an alternative front door to [`Config`]. The CLI loads a `.ini` with
//! [`super::load`]; the post-processing mode builds the config of the host slicer's print with
//! [`from_slic3r_env`]. Both end in [`from_prusa_pairs`].
//!
//! # Mapping
//!
//! Keys start from [`Config::default`] and overwrite what PrusaSlicer states. A `.ini` is read
//! as PrusaSlicer reads it: the keys it leaves out take PrusaSlicer's defaults
//! ([`super::prusa_defaults`]) before the mapping, and what conduit prints otherwise than such a
//! default is said in one warning; the other inputs (a host slicer's environment, a G-code's or
//! a 3MF's settings) state every key of the slicer that wrote them.
//!
//! - printer: `bed_shape` (polygon; its bounding box gives `bed_size` and `bed_origin`),
//!   `max_print_height`, `gcode_flavor` (`marlin`, `marlin2`, `reprapfirmware`, `klipper`;
//!   others become marlin with a warning), `start_gcode`, `end_gcode`, `before_layer_gcode`,
//!   `layer_gcode`, `color_change_gcode`, `pause_print_gcode`, `template_custom_gcode`
//!   (`\n` escapes undone),
//!   `bed_temperature`, `first_layer_bed_temperature`, `retract_length`, `retract_speed`,
//!   `deretract_speed`, `retract_before_travel`, `retract_lift`, `travel_speed`,
//!   `machine_max_acceleration_extruding` (or `default_acceleration`),
//!   `use_relative_e_distances`, `use_firmware_retraction`,
//!   `only_retract_when_crossing_perimeters` (when the file states it; conduit's default, on,
//!   stays otherwise), `min_fan_speed`, `max_fan_speed`,
//!   `disable_fan_first_layers`, `slowdown_below_layer_time`, `fan_below_layer_time`,
//!   `min_print_speed`;
//! - tools: the comma-separated lists give one value per extruder: `nozzle_diameter`,
//!   `filament_diameter`, `filament_density` (0, PrusaSlicer's "unknown", keeps the default),
//!   `filament_type` (the tool's name), `temperature`,
//!   `first_layer_temperature`, `idle_temperature`, `extrusion_multiplier`, `extruder_offset`,
//!   per-extruder `retract_length` (the first is the printer's, others that differ become tool
//!   overrides), `start_filament_gcode` / `end_filament_gcode` (→ the tools' `start_gcode` /
//!   `end_gcode`; one value serves every extruder). PrusaSlicer's extruders become filament tools `0..n`; conduit's default paste
//!   tool ([`super::Tool::paste`]) is appended as tool `n` so that a plastic-only profile can
//!   still drive the conductive tool.
//! - slice: `layer_height`, `first_layer_height` (mm, or % of `layer_height`), `perimeters`,
//!   `top_solid_layers`, `bottom_solid_layers`, `fill_density` (`20%` → 0.2), `fill_pattern`,
//!   `top_fill_pattern` / `bottom_fill_pattern` (Slic3r: `top_infill_pattern`, …), `fill_angle`,
//!   `infill_overlap`, `solid_infill_below_area`, `gap_fill_enabled`, `external_perimeters_first`, `support_material`, `skirts`,
//!   `skirt_distance`, `brim_width`, `bridge_speed`, `gap_fill_speed`, `perimeter_generator` (`classic`, or `arachne`, also when
//!   missing, for the variable generator) with `thin_walls` (classic only: Arachne prints thin
//!   features anyway), `seam_position`, OrcaSlicer's `seam_gap` (mm or `%` of the nozzle;
//!   PrusaSlicer's loop clipping, 15 %, when missing), the speeds (a `%` speed is relative to its
//!   PrusaSlicer parent: external perimeter → perimeter, solid infill → infill, top solid →
//!   solid infill, first layer → perimeter, support → perimeter), `support_material_speed` (→
//!   `support_speed` and `skirt_speed`, as PrusaSlicer prints skirts at support speed),
//!   `support_material_interface_speed` (`%` of the support speed), `brim_separation`,
//!   `brim_type` (`no_brim` clears `brim_width`; OrcaSlicer's `brim_ears` → `ears`),
//!   `overhangs`, `enable_dynamic_overhang_speeds` (off when missing, as in PrusaSlicer) with
//!   `overhang_speed_0..3` (mm/s or `%` of the external perimeter speed), `bridge_fan_speed`,
//!   `enable_dynamic_fan_speeds` and `overhang_fan_speed_0..3` (the first extruder's);
//! - support (`[support]`): `support_material_threshold` (from the horizontal there, from the
//!   vertical here: `90 − t`; 0, automatic, keeps 45°), `support_material_contact_distance` →
//!   `z_gap`, `support_material_xy_spacing` (mm or `%` of the external perimeter width) →
//!   `xy_gap`, `support_material_interface_layers`, `support_material_spacing`,
//!   `support_material_interface_spacing`, `support_material_pattern` (`rectilinear`,
//!   `rectilinear-grid` → `grid`, `honeycomb` → `grid` and others → `rectilinear` with a
//!   warning),
//!   `support_material_angle`, `support_material_buildplate_only`,
//!   `support_material_with_sheath`;
//! - wipe tower (`[wipe_tower]`): `wipe_tower`, `wipe_tower_x`, `wipe_tower_y` (its front-left
//!   corner), `wipe_tower_width`, `wipe_tower_bridging` → `sparse_spacing`,
//!   `wipe_tower_brim_width`, `wipe_tower_rotation_angle` → `rotation`,
//!   `wiping_volumes_matrix` (its largest entry → `purge_volume`);
//! - widths: `extrusion_width` and `first_layer_`, `perimeter_`, `external_perimeter_`,
//!   `infill_`, `solid_infill_`, `top_infill_extrusion_width`. A value is mm or `%` of the first
//!   nozzle diameter. 0 (or a missing key) falls back to `extrusion_width`, and when that is 0 too to PrusaSlicer's
//!   automatic width (`Flow::auto_extrusion_width`): 1.125 × nozzle for perimeters and
//!   (solid) infill, 1 × nozzle for top solid infill. A first-layer width of 0 means each role's
//!   own width; conduit has one first-layer width and takes the perimeter width.
//!
//! The G-code snippets (`start_gcode`, `end_gcode`, `toolchange_gcode`) keep PrusaSlicer's
//! macros, which the G-code writer fills (`emit::gcode::macros`); one that does not parse is
//! named in a warning. Every key of the profile, read or not, is kept as written in
//! `printer.profile`, where those macros find what conduit has no field for
//! (`{filament_type[0]}`, `{z_offset}`).
//!
//! Every other key is listed, once, in a warning as ignored — among them `max_print_speed`,
//! which in PrusaSlicer only limits automatic speeds while conduit's clamps every speed. The
//! warning counts them and names first those that change what is printed (a curated list:
//! seam, ironing, supports, spiral vase…, each only when set to a value conduit does not
//! print), then after [`IGNORED_LIST_MARK`] all of them, so a front end can show the summary
//! alone.
//!
//! G-code written by PrusaSlicer or Slic3r carries its settings as `; key = value` comments;
//! [`pairs_from_gcode`] collects them for [`from_prusa_pairs`].

use std::collections::BTreeMap;
use std::collections::BTreeSet;

use super::prusa_defaults::PRUSASLICER_DEFAULTS;
use super::{Config, ConfigError, Flavor, SolidPattern, Tool};
use crate::region::{BrimType, InfillPatternKind, PerimeterGenerator, SupportPattern};
use crate::toolpaths::SeamRule;

/// Reads a PrusaSlicer `.ini` (`key = value` lines, `#` comments, `[section]` headers of a
/// config bundle are skipped). Errors carry the line number.
pub fn from_ini_str(src: &str) -> Result<(Config, Vec<String>), ConfigError> {
    let mut pairs = Vec::new();
    for (i, raw) in src.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with(';') {
            continue;
        }
        if line.starts_with('[') && line.ends_with(']') {
            continue;
        }
        let Some((key, value)) = line.split_once('=') else {
            return Err(ConfigError::Ini {
                path: None,
                line: Some(i + 1),
                key: line.to_owned(),
                value: String::new(),
                message: "expected `key = value`".to_owned(),
            });
        };
        pairs.push((key.trim().to_owned(), value.trim().to_owned(), Some(i + 1)));
    }
    let (pairs, defaulted) = with_prusaslicer_defaults(pairs);
    convert(pairs, defaulted)
}

/// The warning that lists what conduit prints otherwise than PrusaSlicer's defaults for the
/// keys a `.ini` leaves out (after their number).
pub(crate) const DEFAULTS_PRINTED_OTHERWISE: &str =
    "PrusaSlicer default(s) of keys the file leaves out are printed otherwise";

/// Keys that Slic3r and PrusaSlicer name differently: when a file states one, the other's
/// default is not added (it would override or contradict what the file states).
const TWINS: &[[&str; 2]] = &[
    ["top_fill_pattern", "top_infill_pattern"],
    ["bottom_fill_pattern", "bottom_infill_pattern"],
];

/// `pairs` with PrusaSlicer's default (see [`super::prusa_defaults`]) first for every key they
/// do not state, as PrusaSlicer reads a `.ini`; and the keys so added.
fn with_prusaslicer_defaults(pairs: LinedPairs) -> (LinedPairs, BTreeSet<String>) {
    let stated: BTreeSet<&str> = pairs.iter().map(|(k, _, _)| k.as_str()).collect();
    let twin_stated = |key: &str| {
        TWINS
            .iter()
            .filter(|t| t.contains(&key))
            .flatten()
            .any(|k| stated.contains(k))
    };
    let defaulted: BTreeSet<String> = PRUSASLICER_DEFAULTS
        .iter()
        .filter(|(k, _)| !stated.contains(k) && !twin_stated(k))
        .map(|(k, _)| (*k).to_owned())
        .collect();
    let mut all: LinedPairs = PRUSASLICER_DEFAULTS
        .iter()
        .filter(|(k, _)| defaulted.contains(*k))
        .map(|(k, v)| ((*k).to_owned(), (*v).to_owned(), None))
        .collect();
    all.extend(pairs);
    (all, defaulted)
}

/// Keys, values as written and the line of each (none for a value not from a file).
type LinedPairs = Vec<(String, String, Option<usize>)>;

/// Builds a config from PrusaSlicer `key`/`value` pairs (keys as in the `.ini`, values as
/// written there). Later pairs override earlier ones. Returns the config and the warnings.
pub fn from_prusa_pairs(
    pairs: impl IntoIterator<Item = (String, String)>,
) -> Result<(Config, Vec<String>), ConfigError> {
    convert(
        pairs.into_iter().map(|(k, v)| (k, v, None)).collect(),
        BTreeSet::new(),
    )
}

/// Builds a config from the environment of a PrusaSlicer post-processing call: variables named
/// `SLIC3R_<KEY>` (upper-case key) carry each setting. Other variables are skipped. Pass
/// `std::env::vars()`.
pub fn from_slic3r_env(
    vars: impl IntoIterator<Item = (String, String)>,
) -> Result<(Config, Vec<String>), ConfigError> {
    from_prusa_pairs(vars.into_iter().filter_map(|(k, v)| {
        k.strip_prefix("SLIC3R_")
            .map(|key| (key.to_ascii_lowercase(), v))
    }))
}

/// The settings a PrusaSlicer or Slic3r G-code file carries as comments: the lines
/// `; key = value` between `; prusaslicer_config = begin` and `= end` when present, otherwise
/// every comment-only line of that form (Slic3r's footer). Keys are lower-case words with `_`,
/// so header lines such as `; filament used [mm] = 1328.49` are not taken.
pub fn pairs_from_gcode(g: &conduit_gcode::Gcode) -> Vec<(String, String)> {
    let comment_pair = |line: &conduit_gcode::Line| -> Option<(String, String)> {
        if !line.words.is_empty() {
            return None;
        }
        let text = line.comment_text()?;
        let (key, value) = text.split_once('=')?;
        let key = key.trim();
        let is_key = !key.is_empty()
            && key
                .bytes()
                .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_');
        is_key.then(|| (key.to_owned(), value.trim().to_owned()))
    };
    let begin = g
        .lines
        .iter()
        .position(|l| l.comment_text() == Some("prusaslicer_config = begin"));
    match begin {
        Some(start) => g.lines[start + 1..]
            .iter()
            .take_while(|l| l.comment_text() != Some("prusaslicer_config = end"))
            .filter_map(comment_pair)
            .collect(),
        None => g.lines.iter().filter_map(comment_pair).collect(),
    }
}

struct Pairs {
    values: BTreeMap<String, (String, Option<usize>)>,
    used: BTreeSet<String>,
    /// The keys the input does not state, whose values are PrusaSlicer's defaults.
    defaulted: BTreeSet<String>,
}

impl Pairs {
    /// The value of `key`, marking it used; `None` when absent or empty (PrusaSlicer writes
    /// `key = ` for unset strings).
    fn raw(&mut self, key: &str) -> Option<&str> {
        let (v, _) = self.values.get(key)?;
        self.used.insert(key.to_owned());
        Some(v.as_str()).filter(|v| !v.trim().is_empty())
    }

    fn err(&self, key: &str, message: impl Into<String>) -> ConfigError {
        let (value, line) = self.values.get(key).cloned().unwrap_or_default();
        ConfigError::Ini {
            path: None,
            line,
            key: key.to_owned(),
            value,
            message: message.into(),
        }
    }

    /// A plain number (the first item of a list).
    fn num(&mut self, key: &str) -> Result<Option<f64>, ConfigError> {
        Ok(self.list(key)?.first().copied())
    }

    /// A comma-separated list of numbers.
    fn list(&mut self, key: &str) -> Result<Vec<f64>, ConfigError> {
        let Some(raw) = self.raw(key).map(str::to_owned) else {
            return Ok(Vec::new());
        };
        raw.split(',')
            .map(|s| {
                s.trim()
                    .parse::<f64>()
                    .map_err(|_| self.err(key, "expected a number (or a comma-separated list)"))
            })
            .collect()
    }

    /// A comma-separated list of strings (PrusaSlicer quotes list items that need it).
    fn strings(&mut self, key: &str) -> Vec<String> {
        self.raw(key)
            .map(|raw| {
                raw.split(';')
                    .flat_map(|s| s.split(','))
                    .map(|s| s.trim().trim_matches('"').to_owned())
                    .collect()
            })
            .unwrap_or_default()
    }

    /// A per-extruder list of G-code strings (`"M900 K0.05";"M900 K0"`, escapes undone), its
    /// first item repeated after the last as PrusaSlicer's `get_at` does; a single unquoted
    /// value is the one item. Empty when the key is missing.
    fn gcodes(&mut self, key: &str) -> impl Iterator<Item = String> + use<> {
        let items = match self.raw(key) {
            None => Vec::new(),
            Some(raw) => conduit_gcode::string_list(raw).unwrap_or_else(|| vec![unescape(raw)]),
        };
        let first = items.first().cloned();
        items
            .into_iter()
            .chain(std::iter::repeat_with(move || first.clone()).map_while(|f| f))
    }

    /// An integer count.
    fn count(&mut self, key: &str) -> Result<Option<usize>, ConfigError> {
        // A plain integer is read exactly (through f64, 2⁶³ − 1 would read as 2⁶³).
        let exact = self
            .raw(key)
            .and_then(|raw| raw.split(',').next())
            .and_then(|first| first.trim().parse::<usize>().ok());
        if exact.is_some() {
            return Ok(exact);
        }
        match self.num(key)? {
            // `as` would saturate a larger number to usize::MAX, hiding what was written.
            Some(v) if v >= 0.0 && v.fract() == 0.0 && v < usize::MAX as f64 => {
                Ok(Some(v as usize))
            }
            Some(v) if v >= 0.0 && v.fract() == 0.0 => Err(self.err(key, "too large for a count")),
            Some(_) => Err(self.err(key, "expected a whole number ≥ 0")),
            None => Ok(None),
        }
    }

    /// A boolean (`0`/`1`, `true`/`false`), the first of a list.
    fn flag(&mut self, key: &str) -> Result<Option<bool>, ConfigError> {
        let Some(raw) = self.raw(key).map(str::to_owned) else {
            return Ok(None);
        };
        match raw.split(',').next().map(str::trim) {
            Some("1" | "true") => Ok(Some(true)),
            Some("0" | "false") => Ok(Some(false)),
            _ => Err(self.err(key, "expected 0 or 1")),
        }
    }

    /// A number or a percentage of `base`.
    fn abs_or_percent(&mut self, key: &str, base: f64) -> Result<Option<f64>, ConfigError> {
        let Some(raw) = self.raw(key).map(str::to_owned) else {
            return Ok(None);
        };
        let first = raw.split(',').next().unwrap_or_default().trim();
        let parsed = match first.strip_suffix('%') {
            Some(p) => p.trim().parse::<f64>().map(|p| p / 100.0 * base),
            None => first.parse::<f64>(),
        };
        parsed
            .map(Some)
            .map_err(|_| self.err(key, "expected a number or a percentage"))
    }

    /// A G-code string, with PrusaSlicer's C-style escapes undone.
    fn gcode(&mut self, key: &str) -> Option<String> {
        let raw = self.raw(key)?;
        let raw = raw
            .strip_prefix('"')
            .and_then(|r| r.strip_suffix('"'))
            .unwrap_or(raw);
        Some(unescape(raw))
    }
}

pub(crate) use conduit_gcode::unescape_cstyle as unescape;

/// Keys read elsewhere that give no warning when present.
const ACCEPTED: &[&str] = &["printer_technology", "perimeter_generator", "thin_walls"];

/// Lists whose length tells the number of extruders.
const PER_EXTRUDER: &[&str] = &[
    "nozzle_diameter",
    "filament_diameter",
    "temperature",
    "first_layer_temperature",
    "extruder_offset",
    "extrusion_multiplier",
    "filament_density",
    "retract_length",
];

/// A field of the config that one key writes.
type Field<T> = fn(&mut Config) -> &mut T;

/// A number field of a tool that one per-extruder list writes.
type ToolField = fn(&mut Tool) -> &mut f64;

/// Per-extruder number lists, in reading order, and the tool field each fills. A list shorter
/// than the number of extruders repeats its last value.
const TOOL_NUMBERS: &[(&str, ToolField)] = &[
    ("nozzle_diameter", |t| &mut t.nozzle_diameter),
    ("filament_diameter", |t| &mut t.filament_diameter),
    ("filament_density", |t| &mut t.filament_density),
    ("temperature", |t| &mut t.temperature),
    ("first_layer_temperature", |t| {
        &mut t.first_layer_temperature
    }),
    ("extrusion_multiplier", |t| &mut t.extrusion_multiplier),
];

/// How the value of one PrusaSlicer key lands in the config.
enum Rule {
    /// A number, copied as is.
    Num(Field<f64>),
    /// A whole number ≥ 0.
    Count(Field<usize>),
    /// A flag (`0`/`1`).
    Flag(Field<bool>),
    /// A number, or a percentage of the value the first function reads from the config as
    /// filled so far (the PrusaSlicer parent setting).
    Percent(fn(&Config) -> f64, Field<f64>),
    /// A G-code snippet with its escapes undone; a warning names the key when it uses macros.
    Gcode(Field<String>),
    /// A solid-infill pattern: conduit prints rectilinear and warns about any other.
    Solid(Field<SolidPattern>),
    /// A key with its own reader (which may read further keys).
    Custom(fn(&mut Import, &str) -> Result<(), ConfigError>),
}

/// The printer and slicing keys after the tools, in reading order: the order decides which
/// error is reported first, the order of the warnings, and which values a `%` refers to.
const RULES: &[(&str, Rule)] = &[
    // Printer.
    ("bed_shape", Rule::Custom(bed_shape)),
    ("max_print_height", Rule::Num(|c| &mut c.printer.max_height)),
    ("gcode_flavor", Rule::Custom(gcode_flavor)),
    ("start_gcode", Rule::Gcode(|c| &mut c.printer.start_gcode)),
    ("end_gcode", Rule::Gcode(|c| &mut c.printer.end_gcode)),
    (
        "before_layer_gcode",
        Rule::Gcode(|c| &mut c.printer.before_layer_gcode),
    ),
    ("layer_gcode", Rule::Gcode(|c| &mut c.printer.layer_gcode)),
    (
        "color_change_gcode",
        Rule::Gcode(|c| &mut c.printer.color_change_gcode),
    ),
    (
        "pause_print_gcode",
        Rule::Gcode(|c| &mut c.printer.pause_print_gcode),
    ),
    (
        "template_custom_gcode",
        Rule::Gcode(|c| &mut c.printer.template_custom_gcode),
    ),
    ("toolchange_gcode", Rule::Custom(toolchange_gcode)),
    (
        "bed_temperature",
        Rule::Num(|c| &mut c.printer.bed_temperature),
    ),
    (
        "first_layer_bed_temperature",
        Rule::Num(|c| &mut c.printer.first_layer_bed_temperature),
    ),
    ("retract_speed", Rule::Num(|c| &mut c.printer.retract_speed)),
    (
        "deretract_speed",
        Rule::Num(|c| &mut c.printer.deretract_speed),
    ),
    (
        "retract_before_travel",
        Rule::Num(|c| &mut c.printer.retract_before_travel),
    ),
    ("retract_lift", Rule::Num(|c| &mut c.printer.retract_lift)),
    ("travel_speed", Rule::Num(|c| &mut c.printer.travel_speed)),
    ("min_fan_speed", Rule::Num(|c| &mut c.printer.fan_min_speed)),
    ("max_fan_speed", Rule::Num(|c| &mut c.printer.fan_max_speed)),
    (
        "slowdown_below_layer_time",
        Rule::Num(|c| &mut c.printer.slowdown_below_layer_time),
    ),
    (
        "fan_below_layer_time",
        Rule::Num(|c| &mut c.printer.fan_below_layer_time),
    ),
    (
        "min_print_speed",
        Rule::Num(|c| &mut c.printer.min_print_speed),
    ),
    (
        "machine_max_acceleration_extruding",
        Rule::Custom(acceleration),
    ),
    (
        "disable_fan_first_layers",
        Rule::Count(|c| &mut c.printer.disable_fan_first_layers),
    ),
    (
        "use_relative_e_distances",
        Rule::Flag(|c| &mut c.printer.use_relative_e_distances),
    ),
    (
        "use_firmware_retraction",
        Rule::Flag(|c| &mut c.printer.use_firmware_retraction),
    ),
    (
        "only_retract_when_crossing_perimeters",
        Rule::Flag(|c| &mut c.printer.only_retract_when_crossing_perimeters),
    ),
    // Slicing.
    ("layer_height", Rule::Num(|c| &mut c.slice.layer_height)),
    (
        "first_layer_height",
        Rule::Percent(
            |c| c.slice.layer_height,
            |c| &mut c.slice.first_layer_height,
        ),
    ),
    ("perimeters", Rule::Count(|c| &mut c.slice.perimeters)),
    (
        "top_solid_layers",
        Rule::Count(|c| &mut c.slice.top_solid_layers),
    ),
    (
        "bottom_solid_layers",
        Rule::Count(|c| &mut c.slice.bottom_solid_layers),
    ),
    ("skirts", Rule::Count(|c| &mut c.slice.skirt_loops)),
    ("fill_density", Rule::Custom(fill_density)),
    (
        "solid_infill_below_area",
        Rule::Num(|c| &mut c.slice.solid_infill_below_area),
    ),
    ("gap_fill_enabled", Rule::Flag(|c| &mut c.slice.gap_fill)),
    ("fill_pattern", Rule::Custom(fill_pattern)),
    (
        "top_fill_pattern",
        Rule::Solid(|c| &mut c.slice.top_fill_pattern),
    ),
    (
        "top_infill_pattern",
        Rule::Solid(|c| &mut c.slice.top_fill_pattern),
    ),
    (
        "bottom_fill_pattern",
        Rule::Solid(|c| &mut c.slice.bottom_fill_pattern),
    ),
    (
        "bottom_infill_pattern",
        Rule::Solid(|c| &mut c.slice.bottom_fill_pattern),
    ),
    ("fill_angle", Rule::Num(|c| &mut c.slice.infill_angle_deg)),
    ("infill_overlap", Rule::Custom(infill_overlap)),
    (
        "external_perimeters_first",
        Rule::Flag(|c| &mut c.slice.external_perimeters_first),
    ),
    (
        "support_material",
        Rule::Flag(|c| &mut c.slice.support_material),
    ),
    ("skirt_distance", Rule::Num(|c| &mut c.slice.skirt_distance)),
    ("brim_width", Rule::Num(|c| &mut c.slice.brim_width)),
    (
        "brim_separation",
        Rule::Num(|c| &mut c.slice.brim_separation),
    ),
    ("brim_type", Rule::Custom(brim_type)),
    ("perimeter_generator", Rule::Custom(perimeter_generator)),
    ("seam_position", Rule::Custom(seam_position)),
    // After the nozzle: a gap in mm is a fraction of it.
    ("seam_gap", Rule::Custom(seam_gap)),
    // Widths (every role width is read with the generic one).
    ("extrusion_width", Rule::Custom(extrusion_widths)),
    // Speeds; a percentage is of the parent PrusaSlicer uses.
    (
        "perimeter_speed",
        Rule::Num(|c| &mut c.slice.perimeter_speed),
    ),
    (
        "external_perimeter_speed",
        Rule::Percent(
            |c| c.slice.perimeter_speed,
            |c| &mut c.slice.external_perimeter_speed,
        ),
    ),
    ("infill_speed", Rule::Num(|c| &mut c.slice.infill_speed)),
    (
        "solid_infill_speed",
        Rule::Percent(
            |c| c.slice.infill_speed,
            |c| &mut c.slice.solid_infill_speed,
        ),
    ),
    (
        "top_solid_infill_speed",
        Rule::Percent(
            |c| c.slice.solid_infill_speed,
            |c| &mut c.slice.top_solid_infill_speed,
        ),
    ),
    ("bridge_speed", Rule::Num(|c| &mut c.slice.bridge_speed)),
    ("gap_fill_speed", Rule::Num(|c| &mut c.slice.gap_fill_speed)),
    (
        "first_layer_speed",
        Rule::Percent(
            |c| c.slice.perimeter_speed,
            |c| &mut c.slice.first_layer_speed,
        ),
    ),
    ("support_material_speed", Rule::Custom(support_speed)),
    // Overhangs (after the external perimeter speed: overhang speeds may be a % of it).
    ("overhangs", Rule::Flag(|c| &mut c.slice.overhangs)),
    (
        "enable_dynamic_overhang_speeds",
        Rule::Custom(dynamic_overhang_speeds),
    ),
    (
        "bridge_fan_speed",
        Rule::Num(|c| &mut c.printer.bridge_fan_speed),
    ),
    (
        "enable_dynamic_fan_speeds",
        Rule::Flag(|c| &mut c.printer.dynamic_fan_speeds),
    ),
    (
        "overhang_fan_speed_0",
        Rule::Num(|c| &mut c.printer.overhang_fan_speed_0),
    ),
    (
        "overhang_fan_speed_1",
        Rule::Num(|c| &mut c.printer.overhang_fan_speed_1),
    ),
    (
        "overhang_fan_speed_2",
        Rule::Num(|c| &mut c.printer.overhang_fan_speed_2),
    ),
    (
        "overhang_fan_speed_3",
        Rule::Num(|c| &mut c.printer.overhang_fan_speed_3),
    ),
    (
        "support_material_interface_speed",
        Rule::Percent(
            |c| c.slice.support_speed,
            |c| &mut c.slice.support_interface_speed,
        ),
    ),
    // Support (after the widths: the xy gap may be a % of the external perimeter width).
    (
        "support_material_threshold",
        Rule::Custom(support_threshold),
    ),
    (
        "support_material_contact_distance",
        Rule::Num(|c| &mut c.support.z_gap),
    ),
    (
        "support_material_xy_spacing",
        Rule::Percent(
            |c| c.slice.external_perimeter_width,
            |c| &mut c.support.xy_gap,
        ),
    ),
    (
        "support_material_interface_layers",
        Rule::Count(|c| &mut c.support.interface_layers),
    ),
    (
        "support_material_spacing",
        Rule::Num(|c| &mut c.support.spacing),
    ),
    (
        "support_material_interface_spacing",
        Rule::Num(|c| &mut c.support.interface_spacing),
    ),
    ("support_material_pattern", Rule::Custom(support_pattern)),
    (
        "support_material_angle",
        Rule::Num(|c| &mut c.support.angle),
    ),
    (
        "support_material_buildplate_only",
        Rule::Flag(|c| &mut c.support.buildplate_only),
    ),
    (
        "support_material_with_sheath",
        Rule::Flag(|c| &mut c.support.sheath),
    ),
    // Wipe tower.
    ("wipe_tower", Rule::Flag(|c| &mut c.wipe_tower.enabled)),
    ("wipe_tower_x", Rule::Custom(wipe_tower_corner)),
    ("wipe_tower_y", Rule::Custom(wipe_tower_corner)),
    ("wipe_tower_width", Rule::Num(|c| &mut c.wipe_tower.width)),
    (
        "wipe_tower_bridging",
        Rule::Num(|c| &mut c.wipe_tower.sparse_spacing),
    ),
    (
        "wipe_tower_brim_width",
        Rule::Num(|c| &mut c.wipe_tower.brim_width),
    ),
    (
        "wipe_tower_rotation_angle",
        Rule::Num(|c| &mut c.wipe_tower.rotation),
    ),
    ("wiping_volumes_matrix", Rule::Custom(wiping_volumes)),
];

/// Role widths: key, automatic width (× nozzle) and field. Read after `extrusion_width`.
const WIDTHS: &[(&str, f64, Field<f64>)] = &[
    ("perimeter_extrusion_width", 1.125, |c| {
        &mut c.slice.perimeter_width
    }),
    ("external_perimeter_extrusion_width", 1.125, |c| {
        &mut c.slice.external_perimeter_width
    }),
    ("infill_extrusion_width", 1.125, |c| {
        &mut c.slice.infill_width
    }),
    ("solid_infill_extrusion_width", 1.125, |c| {
        &mut c.slice.solid_infill_width
    }),
    ("top_infill_extrusion_width", 1.0, |c| {
        &mut c.slice.top_solid_infill_width
    }),
];

/// A conversion under way: the pairs (with the keys read so far), the config they fill and the
/// warnings given.
struct Import {
    p: Pairs,
    cfg: Config,
    warnings: Vec<String>,
}

impl Rule {
    /// Reads `key` from the pairs and writes its value into the config (a missing key leaves
    /// the default).
    fn apply(&self, key: &str, imp: &mut Import) -> Result<(), ConfigError> {
        let (p, cfg) = (&mut imp.p, &mut imp.cfg);
        match *self {
            Rule::Num(field) => {
                if let Some(v) = p.num(key)? {
                    *field(cfg) = v;
                }
            }
            Rule::Count(field) => {
                if let Some(v) = p.count(key)? {
                    *field(cfg) = v;
                }
            }
            Rule::Flag(field) => {
                if let Some(v) = p.flag(key)? {
                    *field(cfg) = v;
                }
            }
            Rule::Percent(base, field) => {
                if let Some(v) = p.abs_or_percent(key, base(cfg))? {
                    *field(cfg) = v;
                }
            }
            Rule::Gcode(field) => {
                if let Some(g) = p.gcode(key) {
                    if let Some(w) = syntax_warning(key, &format!("printer.{key}"), &g) {
                        imp.warnings.push(w);
                    }
                    *field(cfg) = g;
                }
            }
            Rule::Solid(field) => {
                if let Some(pat) = p.raw(key).map(str::to_owned) {
                    if pat.trim() != "rectilinear" {
                        imp.warnings.push(format!(
                            "{key} = {}: not available, rectilinear solid infill is printed",
                            pat.trim()
                        ));
                    }
                    *field(cfg) = SolidPattern::Rectilinear;
                }
            }
            Rule::Custom(read) => read(imp, key)?,
        }
        Ok(())
    }
}

/// The conversion: the technology check, the tools, every key of [`RULES`] in order, then one
/// warning for the keys no step read and the config's own validation.
fn convert(
    list: LinedPairs,
    defaulted: BTreeSet<String>,
) -> Result<(Config, Vec<String>), ConfigError> {
    let mut imp = Import {
        p: Pairs {
            values: list.into_iter().map(|(k, v, l)| (k, (v, l))).collect(),
            used: BTreeSet::new(),
            defaulted,
        },
        cfg: Config::default(),
        warnings: Vec::new(),
    };
    check_technology(&mut imp.p)?;
    read_tools(&mut imp)?;
    for (key, rule) in RULES {
        rule.apply(key, &mut imp)?;
    }
    warn_ignored(&mut imp);
    let Import {
        mut cfg,
        warnings,
        p,
    } = imp;
    // What conduit does differently with PrusaSlicer's default for a key the file leaves out
    // is said once, after what it does with the file's own values.
    let (from_defaults, mut warnings): (Vec<String>, Vec<String>) =
        warnings.into_iter().partition(|w| {
            p.defaulted
                .contains(w.split([' ', ':']).next().unwrap_or_default())
        });
    if !from_defaults.is_empty() {
        warnings.push(format!(
            "{} {DEFAULTS_PRINTED_OTHERWISE}: {}",
            from_defaults.len(),
            from_defaults.join("; ")
        ));
    }
    // Every key as written, for the templates' macros (`{filament_type[0]}`, `{z_offset}`).
    cfg.printer.profile = p.values.into_iter().map(|(k, (v, _))| (k, v)).collect();
    let more = cfg.validate()?;
    warnings.extend(more);
    Ok((cfg, warnings))
}

/// Refuses a profile of a printer that is not FFF (`printer_technology`).
fn check_technology(p: &mut Pairs) -> Result<(), ConfigError> {
    if let Some(tech) = p.raw("printer_technology").map(str::to_owned) {
        if !tech.eq_ignore_ascii_case("FFF") {
            return Err(p.err(
                "printer_technology",
                "conduit drives FFF (filament) printers only",
            ));
        }
    }
    Ok(())
}

/// Builds the tools, one per extruder (the longest per-extruder list), then appends conduit's
/// paste tool; the first nozzle becomes the slicing nozzle and the first retraction the
/// printer's.
fn read_tools(imp: &mut Import) -> Result<(), ConfigError> {
    let p = &mut imp.p;
    let n_tools = PER_EXTRUDER
        .iter()
        .filter_map(|k| p.values.get(*k))
        .map(|(v, _)| v.split(',').count())
        .max()
        .unwrap_or(1)
        .max(1);
    let mut tools = vec![Tool::filament(); n_tools];
    read_tool_numbers(p, &mut tools)?;
    for (t, name) in tools.iter_mut().zip(p.strings("filament_type")) {
        if !name.is_empty() {
            t.name = name;
        }
    }
    read_idle_temperatures(p, &mut tools)?;
    for (t, start) in tools.iter_mut().zip(p.gcodes("start_filament_gcode")) {
        t.start_gcode = start;
    }
    for (t, end) in tools.iter_mut().zip(p.gcodes("end_filament_gcode")) {
        t.end_gcode = end;
    }
    if let Some(raw) = p.raw("extruder_offset").map(str::to_owned) {
        for (t, xy) in tools.iter_mut().zip(raw.split(',')) {
            t.offset = parse_xy(xy).ok_or_else(|| p.err("extruder_offset", "expected XxY"))?;
        }
    }
    let retract = p.list("retract_length")?;
    if let Some(&first) = retract.first() {
        imp.cfg.printer.retract_length = first;
        for (t, &r) in tools.iter_mut().zip(&retract) {
            if r != first {
                t.retract_length = Some(r);
            }
        }
    }
    let nozzle = tools[0].nozzle_diameter;
    imp.cfg.tools = tools;
    imp.cfg.tools.push(Tool::paste());
    imp.cfg.slice.nozzle_diameter = nozzle;
    Ok(())
}

/// Fills the number fields of [`TOOL_NUMBERS`]; a density of 0 (PrusaSlicer's "unknown")
/// keeps the default.
fn read_tool_numbers(p: &mut Pairs, tools: &mut [Tool]) -> Result<(), ConfigError> {
    for (key, field) in TOOL_NUMBERS {
        let values = p.list(key)?;
        let default = *field(&mut Tool::filament());
        let fill = values.last().copied().unwrap_or(default);
        for (t, v) in tools
            .iter_mut()
            .zip(values.iter().copied().chain(std::iter::repeat(fill)))
        {
            *field(t) = v;
        }
    }
    for t in tools.iter_mut() {
        if t.filament_density <= 0.0 {
            t.filament_density = Tool::filament().filament_density;
        }
    }
    Ok(())
}

/// Reads `idle_temperature` into the standby temperatures (`nil` leaves a tool without one).
fn read_idle_temperatures(p: &mut Pairs, tools: &mut [Tool]) -> Result<(), ConfigError> {
    if let Some(raw) = p.raw("idle_temperature").map(str::to_owned) {
        for (t, v) in tools.iter_mut().zip(raw.split(',')) {
            let v = v.trim();
            if v != "nil" && !v.is_empty() {
                t.standby_temperature = Some(
                    v.parse()
                        .map_err(|_| p.err("idle_temperature", "expected a number or nil"))?,
                );
            }
        }
    }
    Ok(())
}

/// `bed_shape`: the bounding box of the bed polygon gives the bed origin and size.
fn bed_shape(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let p = &mut imp.p;
    if let Some(raw) = p.raw(key).map(str::to_owned) {
        let points: Option<Vec<[f64; 2]>> = raw.split(',').map(parse_xy).collect();
        let points = points
            .filter(|pts| pts.len() >= 3)
            .ok_or_else(|| p.err(key, "expected a polygon `XxY,XxY,XxY,…`"))?;
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for q in &points {
            for a in 0..2 {
                lo[a] = lo[a].min(q[a]);
                hi[a] = hi[a].max(q[a]);
            }
        }
        let pr = &mut imp.cfg.printer;
        pr.bed_origin = lo;
        pr.bed_size = [hi[0] - lo[0], hi[1] - lo[1]];
    }
    Ok(())
}

/// `gcode_flavor`: the firmware dialect; an unsupported one becomes marlin with a warning.
fn gcode_flavor(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    if let Some(f) = imp.p.raw(key).map(str::to_owned) {
        imp.cfg.printer.flavor = match f.trim() {
            "marlin" | "marlin2" | "marlinlegacy" => Flavor::Marlin,
            "reprapfirmware" => Flavor::RepRapFirmware,
            "klipper" => Flavor::Klipper,
            other => {
                imp.warnings.push(format!(
                    "gcode_flavor = {other}: not supported, G-code is written for marlin"
                ));
                Flavor::Marlin
            }
        };
    }
    Ok(())
}

/// `toolchange_gcode`: PrusaSlicer's tool-change G-code runs before each tool change, as
/// conduit's `before_tool_change_gcode` does; it is kept as written (the templates know
/// `next_extruder` and `previous_extruder` as the writer's `next_tool` and `previous_tool`).
fn toolchange_gcode(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    if let Some(g) = imp.p.gcode(key) {
        if let Some(w) = syntax_warning(key, "printer.before_tool_change_gcode", &g) {
            imp.warnings.push(w);
        }
        imp.cfg.printer.before_tool_change_gcode = g;
    }
    Ok(())
}

/// `machine_max_acceleration_extruding`, or when it is absent or 0 `default_acceleration`.
fn acceleration(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let accel = imp.p.num(key)?;
    let default_accel = imp.p.num("default_acceleration")?;
    if let Some(a) = accel
        .filter(|a| *a > 0.0)
        .or(default_accel.filter(|a| *a > 0.0))
    {
        imp.cfg.printer.max_acceleration = a;
    }
    Ok(())
}

/// `fill_density`: `20%` (or `20`, or `0.2`) → 0.2.
fn fill_density(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    if let Some(raw) = imp.p.raw(key).map(str::to_owned) {
        let raw = raw.trim();
        let d = match raw.strip_suffix('%') {
            Some(pc) => pc.trim().parse::<f64>().map(|v| v / 100.0),
            None => raw
                .parse::<f64>()
                .map(|v| if v > 1.0 { v / 100.0 } else { v }),
        };
        imp.cfg.slice.infill_density = d.map_err(|_| imp.p.err(key, "expected a percentage"))?;
    }
    Ok(())
}

/// `fill_pattern`: the sparse infill pattern; one conduit lacks becomes rectilinear with a
/// warning.
fn fill_pattern(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    if let Some(pat) = imp.p.raw(key).map(str::to_owned) {
        imp.cfg.slice.infill_pattern = match pat.trim() {
            "rectilinear" => InfillPatternKind::Rectilinear,
            "grid" => InfillPatternKind::Grid,
            "triangles" => InfillPatternKind::Triangles,
            other => {
                imp.warnings.push(format!(
                    "fill_pattern = {other}: not available, rectilinear infill is printed"
                ));
                InfillPatternKind::Rectilinear
            }
        };
    }
    Ok(())
}

/// `infill_overlap`: PrusaSlicer gives mm, or % of the perimeter extrusion width; conduit a
/// fraction of it (the perimeter width as it stands before the widths are read).
fn infill_overlap(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let slice = &mut imp.cfg.slice;
    let perimeter_width_guess = slice.perimeter_width;
    if let Some(v) = imp.p.abs_or_percent(key, perimeter_width_guess)? {
        slice.infill_overlap = v / perimeter_width_guess;
    }
    Ok(())
}

/// `perimeter_generator` and `thin_walls`: `classic` is conduit's classic generator and prints
/// thin walls as `thin_walls` says (PrusaSlicer's default, on, when the key is missing); `arachne`
/// (PrusaSlicer's default, also when the key is missing) is conduit's variable generator, which
/// like Arachne prints thin features whatever `thin_walls` says. Any other value warns and takes
/// the variable generator.
fn perimeter_generator(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let named = imp.p.raw(key).map(|g| g.trim().to_owned());
    let thin_walls = imp.p.flag("thin_walls")?;
    let generator = match named.as_deref() {
        Some("classic") => PerimeterGenerator::Classic,
        None | Some("arachne") => PerimeterGenerator::Variable,
        Some(other) => {
            imp.warnings.push(format!(
                "perimeter_generator = {other}: conduit prints variable-width (arachne-like) \
                 perimeters"
            ));
            PerimeterGenerator::Variable
        }
    };
    let slice = &mut imp.cfg.slice;
    slice.perimeter_generator = generator;
    slice.thin_walls = match generator {
        PerimeterGenerator::Classic => thin_walls.unwrap_or(true),
        PerimeterGenerator::Variable => true,
    };
    Ok(())
}

/// `seam_position`: `aligned`, `nearest`, `rear` and `random` are conduit's rules of the same
/// names; PrusaSlicer's default (`aligned`) when the key is missing.
fn seam_position(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let Some(named) = imp.p.raw(key).map(|v| v.trim().to_owned()) else {
        imp.cfg.slice.seam_position = SeamRule::Aligned;
        return Ok(());
    };
    imp.cfg.slice.seam_position = match named.as_str() {
        "aligned" => SeamRule::Aligned,
        "nearest" => SeamRule::Nearest,
        "rear" => SeamRule::Rear,
        "random" => SeamRule::Random,
        _ => {
            return Err(imp.p.err(key, "expected aligned, nearest, rear or random"));
        }
    };
    Ok(())
}

/// `seam_gap` (OrcaSlicer's; PrusaSlicer clips every loop by 15 % of the nozzle, conduit's
/// default): mm, or `%` of the nozzle diameter.
fn seam_gap(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let nozzle = imp.cfg.slice.nozzle_diameter;
    if let Some(mm) = imp.p.abs_or_percent(key, nozzle)? {
        imp.cfg.slice.seam_gap = if nozzle > 0.0 { mm / nozzle } else { 0.0 };
    }
    Ok(())
}

/// `enable_dynamic_overhang_speeds` (off when missing, PrusaSlicer's default) with
/// `overhang_speed_0..3`: mm/s, or `%` of the external perimeter speed; 0 is the external
/// perimeter speed, as in PrusaSlicer.
fn dynamic_overhang_speeds(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    imp.cfg.slice.dynamic_overhang_speeds = imp.p.flag(key)?.unwrap_or(false);
    let base = imp.cfg.slice.external_perimeter_speed;
    for (i, name) in [
        "overhang_speed_0",
        "overhang_speed_1",
        "overhang_speed_2",
        "overhang_speed_3",
    ]
    .into_iter()
    .enumerate()
    {
        if let Some(v) = imp.p.abs_or_percent(name, base)? {
            let v = if v > 0.0 { v } else { base };
            let s = &mut imp.cfg.slice;
            let field = match i {
                0 => &mut s.overhang_speed_0,
                1 => &mut s.overhang_speed_1,
                2 => &mut s.overhang_speed_2,
                _ => &mut s.overhang_speed_3,
            };
            *field = v;
        }
    }
    Ok(())
}

/// `brim_type`: PrusaSlicer's `no_brim` (no brim whatever `brim_width` says), `outer_only`,
/// `inner_only`, `outer_and_inner`, and OrcaSlicer's `brim_ears` (`auto_brim` is read as
/// `outer_only`).
fn brim_type(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let Some(named) = imp.p.raw(key).map(|v| v.trim().to_owned()) else {
        return Ok(());
    };
    let slice = &mut imp.cfg.slice;
    slice.brim_type = match named.as_str() {
        "outer_only" | "auto_brim" => BrimType::Outer,
        "inner_only" => BrimType::Inner,
        "outer_and_inner" => BrimType::Both,
        "brim_ears" => BrimType::Ears,
        "no_brim" => {
            slice.brim_width = 0.0;
            BrimType::Outer
        }
        _ => {
            return Err(imp.p.err(
                key,
                "expected no_brim, outer_only, inner_only, outer_and_inner or brim_ears",
            ));
        }
    };
    Ok(())
}

/// `wipe_tower_x` / `wipe_tower_y`: the tower's front-left corner (PrusaSlicer's position of
/// the unrotated tower).
fn wipe_tower_corner(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    if let Some(v) = imp.p.num(key)? {
        let tower = &mut imp.cfg.wipe_tower;
        if key == "wipe_tower_x" {
            tower.x = Some(v);
        } else {
            tower.y = Some(v);
        }
    }
    Ok(())
}

/// `wiping_volumes_matrix`: mm³ purged from each extruder to each other, row by row. conduit
/// purges one volume after every change: the largest of the matrix, so that no change purges
/// less than PrusaSlicer's.
fn wiping_volumes(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let Some(raw) = imp.p.raw(key).map(str::to_owned) else {
        return Ok(());
    };
    let mut largest: Option<f64> = None;
    for v in raw.split(',').map(str::trim).filter(|v| !v.is_empty()) {
        let v: f64 = v
            .parse()
            .map_err(|_| imp.p.err(key, "expected numbers separated by commas"))?;
        largest = Some(largest.map_or(v, |l: f64| l.max(v)));
    }
    if let Some(v) = largest {
        imp.cfg.wipe_tower.purge_volume = v;
    }
    Ok(())
}

/// `support_material_speed`: the support's speed, and the skirt's (PrusaSlicer prints skirt
/// and brim at the support speed); a `%` is of the perimeter speed.
fn support_speed(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let parent = imp.cfg.slice.perimeter_speed;
    if let Some(v) = imp.p.abs_or_percent(key, parent)? {
        imp.cfg.slice.support_speed = v;
        imp.cfg.slice.skirt_speed = v;
    }
    Ok(())
}

/// `support_material_threshold`: PrusaSlicer counts from the horizontal, conduit from the
/// vertical; 0 (PrusaSlicer's automatic threshold, about half a bead's overhang a layer) keeps
/// conduit's 45°.
fn support_threshold(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    if let Some(raw) = imp.p.raw(key).map(str::trim).filter(|v| v.ends_with('%')) {
        // SuperSlicer's threshold relative to the extrusion width has no angle.
        let raw = raw.to_owned();
        imp.warnings.push(format!(
            "support_material_threshold = {raw}: a threshold relative to the extrusion width \
             is read as conduit's {}°",
            imp.cfg.support.threshold_angle
        ));
        return Ok(());
    }
    match imp.p.num(key)? {
        Some(t) if t > 0.0 && t <= 90.0 => imp.cfg.support.threshold_angle = 90.0 - t,
        Some(0.0) | None => {}
        Some(_) => return Err(imp.p.err(key, "expected an angle from 0 to 90 degrees")),
    }
    Ok(())
}

/// `support_material_pattern`: `rectilinear`, `rectilinear-grid` (conduit's grid); PrusaSlicer's
/// `honeycomb` becomes the grid and any other pattern (Slic3r's `pillars`) rectilinear, with a
/// warning.
fn support_pattern(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let Some(named) = imp.p.raw(key).map(|v| v.trim().to_owned()) else {
        return Ok(());
    };
    imp.cfg.support.pattern = match named.as_str() {
        "rectilinear" => SupportPattern::Rectilinear,
        "rectilinear-grid" => SupportPattern::Grid,
        "honeycomb" => {
            imp.warnings
                .push("support_material_pattern = honeycomb: printed as conduit's grid".to_owned());
            SupportPattern::Grid
        }
        other => {
            // Slic3r's `pillars` and the patterns of other forks.
            imp.warnings.push(format!(
                "support_material_pattern = {other}: printed as conduit's rectilinear"
            ));
            SupportPattern::Rectilinear
        }
    };
    Ok(())
}

/// `extrusion_width` and the role widths of [`WIDTHS`]: a role's 0 (or missing) width falls
/// back to the generic one, and when that is 0 too to the automatic width; a first-layer width
/// of 0 takes the perimeter width.
fn extrusion_widths(imp: &mut Import, key: &str) -> Result<(), ConfigError> {
    let (p, cfg) = (&mut imp.p, &mut imp.cfg);
    // The first tool's nozzle, as `read_tools` set it.
    let nozzle = cfg.slice.nozzle_diameter;
    let generic = p.abs_or_percent(key, nozzle)?.filter(|w| *w > 0.0);
    for (role, auto, field) in WIDTHS {
        *field(cfg) = match p.abs_or_percent(role, nozzle)? {
            Some(w) if w > 0.0 => w,
            _ => generic.unwrap_or(auto * nozzle),
        };
    }
    let slice = &mut cfg.slice;
    match p.abs_or_percent("first_layer_extrusion_width", nozzle)? {
        Some(w) if w > 0.0 => slice.first_layer_width = w,
        _ => slice.first_layer_width = slice.perimeter_width,
    }
    Ok(())
}

/// Where the warning about ignored keys ([`warn_ignored`]) turns from its summary to the full
/// list: a front end that shows only the summary cuts the warning here.
pub const IGNORED_LIST_MARK: &str = "; all of them: ";

/// PrusaSlicer settings that conduit does not honour and that change what is printed (the
/// material laid down, its shape or place) when set to anything but the value given, which
/// prints as conduit does; `None` when every value changes the print. Settings of cooling,
/// accelerations, G-code comments, multi-material ramming and the like change at most how the
/// same paths are run, and are not listed.
const CHANGES_THE_PRINT: &[(&str, Option<&[&str]>)] = &[
    ("bottom_solid_min_thickness", Some(&["0"])),
    ("bridge_angle", Some(&["0"])),
    ("bridge_flow_ratio", Some(&["1"])),
    ("complete_objects", Some(&["0"])),
    ("draft_shield", Some(&["disabled", "0"])),
    ("elefant_foot_compensation", Some(&["0"])),
    ("ensure_vertical_shell_thickness", Some(&["0"])),
    ("extra_perimeters", Some(&["0"])),
    ("extra_perimeters_on_overhangs", Some(&["0"])),
    ("filament_max_volumetric_speed", Some(&["0"])),
    ("fuzzy_skin", Some(&["none"])),
    ("infill_anchor", Some(&["0"])),
    ("infill_anchor_max", Some(&["0"])),
    ("infill_every_layers", Some(&["1"])),
    ("infill_first", Some(&["0"])),
    ("infill_only_where_needed", Some(&["0"])),
    ("interface_shells", Some(&["0"])),
    ("ironing", Some(&["0"])),
    ("max_volumetric_speed", Some(&["0"])),
    ("raft_layers", Some(&["0"])),
    ("solid_infill_every_layers", Some(&["0"])),
    ("spiral_vase", Some(&["0"])),
    ("support_material_auto", Some(&["1"])),
    ("support_material_bottom_contact_distance", Some(&["0"])),
    ("support_material_bottom_interface_layers", Some(&["-1"])),
    ("support_material_enforce_layers", Some(&["0"])),
    ("support_material_style", Some(&["grid"])),
    ("thick_bridges", Some(&["0"])),
    ("top_solid_min_thickness", Some(&["0"])),
    ("xy_size_compensation", Some(&["0"])),
    ("z_offset", Some(&["0"])),
];

/// True when the ignored `key` with `value` changes what is printed ([`CHANGES_THE_PRINT`]);
/// a per-extruder list changes it when any of its values does, a setting of the supports only
/// when the profile prints supports (`support`).
fn changes_the_print(key: &str, value: &str, support: bool) -> bool {
    let Some((_, neutral)) = CHANGES_THE_PRINT.iter().find(|(k, _)| *k == key) else {
        return false;
    };
    if key.starts_with("support_material_") && !support {
        return false;
    }
    let Some(neutral) = neutral else {
        return true;
    };
    value.split(',').map(str::trim).any(|v| {
        !neutral.contains(&v)
            && !v
                .parse::<f64>()
                .is_ok_and(|x| neutral.iter().any(|n| n.parse::<f64>() == Ok(x)))
    })
}

/// How much leaving the setting `key = value` out changes the print, for ordering lists of
/// settings not honoured: 0 for a key conduit reads from a profile, 1 for one of
/// [`CHANGES_THE_PRINT`] set to a value that matters, 2 for the rest.
pub(crate) fn impact(key: &str, value: &str) -> u8 {
    if RULES.iter().any(|(k, _)| *k == key) || PER_EXTRUDER.contains(&key) {
        0
    } else if changes_the_print(key, value, true) {
        1
    } else {
        2
    }
}

/// Builds a config from PrusaSlicer pairs with the line each came from, as
/// [`from_prusa_pairs`] does.
pub(crate) fn from_lined_pairs(pairs: LinedPairs) -> Result<(Config, Vec<String>), ConfigError> {
    convert(pairs, BTreeSet::new())
}

/// Lists, in one warning, every key no step has read: their number, those that change the
/// print ([`CHANGES_THE_PRINT`]) by name, then after [`IGNORED_LIST_MARK`] all of them, sorted.
fn warn_ignored(imp: &mut Import) {
    let p = &mut imp.p;
    for key in ACCEPTED {
        p.used.insert((*key).to_owned());
    }
    let support = p
        .values
        .get("support_material")
        .is_some_and(|(v, _)| v.trim() == "1");
    // `values` is a sorted map: both lists come out sorted.
    // Only the keys the input states: a default is no setting of the user's.
    let ignored: Vec<(&str, &str)> = p
        .values
        .iter()
        .filter(|(k, _)| !p.used.contains(*k) && !p.defaulted.contains(*k))
        .map(|(k, (v, _))| (k.as_str(), v.as_str()))
        .collect();
    if ignored.is_empty() {
        return;
    }
    let changing: Vec<&str> = ignored
        .iter()
        .filter(|(k, v)| changes_the_print(k, v, support))
        .map(|(k, _)| *k)
        .collect();
    let n = ignored.len();
    let keys = if n == 1 { "key" } else { "keys" };
    let which = if changing.is_empty() {
        "none that change the print".to_owned()
    } else {
        format!(
            "{} that change the print: {}",
            changing.len(),
            changing.join(", ")
        )
    };
    let all: Vec<&str> = ignored.iter().map(|(k, _)| *k).collect();
    imp.warnings.push(format!(
        "{n} PrusaSlicer {keys} ignored ({which}){IGNORED_LIST_MARK}{}",
        all.join(", ")
    ));
}

/// `250x125` → [250, 125].
fn parse_xy(s: &str) -> Option<[f64; 2]> {
    let (x, y) = s.trim().split_once(['x', 'X'])?;
    Some([x.trim().parse().ok()?, y.trim().parse().ok()?])
}

/// A warning when the G-code `g` of `key` (conduit's `field`) does not parse as PrusaSlicer's
/// macro language; the G-code is kept, and writing it fails with the same error.
fn syntax_warning(key: &str, field: &str, g: &str) -> Option<String> {
    crate::emit::gcode::macros::check_syntax(g)
        .err()
        .map(|e| format!("{key}: {e}; edit {field}"))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::emit::gcode::macros::{Value, Var};

    /// The warnings about what a file states: all but the one about PrusaSlicer's defaults for
    /// the keys it leaves out.
    pub(crate) fn stated(warnings: &[String]) -> Vec<&String> {
        warnings
            .iter()
            .filter(|w| !w.contains(DEFAULTS_PRINTED_OTHERWISE))
            .collect()
    }

    const BENCH_INI: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/bench/configs/prusaslicer.ini"
    );

    #[test]
    fn bench_profile_lands_in_every_field() -> Result<(), ConfigError> {
        let path = std::path::Path::new(BENCH_INI);
        if !path.exists() {
            println!("skipped: corpus not found");
            return Ok(());
        }
        let (cfg, warnings) = super::super::load(path)?;
        assert!(warnings.is_empty(), "{warnings:?}");
        let (p, s, t) = (&cfg.printer, &cfg.slice, &cfg.tools[0]);
        assert_eq!(p.bed_size, [250.0, 250.0]);
        assert_eq!(p.bed_origin, [0.0, 0.0]);
        assert_eq!(p.max_height, 250.0);
        assert_eq!(p.flavor, Flavor::Marlin);
        assert_eq!(t.nozzle_diameter, 0.4);
        assert_eq!(s.nozzle_diameter, 0.4);
        assert_eq!(t.filament_diameter, 1.75);
        assert_eq!(t.temperature, 210.0);
        assert_eq!(t.first_layer_temperature, 210.0);
        assert_eq!(p.bed_temperature, 60.0);
        assert_eq!(p.first_layer_bed_temperature, 60.0);
        assert_eq!(s.layer_height, 0.2);
        assert_eq!(s.first_layer_height, 0.2);
        assert_eq!(s.first_layer_width, 0.45);
        assert_eq!(s.perimeter_width, 0.45);
        assert_eq!(s.external_perimeter_width, 0.45);
        assert_eq!(s.infill_width, 0.45);
        assert_eq!(s.solid_infill_width, 0.45);
        assert_eq!(s.top_solid_infill_width, 0.45);
        assert_eq!(s.perimeters, 2);
        assert_eq!(s.top_solid_layers, 3);
        assert_eq!(s.bottom_solid_layers, 3);
        assert!((s.infill_density - 0.2).abs() < 1e-12);
        assert_eq!(s.infill_pattern, InfillPatternKind::Rectilinear);
        assert_eq!(s.top_fill_pattern, SolidPattern::Rectilinear);
        assert_eq!(s.bottom_fill_pattern, SolidPattern::Rectilinear);
        assert!(!s.support_material);
        assert_eq!(s.skirt_loops, 0);
        assert_eq!(s.brim_width, 0.0);
        // One filament extruder from the profile, plus conduit's paste tool.
        assert_eq!(cfg.tools.len(), 2);
        assert_eq!(cfg.tools[1], Tool::paste());
        Ok(())
    }

    #[test]
    fn arachne_profile_takes_the_variable_generator_and_classic_its_thin_walls()
    -> Result<(), ConfigError> {
        let path = BENCH_INI.replace("prusaslicer.ini", "prusaslicer-arachne.ini");
        let path = std::path::Path::new(&path);
        if !path.exists() {
            println!("skipped: corpus not found");
            return Ok(());
        }
        let (cfg, warnings) = super::super::load(path)?;
        assert_eq!(warnings, Vec::<String>::new());
        assert_eq!(cfg.slice.perimeter_generator, PerimeterGenerator::Variable);
        assert!(cfg.slice.thin_walls);
        let (classic, _) = super::super::load(std::path::Path::new(BENCH_INI))?;
        assert_eq!(
            classic.slice.perimeter_generator,
            PerimeterGenerator::Classic
        );
        // The bench profile has no `thin_walls`: PrusaSlicer's default is on.
        assert!(classic.slice.thin_walls);
        // Without the key PrusaSlicer takes Arachne; an unknown generator warns.
        let (missing, _) = from_ini_str("layer_height = 0.2\n")?;
        assert_eq!(
            missing.slice.perimeter_generator,
            PerimeterGenerator::Variable
        );
        let (odd, w) = from_ini_str("perimeter_generator = fancy\n")?;
        assert_eq!(odd.slice.perimeter_generator, PerimeterGenerator::Variable);
        assert!(
            w.iter().any(|w| w.contains("perimeter_generator = fancy")),
            "{w:?}"
        );
        let (thin, _) = from_ini_str("perimeter_generator = classic\nthin_walls = 1\n")?;
        assert!(thin.slice.thin_walls);
        Ok(())
    }

    /// The wipe tower's keys as PrusaSlicer 2.5 saves them (`prusa-slicer --wipe-tower
    /// --wipe-tower-x 170 --wipe-tower-y 40 --wipe-tower-width 50 --wipe-tower-bridging 8
    /// --wiping-volumes-matrix 0,120,90,0 --save p.ini`).
    #[test]
    fn wipe_tower_keys_map() -> Result<(), ConfigError> {
        let (cfg, warnings) = from_ini_str(
            "wipe_tower = 1\nwipe_tower_bridging = 8\nwipe_tower_brim_width = 3\n\
             wipe_tower_no_sparse_layers = 0\nwipe_tower_rotation_angle = 30\n\
             wipe_tower_width = 50\nwipe_tower_x = 170\nwipe_tower_y = 40\n\
             wiping_volumes_extruders = 70,70,70,70,70,70,70,70,70,70\n\
             wiping_volumes_matrix = 0,120,90,0\n",
        )?;
        let t = &cfg.wipe_tower;
        assert!(t.enabled);
        assert_eq!((t.x, t.y), (Some(170.0), Some(40.0)));
        assert_eq!(
            (
                t.width,
                t.sparse_spacing,
                t.purge_volume,
                t.brim_width,
                t.rotation
            ),
            (50.0, 8.0, 120.0, 3.0, 30.0)
        );
        // The keys conduit has no use for are named as ignored; the mapped ones are not.
        let ignored = warnings.join("\n");
        assert!(ignored.contains("wipe_tower_no_sparse_layers"), "{ignored}");
        assert!(!ignored.contains("wipe_tower_brim_width"), "{ignored}");
        assert!(!ignored.contains("wipe_tower_rotation_angle"), "{ignored}");
        assert!(!ignored.contains("wipe_tower_width"), "{ignored}");
        // Without the keys, PrusaSlicer's defaults: off, its corner at (180, 140).
        let (off, _) = from_ini_str("layer_height = 0.2\n")?;
        assert_eq!(
            off.wipe_tower,
            crate::toolpaths::TowerParams {
                x: Some(180.0),
                y: Some(140.0),
                ..Default::default()
            }
        );
        Ok(())
    }

    #[test]
    fn overhang_keys_map_with_prusaslicers_defaults_when_missing() -> Result<(), ConfigError> {
        let (missing, _) = from_ini_str("layer_height = 0.2\n")?;
        assert!(missing.slice.overhangs && !missing.slice.dynamic_overhang_speeds);
        assert_eq!(missing.overhang_params().speeds, None);
        let (set, _) = from_ini_str(
            "external_perimeter_speed = 30\noverhangs = 0\nenable_dynamic_overhang_speeds = 1\n\
             overhang_speed_0 = 50%\noverhang_speed_1 = 0\noverhang_speed_3 = 28\n\
             bridge_fan_speed = 80,80\nenable_dynamic_fan_speeds = 1\noverhang_fan_speed_2 = 40\n",
        )?;
        let o = set.overhang_params();
        assert!(!o.bridging);
        assert_eq!(o.speeds, Some([15.0, 30.0, 20.0, 28.0]));
        assert_eq!(o.fans, Some([0.0, 0.0, 40.0, 0.0]));
        assert_eq!(o.bridge_fan, 80.0);
        Ok(())
    }

    #[test]
    fn seam_gap_is_read_in_mm_or_percent_of_the_nozzle() -> Result<(), ConfigError> {
        let (missing, _) = from_ini_str("layer_height = 0.2\n")?;
        assert_eq!(missing.slice.seam_gap, 0.15);
        let (mm, _) = from_ini_str("nozzle_diameter = 0.6\nseam_gap = 0.09\n")?;
        assert!(
            (mm.slice.seam_gap - 0.15).abs() < 1e-12,
            "{}",
            mm.slice.seam_gap
        );
        let (pct, _) = from_ini_str("nozzle_diameter = 0.6\nseam_gap = 10%\n")?;
        assert!(
            (pct.slice.seam_gap - 0.10).abs() < 1e-12,
            "{}",
            pct.slice.seam_gap
        );
        assert!((pct.program_params().seam_gap - 0.06).abs() < 1e-12);
        Ok(())
    }

    #[test]
    fn percentages_auto_widths_lists_and_escapes() -> Result<(), ConfigError> {
        let ini = "\
bed_shape = -100x-90,100x-90,100x90,-100x90
nozzle_diameter = 0.6,0.4
temperature = 215,240
filament_type = PETG;FLEX
extruder_offset = 0x0,20x-5
retract_length = 0.8,2
extrusion_width = 0
perimeter_extrusion_width = 120%
external_perimeter_extrusion_width = 0
top_infill_extrusion_width = 0
first_layer_extrusion_width = 0
perimeter_speed = 60
external_perimeter_speed = 50%
infill_speed = 100
solid_infill_speed = 40%
top_solid_infill_speed = 50%
first_layer_speed = 30
fill_density = 15%
fill_pattern = gyroid
top_fill_pattern = monotonic
start_gcode = G28 ; home\\nM109 S[first_layer_temperature]\\n{if x}
gcode_flavor = klipper
use_relative_e_distances = 1
wipe = 1
gcode_comments = 0
";
        let (cfg, warnings) = from_ini_str(ini)?;
        assert_eq!(cfg.printer.bed_origin, [-100.0, -90.0]);
        assert_eq!(cfg.printer.bed_size, [200.0, 180.0]);
        assert_eq!(cfg.printer.flavor, Flavor::Klipper);
        assert!(cfg.printer.use_relative_e_distances);
        assert_eq!(cfg.tools.len(), 3);
        assert_eq!(cfg.tools[1].nozzle_diameter, 0.4);
        assert_eq!(cfg.tools[1].temperature, 240.0);
        assert_eq!(cfg.tools[1].name, "FLEX");
        assert_eq!(cfg.tools[1].offset, [20.0, -5.0]);
        assert_eq!(cfg.tools[1].retract_length, Some(2.0));
        assert_eq!(cfg.tools[0].retract_length, None);
        assert_eq!(cfg.printer.retract_length, 0.8);
        let s = &cfg.slice;
        assert!((s.perimeter_width - 0.72).abs() < 1e-12);
        assert!((s.external_perimeter_width - 0.675).abs() < 1e-12);
        assert!((s.top_solid_infill_width - 0.6).abs() < 1e-12);
        assert_eq!(s.first_layer_width, s.perimeter_width);
        assert_eq!(s.external_perimeter_speed, 30.0);
        assert_eq!(s.solid_infill_speed, 40.0);
        assert_eq!(s.top_solid_infill_speed, 20.0);
        assert_eq!(s.first_layer_speed, 30.0);
        assert!((s.infill_density - 0.15).abs() < 1e-12);
        assert_eq!(
            cfg.printer.start_gcode,
            "G28 ; home\nM109 S[first_layer_temperature]\n{if x}"
        );
        let all = warnings.join("\n");
        assert!(all.contains("gyroid") && all.contains("monotonic"), "{all}");
        assert!(
            all.contains("start_gcode: line 3: syntax error: missing {endif} in {if x}; edit printer.start_gcode"),
            "{all}"
        );
        assert!(
            all.contains(
                "2 PrusaSlicer keys ignored (none that change the print); all of them: \
                 gcode_comments, wipe"
            ),
            "{all}"
        );
        Ok(())
    }

    #[test]
    fn settings_embedded_in_peer_gcode_import() -> Result<(), Box<dyn std::error::Error>> {
        let dir = BENCH_INI.replace("bench/configs/prusaslicer.ini", "corpus/peer-gcode");
        let dir = std::path::Path::new(&dir);
        if !dir.is_dir() {
            println!("skipped: corpus not found");
            return Ok(());
        }
        for (file, keys) in [
            ("20mm_cube.prusaslicer-2.5.gcode", 264),
            ("20mm_cube.slic3r-1.3.gcode", 156),
        ] {
            let g = conduit_gcode::parse(&std::fs::read(dir.join(file))?)?;
            let pairs = pairs_from_gcode(&g);
            assert_eq!(pairs.len(), keys, "{file}");
            let (cfg, warnings) = from_prusa_pairs(pairs)?;
            println!("{file}: {warnings:#?}");
            let s = &cfg.slice;
            assert_eq!(s.layer_height, 0.2, "{file}");
            assert_eq!(s.perimeters, 2);
            assert_eq!(s.perimeter_width, 0.45);
            assert!((s.infill_density - 0.2).abs() < 1e-12);
            assert_eq!(s.perimeter_speed, 60.0);
            assert_eq!(s.external_perimeter_speed, 30.0);
            assert_eq!(s.top_solid_infill_speed, 15.0);
            assert_eq!(cfg.printer.retract_length, 2.0);
            assert_eq!(cfg.printer.retract_speed, 40.0);
            assert_eq!(cfg.printer.bed_size, [250.0, 250.0]);
            assert_eq!(cfg.tools[0].temperature, 210.0);
            assert_eq!(cfg.tools[0].filament_density, 1.24);
            assert!(cfg.printer.start_gcode.starts_with("G28 ; home all axes\n"));
            let ignored = warnings
                .iter()
                .find(|w| w.contains(" PrusaSlicer keys ignored ("))
                .expect("a warning lists the ignored keys");
            let (summary, all) = ignored
                .split_once(IGNORED_LIST_MARK)
                .expect("the full list follows the summary");
            // The summary names only what changes the print; the list has every key.
            assert!(summary.contains("extra_perimeters"), "{file}: {summary}");
            assert!(!summary.contains("gcode_comments"), "{file}: {summary}");
            assert!(all.contains("gcode_comments"), "{file}: {all}");
            let keys: Vec<&str> = all.split(", ").collect();
            let mut sorted = keys.clone();
            sorted.sort_unstable();
            assert_eq!(keys, sorted, "{file}");
        }
        Ok(())
    }

    #[test]
    fn slic3r_env_and_bad_values() -> Result<(), ConfigError> {
        let env = vec![
            ("SLIC3R_LAYER_HEIGHT".to_owned(), "0.3".to_owned()),
            ("SLIC3R_FIRST_LAYER_HEIGHT".to_owned(), "150%".to_owned()),
            ("HOME".to_owned(), "/root".to_owned()),
        ];
        let (cfg, warnings) = from_slic3r_env(env)?;
        assert_eq!(cfg.slice.layer_height, 0.3);
        assert!((cfg.slice.first_layer_height - 0.45).abs() < 1e-12);
        assert!(warnings.is_empty(), "{warnings:?}");
        let err = from_ini_str("# c\n\nperimeters = two\n").err();
        assert!(
            matches!(&err, Some(ConfigError::Ini { line: Some(3), key, .. }) if key == "perimeters"),
            "{err:?}"
        );
        assert!(from_ini_str("printer_technology = SLA").is_err());
        Ok(())
    }

    /// A `.ini` that states a few keys is read as PrusaSlicer reads it: the others take
    /// PrusaSlicer's defaults (as `prusa-slicer --save` writes them), for the mapping and for
    /// the templates, and only the file's own keys are named as ignored.
    #[test]
    fn keys_a_file_leaves_out_take_prusaslicers_defaults() -> Result<(), ConfigError> {
        let (cfg, warnings) = from_ini_str(
            "layer_height = 0.2\nperimeter_generator = classic\ntop_infill_pattern = \
             rectilinear\nbogus = 1\nstart_gcode = M140 S{chamber_minimal_temperature[0]} \
             {if nozzle_high_flow[0] or filament_abrasive[0]}HF{else}std{endif} {z_offset}\n",
        )?;
        // Stated keys keep their values; the rest are PrusaSlicer 2.5's.
        assert_eq!(cfg.slice.layer_height, 0.2);
        assert_eq!(cfg.slice.first_layer_height, 0.35);
        assert_eq!((cfg.slice.perimeters, cfg.slice.top_solid_layers), (3, 3));
        assert_eq!(
            (cfg.printer.bed_size, cfg.printer.bed_origin),
            ([200.0, 200.0], [0.0, 0.0])
        );
        assert_eq!(
            (cfg.tools[0].nozzle_diameter, cfg.tools[0].temperature),
            (0.4, 200.0)
        );
        assert_eq!(
            (cfg.printer.travel_speed, cfg.printer.retract_length),
            (130.0, 2.0)
        );
        assert_eq!((cfg.slice.skirt_loops, cfg.slice.skirt_distance), (1, 6.0));
        // PrusaSlicer's thin_walls is on: the classic generator prints them.
        assert!(cfg.slice.thin_walls);
        // The template finds the keys newer PrusaSlicer profiles name.
        assert_eq!(
            cfg.render_template(&cfg.printer.start_gcode, 0, &[])?,
            "M140 S0 std 0"
        );
        // One warning names the defaults conduit prints otherwise; the top pattern's is not
        // among them (the file states it under Slic3r's name), nor are defaults listed as
        // ignored keys.
        let note = warnings
            .iter()
            .find(|w| w.contains(DEFAULTS_PRINTED_OTHERWISE))
            .map_or("", String::as_str);
        assert!(note.starts_with("3 PrusaSlicer default(s)"), "{warnings:?}");
        for named in [
            "gcode_flavor = reprap",
            "fill_pattern = stars",
            "bottom_fill_pattern",
        ] {
            assert!(note.contains(named), "{note}");
        }
        assert!(!note.contains("top_fill_pattern"), "{note}");
        assert_eq!(
            stated(&warnings),
            ["1 PrusaSlicer key ignored (none that change the print); all of them: bogus"]
        );
        // Other inputs (a host slicer's environment, a 3MF's profile) state every key: no
        // defaults are added to them.
        let (env, _) = from_prusa_pairs([("layer_height".to_owned(), "0.2".to_owned())])?;
        assert_eq!(env.printer.bed_size, Config::default().printer.bed_size);
        Ok(())
    }

    #[test]
    fn filament_gcode_lists_go_to_their_tools() -> Result<(), ConfigError> {
        let (cfg, warnings) = from_ini_str(
            "nozzle_diameter = 0.4,0.4,0.6\n\
             start_filament_gcode = \"M900 K0.05 ; {filament_extruder_id}\\nM142\";M900 K0;\n\
             end_filament_gcode = \"; Filament-specific end gcode\"\n",
        )?;
        assert!(stated(&warnings).is_empty(), "{warnings:?}");
        let starts: Vec<&str> = cfg.tools.iter().map(|t| t.start_gcode.as_str()).collect();
        // Three extruders and the paste tool; a trailing `;` is one more (empty) item.
        assert_eq!(
            starts,
            [
                "M900 K0.05 ; {filament_extruder_id}\nM142",
                "M900 K0",
                "",
                ""
            ]
        );
        // A single value serves every extruder, as PrusaSlicer's `get_at` does; the paste
        // tool keeps its own (none).
        let ends: Vec<&str> = cfg.tools.iter().map(|t| t.end_gcode.as_str()).collect();
        let end = "; Filament-specific end gcode";
        assert_eq!(ends, [end, end, end, ""]);
        Ok(())
    }

    #[test]
    fn toolchange_gcode_becomes_the_before_tool_change_snippet() -> Result<(), ConfigError> {
        let (cfg, warnings) = from_ini_str(
            "toolchange_gcode = G1 Z{layer_z} ; from [previous_extruder]\\nT{next_extruder}\n",
        )?;
        assert_eq!(
            cfg.printer.before_tool_change_gcode,
            "G1 Z{layer_z} ; from [previous_extruder]\nT{next_extruder}"
        );
        assert!(stated(&warnings).is_empty(), "{warnings:?}");
        let vars = [
            ("previous_tool", Var::Scalar(Value::Int(0))),
            ("next_tool", Var::Scalar(Value::Int(1))),
            ("layer_z", Var::Scalar(Value::Float(0.6))),
        ];
        assert_eq!(
            cfg.render_template(&cfg.printer.before_tool_change_gcode, 0, &vars)?,
            "G1 Z0.6 ; from 0\nT1"
        );
        // The indexed form inside an expression, as PrusaSlicer's XL profile writes it.
        let (cfg, _) = from_ini_str(
            "first_layer_temperature = 215,240\n\
             toolchange_gcode = M109 S{first_layer_temperature[next_extruder] - 5}\n",
        )?;
        assert_eq!(
            cfg.render_template(&cfg.printer.before_tool_change_gcode, 0, &vars)?,
            "M109 S235"
        );
        // Macros parse: no warning; a syntax error is named with its line.
        let (_, warnings) = from_ini_str("toolchange_gcode = {if next_extruder==1}T1{endif}\n")?;
        assert!(stated(&warnings).is_empty(), "{warnings:?}");
        let (_, warnings) = from_ini_str("toolchange_gcode = T{next_extruder}\\n{1 +}\n")?;
        assert!(
            warnings.iter().any(|w| w.starts_with(
                "toolchange_gcode: line 2: syntax error: expected an expression in {1 +}"
            )),
            "{warnings:?}"
        );
        Ok(())
    }
}
