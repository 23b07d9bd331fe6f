//! PrusaSlicer's G-code macro language: the `{if}` blocks, expressions and functions of the
//! custom G-code a PrusaSlicer profile carries, filled as PrusaSlicer fills them.
//!
//! Place in the pipeline: inside the G-code writer. [`GcodeParams::render_template`]
//! (`super::template`) gives every template it writes to [`render`], with the variables of
//! the config, the profile and the print; the steps are [`lexer`] (tokens) → [`parser`] (the
//! template as text, legacy placeholders and statements) → [`eval`] (the text written).
//!
//! # The language
//!
//! - Text is written as it is. `{expr}` writes the value of an expression; `[name]` is the
//!   legacy placeholder (a vector gives the current tool's element, `[name_N]` and
//!   `[name[index_name]]` element N); a `[…]` that names no variable stays text.
//! - `{if cond}…{elsif cond}…{else}…{endif}`, nested and spanning lines, writes the text of
//!   the first true branch; inside one macro, `{if cond then stmt; … elsif … else … endif}`.
//! - Statements in one macro are separated by `;`: `local name = expr` (lives until the end of
//!   the template), `global name = expr` (lives on into the templates after it, see
//!   [`render_with`]), `name = expr` and `name[i] = expr` on such a variable or on a writable
//!   one the caller provides (the writer's `position`), `(a, b, …)` and `repeat(n, value)`
//!   vectors.
//! - Literals: integers, floats (`1.5`, `2e3`), `"strings"` (escapes `\n \r \" \\`), `true`,
//!   `false`. Operators by precedence: `? :`; `or ||`; `and &&`; `== != <> =~ !~`
//!   (`=~ /regex/` matches the whole string); `< > <= >=`; `+ -` (`+` joins strings); `* / %`;
//!   unary `- + ! not`. Integer arithmetic stays integer.
//! - Functions: `min`, `max`, `int` (truncates), `round`, `digits(x, width[, decimals])`,
//!   `zdigits(…)` (zero-padded), `is_nil`, `empty`, `size`, `one_of(x, "a", /re/, ~expr)`,
//!   `interpolate_table(x, (x0, y0), (x1, y1), …)`. `random` is refused: conduit's output is
//!   deterministic.
//! - `name[i]` indexes a vector; an index past its end gives element 0, as in PrusaSlicer.
//!   Beyond PrusaSlicer, a vector without an index gives the current tool's element, a scalar
//!   indexed is itself, and an integer is accepted as a condition (non-zero is true): values
//!   read from a profile are untyped text, so `spiral_vase = 0` is the integer 0.
//! - Output: floats with six significant digits and no trailing zeros (`0.2`, `101.235`),
//!   booleans as `true` / `false` (`1` / `0` in legacy `[…]` placeholders).
//!
//! An unknown variable, a type error or a syntax error is a [`TemplateError`] naming the line
//! and the placeholder.

pub mod eval;
pub mod lexer;
pub mod parser;
pub mod value;

pub use value::{Value, Var};

/// Where the variables of a template come from.
pub trait Variables {
    /// The variable `name`, or `None` when there is none.
    fn var(&self, name: &str) -> Option<Var>;
    /// The current tool: the element a vector without an index gives.
    fn tool(&self) -> usize;
}

/// What is wrong with a template.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Problem {
    /// A syntax error.
    #[error("syntax error: {0}")]
    Syntax(String),
    /// A variable neither the caller, the config nor the profile has.
    #[error("unknown variable `{0}`")]
    UnknownVariable(String),
    /// `local` or `global` names a variable that exists.
    #[error("`{0}` is already defined")]
    Redefined(String),
    /// An assignment to a variable of the config.
    #[error("`{0}` cannot be assigned (only local and global variables can)")]
    ReadOnly(String),
    /// An operator or function that needs a number got something else.
    #[error("not a number")]
    NotNumeric,
    /// A condition that is not a boolean (or an integer).
    #[error("not a boolean expression")]
    NotBoolean,
    /// A regex match or `one_of` on something other than a string.
    #[error("not a string")]
    NotString,
    /// An index or width that is not an integer.
    #[error("not an integer")]
    NotInteger,
    /// A negative index.
    #[error("negative index")]
    NegativeIndex,
    /// An element assigned past the end of a vector.
    #[error("index {0} is past the end of the vector")]
    IndexOutOfRange(usize),
    /// A vector without elements.
    #[error("`{0}` is an empty vector")]
    EmptyVector(String),
    /// `empty`, `size` or an element assignment on a scalar.
    #[error("`{0}` is not a vector")]
    NotAVector(String),
    /// `/` or `%` by zero.
    #[error("division by zero")]
    DivisionByZero,
    /// A regular expression that does not compile.
    #[error("bad regular expression /{0}/")]
    BadRegex(String),
    /// A function called with too few arguments.
    #[error("missing argument")]
    MissingArgument,
    /// `interpolate_table` with x values that decrease.
    #[error("interpolate_table: the x values must increase")]
    TableNotIncreasing,
    /// `interpolate_table` with an x outside the table.
    #[error("interpolate_table: value outside the table")]
    OutsideTable,
    /// `random(…)`.
    #[error("random() is not supported: conduit's output is deterministic")]
    Random,
}

