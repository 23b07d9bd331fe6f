//! Zero-standoff path T: every design point dropped along −z onto the surface.
//!
//! Place in the pipeline: step 4, after discretising the design ([`super::design`]) and before
//! the local geometry ([`super::spline`]). The drop is a downward ray cast (parry) from above
//! the surface, so it finds the top surface a 3-axis nozzle meets. Points with no surface under
//! them split the path: each stretch on the surface becomes its own path.

use super::design::PlanarPath;
use crate::geom::Point3;
use crate::surface::Surface;

/// Paths on the surface, and how many design points found no surface under them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Projected {
    /// Zero-standoff paths T (at least two points each).
    pub paths: Vec<Vec<Point3>>,
    /// Design points off the surface (dropped).
    pub off_surface: usize,
}

/// Drops every point of `paths` onto `surface`.
pub fn project(surface: &Surface, paths: &[PlanarPath]) -> Projected {
    let mut out = Projected::default();
    for p in paths {
        let mut run: Vec<Point3> = Vec::new();
        for q in &p.points {
            match surface.height(q[0], q[1]) {
                Some(z) => run.push(Point3::new(q[0], q[1], z)),
                None => {
                    out.off_surface += 1;
                    if run.len() >= 2 {
                        out.paths.push(std::mem::take(&mut run));
                    }
                    run.clear();
                }
            }
        }
        if run.len() >= 2 {
            out.paths.push(run);
        }
    }
    out
}
