//! Numbers in G-code: the one output formatter ([`fmt_xyz`], [`fmt_e`], [`fmt_f`]) and the
//! tokenizer's decimal reader.

/// Decimal places written for X, Y, Z (and I, J, K, R) coordinates, in millimetres.
pub const XYZ_DECIMALS: usize = 3;
/// Decimal places written for E (extruder) values.
pub const E_DECIMALS: usize = 5;

/// Formats a coordinate (X, Y, Z, I, J, R...) for G-code output: 3 decimals, trailing zeros trimmed.
///
/// See [`fmt_fixed`] for the rounding rule.
///
/// ```
/// assert_eq!(conduit_gcode::fmt_xyz(10.0), "10");
/// assert_eq!(conduit_gcode::fmt_xyz(0.2), "0.2");
/// assert_eq!(conduit_gcode::fmt_xyz(-0.0001), "0");
/// ```
pub fn fmt_xyz(v: f64) -> String {
    fmt_fixed(v, XYZ_DECIMALS)
}

/// Formats an extruder value (E) for G-code output: 5 decimals, trailing zeros trimmed.
///
/// ```
/// assert_eq!(conduit_gcode::fmt_e(1.23456789), "1.23457");
/// ```
pub fn fmt_e(v: f64) -> String {
    fmt_fixed(v, E_DECIMALS)
}

/// Formats a feed rate (F, mm/min) for G-code output: an integer.
///
/// ```
/// assert_eq!(conduit_gcode::fmt_f(1800.4), "1800");
/// ```
pub fn fmt_f(v: f64) -> String {
    fmt_fixed(v, 0)
}

/// Formats `v` with at most `decimals` decimal places, the rule behind [`fmt_xyz`], [`fmt_e`]
/// and [`fmt_f`].
///
/// - The value is rounded correctly from its exact binary value (Rust's `{:.N}` formatting, the
///   same as C++ `std::to_chars` used by PrusaSlicer's `GCodeFormatter`). A value exactly halfway
///   between two outputs (only possible for binary fractions such as `2.5` or `0.0625`) rounds to
///   the even digit: `fmt_f(2.5) == "2"`, `fmt_f(3.5) == "4"`. Most decimal "ties" such as `1.0005`
///   are not exact in binary and round towards their true value.
/// - Trailing zeros and a trailing decimal point are removed (`"10"`, not `"10.000"`).
/// - A result that rounds to zero is written `"0"`, never `"-0"`.
/// - Non-finite values are written as Rust prints them (`NaN`, `inf`, `-inf`), which no firmware
///   accepts: callers must not pass them.
///
/// The output depends only on the arguments, so output files are deterministic.
pub fn fmt_fixed(v: f64, decimals: usize) -> String {
    let mut s = format!("{v:.decimals$}");
    if decimals > 0 && s.contains('.') {
        let trimmed = s.trim_end_matches('0').trim_end_matches('.').len();
        s.truncate(trimmed);
    }
    if s == "-0" {
        s.replace_range(.., "0");
    }
    s
}

