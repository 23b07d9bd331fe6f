//! Routing scenarios on hand-built layers: an annulus plate, a solid plate, two separate blocks.

use super::*;
use crate::geom::{Polygon, intersection, union};

const LAYER_HEIGHT: f64 = 0.2;

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon {
    Polygon::new(vec![
        Point2::from_mm(x0, y0),
        Point2::from_mm(x1, y0),
        Point2::from_mm(x1, y1),
        Point2::from_mm(x0, y1),
    ])
}

fn solid(p: Polygon) -> ExPolygon {
    ExPolygon {
        contour: p,
        holes: Vec::new(),
    }
}

/// `count` layers of 0.2 mm, all with the same islands.
fn stack(islands: Vec<ExPolygon>, count: usize) -> Vec<RouteLayer> {
    (0..count)
        .map(|i| RouteLayer {
            z: LAYER_HEIGHT * (i + 1) as f64,
            height: LAYER_HEIGHT,
            islands: islands.clone(),
        })
        .collect()
}

/// A 60 mm square plate with a 30 mm square hole in the middle, 5 layers.
fn annulus_plate() -> Vec<RouteLayer> {
    let mut hole = rect(15.0, 15.0, 45.0, 45.0);
    hole.points.reverse();
    stack(
        vec![ExPolygon {
            contour: rect(0.0, 0.0, 60.0, 60.0),
            holes: vec![hole],
        }],
        5,
    )
}

fn wire(net: &str, from: (f64, f64, f64), to: (f64, f64, f64)) -> Wire {
    Wire {
        net: net.into(),
        from: Point3::new(from.0, from.1, from.2),
        to: Point3::new(to.0, to.1, to.2),
    }
}

/// A round 1 mm pad on each end of every wire, on the wire's net.
fn end_pads(wires: &[Wire]) -> Vec<PadCopper> {
    wires
        .iter()
        .flat_map(|w| [w.from, w.to].map(|p| PadCopper::round(Some(&w.net), p, 1.0)))
        .collect()
}

fn top(layers: &[RouteLayer]) -> f64 {
    layers.last().map_or(0.0, |l| l.z)
}

fn xy_length(points: &[Point3]) -> f64 {
    points
        .windows(2)
        .map(|w| ((w[1].x - w[0].x).powi(2) + (w[1].y - w[0].y).powi(2)).sqrt())
        .sum()
}

