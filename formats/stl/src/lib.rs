//! STL reader and writer (ASCII and binary).
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
//! [`read`] turns the bytes of a file into an [`Stl`] (a name and a triangle soup with the vertex
//! coordinates exactly as stored); [`write_binary`] and [`write_ascii`] do the reverse. Normals
//! stored in a file are never trusted or kept: [`facet_normal`] recomputes them from the vertices,
//! and the writers store the recomputed ones.
//!
//! # Binary or ASCII
//!
//! The first bytes do not tell the two apart: many binary files have a header starting with
//! `solid`, just like an ASCII file. [`read`] decides in this order:
//!
//! 1. No bytes at all: [`StlError::Empty`].
//! 2. At least 84 bytes and the length is exactly `84 + 50 * count`, where `count` is the
//!    little-endian `u32` at offset 80: **binary**, whatever the header says. (For an ASCII file
//!    the four bytes at offset 80 are text, so in practice `count` is at least `0x0909_0909` and
//!    the length would have to be over 7 GB.)
//! 3. After an optional UTF-8 byte-order mark, whitespace and `#` comment lines, the first word is
//!    `solid` (any case), and there is no NUL byte in the first 84 bytes: **ASCII**. (A binary
//!    file with fewer than 2²⁴ triangles has a NUL at offset 83, so a binary file whose size is
//!    wrong is not mistaken for text.)
//! 4. Anything else is read as **binary**, which reports a file shorter than 84 bytes
//!    ([`StlError::TooShort`]) or shorter than its triangle count requires
//!    ([`StlError::Truncated`]). Bytes after the last declared triangle are ignored.
//!
//! A file that parses but holds no triangle at all is rejected with [`StlError::NoTriangles`],
//! in both encodings: such a file is useless as a model and usually a failed export.
//!
//! # Example
//!
//! ```
//! let tri = [[0.0_f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
//! let mut bytes = Vec::new();
//! conduit_stl::write_binary(&mut bytes, "part", &[tri])?;
//! let stl = conduit_stl::read(&bytes)?;
//! assert_eq!(stl.encoding, conduit_stl::Encoding::Binary);
//! assert_eq!(stl.name.as_deref(), Some("part"));
//! assert_eq!(stl.triangles, vec![tri]);
//! assert_eq!(conduit_stl::facet_normal(&tri), [0.0, 0.0, 1.0]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod ascii;
mod binary;
#[cfg(test)]
mod corpus_tests;

pub use ascii::write_ascii;
pub use binary::write_binary;

/// How an STL file stores its triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// Text: `solid` / `facet normal` / `outer loop` / `vertex` / `endloop` / `endfacet` / `endsolid`.
    Ascii,
    /// An 80-byte header, a little-endian `u32` triangle count, then 50 bytes per triangle.
    Binary,
}

/// The contents of an STL file.
#[derive(Debug, Clone, PartialEq)]
pub struct Stl {
    /// The model's name, `None` when there is none.
    ///
    /// ASCII: the words after the first `solid`, joined by single spaces, up to a `#` comment;
    /// control characters are dropped and invalid UTF-8 becomes U+FFFD. Binary: the header's
    /// text up to its first NUL, trimmed, without a leading `solid` word; `None` when that leaves
    /// nothing or the text is not UTF-8 or holds control characters (many headers hold binary
    /// data such as colours).
    pub name: Option<String>,
    /// Whether the file was ASCII or binary.
    pub encoding: Encoding,
    /// Triangles with their vertex coordinates exactly as stored, in file order. All coordinates
    /// are finite. When an ASCII file holds several `solid` blocks their triangles are concatenated.
    pub triangles: Vec<[[f32; 3]; 3]>,
}

