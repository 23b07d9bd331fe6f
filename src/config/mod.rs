//! The one configuration of a conduit run: printer, tools and slicing settings, read from a TOML
//! file (or imported from a PrusaSlicer `.ini`), with a documented default for every key.
//!
//! Place in the pipeline: the CLI turns command-line arguments and config files into a validated
//! [`Config`] before any work starts (`design.md`, "Configuration"); every later stage (slice,
//! regions, program, emit, check) reads the parts it needs from it and never parses files itself.
//!
//! # File format
//!
//! ```toml
//! [printer]            # the machine: bed, flavour, start/end G-code, retraction, travel
//! flavor = "marlin"
//!
//! [tools.0]            # one table per tool, numbered from 0 without gaps
//! kind = "filament"
//!
//! [tools.1]
//! kind = "paste"
//!
//! [slice]              # layer heights, perimeters, infill, widths, speeds per role
//! layer_height = 0.2
//! ```
//!
//! Every key may be left out and takes its default; `conduit config --defaults` prints them all
//! with their documentation ([`defaults_toml`]). Unknown keys are errors naming the key, so a
//! typo never passes silently. `[route]` and `[pnp]` configure cavities, trace routing and part
//! placement ([`RouteSettings`], [`PnpSettings`]), `[curved]` curved layers (non-planar tops
//! and curved-layer FFF, [`CurvedSettings`]), `[conform]` conformal printing on scanned
//! surfaces ([`ConformSettings`]), `[jet]` aerosol-jet toolpaths ([`JetSettings`]), `[robot]`
//! robot arms and five-axis machines ([`RobotSettings`]) and `[compensate]` gap compensation
//! of robot paths ([`CompensateSettings`]).
//!
//! A `[tools.N]` table, when present, defines the tools: the tool numbers must run `0, 1, …`
//! without gaps, and every key a table leaves out takes the default *of its kind*
//! ([`Tool::filament`] or [`Tool::paste`]). Without any `[tools.N]` table the two default tools
//! of [`Config::default`] are used.
//!
//! # Units
//!
//! Lengths in millimetres, speeds in mm/s, accelerations in mm/s², temperatures in °C,
//! fan speeds in percent, densities in g/cm³, volumetric flows in mm³/s.

mod defaults;
mod electronics;
pub mod embedded;
pub mod host;
mod prusa_defaults;
pub mod prusa_ini;

pub use crate::circuit::settings::RouteSettings;
pub use crate::conform::{ConformSettings, Corrections, Mapping};
pub use crate::curved::{CurvedMode, CurvedSettings};
pub use crate::emit::robot::{FiveAxis, RobotSettings, RotaryAxes};
pub use crate::jet::{JetFill, JetSettings};
pub use crate::robot::compensate::CompensateSettings;
pub use defaults::defaults_toml;
pub use host::{CURA_KEYS, HostSettings, ORCA_KEYS, Setting, SettingSource};
pub use prusa_ini::from_prusa_pairs;

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use serde::de::{self, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::check::CheckParams;
use crate::curved::CurvedParams;
use crate::emit::gcode::macros::Var;
use crate::emit::gcode::{GcodeParams, SwitchedParams, TemplateError};
use crate::program::Role;
pub use crate::program::machine::{
    DEFAULT_END_GCODE, DEFAULT_START_GCODE, Flavor, LayerGcode, LayerGcodeKind, PnpSettings,
    Printer, Tool, ToolKind,
};
use crate::region::{
    BrimParams, BrimType, InfillPatternKind, MIN_LAYER_HEIGHT, NOZZLE_RANGE, PerimeterGenerator,
    RegionParams, SupportParams,
};
use crate::toolpaths::overhang::DEFAULT_OVERHANG_SPEEDS;
use crate::toolpaths::{
    OrderParams, OverhangParams, ProgramParams, RoleSpeeds, SeamRule, ToolPathParams, TravelParams,
};

/// Fastest speed of any move, mm/s: the fastest FFF printers travel at about 1000 mm/s; a
/// larger number is a typo, and would make every time estimate meaningless.
const MAX_SPEED: f64 = 1000.0;
/// Largest bed side and print height, mm: 10 m covers large-format and construction printers
/// and keeps layer counts and skirt offsets bounded.
const MAX_MACHINE_SIZE: f64 = 10_000.0;
/// Hottest nozzle or bed, °C: high-temperature printers (PEEK, PEI) reach about 450 °C.
const MAX_TEMPERATURE: f64 = 500.0;

/// Everything a conduit run is configured with. See the [module docs](self) for the file format.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    /// The machine (`[printer]`).
    pub printer: Printer,
    /// The tools, indexed by tool number (`[tools.0]`, `[tools.1]`, …); never empty.
    #[serde(with = "tools_table")]
    #[schemars(with = "BTreeMap<String, Tool>")]
    pub tools: Vec<Tool>,
    /// Slicing settings (`[slice]`).
    pub slice: SliceSettings,
    /// Cavities, channels and trace routing (`[route]`).
    pub route: RouteSettings,
    /// Part placement commands (`[pnp]`).
    pub pnp: PnpSettings,
    /// Non-planar top surfaces (`[curved]`).
    pub curved: CurvedSettings,
    /// Conformal printing onto scanned surfaces (`[conform]`).
    pub conform: ConformSettings,
    /// Aerosol-jet toolpaths (`[jet]`).
    pub jet: JetSettings,
    /// Robot arms and five-axis machines (`[robot]`).
    pub robot: RobotSettings,
    /// Gap compensation of robot paths (`[compensate]`).
    pub compensate: CompensateSettings,
    /// Support material, when `slice.support_material` is on (`[support]`).
    pub support: SupportParams,
    /// The wipe tower of multi-tool prints (`[wipe_tower]`).
    pub wipe_tower: crate::toolpaths::TowerParams,
}

/// Pattern of solid (top and bottom) infill.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum SolidPattern {
    /// Parallel lines alternating 90° per layer (the only solid pattern of the regions stage).
    #[default]
    Rectilinear,
}

