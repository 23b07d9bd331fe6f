//! Element tree over `quick-xml` events, shared by conduit's XML readers.
//!
//! Part of conduit's `formats/` layer, underneath the readers: `conduit-eagle` and
//! `conduit-svg` turn their input into a [`Node`] tree with [`parse`], walk the tree, and map
//! [`XmlError`] into their own error types, with 1-based lines and columns from [`line_of`] and
//! [`column_of`].
//!
//! The tree keeps elements only: their names, attributes in document order, child elements and
//! the byte offset of each start tag. Text, comments, CDATA, processing instructions and the
//! DOCTYPE are skipped. The input is UTF-8 with an optional byte order mark; offsets count bytes
//! of the whole input, BOM included.
//!
//! Element nesting is bounded by [`Options::max_depth`], so that dropping (or recursively
//! walking) the tree of a hostile, deeply nested input cannot overflow the stack.
//!
//! ```
//! use conduit_xml::{DepthCheck, Entities, Names, Options, parse};
//!
//! let options = Options {
//!     names: Names::Local,
//!     entities: Entities::Strict,
//!     depth_check: DepthCheck::BeforeAttributes,
//!     max_depth: 256,
//! };
//! let src = b"<svg:svg>\n  <svg:g id=\"a&amp;b\"/>\n</svg:svg>";
//! let root = parse(src, &options)?.expect("one element");
//! assert_eq!(root.name, "svg");
//! let g = &root.children[0];
//! assert_eq!((g.name.as_str(), g.attr("id")), ("g", Some("a&b")));
//! assert_eq!((conduit_xml::line_of(src, g.pos), conduit_xml::column_of(src, g.pos)), (2, 3));
//! # Ok::<(), conduit_xml::XmlError>(())
//! ```

use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};

/// How [`Node::name`] spells an element's name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Names {
    /// As written, namespace prefix included (`svg:path`).
    Qualified,
    /// Without the namespace prefix (`svg:path` is `path`).
    Local,
}

/// What becomes of an attribute value that does not decode: one with an entity reference other
/// than the five predefined ones (`&amp;` `&lt;` `&gt;` `&apos;` `&quot;`) and character
/// references, or with a malformed reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Entities {
    /// The document is rejected with [`XmlError::Syntax`] at the element's start tag.
    Strict,
    /// The value is kept exactly as written, with none of its references decoded (Illustrator
    /// writes attributes such as `xmlns:x="&ns_svg;"`). Values that decode are decoded.
    KeepRaw,
}

/// Which error an element reports when it opens one level deeper than [`Options::max_depth`]
/// and its attributes are malformed as well.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DepthCheck {
    /// The depth is checked first: [`XmlError::TooDeep`].
    BeforeAttributes,
    /// The attributes are read first: [`XmlError::Syntax`].
    AfterAttributes,
}

/// How [`parse`] builds the tree: the choices in which the readers differ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Options {
    /// How element names are stored.
    pub names: Names,
    /// What an attribute value that does not decode becomes.
    pub entities: Entities,
    /// Which error wins at an element that is both too deep and malformed.
    pub depth_check: DepthCheck,
    /// Most elements open at once (an element nested `max_depth + 1` levels deep is an error).
    /// Only elements with content count: a self-closing element (`<a/>`) one level deeper is
    /// accepted.
    pub max_depth: usize,
}

/// Why [`parse`] failed. Offsets are bytes of the whole input, BOM included.
#[derive(Debug, thiserror::Error)]
pub enum XmlError {
    /// The input is not UTF-8.
    #[error("not UTF-8: invalid byte at offset {offset}")]
    NotUtf8 {
        /// Byte offset of the first invalid byte.
        offset: usize,
    },
    /// The XML is malformed (including attributes and, with [`Entities::Strict`], their
    /// references).
    #[error("malformed XML at byte {offset}: {source}")]
    Syntax {
        /// Where quick-xml found the problem; for an attribute, the `<` of its start tag.
        offset: usize,
        /// What quick-xml reported.
        #[source]
        source: quick_xml::Error,
    },
    /// An element opens deeper than [`Options::max_depth`].
    #[error("<{element}> at byte {offset} nests deeper than {limit} elements")]
    TooDeep {
        /// Its name, spelled per [`Options::names`].
        element: String,
        /// Byte offset of the `<` of its start tag.
        offset: usize,
        /// The limit, [`Options::max_depth`].
        limit: usize,
    },
    /// The input ended while an element was still open.
    #[error("input ends inside <{element}>")]
    UnexpectedEof {
        /// The innermost element still open.
        element: String,
    },
}

