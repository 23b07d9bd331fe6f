//! Tool orientation of conformal paths: a tool axis per point — the surface normal (smoothed
//! along the path, its tilt from the vertical limited), the vertical, or a fixed direction —
//! for robot arms and five-axis machines.
//!
//! Place in the pipeline: beside [`super::plan`], for `conduit conform --tool-axis`. It reuses
//! steps 3 and 4 (the design's placement and discretisation, the projection or geodesic
//! mapping) and replaces the 3-axis corrections of step 6:
//!
//! - `vertical`: the 3-axis plan of [`super::plan`] unchanged (standoff along z, contact and
//!   downhill corrections, clearance pass), every axis +z.
//! - `normal`: at each zero-standoff point T the upward normal of the top surface across the
//!   nozzle's footprint ([`normals`]), averaged over `smoothing` mm of path, then tilted back
//!   toward the vertical where it leans more than `max_tilt_deg`.
//! - `fixed:i,j,k`: that direction everywhere (it must lean no more than `max_tilt_deg`).
//!
//! With an axis a the tip is T + d·a (d the inner diameter: the standoff along the tool). A
//! tool along the normal meets the surface square, so the 3-axis contact escape and downhill
//! shift, which make up for a vertical nozzle on a slope, are not applied. The whole tilted
//! nozzle is then checked against the surface along its axis
//! ([`crate::surface::ToolSolid::penetration_along`], the needle sampled every quarter of the
//! inner diameter); contacts are reported, not moved.
//!
//! The report ([`OrientationReport`]) gives, per path and overall, the largest angle between
//! the tool axis and the surface normal (for `vertical`: the steepest slope under the tip), the
//! largest tilt from the vertical, how many axes the tilt limit changed, and the contacts. For
//! `normal` and `fixed` the conform report's deposit figures are those of the oriented tips
//! (the deposit model measures from a vertical nozzle's back edge, an approximation for a
//! tilted one), and its comparison lists the 3-axis method and controls on the same path.

pub mod normals;

use super::ConformSettings;
use super::correct::CorrectionCounts;
use super::deposit;
use super::design::Placement;
use super::report::{self, ConformReport, Contact};
use super::{ConformError, ConformParams, Planned};
use crate::geom::{Point3, Vector3};
use crate::program::{LayerItem, Program};
use serde::Serialize;

/// Contacts listed in the report, at most.
const LISTED: usize = 100;

/// How the tool axis is chosen (`--tool-axis`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToolAxis {
    /// Vertical: today's 3-axis planning.
    Vertical,
    /// Along the surface normal.
    Normal,
    /// This unit direction everywhere.
    Fixed(Vector3),
}

/// Why orientation settings were refused.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum OrientError {
    /// The mode is not one of the three.
    ///
    /// How to fix: write `normal`, `vertical` or `fixed:i,j,k`.
    #[error("--tool-axis: `{0}` is not normal, vertical or fixed:i,j,k")]
    Mode(String),
    /// A fixed axis that is not three finite numbers or has zero length.
    ///
    /// How to fix: give a direction from the tip up toward the tool, e.g. `fixed:0,0.5,1`.
    #[error("--tool-axis fixed:{0}: needs three numbers i,j,k of a non-zero direction")]
    BadFixed(String),
    /// A fixed axis leaning more than the tilt limit (or pointing down).
    ///
    /// How to fix: raise `--max-tilt` (`robot.max_tilt`, at most 90) or give a steeper axis.
    #[error(
        "--tool-axis fixed:{axis}: leans {tilt:.1}° from the vertical, more than the {max}° allowed"
    )]
    FixedTooTilted {
        /// The (normalised) axis, 3 decimals.
        axis: String,
        /// Its tilt, degrees.
        tilt: f64,
        /// The limit, degrees.
        max: f64,
    },
    /// The tilt limit is out of range.
    ///
    /// How to fix: give 0 to 90 degrees.
    #[error("the maximum tilt must be 0 to 90 degrees, got {0}")]
    MaxTilt(f64),
    /// The smoothing length is negative or not finite.
    #[error("the axis smoothing length must be ≥ 0 mm, got {0}")]
    Smoothing(f64),
}

