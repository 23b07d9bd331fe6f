//! Boards (`.kicad_pcb`): footprints with their pads, the nets, the board outline.
//!
//! Coordinates are KiCad's: millimetres, y pointing down, angles in degrees counter-clockwise
//! as seen on screen. A footprint's pads are stored in its own frame, already mirrored when it
//! sits on the bottom side (KiCad flips a footprint by negating its items' local y and its
//! angles); a pad's angle in the file includes the footprint's. [`Footprint::board_position`]
//! puts a pad on the board.

use std::collections::BTreeMap;

use crate::error::KicadError;
use crate::netlist::Netlist;
use crate::sexpr::Node;

/// A board.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Pcb {
    /// The `(version …)` date code, e.g. `20211014` (KiCad 6), `20240108` (KiCad 8).
    pub version: u32,
    /// Footprints in file order.
    pub footprints: Vec<Footprint>,
    /// Net names by number, from the board's `(net N "name")` list (number 0 is "no net").
    pub nets: BTreeMap<u32, String>,
    /// The drawings on `Edge.Cuts`, on the board and inside footprints (in board coordinates).
    pub outline: Vec<OutlineShape>,
}

/// A placed footprint.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Footprint {
    /// Reference designator (`R1`): `(fp_text reference …)` up to KiCad 7,
    /// `(property "Reference" …)` from KiCad 8.
    pub reference: String,
    /// The value (`10k`).
    pub value: String,
    /// The library footprint (`Resistor_SMD:R_0805_2012Metric`).
    pub name: String,
    /// Origin x on the board, mm.
    pub x: f64,
    /// Origin y on the board, mm (y down).
    pub y: f64,
    /// Rotation, degrees counter-clockwise on screen.
    pub rotation: f64,
    /// On the bottom side (`(layer "B.Cu")`): the pads are stored mirrored.
    pub bottom: bool,
    /// The pads, in file order.
    pub pads: Vec<Pad>,
}

/// A pad's kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PadKind {
    /// `smd`: copper on one side.
    Smd,
    /// `thru_hole`: plated hole.
    ThroughHole,
    /// `np_thru_hole`: a mechanical hole with no copper.
    NpThroughHole,
    /// `connect`: copper without solder mask opening (edge connectors).
    Connect,
}

/// A pad's copper shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PadShape {
    /// `circle`: diameter is the size's width.
    Circle,
    /// `rect`.
    Rect,
    /// `oval`: a stadium (a circle when square).
    Oval,
    /// `trapezoid`: drawn within its size.
    Trapezoid,
    /// `roundrect`: corners rounded by `ratio` × the shorter side.
    RoundRect {
        /// `(roundrect_rratio …)`, 0 to 0.5 (0.25 when absent).
        ratio: f64,
    },
    /// `custom`: an anchor pad and drawn primitives.
    Custom {
        /// The box covering the anchor and every primitive (with its line width), in the pad's
        /// own frame: `[x0, y0, x1, y1]` mm.
        bounds: [f64; 4],
    },
}

/// A pad of a footprint.
#[derive(Debug, Clone, PartialEq)]
pub struct Pad {
    /// Pad number (`1`, `A3`; empty for mechanical holes).
    pub number: String,
    /// Its kind.
    pub kind: PadKind,
    /// Its copper shape.
    pub shape: PadShape,
    /// Size along the pad's x axis, mm.
    pub width: f64,
    /// Size along the pad's y axis, mm.
    pub height: f64,
    /// Centre x in the footprint frame, mm.
    pub x: f64,
    /// Centre y in the footprint frame, mm (y down; mirrored on bottom footprints).
    pub y: f64,
    /// Rotation on the board, degrees (the footprint's included, as KiCad writes it).
    pub rotation: f64,
    /// Drill size `(width, height)` mm (equal for a round hole), if drilled.
    pub drill: Option<(f64, f64)>,
    /// Copper and technical layers (`F.Cu`, `*.Cu`, `F.Mask`).
    pub layers: Vec<String>,
    /// Net name, `None` when unconnected.
    pub net: Option<String>,
}

/// A drawing on the `Edge.Cuts` layer, board coordinates (mm, y down).
#[derive(Debug, Clone, PartialEq)]
pub enum OutlineShape {
    /// A straight line.
    Line {
        /// Start point.
        start: (f64, f64),
        /// End point.
        end: (f64, f64),
    },
    /// An arc through three points.
    Arc {
        /// Start point.
        start: (f64, f64),
        /// A point on the arc between start and end.
        mid: (f64, f64),
        /// End point.
        end: (f64, f64),
    },
    /// A circle.
    Circle {
        /// Centre.
        centre: (f64, f64),
        /// Radius, mm.
        radius: f64,
    },
    /// A closed polygon (a rectangle is one with four corners).
    Polygon {
        /// Corners in order.
        points: Vec<(f64, f64)>,
    },
}

