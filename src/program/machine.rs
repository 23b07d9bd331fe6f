//! The machine a program runs on: the printer (bed, firmware flavour, custom G-code,
//! retraction, travel, fan), its tools (filament extruders and paste dispensers) and the
//! commands that place parts.
//!
//! Place in the pipeline: vocabulary beside the [`Program`](super::Program). The config's
//! `[printer]`, `[tools.N]` and `[pnp]` sections are these types; the G-code writer
//! (`emit::gcode`), the replay (`check`) and the walks read them from here, so no stage needs
//! the whole configuration to know what machine it drives.

use std::collections::BTreeMap;
use std::fmt;

use serde::{Deserialize, Serialize};

/// G-code dialect of the printer's firmware.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Flavor {
    /// Marlin 1.x / 2.x (also Prusa firmware).
    #[default]
    Marlin,
    /// RepRapFirmware (Duet).
    #[serde(rename = "reprapfirmware")]
    RepRapFirmware,
    /// Klipper.
    Klipper,
}

/// The printer (`[printer]`): bed, firmware, custom G-code, retraction, travel and fan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Printer {
    /// G-code dialect: `"marlin"`, `"reprapfirmware"` or `"klipper"`. Default `"marlin"`.
    pub flavor: Flavor,
    /// Printable bed size [X, Y], mm. Default [250, 250].
    pub bed_size: [f64; 2],
    /// Coordinates of the bed's front-left corner [X, Y], mm: [0, 0] when the origin is at that
    /// corner, [-125, -125] for a 250 mm bed with the origin in its centre. Default [0, 0].
    pub bed_origin: [f64; 2],
    /// Highest printable Z, mm. Default 250.
    pub max_height: f64,
    /// Where `G28` puts the axes [X, Y, Z], mm, as the firmware's endstops do: what `conduit
    /// check` and the replays of conform and the viewer take as the position after homing
    /// (`G28 X Y` homes only the named axes). Absent = the bed's front-left corner at the top,
    /// (`bed_origin[0]`, `bed_origin[1]`, `max_height`) (a Z endstop at the top keeps the
    /// nozzle clear of whatever is on the bed, and so does this default). Default absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(example = [0.0, 0.0, 250.0])]
    pub home: Option<[f64; 3]>,
    /// Bed temperature after the first layer, °C (0 = bed heater off). Default 60.
    pub bed_temperature: f64,
    /// Bed temperature for the first layer, °C. Default 60.
    pub first_layer_bed_temperature: f64,
    /// G-code template written before the print: heats, homes and primes. `{placeholders}` are
    /// filled from this config (see [`Config::render_template`]).
    pub start_gcode: String,
    /// G-code template written after the print: heaters and fan off, lift, home X/Y, motors off.
    pub end_gcode: String,
    /// G-code template written before every tool change (`{previous_tool}` and `{next_tool}`
    /// are available); when it has a `T{next_tool}` line, that line selects the tool and no
    /// other `T` is written. PrusaSlicer's `toolchange_gcode` imports here. Default empty.
    pub before_tool_change_gcode: String,
    /// G-code template written after every tool change (`{previous_tool}` and `{next_tool}` are
    /// available). Default empty.
    pub after_tool_change_gcode: String,
    /// G-code template written at every layer change, after the `;LAYER_CHANGE`, `;Z:` and
    /// `;HEIGHT:` comments and before the move to the new layer (`{layer_num}`, counted from 0,
    /// `{layer_z}` and `{max_layer_z}` are available). PrusaSlicer's `before_layer_gcode`
    /// imports here. Default empty.
    pub before_layer_gcode: String,
    /// G-code template written at every layer change after the move to the new layer, before
    /// its first path (the variables of `before_layer_gcode`). PrusaSlicer's `layer_gcode`
    /// imports here. Default empty.
    pub layer_gcode: String,
    /// G-code template of a colour change (an event of `custom_gcode_per_print_z` with
    /// `type = "color_change"`), with `{color_change_extruder}` the tool whose filament changes
    /// (from 0). PrusaSlicer's `color_change_gcode`. Default `M600`.
    pub color_change_gcode: String,
    /// G-code template of a pause (`type = "pause"`), written after `M117 <message>` when the
    /// pause has a message. PrusaSlicer's `pause_print_gcode`. Default `M601`.
    pub pause_print_gcode: String,
    /// G-code template of an event with `type = "template"`. PrusaSlicer's
    /// `template_custom_gcode`. Default empty.
    pub template_custom_gcode: String,
    /// Colour changes, pauses and custom G-code at given heights (PrusaSlicer's layer slider;
    /// a PrusaSlicer 3MF project's are added), each written once at the start of the first
    /// layer whose top reaches its `print_z`, after the move to that layer: `type` is
    /// `"color_change"` (`;COLOR_CHANGE,T<tool>,<color>` and `color_change_gcode`), `"pause"`
    /// (`;PAUSE_PRINT`, `M117 <extra>`, `pause_print_gcode`), `"template"`
    /// (`template_custom_gcode`) or `"custom"` (the G-code in `extra`). Default none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    #[schemars(example = layer_gcode_example())]
    pub custom_gcode_per_print_z: Vec<LayerGcode>,
    /// Filament pulled back before travels, mm (a tool's own `retract_length` overrides it).
    /// Default 0.8.
    pub retract_length: f64,
    /// Speed of the retraction, mm/s of filament. Default 35.
    pub retract_speed: f64,
    /// Speed of the un-retraction, mm/s of filament; 0 = the same as `retract_speed`. Default 0.
    pub deretract_speed: f64,
    /// Travels shorter than this do not retract, mm. Default 2.
    pub retract_before_travel: f64,
    /// Retract only for travels that cross a perimeter or leave the internal infill: a travel
    /// that stays inside an island's sparse or internal solid infill does not retract, however
    /// long, since what oozes there is covered by the next layers (PrusaSlicer's
    /// `only_retract_when_crossing_perimeters`, stricter: the travel must not touch a
    /// perimeter). Travels over top, bottom and bridge surfaces still retract. Default true.
    pub only_retract_when_crossing_perimeters: bool,
    /// Z lift (z-hop) during retracted travels, mm; 0 = none. Default 0.
    pub retract_lift: f64,
    /// Speed of non-printing moves, mm/s. Default 130.
    pub travel_speed: f64,
    /// Acceleration of the machine, mm/s², used by time estimates. Default 1000.
    pub max_acceleration: f64,
    /// Highest speed of any printing move, mm/s; faster role speeds are clamped to it.
    /// Default 200.
    pub max_print_speed: f64,
    /// Write E as relative distances (`M83`) instead of absolute positions (`M82`).
    /// Default false.
    pub use_relative_e_distances: bool,
    /// Lowest part-cooling fan speed when the fan is on, percent. Default 35.
    pub fan_min_speed: f64,
    /// Highest part-cooling fan speed, percent. Default 100.
    pub fan_max_speed: f64,
    /// Number of bottom layers printed with the fan off. Default 1.
    pub disable_fan_first_layers: usize,
    /// Layers whose printing would take less than this (s) are slowed down to take it, so each
    /// layer cools before the next is laid on it, and get the fan at `fan_max_speed`
    /// (PrusaSlicer's `slowdown_below_layer_time`); 0 = never slow down. Default 5.
    pub slowdown_below_layer_time: f64,
    /// Slowest a slowed-down layer is printed, mm/s (PrusaSlicer's `min_print_speed`); moves
    /// already slower keep their speed. Default 10.
    pub min_print_speed: f64,
    /// Layers taking longer than this (s) get the fan at `fan_min_speed`; between this and
    /// `slowdown_below_layer_time` the fan runs in proportion (PrusaSlicer's
    /// `fan_below_layer_time`). Default 60.
    pub fan_below_layer_time: f64,
    /// Fan speed during bridge infill and overhang perimeters, percent, when it is above the
    /// layer's (PrusaSlicer's `bridge_fan_speed`); 0: the layer's. Default 100.
    pub bridge_fan_speed: f64,
    /// Give overhanging perimeters a fan of their own by how far they hang out
    /// (`overhang_fan_speed_0..3`; PrusaSlicer's `enable_dynamic_fan_speeds`). Default false.
    pub dynamic_fan_speeds: bool,
    /// With `dynamic_fan_speeds`: fan speed for perimeters resting on 0 % of their width on the
    /// layer below (in the air), percent, or the layer's when higher. Default 0.
    pub overhang_fan_speed_0: f64,
    /// Fan speed for perimeters with 25 % of their width on the layer below (or less, down to
    /// 0 %), percent. Default 0.
    pub overhang_fan_speed_1: f64,
    /// Fan speed for perimeters with 50 % of their width on the layer below (down to 25 %),
    /// percent. Default 0.
    pub overhang_fan_speed_2: f64,
    /// Fan speed for perimeters with 75 % of their width on the layer below (down to 50 %),
    /// and those hanging out by more than 5 % of it, percent. Default 0.
    pub overhang_fan_speed_3: f64,
    /// Retract with the firmware's `G10`/`G11` instead of E moves. Default false.
    pub use_firmware_retraction: bool,
    /// The settings of the slicer profile the printer was imported from (a PrusaSlicer `.ini`,
    /// or the profile a 3MF stores), key → value as written there: variables the macros of the
    /// G-code templates read beside conduit's own keys (`{filament_type[0]}`, `{z_offset}`).
    /// Default empty.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    #[schemars(example = profile_example())]
    pub profile: BTreeMap<String, String>,
}

