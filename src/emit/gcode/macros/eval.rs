//! The evaluator: a parsed template run against the variables, writing its text.
//!
//! Place in the pipeline: the last step of filling a template, after the parser
//! ([`super::parser`]). Only the branch of an `{if}` that is taken is evaluated (so a
//! variable a profile names only in a branch for another printer need not exist), and `and`,
//! `or` and `? :` evaluate only what decides their value.

use std::collections::BTreeMap;

use super::parser::{BinOp, Body, Expr, Func, Init, Loc, Node, Pattern, Stmt, UnOp};
use super::value::{Value, Var};
use super::{Problem, Variables};

/// A problem found while evaluating, and the statement it is in.
#[derive(Debug, Clone, PartialEq)]
pub struct EvalError {
    /// What is wrong.
    pub problem: Problem,
    /// Where.
    pub loc: Loc,
}

/// Runs parsed templates: the variables, and those the templates define themselves.
pub struct Evaluator<'a> {
    vars: &'a dyn Variables,
    /// `local` variables defined so far in this template.
    locals: BTreeMap<String, Var>,
    /// `global` variables, which outlive the template (the caller keeps them from one
    /// template to the next), and the writable variables the caller put among them.
    globals: &'a mut BTreeMap<String, Var>,
}

impl<'a> Evaluator<'a> {
    /// An evaluator reading `vars`, with `globals` the global (and writable) variables so far.
    pub fn new(vars: &'a dyn Variables, globals: &'a mut BTreeMap<String, Var>) -> Self {
        Self {
            vars,
            locals: BTreeMap::new(),
            globals,
        }
    }

    /// Whether `name` is a variable already.
    fn exists(&self, name: &str) -> bool {
        self.locals.contains_key(name)
            || self.globals.contains_key(name)
            || self.vars.var(name).is_some()
    }

    /// Writes `nodes` into `out`.
    pub fn nodes(&mut self, nodes: &[Node], out: &mut String) -> Result<(), EvalError> {
        for node in nodes {
            match node {
                Node::Text(t) => out.push_str(t),
                Node::Legacy {
                    name,
                    index,
                    raw,
                    loc,
                } => match self.legacy(name, index.as_deref()) {
                    Ok(Some(v)) => out.push_str(&v),
                    Ok(None) => out.push_str(raw),
                    Err(problem) => return Err(EvalError { problem, loc: *loc }),
                },
                Node::Macro(stmts) => self.stmts(stmts, out)?,
            }
        }
        Ok(())
    }

    fn stmts(&mut self, stmts: &[Stmt], out: &mut String) -> Result<(), EvalError> {
        for s in stmts {
            self.stmt(s, out)?;
        }
        Ok(())
    }

    fn stmt(&mut self, stmt: &Stmt, out: &mut String) -> Result<(), EvalError> {
        let at = |loc: &Loc| {
            let loc = *loc;
            move |problem| EvalError { problem, loc }
        };
        match stmt {
            Stmt::Expr(e, loc) => {
                let v = self.eval(e).map_err(at(loc))?;
                out.push_str(&v.to_string());
            }
            Stmt::Define {
                global,
                name,
                value,
                loc,
            } => {
                if self.exists(name) {
                    return Err(at(loc)(Problem::Redefined(name.clone())));
                }
                let v = self.init(value).map_err(at(loc))?;
                if *global {
                    self.globals.insert(name.clone(), v);
                } else {
                    self.locals.insert(name.clone(), v);
                }
            }
            Stmt::Assign {
                name,
                index,
                value,
                loc,
            } => self.assign(name, index.as_ref(), value).map_err(at(loc))?,
            Stmt::If {
                branches,
                otherwise,
            } => {
                let mut body = otherwise.as_ref();
                for (cond, loc, b) in branches {
                    if self.eval(cond).and_then(|v| v.truth()).map_err(at(loc))? {
                        body = Some(b);
                        break;
                    }
                }
                match body {
                    Some(Body::Text(nodes)) => self.nodes(nodes, out)?,
                    Some(Body::Stmts(stmts)) => self.stmts(stmts, out)?,
                    None => {}
                }
            }
        }
        Ok(())
    }

