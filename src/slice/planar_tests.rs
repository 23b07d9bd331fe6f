//! Analytic tests of planar slicing.

use super::*;
use crate::geom::{Polygon, unscaled};

/// The 12 outward-facing triangles of the box `[x0,x1]×[y0,y1]×[z0,z1]`, as corner positions.
fn box_triangles(min: [f64; 3], max: [f64; 3]) -> Vec<[Point3; 3]> {
    let v = |i: usize| {
        Point3::new(
            if i & 1 == 0 { min[0] } else { max[0] },
            if i & 2 == 0 { min[1] } else { max[1] },
            if i & 4 == 0 { min[2] } else { max[2] },
        )
    };
    // Corners by bits (x, y, z); faces counter-clockwise seen from outside.
    let faces: [[usize; 4]; 6] = [
        [0, 2, 3, 1], // bottom (z = min), seen from below
        [4, 5, 7, 6], // top
        [0, 1, 5, 4], // y = min
        [2, 6, 7, 3], // y = max
        [0, 4, 6, 2], // x = min
        [1, 3, 7, 5], // x = max
    ];
    faces
        .iter()
        .flat_map(|f| [[v(f[0]), v(f[1]), v(f[2])], [v(f[0]), v(f[2]), v(f[3])]])
        .collect()
}

fn cube(s: f64) -> Mesh {
    Mesh::from_triangle_soup("cube", box_triangles([0.0; 3], [s; 3]))
}

fn total_area(islands: &[ExPolygon]) -> f64 {
    islands.iter().map(ExPolygon::area_mm2).sum()
}

/// No repeated consecutive points, at least three points, non-zero area: a clean ring.
fn assert_clean(p: &Polygon) {
    assert!(p.points.len() >= 3, "{p:?}");
    let n = p.points.len();
    for i in 0..n {
        assert_ne!(
            p.points[i],
            p.points[(i + 1) % n],
            "repeated point in {p:?}"
        );
    }
    assert_ne!(p.signed_area2(), 0);
}

#[test]
fn twenty_mm_cube_gives_one_hundred_exact_squares() {
    let (layers, report) = slice_mesh(&cube(20.0), &SliceParams::default());
    assert_eq!(layers.len(), 100);
    assert_eq!(
        report,
        SliceReport {
            layers: 100,
            open_chains_closed: 0,
            open_chains_dropped: 0,
            degenerate_segments: 0
        }
    );
    for (k, layer) in layers.iter().enumerate() {
        assert_eq!(layer.z.index, k);
        assert!((layer.z.top - 0.2 * (k + 1) as f64).abs() < 1e-9);
        assert_eq!(layer.islands.len(), 1);
        let island = &layer.islands[0];
        assert!(island.holes.is_empty());
        assert!((island.area_mm2() - 400.0).abs() < 1e-6);
        assert!(island.contour.is_counter_clockwise());
        let xs: Vec<f64> = island
            .contour
            .points
            .iter()
            .map(|p| unscaled(p.x))
            .collect();
        let ys: Vec<f64> = island
            .contour
            .points
            .iter()
            .map(|p| unscaled(p.y))
            .collect();
        let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(
            (min(&xs), max(&xs), min(&ys), max(&ys)),
            (0.0, 20.0, 0.0, 20.0)
        );
        assert_eq!(island.contour.points.len(), 4);
    }
}

