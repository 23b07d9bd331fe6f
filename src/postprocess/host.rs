//! Which slicer wrote a G-code file, and which layer comments it carries.
//!
//! Place in the pipeline: the first step of post-processing, before the host's settings are read
//! (`crate::config::HostSettings`) and its layers rebuilt ([`super::layers`]). The host decides where its
//! settings live (a `; key = value` block, Cura's `;SETTING_3` lines); the markers found decide
//! how layers are recognised (comments, or Z heights of extrusions when there are none).

use conduit_gcode::Gcode;
use serde::Serialize;

use super::comments::{HostComment, LayerMarker, read_comment};

/// The slicer that wrote a G-code file: the G-code reader's [`Flavour`](conduit_gcode::Flavour),
/// found from the header comments; [`Host::name`] names it in messages.
pub use conduit_gcode::Flavour as Host;

/// What [`detect_host`] found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HostInfo {
    /// The slicer, from the header.
    pub host: Host,
    /// The generator as the header names it, such as `PrusaSlicer 2.5.0+linux-x64`.
    pub generator: Option<String>,
    /// Every layer-change convention the file uses, sorted, each once. OrcaSlicer may write two
    /// (`; CHANGE_LAYER` and `;LAYER_CHANGE`) at the same place. Empty for files without layer
    /// comments (Slic3r 1.3 without `--gcode-comments`, hand-written or CNC G-code), whose
    /// layers are then found from the Z heights of extrusions.
    pub markers: Vec<LayerMarker>,
}

/// Reads the header for the slicer (first 500 lines, as `conduit info` does) and scans the
/// comments for layer markers.
///
/// ```
/// use conduit::postprocess::{Host, LayerMarker, detect_host};
/// let g = conduit_gcode::parse(b";FLAVOR:Marlin\n;Generated with Cura_SteamEngine 5.0\n;LAYER:0\nG1 X1 E1\n")?;
/// let info = detect_host(&g);
/// assert_eq!(info.host, Host::Cura);
/// assert_eq!(info.markers, vec![LayerMarker::LayerNumber]);
/// # Ok::<(), conduit_gcode::GcodeError>(())
/// ```
pub fn detect_host(gcode: &Gcode) -> HostInfo {
    let summary = conduit_gcode::summarize(gcode);
    let host = summary.flavour;
    HostInfo {
        host,
        generator: summary.generator,
        markers: layer_markers(gcode),
    }
}

/// The layer-change conventions used in `gcode`, sorted, each once.
pub fn layer_markers(gcode: &Gcode) -> Vec<LayerMarker> {
    let mut found: Vec<LayerMarker> = Vec::new();
    for line in &gcode.lines {
        if line.comment.is_none() {
            continue;
        }
        if let Some(HostComment::LayerStart { marker, .. }) = read_comment(line) {
            if !found.contains(&marker) {
                found.push(marker);
            }
        }
    }
    found.sort();
    found
}
