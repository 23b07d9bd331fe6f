//! XML plumbing shared by the content-types, relationships and model readers: UTF-8 and DTD
//! checks, namespace classification, attribute iteration, positions and number parsing.

use std::borrow::Cow;

use quick_xml::NsReader;
use quick_xml::events::attributes::AttrError;
use quick_xml::events::{BytesStart, Event};
use quick_xml::name::{QName, ResolveResult};

use crate::error::{Location, ThreeMfError};

/// 3MF core namespace.
pub const NS_CORE: &str = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02";
/// Pre-1.0 (0.93 draft) core namespace, read as core.
pub const NS_LEGACY: &str = "http://schemas.microsoft.com/3dmanufacturing/2013/01";
/// Materials and properties extension.
pub const NS_MATERIAL: &str = "http://schemas.microsoft.com/3dmanufacturing/material/2015/02";
/// Production extension.
pub const NS_PRODUCTION: &str = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06";
/// Slice extension.
pub const NS_SLICE: &str = "http://schemas.microsoft.com/3dmanufacturing/slice/2015/07";
/// Beam lattice extension.
pub const NS_BEAM: &str = "http://schemas.microsoft.com/3dmanufacturing/beamlattice/2017/02";
/// Beam lattice balls extension.
pub const NS_BEAM_BALLS: &str =
    "http://schemas.microsoft.com/3dmanufacturing/beamlattice/balls/2020/07";
/// Secure content extension.
pub const NS_SECURE: &str = "http://schemas.microsoft.com/3dmanufacturing/securecontent/2019/04";
/// Volumetric extension draft used by lib3mf samples.
pub const NS_VOLUMETRIC_2015: &str =
    "http://schemas.microsoft.com/3dmanufacturing/volumetric/2015/02";
/// Triangle sets (core 1.3).
pub const NS_TRIANGLESETS: &str =
    "http://schemas.microsoft.com/3dmanufacturing/trianglesets/2021/07";
/// OPC markup compatibility.
pub const NS_MC: &str = "http://schemas.openxmlformats.org/markup-compatibility/2006";
/// The `xml:` namespace.
pub const NS_XML: &str = "http://www.w3.org/XML/1998/namespace";
/// OPC relationships.
pub const NS_RELS: &str = "http://schemas.openxmlformats.org/package/2006/relationships";
/// OPC content types.
pub const NS_CT: &str = "http://schemas.openxmlformats.org/package/2006/content-types";

/// Extensions a file may list in `requiredextensions` and still be read: conduit reads their
/// markup (materials, production, slice) or can ignore it without misreading the meshes
/// (beam lattice adds beams beside the mesh; secure content fails later if parts are encrypted;
/// the volumetric draft and triangle sets add data beside the mesh).
pub const SUPPORTED_REQUIRED: &[&str] = &[
    NS_CORE,
    NS_MATERIAL,
    NS_PRODUCTION,
    NS_SLICE,
    NS_BEAM,
    NS_BEAM_BALLS,
    NS_SECURE,
    NS_VOLUMETRIC_2015,
    NS_TRIANGLESETS,
];

/// Published 3MF namespaces conduit recognises but does not interpret (markup ignored).
const KNOWN_OTHER: &[&str] = &[
    NS_BEAM_BALLS,
    NS_SECURE,
    NS_VOLUMETRIC_2015,
    NS_TRIANGLESETS,
    "http://schemas.microsoft.com/3dmanufacturing/securecontent/2019/07",
    "http://schemas.microsoft.com/3dmanufacturing/core/2019/05",
    "http://schemas.3mf.io/3dmanufacturing/volumetric/2022/01",
    "http://schemas.3mf.io/3dmanufacturing/implicit/2023/12",
    "http://schemas.3mf.io/3dmanufacturing/booleanoperations/2023/07",
    "http://schemas.3mf.io/3dmanufacturing/displacement/2023/10",
    "http://schemas.microsoft.com/3dmanufacturing/2013/01/printticket",
];

/// Namespace class of an element or attribute name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ns {
    /// No namespace (unprefixed attribute, or element without default namespace).
    None,
    /// 3MF core (or the legacy 0.93 namespace).
    Core,
    /// Materials extension.
    Material,
    /// Production extension.
    Production,
    /// Slice extension.
    Slice,
    /// Beam lattice extension.
    Beam,
    /// Markup compatibility.
    Mc,
    /// `xml:`.
    Xml,
    /// `xmlns` declarations.
    Xmlns,
    /// A published 3MF namespace conduit ignores.
    KnownOther,
    /// A namespace under a 3MF URI space that conduit does not know.
    Unknown3mf,
    /// Any other (vendor) namespace.
    Vendor,
    /// A prefix with no binding in scope.
    Unbound,
}