#[test]
fn cube_with_square_through_hole_has_one_hole_per_layer() {
    // A 20 × 20 × 10 block with a 6 × 6 hole along z, built ring by ring.
    let outer = [(0.0, 0.0), (20.0, 0.0), (20.0, 20.0), (0.0, 20.0)];
    let inner = [(7.0, 7.0), (13.0, 7.0), (13.0, 13.0), (7.0, 13.0)];
    let (z0, z1) = (0.0, 10.0);
    let p = |(x, y): (f64, f64), z: f64| Point3::new(x, y, z);
    let mut tris = Vec::new();
    for i in 0..4 {
        let j = (i + 1) % 4;
        // Outer wall, normal outwards (right of the CCW ring).
        let (a, b) = (outer[i], outer[j]);
        tris.push([p(a, z0), p(b, z0), p(b, z1)]);
        tris.push([p(a, z0), p(b, z1), p(a, z1)]);
        // Hole wall, normal into the hole: walk the hole ring clockwise.
        let (a, b) = (inner[j], inner[i]);
        tris.push([p(a, z0), p(b, z0), p(b, z1)]);
        tris.push([p(a, z0), p(b, z1), p(a, z1)]);
        // Top and bottom caps: one trapezoid per side.
        let (o0, o1, i0, i1) = (outer[i], outer[j], inner[i], inner[j]);
        tris.push([p(o0, z1), p(o1, z1), p(i1, z1)]);
        tris.push([p(o0, z1), p(i1, z1), p(i0, z1)]);
        tris.push([p(o0, z0), p(i1, z0), p(o1, z0)]);
        tris.push([p(o0, z0), p(i0, z0), p(i1, z0)]);
    }
    let mesh = Mesh::from_triangle_soup("holed", tris);
    assert!((mesh.signed_volume() - (400.0 - 36.0) * 10.0).abs() < 1e-9);
    let (layers, report) = slice_mesh(&mesh, &SliceParams::default());
    assert_eq!(layers.len(), 50);
    assert_eq!(report.open_chains_closed + report.open_chains_dropped, 0);
    for layer in &layers {
        assert_eq!(layer.islands.len(), 1);
        let island = &layer.islands[0];
        assert_eq!(island.holes.len(), 1);
        assert!(!island.holes[0].is_counter_clockwise());
        assert!((island.holes[0].area_mm2().abs() - 36.0).abs() < 1e-6);
        assert!((island.area_mm2() - 364.0).abs() < 1e-6);
    }
}

/// A UV sphere of radius `r` resting on z = 0, outward-facing, with exact poles.
fn uv_sphere(r: f64, stacks: usize, sectors: usize) -> Mesh {
    use std::f64::consts::PI;
    let mut vertices = vec![Point3::new(0.0, 0.0, 2.0 * r)];
    for i in 1..stacks {
        let theta = PI * i as f64 / stacks as f64;
        for j in 0..sectors {
            let phi = 2.0 * PI * j as f64 / sectors as f64;
            vertices.push(Point3::new(
                r * theta.sin() * phi.cos(),
                r * theta.sin() * phi.sin(),
                r + r * theta.cos(),
            ));
        }
    }
    vertices.push(Point3::new(0.0, 0.0, 0.0));
    let bottom = (vertices.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * sectors + j % sectors) as u32;
    let mut triangles = Vec::new();
    for j in 0..sectors {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        for i in 1..stacks - 1 {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i + 1, j),
                ring(i + 1, j + 1),
                ring(i, j + 1),
            );
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
        triangles.push([ring(stacks - 1, j), bottom, ring(stacks - 1, j + 1)]);
    }
    Mesh {
        name: "sphere".into(),
        vertices,
        triangles,
    }
}

#[test]
fn sphere_layer_areas_follow_the_circle() {
    let r = 10.0;
    let mesh = uv_sphere(r, 64, 128);
    assert!(mesh.signed_volume() > 0.0);
    let (layers, report) = slice_mesh(&mesh, &SliceParams::default());
    assert_eq!(layers.len(), 100);
    assert_eq!(report.open_chains_closed + report.open_chains_dropped, 0);
    for layer in &layers {
        assert_eq!(layer.islands.len(), 1, "layer {}", layer.z.index);
        assert!(layer.islands[0].holes.is_empty());
        let dz = layer.z.slice_z - r;
        let exact = std::f64::consts::PI * (r * r - dz * dz);
        let area = layer.islands[0].area_mm2();
        // The tessellation lies inside the sphere; away from the poles it is within about
        // 2·r·(1 − cos(π/128)) ≈ 6 µm of it radially, i.e. well within 1 % in area.
        assert!(area <= exact, "layer {}: {area} > {exact}", layer.z.index);
        if dz.abs() < 0.9 * r {
            assert!(
                (exact - area) / exact < 0.01,
                "layer {}: {area} vs {exact}",
                layer.z.index
            );
        }
    }
}

