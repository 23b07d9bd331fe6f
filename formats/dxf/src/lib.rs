//! ASCII DXF reader for 2D designs: `LINE`, `LWPOLYLINE`, `POLYLINE` (with `VERTEX` and
//! `SEQEND`), `ARC` and `CIRCLE` entities of the `ENTITIES` section, flattened to polylines in
//! millimetres.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the
//! pipeline. `jet` takes the [`Design`] it returns (plain polylines) as its design input, as it
//! takes `conduit-svg`'s.
//!
//! A DXF file is a list of group-code / value line pairs; this reader needs five entity types
//! of it, so it reads the pairs itself rather than depending on a full DXF object model (the
//! `dxf` crate generates code for every entity and pulls in an image decoder and a date
//! library). Binary DXF is refused with [`DxfError::Binary`].
//!
//! # Units and geometry
//!
//! - Coordinates are scaled to millimetres by the header's `$INSUNITS` (1 inch, 2 feet,
//!   4 millimetres, 5 centimetres, 6 metres, 13 micrometres; 0 or missing = millimetres; other
//!   codes are refused with [`DxfError::Units`]). Y is up, as in DXF.
//! - Entities in other planes than XY are refused; an extrusion direction of (0, 0, −1) (a
//!   mirrored entity) is mirrored back (x → −x, the arbitrary-axis rule for that normal).
//! - Bulges of polyline segments and `ARC`s are flattened so that no point of the arc is
//!   farther than `tolerance_mm` from its chords; vertices lie on the arc, ends are exact.
//!   A `CIRCLE` is a closed path; an `ARC` runs counter-clockwise from its start angle.
//! - Closed paths do not repeat their first point; consecutive duplicate points are removed.
//! - Entities in `BLOCKS` and `INSERT` references are not drawn (counted in
//!   [`Design::skipped`], as are other entity types).
//!
//! # Example
//!
//! ```
//! let dxf = b"0\nSECTION\n2\nENTITIES\n0\nLINE\n8\nwalls\n10\n0\n20\n0\n11\n2\n21\n0\n0\nENDSEC\n0\nEOF\n";
//! let design = conduit_dxf::read(dxf, 0.001)?;
//! assert_eq!(design.paths[0].points, vec![[0.0, 0.0], [2.0, 0.0]]);
//! assert_eq!(design.paths[0].layer.as_deref(), Some("walls"));
//! # Ok::<(), conduit_dxf::DxfError>(())
//! ```

use std::f64::consts::PI;

/// Why a DXF file could not be read. Lines are 1-based lines of the file.
#[derive(Debug, thiserror::Error)]
pub enum DxfError {
    /// The file is binary DXF.
    ///
    /// How to fix: save the drawing as ASCII DXF.
    #[error("binary DXF is not supported; save the drawing as ASCII DXF")]
    Binary,
    /// The file is not text.
    ///
    /// How to fix: check that the file is a DXF drawing.
    #[error("line {line}: not UTF-8 or Latin-1 text")]
    NotText {
        /// The line.
        line: usize,
    },
    /// A group code is not an integer.
    ///
    /// How to fix: the file is damaged or not DXF; re-export it.
    #[error("line {line}: group code expected, found {text:?}")]
    BadCode {
        /// The line.
        line: usize,
        /// What was found.
        text: String,
    },
    /// A group value could not be read as a number.
    ///
    /// How to fix: correct the value in the named entity, or re-export the file.
    #[error("line {line}: {entity}: group {code} must be a number, found {text:?}")]
    BadNumber {
        /// The line of the value.
        line: usize,
        /// The entity being read.
        entity: String,
        /// The group code.
        code: i32,
        /// What was found.
        text: String,
    },
    /// An entity cannot be drawn (missing coordinates, zero radius, not in the XY plane).
    ///
    /// How to fix: correct or delete the named entity.
    #[error("line {line}: {entity}: {message}")]
    Entity {
        /// The line where the entity starts.
        line: usize,
        /// The entity type.
        entity: String,
        /// What is wrong.
        message: String,
    },
    /// `$INSUNITS` names a unit this reader does not convert.
    ///
    /// How to fix: set the drawing units to millimetres, micrometres, centimetres, metres or
    /// inches.
    #[error("$INSUNITS = {code} is not a supported unit (mm, µm, cm, m, inch, foot)")]
    Units {
        /// The unit code.
        code: i64,
    },
    /// The flattening tolerance is not a positive finite number.
    #[error("flattening tolerance must be > 0 mm, got {tolerance_mm}")]
    InvalidTolerance {
        /// The tolerance given.
        tolerance_mm: f64,
    },
    /// The file ends inside a group pair or a polyline.
    ///
    /// How to fix: the file is truncated; re-export it.
    #[error("line {line}: the file ends early ({context})")]
    Truncated {
        /// The last line.
        line: usize,
        /// What was being read.
        context: &'static str,
    },
}

