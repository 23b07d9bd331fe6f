//! The walk over the element tree: units, viewports, transforms, shapes and path data.

use std::collections::HashMap;
use std::str::FromStr;

use kurbo::{Affine, CubicBez, Point, QuadBez, Vec2};
use svgtypes::{Align, AspectRatio, Length, LengthUnit, PathParser, PathSegment, ViewBox};

use crate::flatten::{self, Ellipse, Out, Overflow};
use crate::{AttributeError, Design, DesignPath, MAX_POINTS, MAX_USE_DEPTH, MM_PER_PX, SvgError};
use conduit_xml::{Node, line_of};

/// Elements never drawn, with everything inside them.
const SKIPPED: [&str; 14] = [
    "defs",
    "clipPath",
    "mask",
    "pattern",
    "marker",
    "symbol",
    "text",
    "style",
    "script",
    "title",
    "desc",
    "metadata",
    "foreignObject",
    "filter",
];

/// A segment of a subpath in user units; each starts where the previous one ended.
#[derive(Debug, Clone, Copy)]
enum Seg {
    Line(Point),
    Quad(Point, Point),
    Cubic(Point, Point, Point),
    Arc {
        center: Point,
        radii: Vec2,
        x_rotation: f64,
        start_angle: f64,
        sweep_angle: f64,
        end: Point,
    },
}

/// One subpath in user units.
#[derive(Debug, Clone)]
struct Sub {
    start: Point,
    segs: Vec<Seg>,
    closed: bool,
}

/// What a shape element describes, in user units.
enum Geom {
    Sub(Sub),
    Ellipse { center: Point, rx: f64, ry: f64 },
}

/// The coordinate system an element is drawn in.
#[derive(Clone, Copy)]
struct Frame {
    /// User units of this element to millimetres, y up.
    ctm: Affine,
    /// Width and height of the nearest viewport in user units (for percentages).
    viewport: (f64, f64),
}

struct Walker<'a> {
    src: &'a [u8],
    tol: f64,
    budget: usize,
    ids: HashMap<&'a str, &'a Node>,
    use_stack: Vec<*const Node>,
    paths: Vec<DesignPath>,
}

pub(crate) fn read(src: &[u8], root: &Node, tol: f64) -> Result<Design, SvgError> {
    let mut ids = HashMap::new();
    collect_ids(root, &mut ids);
    let mut w = Walker {
        src,
        tol,
        budget: MAX_POINTS,
        ids,
        use_stack: Vec::new(),
        paths: Vec::new(),
    };
    let (frame, width_mm, height_mm) = w.root_frame(root)?;
    let frame = Frame {
        ctm: frame.ctm * w.transform(root)?,
        ..frame
    };
    w.children(root, frame, 0)?;
    Ok(Design {
        width_mm,
        height_mm,
        paths: w.paths,
    })
}

fn collect_ids<'a>(node: &'a Node, ids: &mut HashMap<&'a str, &'a Node>) {
    if let Some(id) = node.attr("id") {
        ids.entry(id).or_insert(node);
    }
    for c in &node.children {
        collect_ids(c, ids);
    }
}

/// A length in millimetres, or `None` for percentages (which need a viewport).
fn length_mm(l: Length) -> Option<f64> {
    let n = l.number;
    let mm = match l.unit {
        LengthUnit::None | LengthUnit::Px => n * MM_PER_PX,
        LengthUnit::Mm => n,
        LengthUnit::Cm => n * 10.0,
        LengthUnit::In => n * 25.4,
        LengthUnit::Pt => n * 25.4 / 72.0,
        LengthUnit::Pc => n * 25.4 / 6.0,
        // CSS defaults: 1em = 16px, 1ex = 8px.
        LengthUnit::Em => n * 16.0 * MM_PER_PX,
        LengthUnit::Ex => n * 8.0 * MM_PER_PX,
        LengthUnit::Percent => return None,
    };
    Some(mm)
}

#[derive(Clone, Copy)]
enum Axis {
    X,
    Y,
    Diagonal,
}

