//! Electronic Slic3r's `.3de` files: part placement and wires saved next to an EAGLE
//! schematic by the Slic3r fork for printed electronics (github.com/platsch/Slic3r,
//! `Schematic::write3deFile`). Read into a [`Placement`], an input of the route stage.

use quick_xml::events::{BytesStart, Event};

use super::PinRef;
use super::placement::{
    Connection, Endpoint, NetRouting, Origin, PartPlacement, Placement, PlacementError,
    PlacingMethod, Waypoint,
};

impl Placement {
    /// Parses Electronic Slic3r's `.3de` XML:
    ///
    /// ```text
    /// <electronics version>
    ///   <filename source="board.sch"/>
    ///   <parts><part name library deviceset device package>
    ///     <attributes partHeight footprintHeight placed placingMethod connectionMethod/>
    ///     <position X Y Z/> <rotation X Y Z/>
    ///   </part></parts>
    ///   <nets><net name>
    ///     <waypoints><waypoint key><position X Y Z/></waypoint></waypoints>
    ///     <wires><wire>
    ///       <endpoint_a type="part"><part name pin/></endpoint_a>
    ///       <endpoint_b type="waypoint"><waypoint key/></endpoint_b>
    ///     </wire></wires>
    ///   </net></nets>
    /// </electronics>
    /// ```
    ///
    /// Positions are relative to the object's bounding-box centre ([`Origin::BboxCenter`]);
    /// `position` `Z` is the bottom of the part, `partHeight` its full height. `rotation` `Z`
    /// becomes `rotation`, `X` and `Y` the `tilt`. `placingMethod` is `Automatic`, `Manual` or
    /// `None`, `connectionMethod` `None`, `Layer` or `Part`. Parts with `placed` false (`0`,
    /// `false`) are not in the object: they are left out and named in [`Placement::skipped`]; a missing `attributes` element means
    /// placed, zero heights. Waypoints are named by their `key`; a part endpoint's `pin` may be a
    /// pad or schematic pin name.
    pub fn from_3de(xml: &str) -> Result<Self, PlacementError> {
        let root = parse_xml(xml)?;
        let err = |node: &Node, message: String| PlacementError::ThreeDe {
            line: node.line,
            message,
        };
        if root.name != "electronics" {
            return Err(err(
                &root,
                format!("expected <electronics>, found <{}>", root.name),
            ));
        }
        let mut out = Placement {
            origin: Origin::BboxCenter,
            source: root
                .child("filename")
                .and_then(|f| f.attr("source"))
                .map(str::to_owned),
            ..Placement::default()
        };
        for part in root.grandchildren("parts", "part") {
            let name = part.req("name")?.to_owned();
            let attrs = part.child("attributes");
            let attr = |key| attrs.and_then(|a| a.attr(key));
            if attr("placed").is_some_and(|v| !xml_bool(v)) {
                out.skipped.push(format!(
                    "part {name} is not placed in the object (placed=\"false\" in the .3de \
                     file): it gets no cavity, and its pins no traces"
                ));
                continue;
            }
            let pos = part
                .child("position")
                .ok_or_else(|| err(part, format!("part {name}: <position> is missing")))?;
            let [x, y, z] = pos.xyz()?;
            let [rx, ry, rz] = match part.child("rotation") {
                Some(r) => r.xyz()?,
                None => [0.0; 3],
            };
            let number = |key| match attr(key) {
                Some(v) => parse_f64(v).ok_or_else(|| {
                    err(
                        attrs.unwrap_or(part),
                        format!("{key}: invalid number \"{v}\""),
                    )
                }),
                None => Ok(0.0),
            };
            let method = match attr("placingMethod") {
                None | Some("Automatic") => PlacingMethod::Auto,
                Some("Manual") => PlacingMethod::Manual,
                Some("None") => PlacingMethod::None,
                Some(v) => return Err(err(part, format!("unknown placingMethod \"{v}\""))),
            };
            let connection = match attr("connectionMethod") {
                None | Some("None") => Connection::None,
                Some("Layer") => Connection::Layer,
                Some("Part") => Connection::Part,
                Some(v) => return Err(err(part, format!("unknown connectionMethod \"{v}\""))),
            };
            out.parts.push(PartPlacement {
                name,
                x,
                y,
                z,
                rotation: rz,
                tilt: [rx, ry],
                mirror: false,
                method,
                connection,
                body_height: number("partHeight")?,
                footprint_height: number("footprintHeight")?,
                body_size: None,
                object: 0,
            });
        }
        for net in root.grandchildren("nets", "net") {
            let mut routing = NetRouting {
                name: net.req("name")?.to_owned(),
                waypoints: Vec::new(),
                wires: Vec::new(),
            };
            for wp in net.grandchildren("waypoints", "waypoint") {
                let pos = wp
                    .child("position")
                    .ok_or_else(|| err(wp, "waypoint: <position> is missing".to_owned()))?;
                let [x, y, z] = pos.xyz()?;
                routing.waypoints.push(Waypoint {
                    name: wp.req("key")?.to_owned(),
                    x,
                    y,
                    z,
                    object: 0,
                });
            }
            for wire in net.grandchildren("wires", "wire") {
                let end = |tag: &str| -> Result<Endpoint, PlacementError> {
                    let e = wire
                        .child(tag)
                        .ok_or_else(|| err(wire, format!("wire: <{tag}> is missing")))?;
                    match e.req("type")? {
                        "part" => {
                            let p = e
                                .child("part")
                                .ok_or_else(|| err(e, format!("<{tag}>: <part> is missing")))?;
                            Ok(Endpoint::Pin(PinRef::new(p.req("name")?, p.req("pin")?)))
                        }
                        "waypoint" => {
                            let w = e
                                .child("waypoint")
                                .ok_or_else(|| err(e, format!("<{tag}>: <waypoint> is missing")))?;
                            Ok(Endpoint::Waypoint(w.req("key")?.to_owned()))
                        }
                        t => Err(err(e, format!("<{tag}>: unknown type \"{t}\""))),
                    }
                };
                routing.wires.push([end("endpoint_a")?, end("endpoint_b")?]);
            }
            out.nets.push(routing);
        }
        Ok(out)
    }
}

