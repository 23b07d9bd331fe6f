//! Command-line front end: clap arguments are turned into validated options before any work runs
//! (`args`), then each command runs (`info`, `convert`). Errors are printed with their cause chain.
//!
//! Standard output is written with [`outln!`] and [`out!`], which return write errors instead of
//! panicking as `println!` does; standard error with `eprintln!`, shadowed below by a version
//! that ignores write errors (there is nowhere left to report them).
//!
//! What reaches standard error goes through one switch, the global `-q/--quiet` and
//! `-v/--verbose` flags ([`Verbosity`]): errors always print ([`errorln!`]), warnings
//! ([`warnln!`]), summary and info lines ([`infoln!`]) and progress bars ([`progress`]) only
//! when not quiet, details ([`verbose`]) only when verbose. Every error and warning is one line:
//! control characters of quoted input are escaped ([`one_line`]).

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

/// A warning on standard error, `warning: ` and the message on one line; nothing with
/// `--quiet`.
macro_rules! warnln {
    ($($arg:tt)*) => {{
        if !$crate::cli::quiet() {
            eprintln!("warning: {}", $crate::cli::one_line(&format!($($arg)*)));
        }
    }};
}

/// An error on standard error, `error: ` and the message on one line; printed even with
/// `--quiet`.
macro_rules! errorln {
    ($($arg:tt)*) => {{
        eprintln!("error: {}", $crate::cli::one_line(&format!($($arg)*)));
    }};
}

/// A summary or info line on standard error; nothing with `--quiet`.
macro_rules! infoln {
    ($($arg:tt)*) => {{
        if !$crate::cli::quiet() {
            eprintln!($($arg)*);
        }
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
mod place;
mod route;
mod slice;
mod studio;
mod view;

use clap::Parser;
use std::io::Write;
use std::process::ExitCode;
use std::sync::atomic::{AtomicU8, Ordering};

/// Exit code for bad input or failed work.
const EXIT_FAILURE: u8 = 1;
/// Exit code for usage errors (clap uses the same).
const EXIT_USAGE: u8 = 2;

/// Exit code of a job stopped by Ctrl-C (128 + SIGINT, as shells report it).
pub(crate) const EXIT_INTERRUPTED: u8 = 130;

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

/// How much a run says on standard error besides its errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[repr(u8)]
pub(crate) enum Verbosity {
    /// `--quiet`: errors only.
    Quiet = 0,
    /// Progress, summaries and warnings.
    Normal = 1,
    /// `--verbose`: also the details a warning sums up (such as every ignored setting).
    Verbose = 2,
}

/// The run's [`Verbosity`], set once from the global flags before the command runs.
static VERBOSITY: AtomicU8 = AtomicU8::new(Verbosity::Normal as u8);

/// True with `--quiet`: no progress, summaries or warnings on standard error.
pub(crate) fn quiet() -> bool {
    VERBOSITY.load(Ordering::Relaxed) == Verbosity::Quiet as u8
}

/// True with `--verbose`: warnings that sum up a list also print the list.
pub(crate) fn verbose() -> bool {
    VERBOSITY.load(Ordering::Relaxed) == Verbosity::Verbose as u8
}

/// `text` on one line: line ends, tabs and other control characters (C0, DEL, C1) written as
/// escapes (`\n`, `\r`, `\t`, `\u{1b}`), so that a message quoting raw input (an SVG
/// attribute, an EAGLE value) stays one line that tools can grep.
pub(crate) fn one_line(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c.is_control() => out.push_str(&format!("\\u{{{:x}}}", u32::from(c))),
            c => out.push(c),
        }
    }
    out
}

/// Prints `value` as one pretty JSON document on standard output: the `--json` summary of a
/// command.
pub(crate) fn print_json(value: &impl serde::Serialize) -> Result<(), Failure> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| Failure::Work(anyhow::Error::new(e).context("serialising the summary")))?;
    outln!("{text}")
}

/// The paths of a `--json` summary's `outputs` list, as text.
pub(crate) fn paths<'a>(paths: impl IntoIterator<Item = &'a std::path::Path>) -> Vec<String> {
    paths.into_iter().map(|p| p.display().to_string()).collect()
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
    let verbosity = if cli.quiet {
        Verbosity::Quiet
    } else if cli.verbose {
        Verbosity::Verbose
    } else {
        Verbosity::Normal
    };
    VERBOSITY.store(verbosity as u8, Ordering::Relaxed);
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
        args::Command::View(a) => view::run(a),
        args::Command::Studio(a) => studio::run(a),
        args::Command::Place(a) => place::run(a),
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
    if conduit::interrupt::requested() {
        if let Err(Failure::Work(e)) = &result {
            errorln!("{e:#}");
        }
        return ExitCode::from(EXIT_INTERRUPTED);
    }
    match result {
        Ok(()) | Err(Failure::StdoutClosed) => ExitCode::SUCCESS,
        Err(Failure::Usage(msg)) => {
            errorln!("{msg}");
            eprintln!("For more information, try '--help'.");
            ExitCode::from(EXIT_USAGE)
        }
        Err(Failure::Work(e)) => {
            errorln!("{e:#}");
            ExitCode::from(EXIT_FAILURE)
        }
        Err(Failure::Reported) => ExitCode::from(EXIT_FAILURE),
    }
}
