//! One line of G-code: its exact bytes and the tokens found in them.

use std::ops::Range;

use crate::number::read_number;

/// How a line ends in the file. Writing `text` followed by the ending gives back the exact bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum LineEnding {
    /// `\n` (Unix).
    Lf,
    /// `\r\n` (Windows).
    CrLf,
    /// A lone `\r` (classic Mac OS), or a `\r` not followed by `\n`.
    Cr,
    /// No terminator: the last line of a file that does not end with a newline.
    None,
}

impl LineEnding {
    /// The terminator's bytes.
    pub fn as_bytes(self) -> &'static [u8] {
        match self {
            LineEnding::Lf => b"\n",
            LineEnding::CrLf => b"\r\n",
            LineEnding::Cr => b"\r",
            LineEnding::None => b"",
        }
    }
}

/// A letter and its number, such as `G1`, `X10.5` or `e.2`.
#[derive(Debug, Clone, PartialEq)]
pub struct Word {
    /// The letter, upper-cased ASCII (`b'X'` for both `X10` and `x10`).
    pub letter: u8,
    /// The number as written, read without an exponent (see [`crate`] docs).
    pub value: f64,
    /// Byte range of the letter and number within [`Line::text`].
    pub span: Range<usize>,
}

/// One line of a G-code file: its exact bytes and what the tokenizer found in them.
///
/// Every byte of [`text`](Line::text) belongs to exactly one of: whitespace, a [`Word`], the
/// `N` line number, the `*` checksum, a comment, the [`string_arg`](Line::string_arg) of a
/// message command, or an [`unparsed`](Line::unparsed) span. Nothing is dropped, so
/// [`Line::to_bytes`] is always the original.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// 1-based line number in the file.
    pub number: usize,
    /// The line's content without its terminator, exact bytes (not necessarily UTF-8).
    pub text: Vec<u8>,
    /// How the line ended.
    pub ending: LineEnding,
    /// The words in order, without the `N` line number (see [`line_number_word`](Line::line_number_word)).
    pub words: Vec<Word>,
    /// The line's main comment, verbatim with its delimiters: the `;` comment when there is one
    /// (it runs to the end of the line), otherwise the first `( ... )` comment.
    /// An unclosed `(` comment runs to the end of the line.
    pub comment: Option<Range<usize>>,
    /// Any further `( ... )` comments, in order (rare: CNC dialects put several on one line).
    pub other_comments: Vec<Range<usize>>,
    /// The value after `*` (a checksum as sent by a host to RepRap-style firmware), if 0..=255.
    pub checksum: Option<u8>,
    /// The value of an `N123` line number word, if the line has one.
    pub line_number_word: Option<u64>,
    /// For message and file-name commands (`M23`, `M28`, `M30`... see [`STRING_ARG_COMMANDS`]):
    /// the free text after the command, up to a `;` comment or `*` checksum, trailing blanks
    /// excluded. No words are read from it.
    pub string_arg: Option<Range<usize>>,
    /// Byte ranges that are not words, comments, checksums or whitespace: a letter without a
    /// number, stray symbols, binary garbage. Kept verbatim, never an error.
    pub unparsed: Vec<Range<usize>>,
}

/// `M` commands whose argument is free text (Marlin): `M23` select SD file, `M28` start SD write,
/// `M30` delete SD file, `M32` select and start, `M117` display message, `M118` serial print,
/// `M928` start SD logging.
pub const STRING_ARG_COMMANDS: [u32; 7] = [23, 28, 30, 32, 117, 118, 928];

impl Line {
    /// Tokenizes one line of text (without terminator) to insert into a [`crate::Gcode`]: for
    /// example `Line::new(format!("G1 X{}", fmt_xyz(x)), LineEnding::Lf)`. Its
    /// [`number`](Line::number) is 0 until [`crate::Gcode::renumber`].
    ///
    /// A `\n` or `\r` inside `text` would break the round trip of the file it goes into; they
    /// are kept as they are, so callers must not pass them.
    ///
    /// ```
    /// use conduit_gcode::{Line, LineEnding, fmt_xyz};
    /// let line = Line::new(format!("G1 X{} ; added", fmt_xyz(12.0)), LineEnding::Lf);
    /// assert_eq!(line.get(b'X'), Some(12.0));
    /// assert_eq!(line.to_bytes(), b"G1 X12 ; added\n");
    /// ```
    pub fn new(text: impl Into<Vec<u8>>, ending: LineEnding) -> Line {
        let text = text.into();
        let mut line = tokenize(&text, 0, ending);
        line.number = 0;
        line
    }