/// Distance in xy from `p` to the polyline `line`.
fn distance_to_polyline(p: &Point3, line: &[Point3]) -> f64 {
    line.windows(2)
        .map(|w| {
            let (ax, ay, bx, by) = (w[0].x, w[0].y, w[1].x, w[1].y);
            let (dx, dy) = (bx - ax, by - ay);
            let len2 = dx * dx + dy * dy;
            let t = if len2 > 0.0 {
                (((p.x - ax) * dx + (p.y - ay) * dy) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            ((ax + t * dx - p.x).powi(2) + (ay + t * dy - p.y).powi(2)).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Length of the start of `next` that runs along `prev` (in xy): how far two consecutive layers'
/// traces overlap at a layer change.
fn overlap_length(prev: &[Point3], next: &[Point3]) -> f64 {
    let on = |p: &Point3| distance_to_polyline(p, prev) < 1e-4;
    let mut length = 0.0;
    for w in next.windows(2) {
        if !(on(&w[0]) && on(&w[1])) {
            break;
        }
        length += xy_length(w);
    }
    length
}

/// The union of the channels of one wire's segments on `layer`.
fn wire_channel(route: &WireRoute, layer: usize, params: &RouteParams) -> Vec<ExPolygon> {
    let parts: Vec<ExPolygon> = route
        .segments
        .iter()
        .filter(|(l, _)| *l == layer)
        .flat_map(|(_, pts)| trace_channel(pts, params.channel_half_width()))
        .collect();
    union(&parts)
}

fn area(a: &[ExPolygon]) -> f64 {
    a.iter().map(ExPolygon::area_mm2).sum()
}

/// Whether the xy of `p` is strictly inside the axis-aligned box.
fn strictly_inside(p: (f64, f64), x0: f64, y0: f64, x1: f64, y1: f64) -> bool {
    p.0 > x0 && p.0 < x1 && p.1 > y0 && p.1 < y1
}

#[test]
fn annulus_route_follows_the_perimeters_around_the_hole() {
    let layers = annulus_plate();
    let z = top(&layers);
    let params = RouteParams::default();
    let w = wire("sig", (5.0, 30.0, z), (55.0, 30.0, z));
    let result = route(
        &layers,
        std::slice::from_ref(&w),
        &end_pads(std::slice::from_ref(&w)),
        &params,
    );
    let r = &result.wires[0];
    assert!(r.routed, "{r:?}");
    assert_eq!(r.lower_bound, 50.0);
    // Never inside the hole: every point, and every edge sampled every 0.05 mm.
    for (_, pts) in &r.segments {
        for s in pts.windows(2) {
            let n = (xy_length(s) / 0.05).ceil().max(1.0) as usize;
            for i in 0..=n {
                let t = i as f64 / n as f64;
                let p = (
                    s[0].x + t * (s[1].x - s[0].x),
                    s[0].y + t * (s[1].y - s[0].y),
                );
                assert!(
                    !strictly_inside(p, 15.0, 15.0, 45.0, 45.0),
                    "{p:?} in the hole"
                );
            }
        }
    }
    assert_eq!(r.perimeter_crossings, 0);
    // Shortest path around the hole: to a corner of the hole, along one side, to the other pad.
    let around = 2.0 * (10.0f64.powi(2) + 15.0f64.powi(2)).sqrt() + 30.0;
    assert!(r.length > r.lower_bound, "{}", r.length);
    assert!(r.length < 1.6 * around, "{} vs {around}", r.length);
    // The route stays on the pads' layer: a detour through other layers costs more.
    assert_eq!(r.layer_changes, 0);
    assert!(r.segments.iter().all(|(l, _)| *l == 4));
    // The channel is returned on the trace's layer only.
    assert!(area(&result.channels[4]) > 0.8 * r.length * 0.9);
    assert!(result.channels[..4].iter().all(Vec::is_empty));
}

#[test]
fn crossing_rubberbands_get_disjoint_channels() {
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 4);
    let z = top(&layers);
    let params = RouteParams::default();
    let wires = [
        wire("a", (5.0, 5.0, z), (35.0, 35.0, z)),
        wire("b", (5.0, 35.0, z), (35.0, 5.0, z)),
    ];
    let result = route(&layers, &wires, &end_pads(&wires), &params);
    for r in &result.wires {
        assert!(r.routed, "{r:?}");
        assert!(r.length >= r.lower_bound - 1e-6);
    }
    // Traces of adjacent layers touch where they overlap, so the channels of the two nets are
    // disjoint on each layer and between each layer and the next.
    assert!(!channels_touch(
        &result.wires[0],
        &result.wires[1],
        layers.len(),
        &params
    ));
    // One of them had to change layer (or go around the other's end): it is longer.
    let longest = result.wires.iter().map(|r| r.length / r.lower_bound);
    assert!(longest.fold(0.0, f64::max) > 1.0);
}

/// Whether the channels of routes `a` and `b` share area on one layer or on two adjacent ones.
fn channels_touch(a: &WireRoute, b: &WireRoute, layers: usize, params: &RouteParams) -> bool {
    (0..layers).any(|l| {
        (l.saturating_sub(1)..=(l + 1).min(layers - 1)).any(|m| {
            let common = intersection(&wire_channel(a, l, params), &wire_channel(b, m, params));
            area(&common) > 1e-6
        })
    })
}

#[test]
fn wall_to_wall_wires_cross_with_a_plastic_layer_between() {
    // Both wires span the plate from wall to wall, so neither can go around the other: the
    // second passes under the first, two layers down, so a layer of plastic parts them.
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 6);
    let z = top(&layers);
    let params = RouteParams::default();
    let wires = [
        wire("a", (0.6, 20.0, z), (39.4, 20.0, z)),
        wire("b", (20.0, 0.6, z), (20.0, 39.4, z)),
    ];
    let result = route(&layers, &wires, &end_pads(&wires), &params);
    let (a, b) = (&result.wires[0], &result.wires[1]);
    assert!(a.routed && b.routed, "{a:?} {b:?}");
    assert!(!channels_touch(a, b, layers.len(), &params));
    let lowest = |r: &WireRoute| {
        r.segments
            .iter()
            .map(|(l, _)| *l)
            .min()
            .unwrap_or(usize::MAX)
    };
    assert!(lowest(a).min(lowest(b)) <= 3, "{a:?} {b:?}");
    // With a span of one layer there is no way past.
    let narrow = RouteParams {
        layer_span: 1,
        ..params.clone()
    };
    let result = route(&layers, &wires, &end_pads(&wires), &narrow);
    assert_eq!(result.wires.iter().filter(|r| r.routed).count(), 1);
}

#[test]
fn wire_between_layers_climbs_with_staircase_overlaps() {
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 5);
    let params = RouteParams::default();
    let w = wire("up", (5.0, 20.0, layers[0].z), (35.0, 20.0, layers[4].z));
    let r = route_wire(&layers, &w, &params);
    assert!(r.routed, "{r:?}");
    assert!(r.layer_changes >= 4, "{r:?}");
    assert_eq!(r.layer_changes + 1, r.segments.len());
    assert_eq!(r.segments.first().map(|s| s.0), Some(0));
    assert_eq!(r.segments.last().map(|s| s.0), Some(4));
    for pair in r.segments.windows(2) {
        let ((la, a), (lb, b)) = (&pair[0], &pair[1]);
        assert_eq!(la.abs_diff(*lb), 1);
        // Points sit at their layer's top.
        assert!(a.iter().all(|p| (p.z - layers[*la].z).abs() < 1e-12));
        let overlap = overlap_length(a, b);
        assert!(
            overlap >= params.interlayer_overlap,
            "layers {la}→{lb}: overlap {overlap}"
        );
    }
    assert!(
        r.length > r.lower_bound && r.length < 2.0 * r.lower_bound,
        "{r:?}"
    );
}

#[test]
fn single_stepping_reaches_the_same_route() {
    let layers = annulus_plate();
    let z = top(&layers);
    let params = RouteParams::default();
    let w = wire("sig", (5.0, 30.0, z), (55.0, 30.0, z));
    let mut search = Search::new(&layers, &w, &params);
    assert_eq!(search.state(), SearchState::Running);
    let mut steps = 0;
    let state = loop {
        let s = search.step();
        steps += 1;
        if s != SearchState::Running {
            break s;
        }
    };
    assert_eq!(state, SearchState::Found);
    assert!(steps > 10 && search.expansions() < steps);
    // Stepping a finished search changes nothing.
    assert_eq!(search.step(), SearchState::Found);
    assert_eq!(search.result(), route_wire(&layers, &w, &params));
    assert!(search.result().routed);
}

#[test]
fn pad_on_a_separate_island_is_unrouted_and_the_rest_goes_on() {
    let layers = stack(
        vec![
            solid(rect(0.0, 0.0, 20.0, 20.0)),
            solid(rect(30.0, 0.0, 50.0, 20.0)),
        ],
        3,
    );
    let z = top(&layers);
    let wires = [
        wire("gap", (5.0, 10.0, z), (40.0, 10.0, z)),
        wire("ok", (3.0, 3.0, z), (17.0, 17.0, z)),
    ];
    let result = route(&layers, &wires, &end_pads(&wires), &RouteParams::default());
    let gap = &result.wires[0];
    assert!(!gap.routed);
    assert!(gap.segments.is_empty());
    assert_eq!(gap.length, 0.0);
    assert_eq!(gap.lower_bound, 35.0);
    assert_eq!(gap.reason, Some(Unrouted::NoPath));
    assert!(result.wires[1].routed);
    assert_eq!(result.wires[1].reason, None);
    assert_eq!(result.wires[1].net, "ok");
    assert!(!result.time_limit_reached);
}

#[test]
fn routing_is_deterministic() {
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 6);
    let (z0, z5) = (layers[0].z, layers[5].z);
    let wires = [
        wire("a", (5.0, 5.0, z5), (35.0, 35.0, z5)),
        wire("b", (5.0, 35.0, z5), (35.0, 5.0, z5)),
        wire("c", (20.0, 3.0, z0), (20.0, 37.0, z5)),
        wire("a", (35.0, 35.0, z5), (35.0, 20.0, z5)),
    ];
    let params = RouteParams::default();
    let first = route(&layers, &wires, &end_pads(&wires), &params);
    let second = route(&layers, &wires, &end_pads(&wires), &params);
    assert_eq!(first, second);
    assert!(first.wires.iter().filter(|w| w.routed).count() >= 3);
}

#[test]
fn layer_of_picks_the_containing_or_nearest_layer() {
    let layers = stack(vec![solid(rect(0.0, 0.0, 10.0, 10.0))], 3);
    assert_eq!(layer_of(&layers, 0.2), Some(0));
    // Float noise on a boundary still picks the layer whose top the pad sits on.
    assert_eq!(layer_of(&layers, 0.2 + 1e-12), Some(0));
    assert_eq!(layer_of(&layers, 0.4 - 1e-12), Some(1));
    assert_eq!(layer_of(&layers, 0.3), Some(1));
    assert_eq!(layer_of(&layers, 0.6), Some(2));
    assert_eq!(layer_of(&layers, 5.0), Some(2));
    assert_eq!(layer_of(&layers, -1.0), Some(0));
    assert_eq!(layer_of(&[], 1.0), None);
}

#[test]
fn cheap_outside_weight_lets_the_route_cross_the_hole() {
    let layers = annulus_plate();
    let z = top(&layers);
    let params = RouteParams {
        outside_weight: 1.0,
        ..RouteParams::default()
    };
    let r = route_wire(
        &layers,
        &wire("sig", (5.0, 30.0, z), (55.0, 30.0, z)),
        &params,
    );
    assert!(r.routed);
    // Straight across: into the hole and out again.
    assert!((r.length - 50.0).abs() < 1e-6, "{}", r.length);
    assert_eq!(r.perimeter_crossings, 2);
}

#[test]
fn wires_of_one_net_may_share_a_pad() {
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 3);
    let z = top(&layers);
    let wires = [
        wire("gnd", (2.0, 20.0, z), (20.0, 20.0, z)),
        wire("gnd", (20.0, 20.0, z), (38.0, 20.0, z)),
        wire("sig", (20.0, 5.0, z), (20.0, 35.0, z)),
    ];
    let result = route(&layers, &wires, &end_pads(&wires), &RouteParams::default());
    assert!(result.wires.iter().all(|w| w.routed), "{result:?}");
    // The two gnd wires run straight into their shared pad.
    assert!((result.wires[0].length - 18.0).abs() < 1e-6);
    assert!((result.wires[1].length - 18.0).abs() < 1e-6);
    // The gnd line leaves no room for a trace at its ends: the signal crosses it on another
    // layer and comes back.
    assert!(result.wires[2].layer_changes >= 2, "{:?}", result.wires[2]);
}

