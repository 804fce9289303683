//! The `stackplan` binary. All command logic lives in the library (`src/lib.rs`, one module per command under
//! `src/cmd/`), so the end-to-end tests in `tests/` can build the same program.

fn main() -> std::process::ExitCode {
    stackplan_cli::main()
}