impl ToolAxis {
    /// Reads `normal`, `vertical` or `fixed:i,j,k` (the fixed direction normalised).
    pub fn parse(s: &str) -> Result<Self, OrientError> {
        match s.trim() {
            "normal" => Ok(Self::Normal),
            "vertical" => Ok(Self::Vertical),
            other => {
                let Some(v) = other.strip_prefix("fixed:") else {
                    return Err(OrientError::Mode(other.to_owned()));
                };
                let bad = || OrientError::BadFixed(v.to_owned());
                let n: Vec<f64> = v
                    .split(',')
                    .map(|c| c.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
                    .collect::<Option<_>>()
                    .ok_or_else(bad)?;
                let [i, j, k] = n[..] else {
                    return Err(bad());
                };
                let a = Vector3::new(i, j, k).try_normalize(1e-12).ok_or_else(bad)?;
                Ok(Self::Fixed(a))
            }
        }
    }

    /// The mode's name in the report.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Vertical => "vertical",
            Self::Normal => "normal",
            Self::Fixed(_) => "fixed",
        }
    }
}

/// Validated orientation parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientParams {
    /// How the axis is chosen.
    pub axis: ToolAxis,
    /// Largest tilt from the vertical, degrees (0 to 90).
    pub max_tilt_deg: f64,
    /// Path length over which normals are averaged, mm.
    pub smoothing: f64,
}

impl OrientParams {
    /// Checked parameters: the tilt limit in [0, 90], smoothing ≥ 0, a fixed axis within the
    /// limit.
    pub fn new(axis: ToolAxis, max_tilt_deg: f64, smoothing: f64) -> Result<Self, OrientError> {
        if !(max_tilt_deg.is_finite() && (0.0..=90.0).contains(&max_tilt_deg)) {
            return Err(OrientError::MaxTilt(max_tilt_deg));
        }
        if !(smoothing.is_finite() && smoothing >= 0.0) {
            return Err(OrientError::Smoothing(smoothing));
        }
        if let ToolAxis::Fixed(a) = axis {
            let tilt = normals::angle_deg(&a, &Vector3::z());
            // A hair over the limit is rounding of the numbers given.
            if tilt > max_tilt_deg + 1e-9 || a.z < 0.0 {
                return Err(OrientError::FixedTooTilted {
                    axis: format!("{:.3},{:.3},{:.3}", a.x, a.y, a.z),
                    tilt,
                    max: max_tilt_deg,
                });
            }
        }
        Ok(Self {
            axis,
            max_tilt_deg,
            smoothing,
        })
    }
}

/// Orientation figures of one path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathOrientation {
    /// Points.
    pub points: usize,
    /// Largest angle between the tool axis and the surface normal, degrees.
    pub max_normal_deviation_deg: f64,
    /// Largest tilt of the tool axis from the vertical, degrees.
    pub max_tilt_deg: f64,
    /// Points where the tilted nozzle meets the surface.
    pub contacts: usize,
}

/// The orientation section of the conform report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationReport {
    /// `"vertical"`, `"normal"` or `"fixed"`.
    pub tool_axis: String,
    /// The tilt limit, degrees.
    pub max_tilt_limit_deg: f64,
    /// Largest angle between tool axis and surface normal over all paths, degrees.
    pub max_normal_deviation_deg: f64,
    /// Largest tilt from the vertical over all paths, degrees.
    pub max_tilt_deg: f64,
    /// Axes tilted back to the limit.
    pub limited: usize,
    /// Points where the whole nozzle along its axis meets the surface.
    pub contacts: usize,
    /// The first 100 of them (tip, and how deep the surface reaches into the nozzle, mm).
    pub contact_places: Vec<Contact>,
    /// Per path, in print order.
    pub paths: Vec<PathOrientation>,
}

/// Oriented paths and their reports.
#[derive(Debug, Clone)]
pub struct Oriented {
    /// Tip positions per path (machine frame, mm).
    pub paths: Vec<Vec<Point3>>,
    /// Unit tool axis per point.
    pub axes: Vec<Vec<Vector3>>,
    /// The conform report.
    pub report: ConformReport,
    /// The orientation figures.
    pub orientation: OrientationReport,
    /// The vertices of the design on the surface seen from above (see
    /// [`super::Planned::corners`]).
    pub corners: Vec<[f64; 2]>,
}