#[test]
fn routes_longer_than_the_detour_limit_are_not_searched_for() {
    // Round the hole, pulled taut past its corners 1.75 mm out (the innermost deflated trace),
    // is 2·√(10² + 16.75²) + 30 ≈ 69.0 mm: 1.38 times the straight 50 mm.
    let layers = annulus_plate();
    let z = top(&layers);
    let w = wire("sig", (5.0, 30.0, z), (55.0, 30.0, z));
    let with = |max_detour: f64| RouteParams {
        max_detour,
        detour_slack: 0.0,
        ..RouteParams::default()
    };
    let long = route_wire(&layers, &w, &with(2.0));
    assert!(
        long.routed && long.length > 1.35 * long.lower_bound,
        "{long:?}"
    );
    let short = route_wire(&layers, &w, &with(1.2));
    assert_eq!(short.reason, Some(Unrouted::Detour));
    assert_eq!(
        short.reason.map(|r| r.to_string()).as_deref(),
        Some("no path within the detour limit (route.max_detour)")
    );
    let mut search = Search::new(&layers, &w, &with(1.2));
    while search.step() == SearchState::Running {}
    assert_eq!(search.state(), SearchState::Failed);
    // It gave up well before exploring what the longer limit needed.
    let mut full = Search::new(&layers, &w, &with(2.0));
    while full.step() == SearchState::Running {}
    assert!(search.expansions() < full.expansions());
}

