//! Conformal printing: a 2D design (SVG) laid onto a one-of-a-kind scanned surface and printed
//! with a micro-extrusion nozzle on a 3-axis machine, by point-cloud-based path planning (PCPP).
//!
//! Place in the pipeline: a command of its own (`conduit conform`) that ends in a
//! [`Program`], so the G-code writer, `conduit check` and `conduit preview` work on it. Its
//! stages, in order ([`Stage`]):
//!
//! 1. [`surface`]: the scan as a queryable surface (mesh, or 2.5D Delaunay of a point cloud).
//! 2. [`register`] (and [`markers`] for `--refs-auto`): scan frame → machine frame.
//! 3. [`design`]: SVG paths placed on the top view, two points per inner diameter.
//! 4. [`project`] (or [`geodesic`]): the zero-standoff path T on the surface.
//! 5. [`spline`]: tangent, signed curvature, inflections, direction of travel.
//! 6. [`correct`]: standoff, tip-disk contact escape, shift along the travel (the tip placed
//!    on the deposit model, or the published method's curvature-scaled downhill formula); then
//!    a clearance pass with the whole nozzle ([`nozzle`]: its bore and its tool solid, checked
//!    against the surface by [`crate::surface::contact`], exactly per triangle) lifts what
//!    still touches. Every shift runs along the path, never past a corner nor backwards.
//! 7. [`deposit`]: expected deposit thickness and its errors, for every corrections mode.
//! 8. [`report`]: the JSON report; [`replay`] re-checks the written G-code for contacts (the
//!    replay walk of [`crate::surface::replay`] with the surface as obstacle, `G28` homing to
//!    the printer's home) and measures its accuracy: the tip above the surface, the printed
//!    length against the design's on the surface, the corners' deviation.
//!
//! Robot and five-axis work builds on the same stages: [`orient`] sets a tool axis per point
//! (surface normal, vertical or fixed) for the robot emitters in [`crate::emit::robot`];
//! [`tcp`] (with [`kinematics`]) calibrates the tool centre point from pivot poses, [`frames`]
//! registers two frames from points or poses; [`compensate`] moves a robot path along its tool
//! axis by measured (or simulated) gaps, and [`pattern`] draws calibration patterns on a surface.

pub mod correct;
pub mod deposit;
pub mod design;
pub mod geodesic;
pub mod markers;
pub mod nozzle;
pub mod orient;
pub mod project;
pub mod register;
pub mod replay;
pub mod report;
pub mod scan;
pub mod settings;
pub mod spline;

pub use crate::surface::Surface;
pub use design::Placement;
pub use nozzle::Nozzle;
pub use register::{Registration, register};
pub use report::ConformReport;
pub use settings::{ConformSettings, Corrections, Mapping};

use crate::emit::gcode::GcodeParams;
use crate::geom::Point3;
use crate::program::{Layer, LayerItem, Program, Role, Toolpath};
use deposit::Thresholds;

/// The stages of a conform run, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Stage {
    /// Building the surface.
    Surface,
    /// Registration.
    Register,
    /// Placing and discretising the design, and mapping it onto the surface (projection or
    /// geodesic).
    Design,
    /// Local geometry.
    Geometry,
    /// Corrections and clearance.
    Correct,
    /// Deposit model.
    Deposit,
}

