//! Splitting a file into lines, and the whole-file checks (binary G-code, NUL bytes).

use std::io::{self, Write};

use crate::line::{Line, LineEnding, tokenize};

/// The magic bytes at the start of a Prusa binary G-code (`.bgcode`) file.
pub const BGCODE_MAGIC: &[u8; 4] = b"GCDE";

/// Why a file could not be read as text G-code.
///
/// Text that is not valid G-code is never an error: [`parse`] keeps such bytes as
/// [`Line::unparsed`] spans.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GcodeError {
    /// The file is Prusa binary G-code (`.bgcode`), which starts with the bytes `GCDE`.
    ///
    /// # How to fix
    /// Turn off binary G-code output in the slicer that wrote the file and export again. In
    /// PrusaSlicer it is the printer setting "Supports binary G-code" (Printer Settings > General >
    /// Firmware); when conduit runs as a post-processing script, binary output must be off.
    #[error(
        "this is binary G-code (.bgcode, starts with \"GCDE\"), which conduit cannot read or edit; \
         turn off binary G-code output in the slicer (PrusaSlicer: Printer Settings > General > \
         Firmware > \"Supports binary G-code\") and export again"
    )]
    BinaryGcode,
    /// The file holds a NUL byte, so it is not a text file (a binary format, a UTF-16 text file,
    /// or a damaged download).
    ///
    /// # How to fix
    /// Check that the file is G-code saved as plain ASCII or UTF-8 text.
    #[error("not a text G-code file: NUL byte at byte offset {offset} (line {line})")]
    NotText {
        /// Byte offset of the first NUL byte.
        offset: usize,
        /// 1-based line of that byte.
        line: usize,
    },
}

/// A parsed G-code file: every line, in order, with its exact bytes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Gcode {
    /// The lines in file order. An empty file has none; a file ending with a newline has no
    /// empty last line (the last line's [`ending`](Line::ending) records the newline).
    pub lines: Vec<Line>,
}

impl Gcode {
    /// The exact bytes the file was parsed from (when the lines have not been edited).
    pub fn to_bytes(&self) -> Vec<u8> {
        let len = self.lines.iter().map(|l| l.text.len() + 2).sum();
        let mut out = Vec::with_capacity(len);
        for line in &self.lines {
            out.extend_from_slice(&line.text);
            out.extend_from_slice(line.ending.as_bytes());
        }
        out
    }

    /// The most common line terminator of the file (`Lf` for a file without any), to use for
    /// inserted lines so that a CRLF file stays CRLF.
    pub fn line_ending(&self) -> LineEnding {
        let mut counts = [0usize; 3];
        for line in &self.lines {
            match line.ending {
                LineEnding::Lf => counts[0] += 1,
                LineEnding::CrLf => counts[1] += 1,
                LineEnding::Cr => counts[2] += 1,
                LineEnding::None => {}
            }
        }
        if counts[1] > counts[0] && counts[1] >= counts[2] {
            LineEnding::CrLf
        } else if counts[2] > counts[0] && counts[2] > counts[1] {
            LineEnding::Cr
        } else {
            LineEnding::Lf
        }
    }

    /// Sets every line's [`number`](Line::number) to its 1-based position, after lines were
    /// inserted or removed. (`N` words in the text are not touched.)
    pub fn renumber(&mut self) {
        for (i, line) in self.lines.iter_mut().enumerate() {
            line.number = i + 1;
        }
    }

    /// Writes the same bytes as [`to_bytes`](Gcode::to_bytes) to `w`.
    pub fn write_to<W: Write>(&self, mut w: W) -> io::Result<()> {
        for line in &self.lines {
            w.write_all(&line.text)?;
            w.write_all(line.ending.as_bytes())?;
        }
        Ok(())
    }
}

/// True when `bytes` start with the Prusa binary G-code magic `GCDE`.
pub fn is_binary_gcode(bytes: &[u8]) -> bool {
    bytes.starts_with(BGCODE_MAGIC)
}

