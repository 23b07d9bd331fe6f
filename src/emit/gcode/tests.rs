//! Tests of the G-code writer on real output: every file is re-parsed with `conduit_gcode` and
//! replayed (positions, E, tool) to check what the machine would do.

use super::*;
use crate::geom::Point3;
use crate::program::machine::{Flavor, Tool};
use crate::program::{Event, Layer, LayerItem, Role, Toolpath, e_per_mm};

/// One replayed move.
#[derive(Debug, Clone, Copy)]
struct Move {
    /// Index of the line in the file.
    line: usize,
    tool: usize,
    from: [f64; 3],
    to: [f64; 3],
    /// E change (filament mm).
    de: f64,
}

impl Move {
    fn xy_len(&self) -> f64 {
        ((self.to[0] - self.from[0]).powi(2) + (self.to[1] - self.from[1]).powi(2)).sqrt()
    }
    fn moves_xy(&self) -> bool {
        self.xy_len() > 0.0
    }
}

/// Parses `text` and replays it on the modal machine: positions, E (absolute or relative per
/// M82/M83, G92 E), tool. Returns the lines and the moves from the first `;LAYER_CHANGE` on
/// (the start G-code's priming moves are left out).
fn replay(text: &str) -> (Vec<String>, Vec<Move>) {
    let g = match conduit_gcode::parse(text.as_bytes()) {
        Ok(g) => g,
        Err(e) => panic!("output does not parse: {e}"),
    };
    let lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let mut machine = conduit_gcode::Machine::new(Flavor::Marlin, 25.0);
    let known = |p: conduit_gcode::Position| p.map(|c| c.unwrap_or(0.0));
    let mut moves = Vec::new();
    for (i, l) in g.lines.iter().enumerate() {
        if let Some(m) = machine.step(l) {
            moves.push(Move {
                line: i,
                tool: m.tool,
                from: known(m.from),
                to: known(m.to),
                de: m.e,
            });
        }
    }
    let body = lines.iter().position(|l| l == ";LAYER_CHANGE").unwrap_or(0);
    moves.retain(|m| m.line > body);
    (lines, moves)
}

/// Asserts that the G-code of absolute E `abs_text` and of relative E `rel_text` replay as the
/// same moves with the same extrusion.
fn assert_same_moves(abs_text: &str, rel_text: &str) {
    let ((_, a), (_, r)) = (replay(abs_text), replay(rel_text));
    assert_eq!(a.len(), r.len());
    for (x, y) in a.iter().zip(&r) {
        assert_eq!(x.to, y.to);
        // Absolute E is rounded once per position, relative once per move: 2 roundings apart.
        assert!(
            (x.de - y.de).abs() <= 1.1e-5,
            "line {}: {} vs {}",
            x.line,
            x.de,
            y.de
        );
    }
}

fn path(points: &[(f64, f64)], z: f64, closed: bool, role: Role, tool: usize) -> Toolpath {
    Toolpath {
        points: points.iter().map(|&(x, y)| Point3::new(x, y, z)).collect(),
        closed,
        role,
        tool,
        width: 0.45,
        height: 0.2,
        speed: 30.0,
        segments: None,
        tool_axis: None,
    }
}

fn square(x: f64, y: f64, side: f64, z: f64, role: Role, tool: usize) -> Toolpath {
    path(
        &[(x, y), (x + side, y), (x + side, y + side), (x, y + side)],
        z,
        true,
        role,
        tool,
    )
}

/// One layer: an inner and an outer square loop (short travel between them), an infill line
/// inside (short travel), and a far square (long travel).
fn one_layer_program() -> Program {
    let z = 0.2;
    Program {
        layers: vec![Layer {
            index: 0,
            z,
            height: 0.2,
            items: vec![
                LayerItem::Path(square(11.0, 11.0, 18.0, z, Role::Perimeter, 0)),
                LayerItem::Path(square(10.0, 10.0, 20.0, z, Role::ExternalPerimeter, 0)),
                LayerItem::Path(path(
                    &[(12.0, 12.0), (28.0, 28.0)],
                    z,
                    false,
                    Role::SparseInfill,
                    0,
                )),
                LayerItem::Path(square(60.0, 60.0, 10.0, z, Role::ExternalPerimeter, 0)),
            ],
        }],
    }
}

/// Layer `index` of a print in 0.2 mm layers: one external-perimeter square of tool 0, 10 mm
/// on a side, its corner at (`x`, 10).
fn square_layer(index: usize, x: f64) -> Layer {
    let z = 0.2 * (index + 1) as f64;
    Layer {
        index,
        z,
        height: 0.2,
        items: vec![LayerItem::Path(square(
            x,
            10.0,
            10.0,
            z,
            Role::ExternalPerimeter,
            0,
        ))],
    }
}

fn test_config() -> GcodeParams {
    let mut cfg = GcodeParams::for_tests();
    cfg.printer.retract_length = 0.8;
    cfg.printer.retract_before_travel = 2.0;
    cfg.printer.retract_lift = 0.4;
    cfg
}

fn write(program: &Program, cfg: &GcodeParams) -> (String, GcodeStats) {
    let mut out = Vec::new();
    match write_gcode(program, cfg, &mut out) {
        Ok(stats) => (String::from_utf8_lossy(&out).into_owned(), stats),
        Err(e) => panic!("write_gcode failed: {e}"),
    }
}