/// Slicing settings (`[slice]`): perimeters, infill, widths and layer height (from which
/// [`Config::region_params`] builds the regions stage's [`RegionParams`]), first-layer,
/// solid-fill and speed settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct SliceSettings {
    /// Number of perimeter loops per island, the external one included, 0 to 100. Default 2.
    pub perimeters: usize,
    /// Extrusion width of the external (outermost) loop, mm. Every width is at least
    /// `nozzle_diameter`, more than `layer_height` and at most 3 × `nozzle_diameter` (10 mm at
    /// most). Default 0.45.
    pub external_perimeter_width: f64,
    /// Extrusion width of the inner loops, mm. Default 0.45.
    pub perimeter_width: f64,
    /// Extrusion width of sparse infill lines, mm. Default 0.45.
    pub infill_width: f64,
    /// Extrusion width of solid (bottom and internal solid) infill lines, mm. Default 0.45.
    pub solid_infill_width: f64,
    /// Extrusion width of top solid infill lines (the visible upper surfaces), mm. Default 0.45.
    pub top_solid_infill_width: f64,
    /// Extrusion width of every extrusion on the first layer (loops, infill, gap fill, skirt),
    /// mm; a wider first layer sticks better and evens out an uneven bed. Default 0.45.
    pub first_layer_width: f64,
    /// Number of solid layers under every upward-facing surface, 0 to 100. Default 3.
    pub top_solid_layers: usize,
    /// Number of solid layers over every downward-facing surface (and at the bed), 0 to 100.
    /// Default 3.
    pub bottom_solid_layers: usize,
    /// Density of sparse infill, 0 (none) to 1 (solid). Lines are `spacing / density` apart.
    /// Default 0.2.
    pub infill_density: f64,
    /// Pattern of sparse infill. Default `rectilinear`.
    pub infill_pattern: InfillPatternKind,
    /// Base direction of infill lines, degrees counter-clockwise from +X. Default 45.
    pub infill_angle_deg: f64,
    /// How far infill reaches into the innermost perimeter, as a fraction of `perimeter_width`, so
    /// the two bond. Default 0.25 (solid and sparse infill share it, as in PrusaSlicer).
    pub infill_overlap: f64,
    /// How far solid areas are grown into the neighbouring sparse area (mm) so they are anchored
    /// on the infill around them. Internal solid zones are grown by the perimeter band width on
    /// top of this, so they reach under the perimeters of a part standing on them (see
    /// `region::skins`). Default 3, PrusaSlicer's `EXTERNAL_INFILL_MARGIN`: a top skin that
    /// ends flush with the sparse infill below it sags into the gaps at its edge, and a bridge
    /// needs its lines anchored well beyond the edge of the air it spans. 0 to 100 mm.
    pub solid_infill_margin: f64,
    /// Sparse areas smaller than this (mm²) are filled solid instead: in a small area sparse
    /// lines are short, mostly turns and anchors, and add little stiffness, while a solid fill
    /// is barely more material. Default 70 (PrusaSlicer's `solid_infill_below_area`); 0 = off.
    pub solid_infill_below_area: f64,
    /// Fill the strips left between perimeter loops that are too narrow for another loop with
    /// variable-width centrelines ([`crate::region::gapfill`]), so thin walls and the corners of
    /// the perimeter band are solid. Default true.
    pub gap_fill: bool,
    /// Print the external loop of each island first (better dimensional accuracy, worse
    /// overhangs). Default false: inner loops first.
    pub external_perimeters_first: bool,
    /// Where each perimeter loop starts (PrusaSlicer's `seam_position`): `"aligned"` (default)
    /// in an inside corner where the loop has one (turning by 50° or more), else in an outside
    /// corner, else at the rear, so the seams of all layers line up into one line, hidden in a
    /// corner where the part has one; `"rear"` at the rearmost point (largest Y); `"nearest"` at
    /// the point nearest to the nozzle (least travel, seams scattered); `"random"` at a point
    /// that changes from layer to layer.
    pub seam_position: SeamRule,
    /// How far short of its start a perimeter loop ends, as a fraction of `nozzle_diameter`,
    /// 0 to 1 (OrcaSlicer's `seam_gap`; PrusaSlicer clips every loop by 15 %): the bead's round
    /// end meets its start instead of running over it into a blob at the seam. Loops shorter
    /// than ten gaps close fully. Default 0.15; 0 closes every loop.
    pub seam_gap: f64,
    /// How the perimeter band is laid out: `"variable"` (default) keeps loops from running over
    /// themselves and fills what they leave with beads whose number and width follow the wall's
    /// local thickness, so a 0.3 mm fin or a tapering wall prints at its true thickness;
    /// `"classic"` is PrusaSlicer's classic generator (fixed-width loops that may overlap
    /// themselves by 40 % in narrow places, one gap-fill line between loops). PrusaSlicer's
    /// `perimeter_generator = arachne` maps to `"variable"`.
    pub perimeter_generator: PerimeterGenerator,
    /// Print the parts of an island too thin for its external loop (fins, thin walls, the tips
    /// of sharp corners) as variable-width lines along their middle, down to a quarter of the
    /// nozzle and at least 0.85 nozzle diameters wide, instead of leaving them out. Default true
    /// (PrusaSlicer's `thin_walls`; its Arachne generator always does it).
    pub thin_walls: bool,
    /// Number of skirt loops around the first layer, 0 to 100. Default 0 (no skirt).
    pub skirt_loops: usize,
    /// Clear gap between the first layer's islands and the inner edge of the skirt, mm, from 0
    /// to the larger side of `printer.bed_size`. Default 6.
    pub skirt_distance: f64,
    /// Nozzle diameter, mm, 0.05 to 5. Default 0.4. Used by [`RegionParams::validate`]: widths
    /// below it are rejected.
    pub nozzle_diameter: f64,
    /// Layer height, mm, used in the spacing formula when no per-layer heights are given: from
    /// 0.01 to `nozzle_diameter`. Default 0.2.
    pub layer_height: f64,
    /// Height of the first layer, mm, from 0.01 to 2 × `nozzle_diameter`. Default 0.2.
    pub first_layer_height: f64,
    /// Pattern of top solid infill. Default `"rectilinear"`.
    pub top_fill_pattern: SolidPattern,
    /// Pattern of bottom solid infill. Default `"rectilinear"`.
    pub bottom_fill_pattern: SolidPattern,
    /// Build support material under overhangs (how: `[support]`). Default false.
    pub support_material: bool,
    /// Width of the brim on the first layer, mm, from 0 (none) to the larger side of
    /// `printer.bed_size`: `round(brim_width / spacing)` loops (at least one) of the first
    /// layer's perimeter width. Default 0.
    pub brim_width: f64,
    /// Clear gap between the part and the brim's innermost bead, mm (0: the brim touches the
    /// part; a small gap makes it easier to remove). Default 0.
    pub brim_separation: f64,
    /// Where the brim goes: `"outer"` (default) around each island, `"inner"` inside its holes,
    /// `"both"`, or `"ears"`: outside, only within `brim_width` of convex corners sharper than
    /// 125°, where corners lift first.
    pub brim_type: BrimType,
    /// Speed of inner perimeters, mm/s. Every speed is more than 0 and at most 1000 mm/s.
    /// Default 45.
    pub perimeter_speed: f64,
    /// Speed of external perimeters, mm/s. Default 25.
    pub external_perimeter_speed: f64,
    /// Speed of sparse infill, mm/s. Default 80.
    pub infill_speed: f64,
    /// Speed of internal and bottom solid infill, mm/s. Default 40.
    pub solid_infill_speed: f64,
    /// Speed of top solid infill, mm/s. Default 30.
    pub top_solid_infill_speed: f64,
    /// Speed of bridge infill (threads over air), mm/s. Default 60.
    pub bridge_speed: f64,
    /// Speed of gap fill, mm/s. Default 20.
    pub gap_fill_speed: f64,
    /// Speed of every printing move on the first layer, mm/s. Default 20.
    pub first_layer_speed: f64,
    /// Speed of skirt and brim, mm/s. Default 30.
    pub skirt_speed: f64,
    /// Speed of support material (the columns' base), mm/s. Default 50.
    pub support_speed: f64,
    /// Speed of the support's dense interface layers under the part, mm/s. Default 40.
    pub support_interface_speed: f64,
    /// Speed of conductive traces (paste tools), mm/s. Default 10.
    pub conductive_speed: f64,
    /// Print the stretches of a perimeter whose bead lies more than half a nozzle beyond the
    /// layer below as overhang perimeters (`;TYPE:Overhang perimeter`): round threads of the
    /// nozzle's diameter at `bridge_speed` (`overhang_speed_0` with
    /// `dynamic_overhang_speeds`), with `printer.bridge_fan_speed` (PrusaSlicer's `overhangs`).
    /// Default true.
    pub overhangs: bool,
    /// Slow perimeters down by how much of their bead's width hangs out over the layer below
    /// (PrusaSlicer's `enable_dynamic_overhang_speeds`): each stretch resting on less than
    /// 95 %, 75 %, 50 %, 25 % of its width prints at `overhang_speed_3`, `_2`, `_1`, `_0`
    /// (never faster than its own speed). Default true.
    pub dynamic_overhang_speeds: bool,
    /// Speed of perimeters resting on 0 % of their width (in the air) up to 25 %, mm/s.
    /// Default 15 (PrusaSlicer's).
    pub overhang_speed_0: f64,
    /// Speed of perimeters resting on 25 % to 50 % of their width, mm/s. Default 15.
    pub overhang_speed_1: f64,
    /// Speed of perimeters resting on 50 % to 75 % of their width, mm/s. Default 20.
    pub overhang_speed_2: f64,
    /// Speed of perimeters resting on 75 % to 95 % of their width, mm/s. Default 25.
    pub overhang_speed_3: f64,
    /// Tool of each scene object: object `i` prints with tool `object_tools[i]`; objects past the
    /// end of the list use tool 0. Default [] (everything with tool 0).
    pub object_tools: Vec<usize>,
}

