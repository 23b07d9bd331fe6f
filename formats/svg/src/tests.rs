//! Analytic tests of the reader: units, transforms, shapes, path commands, errors.

use super::*;

const TOL: f64 = 0.01;

fn svg(body: &str) -> String {
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">{body}</svg>"#
    )
}

fn read_ok(doc: &str) -> Design {
    read(doc.as_bytes(), TOL).unwrap_or_else(|e| panic!("{e}"))
}

fn close(a: [f64; 2], b: [f64; 2]) -> bool {
    (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9
}

fn assert_points(got: &[[f64; 2]], want: &[[f64; 2]]) {
    assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(close(*g, *w), "{got:?} vs {want:?}");
    }
}

/// Shoelace area (positive for counter-clockwise).
fn area(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

#[test]
fn circle_radius_and_area() {
    // 100 mm page, 100 user units: 1 user unit = 1 mm. Centre (50,50) is (50,50) mm y-up too.
    let d = read_ok(&svg(r#"<circle id="c" cx="50" cy="50" r="10"/>"#));
    assert_eq!(d.paths.len(), 1);
    let c = &d.paths[0];
    assert!(c.closed);
    assert_eq!(c.id.as_deref(), Some("c"));
    for p in &c.points {
        let r = (p[0] - 50.0).hypot(p[1] - 50.0);
        assert!((r - 10.0).abs() <= TOL, "radius {r}");
    }
    // Chord midpoints are within tolerance too.
    let n = c.points.len();
    for i in 0..n {
        let (a, b) = (c.points[i], c.points[(i + 1) % n]);
        let m = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        let r = (m[0] - 50.0).hypot(m[1] - 50.0);
        assert!(
            (r - 10.0).abs() <= TOL * 1.000001,
            "chord midpoint radius {r}"
        );
    }
    let exact = std::f64::consts::PI * 100.0;
    let rel = (area(&c.points).abs() - exact).abs() / exact;
    assert!(rel < 0.001, "area error {rel}");
}

#[test]
fn circle_in_scaled_units_keeps_tolerance_in_mm() {
    // 1 user unit = 0.1 mm: r = 100 units = 10 mm.
    let doc = r#"<svg width="100mm" height="100mm" viewBox="0 0 1000 1000"><circle cx="500" cy="500" r="100"/></svg>"#;
    let d = read_ok(doc);
    for p in &d.paths[0].points {
        let r = (p[0] - 50.0).hypot(p[1] - 50.0);
        assert!((r - 10.0).abs() <= TOL);
    }
    // Twice the tolerance, fewer points; ten times finer, more.
    let coarse = read(doc.as_bytes(), 0.1).expect("reads").paths[0]
        .points
        .len();
    let fine = read(doc.as_bytes(), 0.001).expect("reads").paths[0]
        .points
        .len();
    assert!(coarse < d.paths[0].points.len() && d.paths[0].points.len() < fine);
}

#[test]
fn units_and_viewbox() {
    let d = read_ok(
        r#"<svg width="100mm" height="100mm" viewBox="0 0 1000 1000"><line x1="0" y1="0" x2="1000" y2="500"/></svg>"#,
    );
    assert_eq!((d.width_mm, d.height_mm), (Some(100.0), Some(100.0)));
    assert_points(&d.paths[0].points, &[[0.0, 100.0], [100.0, 50.0]]);
    assert!(!d.paths[0].closed);

    // No viewBox: 1 user unit = 1 px = 25.4/96 mm; flip within the height.
    let d =
        read_ok(r#"<svg width="96px" height="2in"><line x1="0" y1="0" x2="96" y2="96"/></svg>"#);
    assert_eq!((d.width_mm, d.height_mm), (Some(25.4), Some(50.8)));
    assert_points(&d.paths[0].points, &[[0.0, 50.8], [25.4, 25.4]]);

    // Other units for width/height.
    for (w, mm) in [("10cm", 100.0), ("72pt", 25.4), ("6pc", 25.4), ("96", 25.4)] {
        let d = read_ok(&format!(r#"<svg width="{w}" height="10mm"></svg>"#));
        assert!((d.width_mm.expect("width") - mm).abs() < 1e-12, "{w}");
    }

    // viewBox only: px.
    let d = read_ok(r#"<svg viewBox="0 0 96 48"><line x1="0" y1="48" x2="96" y2="0"/></svg>"#);
    assert_eq!((d.width_mm, d.height_mm), (Some(25.4), Some(12.7)));
    assert_points(&d.paths[0].points, &[[0.0, 0.0], [25.4, 12.7]]);

    // Offset viewBox, width only (height from the aspect ratio).
    let d = read_ok(
        r#"<svg width="50mm" viewBox="-10 -10 20 10"><line x1="-10" y1="0" x2="10" y2="-10"/></svg>"#,
    );
    assert_eq!((d.width_mm, d.height_mm), (Some(50.0), Some(25.0)));
    assert_points(&d.paths[0].points, &[[0.0, 0.0], [50.0, 25.0]]);

    // preserveAspectRatio meet (default) centres a square viewBox in a wide page.
    let d = read_ok(
        r#"<svg width="200mm" height="100mm" viewBox="0 0 10 10"><line x1="0" y1="0" x2="10" y2="10"/></svg>"#,
    );
    assert_points(&d.paths[0].points, &[[50.0, 100.0], [150.0, 0.0]]);
    let d = read_ok(
        r#"<svg width="200mm" height="100mm" viewBox="0 0 10 10" preserveAspectRatio="none"><line x1="0" y1="0" x2="10" y2="10"/></svg>"#,
    );
    assert_points(&d.paths[0].points, &[[0.0, 100.0], [200.0, 0.0]]);

    // Lengths with units on shapes, in a px document.
    let d = read_ok(
        r#"<svg width="100mm" height="100mm" viewBox="0 0 100 100"><line x1="0" y1="0" x2="1in" y2="0"/></svg>"#,
    );
    assert_points(&d.paths[0].points, &[[0.0, 100.0], [96.0, 100.0]]);
}

#[test]
fn rect_with_translate_rotate() {
    // translate(5,5) rotate(90): (x, y) -> (5 - y, 5 + x) in SVG user units (y down); then
    // y up in a 100 mm page: y_mm = 100 - y.
    let d = read_ok(&svg(
        r#"<rect transform="translate(5,5) rotate(90)" x="0" y="0" width="10" height="4"/>"#,
    ));
    let p = &d.paths[0];
    assert!(p.closed);
    let svg_corners = [[0.0, 0.0], [10.0, 0.0], [10.0, 4.0], [0.0, 4.0]];
    let want: Vec<[f64; 2]> = svg_corners
        .iter()
        .map(|[x, y]| [5.0 - y, 100.0 - (5.0 + x)])
        .collect();
    assert_points(&p.points, &want);
    assert_eq!(
        want,
        vec![[5.0, 95.0], [5.0, 85.0], [1.0, 85.0], [1.0, 95.0]]
    );
}

#[test]
fn nested_transforms_compose() {
    let d = read_ok(&svg(
        r#"<g transform="translate(10 20)"><g transform="scale(2)"><line x1="1" y1="1" x2="2" y2="1" transform="matrix(1 0 0 1 3 4)"/></g></g>"#,
    ));
    // (1,1) -> +(3,4) = (4,5) -> *2 = (8,10) -> +(10,20) = (18,30) -> y up: (18,70).
    assert_points(&d.paths[0].points, &[[18.0, 70.0], [20.0, 70.0]]);
    // rotate about a centre, skewX.
    let d = read_ok(&svg(
        r#"<line x1="20" y1="10" x2="10" y2="20" transform="rotate(90 10 10)"/>"#,
    ));
    assert_points(&d.paths[0].points, &[[10.0, 80.0], [0.0, 90.0]]);
    let d = read_ok(&svg(
        r#"<line x1="0" y1="10" x2="0" y2="0" transform="skewX(45)"/>"#,
    ));
    assert_points(&d.paths[0].points, &[[10.0, 90.0], [0.0, 100.0]]);
    let d = read_ok(&svg(
        r#"<line x1="10" y1="0" x2="0" y2="0" transform="skewY(45)"/>"#,
    ));
    assert_points(&d.paths[0].points, &[[10.0, 90.0], [0.0, 100.0]]);
}

#[test]
fn rounded_rect() {
    let d = read_ok(&svg(
        r#"<rect x="10" y="10" width="40" height="20" rx="5"/>"#,
    ));
    let p = &d.paths[0];
    assert!(p.closed);
    // All points lie on the straight sides or within tolerance of the corner circles.
    let (x0, x1, y0, y1) = (10.0, 50.0, 70.0, 90.0); // y up
    for q in &p.points {
        assert!(q[0] >= x0 - 1e-9 && q[0] <= x1 + 1e-9 && q[1] >= y0 - 1e-9 && q[1] <= y1 + 1e-9);
        let cx = q[0].clamp(x0 + 5.0, x1 - 5.0);
        let cy = q[1].clamp(y0 + 5.0, y1 - 5.0);
        let r = (q[0] - cx).hypot(q[1] - cy);
        if r > 1e-9 {
            assert!((r - 5.0).abs() <= TOL, "{q:?} r={r}");
        }
    }
    let exact = 40.0 * 20.0 - (4.0 - std::f64::consts::PI) * 25.0;
    assert!((area(&p.points).abs() - exact).abs() / exact < 0.001);
    // rx larger than half the width is clamped; ry defaults to rx.
    let d = read_ok(&svg(r#"<rect width="10" height="10" rx="50"/>"#));
    let a = area(&d.paths[0].points).abs();
    assert!((a - std::f64::consts::PI * 25.0).abs() / a < 0.01, "{a}");
}

#[test]
fn arc_endpoints_and_midpoint() {
    // Half circle of radius 10 from (40,50) to (60,50), centre (50,50), through (50,40) in SVG
    // (sweep=1 is clockwise on screen, y down): y up that is (50,60).
    let d = read_ok(&svg(r#"<path d="M40 50 A10 10 0 0 1 60 50"/>"#));
    let p = &d.paths[0].points;
    assert_eq!(p[0], [40.0, 50.0]);
    assert_eq!(*p.last().expect("points"), [60.0, 50.0]);
    for q in p {
        let r = (q[0] - 50.0).hypot(q[1] - 50.0);
        assert!(
            (r - 10.0).abs() < 1e-9,
            "vertices of an open arc lie on it: {r}"
        );
        assert!(q[1] >= 50.0 - 1e-9, "upper half in y-up coordinates: {q:?}");
    }
    // The point nearest the arc's middle is on the circle at (50,60) within tolerance.
    let mid = p
        .iter()
        .min_by(|a, b| (a[0] - 50.0).abs().total_cmp(&(b[0] - 50.0).abs()))
        .expect("points");
    assert!((mid[1] - 60.0).abs() <= TOL, "{mid:?}");
    // sweep=0 goes the other way; relative form and large-arc flag.
    let d = read_ok(&svg(r#"<path d="M40 50 a10 10 0 0 0 20 0"/>"#));
    assert!(d.paths[0].points.iter().all(|q| q[1] <= 50.0 + 1e-9));
    let d = read_ok(&svg(r#"<path d="M50 40 A10 10 0 1 1 40 50"/>"#));
    // Three quarters of the circle: the vertices span x in [40, 60].
    let xs: Vec<f64> = d.paths[0].points.iter().map(|q| q[0]).collect();
    let max = xs.iter().copied().fold(f64::MIN, f64::max);
    assert!((max - 60.0).abs() <= TOL);
    // Radii too small are scaled up (SVG F.6.6): a half circle of radius 10.
    let d = read_ok(&svg(r#"<path d="M40 50 A1 1 0 0 1 60 50"/>"#));
    let top = d.paths[0]
        .points
        .iter()
        .map(|q| q[1])
        .fold(f64::MIN, f64::max);
    assert!((top - 60.0).abs() <= TOL);
    // Tiny user units (kurbo alone would call radii under 1e-5 a line): r = 1e-4 units = 10 mm.
    let d = read_ok(
        r#"<svg width="100mm" height="100mm" viewBox="0 0 0.001 0.001"><path d="M0.0004 0.0005 A0.0001 0.0001 0 0 1 0.0006 0.0005"/></svg>"#,
    );
    let p = &d.paths[0].points;
    assert!(p.len() > 10);
    for q in p {
        assert!(
            ((q[0] - 50.0).hypot(q[1] - 50.0) - 10.0).abs() < 1e-6,
            "{q:?}"
        );
    }
    // Zero radius: a straight line.
    let d = read_ok(&svg(r#"<path d="M40 50 A0 10 0 0 1 60 50"/>"#));
    assert_points(&d.paths[0].points, &[[40.0, 50.0], [60.0, 50.0]]);
}

#[test]
fn relative_and_absolute_commands_agree() {
    let abs = read_ok(&svg(
        r#"<path d="M10 10 L20 10 H30 V20 C30 25 35 30 40 30 S50 35 50 40 Q55 45 60 40 T70 40 Z"/>"#,
    ));
    let rel = read_ok(&svg(
        r#"<path d="m10 10 l10 0 h10 v10 c0 5 5 10 10 10 s10 5 10 10 q5 5 10 0 t10 0 z"/>"#,
    ));
    assert_eq!(abs.paths.len(), 1);
    assert_eq!(abs.paths[0].points.len(), rel.paths[0].points.len());
    for (a, r) in abs.paths[0].points.iter().zip(&rel.paths[0].points) {
        assert!((a[0] - r[0]).abs() < 1e-9 && (a[1] - r[1]).abs() < 1e-9);
    }
    let p = &abs.paths[0].points;
    assert!(abs.paths[0].closed);
    assert_points(
        &p[..4],
        &[[10.0, 90.0], [20.0, 90.0], [30.0, 90.0], [30.0, 80.0]],
    );
    assert!(p.iter().any(|q| close(*q, [40.0, 70.0])));
    assert!(p.iter().any(|q| close(*q, [50.0, 60.0])));
    assert!(close(*p.last().expect("points"), [70.0, 60.0]));
}

#[test]
fn smooth_reflection_and_implicit_commands() {
    // S after C reflects the second control point: a symmetric S-curve passes through (20,10).
    let d = read_ok(&svg(r#"<path d="M0 10 C0 0 10 0 10 10 S20 20 20 10"/>"#));
    let p = &d.paths[0].points;
    assert!(p.iter().any(|q| close(*q, [10.0, 90.0])));
    // By symmetry the lowest point (y up) is near x = 15, y = 100 - 17.5.
    let low = p.iter().map(|q| q[1]).fold(f64::MAX, f64::min);
    assert!((low - 82.5).abs() <= TOL, "{low}");
    // Implicit lineto after moveto, and a relative moveto after z starts at the closed start.
    let d = read_ok(&svg(r#"<path d="M0 0 10 0 10 10 z m 20 0 l 5 0"/>"#));
    assert_eq!(d.paths.len(), 2);
    assert!(d.paths[0].closed && !d.paths[1].closed);
    assert_points(
        &d.paths[0].points,
        &[[0.0, 100.0], [10.0, 100.0], [10.0, 90.0]],
    );
    assert_points(&d.paths[1].points, &[[20.0, 100.0], [25.0, 100.0]]);
    // A drawing command right after z starts a new subpath at the previous start.
    let d = read_ok(&svg(r#"<path d="M5 5 h10 v10 z l 0 10"/>"#));
    assert_eq!(d.paths.len(), 2);
    assert_points(&d.paths[1].points, &[[5.0, 95.0], [5.0, 85.0]]);
}

#[test]
fn polylines_polygons_ellipses_and_use() {
    let d = read_ok(&svg(concat!(
        r#"<polyline points="0,0 10,0 10,10"/>"#,
        r#"<polygon points="0 0 10 0 10 10 0 0"/>"#,
        r#"<ellipse cx="50" cy="50" rx="20" ry="10"/>"#,
        r##"<defs><path id="tpl" d="M0 0 L1 0"/><circle id="hidden" r="5"/></defs>"##,
        r##"<use href="#tpl" x="5" y="5"/>"##,
        r##"<use xlink:href="#tpl" transform="translate(10 0)"/>"##,
        r#"<text x="0" y="0">ignored</text>"#,
        r#"<switch><foreignObject/><line x2="1" requiredExtensions="x"/><g><line x2="7"/></g><line x2="9"/></switch>"#,
        r#"<g display="none"><line x2="5"/></g><line style="stroke:red; display: none" x2="5"/>"#,
    )));
    assert_eq!(d.paths.len(), 6, "{:?}", d.paths);
    assert_points(&d.paths[5].points, &[[0.0, 100.0], [7.0, 100.0]]);
    assert!(!d.paths[0].closed);
    // The polygon's repeated first point is dropped.
    assert!(d.paths[1].closed);
    assert_eq!(d.paths[1].points.len(), 3);
    for q in &d.paths[2].points {
        let v = ((q[0] - 50.0) / 20.0).powi(2) + ((q[1] - 50.0) / 10.0).powi(2);
        assert!((v.sqrt() - 1.0).abs() < 0.002, "{q:?}");
    }
    assert_points(&d.paths[3].points, &[[5.0, 95.0], [6.0, 95.0]]);
    assert_eq!(d.paths[3].id.as_deref(), Some("tpl"));
    assert_points(&d.paths[4].points, &[[10.0, 100.0], [11.0, 100.0]]);
}

#[test]
fn malformed_input_is_an_error() {
    let err = read(
        svg(r#"<g><path id="bad" d="M10 10 L20 x"/></g>"#).as_bytes(),
        TOL,
    )
    .expect_err("bad d");
    match &err {
        SvgError::InvalidAttribute(a) => {
            assert_eq!(
                (a.element.as_str(), a.id.as_deref(), a.attribute),
                ("path", Some("bad"), "d")
            );
            assert_eq!(a.line, 1);
            assert!(a.offset > 0);
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(err.to_string().contains("path id=\"bad\""), "{err}");
    // Path data must start with a moveto.
    assert!(read(svg(r#"<path d="L 10 10"/>"#).as_bytes(), TOL).is_err());
    for bad in [
        r#"<path d="M 10"/>"#,
        r#"<path d="M 0 0 A 5 5 0 2 0 10 10"/>"#,
        r#"<path d="M 0 0 Q 1 2 3"/>"#,
        r#"<path d="M 0 0 L 1e999 0"/>"#,
        r#"<rect width="abc" height="5"/>"#,
        r#"<circle r="5" transform="rotate(oops)"/>"#,
        r#"<polyline points="1 2 3"/>"#,
        r#"<polygon points="1 2 x 4"/>"#,
    ] {
        let err = read(svg(bad).as_bytes(), TOL).expect_err(bad);
        assert!(
            matches!(err, SvgError::InvalidAttribute(_)),
            "{bad}: {err:?}"
        );
    }
    // The line is reported.
    let doc = "<svg width=\"10mm\" height=\"10mm\">\n<g>\n\n<path d=\"M0 0 Lx\"/></g></svg>";
    match read(doc.as_bytes(), TOL) {
        Err(SvgError::InvalidAttribute(a)) => assert_eq!(a.line, 4),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        read(b"<html></html>", TOL),
        Err(SvgError::NotSvg { .. })
    ));
    assert!(matches!(read(b"", TOL), Err(SvgError::NotSvg { .. })));
    assert!(matches!(
        read(b"<svg><g></svg>", TOL),
        Err(SvgError::Xml { .. })
    ));
    assert!(matches!(
        read(b"<svg><g>", TOL),
        Err(SvgError::UnexpectedEof { .. })
    ));
    assert!(matches!(
        read(b"<svg>\xff</svg>", TOL),
        Err(SvgError::NotUtf8 { offset: 5, .. })
    ));
    assert!(matches!(
        read(svg("").as_bytes(), 0.0),
        Err(SvgError::InvalidTolerance { .. })
    ));
    assert!(matches!(
        read(svg("").as_bytes(), f64::NAN),
        Err(SvgError::InvalidTolerance { .. })
    ));
    assert!(matches!(
        read(br#"<svg viewBox="0 0 0 10"/>"#, TOL),
        Err(SvgError::InvalidAttribute(_))
    ));
    // use cycles are caught.
    let cyc = svg(r##"<g id="a"><use href="#b"/></g><g id="b"><use href="#a"/></g>"##);
    assert!(matches!(
        read(cyc.as_bytes(), TOL),
        Err(SvgError::TooDeep { .. })
    ));
    // Absurd sizes fail instead of exhausting memory.
    let huge = svg(r#"<circle r="1e15"/>"#);
    assert!(matches!(
        read(huge.as_bytes(), 1e-6),
        Err(SvgError::TooManyPoints { .. })
    ));
}

#[test]
fn garbage_never_panics() {
    let inputs: [&[u8]; 10] = [
        b"<svg><path d=\"M\"/></svg>",
        b"<svg><path d=\"   \"/></svg>",
        b"<svg><path d=\"M0 0 z z z m1 1\"/></svg>",
        b"<svg><path d=\"M0,0 C\"/></svg>",
        b"<svg><path d=\"M0 0 A 1e308 1e308 0 0 1 1 1\"/></svg>",
        b"<svg><path d=\"M0 0 A 1e-300 1e-300 0 0 1 1 1\"/></svg>",
        b"<svg><circle r=\"-5\"/><rect width=\"-1\" height=\"2\"/><ellipse rx=\"0\"/></svg>",
        b"<svg><use href=\"#nope\"/><use/></svg>",
        b"<svg viewBox=\"0 0 1e-300 1e-300\" width=\"1e300mm\"><line x2=\"1\"/></svg>",
        b"<svg width=\"100%\" height=\"50%\"><line x2=\"1\" y2=\"1\"/></svg>",
    ];
    for input in inputs {
        let _ = read(input, TOL);
    }
    // Every prefix of a document.
    let doc = svg(
        r#"<g transform="rotate(30)"><path d="M1 2 C 3 4 5 6 7 8 A 5 5 0 1 0 20 20 Z"/><rect rx="2" width="9" height="9"/></g>"#,
    );
    for end in 0..doc.len() {
        let _ = read(&doc.as_bytes()[..end], TOL);
    }
}

#[test]
fn mutated_documents_never_panic() {
    let doc = svg(concat!(
        r#"<g transform="translate(3 4) rotate(30) skewX(10)">"#,
        r#"<path d="M1 2 C 3 4 5 6 7 8 S 9 9 10 10 Q 1 1 2 2 T 5 5 A 5 3 20 1 0 20 20 Z m1 1 h2 v2 z"/>"#,
        r#"<rect x="1" y="1" rx="2" width="9" height="9"/><circle cx="5" cy="5" r="4"/>"#,
        r##"<polyline points="0,0 1,1 2,0"/><ellipse rx="3" ry="2"/><use href="#x"/></g>"##,
    ));
    let bytes = doc.as_bytes();
    let replacements = b"0-.eE<>/\"' Mz#";
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    for _ in 0..1500 {
        let mut m = bytes.to_vec();
        for _ in 0..3 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let at = (seed % m.len() as u64) as usize;
            m[at] = replacements[((seed >> 32) % replacements.len() as u64) as usize];
        }
        if let Ok(d) = read(&m, TOL) {
            for p in &d.paths {
                assert!(
                    p.points
                        .iter()
                        .all(|q| q[0].is_finite() && q[1].is_finite())
                );
                assert!(p.points.len() >= 2);
            }
        }
    }
}

#[test]
fn random_path_data_never_panics() {
    let commands = b"MmLlHhVvCcSsQqTtAaZz";
    let numbers = [
        "0", "1", "-1", "0.5", "10", "-37.25", "1e-300", "-1e-300", "1e300", "1e-7", "3e5", "90",
        "1",
    ];
    let mut seed = 0x1234_5678_9ABC_DEF1u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    for _ in 0..2000 {
        let mut d = String::from("M 0 0");
        for _ in 0..(next() % 8) {
            let c = commands[(next() % commands.len() as u64) as usize] as char;
            d.push(' ');
            d.push(c);
            let args = match c.to_ascii_uppercase() {
                'H' | 'V' => 1,
                'M' | 'L' | 'T' => 2,
                'S' | 'Q' => 4,
                'C' => 6,
                'A' => 7,
                _ => 0,
            };
            for k in 0..args {
                d.push(' ');
                if c.eq_ignore_ascii_case(&'a') && (k == 3 || k == 4) {
                    d.push(if next() % 2 == 0 { '0' } else { '1' });
                } else {
                    d.push_str(numbers[(next() % numbers.len() as u64) as usize]);
                }
            }
        }
        let doc = svg(&format!(
            r#"<path d="{d}" transform="rotate({} 5 5)"/>"#,
            next() % 360
        ));
        match read(doc.as_bytes(), TOL) {
            Ok(design) => {
                for p in &design.paths {
                    assert!(
                        p.points
                            .iter()
                            .all(|q| q[0].is_finite() && q[1].is_finite()),
                        "{d}"
                    );
                }
            }
            Err(SvgError::InvalidAttribute(_) | SvgError::TooManyPoints { .. }) => {}
            Err(e) => panic!("{d}: {e}"),
        }
    }
}
