//! A progress bar on stderr for batch work, shown only when stderr is a terminal and the run
//! is not `--quiet`.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;

/// A progress bar over `len` items, hidden when stderr is not a terminal, there is one item or
/// the run is `--quiet`.
pub fn bar(len: usize, what: &str) -> ProgressBar {
    if len < 2 || super::quiet() || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len as u64);
    if let Ok(style) = ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {wide_msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_prefix(what.to_string());
    bar
}
