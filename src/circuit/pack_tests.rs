//! Tests of the packer on hand-built circuits and regions.

use std::collections::{BTreeMap, BTreeSet};

use super::*;
use crate::circuit::{Net, Pad, PadShape, Part, PinRef};
use crate::geom::{Point2, Polygon, difference, intersection};

/// A part with rectangular pads `(name, x, y, width, height)`.
fn part(name: &str, pads: &[(&str, f64, f64, f64, f64)]) -> Part {
    Part {
        name: name.into(),
        value: None,
        package: "PKG".into(),
        pads: pads
            .iter()
            .map(|&(n, x, y, width, height)| Pad {
                name: n.into(),
                x,
                y,
                rotation_deg: 0.0,
                shape: PadShape::Rect { width, height },
                smd: true,
            })
            .collect(),
        pins: BTreeMap::new(),
        route_any: BTreeSet::new(),
    }
}

/// A two-pad part `len` mm long (pads 1 × 1 mm at its ends, along x).
fn two_pad(name: &str, len: f64) -> Part {
    let h = (len - 1.0) / 2.0;
    part(name, &[("1", -h, 0.0, 1.0, 1.0), ("2", h, 0.0, 1.0, 1.0)])
}

/// A square part of side `side` with one pad covering it.
fn block(name: &str, side: f64) -> Part {
    part(name, &[("1", 0.0, 0.0, side, side)])
}

fn circuit(parts: Vec<Part>, nets: &[(&str, &[(&str, &str)])]) -> Circuit {
    Circuit {
        parts,
        nets: nets
            .iter()
            .map(|(name, pins)| Net {
                name: (*name).into(),
                pins: pins.iter().map(|&(p, q)| PinRef::new(p, q)).collect(),
            })
            .collect(),
    }
}

fn ring(pts: &[(f64, f64)]) -> Polygon {
    Polygon::new(pts.iter().map(|&(x, y)| Point2::from_mm(x, y)).collect())
}

