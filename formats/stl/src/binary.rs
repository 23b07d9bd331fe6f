//! Binary STL: an 80-byte header, a little-endian `u32` triangle count, then per triangle 50
//! bytes: normal (3 × `f32`), three vertices (9 × `f32`), a `u16` attribute.

use std::io::{self, Write};

use crate::{Encoding, Stl, StlError, facet_normal};

const HEADER: usize = 80;
const PREFIX: usize = HEADER + 4;
const RECORD: usize = 50;
/// Size of the chunks the writers hand to the `Write`r.
pub(crate) const WRITE_CHUNK: usize = 1 << 16;

/// The triangle count at offset 80, if the input is long enough to hold it.
fn declared_count(bytes: &[u8]) -> Option<u32> {
    let count: [u8; 4] = bytes.get(HEADER..PREFIX)?.try_into().ok()?;
    Some(u32::from_le_bytes(count))
}

/// Bytes a binary file with `count` triangles has.
fn expected_len(count: u32) -> u64 {
    PREFIX as u64 + RECORD as u64 * u64::from(count)
}

/// True when the input is exactly as long as its triangle count says.
pub(crate) fn size_matches(bytes: &[u8]) -> bool {
    declared_count(bytes).is_some_and(|count| expected_len(count) == bytes.len() as u64)
}

/// Reads a binary STL. Bytes after the last declared triangle are ignored.
pub(crate) fn read(bytes: &[u8]) -> Result<Stl, StlError> {
    let count = declared_count(bytes).ok_or(StlError::TooShort { len: bytes.len() })?;
    let expected = expected_len(count);
    let actual = bytes.len() as u64;
    // Checked before allocating anything: the allocation below is bounded by the input size.
    let body = usize::try_from(expected)
        .ok()
        .and_then(|end| bytes.get(PREFIX..end))
        .ok_or(StlError::Truncated {
            count,
            expected,
            actual,
        })?;
    let mut triangles = Vec::with_capacity(body.len() / RECORD);
    for (index, record) in body.chunks_exact(RECORD).enumerate() {
        let (triangle, finite) = parse_record(record);
        if !finite {
            return Err(StlError::NonFiniteVertex { triangle: index });
        }
        triangles.push(triangle);
    }
    Ok(Stl {
        name: header_name(bytes.get(..HEADER).unwrap_or_default()),
        encoding: Encoding::Binary,
        triangles,
    })
}

/// The vertices of one 50-byte record, and whether all nine coordinates are finite.
#[inline(always)]
fn parse_record(record: &[u8]) -> ([[f32; 3]; 3], bool) {
    let mut coords = [0.0_f32; 9];
    let mut finite = true;
    // Skip the stored normal (12 bytes); the vertices follow as 9 little-endian f32.
    for (coord, bytes) in coords
        .iter_mut()
        .zip(record.get(12..48).unwrap_or_default().chunks_exact(4))
    {
        let bits = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
        // All exponent bits set: infinity or NaN.
        finite &= bits & 0x7f80_0000 != 0x7f80_0000;
        *coord = f32::from_bits(bits);
    }
    let [a, b, c, d, e, f, g, h, i] = coords;
    ([[a, b, c], [d, e, f], [g, h, i]], finite)
}

/// The header's text up to its first NUL, trimmed, without a leading `solid` word; `None` when
/// that leaves nothing, or text that is not UTF-8 or holds control characters.
fn header_name(header: &[u8]) -> Option<String> {
    let end = header.iter().position(|&b| b == 0).unwrap_or(header.len());
    let text = std::str::from_utf8(header.get(..end)?).ok()?.trim();
    let text = match text.split_once(char::is_whitespace) {
        Some((word, rest)) if word.eq_ignore_ascii_case("solid") => rest.trim_start(),
        _ if text.eq_ignore_ascii_case("solid") => "",
        _ => text,
    };
    (!text.is_empty() && !text.chars().any(char::is_control)).then(|| text.to_owned())
}