#[test]
fn one_layer_square_header_markers_extrusion_retraction_and_zhop() {
    let cfg = test_config();
    let program = one_layer_program();
    let (text, stats) = write(&program, &cfg);
    let (lines, moves) = replay(&text);

    // Header first, with the version and totals; PrusaSlicer's markers in the body.
    assert_eq!(lines[0], format!("; conduit {}", env!("CARGO_PKG_VERSION")));
    assert!(text.contains("; tools used = 0 (PLA)\n"), "{text}");
    assert!(
        text.contains(";LAYER_CHANGE\n;Z:0.2\n;HEIGHT:0.2\nG1 Z0.2 F7800\nG92 E0\n"),
        "{text}"
    );
    for marker in [
        ";TYPE:Perimeter",
        ";TYPE:External perimeter",
        ";TYPE:Internal infill",
        ";WIDTH:0.45",
        ";TYPE:Custom",
    ] {
        assert!(lines.iter().any(|l| l == marker), "{marker} missing");
    }
    assert_eq!(lines.iter().filter(|l| *l == ";WIDTH:0.45").count(), 1);
    assert!(text.contains("M82 ; use absolute distances for extrusion"));
    assert!(text.contains("; estimated printing time (normal mode) = "));
    assert_eq!(stats.layers, 1);

    // E per mm of every extrusion equals the flow formula.
    let k = e_per_mm(0.45, 0.2, 1.75);
    let extrusions: Vec<&Move> = moves
        .iter()
        .filter(|m| m.moves_xy() && m.de > 0.0)
        .collect();
    assert_eq!(extrusions.len(), 4 + 4 + 1 + 4);
    for m in &extrusions {
        assert!(
            (m.de / m.xy_len() - k).abs() < 1e-5,
            "line {}: {} vs {k}",
            m.line,
            m.de / m.xy_len()
        );
        assert!(
            (m.to[2] - 0.2).abs() < 1e-9,
            "z-hop not restored before line {}",
            m.line
        );
    }
    let total: f64 = extrusions.iter().map(|m| m.de).sum();
    assert!((stats.tools[0].filament_mm - total).abs() < 1e-4);
    let expected_len = 4.0 * 18.0 + 4.0 * 20.0 + 16.0 * 2f64.sqrt() + 40.0;
    assert!((total - expected_len * k).abs() < 1e-4, "{total}");
    assert!(stats.tools[0].grams > 0.0 && stats.estimated_time_s > 0.0);

    // Retraction (and z-hop) on long travels only, un-retraction before the next extrusion.
    let mut retracted = false;
    let mut travels = 0;
    for m in &moves {
        if !m.moves_xy() && m.de < 0.0 {
            assert!(!retracted);
            assert!((m.de + 0.8).abs() < 1e-9);
            retracted = true;
        } else if !m.moves_xy() && m.de > 0.0 {
            assert!(retracted);
            retracted = false;
        } else if m.moves_xy() && m.de == 0.0 {
            travels += 1;
            if travels == 1 {
                // From the end of the start G-code, where the writer does not know the
                // position: no retraction.
                continue;
            }
            let long = m.xy_len() > 2.0;
            assert_eq!(
                retracted,
                long,
                "travel at line {} of {} mm",
                m.line,
                m.xy_len()
            );
            let lifted = (m.to[2] - 0.6).abs() < 1e-9;
            assert_eq!(lifted, long, "z-hop at line {}", m.line);
        } else if m.de > 0.0 {
            assert!(!retracted, "extruding while retracted at line {}", m.line);
        }
    }
    // Travels: to the first loop (from the unknown start: not replayed as long), inner→outer
    // (1.4 mm), outer→infill (2.8 mm: long), infill→far square (long).
    assert!(travels >= 3, "{travels}");
    // The end retracts; the last travel restored Z before extruding.
    assert!(retracted);
}

#[test]
fn a_travel_marked_inside_the_infill_does_not_retract_or_lift() {
    let cfg = test_config();
    let z = 0.2;
    let line = |y: f64| {
        LayerItem::Path(path(
            &[(10.0, y), (30.0, y)],
            z,
            false,
            Role::SparseInfill,
            0,
        ))
    };
    // Three infill lines 20 mm long, each travel back 20 mm: the second travel is marked.
    let program = Program {
        layers: vec![Layer {
            index: 0,
            z,
            height: 0.2,
            items: vec![
                line(10.0),
                line(12.0),
                LayerItem::Event(Event::TravelInsideInfill),
                line(14.0),
            ],
        }],
    };
    let (_, moves) = replay(&write(&program, &cfg).0);
    let travels: Vec<&Move> = moves
        .iter()
        .filter(|m| m.moves_xy() && m.de == 0.0)
        .skip(1)
        .collect();
    assert_eq!(travels.len(), 2);
    // The unmarked travel was lifted (0.4 mm) after a retraction, the marked one was not.
    assert!((travels[0].to[2] - 0.6).abs() < 1e-9);
    assert!((travels[1].to[2] - 0.2).abs() < 1e-9);
    // One retraction before the end's: the unmarked travel's.
    let retractions = moves.iter().filter(|m| !m.moves_xy() && m.de < 0.0).count();
    assert_eq!(retractions, 2);
}

/// Two filament tools; tool 0 has a standby temperature, tool 1 an offset.
fn two_tool_config() -> GcodeParams {
    let mut cfg = test_config();
    cfg.tools = vec![
        Tool {
            standby_temperature: Some(170.0),
            ..Tool::filament()
        },
        Tool {
            name: "PETG".to_owned(),
            temperature: 240.0,
            first_layer_temperature: 235.0,
            offset: [20.0, 5.0],
            ..Tool::filament()
        },
    ];
    cfg.printer.before_tool_change_gcode = "; before {previous_tool} -> {next_tool}".to_owned();
    cfg
}