/// A length in user units (1 user unit = 1 px in an un-scaled context).
fn length_user(l: Length, axis: Axis, viewport: (f64, f64)) -> f64 {
    match l.unit {
        LengthUnit::Percent => {
            let (w, h) = viewport;
            let base = match axis {
                Axis::X => w,
                Axis::Y => h,
                Axis::Diagonal => ((w * w + h * h) / 2.0).sqrt(),
            };
            l.number / 100.0 * base
        }
        _ => length_mm(l).map_or(0.0, |mm| mm / MM_PER_PX),
    }
}

/// The map from a viewBox to a viewport of `w` x `h` (y down), per `preserveAspectRatio`.
fn viewbox_transform(vb: ViewBox, w: f64, h: f64, ar: AspectRatio) -> Affine {
    let (mut sx, mut sy) = (w / vb.w, h / vb.h);
    let (mut tx, mut ty) = (0.0, 0.0);
    if ar.align != Align::None {
        let s = if ar.slice { sx.max(sy) } else { sx.min(sy) };
        (sx, sy) = (s, s);
        let (fx, fy) = match ar.align {
            Align::None | Align::XMinYMin => (0.0, 0.0),
            Align::XMidYMin => (0.5, 0.0),
            Align::XMaxYMin => (1.0, 0.0),
            Align::XMinYMid => (0.0, 0.5),
            Align::XMidYMid => (0.5, 0.5),
            Align::XMaxYMid => (1.0, 0.5),
            Align::XMinYMax => (0.0, 1.0),
            Align::XMidYMax => (0.5, 1.0),
            Align::XMaxYMax => (1.0, 1.0),
        };
        tx = fx * (w - vb.w * s);
        ty = fy * (h - vb.h * s);
    }
    Affine::new([sx, 0.0, 0.0, sy, tx - sx * vb.x, ty - sy * vb.y])
}

fn is_hidden(node: &Node) -> bool {
    node.attr("display").is_some_and(|d| d.trim() == "none")
        || node.attr("style").is_some_and(|s| {
            s.split(';').any(|decl| {
                let mut kv = decl.splitn(2, ':');
                kv.next().map(str::trim) == Some("display")
                    && kv.next().map(str::trim) == Some("none")
            })
        })
}

impl<'a> Walker<'a> {
    fn invalid(&self, node: &Node, attribute: &'static str, reason: impl ToString) -> SvgError {
        let value = node.attr(attribute).unwrap_or_default();
        let value = match value.char_indices().nth(80) {
            Some((cut, _)) => format!("{}...", &value[..cut]),
            None => value.to_string(),
        };
        SvgError::InvalidAttribute(Box::new(AttributeError {
            element: node.name.clone(),
            id: node.attr("id").map(str::to_string),
            attribute,
            value,
            reason: reason.to_string(),
            offset: node.pos,
            line: line_of(self.src, node.pos),
        }))
    }

