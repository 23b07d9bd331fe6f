//! KiCad's s-expressions: the tree every KiCad file is written in, read strictly and bounded.
//!
//! First step of the reader: bytes → [`Tree`]. A list is `(keyword item…)`; an item is a bare
//! atom (`1.27`, `thru_hole`, `yes`), a quoted string (`"R1"`, with `\"`, `\\` and `\n`
//! escapes) or a list. Every list starts with a bare keyword, as in every KiCad file. Each list
//! and atom keeps its 1-based line and column, so later steps name where a value is wrong, with
//! the path of keywords that leads to it (`kicad_pcb/footprint/pad/at`).

use crate::error::KicadError;

/// The deepest nesting of lists accepted. KiCad nests a dozen levels; a deeper file is not
/// KiCad's.
pub const MAX_DEPTH: usize = 128;

/// The largest input accepted, bytes (512 MiB): far beyond the largest boards.
pub const MAX_BYTES: usize = 512 << 20;

/// One item of a list.
#[derive(Debug, Clone, PartialEq)]
enum Item {
    /// A bare or quoted atom.
    Atom {
        text: String,
        quoted: bool,
        line: u32,
        column: u32,
    },
    /// A nested list, by index in [`Tree::lists`].
    List(usize),
}

#[derive(Debug, Clone, PartialEq)]
struct ListData {
    keyword: String,
    parent: Option<usize>,
    line: u32,
    column: u32,
    items: Vec<Item>,
}

/// A parsed file: its lists in an arena, the first one the root.
#[derive(Debug, Clone, PartialEq)]
pub struct Tree {
    lists: Vec<ListData>,
}

/// A list of a [`Tree`]: its keyword, atoms and sub-lists.
#[derive(Debug, Clone, Copy)]
pub struct Node<'a> {
    tree: &'a Tree,
    id: usize,
}

/// An atom with where it stands.
#[derive(Debug, Clone, Copy)]
pub struct Atom<'a> {
    /// The text (unescaped when quoted).
    pub text: &'a str,
    /// Whether it was written in quotes.
    pub quoted: bool,
    /// 1-based line.
    pub line: u32,
    /// 1-based column, in characters.
    pub column: u32,
}

impl Tree {
    /// The root list.
    pub fn root(&self) -> Node<'_> {
        Node { tree: self, id: 0 }
    }
}

/// Parses `bytes` into a tree.
///
/// # Errors
/// [`KicadError::TooLarge`], [`KicadError::NotUtf8`], [`KicadError::Syntax`],
/// [`KicadError::TooDeep`] or [`KicadError::UnexpectedEof`].
pub fn parse(bytes: &[u8]) -> Result<Tree, KicadError> {
    if bytes.len() > MAX_BYTES {
        return Err(KicadError::TooLarge {
            bytes: bytes.len(),
            limit: MAX_BYTES,
        });
    }
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let (line, column) = line_column(bytes, e.valid_up_to());
        KicadError::NotUtf8 { line, column }
    })?;
    Parser {
        chars: text.chars().peekable(),
        line: 1,
        column: 1,
        lists: Vec::new(),
        stack: Vec::new(),
    }
    .run()
}

fn line_column(bytes: &[u8], offset: usize) -> (u32, u32) {
    let before = &bytes[..offset.min(bytes.len())];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    let column = String::from_utf8_lossy(&before[start..]).chars().count() + 1;
    (to_u32(line), to_u32(column))
}

fn to_u32(v: usize) -> u32 {
    u32::try_from(v).unwrap_or(u32::MAX)
}

struct Parser<'s> {
    chars: std::iter::Peekable<std::str::Chars<'s>>,
    line: u32,
    column: u32,
    lists: Vec<ListData>,
    stack: Vec<usize>,
}

