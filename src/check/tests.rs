//! Synthetic programs for each modal state and each finding of the checker.

use std::f64::consts::PI;

use super::*;
use crate::program::motion::trapezoid_time;

const HEAT: &str = "M104 S210\nM109 S210\nG28\nG90\nM82\nG92 E0\n";

fn run_with(src: &str, params: &CheckParams) -> CheckReport {
    match conduit_gcode::parse(src.as_bytes()) {
        Ok(g) => check(&g, params),
        Err(e) => panic!("test G-code does not parse: {e}"),
    }
}

fn run(src: &str) -> CheckReport {
    run_with(src, &CheckParams::default())
}

fn filament(r: &CheckReport, tool: usize) -> f64 {
    r.stats
        .tools
        .iter()
        .find(|t| t.tool == tool)
        .map_or(0.0, |t| t.filament_mm)
}

fn kinds(r: &CheckReport) -> Vec<(Severity, FindingKind)> {
    r.findings.iter().map(|f| (f.severity, f.kind)).collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn clean_program_has_no_findings_and_counts_layers() {
    let src = format!(
        "{HEAT}G1 Z0.2 F600\nG1 X10 Y10 F6000\nG1 X20 Y10 E1 F1200\nG1 X20 Y20 E2\n\
         G1 E1.2 F2400 ; retract\nG1 Z0.4\nG1 X10 Y10\nG1 E2 ; unretract\nG1 X20 Y10 E3\n"
    );
    let r = run(&src);
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    assert!(!r.has_errors());
    assert_eq!(r.stats.layers, 2);
    assert_eq!(r.stats.layer_z_range, Some([0.2, 0.4]));
    assert_eq!(r.stats.extrusion_moves, 3);
    assert_eq!(r.stats.travel_moves, 2);
    assert_eq!(r.stats.retractions, 1);
    // Filament used: the E increase of extruding moves only (not the un-retraction).
    assert!(close(filament(&r, 0), 3.0, 1e-12));
    assert!(close(r.stats.tools[0].e_net_mm, 3.0, 1e-12));
    let b = r.stats.extrusion_bounds.expect("bounds");
    assert_eq!(b.min, [10.0, 10.0, 0.2]);
    assert_eq!(b.max, [20.0, 20.0, 0.4]);
    assert!(close(r.stats.print_distance_mm, 30.0, 1e-12));
}

#[test]
fn relative_e_accumulates_and_g92_resets() {
    let rel = run(&format!(
        "{HEAT}M83\nG1 Z0.2\nG1 X10 Y0 E1\nG1 X20 E1.5\nG1 E-0.8\nG1 E0.8\nG1 X30 E0.25\n"
    ));
    assert!(
        close(filament(&rel, 0), 2.75, 1e-12),
        "{:?}",
        rel.stats.tools
    );
    assert!(close(rel.stats.tools[0].e_net_mm, 2.75, 1e-12));
    let abs = run(&format!(
        "{HEAT}G1 Z0.2\nG1 X50 Y0 E5\nG92 E0\nG1 X100 E1\nG92 E100\nG1 X150 E102\n"
    ));
    assert!(close(filament(&abs, 0), 8.0, 1e-12));
    assert!(abs.findings.is_empty(), "{:?}", abs.findings);
    // Marlin: G91 makes E relative too, G90 makes it absolute again.
    let g91 = run(&format!(
        "{HEAT}G1 Z0.2\nG1 X10 Y0 E1\nG91\nG1 X1 E1\nG1 X1 E1\nG90\nG1 X20 E4\n"
    ));
    assert!(
        close(filament(&g91, 0), 4.0, 1e-12),
        "{:?}",
        g91.stats.tools
    );
    assert_eq!(g91.stats.extrusion_bounds.map(|b| b.max[0]), Some(20.0));
    // Klipper: G90 leaves E relative after M83.
    let params = CheckParams {
        flavor: Flavor::Klipper,
        ..CheckParams::default()
    };
    let k = run_with(
        &format!("{HEAT}M83\nG91\nG90\nG1 Z0.2\nG1 X10 Y0 E1\nG1 X20 E1\n"),
        &params,
    );
    assert!(close(filament(&k, 0), 2.0, 1e-12));
}

#[test]
fn inches_scale_every_length_by_25_4() {
    let r = run(&format!(
        "{HEAT}G20\nG1 Z0.01\nG1 X1 Y1 F60\nG1 X2 Y1 E0.1\nG21\nG1 X60 Y25.4 E3.54\n"
    ));
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    let b = r.stats.extrusion_bounds.expect("bounds");
    assert!(
        close(b.max[0], 60.0, 1e-9) && close(b.min[0], 25.4, 1e-9),
        "{b:?}"
    );
    assert!(close(b.min[2], 0.254, 1e-9));
    // 0.1 inch of E is 2.54 mm; then E3.54 mm absolute adds 1 mm.
    assert!(close(filament(&r, 0), 3.54, 1e-9), "{:?}", r.stats.tools);
    assert!(close(r.stats.print_distance_mm, 25.4 + 9.2, 1e-9));
    assert_eq!(r.stats.layers, 1);
}

#[test]
fn arc_length_is_radius_times_angle() {
    let len = |src: &str| {
        let r = run(&format!("{HEAT}G1 Z0.2\nG1 X110 Y100 F600\n{src}\n"));
        assert!(r.findings.is_empty(), "{src}: {:?}", r.findings);
        assert_eq!(r.stats.arcs, 1);
        r.stats.print_distance_mm
    };
    // Quarter circle (r = 10) clockwise about (100, 100), I/J form.
    assert!(close(len("G2 X100 Y90 I-10 J0 E1"), 10.0 * PI / 2.0, 1e-9));
    // The same end counter-clockwise is three quarters.
    assert!(close(
        len("G3 X100 Y90 I-10 J0 E1"),
        10.0 * 3.0 * PI / 2.0,
        1e-9
    ));
    // Start = end: a full circle.
    assert!(close(len("G3 X110 Y100 I-10 J0 E1"), 20.0 * PI, 1e-9));
    // R form: short way (R > 0) and long way (R < 0).
    assert!(close(len("G3 X100 Y110 R10 E1"), 5.0 * PI, 1e-9));
    assert!(close(len("G3 X100 Y110 R-10 E1"), 15.0 * PI, 1e-9));
    // Helical: the Z rise adds in quadrature.
    let h = len("G3 X100 Y110 Z1.2 I-10 J0 E1");
    assert!(close(h, (5.0 * PI).hypot(1.0), 1e-9));
    // A clockwise semicircle bulges to -X: from X = 2 it leaves the bed between its ends,
    // which sampling the arc catches.
    let r = run(&format!(
        "{HEAT}G1 Z0.2\nG1 X20 Y100 F600\nG2 X20 Y120 I0 J10 E1\n"
    ));
    assert!(r.of_kind(FindingKind::OutsideBed).count() == 0);
    let r = run(&format!(
        "{HEAT}G1 Z0.2\nG1 X2 Y100 F600\nG2 X2 Y120 I0 J10 E1\n"
    ));
    assert_eq!(
        r.of_kind(FindingKind::OutsideBed).count(),
        1,
        "{:?}",
        r.findings
    );
    // An R smaller than half the chord is invalid.
    let r = run(&format!("{HEAT}G1 Z0.2\nG1 X10 Y0\nG2 X30 Y0 R5 E1\n"));
    assert_eq!(kinds(&r), vec![(Severity::Error, FindingKind::InvalidArc)]);
}

#[test]
fn time_of_a_long_move_is_trapezoidal() {
    // 100 mm at 100 mm/s with 1000 mm/s²: accelerate 0.1 s over 5 mm, cruise 90 mm in 0.9 s,
    // decelerate 0.1 s: 1.1 s = L/v + v/a.
    assert!(close(trapezoid_time(100.0, 100.0, 1000.0), 1.1, 1e-12));
    // 1 mm never reaches 100 mm/s (needs 10 mm): triangle, 2·√(L/a).
    assert!(close(
        trapezoid_time(1.0, 100.0, 1000.0),
        2.0 * (0.001f64).sqrt(),
        1e-12
    ));
    let params = CheckParams {
        max_acceleration: 1000.0,
        jerk: 0.0,
        ..CheckParams::default()
    };
    let r = run_with("G28\nG1 X100 F6000\nG4 P500\nG4 S2\n", &params);
    assert!(
        close(r.stats.estimated_time_s, 1.1 + 2.5, 1e-9),
        "{}",
        r.stats.estimated_time_s
    );
    // The feed rate cap applies.
    let capped = CheckParams {
        max_feedrate: 50.0,
        ..params.clone()
    };
    let r = run_with("G28\nG1 X100 F6000\n", &capped);
    assert!(close(r.stats.estimated_time_s, 2.0 + 0.05, 1e-9));
    // With jerk, a square of four 50 mm sides at 100 mm/s: each side ramps 10 → 100 → 10 mm/s
    // (0.09 s and 4.95 mm each way) and cruises 40.1 mm.
    let jerk = CheckParams {
        jerk: 10.0,
        ..params
    };
    let r = run_with(
        "G28\nG1 X50 Y50 F6000\nG4 P0\nG1 X100\nG1 Y100\nG1 X50\nG1 Y50\n",
        &jerk,
    );
    let travel_to_start = {
        // 70.71 mm diagonal from rest with 10 mm/s allowed at start and end.
        let l = 50.0 * 2f64.sqrt();
        0.18 + (l - 9.9) / 100.0
    };
    let side = 0.18 + 0.401;
    assert!(
        close(r.stats.estimated_time_s, travel_to_start + 4.0 * side, 1e-9),
        "{}",
        r.stats.estimated_time_s
    );
}

#[test]
fn never_heated_or_heater_off_is_an_error() {
    let r = run("G28\nG1 Z0.2\nG1 X10 Y10 E1\nG1 X20 E2\n");
    assert_eq!(
        kinds(&r),
        vec![(Severity::Error, FindingKind::ColdExtrusion)]
    );
    assert_eq!(r.findings[0].line, 3);
    assert!(r.has_errors());
    let r = run(&format!(
        "{HEAT}G1 Z0.2\nG1 X10 Y10 E1\nM104 S0\nG1 X20 E2\n"
    ));
    assert_eq!(
        kinds(&r),
        vec![(Severity::Error, FindingKind::ColdExtrusion)]
    );
    assert!(
        r.findings[0].message.contains("heater off (line 9)"),
        "{}",
        r.findings[0].message
    );
    // A start macro may heat: only a warning.
    let r = run("PRINT_START BED=60\nG28\nG1 Z0.2\nG1 X10 Y10 E1\n");
    assert_eq!(
        kinds(&r),
        vec![(Severity::Warning, FindingKind::ColdExtrusion)]
    );
    assert!(r.findings[0].message.contains("PRINT_START"));
    // Object labels are not macros that could heat.
    let r = run("EXCLUDE_OBJECT_DEFINE NAME=cube\nG28\nG1 Z0.2\nG1 X10 Y10 E1\n");
    assert_eq!(
        kinds(&r),
        vec![(Severity::Error, FindingKind::ColdExtrusion)]
    );
    // RepRapFirmware 3.3+ sets tool temperatures with M568.
    let r = run("M568 P0 S210\nM116\nG28\nG1 Z0.2\nG1 X10 Y10 E1\n");
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    // Klipper's own temperature commands are understood.
    let r = run("SET_HEATER_TEMPERATURE HEATER=extruder TARGET=210\n\
         TEMPERATURE_WAIT SENSOR=extruder MINIMUM=205\nG28\nG1 Z0.2\nG1 X10 Y10 E1\n");
    assert!(r.findings.is_empty(), "{:?}", r.findings);
}

#[test]
fn heating_without_waiting_is_a_warning_until_time_passes() {
    let r = run("M104 S210\nG28\nG1 Z0.2\nG1 X10 Y10 E1\nG1 X20 E2\n");
    assert_eq!(
        kinds(&r),
        vec![(Severity::Warning, FindingKind::HeatingNotWaited)]
    );
    assert!(!r.has_errors());
    // M116 waits for every heater; RepRapFirmware's G10 sets the temperature.
    let r = run("G10 P0 S215\nM116\nG28\nG1 Z0.2\nG1 X10 Y10 E1\n");
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    // After heat_up_time_s of printing the target counts as reached.
    let r = run("M104 S210\nG28\nG4 S200\nG1 Z0.2\nG1 X10 Y10 E1\n");
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    // Lowering the target after a wait is fine.
    let r = run(&format!("{HEAT}M104 S200\nG1 Z0.2\nG1 X10 Y10 E1\n"));
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    // Below the firmware's minimum extrusion temperature.
    let r = run("M109 S150\nG28\nG1 Z0.2\nG1 X10 Y10 E1\n");
    assert_eq!(
        kinds(&r),
        vec![(Severity::Error, FindingKind::BelowMinTemperature)]
    );
}

#[test]
fn tools_have_their_own_heaters_and_filament() {
    // Tool 1 is the default paste tool: unheated, no temperature check.
    let r = run(&format!(
        "{HEAT}G1 Z0.2\nG1 X10 Y10 E1\nT1\nG1 X20 Y10 E1.5\nT0\nG1 X30 E2\n"
    ));
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    assert_eq!(r.stats.tool_changes, 2);
    assert!(close(filament(&r, 0), 1.5, 1e-12));
    assert!(close(filament(&r, 1), 0.5, 1e-12));
    // With two filament tools, tool 1 must be heated too; M104 T1 addresses it.
    let params = CheckParams {
        tools: vec![ToolCheck::default(), ToolCheck::default()],
        ..CheckParams::default()
    };
    let src = format!("{HEAT}G1 Z0.2\nT1\nG1 X20 Y10 E1.5\n");
    let r = run_with(&src, &params);
    assert_eq!(
        kinds(&r),
        vec![(Severity::Error, FindingKind::ColdExtrusion)]
    );
    let src = format!("{HEAT}M109 T1 S200\nG1 Z0.2\nT1\nG1 X20 Y10 E1.5\n");
    assert!(run_with(&src, &params).findings.is_empty());
    let r = run(&format!("{HEAT}G10\nG11\n"));
    assert_eq!(r.stats.retractions, 1);
}

#[test]
fn moves_outside_the_bed_are_reported_but_prime_lines_are_not() {
    // PrusaSlicer MK3's prime line runs at Y = -3: inside the 5 mm margin.
    let r = run(&format!("{HEAT}G1 Z0.2\nG1 X0 Y-3\nG1 X60 Y-3 E9\n"));
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    let r = run(&format!(
        "{HEAT}G1 Z0.2\nG1 X0 Y-6\nG1 X300 Y10 E9\nG1 X100 Y100\nG1 Z300\n"
    ));
    assert_eq!(
        kinds(&r),
        vec![
            (Severity::Warning, FindingKind::OutsideBed),
            (Severity::Warning, FindingKind::OutsideBed),
            (Severity::Warning, FindingKind::AboveMaxHeight),
        ]
    );
    let r = run(&format!("{HEAT}G1 Z-0.1\nG1 X10 Y10 E1\n"));
    assert_eq!(
        kinds(&r),
        vec![
            (Severity::Warning, FindingKind::BelowBed),
            (Severity::Error, FindingKind::BelowBed)
        ]
    );
    // The bed origin moves the allowed area.
    let params = CheckParams {
        bed_origin: [-125.0, -125.0],
        ..CheckParams::default()
    };
    let r = run_with(
        &format!("{HEAT}G1 Z0.2\nG1 X-120 Y-120\nG1 X120 E9\n"),
        &params,
    );
    assert!(r.findings.is_empty(), "{:?}", r.findings);
}

#[test]
fn extrusion_amount_findings() {
    // Wiping: a small retraction while moving is normal, a large one is not.
    let r = run(&format!(
        "{HEAT}G1 Z0.2\nG1 X10 Y10 E1\nG1 X20 E0.2\nG1 X30 E-6\n"
    ));
    assert_eq!(
        kinds(&r),
        vec![(Severity::Warning, FindingKind::RetractionWhileMoving)]
    );
    assert_eq!(r.findings[0].line, 10);
    // A forgotten G92 E0 in absolute mode.
    let r = run(&format!("{HEAT}G1 Z0.2\nG1 X10 Y10 E500\nG1 X20 E1\n"));
    assert!(kinds(&r).contains(&(Severity::Error, FindingKind::LostExtrusionReset)));
    // 10 mm of filament over a 10 mm path: 2.405 mm³/mm, 19× a 0.4 mm nozzle's area.
    let r = run(&format!("{HEAT}G1 Z0.2\nG1 X10 Y10\nG1 X20 E10\n"));
    assert_eq!(
        kinds(&r),
        vec![(Severity::Warning, FindingKind::ExcessiveExtrusion)]
    );
    assert!(
        r.findings[0].message.contains("19.1×"),
        "{}",
        r.findings[0].message
    );
    // A normal line: 0.45 × 0.2 mm over 10 mm is E 0.374 (0.72× the nozzle's area).
    let r = run(&format!("{HEAT}G1 Z0.2\nG1 X10 Y10\nG1 X20 E0.374\n"));
    assert!(r.findings.is_empty());
}

#[test]
fn findings_are_capped_per_kind_but_counted() {
    let mut src = String::from("G28\nG1 Z0.2\n");
    for i in 0..30 {
        src.push_str(&format!("G1 X{} Y300\n", i + 1));
    }
    let params = CheckParams {
        max_findings_per_kind: 5,
        ..CheckParams::default()
    };
    let r = run_with(&src, &params);
    assert_eq!(r.findings.len(), 5);
    assert_eq!(r.counts.get(&FindingKind::OutsideBed), Some(&30));
    assert_eq!(r.warnings, 30);
    let text = r.to_string();
    assert!(
        text.contains("... and 25 more outside_bed findings"),
        "{text}"
    );
    let json = serde_json::to_string(&r).unwrap_or_default();
    assert!(json.contains("\"outside_bed\":30"), "{json}");
}

#[test]
fn bare_coordinates_continue_the_last_motion() {
    let r = run(&format!("{HEAT}G1 Z0.2\nG1 X10 Y10 E1\nX20 E2\nX30 E3\n"));
    assert_eq!(r.stats.extrusion_moves, 3);
    assert!(close(filament(&r, 0), 3.0, 1e-12));
}

#[test]
fn parameters_that_are_not_numbers_are_errors_on_moves_only() {
    let r =
        run("M104 S210\nM109 S210\nG1 X10 Y10 F1200\nG1 XNaN Y5\nG92 Einf\nM106 Sx\nG1 X5 Y5\n");
    assert_eq!(
        kinds(&r),
        [
            (Severity::Error, FindingKind::UnreadableParameter),
            (Severity::Error, FindingKind::UnreadableParameter),
        ]
    );
    assert_eq!(r.findings[0].line, 4);
    assert!(
        r.findings[0].message.contains("`XNaN`"),
        "{}",
        r.findings[0].message
    );
    assert_eq!(r.findings[1].line, 5);
}