    fn parse_attr<T: FromStr>(&self, node: &Node, key: &'static str) -> Result<Option<T>, SvgError>
    where
        T::Err: ToString,
    {
        match node.attr(key) {
            None => Ok(None),
            Some(v) => T::from_str(v.trim())
                .map(Some)
                .map_err(|e| self.invalid(node, key, e)),
        }
    }

    /// A length attribute in user units (`default` when absent).
    fn len(
        &self,
        node: &Node,
        key: &'static str,
        axis: Axis,
        f: Frame,
        default: f64,
    ) -> Result<f64, SvgError> {
        Ok(self
            .parse_attr::<Length>(node, key)?
            .map_or(default, |l| length_user(l, axis, f.viewport)))
    }

    fn transform(&self, node: &Node) -> Result<Affine, SvgError> {
        Ok(self
            .parse_attr::<svgtypes::Transform>(node, "transform")?
            .map_or(Affine::IDENTITY, |t| {
                Affine::new([t.a, t.b, t.c, t.d, t.e, t.f])
            }))
    }

    fn viewbox(&self, node: &Node) -> Result<Option<ViewBox>, SvgError> {
        let vb = self.parse_attr::<ViewBox>(node, "viewBox")?;
        match vb {
            Some(vb)
                if !(vb.w > 0.0
                    && vb.h > 0.0
                    && [vb.x, vb.y, vb.w, vb.h].iter().all(|v| v.is_finite())) =>
            {
                Err(self.invalid(
                    node,
                    "viewBox",
                    "width and height must be positive and finite",
                ))
            }
            vb => Ok(vb),
        }
    }

    /// The root `<svg>`: user units to millimetres with y up, and the document size.
    fn root_frame(&self, root: &Node) -> Result<(Frame, Option<f64>, Option<f64>), SvgError> {
        let w_mm = self
            .parse_attr::<Length>(root, "width")?
            .and_then(length_mm)
            .filter(|v| *v > 0.0);
        let h_mm = self
            .parse_attr::<Length>(root, "height")?
            .and_then(length_mm)
            .filter(|v| *v > 0.0);
        let ar = self
            .parse_attr::<AspectRatio>(root, "preserveAspectRatio")?
            .unwrap_or_default();
        let vb = self.viewbox(root)?;
        let (ctm, width, height, viewport) = match vb {
            Some(vb) => {
                let (w, h) = match (w_mm, h_mm) {
                    (Some(w), Some(h)) => (w, h),
                    (Some(w), None) => (w, w * vb.h / vb.w),
                    (None, Some(h)) => (h * vb.w / vb.h, h),
                    (None, None) => (vb.w * MM_PER_PX, vb.h * MM_PER_PX),
                };
                let to_viewport = viewbox_transform(vb, w, h, ar);
                let flip = Affine::new([1.0, 0.0, 0.0, -1.0, 0.0, h]);
                (flip * to_viewport, Some(w), Some(h), (vb.w, vb.h))
            }
            None => {
                let h = h_mm.unwrap_or(0.0);
                let ctm = Affine::new([MM_PER_PX, 0.0, 0.0, -MM_PER_PX, 0.0, h]);
                let viewport = (
                    w_mm.map_or(0.0, |w| w / MM_PER_PX),
                    h_mm.map_or(0.0, |h| h / MM_PER_PX),
                );
                (ctm, w_mm, h_mm, viewport)
            }
        };
        if !(width.is_none_or(f64::is_finite) && height.is_none_or(f64::is_finite)) {
            return Err(self.invalid(root, "width", "document size is not finite"));
        }
        Ok((Frame { ctm, viewport }, width, height))
    }

    fn children(&mut self, node: &'a Node, frame: Frame, depth: usize) -> Result<(), SvgError> {
        for child in &node.children {
            self.element(child, frame, depth)?;
        }
        Ok(())
    }

    fn element(&mut self, node: &'a Node, parent: Frame, depth: usize) -> Result<(), SvgError> {
        if SKIPPED.contains(&node.name.as_str()) || is_hidden(node) {
            return Ok(());
        }
        let frame = Frame {
            ctm: parent.ctm * self.transform(node)?,
            ..parent
        };
        match node.name.as_str() {
            "g" | "a" => self.children(node, frame, depth),
            // Draws only its first usable child (Illustrator puts a foreignObject first).
            "switch" => match node.children.iter().find(|c| {
                !SKIPPED.contains(&c.name.as_str()) && c.attr("requiredExtensions").is_none()
            }) {
                Some(child) => self.element(child, frame, depth),
                None => Ok(()),
            },
            "svg" => {
                // A nested viewport: x, y, width, height (default 100%) and an optional viewBox.
                let x = self.len(node, "x", Axis::X, frame, 0.0)?;
                let y = self.len(node, "y", Axis::Y, frame, 0.0)?;
                let w = self.len(node, "width", Axis::X, frame, frame.viewport.0)?;
                let h = self.len(node, "height", Axis::Y, frame, frame.viewport.1)?;
                let mut inner = Frame {
                    ctm: frame.ctm * Affine::translate((x, y)),
                    viewport: (w, h),
                };
                if let Some(vb) = self.viewbox(node)? {
                    let ar = self
                        .parse_attr::<AspectRatio>(node, "preserveAspectRatio")?
                        .unwrap_or_default();
                    inner.ctm *= viewbox_transform(vb, w, h, ar);
                    inner.viewport = (vb.w, vb.h);
                }
                self.children(node, inner, depth)
            }
            "use" => self.use_element(node, frame, depth),
            _ => {
                for geom in self.geometry(node, frame)? {
                    self.emit(node, &geom, frame.ctm)?;
                }
                Ok(())
            }
        }
    }

    fn use_element(&mut self, node: &'a Node, frame: Frame, depth: usize) -> Result<(), SvgError> {
        let href = node.attr("href").or_else(|| node.attr("xlink:href"));
        let Some(target) = href
            .and_then(|h| h.trim().strip_prefix('#'))
            .and_then(|id| self.ids.get(id).copied())
        else {
            return Ok(()); // A missing reference draws nothing, as in browsers.
        };
        let ptr: *const Node = target;
        if depth >= MAX_USE_DEPTH || self.use_stack.contains(&ptr) {
            return Err(SvgError::TooDeep {
                element: node.name.clone(),
                offset: node.pos,
                line: line_of(self.src, node.pos),
                limit: MAX_USE_DEPTH,
            });
        }
        let x = self.len(node, "x", Axis::X, frame, 0.0)?;
        let y = self.len(node, "y", Axis::Y, frame, 0.0)?;
        let inner = Frame {
            ctm: frame.ctm * Affine::translate((x, y)),
            ..frame
        };
        self.use_stack.push(ptr);
        let result = if target.name == "symbol" {
            // A symbol is drawn only through <use>; its own viewBox is not applied.
            let inner = Frame {
                ctm: inner.ctm * self.transform(target)?,
                ..inner
            };
            self.children(target, inner, depth + 1)
        } else {
            self.element(target, inner, depth + 1)
        };
        self.use_stack.pop();
        result
    }

    /// The subpaths a shape element describes, in its user units.
    fn geometry(&self, node: &Node, f: Frame) -> Result<Vec<Geom>, SvgError> {
        let num = |key: &'static str, axis: Axis| self.len(node, key, axis, f, 0.0);
        let geoms = match node.name.as_str() {
            "path" => {
                let d = node.attr("d").unwrap_or_default();
                path_data(d)
                    .map_err(|e| self.invalid(node, "d", e))?
                    .into_iter()
                    .map(Geom::Sub)
                    .collect()
            }
            "line" => {
                let p0 = Point::new(num("x1", Axis::X)?, num("y1", Axis::Y)?);
                let p1 = Point::new(num("x2", Axis::X)?, num("y2", Axis::Y)?);
                vec![Geom::Sub(Sub {
                    start: p0,
                    segs: vec![Seg::Line(p1)],
                    closed: false,
                })]
            }
            "polyline" | "polygon" => {
                let points = node.attr("points").unwrap_or_default();
                let mut numbers = Vec::new();
                for n in svgtypes::NumberListParser::from(points) {
                    numbers.push(n.map_err(|e| self.invalid(node, "points", e))?);
                }
                if numbers.len() % 2 != 0 {
                    return Err(self.invalid(node, "points", "odd number of coordinates"));
                }
                let pts: Vec<Point> = numbers
                    .chunks_exact(2)
                    .map(|c| Point::new(c[0], c[1]))
                    .collect();
                match pts.split_first() {
                    Some((&start, rest)) => vec![Geom::Sub(Sub {
                        start,
                        segs: rest.iter().map(|&p| Seg::Line(p)).collect(),
                        closed: node.name == "polygon",
                    })],
                    None => Vec::new(),
                }
            }
            "circle" => {
                let r = num("r", Axis::Diagonal)?;
                let center = Point::new(num("cx", Axis::X)?, num("cy", Axis::Y)?);
                if r > 0.0 {
                    vec![Geom::Ellipse {
                        center,
                        rx: r,
                        ry: r,
                    }]
                } else {
                    Vec::new()
                }
            }
            "ellipse" => {
                let center = Point::new(num("cx", Axis::X)?, num("cy", Axis::Y)?);
                let (rx, ry) = auto_radii(
                    self.parse_attr::<Length>(node, "rx")?
                        .map(|l| length_user(l, Axis::X, f.viewport)),
                    self.parse_attr::<Length>(node, "ry")?
                        .map(|l| length_user(l, Axis::Y, f.viewport)),
                );
                if rx > 0.0 && ry > 0.0 {
                    vec![Geom::Ellipse { center, rx, ry }]
                } else {
                    Vec::new()
                }
            }
            "rect" => {
                let (x, y) = (num("x", Axis::X)?, num("y", Axis::Y)?);
                let (w, h) = (num("width", Axis::X)?, num("height", Axis::Y)?);
                let (rx, ry) = auto_radii(
                    self.parse_attr::<Length>(node, "rx")?
                        .map(|l| length_user(l, Axis::X, f.viewport)),
                    self.parse_attr::<Length>(node, "ry")?
                        .map(|l| length_user(l, Axis::Y, f.viewport)),
                );
                if w > 0.0 && h > 0.0 {
                    vec![Geom::Sub(rect(
                        x,
                        y,
                        w,
                        h,
                        rx.clamp(0.0, w / 2.0),
                        ry.clamp(0.0, h / 2.0),
                    ))]
                } else {
                    Vec::new()
                }
            }
            _ => Vec::new(),
        };
        Ok(geoms)
    }

    /// Flattens one subpath into millimetres and records it.
    fn emit(&mut self, node: &Node, geom: &Geom, ctm: Affine) -> Result<(), SvgError> {
        let tol = self.tol;
        let mut out = Out {
            points: Vec::new(),
            budget: &mut self.budget,
        };
        let closed = match geom {
            Geom::Ellipse { center, rx, ry } => {
                let e = Ellipse::new(ctm, *center, *rx, *ry, 0.0);
                flatten::full_ellipse(&e, tol, &mut out)
                    .map_err(|Overflow| too_many(self.src, node))?;
                true
            }
            Geom::Sub(sub) => {
                flatten_sub(sub, ctm, tol, &mut out)
                    .map_err(|Overflow| too_many(self.src, node))?;
                sub.closed
            }
        };
        let mut points = out.points;
        if points.iter().any(|p| !(p.x.is_finite() && p.y.is_finite())) {
            let key = if node.name == "path" {
                "d"
            } else {
                "transform"
            };
            return Err(self.invalid(node, key, "coordinates are not finite in millimetres"));
        }
        points.dedup();
        if closed && points.len() > 1 {
            let (first, last) = (points[0], points[points.len() - 1]);
            if (first - last).hypot() <= 1e-9 {
                points.pop();
            }
        }
        if points.len() < 2 {
            return Ok(());
        }
        self.paths.push(DesignPath {
            id: node.attr("id").map(str::to_string),
            points: points.iter().map(|p| [p.x, p.y]).collect(),
            closed,
        });
        Ok(())
    }
}

fn too_many(src: &[u8], node: &Node) -> SvgError {
    SvgError::TooManyPoints {
        element: node.name.clone(),
        offset: node.pos,
        line: line_of(src, node.pos),
        limit: MAX_POINTS,
    }
}

/// `rx`/`ry` of `rect` and `ellipse`: a missing one takes the other's value (SVG 2 `auto`).
fn auto_radii(rx: Option<f64>, ry: Option<f64>) -> (f64, f64) {
    match (rx, ry) {
        (Some(rx), Some(ry)) => (rx, ry),
        (Some(r), None) | (None, Some(r)) => (r, r),
        (None, None) => (0.0, 0.0),
    }
}

/// The outline of a rectangle, clockwise in user space (y down) from the top edge, with
/// elliptical corners of radii `rx`, `ry` (already clamped to half the sides).
fn rect(x: f64, y: f64, w: f64, h: f64, rx: f64, ry: f64) -> Sub {
    use std::f64::consts::FRAC_PI_2;
    let p = Point::new;
    if rx <= 0.0 || ry <= 0.0 {
        return Sub {
            start: p(x, y),
            segs: vec![
                Seg::Line(p(x + w, y)),
                Seg::Line(p(x + w, y + h)),
                Seg::Line(p(x, y + h)),
            ],
            closed: true,
        };
    }
    let corner = |cx: f64, cy: f64, start_angle: f64, end: Point| Seg::Arc {
        center: p(cx, cy),
        radii: Vec2::new(rx, ry),
        x_rotation: 0.0,
        start_angle,
        sweep_angle: FRAC_PI_2,
        end,
    };
    Sub {
        start: p(x + rx, y),
        segs: vec![
            Seg::Line(p(x + w - rx, y)),
            corner(x + w - rx, y + ry, -FRAC_PI_2, p(x + w, y + ry)),
            Seg::Line(p(x + w, y + h - ry)),
            corner(x + w - rx, y + h - ry, 0.0, p(x + w - rx, y + h)),
            Seg::Line(p(x + rx, y + h)),
            corner(x + rx, y + h - ry, FRAC_PI_2, p(x, y + h - ry)),
            Seg::Line(p(x, y + ry)),
            corner(x + rx, y + ry, std::f64::consts::PI, p(x + rx, y)),
        ],
        closed: true,
    }
}

fn flatten_sub(sub: &Sub, ctm: Affine, tol: f64, out: &mut Out<'_>) -> Result<(), Overflow> {
    out.push(ctm * sub.start)?;
    let mut cur = sub.start;
    for seg in &sub.segs {
        match *seg {
            Seg::Line(p) => {
                out.push(ctm * p)?;
                cur = p;
            }
            Seg::Quad(c, p) => {
                flatten::quad(QuadBez::new(ctm * cur, ctm * c, ctm * p), tol, out)?;
                cur = p;
            }
            Seg::Cubic(c1, c2, p) => {
                let c = CubicBez::new(ctm * cur, ctm * c1, ctm * c2, ctm * p);
                flatten::cubic(c, tol, out)?;
                cur = p;
            }
            Seg::Arc {
                center,
                radii,
                x_rotation,
                start_angle,
                sweep_angle,
                end,
            } => {
                let e = Ellipse::new(ctm, center, radii.x, radii.y, x_rotation);
                flatten::arc(&e, start_angle, sweep_angle, ctm * end, tol, out)?;
                cur = end;
            }
        }
    }
    Ok(())
}

/// Whether kurbo's centre construction (SVG F.6.5) has a non-zero denominator for this arc;
/// it only `debug_assert`s that, and the values are NaN otherwise. Replicates its first steps.
fn solvable(arc: &kurbo::SvgArc) -> bool {
    let (sin, cos) = (arc.x_rotation % (2.0 * std::f64::consts::PI)).sin_cos();
    let hd = (arc.from - arc.to) * 0.5;
    let px = cos * hd.x + sin * hd.y;
    let py = -sin * hd.x + cos * hd.y;
    let (mut rx, mut ry) = (arc.radii.x.abs(), arc.radii.y.abs());
    let rf = px * px / (rx * rx) + py * py / (ry * ry);
    if rf > 1.0 {
        rx *= rf.sqrt();
        ry *= rf.sqrt();
    }
    let sum = (rx * py).powi(2) + (ry * px).powi(2);
    sum > 0.0 && sum.is_finite()
}

/// Path data (`d`) to subpaths in user units. Every `M` starts a subpath; `Z` closes it, and a
/// drawing command after `Z` starts a new one at the closed subpath's start.
fn path_data(d: &str) -> Result<Vec<Sub>, svgtypes::Error> {
    let mut subs = Vec::new();
    let mut current: Option<Sub> = None;
    let mut pen = Pen {
        cur: Point::ZERO,
        start: Point::ZERO,
        last_cubic: None,
        last_quad: None,
    };
    for seg in PathParser::from(d) {
        let seg = seg?;
        match seg {
            PathSegment::MoveTo { x, y, .. } => {
                let p = pen.at(seg.is_abs(), x, y);
                subs.extend(current.take());
                current = Some(Sub {
                    start: p,
                    segs: Vec::new(),
                    closed: false,
                });
                pen.move_to(p);
            }
            PathSegment::ClosePath { .. } => {
                if let Some(mut sub) = current.take() {
                    sub.closed = true;
                    subs.push(sub);
                }
                pen.move_to(pen.start);
            }
            _ => {
                let start = pen.cur;
                let sub = current.get_or_insert_with(|| Sub {
                    start,
                    segs: Vec::new(),
                    closed: false,
                });
                if let Some(segment) = pen.draw(seg) {
                    sub.segs.push(segment);
                }
            }
        }
    }
    subs.extend(current);
    Ok(subs)
}

/// Where path data has drawn to.
struct Pen {
    /// The current point.
    cur: Point,
    /// Start of the current subpath, where `Z` returns.
    start: Point,
    /// Control points for S and T reflection: set only by the previous C/S or Q/T.
    last_cubic: Option<Point>,
    last_quad: Option<Point>,
}

impl Pen {
    /// The point of coordinates (`x`, `y`): absolute, or relative to the current point.
    fn at(&self, abs: bool, x: f64, y: f64) -> Point {
        if abs {
            Point::new(x, y)
        } else {
            self.cur + Vec2::new(x, y)
        }
    }

