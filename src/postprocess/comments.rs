//! The structured comments host slicers write into their G-code, recognised one line at a time.
//!
//! Place in the pipeline: the first look at each line of a host file; [`super::layers`] drives
//! its layer and role state from what [`read_comment`] finds. Nothing here keeps state.
//!
//! | meaning | PrusaSlicer, SuperSlicer | OrcaSlicer, BambuStudio | Cura | Slic3r 1.3 `--gcode-comments` | Simplify3D |
//! |---|---|---|---|---|---|
//! | layer starts | `;LAYER_CHANGE` | `; CHANGE_LAYER` | `;LAYER:<n>` | `; move to next layer (<n>)` after a `G1 Z` | `; layer <n>, Z = <z>` |
//! | layer z | `;Z:<z>` | `; Z_HEIGHT: <z>` | (from the moves) | (from the move) | in the marker |
//! | layer height | `;HEIGHT:<h>` | `; LAYER_HEIGHT: <h>` | | | |
//! | feature | `;TYPE:<role>` | `; FEATURE: <role>` | `;TYPE:<ROLE>` | `; <role>` after each move | `; feature <role>` |
//! | width | `;WIDTH:<w>` | `; LINE_WIDTH: <w>` | | | |
//! | layer count | | `; total layer number: <n>` | `;LAYER_COUNT:<n>` | | |

use conduit_gcode::Line;
use serde::Serialize;

/// Which comment convention marks a layer change.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum LayerMarker {
    /// `;LAYER_CHANGE` (PrusaSlicer, SuperSlicer, OrcaSlicer).
    LayerChange,
    /// `; CHANGE_LAYER` (OrcaSlicer, BambuStudio).
    ChangeLayer,
    /// `;LAYER:<n>` (Cura).
    LayerNumber,
    /// `; move to next layer (<n>)` on the layer's `G1 Z` move (Slic3r with `--gcode-comments`).
    MoveToNextLayer,
    /// `; layer <n>, Z = <z>` (Simplify3D).
    LayerWithZ,
}

impl LayerMarker {
    /// The comment as a pattern, for messages: `;LAYER_CHANGE`, `;LAYER:<n>`...
    pub fn pattern(self) -> &'static str {
        match self {
            LayerMarker::LayerChange => ";LAYER_CHANGE",
            LayerMarker::ChangeLayer => "; CHANGE_LAYER",
            LayerMarker::LayerNumber => ";LAYER:<n>",
            LayerMarker::MoveToNextLayer => "; move to next layer (<n>)",
            LayerMarker::LayerWithZ => "; layer <n>, Z = <z>",
        }
    }
}

/// What one line's comment says, when it is one of the structured comments.
#[derive(Debug, Clone, PartialEq)]
pub enum HostComment<'a> {
    /// A new layer starts on this line; `number` is the host's own layer number when the marker
    /// carries one, `z` the layer's z when it does.
    LayerStart {
        /// The convention.
        marker: LayerMarker,
        /// The host's layer number (Cura counts from 0, and below 0 for a raft).
        number: Option<i64>,
        /// The layer's z, mm (Simplify3D only).
        z: Option<f64>,
    },
    /// The current layer's print z (`;Z:`, `; Z_HEIGHT:`), mm.
    Z(f64),
    /// The current layer's height (`;HEIGHT:`, `; LAYER_HEIGHT:`), mm.
    Height(f64),
    /// The feature printed from here on, as written (`External perimeter`, `Outer wall`,
    /// `WALL-OUTER`).
    Feature(&'a str),
    /// The extrusion width from here on (`;WIDTH:`, `; LINE_WIDTH:`), mm.
    Width(f64),
    /// The number of layers the host announces (`;LAYER_COUNT:`, `; total layer number:`).
    LayerCount(usize),
    /// Slic3r's description of the extrusion on this very line (`G1 X1 Y2 E3 ; perimeter`),
    /// as written.
    MoveRole(&'a str),
}

/// Slic3r's per-move descriptions of extrusions (`--gcode-comments`), which name the role of
/// the move they end.
const SLIC3R_MOVE_ROLES: [&str; 12] = [
    "perimeter",
    "external perimeter",
    "overhang perimeter",
    "infill",
    "solid infill",
    "top solid infill",
    "infill (bridge)",
    "gap fill",
    "skirt",
    "brim",
    "support material",
    "support material interface",
];

/// A finite number ≥ 0, or `None`.
fn non_negative(text: &str) -> Option<f64> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
}

