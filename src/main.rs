//! The `conduit` binary: a thin wrapper around [`conduit::cli::run`].

fn main() -> std::process::ExitCode {
    conduit::cli::run()
}
