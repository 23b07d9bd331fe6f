//! Router benchmark: `cargo run --release --example route_bench [small|board] [ordered|negotiated]`
//! (or `bench/route.sh`).
//!
//! Routes a synthetic circuit with [`conduit::route::route`] and [`RouteParams::default`]: a
//! solid block 10 mm tall (50 layers of 0.2 mm, each layer's island the block's square) and
//! wires, one net each — `small`: 20 wires in a 40 mm block, 5 runs; `board`: 100 wires in a
//! 60 mm block, the size of a real board's circuit, 1 run — between pad pairs drawn from a fixed-seed generator. Pads lie at
//! least [`EDGE_MM`] inside the block, on layer tops between 1 and 9 mm; the two pads of a wire
//! are at most [`MAX_LAYER_STEP`] layers apart (so some wires change layer) and pads of different
//! nets on nearby layers keep [`PAD_SPACING_MM`] apart. The same input is routed the case's
//! `runs` times; the program prints the median wall time, the routed count and the total length
//! against the sum of the straight-line lower bounds, and fails (exit 1) if the runs disagree.

use std::time::{Duration, Instant};

use conduit::geom::{ExPolygon, Point2, Point3, Polygon};
use conduit::route::{PadCopper, RouteLayer, RouteParams, RouteResult, Strategy, Wire, route};

/// One benchmark case.
#[derive(Clone, Copy)]
struct Case {
    /// Side of the square block, mm.
    side: f64,
    /// Number of wires (= nets).
    wires: usize,
    /// Timed runs; the median is reported.
    runs: usize,
}

/// The cases by name.
fn case(name: &str) -> Option<Case> {
    match name {
        "small" => Some(Case {
            side: 40.0,
            wires: 20,
            runs: 5,
        }),
        "board" => Some(Case {
            side: 60.0,
            wires: 100,
            runs: 1,
        }),
        _ => None,
    }
}
/// Layer height, mm.
const LAYER_MM: f64 = 0.2;
/// Number of layers (10 mm).
const LAYERS: usize = 50;
/// Distance of every pad from the block's sides, mm.
const EDGE_MM: f64 = 4.0;
/// Smallest xy distance between pads of different nets within [`NEAR_LAYERS`] layers, mm.
const PAD_SPACING_MM: f64 = 3.0;
/// Layers within which pads count as near each other.
const NEAR_LAYERS: i64 = 2;
/// Largest layer difference between the two pads of a wire.
const MAX_LAYER_STEP: i64 = 5;
/// Generator seed.
const SEED: u64 = 0x00c0_ffee_d00d_2024;

/// SplitMix64: a small deterministic generator, so every run routes the same wires.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `lo..hi`.
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform integer in `lo..=hi`.
    fn int(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next() % (hi - lo + 1) as u64) as i64
    }
}

/// The 50 layers of the block.
fn layers(c: Case) -> Vec<RouteLayer> {
    let square = Polygon::new(vec![
        Point2::from_mm(0.0, 0.0),
        Point2::from_mm(c.side, 0.0),
        Point2::from_mm(c.side, c.side),
        Point2::from_mm(0.0, c.side),
    ]);
    let island = ExPolygon {
        contour: square,
        holes: Vec::new(),
    };
    (0..LAYERS)
        .map(|i| RouteLayer {
            z: LAYER_MM * (i + 1) as f64,
            height: LAYER_MM,
            islands: vec![island.clone()],
        })
        .collect()
}