/// Reads the structured comment of `line`, if it has one (see the [module docs](self)).
pub fn read_comment(line: &Line) -> Option<HostComment<'_>> {
    let text = line.comment_text()?;
    if !line.words.is_empty() {
        // Comments after a command: only Slic3r's layer move and role descriptions count.
        if let Some(rest) = text.strip_prefix("move to next layer (") {
            let number = rest.strip_suffix(')').and_then(|n| n.trim().parse().ok());
            return Some(HostComment::LayerStart {
                marker: LayerMarker::MoveToNextLayer,
                number,
                z: None,
            });
        }
        return SLIC3R_MOVE_ROLES
            .contains(&text)
            .then_some(HostComment::MoveRole(text));
    }
    let start = |marker, number, z| Some(HostComment::LayerStart { marker, number, z });
    match text {
        "LAYER_CHANGE" => return start(LayerMarker::LayerChange, None, None),
        "CHANGE_LAYER" => return start(LayerMarker::ChangeLayer, None, None),
        _ => {}
    }
    if let Some(n) = text.strip_prefix("LAYER:") {
        return n
            .trim()
            .parse::<i64>()
            .ok()
            .and_then(|n| start(LayerMarker::LayerNumber, Some(n), None));
    }
    if let Some(rest) = text.strip_prefix("layer ") {
        // Simplify3D: `layer 3, Z = 0.600`.
        let (number, z) = rest.split_once(", Z =")?;
        let number = number.trim().parse::<i64>().ok()?;
        return start(LayerMarker::LayerWithZ, Some(number), non_negative(z));
    }
    if let Some(z) = text
        .strip_prefix("Z:")
        .or_else(|| text.strip_prefix("Z_HEIGHT:"))
    {
        return non_negative(z).map(HostComment::Z);
    }
    if let Some(h) = text
        .strip_prefix("HEIGHT:")
        .or_else(|| text.strip_prefix("LAYER_HEIGHT:"))
    {
        return non_negative(h).map(HostComment::Height);
    }
    if let Some(w) = text
        .strip_prefix("WIDTH:")
        .or_else(|| text.strip_prefix("LINE_WIDTH:"))
    {
        return non_negative(w).filter(|w| *w > 0.0).map(HostComment::Width);
    }
    if let Some(role) = text
        .strip_prefix("TYPE:")
        .or_else(|| text.strip_prefix("FEATURE:"))
        .or_else(|| text.strip_prefix("feature "))
    {
        let role = role.trim();
        return (!role.is_empty()).then_some(HostComment::Feature(role));
    }
    if let Some(n) = text
        .strip_prefix("LAYER_COUNT:")
        .or_else(|| text.strip_prefix("total layer number:"))
    {
        return n.trim().parse().ok().map(HostComment::LayerCount);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use conduit_gcode::LineEnding;

    fn check(text: &str, expected: Option<HostComment<'_>>) {
        let line = Line::new(text, LineEnding::Lf);
        assert_eq!(read_comment(&line), expected, "{text}");
    }

    #[test]
    fn every_host_convention_is_read() {
        use HostComment as C;
        let start = |marker, number, z| C::LayerStart { marker, number, z };
        check(
            ";LAYER_CHANGE",
            start(LayerMarker::LayerChange, None, None).into(),
        );
        check(
            "; CHANGE_LAYER",
            start(LayerMarker::ChangeLayer, None, None).into(),
        );
        check(
            ";LAYER:-2",
            start(LayerMarker::LayerNumber, Some(-2), None).into(),
        );
        check(
            "G1 Z0.400 F7800.000 ; move to next layer (1)",
            start(LayerMarker::MoveToNextLayer, Some(1), None).into(),
        );
        check(
            "; layer 3, Z = 0.600",
            start(LayerMarker::LayerWithZ, Some(3), Some(0.6)).into(),
        );
        check(";Z:.2", Some(C::Z(0.2)));
        check("; Z_HEIGHT: 0.36", Some(C::Z(0.36)));
        check(";HEIGHT:0.2", Some(C::Height(0.2)));
        check("; LAYER_HEIGHT: 0.16", Some(C::Height(0.16)));
        check(";WIDTH:0.45", Some(C::Width(0.45)));
        check("; LINE_WIDTH: 0.42", Some(C::Width(0.42)));
        check(";TYPE:WALL-OUTER", Some(C::Feature("WALL-OUTER")));
        check("; FEATURE: Outer wall", Some(C::Feature("Outer wall")));
        check(";LAYER_COUNT:100", Some(C::LayerCount(100)));
        check("; total layer number: 25", Some(C::LayerCount(25)));
        check(
            "G1 X1 Y2 E3 ; infill (bridge)",
            Some(C::MoveRole("infill (bridge)")),
        );
        for none in [
            ";LAYER:x",
            ";WIDTH:-1",
            ";WIDTH:0",
            "G1 X1 ; note",
            "; layer num/total_layer_count: 1/25",
            ";TYPE:",
            "; generated by PrusaSlicer",
        ] {
            check(none, None);
        }
    }
}
