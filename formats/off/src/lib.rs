//! Object File Format (OFF) mesh reader.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
//!
//! # What is read
//!
//! The ASCII OFF format as written by Geomview, Princeton Shape Benchmark, MeshLab and
//! Online3DViewer:
//!
//! ```text
//! OFF                 # header keyword; `COFF`, `NOFF`, `CNOFF`, `STOFF`, ... are accepted too
//! 8 6 0               # vertex, face and (ignored, optional) edge counts; may also follow the keyword
//! 0.0 0.0 0.0         # one vertex per line; extra columns (colours, normals, uv) are ignored
//! ...
//! 4 0 1 5 4           # n, then n vertex indices (0-based); trailing colour columns are ignored
//! ```
//!
//! * `#` starts a comment anywhere on a line; blank lines are skipped.
//! * Faces with more than three vertices are fan-triangulated (`v0 vi vi+1`), which is exact for
//!   convex polygons. Faces with fewer than three vertices are skipped.
//! * Not supported (clear error): binary OFF (`OFF BINARY`), 4D (`4OFF`) and n-dimensional (`nOFF`).
//!
//! The reader never allocates in proportion to a count it has not yet verified against the file
//! length, and every error carries the 1-based line number it was found on.
//!
//! ```
//! let off = conduit_off::read(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")?;
//! assert_eq!(off.vertices.len(), 3);
//! assert_eq!(off.triangles, vec![[0, 1, 2]]);
//! # Ok::<(), conduit_off::OffError>(())
//! ```

use std::borrow::Cow;

/// A triangle mesh read from an OFF file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Off {
    /// Vertex positions, in file order and file units.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as 0-based indices into [`Off::vertices`]; polygons are fan-triangulated.
    pub triangles: Vec<[u32; 3]>,
}

/// The section of an OFF file a truncation was detected in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Section {
    /// The vertex list.
    Vertices,
    /// The face list.
    Faces,
}

impl std::fmt::Display for Section {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Section::Vertices => "vertices",
            Section::Faces => "faces",
        })
    }
}

/// Why an OFF file could not be read.
///
/// Lines are 1-based. How to fix: these are problems of the file itself; re-export it from the
/// program that wrote it, or repair the named line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OffError {
    /// The file holds nothing but whitespace and comments.
    #[error("empty OFF file: no header")]
    Empty,
    /// The first non-comment line is not an OFF header keyword.
    #[error("line {line}: expected an `OFF` header, found `{found}`")]
    MissingHeader {
        /// Line of the offending token.
        line: usize,
        /// The token found instead.
        found: String,
    },
    /// A valid but unsupported OFF variant (binary, 4D, n-dimensional).
    #[error("line {line}: unsupported OFF variant `{header}` (only 3D ASCII OFF is supported)")]
    Unsupported {
        /// Line of the header.
        line: usize,
        /// The header as found.
        header: String,
    },
    /// The counts line is missing or is not `vertex_count face_count [edge_count]`.
    #[error("line {line}: expected `vertex_count face_count [edge_count]`")]
    InvalidCounts {
        /// Line where the counts were expected.
        line: usize,
    },
    /// A token that should be a number is not one (or is not finite).
    #[error("line {line}: `{token}` is not a valid number")]
    InvalidNumber {
        /// Line of the token.
        line: usize,
        /// The token.
        token: String,
    },
    /// A vertex line with fewer than three coordinates.
    #[error("line {line}: vertex needs 3 coordinates, found {found}")]
    TooFewCoordinates {
        /// Line of the vertex.
        line: usize,
        /// How many numbers the line holds.
        found: usize,
    },
    /// A face line that lists fewer indices than its leading count announces.
    #[error("line {line}: face announces {expected} vertices but lists {found}")]
    ShortFace {
        /// Line of the face.
        line: usize,
        /// The count at the start of the line.
        expected: usize,
        /// The number of indices found.
        found: usize,
    },
    /// A face refers to a vertex that does not exist.
    #[error("line {line}: face refers to vertex {index}, but the file has {vertex_count} vertices")]
    IndexOutOfRange {
        /// Line of the face.
        line: usize,
        /// The offending (0-based) index.
        index: i64,
        /// Number of vertices in the file.
        vertex_count: usize,
    },
    /// The header announces more vertices than 32-bit indices can address.
    #[error("{count} vertices announced; at most 4294967296 are supported")]
    TooManyVertices {
        /// The announced vertex count.
        count: usize,
    },
    /// The file ends before all announced vertices or faces were read.
    #[error("file truncated: header announces {expected} {section}, found {found}")]
    Truncated {
        /// Which list is incomplete.
        section: Section,
        /// The announced count.
        expected: usize,
        /// How many were read.
        found: usize,
    },
}

/// Non-empty, comment-stripped lines with their 1-based line numbers.
struct Lines<'a> {
    rest: &'a [u8],
    line: usize,
}

