//! Placed parts: a circuit's pads moved to where the placement puts them, in model coordinates.
//! An input of the route stage (pad outlines to connect to, footprints to keep clear).
//!
//! A package point `(x, y)` lands at
//! `position + Rx(tilt[0]) · Ry(tilt[1]) · M · Rz(rotation) · (x, y, 0)`,
//! where `position` is the part's pose resolved to model coordinates and `M` negates x for
//! mirrored (EAGLE bottom-side) parts *after* rotating, as EAGLE's `MR` rotations do: KiCad's
//! EAGLE importer turns an `MR<a>` element to `a + 180°` and then flips it top to bottom, which
//! is the same map. (Mirroring first would equal `MR<−a>`: the same for `MR0` and `MR180`, a
//! quarter turn wrong for `MR90` and `MR270`.) Pads keep their own rotation within the
//! package, applied first.

use std::collections::BTreeMap;

use super::placement::{PartPlacement, PlacementError, PlacingMethod};
use super::{Circuit, PadShape};
use crate::geom::{BoundingBox, Point2, Point3, Polygon, Vector3};

/// Vertices of a full circle in pad outlines (round pads and oblong ends, which get half).
/// 32 keeps a 1 mm pad's outline within 2.5 µm of the circle.
pub const ARC_SEGMENTS: usize = 32;

/// A pad where it sits in the object.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedPad {
    /// Pad name.
    pub name: String,
    /// Centre of the pad in model coordinates, on the part's seating plane.
    pub centre: Point3,
    /// The copper outline projected on the xy plane, counter-clockwise, scaled integers.
    pub outline: Polygon,
    /// The net the pad belongs to; `None` for a pin no net uses.
    pub net: Option<String>,
}

/// A part where it sits in the object.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedPart {
    /// Part name.
    pub name: String,
    /// How the part is inserted.
    pub method: PlacingMethod,
    /// The package origin on the seating plane, model coordinates.
    pub position: Point3,
    /// Rotation about +z, degrees.
    pub rotation_deg: f64,
    /// Mirrored (EAGLE bottom side): package x negated before rotating.
    pub mirror: bool,
    /// Height above the seating plane, mm.
    pub body_height: f64,
    /// Scene object index.
    pub object: usize,
    /// All pads of the package, in package order.
    pub pads: Vec<PlacedPad>,
    /// Convex hull of the pad outlines and, when the placement gives `body_size`, the body
    /// rectangle; projected on the xy plane, counter-clockwise.
    pub footprint: Polygon,
}

impl PlacedPart {
    /// The pad named `name` (exact name; resolve schematic pin names with
    /// [`super::Part::pad`] first).
    pub fn pad(&self, name: &str) -> Option<&PlacedPad> {
        self.pads.iter().find(|p| p.name == name)
    }
}

/// Places every part of `placement` (see the module documentation for the transform).
/// `object_bboxes[i]` is the model-space bounding box of scene object `i`, needed for
/// [`super::Origin::BboxCenter`] placements and, when given, checked against each part's
/// `object`. Circuit parts the placement does not list are not placed.
///
/// # Errors
/// The problems of [`super::Placement::validate`], and [`PlacementError::NoSuchObject`].
pub fn place(
    circuit: &Circuit,
    placement: &super::Placement,
    object_bboxes: &[BoundingBox],
) -> Result<Vec<PlacedPart>, PlacementError> {
    placement.validate(circuit)?;
    let model = placement.to_model(object_bboxes)?;
    let nets: BTreeMap<(&str, &str), &str> = circuit
        .nets
        .iter()
        .flat_map(|n| {
            n.pins
                .iter()
                .map(move |p| ((p.part.as_str(), p.pad.as_str()), n.name.as_str()))
        })
        .collect();
    let mut out = Vec::with_capacity(model.parts.len());
    for p in &model.parts {
        if !object_bboxes.is_empty() && p.object >= object_bboxes.len() {
            return Err(PlacementError::NoSuchObject {
                item: format!("part \"{}\"", p.name),
                object: p.object,
                count: object_bboxes.len(),
            });
        }
        let Some(part) = circuit.part(&p.name) else {
            continue; // validate() reported it
        };
        let pose = Pose::new(p);
        let mut hull_points = Vec::new();
        let pads = part
            .pads
            .iter()
            .map(|pad| {
                let (c, s) = cos_sin(pad.rotation_deg);
                let pts: Vec<Point2> = shape_points(&pad.shape)
                    .into_iter()
                    .map(|(x, y)| pose.flat(pad.x + c * x - s * y, pad.y + s * x + c * y))
                    .collect();
                hull_points.extend_from_slice(&pts);
                PlacedPad {
                    name: pad.name.clone(),
                    centre: pose.map(pad.x, pad.y),
                    outline: ccw(Polygon::new(pts)),
                    net: nets
                        .get(&(part.name.as_str(), pad.name.as_str()))
                        .map(|n| (*n).to_owned()),
                }
            })
            .collect();
        if let Some([w, l]) = p.body_size {
            for (x, y) in rect(w, l) {
                hull_points.push(pose.flat(x, y));
            }
        }
        out.push(PlacedPart {
            name: p.name.clone(),
            method: p.method,
            position: Point3::new(p.x, p.y, p.z),
            rotation_deg: p.rotation,
            mirror: p.mirror,
            body_height: p.body_height,
            object: p.object,
            pads,
            footprint: Polygon::convex_hull(&hull_points),
        });
    }
    Ok(out)
}

