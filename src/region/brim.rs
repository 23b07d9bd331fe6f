//! Brim: loops on the first layer that hold the part's edges down, outside the part, inside its
//! holes, or only at its sharp corners ("ears").
//!
//! Place in the pipeline: part of the regions stage, on layer 0 only. Input is the first
//! layer's islands; output is the brim's loops (and the ears' arcs), printed as `Skirt/Brim`
//! before the islands.
//!
//! Loop `k` (0 = nearest to the part) has its centreline `separation + w/2 + k · spacing` from
//! the part, so the innermost bead's edge keeps `separation` (0: the brim touches the part and
//! is torn off with it) and `n = max(1, round(width / spacing))` loops cover the brim's width.
//!
//! - **Outer** loops grow from the islands' outlines with their holes filled (a brim never
//!   goes into a hole from outside); islands closer than twice the brim's width share loops,
//!   and no loop comes nearer to any island than its own distance.
//! - **Inner** loops shrink from each hole's outline into the hole, around any island standing
//!   in it.
//! - **Ears** are the outer loops kept only within `width` of each convex corner sharper than
//!   `ears_max_angle` (where a corner lifts first), as arcs; round outlines get none.

use super::perimeters::oriented;
use crate::geom::{
    ExPolygon, FillRule, Join, Point2, Polygon, Polyline, Tolerances, clip_polylines, difference,
    offset, polygons_to_expolygons,
};
use serde::{Deserialize, Serialize};

/// Where the brim goes.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum BrimType {
    /// Around the outside of each island (PrusaSlicer's `outer_only`).
    #[default]
    Outer,
    /// Inside each hole (`inner_only`).
    Inner,
    /// Both (`outer_and_inner`).
    Both,
    /// Outside, only at sharp convex corners.
    Ears,
}

/// What brim to lay. Lengths in millimetres.
#[derive(Debug, Clone, PartialEq)]
pub struct BrimParams {
    /// Width of the brim; 0 = no brim.
    pub width: f64,
    /// Clear gap between the part and the brim's innermost bead.
    pub separation: f64,
    /// Where the brim goes.
    pub kind: BrimType,
    /// Corners whose inside angle is below this get ears, degrees.
    pub ears_max_angle_deg: f64,
}

impl Default for BrimParams {
    /// No brim; PrusaSlicer's other defaults (OrcaSlicer's ear angle).
    fn default() -> Self {
        Self {
            width: 0.0,
            separation: 0.0,
            kind: BrimType::Outer,
            ears_max_angle_deg: 125.0,
        }
    }
}

/// The brim of the first layer.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Brim {
    /// Closed loops, outermost first, each counter-clockwise.
    pub loops: Vec<Polygon>,
    /// Open arcs of the ears.
    pub ears: Vec<Polyline>,
}

impl Brim {
    /// No brim at all.
    pub fn is_empty(&self) -> bool {
        self.loops.is_empty() && self.ears.is_empty()
    }

    /// Every bead's centreline as a polyline: the ears, then the loops closed on themselves.
    pub fn lines(&self) -> Vec<Polyline> {
        let mut lines = self.ears.clone();
        lines.extend(self.loops.iter().filter_map(closed_polyline));
        lines
    }
}

/// `p` as a polyline that ends where it starts; `None` for a polygon without points.
fn closed_polyline(p: &Polygon) -> Option<Polyline> {
    let first = *p.points.first()?;
    let mut points = p.points.clone();
    points.push(first);
    Some(Polyline { points })
}