/// Why a conform run failed.
#[derive(Debug, thiserror::Error)]
pub enum ConformError {
    /// A setting is out of range.
    ///
    /// How to fix: correct the named `[conform]` key.
    #[error("conform.{key}: {message}")]
    Setting {
        /// The key.
        key: &'static str,
        /// What is wrong.
        message: String,
    },
    /// No design point lies over the surface.
    ///
    /// How to fix: move the design with `--place` over the surface (see the report's surface
    /// bounds), or check the registration.
    #[error("no point of the design lies over the surface")]
    OffSurface,
    /// The design has no paths.
    ///
    /// How to fix: the SVG must hold paths or shapes (text is not read).
    #[error("the design has no paths")]
    EmptyDesign,
    /// A placed design point lies beyond [`crate::surface::MAX_EXTENT`] (10 m) from the
    /// machine origin along an axis, or is not a number.
    ///
    /// How to fix: check the SVG's coordinates and units (`width`/`height`/`viewBox`) and the
    /// `--place` scale.
    #[error(
        "path {path}{}: point {point} at {value:e} mm is beyond the {} mm working extent",
        id.as_deref().map(|i| format!(" (id \"{i}\")")).unwrap_or_default(),
        crate::surface::MAX_EXTENT
    )]
    DesignOutOfRange {
        /// 1-based number of the path, in document order.
        path: usize,
        /// The `id` of its SVG element, when it has one.
        id: Option<String>,
        /// 1-based number of the point in the path.
        point: usize,
        /// The offending coordinate, mm.
        value: f64,
    },
    /// The design, cut two points per inner diameter, would have more than
    /// [`MAX_DESIGN_POINTS`] points.
    ///
    /// How to fix: print the design in parts, or check its scale (a design in the wrong units
    /// is 25.4 or 1000 times too long).
    #[error(
        "the design is {length:.0} mm of paths: {points} points at {step} mm spacing, more than the {max} a run plans (path {path} reaches the limit)"
    )]
    DesignTooLong {
        /// Total length of the placed paths, mm.
        length: f64,
        /// Points the paths would be cut into, at least.
        points: f64,
        /// Point spacing (half the inner diameter), mm.
        step: f64,
        /// The limit, [`MAX_DESIGN_POINTS`].
        max: usize,
        /// 1-based number of the path at which the count passes the limit.
        path: usize,
    },
    /// The G-code could not be written.
    ///
    /// How to fix: see the message (usually a `[printer]` or tool snippet setting).
    #[error("writing G-code: {0}")]
    Emit(#[from] crate::emit::gcode::EmitError),
    /// The written G-code could not be read back for the replay.
    ///
    /// How to fix: a custom G-code snippet in the configuration is not valid G-code.
    #[error("re-reading the written G-code: {0}")]
    Reread(#[from] conduit_gcode::GcodeError),
}

/// Most points a design is cut into for one run (two per inner diameter): 40 000 points is
/// 5 m of trace at the default 0.25 mm nozzle, longer than the traces of a conformal print,
/// and keeps a run within seconds (every point is corrected in each of the five modes and
/// checked with the whole nozzle: a few thousand points a second).
pub const MAX_DESIGN_POINTS: usize = 40_000;

/// Checks the placed paths before they are cut into points: every coordinate finite and
/// within [`crate::surface::MAX_EXTENT`], and the total number of points at most
/// [`MAX_DESIGN_POINTS`].
fn check_design(
    design: &conduit_svg::Design,
    placed: &[design::PlanarPath],
    step: f64,
) -> Result<(), ConformError> {
    let beyond = |points: &[[f64; 2]]| {
        points.iter().enumerate().find_map(|(i, q)| {
            q.iter()
                .copied()
                .find(|v| !v.is_finite() || v.abs() > crate::surface::MAX_EXTENT)
                .map(|v| (i, v))
        })
    };
    // As drawn first (the path at fault is named), then as placed (moved and scaled).
    let numbered = design.paths.iter().enumerate();
    let drawn = numbered
        .clone()
        .map(|(k, p)| (k, p.id.clone(), &p.points[..]));
    let as_placed = numbered
        .filter(|(_, p)| p.points.len() >= 2)
        .zip(placed)
        .map(|((k, s), p)| (k, s.id.clone(), &p.points[..]));
    for (k, id, pts) in drawn.chain(as_placed) {
        if let Some((i, value)) = beyond(pts) {
            return Err(ConformError::DesignOutOfRange {
                path: k + 1,
                id,
                point: i + 1,
                value,
            });
        }
    }
    let mut points = 0.0;
    let mut length = 0.0;
    let numbers = numbered_kept(design);
    for (k, p) in placed.iter().enumerate() {
        let l = p.length();
        length += l;
        // As `design::discretise` cuts it: every segment in ⌈l/step⌉ parts.
        let parts: f64 = p
            .points
            .windows(2)
            .map(|w| ((w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) / step).ceil())
            .sum();
        points += parts.max(1.0) + 1.0;
        if points > MAX_DESIGN_POINTS as f64 {
            // The rest is summed for the message only.
            let rest: f64 = placed[k + 1..].iter().map(design::PlanarPath::length).sum();
            return Err(ConformError::DesignTooLong {
                length: length + rest,
                points: points + rest / step,
                step,
                max: MAX_DESIGN_POINTS,
                path: numbers.get(k).map_or(k, |n| n + 1),
            });
        }
    }
    Ok(())
}

/// The 0-based number in `design` of each path [`design::place`] keeps.
fn numbered_kept(design: &conduit_svg::Design) -> Vec<usize> {
    let kept = design.paths.iter().enumerate();
    kept.filter(|(_, p)| p.points.len() >= 2)
        .map(|(k, _)| k)
        .collect()
}

/// Validated parameters of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct ConformParams {
    /// The nozzle: its bore and its solid.
    pub nozzle: Nozzle,
    /// Extra lateral clearance of contact corrections, mm.
    pub tolerance: f64,
    /// Corrections applied.
    pub corrections: Corrections,
    /// Mapping of the design onto the surface.
    pub mapping: Mapping,
    /// Defect thresholds of the deposit model.
    pub thresholds: Thresholds,
}

