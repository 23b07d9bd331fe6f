//! A scan file read as a conform [`Surface`]: a mesh (every object placed and merged), a point
//! cloud with faces (meshed as it is, unless it is to be read as a cloud), or a bare point cloud
//! (a height field over its top envelope).
//!
//! Place in the pipeline: the first step of the conform walk and of gap compensation on a
//! scanned substrate; what comes after works on the [`Surface`] alone.

use std::path::{Path, PathBuf};

use crate::geom::Point3;
use crate::mesh::Mesh;
use crate::scene::{Content, LoadError, LoadOptions, load, placed_meshes};
use crate::surface::{CloudInfo, Surface, SurfaceError};

/// A scan read from a file.
#[derive(Debug)]
pub struct Scan {
    /// The surface to print on.
    pub surface: Surface,
    /// The mesh the surface was built from (marker holes are found in it); `None` for a point
    /// cloud read as a height field.
    pub mesh: Option<Mesh>,
    /// For a point cloud read as a height field: how many points it had and what was left out.
    pub cloud: Option<CloudInfo>,
    /// What the reader noticed about the file (to be shown with its name).
    pub warnings: Vec<String>,
}

/// Why a scan file gives no surface.
#[derive(Debug, thiserror::Error)]
pub enum ScanError {
    /// The file could not be read.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// The file's geometry makes no surface.
    ///
    /// How to fix: see the wrapped error.
    #[error("{}: {error}", path.display())]
    Surface {
        /// The scan file.
        path: PathBuf,
        /// What is wrong with its geometry.
        error: SurfaceError,
    },
    /// The file holds neither a mesh nor a point cloud (an SVG design, a G-code listing).
    ///
    /// How to fix: pass the scan (STL, OBJ, 3MF, PLY or XYZ) as the surface.
    #[error("{}: holds no surface (a mesh or a point cloud is needed)", path.display())]
    NoSurface {
        /// The file.
        path: PathBuf,
    },
}

/// Reads `path` as a surface with `opts`. A point cloud with faces is meshed as it is unless
/// `as_cloud`; a bare cloud becomes a height field with `fold_gap` ([`Surface::from_cloud`]).
pub fn load_scan(
    path: &Path,
    as_cloud: bool,
    fold_gap: f64,
    opts: &LoadOptions,
) -> Result<Scan, ScanError> {
    let file = load(path, opts)?;
    let named = |error: SurfaceError| ScanError::Surface {
        path: path.to_path_buf(),
        error,
    };
    let (surface, mesh, cloud) = match file.content {
        Content::Mesh { scene, .. } => {
            let mut mesh = Mesh::default();
            for m in placed_meshes(&scene) {
                mesh.append(&m);
            }
            (Surface::from_mesh(&mesh).map_err(named)?, Some(mesh), None)
        }
        Content::PointCloud(cloud) if !cloud.triangles.is_empty() && !as_cloud => {
            let mesh = Mesh {
                name: String::new(),
                vertices: cloud
                    .points
                    .iter()
                    .map(|p| Point3::new(p[0], p[1], p[2]))
                    .collect(),
                triangles: cloud.triangles.clone(),
            };
            (Surface::from_mesh(&mesh).map_err(named)?, Some(mesh), None)
        }
        Content::PointCloud(cloud) => {
            let (surface, info) = Surface::from_cloud(&cloud.points, fold_gap).map_err(named)?;
            (surface, None, Some(info))
        }
        _ => {
            return Err(ScanError::NoSurface {
                path: path.to_path_buf(),
            });
        }
    };
    Ok(Scan {
        surface,
        mesh,
        cloud,
        warnings: file.warnings,
    })
}
