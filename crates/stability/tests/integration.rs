//! The integration tests of this package, one module per file, built as one test binary: one compile and one link
//! instead of one per file (each test binary links every dependency again). `cargo test -p PACKAGE NAME` still
//! filters by module, e.g. `tightness::`.

mod addition;
mod analytic;
mod clearance_slice;
mod common;
mod contacts;
mod grasp_poses;
mod grasp_realparts;
mod growing;
mod insertion;
mod instability;
mod physics;
mod release_clearance;
mod shortcuts;
