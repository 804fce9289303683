//! The `stackplan` command line.
//!
//! Every subcommand is a module in `cmd/` with a `#[derive(clap::Args)] pub struct Args` and a
//! `pub fn run(args: &Args) -> anyhow::Result<Outcome>`; [`Command`] below lists them. Library crates never print:
//! only this crate writes to the terminal or to files (JSON on stdout or atomically into files).

pub mod cmd;
pub mod input;
pub mod logging;
pub mod options;
pub mod output;
pub mod plan_files;
pub mod render;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// What a command reports back to `main`: success, or checks that failed (non-zero exit without an error message).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Everything asked for was done and every check passed.
    Success,
    /// The command ran, but a check it performs failed (exit status 1).
    ChecksFailed,
}

/// Plans how to stack polyhedral sheet-metal parts and analyses how parts touch.
#[derive(Debug, Parser)]
#[command(name = "stackplan", version, about, long_about = None)]
pub struct Cli {
    /// More logging (-v: info, -vv: debug, -vvv: trace).
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    pub verbose: u8,
    /// Only errors: no logging, and no summary from plan, sweep or check without --json (the exit status still
    /// tells). What other commands are asked to print is printed.
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, global = true)]
    pub threads: Option<usize>,
    /// For STL and OBJ parts: a length within which a mesh polygon counts as lying in a face plane of the part's
    /// convex pieces, for meshes written with fewer digits than a turned part's faces need (default: 1e-9 of the
    /// part's size, and for single-precision coordinates 16 roundings to f32 of the largest; see docs/formats.md).
    #[arg(long, global = true, value_name = "MM")]
    pub mesh_tolerance: Option<f64>,
    /// The length unit of STL and OBJ files, which carry none: mm, cm, m or in. STEP files name their own unit.
    #[arg(long, global = true, value_name = "UNIT", default_value = "mm")]
    pub units: stackplan_geom::io::Units,
    /// For STEP files and non-convex meshes recognised as sheet metal: how far a convex piece may stand outside the
    /// solid at a bend or a rounded outline (mm). Bends are covered by segments whose outer arc is made of tangents
    /// and inner arc of chords, so that the pieces always contain the steel.
    #[arg(long, global = true, value_name = "MM", default_value_t = stackplan_geom::cad::recognise::DEFAULT_BEND_TOLERANCE)]
    pub bend_tolerance: f64,
    /// Which solid of a STEP file with several (0-based, in file order).
    #[arg(long, global = true, value_name = "N")]
    pub solid: Option<usize>,
    /// Decompose a non-convex mesh approximately (VHACD) instead of recognising it as sheet metal. The pieces only
    /// approximate the solid (they may fill holes and stand outside it), and the part says so wherever it goes.
    #[arg(long, global = true)]
    pub decompose: bool,
    /// The command.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Information about a part, and export to other formats.
    #[command(subcommand)]
    Part(cmd::part::PartCommand),
    /// A stacking plan for N identical parts, with pictures, a 3-D model and a report (default: 15 Channel parts).
    Plan(cmd::plan::Args),
    /// Redraws the pictures, 3-D model and report of an existing plan file.
    Render(cmd::render::Args),
    /// Many stacking plans from a JSON Lines file of jobs, in parallel, resumable, with a summary table.
    Batch(cmd::batch::Args),
    /// Plans the same stack for several weights w and draws the stacks side by side (the seed's Fig. 2).
    Sweep(cmd::sweep::Args),
    /// The built-in example parts described and drawn under out/.
    Demo(cmd::demo::Args),
    /// The best interference-free placements of one part in a stack.
    Place(cmd::place::Args),
    /// Constant-structure orientation intervals of every convex pair, with the events that end them.
    Intervals(cmd::intervals::Args),
    /// The translational c-space obstacle of every convex pair (JSON, OBJ or SVG slices).
    Cspace(cmd::cspace::Args),
    /// Interfering (penetrating / touching) component pairs of the moving part at a position.
    Interference(cmd::interference::Args),
    /// Interference, clearance, stability, grasp, insertion and removal of every part of a stack (exit 1 on failure).
    Check(cmd::check::Args),
    /// Assembly contact states of two parts within bounded misalignment, with their extremal configurations.
    Contacts(cmd::contacts::Args),
}

