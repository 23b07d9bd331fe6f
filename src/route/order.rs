//! Routing order: wires whose rubberbands collide least go first, then the shorter ones.
//!
//! Place in the pipeline: the first step of routing, before any graph is built. Each wire's
//! naive channel is its rubberband projected onto the xy plane and grown by the channel
//! half-width (a rectangle with square ends). A wire's collision count is the number of times its
//! straight segment crosses the outlines of the naive channels of the wires of other nets. Wires
//! that cross nothing are routed first and take the straight path; wires in the thick of a
//! crossing are routed later, around the channels already placed.

use super::index::RegionIndex;
use super::{RouteParams, Wire};
use crate::geom::Point2;

/// The straight xy segment of a wire, in scaled units.
fn segment(w: &Wire) -> (Point2, Point2) {
    (
        Point2::from_mm(w.from.x, w.from.y),
        Point2::from_mm(w.to.x, w.to.y),
    )
}

/// The naive channel of a wire: its xy segment grown by `half` mm, ends included.
fn naive_channel(w: &Wire, half: f64) -> Vec<Point2> {
    let (dx, dy) = (w.to.x - w.from.x, w.to.y - w.from.y);
    let len = (dx * dx + dy * dy).sqrt();
    let (ux, uy) = if len > 0.0 {
        (dx / len, dy / len)
    } else {
        (1.0, 0.0)
    };
    let (nx, ny) = (-uy, ux);
    let at = |x: f64, y: f64, s: f64, t: f64| {
        Point2::from_mm(
            x + s * ux * half + t * nx * half,
            y + s * uy * half + t * ny * half,
        )
    };
    vec![
        at(w.from.x, w.from.y, -1.0, -1.0),
        at(w.to.x, w.to.y, 1.0, -1.0),
        at(w.to.x, w.to.y, 1.0, 1.0),
        at(w.from.x, w.from.y, -1.0, 1.0),
    ]
}

/// Number of crossings of each wire's straight segment with the naive channel outlines of the
/// wires of other nets.
pub fn collision_counts(wires: &[Wire], params: &RouteParams) -> Vec<usize> {
    let half = params.channel_half_width();
    let outlines: Vec<RegionIndex> = wires
        .iter()
        .map(|w| {
            let ring = naive_channel(w, half);
            RegionIndex::new(&[(0, ring.as_slice())])
        })
        .collect();
    wires
        .iter()
        .enumerate()
        .map(|(i, w)| {
            let (a, b) = segment(w);
            wires
                .iter()
                .enumerate()
                .filter(|(j, o)| *j != i && o.net != w.net)
                .map(|(j, _)| outlines[j].count_crossings(a, b))
                .sum()
        })
        .collect()
}

/// Indices of `wires` in routing order: fewest collisions first (see [`collision_counts`]), then
/// shortest 3D rubberband, then input order.
pub fn wire_order(wires: &[Wire], params: &RouteParams) -> Vec<usize> {
    let counts = collision_counts(wires, params);
    let mut order: Vec<usize> = (0..wires.len()).collect();
    order.sort_by(|&a, &b| {
        let len = |i: usize| (wires[i].to - wires[i].from).norm();
        counts[a]
            .cmp(&counts[b])
            .then(len(a).total_cmp(&len(b)))
            .then(a.cmp(&b))
    });
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point3;

    fn wire(net: &str, a: (f64, f64), b: (f64, f64)) -> Wire {
        Wire {
            net: net.into(),
            from: Point3::new(a.0, a.1, 1.0),
            to: Point3::new(b.0, b.1, 1.0),
        }
    }

    #[test]
    fn crossing_wires_go_after_free_ones() {
        let wires = [
            wire("a", (0.0, 0.0), (20.0, 20.0)),
            wire("b", (0.0, 20.0), (20.0, 0.0)),
            wire("c", (30.0, 0.0), (30.0, 5.0)),
            wire("d", (40.0, 0.0), (40.0, 10.0)),
        ];
        let counts = collision_counts(&wires, &RouteParams::default());
        assert_eq!(counts, vec![2, 2, 0, 0]);
        assert_eq!(
            wire_order(&wires, &RouteParams::default()),
            vec![2, 3, 0, 1]
        );
    }
}
