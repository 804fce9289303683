//! `stackplan demo [--out DIR]`: the built-in example parts, described and drawn, written under `out/`.
//!
//! For each example part: `NAME.json` (the `part info --json` document), `NAME.glb` (binary glTF for any 3-D viewer),
//! `NAME.svg` and `NAME.png` (isometric, top and side views, components coloured), and `summary.json`.

use crate::Outcome;
use crate::cmd::part::part_info;
use crate::output::{json_text, write_all_atomic};
use crate::render::{Marker, Scene, Solid, part_color, png, svg};
use anyhow::Context;
use stackplan_geom::io::glb::{GlbItem, glb_bytes};
use std::path::PathBuf;

/// Arguments of `demo`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output directory (created if missing).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Use the seed's plain triangulation for concave faces.
    #[arg(long)]
    pub triangulate: bool,
}

/// The names of the built-in examples, in the order the demo shows them.
pub const EXAMPLES: [&str; 6] = ["channel", "triangle", "complex", "cube", "l-corner", "block"];

/// Runs the demo.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let decomposition = crate::input::decomposition(args.triangulate);
    let bar = indicatif::ProgressBar::new(EXAMPLES.len() as u64);
    let mut summary = Vec::new();
    // every file of the demo, written all or none at the end
    let mut files: Vec<(std::path::PathBuf, Vec<u8>)> = Vec::new();
    for name in EXAMPLES {
        bar.set_message(name);
        let part = stackplan_geom::examples::part_by_name(name, decomposition)
            .with_context(|| format!("built-in example {name} is missing"))?;
        let info = part_info(&part, true);
        files.push((args.out.join(format!("{name}.json")), json_text(&info)?.into_bytes()));
        files.push((args.out.join(format!("{name}.glb")), glb_bytes(&[GlbItem::part(&part)])));
        let scene = Scene {
            solids: part
                .components
                .iter()
                .enumerate()
                .map(|(i, c)| Solid { polytope: c.clone(), color: part_color(i), part: 0 })
                .collect(),
            markers: vec![Marker { position: part.mass.center_of_gravity, color: [200, 0, 0] }],
            floor: Vec::new(),
            title: format!("{name}: {} convex components, c.g. marked", part.components.len()),
            labels: Vec::new(),
        };
        files.push((args.out.join(format!("{name}.svg")), svg(&scene).into_bytes()));
        files.push((args.out.join(format!("{name}.png")), png(&scene, 2.0)?));
        summary.push(serde_json::json!({
            "name": name,
            "components": info.components,
            "volume": info.volume,
            "center_of_gravity": info.center_of_gravity,
            "files": [format!("{name}.json"), format!("{name}.glb"), format!("{name}.svg"), format!("{name}.png")],
        }));
        bar.inc(1);
    }
    bar.finish_and_clear();
    files.push((args.out.join("summary.json"), json_text(&summary)?.into_bytes()));
    write_all_atomic(files)?;
    tracing::info!("wrote {} examples to {}", EXAMPLES.len(), args.out.display());
    Ok(Outcome::Success)
}
