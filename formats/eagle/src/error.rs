//! Errors of the EAGLE reader.

/// Everything that can go wrong while reading an EAGLE file.
///
/// Errors about a particular element carry its name and the 1-based line of its start tag.
///
/// # How to fix
/// - [`EagleError::BinaryFormat`]: open the file in EAGLE 6 or later and save it again; that
///   writes the XML format this reader understands.
/// - Reference errors ([`EagleError::UnknownLibrary`] and friends): the file is inconsistent,
///   usually because it was edited by hand or by a script. Run EAGLE's "Update all libraries"
///   (or re-save the file in EAGLE), which rewrites the embedded libraries.
/// - [`EagleError::WrongKind`]: pass a `.sch` to [`crate::read_schematic`] and a `.brd` to
///   [`crate::read_board`], or use [`crate::read`] which accepts either.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EagleError {
    /// The file is a binary EAGLE file written by EAGLE 5 or older.
    #[error(
        "binary EAGLE format (before 6.0) is not supported; open and re-save it in EAGLE 6 or later"
    )]
    BinaryFormat,
    /// The input is not valid UTF-8 (EAGLE XML files are always UTF-8).
    #[error("not valid UTF-8 at line {line}, column {column}; EAGLE XML files are UTF-8")]
    NotUtf8 {
        /// 1-based line of the first invalid byte.
        line: usize,
        /// 1-based column (in bytes) of the first invalid byte.
        column: usize,
    },
    /// The input is not well-formed XML.
    #[error("XML error at line {line}, column {column}: {source}")]
    Xml {
        /// 1-based line where the problem was found.
        line: usize,
        /// 1-based column (in bytes) where the problem was found.
        column: usize,
        /// The error reported by the XML parser.
        #[source]
        source: quick_xml::Error,
    },
    /// Elements are nested deeper than any EAGLE file nests them.
    #[error("line {line}: elements nested deeper than {limit} levels; this is not an EAGLE file")]
    TooDeep {
        /// 1-based line of the element that exceeded the limit.
        line: usize,
        /// The nesting limit.
        limit: usize,
    },
    /// The input ended while an element was still open.
    #[error("unexpected end of file inside <{element}>")]
    UnexpectedEof {
        /// The innermost element still open.
        element: String,
    },
    /// The XML root is not `<eagle>`, or `<eagle>` lacks `<drawing>` with a schematic, board or
    /// library.
    #[error(
        "not an EAGLE file: expected <eagle><drawing> with a schematic, board or library, found <{found}>"
    )]
    NotEagle {
        /// The element found instead (empty for an empty document).
        found: String,
    },
    /// A schematic was expected and a board was given, or the other way round.
    #[error("expected an EAGLE {expected}, found a {found}")]
    WrongKind {
        /// What the caller asked for: "schematic" or "board".
        expected: &'static str,
        /// What the file holds: "schematic", "board" or "library".
        found: &'static str,
    },
    /// A required attribute is missing.
    #[error("line {line}: <{element}> has no `{attribute}` attribute")]
    MissingAttribute {
        /// Element name.
        element: String,
        /// Attribute name.
        attribute: &'static str,
        /// 1-based line of the element.
        line: usize,
    },
    /// An attribute value could not be parsed.
    #[error("line {line}: <{element} {attribute}=\"{value}\">: expected {expected}")]
    InvalidAttribute {
        /// Element name.
        element: String,
        /// Attribute name.
        attribute: &'static str,
        /// The value found.
        value: String,
        /// What was expected, e.g. "a number in mm".
        expected: &'static str,
        /// 1-based line of the element.
        line: usize,
    },
    /// A rotation string is not of the form `[M][S]R<degrees>`.
    #[error("invalid EAGLE rotation {value:?}: expected [M][S]R<degrees>, e.g. R90, MR180, SR45")]
    InvalidRotation {
        /// The string found.
        value: String,
    },
    /// A part or element names a library that is not embedded in the file.
    #[error(
        "line {line}: <{element} name=\"{name}\"> refers to library {library:?}, which is not in <libraries>"
    )]
    UnknownLibrary {
        /// `part` or `element`.
        element: &'static str,
        /// Name of the part or element.
        name: String,
        /// The missing library.
        library: String,
        /// 1-based line of the part or element.
        line: usize,
    },
    /// A part names a device set or device that its library does not define.
    #[error("line {line}: part {part}: library {library:?} has no device {deviceset:?}/{device:?}")]
    UnknownDevice {
        /// Part name.
        part: String,
        /// Library name.
        library: String,
        /// Device set name.
        deviceset: String,
        /// Device (variant) name.
        device: String,
        /// 1-based line of the part.
        line: usize,
    },
    /// A device or element names a package that its library does not define.
    #[error("line {line}: {owner}: library {library:?} has no package {package:?}")]
    UnknownPackage {
        /// The part or element (or `deviceset/device`) that refers to the package.
        owner: String,
        /// Library name.
        library: String,
        /// The missing package.
        package: String,
        /// 1-based line of the referring element.
        line: usize,
    },
    /// A `<pinref>`, `<contactref>` or `<portref>` names a part, element or module instance
    /// that does not exist.
    #[error("line {line}: <{element}> refers to unknown {kind} {name:?}")]
    UnknownReference {
        /// `pinref`, `contactref` or `portref`.
        element: &'static str,
        /// `part`, `element` or `module instance`.
        kind: &'static str,
        /// The missing name.
        name: String,
        /// 1-based line of the reference.
        line: usize,
    },
    /// A module instance names a module that is not defined in `<modules>`.
    #[error("line {line}: module instance {instance:?} refers to unknown module {module:?}")]
    UnknownModule {
        /// Instance name.
        instance: String,
        /// The missing module.
        module: String,
        /// 1-based line of the `<moduleinst>`.
        line: usize,
    },
    /// Flattening the module hierarchy would expand more module instances than any real design
    /// has (modules nesting many instances of each other multiply).
    #[error("the module hierarchy expands to more than {limit} module instances")]
    TooManyModuleInstances {
        /// The limit.
        limit: usize,
    },
    /// A module contains an instance of itself (directly or through other modules).
    #[error("module {module:?} contains an instance of itself")]
    RecursiveModule {
        /// The module found on its own instance path.
        module: String,
    },
}

impl EagleError {
    /// The error for a failure of the shared XML tree, with lines and columns in `src`.
    pub(crate) fn from_xml(src: &[u8], e: conduit_xml::XmlError) -> Self {
        use conduit_xml::{XmlError, column_of, line_of};
        match e {
            XmlError::NotUtf8 { offset } => Self::NotUtf8 {
                line: line_of(src, offset),
                column: column_of(src, offset),
            },
            XmlError::Syntax { offset, source } => Self::Xml {
                line: line_of(src, offset),
                column: column_of(src, offset),
                source,
            },
            XmlError::TooDeep { offset, limit, .. } => Self::TooDeep {
                line: line_of(src, offset),
                limit,
            },
            XmlError::UnexpectedEof { element } => Self::UnexpectedEof { element },
        }
    }
}
