//! Filling `{placeholders}` in the custom G-code templates of the printer and the tools, in
//! the style of PrusaSlicer's.
//!
//! Syntax: `{key}` or `{key[N]}`. A key is looked up, in order, in the caller's variables, in
//! `[printer]`, in `[slice]` and in the tools: `{temperature[1]}` is tool 1's temperature,
//! `{temperature}` the current tool's; `{bed_size[0]}` indexes an array. PrusaSlicer's legacy
//! `[key]` form is filled too when `key` is known, and left as written otherwise (square
//! brackets also appear in ordinary comments). Numbers are written as Rust's shortest
//! round-trip form (`60`, `0.2`), booleans as `1` / `0`. PrusaSlicer's macro language (`{if}`,
//! expressions) is not supported: such a placeholder is an unknown-placeholder error.
//!
//! Place in the pipeline: inside the G-code writer, which fills every template it writes; the
//! `[slice]` keys come from [`GcodeParams::template_keys`].

use super::GcodeParams;

/// A `{placeholder}` that is neither a variable of the caller nor a key of the printer, the
/// other settings or the tools (the placeholder without braces).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownPlaceholder(pub String);

impl GcodeParams {
    /// Fills the placeholders of `template` (see the syntax above) for tool `tool`, with the
    /// caller's extra variables `vars` (such as `previous_tool`, `next_tool`, `layer_z`) taking
    /// precedence over config keys.
    ///
    /// ```
    /// let params = conduit::config::Config::default().gcode_params();
    /// let g = params
    ///     .render_template("M190 S{first_layer_bed_temperature}\nM109 S[temperature]", 0, &[])
    ///     .expect("known placeholders");
    /// assert_eq!(g, "M190 S60\nM109 S210");
    /// ```
    pub fn render_template(
        &self,
        template: &str,
        tool: usize,
        vars: &[(&str, String)],
    ) -> Result<String, UnknownPlaceholder> {
        let printer = toml::Value::try_from(&self.printer).ok();
        let lookup =
            |name: &str| -> Option<String> { self.lookup(printer.as_ref()?, name, tool, vars) };
        let mut out = String::with_capacity(template.len());
        let mut rest = template;
        while let Some(pos) = rest.find(['{', '[']) {
            out.push_str(&rest[..pos]);
            let open = rest.as_bytes()[pos];
            let close = if open == b'{' { '}' } else { ']' };
            let after = &rest[pos + 1..];
            // `[key]` with an index inside: `[key[1]]` is not PrusaSlicer syntax; only plain names.
            let end = match open {
                b'{' => after.find('}'),
                _ => after
                    .find([']', '[', '\n', '{'])
                    .filter(|&e| after[e..].starts_with(']')),
            };
            match end {
                Some(end) => {
                    let name = &after[..end];
                    match lookup(name.trim()) {
                        Some(v) => out.push_str(&v),
                        None if open == b'{' => {
                            return Err(UnknownPlaceholder(name.to_owned()));
                        }
                        None => {
                            out.push('[');
                            out.push_str(name);
                            out.push(close);
                        }
                    }
                    rest = &after[end + 1..];
                }
                None if open == b'{' => {
                    return Err(UnknownPlaceholder(
                        after.lines().next().unwrap_or_default().to_owned(),
                    ));
                }
                None => {
                    out.push('[');
                    rest = after;
                }
            }
        }
        out.push_str(rest);
        Ok(out)
    }

    /// The value `name` stands for: a variable, a printer key (`printer` is the printer as a
    /// TOML table), a further key, or a tool key (of tool `tool`, or of the indexed tool).
    fn lookup(
        &self,
        printer: &toml::Value,
        name: &str,
        tool: usize,
        vars: &[(&str, String)],
    ) -> Option<String> {
        if let Some((_, v)) = vars.iter().find(|(k, _)| *k == name) {
            return Some(v.clone());
        }
        let (key, index) = match name.strip_suffix(']').and_then(|n| n.split_once('[')) {
            Some((k, i)) => (k.trim(), Some(i.trim().parse::<usize>().ok()?)),
            None => (name, None),
        };
        if key.is_empty() || !key.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
            return None;
        }
        if let Some(v) = printer.get(key).or_else(|| self.template_keys.get(key)) {
            return match (v, index) {
                (toml::Value::Array(a), Some(i)) => a.get(i).and_then(scalar),
                (v, None) => scalar(v),
                _ => None,
            };
        }
        let t = index.unwrap_or(tool);
        let tool = toml::Value::try_from(self.tools.get(t)?).ok()?;
        scalar(tool.get(key)?)
    }
}

fn scalar(v: &toml::Value) -> Option<String> {
    match v {
        toml::Value::String(s) => Some(s.clone()),
        toml::Value::Integer(i) => Some(i.to_string()),
        toml::Value::Float(f) => Some(f.to_string()),
        toml::Value::Boolean(b) => Some(if *b { "1" } else { "0" }.to_owned()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placeholders_are_filled_from_every_section() -> Result<(), UnknownPlaceholder> {
        let cfg = GcodeParams::for_tests();
        let t = "M140 S{first_layer_bed_temperature}\nM104 T1 S{first_layer_temperature[1]}\n\
                 ; {name} {layer_height} [temperature] {bed_size[0]} {next_tool} [unknown] a[0]";
        let out = cfg.render_template(t, 0, &[("next_tool", "1".to_owned())])?;
        assert_eq!(
            out,
            "M140 S60\nM104 T1 S0\n; PLA 0.2 210 250 1 [unknown] a[0]"
        );
        assert_eq!(
            cfg.render_template("{if x}", 0, &[]),
            Err(UnknownPlaceholder("if x".to_owned()))
        );
        assert!(cfg.render_template("{temperature[7]}", 0, &[]).is_err());
        Ok(())
    }

    #[test]
    fn default_start_and_end_gcode_render() -> Result<(), UnknownPlaceholder> {
        let cfg = GcodeParams::for_tests();
        let start = cfg.render_template(&cfg.printer.start_gcode, 0, &[])?;
        assert!(start.contains("M109 T0 S210"), "{start}");
        assert!(start.contains("M190 S60"), "{start}");
        let end = cfg.render_template(&cfg.printer.end_gcode, 0, &[])?;
        assert!(end.contains("M84"));
        Ok(())
    }
}