    /// The first `G`, `M` or `T` word: the command, such as `(b'G', 1.0)`.
    pub fn command(&self) -> Option<(u8, f64)> {
        self.words
            .iter()
            .find(|w| matches!(w.letter, b'G' | b'M' | b'T'))
            .map(|w| (w.letter, w.value))
    }

    /// True when the [`command`](Line::command) is `letter` with the integer number `number`
    /// (`line.is_command(b'G', 1)` for `G1` and `G01`, not for `G1.1`).
    pub fn is_command(&self, letter: u8, number: u32) -> bool {
        self.command() == Some((letter.to_ascii_uppercase(), f64::from(number)))
    }

    /// The value of the first word with this letter (either case), such as `get(b'X')`.
    pub fn get(&self, letter: u8) -> Option<f64> {
        let letter = letter.to_ascii_uppercase();
        self.words
            .iter()
            .find(|w| w.letter == letter)
            .map(|w| w.value)
    }

    /// The main [`comment`](Line::comment)'s text without its delimiters (`;`, or `(` and `)`)
    /// and with surrounding whitespace trimmed: `"LAYER:3"` for `;LAYER:3`, `"TYPE:Perimeter"`
    /// for `; TYPE:Perimeter `. `None` without a comment or when the comment is not UTF-8.
    pub fn comment_text(&self) -> Option<&str> {
        let range = self.comment.clone()?;
        let raw = self.text.get(range)?;
        let inner = match raw.first() {
            Some(b'(') => {
                let body = &raw[1..];
                body.strip_suffix(b")").unwrap_or(body)
            }
            _ => raw.get(1..).unwrap_or_default(),
        };
        std::str::from_utf8(inner).ok().map(str::trim)
    }

    /// The text of [`string_arg`](Line::string_arg) (for example an `M117` message), if UTF-8.
    pub fn string_arg_text(&self) -> Option<&str> {
        let range = self.string_arg.clone()?;
        std::str::from_utf8(self.text.get(range)?).ok()
    }

    /// Whether the `*` checksum matches: the XOR of every byte before the `*`, as RepRap-style
    /// firmware checks it. `None` when the line has no checksum.
    pub fn checksum_matches(&self) -> Option<bool> {
        let expected = self.checksum?;
        // The checksum's `*` comes before any comment (a comment may hold `*` too).
        let code_end = self
            .comment
            .iter()
            .chain(&self.other_comments)
            .map(|r| r.start)
            .min()
            .unwrap_or(self.text.len());
        let star = memchr::memrchr(b'*', &self.text[..code_end])?;
        let computed = self.text[..star].iter().fold(0u8, |acc, b| acc ^ b);
        Some(computed == expected)
    }

    /// The name of a word-like extended command that starts the line, as used by Klipper macros
    /// and RepRapFirmware meta commands: `EXCLUDE_OBJECT_START NAME=part` gives
    /// `EXCLUDE_OBJECT_START`, `SET_PRESSURE_ADVANCE ADVANCE=0.04` gives `SET_PRESSURE_ADVANCE`.
    ///
    /// It is the first token (letters, digits, `_`, starting with a letter whose next character
    /// is a letter or `_`, so never a G-code word such as `G1`). Such lines are kept verbatim as
    /// [`unparsed`](Line::unparsed) spans; this only names them.
    pub fn extended_command(&self) -> Option<&str> {
        let start = self.text.iter().position(|b| !is_blank(*b))?;
        let rest = &self.text[start..];
        let len = rest
            .iter()
            .position(|b| !(b.is_ascii_alphanumeric() || *b == b'_'))
            .unwrap_or(rest.len());
        let name = &rest[..len];
        match name {
            [first, second, ..]
                if first.is_ascii_alphabetic()
                    && (second.is_ascii_alphabetic() || *second == b'_') =>
            {
                std::str::from_utf8(name).ok()
            }
            _ => None,
        }
    }

