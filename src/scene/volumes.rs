//! A slicer's volumes inside a 3MF object: which triangles are printed, which are subtracted,
//! and which only carry settings or support hints.
//!
//! Place in the pipeline: part of reading a 3MF into a [`super::Scene`]. PrusaSlicer and
//! OrcaSlicer store an object's modifiers, negative volumes and support enforcers and blockers
//! in the object's mesh, naming their triangles in `Metadata/*.config`
//! ([`conduit_3mf::SlicerSettings`]). Only model parts are printed; negative volumes become the
//! object's [`super::SceneObject::negative`] mesh, which the planar slice subtracts layer by
//! layer; modifiers, enforcers and blockers are left out, each named in a warning with the
//! settings it carried that are not honoured.

use std::collections::HashMap;

use conduit_3mf::{FlatMesh, ObjectSettings, SlicerSettings, Volume, VolumeKind, VolumeMesh};

/// An object's triangles sorted by what they are for.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Split {
    /// Triangles of model parts (all of them for an object no slicer described).
    pub printed: Vec<[u32; 3]>,
    /// Triangles of negative volumes.
    pub negative: Vec<[u32; 3]>,
    /// One line per volume that is not printed as it was meant, naming the object.
    pub warnings: Vec<String>,
}

/// The volumes of the described objects, keyed by the id of the mesh object their triangles
/// are in.
pub struct Volumes<'s> {
    by_mesh: HashMap<u32, Vec<(&'s ObjectSettings, &'s Volume)>>,
}

impl<'s> Volumes<'s> {
    /// Indexes the volumes of `settings`.
    pub fn new(settings: &'s SlicerSettings) -> Self {
        let mut by_mesh: HashMap<u32, Vec<_>> = HashMap::new();
        for o in &settings.objects {
            for v in &o.volumes {
                let mesh = match v.mesh {
                    VolumeMesh::Triangles { .. } => o.id,
                    VolumeMesh::Object(id) => id,
                };
                by_mesh.entry(mesh).or_default().push((o, v));
            }
        }
        Volumes { by_mesh }
    }

    /// The volume the triangle `index` of mesh object `mesh` belongs to: `Ok(None)` when no
    /// volume is described for that mesh (it is printed), `Err(())` when volumes are but
    /// none holds the triangle (PrusaSlicer leaves such triangles out).
    fn volume_of(
        &self,
        mesh: u32,
        index: u32,
    ) -> Result<Option<(&'s ObjectSettings, &'s Volume)>, ()> {
        let Some(list) = self.by_mesh.get(&mesh) else {
            return Ok(None);
        };
        list.iter()
            .find(|(_, v)| match v.mesh {
                VolumeMesh::Triangles { first, last } => (first..=last).contains(&index),
                VolumeMesh::Object(_) => true,
            })
            .copied()
            .map(Some)
            .ok_or(())
    }

    /// The name the slicer gave the object `flat` places: the described object with the build
    /// item's id, or the one whose volumes hold its first triangle (another instance).
    pub fn name_of(&self, flat: &FlatMesh) -> Option<&'s str> {
        let by_item = self
            .by_mesh
            .values()
            .flatten()
            .find(|(o, _)| o.id == flat.object_id);
        let by_mesh = || {
            let (mesh, _) = flat.triangle_sources.first()?;
            self.by_mesh.get(mesh)?.first()
        };
        by_item.or_else(by_mesh)?.0.name.as_deref()
    }

    /// Sorts the triangles of `flat` (named `name`).
    pub fn split(&self, flat: &FlatMesh, name: &str) -> Split {
        let mut out = Split::default();
        if self.by_mesh.is_empty() {
            out.printed = flat.triangles.clone();
            return out;
        }
        let mut left_out: Vec<(&Volume, usize)> = Vec::new();
        let mut outside = 0usize;
        for (tri, &(mesh, index)) in flat.triangles.iter().zip(&flat.triangle_sources) {
            match self.volume_of(mesh, index) {
                Ok(None) => out.printed.push(*tri),
                Ok(Some((_, v))) => match v.kind {
                    VolumeKind::ModelPart => out.printed.push(*tri),
                    VolumeKind::NegativeVolume => out.negative.push(*tri),
                    _ => match left_out.iter_mut().find(|(l, _)| std::ptr::eq(*l, v)) {
                        Some((_, n)) => *n += 1,
                        None => left_out.push((v, 1)),
                    },
                },
                Err(()) => outside += 1,
            }
        }
        let mut described: Vec<&Volume> = Vec::new();
        for (mesh, _) in &flat.triangle_sources {
            for (_, v) in self.by_mesh.get(mesh).into_iter().flatten() {
                if !described.iter().any(|d| std::ptr::eq(*d, *v)) {
                    described.push(v);
                }
            }
        }
        for v in described {
            if let Some(w) = warning(name, v, &left_out) {
                out.warnings.push(w);
            }
        }
        if outside > 0 {
            out.warnings.push(format!(
                "object \"{name}\": {outside} triangle(s) in no volume of the slicer's \
                 description were left out, as PrusaSlicer does"
            ));
        }
        out
    }
}

/// What is said about volume `v` of object `name` when it was left out of the print (it is in
/// `left_out`). Its settings are named by the config, which knows which of them matter.
fn warning(name: &str, v: &Volume, left_out: &[(&Volume, usize)]) -> Option<String> {
    left_out.iter().find(|(l, _)| std::ptr::eq(*l, v))?;
    let label = v
        .name
        .as_deref()
        .map_or_else(String::new, |n| format!(" \"{n}\""));
    let kind = v.kind.describe();
    match v.kind {
        VolumeKind::ModelPart | VolumeKind::NegativeVolume => None,
        VolumeKind::Modifier => Some(format!("object \"{name}\": modifier{label} not printed")),
        VolumeKind::SupportEnforcer | VolumeKind::SupportBlocker => Some(format!(
            "object \"{name}\": {kind}{label} not printed and not honoured: supports follow \
             the [support] settings alone"
        )),
    }
}

/// The vertices `triangles` use, in their first-use order, and the triangles renumbered: a
/// mesh of some volumes only, whose bounding box is theirs.
pub fn compact(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut new_index: HashMap<u32, u32> = HashMap::new();
    let mut kept = Vec::new();
    let renumbered = triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                *new_index.entry(v).or_insert_with(|| {
                    kept.push(vertices.get(v as usize).copied().unwrap_or_default());
                    // At most as many vertices as the flattened mesh, which has a u32 index.
                    u32::try_from(kept.len() - 1).unwrap_or(u32::MAX)
                })
            })
        })
        .collect();
    (kept, renumbered)
}
