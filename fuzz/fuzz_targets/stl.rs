//! STL parser (ASCII and binary detection, shell splitting, convexity check) on arbitrary bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use stackplan_geom::io::{ReadOptions, parse_stl};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = parse_stl(data, Path::new("fuzz.stl"), &ReadOptions::default());
});