impl OutlineShape {
    /// Points whose bounding box is the shape's: ends and mid point of lines and arcs, the
    /// four extreme points of a circle, a polygon's corners.
    pub fn extent_points(&self) -> Vec<(f64, f64)> {
        match self {
            OutlineShape::Line { start, end } => vec![*start, *end],
            OutlineShape::Arc { start, mid, end } => vec![*start, *mid, *end],
            OutlineShape::Circle { centre, radius } => {
                let (x, y) = *centre;
                vec![
                    (x - radius, y),
                    (x + radius, y),
                    (x, y - radius),
                    (x, y + radius),
                ]
            }
            OutlineShape::Polygon { points } => points.clone(),
        }
    }
}

impl Footprint {
    /// Where a point of the footprint frame (as stored) lies on the board, mm (y down).
    pub fn to_board(&self, x: f64, y: f64) -> (f64, f64) {
        // KiCad's rotation: counter-clockwise on screen, where y points down.
        let (s, c) = self.rotation.to_radians().sin_cos();
        (self.x + x * c + y * s, self.y - x * s + y * c)
    }

    /// A pad's centre on the board, mm (y down).
    pub fn board_position(&self, pad: &Pad) -> (f64, f64) {
        self.to_board(pad.x, pad.y)
    }

    /// The pad numbered `number`.
    pub fn pad(&self, number: &str) -> Option<&Pad> {
        self.pads.iter().find(|p| p.number == number)
    }
}

impl Pcb {
    /// Net name → the `(reference, pad number)` on it, from the pads' nets.
    pub fn netlist(&self) -> Netlist {
        let mut out: Netlist = BTreeMap::new();
        for f in &self.footprints {
            for p in &f.pads {
                if let Some(net) = &p.net {
                    out.entry(net.clone())
                        .or_default()
                        .insert((f.reference.clone(), p.number.clone()));
                }
            }
        }
        out
    }

    /// The footprint whose reference is `reference`.
    pub fn footprint(&self, reference: &str) -> Option<&Footprint> {
        self.footprints.iter().find(|f| f.reference == reference)
    }
}

/// Reads the `(kicad_pcb …)` root.
pub(crate) fn read(root: Node<'_>) -> Result<Pcb, KicadError> {
    let mut pcb = Pcb {
        version: version(root)?,
        ..Pcb::default()
    };
    for n in root.all("net") {
        let number = n.num(0, "a net number")?;
        let name = n.atom(1).unwrap_or_default().to_owned();
        pcb.nets.insert(net_number(n, number)?, name);
    }
    for item in root.lists() {
        match item.keyword() {
            "footprint" | "module" => {
                let fp = footprint(item, &pcb.nets)?;
                for g in item.lists() {
                    if g.keyword().starts_with("fp_") && g.keyword() != "fp_text" && on_edge_cuts(g)
                    {
                        pcb.outline
                            .push(outline_shape(g, &|x, y| fp.to_board(x, y))?);
                    }
                }
                pcb.footprints.push(fp);
            }
            k if k.starts_with("gr_") && on_edge_cuts(item) => {
                pcb.outline.push(outline_shape(item, &|x, y| (x, y))?);
            }
            _ => {}
        }
    }
    Ok(pcb)
}

/// The `(version N)` of a file's root; 0 when absent.
pub(crate) fn version(root: Node<'_>) -> Result<u32, KicadError> {
    match root.get("version") {
        None => Ok(0),
        Some(v) => {
            let t = v.req_atom(0, "the version")?;
            t.parse().map_err(|_| v.invalid(t, "a version date code"))
        }
    }
}

fn net_number(n: Node<'_>, v: f64) -> Result<u32, KicadError> {
    if v >= 0.0 && v <= f64::from(u32::MAX) && v.fract() == 0.0 {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        Ok(v as u32)
    } else {
        Err(n.invalid(&v.to_string(), "a net number"))
    }
}

fn on_edge_cuts(item: Node<'_>) -> bool {
    item.get("layer").and_then(|l| l.atom(0)) == Some("Edge.Cuts")
}

fn footprint(f: Node<'_>, nets: &BTreeMap<u32, String>) -> Result<Footprint, KicadError> {
    let (x, y, rotation) = f.at()?;
    let layer = f.req("layer")?;
    let bottom = match layer.req_atom(0, "the footprint's layer")? {
        "F.Cu" => false,
        "B.Cu" => true,
        other => return Err(layer.invalid(other, "F.Cu or B.Cu")),
    };
    let text = |kind: &str| {
        f.all("fp_text")
            .find(|t| t.atom(0) == Some(kind))
            .and_then(|t| t.atom(1))
    };
    let mut fp = Footprint {
        reference: f
            .property("Reference")
            .or_else(|| text("reference"))
            .unwrap_or_default()
            .to_owned(),
        value: f
            .property("Value")
            .or_else(|| text("value"))
            .unwrap_or_default()
            .to_owned(),
        name: f.atom(0).unwrap_or_default().to_owned(),
        x,
        y,
        rotation,
        bottom,
        pads: Vec::new(),
    };
    for p in f.all("pad") {
        fp.pads.push(pad(p, nets)?);
    }
    Ok(fp)
}

