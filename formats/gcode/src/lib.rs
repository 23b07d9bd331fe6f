//! G-code tokenizer that round-trips every line byte for byte, the modal machine that
//! interprets the lines, plus the number formatter for writing G-code.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the
//! pipeline. `postprocess` reads another slicer's G-code with [`parse`], edits lines and writes
//! them back; `emit` writes numbers with [`fmt_xyz`], [`fmt_e`] and [`fmt_f`]; `check`,
//! `preview` and `postprocess` replay files on the [`Machine`] (see [`machine`]); `conduit info`
//! shows a [`Summary`], which the machine walks too.
//!
//! # The round-trip guarantee
//!
//! For every input that [`parse`] accepts, [`Gcode::to_bytes`] returns exactly the input bytes:
//! line terminators (`\n`, `\r\n`, a lone `\r`, or none on the last line) are recorded per line,
//! and each [`Line`] keeps its exact bytes in [`Line::text`]. The tokens (words, comments,
//! checksum, `N` number) are byte ranges into that text, so a post-processor can leave every
//! untouched line exactly as the host slicer wrote it.
//!
//! [`parse`] fails only on files that are not text: Prusa binary G-code (`.bgcode`, see
//! [`GcodeError::BinaryGcode`]) and files with NUL bytes. Anything else — lowercase letters,
//! missing numbers, stray symbols, invalid UTF-8, very long lines — is kept, with the bytes that
//! are not G-code recorded as [`Line::unparsed`] spans.
//!
//! # Tokens
//!
//! - A word is a letter (either case; stored upper-cased) followed directly by a number:
//!   optional sign, digits, optional point and digits (`X10.5`, `E.2`, `y-3`, `G01`). There is
//!   no exponent: as in Marlin, `X1e3` is `X1` followed by `E3`.
//! - `N` followed by digits is the line number ([`Line::line_number_word`]), not a word.
//! - `*` followed by digits (0..=255) is the checksum ([`Line::checksum`]).
//! - `;` starts a comment that runs to the end of the line; `(` starts one that runs to `)`.
//! - After a message command such as `M117`, the rest of the line up to `;` or `*` is free text
//!   ([`Line::string_arg`]).
//!
//! # Example
//!
//! ```
//! let bytes = b";LAYER_CHANGE\nG1 X10.5 Y-3 E.2 F1800\r\nT1\nG1 X1 Y1 E0.5";
//! let g = conduit_gcode::parse(bytes)?;
//! assert_eq!(g.to_bytes(), bytes);
//! assert_eq!(g.lines[1].command(), Some((b'G', 1.0)));
//! assert_eq!(g.lines[1].get(b'F'), Some(1800.0));
//! let summary = conduit_gcode::summarize(&g);
//! assert_eq!(summary.layers, 1);
//! assert_eq!(summary.tools, vec![1]);
//! assert_eq!(conduit_gcode::fmt_e(0.123456), "0.12346");
//! # Ok::<(), conduit_gcode::GcodeError>(())
//! ```

mod escape;
pub mod events;
mod line;
pub mod machine;
mod number;
mod parse;
mod summary;

#[cfg(test)]
mod corpus_tests;

pub use escape::{string_list, unescape_cstyle};
pub use line::{Line, LineEnding, STRING_ARG_COMMANDS, Word};
pub use machine::{Command, Firmware, Machine, Move, Moves, Position, Reading, moves, moves_on};
pub use number::{E_DECIMALS, XYZ_DECIMALS, fmt_e, fmt_f, fmt_fixed, fmt_xyz};
pub use parse::{BGCODE_MAGIC, Gcode, GcodeError, is_binary_gcode, parse};
pub use summary::{Bounds, ExtrusionMode, Flavour, LayerSource, Summary, Units, summarize};
