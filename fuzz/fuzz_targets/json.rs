//! Part JSON and stack-file parsers on arbitrary bytes: must return, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use stackplan_geom::io::{ReadOptions, parse_part_json, stack::parse_stack};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let options = ReadOptions::default();
    let _ = parse_part_json(data, Path::new("fuzz.json"), &options);
    // a relative part path resolves to a directory that does not exist, so no real file is read
    let _ = parse_stack(data, Path::new("/nonexistent/fuzz-stack.json"), &options);
});