impl Placement {
    /// The placement as Electronic Slic3r's `.3de` XML (the layout [`Placement::from_3de`]
    /// reads), for `circuit` in an object whose model-space bounding box is `bbox`.
    ///
    /// `.3de` positions are from the object's bounding-box centre (z from its bottom), so a
    /// placement in model coordinates is moved by the box; one in that frame already is written
    /// as it is. The file has no room for a bottom-side mirror or a body outline: a mirrored
    /// part is written turned only. Parts in other objects than `bbox`'s are written in its
    /// frame too (a `.3de` file describes one object).
    pub fn to_3de(&self, circuit: &super::Circuit, bbox: &crate::geom::BoundingBox) -> String {
        use std::fmt::Write as _;
        let shift = match self.origin {
            Origin::Model => [
                (bbox.min[0] + bbox.max[0]) / 2.0,
                (bbox.min[1] + bbox.max[1]) / 2.0,
                bbox.min[2],
            ],
            Origin::BboxCenter => [0.0; 3],
        };
        let xyz = |x: f64, y: f64, z: f64| {
            format!(
                "X=\"{}\" Y=\"{}\" Z=\"{}\"",
                num(x - shift[0]),
                num(y - shift[1]),
                num(z - shift[2])
            )
        };
        let mut out = String::from("<?xml version=\"1.0\"?>\n<electronics version=\"1\">\n");
        if let Some(source) = &self.source {
            let _ = writeln!(out, "  <filename source=\"{}\"/>", attr(source));
        }
        out.push_str("  <parts>\n");
        for p in &self.parts {
            let package = circuit
                .part(&p.name)
                .map_or(String::new(), |c| c.package.clone());
            let _ = writeln!(
                out,
                "    <part name=\"{}\" package=\"{}\">",
                attr(&p.name),
                attr(&package)
            );
            let method = match p.method {
                PlacingMethod::Auto => "Automatic",
                PlacingMethod::Manual => "Manual",
                PlacingMethod::None => "None",
            };
            let connection = match p.connection {
                Connection::None => "None",
                Connection::Layer => "Layer",
                Connection::Part => "Part",
            };
            let _ = writeln!(
                out,
                "      <attributes partHeight=\"{}\" footprintHeight=\"{}\" placed=\"1\" \
                 placingMethod=\"{method}\" connectionMethod=\"{connection}\"/>",
                num(p.body_height),
                num(p.footprint_height)
            );
            let _ = writeln!(out, "      <position {}/>", xyz(p.x, p.y, p.z));
            let _ = writeln!(
                out,
                "      <rotation X=\"{}\" Y=\"{}\" Z=\"{}\"/>",
                num(p.tilt[0]),
                num(p.tilt[1]),
                num(p.rotation)
            );
            out.push_str("    </part>\n");
        }
        out.push_str("  </parts>\n  <nets>\n");
        for net in &self.nets {
            let _ = writeln!(out, "    <net name=\"{}\">", attr(&net.name));
            out.push_str("      <waypoints>\n");
            for w in &net.waypoints {
                let _ = writeln!(
                    out,
                    "        <waypoint key=\"{}\"><position {}/></waypoint>",
                    attr(&w.name),
                    xyz(w.x, w.y, w.z)
                );
            }
            out.push_str("      </waypoints>\n      <wires>\n");
            for [a, b] in &net.wires {
                let end = |tag: &str, e: &Endpoint| match e {
                    Endpoint::Pin(pin) => format!(
                        "<{tag} type=\"part\"><part name=\"{}\" pin=\"{}\"/></{tag}>",
                        attr(&pin.part),
                        attr(&pin.pad)
                    ),
                    Endpoint::Waypoint(key) => format!(
                        "<{tag} type=\"waypoint\"><waypoint key=\"{}\"/></{tag}>",
                        attr(key)
                    ),
                };
                let _ = writeln!(
                    out,
                    "        <wire>{}{}</wire>",
                    end("endpoint_a", a),
                    end("endpoint_b", b)
                );
            }
            out.push_str("      </wires>\n    </net>\n");
        }
        out.push_str("  </nets>\n</electronics>\n");
        out
    }
}