/// Calls `$then!` with the names of the `[slice]` keys that are fields of [`RegionParams`]
/// under the same name: the one list behind [`SliceSettings::default`] and
/// [`Config::region_params`].
macro_rules! with_region_keys {
    ($then:ident) => {
        $then!(
            perimeters,
            external_perimeter_width,
            perimeter_width,
            infill_width,
            solid_infill_width,
            top_solid_infill_width,
            first_layer_width,
            top_solid_layers,
            bottom_solid_layers,
            infill_density,
            infill_pattern,
            infill_angle_deg,
            infill_overlap,
            solid_infill_margin,
            solid_infill_below_area,
            gap_fill,
            external_perimeters_first,
            perimeter_generator,
            thin_walls,
            skirt_loops,
            skirt_distance,
            nozzle_diameter,
            layer_height
        )
    };
}

/// Default `slice.seam_gap`: PrusaSlicer's loop clipping, 15 % of the nozzle diameter.
pub const DEFAULT_SEAM_GAP: f64 = 0.15;

impl Default for SliceSettings {
    /// The regions stage's defaults ([`RegionParams::default`]) and conduit's for the rest.
    fn default() -> Self {
        let region = RegionParams::default();
        macro_rules! build {
            ($($key:ident),+) => {
                Self {
                    $($key: region.$key,)+
                    first_layer_height: 0.2,
                    seam_position: SeamRule::Aligned,
                    seam_gap: DEFAULT_SEAM_GAP,
                    top_fill_pattern: SolidPattern::Rectilinear,
                    bottom_fill_pattern: SolidPattern::Rectilinear,
                    support_material: false,
                    brim_width: 0.0,
                    brim_separation: 0.0,
                    brim_type: BrimType::Outer,
                    perimeter_speed: 45.0,
                    external_perimeter_speed: 25.0,
                    infill_speed: 80.0,
                    solid_infill_speed: 40.0,
                    top_solid_infill_speed: 30.0,
                    bridge_speed: 60.0,
                    gap_fill_speed: 20.0,
                    first_layer_speed: 20.0,
                    skirt_speed: 30.0,
                    support_speed: 50.0,
                    support_interface_speed: 40.0,
                    conductive_speed: 10.0,
                    overhangs: true,
                    dynamic_overhang_speeds: true,
                    overhang_speed_0: DEFAULT_OVERHANG_SPEEDS[0],
                    overhang_speed_1: DEFAULT_OVERHANG_SPEEDS[1],
                    overhang_speed_2: DEFAULT_OVERHANG_SPEEDS[2],
                    overhang_speed_3: DEFAULT_OVERHANG_SPEEDS[3],
                    object_tools: Vec::new(),
                }
            };
        }
        with_region_keys!(build)
    }
}

impl Default for Config {
    /// A two-tool printed-electronics printer on a 250 × 250 × 250 mm Marlin machine: tool 0
    /// prints PLA ([`Tool::filament`]), tool 1 dispenses conductive paste ([`Tool::paste`]).
    fn default() -> Self {
        Self {
            printer: Printer::default(),
            tools: vec![Tool::filament(), Tool::paste()],
            slice: SliceSettings::default(),
            route: RouteSettings::default(),
            pnp: PnpSettings::default(),
            curved: CurvedSettings::default(),
            conform: ConformSettings::default(),
            jet: JetSettings::default(),
            robot: RobotSettings::default(),
            compensate: CompensateSettings::default(),
            support: SupportParams::default(),
            wipe_tower: crate::toolpaths::TowerParams::default(),
        }
    }
}

