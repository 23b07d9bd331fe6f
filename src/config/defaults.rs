//! The default configuration as a commented TOML document (`conduit config --defaults`).
//!
//! Place in the pipeline: part of `config`, which the CLI prints before any walk. The document
//! has one source per part: the comments are the `///` docs of the config types, read from
//! their JSON schema (`schemars`) and turned into plain text; the values are
//! [`Config::default`] serialised to TOML; a key absent by default is shown commented out with
//! the example its field names (`#[schemars(example = …)]`).

use schemars::generate::SchemaSettings;
use serde_json::Value as Json;

use super::Config;

/// Longest comment line of the document, in characters (a word longer than a line stays whole).
const WIDTH: usize = 100;

/// The lines that open the document.
const HEADER: &str = "# conduit configuration: every key with its default value.\n\
                      # Units: lengths mm, speeds mm/s, accelerations mm/s², temperatures °C, \
                      fan %.\n\
                      # Any key may be left out; unknown keys are errors.\n";

/// The introduction of each section, printed above its (first) table.
const SECTION_DOCS: &[(&str, &str)] = &[
    (
        "printer",
        "The machine: bed, firmware, custom G-code, retraction, travel, fan.",
    ),
    (
        "tools",
        "One table per tool, numbered from 0 without gaps. Keys left out take the default of the \
         tool's kind (\"filament\" or \"paste\"), not of the table shown here.",
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
        "Non-planar printing: top solid layers of gentle top surfaces follow the surface \
         (\"tops\"), or a thin shell is printed as curved layers over a planar scaffold \
         (\"clfff\").",
    ),
    (
        "conform",
        "Conformal printing (conduit conform): a 2D design laid onto a scanned surface and \
         printed with a micro-extrusion nozzle: nozzle geometry, corrections, deposit \
         thresholds, pressure snippets.",
    ),
    (
        "jet",
        "Aerosol jet (conduit jet): corner fillet rules, shutter gap, direction blocks, shutter \
         G-code, fill and the corner accumulation model. Lengths mm (the command line takes µm).",
    ),
    (
        "robot",
        "Robot arms and five-axis machines (conduit conform --dialect, conduit calibrate): arm \
         model, frames, tool orientation and the dispense commands of each program dialect.",
    ),
    (
        "compensate",
        "Gap compensation (conduit compensate): measured tool-to-surface gaps move the path \
         along the tool axis, pass after pass.",
    ),
    (
        "support",
        "Support material (conduit slice with slice.support_material = true): which overhangs \
         get columns, the gaps that make them removable, interface layers and patterns. \
         Lengths mm, angles degrees.",
    ),
    (
        "wipe_tower",
        "The wipe tower of multi-tool prints: a block beside the objects where each filament \
         tool purges after a tool change. Lengths mm, volumes mm³.",
    ),
];

/// The default configuration ([`Config::default`]) as a TOML document with every key, its
/// documentation and unit as comments. Parsing it gives `Config::default()` back exactly.
pub fn defaults_toml() -> String {
    let schema = config_schema();
    let tree = match toml::Value::try_from(Config::default()) {
        Ok(t) => t,
        Err(e) => panic!("internal error: default config does not serialise: {e}"),
    };
    let mut out = String::from(HEADER);
    for (section, section_schema) in properties(&schema) {
        let Some(value) = tree.get(section) else {
            continue;
        };
        // A section of numbered tables (`[tools.N]`) describes its tables' keys once, as the
        // schema of any entry; the keys are documented in the first table only.
        let (tables, fields): (Vec<(String, &toml::Value)>, _) =
            match numbered_entry(section_schema) {
                Some(entry) => (
                    value
                        .as_table()
                        .into_iter()
                        .flatten()
                        .map(|(n, v)| (format!("{section}.{n}"), v))
                        .collect(),
                    properties(entry),
                ),
                None => (vec![(section.clone(), value)], properties(section_schema)),
            };
        for (i, (header, table)) in tables.iter().enumerate() {
            let documented = i == 0;
            out.push('\n');
            if documented {
                push_comment(&mut out, &section_doc(section, section_schema));
            }
            out.push_str(&format!("[{header}]\n"));
            for (key, field) in &fields {
                let doc = field.get("description").and_then(Json::as_str);
                if let Some(v) = table.get(key.as_str()) {
                    if documented {
                        push_comment(&mut out, &plain_text(doc.unwrap_or_default(), true));
                    }
                    out.push_str(&format!("{key} = {}\n", format_value(v)));
                } else if let Some(example) = example(field) {
                    if documented {
                        push_comment(&mut out, &plain_text(doc.unwrap_or_default(), false));
                    }
                    out.push_str(&format!("# {key} = {}\n", format_value(&example)));
                }
            }
            // A serialised key without a field in the schema still loads back (and the tests
            // report it as undocumented).
            for (key, v) in table.as_table().into_iter().flatten() {
                if !fields.iter().any(|(k, _)| *k == key) {
                    out.push_str(&format!("{key} = {}\n", format_value(v)));
                }
            }
        }
    }
    out
}

