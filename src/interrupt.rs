//! A request to stop (Ctrl-C), heard by long work and by every writer.
//!
//! Place in the pipeline: beside every stage. The binary asks for it when the user presses
//! Ctrl-C ([`request`]); routing stops its searches as at its deadline, and the writers
//! ([`crate::scene::write_atomically`], [`crate::scene::OutputSet::commit`]) refuse to put any
//! file in place, so an interrupted job leaves no output, old or half-done, and no temporary
//! file behind. Nothing in the library asks for it by itself.

use std::sync::atomic::{AtomicBool, Ordering};

/// Whether a stop has been requested.
static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Asks every running job to stop: work stops where it looks, and no output is written.
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Whether a stop has been requested.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}

/// The error a writer gives once a stop has been requested.
pub fn error() -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::Interrupted,
        "interrupted (Ctrl-C): nothing written",
    )
}
