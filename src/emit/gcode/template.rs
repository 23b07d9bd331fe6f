//! Filling the custom G-code templates of the printer and the tools, in PrusaSlicer's macro
//! language.
//!
//! Syntax: PrusaSlicer's ([`super::macros`]): `{key}`, `{key[N]}`, expressions such as
//! `{first_layer_temperature[0] - 10}`, `{if …}…{elsif …}…{else}…{endif}`, the functions
//! (`min`, `max`, `interpolate_table`, …) and the legacy `[key]` form (left as written when
//! `key` is unknown: square brackets also appear in ordinary comments).
//!
//! A name is looked up, in order, in the caller's variables (the writer's: `layer_z`,
//! `layer_num`, `next_tool`, `first_layer_print_min`, …), in `[printer]`, in `[slice]`, in the
//! tools (`{temperature[1]}` is tool 1's temperature, `{temperature}` the current tool's), in
//! the imported slicer profile (`printer.profile`: `{filament_type[0]}`, `{z_offset}`), and
//! last among the names derived from these: `print_bed_min`, `print_bed_max`,
//! `print_bed_size` (the bed's corners and size), `current_extruder` (the current tool),
//! `next_extruder` / `previous_extruder` (the writer's `next_tool` / `previous_tool`),
//! `num_extruders` (the filament tools), `filament_type` (the tools' names) and
//! `has_single_extruder_multi_material_priming` (a wipe tower and the profile's priming on).
//!
//! Place in the pipeline: inside the G-code writer, which fills every template it writes; the
//! `[slice]` keys come from [`GcodeParams::template_keys`].

use super::GcodeParams;
use super::macros::{self, Value, Var, Variables};
use crate::program::machine::ToolKind;

pub use super::macros::TemplateError;

impl GcodeParams {
    /// Fills `template` (see the syntax above) for tool `tool`, with the caller's extra
    /// variables `vars` (such as `previous_tool`, `next_tool`, `layer_z`) taking precedence
    /// over config keys.
    ///
    /// ```
    /// let params = conduit::config::Config::default().gcode_params();
    /// let g = params
    ///     .render_template(
    ///         "M190 S{first_layer_bed_temperature}\nM109 S[temperature]\n\
    ///          {if first_layer_temperature[0] > 200}M106 S{255 / 2}{endif}",
    ///         0,
    ///         &[],
    ///     )
    ///     .expect("known placeholders");
    /// assert_eq!(g, "M190 S60\nM109 S210\nM106 S127");
    /// ```
    pub fn render_template(
        &self,
        template: &str,
        tool: usize,
        vars: &[(&str, Var)],
    ) -> Result<String, TemplateError> {
        self.render_template_with(template, tool, vars, &mut macros::Globals::new())
    }

    /// [`Self::render_template`] with the `global` variables of the templates before it, which
    /// keep what this one defines or assigns.
    pub fn render_template_with(
        &self,
        template: &str,
        tool: usize,
        vars: &[(&str, Var)],
        globals: &mut macros::Globals,
    ) -> Result<String, TemplateError> {
        let scope = Scope {
            params: self,
            printer: toml::Value::try_from(&self.printer).ok(),
            tools: self
                .tools
                .iter()
                .filter_map(|t| toml::Value::try_from(t).ok())
                .collect(),
            tool,
            vars,
        };
        macros::render_with(template, &scope, globals)
    }
}

/// The variables of one rendering: the caller's, the config's, the profile's.
struct Scope<'a> {
    params: &'a GcodeParams,
    /// The printer as a TOML table.
    printer: Option<toml::Value>,
    /// The tools as TOML tables.
    tools: Vec<toml::Value>,
    tool: usize,
    vars: &'a [(&'a str, Var)],
}

