//! A small element tree over `quick-xml` events.
//!
//! EAGLE files are a few megabytes at most, so the reader builds a tree of elements with their
//! attributes (text content is skipped: EAGLE keeps only descriptions and labels there) and the
//! byte offset of each start tag, from which error messages compute a line number.

use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};

use crate::error::EagleError;

/// Deepest element nesting accepted. EAGLE files nest about ten levels; the limit keeps the
/// recursive drop of a hostile, deeply nested input from overflowing the stack.
pub(crate) const MAX_DEPTH: usize = 256;

/// One XML element: name, attributes in document order, child elements and source offset.
#[derive(Debug, Clone)]
pub(crate) struct Node {
    pub(crate) name: String,
    pub(crate) attrs: Vec<(String, String)>,
    pub(crate) children: Vec<Node>,
    /// Byte offset of the `<` of the start tag in the input.
    pub(crate) pos: usize,
}

impl Node {
    /// The value of attribute `key`, if present.
    pub(crate) fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// Child elements named `name`.
    pub(crate) fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Node> {
        self.children.iter().filter(move |c| c.name == name)
    }

    /// The first child element named `name`.
    pub(crate) fn child(&self, name: &str) -> Option<&Node> {
        self.children.iter().find(|c| c.name == name)
    }

    /// Grandchildren reached through `outer/inner`, e.g. `("parts", "part")`.
    pub(crate) fn list<'a>(
        &'a self,
        outer: &'a str,
        inner: &'a str,
    ) -> impl Iterator<Item = &'a Node> {
        self.children_named(outer)
            .flat_map(move |c| c.children_named(inner))
    }
}

/// Parsed document plus the source needed to turn byte offsets into line numbers.
pub(crate) struct Doc<'a> {
    pub(crate) root: Node,
    src: &'a [u8],
}

impl Doc<'_> {
    /// 1-based line of a byte offset.
    pub(crate) fn line(&self, pos: usize) -> usize {
        line_of(self.src, pos)
    }
}

/// 1-based line number of byte offset `pos` in `src`.
pub(crate) fn line_of(src: &[u8], pos: usize) -> usize {
    let end = pos.min(src.len());
    src[..end].iter().filter(|&&b| b == b'\n').count() + 1
}

/// 1-based column (in bytes) of byte offset `pos` in `src`.
fn column_of(src: &[u8], pos: usize) -> usize {
    let end = pos.min(src.len());
    let line_start = src[..end]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    end - line_start + 1
}

/// Parses `src` (UTF-8, optional BOM) into an element tree.
pub(crate) fn parse(src: &[u8]) -> Result<Doc<'_>, EagleError> {
    let text = match std::str::from_utf8(src) {
        Ok(t) => t,
        Err(e) => {
            let pos = e.valid_up_to();
            return Err(EagleError::NotUtf8 {
                line: line_of(src, pos),
                column: column_of(src, pos),
            });
        }
    };
    let bom = if text.starts_with('\u{feff}') { 3 } else { 0 };
    let mut reader = quick_xml::Reader::from_str(&text[bom..]);
    let xml_err = |pos: usize, source: quick_xml::Error| EagleError::Xml {
        line: line_of(src, pos + bom),
        column: column_of(src, pos + bom),
        source,
    };

    // Stack of open elements; the bottom entry is a synthetic document node.
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
                if stack.len() > MAX_DEPTH {
                    return Err(EagleError::TooDeep {
                        line: line_of(src, before + bom),
                        limit: MAX_DEPTH,
                    });
                }
                let node = element(&e, before + bom).map_err(|e| xml_err(before, e))?;
                stack.push(node);
            }
            Event::Empty(e) => {
                let node = element(&e, before + bom).map_err(|e| xml_err(before, e))?;
                if let Some(parent) = stack.last_mut() {
                    parent.children.push(node);
                }
            }
            // quick-xml checks that end names match, so an open element is on the stack.
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
        return Err(EagleError::UnexpectedEof { element: open });
    }
    let document = stack.pop().ok_or(EagleError::UnexpectedEof {
        element: String::new(),
    })?;
    let mut elements = document.children.into_iter();
    let root = elements.next().ok_or(EagleError::NotEagle {
        found: String::new(),
    })?;
    Ok(Doc { root, src })
}

fn element(e: &BytesStart<'_>, pos: usize) -> Result<Node, quick_xml::Error> {
    let name = e.name().as_ref().to_owned();
    let mut attrs = Vec::new();
    for attr in e.attributes() {
        let attr = attr.map_err(quick_xml::Error::InvalidAttr)?;
        let key = attr.key.as_ref().to_owned();
        let value = attr.normalized_value(XmlVersion::Implicit1_0)?.into_owned();
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

impl Doc<'_> {
    /// A required attribute.
    pub(crate) fn req<'n>(&self, n: &'n Node, key: &'static str) -> Result<&'n str, EagleError> {
        n.attr(key).ok_or_else(|| EagleError::MissingAttribute {
            element: n.name.clone(),
            attribute: key,
            line: self.line(n.pos),
        })
    }

    fn invalid(
        &self,
        n: &Node,
        key: &'static str,
        value: &str,
        expected: &'static str,
    ) -> EagleError {
        EagleError::InvalidAttribute {
            element: n.name.clone(),
            attribute: key,
            value: value.to_owned(),
            expected,
            line: self.line(n.pos),
        }
    }

    /// A required finite number (mm or degrees).
    pub(crate) fn f64(&self, n: &Node, key: &'static str) -> Result<f64, EagleError> {
        let v = self.req(n, key)?;
        self.number(n, key, v)
    }

    /// An optional finite number.
    pub(crate) fn opt_f64(&self, n: &Node, key: &'static str) -> Result<Option<f64>, EagleError> {
        n.attr(key).map(|v| self.number(n, key, v)).transpose()
    }

    fn number(&self, n: &Node, key: &'static str, v: &str) -> Result<f64, EagleError> {
        match v.trim().parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(self.invalid(n, key, v, "a finite number")),
        }
    }

    /// An optional unsigned integer (layer numbers, net classes).
    pub(crate) fn opt_u32(&self, n: &Node, key: &'static str) -> Result<Option<u32>, EagleError> {
        n.attr(key)
            .map(|v| {
                v.trim()
                    .parse::<u32>()
                    .map_err(|_| self.invalid(n, key, v, "an unsigned integer"))
            })
            .transpose()
    }

    /// An optional integer (module instance offsets).
    pub(crate) fn opt_i64(&self, n: &Node, key: &'static str) -> Result<Option<i64>, EagleError> {
        n.attr(key)
            .map(|v| {
                v.trim()
                    .parse::<i64>()
                    .map_err(|_| self.invalid(n, key, v, "an integer"))
            })
            .transpose()
    }

    /// The `rot` attribute; `R0` when absent.
    pub(crate) fn rot(&self, n: &Node) -> Result<crate::Rotation, EagleError> {
        match n.attr("rot") {
            None => Ok(crate::Rotation::default()),
            Some(v) => crate::Rotation::parse(v)
                .map_err(|_| self.invalid(n, "rot", v, "a rotation [M][S]R<degrees>")),
        }
    }
}
