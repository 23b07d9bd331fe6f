//! The conform walk (`conduit conform`): a scan and a 2D design in, a machine program and its
//! deposit report out, as one library call ([`run`]).
//!
//! Steps ([`Stage`]): **register** the scan to the machine (reference points, marker holes, or
//! none) → **plan** the design on the registered surface (projection, corrections, tool
//! orientation: [`crate::conform::orient::plan`]) → **write** the program: 3-axis G-code, which
//! is then replayed against the surface with the whole nozzle ([`write_and_replay`]), or a robot
//! or five-axis program ([`robot_program`]). The writer's parameters come from the config with
//! the conform pressure snippets and travel lift ([`crate::conform::machine_params`]).

use serde::Serialize;

use super::Laps;
use crate::config::Config;
use crate::conform::markers::{Marker, MarkerError, auto_register, find_markers};
use crate::conform::orient::{self, OrientParams, OrientationReport};
use crate::conform::register::RegisterError;
use crate::conform::replay::{self, ReplayContacts, ReplayMachine};
use crate::conform::scan::Scan;
use crate::conform::{
    self, ConformError, ConformParams, ConformReport, Placement, Registration, Surface,
};
use crate::emit::gcode::{GcodeParams, TemplateError, write_gcode};
use crate::emit::robot::{Dialect, RobotError, RobotJob, write_robot};
use crate::geom::Point3;
use crate::program::Program;
use crate::program::machine::Tool;
use crate::surface::SurfaceError;

/// The walk's steps, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// The scan registered to the machine frame.
    Register,
    /// The design laid onto the surface, corrected and oriented.
    Plan,
    /// The program written (and, for G-code, replayed against the surface).
    Write,
}

impl Stage {
    /// A short human name.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Register => "registering",
            Stage::Plan => "planning",
            Stage::Write => "writing",
        }
    }
}

/// How the scan is registered to the machine.
#[derive(Debug, Clone, PartialEq)]
pub enum Refs {
    /// The scan is in machine coordinates already.
    None,
    /// The same points measured in the scan and on the machine (three or more, in order).
    Points {
        /// The points in the scan.
        scan: Vec<Point3>,
        /// The points on the machine.
        machine: Vec<Point3>,
    },
    /// The machine points, matched to marker holes found in the scan's mesh.
    Markers {
        /// The points on the machine.
        machine: Vec<Point3>,
    },
}

/// What to conform: the inputs of [`run`], read and validated.
#[derive(Debug)]
pub struct ConformJob<'a> {
    /// The scanned surface.
    pub scan: Scan,
    /// The 2D design.
    pub design: &'a conduit_svg::Design,
    /// Where the design goes on the surface; `None` centres it on the surface's bounding box.
    pub place: Option<Placement>,
    /// How the scan is registered to the machine.
    pub refs: Refs,
    /// The planning's parameters (nozzle, corrections, thresholds).
    pub params: ConformParams,
    /// The tool axis along the path.
    pub orient: OrientParams,
    /// The robot or five-axis dialect to write; `None` writes 3-axis G-code.
    pub dialect: Option<Dialect>,
    /// The program's name (KRL `DEF`, RAPID `MODULE`).
    pub program_name: String,
}

/// What [`run`] made.
#[derive(Debug)]
pub struct ConformOutput {
    /// The program: G-code or the robot dialect's text.
    pub program: Vec<u8>,
    /// Moves of a robot program (`None` for G-code).
    pub moves: Option<usize>,
    /// The deposit report, with the registration, the markers, the cloud and (G-code) the
    /// replay.
    pub report: ConformReport,
    /// The tool orientation along the paths.
    pub orientation: OrientationReport,
    /// Wall time per stage in seconds, in stage order.
    pub stage_seconds: Vec<(Stage, f64)>,
}