fn rect_ring(x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon {
    ring(&[(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
}

fn rect_region(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<ExPolygon> {
    vec![ExPolygon {
        contour: rect_ring(x0, y0, x1, y1),
        holes: vec![],
    }]
}

fn params(gap: f64) -> PackParams {
    PackParams {
        gap,
        rotate: true,
        step: 0.5,
    }
}

fn names(c: &Circuit) -> Vec<&str> {
    c.parts.iter().map(|p| p.name.as_str()).collect()
}

fn packed(c: &Circuit, region: &[ExPolygon], p: &PackParams) -> Vec<Packed> {
    match pack(c, &names(c), region, p) {
        Ok(v) => v,
        Err(e) => panic!("{e}"),
    }
}

/// The footprint of a packed part, `[x0, y0, x1, y1]` mm, computed from its pads here.
fn footprint(c: &Circuit, p: &Packed) -> [f64; 4] {
    let part = c.part(&p.name).expect("packed part in the circuit");
    let (s, co) = p.rotation.to_radians().sin_cos();
    let mut fp = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for pad in &part.pads {
        let [hx, hy] = pad.half_extent();
        for (dx, dy) in [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)] {
            let (x, y) = (pad.x + dx, pad.y + dy);
            let (u, v) = (p.x + co * x - s * y, p.y + s * x + co * y);
            fp = [fp[0].min(u), fp[1].min(v), fp[2].max(u), fp[3].max(v)];
        }
    }
    fp
}

fn fp_polygon(f: [f64; 4]) -> ExPolygon {
    ExPolygon {
        contour: rect_ring(f[0], f[1], f[2], f[3]),
        holes: vec![],
    }
}

fn distance(a: [f64; 4], b: [f64; 4]) -> f64 {
    let dx = (a[0] - b[2]).max(b[0] - a[2]).max(0.0);
    let dy = (a[1] - b[3]).max(b[1] - a[3]).max(0.0);
    dx.hypot(dy)
}

fn centre(f: [f64; 4]) -> [f64; 2] {
    [(f[0] + f[2]) / 2.0, (f[1] + f[3]) / 2.0]
}

/// Every part packed once, every footprint inside the region (nothing of it left outside,
/// to 10⁻⁶ mm²), every two footprints at least `gap` apart. Returns the footprints by name.
fn check(
    c: &Circuit,
    out: &[Packed],
    region: &[ExPolygon],
    gap: f64,
) -> BTreeMap<String, [f64; 4]> {
    let got: Vec<&str> = out.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(got, names(c), "every part, in order");
    let fps: BTreeMap<String, [f64; 4]> = out
        .iter()
        .map(|p| (p.name.clone(), footprint(c, p)))
        .collect();
    for p in out {
        assert!(
            [0.0, 90.0, 180.0, 270.0].contains(&p.rotation),
            "{}: {}",
            p.name,
            p.rotation
        );
        let f = fps[&p.name];
        let outside: f64 = difference(&[fp_polygon(f)], region)
            .iter()
            .map(ExPolygon::area_mm2)
            .sum();
        assert!(outside < 1e-6, "{} at {f:?}: {outside} mm² outside", p.name);
    }
    for (a, fa) in &fps {
        for (b, fb) in &fps {
            if a < b {
                let d = distance(*fa, *fb);
                assert!(d >= gap - 1e-6, "{a} and {b} are {d} mm apart");
            }
        }
    }
    fps
}

#[test]
fn connected_parts_end_up_closer_than_unconnected_ones() {
    let c = circuit(
        vec![
            two_pad("A", 4.0),
            two_pad("B", 4.0),
            two_pad("C", 4.0),
            two_pad("D", 4.0),
        ],
        &[
            ("N1", &[("A", "1"), ("B", "1")]),
            ("N2", &[("A", "2"), ("B", "2")]),
            ("N3", &[("C", "1"), ("D", "1")]),
            ("N4", &[("C", "2"), ("D", "2")]),
        ],
    );
    let region = rect_region(0.0, 0.0, 40.0, 40.0);
    let out = packed(&c, &region, &params(1.0));
    let fps = check(&c, &out, &region, 1.0);
    let d = |a: &str, b: &str| distance(fps[a], fps[b]);
    // Each pair side by side at the gap (one grid step of slack at most).
    assert!(d("A", "B") <= 1.5 && d("C", "D") <= 1.5, "{fps:?}");
    // Unconnected parts are further apart on average.
    let unconnected = (d("A", "C") + d("A", "D") + d("B", "C") + d("B", "D")) / 4.0;
    assert!(unconnected > (d("A", "B") + d("C", "D")) / 2.0, "{fps:?}");
    // Side by side and parallel: both nets are one gap plus a pad long at most.
    let len = rubberband_length(&c, &out);
    assert!(len <= 4.0 * 2.5 + 1e-9, "{len}");
}

#[test]
fn rubberband_length_is_the_spanning_tree_of_the_pads() {
    let c = circuit(
        vec![
            part("A", &[("1", 0.0, 0.0, 1.0, 1.0)]),
            part("B", &[("1", 1.0, 0.0, 1.0, 1.0)]),
            part("C", &[("1", 0.0, 0.0, 1.0, 1.0)]),
        ],
        &[("N", &[("A", "1"), ("B", "1"), ("C", "1")])],
    );
    let at = |name: &str, x, y, rotation| Packed {
        name: name.into(),
        x,
        y,
        rotation,
    };
    // B's pad (1, 0) turned a quarter lands at (3, 3) + (0, 1) = (3, 4): the spanning tree is
    // A (0, 0) – C (3, 0), 3 mm, and C – B, 4 mm, not A – B, 5 mm.
    let out = [
        at("A", 0.0, 0.0, 0.0),
        at("B", 3.0, 3.0, 90.0),
        at("C", 3.0, 0.0, 0.0),
    ];
    assert!((rubberband_length(&c, &out) - 7.0).abs() < 1e-9);
    // Without C, the one edge A–B.
    assert!((rubberband_length(&c, &out[..2]) - 5.0).abs() < 1e-9);
}

#[test]
fn joined_pads_of_one_pin_count_as_one_point() {
    let mut u = part(
        "U",
        &[("1", 0.0, 0.0, 1.0, 1.0), ("2", 10.0, 0.0, 1.0, 1.0)],
    );
    u.pins
        .insert("G$1.GND".into(), vec!["1".into(), "2".into()]);
    u.route_any.insert("G$1.GND".into());
    let c = circuit(
        vec![u, part("R", &[("1", 0.0, 0.0, 1.0, 1.0)])],
        &[("GND", &[("R", "1"), ("U", "1"), ("U", "2")])],
    );
    let out = [
        Packed {
            name: "U".into(),
            x: 0.0,
            y: 0.0,
            rotation: 0.0,
        },
        Packed {
            name: "R".into(),
            x: 10.0,
            y: 2.0,
            rotation: 0.0,
        },
    ];
    // R joins pad 2 (2 mm away); pads 1 and 2 need no band between them.
    assert!((rubberband_length(&c, &out) - 2.0).abs() < 1e-9);
}

#[test]
fn an_l_shaped_region_keeps_parts_out_of_its_notch() {
    // An L: 30 × 10 along the bottom, 10 × 30 up the left side.
    let region = vec![ExPolygon {
        contour: ring(&[
            (0.0, 0.0),
            (30.0, 0.0),
            (30.0, 10.0),
            (10.0, 10.0),
            (10.0, 30.0),
            (0.0, 30.0),
        ]),
        holes: vec![],
    }];
    // 24 parts of 6 × 1 mm, 14 mm² each with the gap: more than one arm holds.
    let parts: Vec<Part> = (0..24).map(|k| two_pad(&format!("R{k:02}"), 6.0)).collect();
    let nets: Vec<(String, Vec<(String, String)>)> = (0..23)
        .map(|k| {
            (
                format!("N{k}"),
                vec![
                    (format!("R{k:02}"), "2".into()),
                    (format!("R{:02}", k + 1), "1".into()),
                ],
            )
        })
        .collect();
    let c = Circuit {
        parts,
        nets: nets
            .iter()
            .map(|(n, pins)| Net {
                name: n.clone(),
                pins: pins.iter().map(|(p, q)| PinRef::new(p, q)).collect(),
            })
            .collect(),
    };
    let out = packed(&c, &region, &params(1.0));
    let fps = check(&c, &out, &region, 1.0);
    // Nothing in the notch (10..30) × (10..30).
    let notch = [fp_polygon([10.0, 10.0, 30.0, 30.0])];
    for (name, f) in &fps {
        let a: f64 = intersection(&[fp_polygon(*f)], &notch)
            .iter()
            .map(ExPolygon::area_mm2)
            .sum();
        assert_eq!(a, 0.0, "{name} at {f:?}");
    }
    // The region is used: parts in both arms.
    assert!(
        fps.values().any(|f| f[0] >= 10.0) && fps.values().any(|f| f[1] >= 10.0),
        "{fps:?}"
    );
}

#[test]
fn a_ring_region_keeps_parts_out_of_its_hole() {
    let mut hole = rect_ring(10.0, 10.0, 30.0, 30.0);
    hole.points.reverse();
    let region = vec![ExPolygon {
        contour: rect_ring(0.0, 0.0, 40.0, 40.0),
        holes: vec![hole],
    }];
    let parts: Vec<Part> = (0..10).map(|k| block(&format!("U{k}"), 4.0)).collect();
    let c = circuit(
        parts,
        &[
            ("A", &[("U0", "1"), ("U1", "1"), ("U2", "1")]),
            ("B", &[("U3", "1"), ("U4", "1")]),
        ],
    );
    let out = packed(&c, &region, &params(1.0));
    let fps = check(&c, &out, &region, 1.0);
    let hole = [fp_polygon([10.0, 10.0, 30.0, 30.0])];
    for (name, f) in &fps {
        let a: f64 = intersection(&[fp_polygon(*f)], &hole)
            .iter()
            .map(ExPolygon::area_mm2)
            .sum();
        assert_eq!(a, 0.0, "{name} at {f:?} in the hole");
        // The ring is 10 mm wide: a 4 mm part lies within it on one side.
        let [x, y] = centre(*f);
        assert!(!(x > 12.0 && x < 28.0 && y > 12.0 && y < 28.0), "{name}");
    }
}

#[test]
fn parts_spread_over_several_islands() {
    // Two 10 × 10 islands 20 mm apart: two 6 mm blocks 1 mm apart cannot share one island.
    let mut region = rect_region(0.0, 0.0, 10.0, 10.0);
    region.extend(rect_region(30.0, 0.0, 40.0, 10.0));
    let c = circuit(
        (0..2).map(|k| block(&format!("U{k}"), 6.0)).collect(),
        &[("N", &[("U0", "1"), ("U1", "1")])],
    );
    let out = packed(&c, &region, &params(1.0));
    let fps = check(&c, &out, &region, 1.0);
    let xs: Vec<f64> = fps.values().map(|f| centre(*f)[0]).collect();
    assert!(
        xs.iter().any(|&x| x < 10.0) && xs.iter().any(|&x| x > 30.0),
        "{xs:?}"
    );
}

#[test]
fn a_region_too_small_names_the_parts_that_do_not_fit() {
    let c = circuit(
        vec![block("BIG", 8.0), block("MID", 6.0), block("SMALL", 2.0)],
        &[("N", &[("BIG", "1"), ("MID", "1"), ("SMALL", "1")])],
    );
    let region = rect_region(0.0, 0.0, 10.0, 10.0);
    match pack(&c, &names(&c), &region, &params(1.0)) {
        Err(PackError::NoRoom {
            parts,
            free_mm2,
            needed_mm2,
        }) => {
            assert_eq!(parts, ["MID", "SMALL"]);
            assert!((free_mm2 - 100.0).abs() < 1e-9, "{free_mm2}");
            assert!(
                (needed_mm2 - (81.0 + 49.0 + 9.0)).abs() < 1e-9,
                "{needed_mm2}"
            );
        }
        other => panic!("{other:?}"),
    }
    // An empty region has room for nothing.
    match pack(&c, &["SMALL"], &[], &params(1.0)) {
        Err(PackError::NoRoom { parts, .. }) => assert_eq!(parts, ["SMALL"]),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_long_part_turns_to_fit_a_narrow_strip() {
    // A strip 3 mm wide and 30 mm tall; the part is 10 × 2 mm lying along x.
    let region = rect_region(0.0, 0.0, 3.0, 30.0);
    let c = circuit(vec![two_pad("R1", 10.0), two_pad("R2", 10.0)], &[]);
    let out = packed(&c, &region, &params(1.0));
    check(&c, &out, &region, 1.0);
    for p in &out {
        assert!(p.rotation == 90.0 || p.rotation == 270.0, "{p:?}");
    }
    // Without turns it cannot fit.
    let no_turns = PackParams {
        rotate: false,
        ..params(1.0)
    };
    match pack(&c, &names(&c), &region, &no_turns) {
        Err(PackError::NoRoom { parts, .. }) => assert_eq!(parts, ["R1", "R2"]),
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_gap_is_kept_and_no_more_than_needed() {
    let c = circuit(
        vec![block("A", 3.0), block("B", 3.0)],
        &[("N", &[("A", "1"), ("B", "1")])],
    );
    let region = rect_region(0.0, 0.0, 30.0, 30.0);
    for gap in [0.0, 2.0, 3.5] {
        let out = packed(&c, &region, &params(gap));
        let fps = check(&c, &out, &region, gap);
        let d = distance(fps["A"], fps["B"]);
        assert!(d >= gap - 1e-6 && d <= gap + 0.5 + 1e-6, "gap {gap}: {d}");
    }
}

/// A circuit of `n` parts of a few sizes, chained and with a shared supply net.
fn chain(n: usize) -> Circuit {
    let parts: Vec<Part> = (0..n)
        .map(|k| match k % 3 {
            0 => two_pad(&format!("P{k:02}"), 3.0),
            1 => block(&format!("P{k:02}"), 2.0 + (k % 4) as f64),
            _ => part(
                &format!("P{k:02}"),
                &[("1", 0.0, 0.0, 1.0, 1.0), ("2", 2.0, 3.0, 1.0, 1.0)],
            ),
        })
        .collect();
    let mut nets: Vec<Net> = (1..n)
        .map(|k| Net {
            name: format!("N{k:02}"),
            pins: vec![
                PinRef::new(format!("P{:02}", (k * 7) % n), "1"),
                PinRef::new(format!("P{k:02}"), "1"),
            ],
        })
        .collect();
    nets.push(Net {
        name: "VCC".into(),
        pins: (0..n)
            .step_by(4)
            .map(|k| PinRef::new(format!("P{k:02}"), "1"))
            .collect(),
    });
    Circuit { parts, nets }
}

#[test]
fn packing_is_deterministic() {
    let c = chain(16);
    let region = rect_region(-20.0, -15.0, 20.0, 15.0);
    let a = packed(&c, &region, &params(1.5));
    let b = packed(&c, &region, &params(1.5));
    assert_eq!(a, b);
    check(&c, &a, &region, 1.5);
}

#[test]
fn improvement_shortens_the_greedy_rubberbands() {
    // A chain where the greedy order leaves room to improve: the packed length is no longer
    // than every part at the same spot in a name-ordered row would give.
    let c = chain(12);
    let region = rect_region(0.0, 0.0, 40.0, 40.0);
    let out = packed(&c, &region, &params(1.0));
    check(&c, &out, &region, 1.0);
    let mut row = out.clone();
    let mut x = 0.0;
    for p in &mut row {
        let f = footprint(
            &c,
            &Packed {
                rotation: 0.0,
                x: 0.0,
                y: 0.0,
                ..p.clone()
            },
        );
        (p.x, p.y, p.rotation) = (x - f[0], 20.0, 0.0);
        x += f[2] - f[0] + 1.0;
    }
    let (packed_len, row_len) = (rubberband_length(&c, &out), rubberband_length(&c, &row));
    assert!(packed_len < row_len, "{packed_len} vs a row's {row_len}");
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let mut c = circuit(vec![block("A", 2.0), part("EMPTY", &[])], &[]);
    let region = rect_region(0.0, 0.0, 10.0, 10.0);
    let err = |c: &Circuit, names: &[&str], p: PackParams| match pack(c, names, &region, &p) {
        Err(e) => e.to_string(),
        Ok(v) => panic!("{v:?}"),
    };
    assert_eq!(
        err(&c, &["A"], params(f64::NAN)),
        "pack: gap = NaN is not a number from 0 to 10000 mm"
    );
    let zero_step = PackParams {
        step: 0.0,
        ..params(1.0)
    };
    assert_eq!(
        err(&c, &["A"], zero_step),
        "pack: step = 0 is not a number from 0.001 to 10000 mm"
    );
    let fine = PackParams {
        step: 0.001,
        ..params(1.0)
    };
    assert_eq!(
        err(&c, &["A"], fine),
        "pack: a step of 0.001 mm makes 100020001 grid positions over the region (at most 4000000); use a larger step"
    );
    assert_eq!(
        err(&c, &["B"], params(1.0)),
        "pack: the circuit has no part B"
    );
    assert_eq!(
        err(&c, &["A", "A"], params(1.0)),
        "pack: part A is listed twice"
    );
    assert_eq!(
        err(&c, &["EMPTY"], params(1.0)),
        "pack: part EMPTY has no pads"
    );
    c.parts[0].pads[0].x = f64::INFINITY;
    assert_eq!(
        err(&c, &["A"], params(1.0)),
        "pack: part A pad 1: x = inf is not a finite number within bounds"
    );
    // Nothing to pack is no error.
    assert_eq!(pack(&c, &[], &region, &params(1.0)), Ok(Vec::new()));
}

#[test]
fn a_slanted_boundary_is_tested_exactly() {
    // A right triangle: the hypotenuse cuts through grid cells; footprints touch it at most.
    let region = vec![ExPolygon {
        contour: ring(&[(0.0, 0.0), (20.0, 0.0), (0.0, 20.0)]),
        holes: vec![],
    }];
    let c = circuit(
        (0..5).map(|k| two_pad(&format!("R{k}"), 3.3)).collect(),
        &[("N", &[("R0", "1"), ("R4", "2")])],
    );
    let out = packed(&c, &region, &params(0.7));
    check(&c, &out, &region, 0.7);
}

#[test]
fn a_crowded_region_is_packed_when_the_connected_order_leaves_a_part_out() {
    // Four connected 2 mm blocks go to the middle first and leave no 7 mm square free; the
    // large unconnected block only fits in a corner, with the small ones along its sides.
    let mut parts = vec![block("BIG", 7.0)];
    parts.extend((0..4).map(|k| block(&format!("S{k}"), 2.0)));
    let c = circuit(
        parts,
        &[
            ("N1", &[("S0", "1"), ("S1", "1")]),
            ("N2", &[("S1", "1"), ("S2", "1")]),
            ("N3", &[("S2", "1"), ("S3", "1")]),
        ],
    );
    let region = rect_region(0.0, 0.0, 12.0, 12.0);
    let out = packed(&c, &region, &params(1.0));
    let fps = check(&c, &out, &region, 1.0);
    // BIG in a corner: 7 mm plus the gap plus a 2 mm block is 10 mm of the 12.
    let big = fps["BIG"];
    assert!(
        (big[0] <= 0.5 || big[2] >= 11.5) && (big[1] <= 0.5 || big[3] >= 11.5),
        "{big:?}"
    );
}

#[test]
fn a_round_region_of_many_edges() {
    // A disc of radius 15 mm as a 720-gon: every boundary cell is crossed by slanted edges.
    let disc: Vec<(f64, f64)> = (0..720)
        .map(|k| {
            let a = (k as f64 / 2.0).to_radians();
            (15.0 * a.cos(), 15.0 * a.sin())
        })
        .collect();
    let region = vec![ExPolygon {
        contour: ring(&disc),
        holes: vec![],
    }];
    let c = chain(20);
    let out = packed(&c, &region, &params(1.0));
    let fps = check(&c, &out, &region, 1.0);
    // Footprint corners stay within the circle.
    for (name, f) in &fps {
        for (x, y) in [(f[0], f[1]), (f[2], f[1]), (f[2], f[3]), (f[0], f[3])] {
            assert!(x.hypot(y) <= 15.0 + 1e-6, "{name} at {f:?}");
        }
    }
}