fn two_tool_program() -> Program {
    let layer = |index: usize, z: f64, first: usize| {
        let second = 1 - first;
        Layer {
            index,
            z,
            height: 0.2,
            items: vec![
                LayerItem::Path(square(
                    10.0 + 40.0 * first as f64,
                    10.0,
                    10.0,
                    z,
                    Role::ExternalPerimeter,
                    first,
                )),
                LayerItem::Event(Event::ToolChange { tool: second }),
                LayerItem::Path(square(
                    10.0 + 40.0 * second as f64,
                    10.0,
                    10.0,
                    z,
                    Role::ExternalPerimeter,
                    second,
                )),
            ],
        }
    };
    Program {
        layers: vec![layer(0, 0.2, 0), layer(1, 0.4, 1)],
    }
}

#[test]
fn a_before_snippet_that_selects_the_tool_replaces_the_t_line() {
    let mut cfg = two_tool_config();
    cfg.printer.before_tool_change_gcode = "G1 Z5 ; lift\nT{next_tool} ; host style".to_owned();
    let (text, _) = write(&two_tool_program(), &cfg);
    let (lines, moves) = replay(&text);
    // One T per change, the snippet's; the new tool still heats and waits before it prints.
    let selects: Vec<&String> = lines.iter().filter(|l| l.starts_with('T')).collect();
    assert_eq!(
        selects,
        ["T0", "T1 ; host style", "T0 ; host style"],
        "{text}"
    );
    assert!(moves.iter().any(|m| m.tool == 1 && m.de > 0.0), "{text}");
    let at = |s: &str| lines.iter().position(|l| l == s).unwrap_or(usize::MAX);
    assert!(at("T1 ; host style") < at("M109 T1 S235"), "{text}");
}

#[test]
fn two_tools_standby_wait_before_first_use_and_offsets() {
    let cfg = two_tool_config();
    let (text, stats) = write(&two_tool_program(), &cfg);
    let (lines, moves) = replay(&text);
    let at = |s: &str| lines.iter().position(|l| l == s).unwrap_or(usize::MAX);
    let t1 = at("T1");
    assert!(t1 < usize::MAX, "{text}");
    // T0 goes to standby before T1 is selected; T1 heats and waits before it extrudes.
    assert!(at("; before 0 -> 1") < t1);
    assert!(at("M104 T0 S170") < t1);
    let wait = at("M109 T1 S235");
    let first_t1_extrusion = moves
        .iter()
        .find(|m| m.tool == 1 && m.de > 0.0 && m.moves_xy())
        .map_or(usize::MAX, |m| m.line);
    assert!(
        t1 < wait && wait < first_t1_extrusion,
        "{t1} {wait} {first_t1_extrusion}"
    );
    // Layer 1 starts with T1 (no change), then goes back to T0, which is waited for again at
    // its after-first-layer temperature.
    assert!(text.contains("M104 T1 S240"), "{text}");
    assert!(!text.contains("M104 T1 S170"));
    assert!(text.contains("T0\nM109 T0 S210"), "{text}");
    assert_eq!(
        lines.iter().filter(|l| l.starts_with('T')).count(),
        3,
        "T0 at start, T1, T0"
    );
    // Offsets: tool 1's square (nominal x 50..60, y 10..20) is printed at x 30..40, y 5..15.
    for m in moves.iter().filter(|m| m.de > 0.0 && m.moves_xy()) {
        let (x0, y0) = if m.tool == 1 {
            (30.0, 5.0)
        } else {
            (10.0, 10.0)
        };
        for p in [m.from, m.to] {
            assert!(
                p[0] >= x0 - 1e-9 && p[0] <= x0 + 10.0 + 1e-9,
                "tool {} x {}",
                m.tool,
                p[0]
            );
            assert!(
                p[1] >= y0 - 1e-9 && p[1] <= y0 + 10.0 + 1e-9,
                "tool {} y {}",
                m.tool,
                p[1]
            );
        }
    }
    assert_eq!(stats.tools.len(), 2);
    assert!(stats.tools.iter().all(|t| t.filament_mm > 0.0));
    // The start G-code heats only tool 0: tool 1 is preheated right after it.
    let preheat = at("M104 T1 S235");
    assert!(
        at("G92 E0") < preheat && preheat < at(";LAYER_CHANGE"),
        "{text}"
    );
    // Fan off on the first layer (disable_fan_first_layers = 1), on for the short layer 1.
    let layer1 = lines
        .iter()
        .rposition(|l| l == ";LAYER_CHANGE")
        .unwrap_or(0);
    assert!(at("M107") < at(";LAYER_CHANGE"));
    assert!(at("M106 S255") > layer1, "{text}");
    assert_eq!(lines.iter().filter(|l| l.starts_with("M106")).count(), 1);
}