/// Why a file could not be read as STL.
#[derive(Debug, thiserror::Error)]
pub enum StlError {
    /// The input has no bytes.
    ///
    /// How to fix: the export or download did not complete; produce the file again.
    #[error("empty file")]
    Empty,
    /// The input does not start with `solid` and is too short to hold the binary header.
    ///
    /// How to fix: check that the file really is an STL.
    #[error(
        "not an STL file: {len} bytes is too short for a binary STL (at least 84 bytes) and it does not start with `solid`"
    )]
    TooShort {
        /// Length of the input in bytes.
        len: usize,
    },
    /// A binary file is shorter than its triangle count requires.
    ///
    /// How to fix: the file was cut off (interrupted download or copy); produce it again.
    #[error(
        "truncated binary STL: the header declares {count} triangles, which need {expected} bytes, but the file has {actual} bytes"
    )]
    Truncated {
        /// Triangle count stored at offset 80.
        count: u32,
        /// Bytes the file should have: `84 + 50 * count`.
        expected: u64,
        /// Bytes the file has.
        actual: u64,
    },
    /// A binary triangle has an infinite or NaN vertex coordinate.
    ///
    /// How to fix: repair or re-export the model; the exporter wrote invalid geometry.
    #[error("binary STL triangle {triangle} (counting from 0) has a non-finite vertex coordinate")]
    NonFiniteVertex {
        /// Index of the triangle, counting from 0.
        triangle: usize,
    },
    /// An ASCII line does not hold what the grammar requires at that point.
    ///
    /// How to fix: the file is malformed at that line; re-export it or edit the line.
    #[error("line {line}: expected {expected}, found `{found}`")]
    Unexpected {
        /// Line number, counting from 1.
        line: usize,
        /// What the grammar allows here.
        expected: &'static str,
        /// What the line holds (shortened if long).
        found: String,
    },
    /// An ASCII `vertex` coordinate is not a finite number.
    ///
    /// How to fix: the file is malformed at that line; re-export it or edit the line.
    #[error("line {line}: invalid vertex coordinate `{token}` (a finite number is required)")]
    BadCoordinate {
        /// Line number, counting from 1.
        line: usize,
        /// The offending text (shortened if long).
        token: String,
    },
    /// An ASCII `vertex` line has fewer than three coordinates.
    ///
    /// How to fix: the file is malformed at that line; re-export it or edit the line.
    #[error("line {line}: a vertex needs 3 coordinates, found {found}")]
    MissingCoordinates {
        /// Line number, counting from 1.
        line: usize,
        /// How many coordinates the line has.
        found: usize,
    },
    /// An ASCII file ends inside a facet.
    ///
    /// How to fix: the file was cut off; produce it again.
    #[error(
        "the facet starting on line {line} is not complete: the file ends inside it (line {end_line})"
    )]
    UnterminatedFacet {
        /// Line of the facet's `facet` keyword, counting from 1.
        line: usize,
        /// Last line of the file.
        end_line: usize,
    },
    /// An ASCII file ends without the `endsolid` of its last `solid`.
    ///
    /// How to fix: the file was probably cut off between two facets; produce it again.
    #[error(
        "the solid starting on line {line} has no `endsolid`: the file ends at line {end_line}"
    )]
    MissingEndsolid {
        /// Line of the `solid` keyword, counting from 1.
        line: usize,
        /// Last line of the file.
        end_line: usize,
    },
    /// The file is well formed but holds no triangle.
    ///
    /// How to fix: export the model again with its geometry selected.
    #[error("the {encoding:?} STL file contains no triangles")]
    NoTriangles {
        /// Encoding of the file.
        encoding: Encoding,
    },
}

/// Reads an STL file, ASCII or binary, from its bytes.
///
/// The encoding is chosen by the rule in the [crate documentation](crate). Stored normals are
/// ignored (ASCII normals may even be junk such as `+inf` or `weirdvalue`); vertex coordinates
/// must be finite numbers. Never panics, and allocates no more than a small multiple of the
/// input size.
///
/// # Errors
///
/// A [`StlError`] naming the line (ASCII) or triangle / byte counts (binary) of the first problem.
pub fn read(bytes: &[u8]) -> Result<Stl, StlError> {
    if bytes.is_empty() {
        return Err(StlError::Empty);
    }
    let stl = match detect(bytes) {
        Encoding::Binary => binary::read(bytes)?,
        Encoding::Ascii => ascii::read(bytes)?,
    };
    if stl.triangles.is_empty() {
        return Err(StlError::NoTriangles {
            encoding: stl.encoding,
        });
    }
    Ok(stl)
}

