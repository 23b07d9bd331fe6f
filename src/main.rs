//! The `conduit` binary (being assembled).

fn main() {}
