//! A small element tree over `quick-xml` events, with the byte offset of every start tag.

use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};

use crate::error::SvgError;

/// Deepest element nesting accepted; keeps recursion on hostile input off the stack limit.
pub(crate) const MAX_DEPTH: usize = 256;

/// One XML element.
#[derive(Debug, Clone)]
pub(crate) struct Node {
    /// Local name (namespace prefix removed: `svg:path` is `path`).
    pub(crate) name: String,
    /// Attributes in document order, keys as written (`xlink:href`).
    pub(crate) attrs: Vec<(String, String)>,
    pub(crate) children: Vec<Node>,
    /// Byte offset of the `<` of the start tag.
    pub(crate) pos: usize,
}

impl Node {
    pub(crate) fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// 1-based line number of byte offset `pos` in `src`.
pub(crate) fn line_of(src: &[u8], pos: usize) -> usize {
    let end = pos.min(src.len());
    memchr_count(&src[..end]) + 1
}

fn memchr_count(s: &[u8]) -> usize {
    s.iter().filter(|&&b| b == b'\n').count()
}

/// Parses `src` (UTF-8, optional BOM) into its root element.
pub(crate) fn parse(src: &[u8]) -> Result<Node, SvgError> {
    let text = std::str::from_utf8(src).map_err(|e| SvgError::NotUtf8 {
        offset: e.valid_up_to(),
        line: line_of(src, e.valid_up_to()),
    })?;
    let bom = if text.starts_with('\u{feff}') { 3 } else { 0 };
    let mut reader = quick_xml::Reader::from_str(&text[bom..]);
    let xml_err = |pos: usize, source: quick_xml::Error| SvgError::Xml {
        offset: pos + bom,
        line: line_of(src, pos + bom),
        source,
    };
    let mut stack: Vec<Node> = vec![Node {
        name: String::new(),
        attrs: Vec::new(),
        children: Vec::new(),
        pos: 0,
    }];
    loop {
        let before = to_usize(reader.buffer_position());
        let event = reader
            .read_event()
            .map_err(|e| xml_err(to_usize(reader.error_position()), e))?;
        match event {
            Event::Start(e) => {
                let node = element(&e, before + bom).map_err(|e| xml_err(before, e))?;
                if stack.len() > MAX_DEPTH {
                    return Err(SvgError::TooDeep {
                        element: node.name,
                        offset: before + bom,
                        line: line_of(src, before + bom),
                        limit: MAX_DEPTH,
                    });
                }
                stack.push(node);
            }
            Event::Empty(e) => {
                let node = element(&e, before + bom).map_err(|e| xml_err(before, e))?;
                if let Some(parent) = stack.last_mut() {
                    parent.children.push(node);
                }
            }
            Event::End(_) if stack.len() > 1 => {
                if let Some(done) = stack.pop() {
                    if let Some(parent) = stack.last_mut() {
                        parent.children.push(done);
                    }
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if stack.len() != 1 {
        let open = stack.last().map(|n| n.name.clone()).unwrap_or_default();
        return Err(SvgError::UnexpectedEof { element: open });
    }
    let document = stack.pop().map(|d| d.children).unwrap_or_default();
    let root = document.into_iter().next().ok_or(SvgError::NotSvg {
        root: String::new(),
    })?;
    if root.name != "svg" {
        return Err(SvgError::NotSvg { root: root.name });
    }
    Ok(root)
}

fn element(e: &BytesStart<'_>, pos: usize) -> Result<Node, quick_xml::Error> {
    let name = e.local_name().as_ref().to_owned();
    let mut attrs = Vec::new();
    for attr in e.attributes() {
        let attr = attr.map_err(quick_xml::Error::InvalidAttr)?;
        let key = attr.key.as_ref().to_owned();
        // Unknown entities (Illustrator's `&ns_svg;`) are not an error here: keep the raw text.
        let value = match attr.normalized_value(XmlVersion::Implicit1_0) {
            Ok(v) => v.into_owned(),
            Err(_) => attr.value.clone().into_owned(),
        };
        attrs.push((key, value));
    }
    Ok(Node {
        name,
        attrs,
        children: Vec::new(),
        pos,
    })
}

fn to_usize(v: u64) -> usize {
    usize::try_from(v).unwrap_or(usize::MAX)
}
