//! `stackplan demo [--out DIR]`: the built-in example parts, described and drawn, written under `demo/` (not `out/`,
//! where `stackplan plan` writes).
//!
//! For each example part: `NAME.json` (the `part info --json` document), `NAME.glb` (binary glTF for any 3-D viewer),
//! `NAME.svg` and `NAME.png` (isometric, top and side views, components coloured), and `summary.json`.

use crate::Outcome;
use crate::cmd::part::part_info;
use crate::output::{json_text, write_all_atomic};
use crate::render::{CG_MARK, LegendItem, Marker, Scene, Solid, Swatch, part_color, png, svg};
use anyhow::Context;
use stackplan_geom::io::glb::{GlbItem, glb_bytes};
use std::path::PathBuf;

/// Arguments of `demo`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output directory (created if missing; `plan` writes to out/).
    #[arg(long, default_value = "demo")]
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
                .components()
                .iter()
                .enumerate()
                .map(|(i, c)| Solid { polytope: c.clone(), color: part_color(i), part: 0 })
                .collect(),
            markers: vec![Marker { position: part.mass().center_of_gravity, color: CG_MARK }],
            floor: Vec::new(),
            title: format!(
                "{name}: {} convex pieces, {:.0} mm^3, {:.0} x {:.0} x {:.0} mm",
                part.components().len(),
                part.mass().volume,
                info.bounding_box[1][0] - info.bounding_box[0][0],
                info.bounding_box[1][1] - info.bounding_box[0][1],
                info.bounding_box[1][2] - info.bounding_box[0][2]
            ),
            labels: Vec::new(),
            legend: vec![
                LegendItem::new(Swatch::Square(part_color(0)), "one colour per convex piece"),
                LegendItem::new(Swatch::Disc(CG_MARK), "centre of gravity"),
            ],
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
    let count = files.len();
    write_all_atomic(files)?;
    crate::output::print_summary(&format!(
        "wrote {count} files for {} example parts to {} (NAME.json, .glb, .svg, .png; summary.json)\n",
        EXAMPLES.len(),
        args.out.display()
    ))?;
    Ok(Outcome::Success)
}