/// Units a field's documentation states after a comma (`Layer height, mm, …`), longest first
/// where one starts another.
const UNITS: &[&str] = &[
    "mm/s²", "mm³/s", "mm/s", "mm", "µm", "°C", "degrees", "°", "percent", "g/cm³", "s",
];

/// The unit the documentation of the dotted config `key` states (`slice.layer_height` → `mm`,
/// `tools.1.temperature` → `°C`), when it states one: for messages that say what a value must
/// be.
pub(super) fn unit_of(key: &str) -> Option<&'static str> {
    let schema = config_schema();
    // `printer.bed_size[0]` is documented as `printer.bed_size`.
    let mut parts = key.split('.').map(|p| p.split('[').next().unwrap_or(p));
    let mut node = schema.get("properties")?.get(parts.next()?)?;
    if let Some(entry) = numbered_entry(node) {
        parts.next()?;
        node = entry;
    }
    let field = node.get("properties")?.get(parts.next()?)?;
    if parts.next().is_some() {
        return None;
    }
    let doc = field.get("description")?.as_str()?;
    let first = doc.split("\n\n").next()?.replace('\n', " ");
    UNITS.iter().copied().find(|u| {
        first.match_indices(&format!(", {u}")).any(|(i, m)| {
            let after = &first[i + m.len()..];
            after.is_empty() || after.starts_with(['.', ',', ';']) || after.starts_with(" (")
        })
    })
}

/// The JSON schema of [`Config`] with every type inlined, so each section's keys are the
/// `properties` (or, for numbered tables, the `additionalProperties.properties`) of its field.
fn config_schema() -> Json {
    SchemaSettings::draft2020_12()
        .with(|s| s.inline_subschemas = true)
        .into_generator()
        .into_root_schema_for::<Config>()
        .to_value()
}

/// The schema of each entry of a section of numbered tables (`[tools.N]`), whose keys are the
/// entries' numbers (`additionalProperties` is `false` for the other sections: unknown keys are
/// errors).
fn numbered_entry(section: &Json) -> Option<&Json> {
    section
        .get("additionalProperties")
        .filter(|e| e.is_object())
}

/// The named properties of an object schema, in field order.
fn properties(schema: &Json) -> Vec<(&String, &Json)> {
    schema
        .get("properties")
        .and_then(Json::as_object)
        .into_iter()
        .flatten()
        .collect()
}

/// The first example of a field's schema as a TOML value, if it has one.
fn example(field: &Json) -> Option<toml::Value> {
    let first = field.get("examples")?.as_array()?.first()?;
    toml::Value::try_from(first).ok()
}

/// A section's introduction: its line of [`SECTION_DOCS`], else the doc of its `Config` field.
fn section_doc(section: &str, schema: &Json) -> Vec<String> {
    match SECTION_DOCS.iter().find(|(s, _)| *s == section) {
        Some((_, doc)) => vec![(*doc).to_owned()],
        None => plain_text(
            schema
                .get("description")
                .and_then(Json::as_str)
                .unwrap_or_default(),
            false,
        ),
    }
}

/// A field's rustdoc as plain-text paragraphs: lines of a paragraph joined, links reduced to
/// their text (`` [`Tool::filament`] `` → `` `Tool::filament` ``) and, when `value_shown`, the
/// sentences that only state the default left out (the value follows the comment).
fn plain_text(doc: &str, value_shown: bool) -> Vec<String> {
    let mut paragraphs: Vec<String> = doc
        .split("\n\n")
        .map(|p| {
            let joined: Vec<&str> = p.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
            unlink(&joined.join(" "))
        })
        .filter(|p| !p.is_empty())
        .collect();
    if value_shown {
        paragraphs = paragraphs
            .iter()
            .map(|p| without_default_sentence(p))
            .filter(|p| !p.is_empty())
            .collect();
    }
    paragraphs
}