/// The wires: pad pairs from the generator (see the module documentation).
fn wires(c: Case) -> Vec<Wire> {
    let mut rng = Rng(SEED);
    // (layer, x, y) of every pad so far.
    let mut pads: Vec<(i64, f64, f64)> = Vec::new();
    let lowest = (1.0 / LAYER_MM) as i64; // 1 mm
    let highest = LAYERS as i64 - lowest; // 9 mm
    let pad = |rng: &mut Rng, pads: &[(i64, f64, f64)], layer: i64| loop {
        let (x, y) = (
            rng.range(EDGE_MM, c.side - EDGE_MM),
            rng.range(EDGE_MM, c.side - EDGE_MM),
        );
        let clear = pads.iter().all(|&(l, px, py)| {
            (l - layer).abs() > NEAR_LAYERS || (px - x).hypot(py - y) >= PAD_SPACING_MM
        });
        if clear {
            return (layer, x, y);
        }
    };
    let at = |(layer, x, y): (i64, f64, f64)| Point3::new(x, y, LAYER_MM * layer as f64);
    (0..c.wires)
        .map(|k| {
            let a_layer = rng.int(lowest, highest);
            let b_layer =
                (a_layer + rng.int(-MAX_LAYER_STEP, MAX_LAYER_STEP)).clamp(lowest, highest);
            let a = pad(&mut rng, &pads, a_layer);
            pads.push(a);
            let b = pad(&mut rng, &pads, b_layer);
            pads.push(b);
            Wire {
                net: format!("N{:02}", k + 1),
                from: at(a),
                to: at(b),
            }
        })
        .collect()
}

/// Routed count, total length and total lower bound of the routed wires, layer changes.
fn totals(r: &RouteResult) -> (usize, f64, f64, usize) {
    let routed = r.wires.iter().filter(|w| w.routed);
    routed.fold((0, 0.0, 0.0, 0), |(n, l, b, c), w| {
        (n + 1, l + w.length, b + w.lower_bound, c + w.layer_changes)
    })
}

fn main() {
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "small".to_owned());
    let Some(c) = case(&name) else {
        eprintln!("route_bench: unknown case {name:?}; use small or board");
        std::process::exit(2);
    };
    let layers = layers(c);
    let wires = wires(c);
    let strategy = match std::env::args().nth(2).as_deref() {
        None | Some("ordered") => Strategy::Ordered,
        Some("negotiated") => Strategy::Negotiated,
        Some(other) => {
            eprintln!("route_bench: unknown strategy {other:?}; use ordered or negotiated");
            std::process::exit(2);
        }
    };
    let params = RouteParams {
        strategy,
        ..RouteParams::default()
    };
    // A round pad of twice the trace width on each end of every wire.
    let pads: Vec<PadCopper> = wires
        .iter()
        .flat_map(|w| [w.from, w.to].map(|p| PadCopper::round(Some(&w.net), p, 1.2)))
        .collect();
    let mut times: Vec<Duration> = Vec::with_capacity(c.runs);
    let mut first: Option<RouteResult> = None;
    for run in 0..c.runs {
        let started = Instant::now();
        let result = route(&layers, &wires, &pads, &params);
        times.push(started.elapsed());
        match &first {
            None => first = Some(result),
            Some(f) if *f != result => {
                eprintln!("route_bench: run {} routed differently from run 1", run + 1);
                std::process::exit(1);
            }
            Some(_) => {}
        }
    }
    let Some(result) = first else {
        eprintln!("route_bench: no runs");
        std::process::exit(1);
    };
    times.sort();
    let median = times[c.runs / 2];
    let (routed, length, bound, changes) = totals(&result);
    println!(
        "route_bench {name}: {} wires in a {:.0} × {:.0} × {:.0} mm block ({LAYERS} layers)",
        wires.len(),
        c.side,
        c.side,
        LAYERS as f64 * LAYER_MM
    );
    let ms = |d: &Duration| format!("{:.1}", d.as_secs_f64() * 1e3);
    println!(
        "time: median {} ms of {} runs (min {} ms, max {} ms)",
        ms(&median),
        c.runs,
        ms(&times[0]),
        ms(&times[c.runs - 1])
    );
    println!(
        "routed: {routed} of {} wires, {changes} layer changes",
        wires.len()
    );
    println!(
        "length: {length:.1} mm of trace for {bound:.1} mm straight ({:.3}×)",
        if bound > 0.0 {
            length / bound
        } else {
            f64::NAN
        }
    );
    for (w, r) in wires.iter().zip(&result.wires) {
        if !r.routed {
            println!(
                "unrouted: {} from ({:.2}, {:.2}, {:.1}) to ({:.2}, {:.2}, {:.1})",
                w.net, w.from.x, w.from.y, w.from.z, w.to.x, w.to.y, w.to.z
            );
        }
    }
}