#[test]
fn other_nets_pads_are_kept_clear_on_the_layers_next_to_them() {
    // A pad of net "p" sits on layer 3, right over the straight way of a wire of net "b" on
    // layer 2: a trace under the pad would touch the start of the pad's own trace, so the route
    // keeps the pad's clearance on layer 2 as it does on layer 3.
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 6);
    let params = RouteParams::default();
    let z = layers[2].z;
    let w = wire("b", (5.0, 20.0, z), (35.0, 20.0, z));
    let mut pads = end_pads(std::slice::from_ref(&w));
    pads.push(PadCopper::round(
        Some("p"),
        Point3::new(20.0, 20.0, layers[3].z),
        1.0,
    ));
    let result = route(&layers, std::slice::from_ref(&w), &pads, &params);
    let r = &result.wires[0];
    assert!(r.routed, "{r:?}");
    let clear = 0.5 + params.channel_extra / 2.0 + params.channel_half_width();
    let centre = Point3::new(20.0, 20.0, 0.0);
    for (l, points) in r.segments.iter().filter(|(l, _)| (2..=4).contains(l)) {
        let flat: Vec<Point3> = points.iter().map(|p| Point3::new(p.x, p.y, 0.0)).collect();
        let d = distance_to_polyline(&centre, &flat);
        assert!(d >= clear - 1e-3, "layer {l}: {d} mm from the pad");
    }
    // The pad's own net may run under it.
    let own = wire("p", (5.0, 20.0, z), (35.0, 20.0, z));
    let mut pads = end_pads(std::slice::from_ref(&own));
    pads.push(PadCopper::round(
        Some("p"),
        Point3::new(20.0, 20.0, layers[3].z),
        1.0,
    ));
    let r = &route(&layers, std::slice::from_ref(&own), &pads, &params).wires[0];
    assert!(r.routed && (r.length - 30.0).abs() < 0.5, "{r:?}");
}