    fn init(&mut self, init: &Init) -> Result<Var, Problem> {
        Ok(match init {
            Init::Scalar(e) => match e {
                // `local a = b` with a vector `b` copies the vector.
                Expr::Var(name, None) => match self.lookup(name)? {
                    Var::Vector(v) => Var::Vector(v),
                    Var::Scalar(_) => Var::Scalar(self.eval(e)?),
                },
                e => Var::Scalar(self.eval(e)?),
            },
            Init::List(items) => Var::Vector(
                items
                    .iter()
                    .map(|e| self.eval(e))
                    .collect::<Result<_, _>>()?,
            ),
            Init::Repeat(count, value) => {
                let n = match self.eval(count)? {
                    Value::Int(n) if n >= 0 => usize::try_from(n).unwrap_or(0),
                    Value::Int(_) => return Err(Problem::NegativeIndex),
                    _ => return Err(Problem::NotInteger),
                };
                let v = self.eval(value)?;
                Var::Vector(vec![v; n.min(1 << 16)])
            }
        })
    }

    fn assign(&mut self, name: &str, index: Option<&Expr>, value: &Init) -> Result<(), Problem> {
        if !self.locals.contains_key(name) && !self.globals.contains_key(name) {
            return Err(if self.vars.var(name).is_some() {
                Problem::ReadOnly(name.to_owned())
            } else {
                Problem::UnknownVariable(name.to_owned())
            });
        }
        let index = index.map(|i| self.index(i)).transpose()?;
        let new = self.init(value)?;
        let slot = match self.locals.get_mut(name) {
            Some(slot) => slot,
            None => self
                .globals
                .get_mut(name)
                .ok_or_else(|| Problem::UnknownVariable(name.to_owned()))?,
        };
        match (slot, index, new) {
            (Var::Vector(v), Some(i), Var::Scalar(x)) => {
                *v.get_mut(i).ok_or(Problem::IndexOutOfRange(i))? = x;
            }
            (slot, None, new) => *slot = new,
            _ => return Err(Problem::NotAVector(name.to_owned())),
        }
        Ok(())
    }

    fn lookup(&self, name: &str) -> Result<Var, Problem> {
        self.locals
            .get(name)
            .or_else(|| self.globals.get(name))
            .cloned()
            .or_else(|| self.vars.var(name))
            .ok_or_else(|| Problem::UnknownVariable(name.to_owned()))
    }

    /// An index: a non-negative integer.
    fn index(&mut self, e: &Expr) -> Result<usize, Problem> {
        match self.eval(e)? {
            Value::Int(i) => usize::try_from(i).map_err(|_| Problem::NegativeIndex),
            _ => Err(Problem::NotInteger),
        }
    }

    /// Element `index` of `var` (PrusaSlicer's rules: past the end is element 0). Without an
    /// index a vector gives the current tool's element, and a scalar indexed is itself.
    fn element(&self, name: &str, var: Var, index: Option<usize>) -> Result<Value, Problem> {
        match var {
            Var::Scalar(v) => Ok(v),
            Var::Vector(mut v) => {
                let i = index.unwrap_or_else(|| self.vars.tool());
                if v.is_empty() {
                    return Err(Problem::EmptyVector(name.to_owned()));
                }
                let i = if i < v.len() { i } else { 0 };
                Ok(v.swap_remove(i))
            }
        }
    }

    /// A legacy `[name]` / `[name[index_name]]` / `[name_N]`: its text, or `None` when the name
    /// is unknown (the brackets are then kept as text).
    fn legacy(&self, name: &str, index: Option<&str>) -> Result<Option<String>, Problem> {
        let (var, i) = match (self.lookup(name), index) {
            (Ok(var), None) => (var, None),
            (Ok(var), Some(index_name)) => match self.lookup(index_name)? {
                Var::Scalar(Value::Int(i)) => (
                    var,
                    Some(usize::try_from(i).map_err(|_| Problem::NegativeIndex)?),
                ),
                _ => return Err(Problem::NotInteger),
            },
            (Err(_), None) => {
                // `[temperature_1]`: element 1 of a vector.
                let Some((base, n)) = name.rsplit_once('_') else {
                    return Ok(None);
                };
                match (self.lookup(base), n.parse::<usize>()) {
                    (Ok(var @ Var::Vector(_)), Ok(n)) => (var, Some(n)),
                    _ => return Ok(None),
                }
            }
            (Err(_), Some(_)) => return Ok(None),
        };
        Ok(Some(match self.element(name, var, i)? {
            // A flag serialises as 1 / 0.
            Value::Bool(b) => if b { "1" } else { "0" }.to_owned(),
            v => v.to_string(),
        }))
    }