/// Cosine and sine of an angle in degrees, exact at multiples of 90°.
fn cos_sin(deg: f64) -> (f64, f64) {
    let d = deg.rem_euclid(360.0);
    match d {
        0.0 => (1.0, 0.0),
        90.0 => (0.0, 1.0),
        180.0 => (-1.0, 0.0),
        270.0 => (0.0, -1.0),
        _ => {
            let (s, c) = d.to_radians().sin_cos();
            (c, s)
        }
    }
}

/// A part's rigid transform from the package frame to model coordinates.
struct Pose {
    origin: Point3,
    /// Columns: images of the package x and y axes.
    ex: Vector3,
    ey: Vector3,
}

impl Pose {
    fn new(p: &PartPlacement) -> Self {
        let (c, s) = cos_sin(p.rotation);
        let (cx, sx) = cos_sin(p.tilt[0]);
        let (cy, sy) = cos_sin(p.tilt[1]);
        // Rx · Ry applied to the columns of M · Rz: (±c, s, 0) and (∓s, c, 0).
        let tilt = |v: Vector3| {
            let v = Vector3::new(cy * v.x + sy * v.z, v.y, -sy * v.x + cy * v.z);
            Vector3::new(v.x, cx * v.y - sx * v.z, sx * v.y + cx * v.z)
        };
        let m = if p.mirror { -1.0 } else { 1.0 };
        Pose {
            origin: Point3::new(p.x, p.y, p.z),
            ex: tilt(Vector3::new(m * c, s, 0.0)),
            ey: tilt(Vector3::new(-m * s, c, 0.0)),
        }
    }

    fn map(&self, x: f64, y: f64) -> Point3 {
        self.origin + self.ex * x + self.ey * y
    }

    fn flat(&self, x: f64, y: f64) -> Point2 {
        let p = self.map(x, y);
        Point2::from_mm(p.x, p.y)
    }
}

/// Corners of a `w` × `h` rectangle centred on the origin, counter-clockwise.
fn rect(w: f64, h: f64) -> [(f64, f64); 4] {
    let (a, b) = (w / 2.0, h / 2.0);
    [(-a, -b), (a, -b), (a, b), (-a, b)]
}

/// Outline of a pad shape in the pad frame, counter-clockwise.
fn shape_points(shape: &PadShape) -> Vec<(f64, f64)> {
    let arc = |cx: f64, cy: f64, r: f64, from: usize, count: usize| {
        (from..from + count).map(move |k| {
            let (s, c) = (k as f64 * std::f64::consts::TAU / ARC_SEGMENTS as f64).sin_cos();
            (cx + r * c, cy + r * s)
        })
    };
    let half = ARC_SEGMENTS / 2;
    let quarter = ARC_SEGMENTS / 4;
    match *shape {
        PadShape::Round { diameter } => arc(0.0, 0.0, diameter / 2.0, 0, ARC_SEGMENTS).collect(),
        PadShape::Rect { width, height } => rect(width, height).to_vec(),
        PadShape::Oblong { width, height } if width >= height => {
            let (r, d) = (height / 2.0, (width - height) / 2.0);
            // Right end from -90° to 90°, left end from 90° to 270°.
            arc(d, 0.0, r, ARC_SEGMENTS - quarter, half + 1)
                .chain(arc(-d, 0.0, r, quarter, half + 1))
                .collect()
        }
        PadShape::Oblong { width, height } => {
            let (r, d) = (width / 2.0, (height - width) / 2.0);
            arc(0.0, d, r, 0, half + 1)
                .chain(arc(0.0, -d, r, half, half + 1))
                .collect()
        }
    }
}