#[test]
fn fan_follows_layer_time_between_min_and_max() {
    let mut cfg = test_config();
    cfg.printer.disable_fan_first_layers = 0;
    cfg.printer.fan_min_speed = 40.0;
    cfg.printer.fan_max_speed = 100.0;
    // Layer 0: one 40 mm loop at 30 mm/s (under 5 s: full fan). Layer 1: the same loop at
    // 1 mm/s (40 s plus ramps: between). Layer 2: at 0.5 mm/s (80 s: minimum fan).
    let layer = |index: usize, speed: f64| {
        let z = 0.2 * (index + 1) as f64;
        let mut p = square(10.0, 10.0, 10.0, z, Role::Perimeter, 0);
        p.speed = speed;
        Layer {
            index,
            z,
            height: 0.2,
            items: vec![LayerItem::Path(p)],
        }
    };
    let program = Program {
        layers: vec![layer(0, 30.0), layer(1, 1.0), layer(2, 0.5)],
    };
    let (text, _) = write(&program, &cfg);
    let fans: Vec<&str> = text.lines().filter(|l| l.starts_with("M106")).collect();
    // 40 mm at 1 mm/s with 1000 mm/s² ramps: 40.001 s → 100 − 60·35.001/55 = 61.8 % → S158.
    assert_eq!(fans, ["M106 S255", "M106 S158", "M106 S102"], "{text}");
}

#[test]
fn paste_tool_is_switched_on_and_off_without_e() {
    let mut cfg = test_config();
    cfg.tools[1].offset = [0.0, 0.0];
    let mut program = one_layer_program();
    program.layers[0].items.push(LayerItem::Path(square(
        80.0,
        10.0,
        5.0,
        0.2,
        Role::ConductiveTrace,
        1,
    )));
    let (text, stats) = write(&program, &cfg);
    let (lines, moves) = replay(&text);
    let on = lines
        .iter()
        .position(|l| l == "M42 P6 S255 ; paste on")
        .unwrap_or(usize::MAX);
    let off = lines
        .iter()
        .position(|l| l == "M42 P6 S0 ; paste off")
        .unwrap_or(usize::MAX);
    assert!(on < off && off < usize::MAX, "{text}");
    assert!(lines.iter().any(|l| l == ";TYPE:Conductive trace"));
    let paste: Vec<&Move> = moves
        .iter()
        .filter(|m| m.line > on && m.line < off)
        .collect();
    assert_eq!(paste.len(), 4);
    for m in &paste {
        assert_eq!(m.tool, 1);
        assert!(!lines[m.line].contains('E'), "{}", lines[m.line]);
    }
    // Unheated paste tool: no temperature commands for it.
    assert!(!text.contains("T1 S"));
    let t1 = &stats.tools[1];
    assert_eq!(t1.filament_mm, 0.0);
    assert!(
        t1.extrusion_time_s > 0.0
            && (t1.volume_cm3 - t1.extrusion_time_s * 0.5 / 1000.0).abs() < 1e-12
    );
}

#[test]
fn the_paste_tool_lifts_over_its_traces_on_long_travels() {
    let mut cfg = test_config();
    cfg.tools[1].offset = [0.0, 0.0];
    let mut program = one_layer_program();
    for x in [80.0, 100.0] {
        program.layers[0].items.push(LayerItem::Path(square(
            x,
            10.0,
            5.0,
            0.2,
            Role::ConductiveTrace,
            1,
        )));
    }
    let (text, _) = write(&program, &cfg);
    let (lines, moves) = replay(&text);
    let on = lines
        .iter()
        .position(|l| l == "M42 P6 S255 ; paste on")
        .unwrap_or(usize::MAX);
    // Every travel of the paste tool longer than retract_before_travel runs 0.5 mm (the paste
    // tool's travel_lift) above the layer; its printing moves stay on it.
    let lift = cfg.travel_lift(1);
    assert_eq!(lift, 0.5);
    // Whether the paste flows at each line.
    let mut flowing = Vec::with_capacity(lines.len());
    let mut state = false;
    for l in &lines {
        if l.contains("paste on") {
            state = true;
        } else if l.contains("paste off") {
            state = false;
        }
        flowing.push(state);
    }
    let (mut printed, mut travels) = (0, 0);
    for m in moves
        .iter()
        .filter(|m| m.tool == 1 && m.line > on && m.moves_xy())
    {
        if flowing[m.line] {
            printed += 1;
            assert!((m.to[2] - 0.2).abs() < 1e-9, "{}", lines[m.line]);
        } else if m.xy_len() > cfg.printer.retract_before_travel {
            travels += 1;
            assert!((m.to[2] - (0.2 + lift)).abs() < 1e-9, "{}", lines[m.line]);
        }
    }
    assert_eq!(printed, 8, "{text}");
    assert!(travels >= 1, "{text}");
    // Filament tools keep the printer's lift (none by default).
    assert_eq!(cfg.travel_lift(0), cfg.printer.retract_lift);
}

#[test]
fn layer_templates_frame_the_layer_change_and_an_e_reset_in_them_is_followed() {
    let program = two_tool_program();
    let mut cfg = two_tool_config();
    cfg.printer.before_layer_gcode =
        ";before {layer_num} at {layer_z} of {max_layer_z}\nG92 E0".to_owned();
    cfg.printer.layer_gcode = ";after {layer_num} {extruded_weight_total > 0}".to_owned();
    let (abs_text, _) = write(&program, &cfg);
    let lines: Vec<&str> = abs_text.lines().collect();
    let at = |l: &str| lines.iter().position(|x| *x == l).unwrap_or(usize::MAX);
    for (n, z, some) in [(0, "0.2", false), (1, "0.4", true)] {
        let before = at(&format!(";before {n} at {z} of 0.4"));
        assert_eq!(lines[before - 1], ";HEIGHT:0.2", "{abs_text}");
        assert_eq!(lines[before + 1], "G92 E0");
        let after = at(&format!(";after {n} {some}"));
        let lift = lines[before..after]
            .iter()
            .position(|l| l.starts_with("G1 Z") || l.contains(" Z"))
            .expect("the move to the layer lies between the two templates");
        assert!(lift > 1, "{abs_text}");
    }
    // The `G92 E0` of the template is the writer's too: absolute E replays as relative E does
    // (no retraction measured against an E register the printer no longer has). Layer 1
    // starts 50 mm from where layer 0 ends, so the layer change retracts after the template.
    let program = Program {
        layers: vec![square_layer(0, 10.0), square_layer(1, 60.0)],
    };
    let (abs_text, _) = write(&program, &cfg);
    cfg.printer.use_relative_e_distances = true;
    let (rel_text, _) = write(&program, &cfg);
    assert_same_moves(&abs_text, &rel_text);
}

