//! The tokens of a macro: what lies between `{` and `}` cut into names, numbers, strings,
//! regular expressions and operators.
//!
//! Place in the pipeline: the first step of reading a template; the parser
//! ([`super::parser`]) pulls tokens from a [`Lexer`] positioned in the template text, switching
//! back to plain text where an `{if …}` block's text begins. Whitespace, line breaks included,
//! separates tokens and is otherwise skipped.

use super::Problem;

/// One token.
#[derive(Debug, Clone, PartialEq)]
pub enum Tok {
    /// A name or keyword: `[A-Za-z_][A-Za-z0-9_]*`.
    Ident(String),
    /// An integer literal.
    Int(i64),
    /// A literal with a decimal point or an exponent.
    Float(f64),
    /// A `"…"` literal with its escapes (`\n`, `\r`, `\"`, `\\`) undone.
    Str(String),
    /// An operator or punctuation: `( ) [ ] , ; ? : ~ + - * / % ! = == != <> < > <= >= =~ !~
    /// && ||`.
    Sym(&'static str),
    /// The `}` that closes a macro.
    Close,
    /// The end of the template.
    End,
}

/// Operators and punctuation, longest first so that `==` is not read as `=`.
const SYMBOLS: [&str; 27] = [
    "==", "!=", "<>", "<=", ">=", "=~", "!~", "&&", "||", "(", ")", "[", "]", ",", ";", "?", ":",
    "~", "+", "-", "*", "/", "%", "!", "=", "<", ">",
];

/// A cursor over the template text that reads tokens.
#[derive(Debug, Clone)]
pub struct Lexer<'a> {
    src: &'a str,
    /// Byte offset of the next character to read.
    pub pos: usize,
}

impl<'a> Lexer<'a> {
    /// A lexer reading `src` from byte offset `pos`.
    pub fn new(src: &'a str, pos: usize) -> Self {
        Self { src, pos }
    }

    fn skip_space(&mut self) {
        let rest = &self.src[self.pos..];
        self.pos += rest.len() - rest.trim_start().len();
    }

    /// The next token without consuming it, and where it starts.
    pub fn peek(&self) -> Result<(Tok, usize), (Problem, usize)> {
        self.clone().next_token()
    }

    /// Reads the next token; returns it and the byte offset where it starts. An error names
    /// the problem and where it is.
    pub fn next_token(&mut self) -> Result<(Tok, usize), (Problem, usize)> {
        self.skip_space();
        let start = self.pos;
        let rest = &self.src[start..];
        let Some(c) = rest.chars().next() else {
            return Ok((Tok::End, start));
        };
        if c == '}' {
            self.pos += 1;
            return Ok((Tok::Close, start));
        }
        if c.is_ascii_alphabetic() || c == '_' {
            let len = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            self.pos += len;
            return Ok((Tok::Ident(rest[..len].to_owned()), start));
        }
        if c.is_ascii_digit() || (c == '.' && rest[1..].starts_with(|d: char| d.is_ascii_digit())) {
            return self.number(start);
        }
        if c == '"' {
            return self.string(start);
        }
        for sym in SYMBOLS {
            if rest.starts_with(sym) {
                self.pos += sym.len();
                return Ok((Tok::Sym(sym), start));
            }
        }
        Err((
            Problem::Syntax(format!("unexpected character `{c}`")),
            start,
        ))
    }

    /// A number: an integer, or a float when it has a decimal point or an exponent.
    fn number(&mut self, start: usize) -> Result<(Tok, usize), (Problem, usize)> {
        let bytes = self.src.as_bytes();
        let mut end = start;
        let digits = |mut i: usize| {
            while i < bytes.len() && bytes[i].is_ascii_digit() {
                i += 1;
            }
            i
        };
        end = digits(end);
        let mut float = false;
        if end < bytes.len() && bytes[end] == b'.' {
            float = true;
            end = digits(end + 1);
        }
        if end < bytes.len() && (bytes[end] == b'e' || bytes[end] == b'E') {
            let mut e = end + 1;
            if e < bytes.len() && (bytes[e] == b'+' || bytes[e] == b'-') {
                e += 1;
            }
            let after = digits(e);
            if after > e {
                float = true;
                end = after;
            }
        }
        let text = &self.src[start..end];
        self.pos = end;
        let bad = || (Problem::Syntax(format!("bad number `{text}`")), start);
        if float {
            text.parse()
                .map(|f| (Tok::Float(f), start))
                .map_err(|_| bad())
        } else {
            text.parse()
                .map(|i| (Tok::Int(i), start))
                .map_err(|_| bad())
        }
    }

    /// A `"…"` string literal.
    fn string(&mut self, start: usize) -> Result<(Tok, usize), (Problem, usize)> {
        let mut out = String::new();
        let mut chars = self.src[start + 1..].char_indices();
        while let Some((i, c)) = chars.next() {
            match c {
                '"' => {
                    self.pos = start + 1 + i + 1;
                    return Ok((Tok::Str(out), start));
                }
                '\\' => match chars.next() {
                    Some((_, 'n')) => out.push('\n'),
                    Some((_, 'r')) => out.push('\r'),
                    Some((_, e @ ('"' | '\\'))) => out.push(e),
                    _ => {
                        return Err((
                            Problem::Syntax("invalid escape sequence in a string".to_owned()),
                            start + 1 + i,
                        ));
                    }
                },
                c => out.push(c),
            }
        }
        Err((Problem::Syntax("unterminated string".to_owned()), start))
    }

    /// A `/…/` regular expression (after `=~`, `!~`, or in `one_of`): its pattern, with `\/`
    /// read as `/` and every other escape kept for the regex engine.
    pub fn regex(&mut self) -> Result<(String, usize), (Problem, usize)> {
        self.skip_space();
        let start = self.pos;
        if !self.src[start..].starts_with('/') {
            return Err((
                Problem::Syntax("expected a regular expression `/…/`".to_owned()),
                start,
            ));
        }
        let mut out = String::new();
        let mut chars = self.src[start + 1..].char_indices();
        while let Some((i, c)) = chars.next() {
            match c {
                '/' => {
                    self.pos = start + 1 + i + 1;
                    return Ok((out, start));
                }
                '\\' => match chars.next() {
                    Some((_, '/')) => out.push('/'),
                    Some((_, e)) => {
                        out.push('\\');
                        out.push(e);
                    }
                    None => break,
                },
                c => out.push(c),
            }
        }
        Err((
            Problem::Syntax("unterminated regular expression".to_owned()),
            start,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(s: &str) -> Vec<Tok> {
        let mut lx = Lexer::new(s, 0);
        let mut out = Vec::new();
        while let Ok((t, _)) = lx.next_token() {
            if t == Tok::End {
                break;
            }
            out.push(t);
        }
        out
    }

    #[test]
    fn tokens_of_an_expression() {
        assert_eq!(
            tokens("a[0]>=1.5e2 != \"x\\\"y\" }"),
            vec![
                Tok::Ident("a".into()),
                Tok::Sym("["),
                Tok::Int(0),
                Tok::Sym("]"),
                Tok::Sym(">="),
                Tok::Float(150.0),
                Tok::Sym("!="),
                Tok::Str("x\"y".into()),
                Tok::Close,
            ]
        );
        let mut lx = Lexer::new(" /.*PET\\/G.*/ x", 0);
        assert_eq!(lx.regex().map(|r| r.0), Ok(".*PET/G.*".to_owned()));
        assert!(Lexer::new("\"open", 0).next_token().is_err());
        assert!(Lexer::new("@", 0).next_token().is_err());
    }
}
