//! The default configuration as a commented TOML document (`conduit config --defaults`).

use super::Config;

/// One documented key: its section (`tools` stands for every `[tools.N]`), name, doc line, and
/// for keys that are absent by default an example value written commented out.
pub(super) struct KeyDoc {
    section: &'static str,
    key: &'static str,
    doc: &'static str,
    example: Option<&'static str>,
}

pub(super) const fn k(section: &'static str, key: &'static str, doc: &'static str) -> KeyDoc {
    KeyDoc {
        section,
        key,
        doc,
        example: None,
    }
}

const fn opt(
    section: &'static str,
    key: &'static str,
    doc: &'static str,
    example: &'static str,
) -> KeyDoc {
    KeyDoc {
        section,
        key,
        doc,
        example: Some(example),
    }
}

const SECTION_DOCS: &[(&str, &str)] = &[
    (
        "printer",
        "The machine: bed, firmware, custom G-code, retraction, travel, fan.",
    ),
    (
        "tools",
        "One table per tool, numbered from 0 without gaps. Keys left out take the default of the \
         tool's kind\n(\"filament\" or \"paste\"), not of the table shown here.",
    ),
    (
        "slice",
        "Slicing: layer heights, perimeters, infill, extrusion widths, speeds per role.",
    ),
    (
        "route",
        "Electronics: part cavities, wire channels and conductive trace routing.",
    ),
    (
        "pnp",
        "Part placement: what the machine does to place a part.",
    ),
    (
        "curved",
        "Non-planar printing: top solid layers of gentle top surfaces follow the surface (\"tops\"), or\n\
         a thin shell is printed as curved layers over a planar scaffold (\"clfff\").",
    ),
    (
        "conform",
        "Conformal printing (conduit conform): a 2D design laid onto a scanned surface and printed with\n\
         a micro-extrusion nozzle: nozzle geometry, corrections, deposit thresholds, pressure snippets.",
    ),
    (
        "jet",
        "Aerosol jet (conduit jet): corner fillet rules, shutter gap, direction blocks, shutter G-code,\n\
         fill and the corner accumulation model. Lengths mm (the command line takes µm).",
    ),
    (
        "robot",
        "Robot arms and five-axis machines (conduit conform --output, conduit calibrate): arm model,\n\
         frames, tool orientation and the dispense commands of each program dialect.",
    ),
    (
        "compensate",
        "Gap compensation (conduit compensate): measured tool-to-surface gaps move the path along the\n\
         tool axis, pass after pass.",
    ),
];

/// Every documented key: the table below and the sections that keep their own.
fn all_keys() -> impl Iterator<Item = &'static KeyDoc> {
    KEYS.iter()
        .chain(super::robot::KEYS)
        .chain(super::compensate::KEYS)
}

