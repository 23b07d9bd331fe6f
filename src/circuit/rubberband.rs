//! Rubberbands: the straight connections the route stage has to turn into traces.
//!
//! A net with explicit wires in the placement gets exactly those wires (waypoints resolved);
//! any other net gets a minimum spanning tree over its placed pads by 3D distance (Prim's
//! algorithm). Pins on parts the placement does not list are skipped and reported.

use super::placement::{Endpoint, Origin, Placement, PlacementError};
use super::{Circuit, PinRef, PlacedPart};
use crate::geom::Point3;

/// One connection to route, between two pad centres or waypoints in model coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Rubberband {
    /// Net name.
    pub net: String,
    /// Start point.
    pub from: Point3,
    /// End point.
    pub to: Point3,
    /// The pad at `from`, or `None` for a waypoint.
    pub from_pin: Option<PinRef>,
    /// The pad at `to`, or `None` for a waypoint.
    pub to_pin: Option<PinRef>,
}

/// The rubberbands of a circuit and the pins that could not take part.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Rubberbands {
    /// Nets by name; within a net, wires in file order or tree edges in the order Prim adds
    /// them.
    pub bands: Vec<Rubberband>,
    /// `(net, pin)` for every net pin on a part the placement does not list, once per net.
    pub unplaced: Vec<(String, PinRef)>,
}

/// The connections to route. `placed` is [`super::place`]'s output for the same placement.
///
/// The spanning tree starts at the net's first pin (pins sort by part, then pad) and adds the
/// pin nearest to the tree each step; among equal distances the lowest pin index is taken,
/// joined to the tree pin that reached that distance first. A net with fewer than two placed
/// pins gives no rubberband. A wire with an end on an unplaced part is left out.
///
/// # Errors
/// The problems of [`Placement::validate`]; [`PlacementError::NotResolved`] when a net with
/// waypoints is used with an [`Origin::BboxCenter`] placement (call
/// [`Placement::to_model`] first).
pub fn rubberbands(
    circuit: &Circuit,
    placement: &Placement,
    placed: &[PlacedPart],
) -> Result<Rubberbands, PlacementError> {
    placement.validate(circuit)?;
    let mut out = Rubberbands::default();
    for net in &circuit.nets {
        let mut unplaced = Vec::new();
        // A pin's resolved pad name and its centre, or None (and noted) when unplaced.
        let mut locate = |pin: &PinRef| -> Option<(PinRef, Point3)> {
            let pad = circuit.part(&pin.part)?.pad(&pin.pad)?;
            let pin = PinRef::new(&pin.part, &pad.name);
            let at = placed
                .iter()
                .find(|p| p.name == pin.part)
                .and_then(|p| p.pad(&pin.pad));
            match at {
                Some(p) => Some((pin, p.centre)),
                None => {
                    if !unplaced.contains(&pin) {
                        unplaced.push(pin);
                    }
                    None
                }
            }
        };
        let band =
            |(a, pa): (Option<PinRef>, Point3), (b, pb): (Option<PinRef>, Point3)| Rubberband {
                net: net.name.clone(),
                from: pa,
                to: pb,
                from_pin: a,
                to_pin: b,
            };
        match placement.net(&net.name).filter(|r| !r.wires.is_empty()) {
            Some(routing) => {
                if placement.origin != Origin::Model && !routing.waypoints.is_empty() {
                    return Err(PlacementError::NotResolved {
                        net: net.name.clone(),
                    });
                }
                let mut end = |e: &Endpoint| match e {
                    Endpoint::Pin(pin) => locate(pin).map(|(p, at)| (Some(p), at)),
                    Endpoint::Waypoint(name) => routing
                        .waypoints
                        .iter()
                        .find(|w| &w.name == name)
                        .map(|w| (None, Point3::new(w.x, w.y, w.z))),
                };
                for [a, b] in &routing.wires {
                    if let (Some(a), Some(b)) = (end(a), end(b)) {
                        out.bands.push(band(a, b));
                    }
                }
            }
            None => {
                let pins: Vec<(PinRef, Point3)> = net.pins.iter().filter_map(&mut locate).collect();
                let points: Vec<Point3> = pins.iter().map(|(_, p)| *p).collect();
                let groups = joined_groups(circuit, &pins);
                for (i, j) in prim(&points, &groups) {
                    let end = |k: usize| (Some(pins[k].0.clone()), pins[k].1);
                    out.bands.push(band(end(i), end(j)));
                }
            }
        }
        out.unplaced
            .extend(unplaced.into_iter().map(|p| (net.name.clone(), p)));
    }
    Ok(out)
}