/// One polyline of a design, in millimetres, y up.
#[derive(Debug, Clone, PartialEq)]
pub struct DxfPath {
    /// The entity type it came from (`LINE`, `LWPOLYLINE`, `POLYLINE`, `ARC`, `CIRCLE`).
    pub entity: &'static str,
    /// The entity's layer (group 8), when given.
    pub layer: Option<String>,
    /// The entity's handle (group 5), when given.
    pub handle: Option<String>,
    /// 1-based line of the file where the entity starts.
    pub line: usize,
    /// Vertices, mm. A closed path does not repeat its first point.
    pub points: Vec<[f64; 2]>,
    /// Whether the path closes back to its first point.
    pub closed: bool,
}

/// A 2D design read from DXF: its paths in file order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Design {
    /// Millimetres per drawing unit (from `$INSUNITS`).
    pub mm_per_unit: f64,
    /// The paths, in file order.
    pub paths: Vec<DxfPath>,
    /// Entities that were not drawn, by type, in order of first appearance, with counts.
    pub skipped: Vec<(String, usize)>,
}

/// One group: code, value text and the line of the value.
struct Pair {
    code: i32,
    value: String,
    line: usize,
}

fn pairs(bytes: &[u8]) -> Result<Vec<Pair>, DxfError> {
    if bytes.starts_with(b"AutoCAD Binary DXF") {
        return Err(DxfError::Binary);
    }
    let text: String = match std::str::from_utf8(bytes) {
        Ok(t) => t.to_owned(),
        // Older files are often Latin-1 (code page 1252); every byte is a character there.
        Err(_) => bytes.iter().map(|&b| char::from(b)).collect(),
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::with_capacity(lines.len() / 2);
    let mut i = 0;
    while i < lines.len() {
        let code_text = lines[i].trim();
        if code_text.is_empty() && i + 1 == lines.len() {
            break;
        }
        let code: i32 = code_text.parse().map_err(|_| DxfError::BadCode {
            line: i + 1,
            text: code_text.to_owned(),
        })?;
        let Some(value) = lines.get(i + 1) else {
            return Err(DxfError::Truncated {
                line: i + 1,
                context: "a group code without its value",
            });
        };
        out.push(Pair {
            code,
            value: value.trim().to_owned(),
            line: i + 2,
        });
        if code == 0 && value.trim() == "EOF" {
            break;
        }
        i += 2;
    }
    Ok(out)
}

/// An entity's groups, from its `0` pair to the next.
struct Entity<'a> {
    kind: &'a str,
    line: usize,
    groups: &'a [Pair],
}

impl Entity<'_> {
    fn num(&self, p: &Pair) -> Result<f64, DxfError> {
        p.value
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| DxfError::BadNumber {
                line: p.line,
                entity: self.kind.to_owned(),
                code: p.code,
                text: p.value.clone(),
            })
    }

    fn get(&self, code: i32) -> Result<Option<f64>, DxfError> {
        match self.groups.iter().find(|p| p.code == code) {
            Some(p) => self.num(p).map(Some),
            None => Ok(None),
        }
    }

    fn need(&self, code: i32) -> Result<f64, DxfError> {
        self.get(code)?
            .ok_or_else(|| self.error(format!("group {code} is missing")))
    }

    fn text(&self, code: i32) -> Option<String> {
        self.groups
            .iter()
            .find(|p| p.code == code)
            .map(|p| p.value.clone())
    }

    fn error(&self, message: String) -> DxfError {
        DxfError::Entity {
            line: self.line,
            entity: self.kind.to_owned(),
            message,
        }
    }

    /// +1 for the XY plane, −1 for the mirrored XY plane (extrusion (0, 0, −1)).
    fn mirror(&self) -> Result<f64, DxfError> {
        let (x, y, z) = (
            self.get(210)?.unwrap_or(0.0),
            self.get(220)?.unwrap_or(0.0),
            self.get(230)?.unwrap_or(1.0),
        );
        let n = (x * x + y * y + z * z).sqrt();
        if n > 0.0 && x.abs() / n < 1e-9 && y.abs() / n < 1e-9 {
            Ok(z.signum())
        } else {
            Err(self.error(format!(
                "extrusion direction ({x}, {y}, {z}) is not ±Z; only entities in the XY plane are read"
            )))
        }
    }
}

