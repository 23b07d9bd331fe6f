//! The SVG views. One layer: millimetre user units, Y flipped (SVG `y` is −Y) so +Y is up, the
//! view box over the extrusions of every layer plus a margin, a heading with the layer's
//! number and Z above the drawing, the parts placed before the layer outlined and named, and a
//! scale bar and the legend below. The side views: every extrusion projected onto a vertical
//! plane (SVG `y` is −Z), the parts as labelled boxes, a scale bar below. Both are
//! [`SCREEN_PX`] pixels on their longer side (`width`/`height`), the view box in millimetres.

use std::fmt::Write;

use super::{
    PART_COLOUR, PartMark, PartMethod, Preview, SCREEN_PX, SIDE_CURVED_COLOUR, SIDE_PLANAR_COLOUR,
    SideAxis, StrokeKind, TRAVEL_COLOUR, TRAVEL_WIDTH, label_rows, layer_heading, scale_bar_label,
    scale_bar_length,
};

/// Margin around the extrusions, mm.
const MARGIN: f64 = 2.0;

/// A number with exactly 3 decimals, never `-0.000`: every number in the SVG goes through here.
pub fn num(v: f64) -> String {
    let s = format!("{v:.3}");
    if s == "-0.000" { "0.000".to_owned() } else { s }
}

fn hex(rgb: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2])
}

/// `text` with the characters XML gives a meaning escaped, for text and attribute values.
pub(crate) fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(c),
        }
    }
    out
}

fn points(pts: &[[f64; 2]]) -> String {
    let mut s = String::with_capacity(pts.len() * 16);
    for (i, p) in pts.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        s.push_str(&num(p[0]));
        s.push(',');
        s.push_str(&num(-p[1]));
    }
    s
}

/// Writes the layer's extrusions and travels, each kind in its own group.
fn write_strokes(s: &mut String, preview: &Preview, layer: &super::LayerStrokes) {
    let _ = writeln!(
        s,
        r#"<g class="extrusions" fill="none" stroke-linecap="round" stroke-linejoin="round">"#
    );
    for stroke in &layer.strokes {
        if let StrokeKind::Extrusion { role, tool, width } = stroke.kind {
            let _ = writeln!(
                s,
                r#"<polyline data-role="{}" data-tool="{tool}" stroke="{}" stroke-width="{}" points="{}"/>"#,
                escape(&preview.roles[role]),
                hex(preview.colour(role, tool)),
                num(width),
                points(&stroke.points)
            );
        }
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(
        s,
        r#"<g class="travels" fill="none" stroke="{}" stroke-width="{}" stroke-linecap="round" stroke-linejoin="round">"#,
        hex(TRAVEL_COLOUR),
        num(TRAVEL_WIDTH)
    );
    for stroke in &layer.strokes {
        if stroke.kind == StrokeKind::Travel {
            let _ = writeln!(s, r#"<polyline points="{}"/>"#, points(&stroke.points));
        }
    }
    let _ = writeln!(s, "</g>");
}

/// The opening of an SVG whose view box is (`vx`, `vy`, `w`, `h`) mm, sized for a screen: the
/// longer side [`SCREEN_PX`] pixels.
fn open_svg(s: &mut String, vx: f64, vy: f64, w: f64, h: f64) {
    let px = SCREEN_PX / w.max(h).max(1e-9);
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}" viewBox="{} {} {} {}">"#,
        (w * px).round().max(1.0),
        (h * px).round().max(1.0),
        num(vx),
        num(vy),
        num(w),
        num(h)
    );
}

