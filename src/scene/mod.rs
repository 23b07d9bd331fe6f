//! Reading files into the pipeline's input types and writing meshes back out.
//!
//! Place in the pipeline: the first step of every command. Format crates under `formats/` describe
//! files; this module converts what they return into [`Scene`]s of [`crate::mesh::Mesh`]es in
//! millimetres.

use crate::geom::Transform;
use crate::mesh::Mesh;

/// One placed object of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneObject {
    /// The object's name.
    pub name: String,
    /// Its mesh, in object coordinates (millimetres).
    pub mesh: Mesh,
    /// Where the build places it.
    pub transform: Transform,
    /// The tool (extruder) that prints it, when the file says.
    pub tool: Option<usize>,
}

/// Objects as a 3MF build would place them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scene {
    /// The placed objects.
    pub objects: Vec<SceneObject>,
}