impl Variables for Scope<'_> {
    fn var(&self, name: &str) -> Option<Var> {
        let caller = |n: &str| self.vars.iter().find(|(k, _)| *k == n).map(|(_, v)| v);
        if let Some(v) = caller(name) {
            return Some(v.clone());
        }
        let config = self
            .printer
            .as_ref()
            .and_then(|p| p.get(name))
            .or_else(|| self.params.template_keys.get(name))
            .and_then(toml_var);
        if config.is_some() {
            return config;
        }
        let tools: Option<Vec<Value>> = self
            .tools
            .iter()
            .map(|t| t.get(name).and_then(toml_value))
            .collect();
        if let Some(values) = tools.filter(|v| !v.is_empty()) {
            return Some(Var::Vector(values));
        }
        if let Some(raw) = self.params.printer.profile.get(name) {
            return Some(profile_var(name, raw));
        }
        self.derived(name, caller)
    }

    fn tool(&self) -> usize {
        self.tool
    }
}

impl Scope<'_> {
    /// The names PrusaSlicer defines that conduit derives from its own settings.
    fn derived<'v>(&self, name: &str, caller: impl Fn(&str) -> Option<&'v Var>) -> Option<Var> {
        let p = &self.params.printer;
        let pair = |a: f64, b: f64| Var::Vector(vec![Value::Float(a), Value::Float(b)]);
        Some(match name {
            "print_bed_min" => pair(p.bed_origin[0], p.bed_origin[1]),
            "print_bed_max" => pair(
                p.bed_origin[0] + p.bed_size[0],
                p.bed_origin[1] + p.bed_size[1],
            ),
            "print_bed_size" => pair(p.bed_size[0], p.bed_size[1]),
            "current_extruder" => Var::Scalar(Value::from(self.tool)),
            "next_extruder" => caller("next_tool")?.clone(),
            "previous_extruder" => caller("previous_tool")?.clone(),
            "num_extruders" => Var::Scalar(Value::from(
                self.params
                    .tools
                    .iter()
                    .filter(|t| t.kind == ToolKind::Filament)
                    .count(),
            )),
            // PrusaSlicer: a wipe tower with single-extruder priming on.
            "has_single_extruder_multi_material_priming" => {
                let tower = match caller("has_wipe_tower") {
                    Some(Var::Scalar(v)) => v.truth().unwrap_or(false),
                    _ => false,
                };
                let priming = self
                    .params
                    .printer
                    .profile
                    .get("single_extruder_multi_material_priming")
                    .is_some_and(|v| v.trim() == "1");
                Var::Scalar(Value::Bool(tower && priming))
            }
            "filament_type" => Var::Vector(
                self.params
                    .tools
                    .iter()
                    .map(|t| Value::from(t.name.as_str()))
                    .collect(),
            ),
            _ => return None,
        })
    }
}

/// A config value as a variable: arrays are vectors, tables are not variables.
fn toml_var(v: &toml::Value) -> Option<Var> {
    match v {
        toml::Value::Array(a) => a
            .iter()
            .map(toml_value)
            .collect::<Option<Vec<_>>>()
            .map(Var::Vector),
        v => toml_value(v).map(Var::Scalar),
    }
}

fn toml_value(v: &toml::Value) -> Option<Value> {
    match v {
        toml::Value::String(s) => Some(Value::Str(s.clone())),
        toml::Value::Integer(i) => Some(Value::Int(*i)),
        toml::Value::Float(f) => Some(Value::Float(*f)),
        toml::Value::Boolean(b) => Some(Value::Bool(*b)),
        _ => None,
    }
}

/// A profile value as PrusaSlicer would type it, told from its text: `"a";"b"` (and a
/// `filament_…` key's `a;b`) a vector of strings, `0.4,0.6` a vector of numbers, `215` or
/// `0.2` a number, anything else a string (with `\n` escapes undone).
fn profile_var(key: &str, raw: &str) -> Var {
    let raw = raw.trim();
    if raw.starts_with('"')
        && let Some(items) = conduit_gcode::string_list(raw)
    {
        return Var::Vector(items.into_iter().map(Value::Str).collect());
    }
    if (key.starts_with("filament_") || key.ends_with("_colour")) && raw.contains(';') {
        return Var::Vector(raw.split(';').map(|s| Value::from(s.trim())).collect());
    }
    let numbers: Option<Vec<Value>> = raw.split(',').map(|s| number(s.trim())).collect();
    match numbers {
        Some(mut n) if n.len() == 1 => Var::Scalar(n.remove(0)),
        Some(n) => Var::Vector(n),
        None => Var::Scalar(Value::Str(conduit_gcode::unescape_cstyle(raw))),
    }
}