/// Writes a binary STL.
///
/// The header holds `name` (cut to 80 bytes at a character boundary, padded with NUL bytes).
/// When `name` starts with the word `solid` (in any case, after any leading whitespace) it is
/// prefixed with `binary ` so that readers which sniff the first word do not take the file for
/// ASCII. Each record stores the normal from [`facet_normal`] and attribute 0. Data goes to `w` in
/// chunks of 64 KiB; wrap a slow writer in a `BufWriter` anyway if it is used for more.
///
/// # Errors
///
/// Errors from `w`, and [`io::ErrorKind::InvalidInput`] for more than `u32::MAX` triangles.
pub fn write_binary<W: Write>(
    w: &mut W,
    name: &str,
    triangles: &[[[f32; 3]; 3]],
) -> io::Result<()> {
    let count = u32::try_from(triangles.len()).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "a binary STL holds at most 2^32 - 1 triangles",
        )
    })?;
    let mut buf = Vec::with_capacity(WRITE_CHUNK + RECORD);
    buf.extend_from_slice(&header(name));
    buf.extend_from_slice(&count.to_le_bytes());
    for t in triangles {
        for c in facet_normal(t)
            .into_iter()
            .chain(t.iter().flatten().copied())
        {
            buf.extend_from_slice(&c.to_le_bytes());
        }
        buf.extend_from_slice(&0u16.to_le_bytes());
        if buf.len() >= WRITE_CHUNK {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}

/// The 80-byte header for `name` (see [`write_binary`]).
fn header(name: &str) -> [u8; HEADER] {
    let starts_with_solid = name
        .trim_start()
        .get(..5)
        .is_some_and(|w| w.eq_ignore_ascii_case("solid"));
    let text = if starts_with_solid {
        format!("binary {name}")
    } else {
        name.to_owned()
    };
    let mut end = text.len().min(HEADER);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    let mut out = [0u8; HEADER];
    for (dst, src) in out
        .iter_mut()
        .zip(text.as_bytes().get(..end).unwrap_or_default())
    {
        *dst = *src;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(normal: [f32; 3], t: [[f32; 3]; 3], attribute: u16) -> Vec<u8> {
        let mut out = Vec::new();
        for c in normal.iter().chain(t.iter().flatten()) {
            out.extend_from_slice(&c.to_le_bytes());
        }
        out.extend_from_slice(&attribute.to_le_bytes());
        out
    }

    fn file(header: &[u8], count: u32, records: &[Vec<u8>]) -> Vec<u8> {
        let mut out = vec![0u8; HEADER];
        out[..header.len()].copy_from_slice(header);
        out.extend_from_slice(&count.to_le_bytes());
        for r in records {
            out.extend_from_slice(r);
        }
        out
    }

    const T0: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [20.0, 0.0, 0.0], [0.0, 20.0, 0.0]];
    const T1: [[f32; 3]; 3] = [[-1.5, 2.25, 1e-3], [3.0e7, -0.0, 7.0], [1.0, 1.0, 1.0]];

    #[test]
    fn reads_vertices_and_ignores_normals_and_attributes() {
        let bytes = file(
            b"Exported by test",
            2,
            &[
                record([f32::NAN, 9.0, 9.0], T0, 0x7fff),
                record([0.0; 3], T1, 0),
            ],
        );
        assert_eq!(bytes.len(), 184);
        let stl = read(&bytes).expect("valid");
        assert_eq!(stl.encoding, Encoding::Binary);
        assert_eq!(stl.name.as_deref(), Some("Exported by test"));
        assert_eq!(stl.triangles, vec![T0, T1]);
        assert!(
            stl.triangles[1][1][1].is_sign_negative(),
            "-0.0 kept as stored"
        );
    }

    #[test]
    fn truncated_file_reports_expected_and_actual_bytes() {
        let mut bytes = file(b"", 3, &[record([0.0; 3], T0, 0), record([0.0; 3], T1, 0)]);
        bytes.extend_from_slice(&[0; 10]);
        let err = crate::read(&bytes).expect_err("truncated");
        assert!(
            matches!(
                err,
                StlError::Truncated {
                    count: 3,
                    expected: 234,
                    actual: 194
                }
            ),
            "{err:?}"
        );
        let msg = err.to_string();
        assert!(
            msg.contains("234") && msg.contains("194") && msg.contains('3'),
            "{msg}"
        );
    }

    #[test]
    fn huge_declared_count_fails_without_allocating_for_it() {
        // 4 billion triangles would need 200 GB; the error must come before any allocation.
        let bytes = file(b"", u32::MAX, &[record([0.0; 3], T0, 0)]);
        let err = crate::read(&bytes).expect_err("truncated");
        assert!(
            matches!(
                err,
                StlError::Truncated {
                    count: u32::MAX,
                    expected: 214_748_364_834,
                    actual: 134
                }
            ),
            "{err:?}"
        );
    }

    #[test]
    fn bytes_shorter_than_the_header_are_too_short() {
        let err = crate::read(&[0u8; 83]).expect_err("short");
        assert!(matches!(err, StlError::TooShort { len: 83 }), "{err:?}");
    }

    #[test]
    fn trailing_bytes_after_the_last_triangle_are_ignored() {
        let mut bytes = file(b"", 1, &[record([0.0; 3], T1, 0)]);
        bytes.extend_from_slice(b"trailing padding");
        let stl = crate::read(&bytes).expect("trailing bytes ignored");
        assert_eq!(stl.encoding, Encoding::Binary);
        assert_eq!(stl.triangles, vec![T1]);
    }

    #[test]
    fn non_finite_vertex_names_the_triangle() {
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let mut t = T1;
            t[2][1] = bad;
            let bytes = file(
                b"",
                3,
                &[
                    record([0.0; 3], T0, 0),
                    record([0.0; 3], T0, 0),
                    record([0.0; 3], t, 0),
                ],
            );
            let err = crate::read(&bytes).expect_err("non-finite");
            assert!(
                matches!(err, StlError::NonFiniteVertex { triangle: 2 }),
                "{err:?}"
            );
        }
    }

    #[test]
    fn header_names() {
        assert_eq!(header_name(&[0; 80]), None);
        assert_eq!(
            header_name(b"  padded  \0\0garbage\x01"),
            Some("padded".to_owned())
        );
        assert_eq!(
            header_name(b"solid part_7                "),
            Some("part_7".to_owned())
        );
        assert_eq!(header_name(b"SOLID\tpart"), Some("part".to_owned()));
        assert_eq!(
            header_name(b"solidworks export"),
            Some("solidworks export".to_owned())
        );
        assert_eq!(header_name(b"solid    "), None);
        assert_eq!(header_name(b"COLOR=\x80\x80\x80\xff MATERIAL"), None);
        assert_eq!(header_name(b"tab\x07bell"), None);
        assert_eq!(header_name("Geräte".as_bytes()), Some("Geräte".to_owned()));
    }

    #[test]
    fn writer_header_never_starts_with_solid() {
        assert!(header("solid cube").starts_with(b"binary solid cube\0"));
        assert!(header("  SOLID").starts_with(b"binary   SOLID\0"));
        assert!(header("cube").starts_with(b"cube\0"));
        let long = "é".repeat(50); // 100 bytes: cut at 80, on a character boundary
        assert_eq!(&header(&long)[..], &long.as_bytes()[..80]);
        let odd = format!("x{long}"); // boundary at 79: the 80th byte is padding
        let h = header(&odd);
        assert_eq!(&h[..79], &odd.as_bytes()[..79]);
        assert_eq!(h[79], 0);
    }

    #[test]
    fn writer_stores_recomputed_normals_and_zero_attributes() {
        let t = [[0.0, 0.0, 0.0], [0.0, 20.0, 0.0], [20.0, 0.0, 0.0]]; // clockwise from +z
        let mut bytes = Vec::new();
        write_binary(&mut bytes, "cube", &[t]).expect("write to Vec");
        assert_eq!(bytes.len(), 134);
        assert_eq!(&bytes[80..84], &1u32.to_le_bytes());
        let f = |o: usize| f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
        assert_eq!([f(84), f(88), f(92)], [0.0, 0.0, -1.0]);
        assert_eq!(&bytes[132..134], &[0, 0]);
    }

    #[test]
    fn round_trip_is_bit_exact_over_random_bit_patterns() {
        let triangles = crate::tests::random_finite_triangles(0x9e37_79b9_7f4a_7c15_u64, 5000);
        let mut bytes = Vec::new();
        write_binary(&mut bytes, "random", &triangles).expect("write to Vec");
        assert_eq!(bytes.len(), 84 + 50 * 5000, "several write chunks");
        let stl = crate::read(&bytes).expect("reads back");
        assert_eq!(stl.name.as_deref(), Some("random"));
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
    fn writer_propagates_io_errors() {
        struct Broken;
        impl Write for Broken {
            fn write(&mut self, _: &[u8]) -> io::Result<usize> {
                Err(io::Error::other("disk full"))
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        let err = write_binary(&mut Broken, "x", &[T0]).expect_err("broken writer");
        assert_eq!(err.to_string(), "disk full");
    }
}