impl Parser<'_> {
    fn bump(&mut self) -> Option<char> {
        let c = self.chars.next()?;
        if c == '\n' {
            self.line = self.line.saturating_add(1);
            self.column = 1;
        } else {
            self.column = self.column.saturating_add(1);
        }
        Some(c)
    }

    fn syntax(&self, message: &'static str) -> KicadError {
        KicadError::Syntax {
            line: self.line,
            column: self.column,
            message,
        }
    }

    fn run(mut self) -> Result<Tree, KicadError> {
        while let Some(&c) = self.chars.peek() {
            let (line, column) = (self.line, self.column);
            match c {
                c if c.is_whitespace() => {
                    self.bump();
                }
                '(' => self.open(line, column)?,
                ')' => {
                    self.bump();
                    if self.stack.pop().is_none() {
                        return Err(KicadError::Syntax {
                            line,
                            column,
                            message: "unmatched `)`",
                        });
                    }
                }
                _ => {
                    let Some(&top) = self.stack.last() else {
                        return Err(self.syntax("text outside the file's top list"));
                    };
                    let (text, quoted) = if c == '"' {
                        (self.quoted()?, true)
                    } else {
                        (self.bare(), false)
                    };
                    self.lists[top].items.push(Item::Atom {
                        text,
                        quoted,
                        line,
                        column,
                    });
                }
            }
        }
        if let Some(&open) = self.stack.last() {
            let l = &self.lists[open];
            return Err(KicadError::UnexpectedEof {
                keyword: l.keyword.clone(),
                line: l.line,
                column: l.column,
            });
        }
        if self.lists.is_empty() {
            return Err(KicadError::NotKicad {
                found: String::new(),
            });
        }
        Ok(Tree { lists: self.lists })
    }

    fn open(&mut self, line: u32, column: u32) -> Result<(), KicadError> {
        self.bump();
        if self.stack.len() >= MAX_DEPTH {
            return Err(KicadError::TooDeep {
                line,
                column,
                limit: MAX_DEPTH,
            });
        }
        if self.stack.is_empty() && !self.lists.is_empty() {
            return Err(KicadError::Syntax {
                line,
                column,
                message: "a second top-level list after the file's end",
            });
        }
        let keyword = match self.chars.peek() {
            Some(&c) if c != '"' && c != '(' && c != ')' && !c.is_whitespace() => self.bare(),
            _ => return Err(self.syntax("a list must start with a keyword")),
        };
        let id = self.lists.len();
        let parent = self.stack.last().copied();
        if let Some(p) = parent {
            self.lists[p].items.push(Item::List(id));
        }
        self.lists.push(ListData {
            keyword,
            parent,
            line,
            column,
            items: Vec::new(),
        });
        self.stack.push(id);
        Ok(())
    }

    fn bare(&mut self) -> String {
        let mut s = String::new();
        while let Some(&c) = self.chars.peek() {
            if c.is_whitespace() || c == '(' || c == ')' || c == '"' {
                break;
            }
            s.push(c);
            self.bump();
        }
        s
    }

    fn quoted(&mut self) -> Result<String, KicadError> {
        let (line, column) = (self.line, self.column);
        self.bump();
        let mut s = String::new();
        loop {
            match self.bump() {
                None => {
                    return Err(KicadError::Syntax {
                        line,
                        column,
                        message: "string not closed before the end of the file",
                    });
                }
                Some('"') => return Ok(s),
                Some('\\') => match self.bump() {
                    Some('n') => s.push('\n'),
                    Some('t') => s.push('\t'),
                    Some('r') => s.push('\r'),
                    Some(c) => s.push(c),
                    None => {
                        return Err(KicadError::Syntax {
                            line,
                            column,
                            message: "string not closed before the end of the file",
                        });
                    }
                },
                Some(c) => s.push(c),
            }
        }
    }
}