/// Classifies a namespace URI.
pub fn classify(uri: &str) -> Ns {
    match uri {
        NS_CORE | NS_LEGACY => Ns::Core,
        NS_MATERIAL => Ns::Material,
        NS_PRODUCTION => Ns::Production,
        NS_SLICE => Ns::Slice,
        NS_BEAM => Ns::Beam,
        NS_MC => Ns::Mc,
        NS_XML => Ns::Xml,
        "http://www.w3.org/2000/xmlns/" => Ns::Xmlns,
        u if KNOWN_OTHER.contains(&u) => Ns::KnownOther,
        u if u.starts_with("http://schemas.microsoft.com/3dmanufacturing/")
            || u.starts_with("http://schemas.3mf.io/3dmanufacturing/") =>
        {
            Ns::Unknown3mf
        }
        _ => Ns::Vendor,
    }
}

fn classify_result(r: &ResolveResult<'_>) -> Ns {
    match r {
        ResolveResult::Unbound => Ns::None,
        ResolveResult::Bound(ns) => classify(ns.as_ref()),
        ResolveResult::Unknown(_) => Ns::Unbound,
    }
}

/// A parsed event of interest.
pub enum Ev<'a> {
    /// Start tag (children follow).
    Start(BytesStart<'a>),
    /// Empty-element tag.
    Empty(BytesStart<'a>),
    /// End tag.
    End,
    /// Character data (entities resolved).
    Text(Cow<'a, str>),
    /// End of document.
    Eof,
}

/// Checks the byte-level rules (UTF-8 only, no UTF-16/32 BOM) and returns the text without BOM.
pub fn utf8_text<'a>(part: &str, bytes: &'a [u8]) -> Result<&'a str, ThreeMfError> {
    let enc_err = |found: &str| ThreeMfError::Encoding {
        part: part.to_string(),
        found: found.to_string(),
    };
    if bytes.starts_with(&[0xFE, 0xFF]) || bytes.starts_with(&[0xFF, 0xFE]) {
        return Err(enc_err("UTF-16 byte order mark"));
    }
    if bytes.starts_with(&[0, 0]) || (bytes.len() > 1 && (bytes[0] == 0 || bytes[1] == 0)) {
        return Err(enc_err("UTF-16/32 encoded text"));
    }
    let bytes = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(bytes);
    std::str::from_utf8(bytes).map_err(|e| {
        enc_err(&format!(
            "invalid UTF-8 byte sequence at byte {}",
            e.valid_up_to()
        ))
    })
}

/// A namespace-aware pull reader over one XML part with 3MF's document-level rules applied:
/// UTF-8 only, no DTD, exactly one root element.
pub struct Xml<'a> {
    /// Part name, for errors.
    pub part: &'a str,
    text: &'a str,
    r: NsReader<&'a [u8]>,
    depth: usize,
    roots: usize,
    /// Byte offset where the last event started.
    pub pos: u64,
    /// Namespace URIs declared ignorable with `mc:Ignorable`.
    pub ignorable: Vec<String>,
    /// (byte offset, line at it, start of that line) of the last location computed.
    line_cache: std::cell::Cell<(usize, usize, usize)>,
}

