//! ASCII STL.
//!
//! The reader works line by line, with keywords in any case and lines ended by LF, CRLF or a lone
//! CR (old Mac files):
//!
//! ```text
//! solid [name]
//!   facet [normal nx ny nz]      <- rest of the line ignored: normals are recomputed
//!     outer loop
//!       vertex x y z             <- exactly three finite numbers
//!       vertex x y z
//!       vertex x y z
//!     endloop                    <- rest of the line ignored
//!   endfacet                     <- rest of the line ignored
//! endsolid [name]                <- rest of the line ignored
//! ```
//!
//! Several `solid` blocks may follow each other; their triangles are concatenated and the name
//! is the first block's. A word starting with `#` starts a comment that runs to the end of the
//! line. After an `endsolid`, lines that are not STL keywords are ignored (some exporters append
//! junk), while `solid` opens another block.

use std::io::{self, Write};

use crate::binary::WRITE_CHUNK;
use crate::{Encoding, Stl, StlError, excerpt};

const BOM: &[u8] = b"\xEF\xBB\xBF";

/// A position in the input that hands out the words of one line at a time. Lines are numbered
/// from 1 and end at LF, CRLF or a lone CR; a word starting with `#` ends the line's words.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Number of the current line (0 before the first).
    line: usize,
    /// Where the current line starts.
    line_start: usize,
}

/// Blanks that separate words on a line (ASCII whitespace other than line ends).
fn is_blank(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\x0c')
}

fn is_eol(b: u8) -> bool {
    b == b'\n' || b == b'\r'
}

impl<'a> Cursor<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        let bytes = bytes.strip_prefix(BOM).unwrap_or(bytes);
        Cursor {
            bytes,
            pos: 0,
            line: 0,
            line_start: 0,
        }
    }

    /// Enters the next line; false at the end of the input.
    fn start_line(&mut self) -> bool {
        if self.pos >= self.bytes.len() {
            return false;
        }
        self.line += 1;
        self.line_start = self.pos;
        true
    }

    /// The next word of the current line, or `None` at the end of the line or at a comment.
    fn word(&mut self) -> Option<&'a [u8]> {
        let rest = self.bytes.get(self.pos..)?;
        let start = rest
            .iter()
            .position(|&b| !is_blank(b))
            .unwrap_or(rest.len());
        let rest = rest.get(start..)?;
        self.pos += start;
        match rest.first() {
            None => return None,
            Some(&b) if is_eol(b) || b == b'#' => return None,
            Some(_) => {}
        }
        let len = rest
            .iter()
            .position(|&b| is_blank(b) || is_eol(b))
            .unwrap_or(rest.len());
        self.pos += len;
        rest.get(..len)
    }

    /// Where the current line's text ends (before its line break).
    fn eol(&self) -> usize {
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        self.pos + rest.iter().position(|&b| is_eol(b)).unwrap_or(rest.len())
    }

    /// Skips the rest of the current line and its line break.
    fn finish_line(&mut self) {
        self.pos = self.eol();
        match self.bytes.get(self.pos..).unwrap_or_default() {
            [b'\r', b'\n', ..] => self.pos += 2,
            [_, ..] => self.pos += 1,
            [] => {}
        }
    }

    /// The current line's text, for error messages.
    fn line_text(&self) -> &'a [u8] {
        self.bytes
            .get(self.line_start..self.eol())
            .unwrap_or_default()
    }
}

/// Case-insensitive keyword match. Keywords are lower-case ASCII letters, and for those
/// `b | 0x20 == k` holds exactly when `b` is `k` or its upper-case form.
#[inline(always)]
fn is(word: &[u8], keyword: &str) -> bool {
    word.len() == keyword.len()
        && word
            .iter()
            .zip(keyword.as_bytes())
            .all(|(&b, &k)| b | 0x20 == k)
}

