//! Writing scenes as STL, 3MF or OBJ, through [`super::output`]: a failed run never leaves a
//! partial file, and a device, pipe or symbolic link given as the output is kept.

use super::Scene;
use super::output::write_atomically;
use crate::mesh::Mesh;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Mesh formats conduit writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum MeshFormat {
    /// Binary STL (all objects merged; STL has no objects).
    Stl,
    /// ASCII STL.
    StlAscii,
    /// 3MF with one object and build item per scene object.
    #[cfg_attr(feature = "cli", value(name = "3mf"))]
    ThreeMf,
    /// Wavefront OBJ with one `o` group per object.
    Obj,
}

impl MeshFormat {
    /// The format an output path's extension names.
    pub fn from_path(path: &Path) -> Option<MeshFormat> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "stl" => Some(MeshFormat::Stl),
            "3mf" => Some(MeshFormat::ThreeMf),
            "obj" => Some(MeshFormat::Obj),
            _ => None,
        }
    }

    /// The file extension for this format.
    pub fn extension(self) -> &'static str {
        match self {
            MeshFormat::Stl | MeshFormat::StlAscii => "stl",
            MeshFormat::ThreeMf => "3mf",
            MeshFormat::Obj => "obj",
        }
    }
}

/// A file that failed to write.
#[derive(Debug, thiserror::Error)]
#[error("{}: {kind}", path.display())]
pub struct SaveError {
    /// The target file.
    pub path: PathBuf,
    /// What went wrong.
    pub kind: SaveErrorKind,
}

/// Why a write failed.
#[derive(Debug, thiserror::Error)]
pub enum SaveErrorKind {
    /// Filesystem error.
    #[error("cannot write: {0}")]
    Io(#[from] std::io::Error),
    /// 3MF writer error.
    #[error("3MF: {0}")]
    ThreeMf(Box<conduit_3mf::ThreeMfError>),
    /// A coordinate does not fit the output format (STL stores 32-bit floats).
    #[error("{0}")]
    Unrepresentable(String),
}

/// The scene's objects with their transforms applied.
pub fn placed_meshes(scene: &Scene) -> Vec<Mesh> {
    scene
        .objects
        .iter()
        .map(|o| {
            let mut m = o.mesh.clone();
            m.name = o.name.clone();
            m.transform(&o.transform);
            m
        })
        .collect()
}

fn f32_triangles(meshes: &[Mesh]) -> Result<Vec<[[f32; 3]; 3]>, SaveErrorKind> {
    let mut out = Vec::with_capacity(meshes.iter().map(|m| m.triangles.len()).sum());
    for m in meshes {
        for tri in m.triangle_corners() {
            let mut t = [[0f32; 3]; 3];
            for (dst, p) in t.iter_mut().zip(tri.iter()) {
                for k in 0..3 {
                    let v = p[k] as f32;
                    if !v.is_finite() {
                        return Err(SaveErrorKind::Unrepresentable(format!(
                            "coordinate {} of object '{}' does not fit a 32-bit float",
                            p[k], m.name
                        )));
                    }
                    dst[k] = v;
                }
            }
            out.push(t);
        }
    }
    Ok(out)
}

/// Builds the 3MF model of a scene: one mesh object and one build item per scene object.
pub fn to_3mf_model(scene: &Scene) -> conduit_3mf::Model {
    let mut model = conduit_3mf::Model {
        unit: conduit_3mf::Unit::Millimeter,
        language: None,
        metadata: vec![conduit_3mf::Metadata {
            name: "Application".into(),
            value: format!("conduit {}", env!("CARGO_PKG_VERSION")),
        }],
        required_extensions: Vec::new(),
        objects: Vec::new(),
        base_materials: Vec::new(),
        color_groups: Vec::new(),
        build: Vec::new(),
    };
    for (i, o) in scene.objects.iter().enumerate() {
        let id = i as u32 + 1;
        model.objects.push(conduit_3mf::Object {
            id,
            name: Some(o.name.clone()),
            kind: conduit_3mf::ObjectType::Model,
            pid: None,
            pindex: None,
            content: conduit_3mf::ObjectContent::Mesh(threemf_mesh(&o.mesh)),
        });
        model.build.push(conduit_3mf::BuildItem {
            object_id: id,
            path: None,
            transform: (!o.transform.is_identity()).then(|| o.transform.to_3mf()),
            part_number: None,
        });
    }
    model
}

/// The 3MF mesh of an indexed mesh. 3MF requires the three vertex indices of a triangle to be
/// distinct; a triangle that collapsed onto a repeated index when the soup was welded (STL files
/// carry such slivers) gets its own copies of the repeated vertex, so every triangle and every
/// coordinate survives the trip unchanged.
fn threemf_mesh(mesh: &Mesh) -> conduit_3mf::Mesh {
    let mut vertices: Vec<[f64; 3]> = mesh.vertices.iter().map(|p| [p.x, p.y, p.z]).collect();
    let triangles = mesh
        .triangles
        .iter()
        .map(|&[a, b, c]| {
            let mut v = [a, b, c];
            for i in 1..3 {
                if v[..i].contains(&v[i]) {
                    vertices.push(vertices[v[i] as usize]);
                    v[i] = (vertices.len() - 1) as u32;
                }
            }
            conduit_3mf::Triangle {
                v,
                pid: None,
                p: [None; 3],
            }
        })
        .collect();
    conduit_3mf::Mesh {
        vertices,
        triangles,
    }
}

/// Writes a scene to `path` in `format`, atomically.
pub fn save(scene: &Scene, path: &Path, format: MeshFormat) -> Result<(), SaveError> {
    write_atomically(path, |f| -> Result<(), SaveErrorKind> {
        let mut w = BufWriter::new(f);
        match format {
            MeshFormat::Stl | MeshFormat::StlAscii => {
                let tris = f32_triangles(&placed_meshes(scene))?;
                let name = stl_name(scene);
                if format == MeshFormat::Stl {
                    conduit_stl::write_binary(&mut w, &name, &tris)?;
                } else {
                    conduit_stl::write_ascii(&mut w, &name, &tris)?;
                }
            }
            MeshFormat::ThreeMf => conduit_3mf::write(&mut w, &to_3mf_model(scene))?,
            MeshFormat::Obj => {
                let objects: Vec<conduit_obj::ObjObject> = placed_meshes(scene)
                    .into_iter()
                    .map(|m| conduit_obj::ObjObject {
                        name: m.name,
                        vertices: m.vertices.iter().map(|p| [p.x, p.y, p.z]).collect(),
                        triangles: m.triangles,
                    })
                    .collect();
                conduit_obj::write(&mut w, &objects)?;
            }
        }
        w.flush()?;
        Ok(())
    })
    .map_err(|kind| SaveError {
        path: path.to_path_buf(),
        kind,
    })
}

fn stl_name(scene: &Scene) -> String {
    match scene.objects.as_slice() {
        [one] => one.name.clone(),
        _ => "conduit".to_string(),
    }
}

impl From<conduit_3mf::ThreeMfError> for SaveErrorKind {
    fn from(e: conduit_3mf::ThreeMfError) -> Self {
        SaveErrorKind::ThreeMf(Box::new(e))
    }
}
