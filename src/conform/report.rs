//! The JSON report of a conform run: surface, registration, design, path geometry, corrections,
//! remaining nozzle contacts, deposit thickness (method and controls), the replay and the
//! accuracy of the written G-code (tip above the surface, length, corners).
//!
//! Place in the pipeline: step 9, the last; [`super::plan`] fills everything it knows, the CLI
//! adds the registration, the markers, the replay of the written G-code and its accuracy.

use super::ConformParams;
use super::Corrections;
use super::correct::CorrectionCounts;
use super::deposit::DepositStats;
use super::design::PlanarPath;
use super::markers::Marker;
use super::project::Projected;
use super::register::Registration;
use super::replay::{Accuracy, ReplayContacts};
use super::spline::Local;
use crate::geom::Point3;
use crate::surface::{CloudInfo, Surface};
use serde::Serialize;

/// A place where the whole nozzle meets the surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Contact {
    /// Tip position [x, y, z], mm.
    pub at: [f64; 3],
    /// How far the surface reaches into the nozzle, mm.
    pub depth: f64,
}

/// Deposit errors of every corrections mode on the same paths, all before the clearance pass:
/// the tip placed on the deposit model (on the surface, and its slope-only control on the
/// tangent plane), the published method and the two controls it is compared with.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    /// The tip placed on the deposit model, its standoff solved on the surface (curvature and
    /// all).
    pub deposit: DepositStats,
    /// Control: the same placement with the standoff solved on the tangent plane (slope, no
    /// curvature).
    pub deposit_plane: DepositStats,
    /// Published full method: contact and curvature-scaled downhill corrections.
    pub full: DepositStats,
    /// Control: downhill correction without curvature.
    pub slope: DepositStats,
    /// Control: no corrections (standoff only).
    pub none: DepositStats,
}

impl Comparison {
    /// The statistics of `mode`.
    pub fn of(&self, mode: Corrections) -> &DepositStats {
        match mode {
            Corrections::Deposit => &self.deposit,
            Corrections::DepositPlane => &self.deposit_plane,
            Corrections::Full => &self.full,
            Corrections::Slope => &self.slope,
            Corrections::None => &self.none,
        }
    }
}

/// Geometry of the zero-standoff path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathGeometry {
    /// Height range of the path, mm.
    pub delta_z: f64,
    /// Steepest inclination of the path, degrees from the horizontal.
    pub max_inclination_deg: f64,
    /// Smallest radius of curvature in the vertical plane of travel, mm (`null` when straight).
    pub min_radius_of_curvature: Option<f64>,
    /// Length of the discretised design in the plane, mm.
    pub length_2d: f64,
    /// Length of the path on the surface, mm.
    pub length_3d: f64,
    /// Inflection points (sign changes of the curvature).
    pub inflections: usize,
}

/// The surface used.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurfaceInfo {
    /// Triangles.
    pub triangles: usize,
    /// Bounding box minimum (machine frame), mm.
    pub min: [f64; 3],
    /// Bounding box maximum, mm.
    pub max: [f64; 3],
    /// For a point cloud: how it was made a surface (fold detection).
    pub cloud: Option<CloudInfo>,
}

/// The report (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConformReport {
    /// The surface.
    pub surface: SurfaceInfo,
    /// The registration.
    pub registration: Registration,
    /// Markers found with `--refs-auto`.
    pub markers: Vec<Marker>,
    /// `"projection"` or `"geodesic"`.
    pub mapping: String,
    /// `"full"`, `"slope"` or `"none"`.
    pub corrections: String,
    /// Separate paths printed.
    pub paths: usize,
    /// Points printed.
    pub points: usize,
    /// Design points with no surface under them (left out).
    pub off_surface: usize,
    /// Geometry of the zero-standoff path.
    pub geometry: PathGeometry,
    /// What the corrections did.
    pub corrected: CorrectionCounts,
    /// Whole-nozzle contacts left after the corrections (up to 100 listed in `contacts`).
    pub remaining_contacts: usize,
    /// The first 100 of them.
    pub contacts: Vec<Contact>,
    /// Points lifted by the clearance pass to remove them.
    pub lifted: usize,
    /// Deposit along the printed path (after the clearance pass).
    pub deposit: DepositStats,
    /// Method against controls (before the clearance pass).
    pub comparison: Comparison,
    /// Contacts found by replaying the written G-code.
    pub replay: Option<ReplayContacts>,
    /// How closely the written G-code follows the design on the surface (3-axis G-code only).
    pub accuracy: Option<Accuracy>,
}

/// What [`build`] needs.
pub(super) struct Inputs<'a> {
    pub surface: &'a Surface,
    pub planar: &'a [PlanarPath],
    pub projected: &'a Projected,
    pub geometry: &'a [(Vec<Point3>, Vec<Local>)],
    pub params: &'a ConformParams,
    pub counts: CorrectionCounts,
    pub remaining: Vec<Contact>,
    pub lifted: usize,
    pub deposit: DepositStats,
    pub comparison: Comparison,
}

pub(super) fn build(i: Inputs<'_>) -> ConformReport {
    let (mut zlo, mut zhi) = (f64::MAX, f64::MIN);
    let (mut incl, mut kmax, mut infl, mut len3) = (0.0f64, 0.0f64, 0, 0.0);
    for (p, g) in i.geometry {
        for q in p {
            zlo = zlo.min(q.z);
            zhi = zhi.max(q.z);
        }
        len3 += p.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>();
        for l in g {
            incl = incl.max(l.tangent.z.abs().clamp(0.0, 1.0).asin().to_degrees());
            kmax = kmax.max(l.curvature.abs());
            infl += usize::from(l.inflection);
        }
    }
    let (lo, hi) = (i.surface.min(), i.surface.max());
    let remaining = i.remaining.len();
    ConformReport {
        surface: SurfaceInfo {
            triangles: i.surface.triangles().len(),
            min: [lo.x, lo.y, lo.z],
            max: [hi.x, hi.y, hi.z],
            cloud: None,
        },
        registration: Registration::identity(),
        markers: Vec::new(),
        mapping: format!("{:?}", i.params.mapping).to_lowercase(),
        corrections: i.params.corrections.name().to_owned(),
        paths: i.projected.paths.len(),
        points: i.projected.paths.iter().map(Vec::len).sum(),
        off_surface: i.projected.off_surface,
        geometry: PathGeometry {
            delta_z: if zhi >= zlo { zhi - zlo } else { 0.0 },
            max_inclination_deg: incl,
            min_radius_of_curvature: (kmax > 1e-12).then(|| 1.0 / kmax),
            length_2d: i.planar.iter().map(PlanarPath::length).sum(),
            length_3d: len3,
            inflections: infl,
        },
        corrected: i.counts,
        remaining_contacts: remaining,
        contacts: i.remaining.into_iter().take(100).collect(),
        lifted: i.lifted,
        deposit: i.deposit,
        comparison: i.comparison,
        replay: None,
        accuracy: None,
    }
}
