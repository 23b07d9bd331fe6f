//! The shell's two surfaces as height fields: the bottom surface every curved layer follows,
//! and the top surface (for the layer count from the shell's thickness and for the sandwich's
//! top skin).
//!
//! Place in the pipeline: built once from the placed meshes, first thing in [`super::plan`];
//! every later step of curved-layer FFF asks it for heights.
//!
//! # Why the mesh's own triangles
//!
//! Heights come from [`HeightField`], the exact plane of the mesh triangle over a point, not
//! from an interpolation of the mesh's vertices. Natural-neighbour interpolation on a spade
//! Delaunay triangulation of the vertices would be smooth but would leave the mesh between its
//! vertices (and re-triangulate a surface that is already triangulated); a parry3d ray cast
//! answers the same question as the height field but needs a BVH and a dependency for one
//! query type. The height field is exact on the model as given, deterministic, and its
//! [`HeightField::edge_crossings`] let paths be split where the surface bends, so a straight
//! segment between two projected points lies on the surface too.
//!
//! Triangles are taken whatever their orientation (an open surface may face either way):
//! every non-vertical triangle is turned to face up; the top surface is the highest of them.
//! The bottom surface is the top surface of the mesh mirrored in z (`z → −z`), negated back.

use crate::geom::Point3;
use crate::mesh::Mesh;
use crate::surface::{HeightField, SurfaceTriangle};

/// Triangles whose unit normal has a z component below this are vertical walls, not surface.
const VERTICAL_NZ: f64 = 1e-6;

/// A triangle is part of the bottom surface when it is within this of the lowest surface at
/// its centroid, mm (rounding between coplanar neighbours).
const VISIBLE_TOLERANCE_MM: f64 = 1e-6;

/// The bottom and top surfaces of the placed shell (see the module docs).
#[derive(Debug, Clone)]
pub struct Shell {
    /// The bottom surface mirrored in z: its `at(x, y).z` is minus the lowest mesh z.
    mirrored: HeightField,
    /// The top surface.
    top: HeightField,
    /// Indices of the mirrored triangles that are the bottom surface somewhere (the lowest at
    /// their centroid): a closed shell's top sheet is in `mirrored` too, hidden above.
    visible: Vec<usize>,
    /// Indices of the top triangles that are the top surface somewhere (the highest at their
    /// centroid): a closed shell's bottom sheet is in `top` too, hidden below.
    visible_top: Vec<usize>,
}

/// Every non-vertical triangle of `meshes` turned to face up, with z multiplied by `sign`.
fn facing_up(meshes: &[Mesh], sign: f64) -> Mesh {
    let mut tris = Vec::new();
    for m in meshes {
        for t in &m.triangles {
            let Some(c) = t
                .iter()
                .map(|&i| {
                    m.vertices
                        .get(i as usize)
                        .map(|p| Point3::new(p.x, p.y, p.z * sign))
                })
                .collect::<Option<Vec<Point3>>>()
            else {
                continue;
            };
            let n = (c[1] - c[0]).cross(&(c[2] - c[0]));
            let len = n.norm();
            if !(len.is_finite() && len > 0.0) || (n.z / len).abs() < VERTICAL_NZ {
                continue;
            }
            if n.z > 0.0 {
                tris.push([c[0], c[1], c[2]]);
            } else {
                tris.push([c[0], c[2], c[1]]);
            }
        }
    }
    Mesh::from_triangle_soup("surface", tris)
}

/// Indices of the triangles of `field` that are its surface somewhere: the highest at their
/// centroid.
fn visible_triangles(field: &HeightField) -> Vec<usize> {
    field
        .triangles()
        .iter()
        .enumerate()
        .filter(|(_, t)| {
            let c = t.centroid();
            field
                .at(c.x, c.y)
                .is_some_and(|s| s.z - t.z_at(c.x, c.y) < VISIBLE_TOLERANCE_MM)
        })
        .map(|(i, _)| i)
        .collect()
}

impl Shell {
    /// The surfaces of the placed meshes (all objects together).
    pub fn from_meshes(meshes: &[Mesh]) -> Self {
        let mirrored = HeightField::from_mesh(&facing_up(meshes, -1.0));
        let top = HeightField::from_mesh(&facing_up(meshes, 1.0));
        let visible = visible_triangles(&mirrored);
        let visible_top = visible_triangles(&top);
        Self {
            mirrored,
            top,
            visible,
            visible_top,
        }
    }

    /// The triangles of the top surface (the highest sheet somewhere), z as in the mesh.
    pub fn top_triangles(&self) -> Vec<SurfaceTriangle> {
        let tris = self.top.triangles();
        self.visible_top
            .iter()
            .filter_map(|&i| tris.get(i))
            .copied()
            .collect()
    }

    /// Parameters in (0, 1) where the segment `a`–`b` (xy, mm) crosses an edge of a top
    /// surface triangle; between two of them the top surface over the segment is one plane.
    pub fn top_crossings(&self, a: (f64, f64), b: (f64, f64)) -> Vec<f64> {
        self.top.edge_crossings(a, b)
    }

    /// The top surface's slope at (x, y), degrees from the horizontal.
    pub fn top_slope_deg(&self, x: f64, y: f64) -> Option<f64> {
        self.top.at(x, y).map(|h| h.slope_deg)
    }

    /// The triangles of the bottom surface (mirrored: their z is minus the mesh's).
    fn bottom_surface(&self) -> impl Iterator<Item = &SurfaceTriangle> {
        let tris = self.mirrored.triangles();
        self.visible.iter().filter_map(|&i| tris.get(i))
    }