impl<'a> Xml<'a> {
    /// Opens a part's bytes.
    pub fn new(part: &'a str, bytes: &'a [u8]) -> Result<Xml<'a>, ThreeMfError> {
        let text = utf8_text(part, bytes)?;
        let mut r = NsReader::from_str(text);
        let cfg = r.config_mut();
        cfg.trim_text(false);
        cfg.check_end_names = true;
        cfg.expand_empty_elements = false;
        Ok(Xml {
            part,
            text,
            r,
            depth: 0,
            roots: 0,
            pos: 0,
            ignorable: Vec::new(),
            line_cache: std::cell::Cell::new((0, 1, 0)),
        })
    }

    /// Location of byte offset `pos` in this part.
    pub fn loc_at(&self, pos: u64) -> Location {
        let pos = usize::try_from(pos)
            .unwrap_or(usize::MAX)
            .min(self.text.len());
        // Positions mostly grow, so count newlines from the last answer when possible: this
        // keeps recording locations (for references checked later) linear overall.
        let (mut from, mut line, mut line_start) = self.line_cache.get();
        if pos < from {
            (from, line, line_start) = (0, 1, 0);
        }
        for (i, &b) in self.text.as_bytes()[from..pos].iter().enumerate() {
            if b == b'\n' {
                line += 1;
                line_start = from + i + 1;
            }
        }
        self.line_cache.set((pos, line, line_start));
        let col = pos - line_start + 1;
        Location {
            part: self.part.to_string(),
            line: u32::try_from(line).unwrap_or(u32::MAX),
            column: u32::try_from(col).unwrap_or(u32::MAX),
        }
    }

    /// Location of the last event.
    pub fn loc(&self) -> Location {
        self.loc_at(self.pos)
    }

    /// An XML error at the last event.
    pub fn xml_err(&self, message: impl Into<String>) -> ThreeMfError {
        ThreeMfError::Xml {
            at: self.loc(),
            message: message.into(),
        }
    }

    fn map_qx(&self, e: quick_xml::Error) -> ThreeMfError {
        let pos = self.r.error_position();
        ThreeMfError::Xml {
            at: self.loc_at(pos),
            message: e.to_string(),
        }
    }

    /// Next event of interest (comments and processing instructions are skipped).
    pub fn next(&mut self) -> Result<Ev<'a>, ThreeMfError> {
        loop {
            self.pos = self.r.buffer_position();
            let ev = self.r.read_event().map_err(|e| self.map_qx(e))?;
            match ev {
                Event::Start(e) => {
                    self.open_element()?;
                    self.depth += 1;
                    return Ok(Ev::Start(e));
                }
                Event::Empty(e) => {
                    self.open_element()?;
                    return Ok(Ev::Empty(e));
                }
                Event::End(_) => {
                    self.depth = self.depth.saturating_sub(1);
                    return Ok(Ev::End);
                }
                Event::Text(t) => {
                    let s = t.xml10_content();
                    if self.depth == 0 {
                        if !s.chars().all(is_xml_ws) {
                            return Err(self.xml_err("text outside the root element"));
                        }
                        continue;
                    }
                    return Ok(Ev::Text(s));
                }
                Event::CData(t) => {
                    if self.depth == 0 {
                        return Err(self.xml_err("CDATA outside the root element"));
                    }
                    return Ok(Ev::Text(t.xml10_content()));
                }
                Event::GeneralRef(r) => {
                    if self.depth == 0 {
                        return Err(self.xml_err("entity reference outside the root element"));
                    }
                    let s: Cow<'a, str> = match r.resolve_char_ref() {
                        Ok(Some(c)) => Cow::Owned(c.to_string()),
                        Ok(None) => match &*r {
                            "lt" => Cow::Borrowed("<"),
                            "gt" => Cow::Borrowed(">"),
                            "amp" => Cow::Borrowed("&"),
                            "apos" => Cow::Borrowed("'"),
                            "quot" => Cow::Borrowed("\""),
                            other => {
                                return Err(
                                    self.xml_err(format!("undefined entity reference &{other};"))
                                );
                            }
                        },
                        Err(e) => return Err(self.map_qx(e)),
                    };
                    return Ok(Ev::Text(s));
                }
                Event::Decl(d) => {
                    if let Some(enc) = d.encoding() {
                        let enc = enc.map_err(|e| self.xml_err(e.to_string()))?;
                        if !enc.eq_ignore_ascii_case("utf-8") {
                            return Err(ThreeMfError::Encoding {
                                part: self.part.to_string(),
                                found: format!("declared encoding {enc:?}"),
                            });
                        }
                    }
                }
                Event::DocType(_) => {
                    return Err(self.xml_err("DTD (<!DOCTYPE>) is not allowed in 3MF"));
                }
                Event::Comment(_) | Event::PI(_) => {}
                Event::Eof => {
                    if self.depth != 0 {
                        return Err(self.xml_err("unexpected end of document"));
                    }
                    if self.roots == 0 {
                        return Err(self.xml_err("document has no root element"));
                    }
                    return Ok(Ev::Eof);
                }
            }
        }
    }

    fn open_element(&mut self) -> Result<(), ThreeMfError> {
        if self.depth == 0 {
            self.roots += 1;
            if self.roots > 1 {
                return Err(self.xml_err("more than one root element"));
            }
        }
        Ok(())
    }

    /// Namespace class and local name of an element.
    pub fn element_ns(&self, e: &BytesStart<'_>) -> Ns {
        let (r, _) = self.r.resolver().resolve_element(e.name());
        classify_result(&r)
    }

    /// Namespace URI (or `prefix:` for unbound ones) of a qualified name, for messages.
    pub fn ns_uri(&self, name: QName<'_>, element: bool) -> String {
        let (r, _) = if element {
            self.r.resolver().resolve_element(name)
        } else {
            self.r.resolver().resolve_attribute(name)
        };
        match r {
            ResolveResult::Bound(ns) => ns.as_ref().to_string(),
            ResolveResult::Unbound => String::new(),
            ResolveResult::Unknown(p) => format!("{p}:"),
        }
    }

    /// Resolves a prefix (from `requiredextensions` / `mc:Ignorable`) in the current scope.
    pub fn resolve_prefix(&self, prefix: &str) -> Option<String> {
        let qname = format!("{prefix}:x");
        let (r, _) = self.r.resolver().resolve_element(QName(&qname));
        match r {
            ResolveResult::Bound(ns) => Some(ns.as_ref().to_string()),
            _ => None,
        }
    }

    /// Calls `f(ns, local_name, value)` for each attribute of `e` (namespace declarations
    /// excluded). Duplicated attributes, malformed attributes and unbound prefixes are errors;
    /// attributes in unknown 3MF namespaces not declared ignorable are errors.
    pub fn attrs(
        &self,
        e: &BytesStart<'_>,
        mut f: impl FnMut(Ns, &str, Cow<'_, str>) -> Result<(), ThreeMfError>,
    ) -> Result<(), ThreeMfError> {
        for a in e.attributes() {
            let a = a.map_err(|err| match err {
                AttrError::Duplicated(pos, _) => {
                    let raw: &str = e;
                    let name: String = raw
                        .get(pos..)
                        .unwrap_or("")
                        .chars()
                        .take_while(|c| *c != '=' && !c.is_whitespace())
                        .collect();
                    self.xml_err(format!(
                        "duplicated attribute {name:?} on <{}>",
                        e.name().as_ref()
                    ))
                }
                other => self.xml_err(format!("attribute error: {other}")),
            })?;
            let key = a.key;
            if key.as_ref() == "xmlns" || key.as_ref().starts_with("xmlns:") {
                continue;
            }
            let (r, local) = self.r.resolver().resolve_attribute(key);
            let ns = classify_result(&r);
            match ns {
                Ns::Unbound => {
                    return Err(self.xml_err(format!(
                        "attribute {} uses an undeclared namespace prefix",
                        key.as_ref()
                    )));
                }
                Ns::Unknown3mf => {
                    let uri = self.ns_uri(key, false);
                    if !self.ignorable.contains(&uri) {
                        return Err(ThreeMfError::UnknownNamespace {
                            at: self.loc(),
                            what: format!("attribute {}", key.as_ref()),
                            namespace: uri,
                        });
                    }
                    continue;
                }
                _ => {}
            }
            let v = a
                .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                .map_err(|err| self.xml_err(format!("attribute value: {err}")))?;
            f(ns, local.as_ref(), v)?;
        }
        Ok(())
    }

    /// Skips the rest of an element whose `Start` was just returned, without resolving names
    /// inside it (markup conduit ignores is not checked further).
    pub fn skip(&mut self) -> Result<(), ThreeMfError> {
        let mut depth = 1usize;
        while depth > 0 {
            self.pos = self.r.buffer_position();
            match self.r.read_event().map_err(|e| self.map_qx(e))? {
                Event::Start(_) => depth += 1,
                Event::End(_) => depth -= 1,
                Event::DocType(_) => return Err(self.xml_err("DTD is not allowed in 3MF")),
                Event::Eof => return Err(self.xml_err("unexpected end of document")),
                _ => {}
            }
        }
        self.depth = self.depth.saturating_sub(1);
        Ok(())
    }
}

