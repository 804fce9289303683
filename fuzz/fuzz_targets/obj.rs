//! OBJ parser (groups, index forms, convexity check) on arbitrary bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use stackplan_geom::io::{ReadOptions, parse_obj};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = parse_obj(data, Path::new("fuzz.obj"), &ReadOptions::default());
});
