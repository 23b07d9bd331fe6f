//! Inter-layer connections: where a route may step to the layer above or below, and the
//! staircase overlap that makes the step conduct.
//!
//! Place in the pipeline: called by the A* search (`astar.rs`) each time it expands a vertex `u`.
//! Conductive traces of two layers connect only where they overlap in xy, so a layer change is
//! allowed only where the route's last stretch on this layer can be printed on the neighbour
//! layer too:
//!
//! 1. walk `u`'s best path back, along this layer (including a staircase overlap this layer
//!    started with), until the walked length exceeds `interlayer_overlap + grid_step`;
//! 2. every point of that piece must have a match on the neighbour layer: a vertex at the same
//!    xy (within `align_tolerance`) inside the material, or a point inside the neighbour's first
//!    deflated area (where a channel fits) and out of its keep-outs; no piece edge may cross a
//!    keep-out;
//! 3. then `u` is joined to its match on the neighbour layer, at the cost of the piece (length ×
//!    `base_weight`) plus `layer_change_penalty`, and the piece is kept: the route prints it on
//!    both layers, at the end of this layer's segment and the start of the next.
//!
//! The rubberband's own crossing of a layer boundary (where the direct connections of two
//! consecutive layers meet) is a vertex of both layers at the same xy, so it is one such
//! candidate; a plain edge there would join two traces with no overlap, which does not conduct.

use super::graph::{Graph, IntMap, PreparedLayer, VertexId};
use super::index::dist;
use crate::geom::Point2;

/// The best-path predecessor of a vertex: the previous vertex and, for a layer change, the
/// staircase overlap piece (an index into the search's list of pieces).
pub(crate) type Parent = Option<(VertexId, Option<u32>)>;

/// The last stretch of the best path to `u` on `u`'s layer, from its far end to `u`, once it is
/// longer than `need` (scaled units); `None` if the path on this layer is shorter.
pub(crate) fn walk_back(
    graph: &Graph,
    parents: &[Parent],
    overlaps: &[Vec<Point2>],
    u: VertexId,
    need: f64,
) -> Option<Vec<Point2>> {
    let layer = graph.layer(u);
    let mut points = vec![graph.pos(u)];
    let mut length = 0.0;
    let mut v = u;
    loop {
        let (p, piece) = parents[v as usize]?;
        match piece {
            None => {
                if graph.layer(p) != layer {
                    return None;
                }
                let q = graph.pos(p);
                length += points.last().map_or(0.0, |&l| dist(l, q));
                points.push(q);
                v = p;
            }
            Some(k) => {
                // `v` was reached by a layer change whose piece is printed on this layer too:
                // walk it backwards; the path before it lies on another layer.
                for &q in overlaps[k as usize].iter().rev().skip(1) {
                    length += points.last().map_or(0.0, |&l| dist(l, q));
                    points.push(q);
                    if length > need {
                        break;
                    }
                }
                if length <= need {
                    return None;
                }
            }
        }
        if length > need {
            points.reverse();
            return Some(points);
        }
    }
}

/// What a search has learnt about printing points and piece edges on a neighbour layer: the
/// region tests of [`piece_fits`] depend only on the layer and the points, and consecutive
/// expansions along a path ask about mostly the same piece, so each is made once per search.
#[derive(Debug, Clone, Default)]
pub(crate) struct FitMemo {
    /// Per (layer, x, y): inside the material, and inside the first deflated area clear of
    /// keep-outs.
    points: IntMap<(usize, i64, i64), (bool, bool)>,
    /// Per (layer, a, b): whether the edge crosses a keep-out.
    edges: IntMap<(usize, i64, i64, i64, i64), bool>,
}

/// Whether every point of `piece` can be printed on `layer` (see the module docs).
pub(crate) fn piece_fits(
    piece: &[Point2],
    graph: &Graph,
    layer: &PreparedLayer,
    tol: i64,
    memo: &mut FitMemo,
) -> bool {
    // A vertex of the neighbour layer at the same xy is a match only inside its material:
    // direct connections also run across holes and cavities, where no trace may be printed.
    let mut fits = |p: Point2| {
        let (material, clear) = *memo
            .points
            .entry((layer.index, p.x, p.y))
            .or_insert_with(|| {
                (
                    layer.material.inside_or_on(p, tol),
                    layer.clearance.inside_or_on(p, tol) && !layer.blocked.contains(p),
                )
            });
        clear || (material && graph.nearest(layer.index, p, tol).is_some())
    };
    if !piece.iter().all(|&p| fits(p)) {
        return false;
    }
    layer.blocked.is_empty()
        || piece.windows(2).all(|w| {
            !*memo
                .edges
                .entry((layer.index, w[0].x, w[0].y, w[1].x, w[1].y))
                .or_insert_with(|| layer.blocked.crosses(w[0], w[1]))
        })
}
