//! `stackplan render PLAN.json [--out DIR] [--png F] [--svg F] [--build-png F] [--build-svg F] [--glb F]
//! [--html F]`: redraws the pictures of an existing plan file (written by `stackplan plan` or `stackplan sweep`)
//! with the same code the planner's command uses, so the files are byte-identical to the ones written with the plan.
//! `--out DIR` writes every standard file (`plan.json`, `stack.svg`, `stack.png`, `build.svg`, `build.png`,
//! `stack.glb`, `report.html`) into DIR; the single-file options write one picture each. A malformed plan file is
//! reported with its name ([`crate::plan_files::PlanFileError`]) before anything is written.

use crate::Outcome;
use crate::output::write_all_atomic;
use crate::plan_files::{plan_pictures, read_plan_file};
use anyhow::Context;
use std::path::PathBuf;

/// Arguments of `render`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The plan file (`plan.json` of `stackplan plan`).
    pub plan: PathBuf,
    /// Write every standard file of a plan into this directory (the HTML report refers to its siblings).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The stack picture as PNG (isometric, top and side views, parts numbered).
    #[arg(long, value_name = "F")]
    pub png: Option<PathBuf>,
    /// The stack picture as SVG.
    #[arg(long, value_name = "F")]
    pub svg: Option<PathBuf>,
    /// The step-by-step build strip as PNG.
    #[arg(long, value_name = "F")]
    pub build_png: Option<PathBuf>,
    /// The step-by-step build strip as SVG.
    #[arg(long, value_name = "F")]
    pub build_svg: Option<PathBuf>,
    /// The stack as binary glTF.
    #[arg(long, value_name = "F")]
    pub glb: Option<PathBuf>,
    /// The HTML report (it shows `stack.png` and `build.png` from its own directory).
    #[arg(long, value_name = "F")]
    pub html: Option<PathBuf>,
}

/// Runs `render`.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    let singles = [&args.png, &args.svg, &args.build_png, &args.build_svg, &args.glb, &args.html];
    anyhow::ensure!(
        args.out.is_some() || singles.iter().any(|o| o.is_some()),
        "nothing to render: give --out DIR or at least one of --png, --svg, --build-png, --build-svg, --glb, --html"
    );
    let file = read_plan_file(&args.plan)?;
    let pictures = plan_pictures(&file)?;
    let text = match &args.out {
        Some(_) => std::fs::read(&args.plan)?,
        None => Vec::new(),
    };
    let outputs: [(&Option<PathBuf>, &[u8]); 6] = [
        (&args.png, &pictures.stack_png),
        (&args.svg, pictures.stack_svg.as_bytes()),
        (&args.build_png, &pictures.build_png),
        (&args.build_svg, pictures.build_svg.as_bytes()),
        (&args.glb, &pictures.glb),
        (&args.html, pictures.html.as_bytes()),
    ];
    // every requested file, or none
    let mut files: Vec<(PathBuf, &[u8])> = Vec::new();
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        files.push((dir.join("plan.json"), &text));
        files.extend(pictures.files().into_iter().map(|(name, bytes)| (dir.join(name), bytes)));
    }
    files.extend(outputs.into_iter().filter_map(|(path, bytes)| path.as_ref().map(|p| (p.clone(), bytes))));
    let written: Vec<PathBuf> = files.iter().map(|(p, _)| p.clone()).collect();
    write_all_atomic(files)?;
    crate::output::print_wrote(&written.iter().map(PathBuf::as_path).collect::<Vec<_>>(), false)?;
    Ok(Outcome::Success)
}
