//! STEP reader (exchange-file parser, entity graph to B-rep, units, and the tessellation of solids with faces on
//! other surfaces than planes and cylinders) on arbitrary bytes. Seed its corpus with `fixtures/realparts/*.stp` and
//! `fixtures/cad/*.step` to reach the B-rep and the tessellation.
#![no_main]

use libfuzzer_sys::fuzz_target;
use stackplan_geom::io::step::{StepOptions, parse_step};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = parse_step(data, Path::new("fuzz.stp"), &StepOptions::default());
});
