//! `cargo xtask`: project automation (the pattern of rust-analyzer's xtask).
//!
//! * `cargo xtask fixtures [--check]` writes `fixtures/parts/` from the built-in example parts, deterministically;
//!   `--check` fails when a committed fixture differs from what the code generates (stale fixture).
//! * `cargo xtask regress [--bless] [--slow] [FILTER]` runs every scenario in `fixtures/regress/*.json` through the library,
//!   compares the results with the golden files in `fixtures/regress/golden/` (tolerances per field), prints a table
//!   and exits non-zero on any difference; `--bless` rewrites the goldens; `--slow` adds `fixtures/regress/slow/`
//!   (scenarios too slow for CI in the dev profile: the 15-part plan of the real part `bendfm_0`).

#![allow(clippy::print_stdout, clippy::print_stderr)] // xtask is a terminal program

mod fixtures;
mod regress;
mod scenarios;

use std::path::PathBuf;
use std::process::ExitCode;

fn workspace_root() -> PathBuf {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    here.parent().map(PathBuf::from).unwrap_or(here)
}

fn usage() -> ExitCode {
    eprintln!("usage: cargo xtask fixtures [--check] | cargo xtask regress [--bless] [--slow] [FILTER]");
    ExitCode::from(2)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let root = workspace_root();
    let result = match args.first().map(String::as_str) {
        Some("fixtures") => {
            let check = args.iter().any(|a| a == "--check");
            fixtures::run(&root, check)
        }
        Some("regress") => {
            let bless = args.iter().any(|a| a == "--bless");
            let filter = args.iter().skip(1).find(|a| !a.starts_with("--")).cloned();
            let slow = args.iter().any(|a| a == "--slow");
            regress::run(&root, bless, filter.as_deref(), slow)
        }
        _ => return usage(),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("xtask: {e:#}");
            ExitCode::from(2)
        }
    }
}