    /// Moves to `p` (by `M`, or back to the start by `Z`), which starts a subpath there.
    fn move_to(&mut self, p: Point) {
        (self.cur, self.start) = (p, p);
        self.last_cubic = None;
        self.last_quad = None;
    }

    /// The line, curve or arc that `seg` draws from the current point, which moves to its end;
    /// `None` for `M` and `Z`.
    fn draw(&mut self, seg: PathSegment) -> Option<Seg> {
        let abs = seg.is_abs();
        let cur = self.cur;
        let at = |x: f64, y: f64| self.at(abs, x, y);
        let (mut next_cubic, mut next_quad) = (None, None);
        let (segment, end) = match seg {
            PathSegment::LineTo { x, y, .. } => {
                let p = at(x, y);
                (Seg::Line(p), p)
            }
            PathSegment::HorizontalLineTo { x, .. } => {
                let p = Point::new(if abs { x } else { cur.x + x }, cur.y);
                (Seg::Line(p), p)
            }
            PathSegment::VerticalLineTo { y, .. } => {
                let p = Point::new(cur.x, if abs { y } else { cur.y + y });
                (Seg::Line(p), p)
            }
            PathSegment::CurveTo {
                x1,
                y1,
                x2,
                y2,
                x,
                y,
                ..
            } => {
                let (c2, p) = (at(x2, y2), at(x, y));
                next_cubic = Some(c2);
                (Seg::Cubic(at(x1, y1), c2, p), p)
            }
            PathSegment::SmoothCurveTo { x2, y2, x, y, .. } => {
                let c1 = self.last_cubic.map_or(cur, |c| cur + (cur - c));
                let (c2, p) = (at(x2, y2), at(x, y));
                next_cubic = Some(c2);
                (Seg::Cubic(c1, c2, p), p)
            }
            PathSegment::Quadratic { x1, y1, x, y, .. } => {
                let (c, p) = (at(x1, y1), at(x, y));
                next_quad = Some(c);
                (Seg::Quad(c, p), p)
            }
            PathSegment::SmoothQuadratic { x, y, .. } => {
                let c = self.last_quad.map_or(cur, |c| cur + (cur - c));
                let p = at(x, y);
                next_quad = Some(c);
                (Seg::Quad(c, p), p)
            }
            PathSegment::EllipticalArc {
                rx,
                ry,
                x_axis_rotation,
                large_arc,
                sweep,
                x,
                y,
                ..
            } => {
                let p = at(x, y);
                let arc = kurbo::SvgArc {
                    from: cur,
                    to: p,
                    radii: Vec2::new(rx, ry),
                    x_rotation: x_axis_rotation.to_radians(),
                    large_arc,
                    sweep,
                };
                (arc_segment(&arc), p)
            }
            PathSegment::MoveTo { .. } | PathSegment::ClosePath { .. } => return None,
        };
        self.cur = end;
        self.last_cubic = next_cubic;
        self.last_quad = next_quad;
        Some(segment)
    }
}

/// The segment an SVG elliptical arc command draws: an arc, or a line when its radii are zero
/// or it has no solution. Equal end points draw nothing; zero radii draw a line (SVG F.6.2).
fn arc_segment(svg: &kurbo::SvgArc) -> Seg {
    let (cur, p) = (svg.from, svg.to);
    // kurbo treats radii below 1e-5 as zero; the centre construction is
    // scale-invariant, so solve it at unit scale around `cur` and scale back.
    let k = svg.radii.x.abs().max(svg.radii.y.abs());
    let arc = kurbo::SvgArc {
        from: Point::ZERO,
        to: Point::ZERO + (p - cur) / k,
        radii: Vec2::new(svg.radii.x / k, svg.radii.y / k),
        x_rotation: svg.x_rotation,
        large_arc: svg.large_arc,
        sweep: svg.sweep,
    };
    let solved = if p == cur || !(k > 0.0 && k.is_finite()) || !solvable(&arc) {
        None
    } else {
        kurbo::Arc::from_svg_arc(&arc)
    };
    match solved {
        Some(a) if a.radii.x.is_finite() && a.radii.y.is_finite() => Seg::Arc {
            center: cur + a.center.to_vec2() * k,
            radii: a.radii * k,
            x_rotation: a.x_rotation,
            start_angle: a.start_angle,
            sweep_angle: a.sweep_angle,
            end: p,
        },
        _ => Seg::Line(p),
    }
}
