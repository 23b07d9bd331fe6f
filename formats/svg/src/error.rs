//! Errors of the SVG reader.

/// Why an SVG file could not be read.
///
/// Positions are byte offsets into the input and 1-based line numbers, pointing at the `<` of the
/// element concerned (or at the XML error).
#[derive(Debug, thiserror::Error)]
pub enum SvgError {
    /// The flattening tolerance is not a finite number of at least [`crate::MIN_TOLERANCE_MM`].
    ///
    /// # How to fix
    /// Pass a tolerance such as `0.01` (mm).
    #[error(
        "flattening tolerance must be a finite number >= {} mm, got {tolerance_mm}",
        crate::MIN_TOLERANCE_MM
    )]
    InvalidTolerance {
        /// The tolerance given.
        tolerance_mm: f64,
    },
    /// The file is not UTF-8 text.
    ///
    /// # How to fix
    /// Save the SVG as UTF-8 (every current editor does by default).
    #[error("SVG is not UTF-8 text: invalid byte at offset {offset} (line {line})")]
    NotUtf8 {
        /// Byte offset of the first invalid byte.
        offset: usize,
        /// Its 1-based line.
        line: usize,
    },
    /// The XML is malformed.
    #[error("malformed XML at byte {offset} (line {line}): {source}")]
    Xml {
        /// Byte offset of the problem.
        offset: usize,
        /// Its 1-based line.
        line: usize,
        /// What the XML reader reported.
        #[source]
        source: quick_xml::Error,
    },
    /// The document ended inside an element.
    #[error("SVG ends inside <{element}>")]
    UnexpectedEof {
        /// The element left open.
        element: String,
    },
    /// The root element is not `<svg>`.
    #[error("not an SVG document: the root element is <{root}>, not <svg>")]
    NotSvg {
        /// The root element's name (empty when there is no element at all).
        root: String,
    },
    /// Elements nest deeper than [`crate::MAX_DEPTH`], or `<use>` references nest deeper than
    /// [`crate::MAX_USE_DEPTH`] or form a cycle.
    #[error("<{element}> at line {line} nests too deeply or references itself (limit {limit})")]
    TooDeep {
        /// The element where the limit was hit.
        element: String,
        /// Byte offset of its start tag.
        offset: usize,
        /// Its 1-based line.
        line: usize,
        /// The nesting limit.
        limit: usize,
    },
    /// An attribute value could not be parsed: malformed path data (`d`), `transform`,
    /// `viewBox`, length, or a coordinate that is not finite. Boxed to keep results small.
    ///
    /// # How to fix
    /// Open the file in an SVG editor, fix or remove the element named here, and save again.
    #[error("{0}")]
    InvalidAttribute(Box<AttributeError>),
    /// Flattening would produce more than [`crate::MAX_POINTS`] points (an absurd size or
    /// tolerance).
    ///
    /// # How to fix
    /// Use a larger tolerance, or check the document's units and scale.
    #[error("<{element}> at line {line} would flatten to more than {limit} points")]
    TooManyPoints {
        /// The element being flattened.
        element: String,
        /// Byte offset of its start tag.
        offset: usize,
        /// Its 1-based line.
        line: usize,
        /// The point limit.
        limit: usize,
    },
}

/// Details of [`SvgError::InvalidAttribute`]: which element and attribute, and where.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "<{element}{}> at line {line} (byte {offset}): invalid {attribute}=\"{value}\": {reason}",
    id.as_deref().map(|id| format!(" id=\"{id}\"")).unwrap_or_default()
)]
pub struct AttributeError {
    /// The element's name, such as `path`.
    pub element: String,
    /// The element's `id`, if any.
    pub id: Option<String>,
    /// The attribute, such as `d`.
    pub attribute: &'static str,
    /// The value (cut to 80 characters).
    pub value: String,
    /// What is wrong, from the value parser (its positions count characters in the value).
    pub reason: String,
    /// Byte offset of the element's start tag.
    pub offset: usize,
    /// Its 1-based line.
    pub line: usize,
}

impl SvgError {
    /// The error for a failure of the shared XML tree, with lines in `src`.
    pub(crate) fn from_xml(src: &[u8], e: conduit_xml::XmlError) -> Self {
        use conduit_xml::{XmlError, line_of};
        match e {
            XmlError::NotUtf8 { offset } => Self::NotUtf8 {
                offset,
                line: line_of(src, offset),
            },
            XmlError::Syntax { offset, source } => Self::Xml {
                offset,
                line: line_of(src, offset),
                source,
            },
            XmlError::TooDeep {
                element,
                offset,
                limit,
            } => Self::TooDeep {
                element,
                offset,
                line: line_of(src, offset),
                limit,
            },
            XmlError::UnexpectedEof { element } => Self::UnexpectedEof { element },
        }
    }
}