/// Why a configuration could not be read or changed.
///
/// A variant that wraps another error shows it in its own message rather than chaining it as
/// a source, so an error printed with its chain names the cause once.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read.
    ///
    /// How to fix: check the path and the file's permissions.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        error: std::io::Error,
    },
    /// The file's extension is neither `.toml` nor `.ini`.
    ///
    /// How to fix: conduit configs are `.toml`; PrusaSlicer exports (File > Export > Export
    /// Config) are `.ini`.
    #[error("{}: unknown config format (expected a .toml conduit config or a PrusaSlicer .ini)", path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The TOML is malformed, has an unknown key or a value of the wrong type.
    ///
    /// How to fix: compare with `conduit config --defaults`, which lists every key.
    #[error(
        "{}{}: {}",
        file_label(path),
        line.map(|l| format!(":{l}")).unwrap_or_default(),
        keyed(key.as_deref(), message)
    )]
    Toml {
        /// The file, if the TOML came from one.
        path: Option<PathBuf>,
        /// 1-based line of the problem, when known.
        line: Option<usize>,
        /// The dotted key the problem is at (`slice.layer_height`, `tools.1`), when inside a
        /// table; an unknown key is named in the message, under the table that holds it.
        key: Option<String>,
        /// What is wrong.
        message: String,
    },
    /// A `--set KEY=VALUE` could not be applied.
    ///
    /// How to fix: use a dotted key of `conduit config --defaults`, such as
    /// `slice.layer_height=0.3` or `tools.1.temperature=25`.
    #[error("--set {}", keyed(Some(key), message))]
    Set {
        /// The dotted key.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A line of a PrusaSlicer `.ini` has a value that cannot be read.
    ///
    /// How to fix: re-export the profile from PrusaSlicer, or correct the value.
    #[error("{}{}: {key} = {value:?}: {message}", file_label(path), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Ini {
        /// The file, if the settings came from one.
        path: Option<PathBuf>,
        /// 1-based line, when the settings came from a file.
        line: Option<usize>,
        /// The PrusaSlicer key.
        key: String,
        /// The value as written.
        value: String,
        /// What is wrong.
        message: String,
    },
    /// The configuration reads but is not usable.
    ///
    /// How to fix: each problem names its key and the allowed values.
    #[error("invalid config: {}", problems.join("; "))]
    Invalid {
        /// Every problem found.
        problems: Vec<String>,
    },
    /// A G-code template cannot be filled: a placeholder that is not a config key, a profile key
    /// or a variable the caller gives, or a macro with a syntax or type error.
    ///
    /// How to fix: use `{key}` with a `printer` or `slice` key, `{key[N]}` with a tool key (or an
    /// array such as `bed_size[0]`), a key of the imported profile, or one of the variables the
    /// caller documents; correct the macro on the named line.
    #[error("G-code template, {0}")]
    Template(TemplateError),
}

/// `message` about `key`: `slice.layer_height must be …` when the message says what the value
/// must be, `key: message` otherwise.
fn keyed(key: Option<&str>, message: &str) -> String {
    match key {
        Some(k) if message.starts_with("must ") => format!("{k} {message}"),
        Some(k) => format!("{k}: {message}"),
        None => message.to_owned(),
    }
}

fn file_label(path: &Option<PathBuf>) -> String {
    match path {
        Some(p) => p.display().to_string(),
        None => "config".to_owned(),
    }
}

impl ConfigError {
    /// The error of reading `src` (from the file `path`, if any) as a config: the line from the
    /// TOML span, the key from the path serde was at.
    fn from_toml(err: &KeyedTomlError, src: &str, path: Option<&Path>) -> Self {
        let line = err
            .error
            .span()
            .map(|span| src[..span.start.min(src.len())].matches('\n').count() + 1);
        Self::Toml {
            path: path.map(Path::to_path_buf),
            line,
            key: err.key.clone(),
            message: explain(err.error.message().trim(), err.key.as_deref()),
        }
    }

    /// This error with an `.ini` error's file set to `path` (the file the key was read from);
    /// other errors as they are.
    fn in_ini_file(self, path: Option<PathBuf>) -> Self {
        match self {
            Self::Ini {
                line,
                key,
                value,
                message,
                ..
            } => Self::Ini {
                path,
                line,
                key,
                value,
                message,
            },
            other => other,
        }
    }
}

/// serde's message about the value of `key` in words: an unknown key as [`explain_unknown_key`]
/// does, a value of the wrong type or range as what it must be and what it is
/// (`must be a number in mm, got "abc"` for serde's `invalid type: string "abc", expected f64`),
/// with the unit the key's documentation gives; other messages as they are.
fn explain(message: &str, key: Option<&str>) -> String {
    if message.starts_with("unknown field `") {
        return explain_unknown_key(message);
    }
    let unit = key.and_then(defaults::unit_of);
    crate::scene::words::must_be(message, unit).unwrap_or_else(|| message.to_owned())
}

/// serde's "unknown field `x`, expected one of `a`, `b`, …" as "unknown key `x`", with the
/// closest known key of that table when one is close enough to be a typo; other messages as
/// they are.
fn explain_unknown_key(message: &str) -> String {
    let Some(rest) = message.strip_prefix("unknown field `") else {
        return message.to_owned();
    };
    let Some((unknown, expected)) = rest.split_once('`') else {
        return message.to_owned();
    };
    let closest = expected
        .split('`')
        .skip(1)
        .step_by(2)
        .map(|known| (strsim::damerau_levenshtein(unknown, known), known))
        .min();
    match closest {
        // A typo changes a few letters; two thirds of a key changed is another word.
        Some((distance, known)) if distance <= 2.max(unknown.len() / 3) => {
            format!("unknown key `{unknown}`; did you mean `{known}`?")
        }
        _ => format!("unknown key `{unknown}` (`conduit config --defaults` lists every key)"),
    }
}

/// A TOML error and the dotted key serde was reading when it happened.
struct KeyedTomlError {
    error: toml::de::Error,
    key: Option<String>,
}

/// Deserialises a config from TOML, keeping the dotted key of an error.
fn read_toml(src: &str) -> Result<Config, KeyedTomlError> {
    let deserializer =
        toml::Deserializer::parse(src).map_err(|error| KeyedTomlError { error, key: None })?;
    serde_path_to_error::deserialize(deserializer).map_err(|e| {
        let key = e.path().to_string();
        KeyedTomlError {
            key: (key != ".").then_some(key),
            error: e.into_inner(),
        }
    })
}

/// Loads a config file by extension: `.toml` is a conduit config, `.ini` a PrusaSlicer profile
/// (see [`prusa_ini`]). Returns the config and warnings (settings that were ignored or
/// adapted), which the caller should show.
pub fn load(path: &Path) -> Result<(Config, Vec<String>), ConfigError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let text = || {
        std::fs::read_to_string(path).map_err(|error| ConfigError::Io {
            path: path.to_path_buf(),
            error,
        })
    };
    match ext.as_deref() {
        Some("toml") => {
            let src = text()?;
            let config =
                read_toml(&src).map_err(|e| ConfigError::from_toml(&e, &src, Some(path)))?;
            let warnings = config.validate()?;
            Ok((config, warnings))
        }
        Some("ini") => {
            let src = text()?;
            prusa_ini::from_ini_str(&src).map_err(|e| e.in_ini_file(Some(path.to_path_buf())))
        }
        _ => Err(ConfigError::UnknownFormat {
            path: path.to_path_buf(),
        }),
    }
}

impl Config {
    /// Parses a conduit TOML config (no validation beyond types and key names; see
    /// [`Config::validate`]).
    pub fn from_toml_str(src: &str) -> Result<Config, toml::de::Error> {
        toml::from_str(src)
    }

