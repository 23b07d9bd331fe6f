//! The macro language, construct by construct, with exact output; errors with their line,
//! placeholder and problem; a start and end G-code in the style of the stock Prusa MK4
//! profile.

use std::collections::BTreeMap;

use super::*;

/// Variables from a table; tool 0 is current.
struct Table(BTreeMap<&'static str, Var>, usize);

impl Variables for Table {
    fn var(&self, name: &str) -> Option<Var> {
        self.0.get(name).cloned()
    }
    fn tool(&self) -> usize {
        self.1
    }
}

fn floats(v: &[f64]) -> Var {
    Var::Vector(v.iter().map(|&x| Value::Float(x)).collect())
}

fn strings(v: &[&str]) -> Var {
    Var::Vector(v.iter().map(|&s| Value::from(s)).collect())
}

fn vars() -> Table {
    let mut t = BTreeMap::new();
    t.insert("layer_z", Var::Scalar(Value::Float(0.35000000000000003)));
    t.insert("layer_num", Var::Scalar(Value::Int(3)));
    t.insert("spiral_vase", Var::Scalar(Value::Int(0)));
    t.insert("has_wipe_tower", Var::Scalar(Value::Bool(false)));
    t.insert("nozzle_diameter", floats(&[0.4, 0.6]));
    t.insert(
        "temperature",
        Var::Vector(vec![Value::Int(215), Value::Int(250)]),
    );
    t.insert("filament_type", strings(&["PETG", "FLEX"]));
    t.insert(
        "printer_notes",
        Var::Scalar(Value::from("x\nPRINTER_MODEL_MK4\ny")),
    );
    t.insert("empty_list", Var::Vector(Vec::new()));
    Table(t, 0)
}

fn fill(template: &str) -> Result<String, TemplateError> {
    render(template, &vars())
}

fn problem(template: &str) -> Option<Problem> {
    fill(template).err().map(|e| e.problem)
}

#[test]
fn literals_and_arithmetic() -> Result<(), TemplateError> {
    assert_eq!(
        fill("{1 + 2 * 3}|{(1 + 2) * 3}|{7 / 2}|{7.0 / 2}|{7 % 3}")?,
        "7|9|3|3.5|1"
    );
    assert_eq!(
        fill("{-2 - -3}|{+4}|{1e3}|{.5 * 3}|{10 - 2 - 3}")?,
        "1|4|1000|1.5|5"
    );
    assert_eq!(
        fill("{\"a\\\"b\" + 1 + 2.5}|{1 + 2 + \"x\"}")?,
        "a\"b12.5|3x"
    );
    assert_eq!(
        fill("{true}|{1 < 2}|{layer_z}|{layer_z * 3}")?,
        "true|true|0.35|1.05"
    );
    Ok(())
}

#[test]
fn comparisons_and_logic() -> Result<(), TemplateError> {
    assert_eq!(
        fill("{1 == 1.0}{2 != 2}{1 <> 2}{3 <= 3}{3 >= 4}{2 > 1}{\"b\" < \"a\"}")?,
        "truefalsetruetruefalsetruefalse"
    );
    assert_eq!(
        fill("{1 < 2 and 2 < 3}{1 > 2 or 2 > 3}{1 < 2 && !(2 < 1)}{not true || false}")?,
        "truefalsetruefalse"
    );
    // Floats are equal within 1e-8, as in PrusaSlicer.
    assert_eq!(fill("{0.1 + 0.2 == 0.3}")?, "true");
    // The right side of `and` is not evaluated when the left decides.
    assert_eq!(fill("{false and missing}")?, "false");
    Ok(())
}

#[test]
fn ternary_and_regex() -> Result<(), TemplateError> {
    assert_eq!(
        fill(
            "{(filament_type[0] == \"PC\" or filament_type[0] == \"PA\") ? 1 : \
              (filament_type[0] =~ /.*PET.*/) ? 175 : 170}"
        )?,
        "175"
    );
    assert_eq!(
        fill("{filament_type[1] !~ /.*PET.*/ ? \"soft\" : \"hard\"}")?,
        "soft"
    );
    // Regexes match the whole string, `.` also line breaks.
    assert_eq!(
        fill("{filament_type[0] =~ /PET/}{printer_notes =~ /.*PRINTER_MODEL_MK4.*/}")?,
        "falsetrue"
    );
    Ok(())
}

#[test]
fn if_blocks_nest_and_span_lines() -> Result<(), TemplateError> {
    let t = "A\n{if layer_num == 1}one\n{elsif layer_num == 3}three\n\
             {if nozzle_diameter[1] == 0.6}  big{else}small{endif}\n{else}other{endif}\nB";
    assert_eq!(fill(t)?, "A\nthree\n  big\n\nB");
    assert_eq!(
        fill("{if 0 > 1}x{else}y{endif}|{if 0 > 1}x{endif}|")?,
        "y||"
    );
    assert_eq!(
        fill("{if spiral_vase}vase{elsif !has_wipe_tower}no tower{endif}")?,
        "no tower"
    );
    // Inside one macro, with `then`.
    assert_eq!(
        fill("{if layer_num > 2 then \"G1 Z\" + layer_z; elsif true then 0; else 1; endif}")?,
        "G1 Z0.35"
    );
    // A branch not taken may name what does not exist.
    assert_eq!(fill("{if false}{missing}{endif}ok")?, "ok");
    Ok(())
}

#[test]
fn vectors_and_indexing() -> Result<(), TemplateError> {
    assert_eq!(
        fill("{temperature[1]}|{temperature[layer_num - 2]}|{temperature[9]}|{temperature}")?,
        "250|250|215|215",
        "past the end is element 0; no index is the current tool's"
    );
    assert_eq!(
        render("{temperature}[temperature]", &Table(vars().0, 1))?,
        "250250"
    );
    assert_eq!(
        fill("[nozzle_diameter] [temperature_1] [temperature[layer_num]] [not a key] x[0]")?,
        "0.4 250 215 [not a key] x[0]"
    );
    assert_eq!(
        fill("{size(temperature)} {empty(temperature)} {empty(empty_list)}")?,
        "2 false true"
    );
    Ok(())
}

#[test]
fn functions() -> Result<(), TemplateError> {
    assert_eq!(
        fill("{min(3, 2)} {max(3, 2.5)} {min(1.5, 2)} {max(-1, 0)}")?,
        "2 3 1.5 0"
    );
    assert_eq!(
        fill("{int(2.7)} {int(-2.7)} {round(2.5)} {round(-2.5)} {round(7)}")?,
        "2 -2 3 -3 7"
    );
    assert_eq!(
        fill(
            "[{digits(3.14159, 6, 2)}] [{zdigits(3.14159, 6, 2)}] [{digits(41.6, 4)}] [{zdigits(7, 3)}]"
        )?,
        "[  3.14] [003.14] [  42] [007]"
    );
    assert_eq!(
        fill(
            "{interpolate_table(700, (0, 4000), (1400, 2500), (10000, 2500))} \
              {interpolate_table(1400, (0, 4000), (1400, 2500))} \
              {interpolate_table(20000, (0,1), (10000,1), (30000, 5))}"
        )?,
        "3250 2500 3"
    );
    assert_eq!(
        fill(
            "{one_of(filament_type[0], \"PLA\", \"PETG\")} {one_of(filament_type[1], /PE.*/, ~\"F.*\")} \
              {one_of(filament_type[1], \"PLA\")}"
        )?,
        "true true false"
    );
    assert_eq!(fill("{is_nil(temperature[0])}")?, "false");
    Ok(())
}

#[test]
fn local_and_global_variables() -> Result<(), TemplateError> {
    assert_eq!(
        fill(
            "{local speed = 350.0; if layer_num < 5 then speed = 120; endif; \"G1 F\" + speed * 60}"
        )?,
        "G1 F7200"
    );
    assert_eq!(
        fill(
            "{global pts = (1, 2.5, 3)}{pts[1]}|{local r = repeat(3, 7)}{size(r)}{r[2]}|\
              {local t = temperature}{t[1]}|{pts[0] = 9}{pts[0]}"
        )?,
        "2.5|37|250|9"
    );
    assert_eq!(
        problem("{local layer_num = 1}"),
        Some(Problem::Redefined("layer_num".to_owned()))
    );
    assert_eq!(
        problem("{layer_num = 1}"),
        Some(Problem::ReadOnly("layer_num".to_owned()))
    );
    Ok(())
}

#[test]
fn errors_name_the_line_the_placeholder_and_the_problem() {
    let err = fill("G28\nM104 S{temperature[0] + bogus}\n").err();
    assert_eq!(
        err.map(|e| e.to_string()),
        Some("line 2: unknown variable `bogus` in {temperature[0] + bogus}".to_owned())
    );
    let err = fill("G28\n\nG1 X{(min(1, 2) - }\n").err();
    assert_eq!(
        err.map(|e| e.to_string()),
        Some("line 3: syntax error: expected an expression in {(min(1, 2) - }".to_owned())
    );
    // A syntax error in a branch not taken is still one.
    let err = fill("{if false}\n{1 +* 2}\n{endif}").err();
    assert_eq!(err.as_ref().map(|e| e.line), Some(2));
    assert_eq!(err.map(|e| e.placeholder), Some("{1 +* 2}".to_owned()));
    // In a macro over several lines, the placeholder is the line of the problem.
    let err = fill("{\nlocal a = 1;\na = a + nope;\n}").err();
    assert_eq!(
        err.map(|e| (e.line, e.placeholder, e.problem)),
        Some((
            3,
            "a = a + nope;".to_owned(),
            Problem::UnknownVariable("nope".to_owned())
        ))
    );
    for (t, p) in [
        ("{if true}x", Problem::Syntax("missing {endif}".to_owned())),
        ("{1 + 2", Problem::Syntax("expected `;` or `}`".to_owned())),
        (
            "{\"open}",
            Problem::Syntax("unterminated string".to_owned()),
        ),
        ("{1 / 0}", Problem::DivisionByZero),
        ("{1.5 % 0.0}", Problem::DivisionByZero),
        ("{\"a\" - 1}", Problem::NotNumeric),
        ("{if \"yes\"}x{endif}", Problem::NotBoolean),
        ("{layer_num =~ /3/}", Problem::NotString),
        ("{temperature[-1]}", Problem::NegativeIndex),
        ("{temperature[0.5]}", Problem::NotInteger),
        (
            "{empty_list[0]}",
            Problem::EmptyVector("empty_list".to_owned()),
        ),
        (
            "{size(layer_num)}",
            Problem::NotAVector("layer_num".to_owned()),
        ),
        (
            "{filament_type[0] =~ /(/}",
            Problem::BadRegex("(".to_owned()),
        ),
        (
            "{interpolate_table(5, (0, 1), (2, 3))}",
            Problem::OutsideTable,
        ),
        (
            "{interpolate_table(1, (2, 1), (0, 3))}",
            Problem::TableNotIncreasing,
        ),
        ("{random(1, 2)}", Problem::Random),
        (
            "{abs(-1)}",
            Problem::Syntax("expected `;` or `}`".to_owned()),
        ),
    ] {
        assert_eq!(problem(t), Some(p), "{t}");
    }
}

/// A start and an end G-code written as the stock Prusa MK4 profile writes them (bed-area
/// probing, per-material temperatures, a purge line placed by the print's first layer).
const MK4_START: &str = "\
M17 ; enable steppers
M862.1 P[nozzle_diameter] ; nozzle diameter check
M555 X{(min(print_bed_max[0], first_layer_print_min[0] + 32) - 32)} Y{(max(0, first_layer_print_min[1]) - 4)} W{((min(print_bed_max[0], max(first_layer_print_min[0] + 32, first_layer_print_max[0])))) - ((min(print_bed_max[0], first_layer_print_min[0] + 32) - 32))} H{((first_layer_print_max[1])) - ((max(0, first_layer_print_min[1]) - 4))}
M140 S[first_layer_bed_temperature] ; set bed temp
M104 T0 S{((filament_notes[0]=~/.*HT_MBL10.*/) ? (first_layer_temperature[0] - 10) : (filament_type[0] == \"PC\" or filament_type[0] == \"PA\") ? (first_layer_temperature[0] - 25) : (filament_type[0] == \"FLEX\") ? 210 : (filament_type[0]=~/.*PET.*/) ? 175 : 170)} ; set extruder temp for bed leveling
G1 X{10 + 32} Y-4 Z5 F4800
{if filament_type[initial_tool]==\"FLEX\"}
G1 E-4 F2400 ; retraction
{else}
G1 E-2 F2400 ; retraction
{endif}
{if first_layer_bed_temperature[initial_tool]<=60}M106 S100{endif}
{if is_extruder_used[1]}M104 T1 S{first_layer_temperature[1]}{endif}
G1 E{(filament_type[0] == \"FLEX\" ? 4 : 2)} F2400 ; deretraction
G0 X{45 + 3} Z{0.05} F{8000} ; wipe
G0 X{45 + 3 * 2} Z0.2 F{8000} ; wipe";

const MK4_END: &str = "\
{if layer_z < max_print_height}G1 Z{z_offset+min(layer_z+1, max_print_height)} F720 ; Move print head up{endif}
M104 S0 ; turn off temperature
{if layer_z < max_print_height}G1 Z{z_offset+min(layer_z+23, max_print_height)} F300 ; Move print head up{endif}
M84 X Y E ; disable motors
; max_layer_z = [max_layer_z]";

fn mk4_vars(filament: &str, notes: &str, layer_z: f64) -> Table {
    let mut t = BTreeMap::new();
    t.insert("nozzle_diameter", floats(&[0.4]));
    t.insert("print_bed_max", floats(&[250.0, 210.0]));
    t.insert("first_layer_print_min", floats(&[99.12781, 96.90092]));
    t.insert("first_layer_print_max", floats(&[138.11811, 113.09908]));
    t.insert(
        "first_layer_bed_temperature",
        Var::Vector(vec![Value::Int(60)]),
    );
    t.insert(
        "first_layer_temperature",
        Var::Vector(vec![Value::Int(230)]),
    );
    t.insert("filament_type", strings(&[filament]));
    t.insert("filament_notes", strings(&[notes]));
    t.insert("initial_tool", Var::Scalar(Value::Int(0)));
    t.insert(
        "is_extruder_used",
        Var::Vector(vec![Value::Bool(true), Value::Bool(false)]),
    );
    t.insert("layer_z", Var::Scalar(Value::Float(layer_z)));
    t.insert("max_layer_z", Var::Scalar(Value::Float(48.05)));
    t.insert("max_print_height", Var::Scalar(Value::Float(220.0)));
    t.insert("z_offset", Var::Scalar(Value::Float(0.0)));
    Table(t, 0)
}

#[test]
fn mk4_style_start_and_end_gcode() -> Result<(), TemplateError> {
    let start = render(MK4_START, &mk4_vars("PLA", "", 0.2))?;
    assert_eq!(
        start.lines().collect::<Vec<_>>(),
        [
            "M17 ; enable steppers",
            "M862.1 P0.4 ; nozzle diameter check",
            "M555 X99.1278 Y92.9009 W38.9903 H20.1982",
            "M140 S60 ; set bed temp",
            "M104 T0 S170 ; set extruder temp for bed leveling",
            "G1 X42 Y-4 Z5 F4800",
            "",
            "G1 E-2 F2400 ; retraction",
            "",
            "M106 S100",
            "",
            "G1 E2 F2400 ; deretraction",
            "G0 X48 Z0.05 F8000 ; wipe",
            "G0 X51 Z0.2 F8000 ; wipe",
        ]
    );
    let flex = render(MK4_START, &mk4_vars("FLEX", "", 0.2))?;
    assert!(flex.contains("\nM104 T0 S210 ;"), "{flex}");
    assert!(flex.contains("\nG1 E-4 F2400 ; retraction\n"), "{flex}");
    assert!(flex.contains("\nG1 E4 F2400 ;"), "{flex}");
    let petg = render(MK4_START, &mk4_vars("PETG", "", 0.2))?;
    assert!(petg.contains("\nM104 T0 S175 ;"), "{petg}");
    let ht = render(MK4_START, &mk4_vars("PETG", "notes: HT_MBL10", 0.2))?;
    assert!(ht.contains("\nM104 T0 S220 ;"), "{ht}");

    let end = render(MK4_END, &mk4_vars("PLA", "", 48.25))?;
    assert_eq!(
        end.lines().collect::<Vec<_>>(),
        [
            "G1 Z49.25 F720 ; Move print head up",
            "M104 S0 ; turn off temperature",
            "G1 Z71.25 F300 ; Move print head up",
            "M84 X Y E ; disable motors",
            "; max_layer_z = 48.05",
        ]
    );
    // Near the top of the machine, the lift stops at max_print_height.
    let end = render(MK4_END, &mk4_vars("PLA", "", 210.0))?;
    assert!(end.starts_with("G1 Z211 F720"), "{end}");
    assert!(end.contains("\nG1 Z220 F300"), "{end}");
    Ok(())
}

#[test]
fn nesting_is_bounded_so_a_deep_template_is_an_error_not_a_crash() {
    let deep = Some(Problem::Syntax(
        "nested more than 256 levels deep".to_owned(),
    ));
    let parens = |n: usize| format!("{{{}1{}}}", "(".repeat(n), ")".repeat(n));
    assert_eq!(fill(&parens(200)).ok(), Some("1".to_owned()));
    assert_eq!(problem(&parens(20_000)), deep);
    assert_eq!(
        problem(&format!("{{{}}}", vec!["1"; 100_000].join("+"))),
        deep
    );
    assert_eq!(problem(&format!("{{{}1}}", "-".repeat(100_000))), deep);
    assert_eq!(
        problem(&format!(
            "{}x{}",
            "{if true}".repeat(5000),
            "{endif}".repeat(5000)
        )),
        deep
    );
    // A long chain within the bound evaluates.
    assert_eq!(
        fill(&format!("{{{}}}", vec!["1"; 200].join("+"))).ok(),
        Some("200".to_owned())
    );
}
