//! The command-line grammar (clap derive).

use clap::{Args, Parser, Subcommand};
use conduit::scene::MeshFormat;
use std::path::PathBuf;

/// What `conduit conform --dialect` writes.
pub(crate) const DIALECTS: [&str; 6] = [
    "gcode",
    "urscript",
    "krl",
    "rapid",
    "poses-csv",
    "gcode-5axis",
];

/// conduit: slicer plugin and file-format converter for printed electronics and non-planar printing.
#[derive(Debug, Parser)]
#[command(name = "conduit", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    /// Print only errors on stderr: no progress bars, summaries or warnings.
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    pub quiet: bool,
    /// Print the details a warning sums up, such as every ignored PrusaSlicer setting.
    #[arg(short, long, global = true)]
    pub verbose: bool,
    /// Read 3MF files strictly: refuse the harmless defects that are otherwise read past with
    /// a warning (a metadata name missing, duplicated or undefined, a relationship Id used
    /// twice, a second StartPart, a duplicated resource id nothing references).
    #[arg(long, global = true)]
    pub strict: bool,
    /// The command to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Show what is in files: meshes, 3MF builds, EAGLE and KiCad designs, G-code, point clouds, SVG designs.
    Info(InfoArgs),
    /// Convert meshes between STL, 3MF and OBJ (reads STL, 3MF, OBJ, OFF, PLY), in parallel.
    Convert(ConvertArgs),
    /// Slice models into G-code (planar layers; one object per tool as the config assigns).
    Slice(SliceArgs),
    /// Replay a G-code file and report problems, layers, filament and time.
    Check(CheckArgs),
    /// Print or check configuration files.
    Config(ConfigArgs),
    /// Draw a G-code file (conduit's or another slicer's): one SVG per layer and a PNG contact sheet.
    Preview(PreviewArgs),
    /// Place a circuit in models and route its nets, without G-code: a report and one SVG per
    /// layer (material, cavities, channels, traces).
    Route(RouteArgs),
    /// Show G-code in 3D in the browser: one self-contained HTML page with a layer slider,
    /// colours by feature, tool, speed, width or layer time, and the model and circuit when
    /// given.
    View(ViewArgs),
    /// Place a circuit's parts by hand in a 3D view in the browser, served on 127.0.0.1: drag
    /// parts, see the checks and rubberbands follow, route, save the placement TOML.
    Studio(StudioArgs),
    /// Write a placement (TOML to edit) for a circuit in a model: an EAGLE or KiCad board's
    /// layout moved into the object (`--from-brd`, `--from-pcb`), or the parts packed inside its
    /// solid (`--auto`); every part is checked against the solid and the others.
    Place(PlaceArgs),
    /// Slicer plugin mode: read another slicer's G-code (PrusaSlicer, SuperSlicer, OrcaSlicer,
    /// Cura, Slic3r...) with its settings (unless `-c` is given) and edit it in place; without a
    /// circuit it only reports what it finds.
    Postprocess(PostprocessArgs),
    /// Conformal printing: lay a 2D design (SVG) onto a scanned surface (mesh or point cloud),
    /// register it to the machine, correct the path for the nozzle and write G-code with a
    /// deposit report.
    Conform(ConformArgs),
    /// Aerosol-jet toolpaths for micro-walls from an SVG or DXF design: corner fillets by angle,
    /// a shutter gap in closed contours that moves every layer, direction reversed every block
    /// of layers. `conduit jet model ...` evaluates the corner accumulation model.
    Jet(JetArgs),
    /// Robot calibration: the tool centre point from pivot poses (`tcp`), or the rigid
    /// transform between two frames from corresponding points or poses (`register`).
    Calibrate(super::calibrate::CalibrateArgs),
    /// Gap compensation: move a robot path along its tool axis by the measured gaps (or gaps
    /// simulated on a known surface with a robot error model), pass after pass.
    Compensate(Box<super::compensate::CompensateArgs>),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell), e.g.
    /// `conduit completions bash > ~/.local/share/bash-completion/completions/conduit`.
    Completions(CompletionsArgs),
    /// Write the manual pages (roff): `conduit.1` and one `conduit-COMMAND.1` per command.
    Man(ManArgs),
}

