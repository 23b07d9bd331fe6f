//! Mesh validation: edge manifoldness, boundary edges, winding consistency, shells, orientation.

use super::Mesh;
use serde::Serialize;

/// Which way a mesh's triangles face.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Orientation {
    /// Consistent winding and positive volume: normals point out.
    Outward,
    /// Consistent winding and negative volume: normals point in.
    Inward,
    /// Neighbouring triangles disagree on winding.
    Inconsistent,
    /// Consistent winding but the mesh is open, so in/out is not defined.
    Open,
    /// No triangles.
    Empty,
}

/// What validation found in a mesh.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TopologyReport {
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges shared by two triangles that traverse it in the same direction.
    pub inconsistent_edges: usize,
    /// Triangles with repeated vertex indices or (near-)zero area.
    pub degenerate_triangles: usize,
    /// Connected components (by shared edges).
    pub shells: usize,
    /// No boundary and no non-manifold edges.
    pub closed: bool,
    /// Winding and facing.
    pub orientation: Orientation,
}

impl Mesh {
    /// Validates the mesh topology.
    pub fn topology(&self) -> TopologyReport {
        todo!("topology analysis")
    }
}