#[test]
fn routes_are_pulled_taut() {
    // Across open material the rubberband itself is the route.
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 3);
    let z = top(&layers);
    let w = wire("sig", (5.0, 5.0, z), (35.0, 17.0, z));
    let r = route_wire(&layers, &w, &RouteParams::default());
    assert!(r.routed && r.length < r.lower_bound * 1.001, "{r:?}");
    // Round the annulus's hole the search runs on grid steps and ring points; pulled taut, the
    // route is the string past the hole's corners 1.75 mm out (its innermost deflated trace):
    // 2·√(10² + 16.75²) + 30 ≈ 69.0 mm, plus the rounding of those corners.
    let layers = annulus_plate();
    let z = top(&layers);
    let w = wire("sig", (5.0, 30.0, z), (55.0, 30.0, z));
    let r = route_wire(&layers, &w, &RouteParams::default());
    let taut = 2.0 * (10.0f64.powi(2) + 16.75f64.powi(2)).sqrt() + 30.0;
    assert!(
        r.routed && r.length > taut && r.length < 1.03 * taut,
        "{r:?}"
    );
    // No run has a point it could skip: every kept point turns the route.
    for (_, run) in &r.segments {
        for t in run.windows(3) {
            let d = distance_to_polyline(&t[1], &[t[0], t[2]]);
            assert!(d > 1e-3, "{:?} lies on the line of its neighbours", t[1]);
        }
    }
}

#[test]
fn a_wire_may_end_on_its_nets_trace_as_a_t_joint() {
    // Net "n": C–A (12.8 mm) is routed first; B is 30 mm from A but only 21.5 mm from C, the
    // far end of A's trace: B's wire ends on that trace instead of running beside it to A.
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 30.0))], 3);
    let z = top(&layers);
    let (a, b, c) = ((5.0, 5.0, z), (35.0, 5.0, z), (15.0, 13.0, z));
    let wires = [wire("n", a, b), wire("n", c, a)];
    let result = route(&layers, &wires, &end_pads(&wires), &RouteParams::default());
    let (ab, ca) = (&result.wires[0], &result.wires[1]);
    assert!(ab.routed && ca.routed, "{result:?}");
    assert_eq!((ab.ends_on_wire, ca.ends_on_wire), (Some(1), None));
    let trace: Vec<Point3> = ca.segments.iter().flat_map(|(_, p)| p.clone()).collect();
    let (_, last) = ab.segments.last().expect("a segment");
    let end = last.last().expect("a point");
    assert!(
        distance_to_polyline(end, &trace) < 1e-3,
        "{end:?} off {trace:?}"
    );
    // It starts at B (the pad with no copper yet) and is far shorter than B to A.
    let (_, first) = &ab.segments[0];
    assert!((first[0].x - b.0).abs() < 1e-6 && (first[0].y - b.1).abs() < 1e-6);
    let straight = ((end.x - b.0).powi(2) + (end.y - b.1).powi(2)).sqrt();
    assert!((ab.lower_bound - straight).abs() < 1e-6, "{ab:?}");
    assert!(ab.length >= ab.lower_bound - 1e-9);
    assert!(ab.length < 24.0, "{ab:?}");
}