/// `conduit completions`.
#[derive(Debug, Args)]
pub struct CompletionsArgs {
    /// The shell to complete for.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// `conduit man`.
#[derive(Debug, Args)]
pub struct ManArgs {
    /// Folder for the pages (made when missing).
    #[arg(long, value_name = "DIR")]
    pub out_dir: PathBuf,
}

/// Where settings come from: a config file plus `--set` overrides.
#[derive(Debug, Args)]
pub struct ConfigSource {
    /// Config file: conduit TOML (`conduit config --defaults` prints every key) or a PrusaSlicer
    /// `.ini` profile.
    #[arg(short = 'c', long = "config", value_name = "CONFIG")]
    pub config: Option<PathBuf>,
    /// Override one setting, e.g. `--set slice.layer_height=0.3` or `--set tools.1.temperature=25`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

/// Arguments of `conduit place`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("how").required(true).args(["from_brd", "from_pcb", "auto"])))]
#[command(group(clap::ArgGroup::new("board").args(["from_brd", "from_pcb"])))]
pub struct PlaceArgs {
    /// The model the parts go into (STL, 3MF, OBJ, OFF, PLY; its first object).
    #[arg(long, value_name = "MODEL")]
    pub model: PathBuf,
    /// Lay the parts out as this EAGLE board has them.
    #[arg(long, value_name = "X.brd")]
    pub from_brd: Option<PathBuf>,
    /// Lay the parts out as this KiCad board has them (as --from-brd does).
    #[arg(long, value_name = "X.kicad_pcb")]
    pub from_pcb: Option<PathBuf>,
    /// Pack the parts inside the model's solid, keeping nets short.
    #[arg(long)]
    pub auto: bool,
    /// The circuit (.sch, .brd, .kicad_sch, .kicad_pcb or .net) the placement is for; with
    /// --from-brd or --from-pcb, the board by default.
    #[arg(
        long,
        value_name = "X.sch|X.brd|X.kicad_sch|X.kicad_pcb|X.net",
        required_unless_present_any = ["from_brd", "from_pcb"]
    )]
    pub circuit: Option<PathBuf>,
    /// Settings (`route.wall_clearance`, `route.cavity_offset`, the trace width, the layers).
    #[command(flatten)]
    pub config: ConfigSource,
    /// The placement TOML to write.
    #[arg(short, long, value_name = "P.toml")]
    pub output: PathBuf,
    /// Write the placement even when a part is outside the solid or in another's cavity.
    #[arg(long)]
    pub force: bool,
    /// Seating plane of the (top) parts, model z in mm; by default under the model's top by the
    /// body height and `route.wall_clearance`.
    #[arg(long, value_name = "Z", conflicts_with_all = ["z_from_top", "z_range"], allow_hyphen_values = true)]
    pub z: Option<f64>,
    /// Seating plane this far below the model's top, mm.
    #[arg(
        long,
        value_name = "D",
        conflicts_with = "z_range",
        allow_hyphen_values = true
    )]
    pub z_from_top: Option<f64>,
    /// With --from-brd or --from-pcb: where the board's centre goes, `X,Y` in model mm (default: the middle
    /// of the model's bounding box).
    #[arg(long, value_name = "X,Y", value_parser = parse_xy, requires = "board", allow_hyphen_values = true)]
    pub at: Option<[f64; 2]>,
    /// With --from-brd or --from-pcb: turn the layout about the board's centre, degrees counter-clockwise.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        requires = "board",
        allow_hyphen_values = true
    )]
    pub rotate: f64,
    /// With --from-brd or --from-pcb: spread the layout (distances between parts times S; parts keep their
    /// size). The summary suggests the smallest scale that leaves traces room between pads.
    #[arg(long, value_name = "S", default_value_t = 1.0, requires = "board")]
    pub scale: f64,
    /// With --from-brd or --from-pcb: seating plane of the bottom-side parts (face up); by default under
    /// the top plane by the body height and `route.wall_clearance`.
    #[arg(
        long,
        value_name = "Z",
        requires = "board",
        conflicts_with = "bottom",
        allow_hyphen_values = true
    )]
    pub bottom_z: Option<f64>,
    /// With --from-brd or --from-pcb: `refuse` fails on a board with bottom-side parts instead of placing
    /// them face up below the top parts.
    #[arg(long, value_name = "below|refuse", value_parser = ["below", "refuse"], requires = "board")]
    pub bottom: Option<String>,
    /// Body height written for every part, mm (board files have none: measure your parts).
    #[arg(long, value_name = "H", default_value_t = 1.0)]
    pub body_height: f64,
    /// With --auto: the seating plane is chosen in this range of model z, `A..B` mm (default:
    /// from `route.wall_clearance` above the bottom to under the top by the body height and
    /// `route.wall_clearance`).
    #[arg(long, value_name = "A..B", value_parser = parse_range, requires = "auto", allow_hyphen_values = true)]
    pub z_range: Option<[f64; 2]>,
    /// With --auto: smallest distance between two parts' footprints, mm (default: both
    /// cavities, `route.wall_clearance` and four traces with their channels).
    #[arg(long, value_name = "MM", requires = "auto")]
    pub spacing: Option<f64>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// A finite number, blanks around it allowed.