/// The brim around `first_layer` (see the module docs) for beads `line_width` wide laid
/// `spacing` apart.
pub fn make_brim(
    first_layer: &[ExPolygon],
    params: &BrimParams,
    line_width: f64,
    spacing: f64,
) -> Brim {
    let usable = |v: f64| v.is_finite() && v > 0.0;
    let separation_ok = params.separation.is_finite() && params.separation >= 0.0;
    if first_layer.is_empty()
        || !usable(params.width)
        || !usable(line_width)
        || !usable(spacing)
        || !separation_ok
    {
        return Brim::default();
    }
    let loops_n = ((params.width / spacing).round() as usize).clamp(1, 1000);
    let distance = |k: usize| params.separation + line_width / 2.0 + k as f64 * spacing;
    let join = Join::Round(Tolerances::default().curve_flattening.mm());
    let rings = |area: &[ExPolygon]| -> Vec<Polygon> {
        area.iter()
            .flat_map(|e| std::iter::once(&e.contour).chain(&e.holes))
            .map(|p| oriented(p.clone(), true))
            .collect()
    };
    let mut brim = Brim::default();
    if params.kind != BrimType::Inner {
        let filled: Vec<Polygon> = first_layer
            .iter()
            .map(|e| oriented(e.contour.clone(), true))
            .collect();
        let base = polygons_to_expolygons(&filled, FillRule::NonZero);
        let outer: Vec<Polygon> = (0..loops_n)
            .rev()
            .flat_map(|k| rings(&offset(&base, distance(k), join)))
            .collect();
        if params.kind == BrimType::Ears {
            let discs = ear_discs(first_layer, params, join);
            let closed: Vec<Polyline> = outer.iter().filter_map(closed_polyline).collect();
            if !discs.is_empty() {
                brim.ears = clip_polylines(&closed, &discs);
            }
        } else {
            brim.loops = outer;
        }
    }
    if matches!(params.kind, BrimType::Inner | BrimType::Both) {
        for island in first_layer {
            for hole in &island.holes {
                let inside = ExPolygon {
                    contour: oriented(hole.clone(), true),
                    holes: Vec::new(),
                };
                // Islands standing in the hole, kept as far from the brim as the hole's edge.
                let free = difference(&[inside], first_layer);
                brim.loops.extend(
                    (0..loops_n)
                        .rev()
                        .flat_map(|k| rings(&offset(&free, -distance(k), join))),
                );
            }
        }
    }
    brim
}

/// Discs of radius `separation + width` around every convex corner of an island's outline
/// whose inside angle is below the ear angle.
fn ear_discs(first_layer: &[ExPolygon], params: &BrimParams, join: Join) -> Vec<ExPolygon> {
    let limit = params.ears_max_angle_deg.to_radians();
    let radius = params.separation + params.width;
    let mut corners = Vec::new();
    for island in first_layer {
        let ring = oriented(island.contour.clone(), true);
        let n = ring.points.len();
        for i in 0..n {
            let (a, b, c) = (
                ring.points[(i + n - 1) % n],
                ring.points[i],
                ring.points[(i + 1) % n],
            );
            let (u, v) = (to_mm(a, b), to_mm(c, b));
            let cross = u.0 * v.1 - u.1 * v.0;
            // Counter-clockwise outline: a convex corner turns left, b→a × b→c < 0.
            let inside = u.1.atan2(u.0) - v.1.atan2(v.0);
            let angle = inside.rem_euclid(std::f64::consts::TAU);
            if cross < 0.0 && angle < limit {
                corners.push(b);
            }
        }
    }
    disc_union(&corners, radius, join)
}

/// `b → a` in millimetres.
fn to_mm(a: Point2, b: Point2) -> (f64, f64) {
    ((a.x - b.x) as f64 / 1e6, (a.y - b.y) as f64 / 1e6)
}

