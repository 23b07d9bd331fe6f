//! Surface normals under a path and the tool axes made of them: the normal from the slope of
//! the top surface across the nozzle's footprint, averaged along the path, and tilted back
//! toward the vertical where it leans more than the machine allows.
//!
//! Place in the pipeline: used by [`super::plan`] between the projection and the standoff.
//!
//! The normal at (x, y) is (−∂h/∂x, −∂h/∂y, 1) normalised, with the slopes of the top height h
//! from central differences over ±`half` (the outer radius of the nozzle): across a faceted
//! scan this averages the facets under the tip instead of taking one facet's normal, which is
//! off by up to half the angle between neighbouring facets. Where a difference reaches past
//! the surface's edge the normal of the facet under the point is taken.

use crate::geom::{Point3, Vector3};
use crate::surface::Surface;

/// The upward unit normal of the top surface at (x, y), from slopes over ±`half` mm; `None` off
/// the surface.
pub fn normal_at(surface: &Surface, x: f64, y: f64, half: f64) -> Option<Vector3> {
    let h = |x, y| surface.height(x, y);
    let diff = match (
        h(x + half, y),
        h(x - half, y),
        h(x, y + half),
        h(x, y - half),
    ) {
        (Some(xp), Some(xm), Some(yp), Some(ym)) => Some(
            Vector3::new(-(xp - xm) / (2.0 * half), -(yp - ym) / (2.0 * half), 1.0).normalize(),
        ),
        _ => None,
    };
    diff.or_else(|| surface.top(x, y).map(|(_, n)| n))
}

/// `normals` of the points of `path` averaged over a window of `length` mm of path centred on
/// each point; the window shrinks near the ends so it stays centred (the ends keep their own
/// normal), which keeps the average of a symmetric bend on the bend's own normal.
pub fn smooth(path: &[Point3], normals: &[Vector3], length: f64) -> Vec<Vector3> {
    if length <= 0.0 || path.len() < 3 {
        return normals.to_vec();
    }
    let mut s = Vec::with_capacity(path.len());
    let mut acc = 0.0;
    for (i, p) in path.iter().enumerate() {
        if i > 0 {
            acc += (p - path[i - 1]).norm();
        }
        s.push(acc);
    }
    let total = acc;
    (0..path.len())
        .map(|i| {
            let half = (length / 2.0).min(s[i]).min(total - s[i]);
            let lo = s.partition_point(|&v| v < s[i] - half - 1e-12);
            let hi = s.partition_point(|&v| v <= s[i] + half + 1e-12);
            let sum: Vector3 = normals[lo..hi].iter().sum();
            sum.try_normalize(1e-12).unwrap_or(normals[i])
        })
        .collect()
}

/// `axis` tilted back toward +z, in its vertical plane, so it leans at most `max_deg` from the
/// vertical; also whether it had to be.
pub fn limit_tilt(axis: &Vector3, max_deg: f64) -> (Vector3, bool) {
    let tilt = axis.z.clamp(-1.0, 1.0).acos();
    let max = max_deg.to_radians();
    if tilt <= max {
        return (*axis, false);
    }
    let h = Vector3::new(axis.x, axis.y, 0.0)
        .try_normalize(1e-12)
        .unwrap_or_else(Vector3::x);
    (h * max.sin() + Vector3::z() * max.cos(), true)
}

/// Angle between two unit vectors, degrees.
pub fn angle_deg(a: &Vector3, b: &Vector3) -> f64 {
    a.dot(b).clamp(-1.0, 1.0).acos().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ramp_has_its_normal_and_tilts_are_limited() -> Result<(), String> {
        // z = 0.5·x: normal (−0.5, 0, 1)/|…|.
        let tris = vec![
            [
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(10.0, 0.0, 5.0),
                Point3::new(10.0, 10.0, 5.0),
            ],
            [
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(10.0, 10.0, 5.0),
                Point3::new(0.0, 10.0, 0.0),
            ],
        ];
        let s = Surface::from_triangles(tris).map_err(|e| e.to_string())?;
        let n = normal_at(&s, 5.0, 5.0, 0.25).ok_or("on the surface")?;
        let want = Vector3::new(-0.5, 0.0, 1.0).normalize();
        assert!((n - want).norm() < 1e-9, "{n}");
        // At the edge the facet's normal.
        let e = normal_at(&s, 0.1, 5.0, 0.25).ok_or("on the surface")?;
        assert!((e - want).norm() < 1e-9, "{e}");
        let (l, limited) = limit_tilt(&want, 20.0);
        assert!(limited);
        assert!((angle_deg(&l, &Vector3::z()) - 20.0).abs() < 1e-9);
        assert!(l.x < 0.0 && l.y.abs() < 1e-12);
        assert_eq!(limit_tilt(&want, 30.0), (want, false));
        Ok(())
    }

    #[test]
    fn smoothing_a_symmetric_bend_keeps_the_middle_normal() {
        let path: Vec<Point3> = (0..=10)
            .map(|i| Point3::new(f64::from(i), 0.0, 0.0))
            .collect();
        let normals: Vec<Vector3> = (0..=10)
            .map(|i| Vector3::new(0.1 * f64::from(i - 5), 0.0, 1.0).normalize())
            .collect();
        let s = smooth(&path, &normals, 4.0);
        assert!((s[5] - Vector3::z()).norm() < 1e-12);
        // The end keeps its own normal (renormalised).
        assert!((s[0] - normals[0]).norm() < 1e-12);
        // Point 2 averages points 0 to 4 (x of −0.5 … −0.1 before normalising): between the
        // end's lean and none, near the middle one's.
        assert!(s[2].x < normals[3].x && s[2].x > normals[1].x, "{}", s[2]);
    }
}
