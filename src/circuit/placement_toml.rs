//! A placement written as the TOML a user edits (the form [`Placement::from_toml`] reads):
//! what `conduit place` hands over.
//!
//! Place in the pipeline: the last step of `conduit place`; the file it writes is the
//! `--placement` of `slice`, `route`, `postprocess` and `check`. Every part gets a comment line
//! (value, package, where it came from) and every key the reader knows for a part seated
//! upright, so the file shows what can be changed; numbers are written to 0.1 µm.

use std::fmt::Write as _;

use super::placement::{Connection, Origin, Placement, PlacingMethod};

/// A number as TOML float: at most four decimals, trailing zeros dropped, always with a
/// decimal point, never `-0.0`.
pub fn toml_number(v: f64) -> String {
    let rounded = (v * 1e4).round() / 1e4;
    let rounded = if rounded == 0.0 { 0.0 } else { rounded };
    let mut s = format!("{rounded:.4}");
    while s.ends_with('0') && !s.ends_with(".0") {
        s.pop();
    }
    s
}

/// A TOML basic string.
pub fn toml_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04X}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The placement as TOML: `header` lines first (each written as a `#` comment), then
/// `origin` and `source`, then one `[[part]]` table per part preceded by its comment from
/// `comment` (a `#` line when it returns one). Nets with routing hints are written too.
pub fn placement_toml(
    placement: &Placement,
    header: &[String],
    comment: impl Fn(&str) -> Option<String>,
) -> String {
    let mut out = String::new();
    for line in header {
        let _ = writeln!(out, "# {line}");
    }
    if !header.is_empty() {
        out.push('\n');
    }
    let origin = match placement.origin {
        Origin::Model => "model",
        Origin::BboxCenter => "bbox_center",
    };
    let _ = writeln!(out, "origin = \"{origin}\"");
    if let Some(source) = &placement.source {
        let _ = writeln!(out, "source = {}", toml_string(source));
    }
    for p in &placement.parts {
        out.push('\n');
        if let Some(c) = comment(&p.name) {
            let _ = writeln!(out, "# {c}");
        }
        let method = match p.method {
            PlacingMethod::Auto => "auto",
            PlacingMethod::Manual => "manual",
            PlacingMethod::None => "none",
        };
        let _ = writeln!(out, "[[part]]\nname = {}", toml_string(&p.name));
        for (key, v) in [("x", p.x), ("y", p.y), ("z", p.z), ("rotation", p.rotation)] {
            let _ = writeln!(out, "{key} = {}", toml_number(v));
        }
        let _ = writeln!(out, "method = \"{method}\"");
        let _ = writeln!(out, "body_height = {}", toml_number(p.body_height));
        if p.footprint_height > 0.0 {
            let _ = writeln!(
                out,
                "footprint_height = {}",
                toml_number(p.footprint_height)
            );
        }
        if let Some([w, l]) = p.body_size {
            let _ = writeln!(out, "body_size = [{}, {}]", toml_number(w), toml_number(l));
        }
        if p.tilt != [0.0; 2] {
            let _ = writeln!(
                out,
                "tilt = [{}, {}]",
                toml_number(p.tilt[0]),
                toml_number(p.tilt[1])
            );
        }
        if p.mirror {
            out.push_str("mirror = true\n");
        }
        let connection = match p.connection {
            Connection::None => None,
            Connection::Layer => Some("layer"),
            Connection::Part => Some("part"),
        };
        if let Some(c) = connection {
            let _ = writeln!(out, "connection = \"{c}\"");
        }
        if p.object != 0 {
            let _ = writeln!(out, "object = {}", p.object);
        }
    }
    for n in &placement.nets {
        let _ = writeln!(out, "\n[[net]]\nname = {}", toml_string(&n.name));
        if !n.waypoints.is_empty() {
            out.push_str("waypoints = [\n");
            for w in &n.waypoints {
                let _ = write!(
                    out,
                    "  {{ name = {}, x = {}, y = {}, z = {}",
                    toml_string(&w.name),
                    toml_number(w.x),
                    toml_number(w.y),
                    toml_number(w.z)
                );
                if w.object != 0 {
                    let _ = write!(out, ", object = {}", w.object);
                }
                out.push_str(" },\n");
            }
            out.push_str("]\n");
        }
        if !n.wires.is_empty() {
            out.push_str("wires = [\n");
            for [a, b] in &n.wires {
                let _ = writeln!(
                    out,
                    "  [{}, {}],",
                    toml_string(&a.to_string()),
                    toml_string(&b.to_string())
                );
            }
            out.push_str("]\n");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::circuit::placement::{Endpoint, NetRouting, PartPlacement, Waypoint};

    #[test]
    fn numbers_are_floats_to_a_tenth_of_a_micrometre() {
        assert_eq!(toml_number(10.0), "10.0");
        assert_eq!(toml_number(-0.00001), "0.0");
        assert_eq!(toml_number(1.23456), "1.2346");
        assert_eq!(toml_number(-2.5), "-2.5");
        assert_eq!(toml_number(90.0), "90.0");
    }

    #[test]
    fn a_written_placement_reads_back_the_same() {
        let part = |name: &str, x: f64| PartPlacement {
            name: name.into(),
            x,
            y: -3.25,
            z: 1.2,
            rotation: 270.0,
            tilt: [0.0; 2],
            mirror: false,
            method: PlacingMethod::Manual,
            connection: Connection::Layer,
            body_height: 1.5,
            footprint_height: 0.2,
            body_size: Some([2.0, 1.25]),
            object: 1,
        };
        let placement = Placement {
            origin: Origin::BboxCenter,
            source: Some("a \"b\".sch".into()),
            parts: vec![part("R1", 10.5), part("LED\\2", -0.125)],
            nets: vec![NetRouting {
                name: "VCC".into(),
                waypoints: vec![Waypoint {
                    name: "t".into(),
                    x: 1.0,
                    y: 2.0,
                    z: 3.0,
                    object: 1,
                }],
                wires: vec![[
                    Endpoint::from("R1.1".to_owned()),
                    Endpoint::from("t".to_owned()),
                ]],
            }],
            skipped: Vec::new(),
        };
        let text = placement_toml(&placement, &["made by a test".into()], |n| {
            Some(format!("{n}: a part"))
        });
        assert!(
            text.starts_with("# made by a test\n\norigin = \"bbox_center\"\n"),
            "{text}"
        );
        assert!(text.contains("# LED\\2: a part\n[[part]]\n"), "{text}");
        let back = Placement::from_toml(&text).expect("reads back");
        assert_eq!(back, placement);
    }
}
