//! The scanned surface as a queryable triangle mesh: top height at (x, y), closest point, normal.
//!
//! Place in the pipeline: the first step of conformal printing. Built from a triangle mesh (STL,
//! OBJ, 3MF, PLY with faces) or from a point cloud (XYZ, PLY points), registered into the
//! machine frame ([`crate::conform::register`]), then asked by every later step. Queries go through parry's
//! bounding-volume hierarchy: a downward ray cast gives the top height (what a 3-axis nozzle
//! coming from above meets), a point projection the closest point and its triangle.
//!
//! # Point clouds
//!
//! A scan of a height field (a film on a table, the top of a part) is triangulated by a 2D
//! Delaunay triangulation (spade) over x, y with each vertex keeping its z (2.5D). A cloud that
//! folds over itself (a whole object scanned from all sides) has several z for one (x, y),
//! which a height field cannot hold: the cloud is binned in a grid of cells about the point
//! spacing wide, and points more than `fold_gap` below the top of their cell are left out. How
//! many were left out is reported ([`CloudInfo`]), so a user sees that only the top envelope
//! was kept.
//!
//! # Two kinds of height query
//!
//! [`Surface::top`] (the projection of the design, step 4) is a parry ray cast and also gives
//! the hit's normal. The nozzle checks ask the height hundreds of times per path point, so
//! [`Surface::height`] answers from the exact height field of the triangles turned to face up
//! ([`HeightField`]: a uniform xy grid, the plane of each triangle containing the point, the
//! highest wins). Both are exact on the triangles; the grid avoids walking a 3D hierarchy for
//! a question that is two-dimensional, about ten times faster on the test scans. Scans are
//! often wound inconsistently, so every non-vertical triangle takes part whatever its winding.

use super::HeightField;
use crate::geom::{Point3, Vector3};
use crate::mesh::Mesh;
use nalgebra::Isometry3;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::{PointQueryWithLocation, Ray, RayCast};
use parry3d_f64::shape::TriMesh;
use serde::Serialize;
use spade::{DelaunayTriangulation, Point2 as SPoint, Triangulation};

/// Why a surface could not be built.
#[derive(Debug, thiserror::Error)]
pub enum SurfaceError {
    /// No usable triangles (or fewer than three distinct points in a cloud).
    ///
    /// How to fix: check that the file holds the scan and not an empty or flat-line export.
    #[error("the surface has no usable triangles")]
    Empty,
    /// A coordinate is NaN or infinite.
    ///
    /// How to fix: clean the scan (remove invalid points) and export again.
    #[error("the surface has a coordinate that is not finite")]
    NotFinite,
    /// The triangulation of a cloud failed.
    #[error("triangulating the point cloud: {0}")]
    Triangulation(String),
    /// A point lies farther than [`MAX_EXTENT`] from the origin along an axis: a stray point
    /// (or a file in other units) that would size the surface's grids by its distance.
    ///
    /// How to fix: remove the outlier from the scan, or export it in millimetres.
    #[error(
        "{element} {index}: coordinate {value:e} mm is beyond the {MAX_EXTENT} mm working extent (a stray point or a file not in mm)"
    )]
    OutOfRange {
        /// What is numbered: `"point"` (a cloud) or `"triangle"` (a mesh).
        element: &'static str,
        /// 1-based number of the point or triangle, in file order.
        index: usize,
        /// The offending coordinate, mm.
        value: f64,
    },
}

/// Largest coordinate (absolute, per axis) of a surface, mm: 10 m. No bed, robot cell or scanner
/// volume this tool drives comes near it, and every grid over a surface is sized from its
/// extent, so one far stray point would otherwise make the grids (or the work over them) grow
/// with its distance.
pub const MAX_EXTENT: f64 = 10_000.0;

/// The first coordinate of `p` that is beyond [`MAX_EXTENT`].
fn out_of_range(p: &[f64; 3]) -> Option<f64> {
    p.iter().copied().find(|v| v.abs() > MAX_EXTENT)
}