/// Per located pin, the index of the first pin of its group: pads of one `route="any"` pin of a
/// part form a group (joined inside the part); every other pin is a group of its own.
fn joined_groups(circuit: &Circuit, pins: &[(PinRef, Point3)]) -> Vec<usize> {
    fn key<'a>(circuit: &'a Circuit, pin: &'a PinRef) -> Option<(&'a str, &'a str)> {
        circuit
            .part(&pin.part)
            .and_then(|part| part.joined_pin(&pin.pad))
            .map(|joined| (pin.part.as_str(), joined))
    }
    let key = |pin| key(circuit, pin);
    (0..pins.len())
        .map(|i| match key(&pins[i].0) {
            Some(k) => (0..i).find(|&j| key(&pins[j].0) == Some(k)).unwrap_or(i),
            None => i,
        })
        .collect()
}

/// Minimum spanning tree edges `(tree vertex, new vertex)` in the order they are added, where
/// the vertices sharing a `groups` value are already joined: when one of them is reached, all
/// of them are in the tree (no edge between them).
fn prim(points: &[Point3], groups: &[usize]) -> Vec<(usize, usize)> {
    let n = points.len();
    let mut edges = Vec::with_capacity(n.saturating_sub(1));
    if n < 2 {
        return edges;
    }
    let mut in_tree = vec![false; n];
    // Per vertex outside the tree: squared distance to the tree and the tree vertex at it.
    let mut best: Vec<(f64, usize)> = vec![(f64::INFINITY, 0); n];
    let join = |j: usize, in_tree: &mut Vec<bool>, best: &mut Vec<(f64, usize)>| {
        for m in (0..n).filter(|&m| groups[m] == groups[j]) {
            in_tree[m] = true;
            for k in 0..n {
                let d = (points[k] - points[m]).norm_squared();
                if !in_tree[k] && d < best[k].0 {
                    best[k] = (d, m);
                }
            }
        }
    };
    join(0, &mut in_tree, &mut best);
    while let Some(j) = (0..n)
        .filter(|&j| !in_tree[j])
        .min_by(|&a, &b| best[a].0.total_cmp(&best[b].0).then(a.cmp(&b)))
    {
        edges.push((best[j].1, j));
        join(j, &mut in_tree, &mut best);
    }
    edges
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use crate::circuit::placement::tests::sample_placement;
    use crate::circuit::tests::sample;
    use crate::circuit::three_de::tests::THREE_DE;
    use crate::circuit::{Net, Pad, PadShape, Part, place};

    fn bands(c: &Circuit, p: &Placement) -> Rubberbands {
        let placed = match place(c, p, &[]) {
            Ok(v) => v,
            Err(e) => panic!("{e}"),
        };
        match rubberbands(c, p, &placed) {
            Ok(r) => r,
            Err(e) => panic!("{e}"),
        }
    }

    type Edge = (String, String, String);

    fn edges(r: &Rubberbands) -> Vec<Edge> {
        let name = |p: &Option<PinRef>, at: &Point3| match p {
            Some(p) => p.to_string(),
            None => format!("({}, {}, {})", at.x, at.y, at.z),
        };
        r.bands
            .iter()
            .map(|b| {
                (
                    b.net.clone(),
                    name(&b.from_pin, &b.from),
                    name(&b.to_pin, &b.to),
                )
            })
            .collect()
    }

    fn e(net: &str, a: &str, b: &str) -> Edge {
        (net.into(), a.into(), b.into())
    }

    #[test]
    fn mst_on_collinear_pads_joins_neighbours() {
        // Pin order (A.1, A.2, B.1, B.2) differs from the order along x (A.1, B.1, B.2, A.2).
        let pad = |name: &str, x| Pad {
            name: name.into(),
            x,
            y: 0.0,
            rotation_deg: 0.0,
            shape: PadShape::Round { diameter: 0.5 },
            smd: true,
        };
        let part = |name: &str, pads| Part {
            name: name.into(),
            value: None,
            package: "P".into(),
            pads,
            pins: BTreeMap::new(),
            route_any: Default::default(),
        };
        let c = Circuit {
            parts: vec![
                part("A", vec![pad("1", 0.0), pad("2", 3.0)]),
                part("B", vec![pad("1", 0.0), pad("2", 1.0)]),
            ],
            nets: vec![Net {
                name: "N".into(),
                pins: ["A.1", "A.2", "B.1", "B.2"]
                    .map(|s| {
                        let (a, b) = s.split_once('.').unwrap_or_default();
                        PinRef::new(a, b)
                    })
                    .to_vec(),
            }],
        };
        let p = match Placement::from_toml(
            "[[part]]\nname = \"A\"\nx = 0.0\ny = 0.0\nz = 1.0\n\
             [[part]]\nname = \"B\"\nx = 1.0\ny = 0.0\nz = 1.0\n",
        ) {
            Ok(p) => p,
            Err(e) => panic!("{e}"),
        };
        let r = bands(&c, &p);
        assert_eq!(
            edges(&r),
            [
                e("N", "A.1", "B.1"),
                e("N", "B.1", "B.2"),
                e("N", "B.2", "A.2")
            ]
        );
        assert_eq!(r.bands[2].to, Point3::new(3.0, 0.0, 1.0));
        // A's pads 1 and 2 on one route="any" pin: no wire between them; B's pads join A at
        // whichever of its pads is nearer (ties to the earlier tree pin).
        let mut joined = c.clone();
        joined.parts[0].pins = BTreeMap::from([("G$1.GND".into(), vec!["1".into(), "2".into()])]);
        joined.parts[0].route_any = ["G$1.GND".to_owned()].into();
        assert_eq!(
            edges(&bands(&joined, &p)),
            [e("N", "A.1", "B.1"), e("N", "A.2", "B.2")]
        );
        // Equal distances (a unit square): lowest pin index first, from the earliest tree pin.
        let square =
            [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(x, y)| Point3::new(x, y, 0.0));
        let alone = [0, 1, 2, 3];
        assert_eq!(prim(&square, &alone), [(0, 1), (0, 2), (1, 3)]);
        assert!(prim(&square[..1], &alone[..1]).is_empty());
        // Joined vertices 0 and 3 (one route="any" pin): no edge between them, and the
        // others reach the group by its nearest member.
        assert_eq!(prim(&square, &[0, 1, 2, 0]), [(0, 1), (0, 2)]);
        assert!(prim(&square[..2], &[0, 0]).is_empty());
    }

    #[test]
    fn sample_gives_wires_with_waypoints_and_trees() {
        let r = bands(&sample(), &sample_placement());
        assert_eq!(
            edges(&r),
            [
                e("GND", "BAT1.-", "LED1.C"),
                e("N1", "LED1.A", "R1.2"),
                e("VCC", "BAT1.+", "(4, 3, 4)"),
                e("VCC", "(4, 3, 4)", "R1.1"),
            ]
        );
        assert_eq!(r.bands[0].from, Point3::new(15.0, 15.0, 4.0));
        assert_eq!(r.bands[0].to, Point3::new(32.0, 23.0, 4.0));
        assert!(r.unplaced.is_empty());
    }

    #[test]
    fn pins_of_unplaced_parts_are_skipped_and_reported() {
        let mut p = sample_placement();
        p.parts.retain(|q| q.name != "R1");
        let r = bands(&sample(), &p);
        // N1 and VCC lose R1: N1 has one placed pin left, VCC's second wire is dropped.
        assert_eq!(
            edges(&r),
            [
                e("GND", "BAT1.-", "LED1.C"),
                e("VCC", "BAT1.+", "(4, 3, 4)")
            ]
        );
        assert_eq!(
            r.unplaced,
            [
                ("N1".to_owned(), PinRef::new("R1", "2")),
                ("VCC".to_owned(), PinRef::new("R1", "1")),
            ]
        );
    }

    #[test]
    fn three_de_wires_name_pins_and_need_model_coordinates() {
        let p = match Placement::from_3de(THREE_DE) {
            Ok(p) => p,
            Err(e) => panic!("{e}"),
        };
        let bb = crate::geom::BoundingBox {
            min: [0.0, 0.0, 0.0],
            max: [40.0, 30.0, 8.0],
        };
        let c = sample();
        let placed = match place(&c, &p, &[bb]) {
            Ok(v) => v,
            Err(e) => panic!("{e}"),
        };
        let r = rubberbands(&c, &p, &placed);
        assert!(matches!(r, Err(PlacementError::NotResolved { ref net }) if net == "GND"));
        let m = match p.to_model(&[bb]) {
            Ok(m) => m,
            Err(e) => panic!("{e}"),
        };
        let r = match rubberbands(&c, &m, &placed) {
            Ok(r) => r,
            Err(e) => panic!("{e}"),
        };
        assert_eq!(
            edges(&r),
            [
                e("GND", "LED1.C", "(25, 5, 4.5)"),
                e("GND", "(25, 5, 4.5)", "BAT1.-")
            ]
        );
        // R1 is not placed in the .3de document.
        assert_eq!(
            r.unplaced,
            [
                ("N1".to_owned(), PinRef::new("R1", "2")),
                ("VCC".to_owned(), PinRef::new("R1", "1")),
            ]
        );
    }
}