#[test]
fn open_mesh_is_closed_across_the_missing_face() {
    // A 1 mm cube without its y = max face: each layer is an open U whose ends are 1 mm apart.
    let mut tris = box_triangles([0.0; 3], [1.0; 3]);
    tris.drain(6..8);
    let mesh = Mesh::from_triangle_soup("open", tris);
    let (layers, report) = slice_mesh(&mesh, &SliceParams::default());
    assert_eq!(layers.len(), 5);
    assert_eq!(report.open_chains_closed, 5);
    assert_eq!(report.open_chains_dropped, 0);
    for layer in &layers {
        assert_eq!(layer.islands.len(), 1);
        assert!((layer.islands[0].area_mm2() - 1.0).abs() < 1e-9);
    }
    // The same hole on a 20 mm cube is wider than the 2 mm gap: the contours are dropped.
    let mut tris = box_triangles([0.0; 3], [20.0; 3]);
    tris.drain(6..8);
    let mesh = Mesh::from_triangle_soup("open", tris);
    let (layers, report) = slice_mesh(&mesh, &SliceParams::default());
    assert_eq!(report.open_chains_dropped, 100);
    assert!(layers.iter().all(|l| l.islands.is_empty()));
    // ...unless the caller allows a wider gap.
    let (layers, report) = slice_mesh_with_gap(&mesh, &SliceParams::default(), 25.0);
    assert_eq!(
        (report.open_chains_closed, report.open_chains_dropped),
        (100, 0)
    );
    assert!(
        layers
            .iter()
            .all(|l| (total_area(&l.islands) - 400.0).abs() < 1e-6)
    );
}

#[test]
fn two_disjoint_cubes_give_two_islands_in_canonical_order() {
    let mut tris = box_triangles([30.0, 0.0, 0.0], [40.0, 10.0, 10.0]);
    tris.extend(box_triangles([0.0; 3], [10.0; 3]));
    let mesh = Mesh::from_triangle_soup("two", tris);
    let (layers, _) = slice_mesh(&mesh, &SliceParams::default());
    assert_eq!(layers.len(), 50);
    for layer in &layers {
        assert_eq!(layer.islands.len(), 2);
        assert_eq!(
            layer.islands[0].contour.points[0],
            Point2::from_mm(0.0, 0.0)
        );
        assert_eq!(
            layer.islands[1].contour.points[0],
            Point2::from_mm(30.0, 0.0)
        );
        assert!((total_area(&layer.islands) - 200.0).abs() < 1e-6);
    }
}

#[test]
fn overlapping_shells_are_united() {
    let mut tris = box_triangles([0.0; 3], [10.0; 3]);
    tris.extend(box_triangles([5.0, 5.0, 0.0], [15.0, 15.0, 10.0]));
    let (layers, _) = slice_mesh(
        &Mesh::from_triangle_soup("two", tris),
        &SliceParams::default(),
    );
    for layer in &layers {
        assert_eq!(layer.islands.len(), 1);
        assert!((layer.islands[0].area_mm2() - 175.0).abs() < 1e-6);
    }
}

#[test]
fn inside_out_mesh_is_sliced_as_solid() {
    let mut mesh = cube(10.0);
    for t in &mut mesh.triangles {
        t.swap(1, 2);
    }
    let (layers, _) = slice_mesh(&mesh, &SliceParams::default());
    assert_eq!(layers.len(), 50);
    assert!(
        layers
            .iter()
            .all(|l| (total_area(&l.islands) - 100.0).abs() < 1e-6)
    );
}