/// A scale bar for a drawing `extent` mm across, its left end at (`x`, `y`) (SVG units, the
/// bar's top): a bar of [`scale_bar_length`] with its ends ticked and its length written after
/// it.
fn scale_bar(s: &mut String, x: f64, y: f64, extent: f64, row: f64) {
    let length = scale_bar_length(extent);
    let thick = row * 0.2;
    let _ = writeln!(
        s,
        r##"<g class="scale-bar" fill="#000000" data-length="{}">"##,
        num(length)
    );
    let _ = writeln!(
        s,
        r#"<rect x="{}" y="{}" width="{}" height="{}"/>"#,
        num(x),
        num(y),
        num(length),
        num(thick)
    );
    for end in [x, x + length - thick * 0.5] {
        let _ = writeln!(
            s,
            r#"<rect x="{}" y="{}" width="{}" height="{}"/>"#,
            num(end),
            num(y - thick),
            num(thick * 0.5),
            num(thick * 3.0)
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" font-family="sans-serif" font-size="{}">{}</text>"#,
        num(x + length + row * 0.4),
        num(y + thick + row * 0.2),
        num(row * 0.7),
        scale_bar_label(length)
    );
    let _ = writeln!(s, "</g>");
}

/// Writes the outlines (a ring where the file gives none) and names of the machine-placed
/// `parts`, names above their outlines; `project` maps a point [X, Y] to SVG units.
fn write_parts<'a>(
    s: &mut String,
    parts: impl Iterator<Item = &'a PartMark>,
    row: f64,
    project: impl Fn([f64; 2]) -> [f64; 2],
) {
    let placed: Vec<&PartMark> = parts.filter(|p| p.position.is_some()).collect();
    if placed.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        r#"<g class="parts" fill="none" stroke="{}" stroke-width="{}">"#,
        hex(PART_COLOUR),
        num(row * 0.08)
    );
    for part in &placed {
        let Some([x, y, _]) = part.position else {
            continue;
        };
        if part.outline.len() >= 2 {
            let pts: Vec<String> = part
                .outline
                .iter()
                .map(|&p| {
                    let [u, v] = project(p);
                    format!("{},{}", num(u), num(v))
                })
                .collect();
            let _ = writeln!(
                s,
                r#"<polygon data-part="{}" points="{}"/>"#,
                escape(&part.name),
                pts.join(" ")
            );
        } else {
            let [u, v] = project([x, y]);
            let _ = writeln!(
                s,
                r#"<circle data-part="{}" cx="{}" cy="{}" r="{}"/>"#,
                escape(&part.name),
                num(u),
                num(v),
                num(row * 0.3)
            );
        }
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(
        s,
        r##"<g class="part-names" font-family="sans-serif" font-size="{}" text-anchor="middle" fill="{}" stroke="#ffffff" stroke-width="{}" paint-order="stroke">"##,
        num(row * 0.6),
        hex(PART_COLOUR),
        num(row * 0.12)
    );
    for part in &placed {
        let Some([x0, _, x1, y1]) = part.extent() else {
            continue;
        };
        // Above the outline: the top edge's middle, a little higher.
        let [u, v] = project([(x0 + x1) / 2.0, y1]);
        let _ = writeln!(
            s,
            r#"<text data-part="{}" x="{}" y="{}">{}</text>"#,
            escape(&part.name),
            num(u),
            num(v - row * 0.35),
            escape(&part.name)
        );
    }
    let _ = writeln!(s, "</g>");
}