/// Parses text G-code. Any text is accepted, and [`Gcode::to_bytes`] gives back exactly `bytes`.
///
/// Lines end at `\n`, `\r\n` or a lone `\r`. Errors only for files that are not text:
/// [`GcodeError::BinaryGcode`] for Prusa `.bgcode`, [`GcodeError::NotText`] for a NUL byte.
///
/// ```
/// let g = conduit_gcode::parse(b"G1 X10.5 Y-3 E.2 F1800 ; go\r\nM104 S210")?;
/// assert_eq!(g.lines.len(), 2);
/// assert_eq!(g.lines[0].get(b'E'), Some(0.2));
/// assert_eq!(g.lines[0].comment_text(), Some("go"));
/// assert_eq!(g.to_bytes(), b"G1 X10.5 Y-3 E.2 F1800 ; go\r\nM104 S210");
/// # Ok::<(), conduit_gcode::GcodeError>(())
/// ```
pub fn parse(bytes: &[u8]) -> Result<Gcode, GcodeError> {
    if is_binary_gcode(bytes) {
        return Err(GcodeError::BinaryGcode);
    }
    if let Some(offset) = memchr::memchr(0, bytes) {
        let line = 1 + memchr::memchr_iter(b'\n', &bytes[..offset]).count();
        return Err(GcodeError::NotText { offset, line });
    }
    // Slicer output averages 20-30 bytes a line; reserving avoids most regrowth.
    let mut lines = Vec::with_capacity(bytes.len() / 24 + 1);
    let mut start = 0;
    let mut number = 1;
    while start < bytes.len() {
        let rest = &bytes[start..];
        match memchr::memchr2(b'\n', b'\r', rest) {
            Some(p) => {
                let (ending, skip) = match (rest[p], rest.get(p + 1)) {
                    (b'\n', _) => (LineEnding::Lf, 1),
                    (_, Some(b'\n')) => (LineEnding::CrLf, 2),
                    _ => (LineEnding::Cr, 1),
                };
                lines.push(tokenize(&rest[..p], number, ending));
                start += p + skip;
            }
            None => {
                lines.push(tokenize(rest, number, LineEnding::None));
                break;
            }
        }
        number += 1;
    }
    Ok(Gcode { lines })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip(bytes: &[u8]) -> Gcode {
        let g = parse(bytes).expect("text G-code parses");
        assert_eq!(
            g.to_bytes(),
            bytes,
            "round trip of {:?}",
            String::from_utf8_lossy(bytes)
        );
        let mut written = Vec::new();
        g.write_to(&mut written).expect("writing to a Vec");
        assert_eq!(written, bytes);
        g
    }

    #[test]
    fn round_trips_line_endings() {
        let g = round_trip(b"G28\nG1 X1\n");
        assert_eq!(g.lines.len(), 2);
        assert_eq!(g.lines[1].ending, LineEnding::Lf);
        let g = round_trip(b"G28\r\nG1 X1\r\n");
        assert_eq!(g.lines[0].ending, LineEnding::CrLf);
        assert_eq!(g.lines[0].text, b"G28");
        let g = round_trip(b"G28\r\nG1 X1\nG1 Y2\rG1 Z3\r\r\n\n\nM84");
        let endings: Vec<LineEnding> = g.lines.iter().map(|l| l.ending).collect();
        use LineEnding::*;
        assert_eq!(endings, vec![CrLf, Lf, Cr, Cr, CrLf, Lf, Lf, None]);
        assert_eq!(
            g.lines.iter().map(|l| l.number).collect::<Vec<_>>(),
            (1..=8).collect::<Vec<_>>()
        );
        assert_eq!(g.lines[3].get(b'Z'), Some(3.0));
        let g = round_trip(b"");
        assert!(g.lines.is_empty());
        let g = round_trip(b"\n");
        assert_eq!(g.lines.len(), 1);
        assert!(g.lines[0].is_blank());
        round_trip(b"\r");
        round_trip(b"\r\n\r\n");
        round_trip(b"G1 X3.14");
    }

    #[test]
    fn round_trips_everything_else() {
        let file = concat!(
            "; generated by Nobody 1.0\r\n",
            "(program start)\n",
            "N1 G28*18 ; home\n",
            "n2 g1 x10 y-2.50 f3000*99\n",
            "  \tG1   X.5  ;  spaced   \r\n",
            "G0 (a) X1 (b) Y2 (unclosed\n",
            "M117 Printing... 50%\n",
            "%\n",
            "\u{e9}t\u{e9} ;caf\u{e9}\n",
            "*** $$$ @@@ 1e30 --5 ..3\n",
            "G1 X1e30 Y-1e30 E999999999999999999999\n",
            "\x7f\x01\x1b[0m\n",
        );
        let g = round_trip(file.as_bytes());
        assert_eq!(g.lines[2].line_number_word, Some(1));
        assert_eq!(g.lines[2].checksum, Some(18));
        assert_eq!(g.lines[3].line_number_word, Some(2));
        assert_eq!(g.lines[3].get(b'Y'), Some(-2.5));
        assert_eq!(g.lines[4].get(b'X'), Some(0.5));
        assert_eq!(g.lines[4].comment_text(), Some("spaced"));
        assert_eq!(g.lines[8].comment_text(), Some("caf\u{e9}"));
        // No exponents (as in Marlin): X1e30 is X1 then E30.
        assert_eq!(g.lines[10].get(b'X'), Some(1.0));
        assert_eq!(g.lines[10].get(b'E'), Some(30.0));
        // Invalid UTF-8 and other garbage bytes survive.
        round_trip(b"G1 X\xff\xfe1 ;\xc3\x28\n\x80\x81\x82\r\n");
    }

    #[test]
    fn random_text_round_trips() {
        // Deterministic pseudo-random lines over an alphabet rich in G-code's special bytes.
        let alphabet = b"GMTNXYZEFIJKRSgxyz0123456789.-+ \t;()*%\r\n\xff\x80abc_=";
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..3000 {
            let mut bytes = Vec::new();
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            for _ in 0..(seed % 120) {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                bytes.push(alphabet[(seed % alphabet.len() as u64) as usize]);
            }
            let g = round_trip(&bytes);
            let _ = crate::summarize(&g);
            // Every token span lies inside its line and no two overlap.
            for line in &g.lines {
                let mut spans: Vec<std::ops::Range<usize>> =
                    line.words.iter().map(|w| w.span.clone()).collect();
                spans.extend(line.comment.clone());
                spans.extend(line.other_comments.iter().cloned());
                spans.extend(line.unparsed.iter().cloned());
                spans.extend(line.string_arg.clone());
                spans.sort_by_key(|r| r.start);
                for pair in spans.windows(2) {
                    assert!(
                        pair[0].end <= pair[1].start,
                        "{:?} in {:?}",
                        spans,
                        line.text
                    );
                }
                assert!(
                    spans
                        .iter()
                        .all(|r| r.start < r.end && r.end <= line.text.len())
                );
            }
        }
    }

    #[test]
    fn edit_insert_and_renumber() {
        let mut g = parse(b"G28\r\nG1 X1\r\nM84").expect("parses");
        assert_eq!(g.line_ending(), LineEnding::CrLf);
        let ending = g.line_ending();
        g.lines.insert(1, Line::new("G1 Z0.2 F600", ending));
        g.renumber();
        assert_eq!(g.to_bytes(), b"G28\r\nG1 Z0.2 F600\r\nG1 X1\r\nM84");
        assert_eq!(
            g.lines.iter().map(|l| l.number).collect::<Vec<_>>(),
            vec![1, 2, 3, 4]
        );
        assert_eq!(g.lines[1].get(b'Z'), Some(0.2));
        assert_eq!(parse(b"").expect("parses").line_ending(), LineEnding::Lf);
        assert_eq!(
            parse(b"a\rb\rc\n").expect("parses").line_ending(),
            LineEnding::Cr
        );
    }

    #[test]
    fn rejects_binary() {
        let mut bgcode = b"GCDE".to_vec();
        bgcode.extend_from_slice(&[1, 0, 0, 0, 1, 0]);
        assert!(is_binary_gcode(&bgcode));
        let err = parse(&bgcode).expect_err("bgcode is rejected");
        assert_eq!(err, GcodeError::BinaryGcode);
        assert!(err.to_string().contains("turn off binary G-code"), "{err}");
        assert!(!is_binary_gcode(b"G28\n"));
        let err = parse(b"G28\nG1 X1\0\n").expect_err("NUL is rejected");
        assert_eq!(err, GcodeError::NotText { offset: 9, line: 2 });
        // UTF-16 text has NULs too.
        assert!(parse(&[0xff, 0xfe, b'G', 0, b'1', 0]).is_err());
    }
}