#[test]
fn a_gap_too_narrow_for_perimeter_traces_is_squeezed_through() {
    // Two wide pads of net "x" close a 40 mm plate but for a 1.4 mm gap at x = 20: too narrow
    // for a deflated trace on each side (2 × (0.1 + 0.75) mm), wide enough for one channel clear
    // of both keep-outs. One layer, so the wire cannot pass over them.
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 30.0))], 1);
    let z = top(&layers);
    let w = wire("s", (10.0, 4.0, z), (30.0, 26.0, z));
    let mut pads = end_pads(std::slice::from_ref(&w));
    for (x0, x1) in [(-1.0, 19.3), (20.7, 41.0)] {
        pads.push(PadCopper {
            net: Some("x".into()),
            z,
            outline: rect(x0, 10.0, x1, 18.0),
        });
    }
    let squeezed = route(
        &layers,
        std::slice::from_ref(&w),
        &pads,
        &RouteParams::default(),
    );
    let r = &squeezed.wires[0];
    assert!(r.routed, "{r:?}");
    // Where the trace crosses the middle of the pads (y = 14), it is in the gap, a keep-out
    // (0.41 mm) clear of both pads.
    let crossings: Vec<f64> = r
        .segments
        .iter()
        .flat_map(|(_, p)| p.windows(2))
        .filter(|s| (s[0].y - 14.0) * (s[1].y - 14.0) <= 0.0 && s[0].y != s[1].y)
        .map(|s| s[0].x + (14.0 - s[0].y) / (s[1].y - s[0].y) * (s[1].x - s[0].x))
        .collect();
    assert_eq!(crossings.len(), 1, "{r:?}");
    assert!(
        crossings[0] > 19.3 + 0.4 && crossings[0] < 20.7 - 0.4,
        "{crossings:?}"
    );
    // Without the squeeze region the gap is closed.
    let params = RouteParams {
        squeeze_weight: f64::INFINITY,
        ..RouteParams::default()
    };
    let closed = route(&layers, std::slice::from_ref(&w), &pads, &params);
    assert!(!closed.wires[0].routed, "{:?}", closed.wires[0]);
}

/// Wires of the determinism test: four on a solid plate of six layers.
fn four_wires() -> (Vec<RouteLayer>, Vec<Wire>) {
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 6);
    let (z0, z5) = (layers[0].z, layers[5].z);
    let wires = vec![
        wire("a", (5.0, 5.0, z5), (35.0, 35.0, z5)),
        wire("b", (5.0, 35.0, z5), (35.0, 5.0, z5)),
        wire("c", (20.0, 3.0, z0), (20.0, 37.0, z5)),
        wire("a", (35.0, 35.0, z5), (35.0, 20.0, z5)),
    ];
    (layers, wires)
}

#[test]
fn a_passed_deadline_routes_nothing_and_says_why() {
    let (layers, wires) = four_wires();
    let params = RouteParams {
        time_limit: 7.5,
        watch: RouteWatch {
            deadline: Some(std::time::Instant::now()),
            progress: None,
        },
        ..RouteParams::default()
    };
    let result = route(&layers, &wires, &end_pads(&wires), &params);
    assert!(result.time_limit_reached);
    assert_eq!(result.rounds, 0);
    assert!(result.channels.iter().all(Vec::is_empty));
    for w in &result.wires {
        assert!(!w.routed && w.segments.is_empty(), "{w:?}");
        assert_eq!(w.reason, Some(Unrouted::TimeLimit(7.5)));
    }
    assert_eq!(
        Unrouted::TimeLimit(7.5).to_string(),
        "time limit reached (route.time_limit = 7.5 s)"
    );
}

