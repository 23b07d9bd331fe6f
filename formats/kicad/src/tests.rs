//! Unit tests on hand-written files.
