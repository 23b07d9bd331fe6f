//! Compact number streams for the 3D view: the page carries every vertex of a print, so the
//! numbers travel as variable-length integers in base64 instead of JSON text.
//!
//! Place in the pipeline: the last step of [`super::job`] and [`super::overlay`], decoded by
//! the page's `decode.js`.
//!
//! - Positions are quantised to 1 µm (G-code carries at most 3 decimals in mm, so this is
//!   exact for every file seen so far) and stored as deltas from the previous vertex, zigzag
//!   mapped to unsigned, as LEB128 varints: a typical 0.1–20 mm step takes 2–3 bytes per axis
//!   and a planar step 1 byte for z.
//! - Plain unsigned streams (counts, indices) are LEB128 varints.
//! - Run-length streams are pairs (value, repeat) of varints, for per-segment values such as
//!   feed and width that change rarely.

use base64::Engine;

/// Micrometres per millimetre: the quantum of encoded positions.
pub const UNITS_PER_MM: f64 = 1000.0;

/// Appends `v` as an unsigned LEB128 varint.
pub fn push_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// Zigzag mapping of a signed value to unsigned: 0, −1, 1, −2… → 0, 1, 2, 3…
pub fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

/// A millimetre coordinate in µm, rounded; non-finite values become 0.
pub fn quantise(mm: f64) -> i64 {
    let v = (mm * UNITS_PER_MM).round();
    if v.is_finite() {
        // Clamped far beyond any machine (±9 km) so the cast cannot saturate silently.
        v.clamp(-9e12, 9e12) as i64
    } else {
        0
    }
}

/// Delta-encoded 3D positions: each point's µm coordinates minus the previous point's.
#[derive(Debug, Default, Clone)]
pub struct PositionStream {
    bytes: Vec<u8>,
    last: [i64; 3],
    count: usize,
}

impl PositionStream {
    /// Appends a point, mm.
    pub fn push(&mut self, p: [f64; 3]) {
        for (axis, &c) in p.iter().enumerate() {
            let q = quantise(c);
            push_varint(&mut self.bytes, zigzag(q - self.last[axis]));
            self.last[axis] = q;
        }
        self.count += 1;
    }

    /// Points appended so far.
    pub fn len(&self) -> usize {
        self.count
    }

    /// No point appended yet.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The stream as base64.
    pub fn base64(&self) -> String {
        base64(&self.bytes)
    }
}

/// Run-length-encoded unsigned values: pairs (value, repeat).
#[derive(Debug, Default, Clone)]
pub struct RunStream {
    bytes: Vec<u8>,
    current: Option<(u64, u64)>,
}

impl RunStream {
    /// Appends one value.
    pub fn push(&mut self, v: u64) {
        match &mut self.current {
            Some((value, repeat)) if *value == v => *repeat += 1,
            _ => {
                self.flush();
                self.current = Some((v, 1));
            }
        }
    }

    fn flush(&mut self) {
        if let Some((value, repeat)) = self.current.take() {
            push_varint(&mut self.bytes, value);
            push_varint(&mut self.bytes, repeat);
        }
    }

    /// The stream as base64.
    pub fn base64(mut self) -> String {
        self.flush();
        base64(&self.bytes)
    }
}

/// Unsigned values as consecutive varints, base64.
pub fn varints_base64(values: impl IntoIterator<Item = u64>) -> String {
    let mut bytes = Vec::new();
    for v in values {
        push_varint(&mut bytes, v);
    }
    base64(&bytes)
}

/// Standard base64 with padding.
pub fn base64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decoder the page uses, written again here: unsigned LEB128.
    fn read_varints(bytes: &[u8]) -> Vec<u64> {
        let mut out = Vec::new();
        let (mut v, mut shift) = (0u64, 0);
        for &b in bytes {
            v |= u64::from(b & 0x7f) << shift;
            if b & 0x80 == 0 {
                out.push(v);
                (v, shift) = (0, 0);
            } else {
                shift += 7;
            }
        }
        out
    }

    fn unzigzag(v: u64) -> i64 {
        ((v >> 1) as i64) ^ -((v & 1) as i64)
    }

    fn decode(b64: &str) -> Vec<u8> {
        base64::engine::general_purpose::STANDARD
            .decode(b64)
            .expect("valid base64")
    }

    #[test]
    fn varints_and_zigzag_round_trip() {
        let values = [0u64, 1, 127, 128, 300, 16_383, 16_384, u64::from(u32::MAX)];
        let mut bytes = Vec::new();
        for v in values {
            push_varint(&mut bytes, v);
        }
        assert_eq!(read_varints(&bytes), values);
        // 0 and 127 take one byte, 128..16383 two, 16384 three, u32::MAX five.
        assert_eq!(bytes.len(), 1 + 1 + 1 + 2 + 2 + 2 + 3 + 5);
        for v in [0i64, -1, 1, -2, 2, -1_000_000, 1_000_000] {
            assert_eq!(unzigzag(zigzag(v)), v);
        }
        assert_eq!(zigzag(-1), 1);
        assert_eq!(zigzag(1), 2);
    }

    #[test]
    fn positions_decode_to_the_micrometre() {
        let points = [[10.0, 20.0, 0.2], [30.123, -4.5, 0.2], [30.1234, -4.5, 0.4]];
        let mut s = PositionStream::default();
        for p in points {
            s.push(p);
        }
        assert_eq!(s.len(), 3);
        let v = read_varints(&decode(&s.base64()));
        assert_eq!(v.len(), 9);
        let mut last = [0i64; 3];
        let mut got = Vec::new();
        for chunk in v.chunks(3) {
            for k in 0..3 {
                last[k] += unzigzag(chunk[k]);
            }
            got.push(last.map(|c| c as f64 / UNITS_PER_MM));
        }
        // 30.1234 rounds to 30.123.
        assert_eq!(
            got,
            vec![[10.0, 20.0, 0.2], [30.123, -4.5, 0.2], [30.123, -4.5, 0.4]]
        );
        assert_eq!(quantise(f64::NAN), 0);
    }

    #[test]
    fn runs_pair_values_with_repeats() {
        let mut r = RunStream::default();
        for v in [5, 5, 5, 7, 5] {
            r.push(v);
        }
        assert_eq!(read_varints(&decode(&r.base64())), [5, 3, 7, 1, 5, 1]);
        assert_eq!(RunStream::default().base64(), "");
        assert_eq!(read_varints(&decode(&varints_base64([1, 200]))), [1, 200]);
    }
}