/// A number as the `.3de` writer writes it: shortest form that reads back exactly, `-0` as `0`.
fn num(v: f64) -> String {
    if v == 0.0 {
        "0".to_owned()
    } else {
        format!("{v}")
    }
}

/// `s` for a double-quoted XML attribute.
fn attr(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `pugixml`'s boolean reading, which Electronic Slic3r writes `placed` with: true when the
/// value starts with `1`, `t`, `T`, `y` or `Y`.
fn xml_bool(v: &str) -> bool {
    matches!(
        v.trim_start().bytes().next(),
        Some(b'1' | b't' | b'T' | b'y' | b'Y')
    )
}

fn parse_f64(v: &str) -> Option<f64> {
    v.trim().parse::<f64>().ok().filter(|f| f.is_finite())
}

/// A minimal element tree of a `.3de` document.
#[derive(Debug)]
struct Node {
    name: String,
    attrs: Vec<(String, String)>,
    children: Vec<Node>,
    line: usize,
}

impl Node {
    fn new(name: String, line: usize) -> Self {
        Node {
            name,
            attrs: Vec::new(),
            children: Vec::new(),
            line,
        }
    }

    fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    fn req(&self, key: &str) -> Result<&str, PlacementError> {
        self.attr(key).ok_or_else(|| PlacementError::ThreeDe {
            line: self.line,
            message: format!("<{}>: attribute {key} is missing", self.name),
        })
    }

    fn child(&self, name: &str) -> Option<&Node> {
        self.children.iter().find(|c| c.name == name)
    }

    fn grandchildren<'a>(&'a self, list: &'a str, item: &'a str) -> impl Iterator<Item = &'a Node> {
        self.children
            .iter()
            .filter(move |c| c.name == list)
            .flat_map(move |l| l.children.iter().filter(move |c| c.name == item))
    }

    /// The `X`, `Y`, `Z` attributes.
    fn xyz(&self) -> Result<[f64; 3], PlacementError> {
        let mut out = [0.0; 3];
        for (o, key) in out.iter_mut().zip(["X", "Y", "Z"]) {
            let v = self.req(key)?;
            *o = parse_f64(v).ok_or_else(|| PlacementError::ThreeDe {
                line: self.line,
                message: format!("<{}> attribute {key}: invalid number \"{v}\"", self.name),
            })?;
        }
        Ok(out)
    }
}