/// A template that cannot be filled: the line (1-based, in the template), the placeholder (the
/// `{…}` macro, or for a macro over several lines the line of the problem) and the problem.
///
/// How to fix: correct the placeholder, or define the variable (`--set`, or the profile).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("line {line}: {problem} in {placeholder}")]
pub struct TemplateError {
    /// 1-based line in the template.
    pub line: usize,
    /// The placeholder as written.
    pub placeholder: String,
    /// What is wrong.
    pub problem: Problem,
}

/// Fills `template` with `vars`.
///
/// ```
/// use conduit::emit::gcode::macros::{render, Value, Var, Variables};
/// struct Bed;
/// impl Variables for Bed {
///     fn var(&self, name: &str) -> Option<Var> {
///         (name == "print_bed_max")
///             .then(|| Var::Vector(vec![Value::Float(250.0), Value::Float(210.0)]))
///     }
///     fn tool(&self) -> usize {
///         0
///     }
/// }
/// let g = render("G1 X{print_bed_max[0] / 2}{if print_bed_max[1] > 200} ; large{endif}", &Bed)?;
/// assert_eq!(g, "G1 X125 ; large");
/// # Ok::<(), conduit::emit::gcode::macros::TemplateError>(())
/// ```
pub fn render(template: &str, vars: &dyn Variables) -> Result<String, TemplateError> {
    render_with(template, vars, &mut Globals::new())
}

/// The `global` variables of one G-code file, carried from each template to the next, and the
/// writable variables a writer puts among them for one template (`position`).
pub type Globals = std::collections::BTreeMap<String, Var>;

/// Fills `template` with `vars` and `globals`: what it defines as `global` (or assigns to a
/// variable of `globals`) stays in `globals` for the next template.
///
/// ```
/// use conduit::emit::gcode::macros::{render_with, Globals, Value, Var, Variables};
/// struct None_;
/// impl Variables for None_ {
///     fn var(&self, _: &str) -> Option<Var> {
///         None
///     }
///     fn tool(&self) -> usize {
///         0
///     }
/// }
/// let mut globals = Globals::new();
/// render_with("{global purged = 0}", &None_, &mut globals)?;
/// assert_eq!(render_with("{purged = purged + 5}{purged}", &None_, &mut globals)?, "5");
/// assert_eq!(globals["purged"], Var::Scalar(Value::Int(5)));
/// # Ok::<(), conduit::emit::gcode::macros::TemplateError>(())
/// ```
pub fn render_with(
    template: &str,
    vars: &dyn Variables,
    globals: &mut Globals,
) -> Result<String, TemplateError> {
    let nodes = parser::parse(template).map_err(|e| error(template, e.loc, e.problem))?;
    let mut out = String::with_capacity(template.len());
    eval::Evaluator::new(vars, globals)
        .nodes(&nodes, &mut out)
        .map_err(|e| error(template, e.loc, e.problem))?;
    Ok(out)
}

/// Parses `template` only: `Err` on a syntax error.
pub fn check_syntax(template: &str) -> Result<(), TemplateError> {
    parser::parse(template)
        .map(|_| ())
        .map_err(|e| error(template, e.loc, e.problem))
}

/// The error for `problem` at `loc`: its line and the placeholder around it.
fn error(src: &str, loc: parser::Loc, problem: Problem) -> TemplateError {
    let at = loc.at.min(src.len());
    let line = 1 + src.as_bytes()[..at].iter().filter(|&&b| b == b'\n').count();
    TemplateError {
        line,
        placeholder: placeholder(src, loc.open, at),
        problem,
    }
}

/// The text of the placeholder opened at `open`: up to its `}` (or `]`), or, when that spans
/// lines, the line of `at` trimmed.
fn placeholder(src: &str, open: usize, at: usize) -> String {
    let open = open.min(at);
    let end = if src[open..].starts_with('[') {
        src[open..].find(']').map(|e| open + e + 1)
    } else {
        let mut lx = lexer::Lexer::new(src, open + 1);
        loop {
            match lx.next_token() {
                Ok((lexer::Tok::Close, p)) => break Some(p + 1),
                Ok((lexer::Tok::End, _)) | Err(_) => break None,
                Ok(_) => {}
            }
        }
    };
    match end {
        Some(end) if !src[open..end].contains('\n') => src[open..end].to_owned(),
        _ => {
            let start = src[..at].rfind('\n').map_or(0, |i| i + 1);
            let stop = src[at..].find('\n').map_or(src.len(), |i| at + i);
            src[start..stop].trim().to_owned()
        }
    }
}

#[cfg(test)]
mod tests;