/// True when the first word, after an optional byte-order mark, whitespace and `#` comment lines,
/// is `solid` (any case).
pub(crate) fn starts_with_solid(bytes: &[u8]) -> bool {
    let mut cursor = Cursor::new(bytes);
    while cursor.start_line() {
        if let Some(word) = cursor.word() {
            return is(word, "solid");
        }
        cursor.finish_line();
    }
    false
}

/// Where the parser is in the grammar.
#[derive(Clone, Copy)]
enum State {
    /// Before the first `solid` or after an `endsolid`.
    Outside { seen_solid: bool },
    /// Inside `solid`, between facets.
    Solid,
    /// After `facet`, before `outer loop`.
    Facet,
    /// Inside `outer loop`, with this many vertices read.
    Loop(usize),
    /// After `endloop`, before `endfacet`.
    EndLoop,
}

/// Reads an ASCII STL.
pub(crate) fn read(bytes: &[u8]) -> Result<Stl, StlError> {
    let mut cur = Cursor::new(bytes);
    let mut name: Option<String> = None;
    // About 250 bytes per facet in typical files; bounded by the input size.
    let mut triangles = Vec::with_capacity(bytes.len() / 256);
    let mut triangle = [[0.0_f32; 3]; 3];
    let mut state = State::Outside { seen_solid: false };
    let (mut solid_line, mut facet_line) = (0, 0);

    while cur.start_line() {
        let Some(keyword) = cur.word() else {
            cur.finish_line(); // blank or comment-only line
            continue;
        };
        state = match state {
            State::Loop(n) if n < 3 => {
                if !is(keyword, "vertex") {
                    return Err(unexpected(&cur, "`vertex`", cur.line_text()));
                }
                let Some(vertex) = triangle.get_mut(n) else {
                    return Err(unexpected(&cur, "`endloop`", cur.line_text()));
                };
                *vertex = coordinates(&mut cur)?;
                State::Loop(n + 1)
            }
            State::Loop(_) => {
                if is(keyword, "endloop") {
                    State::EndLoop
                } else {
                    return Err(unexpected(&cur, "`endloop`", cur.line_text()));
                }
            }
            State::EndLoop => {
                if is(keyword, "endfacet") {
                    triangles.push(triangle);
                    State::Solid
                } else {
                    return Err(unexpected(&cur, "`endfacet`", cur.line_text()));
                }
            }
            State::Solid => {
                if is(keyword, "facet") {
                    facet_line = cur.line;
                    State::Facet
                } else if is(keyword, "endsolid") {
                    State::Outside { seen_solid: true }
                } else {
                    return Err(unexpected(&cur, "`facet` or `endsolid`", cur.line_text()));
                }
            }
            State::Facet => {
                if is(keyword, "outer") && cur.word().is_some_and(|w| is(w, "loop")) {
                    State::Loop(0)
                } else {
                    return Err(unexpected(&cur, "`outer loop`", cur.line_text()));
                }
            }
            State::Outside { seen_solid } => {
                if is(keyword, "solid") {
                    if !seen_solid {
                        name = solid_name(&mut cur);
                    }
                    solid_line = cur.line;
                    State::Solid
                } else if !seen_solid {
                    return Err(unexpected(&cur, "`solid`", cur.line_text()));
                } else if is_keyword(keyword) {
                    return Err(unexpected(
                        &cur,
                        "`solid` or the end of the file",
                        cur.line_text(),
                    ));
                } else {
                    state // trailing junk after `endsolid`
                }
            }
        };
        cur.finish_line();
    }

    let end_line = cur.line;
    match state {
        State::Outside { .. } => Ok(Stl {
            name,
            encoding: Encoding::Ascii,
            triangles,
        }),
        State::Solid => Err(StlError::MissingEndsolid {
            line: solid_line,
            end_line,
        }),
        _ => Err(StlError::UnterminatedFacet {
            line: facet_line,
            end_line,
        }),
    }
}

/// The error for a line that is not what the grammar `expected` at this point; `text` is what
/// was found.
fn unexpected(cur: &Cursor, expected: &'static str, text: &[u8]) -> StlError {
    StlError::Unexpected {
        line: cur.line,
        expected,
        found: excerpt(text.trim_ascii()),
    }
}

