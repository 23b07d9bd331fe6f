//! Progress bars on stderr for batch work and for the router, shown only when stderr is a
//! terminal and the run is not `--quiet`.

use conduit::pipeline::{ProgressFn, RouteProgress};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Arc;

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

/// How the router's bar reads: `routing [=====>    ] 120/198 wires, round 1, 5 unrouted`.
const ROUTING_TEMPLATE: &str = "routing [{bar:30}] {pos}/{len} wires{msg}";

/// A bar for the router alone (`conduit route`, `conduit postprocess`), hidden when stderr is
/// not a terminal or the run is `--quiet`, and the callback the router moves it with.
pub fn routing_bar() -> (ProgressBar, ProgressFn) {
    let bar = if super::quiet() || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(0)
    };
    let callback = routing_callback(&bar);
    (bar, callback)
}

/// The router's callback moving `bar`: it shows `bar` as the routing bar (wires done of the
/// job's, the negotiation round and the wires still in conflict or the rip-up round, the wires
/// unrouted so far) until something restyles it.
pub fn routing_callback(bar: &ProgressBar) -> ProgressFn {
    let bar = bar.clone();
    Arc::new(move |p: RouteProgress| {
        routing_style(&bar);
        bar.update(|state| {
            state.set_len(p.total as u64);
            state.set_pos(p.done as u64);
        });
        if p.negotiation > 0 {
            bar.set_message(format!(
                ", negotiation round {}, {} in conflict, {} unrouted",
                p.negotiation, p.conflicts, p.unrouted
            ));
        } else {
            bar.set_message(format!(", round {}, {} unrouted", p.round, p.unrouted));
        }
    })
}

/// Styles `bar` as the routing bar, with no wire counted yet.
pub fn routing_style(bar: &ProgressBar) {
    if let Ok(style) = ProgressStyle::with_template(ROUTING_TEMPLATE) {
        bar.set_style(style.progress_chars("=> "));
    }
}
