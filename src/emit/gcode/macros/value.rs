//! The values of the macro language: booleans, integers, floats and strings, the vectors
//! variables may hold, the operators on them and how a value is written into the G-code.
//!
//! Place in the pipeline: the evaluator ([`super::eval`]) computes with these; the variables
//! a template reads ([`super::Variables`]) are given as [`Var`]s.
//!
//! The rules are PrusaSlicer's: `+` joins strings when either side is one, integer arithmetic
//! stays integer (`7 / 2` is 3), a float is written with six significant digits and no
//! trailing zeros (`0.2`, `101.235`, `1e+06`), a boolean as `true` / `false`. Where PrusaSlicer
//! refuses a type, conduit also accepts an integer as a condition (non-zero is true), since
//! the profile's flags (`spiral_vase = 0`) arrive as plain numbers.

use super::Problem;

/// One value of an expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// `true` or `false`.
    Bool(bool),
    /// A whole number.
    Int(i64),
    /// A floating-point number.
    Float(f64),
    /// Text.
    Str(String),
}

/// What a variable holds: one value or a vector of them (one per extruder, or a coordinate
/// pair such as `print_bed_max`).
#[derive(Debug, Clone, PartialEq)]
pub enum Var {
    /// A single value.
    Scalar(Value),
    /// A vector, indexed from 0.
    Vector(Vec<Value>),
}

impl From<bool> for Value {
    fn from(b: bool) -> Self {
        Value::Bool(b)
    }
}

impl From<i64> for Value {
    fn from(i: i64) -> Self {
        Value::Int(i)
    }
}

impl From<usize> for Value {
    fn from(i: usize) -> Self {
        Value::Int(i64::try_from(i).unwrap_or(i64::MAX))
    }
}

impl From<f64> for Value {
    fn from(f: f64) -> Self {
        Value::Float(f)
    }
}

impl From<&str> for Value {
    fn from(s: &str) -> Self {
        Value::Str(s.to_owned())
    }
}

impl From<String> for Value {
    fn from(s: String) -> Self {
        Value::Str(s)
    }
}

impl std::fmt::Display for Value {
    /// The value as written into the G-code: PrusaSlicer's formatting.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Bool(b) => f.write_str(if *b { "true" } else { "false" }),
            Value::Int(i) => write!(f, "{i}"),
            Value::Float(x) => f.write_str(&format_float(*x)),
            Value::Str(s) => f.write_str(s),
        }
    }
}