#[test]
fn progress_and_a_far_deadline_change_nothing() {
    let (layers, wires) = four_wires();
    let pads = end_pads(&wires);
    let plain = route(&layers, &wires, &pads, &RouteParams::default());
    let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let sink = seen.clone();
    let params = RouteParams {
        time_limit: 0.0,
        watch: RouteWatch {
            deadline: RouteWatch::deadline_in(3600.0),
            progress: Some(std::sync::Arc::new(move |p| {
                sink.lock().expect("progress list").push(p)
            })),
        },
        ..RouteParams::default()
    };
    let watched = route(&layers, &wires, &pads, &params);
    assert_eq!(plain, watched);
    assert!(!watched.time_limit_reached);
    let seen = seen.lock().expect("progress list");
    // One report per wire of the first pass, counting up, then one per round and attempt.
    let first: Vec<usize> = seen
        .iter()
        .filter(|p| p.round == 0)
        .map(|p| p.done)
        .collect();
    assert_eq!(first, vec![1, 2, 3, 4]);
    assert!(seen.iter().all(|p| p.total == 4));
    let last = seen.last().expect("progress told");
    let unrouted = watched.wires.iter().filter(|w| !w.routed).count();
    assert_eq!(last.unrouted, unrouted);
    assert_eq!(
        seen.iter().map(|p| p.round).max(),
        Some(watched.rounds),
        "{seen:?}"
    );
}

#[test]
fn deadline_in_takes_positive_finite_seconds() {
    assert!(RouteWatch::deadline_in(0.0).is_none());
    assert!(RouteWatch::deadline_in(-1.0).is_none());
    assert!(RouteWatch::deadline_in(f64::NAN).is_none());
    assert!(RouteWatch::deadline_in(f64::INFINITY).is_none());
    let soon = RouteWatch::deadline_in(60.0).expect("a deadline");
    assert!(soon > std::time::Instant::now());
}

#[test]
fn negotiated_routing_settles_crossings_with_disjoint_channels() {
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 6);
    let z = top(&layers);
    let params = RouteParams {
        strategy: Strategy::Negotiated,
        ..RouteParams::default()
    };
    // Two wall-to-wall wires and two diagonals: every rubberband crosses every other.
    let wires = [
        wire("a", (0.6, 20.0, z), (39.4, 20.0, z)),
        wire("b", (20.0, 0.6, z), (20.0, 39.4, z)),
        wire("c", (5.0, 5.0, z), (35.0, 35.0, z)),
        wire("d", (5.0, 35.0, z), (35.0, 5.0, z)),
    ];
    let pads = end_pads(&wires);
    let result = route(&layers, &wires, &pads, &params);
    assert!(result.negotiation_rounds >= 1);
    for (i, a) in result.wires.iter().enumerate() {
        assert!(a.routed, "{a:?}");
        assert!(a.length >= a.lower_bound - 1e-6);
        for b in &result.wires[i + 1..] {
            assert!(!channels_touch(a, b, layers.len(), &params), "{a:?} {b:?}");
        }
    }
    // The same bytes again.
    assert_eq!(route(&layers, &wires, &pads, &params), result);
}

#[test]
fn an_impossible_board_names_what_blocks_each_unrouted_wire() {
    // A span of one layer leaves no way past a wall-to-wall trace (see above).
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 6);
    let z = top(&layers);
    let params = RouteParams {
        layer_span: 1,
        ..RouteParams::default()
    };
    let wires = [
        wire("a", (0.6, 20.0, z), (39.4, 20.0, z)),
        wire("b", (20.0, 0.6, z), (20.0, 39.4, z)),
    ];
    let pads = end_pads(&wires);
    let result = route(&layers, &wires, &pads, &params);
    let (routed, failed): (Vec<usize>, Vec<usize>) = (0..2).partition(|&i| result.wires[i].routed);
    assert_eq!((routed.len(), failed.len()), (1, 1), "{result:?}");
    let (ok, bad) = (routed[0], failed[0]);
    assert_eq!(result.wires[ok].blockage, None);
    let blockage = result.wires[bad].blockage.as_ref().expect("a blockage");
    assert_eq!(blockage.traces, vec![ok]);
    assert!(blockage.pads.is_empty());
    assert!(blockage.way_without_traces);

    // A pad of net d 0.5 mm from b's end, closer than two traces can run, walls that end in:
    // b has no way even without a's trace, and the pad is named with its distance.
    let mut pads = pads;
    pads.push(PadCopper::round(Some("d"), Point3::new(20.5, 39.4, z), 0.2));
    let result = route(&layers, &wires, &pads, &params);
    let b = &result.wires[1];
    assert!(!b.routed);
    let blockage = b.blockage.as_ref().expect("a blockage");
    assert_eq!(blockage.pads.len(), 1, "{blockage:?}");
    assert_eq!(blockage.pads[0].pad, pads.len() - 1);
    assert!(blockage.pads[0].near_to, "{blockage:?}");
    assert!(
        (blockage.pads[0].distance - 0.5).abs() < 0.01,
        "{blockage:?}"
    );
    assert!(!blockage.way_without_traces);
    assert!(blockage.traces.is_empty());
}