/// What was done to a point cloud to make a surface of it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CloudInfo {
    /// Points in the file.
    pub points: usize,
    /// Points used as vertices (the top envelope).
    pub used: usize,
    /// Points left out because they lie below a higher layer of the cloud.
    pub below_fold: usize,
    /// Whether the cloud folds over itself (some points were left out): a height field holds
    /// only its top.
    pub folds: bool,
    /// Grid cell used to find folds, mm.
    pub cell: f64,
}

/// A closest-point answer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// The closest surface point.
    pub point: Point3,
    /// Unit normal of its triangle (pointing up where the triangle faces up).
    pub normal: Vector3,
    /// Distance to it, mm.
    pub distance: f64,
}

/// A triangle surface with spatial queries (see the module docs).
pub struct Surface {
    triangles: Vec<[Point3; 3]>,
    normals: Vec<Vector3>,
    shape: TriMesh,
    lo: Point3,
    hi: Point3,
    /// Highest z of the triangles overlapping each cell of a coarse xy grid (row-major), for
    /// cheap upper bounds of the height over an area.
    grid_max: Vec<f64>,
    grid_dims: [usize; 2],
    grid_cell: f64,
    heights: HeightField,
}

/// Cells per side of the coarse height grid, at most.
const GRID_CELLS: usize = 128;

impl std::fmt::Debug for Surface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Surface")
            .field("triangles", &self.triangles.len())
            .field("lo", &self.lo)
            .field("hi", &self.hi)
            .finish()
    }
}

fn pv(p: &Point3) -> PVec {
    PVec::new(p.x, p.y, p.z)
}

impl Surface {
    /// The surface of a mesh's triangles (degenerate ones and bad indices skipped).
    pub fn from_mesh(mesh: &Mesh) -> Result<Self, SurfaceError> {
        let tris = mesh.triangles.iter().filter_map(|t| {
            let c = [
                *mesh.vertices.get(t[0] as usize)?,
                *mesh.vertices.get(t[1] as usize)?,
                *mesh.vertices.get(t[2] as usize)?,
            ];
            Some(c)
        });
        Self::from_triangles(tris.collect())
    }