const KEYS: &[KeyDoc] = &[
    k(
        "printer",
        "flavor",
        "G-code dialect: \"marlin\", \"reprapfirmware\" or \"klipper\".",
    ),
    k("printer", "bed_size", "Printable bed size [X, Y], mm."),
    k(
        "printer",
        "bed_origin",
        "Coordinates of the bed's front-left corner [X, Y], mm ([-125, -125] for a 250 mm bed \
         with the origin in its centre).",
    ),
    k("printer", "max_height", "Highest printable Z, mm."),
    k(
        "printer",
        "bed_temperature",
        "Bed temperature after the first layer, °C (0 = off).",
    ),
    k(
        "printer",
        "first_layer_bed_temperature",
        "Bed temperature for the first layer, °C.",
    ),
    k(
        "printer",
        "start_gcode",
        "Written before the print. Placeholders: {key} for a printer or slice key, {key[N]} for \
         tool N's key or an array element;\n\
         {key} with a tool key means the current tool. PrusaSlicer's [key] works too.",
    ),
    k("printer", "end_gcode", "Written after the print."),
    k(
        "printer",
        "before_tool_change_gcode",
        "Written before every tool change; {previous_tool} and {next_tool} are available.",
    ),
    k(
        "printer",
        "after_tool_change_gcode",
        "Written after every tool change; {previous_tool} and {next_tool} are available.",
    ),
    k(
        "printer",
        "retract_length",
        "Filament pulled back before travels, mm (a tool's retract_length overrides it).",
    ),
    k(
        "printer",
        "retract_speed",
        "Retraction speed, mm/s of filament.",
    ),
    k(
        "printer",
        "deretract_speed",
        "Un-retraction speed, mm/s; 0 = retract_speed.",
    ),
    k(
        "printer",
        "retract_before_travel",
        "Travels shorter than this do not retract, mm.",
    ),
    k(
        "printer",
        "retract_lift",
        "Z lift during retracted travels, mm; 0 = none.",
    ),
    k(
        "printer",
        "travel_speed",
        "Speed of non-printing moves, mm/s.",
    ),
    k(
        "printer",
        "max_acceleration",
        "Machine acceleration for time estimates, mm/s².",
    ),
    k(
        "printer",
        "max_print_speed",
        "Highest speed of any printing move, mm/s; faster role speeds are clamped.",
    ),
    k(
        "printer",
        "use_relative_e_distances",
        "Relative E (M83) instead of absolute E (M82).",
    ),
    k(
        "printer",
        "fan_min_speed",
        "Lowest part-cooling fan speed when on, %.",
    ),
    k(
        "printer",
        "fan_max_speed",
        "Highest part-cooling fan speed, %.",
    ),
    k(
        "printer",
        "disable_fan_first_layers",
        "Number of bottom layers printed with the fan off.",
    ),
    k(
        "printer",
        "use_firmware_retraction",
        "Retract with G10/G11 instead of E moves.",
    ),
    k("tools", "name", "Name shown in comments and reports."),
    k(
        "tools",
        "kind",
        "\"filament\" (E-driven extruder) or \"paste\" (dispenser switched by paste_on_gcode / \
         paste_off_gcode, time-based flow).",
    ),
    k(
        "tools",
        "nozzle_diameter",
        "Nozzle or needle inner diameter, mm.",
    ),
    k(
        "tools",
        "filament_diameter",
        "Filament diameter, mm (filament tools).",
    ),
    k(
        "tools",
        "filament_density",
        "Material density for the weight estimate, g/cm³.",
    ),
    k(
        "tools",
        "temperature",
        "Nozzle temperature after the first layer, °C; 0 = not heated.",
    ),
    k(
        "tools",
        "first_layer_temperature",
        "Nozzle temperature for the first layer, °C.",
    ),
    opt(
        "tools",
        "standby_temperature",
        "Temperature while parked during another tool's work, °C; absent = keep temperature.",
        "150.0",
    ),
    k(
        "tools",
        "offset",
        "Nozzle offset from tool 0 [X, Y], mm, when the firmware does not apply it.",
    ),
    k(
        "tools",
        "extrusion_multiplier",
        "Factor on the computed flow.",
    ),
    k(
        "tools",
        "paste_on_gcode",
        "G-code that starts the paste flow (paste tools). The default drives output pin 6 high:\n\
         set P to the pin wired to your dispenser's valve or screw driver (Klipper: SET_PIN).",
    ),
    k(
        "tools",
        "paste_off_gcode",
        "G-code that stops the paste flow (paste tools).",
    ),
    k(
        "tools",
        "paste_flow_mm3_s",
        "Volume dispensed per second while on, mm³/s (paste tools).",
    ),
    opt(
        "tools",
        "retract_length",
        "This tool's retraction, mm; absent = printer.retract_length.",
        "1.0",
    ),
    opt(
        "tools",
        "travel_lift",
        "Z lift of this tool's long travels, mm; absent = printer.retract_lift (paste tools: 0.5).",
        "0.5",
    ),
    k("slice", "layer_height", "Layer height, mm."),
    k(
        "slice",
        "first_layer_height",
        "Height of the first layer, mm.",
    ),
    k(
        "slice",
        "nozzle_diameter",
        "Nozzle diameter the widths are checked against, mm (keep equal to tools.0.nozzle_diameter).",
    ),
    k(
        "slice",
        "perimeters",
        "Perimeter loops per island, the external one included.",
    ),
    k(
        "slice",
        "external_perimeters_first",
        "Print the external loop first (better accuracy, worse overhangs).",
    ),
    k(
        "slice",
        "top_solid_layers",
        "Solid layers under every top surface.",
    ),
    k(
        "slice",
        "bottom_solid_layers",
        "Solid layers over every bottom surface and the bed.",
    ),
    k(
        "slice",
        "infill_density",
        "Sparse infill density, 0 (none) to 1 (solid).",
    ),
    k(
        "slice",
        "infill_pattern",
        "Sparse infill pattern: \"rectilinear\", \"grid\" or \"triangles\".",
    ),
    k(
        "slice",
        "infill_angle_deg",
        "Base infill direction, degrees counter-clockwise from +X.",
    ),
    k(
        "slice",
        "infill_overlap",
        "How far infill reaches into the innermost perimeter, fraction of perimeter_width.",
    ),
    k(
        "slice",
        "solid_infill_margin",
        "How far solid areas grow into the neighbouring sparse area, mm.",
    ),
    k(
        "slice",
        "solid_infill_below_area",
        "Sparse areas smaller than this are filled solid, mm²; 0 = never.",
    ),
    k(
        "slice",
        "gap_fill",
        "Fill strips too narrow for another perimeter with variable-width lines.",
    ),
    k(
        "slice",
        "top_fill_pattern",
        "Top solid infill pattern: \"rectilinear\".",
    ),
    k(
        "slice",
        "bottom_fill_pattern",
        "Bottom solid infill pattern: \"rectilinear\".",
    ),
    k(
        "slice",
        "external_perimeter_width",
        "Extrusion width of the external loop, mm.",
    ),
    k(
        "slice",
        "perimeter_width",
        "Extrusion width of inner loops, mm.",
    ),
    k(
        "slice",
        "infill_width",
        "Extrusion width of sparse infill, mm.",
    ),
    k(
        "slice",
        "solid_infill_width",
        "Extrusion width of solid infill, mm.",
    ),
    k(
        "slice",
        "top_solid_infill_width",
        "Extrusion width of top solid infill, mm.",
    ),
    k(
        "slice",
        "first_layer_width",
        "Extrusion width on the first layer (all roles), mm.",
    ),
    k(
        "slice",
        "skirt_loops",
        "Skirt loops around the first layer; 0 = no skirt.",
    ),
    k(
        "slice",
        "skirt_distance",
        "Gap between the objects and the skirt, mm.",
    ),
    k(
        "slice",
        "brim_width",
        "Brim width around the first layer, mm; 0 = none.",
    ),
    k("slice", "support_material", "Generate support material."),
    k(
        "slice",
        "perimeter_speed",
        "Speed of inner perimeters, mm/s.",
    ),
    k(
        "slice",
        "external_perimeter_speed",
        "Speed of external perimeters, mm/s.",
    ),
    k("slice", "infill_speed", "Speed of sparse infill, mm/s."),
    k(
        "slice",
        "solid_infill_speed",
        "Speed of internal and bottom solid infill, mm/s.",
    ),
    k(
        "slice",
        "top_solid_infill_speed",
        "Speed of top solid infill, mm/s.",
    ),
    k(
        "slice",
        "bridge_speed",
        "Speed of bridge infill (threads over air), mm/s.",
    ),
    k("slice", "gap_fill_speed", "Speed of gap fill, mm/s."),
    k(
        "slice",
        "first_layer_speed",
        "Speed of every printing move on the first layer, mm/s.",
    ),
    k("slice", "skirt_speed", "Speed of skirt and brim, mm/s."),
    k(
        "slice",
        "conductive_speed",
        "Speed of conductive traces (paste tools), mm/s.",
    ),
    k(
        "slice",
        "object_tools",
        "Tool of each scene object: object i prints with object_tools[i]; objects past the end \
         use tool 0.",
    ),
    k(
        "route",
        "conductive_tool",
        "Tool that prints the conductive traces.",
    ),
    k(
        "route",
        "conductive_width",
        "Width of a conductive trace, mm.",
    ),
    k(
        "route",
        "conductive_height",
        "Height of a conductive trace, mm; 0 = the layer height.",
    ),
    k(
        "route",
        "channel_extra",
        "Clearance of a channel beyond the trace width, mm.",
    ),
    k(
        "route",
        "cavity_offset",
        "How far a part's cavity reaches beyond its pads and body, mm.",
    ),
    k(
        "route",
        "perimeters",
        "Deflated perimeter traces the router may follow per layer.",
    ),
    k(
        "route",
        "perimeter_weights",
        "Cost per mm on each deflated trace, outermost first (inner ones cheaper).",
    ),
    k(
        "route",
        "base_weight",
        "Cost per mm of a straight section inside material.",
    ),
    k(
        "route",
        "outside_weight",
        "Cost per mm of a straight section outside material or across a hole.",
    ),
    k(
        "route",
        "squeeze_weight",
        "Cost per mm of trace through gaps the deflated perimeter traces do not reach.",
    ),
    k(
        "route",
        "grid_step",
        "Step of the grid explored in the infill area, mm.",
    ),
    k(
        "route",
        "interlayer_overlap",
        "Overlap of the traces of two layers where a wire changes layer, mm.",
    ),
    k(
        "route",
        "layer_change_penalty",
        "Extra cost of each layer change, mm of straight path.",
    ),
    k(
        "route",
        "layer_span",
        "Layers below and above the pads a route may use to pass other traces.",
    ),
    k(
        "route",
        "rip_up_rounds",
        "Rounds of rip-up and reroute for wires that could not be routed.",
    ),
    k(
        "route",
        "max_detour",
        "Longest route worth printing, times the straight pad-to-pad distance (plus detour_slack).",
    ),
    k(
        "route",
        "detour_slack",
        "Allowance added to the detour limit, mm.",
    ),
    k(
        "route",
        "pad_drops",
        "A conductive drop on every pad, also on pins no net uses.",
    ),
    k(
        "pnp",
        "auto_gcode",
        "G-code placing a part with the vacuum tool. Placeholders {id} {part} {x} {y} {z} \
         {rotation}.",
    ),
    k(
        "pnp",
        "manual_gcode",
        "G-code after `M117 Insert <part>` for a part inserted by hand; {pause} is the \
         firmware's pause.",
    ),
    k(
        "pnp",
        "lift",
        "How far the nozzle lifts above the layer before a part is placed, mm.",
    ),
    k(
        "curved",
        "mode",
        "\"off\", \"tops\" (curved top surfaces) or \"clfff\" (curved-layer shells); also \
         `conduit slice --curved MODE`.",
    ),
    k(
        "curved",
        "max_angle",
        "Steepest top-surface slope printed curved, degrees from the horizontal.",
    ),
    k(
        "curved",
        "step",
        "Longest segment of a curved path, mm (paths also split at surface triangle edges).",
    ),
    k(
        "curved",
        "head_angle",
        "Half-angle of the print head's cone around the nozzle, degrees from the vertical.",
    ),
    k(
        "curved",
        "head_height",
        "Height of the head's cone above the nozzle tip, mm.",
    ),
    k(
        "curved",
        "carriage_radius",
        "Radius of the carriage cylinder around the nozzle axis, mm; 0 = not modelled.",
    ),
    k(
        "curved",
        "carriage_clearance",
        "Height of the carriage cylinder's bottom above the nozzle tip, mm.",
    ),
    k(
        "curved",
        "max_z_speed",
        "Fastest z motion while extruding, mm/s; faster moves are slowed.",
    ),
    k(
        "curved",
        "raise",
        "clfff: height of the shell's lowest point (or its buffer's) above the bed, room for \
         scaffold, mm.",
    ),
    k(
        "curved",
        "scaffold",
        "clfff: print a planar scaffold under the shell.",
    ),
    k(
        "curved",
        "scaffold_margin",
        "clfff: growth of the scaffold area (convex hull of the shell's outline), mm.",
    ),
    k(
        "curved",
        "scaffold_vectors",
        "clfff: directions [x, y] of the scaffold lines, one per layer, cycled (two make a grid).",
    ),
    k(
        "curved",
        "scaffold_spacing",
        "clfff: distance between neighbouring scaffold lines, mm.",
    ),
    k(
        "curved",
        "scaffold_tool",
        "clfff: tool printing the scaffold.",
    ),
    k(
        "curved",
        "scaffold_clearance",
        "clfff: gap between the scaffold's top and the bottom of the lowest curved layer, mm.",
    ),
    k(
        "curved",
        "buffer",
        "clfff: print one buffer layer following the bottom surface between scaffold and model.",
    ),
    k(
        "curved",
        "buffer_tool",
        "clfff: tool printing the buffer layer.",
    ),
    k(
        "curved",
        "layers",
        "clfff: number of curved model layers; 0 = the shell's median thickness / layer height.",
    ),
    k(
        "curved",
        "angles",
        "clfff: raster angle of each curved layer, degrees from +X, cycled through the layers.",
    ),
    k(
        "curved",
        "travel_clearance",
        "clfff: how far above the highest material under a travel the nozzle passes, mm.",
    ),
    k(
        "curved",
        "split_sections",
        "clfff: write OUT.scaffold.gcode, OUT.buffer.gcode and OUT.model.gcode instead of one \
         file (also --split-sections).",
    ),
    k(
        "curved",
        "sandwich",
        "clfff: thick part as a curved bottom skin (curved.layers), a planar core and a curved \
         top skin (curved.top_layers).",
    ),
    k(
        "curved",
        "top_layers",
        "clfff sandwich: number of top skin layers, the last on the top surface.",
    ),
    k(
        "conform",
        "tool",
        "Tool that dispenses (a paste tool: its snippets switch the pressure).",
    ),
    k(
        "conform",
        "inner_diameter",
        "Nozzle inner diameter d, mm: standoff, bead width, point spacing (two points per d).",
    ),
    k(
        "conform",
        "outer_diameter",
        "Nozzle outer diameter d_o, mm: the tip disk of the contact check.",
    ),
    k(
        "conform",
        "tolerance",
        "Extra lateral clearance of every contact correction, mm.",
    ),
    k("conform", "feed", "Feed rate while dispensing, mm/s."),
    k(
        "conform",
        "pressure_on_gcode",
        "G-code that switches the pressure on; empty = the tool's paste_on_gcode.",
    ),
    k(
        "conform",
        "pressure_off_gcode",
        "G-code that switches the pressure off; empty = the tool's paste_off_gcode.",
    ),
    k(
        "conform",
        "mapping",
        "\"projection\" (drop along -z) or \"geodesic\" (keep arc length on the surface); also --mapping.",
    ),
    k(
        "conform",
        "corrections",
        "\"deposit\" (the tip placed on the deposit model: back edge over the design point, standoff solved on the surface), \"deposit-plane\" (the same on the tangent plane: no curvature), \"full\" (the published method: contact + curvature-scaled downhill), \"slope\" (its downhill shift without curvature) or \"none\".",
    ),
    k(
        "conform",
        "needle_length",
        "Length of the straight needle above the tip, mm.",
    ),
    k(
        "conform",
        "cone_angle",
        "Half-angle of the cone above the needle, degrees from the vertical; 0 = needle only.",
    ),
    k("conform", "cone_height", "Height of that cone, mm."),
    k(
        "conform",
        "contact_thickness",
        "Deposit thickness at or below which the nozzle touches the surface, mm.",
    ),
    k(
        "conform",
        "flattening_error",
        "Thickness error below minus this counts as flattening, mm.",
    ),
    k(
        "conform",
        "floating_error",
        "Thickness error above this counts as floating, mm.",
    ),
    k(
        "conform",
        "marker_max_size",
        "--refs-auto: largest hole (longest bounding-box side) taken as a marker, mm.",
    ),
    k(
        "conform",
        "fold_gap",
        "Point clouds: points this far below the top of their grid cell are a fold, not the surface, mm.",
    ),
    k(
        "conform",
        "travel_clearance",
        "Height above the highest surface point that travels between paths clear, mm.",
    ),
    k(
        "jet",
        "tool",
        "Tool that jets: a kind = \"paste\" tool (its own paste snippets are not used).",
    ),
    k(
        "jet",
        "corner_rules",
        "Minimum fillet radius per corner angle (180 = straight): [min_angle_deg, radius / line \
         width] rows; the row with the largest min_angle_deg <= the corner's angle applies.",
    ),
    k(
        "jet",
        "split_below",
        "Corners sharper than this, degrees, are split: the shutter closes, the next segment starts \
         fresh.",
    ),
    k(
        "jet",
        "arcs",
        "Write fillets as G2/G3 arcs (Klipper needs [gcode_arcs]); false flattens them into G1.",
    ),
    k(
        "jet",
        "arc_tolerance",
        "Largest distance between a flattened fillet and its chords, mm.",
    ),
    k(
        "jet",
        "gap",
        "Gap between the end and the start of a closed contour, mm (where the shutter acts).",
    ),
    k(
        "jet",
        "gap_positions",
        "Places the gap cycles through, one per layer, on straight segments away from corners.",
    ),
    k(
        "jet",
        "block_layers",
        "The print direction reverses after every block of this many layers.",
    ),
    k(
        "jet",
        "fill",
        "Closed outlines: \"wall\" (one line), \"contour\" (inward loops) or \"serpentine\".",
    ),
    k(
        "jet",
        "fill_spacing",
        "Distance between fill lines, as a multiple of the line width.",
    ),
    k(
        "jet",
        "fill_angle",
        "Direction of serpentine lines, degrees from +X.",
    ),
    k("jet", "speed", "Feed while jetting, mm/s."),
    k(
        "jet",
        "travel_speed",
        "Feed of travels (shutter closed), mm/s.",
    ),
    k(
        "jet",
        "shutter_open_gcode",
        "G-code that opens the shutter.",
    ),
    k(
        "jet",
        "shutter_close_gcode",
        "G-code that closes the shutter.",
    ),
    k(
        "jet",
        "shutter_lead_time",
        "Shutter-on-the-fly: open/close commands this long (s, at the jetting speed) before a \
         path's start and end; 0 = at the ends.",
    ),
    k(
        "jet",
        "start_gcode",
        "Written once before the job (after G21, G90, M83).",
    ),
    k(
        "jet",
        "end_gcode",
        "Written once after the job (after the shutter closes).",
    ),
    k(
        "jet",
        "e_words",
        "Write E (deposited volume, mm³, relative) so conduit check and preview see the lines.",
    ),
    k(
        "jet",
        "leveling_factor",
        "Factor on the accumulation model: the bare model over-predicts the inside/outside height \
         difference about tenfold.",
    ),
    k(
        "jet",
        "model_roi",
        "Region of interest around each corner for the accumulation model in the report, mm.",
    ),
];

