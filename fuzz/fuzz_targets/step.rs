//! STEP reader (exchange-file parser, entity graph to B-rep, units) on arbitrary bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use stackplan_geom::io::step::{StepOptions, parse_step};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = parse_step(data, Path::new("fuzz.stp"), &StepOptions::default());
});
