//! Tests of the TOML config: defaults, kind-dependent tool defaults, errors naming keys, `--set`.

use super::*;

fn parse(src: &str) -> Result<Config, ConfigError> {
    Config::parse(src).map(|(c, _)| c)
}

#[test]
fn empty_file_is_the_default_two_tool_printer() -> Result<(), ConfigError> {
    let cfg = parse("")?;
    assert_eq!(cfg, Config::default());
    assert_eq!(cfg.tools.len(), 2);
    assert_eq!(cfg.tools[0].kind, ToolKind::Filament);
    assert_eq!(cfg.tools[1].kind, ToolKind::Paste);
    assert_eq!(cfg.slice.layer_height, 0.2);
    assert_eq!(cfg.slice.perimeter_speed, 45.0);
    assert_eq!(cfg.printer.bed_size, [250.0, 250.0]);
    assert!(Config::default().validate()?.is_empty());
    Ok(())
}

#[test]
fn tool_tables_take_the_defaults_of_their_kind() -> Result<(), ConfigError> {
    let cfg = parse(
        "[tools.0]\nname = \"PETG\"\ntemperature = 240\n\n\
         [tools.1]\nkind = \"paste\"\nnozzle_diameter = 0.25\n\n\
         [tools.2]\nstandby_temperature = 170\n",
    )?;
    assert_eq!(cfg.tools.len(), 3);
    assert_eq!(cfg.tools[0].name, "PETG");
    assert_eq!(cfg.tools[0].temperature, 240.0);
    assert_eq!(cfg.tools[0].first_layer_temperature, 210.0);
    assert_eq!(
        cfg.tools[1],
        Tool {
            nozzle_diameter: 0.25,
            ..Tool::paste()
        }
    );
    assert_eq!(cfg.tools[2].standby_temperature, Some(170.0));
    assert_eq!(cfg.tools[2].kind, ToolKind::Filament);
    // An array of tables works too.
    let cfg = parse("[[tools]]\nkind = \"paste\"\n")?;
    assert_eq!(cfg.tools, vec![Tool::paste()]);
    Ok(())
}

#[test]
fn slice_keys_of_the_regions_stage_sit_in_the_slice_table() -> Result<(), ConfigError> {
    let cfg = parse(
        "[slice]\nlayer_height = 0.3\nperimeters = 3\ninfill_pattern = \"grid\"\n\
         first_layer_height = 0.25\nconductive_speed = 8\nobject_tools = [0, 1]\n",
    )?;
    assert_eq!(cfg.slice.layer_height, 0.3);
    assert_eq!(cfg.slice.perimeters, 3);
    assert_eq!(
        cfg.slice.infill_pattern,
        crate::region::InfillPatternKind::Grid
    );
    assert_eq!(cfg.slice.first_layer_height, 0.25);
    assert_eq!(cfg.slice.conductive_speed, 8.0);
    assert_eq!(cfg.tool_for_object(1), 1);
    assert_eq!(cfg.tool_for_object(5), 0);
    Ok(())
}

#[test]
fn typos_are_errors_naming_the_key_and_line() {
    for (src, key, line) in [
        (
            "[printer]\nflavor = \"marlin\"\nbed_sise = [1, 2]\n",
            "bed_sise",
            3,
        ),
        ("\n[slice]\nperimetres = 3\n", "perimetres", 3),
        ("[tools.0]\n\ntemprature = 200\n", "temprature", 3),
        ("[printr]\n", "printr", 1),
    ] {
        match parse(src) {
            Err(ConfigError::Toml {
                line: Some(l),
                message,
                ..
            }) => {
                assert!(message.contains(key), "{message}");
                assert_eq!(l, line, "{src:?}: {message}");
            }
            other => panic!("{src:?} gave {other:?}"),
        }
    }
    let err = parse("[printer]\nflavor = \"sprinter\"\n").err();
    assert!(format!("{err:?}").contains("sprinter"), "{err:?}");
}

#[test]
fn tool_numbers_must_not_have_gaps() {
    let err = parse("[tools.1]\ntemperature = 25\n").err();
    let text = err.map(|e| e.to_string()).unwrap_or_default();
    assert!(text.contains("tools.0 is missing"), "{text}");
    let err = parse("[tools.a]\n").err();
    assert!(err.is_some());
}