    /// The surface of triangles given by their corners.
    pub fn from_triangles(tris: Vec<[Point3; 3]>) -> Result<Self, SurfaceError> {
        let mut triangles = Vec::with_capacity(tris.len());
        let mut normals = Vec::with_capacity(tris.len());
        for (i, c) in tris.into_iter().enumerate() {
            if c.iter()
                .any(|p| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()))
            {
                return Err(SurfaceError::NotFinite);
            }
            if let Some(value) = c.iter().find_map(|p| out_of_range(&[p.x, p.y, p.z])) {
                return Err(SurfaceError::OutOfRange {
                    element: "triangle",
                    index: i + 1,
                    value,
                });
            }
            let n = (c[1] - c[0]).cross(&(c[2] - c[0]));
            let len = n.norm();
            if len <= 1e-12 {
                continue;
            }
            triangles.push(c);
            normals.push(n / len);
        }
        if triangles.is_empty() {
            return Err(SurfaceError::Empty);
        }
        let mut lo = Point3::new(f64::MAX, f64::MAX, f64::MAX);
        let mut hi = Point3::new(f64::MIN, f64::MIN, f64::MIN);
        let mut vertices = Vec::with_capacity(triangles.len() * 3);
        let mut indices = Vec::with_capacity(triangles.len());
        for (i, c) in triangles.iter().enumerate() {
            for p in c {
                lo = lo.inf(p);
                hi = hi.sup(p);
                vertices.push(pv(p));
            }
            let b = (i * 3) as u32;
            indices.push([b, b + 1, b + 2]);
        }
        let shape = TriMesh::new(vertices, indices).map_err(|_| SurfaceError::Empty)?;
        let grid_cell = ((hi.x - lo.x).max(hi.y - lo.y) / GRID_CELLS as f64).max(1e-6);
        let grid_dims = [
            ((hi.x - lo.x) / grid_cell) as usize + 1,
            ((hi.y - lo.y) / grid_cell) as usize + 1,
        ];
        let mut grid_max = vec![f64::MIN; grid_dims[0] * grid_dims[1]];
        for c in &triangles {
            let (mut a, mut b) = (c[0], c[0]);
            for p in c {
                a = a.inf(p);
                b = b.sup(p);
            }
            let top = b.z;
            let [i0, j0] = cell_of(lo, grid_cell, grid_dims, a.x, a.y);
            let [i1, j1] = cell_of(lo, grid_cell, grid_dims, b.x, b.y);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let m = &mut grid_max[j * grid_dims[0] + i];
                    *m = m.max(top);
                }
            }
        }
        let upward = Mesh {
            name: String::new(),
            vertices: triangles.iter().flatten().copied().collect(),
            triangles: normals
                .iter()
                .enumerate()
                .map(|(i, n)| {
                    let b = (i * 3) as u32;
                    if n.z < 0.0 {
                        [b, b + 2, b + 1]
                    } else {
                        [b, b + 1, b + 2]
                    }
                })
                .collect(),
        };
        let heights = HeightField::from_mesh(&upward);
        Ok(Self {
            triangles,
            normals,
            shape,
            lo,
            hi,
            heights,
            grid_max,
            grid_dims,
            grid_cell,
        })
    }

    /// The 2.5D Delaunay surface of a point cloud's top envelope (see the module docs); points
    /// are in mm. `fold_gap` is how far below the top of its cell a point is taken as a fold.
    pub fn from_cloud(
        points: &[[f64; 3]],
        fold_gap: f64,
    ) -> Result<(Self, CloudInfo), SurfaceError> {
        if points.iter().flatten().any(|v| !v.is_finite()) {
            return Err(SurfaceError::NotFinite);
        }
        if let Some((i, value)) = points
            .iter()
            .enumerate()
            .find_map(|(i, p)| out_of_range(p).map(|v| (i, v)))
        {
            return Err(SurfaceError::OutOfRange {
                element: "point",
                index: i + 1,
                value,
            });
        }
        if points.len() < 3 {
            return Err(SurfaceError::Empty);
        }
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in points {
            lo = [lo[0].min(p[0]), lo[1].min(p[1])];
            hi = [hi[0].max(p[0]), hi[1].max(p[1])];
        }
        let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(1e-12);
        // A cell about twice the mean point spacing: a cell of a single-layer scan then holds a
        // few points of one layer, a folded scan points of both layers.
        let cell = (2.0 * (area / points.len() as f64).sqrt()).max(1e-6);
        // Counted in f64 and capped before the cast, so no extent overflows the count.
        let cells = |w: f64| ((w / cell).floor().min(f64::from(1 << 15) - 1.0) as usize) + 1;
        let (nx, ny) = (cells(hi[0] - lo[0]), cells(hi[1] - lo[1]));
        let key = |p: &[f64; 3]| {
            let i = (((p[0] - lo[0]) / cell) as usize).min(nx - 1);
            let j = (((p[1] - lo[1]) / cell) as usize).min(ny - 1);
            j * nx + i
        };
        let mut top = vec![f64::MIN; nx * ny];
        for p in points {
            let k = key(p);
            top[k] = top[k].max(p[2]);
        }
        let mut tri: DelaunayTriangulation<SPoint<f64>> = DelaunayTriangulation::new();
        let mut heights = std::collections::HashMap::new();
        let mut below = 0;
        for p in points {
            if p[2] < top[key(p)] - fold_gap {
                below += 1;
                continue;
            }
            let h = tri
                .insert(SPoint::new(p[0], p[1]))
                .map_err(|e| SurfaceError::Triangulation(format!("{e:?}")))?;
            // Duplicate xy: the highest z wins, deterministically.
            let z = heights.entry(h.index()).or_insert(p[2]);
            *z = f64::max(*z, p[2]);
        }
        let mut tris = Vec::with_capacity(tri.num_inner_faces());
        for f in tri.inner_faces() {
            let v = f.vertices();
            let c = v.map(|h| {
                let p = h.position();
                Point3::new(
                    p.x,
                    p.y,
                    heights.get(&h.fix().index()).copied().unwrap_or(0.0),
                )
            });
            tris.push(c);
        }
        let used = tri.num_vertices();
        let surface = Self::from_triangles(tris)?;
        Ok((
            surface,
            CloudInfo {
                points: points.len(),
                used,
                below_fold: below,
                folds: below > 0,
                cell,
            },
        ))
    }

    /// The triangles, corners in mm.
    pub fn triangles(&self) -> &[[Point3; 3]] {
        &self.triangles
    }

    /// Lowest corner of the bounding box.
    pub fn min(&self) -> Point3 {
        self.lo
    }

    /// Highest corner of the bounding box.
    pub fn max(&self) -> Point3 {
        self.hi
    }

    /// The surface moved by a rigid transform.
    pub fn transformed(&self, g: &Isometry3<f64>) -> Result<Self, SurfaceError> {
        Self::from_triangles(
            self.triangles
                .iter()
                .map(|c| c.map(|p| g.transform_point(&p)))
                .collect(),
        )
    }

    /// The highest surface point at (x, y) and its (upward) unit normal; `None` off the
    /// surface.
    pub fn top(&self, x: f64, y: f64) -> Option<(f64, Vector3)> {
        let start = self.hi.z + 1.0;
        let (t, n) = self.cast(
            &Point3::new(x, y, start),
            &-Vector3::z(),
            start - self.lo.z + 1.0,
        )?;
        Some((start - t, n))
    }

    /// Where the ray from `origin` along the unit `direction` first meets the surface within
    /// `max` mm: the distance along the ray and the unit normal there, turned to face the ray's
    /// origin.
    pub fn cast(&self, origin: &Point3, direction: &Vector3, max: f64) -> Option<(f64, Vector3)> {
        let ray = Ray::new(
            PVec::new(origin.x, origin.y, origin.z),
            PVec::new(direction.x, direction.y, direction.z),
        );
        let hit = self.shape.cast_local_ray_and_get_normal(&ray, max, false)?;
        let n = Vector3::new(hit.normal.x, hit.normal.y, hit.normal.z);
        let n = if n.dot(direction) > 0.0 { -n } else { n };
        Some((hit.time_of_impact, n))
    }

    /// An upper bound of the surface's height over the square of half-side `r` around
    /// (x, y); `None` when no triangle can be there.
    pub fn max_height_near(&self, x: f64, y: f64, r: f64) -> Option<f64> {
        if x + r < self.lo.x || x - r > self.hi.x || y + r < self.lo.y || y - r > self.hi.y {
            return None;
        }
        let [i0, j0] = cell_of(self.lo, self.grid_cell, self.grid_dims, x - r, y - r);
        let [i1, j1] = cell_of(self.lo, self.grid_cell, self.grid_dims, x + r, y + r);
        let mut m = f64::MIN;
        for j in j0..=j1 {
            for i in i0..=i1 {
                m = m.max(self.grid_max[j * self.grid_dims[0] + i]);
            }
        }
        (m > f64::MIN).then_some(m)
    }

    /// The exact height field of the triangles turned to face up (what [`Surface::height`]
    /// and the exact clearance queries of [`super::clearance`] read).
    pub fn height_field(&self) -> &HeightField {
        &self.heights
    }

    /// The highest the surface reaches over the disc of radius `r` about (x, y), exactly
    /// ([`HeightField::max_in_disc`]); `None` when no triangle lies under the disc.
    pub fn max_height_in_disc(&self, x: f64, y: f64, r: f64) -> Option<f64> {
        self.heights.max_in_disc(x, y, r)
    }

    /// Top height at (x, y), mm.
    pub fn height(&self, x: f64, y: f64) -> Option<f64> {
        self.heights.at(x, y).map(|h| h.z)
    }

    /// The closest surface point to `p`.
    pub fn closest(&self, p: &Point3) -> Closest {
        let (proj, (tri, _)) = self
            .shape
            .project_local_point_and_get_location(pv(p), false);
        let q = Point3::new(proj.point.x, proj.point.y, proj.point.z);
        let normal = self
            .normals
            .get(tri as usize)
            .copied()
            .unwrap_or_else(Vector3::z);
        Closest {
            point: q,
            normal,
            distance: (q - p).norm(),
        }
    }

    /// Signed clearance of `p` above the surface: the distance to the closest surface point,
    /// negative when `p` lies below the top surface at its (x, y).
    pub fn signed_distance(&self, p: &Point3) -> f64 {
        let d = self.closest(p).distance;
        match self.height(p.x, p.y) {
            Some(h) if p.z < h => -d,
            _ => d,
        }
    }
}

