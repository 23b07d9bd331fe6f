//! Reading files into the pipeline's input types and writing meshes back out.
//!
//! Place in the pipeline: the first step of every command (and the last of `convert`). Format
//! crates under `formats/` describe files; this module converts what they return into [`Scene`]s of
//! [`crate::mesh::Mesh`]es in millimetres, and back. Every command's output files go through
//! `output` ([`OutputSet`], [`write_atomically`]): never clobbering an input, a device or a link.

mod detect;
mod load;
mod output;
mod save;
pub mod volumes;
pub mod words;

pub use detect::FileKind;
pub use load::{
    Content, LoadError, LoadErrorKind, LoadOptions, LoadedFile, MeshDetails, ThreeMfDetails, load,
    load_scene, load_scene_and_settings,
};
pub use output::{OutputError, OutputSet, write_atomically};
pub use save::{MeshFormat, SaveError, SaveErrorKind, placed_meshes, save, to_3mf_model};

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
    /// The tool (extruder) that prints it, when known.
    pub tool: Option<usize>,
    /// Its negative volumes (a slicer's 3MF), in the same coordinates as `mesh`: the planar
    /// slice subtracts them layer by layer.
    pub negative: Option<Mesh>,
}

/// Objects as a 3MF build would place them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scene {
    /// The placed objects.
    pub objects: Vec<SceneObject>,
}

impl Scene {
    /// True when an object has negative volumes to subtract.
    pub fn has_negative_volumes(&self) -> bool {
        self.objects.iter().any(|o| o.negative.is_some())
    }

    /// Total triangle count over all objects.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.mesh.triangles.len()).sum()
    }
}