fn finite_number(t: &str) -> Result<f64, String> {
    t.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("{t:?} is not a number"))
}

/// `X,Y` as two numbers.
fn parse_xy(s: &str) -> Result<[f64; 2], String> {
    let (x, y) = s
        .split_once(',')
        .ok_or_else(|| format!("expected X,Y (two numbers in mm), got {s:?}"))?;
    Ok([finite_number(x)?, finite_number(y)?])
}

/// `A..B` as two numbers, A ≤ B.
fn parse_range(s: &str) -> Result<[f64; 2], String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("expected A..B (two heights in mm), got {s:?}"))?;
    let (a, b) = (finite_number(a)?, finite_number(b)?);
    if a > b {
        return Err(format!("{a} is above {b}: give the lower height first"));
    }
    Ok([a, b])
}

/// Arguments of `conduit slice`.
#[derive(Debug, Args)]
pub struct SliceArgs {
    /// Models to slice (STL, 3MF, OBJ, OFF, PLY); objects keep their order for tool assignment.
    #[arg(required = true, value_name = "MODEL")]
    pub models: Vec<PathBuf>,
    /// Settings.
    #[command(flatten)]
    pub config: ConfigSource,
    /// The G-code file to write.
    #[arg(short, long, value_name = "OUT.gcode")]
    pub output: PathBuf,
    /// Also write a JSON report (objects, layers, filament, time, stage timings; with a circuit
    /// also parts and, per wire, routed/length/lower bound/layer changes/perimeter crossings).
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Circuit to build into the object: an EAGLE schematic or board (.sch, .brd) or a KiCad
    /// schematic, board or netlist (.kicad_sch, .kicad_pcb, .net). Needs
    /// `--placement`. Also writes the pick-and-place files OUT.pos (KiCad's ASCII table, as
    /// OpenPnP imports it), OUT-pos.csv (KiCad's CSV) and OUT.board.xml (an OpenPnP board).
    #[arg(
        long,
        value_name = "X.sch|X.brd|X.kicad_sch|X.kicad_pcb|X.net",
        requires = "placement"
    )]
    pub circuit: Option<PathBuf>,
    /// Where the circuit's parts go: a placement TOML or an Electronic Slic3r .3de file.
    #[arg(long, value_name = "P.toml|P.3de", requires = "circuit")]
    pub placement: Option<PathBuf>,
    /// Curved layers: `tops` prints the top solid layers of gently sloped top surfaces along
    /// the surface; `clfff` prints a thin shell in curved layers following its bottom surface
    /// over a planar scaffold (curved-layer FFF); `off` keeps every layer planar. The
    /// `[curved]` settings apply. Overrides `curved.mode`.
    #[arg(long, value_name = "MODE", value_parser = ["tops", "clfff", "off"])]
    pub curved: Option<String>,
    /// With `--curved clfff`: write the scaffold, buffer and model to OUT.scaffold.gcode,
    /// OUT.buffer.gcode and OUT.model.gcode (for a material change between them) instead of
    /// one file with a tool per section. Sets `curved.split_sections`.
    #[arg(long)]
    pub split_sections: bool,
    /// Print one JSON document on stdout summarising what was done (outputs written, counts,
    /// key figures) instead of the text summary on stderr.
    #[arg(long)]
    pub json: bool,
    /// Write the outputs even when the circuit is not built as asked (a wire not routed, a
    /// part outside the solid or colliding with another, a placement that places nothing):
    /// the problems become warnings and the exit code 0.
    #[arg(long)]
    pub allow_unrouted: bool,
}