    /// Parses and validates a conduit TOML config, with errors carrying the line. Returns the
    /// config and its warnings.
    pub fn parse(src: &str) -> Result<(Config, Vec<String>), ConfigError> {
        let config = read_toml(src).map_err(|e| ConfigError::from_toml(&e, src, None))?;
        let warnings = config.validate()?;
        Ok((config, warnings))
    }

    /// The config as a TOML document (every key, tools as `[tools.N]` tables).
    pub fn to_toml_string(&self) -> String {
        match toml::to_string(self) {
            Ok(s) => s,
            // Every field is a TOML-representable type; failure would be a bug here.
            Err(e) => panic!("internal error: config does not serialise to TOML: {e}"),
        }
    }

    /// Checks what types alone cannot: at least one tool, tool references in range, the
    /// regions stage's own rules ([`RegionParams::validate`]), positive speeds and heights.
    /// Returns the warnings (usable but suspicious settings) or every error at once.
    pub fn validate(&self) -> Result<Vec<String>, ConfigError> {
        let mut problems = Vec::new();
        let mut warnings = Vec::new();
        if self.tools.is_empty() {
            problems.push("at least one [tools.N] table is needed".to_owned());
        }
        for (i, &t) in self.slice.object_tools.iter().enumerate() {
            if t >= self.tools.len() {
                problems.push(format!(
                    "slice.object_tools[{i}] = {t}, but only tools 0..{} exist",
                    self.tools.len()
                ));
            }
        }
        problems.extend(self.route.problems());
        problems.extend(self.curved.problems());
        problems.extend(self.jet.problems());
        problems.extend(self.robot.problems());
        problems.extend(self.compensate.problems());
        if !(self.pnp.lift.is_finite() && self.pnp.lift >= 0.0) {
            problems.push(format!("pnp.lift must be ≥ 0, got {}", self.pnp.lift));
        }
        for (i, e) in self.printer.custom_gcode_per_print_z.iter().enumerate() {
            if !(e.print_z.is_finite() && e.print_z >= 0.0) {
                problems.push(format!(
                    "printer.custom_gcode_per_print_z[{i}].print_z must be ≥ 0, got {}",
                    e.print_z
                ));
            }
            if let Some(t) = e.tool.filter(|&t| t >= self.tools.len()) {
                problems.push(format!(
                    "printer.custom_gcode_per_print_z[{i}].tool = {t}, but only tools 0..{} exist",
                    self.tools.len()
                ));
            }
        }
        problems.extend(
            self.region_params()
                .validate()
                .into_iter()
                .map(|e| format!("slice.{e}")),
        );
        let s = &self.slice;
        let p = &self.printer;
        problems.extend(self.range_problems());
        let first = [("slice.first_layer_height", s.first_layer_height)];
        let rest = [
            ("printer.max_acceleration", p.max_acceleration),
            ("printer.max_print_speed", p.max_print_speed),
            ("printer.max_height", p.max_height),
            ("printer.bed_size[0]", p.bed_size[0]),
            ("printer.bed_size[1]", p.bed_size[1]),
        ];
        for (key, v) in first.into_iter().chain(self.speed_keys()).chain(rest) {
            if !(v.is_finite() && v > 0.0) {
                problems.push(format!("{key} must be > 0, got {v}"));
            }
        }
        for (i, t) in self.tools.iter().enumerate() {
            for (key, v) in [
                ("nozzle_diameter", t.nozzle_diameter),
                ("filament_diameter", t.filament_diameter),
                ("extrusion_multiplier", t.extrusion_multiplier),
            ] {
                if !(v.is_finite() && v > 0.0) {
                    problems.push(format!("tools.{i}.{key} must be > 0, got {v}"));
                }
            }
        }
        if let Some(t0) = self.tools.first() {
            if (t0.nozzle_diameter - s.nozzle_diameter).abs() > 1e-9 {
                warnings.push(format!(
                    "slice.nozzle_diameter = {} differs from tools.0.nozzle_diameter = {}",
                    s.nozzle_diameter, t0.nozzle_diameter
                ));
            }
        }
        if problems.is_empty() {
            Ok(warnings)
        } else {
            Err(ConfigError::Invalid { problems })
        }
    }