/// The default configuration ([`Config::default`]) as a TOML document with every key, its
/// documentation and unit as comments. Parsing it gives `Config::default()` back exactly.
pub fn defaults_toml() -> String {
    let mut out = String::from(
        "# conduit configuration: every key with its default value.\n\
         # Units: lengths mm, speeds mm/s, accelerations mm/s², temperatures °C, fan %.\n\
         # Any key may be left out; unknown keys are errors.\n",
    );
    let tree = match toml::Value::try_from(Config::default()) {
        Ok(t) => t,
        Err(e) => panic!("internal error: default config does not serialise: {e}"),
    };
    for &(section, section_doc) in SECTION_DOCS {
        let Some(value) = tree.get(section) else {
            continue;
        };
        let tables: Vec<(String, &toml::Value)> = if section == "tools" {
            value
                .as_table()
                .map(|t| t.iter().map(|(n, v)| (format!("tools.{n}"), v)).collect())
                .unwrap_or_default()
        } else {
            vec![(section.to_owned(), value)]
        };
        for (i, (header, table)) in tables.iter().enumerate() {
            out.push('\n');
            if i == 0 {
                push_comment(&mut out, section_doc);
            }
            out.push_str(&format!("[{header}]\n"));
            for doc in all_keys().filter(|d| d.section == section) {
                // Tool keys are documented once, in the first tool's table.
                if i == 0 {
                    push_comment(&mut out, doc.doc);
                }
                match (table.get(doc.key), doc.example) {
                    (Some(v), _) => out.push_str(&format!("{} = {}\n", doc.key, format_value(v))),
                    (None, Some(example)) => out.push_str(&format!("# {} = {example}\n", doc.key)),
                    (None, None) => {}
                }
            }
        }
    }
    out
}

