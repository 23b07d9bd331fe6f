//! Command-line front end: clap arguments are turned into validated options before any work runs
//! (`args`), then each command runs (`info`, `convert`). Errors are printed with their cause chain.
//!
//! Standard output is written with [`outln!`] and [`out!`], which return write errors instead of
//! panicking as `println!` does; standard error with `eprintln!`, shadowed below by a version
//! that ignores write errors (there is nowhere left to report them).

/// Writes a line to standard output; a write error becomes a [`Failure`] (a closed pipe a
/// quiet end, anything else an error), never a panic. Use as `outln!("...")?`.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*).map_err($crate::cli::Failure::stdout)
    }};
}

/// [`outln!`] without the line end.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*).map_err($crate::cli::Failure::stdout)
    }};
}

/// `eprintln!` that ignores write errors instead of panicking: a message that cannot reach a
/// closed or full standard error has nowhere else to go, and the exit code still tells.
macro_rules! eprintln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr().lock(), $($arg)*);
    }};
}

mod args;
mod calibrate;
mod check;
mod compensate;
mod config;
mod conform;
mod convert;
mod manual;
mod info;
mod jet;
mod postprocess;
mod preview;
mod progress;
mod route;
mod slice;

use clap::Parser;
use std::io::Write;
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
    /// Standard output was closed by its reader (`conduit check FILE | head`): exit 0 quietly.
    StdoutClosed,
}

impl Failure {
    /// The failure of a write to standard output. A closed pipe ends the run quietly with exit
    /// 0, as ripgrep does (git dies of SIGPIPE instead, 141 in the shell): the reader chose to
    /// stop, and a non-zero status would fail `set -o pipefail` scripts that only wanted the
    /// first lines. Any other error (a full disk: `> /dev/full`) fails the run, exit 1.
    pub(crate) fn stdout(e: std::io::Error) -> Failure {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            Failure::StdoutClosed
        } else {
            Failure::Work(anyhow::Error::new(e).context("cannot write to standard output"))
        }
    }
}

impl From<conduit::scene::OutputError> for Failure {
    fn from(e: conduit::scene::OutputError) -> Self {
        Failure::Work(e.into())
    }
}

impl From<anyhow::Error> for Failure {
    fn from(e: anyhow::Error) -> Self {
        Failure::Work(e)
    }
}

/// How every command reads its input files, set once from the global options before the
/// command runs.
static LOAD_OPTIONS: std::sync::OnceLock<conduit::scene::LoadOptions> = std::sync::OnceLock::new();

/// The options every command reads files with (`--strict` for 3MF).
pub(crate) fn load_options() -> conduit::scene::LoadOptions {
    LOAD_OPTIONS.get().cloned().unwrap_or_default()
}

/// Runs the command line and returns the process exit code.
pub fn run() -> ExitCode {
    let cli = match args::Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            // --help and --version are not errors.
            let code = if e.use_stderr() { EXIT_USAGE } else { 0 };
            // Help that cannot be written (`--help > /dev/full`) fails like any other output; a
            // closed pipe (`--help | head -1`) does not.
            return match e.print() {
                Err(io) if !e.use_stderr() && io.kind() != std::io::ErrorKind::BrokenPipe => {
                    eprintln!("error: cannot write to standard output: {io}");
                    ExitCode::from(EXIT_FAILURE)
                }
                _ => ExitCode::from(code),
            };
        }
    };
    let _ = LOAD_OPTIONS.set(conduit::scene::LoadOptions {
        threemf_read: conduit_3mf::ReadOptions { strict: cli.strict },
        ..conduit::scene::LoadOptions::default()
    });
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
        args::Command::Completions(a) => manual::completions(a),
        args::Command::Man(a) => manual::man(a),
    };
    // Output still buffered (a last line without its end) fails here rather than unseen at exit.
    let result = result.and_then(|()| std::io::stdout().flush().map_err(Failure::stdout));
    match result {
        Ok(()) | Err(Failure::StdoutClosed) => ExitCode::SUCCESS,
        Err(Failure::Usage(msg)) => {
            eprintln!("error: {msg}");
            eprintln!("For more information, try '--help'.");
            ExitCode::from(EXIT_USAGE)
        }
        Err(Failure::Work(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(EXIT_FAILURE)
        }
        Err(Failure::Reported) => ExitCode::from(EXIT_FAILURE),
    }
}