/// The grid cell of (x, y), clamped to the grid.
fn cell_of(lo: Point3, cell: f64, dims: [usize; 2], x: f64, y: f64) -> [usize; 2] {
    let i = ((x - lo.x) / cell).floor().clamp(0.0, (dims[0] - 1) as f64) as usize;
    let j = ((y - lo.y) / cell).floor().clamp(0.0, (dims[1] - 1) as f64) as usize;
    [i, j]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_far_stray_point_is_refused_by_number() {
        let pts = [
            [50.0, 50.0, 1.0],
            [80.0, 50.0, 1.0],
            [50.0, 80.0, 1.0],
            [1e18, 60.0, 1.0],
        ];
        let e = Surface::from_cloud(&pts, 1.0).map(|_| ());
        assert!(
            matches!(
                e,
                Err(SurfaceError::OutOfRange {
                    element: "point",
                    index: 4,
                    ..
                })
            ),
            "{e:?}"
        );
        let far = Point3::new(0.0, 2e4, 0.0);
        let tri = [Point3::origin(), Point3::new(1.0, 0.0, 0.0), far];
        let e = Surface::from_triangles(vec![tri]).map(|_| ());
        assert!(
            matches!(
                e,
                Err(SurfaceError::OutOfRange {
                    element: "triangle",
                    index: 1,
                    ..
                })
            ),
            "{e:?}"
        );
    }

    #[test]
    fn a_thin_wide_cloud_is_refused_or_built_never_a_panic() {
        // The fuzzed cloud: 1e20 mm wide, 1e-30 mm deep (its fold grid overflowed its count).
        let wide = [
            [0.0, 0.0, 0.0],
            [1e20, 0.0, 0.0],
            [0.0, 1e-30, 0.0],
            [5e19, 1e-30, 1.0],
        ];
        let e = Surface::from_cloud(&wide, 1.0).map(|_| ());
        assert!(
            matches!(e, Err(SurfaceError::OutOfRange { index: 2, .. })),
            "{e:?}"
        );
        // As wide as allowed and as thin: slivers, but a bounded grid and no panic.
        let thin = wide.map(|p| [p[0] * 1e-16, p[1], p[2]]);
        let _ = Surface::from_cloud(&thin, 1.0);
    }

    #[test]
    fn a_ramp_cloud_gives_exact_heights_and_a_folded_cloud_is_noted() -> Result<(), SurfaceError> {
        let mut pts = Vec::new();
        for i in 0..=20 {
            for j in 0..=20 {
                let (x, y) = (i as f64, j as f64);
                pts.push([x, y, 0.5 * x]);
            }
        }
        let (s, info) = Surface::from_cloud(&pts, 1.0)?;
        assert!(!info.folds);
        let h = s.height(7.3, 4.1).unwrap_or(f64::NAN);
        assert!((h - 3.65).abs() < 1e-9, "{h}");
        // A second layer 5 mm below: a fold, left out.
        let lower: Vec<[f64; 3]> = pts
            .iter()
            .map(|p| [p[0] + 0.1, p[1] + 0.1, p[2] - 5.0])
            .collect();
        pts.extend(lower);
        let (s, info) = Surface::from_cloud(&pts, 1.0)?;
        assert!(info.folds && info.below_fold > 300, "{info:?}");
        let h = s.height(7.3, 4.1).unwrap_or(f64::NAN);
        assert!((h - 3.65).abs() < 1e-6, "{h}");
        Ok(())
    }
}
