//! The parser: a template read into text, legacy `[key]` placeholders and macros, each macro
//! a list of statements and expressions.
//!
//! Place in the pipeline: between the lexer ([`super::lexer`]) and the evaluator
//! ([`super::eval`]). The whole template is parsed before anything is evaluated, so a syntax
//! error anywhere (in an `{if}` branch that would not be taken, too) is reported.
//!
//! Grammar (PrusaSlicer's, as its documentation and `PlaceholderParser` read it):
//!
//! ```text
//! template  := ( text | '[' name ']' | '[' name '[' name ']' ']' | '{' macro '}' )*
//! macro     := ( if_block | statement (';' | before '}') | ';' )*
//! if_block  := 'if' cond ( '}' template '{' | 'then' statements )
//!              ( 'elsif' cond ( … the same … ) )* ( 'else' ( '}' template '{' | statements ) )?
//!              'endif'
//! statement := ('local' | 'global') name '=' init | name ('[' add ']')? '=' init | cond
//! init      := '(' cond (',' cond)* ')' | 'repeat' '(' add ',' cond ')' | cond
//! cond      := or ('?' cond ':' cond)?
//! or        := and (('or' | '||') and)*          and := eq (('and' | '&&') eq)*
//! eq        := rel (('==' | '!=' | '<>') rel | ('=~' | '!~') regex)*
//! rel       := add (('<' | '>' | '<=' | '>=') add)*
//! add       := mul (('+' | '-') mul)*            mul := unary (('*' | '/' | '%') unary)*
//! unary     := ('-' | '+' | '!' | 'not') unary | '(' cond ')' | function '(' … ')'
//!            | name ('[' add ']')? | number | string | 'true' | 'false'
//! ```

use super::Problem;
use super::lexer::{Lexer, Tok};
use super::value::Value;

/// Where a statement is: the byte offset of its macro's `{` and of its own start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Loc {
    /// Offset of the `{` that opens the macro part the statement is in.
    pub open: usize,
    /// Offset of the statement (or condition) itself.
    pub at: usize,
}

/// A piece of a parsed template.
#[derive(Debug, Clone, PartialEq)]
pub enum Node {
    /// Text written as it is.
    Text(String),
    /// A legacy `[name]` or `[name[index_name]]` placeholder (`raw` is the text as written,
    /// kept when the name is unknown).
    Legacy {
        /// The variable.
        name: String,
        /// The name of the variable holding the index, if any.
        index: Option<String>,
        /// The placeholder as written, brackets included.
        raw: String,
        /// Where it is.
        loc: Loc,
    },
    /// The statements of one `{…}` macro.
    Macro(Vec<Stmt>),
}

/// A statement of a macro.
#[derive(Debug, Clone, PartialEq)]
pub enum Stmt {
    /// An expression: its value is written.
    Expr(Expr, Loc),
    /// `local name = …` or `global name = …`.
    Define {
        /// `global`: the variable outlives the macro (here: the template).
        global: bool,
        /// The new variable.
        name: String,
        /// Its value.
        value: Init,
        /// Where it is.
        loc: Loc,
    },
    /// `name = …` or `name[index] = …` on a variable defined before.
    Assign {
        /// The variable.
        name: String,
        /// The element, for a vector.
        index: Option<Expr>,
        /// The value.
        value: Init,
        /// Where it is.
        loc: Loc,
    },
    /// `if … elsif … else … endif`.
    If {
        /// Each condition with its place and its body, in order.
        branches: Vec<(Expr, Loc, Body)>,
        /// The `else` body.
        otherwise: Option<Body>,
    },
}

/// The right side of a definition or an assignment.
#[derive(Debug, Clone, PartialEq)]
pub enum Init {
    /// One value.
    Scalar(Expr),
    /// `(a, b, …)`: a vector.
    List(Vec<Expr>),
    /// `repeat(count, value)`: a vector of `count` copies.
    Repeat(Expr, Expr),
}

/// The body of an `if` branch.
#[derive(Debug, Clone, PartialEq)]
pub enum Body {
    /// `{if c}text{endif}`: a template.
    Text(Vec<Node>),
    /// `{if c then a; b; endif}`: statements.
    Stmts(Vec<Stmt>),
}

