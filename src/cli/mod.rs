//! The command-line front end: clap arguments turned into validated work, exit codes, progress.

use std::process::ExitCode;

/// Runs the command line and returns the process exit code.
pub fn run() -> ExitCode {
    ExitCode::SUCCESS
}