    /// Whether the shell has any surface at all.
    pub fn is_empty(&self) -> bool {
        self.top.triangles().is_empty()
    }

    /// The lowest mesh z at (x, y), mm: the bottom surface the curved layers follow; `None`
    /// outside the shell's outline.
    pub fn bottom(&self, x: f64, y: f64) -> Option<f64> {
        self.mirrored.at(x, y).map(|h| -h.z)
    }

    /// The highest mesh z at (x, y), mm; `None` outside the outline.
    pub fn top(&self, x: f64, y: f64) -> Option<f64> {
        self.top.at(x, y).map(|h| h.z)
    }

    /// The bottom surface's slope at (x, y), degrees from the horizontal.
    pub fn bottom_slope_deg(&self, x: f64, y: f64) -> Option<f64> {
        self.mirrored.at(x, y).map(|h| h.slope_deg)
    }

    /// Parameters in (0, 1) where the segment `a`–`b` (xy, mm) crosses an edge of a bottom
    /// surface triangle (see [`HeightField::edge_crossings`]); between two of them the bottom
    /// surface over the segment is one plane.
    pub fn bottom_crossings(&self, a: (f64, f64), b: (f64, f64)) -> Vec<f64> {
        self.mirrored.edge_crossings(a, b)
    }

    /// The bottom surface's triangles, mirrored (their z is minus the mesh's): their xy
    /// projection is the shell's outline.
    pub fn bottom_triangles(&self) -> Vec<SurfaceTriangle> {
        self.bottom_surface().copied().collect()
    }

    /// Lowest and highest z of the bottom surface, mm.
    pub fn bottom_range(&self) -> Option<(f64, f64)> {
        let zs = self
            .bottom_surface()
            .flat_map(|t| t.corners.iter().map(|p| -p.z));
        zs.fold(None, |acc, z| match acc {
            None => Some((z, z)),
            Some((lo, hi)) => Some((f64::min(lo, z), f64::max(hi, z))),
        })
    }

    /// Steepest triangle of the bottom surface, degrees from the horizontal.
    pub fn max_slope_deg(&self) -> f64 {
        self.bottom_surface()
            .map(SurfaceTriangle::slope_deg)
            .fold(0.0, f64::max)
    }

    /// Median of top − bottom at the bottom triangles' centroids, mm (0 for an open surface).
    pub fn median_thickness(&self) -> f64 {
        let mut t: Vec<f64> = self
            .bottom_surface()
            .filter_map(|tri| {
                let c = tri.centroid();
                Some(self.top(c.x, c.y)? - self.bottom(c.x, c.y)?)
            })
            .collect();
        if t.is_empty() {
            return 0.0;
        }
        t.sort_by(f64::total_cmp);
        t[t.len() / 2]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed slab over [0, 10]² with bottom z = 1 + 0.1·x and top 0.6 above it, triangles
    /// counter-clockwise from outside.
    fn slab() -> Mesh {
        let b = |x: f64, y: f64| Point3::new(x, y, 1.0 + 0.1 * x);
        let t = |x: f64, y: f64| Point3::new(x, y, 1.6 + 0.1 * x);
        let mut tris = vec![
            [t(0.0, 0.0), t(10.0, 0.0), t(10.0, 10.0)],
            [t(0.0, 0.0), t(10.0, 10.0), t(0.0, 10.0)],
            [b(0.0, 0.0), b(10.0, 10.0), b(10.0, 0.0)],
            [b(0.0, 0.0), b(0.0, 10.0), b(10.0, 10.0)],
        ];
        // Walls (vertical, ignored by the surfaces).
        tris.push([b(0.0, 0.0), b(10.0, 0.0), t(10.0, 0.0)]);
        Mesh::from_triangle_soup("slab", tris)
    }

    #[test]
    fn bottom_and_top_of_a_slab_are_its_two_sheets() {
        let s = Shell::from_meshes(&[slab()]);
        for (x, y) in [(0.0, 0.0), (3.3, 7.1), (10.0, 5.0)] {
            let (b, t) = (s.bottom(x, y), s.top(x, y));
            assert!(
                b.is_some_and(|b| (b - (1.0 + 0.1 * x)).abs() < 1e-12),
                "{b:?}"
            );
            assert!(
                t.is_some_and(|t| (t - (1.6 + 0.1 * x)).abs() < 1e-12),
                "{t:?}"
            );
        }
        assert!(s.bottom(-1.0, 5.0).is_none());
        assert!((s.median_thickness() - 0.6).abs() < 1e-12);
        assert!((s.max_slope_deg() - 0.1f64.atan().to_degrees()).abs() < 1e-9);
        assert_eq!(s.bottom_range(), Some((1.0, 2.0)));
    }

    #[test]
    fn an_open_sheet_facing_down_is_both_bottom_and_top() {
        let p = |x: f64, y: f64| Point3::new(x, y, 2.0 + 0.05 * y);
        // Clockwise from above: facing down.
        let sheet = Mesh::from_triangle_soup(
            "sheet",
            [
                [p(0.0, 0.0), p(4.0, 4.0), p(4.0, 0.0)],
                [p(0.0, 0.0), p(0.0, 4.0), p(4.0, 4.0)],
            ],
        );
        let s = Shell::from_meshes(&[sheet]);
        assert_eq!(s.bottom(1.0, 2.0), s.top(1.0, 2.0));
        assert!(s.bottom(1.0, 2.0).is_some_and(|z| (z - 2.1).abs() < 1e-12));
        assert_eq!(s.median_thickness(), 0.0);
    }
}