/// What a [`LayerGcode`] does.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum LayerGcodeKind {
    /// A filament change: `;COLOR_CHANGE,T<extruder>,<color>`, then
    /// `printer.color_change_gcode`.
    #[default]
    ColorChange,
    /// A pause: `;PAUSE_PRINT`, `M117 <extra>` when there is a message, then
    /// `printer.pause_print_gcode`.
    Pause,
    /// `;CUSTOM_GCODE`, then `printer.template_custom_gcode`.
    Template,
    /// `;CUSTOM_GCODE`, then the event's own G-code (`extra`).
    Custom,
}

/// One event of `printer.custom_gcode_per_print_z`: G-code written at the start of a layer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LayerGcode {
    /// Height, mm: the event comes before the first layer whose top is at or above it
    /// (within 0.1 µm), as PrusaSlicer places it.
    pub print_z: f64,
    /// What it does: `"color_change"`, `"pause"`, `"template"` or `"custom"`.
    #[serde(rename = "type")]
    pub kind: LayerGcodeKind,
    /// The tool whose filament changes (colour changes), from 0; absent = the tool printing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool: Option<usize>,
    /// The new filament's colour (`#RRGGBB`), written in the `;COLOR_CHANGE` tag.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub color: String,
    /// The pause's message, or the custom G-code.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub extra: String,
}