/// XML whitespace (space, tab, CR, LF).
pub fn is_xml_ws(c: char) -> bool {
    matches!(c, ' ' | '\t' | '\r' | '\n')
}

/// Parses an `xs:double` (leading/trailing XML whitespace allowed, `+1E+2` allowed);
/// rejects comma decimal separators, `NaN`/`INF` and anything else non-numeric.
pub fn parse_f64(s: &str) -> Result<f64, &'static str> {
    let t = s.trim_matches(is_xml_ws);
    if t.is_empty() {
        return Err("empty number");
    }
    if t.contains(',') {
        return Err("comma decimal separator (3MF numbers use '.')");
    }
    if !t
        .bytes()
        .all(|b| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E'))
    {
        return Err("not a number");
    }
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err("number out of range"),
        Err(_) => Err("not a number"),
    }
}

/// Parses a non-negative integer (`xs:nonNegativeInteger` that fits in `u32`).
pub fn parse_u32(s: &str) -> Result<u32, &'static str> {
    let t = s.trim_matches(is_xml_ws);
    let t = t.strip_prefix('+').unwrap_or(t);
    if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
        return Err("not a non-negative integer");
    }
    t.parse::<u32>().map_err(|_| "integer out of range")
}

/// Parses `#RRGGBB` or `#RRGGBBAA` into RGBA.
pub fn parse_color(s: &str) -> Result<[u8; 4], &'static str> {
    let t = s.trim_matches(is_xml_ws);
    let hex = t.strip_prefix('#').ok_or("colour must start with '#'")?;
    if !(hex.len() == 6 || hex.len() == 8) || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err("colour must be #RRGGBB or #RRGGBBAA");
    }
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).map_err(|_| "bad hex digit");
    Ok([
        byte(0)?,
        byte(2)?,
        byte(4)?,
        if hex.len() == 8 { byte(6)? } else { 255 },
    ])
}