/// Deepest nesting accepted; `.3de` documents nest six levels.
const MAX_DEPTH: usize = 64;

/// Reads the element tree of a `.3de` document with quick-xml: elements and their attributes
/// (entities decoded), nothing else; errors carry the line.
fn parse_xml(xml: &str) -> Result<Node, PlacementError> {
    let src = xml.strip_prefix('\u{feff}').unwrap_or(xml);
    // Offsets of the line breaks, found once: every element asks for its line.
    let newlines: Vec<usize> = src
        .bytes()
        .enumerate()
        .filter(|(_, b)| *b == b'\n')
        .map(|(i, _)| i)
        .collect();
    let line_of = |pos: u64| {
        let pos = usize::try_from(pos).unwrap_or(usize::MAX);
        newlines.partition_point(|&nl| nl < pos) + 1
    };
    let fail = |pos: u64, message: String| PlacementError::ThreeDe {
        line: line_of(pos),
        message,
    };
    let element = |e: &BytesStart<'_>, pos: u64| -> Result<Node, PlacementError> {
        let name = e.local_name().as_ref().to_owned();
        let mut node = Node::new(name, line_of(pos));
        for a in e.attributes() {
            let a = a.map_err(|err| fail(pos, format!("<{}>: {err}", node.name)))?;
            let value = a
                .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                .map_err(|err| fail(pos, format!("<{}>: {err}", node.name)))?;
            let key = a.key.local_name().as_ref().to_owned();
            node.attrs.push((key, value.into_owned()));
        }
        Ok(node)
    };
    let mut reader = quick_xml::Reader::from_str(src);
    reader.config_mut().check_end_names = true;
    let mut stack = vec![Node::new(String::new(), 1)];
    loop {
        let pos = reader.buffer_position();
        match reader.read_event() {
            Err(e) => return Err(fail(reader.error_position(), e.to_string())),
            Ok(Event::Start(e)) => {
                if stack.len() > MAX_DEPTH {
                    return Err(fail(pos, "elements nested too deep".to_owned()));
                }
                stack.push(element(&e, pos)?);
            }
            Ok(Event::Empty(e)) => {
                let node = element(&e, pos)?;
                if let Some(parent) = stack.last_mut() {
                    parent.children.push(node);
                }
            }
            Ok(Event::End(_)) => {
                if stack.len() < 2 {
                    return Err(fail(pos, "closing tag without an open element".to_owned()));
                }
                if let Some(done) = stack.pop()
                    && let Some(parent) = stack.last_mut()
                {
                    parent.children.push(done);
                }
            }
            Ok(Event::Eof) => break,
            Ok(_) => {}
        }
    }
    if let [_, .., open] = stack.as_slice() {
        return Err(fail(
            src.len() as u64,
            format!("unexpected end of file inside <{}>", open.name),
        ));
    }
    stack
        .pop()
        .and_then(|d| d.children.into_iter().next())
        .ok_or_else(|| fail(0, "no root element".to_owned()))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::circuit::placement::tests::err_text;
    use crate::circuit::tests::sample;

    pub(crate) const THREE_DE: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<electronics version="0.1">
  <filename source="led_coin.sch"/>
  <parts>
    <part name="LED1" library="conduit_demo" deviceset="LED" device="" package="LED-0805">
      <attributes partHeight="1" footprintHeight="0.2" placed="1" placingMethod="Manual" connectionMethod="Layer"/>
      <position X="12" Y="7" Z="4"/>
      <rotation X="0" Y="0" Z="90"/>
    </part>
    <part name="R1" library="conduit_demo" deviceset="R" device="" package="R0805">
      <attributes partHeight="0.6" footprintHeight="0.2" placed="0" placingMethod="Automatic" connectionMethod="None"/>
      <position X="0" Y="0" Z="0"/>
      <rotation X="0" Y="0" Z="0"/>
    </part>
    <part name="BAT1" library="conduit_demo" deviceset="CR2032" device="" package="CR2032-SMD">
      <attributes partHeight="3.2" footprintHeight="0.2" placed="true" placingMethod="Automatic" connectionMethod="Part"/>
      <position X="-6" Y="0" Z="4"/>
      <rotation X="0" Y="0" Z="0"/>
    </part>
  </parts>
  <nets>
    <net name="GND">
      <waypoints>
        <waypoint key="7"><position X="5" Y="-10" Z="4.5"/></waypoint>
      </waypoints>
      <wires>
        <wire>
          <endpoint_a type="part"><part name="LED1" pin="C"/></endpoint_a>
          <endpoint_b type="waypoint"><waypoint key="7"/></endpoint_b>
        </wire>
        <wire>
          <endpoint_a type="waypoint"><waypoint key="7"/></endpoint_a>
          <endpoint_b type="part"><part name="BAT1" pin="-"/></endpoint_b>
        </wire>
      </wires>
    </net>
  </nets>
