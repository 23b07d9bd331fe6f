//! Slicer plugin mode: read another slicer's G-code, understand its layers, and edit it in place.
//!
//! Place in the pipeline: the other front door. Instead of slicing a model, conduit takes the
//! G-code of a host slicer (PrusaSlicer, SuperSlicer, OrcaSlicer, Cura, Slic3r, or any G-code
//! with extrusion moves) that calls it as a post-processing script, and adds what the host cannot
//! (cavities, channels and conductive traces for a circuit, part placement events), leaving every
//! other line byte for byte as the host wrote it ([`conduit_gcode`]'s round-trip guarantee).
//!
//! The steps, one module each:
//!
//! 1. [`read_gcode`]: the file as lines; binary G-code is refused ([`PostprocessError::Gcode`]).
//! 2. [`host`]: which slicer wrote it and which layer comments it uses ([`detect_host`]).
//! 3. [`settings`]: the host's settings from the `SLIC3R_<KEY>` environment of the call and
//!    from the file itself ([`HostSettings::collect`]), as a conduit [`Config`].
//! 4. [`layers`]: the host's layers rebuilt ([`read_layers`]): line ranges, z, height, E mode,
//!    tools, retraction style, extrusions as polylines with role and width ([`comments`] reads the
//!    structured comments, [`roles`] maps feature names to conduit's roles).
//! 5. [`regions`]: the area printed in each layer ([`printed_regions`]).
//! 6. [`edit`]: the changes a circuit asks for. Inserting a circuit is not available yet:
//!    [`edit`] leaves a file without circuit unchanged and refuses one with a circuit
//!    ([`PostprocessError::CircuitsNotYetSupported`]).
//! 7. [`report`]: what was found and done, for `--report` and the one-line summary.
//!
//! The `conduit postprocess` command (`src/cli/postprocess.rs`) runs these steps and writes the
//! file back only when something changed (a temporary file beside it, then a rename).

pub mod comments;
pub mod host;
pub mod layers;
pub mod regions;
pub mod report;
pub mod roles;
pub mod settings;

pub use comments::{HostComment, LayerMarker, read_comment};
pub use host::{Host, HostInfo, detect_host};
pub use layers::{
    EMode, ExtrusionPath, HostLayer, HostLayers, LayerMethod, LayerParams, PathMove,
    RetractionStyle, RoleWidth, WidthSource, Z_TOLERANCE, ZSource, read_layers,
};
pub use regions::{RegionParams, printed_regions};
pub use report::PostprocessReport;
pub use roles::role_of;
pub use settings::{HostSettings, Setting, SettingSource};

use std::path::{Path, PathBuf};

use conduit_gcode::{Gcode, GcodeError};

use crate::config::{Config, ConfigError};
use crate::pipeline::Electronics;

/// Why a host file cannot be post-processed.
#[derive(Debug, thiserror::Error)]
pub enum PostprocessError {
    /// The file is not text G-code: binary G-code (`.bgcode`) or a file with NUL bytes.
    ///
    /// # How to fix
    /// Turn off binary G-code in the host slicer (PrusaSlicer: Printer Settings > General >
    /// Firmware > "Supports binary G-code") and export again.
    #[error(transparent)]
    Gcode(#[from] GcodeError),
    /// The host's settings could not be turned into a conduit configuration.
    ///
    /// # How to fix
    /// The message names the setting; correct it in the host, or pass a conduit config with
    /// `-c`.
    #[error("the host's settings: {0}")]
    Settings(#[from] ConfigError),
    /// A circuit was given, but inserting circuits into a host's G-code is not available in
    /// this version.
    ///
    /// # How to fix
    /// Slice the model with `conduit slice --circuit ... --placement ...`, or run
    /// `conduit postprocess` without a circuit (it then only reports what it finds).
    #[error(
        "inserting a circuit into another slicer's G-code is not available yet: the circuit and \
         placement are valid ({parts} parts, {nets} nets), but the file was left unchanged; \
         use `conduit slice --circuit ... --placement ...` meanwhile"
    )]
    CircuitsNotYetSupported {
        /// Parts in the circuit.
        parts: usize,
        /// Nets in the circuit.
        nets: usize,
    },
}

