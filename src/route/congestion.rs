//! The congestion history of negotiated routing: how often traces of different nets met, where.
//!
//! Place in the pipeline: kept by the negotiation driver (`board/negotiate.rs`) across its
//! rounds and read by the A* search (`astar.rs`), which multiplies the cost of a link by
//! `1 + history` at the link's midpoint. After every round the driver adds to the cells where
//! two nets' channels overlapped, so places that stay contested grow dearer for every wire, and
//! the wires with a way round take it: the history term of negotiated congestion
//! (McMurchie and Ebeling, "PathFinder: a negotiation-based performance-driven router for
//! FPGAs", FPGA 1995).

use super::graph::IntMap;
use crate::geom::{ExPolygon, Point2};

/// Accumulated congestion per layer on a square grid of cells.
#[derive(Debug, Clone, Default)]
pub(crate) struct History {
    /// Cell size, scaled units.
    cell: i64,
    /// Cost added per cell, keyed by (layer, cell x, cell y); cells never contested are absent.
    cells: IntMap<(usize, i64, i64), f64>,
    /// Most a cell holds: bounds how far a route may be driven round a contested place.
    cap: f64,
}

impl History {
    /// An empty history on cells of `cell` scaled units, each holding at most `cap`.
    pub(crate) fn new(cell: i64, cap: f64) -> Self {
        Self {
            cell: cell.max(1),
            cells: IntMap::default(),
            cap,
        }
    }

    /// The history at `p` on `layer` (0 where no traces ever met).
    pub(crate) fn at(&self, layer: usize, p: Point2) -> f64 {
        self.cells
            .get(&(layer, p.x.div_euclid(self.cell), p.y.div_euclid(self.cell)))
            .copied()
            .unwrap_or(0.0)
    }

    /// Adds `amount` to every cell of `layer` that the boxes of `regions` (grown by one cell)
    /// touch, up to the cap.
    pub(crate) fn add(&mut self, layer: usize, regions: &[ExPolygon], amount: f64) {
        for ex in regions {
            let Some((lo, hi)) = bounds(&ex.contour.points) else {
                continue;
            };
            let c = self.cell;
            for cx in (lo.x - c).div_euclid(c)..=(hi.x + c).div_euclid(c) {
                for cy in (lo.y - c).div_euclid(c)..=(hi.y + c).div_euclid(c) {
                    let v = self.cells.entry((layer, cx, cy)).or_insert(0.0);
                    *v = (*v + amount).min(self.cap);
                }
            }
        }
    }

    /// Most a cell holds.
    pub(crate) fn cap(&self) -> f64 {
        self.cap
    }
}

/// The corners of the box around `points`.
fn bounds(points: &[Point2]) -> Option<(Point2, Point2)> {
    let first = *points.first()?;
    Some(points.iter().fold((first, first), |(lo, hi), p| {
        (
            Point2::new(lo.x.min(p.x), lo.y.min(p.y)),
            Point2::new(hi.x.max(p.x), hi.y.max(p.y)),
        )
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Polygon;

    #[test]
    fn contested_cells_grow_dearer_up_to_the_cap() {
        let mut h = History::new(Point2::from_mm(0.5, 0.0).x, 1.0);
        let square = ExPolygon {
            contour: Polygon::new(vec![
                Point2::from_mm(1.1, 1.1),
                Point2::from_mm(1.3, 1.1),
                Point2::from_mm(1.3, 1.3),
                Point2::from_mm(1.1, 1.3),
            ]),
            holes: Vec::new(),
        };
        h.add(2, std::slice::from_ref(&square), 0.4);
        assert_eq!(h.at(2, Point2::from_mm(1.2, 1.2)), 0.4);
        // One cell round the box too, not beyond.
        assert_eq!(h.at(2, Point2::from_mm(0.7, 1.7)), 0.4);
        assert_eq!(h.at(2, Point2::from_mm(0.2, 1.2)), 0.0);
        assert_eq!(h.at(1, Point2::from_mm(1.2, 1.2)), 0.0);
        for _ in 0..5 {
            h.add(2, std::slice::from_ref(&square), 0.4);
        }
        assert_eq!(h.at(2, Point2::from_mm(1.2, 1.2)), 1.0);
    }
}
