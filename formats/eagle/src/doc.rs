//! The parsed EAGLE document: the shared element tree ([`conduit_xml`]) with its source, and
//! typed attribute accessors whose errors name the element and its line.
//!
//! EAGLE files are a few megabytes at most, so the reader builds the whole tree of elements
//! with their attributes (text content is skipped: EAGLE keeps only descriptions and labels
//! there) and the byte offset of each start tag, from which error messages compute a line
//! number.

pub(crate) use conduit_xml::Node;
use conduit_xml::{DepthCheck, Entities, Names, Options};

use crate::error::EagleError;

/// Deepest element nesting accepted. EAGLE files nest about ten levels; the limit keeps the
/// recursive drop of a hostile, deeply nested input from overflowing the stack.
const MAX_DEPTH: usize = 256;

/// How EAGLE files are parsed: names as written, attribute references that do not decode are
/// errors, and the depth limit is checked before an element's attributes are read.
const OPTIONS: Options = Options {
    names: Names::Qualified,
    entities: Entities::Strict,
    depth_check: DepthCheck::BeforeAttributes,
    max_depth: MAX_DEPTH,
};

/// Parsed document plus the offsets of its line breaks, to turn byte offsets into line numbers.
pub(crate) struct Doc {
    pub(crate) root: Node,
    /// Byte offsets of every `\n` of the source, ascending.
    newlines: Vec<usize>,
}

impl Doc {
    /// 1-based line of a byte offset (offsets past the end count as the end), as
    /// [`conduit_xml::line_of`] gives it, in logarithmic time: readers ask it for every part
    /// and element.
    pub(crate) fn line(&self, pos: usize) -> usize {
        self.newlines.partition_point(|&nl| nl < pos) + 1
    }
}

/// Parses `src` (UTF-8, optional BOM) into an element tree; an input without any element is
/// [`EagleError::NotEagle`].
pub(crate) fn parse(src: &[u8]) -> Result<Doc, EagleError> {
    let root = conduit_xml::parse(src, &OPTIONS)
        .map_err(|e| EagleError::from_xml(src, e))?
        .ok_or(EagleError::NotEagle {
            found: String::new(),
        })?;
    let newlines = src
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .map(|(i, _)| i)
        .collect();
    Ok(Doc { root, newlines })
}

impl Doc {
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
