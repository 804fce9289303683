//! The `stackplan` program, built inside the end-to-end test package (see Cargo.toml).

fn main() -> std::process::ExitCode {
    stackplan_cli::main()
}