/// Largest coordinate (absolute, per axis) of a flattened point, mm: 10 m, beyond any bed or
/// substrate a design is printed on. A larger one is a stray value or a file in other units,
/// and every later step (fills, layers, lengths) would grow with it.
pub const MAX_EXTENT_MM: f64 = 10_000.0;

/// Largest bulge (tan of a quarter of the segment's sweep) of a polyline vertex, absolute: a
/// sweep of 359.9998°. A larger one puts the arc's centre at infinity or makes it non-finite.
pub const MAX_BULGE: f64 = 1e6;

/// Reads an ASCII DXF document into polylines in millimetres, flattening arcs and bulges so
/// that no point of a curve is farther than `tolerance_mm` from its polyline.
pub fn read(bytes: &[u8], tolerance_mm: f64) -> Result<Design, DxfError> {
    if !(tolerance_mm.is_finite() && tolerance_mm > 0.0) {
        return Err(DxfError::InvalidTolerance { tolerance_mm });
    }
    let pairs = pairs(bytes)?;
    let (entities, units) = entities_and_units(&pairs)?;
    let mm_per_unit = mm_per_unit(units)?;
    let tol = tolerance_mm / mm_per_unit;
    let mut design = Design {
        mm_per_unit,
        ..Design::default()
    };
    let mut k = 0;
    while k < entities.len() {
        let e = &entities[k];
        k += 1;
        let (entity, points, closed) = match e.kind {
            "LINE" => line(e)?,
            "CIRCLE" => circle(e, tol)?,
            "ARC" => arc(e, tol)?,
            "LWPOLYLINE" => lwpolyline(e, tol)?,
            "POLYLINE" => polyline(e, &entities, &mut k, tol)?,
            other => {
                match design.skipped.iter_mut().find(|(n, _)| n == other) {
                    Some((_, c)) => *c += 1,
                    None => design.skipped.push((other.to_owned(), 1)),
                }
                continue;
            }
        };
        let pts = in_millimetres(points, mm_per_unit, closed);
        if let Some(v) = pts
            .iter()
            .flatten()
            .find(|v| !v.is_finite() || v.abs() > MAX_EXTENT_MM)
        {
            return Err(e.error(format!(
                "a point at {v:e} mm is beyond the {MAX_EXTENT_MM} mm working extent (check the coordinates, radii, bulges and $INSUNITS)"
            )));
        }
        if pts.len() < 2 {
            continue;
        }
        design.paths.push(DxfPath {
            entity,
            layer: e.text(8),
            handle: e.text(5),
            line: e.line,
            points: pts,
            closed,
        });
    }
    Ok(design)
}

