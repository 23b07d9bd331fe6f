//! Text in the PNG previews: the glyphs of `font8x8` (a public-domain 8 × 8 bitmap font kept as
//! constants, so no font file is read) copied into a `tiny-skia` pixmap, each font pixel an
//! `s` × `s` square. Characters the font lacks are drawn as `?`. No anti-aliasing: the same
//! text gives the same pixels on every machine.

use font8x8::UnicodeFonts;
use tiny_skia::{Pixmap, PremultipliedColorU8};

/// Width and height of a glyph, font pixels.
pub const GLYPH: u32 = 8;

/// The 8 rows of `c` (bit 0 is the leftmost pixel).
fn glyph(c: char) -> [u8; 8] {
    font8x8::BASIC_FONTS
        .get(c)
        .or_else(|| font8x8::LATIN_FONTS.get(c))
        .or_else(|| font8x8::GREEK_FONTS.get(c))
        .or_else(|| font8x8::BASIC_FONTS.get('?'))
        .unwrap_or([0; 8])
}

/// Width of `text` at scale `s`, pixels.
pub fn width(text: &str, s: u32) -> u32 {
    let chars = u32::try_from(text.chars().count()).unwrap_or(u32::MAX);
    chars.saturating_mul(GLYPH * s)
}

/// Draws `text` with its top left corner at (`x`, `y`) in opaque `rgb`, each font pixel an
/// `s` × `s` square. Pixels outside the pixmap, or at `x` ≥ `right`, are left out (the text is
/// clipped there).
pub fn draw(pixmap: &mut Pixmap, x: i64, y: i64, s: u32, right: i64, rgb: [u8; 3], text: &str) {
    let Some(colour) = PremultipliedColorU8::from_rgba(rgb[0], rgb[1], rgb[2], 255) else {
        return;
    };
    let (w, h) = (i64::from(pixmap.width()), i64::from(pixmap.height()));
    let right = right.min(w);
    let s = i64::from(s.max(1));
    let pixels = pixmap.pixels_mut();
    for (k, c) in text.chars().enumerate() {
        let left = x + k as i64 * 8 * s;
        if left >= right {
            break;
        }
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                let (px, py) = (left + col * s, y + row as i64 * s);
                for dy in 0..s {
                    for dx in 0..s {
                        let (qx, qy) = (px + dx, py + dy);
                        if (0..right).contains(&qx) && (0..h).contains(&qy) {
                            // In range: 0 ≤ qx < w and 0 ≤ qy < h.
                            pixels[(qy * w + qx) as usize] = colour;
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_drawn_scaled_and_clipped() {
        let mut p = Pixmap::new(40, 20).expect("pixmap");
        draw(&mut p, 0, 0, 2, 20, [0, 0, 0], "LL");
        let dark = |x: u32, y: u32| p.pixel(x, y).is_some_and(|c| c.alpha() == 255);
        // `L`'s stem: font column 0 (bits 0 and 1 set in rows 0..6 of font8x8's 'L'),
        // drawn at scale 2.
        let rows = glyph('L');
        assert_ne!(rows[0], 0);
        let on: Vec<(u32, u32)> = (0..40)
            .flat_map(|x| (0..20).map(move |y| (x, y)))
            .filter(|&(x, y)| dark(x, y))
            .collect();
        assert!(!on.is_empty());
        // Nothing at or past the clip edge, nothing below the 16 px glyph.
        assert!(on.iter().all(|&(x, y)| x < 20 && y < 16), "{on:?}");
        assert_eq!(width("L12", 2), 48);
        // An unknown character is the question mark.
        assert_eq!(glyph('\u{1F600}'), glyph('?'));
    }
}
