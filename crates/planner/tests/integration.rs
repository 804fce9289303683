//! The integration tests of this package, one module per file, built as one test binary: one compile and one link
//! instead of one per file (each test binary links every dependency again). `cargo test -p PACKAGE NAME` still
//! filters by module, e.g. `tightness::`.

mod carried_frontiers;
mod common;
mod exactness;
mod extrapolation;
mod omega;
mod omega_2d;
mod paper_scenarios;
mod partitions;
mod placement;
mod plans_vs_parry;
mod plates;
mod resumable;
mod searched_elsewhere;