    /// True when the line has no words, comment or other content (only whitespace or nothing).
    pub fn is_blank(&self) -> bool {
        self.text.iter().all(|b| is_blank(*b))
    }

    /// The exact bytes of the line including its terminator.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.text.len() + 2);
        out.extend_from_slice(&self.text);
        out.extend_from_slice(self.ending.as_bytes());
        out
    }
}

const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

fn is_blank(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\x0b' | b'\x0c')
}

/// Splits one line's bytes into tokens. Never fails: anything unexpected is kept as unparsed.
pub(crate) fn tokenize(text: &[u8], number: usize, ending: LineEnding) -> Line {
    // Most lines are either a command with a few words or a comment: size the word list once
    // instead of growing it 0 -> 4 -> 8 (a measurable share of parse time).
    let first = text.iter().position(|b| !is_blank(*b));
    let words = match first.map(|i| text[i]) {
        Some(b) if b.is_ascii_alphabetic() => Vec::with_capacity((text.len() / 4).clamp(2, 8)),
        _ => Vec::new(),
    };
    let mut line = Line {
        number,
        text: text.to_vec(),
        ending,
        words,
        comment: None,
        other_comments: Vec::new(),
        checksum: None,
        line_number_word: None,
        string_arg: None,
        unparsed: Vec::new(),
    };
    let t = text;
    let n = t.len();
    // A UTF-8 byte-order mark at the start of the file is not G-code; it stays in `text`.
    let mut i = if number == 1 && t.starts_with(UTF8_BOM) {
        UTF8_BOM.len()
    } else {
        0
    };
    while i < n {
        let b = t[i];
        match b {
            b' ' | b'\t' | b'\x0b' | b'\x0c' => i += 1,
            b';' => {
                if let Some(paren) = line.comment.replace(i..n) {
                    line.other_comments.insert(0, paren);
                }
                break;
            }
            b'(' => {
                let end = memchr::memchr(b')', &t[i + 1..]).map_or(n, |p| i + 1 + p + 1);
                if line.comment.is_none() {
                    line.comment = Some(i..end);
                } else {
                    line.other_comments.push(i..end);
                }
                i = end;
            }
            b'*' => i = read_checksum(&mut line, t, i),
            b'A'..=b'Z' | b'a'..=b'z' => {
                let letter = b.to_ascii_uppercase();
                if letter == b'N' {
                    i = read_line_number(&mut line, t, i);
                    continue;
                }
                match read_number(t, i + 1) {
                    Some((value, end)) => {
                        line.words.push(Word {
                            letter,
                            value,
                            span: i..end,
                        });
                        i = end;
                        if letter == b'M'
                            && line.words.len() == 1
                            && STRING_ARG_COMMANDS.iter().any(|&c| f64::from(c) == value)
                        {
                            i = read_string_arg(&mut line, t, i);
                        }
                    }
                    None => i = push_unparsed(&mut line.unparsed, t, i),
                }
            }
            _ => i = push_unparsed(&mut line.unparsed, t, i),
        }
    }
    line
}

/// Reads the checksum `*digits` at `i` (the first one of the line, 0..=255, ending at a
/// separator), or keeps the token as unparsed; returns where the next token starts.
fn read_checksum(line: &mut Line, t: &[u8], i: usize) -> usize {
    let digits_end = skip_digits(t, i + 1);
    let value = std::str::from_utf8(&t[i + 1..digits_end])
        .ok()
        .and_then(|s| s.parse::<u8>().ok());
    match value {
        Some(v) if line.checksum.is_none() && at_token_end(t, digits_end) => {
            line.checksum = Some(v);
            digits_end
        }
        _ => push_unparsed(&mut line.unparsed, t, i),
    }
}

/// Reads the line number `Ndigits` at `i` (the first one of the line, ending at a separator),
/// or keeps the token as unparsed; returns where the next token starts.
fn read_line_number(line: &mut Line, t: &[u8], i: usize) -> usize {
    let digits_end = skip_digits(t, i + 1);
    let value = std::str::from_utf8(&t[i + 1..digits_end])
        .ok()
        .and_then(|s| s.parse::<u64>().ok());
    match value {
        Some(v) if line.line_number_word.is_none() && at_token_end(t, digits_end) => {
            line.line_number_word = Some(v);
            digits_end
        }
        _ => push_unparsed(&mut line.unparsed, t, i),
    }
}