/// Chooses the encoding of a non-empty input (rules 2 to 4 of the crate documentation).
fn detect(bytes: &[u8]) -> Encoding {
    if binary::size_matches(bytes) {
        return Encoding::Binary;
    }
    let head = bytes.get(..84).unwrap_or(bytes);
    if ascii::starts_with_solid(bytes) && !head.contains(&0) {
        Encoding::Ascii
    } else {
        Encoding::Binary
    }
}

/// Unit normal of a triangle from its vertices, by the right-hand rule (counter-clockwise seen
/// from the side the normal points to).
///
/// Computed in `f64` and rounded once. Returns `[0.0, 0.0, 0.0]` for a degenerate triangle (zero
/// area) or when a coordinate is not finite. Components are never negative zero.
pub fn facet_normal(t: &[[f32; 3]; 3]) -> [f32; 3] {
    let p = t.map(|v| v.map(f64::from));
    let u = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
    let v = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        // `+ 0.0` turns -0.0 into 0.0, so writers never print `-0` for an axis-aligned normal.
        n.map(|c| (c / len) as f32 + 0.0)
    } else {
        [0.0; 3]
    }
}

/// Text for an error message: lossy UTF-8, at most 40 characters.
fn excerpt(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    let mut out: String = text.chars().take(40).collect();
    if text.chars().nth(40).is_some() {
        out.push('…');
    }
    out
}

#[cfg(test)]
mod tests {
    /// `count` triangles whose coordinates are random finite `f32` bit patterns (xorshift64 from
    /// `seed`), for bit-exact round-trip tests of both encodings.
    pub(crate) fn random_finite_triangles(seed: u64, count: usize) -> Vec<[[f32; 3]; 3]> {
        let mut state = seed;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut triangles = Vec::with_capacity(count);
        while triangles.len() < count {
            let mut t = [[0.0_f32; 3]; 3];
            for c in t.iter_mut().flatten() {
                *c = loop {
                    let v = f32::from_bits(next() as u32);
                    if v.is_finite() {
                        break v;
                    }
                };
            }
            triangles.push(t);
        }
        triangles
    }

    use super::*;