#[test]
fn tilted_mesh_with_vertices_on_slice_planes_gives_clean_output() {
    // A sheared prism of three square rings; the middle ring lies exactly on a slicing plane and
    // the top on a layer top. Every cross-section is a translated 10 × 10 square.
    let params = SliceParams::default();
    let planes = layer_schedule(10.0, &params);
    let z_mid = planes[20].slice_z;
    let rings = [(0.0, 0.0, 0.0), (3.0, 2.0, z_mid), (5.0, 0.0, 6.0)];
    let square = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)];
    let p = |r: (f64, f64, f64), s: (f64, f64)| Point3::new(r.0 + s.0, r.1 + s.1, r.2);
    let mut tris = Vec::new();
    for w in rings.windows(2) {
        for i in 0..4 {
            let (a, b) = (square[i], square[(i + 1) % 4]);
            tris.push([p(w[0], a), p(w[0], b), p(w[1], b)]);
            tris.push([p(w[0], a), p(w[1], b), p(w[1], a)]);
        }
    }
    let (bot, top) = (rings[0], rings[2]);
    tris.push([p(bot, square[0]), p(bot, square[2]), p(bot, square[1])]);
    tris.push([p(bot, square[0]), p(bot, square[3]), p(bot, square[2])]);
    tris.push([p(top, square[0]), p(top, square[1]), p(top, square[2])]);
    tris.push([p(top, square[0]), p(top, square[2]), p(top, square[3])]);
    let mesh = Mesh::from_triangle_soup("tilted", tris);
    let (layers, report) = slice_mesh(&mesh, &params);
    assert_eq!(layers.len(), 30);
    assert_eq!(
        report,
        SliceReport {
            layers: 30,
            open_chains_closed: 0,
            open_chains_dropped: 0,
            degenerate_segments: 0
        }
    );
    for layer in &layers {
        assert_eq!(layer.islands.len(), 1, "layer {}", layer.z.index);
        let island = &layer.islands[0];
        assert_clean(&island.contour);
        assert_eq!(island.contour.points.len(), 4, "layer {}", layer.z.index);
        assert!(
            (island.area_mm2() - 100.0).abs() < 1e-6,
            "layer {}",
            layer.z.index
        );
    }
    // The layer cut through the middle ring is that ring exactly.
    assert_eq!(
        layers[20].islands[0].contour.points[0],
        Point2::from_mm(3.0, 2.0)
    );
}

#[test]
fn apex_touching_a_plane_adds_nothing() {
    // A pyramid standing on its apex at a slicing plane, base above: the apex plane cuts
    // nothing, the next planes cut growing squares.
    let params = SliceParams::default();
    let z_apex = layer_schedule(10.0, &params)[5].slice_z;
    let apex = Point3::new(0.0, 0.0, z_apex);
    let h = 4.0;
    let base = [(-2.0, -2.0), (2.0, -2.0), (2.0, 2.0), (-2.0, 2.0)]
        .map(|(x, y)| Point3::new(x, y, z_apex + h));
    let mut tris = Vec::new();
    for i in 0..4 {
        let (a, b) = (base[i], base[(i + 1) % 4]);
        tris.push([apex, b, a]);
    }
    tris.push([base[0], base[1], base[2]]);
    tris.push([base[0], base[2], base[3]]);
    let mesh = Mesh::from_triangle_soup("pyramid", tris);
    assert!(mesh.signed_volume() > 0.0);
    let (layers, report) = slice_mesh(&mesh, &params);
    assert_eq!(report.degenerate_segments, 0);
    assert_eq!(report.open_chains_closed + report.open_chains_dropped, 0);
    assert!(layers[..=5].iter().all(|l| l.islands.is_empty()));
    for layer in &layers[6..] {
        assert_eq!(layer.islands.len(), 1);
        assert_clean(&layer.islands[0].contour);
        let side = 4.0 * (layer.z.slice_z - z_apex) / h;
        assert!((layer.islands[0].area_mm2() - side * side).abs() < 1e-5);
    }
}

#[test]
fn slicing_is_deterministic() {
    let mesh = uv_sphere(5.0, 16, 24);
    let a = slice_mesh(&mesh, &SliceParams::default());
    let b = slice_mesh(&mesh, &SliceParams::default());
    assert_eq!(a, b);
}