    /// The speeds every print move or travel uses, with their keys: each must be positive
    /// and at most [`MAX_SPEED`].
    fn speed_keys(&self) -> [(&'static str, f64); 18] {
        let s = &self.slice;
        let p = &self.printer;
        [
            ("slice.perimeter_speed", s.perimeter_speed),
            ("slice.external_perimeter_speed", s.external_perimeter_speed),
            ("slice.infill_speed", s.infill_speed),
            ("slice.solid_infill_speed", s.solid_infill_speed),
            ("slice.top_solid_infill_speed", s.top_solid_infill_speed),
            ("slice.bridge_speed", s.bridge_speed),
            ("slice.gap_fill_speed", s.gap_fill_speed),
            ("slice.first_layer_speed", s.first_layer_speed),
            ("slice.skirt_speed", s.skirt_speed),
            ("slice.support_speed", s.support_speed),
            ("slice.support_interface_speed", s.support_interface_speed),
            ("slice.conductive_speed", s.conductive_speed),
            ("slice.overhang_speed_0", s.overhang_speed_0),
            ("slice.overhang_speed_1", s.overhang_speed_1),
            ("slice.overhang_speed_2", s.overhang_speed_2),
            ("slice.overhang_speed_3", s.overhang_speed_3),
            ("printer.travel_speed", p.travel_speed),
            ("printer.retract_speed", p.retract_speed),
        ]
    }

    /// The upper (and lower) bounds of the keys that size work, beyond the positivity checks
    /// of [`Config::validate`]: a number a real printer never uses (10¹⁸ perimeters, 10⁻⁹ mm
    /// layers, 10⁸ skirt loops) would otherwise turn into billions of loops or layers.
    fn range_problems(&self) -> Vec<String> {
        let s = &self.slice;
        let p = &self.printer;
        let mut problems = Vec::new();
        let nozzle = if (NOZZLE_RANGE[0]..=NOZZLE_RANGE[1]).contains(&s.nozzle_diameter) {
            s.nozzle_diameter
        } else {
            NOZZLE_RANGE[1]
        };
        // A thick first layer evens out an uneven bed (PrusaSlicer's `150%` of a 0.3 mm layer
        // is 0.45 mm on a 0.4 mm nozzle); past two nozzle diameters the bead is no longer
        // pressed onto the bed.
        let max_first = ((2.0 * nozzle) * 1e6).round() / 1e6;
        let h = s.first_layer_height;
        if h > 0.0 && !(MIN_LAYER_HEIGHT..=max_first).contains(&h) {
            problems.push(format!(
                "slice.first_layer_height must be between {MIN_LAYER_HEIGHT} mm and \
                 2 × slice.nozzle_diameter ({max_first} mm), got {h}"
            ));
        }
        let more = [
            ("printer.deretract_speed", p.deretract_speed),
            ("printer.max_print_speed", p.max_print_speed),
        ];
        for (key, v) in self.speed_keys().into_iter().chain(more) {
            if v > MAX_SPEED {
                problems.push(format!("{key} must be at most {MAX_SPEED} mm/s, got {v}"));
            }
        }
        for (key, v) in [
            ("printer.bed_size[0]", p.bed_size[0]),
            ("printer.bed_size[1]", p.bed_size[1]),
            ("printer.max_height", p.max_height),
        ] {
            if v > MAX_MACHINE_SIZE {
                problems.push(format!(
                    "{key} must be at most {MAX_MACHINE_SIZE} mm, got {v}"
                ));
            }
        }
        if !(0.0..=1.0).contains(&s.seam_gap) {
            problems.push(format!(
                "slice.seam_gap must be between 0 and 1 (a fraction of slice.nozzle_diameter), \
                 got {}",
                s.seam_gap
            ));
        }
        // A skirt farther out than the bed is wide would be printed off the bed.
        let bed = p.bed_size[0].max(p.bed_size[1]);
        if s.skirt_distance > bed {
            problems.push(format!(
                "slice.skirt_distance must be at most the bed size ({bed} mm), got {}",
                s.skirt_distance
            ));
        }
        for (key, v) in [
            ("slice.brim_width", s.brim_width),
            ("slice.brim_separation", s.brim_separation),
        ] {
            if !(v.is_finite() && (0.0..=bed).contains(&v)) {
                problems.push(format!(
                    "{key} must be between 0 and the bed size ({bed} mm), got {v}"
                ));
            }
        }
        problems.extend(self.support.problems());
        problems.extend(self.wipe_tower.problems());
        for (key, v) in [
            ("printer.bed_temperature", p.bed_temperature),
            (
                "printer.first_layer_bed_temperature",
                p.first_layer_bed_temperature,
            ),
        ] {
            if !(0.0..=MAX_TEMPERATURE).contains(&v) {
                problems.push(format!(
                    "{key} must be between 0 and {MAX_TEMPERATURE} °C, got {v}"
                ));
            }
        }
        for (key, v) in [
            ("printer.bed_origin[0]", p.bed_origin[0]),
            ("printer.bed_origin[1]", p.bed_origin[1]),
            ("printer.retract_length", p.retract_length),
            ("printer.retract_before_travel", p.retract_before_travel),
            ("printer.retract_lift", p.retract_lift),
            ("printer.fan_min_speed", p.fan_min_speed),
            ("printer.fan_max_speed", p.fan_max_speed),
            ("slice.infill_angle_deg", s.infill_angle_deg),
        ] {
            if !v.is_finite() {
                problems.push(format!("{key} must be a finite number, got {v}"));
            }
        }
        for (key, v) in [
            ("printer.bridge_fan_speed", p.bridge_fan_speed),
            ("printer.overhang_fan_speed_0", p.overhang_fan_speed_0),
            ("printer.overhang_fan_speed_1", p.overhang_fan_speed_1),
            ("printer.overhang_fan_speed_2", p.overhang_fan_speed_2),
            ("printer.overhang_fan_speed_3", p.overhang_fan_speed_3),
        ] {
            if !(0.0..=100.0).contains(&v) {
                problems.push(format!("{key} must be between 0 and 100 %, got {v}"));
            }
        }
        for (key, v) in [
            (
                "printer.slowdown_below_layer_time",
                p.slowdown_below_layer_time,
            ),
            ("printer.fan_below_layer_time", p.fan_below_layer_time),
            ("printer.min_print_speed", p.min_print_speed),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                problems.push(format!("{key} must be a finite number ≥ 0, got {v}"));
            }
        }
        for (i, t) in self.tools.iter().enumerate() {
            for (key, v) in [
                ("temperature", Some(t.temperature)),
                ("first_layer_temperature", Some(t.first_layer_temperature)),
                ("standby_temperature", t.standby_temperature),
            ] {
                if let Some(v) = v
                    && !(0.0..=MAX_TEMPERATURE).contains(&v)
                {
                    problems.push(format!(
                        "tools.{i}.{key} must be between 0 and {MAX_TEMPERATURE} °C, got {v}"
                    ));
                }
            }
            for (key, v) in [
                ("offset[0]", Some(t.offset[0])),
                ("offset[1]", Some(t.offset[1])),
                ("filament_density", Some(t.filament_density)),
                ("paste_flow_mm3_s", Some(t.paste_flow_mm3_s)),
                ("retract_length", t.retract_length),
                ("travel_lift", t.travel_lift),
            ] {
                if let Some(v) = v
                    && !v.is_finite()
                {
                    problems.push(format!("tools.{i}.{key} must be a finite number, got {v}"));
                }
            }
        }
        problems
    }

    /// The tool that prints scene object `object` (see [`SliceSettings::object_tools`]).
    pub fn tool_for_object(&self, object: usize) -> usize {
        self.slice.object_tools.get(object).copied().unwrap_or(0)
    }

    /// The G-code writer's parameters: the printer, the tools, the part-placement commands and,
    /// for the custom G-code templates, the `[slice]` keys.
    pub fn gcode_params(&self) -> GcodeParams {
        let template_keys = match toml::Value::try_from(&self.slice) {
            Ok(toml::Value::Table(t)) => t,
            _ => toml::Table::new(),
        };
        GcodeParams {
            printer: self.printer.clone(),
            tools: self.tools.clone(),
            pnp: self.pnp.clone(),
            template_keys,
            switched: None,
        }
    }

    /// The G-code writer's parameters for an aerosol-jet job printing lines `width` mm wide:
    /// the printer and tools of [`Config::gcode_params`], written in the switched-tool style
    /// with the `[jet]` snippets, travel speed, `E` words and arcs (a header note names the
    /// tool, the width, the arcs and the shutter lead).
    pub fn jet_gcode_params(&self, width: f64) -> GcodeParams {
        let jet = &self.jet;
        let note = format!(
            "jet: tool {}, line width {} mm, arcs {}, shutter lead {} s",
            jet.tool,
            conduit_gcode::fmt_xyz(width),
            if jet.arcs { "G2/G3" } else { "flattened" },
            conduit_gcode::fmt_e(jet.shutter_lead_time)
        );
        GcodeParams {
            switched: Some(SwitchedParams {
                job: "jet".to_owned(),
                notes: vec![note],
                start_gcode: jet.start_gcode.clone(),
                end_gcode: jet.end_gcode.clone(),
                on_gcode: jet.shutter_open_gcode.clone(),
                off_gcode: jet.shutter_close_gcode.clone(),
                lead_in_comment: "shutter lead-in".to_owned(),
                travel_speed: jet.travel_speed,
                e_words: jet.e_words,
                arc_chords: (!jet.arcs).then_some(jet.arc_tolerance),
            }),
            ..self.gcode_params()
        }
    }

