//! The integration tests of this package, one module per file, built as one test binary: one compile and one link
//! instead of one per file (each test binary links every dependency again). `cargo test -p PACKAGE NAME` still
//! filters by module, e.g. `tightness::`.

mod cadparts;
mod decomposition;
mod from_faces_and_edges;
mod hull_props;
mod io_broken;
mod io_never_panics;
mod io_roundtrip;
mod realparts;
mod step;
