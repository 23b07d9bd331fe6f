//! OctoPNP's part description read back from a G-code file: the XML that the OctoPrint plugin
//! OctoPNP collects from comment lines to answer `M361 P<id>`, as conduit writes it after the
//! last layer (`<object>`, then per machine-placed part `<part id name>` with `<size height>`,
//! `<shape>` corners in the package frame and `<destination x y z orientation>`).
//!
//! Readers never panic; a block that is not well-formed XML is an error naming what is wrong.

/// One `<part>` of an OctoPNP block, as read back from a G-code file.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct OctoPart {
    /// The number its `M361 P<id>` event carries.
    pub id: u32,
    /// Part name.
    pub name: String,
    /// Body height, mm.
    pub height: f64,
    /// Outline corners in the package frame (mm, unrotated).
    pub shape: Vec<[f64; 2]>,
    /// Package origin on the seating plane, bed coordinates, mm.
    pub destination: [f64; 3],
    /// Rotation about +z, degrees.
    pub orientation: f64,
}

impl OctoPart {
    /// The outline in bed coordinates: rotated by the orientation about the destination.
    pub fn outline_on_bed(&self) -> Vec<[f64; 2]> {
        let [x, y, _] = self.destination;
        self.outline_at([x, y], self.orientation)
    }

    /// The outline with the package origin at `at` (bed x, y, mm), turned by `rotation_deg`.
    pub fn outline_at(&self, at: [f64; 2], rotation_deg: f64) -> Vec<[f64; 2]> {
        let (s, c) = rotation_deg.to_radians().sin_cos();
        self.shape
            .iter()
            .map(|&[u, v]| [at[0] + u * c - v * s, at[1] + u * s + v * c])
            .collect()
    }
}

/// Reads the OctoPNP block of a G-code file: the parts, in file order. `lines` are the raw
/// lines of the file; the text OctoPNP would collect ([`collected`]) is parsed as XML.
///
/// # Errors
/// The collected text is not well-formed XML, or a part lacks its name or destination: the
/// message says which.
pub fn read_block<'a>(lines: impl IntoIterator<Item = &'a [u8]>) -> Result<Vec<OctoPart>, String> {
    use quick_xml::events::Event;
    let mut text = Vec::new();
    for line in lines {
        if let Some(c) = collected(line) {
            text.extend_from_slice(c);
            text.push(b'\n');
        }
    }
    let mut parts = Vec::new();
    if text.is_empty() {
        return Ok(parts);
    }
    let text = String::from_utf8_lossy(&text);
    let mut reader = quick_xml::Reader::from_str(&text);
    let mut current: Option<(OctoPart, bool)> = None;
    let attr = |e: &quick_xml::events::BytesStart, key: &str| -> Option<String> {
        e.attributes()
            .flatten()
            .find(|a| a.key.local_name().as_ref() == key)
            .and_then(|a| {
                a.normalized_value(quick_xml::XmlVersion::Implicit1_0)
                    .ok()
                    .map(|v| v.into_owned())
            })
    };
    let attr_f64 = |e: &quick_xml::events::BytesStart, key: &str| -> Option<f64> {
        attr(e, key)?
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
    };
    loop {
        let event = reader
            .read_event()
            .map_err(|e| format!("OctoPNP block: {e}"))?;
        match event {
            Event::Eof => break,
            Event::Start(e) | Event::Empty(e) => match e.local_name().as_ref() {
                "part" => {
                    let name = attr(&e, "name").ok_or("OctoPNP block: a <part> has no name")?;
                    let id = attr_f64(&e, "id").unwrap_or(0.0) as u32;
                    current = Some((
                        OctoPart {
                            id,
                            name,
                            height: 0.0,
                            shape: Vec::new(),
                            destination: [0.0; 3],
                            orientation: 0.0,
                        },
                        false,
                    ));
                }
                "size" => {
                    if let Some((p, _)) = &mut current {
                        p.height = attr_f64(&e, "height").unwrap_or(0.0);
                    }
                }
                "point" => {
                    if let (Some((p, _)), Some(x), Some(y)) =
                        (&mut current, attr_f64(&e, "x"), attr_f64(&e, "y"))
                    {
                        p.shape.push([x, y]);
                    }
                }
                "destination" => {
                    if let Some((p, has)) = &mut current {
                        let xyz = ["x", "y", "z"].map(|k| attr_f64(&e, k));
                        if let [Some(x), Some(y), Some(z)] = xyz {
                            p.destination = [x, y, z];
                            p.orientation = attr_f64(&e, "orientation").unwrap_or(0.0);
                            *has = true;
                        }
                    }
                }
                _ => {}
            },
            Event::End(e) if e.local_name().as_ref() == "part" => {
                if let Some((p, has)) = current.take() {
                    if !has {
                        return Err(format!(
                            "OctoPNP block: part {} has no complete <destination>",
                            p.name
                        ));
                    }
                    parts.push(p);
                }
            }
            _ => {}
        }
    }
    Ok(parts)
}

/// What OctoPNP collects from one line of a G-code file: the text from its first `<` to its
/// last `>`, or `None` when the line has no `>` after a `<`.
///
/// ```
/// use conduit_pnp::octopnp::collected;
/// assert_eq!(collected(b";<size height=\"1\"/>"), Some(&b"<size height=\"1\"/>"[..]));
/// assert_eq!(collected(b"; end_gcode = {if max_layer_z < max_print_height}G1 Z5{endif}"), None);
/// ```
pub fn collected(line: &[u8]) -> Option<&[u8]> {
    let first = line.iter().position(|&b| b == b'<')?;
    let last = line.iter().rposition(|&b| b == b'>')?;
    line.get(first..=last).filter(|_| first < last)
}

#[cfg(test)]
mod tests {
    use super::*;

    const BLOCK: &str = ";<object name=\"block\">\n;<part id=\"2\" name=\"R1\">\n\
        ;  <position box=\"1\"/>\n;  <size height=\"0.6\"/>\n;  <shape>\n\
        ;    <point x=\"-1.45\" y=\"-0.65\"/>\n;    <point x=\"1.45\" y=\"-0.65\"/>\n\
        ;    <point x=\"1.45\" y=\"0.65\"/>\n;  </shape>\n\
        ;  <destination x=\"137\" y=\"118\" z=\"4\" orientation=\"90\"/>\n;</part>\n;</object>\n";

    #[test]
    fn the_block_reads_back_with_its_outline_on_the_bed() {
        let lines: Vec<&[u8]> = BLOCK.lines().map(str::as_bytes).collect();
        let parts = read_block(lines.iter().copied()).expect("well-formed");
        assert_eq!(parts.len(), 1);
        let r1 = &parts[0];
        assert_eq!((r1.id, r1.name.as_str(), r1.height), (2, "R1", 0.6));
        assert_eq!(r1.destination, [137.0, 118.0, 4.0]);
        assert_eq!(r1.shape.len(), 3);
        // A quarter turn: package (1.45, -0.65) lands at (137 + 0.65, 118 + 1.45).
        let on_bed = r1.outline_on_bed();
        assert!((on_bed[1][0] - 137.65).abs() < 1e-9 && (on_bed[1][1] - 119.45).abs() < 1e-9);
        assert_eq!(read_block(std::iter::empty()), Ok(Vec::new()));
        let broken = [&b";<object><part name=\"X\"></object>"[..]];
        assert!(read_block(broken.iter().copied()).is_err());
        let no_destination = [&b";<object><part name=\"X\"></part></object>"[..]];
        assert!(
            read_block(no_destination.iter().copied())
                .is_err_and(|e| e.contains("part X has no complete <destination>"))
        );
    }
}