/// Parses a 3MF `ST_Matrix3D`: exactly 12 numbers.
pub fn parse_matrix(s: &str) -> Result<[f64; 12], &'static str> {
    let mut m = [0.0; 12];
    let mut n = 0;
    for tok in s.split(is_xml_ws).filter(|t| !t.is_empty()) {
        if n == 12 {
            return Err("transform must have exactly 12 numbers");
        }
        m[n] = parse_f64(tok)?;
        n += 1;
    }
    if n != 12 {
        return Err("transform must have exactly 12 numbers");
    }
    Ok(m)
}

/// Truncates a value for error messages.
pub fn clip(s: &str) -> String {
    if s.chars().count() <= 64 {
        s.to_string()
    } else {
        let mut t: String = s.chars().take(61).collect();
        t.push_str("...");
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers() {
        assert_eq!(parse_f64(" +1E+2 "), Ok(100.0));
        assert_eq!(parse_f64(".1e3"), Ok(100.0));
        assert!(parse_f64("1,5").is_err());
        assert!(parse_f64("NaN").is_err());
        assert!(parse_f64("inf").is_err());
        assert!(parse_f64("abc").is_err());
        assert_eq!(parse_u32(" 7 "), Ok(7));
        assert!(parse_u32("-1").is_err());
        assert_eq!(parse_color("#0000FF"), Ok([0, 0, 255, 255]));
        assert_eq!(parse_color("#14C80A64"), Ok([0x14, 0xC8, 0x0A, 0x64]));
        assert!(parse_color("").is_err());
        assert!(parse_matrix("1 0 0 0 1 0 0 0 1 0 0").is_err());
    }

    #[test]
    fn locations_are_line_and_column() -> Result<(), ThreeMfError> {
        let x = Xml::new("/p", b"<a>\n  <b/>\n<c/></a>")?;
        let at = |pos| {
            let l = x.loc_at(pos);
            (l.line, l.column)
        };
        assert_eq!(at(0), (1, 1));
        assert_eq!(at(6), (2, 3));
        assert_eq!(at(11), (3, 1));
        assert_eq!(at(4), (2, 1)); // going back recomputes from the start
        assert_eq!(at(12), (3, 2));
        assert_eq!(x.loc_at(999).line, 3);
        Ok(())
    }

    #[test]
    fn rejects_second_root_and_dtd() -> Result<(), ThreeMfError> {
        let mut x = Xml::new("/a", b"<a/><b/>")?;
        assert!(matches!(x.next()?, Ev::Empty(_)));
        assert!(x.next().is_err());
        let mut x = Xml::new("/a", b"<!DOCTYPE a []><a/>")?;
        assert!(x.next().is_err());
        assert!(Xml::new("/a", &[0xFF, 0xFE, b'<', 0]).is_err());
        Ok(())
    }
}