/// One entity flattened, in drawing units: its type name, points and whether it is closed.
type Flattened = (&'static str, Vec<[f64; 2]>, bool);

/// The entities of the `ENTITIES` section (spans from one `0` pair to the next) and the
/// header's `$INSUNITS` code (0 when missing).
fn entities_and_units(pairs: &[Pair]) -> Result<(Vec<Entity<'_>>, i64), DxfError> {
    let mut entities = Vec::new();
    let mut section = String::new();
    let mut units = 0i64;
    for (i, p) in pairs.iter().enumerate() {
        let end = pairs[i + 1..]
            .iter()
            .position(|q| q.code == 0)
            .map_or(pairs.len(), |k| i + 1 + k);
        if p.code == 0 {
            match p.value.as_str() {
                "SECTION" => {
                    section = pairs[i + 1..end]
                        .iter()
                        .find(|q| q.code == 2)
                        .map(|q| q.value.clone())
                        .unwrap_or_default();
                }
                "ENDSEC" => section.clear(),
                kind if section == "ENTITIES" => entities.push(Entity {
                    kind,
                    line: p.line.saturating_sub(1),
                    groups: &pairs[i + 1..end],
                }),
                _ => {}
            }
        } else if section == "HEADER" && p.code == 9 && p.value == "$INSUNITS" {
            if let Some(v) = pairs.get(i + 1).filter(|q| q.code == 70) {
                units = v.value.parse().map_err(|_| DxfError::BadNumber {
                    line: v.line,
                    entity: "$INSUNITS".to_owned(),
                    code: 70,
                    text: v.value.clone(),
                })?;
            }
        }
    }
    Ok((entities, units))
}

/// Millimetres per drawing unit of an `$INSUNITS` code.
fn mm_per_unit(units: i64) -> Result<f64, DxfError> {
    Ok(match units {
        0 | 4 => 1.0,
        1 => 25.4,
        2 => 304.8,
        5 => 10.0,
        6 => 1000.0,
        13 => 0.001,
        code => return Err(DxfError::Units { code }),
    })
}

/// A `LINE`: its two ends.
fn line(e: &Entity) -> Result<Flattened, DxfError> {
    let m = e.mirror()?;
    let a = [m * e.need(10)?, e.need(20)?];
    let b = [m * e.need(11)?, e.need(21)?];
    Ok(("LINE", vec![a, b], false))
}

/// The centre and radius of a `CIRCLE` or `ARC` (mirrored back into XY); the radius must be
/// positive.
fn centre_and_radius(e: &Entity, m: f64) -> Result<([f64; 2], f64), DxfError> {
    let (c, r) = ([m * e.need(10)?, e.need(20)?], e.need(40)?);
    if r <= 0.0 {
        return Err(e.error(format!("radius must be > 0, got {r}")));
    }
    // In drawing units, loose enough for a drawing in µm: this keeps the arc finite; its
    // points are held to the extent in mm once flattened.
    if r > MAX_EXTENT_MM * 1e3 {
        return Err(e.error(format!(
            "radius {r:e} is beyond the {MAX_EXTENT_MM} mm working extent"
        )));
    }
    Ok((c, r))
}

/// A `CIRCLE`: a closed path that does not repeat its first point.
fn circle(e: &Entity, tol: f64) -> Result<Flattened, DxfError> {
    let m = e.mirror()?;
    let (c, r) = centre_and_radius(e, m)?;
    let mut pts = arc_points(c, r, 0.0, 2.0 * PI, tol);
    pts.pop();
    Ok(("CIRCLE", pts, true))
}

/// An `ARC`, counter-clockwise from its start angle to its end angle (a full turn when they
/// are equal).
fn arc(e: &Entity, tol: f64) -> Result<Flattened, DxfError> {
    let m = e.mirror()?;
    let (c, r) = centre_and_radius(e, m)?;
    let (a0, a1) = (e.need(50)?.to_radians(), e.need(51)?.to_radians());
    let mut sweep = (a1 - a0).rem_euclid(2.0 * PI);
    if sweep == 0.0 {
        sweep = 2.0 * PI;
    }
    // Mirrored: angles are measured in the mirrored plane, so the arc runs
    // clockwise in XY from the mirrored start.
    let pts = if m < 0.0 {
        arc_points(c, r, PI - a0, -sweep, tol)
    } else {
        arc_points(c, r, a0, sweep, tol)
    };
    Ok(("ARC", pts, false))
}

/// An `LWPOLYLINE`: its vertices are `10`/`20` pairs in its own groups, each with an optional
/// bulge (`42`).
fn lwpolyline(e: &Entity, tol: f64) -> Result<Flattened, DxfError> {
    let m = e.mirror()?;
    let flags = e.get(70)?.unwrap_or(0.0) as i64;
    let mut verts: Vec<([f64; 2], f64)> = Vec::new();
    let mut x: Option<f64> = None;
    for p in e.groups {
        match p.code {
            10 => x = Some(m * e.num(p)?),
            20 => {
                let xv = x
                    .take()
                    .ok_or_else(|| e.error(format!("line {}: y (20) without x (10)", p.line)))?;
                verts.push(([xv, e.num(p)?], 0.0));
            }
            42 => {
                if let Some(v) = verts.last_mut() {
                    v.1 = m * bulge(e, e.num(p)?, p.line)?;
                }
            }
            _ => {}
        }
    }
    let closed = flags & 1 == 1;
    Ok(("LWPOLYLINE", bulged(&verts, closed, tol), closed))
}

/// `b`, the bulge read on `line` of entity `e`, when it is at most [`MAX_BULGE`].
fn bulge(e: &Entity, b: f64, line: usize) -> Result<f64, DxfError> {
    if b.abs() <= MAX_BULGE {
        Ok(b)
    } else {
        Err(e.error(format!(
            "line {line}: bulge {b:e} is beyond ±{MAX_BULGE:e} (a sweep of almost 360°)"
        )))
    }
}

/// A `POLYLINE`: its vertices are the `VERTEX` entities that follow it (from `entities[*k]`)
/// up to its `SEQEND`; `*k` is moved past the `SEQEND`.
fn polyline(
    e: &Entity,
    entities: &[Entity],
    k: &mut usize,
    tol: f64,
) -> Result<Flattened, DxfError> {
    let m = e.mirror()?;
    let flags = e.get(70)?.unwrap_or(0.0) as i64;
    if flags & (16 | 64) != 0 {
        return Err(e.error("polygon meshes and polyface meshes are not 2D designs".to_owned()));
    }
    let mut verts = Vec::new();
    loop {
        let Some(v) = entities.get(*k) else {
            return Err(DxfError::Truncated {
                line: e.line,
                context: "a POLYLINE without SEQEND",
            });
        };
        *k += 1;
        match v.kind {
            "VERTEX" => verts.push((
                [m * v.need(10)?, v.need(20)?],
                m * bulge(v, v.get(42)?.unwrap_or(0.0), v.line)?,
            )),
            "SEQEND" => break,
            other => {
                return Err(e.error(format!(
                    "{other} inside the polyline (expected VERTEX or SEQEND)"
                )));
            }
        }
    }
    let closed = flags & 1 == 1;
    Ok(("POLYLINE", bulged(&verts, closed, tol), closed))
}

/// `points` scaled to millimetres, without consecutive duplicates and, when `closed`, without
/// a repeated first point.
fn in_millimetres(points: Vec<[f64; 2]>, mm_per_unit: f64, closed: bool) -> Vec<[f64; 2]> {
    let mut pts: Vec<[f64; 2]> = Vec::with_capacity(points.len());
    for p in points {
        let q = [p[0] * mm_per_unit, p[1] * mm_per_unit];
        if pts.last() != Some(&q) {
            pts.push(q);
        }
    }
    if closed && pts.len() > 1 && pts.first() == pts.last() {
        pts.pop();
    }
    pts
}

/// Points of an arc of centre `c`, radius `r` from angle `a0` sweeping `sweep` (radians,
/// positive counter-clockwise), both ends included, chord deviation at most `tol`.
fn arc_points(c: [f64; 2], r: f64, a0: f64, sweep: f64, tol: f64) -> Vec<[f64; 2]> {
    let step = if tol >= r {
        PI / 2.0
    } else {
        (2.0 * (1.0 - tol / r).acos()).clamp(1e-4, PI / 2.0)
    };
    let n = ((sweep.abs() / step).ceil() as usize).max(1);
    (0..=n)
        .map(|i| {
            let a = a0 + sweep * i as f64 / n as f64;
            [c[0] + r * a.cos(), c[1] + r * a.sin()]
        })
        .collect()
}

/// A polyline's points with every bulged segment flattened (bulge = tan(sweep / 4), positive
/// counter-clockwise, stored on the segment's first vertex).
fn bulged(verts: &[([f64; 2], f64)], closed: bool, tol: f64) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    let n = verts.len();
    let segs = if closed { n } else { n.saturating_sub(1) };
    if let Some(v) = verts.first() {
        out.push(v.0);
    }
    for i in 0..segs {
        let (p0, b) = verts[i];
        let p1 = verts[(i + 1) % n].0;
        if b.abs() > 1e-12 {
            let (dx, dy) = (p1[0] - p0[0], p1[1] - p0[1]);
            let chord = dx.hypot(dy);
            if chord > 0.0 {
                // Centre on the left of the chord for a counter-clockwise (positive) bulge.
                let k = (1.0 - b * b) / (4.0 * b);
                let c = [
                    (p0[0] + p1[0]) / 2.0 - dy * k,
                    (p0[1] + p1[1]) / 2.0 + dx * k,
                ];
                let r = (p0[0] - c[0]).hypot(p0[1] - c[1]);
                let a0 = (p0[1] - c[1]).atan2(p0[0] - c[0]);
                let pts = arc_points(c, r, a0, 4.0 * b.atan(), tol);
                // Interior points; the end is the exact next vertex.
                out.extend_from_slice(&pts[1..pts.len() - 1]);
            }
        }
        out.push(p1);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_bulges_radii_and_coordinates_are_refused_by_entity() {
        let bulge =
            doc("0\nLWPOLYLINE\n8\n0\n90\n2\n70\n0\n10\n0\n20\n0\n42\n1e308\n10\n0\n20\n1\n");
        let e = read(&bulge, 0.01);
        assert!(
            matches!(&e, Err(DxfError::Entity { message, .. }) if message.contains("bulge")),
            "{e:?}"
        );
        let circle = doc("0\nCIRCLE\n8\n0\n10\n0\n20\n0\n40\n1e308\n");
        let e = read(&circle, 0.01);
        assert!(
            matches!(&e, Err(DxfError::Entity { message, .. }) if message.contains("radius")),
            "{e:?}"
        );
        let far = doc("0\nLINE\n8\n0\n10\n0\n20\n0\n11\n0\n21\n1e308\n");
        let e = read(&far, 0.01);
        assert!(
            matches!(&e, Err(DxfError::Entity { message, .. }) if message.contains("extent")),
            "{e:?}"
        );
    }

    fn doc(entities: &str) -> Vec<u8> {
        format!("0\nSECTION\n2\nENTITIES\n{entities}0\nENDSEC\n0\nEOF\n").into_bytes()
    }

    #[test]
    fn lwpolyline_with_a_semicircle_bulge_and_units() -> Result<(), DxfError> {
        // A 2 × 1 rectangle whose top edge is a half circle of radius 1 bulging up (bulge −1
        // going from (2, 1) to (0, 1) counter-clockwise would bulge down; +1 bulges up).
        let e = "0\nLWPOLYLINE\n90\n4\n70\n1\n10\n0\n20\n0\n10\n2\n20\n0\n10\n2\n20\n1\n42\n1\n10\n0\n20\n1\n";
        let d = read(&doc(e), 0.001)?;
        let p = &d.paths[0];
        assert!(p.closed);
        let top = p.points.iter().map(|q| q[1]).fold(f64::MIN, f64::max);
        assert!((top - 2.0).abs() < 1e-3, "top of the bulge {top}");
        for q in &p.points[3..p.points.len() - 1] {
            assert!(((q[0] - 1.0).hypot(q[1] - 1.0) - 1.0).abs() < 1e-12);
        }
        let head = "0\nSECTION\n2\nHEADER\n9\n$INSUNITS\n70\n13\n0\nENDSEC\n";
        let mut bytes = head.as_bytes().to_vec();
        bytes.extend(doc("0\nLINE\n10\n0\n20\n0\n11\n1000\n21\n0\n"));
        let d = read(&bytes, 0.001)?;
        assert_eq!(d.paths[0].points, vec![[0.0, 0.0], [1.0, 0.0]]);
        Ok(())
    }

    #[test]
    fn polyline_arc_circle_and_errors() -> Result<(), DxfError> {
        let e = "0\nPOLYLINE\n70\n1\n0\nVERTEX\n10\n0\n20\n0\n0\nVERTEX\n10\n1\n20\n0\n0\nVERTEX\n10\n1\n20\n1\n0\nSEQEND\n\
                 0\nARC\n10\n0\n20\n0\n40\n2\n50\n0\n51\n90\n0\nCIRCLE\n10\n5\n20\n5\n40\n1\n0\nTEXT\n1\nhi\n";
        let d = read(&doc(e), 0.0001)?;
        assert_eq!(d.paths.len(), 3);
        assert_eq!(d.paths[0].points.len(), 3);
        let arc = &d.paths[1];
        assert_eq!(arc.points[0], [2.0, 0.0]);
        let last = arc.points[arc.points.len() - 1];
        assert!(last[0].abs() < 1e-12 && (last[1] - 2.0).abs() < 1e-12);
        assert!(d.paths[2].closed);
        assert_eq!(d.skipped, vec![("TEXT".to_owned(), 1)]);
        let bad = read(&doc("0\nLINE\n10\nabc\n20\n0\n11\n1\n21\n0\n"), 0.001);
        assert!(matches!(
            bad,
            Err(DxfError::BadNumber {
                line: 8,
                code: 10,
                ..
            })
        ));
        let missing = read(&doc("0\nCIRCLE\n10\n0\n20\n0\n"), 0.001);
        assert!(matches!(missing, Err(DxfError::Entity { line: 5, .. })));
        assert!(matches!(
            read(b"AutoCAD Binary DXF\r\n", 0.001),
            Err(DxfError::Binary)
        ));
        Ok(())
    }
}