#[test]
fn events_by_height_come_before_the_first_layer_reaching_them() {
    use crate::program::machine::{LayerGcode, LayerGcodeKind};
    let event = |print_z: f64, kind: LayerGcodeKind, extra: &str| LayerGcode {
        print_z,
        kind,
        tool: None,
        color: String::new(),
        extra: extra.to_owned(),
    };
    let mut cfg = test_config();
    cfg.printer.color_change_gcode = "M600 T{color_change_extruder} ; at {layer_z}".to_owned();
    cfg.printer.template_custom_gcode = "M117 layer {layer_num}".to_owned();
    cfg.printer.custom_gcode_per_print_z = vec![
        event(0.6, LayerGcodeKind::Pause, "swap magnets"),
        LayerGcode {
            tool: Some(0),
            color: "#00FF00".to_owned(),
            ..event(0.3, LayerGcodeKind::ColorChange, "")
        },
        event(0.8, LayerGcodeKind::Custom, "G4 P10\nM117 done"),
        event(0.8, LayerGcodeKind::Template, ""),
        event(5.0, LayerGcodeKind::Pause, "never"),
    ];
    // Four layers 0.2 mm high, each starting 50 mm from where the one below ends, so every
    // layer change retracts.
    let program = Program {
        layers: (0..4)
            .map(|i| square_layer(i, 10.0 + 50.0 * (i % 2) as f64))
            .collect(),
    };
    let (abs_text, _) = write(&program, &cfg);
    let lines: Vec<&str> = abs_text.lines().collect();
    let at = |l: &str| {
        let found: Vec<usize> = (0..lines.len()).filter(|&i| lines[i] == l).collect();
        assert_eq!(found.len(), 1, "{l:?} once in {abs_text}");
        found[0]
    };
    // Each event is in the layer whose top first reaches it, after the move to that layer and
    // before its first extrusion.
    let layer_of = |i: usize| {
        lines[..i]
            .iter()
            .rev()
            .find_map(|l| l.strip_prefix(";Z:"))
            .unwrap_or_default()
    };
    let change = at(";COLOR_CHANGE,T0,#00FF00");
    assert_eq!(lines[change + 1], "M600 T0 ; at 0.4");
    let pause = at(";PAUSE_PRINT");
    assert_eq!(lines[pause + 1..pause + 3], ["M117 swap magnets", "M601"]);
    let custom = (0..lines.len())
        .filter(|&i| lines[i] == ";CUSTOM_GCODE")
        .collect::<Vec<_>>();
    assert_eq!(custom.len(), 2, "{abs_text}");
    assert_eq!(lines[custom[0] + 1..custom[0] + 3], ["G4 P10", "M117 done"]);
    assert_eq!(lines[custom[1] + 1], "M117 layer 3");
    for (i, z) in [(change, "0.4"), (pause, "0.6"), (custom[0], "0.8")] {
        assert_eq!(layer_of(i), z, "{abs_text}");
        let layer_start = (0..i)
            .rev()
            .find(|&k| lines[k] == ";LAYER_CHANGE")
            .unwrap_or(0);
        assert!(
            lines[layer_start..i].iter().any(|l| l.starts_with("G1 Z")),
            "the event follows the move to the layer: {abs_text}"
        );
        assert!(
            !lines[layer_start..i]
                .iter()
                .any(|l| l.starts_with("G1 X") && l.contains(" E")),
            "nothing is extruded on the layer before the event: {abs_text}"
        );
    }
    assert!(
        !abs_text.contains("never"),
        "an event above the print is not written"
    );
    // The firmware's filament change leaves the nozzle primed: the retraction of the layer
    // change (layer 1 starts 50 mm away) is not undone after it, so with relative E the
    // filament moves of that layer change come to one retraction; and absolute E still replays
    // as relative E does.
    cfg.printer.use_relative_e_distances = true;
    let (rel_text, _) = write(&program, &cfg);
    let rel: Vec<&str> = rel_text.lines().collect();
    let from = rel.iter().position(|l| *l == ";Z:0.4").unwrap_or_default();
    let to = (from..rel.len())
        .find(|&k| rel[k].starts_with("G1 X") && rel[k].contains(" E"))
        .unwrap_or(rel.len());
    let filament: f64 = rel[from..to]
        .iter()
        .filter_map(|l| l.strip_prefix("G1 E"))
        .filter_map(|w| w.split_whitespace().next()?.parse::<f64>().ok())
        .sum();
    assert!(
        (filament + cfg.printer.retract_length).abs() < 1e-9,
        "{filament} mm: {rel_text}"
    );
    assert_same_moves(&abs_text, &rel_text);
}