    /// The value of `e`.
    pub fn eval(&mut self, e: &Expr) -> Result<Value, Problem> {
        match e {
            Expr::Lit(v) => Ok(v.clone()),
            Expr::Var(name, index) => {
                let var = self.lookup(name)?;
                let i = index.as_deref().map(|i| self.index(i)).transpose()?;
                self.element(name, var, i)
            }
            Expr::Unary(UnOp::Neg, x) => self.eval(x)?.negated(),
            Expr::Unary(UnOp::Not, x) => Ok(Value::Bool(!self.eval(x)?.truth()?)),
            Expr::Binary(op, a, b) => self.binary(*op, a, b),
            Expr::Regex(x, re, negate) => match self.eval(x)? {
                Value::Str(s) => Ok(Value::Bool(full_match(re, &s)? != *negate)),
                _ => Err(Problem::NotString),
            },
            Expr::Ternary(c, a, b) => {
                if self.eval(c)?.truth()? {
                    self.eval(a)
                } else {
                    self.eval(b)
                }
            }
            Expr::Call(f, args) => {
                let args = args
                    .iter()
                    .map(|a| self.eval(a))
                    .collect::<Result<Vec<_>, _>>()?;
                call(*f, args)
            }
            Expr::OneOf(x, patterns) => {
                let Value::Str(s) = self.eval(x)? else {
                    return Err(Problem::NotString);
                };
                for p in patterns {
                    let hit = match p {
                        Pattern::Equal(e) => match self.eval(e)? {
                            Value::Str(p) => p == s,
                            _ => return Err(Problem::NotString),
                        },
                        Pattern::Regex(e) => match self.eval(e)? {
                            Value::Str(re) => full_match(&re, &s)?,
                            _ => return Err(Problem::NotString),
                        },
                    };
                    if hit {
                        return Ok(Value::Bool(true));
                    }
                }
                Ok(Value::Bool(false))
            }
            Expr::Interpolate(x, table) => {
                let x = self.eval(x)?.as_f64()?;
                let mut points = Vec::with_capacity(table.len());
                for (a, b) in table {
                    points.push((self.eval(a)?.as_f64()?, self.eval(b)?.as_f64()?));
                }
                interpolate(x, &points)
            }
            Expr::IsNil(name, index) => {
                // Neither the config nor the writer has optional (nil) values; the variable
                // must exist all the same.
                self.lookup(name)?;
                if let Some(i) = index {
                    self.index(i)?;
                }
                Ok(Value::Bool(false))
            }
            Expr::Empty(name) | Expr::Size(name) => match self.lookup(name)? {
                Var::Vector(v) if matches!(e, Expr::Empty(_)) => Ok(Value::Bool(v.is_empty())),
                Var::Vector(v) => Ok(Value::from(v.len())),
                Var::Scalar(_) => Err(Problem::NotAVector(name.clone())),
            },
        }
    }

    fn binary(&mut self, op: BinOp, a: &Expr, b: &Expr) -> Result<Value, Problem> {
        use std::cmp::Ordering::{Equal, Greater, Less};
        match op {
            BinOp::And => {
                return Ok(Value::Bool(
                    self.eval(a)?.truth()? && self.eval(b)?.truth()?,
                ));
            }
            BinOp::Or => {
                return Ok(Value::Bool(
                    self.eval(a)?.truth()? || self.eval(b)?.truth()?,
                ));
            }
            _ => {}
        }
        let (l, r) = (self.eval(a)?, self.eval(b)?);
        let ord = |l: &Value, r: &Value| l.compare(r);
        Ok(match op {
            BinOp::Add => l.plus(r)?,
            BinOp::Sub => l.minus(r)?,
            BinOp::Mul => l.times(r)?,
            BinOp::Div => l.divided_by(r)?,
            BinOp::Rem => l.remainder(r)?,
            BinOp::Eq => Value::Bool(ord(&l, &r)? == Equal),
            BinOp::Ne => Value::Bool(ord(&l, &r)? != Equal),
            BinOp::Lt => Value::Bool(ord(&l, &r)? == Less),
            BinOp::Gt => Value::Bool(ord(&l, &r)? == Greater),
            BinOp::Le => Value::Bool(ord(&l, &r)? != Greater),
            BinOp::Ge => Value::Bool(ord(&l, &r)? != Less),
            BinOp::And | BinOp::Or => Value::Bool(false),
        })
    }
}