    #[test]
    fn normal_follows_right_hand_rule() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(facet_normal(&t), [0.0, 0.0, 1.0]);
        let flipped = [t[0], t[2], t[1]];
        assert_eq!(facet_normal(&flipped), [0.0, 0.0, -1.0]);
        assert!(
            facet_normal(&flipped)
                .iter()
                .take(2)
                .all(|c| c.is_sign_positive()),
            "no -0.0"
        );
        // Tilted at 45 degrees about x: normal (0, -1, 1) / sqrt(2).
        let tilted = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 3.0]];
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert_eq!(facet_normal(&tilted), [0.0, -h, h]);
    }

    #[test]
    fn normal_of_degenerate_or_non_finite_is_zero() {
        let line = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]];
        assert_eq!(facet_normal(&line), [0.0; 3]);
        let point = [[5.0, 5.0, 5.0]; 3];
        assert_eq!(facet_normal(&point), [0.0; 3]);
        let nan = [[f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(facet_normal(&nan), [0.0; 3]);
        let inf = [[f32::INFINITY, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(facet_normal(&inf), [0.0; 3]);
    }

    #[test]
    fn tiny_and_huge_triangles_still_get_unit_normals() {
        let tiny = [[0.0, 0.0, 0.0], [1e-30, 0.0, 0.0], [0.0, 1e-30, 0.0]];
        assert_eq!(facet_normal(&tiny), [0.0, 0.0, 1.0]);
        let huge = [[0.0, 0.0, 0.0], [0.0, 3e38, 0.0], [0.0, 0.0, 3e38]];
        assert_eq!(facet_normal(&huge), [1.0, 0.0, 0.0]);
    }

    #[test]
    fn empty_input_is_an_error() {
        let err = read(b"").expect_err("empty input");
        assert!(matches!(err, StlError::Empty));
        assert_eq!(err.to_string(), "empty file");
    }

    #[test]
    fn files_without_triangles_are_rejected_in_both_encodings() {
        let err = read(b"solid x\nendsolid x").expect_err("no facets");
        assert!(matches!(
            err,
            StlError::NoTriangles {
                encoding: Encoding::Ascii
            }
        ));
        let mut bin = Vec::new();
        write_binary(&mut bin, "x", &[]).expect("write to Vec");
        assert_eq!(bin.len(), 84);
        let err = read(&bin).expect_err("no triangles");
        assert!(matches!(
            err,
            StlError::NoTriangles {
                encoding: Encoding::Binary
            }
        ));
    }

    #[test]
    fn short_non_solid_input_is_too_short() {
        let err = read(b"hello").expect_err("not STL");
        assert!(matches!(err, StlError::TooShort { len: 5 }), "{err:?}");
    }

    #[test]
    fn binary_whose_header_starts_with_solid_is_binary() {
        let tri = [[1.5, -2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.25]];
        let mut bytes = Vec::new();
        write_binary(&mut bytes, "x", &[tri, tri]).expect("write to Vec");
        bytes[..80].fill(b' ');
        bytes[..16].copy_from_slice(b"solid unit_cube ");
        let stl = read(&bytes).expect("binary with solid header");
        assert_eq!(stl.encoding, Encoding::Binary);
        assert_eq!(stl.name.as_deref(), Some("unit_cube"));
        assert_eq!(stl.triangles, vec![tri, tri]);
    }

    #[test]
    fn truncated_binary_with_solid_header_reports_the_size() {
        let tri = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]];
        let mut bytes = Vec::new();
        write_binary(&mut bytes, "x", &[tri, tri]).expect("write to Vec");
        bytes[..6].copy_from_slice(b"solid ");
        bytes.truncate(84 + 50 + 20);
        let err = read(&bytes).expect_err("truncated");
        assert!(
            matches!(
                err,
                StlError::Truncated {
                    count: 2,
                    expected: 184,
                    actual: 154
                }
            ),
            "{err:?}"
        );
    }

    /// Every prefix and thousands of byte mutations of a valid file of each encoding: a result or
    /// an error, never a panic; whatever reads has finite coordinates and round-trips.
    #[test]
    fn damaged_files_never_panic() {
        let tris = [
            [[0.0, 0.0, 0.0], [20.0, 0.0, 0.0], [0.0, 20.0, 0.0]],
            [[1.5, -2.5, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]],
        ];
        let (mut bin, mut text) = (Vec::new(), Vec::new());
        write_binary(&mut bin, "part", &tris).expect("write to Vec");
        write_ascii(&mut text, "part", &tris).expect("write to Vec");
        let check = |bytes: &[u8]| {
            if let Ok(stl) = read(bytes) {
                assert!(
                    stl.triangles
                        .iter()
                        .flatten()
                        .flatten()
                        .all(|c| c.is_finite())
                );
                let mut out = Vec::new();
                write_binary(&mut out, "x", &stl.triangles).expect("write to Vec");
                assert_eq!(
                    read(&out).expect("own output reads").triangles,
                    stl.triangles
                );
            }
        };
        let mut state = 0x853c_49e6_748f_ea9b_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state as usize
        };
        for file in [&bin, &text] {
            for len in 0..=file.len() {
                check(&file[..len]);
            }
            let alphabet =
                b"\0\r\n #.-+eE01solidfacetnormalouterloopvertexendloopendfacetendsolid\xff";
            for _ in 0..5000 {
                let mut damaged = file.clone();
                for _ in 0..1 + next() % 4 {
                    let at = next() % damaged.len();
                    damaged[at] = alphabet[next() % alphabet.len()];
                }
                check(&damaged);
            }
        }
        // Sanity: the undamaged files read.
        assert_eq!(read(&bin).expect("binary").triangles.len(), 2);
        assert_eq!(read(&text).expect("ascii").triangles.len(), 2);
    }

    #[test]
    fn excerpt_shortens_long_text() {
        assert_eq!(excerpt(b"abc"), "abc");
        let long = excerpt(&[b'x'; 100]);
        assert_eq!(long.chars().count(), 41);
        assert!(long.ends_with('…'));
    }
}
