//! The parts a G-code file places, read back from its comments for the previews to label.
//!
//! conduit's G-code (and a host's file that `conduit postprocess` rewrote) marks each part
//! with an event comment where the print stops for it:
//!
//! - `;PICK_AND_PLACE PART=R1 X=137 Y=118 Z=4 ROTATION=0`: the machine places the part with
//!   its package origin at X, Y on the seating plane Z, turned by ROTATION degrees;
//! - `;MANUAL_INSERT PART=BAT1`: the print pauses for a part inserted by hand (no position).
//!
//! After the last layer, OctoPNP's part description gives each machine-placed part's outline
//! in the package frame and its height: `;<part id="2" name="R1">`, `;  <size height="0.6"/>`,
//! `;  <shape>` with `;    <point x="-1.45" y="-0.65"/>`…, and
//! `;  <destination x="137" y="118" z="4" orientation="0"/>`, up to `;</part>`.
//!
//! [`placed_parts`] pairs the two: each event becomes a [`PartMark`] on the printed layer that
//! follows it in the file (the layer of the next extruding move: the one printed over the
//! part), with its outline turned by its rotation about its position into bed coordinates.
//! Names in events have their spaces written as `_`; the description's names are matched so.
//! The comments are read by [`conduit_gcode::events`] and [`conduit_pnp::octopnp::read_block`].
//! Malformed comments are skipped, never an error: the previews draw what they can read.

use conduit_gcode::{Gcode, Moves};

use conduit_gcode::events::part_events;
use conduit_pnp::octopnp::read_block;

/// How a part gets into the print.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartMethod {
    /// Placed by the machine (`;PICK_AND_PLACE`), at a known position.
    Machine,
    /// Inserted by hand during a pause (`;MANUAL_INSERT`); no position in the file.
    Hand,
}

/// One part event of a G-code file, as the previews draw it.
#[derive(Debug, Clone, PartialEq)]
pub struct PartMark {
    /// The part's name as the event writes it (spaces as `_`).
    pub name: String,
    /// Machine-placed or inserted by hand.
    pub method: PartMethod,
    /// 0-based printed layer the part is placed before (the layer of the next extruding move).
    pub layer: usize,
    /// 1-based line of the event in the file.
    pub line: usize,
    /// Package origin on the seating plane [X, Y, Z], mm (`None` for a part inserted by hand).
    pub position: Option<[f64; 3]>,
    /// Rotation about Z, degrees (0 for a part inserted by hand).
    pub rotation_deg: f64,
    /// Outline in bed coordinates [X, Y], mm: the description's shape turned by the rotation
    /// about the position; empty when the file does not describe the part.
    pub outline: Vec<[f64; 2]>,
    /// Body height above the seating plane, mm (from the description), if known.
    pub height: Option<f64>,
}

impl PartMark {
    /// Extent of the outline, or of the position alone without one: [min X, min Y, max X,
    /// max Y], mm (`None` for a part inserted by hand).
    pub fn extent(&self) -> Option<[f64; 4]> {
        let [x, y, _] = self.position?;
        let mut b = [x, y, x, y];
        for p in &self.outline {
            b = [
                b[0].min(p[0]),
                b[1].min(p[1]),
                b[2].max(p[0]),
                b[3].max(p[1]),
            ];
        }
        Some(b)
    }
}

/// The part events of `gcode`, in file order, each on the layer of `moves` it is placed before
/// (see the module doc). `moves` must be the replay of `gcode` (its move lines index `gcode`).
pub fn placed_parts(gcode: &Gcode, moves: &Moves) -> Vec<PartMark> {
    // A description that is not well-formed XML gives no outlines; the events are still drawn.
    let described = read_block(gcode.lines.iter().map(|l| &l.text[..])).unwrap_or_default();
    let mut marks = Vec::new();
    for event in part_events(gcode) {
        let (method, position, rotation_deg) = if event.machine {
            let [Some(x), Some(y), Some(z)] = event.at else {
                continue;
            };
            (
                PartMethod::Machine,
                Some([x, y, z]),
                event.rotation.unwrap_or(0.0),
            )
        } else {
            (PartMethod::Hand, None, 0.0)
        };
        let mut mark = PartMark {
            layer: moves.next_extruding_layer(event.line),
            line: event.line,
            name: event.part,
            method,
            position,
            rotation_deg,
            outline: Vec::new(),
            height: None,
        };
        if let (Some([x, y, _]), Some(d)) = (
            mark.position,
            described
                .iter()
                .find(|d| d.name.replace(' ', "_") == mark.name),
        ) {
            mark.outline = d.outline_at([x, y], mark.rotation_deg);
            mark.height = Some(d.height).filter(|h| *h > 0.0);
        }
        marks.push(mark);
    }
    marks
}

#[cfg(test)]
mod tests {
    use super::*;
    use conduit_gcode::{Firmware, moves};

    /// Two layers; a part placed by the machine before layer 2, one by hand after it, and the
    /// description of the first (a 2 × 1 mm outline turned by 90°).
    const EVENTS: &str = ";LAYER_CHANGE\n;Z:0.2\nG1 Z0.2\nG1 X0 Y0\nG1 X10 Y0 E1\n\
        ;LAYER_CHANGE\n;Z:0.4\nG1 Z0.4\n;PICK_AND_PLACE PART=R_1 X=5 Y=6 Z=0.2 ROTATION=90\n\
        G1 X0 Y0\nG1 X10 Y0 E2\n;MANUAL_INSERT PART=BAT1\n;PICK_AND_PLACE PART=Q1 X=oops\n\
        ;<object name=\"o\">\n;<part id=\"1\" name=\"R 1\">\n;  <size height=\"0.6\"/>\n\
        ;  <shape>\n;    <point x=\"-1\" y=\"-0.5\"/>\n;    <point x=\"1\" y=\"-0.5\"/>\n\
        ;    <point x=\"1\" y=\"0.5\"/>\n;  </shape>\n\
        ;  <destination x=\"5\" y=\"6\" z=\"0.2\" orientation=\"90\"/>\n;</part>\n;</object>\n";

    #[test]
    fn events_are_read_with_their_layer_and_turned_outline() {
        let g = conduit_gcode::parse(EVENTS.as_bytes()).expect("parses");
        let m = moves(&g, Firmware::Marlin);
        assert_eq!(m.layer_z, vec![0.2, 0.4]);
        let parts = placed_parts(&g, &m);
        assert_eq!(parts.len(), 2, "{parts:?}");
        let r1 = &parts[0];
        assert_eq!(
            (r1.name.as_str(), r1.method, r1.layer, r1.line),
            ("R_1", PartMethod::Machine, 1, 9)
        );
        assert_eq!(
            (r1.position, r1.rotation_deg),
            (Some([5.0, 6.0, 0.2]), 90.0)
        );
        assert_eq!(r1.height, Some(0.6));
        let rounded: Vec<[f64; 2]> = r1
            .outline
            .iter()
            .map(|p| p.map(|v| (v * 1000.0).round() / 1000.0))
            .collect();
        // (u, v) turned by 90° is (−v, u), about (5, 6).
        assert_eq!(rounded, vec![[5.5, 5.0], [5.5, 7.0], [4.5, 7.0]]);
        assert_eq!(r1.extent(), Some([4.5, 5.0, 5.5, 7.0]));
        // After the last extrusion: the last layer.
        let bat = &parts[1];
        assert_eq!(
            (bat.name.as_str(), bat.method, bat.layer, bat.position),
            ("BAT1", PartMethod::Hand, 1, None)
        );
        assert!(bat.outline.is_empty() && bat.extent().is_none());
    }
}
