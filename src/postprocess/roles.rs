//! The host slicers' feature names mapped onto conduit's extrusion [`Role`]s.
//!
//! Place in the pipeline: used by [`super::layers`] to give every host extrusion a role the
//! later stages understand (cavities and channels treat perimeters and infill differently),
//! while the name as written stays in [`super::ExtrusionPath::host_role`].

use crate::program::Role;

/// Feature names of PrusaSlicer / SuperSlicer (`;TYPE:`), OrcaSlicer / BambuStudio
/// (`; FEATURE:`), Cura (`;TYPE:`), Slic3r 1.3 (`--gcode-comments` move descriptions) and
/// Simplify3D (`; feature`), compared case-insensitively.
const NAMES: &[(&str, Role)] = &[
    ("external perimeter", Role::ExternalPerimeter),
    ("outer wall", Role::ExternalPerimeter),
    ("wall-outer", Role::ExternalPerimeter),
    ("outer perimeter", Role::ExternalPerimeter),
    ("perimeter", Role::Perimeter),
    ("overhang perimeter", Role::Perimeter),
    ("inner wall", Role::Perimeter),
    ("overhang wall", Role::Perimeter),
    ("wall-inner", Role::Perimeter),
    ("inner perimeter", Role::Perimeter),
    ("internal infill", Role::SparseInfill),
    ("sparse infill", Role::SparseInfill),
    ("fill", Role::SparseInfill),
    // Slic3r 1.3 writes `infill` for sparse and solid infill alike.
    ("infill", Role::SparseInfill),
    ("solid infill", Role::SolidInfill),
    ("internal solid infill", Role::SolidInfill),
    ("skin", Role::SolidInfill),
    ("solid layer", Role::SolidInfill),
    ("top solid infill", Role::TopSolidInfill),
    ("top surface", Role::TopSolidInfill),
    ("bottom surface", Role::BottomSolidInfill),
    ("bridge infill", Role::BridgeInfill),
    ("internal bridge infill", Role::BridgeInfill),
    ("bridge", Role::BridgeInfill),
    ("internal bridge", Role::BridgeInfill),
    ("infill (bridge)", Role::BridgeInfill),
    ("gap fill", Role::GapFill),
    ("gap infill", Role::GapFill),
    ("skirt/brim", Role::Skirt),
    ("skirt", Role::Skirt),
    ("brim", Role::Skirt),
    ("support material", Role::Support),
    ("support", Role::Support),
    ("support material interface", Role::SupportInterface),
    ("support interface", Role::SupportInterface),
    ("support-interface", Role::SupportInterface),
    ("support transition", Role::Support),
    ("custom", Role::Custom),
];

/// conduit's role for a host feature name, or `None` for features conduit has no role for
/// (wipe and prime towers, ironing) and for names it does not know.
///
/// ```
/// use conduit::postprocess::role_of;
/// use conduit::program::Role;
/// assert_eq!(role_of("External perimeter"), Some(Role::ExternalPerimeter));
/// assert_eq!(role_of("Outer wall"), Some(Role::ExternalPerimeter));
/// assert_eq!(role_of("WALL-INNER"), Some(Role::Perimeter));
/// assert_eq!(role_of("SKIN"), Some(Role::SolidInfill));
/// assert_eq!(role_of("Support material"), Some(Role::Support));
/// assert_eq!(role_of("SUPPORT-INTERFACE"), Some(Role::SupportInterface));
/// assert_eq!(role_of("Wipe tower"), None);
/// ```
pub fn role_of(host_name: &str) -> Option<Role> {
    let name = host_name.trim();
    NAMES
        .iter()
        .find(|(known, _)| known.eq_ignore_ascii_case(name))
        .map(|(_, role)| *role)
}
