//! The `conduit` binary: parses the command line, runs the command, maps failures to exit codes.
//!
//! Exit codes: 0 success, 1 bad input or failed work (the message names the file), 2 usage error.

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    cli::run()
}