impl<'a> Node<'a> {
    fn data(&self) -> &'a ListData {
        &self.tree.lists[self.id]
    }

    /// The list's keyword (`footprint`, `pad`, `at`).
    pub fn keyword(&self) -> &'a str {
        &self.data().keyword
    }

    /// 1-based line of the list's `(`.
    pub fn line(&self) -> u32 {
        self.data().line
    }

    /// 1-based column of the list's `(`.
    pub fn column(&self) -> u32 {
        self.data().column
    }

    /// The keywords from the root to this list, joined by `/` (`kicad_pcb/footprint/pad`).
    pub fn path(&self) -> String {
        let mut names = vec![self.keyword()];
        let mut at = self.data().parent;
        while let Some(p) = at {
            names.push(&self.tree.lists[p].keyword);
            at = self.tree.lists[p].parent;
        }
        names.reverse();
        names.join("/")
    }

    /// The sub-lists in order.
    pub fn lists(&self) -> impl Iterator<Item = Node<'a>> + 'a {
        let tree = self.tree;
        self.data().items.iter().filter_map(move |i| match i {
            Item::List(id) => Some(Node { tree, id: *id }),
            Item::Atom { .. } => None,
        })
    }

    /// The sub-lists whose keyword is `keyword`.
    pub fn all(&self, keyword: &'a str) -> impl Iterator<Item = Node<'a>> + 'a {
        self.lists().filter(move |n| n.keyword() == keyword)
    }

    /// The first sub-list whose keyword is `keyword`.
    pub fn get(&self, keyword: &str) -> Option<Node<'a>> {
        self.lists().find(|n| n.keyword() == keyword)
    }

    /// The first sub-list named `keyword`, or [`KicadError::Missing`].
    pub fn req(&self, keyword: &'static str) -> Result<Node<'a>, KicadError> {
        self.get(keyword)
            .ok_or_else(|| self.missing_owned(format!("({keyword} …)")))
    }

    /// The atoms after the keyword, in order.
    pub fn atoms(&self) -> impl Iterator<Item = Atom<'a>> + 'a {
        self.data().items.iter().filter_map(|i| match i {
            Item::Atom {
                text,
                quoted,
                line,
                column,
            } => Some(Atom {
                text,
                quoted: *quoted,
                line: *line,
                column: *column,
            }),
            Item::List(_) => None,
        })
    }

    /// The `i`-th atom's text (0 is the first after the keyword).
    pub fn atom(&self, i: usize) -> Option<&'a str> {
        self.atoms().nth(i).map(|a| a.text)
    }

    /// The `i`-th atom's text, or [`KicadError::Missing`] naming `what`.
    pub fn req_atom(&self, i: usize, what: &'static str) -> Result<&'a str, KicadError> {
        self.atom(i).ok_or_else(|| self.missing(what))
    }

    /// The `i`-th atom as a finite number, or an error naming `what`.
    pub fn num(&self, i: usize, what: &'static str) -> Result<f64, KicadError> {
        let Some(a) = self.atoms().nth(i) else {
            return Err(self.missing(what));
        };
        match a.text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(KicadError::Invalid {
                path: self.path(),
                line: a.line,
                column: a.column,
                value: a.text.to_owned(),
                expected: what,
            }),
        }
    }

    /// The `i`-th atom as a number, `None` when the list has fewer atoms.
    pub fn opt_num(&self, i: usize, what: &'static str) -> Result<Option<f64>, KicadError> {
        if self.atoms().nth(i).is_none() {
            return Ok(None);
        }
        self.num(i, what).map(Some)
    }

    /// A yes/no flag written either as a bare atom (`hide`, KiCad 6-7) or as a sub-list
    /// (`(hide yes)`, KiCad 8+).
    pub fn flag(&self, name: &str) -> bool {
        self.atoms().any(|a| !a.quoted && a.text == name)
            || self
                .get(name)
                .is_some_and(|n| n.atom(0).is_none_or(|v| v == "yes"))
    }

    /// The value of `(property "NAME" "VALUE" …)`, the first one named `name`.
    pub fn property(&self, name: &str) -> Option<&'a str> {
        self.all("property")
            .find(|p| p.atom(0) == Some(name))
            .and_then(|p| p.atom(1))
    }

    /// `(at x y [angle])` of this list: x, y and the angle (0 when absent).
    pub fn at(&self) -> Result<(f64, f64, f64), KicadError> {
        let at = self.req("at")?;
        Ok((
            at.num(0, "x, mm")?,
            at.num(1, "y, mm")?,
            at.opt_num(2, "an angle in degrees")?.unwrap_or(0.0),
        ))
    }

    /// `(KEYWORD x y)` of this list as a point.
    pub fn point(&self, keyword: &'static str) -> Result<(f64, f64), KicadError> {
        let n = self.req(keyword)?;
        Ok((n.num(0, "x, mm")?, n.num(1, "y, mm")?))
    }

    /// The error for something this list lacks.
    pub fn missing(&self, what: &'static str) -> KicadError {
        self.missing_owned(what.to_owned())
    }

    fn missing_owned(&self, what: String) -> KicadError {
        KicadError::Missing {
            path: self.path(),
            line: self.line(),
            column: self.column(),
            what,
        }
    }

    /// The error for a value of this list that is not what it should be.
    pub fn invalid(&self, value: &str, expected: &'static str) -> KicadError {
        KicadError::Invalid {
            path: self.path(),
            line: self.line(),
            column: self.column(),
            value: value.to_owned(),
            expected,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_atoms_strings_and_positions() {
        let t = parse(b"(kicad_pcb (version 20211014)\n  (net 1 \"a \\\"b\\\"\") hide)")
            .expect("test data");
        let r = t.root();
        assert_eq!(r.keyword(), "kicad_pcb");
        let net = r.get("net").expect("test data");
        assert_eq!((net.line(), net.column()), (2, 3));
        assert_eq!(net.atom(1), Some("a \"b\""));
        assert_eq!(net.num(0, "n").expect("test data"), 1.0);
        assert_eq!(net.path(), "kicad_pcb/net");
        assert!(r.flag("hide"));
        assert!(!net.flag("hide"));
    }

    #[test]
    fn bad_input_is_refused_with_its_place() {
        let e = parse(b"(a (b 1)").expect_err("must be refused");
        assert!(
            matches!(
                e,
                KicadError::UnexpectedEof {
                    line: 1,
                    column: 1,
                    ..
                }
            ),
            "{e}"
        );
        assert!(matches!(
            parse(b"(a))"),
            Err(KicadError::Syntax {
                line: 1,
                column: 4,
                ..
            })
        ));
        assert!(matches!(parse(b"( \"x\")"), Err(KicadError::Syntax { .. })));
        assert!(matches!(parse(b"(a \"x)"), Err(KicadError::Syntax { .. })));
        assert!(matches!(parse(b"(a)(b)"), Err(KicadError::Syntax { .. })));
        assert!(matches!(parse(b""), Err(KicadError::NotKicad { .. })));
        assert!(matches!(
            parse(b"(a \xff)"),
            Err(KicadError::NotUtf8 { line: 1, column: 4 })
        ));
        let deep = "(a ".repeat(MAX_DEPTH + 1);
        assert!(matches!(
            parse(deep.as_bytes()),
            Err(KicadError::TooDeep { .. })
        ));
        let t = parse(b"(a (at 1 x))").expect("test data");
        let e = t.root().at().expect_err("must be refused");
        assert_eq!(e.to_string(), "a/at, line 1, column 10: \"x\" is not y, mm");
    }
}
