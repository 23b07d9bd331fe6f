//! One layer of the routing view (`conduit route`) as SVG: the material left after cavities and
//! channels in grey, cavities outlined in orange, channels in light blue, traces in dark blue.
//!
//! Place in the pipeline: emit stage, drawing one [`RouteViewLayer`] that the route walk assembles; millimetre
//! user units, Y flipped so +Y is up, the same view box on every layer.

use std::fmt::Write;

use super::preview::svg::{escape, num};
use crate::geom::{ExPolygon, Point3, Polygon, unscaled};

/// One layer as `conduit route` draws it, bed coordinates: what the electronics stage made of
/// the layer.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteViewLayer {
    /// Top of the layer, mm.
    pub z: f64,
    /// The material left after cavities and channels, all objects.
    pub islands: Vec<ExPolygon>,
    /// Part cavities cut from this layer.
    pub cavities: Vec<ExPolygon>,
    /// Wire channels cut from this layer.
    pub channels: Vec<ExPolygon>,
    /// Conductive paths printed on this layer (traces and drops).
    pub traces: Vec<Vec<Point3>>,
    /// Pads seated on this layer's top: `PART.PAD` and the copper outline.
    pub pads: Vec<(String, Polygon)>,
}

/// Margin around the drawing, mm.
const MARGIN: f64 = 2.0;

/// `[min_x, min_y, max_x, max_y]` (mm) over the islands, cavities and traces of every layer.
pub fn view_box(layers: &[RouteViewLayer]) -> Option<[f64; 4]> {
    let mut b: Option<[f64; 4]> = None;
    let mut add = |x: f64, y: f64| {
        let r = b.get_or_insert([x, y, x, y]);
        *r = [r[0].min(x), r[1].min(y), r[2].max(x), r[3].max(y)];
    };
    for l in layers {
        for ex in l.islands.iter().chain(&l.cavities) {
            for p in &ex.contour.points {
                add(unscaled(p.x), unscaled(p.y));
            }
        }
        for t in &l.traces {
            for p in t {
                add(p.x, p.y);
            }
        }
    }
    b
}

fn ring(out: &mut String, poly: &Polygon) {
    for (i, p) in poly.points.iter().enumerate() {
        let cmd = if i == 0 { 'M' } else { 'L' };
        let _ = write!(out, "{cmd}{} {} ", num(unscaled(p.x)), num(-unscaled(p.y)));
    }
    out.push_str("Z ");
}

fn areas(out: &mut String, polys: &[ExPolygon], style: &str) {
    if polys.is_empty() {
        return;
    }
    let mut d = String::new();
    for ex in polys {
        ring(&mut d, &ex.contour);
        for h in &ex.holes {
            ring(&mut d, h);
        }
    }
    let _ = writeln!(
        out,
        "<path fill-rule=\"evenodd\" {style} d=\"{}\"/>",
        d.trim_end()
    );
}

/// The SVG of `layer` over `view` (from [`view_box`]), traces drawn `trace_width` mm wide.
pub fn layer_svg(layer: &RouteViewLayer, view: [f64; 4], trace_width: f64) -> String {
    let (x0, y0) = (view[0] - MARGIN, -(view[3] + MARGIN));
    let (w, h) = (
        view[2] - view[0] + 2.0 * MARGIN,
        view[3] - view[1] + 2.0 * MARGIN,
    );
    let mut out = String::new();
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\" width=\"{}mm\" height=\"{}mm\">",
        num(x0),
        num(y0),
        num(w),
        num(h),
        num(w),
        num(h)
    );
    let _ = writeln!(out, "<title>z = {} mm</title>", num(layer.z));
    areas(
        &mut out,
        &layer.islands,
        "fill=\"#d9d9d9\" stroke=\"#888888\" stroke-width=\"0.05\"",
    );
    areas(
        &mut out,
        &layer.channels,
        "fill=\"#8ecae6\" stroke=\"none\"",
    );
    areas(
        &mut out,
        &layer.cavities,
        "fill=\"none\" stroke=\"#e07000\" stroke-width=\"0.15\" stroke-dasharray=\"0.6 0.3\"",
    );
    for (name, outline) in &layer.pads {
        let pts: Vec<String> = outline
            .points
            .iter()
            .map(|p| format!("{},{}", num(unscaled(p.x)), num(-unscaled(p.y))))
            .collect();
        let _ = writeln!(
            out,
            "<polygon fill=\"#c88a2e\" stroke=\"none\" points=\"{}\"><title>{}</title></polygon>",
            pts.join(" "),
            escape(name)
        );
    }
    for t in &layer.traces {
        let pts: Vec<String> = t
            .iter()
            .map(|p| format!("{},{}", num(p.x), num(-p.y)))
            .collect();
        let _ = writeln!(
            out,
            "<polyline fill=\"none\" stroke=\"#005f99\" stroke-width=\"{}\" stroke-linecap=\"round\" stroke-linejoin=\"round\" points=\"{}\"/>",
            num(trace_width),
            pts.join(" ")
        );
    }
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Point2, Point3};

    #[test]
    fn a_layer_draws_its_material_cavity_channel_and_trace() {
        let square = |x0: f64, y0: f64, s: f64| ExPolygon {
            contour: Polygon::new(vec![
                Point2::from_mm(x0, y0),
                Point2::from_mm(x0 + s, y0),
                Point2::from_mm(x0 + s, y0 + s),
                Point2::from_mm(x0, y0 + s),
            ]),
            holes: vec![],
        };
        let layer = RouteViewLayer {
            z: 1.2,
            islands: vec![square(0.0, 0.0, 20.0)],
            cavities: vec![square(5.0, 5.0, 4.0)],
            channels: vec![square(12.0, 12.0, 1.0)],
            traces: vec![vec![
                Point3::new(1.0, 2.0, 1.2),
                Point3::new(18.0, 2.0, 1.2),
            ]],
            pads: vec![("R1.<1>".into(), square(17.5, 1.5, 1.0).contour)],
        };
        let view = view_box(std::slice::from_ref(&layer)).expect("something to draw");
        assert_eq!(view, [0.0, 0.0, 20.0, 20.0]);
        let svg = layer_svg(&layer, view, 0.6);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(svg.contains("viewBox=\"-2.000 -22.000 24.000 24.000\""));
        assert!(svg.contains("<title>z = 1.200 mm</title>"));
        assert_eq!(svg.matches("<path").count(), 3);
        assert!(svg.contains("points=\"1.000,-2.000 18.000,-2.000\""));
        assert!(svg.contains("M5.000 -5.000 L9.000 -5.000 L9.000 -9.000 L5.000 -9.000 Z"));
        assert!(svg.contains(
            "points=\"17.500,-1.500 18.500,-1.500 18.500,-2.500 17.500,-2.500\"><title>R1.&lt;1&gt;</title>"
        ));
    }
}