/// `x` as C++'s default stream formatting writes it (`printf("%g")`): six significant digits,
/// trailing zeros dropped, an exponent below 1e-4 and from 1e6 on.
pub fn format_float(x: f64) -> String {
    if x.is_nan() {
        return "nan".to_owned();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.to_owned();
    }
    if x == 0.0 {
        return if x.is_sign_negative() { "-0" } else { "0" }.to_owned();
    }
    // The exponent after rounding to six significant digits decides the style.
    let sci = format!("{x:.5e}");
    let (mantissa, exp) = sci.split_once('e').unwrap_or((sci.as_str(), "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    if !(-4..6).contains(&exp) {
        let mantissa = trim_zeros(mantissa);
        let sign = if exp < 0 { '-' } else { '+' };
        return format!("{mantissa}e{sign}{:02}", exp.abs());
    }
    let decimals = usize::try_from(5 - exp).unwrap_or(0);
    trim_zeros(&format!("{x:.decimals$}")).to_owned()
}

/// `s` without the trailing zeros of its fraction (and without a bare `.`).
fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

impl Value {
    /// True for integers and floats.
    pub fn is_numeric(&self) -> bool {
        matches!(self, Value::Int(_) | Value::Float(_))
    }

    /// The number as a float.
    pub fn as_f64(&self) -> Result<f64, Problem> {
        match self {
            Value::Int(i) => Ok(*i as f64),
            Value::Float(f) => Ok(*f),
            _ => Err(Problem::NotNumeric),
        }
    }

    /// The value as a condition: a boolean, or an integer (non-zero is true).
    pub fn truth(&self) -> Result<bool, Problem> {
        match self {
            Value::Bool(b) => Ok(*b),
            Value::Int(i) => Ok(*i != 0),
            _ => Err(Problem::NotBoolean),
        }
    }

    /// `self + rhs`: strings join, numbers add.
    pub fn plus(self, rhs: Value) -> Result<Value, Problem> {
        match (self, rhs) {
            (Value::Str(mut s), r) => {
                s.push_str(&r.to_string());
                Ok(Value::Str(s))
            }
            (l, Value::Str(s)) => Ok(Value::Str(format!("{l}{s}"))),
            (l, r) => arithmetic(l, r, i64::wrapping_add, |a, b| a + b),
        }
    }

    /// `self - rhs`.
    pub fn minus(self, rhs: Value) -> Result<Value, Problem> {
        arithmetic(self, rhs, i64::wrapping_sub, |a, b| a - b)
    }

    /// `self * rhs`.
    pub fn times(self, rhs: Value) -> Result<Value, Problem> {
        arithmetic(self, rhs, i64::wrapping_mul, |a, b| a * b)
    }

    /// `self / rhs` (integer division when both are integers); dividing by zero is an error.
    pub fn divided_by(self, rhs: Value) -> Result<Value, Problem> {
        check_divisor(&rhs)?;
        arithmetic(self, rhs, i64::wrapping_div, |a, b| a / b)
    }

    /// `self % rhs` (the remainder has the sign of `self`, as in C).
    pub fn remainder(self, rhs: Value) -> Result<Value, Problem> {
        check_divisor(&rhs)?;
        arithmetic(self, rhs, i64::wrapping_rem, |a, b| a % b)
    }

    /// `-self`.
    pub fn negated(self) -> Result<Value, Problem> {
        match self {
            Value::Int(i) => Ok(Value::Int(i.wrapping_neg())),
            Value::Float(f) => Ok(Value::Float(-f)),
            _ => Err(Problem::NotNumeric),
        }
    }

    /// Compares two values: numbers by value (floats equal within 1e-8), booleans with
    /// booleans, anything with a string as strings. `Less`/`Greater` for the ordering
    /// operators; booleans only compare for equality.
    pub fn compare(&self, rhs: &Value) -> Result<std::cmp::Ordering, Problem> {
        use std::cmp::Ordering;
        match (self, rhs) {
            (Value::Int(a), Value::Int(b)) => Ok(a.cmp(b)),
            (a, b) if a.is_numeric() && b.is_numeric() => {
                let (a, b) = (a.as_f64()?, b.as_f64()?);
                Ok(if (a - b).abs() < 1e-8 {
                    Ordering::Equal
                } else if a < b {
                    Ordering::Less
                } else {
                    Ordering::Greater
                })
            }
            (Value::Str(_), _) | (_, Value::Str(_)) => Ok(self.to_string().cmp(&rhs.to_string())),
            // A flag read from a profile is an integer: compare it with a boolean as 0 / 1.
            (a, b) => Ok(a.truth()?.cmp(&b.truth()?)),
        }
    }
}

fn check_divisor(rhs: &Value) -> Result<(), Problem> {
    match rhs {
        Value::Int(0) => Err(Problem::DivisionByZero),
        Value::Float(f) if *f == 0.0 => Err(Problem::DivisionByZero),
        _ => Ok(()),
    }
}

/// Integer arithmetic when both sides are integers, float arithmetic otherwise.
fn arithmetic(
    l: Value,
    r: Value,
    int: fn(i64, i64) -> i64,
    float: fn(f64, f64) -> f64,
) -> Result<Value, Problem> {
    match (&l, &r) {
        (Value::Int(a), Value::Int(b)) => Ok(Value::Int(int(*a, *b))),
        _ => Ok(Value::Float(float(l.as_f64()?, r.as_f64()?))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_print_as_cpp_streams_do() {
        for (x, s) in [
            (0.2, "0.2"),
            (60.0, "60"),
            (101.234567, "101.235"),
            (0.35000000000000003, "0.35"),
            (-4.0, "-4"),
            (1234567.0, "1.23457e+06"),
            (999999.4, "999999"),
            (999999.6, "1e+06"),
            (0.0001, "0.0001"),
            (0.00001234, "1.234e-05"),
            (0.0, "0"),
        ] {
            assert_eq!(format_float(x), s, "{x}");
        }
    }

    #[test]
    fn arithmetic_follows_the_operand_types() -> Result<(), Problem> {
        assert_eq!(Value::Int(7).divided_by(Value::Int(2))?, Value::Int(3));
        assert_eq!(Value::Int(-7).remainder(Value::Int(2))?, Value::Int(-1));
        assert_eq!(
            Value::Float(7.0).divided_by(Value::Int(2))?,
            Value::Float(3.5)
        );
        assert_eq!(
            Value::from("G1 F").plus(Value::Float(21000.0))?,
            Value::from("G1 F21000")
        );
        assert_eq!(
            Value::Int(1).plus(Value::from("x"))?,
            Value::from("1x"),
            "a number before a string joins"
        );
        assert_eq!(
            Value::Int(1).divided_by(Value::Int(0)),
            Err(Problem::DivisionByZero)
        );
        assert_eq!(
            Value::Bool(true).minus(Value::Int(1)),
            Err(Problem::NotNumeric)
        );
        Ok(())
    }
}
