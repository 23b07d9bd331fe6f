//! serde's messages about a value of the wrong type or range in the words of a file's reader:
//! `must be a number in mm, got "abc"` rather than `invalid type: string "abc", expected f64`.
//!
//! Place in the pipeline: shared by the readers of the TOML files a command takes (the config,
//! placements), which put the key (and the file and line) in front.

/// serde's message about a value as what it must be and what it is (`must be a number in mm,
/// got "abc"` for `invalid type: string "abc", expected f64`; `must be "a" or "b", got "c"` for
/// an unknown variant), numbers with their `unit` when known; `None` for any other message
/// (an unknown key, a syntax error), which the caller shows as it is.
pub fn must_be(message: &str, unit: Option<&str>) -> Option<String> {
    if let Some(rest) = message.strip_prefix("unknown variant `")
        && let Some((got, expected)) = rest.split_once("`, expected ")
    {
        let names: Vec<String> = expected
            .split('`')
            .skip(1)
            .step_by(2)
            .map(|n| format!("\"{n}\""))
            .collect();
        let which = match names.as_slice() {
            [] => return None,
            [one] => one.clone(),
            [init @ .., last] => format!("{} or {last}", init.join(", ")),
        };
        return Some(format!("must be {which}, got \"{got}\""));
    }
    let (got, expected) = if let Some(rest) = message
        .strip_prefix("invalid type: ")
        .or_else(|| message.strip_prefix("invalid value: "))
    {
        match rest.rsplit_once(", expected ") {
            Some((got, expected)) => (value_words(got), expected),
            None => return None,
        }
    } else if let Some(rest) = message.strip_prefix("invalid length ") {
        match rest.split_once(", expected ") {
            Some(("1", expected)) => ("1 value".to_owned(), expected),
            Some((n, expected)) => (format!("{n} values"), expected),
            None => return None,
        }
    } else {
        return None;
    };
    let words = expected_words(expected, unit)?;
    Some(format!("must be {words}, got {got}"))
}

/// serde's words for the value it found (`string "abc"`, ``integer `3` ``) as written in the
/// file (`"abc"`, `3`).
fn value_words(got: &str) -> String {
    let quoted = |s: &str| {
        s.strip_prefix('`')
            .and_then(|s| s.strip_suffix('`'))
            .map(str::to_owned)
    };
    for prefix in ["integer ", "floating point ", "boolean ", "character "] {
        if let Some(v) = got.strip_prefix(prefix).and_then(quoted) {
            return v;
        }
    }
    if let Some(s) = got.strip_prefix("string ") {
        return s.to_owned();
    }
    match got {
        "sequence" => "a list".to_owned(),
        "map" => "a table".to_owned(),
        other => other.to_owned(),
    }
}

/// What serde expected (`f64`, `usize`, `a sequence`, `an array of length 2`) in words, with
/// the `unit` of numbers when known; a description of the config's own (`[tools.N] tables
/// numbered …`) as it is; `None` for another single word, a type name that has no words here.
fn expected_words(expected: &str, unit: Option<&str>) -> Option<String> {
    let unit = unit.map(|u| format!(" in {u}")).unwrap_or_default();
    Some(match expected {
        "f64" | "f32" => format!("a number{unit}"),
        "u8" | "u16" | "u32" | "u64" | "u128" | "usize" => format!("a whole number ≥ 0{unit}"),
        "i8" | "i16" | "i32" | "i64" | "i128" | "isize" => format!("a whole number{unit}"),
        "bool" | "a boolean" => "true or false".to_owned(),
        "a string" | "string" => "text in quotes".to_owned(),
        "char" | "a character" => "one character in quotes".to_owned(),
        "a sequence" => "a list `[…]`".to_owned(),
        "a map" | "a table" => "a table".to_owned(),
        other => {
            if let Some(n) = other
                .strip_prefix("an array of length ")
                .or_else(|| other.strip_prefix("a tuple of size "))
            {
                format!("a list of {n} values `[…]`")
            } else if other.starts_with("struct ") {
                "a table".to_owned()
            } else if other.contains(' ') {
                other.to_owned()
            } else {
                return None;
            }
        }
    })
}
