//! PrusaSlicer's C-style string escapes and quoted string lists, as its config block at the end of a G-code file (and
//! its `.ini` and 3MF profiles) write multi-line values such as `start_gcode`.
//!
//! Place: shared by the readers of those config blocks and by the writers that fill G-code
//! templates from a profile's raw values.

/// Undoes PrusaSlicer's `escape_string_cstyle`: `\n`, `\r`, `\t`, and `\x` → `x`; a lone
/// trailing backslash stays. Cura escapes the settings JSON it cuts into `;SETTING_3` comments
/// the same way.
///
/// ```
/// assert_eq!(conduit_gcode::unescape_cstyle(r#"G28\nM117 \"hi\""#), "G28\nM117 \"hi\"");
/// ```
pub fn unescape_cstyle(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        out.push(chars.next().map_or('\\', escaped));
    }
    out
}

/// A list of strings as PrusaSlicer writes a per-extruder string option
/// (`start_filament_gcode = "M900 K0.05";"M900 K0"`), read as its `unescape_strings_cstyle`
/// reads it: items separated by `;`, an item in quotes with its escapes undone, an item
/// without quotes taken as written up to the next `;`, a trailing `;` one more empty item.
/// `None` when the text is not such a list (an unclosed quote, text after a closing quote).
///
/// ```
/// let items = conduit_gcode::string_list(r#""G28\nG1 Z5"; M900 K0"#);
/// assert_eq!(items, Some(vec!["G28\nG1 Z5".to_owned(), "M900 K0".to_owned()]));
/// assert_eq!(conduit_gcode::string_list(r#""a" b"#), None);
/// ```
pub fn string_list(raw: &str) -> Option<Vec<String>> {
    let mut items = Vec::new();
    let mut chars = raw.chars().peekable();
    let skip_blanks = |chars: &mut std::iter::Peekable<std::str::Chars>| {
        while chars.next_if(|c| matches!(c, ' ' | '\t')).is_some() {}
    };
    skip_blanks(&mut chars);
    if chars.peek().is_none() {
        return Some(items);
    }
    loop {
        skip_blanks(&mut chars);
        let mut item = String::new();
        if chars.next_if_eq(&'"').is_some() {
            loop {
                match chars.next()? {
                    '"' => break,
                    '\\' => item.push(escaped(chars.next()?)),
                    c => item.push(c),
                }
            }
            skip_blanks(&mut chars);
        } else {
            while let Some(c) = chars.next_if(|&c| c != ';') {
                item.push(c);
            }
        }
        items.push(item);
        match chars.next() {
            None => return Some(items),
            Some(';') if chars.peek().is_none() => {
                items.push(String::new());
                return Some(items);
            }
            Some(';') => {}
            Some(_) => return None,
        }
    }
}

/// The character a backslash before `c` stands for: `\n`, `\r`, `\t`, or `c` itself.
fn escaped(c: char) -> char {
    match c {
        'n' => '\n',
        'r' => '\r',
        't' => '\t',
        c => c,
    }
}

#[cfg(test)]
mod tests {
    use super::{string_list, unescape_cstyle};

    #[test]
    fn escapes_are_undone_and_a_trailing_backslash_kept() {
        assert_eq!(unescape_cstyle(r"a\nb\tc\rd"), "a\nb\tc\rd");
        assert_eq!(unescape_cstyle(r#"say \"hi\" \\ \q"#), r#"say "hi" \ q"#);
        assert_eq!(unescape_cstyle("end\\"), "end\\");
        assert_eq!(unescape_cstyle(""), "");
    }

    #[test]
    fn string_lists_read_as_prusaslicer_reads_them() {
        let items = string_list(r#""a;b" ;"c\"d";plain text;"#);
        let want = ["a;b", "c\"d", "plain text", ""]
            .map(str::to_owned)
            .to_vec();
        assert_eq!(items, Some(want));
        assert_eq!(string_list("  "), Some(Vec::new()));
        assert_eq!(string_list(r#""unclosed"#), None);
        assert_eq!(string_list(r#""a" x"#), None);
        assert_eq!(string_list("one"), Some(vec!["one".to_owned()]));
    }
}
