//! Corpus schematics packed into a square: every part with pads inside it, 3 mm apart, with
//! rubberbands no longer than a grid of cells improved by swaps gives.

use std::collections::BTreeMap;
use std::time::Instant;

use conduit::circuit::pack::{PackParams, Packed, pack, rubberband_length};
use conduit::circuit::{Circuit, Part};
use conduit::geom::{ExPolygon, Point2, Polygon, difference};

use crate::support::{corpus, eagle_file};

/// Distance between footprints, mm.
const GAP_MM: f64 = 3.0;

/// A packed part's footprint in the region's frame, `[x0, y0, x1, y1]` mm.
fn footprint(c: &Circuit, p: &Packed) -> [f64; 4] {
    let part = c.part(&p.name).expect("packed part in the circuit");
    let e = part.pad_extent().expect("a part with pads");
    let (s, co) = p.rotation.to_radians().sin_cos();
    let mut f = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for (x, y) in [(e[0], e[1]), (e[2], e[1]), (e[2], e[3]), (e[0], e[3])] {
        let (u, v) = (p.x + co * x - s * y, p.y + s * x + co * y);
        f = [f[0].min(u), f[1].min(v), f[2].max(u), f[3].max(v)];
    }
    f
}

fn rect(f: [f64; 4]) -> ExPolygon {
    ExPolygon {
        contour: Polygon::new(vec![
            Point2::from_mm(f[0], f[1]),
            Point2::from_mm(f[2], f[1]),
            Point2::from_mm(f[2], f[3]),
            Point2::from_mm(f[0], f[3]),
        ]),
        holes: vec![],
    }
}

/// The crude arrangement the corpus routing test starts from: parts in the cells of a square
/// grid (`ceil(sqrt(n))` columns; each column as wide as its widest footprint, each row as deep
/// as its deepest, plus half the gap on each side; footprints centred), all at rotation 0,
/// swapping cells (first improvement, fixed order) while the rubberbands get shorter.
fn grid_placement(c: &Circuit, parts: &[(&Part, [f64; 4])]) -> Vec<Packed> {
    let layout = |order: &[(&Part, [f64; 4])]| -> Vec<Packed> {
        let cols = (order.len() as f64).sqrt().ceil().max(1.0) as usize;
        let rows = order.len().div_ceil(cols);
        let (mut widths, mut depths) = (vec![0.0f64; cols], vec![0.0f64; rows]);
        for (k, (_, e)) in order.iter().enumerate() {
            widths[k % cols] = widths[k % cols].max(e[2] - e[0] + GAP_MM);
            depths[k / cols] = depths[k / cols].max(e[3] - e[1] + GAP_MM);
        }
        let starts = |sizes: &[f64]| -> Vec<f64> {
            sizes
                .iter()
                .scan(0.0, |next, s| {
                    let start = *next;
                    *next += s;
                    Some(start)
                })
                .collect()
        };
        let (xs, ys) = (starts(&widths), starts(&depths));
        order
            .iter()
            .enumerate()
            .map(|(k, (p, e))| {
                let (col, row) = (k % cols, k / cols);
                Packed {
                    name: p.name.clone(),
                    x: xs[col] + widths[col] / 2.0 - (e[0] + e[2]) / 2.0,
                    y: ys[row] + depths[row] / 2.0 - (e[1] + e[3]) / 2.0,
                    rotation: 0.0,
                }
            })
            .collect()
    };
    let mut order = parts.to_vec();
    let mut current = rubberband_length(c, &layout(&order));
    let mut improved = true;
    while improved {
        improved = false;
        for i in 0..order.len() {
            for j in i + 1..order.len() {
                order.swap(i, j);
                let l = rubberband_length(c, &layout(&order));
                if l < current - 1e-9 {
                    current = l;
                    improved = true;
                } else {
                    order.swap(i, j);
                }
            }
        }
    }
    layout(&order)
}

/// Packs every part with pads of corpus board `name` into a square of twice their footprints
/// grown by half the gap on each side, and checks it.
fn packs(name: &str) {
    let Some(corpus) = corpus() else {
        return;
    };
    let c = Circuit::load(&eagle_file(&corpus, name, "sch")).unwrap_or_else(|e| panic!("{e}"));
    let parts: Vec<(&Part, [f64; 4])> = c
        .parts
        .iter()
        .filter_map(|p| p.pad_extent().map(|e| (p, e)))
        .collect();
    let names: Vec<&str> = parts.iter().map(|(p, _)| p.name.as_str()).collect();
    let need: f64 = parts
        .iter()
        .map(|(_, e)| (e[2] - e[0] + GAP_MM) * (e[3] - e[1] + GAP_MM))
        .sum();
    let side = (2.0 * need).sqrt().ceil();
    let region = [rect([0.0, 0.0, side, side])];
    let params = PackParams {
        gap: GAP_MM,
        rotate: true,
        step: 0.5,
    };
    let started = Instant::now();
    let out = pack(&c, &names, &region, &params).unwrap_or_else(|e| panic!("{name}: {e}"));
    let seconds = started.elapsed().as_secs_f64();
    let again = pack(&c, &names, &region, &params).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(out, again, "{name}: two runs differ");

    let got: Vec<&str> = out.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(got, names, "{name}: every part, in order");
    let fps: BTreeMap<&str, [f64; 4]> = out
        .iter()
        .map(|p| (p.name.as_str(), footprint(&c, p)))
        .collect();
    for (part, f) in &fps {
        let outside: f64 = difference(&[rect(*f)], &region)
            .iter()
            .map(ExPolygon::area_mm2)
            .sum();
        assert!(outside < 1e-6, "{name}: {part} at {f:?} is outside");
    }
    for (a, fa) in &fps {
        for (b, fb) in &fps {
            if a < b {
                let dx = (fa[0] - fb[2]).max(fb[0] - fa[2]).max(0.0);
                let dy = (fa[1] - fb[3]).max(fb[1] - fa[3]).max(0.0);
                let d = dx.hypot(dy);
                assert!(d >= GAP_MM - 1e-6, "{name}: {a} and {b} are {d} mm apart");
            }
        }
    }
    let packed_len = rubberband_length(&c, &out);
    let grid = grid_placement(&c, &parts);
    let grid_len = rubberband_length(&c, &grid);
    let grid_size = grid.iter().fold([0.0f64; 2], |m, p| {
        let f = footprint(&c, p);
        [m[0].max(f[2] + GAP_MM / 2.0), m[1].max(f[3] + GAP_MM / 2.0)]
    });
    let turned = out.iter().filter(|p| p.rotation != 0.0).count();
    println!(
        "{name}: {} parts ({turned} turned) in a {side} × {side} mm square, {:.1} mm of rubberband \
         (a swapped grid of {:.0} × {:.0} mm: {:.1} mm), {:.2} s",
        out.len(),
        packed_len,
        grid_size[0],
        grid_size[1],
        grid_len,
        seconds
    );
    assert!(
        packed_len <= grid_len + 1e-9,
        "{name}: packed {packed_len} mm, grid {grid_len} mm"
    );
}

#[test]
fn lilypad_vibe_board_packs() {
    packs("LilyPad_Vibe_Board");
}

#[test]
fn lilypad_tri_color_led_packs() {
    packs("LilyPad_Tri-Color_LED");
}

#[test]
fn openlog_packs() {
    packs("OpenLog");
}

#[test]
fn redbot_packs() {
    packs("RedBot");
}
