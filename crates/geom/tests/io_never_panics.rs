//! Every parser returns (Ok or a located Err) on arbitrary bytes and on mutated valid files; it never panics.
//! This is the in-CI counterpart of the cargo-fuzz targets in `fuzz/`.

use proptest::prelude::*;
use stackplan_geom::io::stack::parse_stack;
use stackplan_geom::io::{self, ReadOptions};
use std::path::{Path, PathBuf};

fn corpus() -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    for dir in ["tests/data/broken", "tests/data/good"] {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(dir);
        let Ok(entries) = std::fs::read_dir(&dir) else { continue };
        for entry in entries.flatten() {
            let path = entry.path();
            if let (Some(name), Ok(bytes)) = (path.file_name().and_then(|n| n.to_str()), std::fs::read(&path)) {
                files.push((name.to_string(), bytes));
            }
        }
    }
    files.sort();
    files
}

/// Runs every parser on `bytes`; any error must name the file.
fn parse_all(bytes: &[u8]) {
    let options = ReadOptions::default();
    let check = |r: Result<(), io::IoError>, name: &str| {
        if let Err(e) = r {
            assert!(e.to_string().contains(name), "error without the file name: {e}");
        }
    };
    check(io::parse_part_json(bytes, Path::new("fuzz.json"), &options).map(|_| ()), "fuzz.json");
    check(io::parse_stl(bytes, Path::new("fuzz.stl"), &options).map(|_| ()), "fuzz.stl");
    check(io::parse_obj(bytes, Path::new("fuzz.obj"), &options).map(|_| ()), "fuzz.obj");
    check(parse_stack(bytes, Path::new("/nonexistent/fuzz-stack.json"), &options).map(|_| ()), "fuzz-stack.json");
}

#[derive(Debug, Clone)]
enum Mutation {
    Flip { at: usize, value: u8 },
    Truncate { at: usize },
    Insert { at: usize, text: &'static str },
    Delete { at: usize, len: usize },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let tokens = prop::sample::select(vec![
        "-",
        "nan",
        "1e400",
        "0",
        "-1",
        "/",
        " ",
        "\n",
        "f 1 2 3\n",
        "v 0 0 0\n",
        "g x\n",
        "[",
        "]",
        "{",
        "}",
        ",",
        "\"",
        "facet",
        "endsolid",
        "\u{0}",
        "\"convex_pieces\": []",
        "9999999999",
    ]);
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(at, value)| Mutation::Flip { at, value }),
        any::<usize>().prop_map(|at| Mutation::Truncate { at }),
        (any::<usize>(), tokens).prop_map(|(at, text)| Mutation::Insert { at, text }),
        (any::<usize>(), 1usize..16).prop_map(|(at, len)| Mutation::Delete { at, len }),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let n = bytes.len().max(1);
    match *m {
        Mutation::Flip { at, value } => {
            if !bytes.is_empty() {
                bytes[at % n] = value;
            }
        }
        Mutation::Truncate { at } => bytes.truncate(at % n),
        Mutation::Insert { at, text } => {
            let at = at % (bytes.len() + 1);
            bytes.splice(at..at, text.bytes());
        }
        Mutation::Delete { at, len } => {
            let at = at % n;
            let end = (at + len).min(bytes.len());
            if at < end {
                bytes.drain(at..end);
            }
        }
    }
}

proptest! {
    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        parse_all(&bytes);
    }

    #[test]
    fn text_like_bytes_never_panic(text in "(solid|facet|vertex|endloop|v|f|g|o|[0-9./ -]|\n|\\{|\\}|\\[|\\]|,|:|\"name\"|\"convex_pieces\"){0,80}") {
        parse_all(text.as_bytes());
    }

    #[test]
    fn mutated_files_never_panic(seed in any::<prop::sample::Index>(), mutations in prop::collection::vec(mutation(), 1..6)) {
        let files = corpus();
        prop_assume!(!files.is_empty());
        let (_, original) = &files[seed.index(files.len())];
        let mut bytes = original.clone();
        for m in &mutations {
            apply(&mut bytes, m);
        }
        parse_all(&bytes);
    }
}

#[test]
fn the_whole_corpus_parses_without_panicking_in_every_parser() {
    let files = corpus();
    assert!(files.len() >= 20, "corpus too small: {}", files.len());
    for (_, bytes) in &files {
        parse_all(bytes);
    }
}
