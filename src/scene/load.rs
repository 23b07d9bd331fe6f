//! Reading any supported file into pipeline types, with errors that name the file.

use super::detect::FileKind;
use super::{Scene, SceneObject};
use crate::geom::{Point3, Transform};
use crate::mesh::Mesh;
use std::path::{Path, PathBuf};

/// Settings for reading files.
#[derive(Debug, Clone)]
pub struct LoadOptions {
    /// Files larger than this many bytes are refused before they are read (default 4 GiB).
    pub max_file_bytes: u64,
    /// Limits applied to 3MF packages (zip-bomb and count guards).
    pub threemf_limits: conduit_3mf::Limits,
    /// How 3MF packages are read: the default mode reads past harmless defects with a warning
    /// each, strict mode refuses them (`conduit --strict`).
    pub threemf_read: conduit_3mf::ReadOptions,
    /// Curve flattening tolerance for SVG designs, in millimetres.
    pub svg_tolerance_mm: f64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            max_file_bytes: 4 << 30,
            threemf_limits: conduit_3mf::Limits::default(),
            threemf_read: conduit_3mf::ReadOptions::default(),
            svg_tolerance_mm: crate::geom::Tolerances::default().curve_flattening.mm(),
        }
    }
}

/// A file that failed to load, with the reason.
#[derive(Debug, thiserror::Error)]
#[error("{}: {kind}", path.display())]
pub struct LoadError {
    /// The file.
    pub path: PathBuf,
    /// What went wrong (boxed: format errors carry rich context and errors should stay cheap to
    /// return).
    pub kind: Box<LoadErrorKind>,
}

