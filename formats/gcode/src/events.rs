//! Part events as a G-code file carries them: the comment markers conduit writes where a part
//! goes in, read back by the checks, post-processing and the previews.
//!
//! The reader side of the markers conduit's G-code writer puts in:
//! `;PICK_AND_PLACE PART=<name> X=<x> Y=<y> Z=<z> ROTATION=<deg>` before a machine placement
//! and `;MANUAL_INSERT PART=<name>` before a pause for a person. Part names have their spaces
//! written as `_`.

use crate::Gcode;

/// One part event of a G-code file.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PartEvent {
    /// Part name as written (spaces as `_`).
    pub part: String,
    /// Placed by the machine (`PICK_AND_PLACE`), else by hand (`MANUAL_INSERT`).
    pub machine: bool,
    /// 1-based line of the marker.
    pub line: usize,
    /// Where the machine puts the package origin, bed mm (each `None` when not given).
    pub at: [Option<f64>; 3],
    /// Its rotation, degrees, when given.
    pub rotation: Option<f64>,
}

/// The event a comment's text names (`comment_text` of a line, without the `;`), with the
/// line number `line`; `None` for any other comment.
pub fn part_event(text: &str, line: usize) -> Option<PartEvent> {
    let (rest, machine) = if let Some(r) = text.strip_prefix("PICK_AND_PLACE PART=") {
        (r, true)
    } else if let Some(r) = text.strip_prefix("MANUAL_INSERT PART=") {
        (r, false)
    } else {
        return None;
    };
    let mut words = rest.split_whitespace();
    let part = words.next()?.to_owned();
    let mut at = [None; 3];
    let mut rotation = None;
    for w in words {
        for (k, axis) in ["X=", "Y=", "Z="].iter().enumerate() {
            if let Some(v) = w.strip_prefix(axis) {
                at[k] = v.parse::<f64>().ok().filter(|v| v.is_finite());
            }
        }
        if let Some(v) = w.strip_prefix("ROTATION=") {
            rotation = v.parse::<f64>().ok().filter(|v| v.is_finite());
        }
    }
    Some(PartEvent {
        part,
        machine,
        line,
        at,
        rotation,
    })
}

/// Every part event of `gcode`, in file order.
pub fn part_events(gcode: &Gcode) -> Vec<PartEvent> {
    gcode
        .lines
        .iter()
        .enumerate()
        .filter_map(|(i, l)| part_event(l.comment_text()?, i + 1))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_markers_are_read_with_their_values() {
        let g = crate::parse(
            b"G1 X1\n;PICK_AND_PLACE PART=R1 X=137 Y=118.5 Z=4 ROTATION=90\nM0\n\
              ;MANUAL_INSERT PART=BAT_1\n; part R2 something else\n",
        )
        .expect("parses");
        let events = part_events(&g);
        assert_eq!(
            events,
            vec![
                PartEvent {
                    part: "R1".into(),
                    machine: true,
                    line: 2,
                    at: [Some(137.0), Some(118.5), Some(4.0)],
                    rotation: Some(90.0),
                },
                PartEvent {
                    part: "BAT_1".into(),
                    machine: false,
                    line: 4,
                    at: [None; 3],
                    rotation: None,
                }
            ]
        );
        assert_eq!(part_event("PICK_AND_PLACE PART=", 1), None);
        let odd = part_event("PICK_AND_PLACE PART=U1 X=nan Y=abc", 7).expect("named");
        assert_eq!(odd.at, [None; 3]);
    }
}
