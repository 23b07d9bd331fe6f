//! The `conduit` binary: parses the command line, runs the command, maps failures to exit codes.
//!
//! Exit codes: 0 success, 1 bad input or failed work (the message names the file), 2 usage error,
//! 130 stopped by Ctrl-C (nothing written).

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    // The first Ctrl-C asks the job to stop: routing gives up its searches, no output is put in
    // place and temporary files are removed on the way out. A second one ends the process at
    // once.
    let _ = ctrlc::set_handler(|| {
        if conduit::interrupt::requested() {
            std::process::exit(cli::EXIT_INTERRUPTED.into());
        }
        conduit::interrupt::request();
        eprintln!("conduit: stopping, nothing will be written (Ctrl-C again to quit at once)");
    });
    cli::run()
}