/// The example of [`Printer::custom_gcode_per_print_z`] in the documented defaults.
fn layer_gcode_example() -> Vec<LayerGcode> {
    vec![LayerGcode {
        print_z: 2.2,
        kind: LayerGcodeKind::ColorChange,
        tool: Some(0),
        color: "#FF0000".to_owned(),
        extra: String::new(),
    }]
}

/// What a tool deposits and therefore how it is driven.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum ToolKind {
    /// A filament extruder: flow is E distance, computed from the cross-section of the
    /// extrusion and the filament diameter.
    #[default]
    Filament,
    /// A paste dispenser (pneumatic or screw): switched on and off by G-code snippets, flow is
    /// time-based (`paste_flow_mm3_s`).
    Paste,
}

/// One tool (`[tools.N]`). Keys left out take the default of the tool's `kind`:
/// [`Tool::filament`] or [`Tool::paste`].
#[derive(Debug, Clone, PartialEq, Serialize, schemars::JsonSchema)]
pub struct Tool {
    /// Name shown in comments and reports. Default `"PLA"` (filament) / `"conductive paste"`.
    pub name: String,
    /// `"filament"` or `"paste"`. Default `"filament"`.
    pub kind: ToolKind,
    /// Nozzle (or needle) inner diameter, mm. Default 0.4.
    pub nozzle_diameter: f64,
    /// Filament diameter, mm (filament tools). Default 1.75.
    pub filament_diameter: f64,
    /// Density of the material, g/cm³, for the weight estimate. Default 1.24 (PLA) / 3.0
    /// (silver-filled paste).
    pub filament_density: f64,
    /// Nozzle temperature after the first layer, °C; 0 = not heated. Default 210 (filament) /
    /// 0 (paste).
    pub temperature: f64,
    /// Nozzle temperature for the first layer, °C; 0 = not heated. Default 210 / 0.
    pub first_layer_temperature: f64,
    /// Temperature while the tool is parked during another tool's work, °C; absent = keep
    /// `temperature`. Default absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(example = 150.0)]
    pub standby_temperature: Option<f64>,
    /// Offset of this tool's nozzle from tool 0's [X, Y], mm, when the firmware does not apply
    /// it. Default [0, 0].
    pub offset: [f64; 2],
    /// Factor on the computed flow. Default 1.0.
    pub extrusion_multiplier: f64,
    /// G-code that starts the paste flow (pressure valve or screw on), paste tools. Default
    /// `M42 P6 S255` (drive output pin 6 high: wire the dispenser's trigger to a free output
    /// and set its pin here).
    pub paste_on_gcode: String,
    /// G-code that stops the paste flow, paste tools. Default `M42 P6 S0`.
    pub paste_off_gcode: String,
    /// Volume dispensed per second while the paste flow is on, mm³/s (paste tools; filament
    /// tools 0). Default 0.5.
    pub paste_flow_mm3_s: f64,
    /// This tool's retraction length, mm, overriding `printer.retract_length`; absent = use the
    /// printer's. Default absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(example = 1.0)]
    pub retract_length: Option<f64>,
    /// Z lift during this tool's travels longer than `printer.retract_before_travel`, mm,
    /// overriding `printer.retract_lift`; absent = use the printer's. The paste tool's default
    /// is 0.5: a dispensing nozzle dragged from one trace to the next at the layer's top would
    /// smear the paste it just laid. Filament default absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(example = 0.5)]
    pub travel_lift: Option<f64>,
    /// G-code written each time this tool is selected, once it is at temperature: after the
    /// start G-code for the first tool, after the tool-change snippets for the others
    /// (PrusaSlicer's `start_filament_gcode`, where profiles set linear or pressure advance).
    /// The template language of `printer.start_gcode`, with `{filament_extruder_id}` this
    /// tool's number. Default empty.
    pub start_gcode: String,
    /// G-code written when this tool is put away: before the tool-change snippets, and at the
    /// end of the print before `printer.end_gcode` for every tool that has one, in tool order
    /// (PrusaSlicer's `end_filament_gcode`). Default empty.
    pub end_gcode: String,
}