fn pad(p: Node<'_>, nets: &BTreeMap<u32, String>) -> Result<Pad, KicadError> {
    let number = p.req_atom(0, "the pad number")?.to_owned();
    let kind_text = p.req_atom(1, "the pad kind")?;
    let kind = match kind_text {
        "smd" => PadKind::Smd,
        "thru_hole" => PadKind::ThroughHole,
        "np_thru_hole" => PadKind::NpThroughHole,
        "connect" => PadKind::Connect,
        other => {
            return Err(p.invalid(other, "smd, thru_hole, np_thru_hole or connect"));
        }
    };
    let (x, y, rotation) = p.at()?;
    let size = p.req("size")?;
    let (width, height) = (size.num(0, "a width, mm")?, size.num(1, "a height, mm")?);
    let shape = match p.req_atom(2, "the pad shape")? {
        "circle" => PadShape::Circle,
        "rect" => PadShape::Rect,
        "oval" => PadShape::Oval,
        "trapezoid" => PadShape::Trapezoid,
        "roundrect" => PadShape::RoundRect {
            ratio: match p.get("roundrect_rratio") {
                Some(r) => r.num(0, "a corner ratio")?,
                None => 0.25,
            },
        },
        "custom" => PadShape::Custom {
            bounds: custom_bounds(p, width, height)?,
        },
        other => {
            return Err(p.invalid(other, "circle, rect, oval, trapezoid, roundrect or custom"));
        }
    };
    let drill = match p.get("drill") {
        None => None,
        Some(d) => {
            let oval = d.atom(0) == Some("oval");
            let first = usize::from(oval);
            match d.opt_num(first, "a drill size, mm")? {
                None => None,
                Some(w) => Some((w, d.opt_num(first + 1, "a drill size, mm")?.unwrap_or(w))),
            }
        }
    };
    let layers = p
        .get("layers")
        .map(|l| l.atoms().map(|a| a.text.to_owned()).collect())
        .unwrap_or_default();
    let net = match p.get("net") {
        None => None,
        Some(n) => match (n.atom(0), n.atom(1)) {
            (Some(_), Some(name)) => Some(name.to_owned()),
            (Some(only), None) => match only.parse::<u32>() {
                // `(net N)` alone: the number's name from the board's list.
                Ok(num) => nets.get(&num).cloned(),
                Err(_) => Some(only.to_owned()),
            },
            _ => None,
        },
    }
    .filter(|n| !n.is_empty());
    Ok(Pad {
        number,
        kind,
        shape,
        width,
        height,
        x,
        y,
        rotation,
        drill,
        layers,
        net,
    })
}

/// The box covering a custom pad's anchor and primitives, pad frame.
fn custom_bounds(p: Node<'_>, width: f64, height: f64) -> Result<[f64; 4], KicadError> {
    let mut b = [-width / 2.0, -height / 2.0, width / 2.0, height / 2.0];
    let Some(prims) = p.get("primitives") else {
        return Ok(b);
    };
    for g in prims.lists() {
        let half = match g.get("width") {
            Some(w) => w.num(0, "a line width, mm")? / 2.0,
            None => 0.0,
        };
        let points = outline_shape(g, &|x, y| (x, y))?.extent_points();
        for (x, y) in points {
            b = [
                b[0].min(x - half),
                b[1].min(y - half),
                b[2].max(x + half),
                b[3].max(y + half),
            ];
        }
    }
    Ok(b)
}

/// A drawing (`gr_line`, `gr_arc`, `gr_circle`, `gr_rect`, `gr_poly` or their `fp_` forms),
/// its points mapped by `to`.
pub(crate) fn outline_shape(
    g: Node<'_>,
    to: &dyn Fn(f64, f64) -> (f64, f64),
) -> Result<OutlineShape, KicadError> {
    let pt = |k: &'static str| -> Result<(f64, f64), KicadError> {
        let (x, y) = g.point(k)?;
        Ok(to(x, y))
    };
    let kind = g.keyword().split_once('_').map_or("", |(_, k)| k);
    Ok(match kind {
        "line" => OutlineShape::Line {
            start: pt("start")?,
            end: pt("end")?,
        },
        "arc" => OutlineShape::Arc {
            start: pt("start")?,
            mid: pt("mid")?,
            end: pt("end")?,
        },
        "circle" => {
            let (cx, cy) = g.point("center")?;
            let (ex, ey) = g.point("end")?;
            OutlineShape::Circle {
                centre: to(cx, cy),
                radius: (ex - cx).hypot(ey - cy),
            }
        }
        "rect" => {
            let (x0, y0) = g.point("start")?;
            let (x1, y1) = g.point("end")?;
            OutlineShape::Polygon {
                points: vec![to(x0, y0), to(x1, y0), to(x1, y1), to(x0, y1)],
            }
        }
        "poly" => {
            let pts = g.req("pts")?;
            let mut points = Vec::new();
            for xy in pts.all("xy") {
                points.push(to(xy.num(0, "x, mm")?, xy.num(1, "y, mm")?));
            }
            OutlineShape::Polygon { points }
        }
        _ => OutlineShape::Polygon { points: Vec::new() },
    })
}