/// `text` with rustdoc and markdown links replaced by their labels: `` [`X`] ``,
/// `` [`X`](target) `` and `` [`X`][target] `` become `` `X` ``, `[label](target)` and
/// `[label][target]` become `label`, and a bare path link `[a::b]` becomes `a::b`. Code spans
/// and other brackets (`[X, Y]`, `[[90, 0], [45, 0.5]]`) are kept as they are.
fn unlink(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(['[', '`']) {
        out.push_str(&rest[..i]);
        rest = &rest[i..];
        if let Some(code) = rest.strip_prefix('`') {
            let Some(end) = code.find('`') else {
                break;
            };
            out.push_str(&rest[..end + 2]);
            rest = &rest[end + 2..];
        } else if let Some((label, after)) = link(rest) {
            out.push_str(label);
            rest = after;
        } else {
            out.push('[');
            rest = &rest[1..];
        }
    }
    out.push_str(rest);
    out
}

/// The link that `s` (starting with `[`) opens: its label and the text after the link.
fn link(s: &str) -> Option<(&str, &str)> {
    let inner = s.strip_prefix('[')?;
    if let Some(code) = inner.strip_prefix('`') {
        let end = code.find('`')? + 2;
        let after = inner[end..].strip_prefix(']')?;
        return Some((&inner[..end], skip_target(after).unwrap_or(after)));
    }
    let end = inner.find(']')?;
    let label = &inner[..end];
    let after = &inner[end + 1..];
    if label.is_empty() || label.contains(['[', '`']) {
        return None;
    }
    match skip_target(after) {
        Some(rest) => Some((label, rest)),
        None if label.contains("::")
            && label
                .chars()
                .all(|c| c.is_alphanumeric() || matches!(c, '_' | ':' | '(' | ')')) =>
        {
            Some((label, after))
        }
        None => None,
    }
}

/// The text after a link target, `(target)` or `[target]`, that `s` starts with.
fn skip_target(s: &str) -> Option<&str> {
    let close = match s.chars().next()? {
        '(' => ')',
        '[' => ']',
        _ => return None,
    };
    let end = s.find(close)?;
    Some(&s[end + 1..])
}

/// `text` without the sentences that only state the default, which the value printed after
/// the comment repeats: `Default 25.`, `Default [0, 0].`, `Default `"rectilinear"`.`,
/// `Default 210 (filament) / 0 (paste).`, `Default all 0.` A sentence that says more than the
/// value (`Default X, the command OctoPNP answers.`, `Default false: inner loops first.`) is
/// kept.
fn without_default_sentence(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    loop {
        let at_start = out.is_empty() || out.ends_with(". ");
        if let Some(len) = default_sentence_len(rest).filter(|_| at_start) {
            rest = rest[len..].trim_start();
            continue;
        }
        match rest.find(". ") {
            Some(i) => {
                out.push_str(&rest[..i + 2]);
                rest = &rest[i + 2..];
            }
            None => {
                out.push_str(rest);
                break;
            }
        }
    }
    out.trim_end().to_owned()
}

/// The length of the sentence that `s` starts with when it is `Default` and values only: no
/// `,`, `;` or `:` and no full stop but its last outside code spans, brackets and parentheses
/// (a full stop before a digit is a decimal point).
fn default_sentence_len(s: &str) -> Option<usize> {
    let body = s.strip_prefix("Default ")?;
    let offset = "Default ".len();
    let mut depth = 0usize;
    let mut code = false;
    let mut chars = body.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        if code {
            code = c != '`';
            continue;
        }
        match c {
            '`' => code = true,
            '[' | '(' => depth += 1,
            ']' | ')' => depth = depth.checked_sub(1)?,
            _ if depth > 0 => {}
            ',' | ';' | ':' => return None,
            '.' => match chars.peek() {
                Some((_, next)) if next.is_ascii_digit() => {}
                Some((_, ' ')) | None if i > 0 => return Some(offset + i + 1),
                _ => return None,
            },
            _ => {}
        }
    }
    None
}