impl ConformParams {
    /// Parameters from the `[conform]` settings, checked.
    pub fn from_settings(s: &ConformSettings) -> Result<Self, ConformError> {
        let positive = |key, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(ConformError::Setting {
                    key,
                    message: format!("must be a positive number, got {v}"),
                })
            }
        };
        let inner = positive("inner_diameter", s.inner_diameter)?;
        let outer = positive("outer_diameter", s.outer_diameter)?;
        if outer < inner {
            return Err(ConformError::Setting {
                key: "outer_diameter",
                message: format!("{outer} is smaller than inner_diameter {inner}"),
            });
        }
        positive("feed", s.feed)?;
        for (key, v) in [
            ("tolerance", s.tolerance),
            ("needle_length", s.needle_length),
            ("cone_height", s.cone_height),
            ("flattening_error", s.flattening_error),
            ("floating_error", s.floating_error),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ConformError::Setting {
                    key,
                    message: format!("must be 0 or more, got {v}"),
                });
            }
        }
        if !(0.0..90.0).contains(&s.cone_angle) {
            return Err(ConformError::Setting {
                key: "cone_angle",
                message: format!("must be in [0, 90), got {}", s.cone_angle),
            });
        }
        Ok(Self {
            nozzle: Nozzle::new(inner, outer, s.needle_length, s.cone_angle, s.cone_height),
            tolerance: s.tolerance,
            corrections: s.corrections,
            mapping: s.mapping,
            thresholds: Thresholds {
                contact_thickness: s.contact_thickness,
                flattening_error: s.flattening_error,
                floating_error: s.floating_error,
            },
        })
    }
}

/// How far along a path its first tip may start ahead of the design (the largest shift of the
/// corrections: d_o/2 + d, the published method's most), mm: the corners of the accuracy report
/// are counted from there.
pub fn corner_skip(params: &ConformParams) -> f64 {
    params.nozzle.tip_radius() + params.nozzle.inner
}

/// The planned paths of a run.
#[derive(Debug, Clone)]
pub struct Planned {
    /// Final tip positions per path (machine frame, mm).
    pub paths: Vec<Vec<Point3>>,
    /// The report (registration and replay are filled in by the caller).
    pub report: ConformReport,
    /// The vertices of the design on the surface seen from above ([`correct::corners`]): where
    /// the printed path must pass, for the report's accuracy.
    pub corners: Vec<[f64; 2]>,
}

/// Tip paths of `t` (zero-standoff paths with their local geometry) under `mode`.
fn corrected(
    surface: &Surface,
    params: &ConformParams,
    mode: Corrections,
    t: &[(Vec<Point3>, Vec<spline::Local>)],
    counts: &mut correct::CorrectionCounts,
) -> Vec<Vec<Point3>> {
    t.iter()
        .map(|(p, g)| {
            correct::correct(
                surface,
                &params.nozzle,
                params.tolerance,
                mode,
                p,
                g,
                counts,
            )
        })
        .collect()
}

/// The design on the surface: its discretised top view and the zero-standoff paths T.
#[derive(Debug, Clone)]
pub struct OnSurface {
    /// The design placed and discretised, two points per inner diameter.
    pub planar: Vec<design::PlanarPath>,
    /// The zero-standoff paths T.
    pub projected: project::Projected,
}