/// Arguments of `conduit route`.
#[derive(Debug, Args)]
pub struct RouteArgs {
    /// Models the circuit is built into (STL, 3MF, OBJ, OFF, PLY).
    #[arg(required = true, value_name = "MODEL")]
    pub models: Vec<PathBuf>,
    /// Settings.
    #[command(flatten)]
    pub config: ConfigSource,
    /// The circuit: an EAGLE schematic or board (.sch, .brd) or a KiCad
    /// schematic, board or netlist (.kicad_sch, .kicad_pcb, .net).
    #[arg(long, value_name = "X.sch|X.brd|X.kicad_sch|X.kicad_pcb|X.net")]
    pub circuit: PathBuf,
    /// Where the parts go: a placement TOML or an Electronic Slic3r .3de file.
    #[arg(long, value_name = "P.toml|P.3de")]
    pub placement: PathBuf,
    /// Folder for `layer_0001.svg`... (made when missing). `-o` is taken as an older spelling.
    #[arg(long = "out-dir", short_alias = 'o', value_name = "DIR")]
    pub out_dir: PathBuf,
    /// Also write the JSON report (parts; per wire routed, length, lower bound, layer changes,
    /// perimeter crossings; totals).
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Print one JSON document on stdout summarising what was done (outputs written, counts,
    /// key figures) instead of the text summary on stderr.
    #[arg(long)]
    pub json: bool,
    /// Exit 0 even when the circuit is not built as asked (a wire not routed, a
    /// part outside the solid or colliding with another, a placement that places nothing):
    /// the problems become warnings. The drawings and report are written either way.
    #[arg(long)]
    pub allow_unrouted: bool,
}

/// Arguments of `conduit postprocess`.
#[derive(Debug, Args)]
pub struct PostprocessArgs {
    /// The host's G-code, edited in place (PrusaSlicer, SuperSlicer and OrcaSlicer pass the path
    /// of a temporary copy). Binary G-code (.bgcode) is refused.
    #[arg(value_name = "GCODE")]
    pub file: PathBuf,
    /// Settings (default: the host's own, from the `SLIC3R_*` environment of the call and the
    /// settings written into the G-code).
    #[command(flatten)]
    pub config: ConfigSource,
    /// Circuit to build into the print: an EAGLE schematic or board (.sch, .brd) or a KiCad
    /// schematic, board or netlist (.kicad_sch, .kicad_pcb, .net). Needs
    /// `--placement`. Its parts get cavities cut from the host's extrusion, its wires are routed
    /// in channels and printed on the conductive tool at layer ends, with part events; the
    /// placement is in the host's bed coordinates (`origin = "model"`) or relative to the
    /// printed object's centre (`origin = "bbox_center"`).
    #[arg(
        long,
        value_name = "X.sch|X.brd|X.kicad_sch|X.kicad_pcb|X.net",
        requires = "placement"
    )]
    pub circuit: Option<PathBuf>,
    /// Where the circuit's parts go: a placement TOML or an Electronic Slic3r .3de file.
    #[arg(long, value_name = "P.toml|P.3de", requires = "circuit")]
    pub placement: Option<PathBuf>,
    /// Also write a JSON report (host, layers with z, height, lines, widths per feature, tools,
    /// E mode, retraction; whether the file changed).
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Ask the host to give its output this file name: written to `GCODE.output_name`, which
    /// PrusaSlicer, SuperSlicer and OrcaSlicer read after the script (a name without folder
    /// stays in the output folder).
    #[arg(long, value_name = "NAME")]
    pub output_name: Option<String>,
    /// Print one JSON document on stdout summarising what was done (outputs written, counts,
    /// key figures) instead of the text summary on stderr.
    #[arg(long)]
    pub json: bool,
    /// Rewrite the host's file even when the circuit is not built as asked (a wire not routed, a
    /// part outside the solid or colliding with another, a placement that places nothing):
    /// the problems become warnings and the exit code 0.
    #[arg(long)]
    pub allow_unrouted: bool,
}

