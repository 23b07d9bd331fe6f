//! Command-line front end: clap arguments are turned into validated options before any work runs
//! (`args`), then each command runs (`info`, `convert`). Errors are printed with their cause chain.

mod args;
mod calibrate;
mod check;
mod compensate;
mod config;
mod conform;
mod convert;
mod info;
mod jet;
mod postprocess;
mod preview;
mod progress;
mod route;
mod slice;

use clap::Parser;
use std::process::ExitCode;

/// Exit code for bad input or failed work.
const EXIT_FAILURE: u8 = 1;
/// Exit code for usage errors (clap uses the same).
const EXIT_USAGE: u8 = 2;

/// A failure that decides the exit code.
pub(crate) enum Failure {
    /// Bad arguments: exit 2.
    Usage(String),
    /// Bad input or failed work: exit 1. Messages were already printed per file.
    Work(anyhow::Error),
    /// Some files failed and were reported already: exit 1 with nothing more to say.
    Reported,
}

impl From<anyhow::Error> for Failure {
    fn from(e: anyhow::Error) -> Self {
        Failure::Work(e)
    }
}

/// Runs the command line and returns the process exit code.
pub fn run() -> ExitCode {
    let cli = match args::Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            // --help and --version are not errors.
            let code = if e.use_stderr() { EXIT_USAGE } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let result = match cli.command {
        args::Command::Info(a) => info::run(a),
        args::Command::Convert(a) => convert::run(a),
        args::Command::Slice(a) => slice::run(a),
        args::Command::Check(a) => check::run(a),
        args::Command::Config(a) => config::run(a),
        args::Command::Preview(a) => preview::run(a),
        args::Command::Route(a) => route::run(a),
        args::Command::Postprocess(a) => postprocess::run(a),
        args::Command::Conform(a) => conform::run(a),
        args::Command::Jet(a) => jet::run(a),
        args::Command::Calibrate(a) => calibrate::run(a),
        args::Command::Compensate(a) => compensate::run(*a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Usage(msg)) => {
            eprintln!("error: {msg}");
            eprintln!("For more information, try '--help'.");
            ExitCode::from(EXIT_USAGE)
        }
        Err(Failure::Work(e)) => {
            if is_broken_pipe(&e) {
                return ExitCode::SUCCESS;
            }
            eprintln!("error: {e:#}");
            ExitCode::from(EXIT_FAILURE)
        }
        Err(Failure::Reported) => ExitCode::from(EXIT_FAILURE),
    }
}

/// Output piped into `head` and closed early is not a failure.
fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}