/// Parses a host's G-code for post-processing. Any text is accepted (lines that are not G-code
/// are kept as they are).
///
/// # Errors
/// [`PostprocessError::Gcode`] for binary G-code ([`GcodeError::BinaryGcode`], whose message
/// tells how to turn it off in the host) and for files with NUL bytes (naming the line).
pub fn read_gcode(bytes: &[u8]) -> Result<Gcode, PostprocessError> {
    Ok(conduit_gcode::parse(bytes)?)
}

/// Everything read from a host's G-code.
#[derive(Debug, Clone, PartialEq)]
pub struct HostPrint {
    /// The slicer and its layer comments.
    pub host: HostInfo,
    /// The slicer's settings.
    pub settings: HostSettings,
    /// The layers.
    pub layers: HostLayers,
}

impl HostPrint {
    /// Reads `gcode` with the host's own settings: the host is detected, its settings collected
    /// from the file and `env` (the `SLIC3R_<KEY>` variables of the call), and the layers rebuilt
    /// with the flavour and filament of those settings. Returns the print and the config the
    /// settings give (see [`HostSettings::to_config`]).
    ///
    /// # Errors
    /// [`PostprocessError::Settings`] when a setting cannot be read.
    pub fn read(
        gcode: &Gcode,
        env: impl IntoIterator<Item = (String, String)>,
    ) -> Result<(HostPrint, Config), PostprocessError> {
        let host = detect_host(gcode);
        let settings = HostSettings::collect(gcode, host.host, env);
        let (config, _warnings) = settings.to_config()?;
        let params = LayerParams::from_config(&config).for_host(host.host);
        let print = Self::read_with(gcode, host, settings, &params);
        Ok((print, config))
    }

    /// Rebuilds the layers of `gcode` with `params` (built from any config, for instance one the
    /// user gave instead of the host's settings, and [`LayerParams::for_host`]).
    pub fn read_with(
        gcode: &Gcode,
        host: HostInfo,
        settings: HostSettings,
        params: &LayerParams,
    ) -> HostPrint {
        let layers = read_layers(gcode, &host.markers, params);
        HostPrint {
            host,
            settings,
            layers,
        }
    }
}

/// What post-processing does to the file.
#[derive(Debug, Clone, PartialEq)]
pub enum Edit {
    /// Nothing to change: the file stays as the host wrote it (and is not rewritten).
    Unchanged,
    /// The edited file, to be written in place of the host's.
    Rewritten(Gcode),
}

/// Plans the edits of `gcode` (read as `print`) for `electronics`: none without a circuit.
///
/// # Errors
/// [`PostprocessError::CircuitsNotYetSupported`] when a circuit is given: inserting cavities,
/// channels and traces into a host's G-code is not available in this version.
pub fn edit(
    gcode: &Gcode,
    print: &HostPrint,
    electronics: Option<&Electronics>,
    config: &Config,
) -> Result<Edit, PostprocessError> {
    // The file, its layers and the config are what inserting a circuit works from.
    let _ = (gcode, print, config);
    match electronics {
        None => Ok(Edit::Unchanged),
        Some(e) => Err(PostprocessError::CircuitsNotYetSupported {
            parts: e.circuit.parts.len(),
            nets: e.circuit.nets.len(),
        }),
    }
}

/// The file through which a post-processing script renames the host's output: `<path>.output_name`
/// beside the G-code `path`. PrusaSlicer (and its descendants) read the new name from its first
/// line after the script ends (a name without folder stays in the output folder).
///
/// ```
/// use std::path::Path;
/// assert_eq!(
///     conduit::postprocess::output_name_file(Path::new("/tmp/part.gcode.pp")),
///     Path::new("/tmp/part.gcode.pp.output_name")
/// );
/// ```
pub fn output_name_file(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".output_name");
    PathBuf::from(name)
}
