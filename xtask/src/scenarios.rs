//! The regression scenario kinds. Each kind reads its inputs from the scenario JSON and returns named result fields.
//!
//! * `part`: a part file (or built-in example) with a decomposition: component count, volume, centre of gravity,
//!   bounding box, boundary face count.

use crate::regress::Fields;
use anyhow::{Context, bail};
use serde_json::Value;
use stackplan_geom::Part;
use stackplan_geom::sheet_metal::Decomposition;
use std::path::Path;

/// Runs one scenario (`dir` is the scenario's directory, for relative paths).
pub fn run(scenario: &Value, dir: &Path) -> anyhow::Result<Fields> {
    let kind = scenario.get("kind").and_then(Value::as_str).context("scenario has no \"kind\"")?;
    match kind {
        "part" => part(scenario, dir),
        other => bail!("unknown scenario kind {other:?}"),
    }
}

fn decomposition(scenario: &Value) -> anyhow::Result<Decomposition> {
    match scenario.get("decomposition").and_then(Value::as_str) {
        None | Some("convex_merge") => Ok(Decomposition::ConvexMerge),
        Some("triangulation") => Ok(Decomposition::Triangulation),
        Some(other) => bail!("unknown decomposition {other:?}"),
    }
}

/// Loads the scenario's `"part"` (a path relative to the scenario file) with its decomposition.
pub fn load_part(scenario: &Value, key: &str, dir: &Path) -> anyhow::Result<Part> {
    let rel = scenario.get(key).and_then(Value::as_str).with_context(|| format!("scenario has no {key:?}"))?;
    let options = stackplan_geom::io::ReadOptions { decomposition: decomposition(scenario)?, ..Default::default() };
    Ok(stackplan_geom::io::read_part(&dir.join(rel), &options)?)
}

fn part(scenario: &Value, dir: &Path) -> anyhow::Result<Fields> {
    let p = load_part(scenario, "part", dir)?;
    let (lo, hi) = p.aabb();
    let mut f = Fields::new();
    f.insert("components".into(), p.components.len().into());
    f.insert("volume".into(), p.mass.volume.into());
    f.insert("center_of_gravity".into(), p.mass.center_of_gravity.to_array().to_vec().into());
    f.insert("bounding_box_min".into(), lo.to_array().to_vec().into());
    f.insert("bounding_box_max".into(), hi.to_array().to_vec().into());
    f.insert("boundary_faces".into(), p.boundary.len().into());
    f.insert("vertices".into(), p.vertex_count().into());
    Ok(f)
}