/// Runs the command line with the process arguments; returns the exit status.
/// The command line as clap sees it, with negative numbers taken as values in every subcommand (`--theta-deg -30`,
/// `--fixed-z -1`, `--height -5` reaches its own check), not as unknown flags.
///
/// clap's own test for a negative number does not take a signed exponent (`-1e-5`), so every option whose value is a
/// single `f64` also takes values that start with a hyphen: `--theta-deg -1e-5` is a turn, and `--w -v` is an invalid
/// number for `--w` rather than a missing value.
pub fn command() -> clap::Command {
    with_negatives(<Cli as clap::CommandFactory>::command())
}

/// `c` and its subcommands taking negative numbers as values ([`command`]).
pub fn with_negatives(c: clap::Command) -> clap::Command {
    c.allow_negative_numbers(true)
        .mut_args(|a| {
            if a.get_value_parser().type_id() == std::any::TypeId::of::<f64>() {
                a.allow_hyphen_values(true)
            } else {
                a
            }
        })
        .mut_subcommands(with_negatives)
}

pub fn main() -> ExitCode {
    let cli = match <Cli as clap::FromArgMatches>::from_arg_matches(&command().get_matches()) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    logging::init(cli.verbose, cli.quiet);
    output::set_quiet(cli.quiet);
    let settings = input::ReadSettings {
        mesh_tolerance: cli.mesh_tolerance,
        units: cli.units,
        bend_tolerance: Some(cli.bend_tolerance),
        solid: cli.solid,
        decompose: cli.decompose,
    };
    if let Some(n) = cli.threads
        && let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n.max(1)).build_global()
    {
        tracing::warn!("could not set the thread count: {e}");
    }
    let result = input::set_read_settings(settings).and_then(|()| match &cli.command {
        Command::Part(c) => cmd::part::run(c),
        Command::Plan(a) => cmd::plan::run(a),
        Command::Batch(a) => cmd::batch::run(a),
        Command::Render(a) => cmd::render::run(a),
        Command::Sweep(a) => cmd::sweep::run(a),
        Command::Demo(a) => cmd::demo::run(a),
        Command::Place(a) => cmd::place::run(a),
        Command::Intervals(a) => cmd::intervals::run(a),
        Command::Cspace(a) => cmd::cspace::run(a),
        Command::Interference(a) => cmd::interference::run(a),
        Command::Check(a) => cmd::check::run(a),
        Command::Contacts(a) => cmd::contacts::run(a),
    });
    // every distinct warning once, with its count, before the error (if any)
    logging::flush_warnings();
    match result {
        Ok(Outcome::Success) => ExitCode::SUCCESS,
        Ok(Outcome::ChecksFailed) => ExitCode::from(1),
        Err(e) => {
            // the one place where the program writes errors for people
            #[allow(clippy::print_stderr)]
            {
                eprintln!("error: {}", error_text(&e));
            }
            ExitCode::from(2)
        }
    }
}

/// The error and its causes joined by ": " (as `{:#}` prints them), leaving out a cause whose message the text
/// already ends with: the typed errors of the libraries name their source in their own message.
pub fn error_text(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let message = cause.to_string();
        if text.ends_with(&message) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&message);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::error_text;
    use anyhow::Context;

    #[derive(Debug, thiserror::Error)]
    #[error("the hull is flat")]
    struct Flat;

    /// A typed error that names its source in its own message.
    #[derive(Debug, thiserror::Error)]
    #[error("part.json: piece 0: degenerate piece: {source}")]
    struct Degenerate {
        source: Flat,
    }

    #[test]
    fn a_cause_the_message_already_names_is_printed_once() {
        let e = anyhow::Error::new(Degenerate { source: Flat });
        assert_eq!(format!("{e:#}"), "part.json: piece 0: degenerate piece: the hull is flat: the hull is flat");
        assert_eq!(error_text(&e), "part.json: piece 0: degenerate piece: the hull is flat");
        let wrapped = Err::<(), _>(e).context("reading the stack s.json").expect_err("an error");
        assert_eq!(
            error_text(&wrapped),
            "reading the stack s.json: part.json: piece 0: degenerate piece: the hull is flat"
        );
        // causes not named by the message above them stay
        let plain = Err::<(), _>(Flat).context("loading").expect_err("an error");
        assert_eq!(error_text(&plain), "loading: the hull is flat");
    }
}