/// One XML element: name, attributes in document order, child elements and source offset.
#[derive(Debug, Clone, Default)]
pub struct Node {
    /// Element name, spelled per [`Options::names`].
    pub name: String,
    /// Attributes in document order, keys as written (`xlink:href`), values decoded.
    pub attrs: Vec<(String, String)>,
    /// Child elements in document order.
    pub children: Vec<Node>,
    /// Byte offset of the `<` of the start tag in the input.
    pub pos: usize,
}

impl Node {
    /// The value of attribute `key`, if present (the first one if repeated).
    pub fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// Child elements named `name`.
    pub fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Node> {
        self.children.iter().filter(move |c| c.name == name)
    }

    /// The first child element named `name`.
    pub fn child(&self, name: &str) -> Option<&Node> {
        self.children.iter().find(|c| c.name == name)
    }

    /// Grandchildren reached through `outer/inner`, e.g. `("parts", "part")`.
    pub fn list<'a>(&'a self, outer: &'a str, inner: &'a str) -> impl Iterator<Item = &'a Node> {
        self.children_named(outer)
            .flat_map(move |c| c.children_named(inner))
    }
}

/// 1-based line number of byte offset `pos` in `src` (offsets past the end count as the end).
pub fn line_of(src: &[u8], pos: usize) -> usize {
    let end = pos.min(src.len());
    src[..end].iter().filter(|&&b| b == b'\n').count() + 1
}

/// 1-based column, in bytes, of byte offset `pos` in `src` (offsets past the end count as the
/// end).
pub fn column_of(src: &[u8], pos: usize) -> usize {
    let end = pos.min(src.len());
    let line_start = src[..end]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    end - line_start + 1
}

/// Parses `src` (UTF-8, optional BOM) into its first top-level element; `None` when the input
/// has no element at all.
///
/// The whole input is read, so a malformed part after the first element is still an error.
pub fn parse(src: &[u8], options: &Options) -> Result<Option<Node>, XmlError> {
    let text = std::str::from_utf8(src).map_err(|e| XmlError::NotUtf8 {
        offset: e.valid_up_to(),
    })?;
    let bom = if text.starts_with('\u{feff}') { 3 } else { 0 };
    let mut reader = quick_xml::Reader::from_str(&text[bom..]);
    let syntax = |pos: usize, source: quick_xml::Error| XmlError::Syntax {
        offset: pos + bom,
        source,
    };
    let too_deep = |element: String, offset: usize| XmlError::TooDeep {
        element,
        offset,
        limit: options.max_depth,
    };

    // Stack of open elements; the bottom entry is a synthetic document node.
    let mut stack: Vec<Node> = vec![Node::default()];
    loop {
        let before = to_usize(reader.buffer_position());
        let event = reader
            .read_event()
            .map_err(|e| syntax(to_usize(reader.error_position()), e))?;
        match event {
            Event::Start(e) => {
                let pos = before + bom;
                let full = stack.len() > options.max_depth;
                if full && options.depth_check == DepthCheck::BeforeAttributes {
                    return Err(too_deep(name(&e, options.names), pos));
                }
                let node = element(&e, pos, options).map_err(|e| syntax(before, e))?;
                if full {
                    return Err(too_deep(node.name, pos));
                }
                stack.push(node);
            }
            Event::Empty(e) => {
                let node = element(&e, before + bom, options).map_err(|e| syntax(before, e))?;
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
        return Err(XmlError::UnexpectedEof { element: open });
    }
    let document = stack.pop().map(|d| d.children).unwrap_or_default();
    Ok(document.into_iter().next())
}

/// The element's name, spelled per `names`.
fn name(e: &BytesStart<'_>, names: Names) -> String {
    match names {
        Names::Qualified => e.name().as_ref().to_owned(),
        Names::Local => e.local_name().as_ref().to_owned(),
    }
}

/// The element of start tag `e` at byte `pos`, with its attributes and no children yet.
fn element(e: &BytesStart<'_>, pos: usize, options: &Options) -> Result<Node, quick_xml::Error> {
    let mut attrs = Vec::new();
    for attr in e.attributes() {
        let attr = attr.map_err(quick_xml::Error::InvalidAttr)?;
        let key = attr.key.as_ref().to_owned();
        let value = match (
            attr.normalized_value(XmlVersion::Implicit1_0),
            options.entities,
        ) {
            (Ok(v), _) => v.into_owned(),
            (Err(e), Entities::Strict) => return Err(e),
            (Err(_), Entities::KeepRaw) => attr.value.clone().into_owned(),
        };
        attrs.push((key, value));
    }
    Ok(Node {
        name: name(e, options.names),
        attrs,
        children: Vec::new(),
        pos,
    })
}

fn to_usize(v: u64) -> usize {
    usize::try_from(v).unwrap_or(usize::MAX)
}

#[cfg(test)]
mod tests;