/// The three coordinates of a `vertex` line, which must end after them.
#[inline]
fn coordinates(cur: &mut Cursor) -> Result<[f32; 3], StlError> {
    let mut vertex = [0.0_f32; 3];
    for (i, coord) in vertex.iter_mut().enumerate() {
        let line = cur.line;
        let word = cur
            .word()
            .ok_or(StlError::MissingCoordinates { line, found: i })?;
        *coord = parse_coord(word).ok_or_else(|| StlError::BadCoordinate {
            line,
            token: excerpt(word),
        })?;
    }
    if let Some(extra) = cur.word() {
        return Err(unexpected(
            cur,
            "the end of the line after 3 coordinates",
            extra,
        ));
    }
    Ok(vertex)
}

/// The name after `solid`: the rest of the line's words without control characters, joined by
/// single spaces; `None` when empty.
fn solid_name(cur: &mut Cursor) -> Option<String> {
    let mut text = String::new();
    while let Some(word) = cur.word() {
        let word = String::from_utf8_lossy(word);
        let word = word.chars().filter(|c| !c.is_control());
        if !text.is_empty() && word.clone().next().is_some() {
            text.push(' ');
        }
        text.extend(word);
    }
    (!text.is_empty()).then_some(text)
}

/// True for the keywords that may only appear inside a `solid` block.
fn is_keyword(word: &[u8]) -> bool {
    [
        "facet", "outer", "vertex", "endloop", "endfacet", "endsolid",
    ]
    .iter()
    .any(|k| is(word, k))
}

/// A finite `f32` from a word such as `1`, `-2.5`, `.5`, `1.96850394E+00`; `None` otherwise.
///
/// `fast-float2` gives correctly rounded results like `str::parse` and made whole-file ASCII
/// parsing about 30 % faster in `examples/stl_throughput.rs`. It accepts `inf` and `nan`, which
/// the finiteness check then rejects.
fn parse_coord(word: &[u8]) -> Option<f32> {
    let value: f32 = fast_float2::parse(word).ok()?;
    value.is_finite().then_some(value)
}