/// Why the conform walk failed.
#[derive(Debug, thiserror::Error)]
pub enum ConformWalkError {
    /// The reference points do not register.
    #[error("registration: {0}")]
    Register(RegisterError),
    /// Marker holes were asked for on a scan that is a point cloud.
    ///
    /// How to fix: give a mesh scan, or the scan's points with `--refs-scan`.
    #[error("--refs-auto finds marker holes in a mesh; this scan is a point cloud")]
    MarkersNeedMesh,
    /// The marker holes do not register to the machine points.
    #[error("--refs-auto: {0}")]
    Markers(MarkerError),
    /// The registered surface is not usable.
    #[error("registered surface: {0}")]
    Registered(SurfaceError),
    /// The design could not be planned on the surface.
    #[error("{0}")]
    Plan(ConformError),
    /// The program could not be written.
    #[error("[conform]: {0}")]
    Write(ConformError),
    /// A dispensing snippet cannot be filled (an unknown placeholder, a macro error).
    #[error("tools.{tool}.{key}: G-code template, {error}")]
    Template {
        /// The dispensing tool.
        tool: usize,
        /// `paste_on_gcode` or `paste_off_gcode`.
        key: &'static str,
        /// The line, the placeholder and the problem.
        error: TemplateError,
    },
    /// The robot program could not be written.
    #[error("writing the {dialect} program: {error}")]
    Robot {
        /// The dialect's name.
        dialect: &'static str,
        /// What the writer said.
        error: RobotError,
    },
}

/// Runs the conform walk: registers `job.scan`, plans `job.design` on it and writes the
/// program, with the settings of `cfg` (`[conform]`, `[robot]`, the printer and the tools).
/// `progress` is called with each stage as it starts.
pub fn run(
    job: ConformJob<'_>,
    cfg: &Config,
    mut progress: impl FnMut(Stage),
) -> Result<ConformOutput, ConformWalkError> {
    let mut laps = Laps::new();
    progress(Stage::Register);
    let Scan {
        surface,
        mesh,
        cloud,
        ..
    } = job.scan;
    let (registration, markers) = register(&job.refs, mesh.as_ref(), cfg)?;
    let surface = if registration.method == "identity" {
        surface
    } else {
        surface
            .transformed(&registration.transform)
            .map_err(ConformWalkError::Registered)?
    };
    laps.lap(Stage::Register);

    progress(Stage::Plan);
    let (lo, hi) = (surface.min(), surface.max());
    let place = job.place.unwrap_or(Placement {
        x: (lo.x + hi.x) / 2.0,
        y: (lo.y + hi.y) / 2.0,
        rot_deg: 0.0,
        scale: 1.0,
    });
    let planned = orient::plan(&surface, job.design, &place, &job.params, &job.orient)
        .map_err(ConformWalkError::Plan)?;
    let mut report = planned.report;
    report.registration = registration;
    report.markers = markers;
    report.surface.cloud = cloud;
    laps.lap(Stage::Plan);

    progress(Stage::Write);
    let (program, moves) = match job.dialect {
        None => {
            let written = write_and_replay(&planned.paths, cfg, &surface, &job.params)
                .map_err(ConformWalkError::Write)?;
            report.replay = Some(written.contacts);
            report.accuracy = Some(replay::accuracy(
                &written.parsed,
                &written.machine,
                &surface,
                &job.params.nozzle,
                &planned.corners,
                report.geometry.length_3d,
            ));
            (written.gcode, None)
        }
        Some(dialect) => {
            let lowest = planned
                .paths
                .iter()
                .flatten()
                .map(|p| p.z)
                .fold(f64::MAX, f64::min);
            let writer =
                conform::machine_params(cfg.gcode_params(), &cfg.conform, &surface, lowest)
                    .map_err(ConformWalkError::Write)?;
            let safe_z = hi.z + cfg.conform.travel_clearance;
            let program = orient::program(&planned.paths, &planned.axes, &cfg.conform, safe_z);
            let (text, moves) = robot_program(&program, dialect, cfg, &writer, &job.program_name)?;
            (text, Some(moves))
        }
    };
    laps.lap(Stage::Write);
    Ok(ConformOutput {
        program,
        moves,
        report,
        orientation: planned.orientation,
        stage_seconds: laps.times,
    })
}