/// Steps 3 and 4: `design` placed by `place`, discretised and mapped onto `surface`.
pub fn on_surface(
    surface: &Surface,
    design: &conduit_svg::Design,
    place: &Placement,
    params: &ConformParams,
) -> Result<OnSurface, ConformError> {
    let placed = design::place(design, place);
    if placed.is_empty() {
        return Err(ConformError::EmptyDesign);
    }
    check_design(design, &placed, params.nozzle.inner / 2.0)?;
    let planar: Vec<design::PlanarPath> = placed
        .iter()
        .map(|p| design::discretise(p, params.nozzle.inner / 2.0))
        .collect();
    let projected = match params.mapping {
        Mapping::Projection => project::project(surface, &planar),
        Mapping::Geodesic => geodesic::map_geodesic(surface, &planar),
    };
    if projected.paths.is_empty() {
        return Err(ConformError::OffSurface);
    }
    Ok(OnSurface { planar, projected })
}

/// Step 5: every zero-standoff path with its local geometry (the section curvature from the
/// surface's normals under the path).
pub fn local_geometry(
    surface: &Surface,
    projected: &project::Projected,
) -> Vec<(Vec<Point3>, Vec<spline::Local>)> {
    projected
        .paths
        .iter()
        .map(|p| {
            let normals: Vec<_> = p
                .iter()
                .map(|q| {
                    surface
                        .top(q.x, q.y)
                        .map_or_else(crate::geom::Vector3::z, |t| t.1)
                })
                .collect();
            (p.clone(), spline::local_geometry(p, &normals))
        })
        .collect()
}

/// The tips of the configured corrections (with what they did) and the deposit comparison of
/// every corrections mode on the same paths, before any clearance pass.
pub fn corrections_compared(
    surface: &Surface,
    params: &ConformParams,
    geometry: &[(Vec<Point3>, Vec<spline::Local>)],
) -> (
    Vec<Vec<Point3>>,
    correct::CorrectionCounts,
    report::Comparison,
) {
    let mut counts = correct::CorrectionCounts::default();
    let method = corrected(surface, params, params.corrections, geometry, &mut counts);
    let mut scratch = correct::CorrectionCounts::default();
    let [deposit, deposit_plane, full, slope, none] = Corrections::ALL.map(|mode| {
        let paths = if mode == params.corrections {
            method.clone()
        } else {
            corrected(surface, params, mode, geometry, &mut scratch)
        };
        deposit::deposit(surface, &paths, &params.nozzle, &params.thresholds)
    });
    (
        method,
        counts,
        report::Comparison {
            deposit,
            deposit_plane,
            full,
            slope,
            none,
        },
    )
}

/// Plans the paths of `design` placed by `place` on `surface` (already in the machine frame):
/// steps 3 to 7 of the module docs. `progress` is called at the start of each stage.
pub fn plan(
    surface: &Surface,
    design: &conduit_svg::Design,
    place: &Placement,
    params: &ConformParams,
    mut progress: impl FnMut(Stage),
) -> Result<Planned, ConformError> {
    progress(Stage::Design);
    let on = on_surface(surface, design, place, params)?;
    progress(Stage::Geometry);
    let t = local_geometry(surface, &on.projected);
    progress(Stage::Correct);
    let (method, counts, comparison) = corrections_compared(surface, params, &t);
    // The whole-nozzle check of the method's path, before anything is lifted.
    let mut remaining = Vec::new();
    for p in method.iter().flatten() {
        let pen = params.nozzle.solid.penetration(surface, p);
        if pen > 0.0 {
            remaining.push(report::Contact {
                at: [p.x, p.y, p.z],
                depth: pen,
            });
        }
    }
    let mut paths = method;
    let lifted: usize = paths
        .iter_mut()
        .map(|p| correct::clear(surface, &params.nozzle, p, correct::CLEARANCE))
        .sum();
    progress(Stage::Deposit);
    let report = report::build(report::Inputs {
        surface,
        planar: &on.planar,
        projected: &on.projected,
        geometry: &t,
        params,
        counts,
        remaining,
        lifted,
        deposit: deposit::deposit(surface, &paths, &params.nozzle, &params.thresholds),
        comparison,
    });
    Ok(Planned {
        paths,
        report,
        corners: correct::corners(&on.projected.paths, corner_skip(params)),
    })
}