    /// The regions stage's parameters: the `[slice]` keys of the same names.
    pub fn region_params(&self) -> RegionParams {
        let s = &self.slice;
        macro_rules! build {
            ($($key:ident),+) => {
                RegionParams {
                    $($key: s.$key,)+
                    brim: BrimParams {
                        width: s.brim_width,
                        separation: s.brim_separation,
                        kind: s.brim_type,
                        ..BrimParams::default()
                    },
                    support: SupportParams {
                        enabled: s.support_material,
                        ..self.support.clone()
                    },
                    overhangs: s.overhangs
                        || s.dynamic_overhang_speeds
                        || self.printer.dynamic_fan_speeds,
                }
            };
        }
        with_region_keys!(build)
    }

    /// The curved stages' parameters: `[curved]` and the planar settings they print beside.
    pub fn curved_params(&self) -> CurvedParams {
        CurvedParams {
            curved: self.curved.clone(),
            region: self.region_params(),
            first_layer_height: self.slice.first_layer_height,
            program: self.program_params(),
            bed_origin: self.printer.bed_origin,
            retract_before_travel: self.printer.retract_before_travel,
            tool_count: self.tools.len(),
        }
    }

    /// The toolpaths stage's parameters: role speeds and the first-layer speed from `[slice]`
    /// limited to `printer.max_print_speed`; paste tools print every path as [`Role::ConductiveTrace`] at `slice.conductive_speed`
    /// (also on the first layer, if that is slower than `first_layer_speed`). Ordering and
    /// start position take their defaults.
    pub fn program_params(&self) -> ProgramParams {
        let s = &self.slice;
        let max = self.printer.max_print_speed;
        let speeds = RoleSpeeds {
            external_perimeter: s.external_perimeter_speed,
            perimeter: s.perimeter_speed,
            solid_infill: s.solid_infill_speed,
            top_solid_infill: s.top_solid_infill_speed,
            sparse_infill: s.infill_speed,
            bridge: s.bridge_speed,
            gap_fill: s.gap_fill_speed,
            skirt: s.skirt_speed,
            support: s.support_speed,
            support_interface: s.support_interface_speed,
            conductive: s.conductive_speed,
        }
        .clamped(max);
        let tools = self
            .tools
            .iter()
            .map(|t| {
                let base = ToolPathParams {
                    speeds,
                    first_layer_speed: s.first_layer_speed.min(max),
                    ..ToolPathParams::default()
                };
                match t.kind {
                    ToolKind::Filament => base,
                    ToolKind::Paste => ToolPathParams {
                        role: Some(Role::ConductiveTrace),
                        first_layer_speed: base.first_layer_speed.min(speeds.conductive),
                        ..base
                    },
                }
            })
            .collect();
        ProgramParams {
            tools,
            order: OrderParams {
                seam: s.seam_position,
                ..OrderParams::default()
            },
            seam_gap: s.seam_gap * s.nozzle_diameter,
            overhang: self.overhang_params(),
            travel: TravelParams {
                only_retract_when_crossing_perimeters: self
                    .printer
                    .only_retract_when_crossing_perimeters,
                min_length: self.printer.retract_before_travel,
            },
            ..ProgramParams::default()
        }
    }

    /// The wipe tower's settings as printed: `[wipe_tower]` with its speed held to
    /// `printer.max_print_speed`, like every print speed.
    pub fn tower_params(&self) -> crate::toolpaths::TowerParams {
        crate::toolpaths::TowerParams {
            speed: self.wipe_tower.speed.min(self.printer.max_print_speed),
            ..self.wipe_tower.clone()
        }
    }

    /// What the wipe tower pass needs of the machine: the bed, which tools are filament tools,
    /// their bead width on the tower (`slice.infill_width`) and the first layer's speed.
    pub fn tower_machine(&self) -> crate::toolpaths::TowerMachine {
        let p = &self.printer;
        crate::toolpaths::TowerMachine {
            bed: [
                p.bed_origin[0],
                p.bed_origin[1],
                p.bed_origin[0] + p.bed_size[0],
                p.bed_origin[1] + p.bed_size[1],
            ],
            filament: self
                .tools
                .iter()
                .map(|t| t.kind == ToolKind::Filament)
                .collect(),
            width: vec![self.slice.infill_width; self.tools.len()],
            first_layer_speed: self.slice.first_layer_speed.min(p.max_print_speed),
        }
    }

    /// How perimeters over air and bridges print: `slice.overhangs`, the dynamic overhang
    /// speeds (limited to `printer.max_print_speed`) and the bridge and overhang fans.
    pub fn overhang_params(&self) -> OverhangParams {
        let s = &self.slice;
        let p = &self.printer;
        let max = p.max_print_speed;
        OverhangParams {
            bridging: s.overhangs,
            speeds: s.dynamic_overhang_speeds.then(|| {
                [
                    s.overhang_speed_0,
                    s.overhang_speed_1,
                    s.overhang_speed_2,
                    s.overhang_speed_3,
                ]
                .map(|v| v.min(max))
            }),
            fans: p.dynamic_fan_speeds.then_some([
                p.overhang_fan_speed_0,
                p.overhang_fan_speed_1,
                p.overhang_fan_speed_2,
                p.overhang_fan_speed_3,
            ]),
            bridge_fan: p.bridge_fan_speed,
            bridge_width: s.nozzle_diameter,
        }
    }

    /// The replay checker's parameters: the printer and the tools, with the default thresholds.
    pub fn check_params(&self) -> CheckParams {
        CheckParams::for_machine(&self.printer, &self.tools)
    }

    /// Fills the `{placeholders}` of `template` for tool `tool` as the G-code writer does
    /// ([`GcodeParams::render_template`]), with the caller's extra variables `vars` (such as
    /// `previous_tool`, `next_tool`, `layer_z`) taking precedence over config keys.
    ///
    /// ```
    /// let cfg = conduit::config::Config::default();
    /// let g = cfg.render_template("M190 S{first_layer_bed_temperature}\nM109 S[temperature]", 0, &[])?;
    /// assert_eq!(g, "M190 S60\nM109 S210");
    /// # Ok::<(), conduit::config::ConfigError>(())
    /// ```
    pub fn render_template(
        &self,
        template: &str,
        tool: usize,
        vars: &[(&str, Var)],
    ) -> Result<String, ConfigError> {
        self.gcode_params()
            .render_template(template, tool, vars)
            .map_err(ConfigError::Template)
    }

