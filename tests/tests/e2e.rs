//! The integration tests of this package, one module per file, built as one test binary: one compile and one link
//! instead of one per file (each test binary links every dependency again). `cargo test -p PACKAGE NAME` still
//! filters by module, e.g. `tightness::`.

mod batch;
mod commands;
mod common;
mod conventions;
mod part;
mod plans;