/// Arguments of `conduit conform`.
#[derive(Debug, Args)]
pub struct ConformArgs {
    /// The scanned surface: a mesh (STL, OBJ, 3MF, PLY with faces) or a point cloud (XYZ, PLY
    /// without faces), in mm.
    #[arg(long, value_name = "SCAN")]
    pub surface: PathBuf,
    /// Read a PLY with faces as a point cloud (its faces ignored; 2.5D Delaunay of the points).
    #[arg(long)]
    pub as_cloud: bool,
    /// The design: an SVG of paths (centre lines).
    #[arg(long, value_name = "DESIGN.svg")]
    pub design: PathBuf,
    /// Where the design goes on the surface's top view (machine frame): its bounding-box
    /// centre at x,y (mm), rotated by rot degrees and scaled by scale. Default: the centre of
    /// the surface, 0, 1.
    #[arg(long, value_name = "x,y,rot,scale", allow_hyphen_values = true)]
    pub place: Option<String>,
    /// Reference points in the scan frame, `x,y,z;x,y,z;x,y,z` (three or more).
    #[arg(
        long,
        value_name = "POINTS",
        requires = "refs_machine",
        conflicts_with = "refs_auto",
        allow_hyphen_values = true
    )]
    pub refs_scan: Option<String>,
    /// The same reference points measured on the machine, in the same order.
    #[arg(long, value_name = "POINTS", allow_hyphen_values = true)]
    pub refs_machine: Option<String>,
    /// Find the reference points in the scan: small holes (markers) up to
    /// `conform.marker_max_size`, matched to `--refs-machine` in the order that fits best.
    #[arg(long, requires = "refs_machine")]
    pub refs_auto: bool,
    /// `projection` (drop along −z) or `geodesic` (keep arc length). Overrides
    /// `conform.mapping`.
    #[arg(long, value_name = "MAPPING", value_parser = ["projection", "geodesic"])]
    pub mapping: Option<String>,
    /// Settings (`[conform]`, `[robot]`, tools, printer).
    #[command(flatten)]
    pub config: ConfigSource,
    /// The file to write: G-code, or the program of `--dialect` (`--out` is the older
    /// spelling).
    // `--output` once named the dialect (`--output krl`): a value that is a dialect name, given
    // beside the file and without `--dialect`, is still read as one with a warning. The values
    // are collected (not refused as a repeated option) to tell the two apart; see
    // `conform::output_and_dialect`.
    #[arg(
        short = 'o',
        long = "output",
        alias = "out",
        value_name = "OUT",
        required = true,
        action = clap::ArgAction::Append
    )]
    pub output: Vec<PathBuf>,
    /// What to write: `gcode` (3-axis, the printer's flavour; the default), `urscript`, `krl`
    /// (KUKA .src), `rapid` (ABB module), `poses-csv` (x,y,z,qw,qx,qy,qz,dispense) or
    /// `gcode-5axis` (`robot.five_axis`: I J K tool vectors, or a head or table with rotary
    /// axes). The `[robot]` section sets frames, clearance, speeds and the dispense output.
    #[arg(long, value_name = "DIALECT", value_parser = DIALECTS)]
    pub dialect: Option<String>,
    /// Tool axis per point: `vertical` (3-axis planning with its corrections, the default),
    /// `normal` (along the surface normal, smoothed along the path over
    /// `robot.axis_smoothing`, tilt limited by `--max-tilt`; standoff along the axis) or
    /// `fixed:i,j,k` (that direction, from the tip up toward the tool). A tilted tool needs a
    /// multi-axis `--dialect`.
    #[arg(
        long,
        value_name = "normal|vertical|fixed:i,j,k",
        allow_hyphen_values = true
    )]
    pub tool_axis: Option<String>,
    /// Largest tilt of the tool axis from the vertical, degrees (0 to 90). Overrides
    /// `robot.max_tilt`.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub max_tilt: Option<f64>,
    /// Also write the JSON report (geometry, corrections, deposit thickness against the
    /// controls, contacts, replay, tool orientation).
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Print one JSON document on stdout summarising what was done (outputs written, counts,
    /// key figures) instead of the text summary on stderr.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `conduit jet`.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct JetArgs {
    /// `model`: evaluate the accumulation model instead of making toolpaths.
    #[command(subcommand)]
    pub command: Option<JetCommand>,
    /// Designs (.svg, .dxf: LINE, LWPOLYLINE, POLYLINE, ARC, CIRCLE); every path is one
    /// structure, printed layer by layer in turn with the others.
    #[arg(required = true, value_name = "DESIGN")]
    pub designs: Vec<PathBuf>,
    /// Line width, µm.
    #[arg(long, value_name = "UM", required = true)]
    pub width: Option<f64>,
    /// Number of layers.
    #[arg(long, value_name = "N", required = true, value_parser = clap::value_parser!(u32).range(1..))]
    pub layers: Option<u32>,
    /// Layer height, µm.
    #[arg(long = "layer-height", value_name = "UM", required = true)]
    pub layer_height: Option<f64>,
    /// Settings (the `[jet]` section and the jet tool).
    #[command(flatten)]
    pub config: ConfigSource,
    /// The G-code file to write.
    #[arg(short, long, value_name = "OUT.gcode", required = true)]
    pub output: Option<PathBuf>,
    /// Also write a JSON report: every corner (angle, rule, fillet, model), gap places, the
    /// layer plan, totals.
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Print one JSON document on stdout summarising what was done (outputs written, counts,
    /// key figures) instead of the text summary on stderr.
    #[arg(long)]
    pub json: bool,
}

/// Subcommands of `conduit jet`.
#[derive(Debug, Subcommand)]
pub enum JetCommand {
    /// The corner accumulation model: inside minus outside height of a line at a bend.
    Model(JetModelArgs),
}

/// Arguments of `conduit jet model`.
#[derive(Debug, Args)]
pub struct JetModelArgs {
    /// Corner angle between the two segments, degrees (180 = straight).
    #[arg(long, value_name = "DEG")]
    pub angle: f64,
    /// Fillet radius of the line's centre, µm.
    #[arg(long, value_name = "UM", default_value_t = 0.0)]
    pub radius: f64,
    /// Line width, µm.
    #[arg(long, value_name = "UM")]
    pub width: f64,
    /// Line (wall) height, µm.
    #[arg(long, value_name = "UM")]
    pub height: f64,
    /// Region of interest along the centreline, µm; `A..B` for a sweep.
    #[arg(long, value_name = "UM[..UM]")]
    pub roi: String,
    /// Rows of a sweep.
    #[arg(long, value_name = "N", default_value_t = 10, value_parser = clap::value_parser!(u32).range(2..=1000))]
    pub steps: u32,
    /// Settings (for `jet.leveling_factor`).
    #[command(flatten)]
    pub config: ConfigSource,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `conduit check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// G-code file to replay.
    #[arg(value_name = "FILE.gcode")]
    pub file: PathBuf,
    /// Printer settings for the bed volume and filament diameters (default: conduit's defaults).
    #[command(flatten)]
    pub config: ConfigSource,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Check the circuit in the G-code too: nets connected, no shorts, no conductive material
    /// outside the solid, part events after their cavity (EAGLE `.sch`, `.brd`, or KiCad `.kicad_sch`, `.kicad_pcb`, `.net`).
    #[arg(long, value_name = "FILE", requires = "placement")]
    pub circuit: Option<PathBuf>,
    /// Where the circuit's parts sit (`.toml` or `.3de`), as given to slice or postprocess.
    #[arg(long, value_name = "FILE", requires = "circuit")]
    pub placement: Option<PathBuf>,
    /// The model the G-code was sliced from by `conduit slice`: its frame places a placement
    /// with `origin = "model"` (without it, the G-code's coordinates are the frame).
    #[arg(long, value_name = "MODEL", requires = "circuit")]
    pub model: Option<PathBuf>,
}

/// Arguments of `conduit preview`.
#[derive(Debug, Args)]
pub struct PreviewArgs {
    /// G-code file to draw.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// Folder for `layer_0001.svg`..., `contact_sheet.png` and the side views (made when
    /// missing). Layer views there that this run does not write (`layer_NNNN.svg` of an
    /// earlier run with more layers) are removed; other files are left alone. `-o` is taken as
    /// an older spelling.
    #[arg(long = "out-dir", short_alias = 'o', value_name = "DIR")]
    pub out_dir: PathBuf,
    /// Contact sheet: every Nth layer (default: the smallest N giving at most 36 tiles).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub every: Option<u32>,
    /// Contact sheet tile size, pixels.
    #[arg(long, value_name = "PX", default_value_t = 256, value_parser = clap::value_parser!(u32).range(16..=4096))]
    pub tile: u32,
    /// Print one JSON document on stdout summarising what was done (outputs written, counts,
    /// key figures) instead of the text summary on stderr.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `conduit config`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("what").required(true).args(["defaults", "check"])))]
pub struct ConfigArgs {
    /// Print the default configuration as commented TOML.
    #[arg(long)]
    pub defaults: bool,
    /// Load a config file (TOML or PrusaSlicer .ini), report problems, print the result as TOML.
    #[arg(long, value_name = "CONFIG")]
    pub check: Option<PathBuf>,
}

/// Arguments of `conduit info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Files to inspect (format recognised by extension, else by content).
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// Print one JSON document (an array with one entry per file) instead of text.
    #[arg(long)]
    pub json: bool,
    /// Skip the trial mesh repair (faster on huge meshes; repair findings are then omitted).
    #[arg(long)]
    pub no_repair: bool,
}

/// Arguments of `conduit convert`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("target").required(true).args(["output", "to"])))]
pub struct ConvertArgs {
    /// Mesh files to convert.
    #[arg(required = true, value_name = "IN")]
    pub inputs: Vec<PathBuf>,
    /// Output file (one input only); the format follows its extension (.stl, .3mf, .obj).
    #[arg(short, long, value_name = "OUT", conflicts_with_all = ["to", "out_dir"])]
    pub output: Option<PathBuf>,
    /// Output format for batch conversion (with --out-dir).
    #[arg(long, value_enum, value_name = "FORMAT", requires = "out_dir")]
    pub to: Option<MeshFormat>,
    /// Folder for batch outputs, named after each input's file stem (made when missing).
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// Repair meshes before writing (merge near vertices, drop degenerate facets, fix winding, fill holes).
    #[arg(long)]
    pub repair: bool,
    /// Write ASCII instead of binary STL.
    #[arg(long)]
    pub ascii: bool,
    /// Print one JSON document on stdout summarising what was done (outputs written, counts,
    /// key figures) instead of the text summary on stderr.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `conduit view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// G-code files to show (conduit's or another slicer's); the page switches between them.
    #[arg(value_name = "FILE", required = true)]
    pub files: Vec<PathBuf>,
    /// The HTML page to write (default: the first file with `.html` for its extension).
    #[arg(short = 'o', long = "output", value_name = "view.html")]
    pub output: Option<PathBuf>,
    /// Open the page in the desktop's browser when it is written.
    #[arg(long)]
    pub open: bool,
    /// Show the model too (STL, 3MF, OBJ, OFF, PLY), placed on the bed as `conduit slice`
    /// places it with the same config.
    #[arg(long, value_name = "MODEL")]
    pub model: Option<PathBuf>,
    /// Show the circuit (EAGLE `.sch`/`.brd`, KiCad `.kicad_sch`/`.kicad_pcb`/`.net`): parts as labelled boxes, cavities, and the
    /// wires the first file's traces do not connect.
    #[arg(long, value_name = "FILE", requires = "placement")]
    pub circuit: Option<PathBuf>,
    /// Where the circuit's parts sit (`.toml` or `.3de`), as given to slice.
    #[arg(long, value_name = "FILE", requires = "circuit")]
    pub placement: Option<PathBuf>,
    /// Printer settings (firmware flavour, bed, tools, the time model) as for `conduit check`.
    #[command(flatten)]
    pub config: ConfigSource,
    /// Print one JSON document on stdout summarising what was done.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `conduit studio`.
#[derive(Debug, Args)]
pub struct StudioArgs {
    /// The model the parts go into (STL, 3MF, OBJ, OFF, PLY).
    #[arg(value_name = "MODEL")]
    pub model: PathBuf,
    /// The circuit (EAGLE `.sch`, `.brd`, or KiCad `.kicad_sch`, `.kicad_pcb`, `.net`).
    #[arg(long, value_name = "FILE")]
    pub circuit: PathBuf,
    /// The placement to start from (`.toml` or `.3de`); without it the parts are laid out as
    /// the `.brd` has them, else packed inside the solid (`conduit place`), else put in a row
    /// beside the model.
    #[arg(long, value_name = "FILE")]
    pub placement: Option<PathBuf>,
    /// Where *Save* writes the placement TOML (default: `--placement` when it is a `.toml`,
    /// else the model's name with `.placement.toml`).
    #[arg(long, value_name = "FILE")]
    pub save: Option<PathBuf>,
    /// The port on 127.0.0.1 (0: any free port). The address is printed.
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// Open the page in the desktop's browser.
    #[arg(long)]
    pub open: bool,
    /// Printer and routing settings, as for `conduit slice`.
    #[command(flatten)]
    pub config: ConfigSource,
}