    /// Applies one `KEY=VALUE` override, as given to `--set`: `KEY` is a dotted path into the
    /// TOML tree (`slice.layer_height`, `tools.1.temperature`, `printer.bed_size`), `VALUE` is a
    /// TOML value (`0.3`, `[200, 200]`, `"klipper"`; a bare word that is not valid TOML is taken
    /// as a string, so `printer.flavor=klipper` works). Unknown keys and wrong types are errors
    /// naming the key; the config is unchanged on error.
    pub fn apply_set(&mut self, key_value: &str) -> Result<(), ConfigError> {
        let (key, value) = key_value.split_once('=').ok_or_else(|| ConfigError::Set {
            key: key_value.to_owned(),
            message: "expected KEY=VALUE".to_owned(),
        })?;
        let key = key.trim();
        let value = value.trim();
        let set_err = |message: String| ConfigError::Set {
            key: key.to_owned(),
            message,
        };
        let parsed: toml::Value = match toml::from_str::<toml::Table>(&format!("v = {value}")) {
            Ok(mut t) => t
                .remove("v")
                .ok_or_else(|| set_err("no value".to_owned()))?,
            Err(_) => toml::Value::String(value.to_owned()),
        };
        let mut tree = toml::Value::try_from(&*self)
            .map_err(|e| set_err(format!("internal error serialising the config: {e}")))?;
        let parts: Vec<&str> = key.split('.').map(str::trim).collect();
        if parts.iter().any(|p| p.is_empty()) {
            return Err(set_err("empty key segment".to_owned()));
        }
        let mut node = &mut tree;
        for (i, part) in parts.iter().enumerate() {
            let here = parts[..i].join(".");
            let table = node.as_table_mut().ok_or_else(|| {
                set_err(format!(
                    "`{here}` is a value, not a table, so `{part}` cannot be set in it"
                ))
            })?;
            if i + 1 == parts.len() {
                table.insert((*part).to_owned(), parsed);
                break;
            }
            // A new table may only be a new tool (`tools.2.kind=paste`); any other missing
            // table is an unknown key.
            if !table.contains_key(*part) {
                if here == "tools" {
                    table.insert((*part).to_owned(), toml::Value::Table(toml::Table::new()));
                } else {
                    return Err(set_err(format!("unknown key `{}`", parts[..=i].join("."))));
                }
            }
            node = table
                .get_mut(*part)
                .ok_or_else(|| set_err("internal error walking the key".to_owned()))?;
        }
        let new: Config = tree
            .try_into()
            .map_err(|e: toml::de::Error| set_err(explain(e.message().trim(), Some(key))))?;
        *self = new;
        Ok(())
    }
}

/// The keys of a `[tools.N]` table, every one optional: what is left out comes from the
/// kind's default tool.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ToolSpec {
    name: Option<String>,
    kind: Option<ToolKind>,
    nozzle_diameter: Option<f64>,
    filament_diameter: Option<f64>,
    filament_density: Option<f64>,
    temperature: Option<f64>,
    first_layer_temperature: Option<f64>,
    standby_temperature: Option<f64>,
    offset: Option<[f64; 2]>,
    extrusion_multiplier: Option<f64>,
    paste_on_gcode: Option<String>,
    paste_off_gcode: Option<String>,
    paste_flow_mm3_s: Option<f64>,
    retract_length: Option<f64>,
    travel_lift: Option<f64>,
    start_gcode: Option<String>,
    end_gcode: Option<String>,
}

impl<'de> Deserialize<'de> for Tool {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let s = ToolSpec::deserialize(deserializer)?;
        let d = Tool::of_kind(s.kind.unwrap_or_default());
        Ok(Tool {
            name: s.name.unwrap_or(d.name),
            kind: d.kind,
            nozzle_diameter: s.nozzle_diameter.unwrap_or(d.nozzle_diameter),
            filament_diameter: s.filament_diameter.unwrap_or(d.filament_diameter),
            filament_density: s.filament_density.unwrap_or(d.filament_density),
            temperature: s.temperature.unwrap_or(d.temperature),
            first_layer_temperature: s
                .first_layer_temperature
                .unwrap_or(d.first_layer_temperature),
            standby_temperature: s.standby_temperature.or(d.standby_temperature),
            offset: s.offset.unwrap_or(d.offset),
            extrusion_multiplier: s.extrusion_multiplier.unwrap_or(d.extrusion_multiplier),
            paste_on_gcode: s.paste_on_gcode.unwrap_or(d.paste_on_gcode),
            paste_off_gcode: s.paste_off_gcode.unwrap_or(d.paste_off_gcode),
            paste_flow_mm3_s: s.paste_flow_mm3_s.unwrap_or(d.paste_flow_mm3_s),
            retract_length: s.retract_length.or(d.retract_length),
            travel_lift: s.travel_lift.or(d.travel_lift),
            start_gcode: s.start_gcode.unwrap_or(d.start_gcode),
            end_gcode: s.end_gcode.unwrap_or(d.end_gcode),
        })
    }
}

/// `tools` as `[tools.0]`, `[tools.1]`… tables (an array of tables `[[tools]]` is accepted too).
mod tools_table {
    use super::*;

    pub fn serialize<S: Serializer>(tools: &[Tool], s: S) -> Result<S::Ok, S::Error> {
        s.collect_map(tools.iter().enumerate().map(|(i, t)| (i.to_string(), t)))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Tool>, D::Error> {
        d.deserialize_any(ToolsVisitor)
    }

    struct ToolsVisitor;

    impl<'de> Visitor<'de> for ToolsVisitor {
        type Value = Vec<Tool>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("[tools.N] tables numbered 0, 1, 2…")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<Tool>, A::Error> {
            let mut tools = Vec::new();
            while let Some(t) = seq.next_element()? {
                tools.push(t);
            }
            if tools.is_empty() {
                return Err(de::Error::custom("at least one tool is needed"));
            }
            Ok(tools)
        }

        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Vec<Tool>, A::Error> {
            let mut tools = BTreeMap::new();
            while let Some(key) = map.next_key::<String>()? {
                let n: usize = key.trim().parse().map_err(|_| {
                    de::Error::custom(format!(
                        "`tools.{key}`: tools are numbered, as in [tools.0], [tools.1]"
                    ))
                })?;
                let tool: Tool = map.next_value()?;
                if tools.insert(n, tool).is_some() {
                    return Err(de::Error::custom(format!("tools.{n} is given twice")));
                }
            }
            if tools.is_empty() {
                return Err(de::Error::custom("at least one tool is needed"));
            }
            if let Some(missing) = (0..tools.len()).find(|i| !tools.contains_key(i)) {
                return Err(de::Error::custom(format!(
                    "tools must be numbered 0, 1, 2… without gaps: tools.{missing} is missing \
                     (tools given: {:?})",
                    tools.keys().collect::<Vec<_>>()
                )));
            }
            Ok(tools.into_values().collect())
        }
    }
}

#[cfg(test)]
mod tests;