/// A unary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnOp {
    /// `-x`.
    Neg,
    /// `!x`, `not x`.
    Not,
}

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    /// `+` (also joins strings).
    Add,
    /// `-`.
    Sub,
    /// `*`.
    Mul,
    /// `/`.
    Div,
    /// `%`.
    Rem,
    /// `==`.
    Eq,
    /// `!=`, `<>`.
    Ne,
    /// `<`.
    Lt,
    /// `>`.
    Gt,
    /// `<=`.
    Le,
    /// `>=`.
    Ge,
    /// `and`, `&&`.
    And,
    /// `or`, `||`.
    Or,
}

/// A function of one or more expressions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    /// `min(a, b)`.
    Min,
    /// `max(a, b)`.
    Max,
    /// `int(x)`: truncated towards zero.
    Int,
    /// `round(x)`: to the nearest integer, halves away from zero.
    Round,
    /// `digits(x, width[, decimals])`: right-aligned in `width` characters.
    Digits,
    /// `zdigits(x, width[, decimals])`: padded with leading zeros.
    Zdigits,
}

/// An element of `one_of(x, …)`'s list.
#[derive(Debug, Clone, PartialEq)]
pub enum Pattern {
    /// Equal to the value.
    Equal(Expr),
    /// `~expr` or `/regex/`: matches the whole string.
    Regex(Expr),
}

/// An expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A literal.
    Lit(Value),
    /// `name` or `name[index]`.
    Var(String, Option<Box<Expr>>),
    /// A unary operator.
    Unary(UnOp, Box<Expr>),
    /// A binary operator.
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `x =~ /re/` (or `!~` when the flag is set).
    Regex(Box<Expr>, String, bool),
    /// `c ? a : b`.
    Ternary(Box<Expr>, Box<Expr>, Box<Expr>),
    /// A function call.
    Call(Func, Vec<Expr>),
    /// `one_of(x, patterns…)`.
    OneOf(Box<Expr>, Vec<Pattern>),
    /// `interpolate_table(x, (x0, y0), (x1, y1), …)`.
    Interpolate(Box<Expr>, Vec<(Expr, Expr)>),
    /// `is_nil(name[index])`.
    IsNil(String, Option<Box<Expr>>),
    /// `empty(name)`.
    Empty(String),
    /// `size(name)`.
    Size(String),
}

/// A syntax error: what and at which byte offset, and the `{` of its macro.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxError {
    /// What is wrong.
    pub problem: Problem,
    /// Where.
    pub loc: Loc,
}

/// Parses `src` into nodes.
pub fn parse(src: &str) -> Result<Vec<Node>, SyntaxError> {
    let mut p = Parser {
        lx: Lexer::new(src, 0),
        src,
        open: 0,
        depth: 0,
    };
    p.text(false)
}

/// Keywords that end a branch of an `if`.
fn ends_branch(t: &Tok) -> bool {
    matches!(t, Tok::Ident(k) if k == "elsif" || k == "else" || k == "endif")
}

/// How deep expressions and `if` blocks may nest (operators of one chain count as levels):
/// far beyond any profile's templates, and shallow enough that parsing and evaluating
/// recursively cannot run out of stack on a template made to be deep.
const MAX_DEPTH: usize = 256;

struct Parser<'a> {
    lx: Lexer<'a>,
    src: &'a str,
    /// Offset of the `{` of the macro being read.
    open: usize,
    /// Levels of nesting open at the token being read (see [`MAX_DEPTH`]).
    depth: usize,
}

type Parsed<T> = Result<T, SyntaxError>;

