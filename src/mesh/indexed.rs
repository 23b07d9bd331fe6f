//! The indexed mesh type: shared vertices plus triangles of vertex indices.

use super::edges::FastMap;
use crate::geom::{BoundingBox, Point3, Transform};

/// An indexed triangle mesh in millimetres.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// A human-readable name (object name, file stem).
    pub name: String,
    /// Vertex positions.
    pub vertices: Vec<Point3>,
    /// Triangles as indices into `vertices`, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Builds a mesh from a triangle soup, welding vertices with bit-identical coordinates (as STL
    /// files repeat each shared vertex). Near-coincident vertices are left to [`Mesh::repair`].
    pub fn from_triangle_soup<I>(name: impl Into<String>, triangles: I) -> Mesh
    where
        I: IntoIterator<Item = [Point3; 3]>,
    {
        let iter = triangles.into_iter();
        let mut mesh = Mesh {
            name: name.into(),
            ..Mesh::default()
        };
        mesh.triangles.reserve(iter.size_hint().0);
        // Vertex ids come from first appearance, so the hash order never reaches the result.
        let mut index: FastMap<[u64; 3], u32> =
            FastMap::with_capacity_and_hasher(iter.size_hint().0 / 2 + 1, Default::default());
        for tri in iter {
            let mut t = [0u32; 3];
            for (slot, p) in t.iter_mut().zip(tri.iter()) {
                // -0.0 and 0.0 are the same point: normalise before hashing bits.
                let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
                *slot = *index.entry(key).or_insert_with(|| {
                    mesh.vertices.push(*p);
                    (mesh.vertices.len() - 1) as u32
                });
            }
            mesh.triangles.push(t);
        }
        mesh
    }

    /// An axis-aligned box between two corners: 8 vertices, 12 outward-facing triangles. Used for
    /// part bodies and cavities, and as the standard test solid.
    pub fn cuboid(name: impl Into<String>, min: Point3, max: Point3) -> Mesh {
        let corner = |i: usize| {
            Point3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        };
        // Corner i has x from bit 0, y from bit 1, z from bit 2; each face counter-clockwise from
        // outside.
        const FACES: [[usize; 3]; 12] = [
            [0, 3, 1],
            [0, 2, 3],
            [4, 5, 7],
            [4, 7, 6],
            [0, 1, 5],
            [0, 5, 4],
            [1, 3, 7],
            [1, 7, 5],
            [3, 2, 6],
            [3, 6, 7],
            [2, 0, 4],
            [2, 4, 6],
        ];
        Mesh::from_triangle_soup(name, FACES.iter().map(|f| f.map(corner)))
    }

    /// The three corner positions of triangle `i`.
    pub fn corners(&self, i: usize) -> [Point3; 3] {
        self.triangles[i].map(|v| self.vertices[v as usize])
    }

    /// Iterates the triangles as corner positions.
    pub fn triangle_corners(&self) -> impl Iterator<Item = [Point3; 3]> + '_ {
        (0..self.triangles.len()).map(|i| self.corners(i))
    }

    /// Signed volume in mm³ by the divergence theorem: positive for a closed mesh whose triangles
    /// wind counter-clockwise seen from outside. Summed relative to the bounding-box centre so large
    /// offsets from the origin do not cost precision.
    pub fn signed_volume(&self) -> f64 {
        let Some(bb) = self.bounding_box() else {
            return 0.0;
        };
        let c = Point3::new(
            (bb.min[0] + bb.max[0]) / 2.0,
            (bb.min[1] + bb.max[1]) / 2.0,
            (bb.min[2] + bb.max[2]) / 2.0,
        );
        self.triangle_corners()
            .map(|[a, b, d]| (a - c).dot(&(b - c).cross(&(d - c))))
            .sum::<f64>()
            / 6.0
    }

    /// Surface area in mm².
    pub fn area(&self) -> f64 {
        self.triangle_corners()
            .map(|[a, b, c]| (b - a).cross(&(c - a)).norm() / 2.0)
            .sum()
    }

    /// The axis-aligned bounding box of the referenced vertices, or `None` for an empty mesh.
    pub fn bounding_box(&self) -> Option<BoundingBox> {
        if self.triangles.is_empty() {
            return None;
        }
        BoundingBox::from_points(&self.vertices)
    }

    /// Applies a transform to every vertex; a mirroring transform also flips the winding so the
    /// mesh stays outward-facing.
    pub fn transform(&mut self, t: &Transform) {
        if t.is_identity() {
            return;
        }
        for v in &mut self.vertices {
            *v = t.apply(v);
        }
        if t.determinant() < 0.0 {
            for tri in &mut self.triangles {
                tri.swap(1, 2);
            }
        }
    }

    /// Appends another mesh's vertices and triangles.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|v| v + base)));
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// An axis-aligned cube of side `s` with its minimum corner at the origin, outward-facing.
    pub(crate) fn cube(s: f64) -> Mesh {
        Mesh::cuboid("cube", Point3::origin(), Point3::new(s, s, s))
    }

    #[test]
    fn cube_soup_welds_to_eight_vertices_with_exact_volume() {
        let m = cube(20.0);
        assert_eq!(m.vertices.len(), 8);
        assert_eq!(m.triangles.len(), 12);
        assert!((m.signed_volume() - 8000.0).abs() < 1e-9);
        assert!((m.area() - 2400.0).abs() < 1e-9);
    }

    #[test]
    fn mirroring_keeps_volume_positive() {
        let mut m = cube(2.0);
        m.transform(&Transform::from_3mf(&[
            -1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0,
        ]));
        assert!((m.signed_volume() - 8.0).abs() < 1e-12);
    }
}