#[test]
fn a_print_with_tool_0_alone_names_no_tool_in_its_temperatures() {
    // As PrusaSlicer: `M104 S` / `M109 S` when the highest tool used is 0, whatever tools the
    // printer has; a print that uses tool 1 too names the tool.
    let mut cfg = two_tool_config();
    cfg.printer.start_gcode = "G28".to_owned();
    cfg.tools[0].first_layer_temperature = 215.0;
    cfg.tools[0].temperature = 205.0;
    let single = Program {
        layers: vec![square_layer(0, 10.0), square_layer(1, 10.0)],
    };
    let (text, _) = write(&single, &cfg);
    for line in ["M104 S215", "M109 S215", "M104 S205"] {
        assert!(text.lines().any(|l| l == line), "{line}: {text}");
    }
    // (The default end G-code's own `M104 T0 S0` is a template's, written as given.)
    for named in ["M104 T0 S2", "M109 T0"] {
        assert!(!text.contains(named), "{named}: {text}");
    }
    let (text, _) = write(&two_tool_program(), &cfg);
    assert!(text.contains("M109 T0 S215"), "{text}");
}

#[test]
fn relative_and_absolute_e_give_the_same_moves() {
    let program = two_tool_program();
    let mut cfg = two_tool_config();
    let (abs_text, abs_stats) = write(&program, &cfg);
    cfg.printer.use_relative_e_distances = true;
    let (rel_text, rel_stats) = write(&program, &cfg);
    assert!(rel_text.contains("M83 ; use relative distances for extrusion"));
    let body = rel_text.find(";LAYER_CHANGE").unwrap_or(0);
    assert!(
        !rel_text[body..].contains("G92 E0"),
        "no E resets in relative mode"
    );
    assert_same_moves(&abs_text, &rel_text);
    assert!((abs_stats.tools[0].filament_mm - rel_stats.tools[0].filament_mm).abs() < 1e-9);
}

#[test]
fn unknown_placeholders_are_errors_naming_them() {
    let mut cfg = test_config();
    cfg.printer.start_gcode = "M190 S{bed_temperature}\nM104 S{nozzle_temp}\n".to_owned();
    let err = write_gcode(&one_layer_program(), &cfg, &mut Vec::new());
    assert!(
        matches!(&err, Err(EmitError::Template { template, error })
            if template == "printer.start_gcode" && error.placeholder == "{nozzle_temp}"
                && error.line == 2),
        "{err:?}"
    );
    let mut cfg = two_tool_config();
    cfg.printer.after_tool_change_gcode = "G1 E{purge_length}".to_owned();
    let err = write_gcode(&two_tool_program(), &cfg, &mut Vec::new());
    assert!(
        matches!(&err, Err(EmitError::Template { error, .. }) if error.placeholder == "{purge_length}")
    );
    // Known placeholders of every kind are filled.
    let mut cfg = two_tool_config();
    cfg.printer.start_gcode =
        "M140 S{bed_temperature} ; {first_layer_bed_temperature} {temperature[0]} \
                               {first_layer_temperature[1]} {layer_height} {total_layer_count}"
            .to_owned();
    let (text, _) = write(&two_tool_program(), &cfg);
    assert!(text.contains("M140 S60 ; 60 210 235 0.2 2\n"), "{text}");
}

#[test]
fn each_tools_own_gcode_frames_its_work() {
    let mut cfg = two_tool_config();
    for (t, tool) in cfg.tools.iter_mut().enumerate() {
        tool.start_gcode = format!("M117 start {{filament_extruder_id}} of {t}");
        tool.end_gcode = "M117 end {filament_extruder_id} at {layer_num}".to_owned();
    }
    cfg.printer.before_tool_change_gcode = "; before {next_tool}".to_owned();
    cfg.printer.after_tool_change_gcode = "; after {next_tool}".to_owned();
    cfg.printer.end_gcode = "M84 ; printer end".to_owned();
    let (text, _) = write(&two_tool_program(), &cfg);
    let lines: Vec<&str> = text.lines().collect();
    let at = |l: &str| {
        lines
            .iter()
            .enumerate()
            .filter(|(_, x)| **x == l)
            .map(|(i, _)| i)
            .collect::<Vec<_>>()
    };
    // Tool 0 starts the print once, after the preamble; each of the two changes puts the old
    // tool away before the change snippets and starts the new one after them; at the end every
    // tool's end G-code, in tool order, comes before the printer's.
    let (start0, start1) = (at("M117 start 0 of 0"), at("M117 start 1 of 1"));
    assert_eq!(start0.len(), 2, "{text}");
    assert_eq!(start1.len(), 1, "{text}");
    assert!(start0[0] > at("G90 ; use absolute coordinates")[0]);
    let before = at("; before 1")[0];
    assert_eq!(lines[before - 1], "M117 end 0 at 0");
    let after = at("; after 1")[0];
    assert_eq!(lines[after + 1], "M117 start 1 of 1");
    assert!(lines[before..after].contains(&"T1"));
    let printer_end = at("M84 ; printer end")[0];
    assert_eq!(
        lines[printer_end - 2..printer_end],
        ["M117 end 0 at 1", "M117 end 1 at 1"]
    );
    assert_eq!(
        at("M117 end 1 at 1").len(),
        2,
        "tool 1 put away at layer 1 and at the end"
    );
}

