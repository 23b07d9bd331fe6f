//! The contact sheet, and the side views as images.
//!
//! The contact sheet: every Nth layer rasterised with `tiny-skia` into square tiles on a grid
//! (as many columns as `⌈√tiles⌉`, filled row by row), a legend below the grid, encoded as
//! RGBA PNG.
//!
//! Each tile is white with a light grey frame; the extrusions of all layers fit its square
//! drawing at the same scale (so tiles line up), +Y up, each stroke at its width (at least one
//! pixel) in its role/tool colour. Travels are left out at this size. The parts placed before
//! the layer are outlined and named on it. A strip under the drawing labels the tile with the
//! layer's number and Z ([`tile_label`]). The legend gives each role and tool's colour
//! ([`Preview::style_label`]) and the parts' outline. Text is `font8x8`'s 8 × 8 bitmap font
//! at [`font_scale`] pixels per font pixel.

use tiny_skia::{LineCap, LineJoin, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use super::text::{self, GLYPH};
use super::{
    PART_COLOUR, PartMark, Preview, PreviewError, SIDE_CURVED_COLOUR, SIDE_PLANAR_COLOUR, SideAxis,
    StrokeKind, label_rows, svg::side_box, tile_label,
};

/// Sheet background (the frame between tiles), RGB.
const FRAME: [u8; 3] = [0xd0, 0xd0, 0xd0];
/// Tile background, RGB.
pub const BACKGROUND: [u8; 3] = [0xff, 0xff, 0xff];
/// Colour of the tiles' labels and the legend's text, RGB.
pub const TEXT: [u8; 3] = [0x20, 0x20, 0x20];

/// Padding inside a tile around the drawing, pixels.
fn padding(tile: u32) -> f32 {
    (tile as f32 / 16.0).max(4.0)
}

/// Pixels per font pixel of the text on a sheet of `tile`-pixel tiles: 1 up to 255 px tiles, 2
/// from 256 px, and so on (a label of 12 characters then takes at most ¾ of the tile).
pub fn font_scale(tile: u32) -> u32 {
    (tile / 128).max(1)
}

/// Height of the label strip under each tile's drawing, pixels.
pub fn label_strip(tile: u32) -> u32 {
    (GLYPH + 4) * font_scale(tile)
}

/// Columns and rows of a sheet of `tiles` tiles.
pub fn grid(tiles: usize) -> (usize, usize) {
    let mut cols = 1;
    while cols * cols < tiles {
        cols += 1;
    }
    (cols, tiles.div_ceil(cols).max(1))
}

/// Longest legend label on the contact sheet, characters (longer role names are cut).
const LEGEND_LABEL_CHARS: usize = 40;

/// The contact sheet's legend: entries of a swatch (2 glyphs wide, a frame only for the part
/// outline), a glyph's gap and the label, in columns as wide as the longest entry, as many as
/// fit the sheet.
struct Legend {
    /// (colour, label, outline only).
    entries: Vec<([u8; 3], String, bool)>,
    /// Font scale.
    fs: u32,
    /// Width of one entry with the gap after it, pixels.
    entry_w: u32,
}

impl Legend {
    fn new(preview: &Preview, fs: u32) -> Self {
        let mut entries: Vec<([u8; 3], String, bool)> = preview
            .styles
            .iter()
            .map(|&(role, tool)| {
                let mut label = preview.style_label(role, tool);
                if label.chars().count() > LEGEND_LABEL_CHARS {
                    label = label
                        .chars()
                        .take(LEGEND_LABEL_CHARS - 3)
                        .collect::<String>()
                        + "...";
                }
                (preview.colour(role, tool), label, false)
            })
            .collect();
        if preview.has_placed_parts() {
            entries.push((PART_COLOUR, "Part outline".to_owned(), true));
        }
        let entry_w = entries
            .iter()
            .map(|(_, label, _)| 4 * GLYPH * fs + text::width(label, fs))
            .max()
            .unwrap_or(0);
        Self {
            entries,
            fs,
            entry_w,
        }
    }

    /// The margin around the legend, pixels.
    fn gap(&self) -> u64 {
        u64::from(GLYPH * self.fs)
    }

    /// The narrowest sheet that holds one column, pixels.
    fn min_width(&self) -> u64 {
        u64::from(self.entry_w) + self.gap()
    }

    /// Columns on a sheet `width` pixels wide.
    fn columns(&self, width: u64) -> u64 {
        (width.saturating_sub(self.gap()) / u64::from(self.entry_w.max(1))).max(1)
    }

    /// Height of a legend row, pixels.
    fn row_h(&self) -> u64 {
        u64::from((GLYPH + 4) * self.fs)
    }

    /// Height on a sheet `width` pixels wide, pixels.
    fn height(&self, width: u64) -> u64 {
        (self.entries.len() as u64).div_ceil(self.columns(width)) * self.row_h() + self.gap()
    }

    /// Draws the legend on white from `top` across a sheet `width` pixels wide.
    fn draw(&self, pixmap: &mut Pixmap, top: u64, width: u64) {
        let mut paint = Paint::default();
        paint.set_color(colour(BACKGROUND));
        let area = Rect::from_xywh(0.0, top as f32, width as f32, self.height(width) as f32);
        if let Some(r) = area {
            pixmap.fill_rect(r, &paint, Transform::identity(), None);
        }
        let (fs, columns) = (self.fs, self.columns(width));
        for (k, (rgb, label, outline)) in self.entries.iter().enumerate() {
            let k = k as u64;
            let x = self.gap() + (k % columns) * u64::from(self.entry_w);
            let y = top + self.gap() / 2 + (k / columns) * self.row_h();
            let swatch = Rect::from_xywh(
                x as f32,
                y as f32,
                (2 * GLYPH * fs) as f32,
                (GLYPH * fs) as f32,
            );
            if let Some(r) = swatch {
                paint.set_color(colour(*rgb));
                if *outline {
                    let stroke = Stroke {
                        width: fs as f32,
                        ..Stroke::default()
                    };
                    let path = PathBuilder::from_rect(r);
                    pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
                } else {
                    pixmap.fill_rect(r, &paint, Transform::identity(), None);
                }
            }
            text::draw(
                pixmap,
                (x + u64::from(3 * GLYPH * fs)) as i64,
                y as i64,
                fs,
                width as i64,
                TEXT,
                label,
            );
        }
    }
}

/// The PNG bytes of the contact sheet of layers 0, `every`, 2·`every`… with `tile` × `tile`
/// pixel drawings, each with its label strip, and the legend under the grid.
pub fn contact_sheet(preview: &Preview, every: usize, tile: u32) -> Result<Vec<u8>, PreviewError> {
    let every = every.max(1);
    let shown: Vec<usize> = (0..preview.layers.len()).step_by(every).collect();
    let (cols, rows) = grid(shown.len());
    let fs = font_scale(tile);
    let cell_h = tile + label_strip(tile);
    let legend = Legend::new(preview, fs);
    let width = (cols as u64 * u64::from(tile)).max(legend.min_width());
    let height = rows as u64 * u64::from(cell_h) + legend.height(width);
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
            (k / cols) as f32 * cell_h as f32,
        );
        paint.set_color(colour(BACKGROUND));
        if let Some(r) = Rect::from_xywh(tx + 1.0, ty + 1.0, tile as f32 - 2.0, cell_h as f32 - 2.0)
        {
            pixmap.fill_rect(r, &paint, Transform::identity(), None);
        }
        let to_px = |p: [f64; 2]| {
            (
                tx + off_x + (p[0] - x0) as f32 * scale,
                ty + off_y + (y1 - p[1]) as f32 * scale,
            )
        };
        for s in &preview.layers[index].strokes {
            let StrokeKind::Extrusion { role, tool, width } = s.kind else {
                continue;
            };
            let Some(path) = polyline(s.points.iter().map(|&p| to_px(p)), false) else {
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
        let right = (tx + tile as f32 - 1.0) as i64;
        for part in preview.parts_on(index) {
            draw_part(&mut pixmap, part, &to_px, fs.div_ceil(2), right);
        }
        // The label strip under the drawing.
        text::draw(
            &mut pixmap,
            (tx + pad) as i64,
            (ty + tile as f32) as i64,
            fs,
            right,
            TEXT,
            &tile_label(index, preview.layers[index].z),
        );
    }
    legend.draw(&mut pixmap, rows as u64 * u64::from(cell_h), width);
    pixmap
        .encode_png()
        .map_err(|e| PreviewError::Png(Box::new(e)))
}

/// A path through `points`, closed when `close`; `None` for fewer than two points.
fn polyline(points: impl Iterator<Item = (f32, f32)>, close: bool) -> Option<tiny_skia::Path> {
    let mut pb = PathBuilder::new();
    for (i, (x, y)) in points.enumerate() {
        if i == 0 {
            pb.move_to(x, y);
        } else {
            pb.line_to(x, y);
        }
    }
    if close {
        pb.close();
    }
    pb.finish()
}

/// Draws a machine-placed `part` on a tile: its outline (a small square where the file gives
/// none) and its name above it at font scale `fs`, clipped at `right`.
fn draw_part(
    pixmap: &mut Pixmap,
    part: &PartMark,
    to_px: &impl Fn([f64; 2]) -> (f32, f32),
    fs: u32,
    right: i64,
) {
    let (Some([x, y, _]), Some([ex0, _, ex1, ey1])) = (part.position, part.extent()) else {
        return;
    };
    let mut paint = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    paint.set_color(colour(PART_COLOUR));
    let stroke = Stroke {
        width: fs as f32,
        ..Stroke::default()
    };
    let path = if part.outline.len() >= 2 {
        polyline(part.outline.iter().map(|&p| to_px(p)), true)
    } else {
        let (u, v) = to_px([x, y]);
        let half = 3.0 * fs as f32;
        Rect::from_xywh(u - half, v - half, 2.0 * half, 2.0 * half).map(PathBuilder::from_rect)
    };
    if let Some(path) = path {
        pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
    }
    let (u, v) = to_px([(ex0 + ex1) / 2.0, ey1]);
    let w = text::width(&part.name, fs) as f32;
    text::draw(
        pixmap,
        (u - w / 2.0).round() as i64,
        (v - ((GLYPH + 2) * fs) as f32).round() as i64,
        fs,
        right,
        PART_COLOUR,
        &part.name,
    );
}

fn colour(rgb: [u8; 3]) -> tiny_skia::Color {
    tiny_skia::Color::from_rgba8(rgb[0], rgb[1], rgb[2], 255)
}

/// The PNG bytes of the side view of `preview` onto the plane of `axis` and Z, `width` pixels
/// wide (the height follows the print's aspect, at least 16 and at most 4·`width` pixels):
/// planar extrusions grey, curved ones highlighted and drawn last, each at least a pixel wide;
/// machine-placed parts as boxes ([`side_box`]) with their names above.
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
    let to_px = |across: f64, z: f64| {
        (
            pad + (across - a0) as f32 * scale,
            height as f32 - pad - (z - z0) as f32 * scale,
        )
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
                let points = s
                    .points
                    .iter()
                    .zip(&s.z)
                    .map(|(p, &z)| to_px(axis.across(*p), z));
                if let Some(path) = polyline(points, false) {
                    pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
                }
            }
        }
    }
    // The parts: boxes with their names above.
    let fs = font_scale(width / 2);
    paint.set_color(colour(PART_COLOUR));
    let part_stroke = Stroke {
        width: fs as f32,
        ..Stroke::default()
    };
    // Boxes in pixels: (part, left, top, right, bottom).
    let boxes: Vec<(&PartMark, [f32; 4])> = preview
        .parts
        .iter()
        .filter_map(|part| {
            let [b0, bz0, b1, bz1] = side_box(preview, part, axis)?;
            let ((u0, v1), (u1, v0)) = (to_px(b0, bz1), to_px(b1, bz0));
            Some((part, [u0, v1, u1.max(u0 + 1.0), v0.max(v1 + 1.0)]))
        })
        .collect();
    for (_, [l, t, r, b]) in &boxes {
        if let Some(rect) = Rect::from_ltrb(*l, *t, *r, *b) {
            let path = PathBuilder::from_rect(rect);
            pixmap.stroke_path(&path, &paint, &part_stroke, Transform::identity(), None);
        }
    }
    // Names above the boxes; names side by side in this view one above the other.
    let spans: Vec<[f64; 2]> = boxes
        .iter()
        .map(|(part, [l, _, r, _])| {
            let half = f64::from(text::width(&part.name, fs) + 2 * fs) / 2.0;
            let mid = f64::from((l + r) / 2.0);
            [mid - half, mid + half]
        })
        .collect();
    let line = ((GLYPH + 2) * fs) as f32;
    for (((part, [l, _, r, _]), k), span) in boxes.iter().zip(label_rows(&spans)).zip(&spans) {
        // Above every box under the name.
        let top = boxes
            .iter()
            .filter(|(_, b)| f64::from(b[0]) < span[1] && span[0] < f64::from(b[2]))
            .map(|(_, b)| b[1])
            .fold(f32::MAX, f32::min);
        let w = text::width(&part.name, fs) as f32;
        let y = top - line * (k as f32 + 1.0);
        text::draw(
            &mut pixmap,
            ((l + r) / 2.0 - w / 2.0).round() as i64,
            y.round() as i64,
            fs,
            i64::from(width),
            PART_COLOUR,
            &part.name,
        );
    }
    pixmap
        .encode_png()
        .map_err(|e| PreviewError::Png(Box::new(e)))
}
