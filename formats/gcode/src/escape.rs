//! PrusaSlicer's C-style string escapes, as its config block at the end of a G-code file (and
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
        match chars.next() {
            Some('n') => out.push('\n'),
            Some('r') => out.push('\r'),
            Some('t') => out.push('\t'),
            Some(other) => out.push(other),
            None => out.push('\\'),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::unescape_cstyle;

    #[test]
    fn escapes_are_undone_and_a_trailing_backslash_kept() {
        assert_eq!(unescape_cstyle(r"a\nb\tc\rd"), "a\nb\tc\rd");
        assert_eq!(unescape_cstyle(r#"say \"hi\" \\ \q"#), r#"say "hi" \ q"#);
        assert_eq!(unescape_cstyle("end\\"), "end\\");
        assert_eq!(unescape_cstyle(""), "");
    }
}