/// Discs of `radius` around `centres`, united.
fn disc_union(centres: &[Point2], radius: f64, join: Join) -> Vec<ExPolygon> {
    // A tiny square around each point, grown round by the rest of the radius.
    let eps = 1e-3;
    let squares: Vec<ExPolygon> = centres
        .iter()
        .map(|p| {
            let (x, y) = p.to_mm();
            ExPolygon {
                contour: Polygon::new(vec![
                    Point2::from_mm(x - eps, y - eps),
                    Point2::from_mm(x + eps, y - eps),
                    Point2::from_mm(x + eps, y + eps),
                    Point2::from_mm(x - eps, y + eps),
                ]),
                holes: Vec::new(),
            }
        })
        .collect();
    offset(&squares, radius - eps, join)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::{bounds, rect, square_island};

    fn params(kind: BrimType) -> BrimParams {
        BrimParams {
            width: 3.0,
            kind,
            ..Default::default()
        }
    }

    const W: f64 = 0.45;
    const S: f64 = 0.4;

    #[test]
    fn outer_loops_keep_their_distance_and_fill_the_width() {
        let brim = make_brim(
            &[square_island(0.0, 0.0, 20.0)],
            &params(BrimType::Outer),
            W,
            S,
        );
        // round(3 / 0.4) = 8 loops, outermost first.
        assert_eq!(brim.loops.len(), 8);
        assert!(brim.ears.is_empty());
        for (k, l) in brim.loops.iter().rev().enumerate() {
            let d = W / 2.0 + k as f64 * S;
            let (x0, y0, x1, y1) = bounds(l);
            for (got, want) in [(x0, -d), (y0, -d), (x1, 20.0 + d), (y1, 20.0 + d)] {
                assert!((got - want).abs() < 1e-6, "loop {k}: {got} != {want}");
            }
            assert!(l.is_counter_clockwise());
        }
        // With a separation the innermost bead's edge is that far out.
        let sep = BrimParams {
            separation: 1.0,
            ..params(BrimType::Outer)
        };
        let b = make_brim(&[square_island(0.0, 0.0, 20.0)], &sep, W, S);
        let (x0, ..) = bounds(&b.loops[7]);
        assert!((-x0 - (1.0 + W / 2.0)).abs() < 1e-6);
    }

    #[test]
    fn inner_brim_goes_into_holes_and_outer_does_not() {
        let mut ring = square_island(0.0, 0.0, 30.0);
        let mut hole = rect(10.0, 10.0, 20.0, 20.0);
        hole.points.reverse();
        ring.holes.push(hole);
        let inside_hole = |p: &Polygon| {
            p.points.iter().all(|q| {
                let (x, y) = q.to_mm();
                (10.0..=20.0).contains(&x) && (10.0..=20.0).contains(&y)
            })
        };
        let outer = make_brim(std::slice::from_ref(&ring), &params(BrimType::Outer), W, S);
        assert_eq!(outer.loops.len(), 8);
        assert!(!outer.loops.iter().any(inside_hole));
        let inner = make_brim(std::slice::from_ref(&ring), &params(BrimType::Inner), W, S);
        assert_eq!(inner.loops.len(), 8);
        assert!(inner.loops.iter().all(inside_hole));
        // The loop nearest the hole's edge is w/2 inside it.
        let (x0, ..) = bounds(&inner.loops[7]);
        assert!((x0 - (10.0 + W / 2.0)).abs() < 1e-6, "{x0}");
        let both = make_brim(&[ring], &params(BrimType::Both), W, S);
        assert_eq!(both.loops.len(), 16);
    }

    #[test]
    fn ears_sit_on_sharp_corners_only() {
        let brim = make_brim(
            &[square_island(0.0, 0.0, 20.0)],
            &params(BrimType::Ears),
            W,
            S,
        );
        assert!(brim.loops.is_empty());
        // Every arc point is within the ear radius of a corner; every corner has arcs.
        let corners = [(0.0, 0.0), (20.0, 0.0), (20.0, 20.0), (0.0, 20.0)];
        let near = |x: f64, y: f64| {
            corners
                .iter()
                .map(|(cx, cy)| (x - cx).hypot(y - cy))
                .fold(f64::MAX, f64::min)
        };
        for arc in &brim.ears {
            for p in &arc.points {
                let (x, y) = p.to_mm();
                assert!(near(x, y) <= 3.0 + 1e-3, "({x}, {y})");
            }
        }
        for (cx, cy) in corners {
            assert!(brim.ears.iter().any(|a| a.points.iter().any(|p| {
                let (x, y) = p.to_mm();
                (x - cx).hypot(y - cy) < 1.0
            })));
        }
        // A 64-gon has no corner sharper than 125°: no ears.
        let circle = Polygon::new(
            (0..64)
                .map(|i| {
                    let a = i as f64 * std::f64::consts::TAU / 64.0;
                    Point2::from_mm(10.0 * a.cos(), 10.0 * a.sin())
                })
                .collect(),
        );
        let disc = ExPolygon {
            contour: circle,
            holes: Vec::new(),
        };
        assert!(make_brim(&[disc], &params(BrimType::Ears), W, S).is_empty());
    }

    #[test]
    fn no_width_no_brim() {
        let island = [square_island(0.0, 0.0, 5.0)];
        assert!(make_brim(&island, &BrimParams::default(), W, S).is_empty());
        assert!(make_brim(&[], &params(BrimType::Outer), W, S).is_empty());
        assert!(make_brim(&island, &params(BrimType::Outer), f64::NAN, S).is_empty());
    }
}