fn number(s: &str) -> Option<Value> {
    if let Ok(i) = s.parse::<i64>() {
        return Some(Value::Int(i));
    }
    // Rust also parses `inf` and `nan`; a profile's numbers are plain decimals.
    let plain = !s.is_empty()
        && s.bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E'));
    plain
        .then(|| s.parse::<f64>().ok().map(Value::Float))
        .flatten()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::gcode::macros::Problem;

    #[test]
    fn placeholders_are_filled_from_every_section() -> Result<(), TemplateError> {
        let cfg = GcodeParams::for_tests();
        let t = "M140 S{first_layer_bed_temperature}\nM104 T1 S{first_layer_temperature[1]}\n\
                 ; {name} {layer_height} [temperature] {bed_size[0]} {next_tool} [unknown] a[0]";
        let out = cfg.render_template(t, 0, &[("next_tool", Var::Scalar(Value::Int(1)))])?;
        assert_eq!(
            out,
            "M140 S60\nM104 T1 S0\n; PLA 0.2 210 250 1 [unknown] a[0]"
        );
        let err = cfg.render_template("G1\n{if x}", 0, &[]);
        assert_eq!(
            err.map_err(|e| (e.line, e.placeholder)),
            Err((2, "{if x}".to_owned()))
        );
        // Past the end of a vector is element 0, as in PrusaSlicer.
        assert_eq!(cfg.render_template("{temperature[7]}", 0, &[])?, "210");
        assert_eq!(
            cfg.render_template("{nozzle_temperature}", 0, &[])
                .map_err(|e| e.problem),
            Err(Problem::UnknownVariable("nozzle_temperature".to_owned()))
        );
        Ok(())
    }

    #[test]
    fn default_start_and_end_gcode_render() -> Result<(), TemplateError> {
        let cfg = GcodeParams::for_tests();
        let start = cfg.render_template(&cfg.printer.start_gcode, 0, &[])?;
        assert!(start.contains("M109 T0 S210"), "{start}");
        assert!(start.contains("M190 S60"), "{start}");
        let end = cfg.render_template(&cfg.printer.end_gcode, 0, &[])?;
        assert!(end.contains("M84"));
        Ok(())
    }

    #[test]
    fn profile_values_are_typed_as_prusaslicer_types_them() -> Result<(), TemplateError> {
        let mut cfg = GcodeParams::for_tests();
        for (k, v) in [
            ("filament_notes", r#""HT_MBL10 \"x\"";"plain""#),
            ("filament_type", "PETG;FLEX"),
            ("z_offset", "0.1"),
            ("spiral_vase", "0"),
            ("wipe_tower_x", "170.5"),
            ("extruder_clearance_height", "20,30"),
            ("printer_notes", "PRINTER_MODEL_MK4\\nPG"),
        ] {
            cfg.printer.profile.insert(k.to_owned(), v.to_owned());
        }
        let t = "{filament_notes[0]}|{filament_notes[1]}|{filament_type[1]}|{z_offset + 1}|\
                 {if ! spiral_vase}vase off{endif}|{wipe_tower_x * 2}|\
                 {extruder_clearance_height[1] / 4}|{printer_notes=~/.*MODEL_MK4\\nPG.*/}|\
                 {print_bed_max[0]}x{print_bed_size[1]}|{num_extruders}|{current_extruder}";
        assert_eq!(
            cfg.render_template(t, 1, &[])?,
            "HT_MBL10 \"x\"|plain|FLEX|1.1|vase off|341|7|true|250x250|1|1"
        );
        Ok(())
    }
}