#[test]
fn validation_reports_every_problem() {
    let err = parse("[slice]\nlayer_height = -1\nobject_tools = [3]\nperimeter_speed = 0\n").err();
    match err {
        Some(ConfigError::Invalid { problems }) => {
            assert_eq!(problems.len(), 3, "{problems:?}");
            assert!(problems.iter().any(|p| p.contains("object_tools[0] = 3")));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn set_edits_any_key_by_dotted_path() -> Result<(), ConfigError> {
    let mut cfg = Config::default();
    cfg.apply_set("slice.layer_height=0.3")?;
    cfg.apply_set("tools.1.temperature=25")?;
    cfg.apply_set("printer.flavor=klipper")?;
    cfg.apply_set("printer.bed_size = [200, 210.5]")?;
    cfg.apply_set("tools.0.standby_temperature=150")?;
    cfg.apply_set("tools.2.kind=paste")?;
    cfg.apply_set("printer.start_gcode=\"G28\"")?;
    assert_eq!(cfg.slice.layer_height, 0.3);
    assert_eq!(cfg.tools[1].temperature, 25.0);
    assert_eq!(cfg.printer.flavor, Flavor::Klipper);
    assert_eq!(cfg.printer.bed_size, [200.0, 210.5]);
    assert_eq!(cfg.tools[0].standby_temperature, Some(150.0));
    assert_eq!(cfg.tools[2], Tool::paste());
    assert_eq!(cfg.printer.start_gcode, "G28");
    let before = cfg.clone();
    for bad in [
        "slice.layer_hieght=0.3",
        "tools.1.temprature=3",
        "route.grid=1",
        "slice.layer_height",
        "slice.layer_height=thick",
        "tools.5.temperature=200",
        "slice.layer_height.x=1",
    ] {
        match cfg.apply_set(bad) {
            Err(ConfigError::Set { key, message }) => {
                assert!(bad.starts_with(&key), "{bad}: {key}");
                if bad.contains("hieght") || bad.contains("temprature") {
                    let wrong =
                        bad.split(['.', '='])
                            .nth(if bad.starts_with("tools") { 2 } else { 1 });
                    assert!(message.contains(wrong.unwrap_or("?")), "{bad}: {message}");
                }
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
    assert_eq!(cfg, before);
    Ok(())
}

#[test]
fn config_round_trips_through_toml() -> Result<(), ConfigError> {
    let mut cfg = Config::default();
    cfg.tools[0].retract_length = Some(1.5);
    cfg.slice.object_tools = vec![1, 0];
    let back = parse(&cfg.to_toml_string())?;
    assert_eq!(back, cfg);
    Ok(())
}

#[test]
fn load_picks_the_format_by_extension() -> Result<(), Box<dyn std::error::Error>> {
    let dir = tempfile::tempdir()?;
    let toml_path = dir.path().join("c.toml");
    std::fs::write(&toml_path, "[slice]\nlayer_height = 0.1\n")?;
    let (cfg, warnings) = load(&toml_path)?;
    assert_eq!(cfg.slice.layer_height, 0.1);
    assert!(warnings.is_empty());
    let ini_path = dir.path().join("p.ini");
    std::fs::write(&ini_path, "layer_height = 0.15\nbogus = 1\n")?;
    let (cfg, warnings) = load(&ini_path)?;
    assert_eq!(cfg.slice.layer_height, 0.15);
    assert_eq!(
        prusa_ini::tests::stated(&warnings),
        ["1 PrusaSlicer key ignored (none that change the print); all of them: bogus"]
    );
    std::fs::write(&ini_path, "layer_height = 0.15\nperimeters = x\n")?;
    let err = load(&ini_path)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(err.contains("p.ini:2: perimeters"), "{err}");
    let bad = dir.path().join("c.json");
    assert!(matches!(load(&bad), Err(ConfigError::UnknownFormat { .. })));
    let bad_toml = dir.path().join("bad.toml");
    std::fs::write(&bad_toml, "[slice]\n\nlayer_height = \"x\"\n")?;
    let err = load(&bad_toml)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(err.contains("bad.toml:3"), "{err}");
    Ok(())
}

#[test]
fn every_corrections_mode_parses_from_its_name() -> Result<(), ConfigError> {
    for mode in Corrections::ALL {
        let cfg = parse(&format!("[conform]\ncorrections = \"{}\"\n", mode.name()))?;
        assert_eq!(cfg.conform.corrections, mode);
    }
    Ok(())
}

#[test]
fn default_start_and_end_gcode_check_clean() -> Result<(), ConfigError> {
    let cfg = Config::default();
    let start = cfg.render_template(&cfg.printer.start_gcode, 0, &[])?;
    let end = cfg.render_template(&cfg.printer.end_gcode, 0, &[])?;
    let src = format!("{start}G1 Z0.2\nG1 X100 Y100 E1\n{end}");
    let g = match conduit_gcode::parse(src.as_bytes()) {
        Ok(g) => g,
        Err(e) => panic!("{e}"),
    };
    let r = crate::check::check(&g, &cfg.check_params());
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    // The prime line (9 mm) and the one line (1 mm).
    let filament = r
        .stats
        .tools
        .iter()
        .find(|t| t.tool == 0)
        .map_or(0.0, |t| t.filament_mm);
    assert!((filament - 10.0).abs() <= 1e-12, "{filament}");
    assert_eq!(r.stats.max_bed_temperature, Some(60.0));
    Ok(())
}

#[test]
fn route_keys_build_the_electronics_params() -> Result<(), ConfigError> {
    // The defaults of `[route]` are the router's own.
    let params = Config::default().electronics_params();
    assert_eq!(params.route, crate::route::RouteParams::default());
    assert_eq!((params.conductive_tool, params.tool_count), (1, 2));
    let cfg = parse(
        "[route]\nconductive_tool = 0\nconductive_width = 0.4\nrip_up_rounds = 0\npad_drops = true\n\
         [slice]\nperimeter_width = 0.5\nconductive_speed = 7\n",
    )?;
    let params = cfg.electronics_params();
    assert_eq!(params.route.conductive_width, 0.4);
    assert_eq!(params.route.rip_up_rounds, 0);
    assert_eq!(params.route.perimeter_width, 0.5);
    assert_eq!(params.conductive_speed, 7.0);
    assert_eq!(params.conductive_tool, 0);
    assert!(params.pad_drops);
    Ok(())
}

#[test]
fn the_default_config_reads_host_layers_as_the_default_layer_params() {
    let cfg = Config::default();
    assert_eq!(
        cfg.host_layer_params(),
        crate::postprocess::LayerParams::default()
    );
    let params = cfg.postprocess_params();
    assert_eq!(params.electronics, cfg.electronics_params());
    assert_eq!(params.gcode, cfg.gcode_params());
}

#[test]
fn slice_settings_round_trip_through_json_with_defaults_filled_in() -> Result<(), serde_json::Error>
{
    let s: SliceSettings = serde_json::from_str(r#"{"perimeters": 3, "infill_pattern": "grid"}"#)?;
    assert_eq!(s.perimeters, 3);
    assert_eq!(s.infill_pattern, crate::region::InfillPatternKind::Grid);
    assert_eq!(s.skirt_distance, 6.0);
    let back: SliceSettings = serde_json::from_str(&serde_json::to_string(&s)?)?;
    assert_eq!(back, s);
    assert!(serde_json::from_str::<SliceSettings>(r#"{"perimetres": 3}"#).is_err());
    let region = Config {
        slice: s,
        ..Config::default()
    }
    .region_params();
    assert_eq!(region.perimeters, 3);
    assert_eq!(region.skirt_distance, 6.0);
    Ok(())
}

#[test]
fn errors_name_the_key_and_suggest_the_closest() {
    let text = |src: &str| parse(src).err().map(|e| e.to_string()).unwrap_or_default();
    assert_eq!(
        text("[slice]\nlayer_height = \"x\"\n"),
        "config:2: slice.layer_height must be a number in mm, got \"x\""
    );
    assert_eq!(
        text("[tools.1]\nnozzle_diameter = true\n"),
        "config:2: tools.1.nozzle_diameter must be a number in mm, got true"
    );
    assert_eq!(
        text("[slice]\nperimeters = 2.5\n"),
        "config:2: slice.perimeters must be a whole number ≥ 0, got 2.5"
    );
    assert_eq!(
        text("[slice]\nperimeters = -1\n"),
        "config:2: slice.perimeters must be a whole number ≥ 0, got -1"
    );
    assert_eq!(
        text("[slice]\nobject_tools = 3\n"),
        "config:2: slice.object_tools must be a list `[…]`, got 3"
    );
    assert_eq!(
        text("[tools.0]\ntemperature = \"hot\"\n"),
        "config:2: tools.0.temperature must be a number in °C, got \"hot\""
    );
    assert_eq!(
        text("[printer]\nuse_relative_e_distances = 1\n"),
        "config:2: printer.use_relative_e_distances must be true or false, got 1"
    );
    // No message names a Rust type.
    for src in [
        "[printer]\nbed_size = [1]\n",
        "[printer]\nbed_size = \"x\"\n",
        "[printer]\nflavor = \"sprinter\"\n",
        "[slice]\nperimeters = true\n",
        "[tools.0]\nname = 3\n",
    ] {
        let t = text(src);
        assert!(t.contains(" must be "), "{src:?}: {t}");
        for word in [
            "f64", "u32", "usize", "Option", "Vec", "sequence", "expected",
        ] {
            assert!(!t.contains(word), "{src:?}: {t}");
        }
    }
    let mut cfg = Config::default();
    let err = cfg.apply_set("slice.layer_height=abc").err();
    assert_eq!(
        err.map(|e| e.to_string()).as_deref(),
        Some("--set slice.layer_height must be a number in mm, got \"abc\"")
    );
    assert_eq!(
        text("[slice]\nlayerheight = 0.3\n"),
        "config:2: slice.layerheight: unknown key `layerheight`; did you mean `layer_height`?"
    );
    assert!(
        text("[slice]\nfoo = 1\n")
            .ends_with("unknown key `foo` (`conduit config --defaults` lists every key)"),
    );
    let mut cfg = Config::default();
    let err = cfg
        .apply_set("curved.max_anlge=30")
        .err()
        .map(|e| e.to_string());
    assert_eq!(
        err.as_deref(),
        Some("--set curved.max_anlge: unknown key `max_anlge`; did you mean `max_angle`?")
    );
}

/// The problems `validate` finds in `src`.
fn problems(src: &str) -> Vec<String> {
    match parse(src) {
        Err(ConfigError::Invalid { problems }) => problems,
        other => panic!("{src:?}: expected invalid, got {other:?}"),
    }
}

#[test]
fn keys_that_size_work_have_ranges_naming_the_key() {
    for (src, expected) in [
        (
            "[slice]\nperimeters = 1000000000000000000\n",
            "slice.perimeters must be at most 100, got 1000000000000000000",
        ),
        (
            "[slice]\nskirt_loops = 100000000\n",
            "slice.skirt_loops must be at most 100, got 100000000",
        ),
        (
            "[slice]\ntop_solid_layers = 101\n",
            "slice.top_solid_layers must be at most 100, got 101",
        ),
        (
            "[slice]\nbottom_solid_layers = 5000\n",
            "slice.bottom_solid_layers must be at most 100, got 5000",
        ),
        (
            "[slice]\nlayer_height = 1e-9\n",
            "slice.layer_height must be between 0.01 and 0.4 mm, got 0.000000001",
        ),
        (
            "[slice]\nlayer_height = 0.5\n",
            "slice.layer_height must be between 0.01 and 0.4 mm, got 0.5",
        ),
        (
            "[slice]\nfirst_layer_height = 0.001\n",
            "slice.first_layer_height must be between 0.01 mm and 2 × slice.nozzle_diameter \
             (0.8 mm), got 0.001",
        ),
        (
            "[slice]\nperimeter_width = 1e39\n",
            "slice.perimeter_width must be at most 1.2 mm (3 × nozzle_diameter, at most 10 mm), \
             got 1000000000000000000000000000000000000000",
        ),
        (
            "[slice]\nskirt_distance = 1e12\n",
            "slice.skirt_distance must be at most the bed size (250 mm), got 1000000000000",
        ),
        (
            "[slice]\nsolid_infill_margin = 500\n",
            "slice.solid_infill_margin must be between 0 and 100 mm, got 500",
        ),
        (
            "[slice]\ninfill_speed = 1e9\n",
            "slice.infill_speed must be at most 1000 mm/s, got 1000000000",
        ),
        (
            "[printer]\nmax_height = 1e9\n",
            "printer.max_height must be at most 10000 mm, got 1000000000",
        ),
        (
            "[printer]\nfirst_layer_bed_temperature = nan\n",
            "printer.first_layer_bed_temperature must be between 0 and 500 °C, got NaN",
        ),
    ] {
        let problems = problems(src);
        assert!(
            problems.iter().any(|p| p == expected),
            "{src}: {problems:?}"
        );
    }
}

#[test]
fn values_at_the_bounds_are_valid() -> Result<(), ConfigError> {
    let cfg = parse(
        "[slice]\nperimeters = 100\nskirt_loops = 100\ntop_solid_layers = 100\n\
         bottom_solid_layers = 100\nlayer_height = 0.4\nfirst_layer_height = 0.01\n\
         perimeter_width = 1.2\nskirt_distance = 250\ninfill_speed = 1000\n",
    )?;
    assert_eq!(cfg.slice.perimeters, 100);
    Ok(())
}

#[test]
fn ini_counts_too_large_for_a_count_name_the_key() {
    let err = prusa_ini::from_ini_str("perimeters = 1e39\n").err();
    assert!(
        matches!(&err, Some(ConfigError::Ini { key, message, .. })
            if key == "perimeters" && message == "too large for a count"),
        "{err:?}"
    );
    let err = prusa_ini::from_ini_str("skirts = 9223372036854775807\n").err();
    let text = err.map(|e| e.to_string()).unwrap_or_default();
    assert!(
        text.contains("slice.skirt_loops must be at most 100, got 9223372036854775807"),
        "{text}"
    );
}