</electronics>
"#;

    #[test]
    fn three_de_document_reads_parts_waypoints_and_wires() {
        let p = match Placement::from_3de(THREE_DE) {
            Ok(p) => p,
            Err(e) => panic!("{e}"),
        };
        assert_eq!(p.origin, Origin::BboxCenter);
        assert_eq!(p.source.as_deref(), Some("led_coin.sch"));
        // R1 is not placed (placed="0").
        let names: Vec<&str> = p.parts.iter().map(|q| q.name.as_str()).collect();
        assert_eq!(names, ["LED1", "BAT1"]);
        let led = p.part("LED1").cloned();
        assert_eq!(
            led.map(|l| (l.x, l.y, l.z, l.rotation, l.tilt, l.method, l.connection)),
            Some((
                12.0,
                7.0,
                4.0,
                90.0,
                [0.0, 0.0],
                PlacingMethod::Manual,
                Connection::Layer
            ))
        );
        let bat = p.part("BAT1").cloned();
        assert_eq!(
            bat.map(|b| (b.body_height, b.footprint_height, b.connection)),
            Some((3.2, 0.2, Connection::Part))
        );
        let gnd = p.net("GND").cloned();
        let Some(gnd) = gnd else { panic!() };
        assert_eq!(
            gnd.waypoints,
            [Waypoint {
                name: "7".into(),
                x: 5.0,
                y: -10.0,
                z: 4.5,
                object: 0
            }]
        );
        assert_eq!(
            gnd.wires,
            [
                [
                    Endpoint::Pin(PinRef::new("LED1", "C")),
                    Endpoint::Waypoint("7".into())
                ],
                [
                    Endpoint::Waypoint("7".into()),
                    Endpoint::Pin(PinRef::new("BAT1", "-"))
                ],
            ]
        );
        assert!(p.validate(&sample()).is_ok());
        // Resolved against a 40 x 30 x 8 block standing on z = 2: centre (20, 15), bottom 2.
        let bb = crate::geom::BoundingBox {
            min: [0.0, 0.0, 2.0],
            max: [40.0, 30.0, 10.0],
        };
        let m = match p.to_model(&[bb]) {
            Ok(m) => m,
            Err(e) => panic!("{e}"),
        };
        assert_eq!(m.origin, Origin::Model);
        assert_eq!(
            m.part("LED1").map(|l| (l.x, l.y, l.z)),
            Some((32.0, 22.0, 6.0))
        );
        assert_eq!(
            m.part("BAT1").map(|l| (l.x, l.y, l.z)),
            Some((14.0, 15.0, 6.0))
        );
        let w = m
            .net("GND")
            .map(|n| (n.waypoints[0].x, n.waypoints[0].y, n.waypoints[0].z));
        assert_eq!(w, Some((25.0, 5.0, 6.5)));
        assert!(err_text(p.to_model(&[])).contains("object 0 does not exist"));
    }

    #[test]
    fn three_de_errors_carry_the_line() {
        let bad = THREE_DE.replace("Y=\"7\"", "Y=\"seven\"");
        let msg = err_text(Placement::from_3de(&bad));
        assert!(msg.starts_with("line 7:") && msg.contains("seven"), "{msg}");
        let msg = err_text(Placement::from_3de("<electronics><parts>"));
        assert!(msg.contains("line 1"), "{msg}");
        let msg = err_text(Placement::from_3de("<eagle/>"));
        assert!(msg.contains("expected <electronics>"), "{msg}");
    }

    #[test]
    fn xml_reader_skips_markup_and_decodes_entities() {
        let doc = "\u{feff}<?xml version=\"1.0\"?>\n<!DOCTYPE electronics>\n<!-- c <x> -->\n\
                   <electronics a='1 &lt;2&gt; &amp; &quot;&apos; &#65;&#x42;'>text<![CDATA[<no/>]]>\n\
                   <parts >\n<part name = \"R1\" /></parts></electronics>";
        let root = match parse_xml(doc) {
            Ok(r) => r,
            Err(e) => panic!("{e}"),
        };
        assert_eq!(root.attr("a"), Some("1 <2> & \"' AB"));
        let part = root.grandchildren("parts", "part").next();
        assert_eq!(
            part.map(|p| (p.attr("name"), p.line)),
            Some((Some("R1"), 6))
        );
        // quick-xml's own findings: reported with a line, whatever its wording.
        for bad in [
            "<a>\n<b></a>",
            "<a x=1/>",
            "<a x='&bogus;'/>",
            "<a\n",
            "<!-- open",
        ] {
            let msg = err_text(parse_xml(bad));
            assert!(msg.starts_with("line "), "{bad:?}: {msg}");
        }
        // Ours.
        for (bad, line, what) in [
            ("<a>\n<b>", 2, "end of file inside <b>"),
            ("just text", 1, "no root element"),
        ] {
            let msg = err_text(parse_xml(bad));
            assert!(
                msg.starts_with(&format!("line {line}:")) && msg.contains(what),
                "{bad:?}: {msg}"
            );
        }
        let deep = "<a>".repeat(100);
        assert!(err_text(parse_xml(&deep)).contains("nested too deep"));
    }

    #[test]
    fn written_3de_reads_back_as_the_same_placement() {
        let mut p = Placement::from_3de(THREE_DE).expect("reads");
        p.skipped.clear();
        let circuit = sample();
        let bbox = crate::geom::BoundingBox {
            min: [0.0, 0.0, 0.0],
            max: [40.0, 30.0, 8.0],
        };
        // Already in the bounding-box frame: written as it is.
        let xml = p.to_3de(&circuit, &bbox);
        assert!(
            xml.contains(r#"<part name="LED1" package="LED-0805">"#),
            "{xml}"
        );
        assert_eq!(Placement::from_3de(&xml).expect("reads back"), p);
        // In model coordinates: moved by the box's centre and bottom.
        let mut model = p.clone();
        model.origin = Origin::Model;
        for part in &mut model.parts {
            part.x += 20.0;
            part.y += 15.0;
        }
        for w in model.nets.iter_mut().flat_map(|n| &mut n.waypoints) {
            w.x += 20.0;
            w.y += 15.0;
        }
        assert_eq!(
            Placement::from_3de(&model.to_3de(&circuit, &bbox)).expect("reads back"),
            p
        );
    }
}