/// The example of [`Printer::profile`] in the documented defaults.
fn profile_example() -> BTreeMap<String, String> {
    [("filament_type", "PETG"), ("z_offset", "0")]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v.to_owned()))
        .collect()
}

impl Printer {
    /// Where `G28` puts the axes: `home`, or the bed's front-left corner at `max_height`.
    pub fn home_position(&self) -> [f64; 3] {
        self.home
            .unwrap_or([self.bed_origin[0], self.bed_origin[1], self.max_height])
    }
}

impl Default for Printer {
    fn default() -> Self {
        Self {
            flavor: Flavor::Marlin,
            bed_size: [250.0, 250.0],
            bed_origin: [0.0, 0.0],
            max_height: 250.0,
            home: None,
            bed_temperature: 60.0,
            first_layer_bed_temperature: 60.0,
            start_gcode: DEFAULT_START_GCODE.to_owned(),
            end_gcode: DEFAULT_END_GCODE.to_owned(),
            before_tool_change_gcode: String::new(),
            after_tool_change_gcode: String::new(),
            before_layer_gcode: String::new(),
            layer_gcode: String::new(),
            color_change_gcode: "M600".to_owned(),
            pause_print_gcode: "M601".to_owned(),
            template_custom_gcode: String::new(),
            custom_gcode_per_print_z: Vec::new(),
            retract_length: 0.8,
            retract_speed: 35.0,
            deretract_speed: 0.0,
            retract_before_travel: 2.0,
            only_retract_when_crossing_perimeters: true,
            retract_lift: 0.0,
            travel_speed: 130.0,
            max_acceleration: 1000.0,
            max_print_speed: 200.0,
            use_relative_e_distances: false,
            fan_min_speed: 35.0,
            fan_max_speed: 100.0,
            disable_fan_first_layers: 1,
            slowdown_below_layer_time: 5.0,
            min_print_speed: 10.0,
            fan_below_layer_time: 60.0,
            bridge_fan_speed: 100.0,
            dynamic_fan_speeds: false,
            overhang_fan_speed_0: 0.0,
            overhang_fan_speed_1: 0.0,
            overhang_fan_speed_2: 0.0,
            overhang_fan_speed_3: 0.0,
            use_firmware_retraction: false,
            profile: BTreeMap::new(),
        }
    }
}

/// Default `printer.start_gcode`: heat bed and tool 0, home, wait, prime a line along the front
/// edge of the bed.
pub const DEFAULT_START_GCODE: &str = "\
M140 S{first_layer_bed_temperature} ; bed heating
M104 T0 S{first_layer_temperature[0]} ; tool 0 heating
G28 ; home all axes
M190 S{first_layer_bed_temperature} ; wait for the bed
M109 T0 S{first_layer_temperature[0]} ; wait for tool 0
G92 E0
G1 Z{first_layer_height} F720
G1 X5 Y5 F6000
G1 X60 Y5 E9 F1000 ; prime line
G92 E0
";