impl Parser<'_> {
    /// Runs `f` one level deeper, or fails at `at` past [`MAX_DEPTH`].
    fn deeper<T>(&mut self, at: usize, f: impl FnOnce(&mut Self) -> Parsed<T>) -> Parsed<T> {
        if self.depth >= MAX_DEPTH {
            return self.err(
                Problem::Syntax(format!("nested more than {MAX_DEPTH} levels deep")),
                at,
            );
        }
        self.depth += 1;
        let r = f(self);
        self.depth -= 1;
        r
    }

    fn err<T>(&self, problem: Problem, at: usize) -> Parsed<T> {
        Err(SyntaxError {
            problem,
            loc: Loc {
                open: self.open,
                at,
            },
        })
    }

    fn next(&mut self) -> Parsed<(Tok, usize)> {
        let open = self.open;
        self.lx.next_token().map_err(|(problem, at)| SyntaxError {
            problem,
            loc: Loc { open, at },
        })
    }

    fn peek(&self) -> Parsed<(Tok, usize)> {
        self.lx.peek().map_err(|(problem, at)| SyntaxError {
            problem,
            loc: Loc {
                open: self.open,
                at,
            },
        })
    }

    fn loc(&self, at: usize) -> Loc {
        Loc {
            open: self.open,
            at,
        }
    }

    /// Consumes `sym` or fails with "expected `sym`".
    fn expect(&mut self, sym: &'static str) -> Parsed<()> {
        let (t, at) = self.next()?;
        if t == Tok::Sym(sym) {
            Ok(())
        } else {
            self.err(Problem::Syntax(format!("expected `{sym}`")), at)
        }
    }

    /// Consumes the next token when it is `sym`.
    fn eat(&mut self, sym: &'static str) -> Parsed<bool> {
        if self.peek()?.0 == Tok::Sym(sym) {
            self.next()?;
            return Ok(true);
        }
        Ok(false)
    }

    fn name(&mut self) -> Parsed<String> {
        match self.next()? {
            (Tok::Ident(n), _) => Ok(n),
            (_, at) => self.err(Problem::Syntax("expected a name".to_owned()), at),
        }
    }

    /// Text up to the end (or, inside an `{if}` block, up to the `{` of its `elsif`, `else`
    /// or `endif`, which is left unread).
    fn text(&mut self, in_if: bool) -> Parsed<Vec<Node>> {
        let mut nodes = Vec::new();
        let mut text = String::new();
        loop {
            let pos = self.lx.pos;
            let rest = &self.src[pos..];
            let Some(i) = rest.find(['{', '[']) else {
                text.push_str(rest);
                self.lx.pos = self.src.len();
                if in_if {
                    return self.err(Problem::Syntax("missing {endif}".to_owned()), pos);
                }
                break;
            };
            text.push_str(&rest[..i]);
            let at = pos + i;
            if rest.as_bytes()[i] == b'[' {
                match legacy(self.src, at) {
                    Some((name, index, end)) => {
                        flush(&mut nodes, &mut text);
                        nodes.push(Node::Legacy {
                            name,
                            index,
                            raw: self.src[at..end].to_owned(),
                            loc: Loc { open: at, at },
                        });
                        self.lx.pos = end;
                    }
                    None => {
                        text.push('[');
                        self.lx.pos = at + 1;
                    }
                }
                continue;
            }
            let after = Lexer::new(self.src, at + 1);
            if in_if && after.peek().is_ok_and(|(t, _)| ends_branch(&t)) {
                self.lx.pos = at;
                break;
            }
            flush(&mut nodes, &mut text);
            let outer = std::mem::replace(&mut self.open, at);
            self.lx.pos = at + 1;
            let stmts = self.statements(true)?;
            self.open = outer;
            nodes.push(Node::Macro(stmts));
        }
        flush(&mut nodes, &mut text);
        Ok(nodes)
    }

    /// Statements up to the macro's `}` (consumed) when `to_close`, else up to an `elsif`,
    /// `else` or `endif` (left unread).
    fn statements(&mut self, to_close: bool) -> Parsed<Vec<Stmt>> {
        let mut stmts = Vec::new();
        loop {
            let (t, at) = self.peek()?;
            match t {
                Tok::Close if to_close => {
                    self.next()?;
                    return Ok(stmts);
                }
                Tok::Sym(";") => {
                    self.next()?;
                }
                ref t if !to_close && ends_branch(t) => return Ok(stmts),
                Tok::Ident(ref k) if k == "if" => {
                    self.next()?;
                    stmts.push(self.if_block()?);
                }
                Tok::End | Tok::Close => {
                    let want = if to_close {
                        "missing `}`"
                    } else {
                        "missing endif"
                    };
                    return self.err(Problem::Syntax(want.to_owned()), at);
                }
                _ => {
                    stmts.push(self.statement()?);
                    let (t, at) = self.peek()?;
                    let ends = match t {
                        Tok::Sym(";") | Tok::Close => true,
                        ref t => !to_close && ends_branch(t),
                    };
                    if !ends {
                        return self.err(Problem::Syntax("expected `;` or `}`".to_owned()), at);
                    }
                }
            }
        }
    }

    /// An `if` block, after its `if`.
    fn if_block(&mut self) -> Parsed<Stmt> {
        let at = self.peek()?.1;
        self.deeper(at, Self::if_branches)
    }

    /// The branches of an `if` block, after its `if`.
    fn if_branches(&mut self) -> Parsed<Stmt> {
        let mut branches = Vec::new();
        let mut otherwise = None;
        loop {
            let at = self.peek()?.1;
            let cond = self.cond()?;
            let loc = self.loc(at);
            let body = self.branch_body(true)?;
            branches.push((cond, loc, body));
            let (t, at) = self.next()?;
            match t {
                Tok::Ident(k) if k == "elsif" => continue,
                Tok::Ident(k) if k == "else" => {
                    otherwise = Some(self.branch_body(false)?);
                    match self.next()? {
                        (Tok::Ident(k), _) if k == "endif" => break,
                        (_, at) => {
                            return self.err(Problem::Syntax("expected endif".to_owned()), at);
                        }
                    }
                }
                Tok::Ident(k) if k == "endif" => break,
                _ => {
                    return self.err(
                        Problem::Syntax("expected elsif, else or endif".to_owned()),
                        at,
                    );
                }
            }
        }
        Ok(Stmt::If {
            branches,
            otherwise,
        })
    }

    /// A branch: `}` text `{` (leaving the keyword after that `{` unread), or statements
    /// (after `then` when `then` is due).
    fn branch_body(&mut self, then: bool) -> Parsed<Body> {
        let (t, at) = self.peek()?;
        if t == Tok::Close {
            self.next()?;
            let nodes = self.text(true)?;
            // `text` stopped at the `{` of elsif / else / endif.
            self.open = self.lx.pos;
            self.lx.pos += 1;
            return Ok(Body::Text(nodes));
        }
        if then {
            match t {
                Tok::Ident(k) if k == "then" => {
                    self.next()?;
                }
                _ => return self.err(Problem::Syntax("expected `}` or then".to_owned()), at),
            }
        }
        Ok(Body::Stmts(self.statements(false)?))
    }

    fn statement(&mut self) -> Parsed<Stmt> {
        let (t, at) = self.peek()?;
        let loc = self.loc(at);
        if let Tok::Ident(k) = &t
            && (k == "local" || k == "global")
        {
            let global = k == "global";
            self.next()?;
            let name = self.name()?;
            self.expect("=")?;
            let value = self.init()?;
            return Ok(Stmt::Define {
                global,
                name,
                value,
                loc,
            });
        }
        if let Tok::Ident(name) = t {
            // `name = …` or `name[i] = …`: try, and fall back to an expression.
            let saved = self.lx.clone();
            self.next()?;
            let index = if self.eat("[")? {
                let i = self.add()?;
                self.expect("]")?;
                Some(i)
            } else {
                None
            };
            if self.eat("=")? {
                let value = self.init()?;
                return Ok(Stmt::Assign {
                    name,
                    index,
                    value,
                    loc,
                });
            }
            self.lx = saved;
        }
        Ok(Stmt::Expr(self.cond()?, loc))
    }

    fn init(&mut self) -> Parsed<Init> {
        let (t, _) = self.peek()?;
        if t == Tok::Ident("repeat".to_owned()) {
            self.next()?;
            self.expect("(")?;
            let count = self.add()?;
            self.expect(",")?;
            let value = self.cond()?;
            self.expect(")")?;
            return Ok(Init::Repeat(count, value));
        }
        if t == Tok::Sym("(") {
            // `(a, b)` is a vector when the statement ends after the `)`.
            let saved = self.lx.clone();
            self.next()?;
            let mut items = Vec::new();
            if !self.eat(")")? {
                loop {
                    items.push(self.cond()?);
                    if self.eat(")")? {
                        break;
                    }
                    self.expect(",")?;
                }
            }
            let (t, _) = self.peek()?;
            if matches!(t, Tok::Sym(";") | Tok::Close) || ends_branch(&t) {
                return Ok(Init::List(items));
            }
            self.lx = saved;
        }
        Ok(Init::Scalar(self.cond()?))
    }

    fn cond(&mut self) -> Parsed<Expr> {
        let c = self.or()?;
        if self.eat("?")? {
            let a = self.cond()?;
            self.expect(":")?;
            let b = self.cond()?;
            return Ok(Expr::Ternary(Box::new(c), Box::new(a), Box::new(b)));
        }
        Ok(c)
    }

    /// A left-associative chain of `next` joined by the operators `ops` names.
    fn chain(
        &mut self,
        next: fn(&mut Self) -> Parsed<Expr>,
        ops: fn(&Tok) -> Option<BinOp>,
    ) -> Parsed<Expr> {
        let base = self.depth;
        let mut lhs = next(self)?;
        while let Some(op) = ops(&self.peek()?.0) {
            let (_, at) = self.next()?;
            // Each operator puts the chain so far one level further down the tree.
            if self.depth >= MAX_DEPTH {
                return self.err(
                    Problem::Syntax(format!("nested more than {MAX_DEPTH} levels deep")),
                    at,
                );
            }
            self.depth += 1;
            let rhs = next(self)?;
            lhs = Expr::Binary(op, Box::new(lhs), Box::new(rhs));
        }
        self.depth = base;
        Ok(lhs)
    }

    fn or(&mut self) -> Parsed<Expr> {
        self.chain(Self::and, |t| match t {
            Tok::Sym("||") => Some(BinOp::Or),
            Tok::Ident(k) if k == "or" => Some(BinOp::Or),
            _ => None,
        })
    }

    fn and(&mut self) -> Parsed<Expr> {
        self.chain(Self::eq, |t| match t {
            Tok::Sym("&&") => Some(BinOp::And),
            Tok::Ident(k) if k == "and" => Some(BinOp::And),
            _ => None,
        })
    }

    fn eq(&mut self) -> Parsed<Expr> {
        let mut lhs = self.rel()?;
        loop {
            let op = match self.peek()?.0 {
                Tok::Sym("==") => BinOp::Eq,
                Tok::Sym("!=" | "<>") => BinOp::Ne,
                Tok::Sym(s @ ("=~" | "!~")) => {
                    self.next()?;
                    let open = self.open;
                    let (re, _) = self.lx.regex().map_err(|(problem, at)| SyntaxError {
                        problem,
                        loc: Loc { open, at },
                    })?;
                    lhs = Expr::Regex(Box::new(lhs), re, s == "!~");
                    continue;
                }
                _ => return Ok(lhs),
            };
            self.next()?;
            let rhs = self.rel()?;
            lhs = Expr::Binary(op, Box::new(lhs), Box::new(rhs));
        }
    }

    fn rel(&mut self) -> Parsed<Expr> {
        self.chain(Self::add, |t| match t {
            Tok::Sym("<") => Some(BinOp::Lt),
            Tok::Sym(">") => Some(BinOp::Gt),
            Tok::Sym("<=") => Some(BinOp::Le),
            Tok::Sym(">=") => Some(BinOp::Ge),
            _ => None,
        })
    }

    fn add(&mut self) -> Parsed<Expr> {
        self.chain(Self::mul, |t| match t {
            Tok::Sym("+") => Some(BinOp::Add),
            Tok::Sym("-") => Some(BinOp::Sub),
            _ => None,
        })
    }

    fn mul(&mut self) -> Parsed<Expr> {
        self.chain(Self::unary, |t| match t {
            Tok::Sym("*") => Some(BinOp::Mul),
            Tok::Sym("/") => Some(BinOp::Div),
            Tok::Sym("%") => Some(BinOp::Rem),
            _ => None,
        })
    }

    fn unary(&mut self) -> Parsed<Expr> {
        let at = self.peek()?.1;
        self.deeper(at, Self::operand)
    }

    /// An operand: a literal, a variable, a call, a parenthesised expression or a prefix
    /// operator and its operand.
    fn operand(&mut self) -> Parsed<Expr> {
        let (t, at) = self.next()?;
        Ok(match t {
            Tok::Int(i) => Expr::Lit(Value::Int(i)),
            Tok::Float(f) => Expr::Lit(Value::Float(f)),
            Tok::Str(s) => Expr::Lit(Value::Str(s)),
            Tok::Sym("-") => Expr::Unary(UnOp::Neg, Box::new(self.unary()?)),
            Tok::Sym("+") => self.unary()?,
            Tok::Sym("!") => Expr::Unary(UnOp::Not, Box::new(self.unary()?)),
            Tok::Sym("(") => {
                let e = self.cond()?;
                self.expect(")")?;
                e
            }
            Tok::Ident(k) => match k.as_str() {
                "true" => Expr::Lit(Value::Bool(true)),
                "false" => Expr::Lit(Value::Bool(false)),
                "not" => Expr::Unary(UnOp::Not, Box::new(self.unary()?)),
                "min" | "max" | "int" | "round" | "digits" | "zdigits" | "one_of"
                | "interpolate_table" | "is_nil" | "empty" | "size" | "random" => {
                    self.function(&k, at)?
                }
                "if" | "elsif" | "else" | "endif" | "then" | "and" | "or" | "local" | "global"
                | "repeat" => {
                    return self.err(Problem::Syntax(format!("unexpected `{k}`")), at);
                }
                _ => {
                    let index = self.index()?;
                    Expr::Var(k, index)
                }
            },
            Tok::Close | Tok::End => {
                return self.err(Problem::Syntax("expected an expression".to_owned()), at);
            }
            Tok::Sym(s) => return self.err(Problem::Syntax(format!("unexpected `{s}`")), at),
        })
    }

    /// `[add]` after a variable's name, if present.
    fn index(&mut self) -> Parsed<Option<Box<Expr>>> {
        if self.eat("[")? {
            let i = self.add()?;
            self.expect("]")?;
            return Ok(Some(Box::new(i)));
        }
        Ok(None)
    }

    fn function(&mut self, name: &str, at: usize) -> Parsed<Expr> {
        self.expect("(")?;
        let e = match name {
            "min" | "max" => {
                let a = self.cond()?;
                self.expect(",")?;
                let b = self.cond()?;
                let f = if name == "min" { Func::Min } else { Func::Max };
                Expr::Call(f, vec![a, b])
            }
            "int" | "round" => {
                let f = if name == "int" {
                    Func::Int
                } else {
                    Func::Round
                };
                Expr::Call(f, vec![self.cond()?])
            }
            "digits" | "zdigits" => {
                let mut args = vec![self.cond()?];
                self.expect(",")?;
                args.push(self.cond()?);
                if self.eat(",")? {
                    args.push(self.cond()?);
                }
                let f = if name == "digits" {
                    Func::Digits
                } else {
                    Func::Zdigits
                };
                Expr::Call(f, args)
            }
            "is_nil" => {
                let n = self.name()?;
                Expr::IsNil(n.clone(), self.index()?)
            }
            "empty" => Expr::Empty(self.name()?),
            "size" => Expr::Size(self.name()?),
            "one_of" => self.one_of()?,
            "interpolate_table" => self.interpolate()?,
            _ => return self.err(Problem::Random, at),
        };
        self.expect(")")?;
        Ok(e)
    }

    fn one_of(&mut self) -> Parsed<Expr> {
        let subject = self.unary()?;
        let mut patterns = Vec::new();
        while self.eat(",")? {
            if self.peek()?.0 == Tok::Sym(")") {
                break;
            }
            let rest = &self.src[self.lx.pos..];
            if rest.trim_start().starts_with('/') {
                let open = self.open;
                let (re, _) = self.lx.regex().map_err(|(problem, at)| SyntaxError {
                    problem,
                    loc: Loc { open, at },
                })?;
                patterns.push(Pattern::Regex(Expr::Lit(Value::Str(re))));
            } else if self.eat("~")? {
                patterns.push(Pattern::Regex(self.unary()?));
            } else {
                patterns.push(Pattern::Equal(self.unary()?));
            }
        }
        Ok(Expr::OneOf(Box::new(subject), patterns))
    }

    fn interpolate(&mut self) -> Parsed<Expr> {
        let x = self.unary()?;
        let mut table = Vec::new();
        while self.eat(",")? {
            self.expect("(")?;
            let a = self.unary()?;
            self.expect(",")?;
            let b = self.unary()?;
            self.expect(")")?;
            table.push((a, b));
        }
        Ok(Expr::Interpolate(Box::new(x), table))
    }
}

fn flush(nodes: &mut Vec<Node>, text: &mut String) {
    if !text.is_empty() {
        nodes.push(Node::Text(std::mem::take(text)));
    }
}

/// A legacy placeholder at `at` (a `[`): `[name]` or `[name[index_name]]`, with the offset
/// after it; `None` when the brackets hold anything else (they are then text).
fn legacy(src: &str, at: usize) -> Option<(String, Option<String>, usize)> {
    let ident = |from: usize| -> Option<(String, usize)> {
        let rest = src.get(from..)?;
        let first = rest.chars().next()?;
        if !(first.is_ascii_alphabetic() || first == '_') {
            return None;
        }
        let len = rest
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        Some((rest[..len].to_owned(), from + len))
    };
    let (name, end) = ident(at + 1)?;
    match src.as_bytes().get(end)? {
        b']' => Some((name, None, end + 1)),
        b'[' => {
            let (index, iend) = ident(end + 1)?;
            (src.get(iend..iend + 2)? == "]]").then_some((name, Some(index), iend + 2))
        }
        _ => None,
    }
}
