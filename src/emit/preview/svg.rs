//! One layer as SVG: millimetre user units, Y flipped (SVG `y` is −Y) so +Y is up, the view box
//! over the extrusions of every layer plus a margin, and a legend below the drawing; and the
//! side views, every extrusion projected onto a vertical plane (SVG `y` is −Z).

use std::fmt::Write;

use super::{
    Preview, SIDE_CURVED_COLOUR, SIDE_PLANAR_COLOUR, SideAxis, StrokeKind, TRAVEL_COLOUR,
    TRAVEL_WIDTH,
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

/// The SVG of layer `index` (0-based) of `preview`.
///
/// # Panics
///
/// When `index` is not a layer of `preview`.
pub fn layer(preview: &Preview, index: usize) -> String {
    let layer = &preview.layers[index];
    let [x0, y0, x1, y1] = preview.bounds;
    let (w, h) = (x1 - x0 + 2.0 * MARGIN, y1 - y0 + 2.0 * MARGIN);
    // Legend: a title row, then the role/tool entries and travel, in columns across the width.
    let row = (w.max(h) / 30.0).max(1.0);
    let font = row * 0.7;
    let col_w = row * 12.0;
    let columns = ((w / col_w).floor() as usize).max(1);
    let entries = preview.styles.len() + 1;
    let rows = 1 + entries.div_ceil(columns);
    let legend_h = rows as f64 * row + row * 0.5;
    let (vx, vy, vh) = (x0 - MARGIN, -y1 - MARGIN, h + legend_h);
    let multi_tool = preview
        .styles
        .iter()
        .any(|&(_, t)| t != preview.styles[0].1);

    let mut s = String::new();
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}mm" height="{}mm" viewBox="{} {} {} {}">"#,
        num(w),
        num(vh),
        num(vx),
        num(vy),
        num(w),
        num(vh)
    );
    let title = format!(
        "layer {} of {}, Z {} mm",
        index + 1,
        preview.layers.len(),
        num(layer.z)
    );
    let _ = writeln!(s, "<title>{title}</title>");
    let _ = writeln!(
        s,
        r##"<rect x="{}" y="{}" width="{}" height="{}" fill="#ffffff"/>"##,
        num(vx),
        num(vy),
        num(w),
        num(vh)
    );
    write_strokes(&mut s, preview, layer);

    // Legend.
    let top = -y0 + MARGIN;
    let _ = writeln!(
        s,
        r##"<g class="legend" font-family="sans-serif" font-size="{}" fill="#000000">"##,
        num(font)
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}">{title}</text>"#,
        num(x0),
        num(top + row * 0.8)
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
        let label = if multi_tool {
            format!("{} (T{tool})", preview.roles[role])
        } else {
            preview.roles[role].clone()
        };
        entry(
            k,
            format!(r#"fill="{}""#, hex(preview.colour(role, tool))),
            label,
            &mut s,
        );
    }
    entry(
        preview.styles.len(),
        format!(r#"fill="{}""#, hex(TRAVEL_COLOUR)),
        "Travel".to_owned(),
        &mut s,
    );
    let _ = writeln!(s, "</g>");
    let _ = writeln!(s, "</svg>");
    s
}

/// Stroke width of the side views' lines, mm.
pub const SIDE_STROKE: f64 = 0.1;

/// The side view of `preview` onto the plane of `axis` and Z: every extrusion as a polyline of
/// (across, −Z) points, in file order. Planar extrusions are grey (`data-curved="false"`),
/// non-planar ones highlighted (`data-curved="true"`); each carries its layer
/// (`data-layer`, 1-based) and role.
pub fn side(preview: &Preview, axis: SideAxis) -> String {
    let [a0, z0, a1, z1] = preview.side_bounds(axis).unwrap_or([0.0, 0.0, 1.0, 1.0]);
    let (w, h) = (a1 - a0 + 2.0 * MARGIN, z1 - z0 + 2.0 * MARGIN);
    let (vx, vy) = (a0 - MARGIN, -z1 - MARGIN);
    let mut s = String::new();
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}mm" height="{}mm" viewBox="{} {} {} {}">"#,
        num(w),
        num(h),
        num(vx),
        num(vy),
        num(w),
        num(h)
    );
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
        num(h)
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
    let _ = writeln!(s, "</svg>");
    s
}
