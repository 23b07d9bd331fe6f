//! Reading a design: SVG (through `conduit-svg`) or DXF (through `conduit-dxf`) into plain
//! polylines in millimetres.
//!
//! Place in the pipeline: **design** → fill → corners → fillet → contour → schedule → program →
//! emit.
//! Each path of the file becomes one [`Outline`], one structure of the job.

use std::path::{Path, PathBuf};

/// One polyline of a design, named after its file and element.
#[derive(Debug, Clone, PartialEq)]
pub struct Outline {
    /// `FILE#id` (SVG `id`, DXF handle) or `FILE#n` (1-based path number).
    pub name: String,
    /// Vertices, mm, y up. Closed outlines do not repeat the first point.
    pub points: Vec<[f64; 2]>,
    /// Whether the outline is closed.
    pub closed: bool,
}

/// Why a design could not be read.
#[derive(Debug, thiserror::Error)]
pub enum DesignError {
    /// The file could not be read.
    ///
    /// How to fix: check the path and permissions.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        error: std::io::Error,
    },
    /// The SVG reader failed.
    ///
    /// How to fix: see the message, which names the element and line.
    #[error("{}: {error}", path.display())]
    Svg {
        /// The file.
        path: PathBuf,
        /// The reader's error.
        error: conduit_svg::SvgError,
    },
    /// The DXF reader failed.
    ///
    /// How to fix: see the message, which names the entity and line.
    #[error("{}: {error}", path.display())]
    Dxf {
        /// The file.
        path: PathBuf,
        /// The reader's error.
        error: conduit_dxf::DxfError,
    },
    /// The extension is neither `.svg` nor `.dxf`.
    ///
    /// How to fix: export the design as SVG or ASCII DXF.
    #[error("{}: unknown design format (expected .svg or .dxf)", path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The file has no path with two distinct points.
    ///
    /// How to fix: draw the walls as paths, polylines, lines, arcs or circles.
    #[error("{}: no paths to print", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
    },
}

/// What a design file gave, with notes for the user (entities that were not drawn).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Loaded {
    /// The outlines in file order.
    pub outlines: Vec<Outline>,
    /// Notes, e.g. DXF entity types that were skipped.
    pub warnings: Vec<String>,
}

/// Reads `path` (`.svg` or `.dxf`, by extension), flattening curves to within `tolerance_mm`.
pub fn load(path: &Path, tolerance_mm: f64) -> Result<Loaded, DesignError> {
    let bytes = std::fs::read(path).map_err(|error| DesignError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    let label = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let mut loaded = Loaded::default();
    match ext.as_deref() {
        Some("svg") => {
            let d = conduit_svg::read(&bytes, tolerance_mm).map_err(|error| DesignError::Svg {
                path: path.to_path_buf(),
                error,
            })?;
            for (i, p) in d.paths.into_iter().enumerate() {
                let id = p.id.unwrap_or_else(|| (i + 1).to_string());
                loaded.outlines.push(Outline {
                    name: format!("{label}#{id}"),
                    points: p.points,
                    closed: p.closed,
                });
            }
        }
        Some("dxf") => {
            let d = conduit_dxf::read(&bytes, tolerance_mm).map_err(|error| DesignError::Dxf {
                path: path.to_path_buf(),
                error,
            })?;
            for (kind, count) in &d.skipped {
                loaded.warnings.push(format!(
                    "{}: {count} {kind} entit{} not drawn (only LINE, LWPOLYLINE, POLYLINE, ARC, CIRCLE are read)",
                    path.display(),
                    if *count == 1 { "y" } else { "ies" }
                ));
            }
            for (i, p) in d.paths.into_iter().enumerate() {
                let id = p.handle.unwrap_or_else(|| (i + 1).to_string());
                loaded.outlines.push(Outline {
                    name: format!("{label}#{id}"),
                    points: p.points,
                    closed: p.closed,
                });
            }
        }
        _ => {
            return Err(DesignError::UnknownFormat {
                path: path.to_path_buf(),
            });
        }
    }
    if loaded.outlines.is_empty() {
        return Err(DesignError::Empty {
            path: path.to_path_buf(),
        });
    }
    Ok(loaded)
}