/// The SVG of layer `index` (0-based) of `preview`: a heading with the layer's number and Z,
/// the drawing (with the parts placed before the layer outlined and named), then a scale bar
/// and the legend.
///
/// # Panics
///
/// When `index` is not a layer of `preview`.
pub fn layer(preview: &Preview, index: usize) -> String {
    let layer = &preview.layers[index];
    let [x0, y0, x1, y1] = preview.bounds;
    let (w, h) = (x1 - x0 + 2.0 * MARGIN, y1 - y0 + 2.0 * MARGIN);
    // Heading row above the drawing; below it the scale bar row, the role/tool entries (and
    // travel, and parts when the file places any) in columns across the width, and a row
    // naming the parts inserted by hand before this layer.
    // Text scales with the drawing: the file is shown SCREEN_PX wide or tall whatever its size
    // in mm, so a row is always about 1/30 of that on screen.
    let row = w.max(h) / 30.0;
    let font = row * 0.7;
    let col_w = row * 12.0;
    let columns = ((w / col_w).floor() as usize).max(1);
    let by_hand: Vec<&str> = preview
        .parts_on(index)
        .filter(|p| p.method == PartMethod::Hand)
        .map(|p| p.name.as_str())
        .collect();
    let entries = preview.styles.len() + 1 + usize::from(preview.has_placed_parts());
    let rows = 1 + entries.div_ceil(columns) + usize::from(!by_hand.is_empty());
    let head_h = row * 1.5;
    let legend_h = rows as f64 * row + row * 0.5;
    let (vx, vy, vh) = (x0 - MARGIN, -y1 - MARGIN - head_h, h + head_h + legend_h);

    let mut s = String::new();
    open_svg(&mut s, vx, vy, w, vh);
    let _ = writeln!(
        s,
        "<title>layer {} of {}, Z {} mm</title>",
        index + 1,
        preview.layers.len(),
        num(layer.z)
    );
    let _ = writeln!(
        s,
        r##"<rect x="{}" y="{}" width="{}" height="{}" fill="#ffffff"/>"##,
        num(vx),
        num(vy),
        num(w),
        num(vh)
    );
    // The heading fits the width of a narrow print (a bold sans-serif glyph is about 0.6 em).
    let heading = layer_heading(index, preview.layers.len(), layer.z);
    let head_font = (row * 0.9).min((w - MARGIN) / (heading.len() as f64 * 0.6));
    let _ = writeln!(
        s,
        r##"<text class="heading" x="{}" y="{}" font-family="sans-serif" font-size="{}" font-weight="bold" fill="#000000">{heading}</text>"##,
        num(x0),
        num(vy + row * 1.05),
        num(head_font)
    );
    write_strokes(&mut s, preview, layer);
    write_parts(&mut s, preview.parts_on(index), row, |[x, y]| [x, -y]);

    // Scale bar, then the legend.
    let top = -y0 + MARGIN;
    scale_bar(&mut s, x0, top + row * 0.4, x1 - x0, row);
    let _ = writeln!(
        s,
        r##"<g class="legend" font-family="sans-serif" font-size="{}" fill="#000000">"##,
        num(font)
    );
    let entry = |k: usize, swatch: String, label: String, s: &mut String| {
        let (c, r) = (k % columns, 1 + k / columns);
        let x = x0 + c as f64 * col_w;
        let y = top + r as f64 * row;
        let _ = writeln!(
            s,
            r#"<rect x="{}" y="{}" width="{}" height="{}" {swatch}/>"#,
            num(x),
            num(y + row * 0.25),
            num(row * 1.2),
            num(row * 0.6)
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}">{}</text>"#,
            num(x + row * 1.5),
            num(y + row * 0.8),
            escape(&label)
        );
    };
    for (k, &(role, tool)) in preview.styles.iter().enumerate() {
        entry(
            k,
            format!(r#"fill="{}""#, hex(preview.colour(role, tool))),
            preview.style_label(role, tool),
            &mut s,
        );
    }
    entry(
        preview.styles.len(),
        format!(r#"fill="{}""#, hex(TRAVEL_COLOUR)),
        "Travel".to_owned(),
        &mut s,
    );
    if preview.has_placed_parts() {
        entry(
            preview.styles.len() + 1,
            format!(
                r#"fill="none" stroke="{}" stroke-width="{}""#,
                hex(PART_COLOUR),
                num(row * 0.08)
            ),
            "Part outline".to_owned(),
            &mut s,
        );
    }
    if !by_hand.is_empty() {
        let _ = writeln!(
            s,
            r#"<text class="by-hand" x="{}" y="{}">Inserted by hand before this layer: {}</text>"#,
            num(x0),
            num(top + (rows - 1) as f64 * row + row * 0.8),
            escape(&by_hand.join(", "))
        );
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(s, "</svg>");
    s
}

/// Stroke width of the side views' lines, mm.
pub const SIDE_STROKE: f64 = 0.1;

/// The side view of `preview` onto the plane of `axis` and Z: every extrusion as a polyline of
/// (across, −Z) points, in file order. Planar extrusions are grey (`data-curved="false"`),
/// non-planar ones highlighted (`data-curved="true"`); each carries its layer
/// (`data-layer`, 1-based) and role. Each machine-placed part is a labelled box from its
/// seating plane up its height (to its layer's Z when the file gives no height); a scale bar
/// runs below.
pub fn side(preview: &Preview, axis: SideAxis) -> String {
    let [a0, z0, a1, z1] = preview.side_bounds(axis).unwrap_or([0.0, 0.0, 1.0, 1.0]);
    let (w, h) = (a1 - a0 + 2.0 * MARGIN, z1 - z0 + 2.0 * MARGIN);
    let row = w.max(h) / 30.0;
    let foot_h = row * 1.5;
    let (vx, vy, vh) = (a0 - MARGIN, -z1 - MARGIN, h + foot_h);
    let mut s = String::new();
    open_svg(&mut s, vx, vy, w, vh);
    let _ = writeln!(
        s,
        "<title>side view {}: {} layers, {} curved extrusions</title>",
        axis.name().to_uppercase(),
        preview.layers.len(),
        preview.curved_strokes()
    );
    let _ = writeln!(
        s,
        r##"<rect x="{}" y="{}" width="{}" height="{}" fill="#ffffff"/>"##,
        num(vx),
        num(vy),
        num(w),
        num(vh)
    );
    // Planar first, curved on top.
    for curved in [false, true] {
        let colour = if curved {
            SIDE_CURVED_COLOUR
        } else {
            SIDE_PLANAR_COLOUR
        };
        let _ = writeln!(
            s,
            r#"<g class="{}" fill="none" stroke="{}" stroke-width="{}" stroke-linecap="round" stroke-linejoin="round">"#,
            if curved { "curved" } else { "planar" },
            hex(colour),
            num(SIDE_STROKE)
        );
        for (i, layer) in preview.layers.iter().enumerate() {
            for stroke in layer.strokes.iter().filter(|st| st.curved == curved) {
                let StrokeKind::Extrusion { role, .. } = stroke.kind else {
                    continue;
                };
                let mut pts = String::with_capacity(stroke.points.len() * 16);
                for (k, (p, &z)) in stroke.points.iter().zip(&stroke.z).enumerate() {
                    if k > 0 {
                        pts.push(' ');
                    }
                    pts.push_str(&num(axis.across(*p)));
                    pts.push(',');
                    pts.push_str(&num(-z));
                }
                let _ = writeln!(
                    s,
                    r#"<polyline data-layer="{}" data-curved="{curved}" data-role="{}" points="{pts}"/>"#,
                    i + 1,
                    escape(&preview.roles[role])
                );
            }
        }
        let _ = writeln!(s, "</g>");
    }
    write_part_boxes(&mut s, preview, axis, row);
    scale_bar(&mut s, a0, -z0 + MARGIN + row * 0.4, a1 - a0, row);
    let _ = writeln!(s, "</svg>");
    s
}

/// Writes each machine-placed part of `preview` as a box in the side view onto `axis`: across
/// its outline's extent, from its seating plane up its [`side_box`], with its name above.
fn write_part_boxes(s: &mut String, preview: &Preview, axis: SideAxis, row: f64) {
    let boxes: Vec<(&PartMark, [f64; 4])> = preview
        .parts
        .iter()
        .filter_map(|p| Some((p, side_box(preview, p, axis)?)))
        .collect();
    if boxes.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        r#"<g class="parts" fill="none" stroke="{}" stroke-width="{}">"#,
        hex(PART_COLOUR),
        num(SIDE_STROKE * 2.0)
    );
    for (part, [b0, bz0, b1, bz1]) in &boxes {
        let _ = writeln!(
            s,
            r#"<rect data-part="{}" data-layer="{}" x="{}" y="{}" width="{}" height="{}"/>"#,
            escape(&part.name),
            part.layer + 1,
            num(*b0),
            num(-bz1),
            num(b1 - b0),
            num(bz1 - bz0)
        );
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(
        s,
        r##"<g class="part-names" font-family="sans-serif" font-size="{}" text-anchor="middle" fill="{}" stroke="#ffffff" stroke-width="{}" paint-order="stroke">"##,
        num(row * 0.6),
        hex(PART_COLOUR),
        num(row * 0.12)
    );
    // Names of parts side by side in this view go one above the other (a sans-serif glyph
    // is about 0.6 em wide).
    let spans: Vec<[f64; 2]> = boxes
        .iter()
        .map(|(part, [b0, _, b1, _])| {
            let half = part.name.chars().count() as f64 * row * 0.6 * 0.3 + row * 0.1;
            [(b0 + b1) / 2.0 - half, (b0 + b1) / 2.0 + half]
        })
        .collect();
    for (((part, [b0, _, b1, _]), k), span) in boxes.iter().zip(label_rows(&spans)).zip(&spans) {
        // Above every box under the name.
        let z = boxes
            .iter()
            .filter(|(_, b)| b[0] < span[1] && span[0] < b[2])
            .map(|(_, b)| b[3])
            .fold(f64::MIN, f64::max);
        let _ = writeln!(
            s,
            r#"<text data-part="{}" x="{}" y="{}">{}</text>"#,
            escape(&part.name),
            num((b0 + b1) / 2.0),
            num(-z - row * 0.3 - k as f64 * row * 0.7),
            escape(&part.name)
        );
    }
    let _ = writeln!(s, "</g>");
}

/// The box of a machine-placed `part` in the side view onto `axis`: [min across, seating Z, max
/// across, top Z], mm; `None` for a part inserted by hand. Its top is the seating plane plus
/// its height, or its layer's Z when the file gives no height (at least 0.1 mm up).
pub fn side_box(preview: &Preview, part: &PartMark, axis: SideAxis) -> Option<[f64; 4]> {
    let [x0, y0, x1, y1] = part.extent()?;
    let [_, _, z] = part.position?;
    let (lo, hi) = match axis {
        SideAxis::X => (x0, x1),
        SideAxis::Y => (y0, y1),
    };
    let layer_z = preview.layers.get(part.layer).map_or(z, |l| l.z);
    let top = z + part.height.unwrap_or(layer_z - z).max(0.1);
    Some([lo, z, hi, top])
}
