//! What the studio page shows besides the view: the placement being edited (each part's pose
//! in the placement's own frame), which parts the checks flag, and where *Save* writes.
//!
//! Place in the pipeline: between `conduit place`'s checks
//! ([`crate::pipeline::place::check_placement`]) and the page ([`super::page`]); the server of
//! `conduit studio` sends it with the page and after every change.

use serde::{Deserialize, Serialize};

use crate::circuit::{Origin, Placement, PlacingMethod};

/// One part's pose as the placement gives it (its own frame: `origin`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartPose {
    /// Part name.
    pub name: String,
    /// Package origin, mm.
    pub x: f64,
    /// See `x`.
    pub y: f64,
    /// Seating plane, mm.
    pub z: f64,
    /// Rotation about +z, degrees.
    pub rotation: f64,
}

/// The studio's editable state.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StudioView {
    /// Placed parts, in placement order.
    pub parts: Vec<StudioPart>,
    /// The placement's frame: `model` or `bbox_center`.
    pub origin: Origin,
    /// Parts a problem is about (outside the solid, overlapping another's cavity).
    pub flagged: Vec<String>,
    /// Problems a print cannot have.
    pub problems: Vec<String>,
    /// Thin material between cavities and the surface or each other.
    pub notes: Vec<String>,
    /// Where *Save* writes the placement TOML.
    pub save_path: String,
}

/// A part of the placement with how it is inserted.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StudioPart {
    /// Its pose.
    #[serde(flatten)]
    pub pose: PartPose,
    /// `auto`, `manual` or `none`.
    pub method: PlacingMethod,
}

/// The poses of `placement`'s parts.
pub fn poses(placement: &Placement) -> Vec<StudioPart> {
    placement
        .parts
        .iter()
        .map(|p| StudioPart {
            pose: PartPose {
                name: p.name.clone(),
                x: p.x,
                y: p.y,
                z: p.z,
                rotation: p.rotation,
            },
            method: p.method,
        })
        .collect()
}

/// Why a pose cannot be applied.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PoseError {
    /// The placement has no part of that name.
    #[error("no part {0} in the placement")]
    UnknownPart(String),
    /// A coordinate is not a finite number or is beyond any machine (±100 m).
    #[error("part {0}: coordinates must be finite numbers within ±100000 mm")]
    BadNumber(String),
}

/// `placement` with the poses in `poses` applied (parts not listed keep theirs).
///
/// # Errors
/// A pose names no part of the placement, or has a non-finite or absurd number.
pub fn apply_poses(placement: &mut Placement, poses: &[PartPose]) -> Result<(), PoseError> {
    for pose in poses {
        if ![pose.x, pose.y, pose.z, pose.rotation]
            .iter()
            .all(|v| v.is_finite() && v.abs() <= 1e5)
        {
            return Err(PoseError::BadNumber(pose.name.clone()));
        }
        let part = placement
            .parts
            .iter_mut()
            .find(|p| p.name == pose.name)
            .ok_or_else(|| PoseError::UnknownPart(pose.name.clone()))?;
        part.x = pose.x;
        part.y = pose.y;
        part.z = pose.z;
        part.rotation = pose.rotation;
    }
    Ok(())
}