/// Plans `design` placed by `place` on `surface` with tool axes per `o` (see the module docs).
pub fn plan(
    surface: &super::Surface,
    design: &conduit_svg::Design,
    place: &Placement,
    params: &ConformParams,
    o: &OrientParams,
) -> Result<Oriented, ConformError> {
    if o.axis == ToolAxis::Vertical {
        let Planned {
            paths,
            report,
            corners,
        } = super::plan(surface, design, place, params, |_| {})?;
        let axes: Vec<Vec<Vector3>> = paths.iter().map(|p| vec![Vector3::z(); p.len()]).collect();
        let half = params.nozzle.tip_radius();
        // Normals under the tips; the whole-nozzle check of a vertical nozzle is the plan's own.
        let normals: Vec<Vec<Option<Vector3>>> = paths
            .iter()
            .map(|p| {
                p.iter()
                    .map(|q| normals::normal_at(surface, q.x, q.y, half))
                    .collect()
            })
            .collect();
        let contacts: Vec<Vec<f64>> = paths
            .iter()
            .map(|p| {
                p.iter()
                    .map(|q| params.nozzle.solid.penetration(surface, q))
                    .collect()
            })
            .collect();
        let orientation = summarise(o, &paths, &axes, &normals, &contacts, 0);
        return Ok(Oriented {
            paths,
            axes,
            report,
            orientation,
            corners,
        });
    }
    let d = params.nozzle.inner;
    let super::OnSurface { planar, projected } = super::on_surface(surface, design, place, params)?;
    let half = params.nozzle.tip_radius();
    let mut limited = 0;
    let mut paths = Vec::with_capacity(projected.paths.len());
    let mut axes = Vec::with_capacity(projected.paths.len());
    let mut all_normals = Vec::with_capacity(projected.paths.len());
    let mut contacts = Vec::with_capacity(projected.paths.len());
    for t in &projected.paths {
        let raw: Vec<Option<Vector3>> = t
            .iter()
            .map(|q| normals::normal_at(surface, q.x, q.y, half))
            .collect();
        let filled: Vec<Vector3> = raw.iter().map(|n| n.unwrap_or_else(Vector3::z)).collect();
        let a: Vec<Vector3> = match o.axis {
            ToolAxis::Fixed(v) => vec![v; t.len()],
            _ => normals::smooth(t, &filled, o.smoothing)
                .iter()
                .map(|n| {
                    let (l, changed) = normals::limit_tilt(n, o.max_tilt_deg);
                    limited += usize::from(changed);
                    l
                })
                .collect(),
        };
        let tips: Vec<Point3> = t.iter().zip(&a).map(|(q, ax)| q + ax * d).collect();
        contacts.push(
            tips.iter()
                .zip(&a)
                .map(|(p, ax)| {
                    params
                        .nozzle
                        .solid
                        .penetration_along(surface, p, ax, d / 4.0)
                })
                .collect(),
        );
        paths.push(tips);
        axes.push(a);
        all_normals.push(raw);
    }
    let orientation = summarise(o, &paths, &axes, &all_normals, &contacts, limited);

    // The conform report of the oriented tips, compared with the 3-axis method and controls.
    let geometry = super::local_geometry(surface, &projected);
    let (_, _, comparison) = super::corrections_compared(surface, params, &geometry);
    let dep = |p: &[Vec<Point3>]| deposit::deposit(surface, p, &params.nozzle, &params.thresholds);
    let remaining: Vec<Contact> = paths
        .iter()
        .flatten()
        .zip(contacts.iter().flatten())
        .filter(|(_, c)| **c > 0.0)
        .map(|(p, c)| Contact {
            at: [p.x, p.y, p.z],
            depth: *c,
        })
        .collect();
    let report = report::build(report::Inputs {
        surface,
        planar: &planar,
        projected: &projected,
        geometry: &geometry,
        params,
        counts: CorrectionCounts::default(),
        remaining,
        lifted: 0,
        deposit: dep(&paths),
        comparison,
    });
    Ok(Oriented {
        paths,
        axes,
        report,
        orientation,
        corners: super::correct::corners(&projected.paths, super::corner_skip(params)),
    })
}

