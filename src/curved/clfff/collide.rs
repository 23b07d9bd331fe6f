//! The head model replayed over a whole curved-layer print: does the head's cone (or carriage)
//! touch anything printed before the nozzle gets there?
//!
//! Place in the pipeline: after the sections are Programs, before they are written; its
//! findings go to the report and to stderr. It uses the head of the `[curved]` head keys
//! ([`ToolSolid::fff_head`]) but not the material model of [`crate::curved::collision`], which
//! tests every nozzle position against every point: a whole print needs a spatial index. The
//! replay is the walk of [`crate::surface::replay`] with the grid as its obstacle.
//!
//! # Method
//!
//! Printed material is kept as a grid of [`CELL_MM`] squares over the bed, each holding the
//! highest printed point that fell in it (a path's points, and points every [`CELL_MM`] along
//! its segments). Each path is tested before it is added: every nozzle position (its points and
//! points every [`CELL_MM`] between them) against the cells within the head's widest radius;
//! a cell's point `q` hits when it is above the tip and closer horizontally than the head's
//! radius at that height ([`ToolSolid::radius_at`]). Positions at or above everything printed so far
//! are skipped (nothing can be above the tip). Keeping one point per cell is an approximation
//! at the scale of a cell: a lower point beside the highest is not tested.

use serde::Serialize;

use crate::geom::Point3;
use crate::program::{Program, Role};
use crate::surface::{Hit, Next, Obstacle, Sample, Spacing, Stretch, ToolPart, ToolSolid, walk};

/// Side of the material grid's cells, mm.
pub const CELL_MM: f64 = 0.25;

/// Collisions listed in the report; the rest are counted.
pub const MAX_LISTED: usize = 20;

/// The head touching printed material.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Collision {
    /// Program layer (index in the printed file) of the path.
    pub layer: usize,
    /// Role of the path being printed.
    pub role: &'static str,
    /// The nozzle tip, mm.
    pub nozzle: [f64; 3],
    /// The material inside the head, mm.
    pub material: [f64; 3],
    /// The part of the head.
    pub part: ToolPart,
}

/// What the replay found.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Collisions {
    /// The first [`MAX_LISTED`] collisions.
    pub listed: Vec<Collision>,
    /// All collisions (one per path at most).
    pub count: usize,
}

/// Printed material: per [`CELL_MM`] cell the highest point laid down in it.
struct Grid {
    origin: [f64; 2],
    dims: [usize; 2],
    cells: Vec<Option<Point3>>,
    top: f64,
}

impl Grid {
    fn new(program: &Program) -> Option<Self> {
        let mut lo = [f64::MAX; 2];
        let mut hi = [f64::MIN; 2];
        for p in program.paths().flat_map(|p| p.points.iter()) {
            lo = [lo[0].min(p.x), lo[1].min(p.y)];
            hi = [hi[0].max(p.x), hi[1].max(p.y)];
        }
        if lo[0] > hi[0] {
            return None;
        }
        let dims = [
            ((hi[0] - lo[0]) / CELL_MM).ceil() as usize + 1,
            ((hi[1] - lo[1]) / CELL_MM).ceil() as usize + 1,
        ];
        Some(Self {
            origin: lo,
            dims,
            cells: vec![None; dims[0] * dims[1]],
            top: f64::MIN,
        })
    }

    fn cell(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        let cx = ((x - self.origin[0]) / CELL_MM).floor();
        let cy = ((y - self.origin[1]) / CELL_MM).floor();
        (cx >= 0.0 && cy >= 0.0 && (cx as usize) < self.dims[0] && (cy as usize) < self.dims[1])
            .then_some((cx as usize, cy as usize))
    }

    fn add(&mut self, p: Point3) {
        if let Some((cx, cy)) = self.cell(p.x, p.y) {
            let slot = &mut self.cells[cy * self.dims[0] + cx];
            if slot.is_none_or(|q| p.z > q.z) {
                *slot = Some(p);
            }
            self.top = self.top.max(p.z);
        }
    }