#[test]
fn a_pad_on_an_island_of_its_own_is_proven_unreachable_from_its_side() {
    // The near pad's search would flood the plate up to the detour limit; the short look from
    // the far pad, boxed in on its island, runs out of material at once.
    let layers = stack(
        vec![
            solid(rect(0.0, 0.0, 40.0, 40.0)),
            solid(rect(43.0, 18.0, 47.0, 22.0)),
        ],
        3,
    );
    let z = top(&layers);
    let wires = [wire("boxed", (37.0, 20.0, z), (45.0, 20.0, z))];
    let result = route(&layers, &wires, &end_pads(&wires), &RouteParams::default());
    let boxed = &result.wires[0];
    assert!(!boxed.routed);
    assert_eq!(boxed.reason, Some(Unrouted::NoPath));
}

#[test]
fn routes_are_the_same_on_any_number_of_threads() {
    // Short wires spread over a plate (searched side by side) among long ones that cross them
    // (searched in their turn), some of them changing layer.
    let layers = stack(vec![solid(rect(0.0, 0.0, 60.0, 60.0))], 6);
    let (z1, z4) = (layers[1].z, layers[4].z);
    let mut wires = Vec::new();
    for k in 0..4 {
        for j in 0..3 {
            let (x, y) = (6.0 + 15.0 * k as f64, 8.0 + 20.0 * j as f64);
            let z = if (k + j) % 2 == 0 { z1 } else { z4 };
            wires.push(wire(&format!("s{k}{j}"), (x, y, z4), (x + 6.0, y + 3.0, z)));
        }
    }
    wires.push(wire("x", (3.0, 30.0, z4), (57.0, 32.0, z4)));
    wires.push(wire("y", (30.0, 3.0, z1), (31.0, 57.0, z4)));
    let params = RouteParams::default();
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        pool.install(|| route(&layers, &wires, &end_pads(&wires), &params))
    };
    let one = on(1);
    assert_eq!(one.wires.iter().filter(|w| w.routed).count(), wires.len());
    assert_eq!(on(2), one);
    assert_eq!(on(3), one);
}

#[test]
fn the_heuristic_never_promises_more_than_a_climb_costs() {
    // Steep climbs (8 layers over 4 mm) and shallow ones (8 layers over 30 mm): every layer
    // change prints a piece longer than overlap + grid step, so a climb costs at least that
    // per layer on top of its xy distance, more than the heuristic's bound.
    let layers = stack(vec![solid(rect(0.0, 0.0, 40.0, 40.0))], 10);
    let params = RouteParams::default();
    let step_cost = params.layer_change_penalty
        + (params.interlayer_overlap + params.grid_step) * params.base_weight;
    for (to_x, to_layer) in [(9.0, 8), (35.0, 8), (30.0, 3)] {
        let w = wire(
            "up",
            (5.0, 20.0, layers[0].z),
            (to_x, 20.0, layers[to_layer].z),
        );
        let mut search = Search::new(&layers, &w, &params);
        while search.step() == SearchState::Running {}
        let r = search.result();
        assert!(r.routed, "{r:?}");
        assert_eq!(r.layer_changes, to_layer, "{r:?}");
        let (slack, cost) = search.heuristic_slack();
        assert!(slack >= -1e-9, "to x {to_x}: heuristic over by {}", -slack);
        // The bound it rests on: the xy distance plus a whole step per layer.
        assert!(cost >= (to_x - 5.0) + step_cost * to_layer as f64 - 1e-9);
    }
}