/// Whether `re` matches the whole of `s`; `.` matches line breaks too, as in PrusaSlicer's
/// (Boost's) regular expressions, so `/.*MODEL_MK4.*/` finds a word in multi-line notes.
fn full_match(re: &str, s: &str) -> Result<bool, Problem> {
    let compiled = regex::Regex::new(&format!("(?s)^(?:{re})$"))
        .map_err(|_| Problem::BadRegex(re.to_owned()))?;
    Ok(compiled.is_match(s))
}

/// A function of already evaluated arguments.
fn call(f: Func, args: Vec<Value>) -> Result<Value, Problem> {
    let arg = |i: usize| args.get(i).ok_or(Problem::MissingArgument);
    match f {
        Func::Min | Func::Max => {
            let (a, b) = (arg(0)?, arg(1)?);
            let pick_a = match a.compare(b)? {
                std::cmp::Ordering::Less => f == Func::Min,
                std::cmp::Ordering::Greater => f == Func::Max,
                std::cmp::Ordering::Equal => true,
            };
            if !a.is_numeric() || !b.is_numeric() {
                return Err(Problem::NotNumeric);
            }
            let v = if pick_a { a } else { b };
            // Mixed integer and float: a float, as PrusaSlicer computes in doubles then.
            Ok(match (a, b) {
                (Value::Int(_), Value::Int(_)) => v.clone(),
                _ => Value::Float(v.as_f64()?),
            })
        }
        Func::Int => match arg(0)? {
            Value::Int(i) => Ok(Value::Int(*i)),
            Value::Float(x) => Ok(Value::Int(x.trunc() as i64)),
            _ => Err(Problem::NotNumeric),
        },
        Func::Round => match arg(0)? {
            Value::Int(i) => Ok(Value::Int(*i)),
            Value::Float(x) => Ok(Value::Int(x.round() as i64)),
            _ => Err(Problem::NotNumeric),
        },
        Func::Digits | Func::Zdigits => {
            let x = arg(0)?;
            if !x.is_numeric() {
                return Err(Problem::NotNumeric);
            }
            let Value::Int(width) = arg(1)? else {
                return Err(Problem::NotInteger);
            };
            let width = usize::try_from((*width).clamp(0, 64)).unwrap_or(0);
            let zeros = f == Func::Zdigits;
            let text = match args.get(2) {
                Some(Value::Int(d)) => {
                    let d = usize::try_from((*d).clamp(0, 64)).unwrap_or(0);
                    let x = x.as_f64()?;
                    if zeros {
                        format!("{x:0width$.d$}")
                    } else {
                        format!("{x:>width$.d$}")
                    }
                }
                Some(_) => return Err(Problem::NotInteger),
                None => {
                    let i = match x {
                        Value::Int(i) => *i,
                        _ => x.as_f64()?.round() as i64,
                    };
                    if zeros {
                        format!("{i:0width$}")
                    } else {
                        format!("{i:>width$}")
                    }
                }
            };
            Ok(Value::Str(text))
        }
    }
}

/// Linear interpolation in a table of (x, y) points with increasing x; an x outside the
/// table is an error.
fn interpolate(x: f64, table: &[(f64, f64)]) -> Result<Value, Problem> {
    if table.windows(2).any(|w| w[0].0 > w[1].0) {
        return Err(Problem::TableNotIncreasing);
    }
    for w in table.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if x >= x0 && x <= x1 {
            let y = if x == x0 {
                y0
            } else if x == x1 {
                y1
            } else if (x1 - x0).abs() < 1e-12 {
                0.5 * (y0 + y1)
            } else {
                y0 + (y1 - y0) * (x - x0) / (x1 - x0)
            };
            return Ok(Value::Float(y));
        }
    }
    // Just outside the table (by less than PrusaSlicer's EPSILON, 1e-4): its end value.
    const EPSILON: f64 = 1e-4;
    match (table.first(), table.last()) {
        (Some(&(x0, y0)), _) if x > x0 - EPSILON && x <= x0 => Ok(Value::Float(y0)),
        (_, Some(&(x1, y1))) if x >= x1 && x < x1 + EPSILON => Ok(Value::Float(y1)),
        _ => Err(Problem::OutsideTable),
    }
}