/// Default `printer.end_gcode`: heaters and fan off, lift by 10 mm, home X/Y, motors off.
pub const DEFAULT_END_GCODE: &str = "\
M104 T0 S0 ; tool 0 heater off
M140 S0 ; bed heater off
M107 ; fan off
G91
G1 Z10 F600 ; lift
G90
G28 X Y
M84 ; motors off
";

/// Z lift of the paste tool's travels by default, mm (see [`Tool::travel_lift`]).
const PASTE_TRAVEL_LIFT_MM: f64 = 0.5;

impl Tool {
    /// The default filament tool: PLA, 1.75 mm, 0.4 mm nozzle, 210 °C.
    pub fn filament() -> Self {
        Self {
            name: "PLA".to_owned(),
            kind: ToolKind::Filament,
            nozzle_diameter: 0.4,
            filament_diameter: 1.75,
            filament_density: 1.24,
            temperature: 210.0,
            first_layer_temperature: 210.0,
            standby_temperature: None,
            offset: [0.0, 0.0],
            extrusion_multiplier: 1.0,
            paste_on_gcode: String::new(),
            paste_off_gcode: String::new(),
            paste_flow_mm3_s: 0.0,
            retract_length: None,
            travel_lift: None,
            start_gcode: String::new(),
            end_gcode: String::new(),
        }
    }

    /// The default paste tool: an unheated conductive-paste dispenser with a 0.4 mm needle,
    /// switched by output pin 6 (`M42 P6 S255` / `M42 P6 S0`), 0.5 mm³/s.
    pub fn paste() -> Self {
        Self {
            name: "conductive paste".to_owned(),
            kind: ToolKind::Paste,
            filament_density: 3.0,
            temperature: 0.0,
            first_layer_temperature: 0.0,
            paste_on_gcode: "M42 P6 S255 ; paste on".to_owned(),
            paste_off_gcode: "M42 P6 S0 ; paste off".to_owned(),
            paste_flow_mm3_s: 0.5,
            travel_lift: Some(PASTE_TRAVEL_LIFT_MM),
            ..Self::filament()
        }
    }

    /// The default tool of a kind: [`Tool::filament`] or [`Tool::paste`].
    pub fn of_kind(kind: ToolKind) -> Self {
        match kind {
            ToolKind::Filament => Self::filament(),
            ToolKind::Paste => Self::paste(),
        }
    }

    /// Cross-section area of the filament, mm² (π·d²/4).
    pub fn filament_area(&self) -> f64 {
        std::f64::consts::PI * self.filament_diameter * self.filament_diameter / 4.0
    }
}

impl Default for Tool {
    /// [`Tool::filament`].
    fn default() -> Self {
        Self::filament()
    }
}

impl From<Flavor> for conduit_gcode::Firmware {
    /// The firmware dialect a G-code replay follows for a printer's `flavor`.
    fn from(flavor: Flavor) -> Self {
        match flavor {
            Flavor::Marlin => conduit_gcode::Firmware::Marlin,
            Flavor::Klipper => conduit_gcode::Firmware::Klipper,
            Flavor::RepRapFirmware => conduit_gcode::Firmware::RepRapFirmware,
        }
    }
}

impl fmt::Display for Flavor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Flavor::Marlin => "marlin",
            Flavor::RepRapFirmware => "reprapfirmware",
            Flavor::Klipper => "klipper",
        })
    }
}

/// What the machine does to place a part (`[pnp]`).
///
/// Before either snippet the writer retracts and lifts the nozzle `lift` mm above the layer
/// about to be printed; after it, it re-selects the active tool and comes back down only once it
/// is over the next path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct PnpSettings {
    /// G-code for a part placed by the vacuum tool (`method = "auto"`). Placeholders: `{id}`
    /// (1-based part number in placement order), `{part}`, `{x}`, `{y}`, `{z}` (seating plane),
    /// `{rotation}`. Default `M361 P{id}`, the command OctoPNP answers.
    pub auto_gcode: String,
    /// G-code after the `M117 Insert <part>` message of a part inserted by hand
    /// (`method = "manual"`). Placeholders as in `auto_gcode`, plus `{pause}`: the firmware's
    /// pause with the message (`M0` on Marlin, `M291` on RepRapFirmware, `PAUSE` on Klipper).
    /// Default `{pause}`.
    pub manual_gcode: String,
    /// How far the nozzle lifts above the layer before a part is placed, mm. Default 10.
    pub lift: f64,
}

impl Default for PnpSettings {
    fn default() -> Self {
        Self {
            auto_gcode: "M361 P{id}".to_owned(),
            manual_gcode: "{pause}".to_owned(),
            lift: 10.0,
        }
    }
}