impl<'a> Lines<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Lines {
            rest: bytes,
            line: 0,
        }
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = (usize, Cow<'a, str>);

    fn next(&mut self) -> Option<Self::Item> {
        while !self.rest.is_empty() {
            let end = self
                .rest
                .iter()
                .position(|&b| b == b'\n')
                .unwrap_or(self.rest.len());
            let raw = &self.rest[..end];
            self.rest = self.rest.get(end + 1..).unwrap_or_default();
            self.line += 1;
            let raw = match raw.iter().position(|&b| b == b'#') {
                Some(hash) => &raw[..hash],
                None => raw,
            };
            if raw.iter().all(u8::is_ascii_whitespace) {
                continue;
            }
            return Some((self.line, String::from_utf8_lossy(raw)));
        }
        None
    }
}

fn parse_f64(line: usize, token: &str) -> Result<f64, OffError> {
    match token.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(OffError::InvalidNumber {
            line,
            token: token.to_owned(),
        }),
    }
}

fn parse_count(line: usize, token: Option<&str>) -> Result<usize, OffError> {
    token
        .and_then(|t| t.parse::<usize>().ok())
        .ok_or(OffError::InvalidCounts { line })
}

/// Checks the header keyword: `[ST][C][N]OFF`; `4`/`n` variants and `BINARY` are unsupported.
fn check_header(line: usize, text: &str) -> Result<(), OffError> {
    let keyword = text.split_whitespace().next().unwrap_or_default();
    let Some(prefix) = keyword.strip_suffix("OFF") else {
        return Err(OffError::MissingHeader {
            line,
            found: keyword.to_owned(),
        });
    };
    let rest = prefix.strip_prefix("ST").unwrap_or(prefix);
    let rest = rest.strip_prefix('C').unwrap_or(rest);
    let rest = rest.strip_prefix('N').unwrap_or(rest);
    let binary = text
        .split_whitespace()
        .nth(1)
        .is_some_and(|t| t.eq_ignore_ascii_case("BINARY"));
    if rest == "4" || rest == "n" || rest == "4n" || binary {
        return Err(OffError::Unsupported {
            line,
            header: text.trim().to_owned(),
        });
    }
    if !rest.is_empty() {
        return Err(OffError::MissingHeader {
            line,
            found: keyword.to_owned(),
        });
    }
    Ok(())
}

/// Reads an ASCII OFF file.
///
/// # Errors
///
/// [`OffError`] for a missing or unsupported header, malformed counts, vertices or faces, an index
/// outside the vertex list, or a file shorter than its counts announce. All but
/// [`OffError::Truncated`] name the line.
pub fn read(bytes: &[u8]) -> Result<Off, OffError> {
    // A UTF-8 byte order mark, as some Windows tools write, is not part of the header.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut lines = Lines::new(bytes);
    let (header_line, header) = lines.next().ok_or(OffError::Empty)?;
    check_header(header_line, &header)?;
    let (vertex_count, face_count) = counts(&mut lines, header_line, &header)?;

    // Counts are untrusted: each vertex line takes at least 6 bytes ("0 0 0\n"), each face 8.
    let mut vertices = Vec::with_capacity(vertex_count.min(bytes.len() / 6));
    while vertices.len() < vertex_count {
        let Some((line, text)) = lines.next() else {
            return Err(OffError::Truncated {
                section: Section::Vertices,
                expected: vertex_count,
                found: vertices.len(),
            });
        };
        vertices.push(vertex(line, &text)?);
    }

    let mut triangles = Vec::with_capacity(face_count.min(bytes.len() / 8));
    let mut face = Vec::new();
    for faces_read in 0..face_count {
        let Some((line, text)) = lines.next() else {
            return Err(OffError::Truncated {
                section: Section::Faces,
                expected: face_count,
                found: faces_read,
            });
        };
        face_indices(line, &text, vertices.len(), &mut face)?;
        // Faces with fewer than three vertices have no area: skipped.
        if let Some((&first, rest)) = face.split_first() {
            for pair in rest.windows(2) {
                triangles.push([first, pair[0], pair[1]]);
            }
        }
    }

    Ok(Off {
        vertices,
        triangles,
    })
}

/// The vertex and face counts: after the keyword on the header line, or on the next line.
fn counts(
    lines: &mut Lines<'_>,
    header_line: usize,
    header: &str,
) -> Result<(usize, usize), OffError> {
    let mut header_tokens = header.split_whitespace().skip(1).peekable();
    let (counts_line, counts_text): (usize, Cow<'_, str>) = if header_tokens.peek().is_some() {
        (
            header_line,
            Cow::Owned(header_tokens.collect::<Vec<_>>().join(" ")),
        )
    } else {
        lines.next().ok_or(OffError::InvalidCounts {
            line: header_line + 1,
        })?
    };
    let mut tokens = counts_text.split_whitespace();
    let vertex_count = parse_count(counts_line, tokens.next())?;
    let face_count = parse_count(counts_line, tokens.next())?;
    if u32::try_from(vertex_count.saturating_sub(1)).is_err() {
        return Err(OffError::TooManyVertices {
            count: vertex_count,
        });
    }
    Ok((vertex_count, face_count))
}

