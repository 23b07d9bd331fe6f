//! The contact sheet, and the side views as images.
//!
//! The contact sheet: every Nth layer rasterised with `tiny-skia` into square tiles on a grid
//! (as many columns as `⌈√tiles⌉`, filled row by row), encoded as RGBA PNG.
//!
//! Each tile is white with a light grey frame; the extrusions of all layers fit its inner area
//! at the same scale (so tiles line up), +Y up, each stroke at its width (at least one pixel)
//! in its role/tool colour. Travels are left out at this size. Under the drawing a dark bar,
//! as long as the layer is far up the print, tells the layers apart without text.

use tiny_skia::{LineCap, LineJoin, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use super::{Preview, PreviewError, SIDE_CURVED_COLOUR, SIDE_PLANAR_COLOUR, SideAxis, StrokeKind};

/// Sheet background (the frame between tiles), RGB.
const FRAME: [u8; 3] = [0xd0, 0xd0, 0xd0];
/// Tile background, RGB.
pub const BACKGROUND: [u8; 3] = [0xff, 0xff, 0xff];
/// Layer bar colour, RGB.
const BAR: [u8; 3] = [0x40, 0x40, 0x40];

/// Padding inside a tile around the drawing, pixels.
fn padding(tile: u32) -> f32 {
    (tile as f32 / 16.0).max(4.0)
}

/// Columns and rows of a sheet of `tiles` tiles.
pub fn grid(tiles: usize) -> (usize, usize) {
    let mut cols = 1;
    while cols * cols < tiles {
        cols += 1;
    }
    (cols, tiles.div_ceil(cols).max(1))
}

/// The PNG bytes of the contact sheet of layers 0, `every`, 2·`every`… with `tile` × `tile`
/// pixel tiles.
pub fn contact_sheet(preview: &Preview, every: usize, tile: u32) -> Result<Vec<u8>, PreviewError> {
    let every = every.max(1);
    let shown: Vec<usize> = (0..preview.layers.len()).step_by(every).collect();
    let (cols, rows) = grid(shown.len());
    let (width, height) = (cols as u64 * u64::from(tile), rows as u64 * u64::from(tile));
    let too_large = PreviewError::SheetTooLarge { width, height };
    // Keep the sheet below 2^28 pixels (1 GiB of RGBA).
    if width * height > 1 << 28 {
        return Err(too_large);
    }
    let mut pixmap = Pixmap::new(width as u32, height as u32).ok_or(too_large)?;
    pixmap.fill(colour(FRAME));

    let [x0, y0, x1, y1] = preview.bounds;
    let pad = padding(tile);
    let inner = tile as f32 - 2.0 * pad;
    let extent = (x1 - x0).max(y1 - y0).max(1e-3) as f32;
    let scale = inner / extent;
    // Centre the drawing in the tile.
    let off_x = pad + (inner - (x1 - x0) as f32 * scale) / 2.0;
    let off_y = pad + (inner - (y1 - y0) as f32 * scale) / 2.0;

    let mut paint = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    for (k, &index) in shown.iter().enumerate() {
        let (tx, ty) = (
            (k % cols) as f32 * tile as f32,
            (k / cols) as f32 * tile as f32,
        );
        paint.set_color(colour(BACKGROUND));
        if let Some(r) = Rect::from_xywh(tx + 1.0, ty + 1.0, tile as f32 - 2.0, tile as f32 - 2.0) {
            pixmap.fill_rect(r, &paint, Transform::identity(), None);
        }
        for s in &preview.layers[index].strokes {
            let StrokeKind::Extrusion { role, tool, width } = s.kind else {
                continue;
            };
            let mut pb = PathBuilder::new();
            for (i, p) in s.points.iter().enumerate() {
                let x = tx + off_x + (p[0] - x0) as f32 * scale;
                let y = ty + off_y + (y1 - p[1]) as f32 * scale;
                if i == 0 {
                    pb.move_to(x, y);
                } else {
                    pb.line_to(x, y);
                }
            }
            let Some(path) = pb.finish() else {
                continue;
            };
            paint.set_color(colour(preview.colour(role, tool)));
            let stroke = Stroke {
                width: (width as f32 * scale).max(1.0),
                line_cap: LineCap::Round,
                line_join: LineJoin::Round,
                ..Stroke::default()
            };
            pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
        }
        // Layer bar: from the left padding, as long as the layer is far up the print.
        let frac = (index + 1) as f32 / preview.layers.len() as f32;
        let bar_h = (pad / 3.0).max(2.0);
        if let Some(r) = Rect::from_xywh(
            tx + pad,
            ty + tile as f32 - pad / 2.0 - bar_h / 2.0,
            inner * frac,
            bar_h,
        ) {
            paint.set_color(colour(BAR));
            pixmap.fill_rect(r, &paint, Transform::identity(), None);
        }
    }
    pixmap
        .encode_png()
        .map_err(|e| PreviewError::Png(Box::new(e)))
}

fn colour(rgb: [u8; 3]) -> tiny_skia::Color {
    tiny_skia::Color::from_rgba8(rgb[0], rgb[1], rgb[2], 255)
}

/// The PNG bytes of the side view of `preview` onto the plane of `axis` and Z, `width` pixels
/// wide (the height follows the print's aspect, at least 16 and at most 4·`width` pixels):
/// planar extrusions grey, curved ones highlighted and drawn last, each at least a pixel wide.
pub fn side(preview: &Preview, axis: SideAxis, width: u32) -> Result<Vec<u8>, PreviewError> {
    let [a0, z0, a1, z1] = preview.side_bounds(axis).unwrap_or([0.0, 0.0, 1.0, 1.0]);
    let width = width.max(16);
    let pad = padding(width);
    let inner = width as f32 - 2.0 * pad;
    let scale = inner / (a1 - a0).max(1e-3) as f32;
    let height = (((z1 - z0) as f32 * scale + 2.0 * pad).ceil() as u32).clamp(16, width * 4);
    let too_large = PreviewError::SheetTooLarge {
        width: u64::from(width),
        height: u64::from(height),
    };
    if u64::from(width) * u64::from(height) > 1 << 28 {
        return Err(too_large);
    }
    let mut pixmap = Pixmap::new(width, height).ok_or(too_large)?;
    pixmap.fill(colour(BACKGROUND));
    let mut paint = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    let stroke = Stroke {
        width: 1.0,
        line_cap: LineCap::Round,
        line_join: LineJoin::Round,
        ..Stroke::default()
    };
    for curved in [false, true] {
        paint.set_color(colour(if curved {
            SIDE_CURVED_COLOUR
        } else {
            SIDE_PLANAR_COLOUR
        }));
        for layer in &preview.layers {
            for s in layer.strokes.iter().filter(|s| s.curved == curved) {
                if s.kind == StrokeKind::Travel {
                    continue;
                }
                let mut pb = PathBuilder::new();
                for (i, (p, &z)) in s.points.iter().zip(&s.z).enumerate() {
                    let x = pad + (axis.across(*p) - a0) as f32 * scale;
                    let y = height as f32 - pad - (z - z0) as f32 * scale;
                    if i == 0 {
                        pb.move_to(x, y);
                    } else {
                        pb.line_to(x, y);
                    }
                }
                if let Some(path) = pb.finish() {
                    pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
                }
            }
        }
    }
    pixmap
        .encode_png()
        .map_err(|e| PreviewError::Png(Box::new(e)))
}