/// Appends paragraphs as `# ` comment lines wrapped at [`WIDTH`] columns, never inside a
/// `` `code` `` span.
fn push_comment(out: &mut String, paragraphs: &[String]) {
    for paragraph in paragraphs {
        let mut line = String::new();
        for word in words(paragraph) {
            if !line.is_empty() && 2 + line.chars().count() + 1 + word.chars().count() > WIDTH {
                out.push_str(&format!("# {line}\n"));
                line.clear();
            }
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(&word);
        }
        if !line.is_empty() {
            out.push_str(&format!("# {line}\n"));
        }
    }
}

/// The words of a paragraph, a `` `code` `` span with spaces counting as one word.
fn words(paragraph: &str) -> Vec<String> {
    let mut words: Vec<String> = Vec::new();
    let mut open = false;
    for word in paragraph.split_whitespace() {
        match words.last_mut() {
            Some(last) if open => {
                last.push(' ');
                last.push_str(word);
            }
            _ => words.push(word.to_owned()),
        }
        if word.matches('`').count() % 2 == 1 {
            open = !open;
        }
    }
    words
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
    use std::collections::BTreeSet;

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

    /// One key of the generated document: its table, key, the whole `key = value` text (the
    /// `# ` of a commented-out key removed), whether it is commented out and whether a comment
    /// line stands right above it.
    struct KeyLine {
        table: String,
        key: String,
        text: String,
        commented_out: bool,
        documented: bool,
    }

    /// The keys of a document as `defaults_toml` writes it: `key = value` lines (a `'''` value
    /// runs to its closing `'''`) and `# key = value` lines whose rest parses as one TOML key.
    fn key_lines(doc: &str) -> Vec<KeyLine> {
        let mut keys = Vec::new();
        let mut table = String::new();
        let mut comment_above = false;
        let mut lines = doc.lines();
        while let Some(line) = lines.next() {
            if let Some(header) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
                table = header.to_owned();
                comment_above = false;
                continue;
            }
            let (mut text, commented_out) = match line.strip_prefix("# ") {
                Some(rest) => (rest.to_owned(), true),
                None => (line.to_owned(), false),
            };
            if !commented_out && text.ends_with("= '''") {
                for body in lines.by_ref() {
                    text.push('\n');
                    text.push_str(body);
                    if body.ends_with("'''") {
                        break;
                    }
                }
            }
            let key = text.split(" = ").next().unwrap_or_default();
            let is_key = key
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
                && key.starts_with(|c: char| c.is_ascii_lowercase())
                && toml::from_str::<toml::Table>(&text).is_ok_and(|t| t.len() == 1);
            if is_key {
                keys.push(KeyLine {
                    table: table.clone(),
                    key: key.to_owned(),
                    text: text.clone(),
                    commented_out,
                    documented: comment_above,
                });
                comment_above = false;
            } else {
                comment_above = commented_out;
            }
        }
        keys
    }

    #[test]
    fn every_key_is_documented_once_and_every_doc_is_a_key() {
        let doc = defaults_toml();
        let tree = match toml::Value::try_from(Config::default()) {
            Ok(t) => t,
            Err(e) => panic!("{e}"),
        };
        let mut serialised = BTreeSet::new();
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
        let mut described = BTreeSet::new();
        for line in key_lines(&doc) {
            let (section, entry) = line
                .table
                .split_once('.')
                .unwrap_or((line.table.as_str(), ""));
            let first_table = entry.is_empty() || entry == "0";
            assert_eq!(
                line.documented, first_table,
                "[{}] {}: keys have a comment in the first table of their section only",
                line.table, line.key
            );
            if !line.documented {
                continue;
            }
            assert!(
                described.insert((section.to_owned(), line.key.clone())),
                "{section}.{} described twice",
                line.key
            );
            if line.commented_out {
                // A commented-out example is a key that exists: uncommented, it loads.
                let one = format!("[{}]\n{}\n", line.table, line.text);
                assert!(
                    Config::from_toml_str(&one).is_ok(),
                    "example `{}` of [{}] does not load",
                    line.text,
                    line.table
                );
            } else {
                assert!(
                    serialised.contains(&(section.to_owned(), line.key.clone())),
                    "{section}.{} is described but not a key of the default config",
                    line.key
                );
            }
        }
        let undocumented: Vec<_> = serialised.difference(&described).collect();
        assert!(
            undocumented.is_empty(),
            "keys without a comment: {undocumented:?}"
        );
        // Every field of every section appears, so a key absent by default needs an example.
        let schema = config_schema();
        for (section, section_schema) in properties(&schema) {
            let fields = properties(numbered_entry(section_schema).unwrap_or(section_schema));
            for (key, _) in fields {
                assert!(
                    described.contains(&(section.clone(), key.clone())),
                    "{section}.{key} is neither in the default config nor given an example"
                );
            }
        }
    }

    #[test]
    fn every_section_has_an_introduction() {
        let schema = config_schema();
        let sections: BTreeSet<&str> = properties(&schema)
            .into_iter()
            .map(|(s, _)| s.as_str())
            .collect();
        let introduced: BTreeSet<&str> = SECTION_DOCS.iter().map(|(s, _)| *s).collect();
        assert_eq!(sections, introduced);
    }

    #[test]
    fn comments_are_plain_text_and_wrapped() {
        let doc = defaults_toml();
        for line in doc.lines().filter(|l| l.starts_with('#')) {
            assert!(
                line.chars().count() <= WIDTH || !line.trim_end().contains(' '),
                "comment longer than {WIDTH} columns: {line}"
            );
            assert!(!line.contains("[`"), "rustdoc link left: {line}");
            assert!(!line.contains("]("), "markdown link left: {line}");
        }
        // Defaults printed as values are not repeated in the comment above them.
        assert!(doc.contains(
            "# Height of the first layer, mm, from 0.01 to 2 × `nozzle_diameter`.\n\
             first_layer_height = 0.2\n"
        ));
    }

    #[test]
    fn links_become_their_labels() {
        assert_eq!(
            unlink("see [`Config::render_template`] and [`Tool::paste`](super::Tool)."),
            "see `Config::render_template` and `Tool::paste`."
        );
        assert_eq!(
            unlink("[the docs](https://x.invalid) [a::b]"),
            "the docs a::b"
        );
        assert_eq!(
            unlink("[X, Y], mm; `[min, max]` rows; [[90, 0], [45, 0.5]] [x]"),
            "[X, Y], mm; `[min, max]` rows; [[90, 0], [45, 0.5]] [x]"
        );
    }

    #[test]
    fn closing_default_sentences_are_left_out() {
        let cases = [
            ("Speed, mm/s. Default 25.", "Speed, mm/s."),
            ("Pattern. Default `\"rectilinear\"`.", "Pattern."),
            ("Offset [X, Y], mm. Default [0, 0].", "Offset [X, Y], mm."),
            ("Rules. Default [[90, 0], [45, 0.5]].", "Rules."),
            ("Standby, °C. Default absent.", "Standby, °C."),
            ("Heat, °C. Default 210 (filament) / 0 (paste).", "Heat, °C."),
            ("Heat, °C. Default 210 / 0.", "Heat, °C."),
            ("Name. Default `\"PLA\"` (filament) / `\"paste\"`.", "Name."),
            ("Tools. Default [] (everything with tool 0).", "Tools."),
            ("Default 0.0005.", ""),
            ("Frames. Default all 0.", "Frames."),
            (
                "Width, mm. Default 0.4. Used by checks.",
                "Width, mm. Used by checks.",
            ),
            ("Flow. Default 1.0 (a remark). More.", "Flow. More."),
            (
                "Lines. Default false: inner first.",
                "Lines. Default false: inner first.",
            ),
            (
                "Margin. Default 3, the peer's.",
                "Margin. Default 3, the peer's.",
            ),
            (
                "Area. Default 70 (the peer's); 0 = off.",
                "Area. Default 70 (the peer's); 0 = off.",
            ),
            ("Eg. Default e.g. this.", "Eg. Default e.g. this."),
            (
                "Place. Default `M361`, what OctoPNP answers.",
                "Place. Default `M361`, what OctoPNP answers.",
            ),
            (
                "Rules. Default `[[90, 0]]`: no fillet.",
                "Rules. Default `[[90, 0]]`: no fillet.",
            ),
            ("Lift; Default 2 mm.", "Lift; Default 2 mm."),
            ("Uses the Default 3.", "Uses the Default 3."),
        ];
        for (doc, kept) in cases {
            assert_eq!(without_default_sentence(doc), kept, "{doc}");
        }
    }
}