/// Why a file failed to load.
#[derive(Debug, thiserror::Error)]
pub enum LoadErrorKind {
    /// The file could not be read.
    #[error("cannot read file: {0}")]
    Io(#[from] std::io::Error),
    /// The file is over the size limit.
    #[error("file is {size} bytes, over the limit of {limit} bytes")]
    TooLarge {
        /// File size in bytes.
        size: u64,
        /// The limit in bytes.
        limit: u64,
    },
    /// Neither the extension nor the content names a format conduit reads.
    #[error(
        "unrecognised file format (supported: STL, 3MF, OBJ, OFF, PLY, XYZ, EAGLE .sch/.brd, KiCad .kicad_pcb/.kicad_sch/.net, G-code, SVG)"
    )]
    Unrecognised,
    /// STL error.
    #[error("STL: {0}")]
    Stl(#[from] conduit_stl::StlError),
    /// 3MF error.
    #[error("3MF: {0}")]
    ThreeMf(Box<conduit_3mf::ThreeMfError>),
    /// OBJ error.
    #[error("OBJ: {0}")]
    Obj(#[from] conduit_obj::ObjError),
    /// OFF error.
    #[error("OFF: {0}")]
    Off(#[from] conduit_off::OffError),
    /// PLY error.
    #[error("PLY: {0}")]
    Ply(#[from] conduit_pointcloud::PlyError),
    /// XYZ error.
    #[error("XYZ: {0}")]
    Xyz(#[from] conduit_pointcloud::XyzError),
    /// EAGLE error.
    #[error("EAGLE: {0}")]
    Eagle(#[from] conduit_eagle::EagleError),
    /// KiCad error.
    #[error("KiCad: {0}")]
    Kicad(#[from] conduit_kicad::KicadError),
    /// G-code error.
    #[error("G-code: {0}")]
    Gcode(#[from] conduit_gcode::GcodeError),
    /// SVG error.
    #[error("SVG: {0}")]
    Svg(#[from] conduit_svg::SvgError),
    /// The file is valid but holds no mesh where one was needed.
    #[error("{0}")]
    NotAMesh(String),
}

/// Format-specific facts about a mesh file, for `conduit info`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(untagged)]
pub enum MeshDetails {
    /// STL.
    Stl {
        /// "ascii" or "binary".
        encoding: &'static str,
        /// The solid name or header text.
        name: Option<String>,
    },
    /// 3MF.
    ThreeMf(Box<ThreeMfDetails>),
    /// OBJ.
    Obj,
    /// OFF.
    Off,
    /// PLY with faces.
    Ply,
}

/// What a 3MF package holds.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ThreeMfDetails {
    /// The root model's unit.
    pub unit: String,
    /// Model parts in the package.
    pub model_parts: usize,
    /// Objects across all model parts.
    pub objects: usize,
    /// Build items of the root model.
    pub build_items: usize,
    /// Base material groups and their total materials.
    pub base_material_groups: usize,
    /// Colour groups.
    pub color_groups: usize,
    /// Metadata entries of the root model as (name, value).
    pub metadata: Vec<(String, String)>,
    /// Required extension namespaces.
    pub required_extensions: Vec<String>,
    /// The profile, object settings and volumes a slicer stored beside the model.
    #[serde(skip)]
    pub slicer: conduit_3mf::SlicerSettings,
}

/// What a file held.
#[derive(Debug, Clone)]
pub enum Content {
    /// Triangle meshes placed in a scene.
    Mesh {
        /// The scene.
        scene: Scene,
        /// Format-specific facts.
        details: MeshDetails,
    },
    /// A point cloud.
    PointCloud(conduit_pointcloud::PointCloud),
    /// An EAGLE schematic, board or library.
    Eagle(conduit_eagle::Document),
    /// A KiCad board, schematic (its sheets read from beside it) or netlist export.
    Kicad(conduit_kicad::Document),
    /// A G-code program (summarised).
    Gcode(conduit_gcode::Summary),
    /// A 2D design.
    Design(conduit_svg::Design),
}

/// A loaded file.
#[derive(Debug, Clone)]
pub struct LoadedFile {
    /// Where it came from.
    pub path: PathBuf,
    /// Its format.
    pub kind: FileKind,
    /// What it held.
    pub content: Content,
    /// Non-fatal findings from the reader.
    pub warnings: Vec<String>,
}

/// Reads a file of any supported format.
pub fn load(path: &Path, opts: &LoadOptions) -> Result<LoadedFile, LoadError> {
    let err = |kind: LoadErrorKind| LoadError {
        path: path.to_path_buf(),
        kind: Box::new(kind),
    };
    let bytes = read_bounded(path, opts.max_file_bytes).map_err(err)?;
    let kind = FileKind::detect(path, &bytes).ok_or_else(|| err(LoadErrorKind::Unrecognised))?;
    let (content, warnings) = parse(path, kind, &bytes, opts).map_err(err)?;
    Ok(LoadedFile {
        path: path.to_path_buf(),
        kind,
        content,
        warnings,
    })
}

/// Reads a file that must hold a triangle mesh and returns its scene.
pub fn load_scene(path: &Path, opts: &LoadOptions) -> Result<(Scene, Vec<String>), LoadError> {
    let file = load(path, opts)?;
    match file.content {
        Content::Mesh { scene, .. } => Ok((scene, file.warnings)),
        _ => Err(LoadError {
            path: path.to_path_buf(),
            kind: Box::new(LoadErrorKind::NotAMesh(format!(
                "a {:?} file holds no triangle mesh",
                file.kind
            ))),
        }),
    }
}

/// [`load_scene`], also returning the settings a slicer stored in a 3MF (empty for other
/// files): what `conduit slice` takes as the job's profile.
pub fn load_scene_and_settings(
    path: &Path,
    opts: &LoadOptions,
) -> Result<(Scene, Vec<String>, conduit_3mf::SlicerSettings), LoadError> {
    let file = load(path, opts)?;
    match file.content {
        Content::Mesh { scene, details } => {
            let settings = match details {
                MeshDetails::ThreeMf(d) => d.slicer,
                _ => conduit_3mf::SlicerSettings::default(),
            };
            Ok((scene, file.warnings, settings))
        }
        _ => Err(LoadError {
            path: path.to_path_buf(),
            kind: Box::new(LoadErrorKind::NotAMesh(format!(
                "a {:?} file holds no triangle mesh",
                file.kind
            ))),
        }),
    }
}

fn read_bounded(path: &Path, limit: u64) -> Result<Vec<u8>, LoadErrorKind> {
    let size = std::fs::metadata(path)?.len();
    if size > limit {
        return Err(LoadErrorKind::TooLarge { size, limit });
    }
    Ok(std::fs::read(path)?)
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn point(v: &[f64; 3]) -> Point3 {
    Point3::new(v[0], v[1], v[2])
}

fn object(name: String, mesh: Mesh) -> SceneObject {
    SceneObject {
        name,
        mesh,
        transform: Transform::identity(),
        tool: None,
        negative: None,
    }
}

fn indexed_mesh(name: &str, vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Mesh {
    Mesh {
        name: name.to_string(),
        vertices: vertices.iter().map(point).collect(),
        triangles: triangles.to_vec(),
    }
}

fn parse(
    path: &Path,
    kind: FileKind,
    bytes: &[u8],
    opts: &LoadOptions,
) -> Result<(Content, Vec<String>), LoadErrorKind> {
    let mut warnings = Vec::new();
    let content = match kind {
        FileKind::Stl => stl_content(path, bytes)?,
        FileKind::ThreeMf => threemf_content(bytes, opts, &mut warnings)?,
        FileKind::Obj => obj_content(path, bytes, &mut warnings)?,
        FileKind::Off => {
            let off = conduit_off::read(bytes)?;
            let name = stem(path);
            let mesh = indexed_mesh(&name, &off.vertices, &off.triangles);
            single_mesh(name, mesh, MeshDetails::Off)
        }
        FileKind::Ply => {
            let cloud = conduit_pointcloud::read_ply(bytes)?;
            if cloud.triangles.is_empty() {
                Content::PointCloud(cloud)
            } else {
                let name = stem(path);
                let mesh = indexed_mesh(&name, &cloud.points, &cloud.triangles);
                single_mesh(name, mesh, MeshDetails::Ply)
            }
        }
        FileKind::Xyz => Content::PointCloud(conduit_pointcloud::read_xyz(bytes)?),
        FileKind::Eagle => Content::Eagle(conduit_eagle::read(bytes)?),
        FileKind::Kicad => {
            Content::Kicad(conduit_kicad::read(bytes, path, &mut |p| std::fs::read(p))?)
        }
        FileKind::Gcode => Content::Gcode(conduit_gcode::summarize(&conduit_gcode::parse(bytes)?)),
        FileKind::Svg => Content::Design(conduit_svg::read(bytes, opts.svg_tolerance_mm)?),
    };
    Ok((content, warnings))
}

/// A mesh file's content of one object.
fn single_mesh(name: String, mesh: Mesh, details: MeshDetails) -> Content {
    Content::Mesh {
        scene: Scene {
            objects: vec![object(name, mesh)],
        },
        details,
    }
}

/// An STL file: one object named after its solid, or after the file when the solid has none.
fn stl_content(path: &Path, bytes: &[u8]) -> Result<Content, LoadErrorKind> {
    let stl = conduit_stl::read(bytes)?;
    let name = stl
        .name
        .clone()
        .filter(|n| !n.is_empty())
        .unwrap_or_else(|| stem(path));
    let mesh = Mesh::from_triangle_soup(
        name.clone(),
        stl.triangles
            .iter()
            .map(|t| t.map(|v| Point3::new(v[0] as f64, v[1] as f64, v[2] as f64))),
    );
    let encoding = match stl.encoding {
        conduit_stl::Encoding::Ascii => "ascii",
        conduit_stl::Encoding::Binary => "binary",
    };
    let details = MeshDetails::Stl {
        encoding,
        name: stl.name,
    };
    Ok(single_mesh(name, mesh, details))
}

/// A 3MF package: one object per flattened build object (named as the slicer that wrote it
/// names it, else as the 3MF does, else `object <id>`),
/// holding its model parts, with its negative volumes beside them
/// ([`super::volumes`]); the reader's warnings and what the volumes left out are added to
/// `warnings`, each once.
fn threemf_content(
    bytes: &[u8],
    opts: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Result<Content, LoadErrorKind> {
    let mut package = conduit_3mf::read_with(bytes, &opts.threemf_limits, opts.threemf_read)?;
    let flat = package.flatten()?;
    warnings.extend(package.warnings.iter().cloned());
    let slicer = std::mem::take(&mut package.slicer);
    let volumes = super::volumes::Volumes::new(&slicer);
    let root = package.root();
    let mut objects = Vec::with_capacity(flat.len());
    for f in &flat {
        let name = match volumes.name_of(f) {
            Some(n) if !n.is_empty() => n.to_owned(),
            _ if f.name.is_empty() => format!("object {}", f.object_id),
            _ => f.name.clone(),
        };
        let split = volumes.split(f, &name);
        for w in split.warnings {
            if !warnings.contains(&w) {
                warnings.push(w);
            }
        }
        let mesh = if split.printed.len() == f.triangles.len() {
            indexed_mesh(&name, &f.vertices, &f.triangles)
        } else {
            let (vertices, triangles) = super::volumes::compact(&f.vertices, &split.printed);
            indexed_mesh(&name, &vertices, &triangles)
        };
        let mut o = object(name.clone(), mesh);
        if !split.negative.is_empty() {
            let (vertices, triangles) = super::volumes::compact(&f.vertices, &split.negative);
            o.negative = Some(indexed_mesh(&name, &vertices, &triangles));
        }
        objects.push(o);
    }
    let details = ThreeMfDetails {
        unit: format!("{:?}", root.unit).to_lowercase(),
        model_parts: package.models.len(),
        objects: package.models.values().map(|m| m.objects.len()).sum(),
        build_items: root.build.len(),
        base_material_groups: root.base_materials.len(),
        color_groups: root.color_groups.len(),
        metadata: root
            .metadata
            .iter()
            .map(|m| (m.name.clone(), m.value.clone()))
            .collect(),
        required_extensions: root.required_extensions.clone(),
        slicer,
    };
    Ok(Content::Mesh {
        scene: Scene { objects },
        details: MeshDetails::ThreeMf(Box::new(details)),
    })
}

/// An OBJ file: one object per model (nameless ones named after the file); the reader's
/// warnings are added to `warnings`.
fn obj_content(
    path: &Path,
    bytes: &[u8],
    warnings: &mut Vec<String>,
) -> Result<Content, LoadErrorKind> {
    let obj = conduit_obj::read(bytes, path.parent())?;
    warnings.extend(obj.warnings);
    let objects = obj
        .objects
        .iter()
        .map(|o| {
            let name = if o.name.is_empty() {
                stem(path)
            } else {
                o.name.clone()
            };
            object(name.clone(), indexed_mesh(&name, &o.vertices, &o.triangles))
        })
        .collect();
    Ok(Content::Mesh {
        scene: Scene { objects },
        details: MeshDetails::Obj,
    })
}

impl From<conduit_3mf::ThreeMfError> for LoadErrorKind {
    fn from(e: conduit_3mf::ThreeMfError) -> Self {
        LoadErrorKind::ThreeMf(Box::new(e))
    }
}
