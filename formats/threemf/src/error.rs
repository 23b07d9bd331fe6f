//! Errors of the 3MF reader, writer and flattener.

use std::fmt;

/// Where in a package something was found: part name, plus line and column (1-based) inside
/// the part's XML when known (0 means "not applicable").
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Location {
    /// Part name, e.g. `/3D/3dmodel.model`.
    pub part: String,
    /// 1-based line, 0 when unknown.
    pub line: u32,
    /// 1-based column (in bytes), 0 when unknown.
    pub column: u32,
}

impl Location {
    /// A location naming only a part.
    pub fn part(part: impl Into<String>) -> Location {
        Location {
            part: part.into(),
            line: 0,
            column: 0,
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.part)
        } else if self.column == 0 {
            write!(f, "{}:{}", self.part, self.line)
        } else {
            write!(f, "{}:{}:{}", self.part, self.line, self.column)
        }
    }
}

/// Everything that can go wrong reading, writing or flattening a 3MF package.
///
/// Every message is one line and names the part (and the XML line/column, element and
/// attribute where there is one).
///
/// # How to fix
/// Errors other than [`ThreeMfError::Io`], [`ThreeMfError::LimitExceeded`] and
/// [`ThreeMfError::CompressionRatio`] mean the file breaks a rule of the 3MF core or extension
/// specifications (or of OPC); re-export it from the producing application. Limit errors can be
/// lifted by passing larger [`crate::Limits`] when the file is trusted.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ThreeMfError {
    /// The bytes are not a readable ZIP archive.
    #[error("not a 3MF package (ZIP): {source}")]
    Zip {
        /// The ZIP library's error.
        #[source]
        source: zip::result::ZipError,
    },
    /// Inflating or reading a part failed (corrupt data, CRC mismatch) or writing failed.
    #[error("{part}: I/O error: {source}")]
    Io {
        /// Part being read or written (`<output>` for the writer's sink).
        part: String,
        /// Underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A configured [`crate::Limits`] value was exceeded.
    #[error("{part}: limit exceeded: {limit} = {max} (found {found})")]
    LimitExceeded {
        /// Part (or package) where it happened.
        part: String,
        /// Name of the `Limits` field.
        limit: &'static str,
        /// Configured maximum.
        max: u64,
        /// Value found (or reached when reading stopped).
        found: u64,
    },
    /// A part inflates more than `max_compression_ratio` times its compressed size.
    #[error(
        "{part}: compression ratio above {max_ratio}:1 ({inflated} bytes inflated from {compressed}); refusing a possible zip bomb"
    )]
    CompressionRatio {
        /// Part being inflated.
        part: String,
        /// Compressed size.
        compressed: u64,
        /// Bytes inflated when reading stopped.
        inflated: u64,
        /// Configured ratio limit.
        max_ratio: u64,
    },
    /// A part the package needs is missing.
    #[error("{part}: missing part ({needed_for})")]
    MissingPart {
        /// Part name looked for.
        part: String,
        /// What referenced it.
        needed_for: String,
    },
    /// Two ZIP entries map to the same (case-insensitive) OPC part name, or a name is not a
    /// valid part name.
    #[error("{part}: invalid or duplicated part name ({reason})")]
    PartName {
        /// Offending entry name.
        part: String,
        /// Why.
        reason: &'static str,
    },
    /// A relationship breaks an OPC or 3MF rule.
    #[error("{rels_part}: relationship {id:?} to {target:?}: {reason}")]
    Relationship {
        /// The `.rels` part.
        rels_part: String,
        /// Relationship `Id`.
        id: String,
        /// Relationship `Target`.
        target: String,
        /// Rule broken.
        reason: &'static str,
    },
    /// The package has no 3D model StartPart relationship, or more than one.
    #[error(
        "/_rels/.rels: {found} StartPart relationships of type 3dmodel (exactly one is required){detail}"
    )]
    StartPart {
        /// How many were found.
        found: usize,
        /// Targets, for the message.
        detail: String,
    },
    /// A part has a missing or wrong content type.
    #[error("{part}: content type {found:?} where {expected} is required")]
    ContentType {
        /// Part.
        part: String,
        /// Content type found (`None` when the part has none).
        found: Option<String>,
        /// What the spec requires.
        expected: &'static str,
    },
    /// The XML is not UTF-8 (or declares another encoding).
    #[error("{part}: XML must be UTF-8 ({found})")]
    Encoding {
        /// Part.
        part: String,
        /// What was found.
        found: String,
    },
    /// Not well-formed XML, a DTD, an unbound namespace prefix, or a second root element.
    #[error("{at}: XML error: {message}")]
    Xml {
        /// Where.
        at: Location,
        /// Description.
        message: String,
    },
    /// A required attribute is absent.
    #[error("{at}: <{element}> is missing required attribute {attribute:?}")]
    MissingAttribute {
        /// Where.
        at: Location,
        /// Element local name.
        element: &'static str,
        /// Attribute name.
        attribute: &'static str,
    },
    /// An attribute value is malformed or not allowed.
    #[error("{at}: <{element}> attribute {attribute}={value:?}: {reason}")]
    InvalidAttribute {
        /// Where.
        at: Location,
        /// Element local name.
        element: String,
        /// Attribute name.
        attribute: String,
        /// Value as written (truncated to 64 characters).
        value: String,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// A required child element is missing.
    #[error("{at}: <{parent}> has no <{element}> element")]
    MissingElement {
        /// Where.
        at: Location,
        /// Parent element.
        parent: &'static str,
        /// Missing child.
        element: &'static str,
    },
    /// Two resources of one model part share an id.
    #[error("{at}: resource id {id} is already used by another resource in this part")]
    DuplicateResourceId {
        /// Where the second definition is.
        at: Location,
        /// The id.
        id: u32,
    },
    /// Two metadata entries of one scope share a name.
    #[error("{at}: duplicated metadata name {name:?}")]
    DuplicateMetadata {
        /// Where the second entry is.
        at: Location,
        /// The name.
        name: String,
    },
    /// An id reference does not resolve to a resource of the required kind.
    #[error("{at}: <{element}> {attribute}={id} does not reference {expected}")]
    UnresolvedReference {
        /// Where.
        at: Location,
        /// Element local name.
        element: &'static str,
        /// Attribute name.
        attribute: &'static str,
        /// The id.
        id: u32,
        /// What it must reference.
        expected: &'static str,
    },
    /// An index is out of range of what it indexes.
    #[error("{at}: <{element}> {attribute}={index} is out of range (count {count})")]
    IndexOutOfRange {
        /// Where.
        at: Location,
        /// Element local name.
        element: &'static str,
        /// Attribute name.
        attribute: &'static str,
        /// The index.
        index: u64,
        /// Number of entries available.
        count: usize,
    },
    /// `requiredextensions` names a prefix that is not declared.
    #[error("{at}: requiredextensions names prefix {prefix:?} that is not declared")]
    UndeclaredExtensionPrefix {
        /// Where.
        at: Location,
        /// The prefix.
        prefix: String,
    },
    /// `requiredextensions` names a namespace conduit does not support.
    #[error("{at}: required extension {namespace} is not supported by conduit")]
    UnsupportedExtension {
        /// Where.
        at: Location,
        /// The namespace URI.
        namespace: String,
    },
    /// Markup in a 3MF namespace conduit does not know, not declared ignorable.
    #[error("{at}: {what} in unknown 3MF namespace {namespace} (not declared mc:Ignorable)")]
    UnknownNamespace {
        /// Where.
        at: Location,
        /// Element or attribute name.
        what: String,
        /// The namespace URI.
        namespace: String,
    },
    /// Any other rule of the 3MF specifications that the file breaks.
    #[error("{at}: <{element}>: {rule}")]
    Rule {
        /// Where.
        at: Location,
        /// Element local name.
        element: &'static str,
        /// The rule, stated briefly.
        rule: &'static str,
    },
    /// Components reference each other in a cycle.
    #[error("{part}: object {object_id} contains itself through its components")]
    ComponentCycle {
        /// Part holding the object.
        part: String,
        /// An object on the cycle.
        object_id: u32,
    },
    /// A slicer's settings part (`Metadata/Slic3r_PE.config`, `project_settings.config`, ...)
    /// does not read.
    ///
    /// How to fix: re-save the project from the slicer, or delete the part to slice the model
    /// without it.
    #[error("{at}: slicer settings: {message}")]
    SlicerSettings {
        /// The part, and the line when known.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// The writer was given a model it cannot write as a valid single-part 3MF.
    #[error("cannot write model: {reason}")]
    Unwritable {
        /// Why.
        reason: String,
    },
}

impl ThreeMfError {
    pub(crate) fn io(part: &str, source: std::io::Error) -> ThreeMfError {
        ThreeMfError::Io {
            part: part.to_string(),
            source,
        }
    }
}

/// The kind of a reader error message: the message without its location (everything up to the
/// first `": "`), quoted text blanked to `"_"` and each run of digits to `#`, so the same defect
/// found in two files compares equal (`/3D/a.model:4:3: duplicated metadata name "Title"` and
/// `/3D/3dmodel.model:8:3: duplicated metadata name "Description"` are one kind).
pub fn error_kind(message: &str) -> String {
    let rest = message.split_once(": ").map_or(message, |(_, r)| r);
    let mut out = String::new();
    let mut quoted = false;
    for c in rest.chars() {
        match c {
            '"' => {
                quoted = !quoted;
                if quoted {
                    out.push_str("\"_\"");
                }
            }
            _ if quoted => {}
            '0'..='9' => {
                if !out.ends_with('#') {
                    out.push('#');
                }
            }
            _ => out.push(c),
        }
    }
    out
}