/// The three coordinates of a vertex line (values after them are ignored).
fn vertex(line: usize, text: &str) -> Result<[f64; 3], OffError> {
    let mut coords = [0.0; 3];
    let mut found = 0;
    for token in text.split_whitespace().take(3) {
        coords[found] = parse_f64(line, token)?;
        found += 1;
    }
    if found < 3 {
        return Err(OffError::TooFewCoordinates { line, found });
    }
    Ok(coords)
}

/// Reads a face line (`n i1 .. in`, values after them ignored) into `face`: `n` indices into
/// the `vertex_count` vertices.
fn face_indices(
    line: usize,
    text: &str,
    vertex_count: usize,
    face: &mut Vec<u32>,
) -> Result<(), OffError> {
    let mut tokens = text.split_whitespace();
    let n: usize = match tokens.next().map(str::parse) {
        Some(Ok(n)) => n,
        Some(Err(_)) | None => {
            return Err(OffError::InvalidNumber {
                line,
                token: text
                    .split_whitespace()
                    .next()
                    .unwrap_or_default()
                    .to_owned(),
            });
        }
    };
    face.clear();
    // `take(n)` bounds the loop by the tokens present, not by the untrusted `n`.
    for token in tokens.take(n) {
        let index: i64 = token.parse().map_err(|_| OffError::InvalidNumber {
            line,
            token: token.to_owned(),
        })?;
        let valid = usize::try_from(index).ok().filter(|&i| i < vertex_count);
        let Some(index) = valid.and_then(|i| u32::try_from(i).ok()) else {
            return Err(OffError::IndexOutOfRange {
                line,
                index,
                vertex_count,
            });
        };
        face.push(index);
    }
    if face.len() < n {
        return Err(OffError::ShortFace {
            line,
            expected: n,
            found: face.len(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Signed volume by the divergence theorem; positive for outward-facing triangles.
    fn volume(off: &Off) -> f64 {
        off.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| off.vertices[i as usize]);
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum()
    }

    const CUBE: &str = "OFF\n# a 2 mm cube\n8 6 12\n\
        0 0 0\n2 0 0\n2 2 0\n0 2 0\n0 0 2\n2 0 2\n2 2 2\n0 2 2\n\
        4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n4 0 3 2 1\n4 4 5 6 7\n";

    #[test]
    fn cube_volume_and_triangle_count() -> Result<(), OffError> {
        let off = read(CUBE.as_bytes())?;
        assert_eq!(off.vertices.len(), 8);
        assert_eq!(off.triangles.len(), 12);
        assert!((volume(&off) - 8.0).abs() < 1e-12, "{}", volume(&off));
        assert_eq!(off.triangles[0], [0, 1, 5]);
        assert_eq!(off.triangles[1], [0, 5, 4]);
        Ok(())
    }

    #[test]
    fn header_variants_and_counts_on_header_line() -> Result<(), OffError> {
        let expected = read(CUBE.as_bytes())?;
        for header in ["COFF", "NOFF", "CNOFF", "STOFF"] {
            let text = CUBE.replacen("OFF", header, 1);
            assert_eq!(read(text.as_bytes())?, expected, "{header}");
        }
        let inline = CUBE.replacen("OFF\n# a 2 mm cube\n8 6 12", "OFF 8 6 12", 1);
        assert_eq!(read(inline.as_bytes())?, expected);
        let crlf = CUBE.replace('\n', "\r\n");
        assert_eq!(read(crlf.as_bytes())?, expected);
        let bom = format!("\u{feff}{CUBE}");
        assert_eq!(read(bom.as_bytes())?, expected);
        Ok(())
    }

    #[test]
    fn colours_and_comments_are_ignored() -> Result<(), OffError> {
        let text = "# leading comment\nCOFF\n# c\n4 1 # counts\n\
            0 0 0 255 0 0 255\n1 0 0 0.0 1.0 0.0 1.0 # float colour\n\n1 1 0 0 0 255\n0 1 0\n\
            4 0 1 2 3 1.0 0.5 0.0\n";
        let off = read(text.as_bytes())?;
        assert_eq!(off.vertices[1], [1.0, 0.0, 0.0]);
        assert_eq!(off.vertices[3], [0.0, 1.0, 0.0]);
        assert_eq!(off.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        Ok(())
    }

    #[test]
    fn errors_name_the_line() {
        let bad_index = "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n";
        assert_eq!(
            read(bad_index.as_bytes()),
            Err(OffError::IndexOutOfRange {
                line: 6,
                index: 3,
                vertex_count: 3
            })
        );
        let negative = "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n";
        assert!(matches!(
            read(negative.as_bytes()),
            Err(OffError::IndexOutOfRange { line: 6, .. })
        ));
        let short_vertex = "OFF\n3 1\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n";
        assert_eq!(
            read(short_vertex.as_bytes()),
            Err(OffError::TooFewCoordinates { line: 4, found: 2 })
        );
        let short_face = "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n";
        assert!(matches!(
            read(short_face.as_bytes()),
            Err(OffError::ShortFace { line: 6, .. })
        ));
        let nan = "OFF\n3 1\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n";
        assert!(matches!(
            read(nan.as_bytes()),
            Err(OffError::InvalidNumber { line: 4, .. })
        ));
    }

    #[test]
    fn hostile_headers_do_not_allocate_or_panic() {
        assert_eq!(read(b""), Err(OffError::Empty));
        assert_eq!(read(b"# only\n\n"), Err(OffError::Empty));
        assert!(matches!(
            read(b"ply\n"),
            Err(OffError::MissingHeader { line: 1, .. })
        ));
        assert!(matches!(
            read(b"OFF BINARY\n"),
            Err(OffError::Unsupported { .. })
        ));
        assert!(matches!(read(b"4OFF\n"), Err(OffError::Unsupported { .. })));
        assert!(matches!(
            read(b"OFF\n"),
            Err(OffError::InvalidCounts { line: 2 })
        ));
        assert!(matches!(
            read(b"OFF\nx 1\n"),
            Err(OffError::InvalidCounts { line: 2 })
        ));
        let huge = format!("OFF\n{} {}\n0 0 0\n", u32::MAX, usize::MAX);
        assert_eq!(
            read(huge.as_bytes()),
            Err(OffError::Truncated {
                section: Section::Vertices,
                expected: u32::MAX as usize,
                found: 1
            })
        );
        let huge_faces = format!(
            "OFF\n3 {}\n0 0 0\n1 0 0\n0 1 0\n99999999999 0 1 2\n",
            usize::MAX
        );
        assert!(matches!(
            read(huge_faces.as_bytes()),
            Err(OffError::ShortFace { line: 6, .. })
        ));
        let too_many = format!("OFF\n{} 0\n", u64::MAX);
        assert!(matches!(
            read(too_many.as_bytes()),
            Err(OffError::TooManyVertices { .. })
        ));
    }

    #[test]
    fn adversarial_bytes_never_panic() {
        let seed = CUBE.as_bytes();
        let mut state = 0x853c_49e6_748f_ea9b_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for cut in 0..seed.len() {
            let _ = read(&seed[..cut]);
        }
        let alphabet = b"0123456789 -.#\nOFCN";
        for _ in 0..5000 {
            let mut bytes = seed.to_vec();
            for _ in 0..1 + next() % 6 {
                let at = (next() % bytes.len() as u64) as usize;
                bytes[at] = alphabet[(next() % alphabet.len() as u64) as usize];
            }
            let _ = read(&bytes);
        }
    }

    #[test]
    fn degenerate_faces_are_skipped() -> Result<(), OffError> {
        let text = "OFF\n3 3\n0 0 0\n1 0 0\n0 1 0\n0\n2 0 1\n3 2 1 0\n";
        assert_eq!(read(text.as_bytes())?.triangles, vec![[2, 1, 0]]);
        Ok(())
    }

    #[test]
    fn corpus() {
        let root = std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/corpus"
        ));
        let Ok(manifest) = std::fs::read_to_string(root.join("MANIFEST.json")) else {
            println!("skipped: corpus not found");
            return;
        };
        let entries: Vec<serde_json::Value> =
            serde_json::from_str(&manifest).expect("MANIFEST.json is a JSON array");
        let (mut loaded, mut rejected, mut either) = (0, 0, 0);
        for entry in entries.iter().filter(|e| e["format"] == "OFF") {
            let staged = entry["staged"].as_str().expect("staged is a string");
            let bytes = std::fs::read(root.join(staged)).expect("corpus file readable");
            let result = read(&bytes);
            match entry["outcome"].as_str() {
                Some("load") => {
                    let off = result.unwrap_or_else(|e| panic!("{staged}: {e}"));
                    assert!(!off.triangles.is_empty(), "{staged}: no triangles");
                    loaded += 1;
                }
                Some("reject") => {
                    assert!(result.is_err(), "{staged}: expected an error");
                    rejected += 1;
                }
                _ => either += 1,
            }
        }
        println!("OFF corpus: {loaded} loaded, {rejected} rejected, {either} either");
        assert!(loaded > 0);
    }
}
