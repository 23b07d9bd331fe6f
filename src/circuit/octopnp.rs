//! OctoPNP's part description: the XML that the OctoPrint plugin OctoPNP reads from comment
//! lines of a G-code file to answer `M361 P<id>` (which tray box to pick from, how tall the
//! part is, its outline and pads for the camera alignment, and where it goes).
//!
//! Place in the pipeline: written from the placed parts (bed coordinates) and the circuit's
//! packages by the slice walk, after the G-code, and by the post-processing walk inside the
//! host's rewritten file, after the last layer's last extrusion and before the host's end
//! G-code (`crate::postprocess::rewrite`), so that every line of the host stays where it was.
//! OctoPNP collects the text between the first `<` and the last `>` of *every* line of the file
//! ([`collected`]), so the block must be the only text of the file in angle brackets; it starts
//! with the `<object>` root, as OctoPNP expects on the first line it collects. conduit writes no
//! other such text; a host's own lines may (PrusaSlicer's settings at the end of its file hold
//! the custom G-code templates), and post-processing warns when they do.
//!
//! Per part the machine places (`method = "auto"`), in placement order:
//! `<part id name>` with `id` the number its `M361 P<id>` event carries, `<position box>` the
//! tray box (1, 2, … in the same order: load the tray so), `<size height>` the body height,
//! `<shape>` the outline's corners and `<pads>` each pad's bounding rectangle (`x1 y1 x2 y2`),
//! both in the package frame (mm, unrotated), and `<destination x y z orientation>` the
//! package origin on the seating plane in bed coordinates and its rotation in degrees.

use std::fmt::Write as _;

use super::{Circuit, PlacedPart, PlacingMethod};

/// The OctoPNP block for `parts` (bed coordinates, placement order) of `circuit`, as `;`
/// comment lines, or an empty string when no part is placed by the machine. `name` names the
/// `<object>`.
pub fn octopnp_block(circuit: &Circuit, parts: &[PlacedPart], name: &str) -> String {
    let auto: Vec<(usize, &PlacedPart)> = parts
        .iter()
        .enumerate()
        .filter(|(_, p)| p.method == PlacingMethod::Auto)
        .collect();
    if auto.is_empty() {
        return String::new();
    }
    let mut out = format!(";<object name=\"{}\">\n", attr(name));
    for (box_number, (index, part)) in auto.iter().enumerate() {
        let _ = writeln!(
            out,
            ";<part id=\"{}\" name=\"{}\">",
            index + 1,
            attr(&part.name)
        );
        let _ = writeln!(out, ";  <position box=\"{}\"/>", box_number + 1);
        let _ = writeln!(out, ";  <size height=\"{}\"/>", num(part.body_height));
        out.push_str(";  <shape>\n");
        for [x, y] in package_outline(part) {
            let _ = writeln!(out, ";    <point x=\"{}\" y=\"{}\"/>", num(x), num(y));
        }
        out.push_str(";  </shape>\n;  <pads>\n");
        let pads = circuit.part(&part.name).map_or(&[][..], |c| &c.pads[..]);
        for pad in pads {
            let [x1, y1, x2, y2] = pad.extent();
            let _ = writeln!(
                out,
                ";    <pad x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>",
                num(x1),
                num(y1),
                num(x2),
                num(y2)
            );
        }
        out.push_str(";  </pads>\n");
        let _ = writeln!(
            out,
            ";  <destination x=\"{}\" y=\"{}\" z=\"{}\" orientation=\"{}\"/>",
            num(part.position.x),
            num(part.position.y),
            num(part.position.z),
            num(part.rotation_deg.rem_euclid(360.0))
        );
        out.push_str(";</part>\n");
    }
    out.push_str(";</object>\n");
    out
}

/// The part's outline (its footprint: pads and body) turned back into the package frame:
/// moved to the package origin, rotated by minus its rotation, mirrored back for a bottom-side
/// part.
fn package_outline(part: &PlacedPart) -> Vec<[f64; 2]> {
    let (s, c) = (-part.rotation_deg).to_radians().sin_cos();
    let mirror = if part.mirror { -1.0 } else { 1.0 };
    part.footprint
        .points_mm()
        .into_iter()
        .map(|[x, y]| {
            let (dx, dy) = (x - part.position.x, y - part.position.y);
            [mirror * (dx * c - dy * s), dx * s + dy * c]
        })
        .collect()
}

pub use conduit_pnp::octopnp::{OctoPart, collected, read_block};

/// A number with up to 4 decimals (trailing zeros dropped), `-0` as `0`.
fn num(v: f64) -> String {
    let s = format!("{:.4}", v);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    match s {
        "-0" | "" => "0".to_owned(),
        s => s.to_owned(),
    }
}

/// `s` for a double-quoted XML attribute.
fn attr(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '&' => "&amp;".to_owned(),
            '<' => "&lt;".to_owned(),
            '>' => "&gt;".to_owned(),
            '"' => "&quot;".to_owned(),
            c if c.is_control() => " ".to_owned(),
            c => c.to_string(),
        })
        .collect()
}
