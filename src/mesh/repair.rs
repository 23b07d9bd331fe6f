//! Mesh repair: merge near vertices, drop degenerate and duplicate facets, make the winding
//! consistent and outward, fill simple holes.

use super::Mesh;
use crate::geom::Tolerances;
use serde::Serialize;

/// What a repair pass changed.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct RepairReport {
    /// Vertices merged into a neighbour within `Tolerances::vertex_merge`.
    pub merged_vertices: usize,
    /// Degenerate triangles removed.
    pub removed_degenerate: usize,
    /// Duplicate triangles removed.
    pub removed_duplicate: usize,
    /// Triangles whose winding was flipped.
    pub flipped_triangles: usize,
    /// Holes (boundary loops) filled.
    pub holes_filled: usize,
    /// Triangles added by hole filling.
    pub triangles_added: usize,
}

impl Mesh {
    /// Repairs the mesh in place and reports what changed.
    pub fn repair(&mut self, tol: &Tolerances) -> RepairReport {
        let _ = tol;
        todo!("mesh repair")
    }
}