/// The planned paths as a one-layer Program for `cfg`'s writer: conductive traces of tool
/// `settings.tool`, width and height d, at `settings.feed`. The layer's height `safe_z` is where
/// the nozzle arrives before travelling to the first path (the surface's top plus clearance).
pub fn program(paths: &[Vec<Point3>], settings: &ConformSettings, safe_z: f64) -> Program {
    let items = paths
        .iter()
        .filter(|p| p.len() >= 2)
        .map(|p| {
            LayerItem::Path(Toolpath {
                points: p.clone(),
                closed: false,
                role: Role::ConductiveTrace,
                tool: settings.tool,
                width: settings.inner_diameter,
                height: settings.inner_diameter,
                speed: settings.feed,
                segments: None,
                tool_axis: None,
            })
        })
        .collect();
    Program {
        layers: vec![Layer {
            index: 0,
            z: safe_z,
            height: settings.inner_diameter,
            items,
        }],
    }
}

/// The G-code writer's `params` with the pressure snippets of `[conform]` (when set) as the
/// dispensing tool's paste snippets: what every conform program (G-code or robot) switches the
/// dispenser with.
pub fn pressure_params(
    mut params: GcodeParams,
    settings: &ConformSettings,
) -> Result<GcodeParams, ConformError> {
    let tools = params.tools.len();
    let Some(tool) = params.tools.get_mut(settings.tool) else {
        return Err(ConformError::Setting {
            key: "tool",
            message: format!("tool {} is not defined ({tools} tool(s))", settings.tool),
        });
    };
    if !settings.pressure_on_gcode.is_empty() {
        tool.paste_on_gcode = settings.pressure_on_gcode.clone();
    }
    if !settings.pressure_off_gcode.is_empty() {
        tool.paste_off_gcode = settings.pressure_off_gcode.clone();
    }
    Ok(params)
}

/// The G-code writer's `params` for a conform program over `surface`: the pressure snippets
/// ([`pressure_params`]), and every travel lifted over the surface's top by
/// `travel_clearance` (a hop on every travel, however short).
pub fn machine_params(
    params: GcodeParams,
    settings: &ConformSettings,
    surface: &Surface,
    lowest_tip: f64,
) -> Result<GcodeParams, ConformError> {
    let mut out = pressure_params(params, settings)?;
    if let Some(tool) = out.tools.get_mut(settings.tool) {
        tool.travel_lift =
            Some((surface.max().z - lowest_tip).max(0.0) + settings.travel_clearance);
    }
    out.printer.retract_before_travel = 0.0;
    Ok(out)
}

#[cfg(test)]
mod bound_tests {
    use super::*;

    fn design(points: Vec<[f64; 2]>) -> conduit_svg::Design {
        conduit_svg::Design {
            width_mm: None,
            height_mm: None,
            paths: vec![conduit_svg::DesignPath {
                id: Some("trace".to_owned()),
                points,
                closed: false,
            }],
        }
    }

    fn placed(d: &conduit_svg::Design) -> Vec<design::PlanarPath> {
        let at = Placement {
            x: 0.0,
            y: 0.0,
            rot_deg: 0.0,
            scale: 1.0,
        };
        design::place(d, &at)
    }

    #[test]
    fn a_design_point_beyond_the_extent_is_named() {
        let d = design(vec![[0.0, 0.0], [1e9, 0.0]]);
        let e = check_design(&d, &placed(&d), 0.125);
        assert!(
            matches!(
                &e,
                Err(ConformError::DesignOutOfRange {
                    path: 1,
                    point: 2,
                    ..
                })
            ),
            "{e:?}"
        );
        let msg = e.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.contains("id \"trace\"") && !msg.contains('\n'), "{msg}");
    }

    #[test]
    fn a_design_too_long_to_cut_is_refused_before_cutting() {
        // 9 m back and forth 10 times: 90 m, 720 000 points at 0.125 mm.
        let zigzag = (0..=10)
            .map(|i| [if i % 2 == 0 { -4500.0 } else { 4500.0 }, i as f64])
            .collect();
        let d = design(zigzag);
        let e = check_design(&d, &placed(&d), 0.125);
        assert!(
            matches!(e, Err(ConformError::DesignTooLong { path: 1, .. })),
            "{e:?}"
        );
        let ok = design(vec![[0.0, 0.0], [100.0, 0.0]]);
        assert!(check_design(&ok, &placed(&ok), 0.125).is_ok());
    }
}