/// The orientation report of tips `paths` with `axes`, surface `normals` under them (`None`
/// off the surface) and nozzle penetrations `contacts` (> 0: contact).
fn summarise(
    o: &OrientParams,
    paths: &[Vec<Point3>],
    axes: &[Vec<Vector3>],
    normals: &[Vec<Option<Vector3>>],
    contacts: &[Vec<f64>],
    limited: usize,
) -> OrientationReport {
    let mut per_path = Vec::with_capacity(paths.len());
    let mut places = Vec::new();
    for (((p, a), n), c) in paths.iter().zip(axes).zip(normals).zip(contacts) {
        let deviation = a
            .iter()
            .zip(n)
            .filter_map(|(a, n)| n.map(|n| normals::angle_deg(a, &n)))
            .fold(0.0, f64::max);
        let tilt = a
            .iter()
            .map(|a| normals::angle_deg(a, &Vector3::z()))
            .fold(0.0, f64::max);
        let mut count = 0;
        for (q, depth) in p.iter().zip(c) {
            if *depth > 0.0 {
                count += 1;
                places.push(Contact {
                    at: [q.x, q.y, q.z],
                    depth: *depth,
                });
            }
        }
        per_path.push(PathOrientation {
            points: p.len(),
            max_normal_deviation_deg: deviation,
            max_tilt_deg: tilt,
            contacts: count,
        });
    }
    OrientationReport {
        tool_axis: o.axis.name().to_owned(),
        max_tilt_limit_deg: o.max_tilt_deg,
        max_normal_deviation_deg: per_path
            .iter()
            .map(|p| p.max_normal_deviation_deg)
            .fold(0.0, f64::max),
        max_tilt_deg: per_path.iter().map(|p| p.max_tilt_deg).fold(0.0, f64::max),
        limited,
        contacts: places.len(),
        contact_places: places.into_iter().take(LISTED).collect(),
        paths: per_path,
    }
}

/// The oriented paths as a one-layer Program (as [`super::program`], with the tool axes).
pub fn program(
    paths: &[Vec<Point3>],
    axes: &[Vec<Vector3>],
    settings: &ConformSettings,
    safe_z: f64,
) -> Program {
    let kept: Vec<(&Vec<Point3>, &Vec<Vector3>)> = paths
        .iter()
        .zip(axes)
        .filter(|(p, _)| p.len() >= 2)
        .collect();
    let points: Vec<Vec<Point3>> = kept.iter().map(|(p, _)| (*p).clone()).collect();
    let mut program = super::program(&points, settings, safe_z);
    let mut axes = kept.iter().map(|(_, a)| (*a).clone());
    for layer in &mut program.layers {
        for item in &mut layer.items {
            if let LayerItem::Path(t) = item {
                t.tool_axis = axes.next();
            }
        }
    }
    program
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_parse_and_bad_ones_are_named() {
        assert_eq!(ToolAxis::parse("normal"), Ok(ToolAxis::Normal));
        assert_eq!(ToolAxis::parse("vertical"), Ok(ToolAxis::Vertical));
        assert_eq!(
            ToolAxis::parse("fixed:0,3,4"),
            Ok(ToolAxis::Fixed(Vector3::new(0.0, 0.6, 0.8)))
        );
        assert_eq!(
            ToolAxis::parse("fixed:0,0,0"),
            Err(OrientError::BadFixed("0,0,0".into()))
        );
        assert_eq!(
            ToolAxis::parse("fixed:1,2"),
            Err(OrientError::BadFixed("1,2".into()))
        );
        assert_eq!(
            ToolAxis::parse("sideways"),
            Err(OrientError::Mode("sideways".into()))
        );
        let tilted = ToolAxis::Fixed(Vector3::new(1.0, 0.0, 1.0).normalize());
        assert!(OrientParams::new(tilted, 45.0, 0.5).is_ok());
        assert!(matches!(
            OrientParams::new(tilted, 30.0, 0.5),
            Err(OrientError::FixedTooTilted { .. })
        ));
        assert_eq!(
            OrientParams::new(ToolAxis::Normal, 95.0, 0.5),
            Err(OrientError::MaxTilt(95.0))
        );
    }
}