/// The registration `refs` asks for, and the markers it used.
fn register(
    refs: &Refs,
    mesh: Option<&crate::mesh::Mesh>,
    cfg: &Config,
) -> Result<(Registration, Vec<Marker>), ConformWalkError> {
    match refs {
        Refs::None => Ok((Registration::identity(), Vec::new())),
        Refs::Points { scan, machine } => Ok((
            conform::register(scan, machine).map_err(ConformWalkError::Register)?,
            Vec::new(),
        )),
        Refs::Markers { machine } => {
            let mesh = mesh.ok_or(ConformWalkError::MarkersNeedMesh)?;
            let markers = find_markers(mesh, cfg.conform.marker_max_size);
            let registration =
                auto_register(&markers, machine).map_err(ConformWalkError::Markers)?;
            Ok((registration, markers))
        }
    }
}

/// A written conform G-code and its replay.
#[derive(Debug)]
pub struct Written {
    /// The G-code.
    pub gcode: Vec<u8>,
    /// It, parsed back.
    pub parsed: conduit_gcode::Gcode,
    /// The machine it was replayed on.
    pub machine: ReplayMachine,
    /// What the replay found.
    pub contacts: ReplayContacts,
}

/// The G-code of `paths` for `cfg` over `surface`, and its replay: every move of the written
/// file checked against the surface with the whole nozzle, on the machine of `[printer]`
/// (`G28` homes to `printer.home`). The program's first travel arrives at the surface's top
/// plus `conform.travel_clearance`.
pub fn write_and_replay(
    paths: &[Vec<Point3>],
    cfg: &Config,
    surface: &Surface,
    params: &ConformParams,
) -> Result<Written, ConformError> {
    let lowest = paths.iter().flatten().map(|p| p.z).fold(f64::MAX, f64::min);
    let safe_z = surface.max().z + cfg.conform.travel_clearance;
    let program = conform::program(paths, &cfg.conform, safe_z);
    let writer = conform::machine_params(cfg.gcode_params(), &cfg.conform, surface, lowest)?;
    let mut gcode = Vec::new();
    write_gcode(&program, &writer, &mut gcode)?;
    let parsed = conduit_gcode::parse(&gcode)?;
    let machine = ReplayMachine {
        flavor: cfg.printer.flavor,
        home: cfg.printer.home_position(),
        print_feed: cfg.conform.feed,
        body: replay::body_lines(&String::from_utf8_lossy(&gcode)),
    };
    let contacts = replay::replay(&parsed, &machine, surface, &params.nozzle);
    Ok(Written {
        gcode,
        parsed,
        machine,
        contacts,
    })
}

/// `program` as a robot or five-axis program in `dialect`, named `name`, and its moves. The
/// dispenser is switched by the conform tool's paste snippets of `writer` (`gcode-5axis`),
/// filled as the G-code writer fills them; frames and speeds come from `[robot]`.
pub fn robot_program(
    program: &Program,
    dialect: Dialect,
    cfg: &Config,
    writer: &GcodeParams,
    name: &str,
) -> Result<(Vec<u8>, usize), ConformWalkError> {
    let tool = cfg.conform.tool;
    let snippet = |key: &'static str, pick: fn(&Tool) -> &String| {
        let text = writer
            .tools
            .get(tool)
            .map(pick)
            .cloned()
            .unwrap_or_default();
        writer
            .render_template(&text, tool, &[])
            .map_err(|error| ConformWalkError::Template { tool, key, error })
    };
    let on = snippet("paste_on_gcode", |t| &t.paste_on_gcode)?;
    let off = snippet("paste_off_gcode", |t| &t.paste_off_gcode)?;
    let job = RobotJob {
        settings: &cfg.robot,
        name,
        dispense_on_gcode: &on,
        dispense_off_gcode: &off,
    };
    let mut text = Vec::new();
    let moves = write_robot(program, dialect, &job, &mut text).map_err(|error| {
        ConformWalkError::Robot {
            dialect: dialect.name(),
            error,
        }
    })?;
    Ok((text, moves))
}
