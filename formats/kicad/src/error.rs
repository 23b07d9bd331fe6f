//! Errors of the KiCad reader.

use std::path::PathBuf;

/// Everything that can go wrong while reading a KiCad file.
///
/// Errors about a value carry the path of keywords that leads to it
/// (`kicad_pcb/footprint/pad/at`) and the 1-based line and column of its list or atom.
///
/// # How to fix
/// - Syntax errors, [`KicadError::NotKicad`]: the file is not a KiCad 6-9 file (KiCad 5's
///   `.sch` and `.kicad_pcb` version 4 files differ); open it in KiCad 6 or later and save it.
/// - [`KicadError::Missing`], [`KicadError::Invalid`]: the file was edited by hand or by a
///   script; open and save it in KiCad, which rewrites it whole.
/// - [`KicadError::Sheet`]: a hierarchical sheet's file is missing beside the root schematic;
///   copy the whole project folder.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum KicadError {
    /// The input is larger than any KiCad file.
    #[error("{bytes} bytes is more than the {limit} bytes a KiCad file is read to")]
    TooLarge {
        /// Size of the input.
        bytes: usize,
        /// The limit.
        limit: usize,
    },
    /// The input is not valid UTF-8 (KiCad writes UTF-8).
    #[error("not valid UTF-8 at line {line}, column {column}; KiCad files are UTF-8")]
    NotUtf8 {
        /// 1-based line of the first invalid byte.
        line: u32,
        /// 1-based column of the first invalid byte.
        column: u32,
    },
    /// The input is not a well-formed s-expression.
    #[error("line {line}, column {column}: {message}")]
    Syntax {
        /// 1-based line.
        line: u32,
        /// 1-based column.
        column: u32,
        /// What is wrong.
        message: &'static str,
    },
    /// Lists are nested deeper than any KiCad file nests them.
    #[error("line {line}, column {column}: lists nested deeper than {limit} levels")]
    TooDeep {
        /// 1-based line of the list that exceeded the limit.
        line: u32,
        /// 1-based column.
        column: u32,
        /// The limit.
        limit: usize,
    },
    /// The input ended inside a list.
    #[error("the file ends inside ({keyword} opened at line {line}, column {column}")]
    UnexpectedEof {
        /// Keyword of the innermost open list.
        keyword: String,
        /// 1-based line of its `(`.
        line: u32,
        /// 1-based column of its `(`.
        column: u32,
    },
    /// The top list is not one of KiCad's files.
    #[error("not a KiCad file: expected (kicad_pcb, (kicad_sch or (export, found ({found}")]
    NotKicad {
        /// Keyword of the top list (empty for an empty file).
        found: String,
    },
    /// A board was expected and a schematic was given, or the like.
    #[error("expected a KiCad {expected}, found a {found}")]
    WrongKind {
        /// What the caller asked for.
        expected: &'static str,
        /// What the file holds.
        found: &'static str,
    },
    /// A list lacks a value it must have.
    #[error("{path}, line {line}, column {column}: {what} is missing")]
    Missing {
        /// Keywords from the root to the list.
        path: String,
        /// 1-based line of the list.
        line: u32,
        /// 1-based column of the list.
        column: u32,
        /// What is missing, e.g. `(at …)` or `the pad number`.
        what: String,
    },
    /// A value is not what it should be.
    #[error("{path}, line {line}, column {column}: {value:?} is not {expected}")]
    Invalid {
        /// Keywords from the root to the list.
        path: String,
        /// 1-based line of the value (or of its list).
        line: u32,
        /// 1-based column.
        column: u32,
        /// The value found.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A schematic symbol names a library symbol the file does not embed.
    #[error("{path}, line {line}: symbol {reference} uses {lib_id:?}, which is not in lib_symbols")]
    UnknownSymbol {
        /// Keywords from the root to the symbol.
        path: String,
        /// 1-based line of the symbol.
        line: u32,
        /// The symbol's reference.
        reference: String,
        /// The missing library symbol.
        lib_id: String,
    },
    /// An error inside a hierarchical sheet's file.
    #[error("{}: {source}", file.display())]
    Sheet {
        /// The sheet's file.
        file: PathBuf,
        /// What is wrong in it.
        #[source]
        source: Box<KicadError>,
    },
    /// A hierarchical sheet's file could not be read.
    #[error("{}: {error}", file.display())]
    SheetIo {
        /// The sheet's file.
        file: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
    /// A sheet contains itself, directly or through other sheets.
    #[error("sheet {} contains itself", file.display())]
    RecursiveSheet {
        /// The sheet's file.
        file: PathBuf,
    },
    /// The sheet hierarchy expands to more sheet instances than any design has.
    #[error("the sheet hierarchy expands to more than {limit} sheet instances")]
    TooManySheets {
        /// The limit.
        limit: usize,
    },
}