/// True when a token ending at `i` is followed by a separator (or the end of the line), so that
/// `*12abc` or `N10x` are not half-read.
fn at_token_end(t: &[u8], i: usize) -> bool {
    match t.get(i) {
        None => true,
        Some(&b) => is_blank(b) || b == b';' || b == b'(' || b.is_ascii_alphabetic() || b == b'*',
    }
}

fn skip_digits(t: &[u8], mut i: usize) -> usize {
    while t.get(i).is_some_and(u8::is_ascii_digit) {
        i += 1;
    }
    i
}

/// Records an unparsed span starting at `start` and running to the next blank, `;` or `(`
/// (merged with the previous span when they touch). Returns the index after it.
fn push_unparsed(unparsed: &mut Vec<Range<usize>>, t: &[u8], start: usize) -> usize {
    let mut end = start + 1;
    while let Some(&b) = t.get(end) {
        if is_blank(b) || b == b';' || b == b'(' {
            break;
        }
        end += 1;
    }
    match unparsed.last_mut() {
        Some(last) if last.end == start => last.end = end,
        _ => unparsed.push(start..end),
    }
    end
}

/// Reads the free-text argument of a message command starting at `i`; returns where to go on.
fn read_string_arg(line: &mut Line, t: &[u8], mut i: usize) -> usize {
    while t.get(i).copied().is_some_and(is_blank) {
        i += 1;
    }
    let limit = memchr::memchr(b';', &t[i..]).map_or(t.len(), |p| i + p);
    let mut end = limit;
    // A trailing `*NN` checksum (digits then blanks only) is not part of the text.
    if let Some(star) = memchr::memrchr(b'*', &t[i..limit]).map(|p| i + p) {
        let digits_end = skip_digits(t, star + 1);
        if digits_end > star + 1 && t[digits_end..limit].iter().all(|&b| is_blank(b)) {
            end = star;
        }
    }
    while end > i && is_blank(t[end - 1]) {
        end -= 1;
    }
    if end > i {
        line.string_arg = Some(i..end);
    }
    end.max(i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tok(s: &str) -> Line {
        tokenize(s.as_bytes(), 1, LineEnding::Lf)
    }

    fn span<'a>(line: &'a Line, r: &Range<usize>) -> &'a str {
        std::str::from_utf8(&line.text[r.clone()]).expect("utf-8 test input")
    }

    #[test]
    fn words_and_values() {
        let l = tok("G1 X10.5 Y-3 E.2 F1800");
        let got: Vec<(u8, f64)> = l.words.iter().map(|w| (w.letter, w.value)).collect();
        assert_eq!(
            got,
            vec![
                (b'G', 1.0),
                (b'X', 10.5),
                (b'Y', -3.0),
                (b'E', 0.2),
                (b'F', 1800.0)
            ]
        );
        assert_eq!(span(&l, &l.words[1].span), "X10.5");
        assert_eq!(span(&l, &l.words[3].span), "E.2");
        assert_eq!(l.command(), Some((b'G', 1.0)));
        assert!(l.is_command(b'g', 1));
        assert_eq!(l.get(b'x'), Some(10.5));
        assert_eq!(l.get(b'Z'), None);
        assert!(l.unparsed.is_empty() && l.comment.is_none());
    }

    #[test]
    fn lowercase_and_compact() {
        let l = tok("g1x1.5y2e-0.5");
        let got: Vec<(u8, f64)> = l.words.iter().map(|w| (w.letter, w.value)).collect();
        assert_eq!(
            got,
            vec![(b'G', 1.0), (b'X', 1.5), (b'Y', 2.0), (b'E', -0.5)]
        );
    }

    #[test]
    fn comments() {
        let l = tok("G1 X1 ; move it ");
        assert_eq!(span(&l, l.comment.as_ref().expect("comment")), "; move it ");
        assert_eq!(l.comment_text(), Some("move it"));
        let l = tok("G0 (fast) X2 (second) ; last");
        assert_eq!(l.get(b'X'), Some(2.0));
        assert_eq!(l.comment_text(), Some("last"));
        assert_eq!(l.other_comments.len(), 2);
        assert_eq!(span(&l, &l.other_comments[0]), "(fast)");
        let l = tok("(unclosed comment X5");
        assert_eq!(l.comment_text(), Some("unclosed comment X5"));
        assert!(l.words.is_empty());
        let l = tok("G20 ;(Units: Inches)");
        assert_eq!(l.comment_text(), Some("(Units: Inches)"));
        let l = tok(";LAYER:3");
        assert_eq!(l.comment_text(), Some("LAYER:3"));
    }

    #[test]
    fn line_numbers_and_checksums() {
        let l = tok("N123 G1 X5*97 ; c");
        assert_eq!(l.line_number_word, Some(123));
        assert_eq!(l.checksum, Some(97));
        assert_eq!(l.words.len(), 2);
        assert_eq!(l.comment_text(), Some("c"));
        // Checksum of "N1 G28" is 'N'^'1'^' '^'G'^'2'^'8'.
        let cs = b"N1 G28".iter().fold(0u8, |a, b| a ^ b);
        let l = tok(&format!("N1 G28*{cs}"));
        assert_eq!(l.checksum_matches(), Some(true));
        let l = tok(&format!("N1 G28*{}", cs ^ 1));
        assert_eq!(l.checksum_matches(), Some(false));
        let l = tok(&format!("N1 G28*{cs} ; a*b"));
        assert_eq!(l.checksum_matches(), Some(true));
        let l = tok("G1 X1*999");
        assert_eq!(l.checksum, None);
        assert_eq!(span(&l, &l.unparsed[0]), "*999");
        let l = tok("N-5 G1");
        assert_eq!(l.line_number_word, None);
        assert_eq!(l.unparsed.len(), 1);
    }

    #[test]
    fn string_arguments() {
        let l = tok("M117 Hello X10 world ; note");
        assert_eq!(l.words.len(), 1);
        assert_eq!(l.string_arg_text(), Some("Hello X10 world"));
        assert_eq!(l.comment_text(), Some("note"));
        let l = tok("N5 M23 file.gco*42");
        assert_eq!(l.string_arg_text(), Some("file.gco"));
        assert_eq!(l.checksum, Some(42));
        let l = tok("M117");
        assert_eq!(l.string_arg, None);
    }

    #[test]
    fn extended_commands_and_bom() {
        let l = tok("  EXCLUDE_OBJECT_START NAME=cube_id_0_copy_0 ; klipper");
        assert_eq!(l.extended_command(), Some("EXCLUDE_OBJECT_START"));
        assert!(l.words.is_empty());
        assert_eq!(l.comment_text(), Some("klipper"));
        assert_eq!(
            tok("SET_PRESSURE_ADVANCE ADVANCE=0.04").extended_command(),
            Some("SET_PRESSURE_ADVANCE")
        );
        assert_eq!(tok("G1 X1").extended_command(), None);
        assert_eq!(tok("M117 Hi").extended_command(), None);
        assert_eq!(tok("T0").extended_command(), None);
        assert_eq!(tok("G1X5").extended_command(), None);
        assert_eq!(tok("").extended_command(), None);
        let l = tokenize(b"\xEF\xBB\xBFG28 X0", 1, LineEnding::Lf);
        assert_eq!(l.command(), Some((b'G', 28.0)));
        assert!(l.unparsed.is_empty());
        assert_eq!(l.text, b"\xEF\xBB\xBFG28 X0");
    }

    #[test]
    fn garbage_is_kept() {
        let l = tok("G1 X Y10 %$ 12 Zq");
        assert_eq!(l.words.iter().map(|w| w.letter).collect::<Vec<_>>(), b"GY");
        let spans: Vec<&str> = l.unparsed.iter().map(|r| span(&l, r)).collect();
        assert_eq!(spans, vec!["X", "%$", "12", "Zq"]);
        let l = tokenize(b"\xff\xfeG1 \x80X1", 1, LineEnding::None);
        assert_eq!(l.unparsed.len(), 2);
        assert_eq!(l.comment_text(), None);
    }
}