#[test]
fn empty_mesh_and_invalid_params_give_no_layers() {
    let (layers, report) = slice_mesh(&Mesh::default(), &SliceParams::default());
    assert!(layers.is_empty());
    assert_eq!(report, SliceReport::default());
    let bad = SliceParams {
        layer_height: -0.2,
        first_layer_height: 0.2,
    };
    assert!(slice_mesh(&cube(1.0), &bad).0.is_empty());
}

/// Reads `name` from the shared corpus and places it on the bed, or `None` when the corpus is
/// not there.
fn corpus_mesh(name: &str) -> Option<Mesh> {
    let path = format!(
        "{}/../shared/corpus/bench-models/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    let Ok(bytes) = std::fs::read(&path) else {
        println!("skipped: corpus not found ({path})");
        return None;
    };
    let stl = match conduit_stl::read(&bytes) {
        Ok(stl) => stl,
        Err(e) => panic!("{name} does not read: {e}"),
    };
    let soup = stl
        .triangles
        .iter()
        .map(|t| t.map(|v| Point3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]))));
    let mut mesh = Mesh::from_triangle_soup(name, soup);
    let min_z = mesh.bounding_box()?.min[2];
    for v in &mut mesh.vertices {
        v.z -= min_z;
    }
    Some(mesh)
}

/// Slices `3DBenchy.stl` (48 mm tall: 240 layers at 0.2 mm) when the corpus is present.
#[test]
fn benchy_slices_without_dropped_chains() {
    let Some(mesh) = corpus_mesh("3DBenchy.stl") else {
        return;
    };
    let height = mesh.bounding_box().map_or(0.0, |bb| bb.max[2]);
    assert!((height - 48.0).abs() < 0.01, "Benchy is {height} mm tall");
    let start = std::time::Instant::now();
    let (layers, report) = slice_mesh(&mesh, &SliceParams::default());
    let elapsed = start.elapsed();
    println!(
        "3DBenchy: {} triangles, {} layers in {:.1} ms, report {report:?}",
        mesh.triangles.len(),
        layers.len(),
        elapsed.as_secs_f64() * 1e3
    );
    assert_eq!(layers.len(), 240);
    assert_eq!(report.open_chains_dropped, 0);
    assert!(layers.iter().all(|l| !l.islands.is_empty()));
    assert_volume_matches(&mesh, &layers, 0.01);
}

/// Layer areas × heights add up to the mesh volume within `rel` (midpoint rule).
fn assert_volume_matches(mesh: &Mesh, layers: &[SlicedLayer], rel: f64) {
    let sliced: f64 = layers
        .iter()
        .map(|l| total_area(&l.islands) * l.z.height())
        .sum();
    let volume = mesh.signed_volume();
    println!(
        "{}: sliced volume {sliced:.1} mm³, mesh volume {volume:.1} mm³",
        mesh.name
    );
    assert!(
        (sliced - volume).abs() < rel * volume,
        "{}: {sliced} vs {volume}",
        mesh.name
    );
}

/// The other corpus models slice into non-empty layers without dropped chains.
#[test]
fn corpus_models_slice_without_dropped_chains() {
    for name in [
        "20mm_cube.stl",
        "voron2_a_drive_frame_lower.stl",
        "voron2_exhaust_filter_housing.stl",
    ] {
        let Some(mesh) = corpus_mesh(name) else {
            return;
        };
        let (layers, report) = slice_mesh(&mesh, &SliceParams::default());
        let height = mesh.bounding_box().map_or(0.0, |bb| bb.max[2]);
        println!("{name}: {height} mm, {} layers, {report:?}", layers.len());
        assert_eq!(report.open_chains_dropped, 0, "{name}");
        assert!(layers.iter().all(|l| !l.islands.is_empty()), "{name}");
        assert_volume_matches(&mesh, &layers, 0.01);
    }
}
