//! Affine transforms (nalgebra) and axis-aligned bounding boxes.

use super::point::{Point3, Vector3};
use serde::Serialize;

/// An affine 3D transform (rotation, scale, shear and translation), as a 3MF build places objects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform(pub nalgebra::Affine3<f64>);

impl Default for Transform {
    fn default() -> Self {
        Self::identity()
    }
}

impl Transform {
    /// The identity transform.
    pub fn identity() -> Self {
        Self(nalgebra::Affine3::identity())
    }

    /// A pure translation.
    pub fn translation(x: f64, y: f64, z: f64) -> Self {
        Self(nalgebra::convert(nalgebra::Translation3::new(x, y, z)))
    }

    /// A transform from the 3MF row layout `m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32`, where a
    /// point is the row vector `[x y z 1]` multiplied on the left.
    pub fn from_3mf(m: &[f64; 12]) -> Self {
        let mat = nalgebra::Matrix4::new(
            m[0], m[3], m[6], m[9], //
            m[1], m[4], m[7], m[10], //
            m[2], m[5], m[8], m[11], //
            0.0, 0.0, 0.0, 1.0,
        );
        Self(nalgebra::Affine3::from_matrix_unchecked(mat))
    }

    /// The 3MF row layout of this transform (inverse of [`Transform::from_3mf`]).
    pub fn to_3mf(&self) -> [f64; 12] {
        let m = self.0.matrix();
        [
            m[(0, 0)],
            m[(1, 0)],
            m[(2, 0)],
            m[(0, 1)],
            m[(1, 1)],
            m[(2, 1)],
            m[(0, 2)],
            m[(1, 2)],
            m[(2, 2)],
            m[(0, 3)],
            m[(1, 3)],
            m[(2, 3)],
        ]
    }

    /// Whether this is exactly the identity.
    pub fn is_identity(&self) -> bool {
        *self.0.matrix() == nalgebra::Matrix4::identity()
    }

    /// `self ∘ other`: apply `other` first, then `self`.
    pub fn then_after(&self, other: &Transform) -> Transform {
        Transform(self.0 * other.0)
    }

    /// Applies the transform to a point.
    pub fn apply(&self, p: &Point3) -> Point3 {
        self.0 * p
    }

    /// The determinant of the linear part; negative when the transform mirrors.
    pub fn determinant(&self) -> f64 {
        self.0.matrix().fixed_view::<3, 3>(0, 0).determinant()
    }
}

/// An axis-aligned bounding box in millimetres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BoundingBox {
    /// The minimum corner.
    pub min: [f64; 3],
    /// The maximum corner.
    pub max: [f64; 3],
}

impl BoundingBox {
    /// The smallest box holding every point, or `None` when there are none.
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Point3>) -> Option<Self> {
        let mut it = points.into_iter();
        let first = it.next()?;
        let mut bb = BoundingBox {
            min: [first.x, first.y, first.z],
            max: [first.x, first.y, first.z],
        };
        for p in it {
            for k in 0..3 {
                bb.min[k] = bb.min[k].min(p[k]);
                bb.max[k] = bb.max[k].max(p[k]);
            }
        }
        Some(bb)
    }

    /// Edge lengths along x, y, z.
    pub fn size(&self) -> Vector3 {
        Vector3::new(
            self.max[0] - self.min[0],
            self.max[1] - self.min[1],
            self.max[2] - self.min[2],
        )
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &BoundingBox) -> BoundingBox {
        let mut out = *self;
        for k in 0..3 {
            out.min[k] = out.min[k].min(other.min[k]);
            out.max[k] = out.max[k].max(other.max[k]);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threemf_layout_round_trips_and_applies_translation_last() {
        // 90° about z, then translate by (10, 0, 5).
        let m = [0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 10.0, 0.0, 5.0];
        let t = Transform::from_3mf(&m);
        assert_eq!(t.to_3mf(), m);
        let p = t.apply(&Point3::new(1.0, 0.0, 0.0));
        assert!((p - Point3::new(10.0, 1.0, 5.0)).norm() < 1e-12);
        assert!((t.determinant() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn composition_applies_inner_first() {
        let a = Transform::translation(1.0, 0.0, 0.0);
        let s = Transform::from_3mf(&[2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0]);
        // scale after translate: (0+1)*2 = 2
        let p = s.then_after(&a).apply(&Point3::origin());
        assert_eq!(p, Point3::new(2.0, 0.0, 0.0));
    }
}