    /// The first material point inside the head with its tip at `p`.
    fn hit(&self, head: &ToolSolid, p: Point3) -> Option<Hit> {
        if p.z >= self.top {
            return None;
        }
        let r = head.widest();
        let (x0, y0) = (p.x - r, p.y - r);
        let c0 = (
            ((x0 - self.origin[0]) / CELL_MM).floor().max(0.0) as usize,
            ((y0 - self.origin[1]) / CELL_MM).floor().max(0.0) as usize,
        );
        let c1 = (
            (((p.x + r - self.origin[0]) / CELL_MM).floor().max(0.0) as usize)
                .min(self.dims[0] - 1),
            (((p.y + r - self.origin[1]) / CELL_MM).floor().max(0.0) as usize)
                .min(self.dims[1] - 1),
        );
        for cy in c0.1..=c1.1 {
            for cx in c0.0..=c1.0 {
                let Some(q) = self.cells[cy * self.dims[0] + cx] else {
                    continue;
                };
                if let Some(hit) = Hit::of_point(head, p, q) {
                    return Some(hit);
                }
            }
        }
        None
    }
}

/// The grid as an obstacle: the contact is its first point inside the head; a path lays down
/// its tested positions.
impl Obstacle for Grid {
    type Contact = Option<Hit>;

    fn contact(&self, tool: &ToolSolid, _index: usize, sample: &Sample) -> Option<Hit> {
        self.hit(tool, sample.tip)
    }

    fn lay(&mut self, _index: usize, _stretch: &Stretch<'_>, samples: &[Sample]) {
        for s in samples {
            self.add(s.tip);
        }
    }
}

/// Replays `program` with `head` (see the module docs): the walk of its paths, in print order,
/// positions at most [`CELL_MM`] apart; scaffold paths are laid down but not tested.
pub fn replay(program: &Program, head: &ToolSolid) -> Collisions {
    let mut found = Collisions::default();
    let Some(mut grid) = Grid::new(program) else {
        return found;
    };
    let paths: Vec<(usize, &crate::program::Toolpath)> = program
        .layers
        .iter()
        .flat_map(|layer| layer.paths().map(move |path| (layer.index, path)))
        .collect();
    let stretches = paths.iter().map(|(_, path)| Stretch {
        points: &path.points,
        closed: path.closed,
        tested: path.role != Role::Scaffold,
    });
    walk(
        head,
        &mut grid,
        stretches,
        Spacing::Horizontal(CELL_MM),
        |i, _, hit| {
            let Some(hit) = hit else {
                return Next::Sample;
            };
            let (layer, path) = paths[i];
            found.count += 1;
            if found.listed.len() < MAX_LISTED {
                let (p, q) = (hit.nozzle, hit.material);
                found.listed.push(Collision {
                    layer,
                    role: path.role.type_name(),
                    nozzle: [p.x, p.y, p.z],
                    material: [q.x, q.y, q.z],
                    part: hit.part,
                });
            }
            Next::Stretch
        },
    );
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::{Layer, LayerItem, Toolpath};

    fn path(points: Vec<Point3>, role: Role) -> LayerItem {
        LayerItem::Path(Toolpath {
            points,
            closed: false,
            role,
            tool: 0,
            width: 0.45,
            height: 0.2,
            speed: 40.0,
            segments: None,
            tool_axis: None,
        })
    }

    #[test]
    fn a_wall_beside_a_low_path_is_hit_and_a_far_one_is_not() {
        let head = ToolSolid::fff_head(45.0, 5.0, 0.0, 10.0);
        let wall = path(
            vec![Point3::new(10.0, 0.0, 3.0), Point3::new(10.0, 5.0, 3.0)],
            Role::ExternalPerimeter,
        );
        let near = path(
            vec![Point3::new(8.5, 1.0, 1.0), Point3::new(8.5, 2.0, 1.0)],
            Role::SolidInfill,
        );
        let far = path(
            vec![Point3::new(7.5, 1.0, 1.0), Point3::new(7.5, 2.0, 1.0)],
            Role::SolidInfill,
        );
        let program = |items| Program {
            layers: vec![Layer {
                index: 0,
                z: 3.0,
                height: 0.2,
                items,
            }],
        };
        let hit = replay(&program(vec![wall.clone(), near]), &head);
        assert_eq!(hit.count, 1);
        assert_eq!(hit.listed[0].part, ToolPart::Cone);
        assert!((hit.listed[0].material[0] - 10.0).abs() < 1e-9);
        assert_eq!(replay(&program(vec![wall, far]), &head).count, 0);
    }
}