/// Exact powers of ten representable in an `f64` (10^0 ..= 10^22).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Reads a G-code number starting at `text[start]`: an optional sign, digits, an optional point
/// and digits, with at least one digit (`10`, `-3`, `.2`, `+1.`, `007`).
///
/// There is no exponent: like Marlin, `1e3` is the number `1` followed by the word `E3`.
/// Returns the value and the index just past the number, or `None` when no number starts there.
pub(crate) fn read_number(text: &[u8], start: usize) -> Option<(f64, usize)> {
    let s = text.get(start..)?;
    let (negative, mut i) = match s.first() {
        Some(b'-') => (true, 1),
        Some(b'+') => (false, 1),
        _ => (false, 0),
    };
    let digits_start = i;
    // Accumulates every digit; wraps silently past 19 digits, where `exact` below is false.
    let mut mantissa: u64 = 0;
    while i < s.len() && s[i].is_ascii_digit() {
        mantissa = mantissa
            .wrapping_mul(10)
            .wrapping_add(u64::from(s[i] - b'0'));
        i += 1;
    }
    let int_digits = i - digits_start;
    let mut frac_digits = 0;
    if i < s.len() && s[i] == b'.' {
        i += 1;
        let frac_start = i;
        while i < s.len() && s[i].is_ascii_digit() {
            mantissa = mantissa
                .wrapping_mul(10)
                .wrapping_add(u64::from(s[i] - b'0'));
            i += 1;
        }
        frac_digits = i - frac_start;
    }
    let digits = int_digits + frac_digits;
    if digits == 0 {
        return None;
    }
    // Clinger's fast path: an integer mantissa below 2^53 and a power of ten up to 10^22 are both
    // exact in f64, so one division gives the correctly rounded value. Anything longer (more than
    // 19 digits, counting leading zeros) goes through the standard library's correctly rounded
    // parser.
    let magnitude = if digits <= 19 && mantissa < (1u64 << 53) && frac_digits < POW10.len() {
        mantissa as f64 / POW10[frac_digits]
    } else {
        // The slice is ASCII digits and at most one point ("1." and ".5" are valid Rust floats).
        std::str::from_utf8(&s[digits_start..i])
            .ok()?
            .parse::<f64>()
            .ok()?
    };
    Some((if negative { -magnitude } else { magnitude }, start + i))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formatter_trims_and_rounds() {
        assert_eq!(fmt_xyz(10.0), "10");
        assert_eq!(fmt_xyz(10.5), "10.5");
        assert_eq!(fmt_xyz(-3.0), "-3");
        assert_eq!(fmt_xyz(0.0), "0");
        assert_eq!(fmt_xyz(-0.0), "0");
        assert_eq!(fmt_xyz(-0.0001), "0");
        assert_eq!(fmt_xyz(-0.0004999), "0");
        assert_eq!(fmt_xyz(-0.0005001), "-0.001");
        assert_eq!(fmt_xyz(123.45678), "123.457");
        assert_eq!(fmt_xyz(0.1 + 0.2), "0.3");
        assert_eq!(fmt_xyz(1e-9), "0");
        assert_eq!(fmt_e(1.23456789), "1.23457");
        assert_eq!(fmt_e(-0.000004), "0");
        assert_eq!(fmt_e(0.00001), "0.00001");
        assert_eq!(fmt_e(2.0), "2");
        assert_eq!(fmt_f(1800.0), "1800");
        assert_eq!(fmt_f(1799.6), "1800");
        assert_eq!(fmt_f(-0.4), "0");
        assert_eq!(fmt_f(0.0), "0");
    }

    #[test]
    fn formatter_ties() {
        // Exact binary ties round to even.
        assert_eq!(fmt_f(2.5), "2");
        assert_eq!(fmt_f(3.5), "4");
        assert_eq!(fmt_f(-2.5), "-2");
        assert_eq!(fmt_xyz(0.0625), "0.062");
        assert_eq!(fmt_xyz(0.1875), "0.188");
        // Decimal "ties" are not exact in binary: they round towards their true value.
        // 1.0005 is stored as 1.000499999999999989...; 0.0005 as 0.000500000000000000010...
        assert_eq!(fmt_xyz(1.0005), "1");
        assert_eq!(fmt_xyz(0.0005), "0.001");
        assert_eq!(fmt_e(0.000015), "0.00002");
    }

    #[test]
    fn formatter_is_deterministic_and_reparses() {
        for i in -2000..2000 {
            let v = f64::from(i) * 0.0137;
            let s = fmt_xyz(v);
            assert_eq!(s, fmt_xyz(v));
            assert!(!s.ends_with('0') || !s.contains('.'), "{s}");
            let back: f64 = s.parse().expect("formatter output is a number");
            assert!((back - v).abs() <= 0.0005 + 1e-12, "{v} -> {s}");
        }
    }

    #[test]
    fn reads_numbers() {
        let r = |s: &str| read_number(s.as_bytes(), 0);
        assert_eq!(r("10.5"), Some((10.5, 4)));
        assert_eq!(r("-3"), Some((-3.0, 2)));
        assert_eq!(r(".2"), Some((0.2, 2)));
        assert_eq!(r("+1."), Some((1.0, 3)));
        assert_eq!(r("007"), Some((7.0, 3)));
        assert_eq!(r("1e30"), Some((1.0, 1)));
        assert_eq!(r("-"), None);
        assert_eq!(r("."), None);
        assert_eq!(r("-."), None);
        assert_eq!(r("X"), None);
        assert_eq!(r(""), None);
        assert_eq!(r("0.00000000001"), Some((1e-11, 13)));
        assert_eq!(
            r("999999999999999999999"),
            Some((999999999999999999999.0, 21))
        );
        assert_eq!(
            r("3.14159265358979323846264338327950288"),
            Some((std::f64::consts::PI, 37))
        );
        // The fast path and the standard parser agree.
        for s in [
            "0.1",
            "0.3",
            "123.456",
            "-0.00001",
            "1234567.891",
            "0.000000000000000000001",
        ] {
            assert_eq!(r(s).map(|x| x.0), s.parse::<f64>().ok(), "{s}");
        }
    }
}