/// `p` counter-clockwise (mirroring reverses the vertex order).
fn ccw(mut p: Polygon) -> Polygon {
    if p.signed_area2() < 0 {
        p.points.reverse();
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::circuit::placement::tests::{BOARD, sample_placement};
    use crate::circuit::tests::sample;
    use crate::circuit::three_de::tests::THREE_DE;
    use crate::circuit::{Placement, PlacementError};
    use crate::geom::scaled;

    fn placed(c: &Circuit, p: &Placement, bb: &[BoundingBox]) -> Vec<PlacedPart> {
        match place(c, p, bb) {
            Ok(v) => v,
            Err(e) => panic!("{e}"),
        }
    }

    fn bounds(p: &Polygon) -> [f64; 4] {
        let xs = p.points.iter().map(|q| q.x);
        let ys = p.points.iter().map(|q| q.y);
        let u = crate::geom::unscaled;
        [
            u(xs.clone().min().unwrap_or(0)),
            u(ys.clone().min().unwrap_or(0)),
            u(xs.max().unwrap_or(0)),
            u(ys.max().unwrap_or(0)),
        ]
    }

    fn centre(parts: &[PlacedPart], part: &str, pad: &str) -> Option<(f64, f64, f64)> {
        let p = parts.iter().find(|p| p.name == part)?.pad(pad)?.centre;
        Some((p.x, p.y, p.z))
    }

    #[test]
    fn rotated_part_pads_land_where_computed_by_hand() {
        let parts = placed(&sample(), &sample_placement(), &[]);
        assert_eq!(parts.len(), 3);
        // LED1 at (32, 22, 4) turned 90°: package (x, y) -> (32 - y, 22 + x).
        assert_eq!(centre(&parts, "LED1", "A"), Some((32.0, 21.0, 4.0)));
        assert_eq!(centre(&parts, "LED1", "C"), Some((32.0, 23.0, 4.0)));
        // R1 at (32, 8) unrotated: pads at x -/+ 0.95.
        assert_eq!(centre(&parts, "R1", "1"), Some((31.05, 8.0, 4.0)));
        // LED1.A is 1.0 x 1.2 along the package x; turned, it spans 1.2 in x and 1.0 in y.
        let led = parts.iter().find(|p| p.name == "LED1");
        let a = led.and_then(|p| p.pad("A")).map(|p| p.outline.clone());
        let Some(a) = a else { panic!() };
        assert!(a.is_counter_clockwise());
        assert_eq!(bounds(&a), [31.4, 20.5, 32.6, 21.5]);
        assert_eq!(
            a.signed_area2(),
            2 * scaled(1.2) as i128 * scaled(1.0) as i128
        );
        // Footprint of R1: the hull of both pads, 2.9 x 1.3.
        let r1 = parts
            .iter()
            .find(|p| p.name == "R1")
            .map(|p| p.footprint.clone());
        let Some(r1) = r1 else { panic!() };
        assert_eq!(r1.points.len(), 4);
        assert!(r1.is_counter_clockwise());
        assert_eq!(bounds(&r1), [30.55, 7.35, 33.45, 8.65]);
        // BAT1 footprint includes its 24 x 21 body.
        let bat = parts
            .iter()
            .find(|p| p.name == "BAT1")
            .map(|p| p.footprint.clone());
        assert_eq!(bat.map(|f| bounds(&f)), Some([2.75, 4.5, 27.0, 25.5]));
    }

    #[test]
    fn round_and_oblong_outlines_are_ccw_and_sized() {
        for (shape, w, h) in [
            (PadShape::Round { diameter: 2.0 }, 2.0, 2.0),
            (
                PadShape::Oblong {
                    width: 3.0,
                    height: 1.0,
                },
                3.0,
                1.0,
            ),
            (
                PadShape::Oblong {
                    width: 1.0,
                    height: 3.0,
                },
                1.0,
                3.0,
            ),
        ] {
            let pts: Vec<Point2> = shape_points(&shape)
                .into_iter()
                .map(|(x, y)| Point2::from_mm(x, y))
                .collect();
            let p = Polygon::new(pts);
            assert!(p.is_counter_clockwise(), "{shape:?}");
            assert_eq!(
                bounds(&p),
                [-w / 2.0, -h / 2.0, w / 2.0, h / 2.0],
                "{shape:?}"
            );
        }
    }

    #[test]
    fn mirrored_part_negates_x_after_rotating() {
        let b = match conduit_eagle::read_board(BOARD.as_bytes()) {
            Ok(b) => b,
            Err(e) => panic!("{e}"),
        };
        let c = Circuit::from_board(&b);
        let mut p = Placement::from_board(&b, 1.0, [0.0, 0.0]);
        let parts = placed(&c, &p, &[]);
        // R2 at (30, 20), MR0: pad 1 at package x = -1 lands at x = 31.
        assert_eq!(centre(&parts, "R2", "1"), Some((31.0, 20.0, 1.0)));
        assert_eq!(centre(&parts, "R2", "2"), Some((29.0, 20.0, 1.0)));
        // R1 at (10, 20), R90: pad 1 (-1, 0) -> (10, 19).
        assert_eq!(centre(&parts, "R1", "1"), Some((10.0, 19.0, 1.0)));
        // MR90: (-1, 0) -> turned (0, -1) -> mirrored (0, -1); MR270: -> (0, 1).
        p.parts[1].rotation = 90.0;
        let parts = placed(&c, &p, &[]);
        assert_eq!(centre(&parts, "R2", "1"), Some((30.0, 19.0, 1.0)));
        p.parts[1].rotation = 270.0;
        let parts = placed(&c, &p, &[]);
        assert_eq!(centre(&parts, "R2", "1"), Some((30.0, 21.0, 1.0)));
        assert!(
            parts
                .iter()
                .all(|q| q.pads.iter().all(|d| d.outline.is_counter_clockwise()))
        );
    }

    #[test]
    fn a_tilted_part_is_refused_by_name_and_whole_turns_are_upright() {
        let mut p = sample_placement();
        p.parts[1].tilt = [0.0, 90.0]; // R1 about y: its pads would leave the seating plane.
        let err = match place(&sample(), &p, &[]) {
            Ok(_) => panic!("a tilted part is placed"),
            Err(e) => e.to_string(),
        };
        assert!(
            err.contains("part \"R1\" is turned 0° about x and 90° about y"),
            "{err}"
        );
        p.parts[1].tilt = [360.0, -720.0];
        let parts = placed(&sample(), &p, &[]);
        let (x, y, z) = centre(&parts, "R1", "2").unwrap_or_default();
        assert!((x - 32.95).abs() < 1e-9 && (y - 8.0).abs() < 1e-9 && (z - 4.0).abs() < 1e-9);
    }

    #[test]
    fn bbox_centre_placement_resolves_against_the_object_box() {
        let p = match Placement::from_3de(THREE_DE) {
            Ok(p) => p,
            Err(e) => panic!("{e}"),
        };
        let bb = BoundingBox {
            min: [0.0, 0.0, 0.0],
            max: [40.0, 30.0, 8.0],
        };
        let parts = placed(&sample(), &p, &[bb]);
        // LED1 at (12, 7, 4) from the centre (20, 15) of the box's bottom.
        assert_eq!(centre(&parts, "LED1", "A"), Some((32.0, 21.0, 4.0)));
        assert_eq!(
            parts.iter().map(|q| q.method).collect::<Vec<_>>(),
            [PlacingMethod::Manual, PlacingMethod::Auto]
        );
        let e = place(&sample(), &p, &[]);
        assert!(matches!(
            e,
            Err(PlacementError::NoSuchObject { object: 0, .. })
        ));
        let mut q = sample_placement();
        q.parts[0].object = 3;
        let e = place(&sample(), &q, &[bb]).err().map(|e| e.to_string());
        assert_eq!(
            e.as_deref(),
            Some("part \"BAT1\": object 3 does not exist (the scene has 1)")
        );
    }

    #[test]
    fn sample_parts_sit_inside_the_block() {
        let path = crate::circuit::tests::sample_dir().join("block.stl");
        if !path.is_file() {
            println!("skipped: {} not found", path.display());
            return;
        }
        let scene = crate::scene::load_scene(&path, &Default::default());
        let bb = scene
            .ok()
            .and_then(|(s, _)| s.objects.first()?.mesh.bounding_box());
        let Some(bb) = bb else {
            panic!("{}: no mesh", path.display())
        };
        assert_eq!((bb.min, bb.max), ([0.0; 3], [40.0, 30.0, 8.0]));
        for p in placed(&sample(), &sample_placement(), &[bb]) {
            let [x0, y0, x1, y1] = bounds(&p.footprint);
            assert!(
                x0 >= 2.0 && y0 >= 2.0 && x1 <= 38.0 && y1 <= 28.0,
                "{}",
                p.name
            );
            assert!(p.position.z + p.body_height < bb.max[2], "{}", p.name);
        }
    }

    #[test]
    fn hull_drops_inner_and_collinear_points() {
        let pts = [(0, 0), (2, 0), (1, 0), (2, 2), (0, 2), (1, 1), (0, 1)]
            .map(|(x, y)| Point2::new(x, y))
            .to_vec();
        let h = Polygon::convex_hull(&pts);
        let want = [(0, 0), (2, 0), (2, 2), (0, 2)].map(|(x, y)| Point2::new(x, y));
        assert_eq!(h.points, want);
    }
}