/// Writes an ASCII STL.
///
/// `name` follows `solid` and `endsolid`, with line breaks and other control characters replaced
/// by spaces and surrounding whitespace trimmed. (Readers that accept comments, this one
/// included, drop a name's words from one starting with `#` on.) Normals come from
/// [`crate::facet_normal`]. Numbers are written in the shortest form that reads back to the same `f32` bit for bit
/// (plain decimals such as `20` or `-0.125` between 1e-5 and 1e9, exponent form such as `1e-30`
/// outside); non-finite coordinates are written as `NaN` / `inf`, which readers (this one
/// included) reject. Data goes to `w` in chunks of 64 KiB.
///
/// # Errors
///
/// Errors from `w`.
pub fn write_ascii<W: Write>(w: &mut W, name: &str, triangles: &[[[f32; 3]; 3]]) -> io::Result<()> {
    let name: String = name
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    let name = name.trim();
    let space = if name.is_empty() { "" } else { " " };
    let mut buf = Vec::with_capacity(WRITE_CHUNK + 512);
    writeln!(buf, "solid{space}{name}")?;
    for t in triangles {
        buf.extend_from_slice(b"  facet normal");
        push_xyz(&mut buf, crate::facet_normal(t))?;
        buf.extend_from_slice(b"    outer loop\n");
        for v in t {
            buf.extend_from_slice(b"      vertex");
            push_xyz(&mut buf, *v)?;
        }
        buf.extend_from_slice(b"    endloop\n  endfacet\n");
        if buf.len() >= WRITE_CHUNK {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    writeln!(buf, "endsolid{space}{name}")?;
    w.write_all(&buf)
}

/// Appends ` x y z\n`, each number in its shortest round-trip form.
fn push_xyz(buf: &mut Vec<u8>, v: [f32; 3]) -> io::Result<()> {
    for c in v {
        // Display and LowerExp without a precision both print the shortest digits that parse back
        // to the same f32; the exponent form only keeps tiny and huge values short.
        let a = c.abs();
        if a == 0.0 || (1e-5..1e9).contains(&a) {
            write!(buf, " {c}")?;
        } else {
            write!(buf, " {c:e}")?;
        }
    }
    buf.push(b'\n');
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read;

    const CUBE_FACET: [[f32; 3]; 3] = [[20.0, 20.0, 0.0], [20.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
    const FACET_TEXT: &str = "  facet normal 0 0 -1\n    outer loop\n      vertex 20 20 0\n      \
                              vertex 2.000000e+01 0 0\n      vertex 0.0 0.0 0.0\n    endloop\n  endfacet\n";

    fn two_facets(eol: &str) -> String {
        format!("solid cube\n{FACET_TEXT}{FACET_TEXT}endsolid cube\n").replace('\n', eol)
    }

    #[test]
    fn reads_lf_crlf_and_cr_line_endings() {
        for eol in ["\n", "\r\n", "\r"] {
            let stl = read(two_facets(eol).as_bytes()).expect("valid ASCII");
            assert_eq!(stl.encoding, Encoding::Ascii);
            assert_eq!(stl.name.as_deref(), Some("cube"));
            assert_eq!(stl.triangles, vec![CUBE_FACET; 2], "eol {eol:?}");
        }
    }

    #[test]
    fn line_numbers_count_crlf_once_and_lone_cr() {
        for eol in ["\n", "\r\n", "\r"] {
            let text = two_facets(eol).replace("vertex 0.0 0.0 0.0", "vertex 0.0 oops 0.0");
            let err = read(text.as_bytes()).expect_err("bad vertex");
            assert!(
                matches!(&err, StlError::BadCoordinate { line: 6, token } if token == "oops"),
                "{err:?}"
            );
        }
    }

    #[test]
    fn reads_upper_case_keywords() {
        let text = two_facets("\n")
            .to_uppercase()
            .replace("SOLID CUBE", "SOLID  Untitled1");
        let stl = read(text.as_bytes()).expect("upper case");
        assert_eq!(stl.name.as_deref(), Some("Untitled1"));
        assert_eq!(stl.triangles, vec![CUBE_FACET; 2]);
    }

    #[test]
    fn junk_normals_are_ignored() {
        for normal in [
            "+inf -inf weirdvalue",
            "nan nan nan",
            "",
            "1 2",
            "0 0 1 extra",
        ] {
            let text = two_facets("\n").replacen("normal 0 0 -1", &format!("normal {normal}"), 1);
            let stl = read(text.as_bytes()).expect("junk normal ignored");
            assert_eq!(stl.triangles, vec![CUBE_FACET; 2], "normal {normal:?}");
        }
        let bare = two_facets("\n").replacen("facet normal 0 0 -1", "facet", 1);
        assert_eq!(
            read(bare.as_bytes())
                .expect("facet without normal")
                .triangles
                .len(),
            2
        );
    }

    #[test]
    fn junk_vertex_coordinates_are_errors_naming_the_line() {
        for junk in [
            "weirdvalue",
            "nan",
            "+inf",
            "-infinity",
            "1e99",
            "1,5",
            "0x10",
        ] {
            let text =
                two_facets("\n").replacen("vertex 20 20 0", &format!("vertex 20 {junk} 0"), 1);
            let err = read(text.as_bytes()).expect_err("junk vertex");
            assert!(
                matches!(&err, StlError::BadCoordinate { line: 4, token } if token == junk),
                "{junk}: {err:?}"
            );
            assert!(err.to_string().starts_with("line 4: "), "{err}");
        }
        let text = two_facets("\n").replacen("vertex 20 20 0", "vertex 20 20", 1);
        let err = read(text.as_bytes()).expect_err("two coordinates");
        assert!(
            matches!(err, StlError::MissingCoordinates { line: 4, found: 2 }),
            "{err:?}"
        );
        let text = two_facets("\n").replacen("vertex 20 20 0", "vertex 20 20 0 1", 1);
        let err = read(text.as_bytes()).expect_err("four coordinates");
        assert!(
            matches!(&err, StlError::Unexpected { line: 4, found, .. } if found == "1"),
            "{err:?}"
        );
    }

    #[test]
    fn text_after_end_keywords_is_ignored() {
        let text = two_facets("\n")
            .replacen("endloop", "endloop foo", 1)
            .replacen("endfacet", "endfacet bar ", 1)
            .replace(
                "endsolid cube",
                "endsolid some blah blah\n\ntrailing junk line\n\0\0",
            );
        let stl = read(text.as_bytes()).expect("trailing text");
        assert_eq!(stl.triangles, vec![CUBE_FACET; 2]);
    }

    #[test]
    fn multiple_solids_are_concatenated() {
        let other = FACET_TEXT.replace("vertex 20 20 0", "vertex -1 -2 -3");
        let text = format!(
            "solid first\n{FACET_TEXT}endsolid first\nSolid second\n{other}{other}EndSolid\n"
        );
        let stl = read(text.as_bytes()).expect("two solids");
        assert_eq!(stl.name.as_deref(), Some("first"));
        let mut moved = CUBE_FACET;
        moved[0] = [-1.0, -2.0, -3.0];
        assert_eq!(stl.triangles, vec![CUBE_FACET, moved, moved]);
    }

    #[test]
    fn comments_blank_lines_bom_and_tabs_are_accepted() {
        let text = format!(
            "\u{feff}# made by hand\n\n solid  Mesh \x07 Name # comment\n\t# c\n{}endsolid # c\n",
            FACET_TEXT
                .replace("outer loop", "outer\tloop # c")
                .replace('\n', " # c\n")
        );
        let stl = read(text.as_bytes()).expect("comments");
        assert_eq!(stl.name.as_deref(), Some("Mesh Name"));
        assert_eq!(stl.triangles, vec![CUBE_FACET]);
    }

    #[test]
    fn empty_solid_has_no_name_and_no_triangles() {
        let err = read(b"solid\nendsolid\n").expect_err("no triangles");
        assert!(matches!(
            err,
            StlError::NoTriangles {
                encoding: Encoding::Ascii
            }
        ));
        let stl = super::read(b"solid\nendsolid\n").expect("parses");
        assert_eq!(stl.name, None);
    }

    #[test]
    fn truncated_facet_names_its_line() {
        let full = two_facets("\n");
        let cut = &full[..full.find("endloop").expect("has endloop")];
        let err = read(cut.as_bytes()).expect_err("truncated");
        assert!(
            matches!(
                err,
                StlError::UnterminatedFacet {
                    line: 2,
                    end_line: 7
                }
            ),
            "{err:?}"
        );
        assert!(err.to_string().contains("line 2"), "{err}");
        let cut = &full[..full.rfind("endfacet").expect("has endfacet")];
        let err = read(cut.as_bytes()).expect_err("truncated");
        assert!(
            matches!(
                err,
                StlError::UnterminatedFacet {
                    line: 9,
                    end_line: 15
                }
            ),
            "{err:?}"
        );
    }

    #[test]
    fn missing_endsolid_is_an_error() {
        let full = two_facets("\n");
        let cut = &full[..full.find("endsolid").expect("has endsolid")];
        let err = read(cut.as_bytes()).expect_err("no endsolid");
        assert!(
            matches!(
                err,
                StlError::MissingEndsolid {
                    line: 1,
                    end_line: 15
                }
            ),
            "{err:?}"
        );
    }

    #[test]
    fn grammar_errors_name_line_and_expectation() {
        let cases: [(&str, &str, usize, &str); 6] = [
            ("outer loop", "inner loop", 3, "`outer loop`"),
            ("      vertex 2.000000e+01 0 0\n", "", 6, "`vertex`"),
            (
                "    endloop\n  endfacet\n  facet",
                "    endloop\n  facet",
                8,
                "`endfacet`",
            ),
            (
                "vertex 0.0 0.0 0.0\n",
                "vertex 0.0 0.0 0.0\n vertex 1 1 1\n",
                7,
                "`endloop`",
            ),
            ("solid cube", "facet normal 0 0 1", 1, "`solid`"),
            (
                "endsolid cube\n",
                "endsolid cube\nendfacet\n",
                17,
                "`solid` or the end of the file",
            ),
        ];
        for (from, to, line, expected) in cases {
            let text = two_facets("\n").replacen(from, to, 1);
            let err = super::read(text.as_bytes()).expect_err(from);
            match err {
                StlError::Unexpected {
                    line: l,
                    expected: e,
                    ..
                } => {
                    assert_eq!((l, e), (line, expected), "{from:?} -> {to:?}");
                }
                other => panic!("{from:?}: {other:?}"),
            }
        }
        let text = two_facets("\n").replacen("  facet", "  facet\n  endsolid", 1);
        let err = read(text.as_bytes()).expect_err("endsolid inside facet");
        assert!(
            matches!(
                err,
                StlError::Unexpected {
                    line: 3,
                    expected: "`outer loop`",
                    ..
                }
            ),
            "{err:?}"
        );
    }

    #[test]
    fn writer_output_is_standard_and_reads_back() {
        let t = [[0.0, 0.0, 0.0], [20.0, 0.0, 0.0], [0.0, 0.5, -1e-30]];
        let mut out = Vec::new();
        write_ascii(&mut out, "my\npart", &[t]).expect("write to Vec");
        let text = String::from_utf8(out).expect("UTF-8");
        assert_eq!(
            text,
            "solid my part\n  facet normal 0 2e-30 1\n    outer loop\n      vertex 0 0 0\n      \
             vertex 20 0 0\n      vertex 0 0.5 -1e-30\n    endloop\n  endfacet\nendsolid my part\n"
        );
        let stl = read(text.as_bytes()).expect("reads back");
        assert_eq!(stl.name.as_deref(), Some("my part"));
        assert_eq!(stl.triangles, vec![t]);
        let mut empty_name = Vec::new();
        write_ascii(&mut empty_name, "  ", &[t]).expect("write to Vec");
        assert!(empty_name.starts_with(b"solid\n") && empty_name.ends_with(b"\nendsolid\n"));
        assert_eq!(read(&empty_name).expect("reads back").name, None);
    }

    #[test]
    fn round_trip_is_bit_exact_over_random_bit_patterns() {
        let mut triangles =
            crate::tests::random_finite_triangles(0x2545_f491_4f6c_dd1d_u64, 20_000);
        // Edge values: signed zeros, the extremes, subnormals, values near the format switch.
        let edges = [
            0.0,
            -0.0,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            1e-45,
            -1e-45,
            f32::EPSILON,
            1e-5,
            9.999999e-6,
            1e9,
            999_999_940.0,
            16_777_217.0,
            0.1,
            1.0 / 3.0,
        ];
        for chunk in edges.chunks_exact(8) {
            triangles.push([
                [chunk[0], chunk[1], chunk[2]],
                [chunk[3], chunk[4], chunk[5]],
                [chunk[6], chunk[7], 1.0],
            ]);
        }
        let mut out = Vec::new();
        write_ascii(&mut out, "random", &triangles).expect("write to Vec");
        let stl = read(&out).expect("reads back");
        assert_eq!(stl.encoding, Encoding::Ascii);
        let bits = |ts: &[[[f32; 3]; 3]]| {
            ts.iter()
                .flatten()
                .flatten()
                .map(|c| c.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&stl.triangles), bits(&triangles));
    }

    #[test]
    fn solid_sniffing() {
        assert!(starts_with_solid(b"solid"));
        assert!(starts_with_solid(
            b"\xEF\xBB\xBF  \r\n# comment\r\n\tSOLID x"
        ));
        assert!(!starts_with_solid(b"solidworks"));
        assert!(!starts_with_solid(b"# only a comment\n"));
        assert!(!starts_with_solid(b"facet normal"));
        assert!(!starts_with_solid(b""));
    }
}