#[test]
fn globals_carry_across_templates_and_a_position_set_is_taken_over() {
    let mut cfg = two_tool_config();
    cfg.printer.start_gcode = "G28\n{global changes = 0}".to_owned();
    // As the XL's tool change: the firmware lifts the nozzle 2 mm, and the template says so.
    cfg.printer.before_tool_change_gcode =
        "{changes = changes + 1}; change {changes} at z {position[2]}\n\
         {position[2] = position[2] + 2}"
            .to_owned();
    cfg.printer.end_gcode = "; {changes} changes".to_owned();
    let (text, _) = write(&two_tool_program(), &cfg);
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines.contains(&"; 2 changes"), "{text}");
    for (n, z) in [(1, "0.2"), (2, "0.4")] {
        let change = lines
            .iter()
            .position(|l| *l == format!("; change {n} at z {z}"))
            .unwrap_or_else(|| panic!("change {n} in {text}"));
        // The writer believes the nozzle 2 mm up: its travel's lift starts from there, and it
        // comes back down to the layer before it extrudes again.
        let z_of = |l: &&str| {
            l.split_whitespace()
                .find_map(|w| w.strip_prefix('Z'))
                .and_then(|v| v.parse::<f64>().ok())
        };
        let first_z = lines[change..].iter().find_map(z_of).expect("a Z move");
        let layer_z: f64 = z.parse().expect("z");
        assert!(
            first_z >= layer_z + 2.0,
            "first Z {first_z} after change {n}: {text}"
        );
        let first_extrusion = change
            + lines[change..]
                .iter()
                .position(|l| l.starts_with("G1 X") && l.contains(" E"))
                .expect("an extrusion after the change");
        let down = lines[change..first_extrusion]
            .iter()
            .any(|l| l.starts_with("G1") && l.contains(&format!("Z{z}")));
        assert!(down, "no move back to z {z} after change {n}: {text}");
    }
    // A `position` that is no longer three numbers is an error naming the template.
    cfg.printer.before_tool_change_gcode = "{position = 1}".to_owned();
    let err = write_gcode(&two_tool_program(), &cfg, &mut Vec::new());
    assert!(
        matches!(&err, Err(EmitError::Template { template, .. })
            if template == "printer.before_tool_change_gcode"),
        "{err:?}"
    );
}

#[test]
fn unknown_tools_are_errors() {
    let mut program = one_layer_program();
    program.layers[0].items.push(LayerItem::Path(square(
        0.0,
        0.0,
        1.0,
        0.2,
        Role::Perimeter,
        5,
    )));
    assert!(matches!(
        write_gcode(&program, &test_config(), &mut Vec::new()),
        Err(EmitError::UnknownTool { tool: 5, count: 2 })
    ));
}

#[test]
fn output_is_byte_identical_across_runs() {
    let program = two_tool_program();
    let cfg = two_tool_config();
    let (a, _) = write(&program, &cfg);
    let (b, _) = write(&program, &cfg);
    assert_eq!(a.as_bytes(), b.as_bytes());
}

#[test]
fn flavours_differ_in_temperatures_and_firmware_retraction() {
    let program = two_tool_program();
    let mut cfg = two_tool_config();
    cfg.printer.flavor = Flavor::RepRapFirmware;
    cfg.printer.use_firmware_retraction = true;
    let (rrf, _) = write(&program, &cfg);
    assert!(rrf.contains("G10 P0 S210 R170\n"), "{rrf}");
    assert!(rrf.contains("G10 P1 S235 R235\n"));
    assert!(rrf.contains("T1\nM116 P1\n"));
    assert!(!rrf.contains("M104 T0 S170"), "RRF applies standby itself");
    assert!(rrf.contains("G10 ; retract\n") && rrf.contains("G11 ; unretract\n"));
    assert!(!rrf.lines().any(|l| l.starts_with("G1 E")));
    cfg.printer.flavor = Flavor::Klipper;
    let (klipper, _) = write(&program, &cfg);
    assert!(klipper.contains("M104 T0 S170\n") && klipper.contains("M109 T1 S235\n"));
}

#[test]
fn events_become_markers_pauses_and_dwells() {
    let mut program = one_layer_program();
    program.layers[0].items.extend([
        LayerItem::Event(Event::Comment("two\nlines".to_owned())),
        LayerItem::Event(Event::Dwell { seconds: 1.5 }),
        LayerItem::Event(Event::PickAndPlace {
            id: 1,
            part: "R1".to_owned(),
            x: 12.5,
            y: 3.0,
            z: 2.4,
            rotation_deg: 90.0,
        }),
        LayerItem::Event(Event::ManualInsertPause {
            part: "U1".to_owned(),
            message: "insert U1; pin 1 top-left".to_owned(),
        }),
    ]);
    let (text, _) = write(&program, &test_config());
    assert!(text.contains("; two\n; lines\nG4 P1500\n"), "{text}");
    // Marker, lift 10 mm over the layer (0.2), the OctoPNP command, the tool again.
    assert!(
        text.contains(
            ";PICK_AND_PLACE PART=R1 X=12.5 Y=3 Z=2.4 ROTATION=90\nG1 E6.46488 F2100\nG1 Z10.2 F7800\nM361 P1\nT0\n"
        ),
        "{text}"
    );
    assert!(
        text.contains(";MANUAL_INSERT PART=U1\nM117 Insert U1\nM0 insert U1  pin 1 top-left\nT0\n"),
        "{text}"
    );
}