fn push_comment(out: &mut String, text: &str) {
    for line in text.lines() {
        out.push_str("# ");
        out.push_str(line.trim());
        out.push('\n');
    }
}

/// One value as TOML; strings with newlines as multi-line literal strings for readability.
fn format_value(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) if s.contains('\n') && !s.contains("'''") && !s.contains('\r') => {
            format!("'''\n{s}'''")
        }
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_toml_loads_back_to_the_default_config() -> Result<(), toml::de::Error> {
        let text = defaults_toml();
        let back = Config::from_toml_str(&text)?;
        assert_eq!(back, Config::default());
        assert!(text.contains("[tools.1]\n"));
        assert!(text.contains("# standby_temperature = 150.0\n"));
        Ok(())
    }

    #[test]
    fn every_key_is_documented_once_and_every_doc_is_a_key() {
        let tree = match toml::Value::try_from(Config::default()) {
            Ok(t) => t,
            Err(e) => panic!("{e}"),
        };
        let mut serialised = std::collections::BTreeSet::new();
        for (section, value) in tree.as_table().into_iter().flatten() {
            let tables: Vec<&toml::Value> = if section == "tools" {
                value
                    .as_table()
                    .into_iter()
                    .flat_map(|t| t.values())
                    .collect()
            } else {
                vec![value]
            };
            for t in tables {
                for key in t.as_table().into_iter().flat_map(|t| t.keys()) {
                    serialised.insert((section.clone(), key.clone()));
                }
            }
        }
        let mut documented = std::collections::BTreeSet::new();
        for d in all_keys() {
            assert!(
                documented.insert((d.section.to_owned(), d.key.to_owned())),
                "{}.{} documented twice",
                d.section,
                d.key
            );
        }
        let optional: std::collections::BTreeSet<_> = all_keys()
            .filter(|d| d.example.is_some())
            .map(|d| (d.section.to_owned(), d.key.to_owned()))
            .collect();
        let undocumented: Vec<_> = serialised.difference(&documented).collect();
        assert!(
            undocumented.is_empty(),
            "undocumented keys: {undocumented:?}"
        );
        let unknown: Vec<_> = documented
            .difference(&serialised)
            .filter(|k| !optional.contains(*k))
            .collect();
        assert!(
            unknown.is_empty(),
            "documented keys that do not exist: {unknown:?}"
        );
    }
}