/// A switched-tool job (the jet's style): one layer with a line and a quarter arc between a
/// switch-on and a switch-off with lead time `lead_time`.
fn switched_job(lead_time: f64, arc_chords: Option<f64>) -> (String, GcodeStats) {
    use crate::program::Segment;
    let segments = vec![
        Segment::Line {
            a: [0.0, 0.0],
            b: [1.0, 0.0],
        },
        Segment::Arc {
            a: [1.0, 0.0],
            b: [2.0, 1.0],
            c: [1.0, 1.0],
            r: 1.0,
            sweep: std::f64::consts::FRAC_PI_2,
        },
    ];
    let mut jet = path(
        &[(0.0, 0.0), (1.0, 0.0), (2.0, 1.0)],
        0.01,
        false,
        Role::JetWall,
        1,
    );
    jet.speed = 2.0;
    jet.segments = Some(segments);
    let switch = |on| LayerItem::Event(Event::Switch { on, lead_time });
    let program = Program {
        layers: vec![Layer {
            index: 0,
            z: 0.01,
            height: 0.01,
            items: vec![switch(true), LayerItem::Path(jet), switch(false)],
        }],
    };
    let params = GcodeParams {
        switched: Some(SwitchedParams {
            job: "jet".to_owned(),
            on_gcode: "M42 P5 S255".to_owned(),
            off_gcode: "M42 P5 S0".to_owned(),
            lead_in_comment: "lead-in".to_owned(),
            travel_speed: 10.0,
            e_words: true,
            arc_chords,
            ..SwitchedParams::default()
        }),
        ..GcodeParams::for_tests()
    };
    let mut out: Vec<u8> = Vec::new();
    let stats = write_gcode(&program, &params, &mut out).expect("written");
    (String::from_utf8_lossy(&out).into_owned(), stats)
}

#[test]
fn a_switched_job_writes_arcs_between_the_switch_snippets() {
    let (text, stats) = switched_job(0.0, None);
    let body: Vec<&str> = text.lines().skip_while(|l| *l != "T1").collect();
    assert_eq!(
        body,
        [
            "T1",
            ";LAYER_CHANGE",
            ";Z:0.01",
            ";HEIGHT:0.01",
            "G1 Z0.01 F600",
            ";TYPE:Jet wall",
            ";WIDTH:0.45",
            "G1 X0 Y0",
            "M42 P5 S255",
            "G1 X1 Y0 E1 F120",
            "G3 X2 Y1 I0 J1 E1.5708",
            "M42 P5 S0",
            ";TYPE:Custom",
            "M42 P5 S0",
        ]
    );
    assert!(text.starts_with("; conduit "));
    assert!(text.contains("(jet)\n; flavor = marlin\n; layer count = 1\n"));
    let s = stats.switched.expect("switched totals");
    assert_eq!(s.paths, 1);
    assert!((s.printed_mm - (1.0 + std::f64::consts::FRAC_PI_2)).abs() < 1e-12);
    assert_eq!(s.travel_mm, 0.0, "the first travel starts from nowhere");
    assert!((stats.estimated_time_s - s.printed_mm / 2.0).abs() < 1e-12);
}

#[test]
fn a_switch_lead_time_runs_in_and_switches_off_before_the_end() {
    // 0.25 s at 2 mm/s: half a millimetre.
    let (text, stats) = switched_job(0.25, Some(0.0005));
    let body: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.starts_with(";WIDTH"))
        .collect();
    assert_eq!(
        &body[1..5],
        ["G1 X-0.5 Y0", "M42 P5 S255", "; lead-in", "G1 X0 Y0 F120"]
    );
    assert_eq!(body[5], "G1 X1 Y0 E1");
    let off = body
        .iter()
        .position(|l| *l == "M42 P5 S0")
        .expect("switched off");
    assert!(
        body[6..off].iter().all(|l| l.starts_with("G1 X")),
        "chords, no arcs"
    );
    assert!(
        body[off + 1].starts_with("G1 X"),
        "the path goes on after the switch-off"
    );
    assert!(
        body.iter()
            .any(|l| *l == "G1 X2 Y1" || l.starts_with("G1 X2 Y1 E"))
    );
    let s = stats.switched.expect("switched totals");
    assert!((s.printed_mm - (1.0 + std::f64::consts::FRAC_PI_2)).abs() < 1e-12);
}

#[test]
fn tool_change_snippets_that_move_the_nozzle_leave_every_extrusion_at_its_layer() {
    // A wipe and lift in the tool-change G-code: the writer follows the snippet's moves, so
    // the next tool's first travel writes its own Z and F again instead of printing at the
    // snippet's height and speed.
    let mut cfg = two_tool_config();
    cfg.printer.after_tool_change_gcode =
        "G1 Z{layer_z} F600\nG91\nG1 Z8\nG90\nG1 X150 Y5 F9000".to_owned();
    let (text, _) = write(&two_tool_program(), &cfg);
    let (_, moves) = replay(&text);
    let layer_of = |z: f64| if z < 0.3 { 0.2 } else { 0.4 };
    let extrusions: Vec<&Move> = moves
        .iter()
        .filter(|m| m.de > 0.0 && m.moves_xy())
        .collect();
    assert!(extrusions.len() >= 16, "{text}");
    for m in extrusions {
        let z = m.to[2];
        assert!((z - layer_of(z)).abs() < 1e-9, "extrusion at z {z}: {text}");
        assert!(
            m.from[0] < 100.0 && m.to[0] < 100.0,
            "extrusion from the wipe: {text}"
        );
    }
    // Every travel after a snippet names its feed: the snippet's F9000 is not the travel's.
    let lines: Vec<&str> = text.lines().collect();
    for (i, l) in lines.iter().enumerate() {
        if l.starts_with("G1 X150 Y5") {
            let next_move = lines[i + 1..]
                .iter()
                .find(|l| l.starts_with("G1 X") || l.starts_with("G1 Z"))
                .expect("a move after the snippet");
            assert!(next_move.contains(" F"), "{next_move}: {text}");
        }
    }
}
