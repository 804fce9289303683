//! `cargo xtask fixtures [--check]`: the committed part files under `fixtures/parts/`, generated from the built-in
//! examples of `stackplan_geom::examples` (the single source of the part designs).

use anyhow::Context;
use stackplan_geom::examples::{self, Example};
use std::path::Path;

/// (file name, JSON text) of every fixture part, in a fixed order.
fn generate() -> anyhow::Result<Vec<(String, String)>> {
    let mut out = Vec::new();
    for name in examples::NAMES {
        let value = match examples::by_name(name).with_context(|| format!("example {name} is missing"))? {
            // sheet-metal parts are written as their mid-surface model, so the fixture is the design itself
            Example::SheetMetal(model) => serde_json::json!({ "name": name, "sheet_metal": model }),
            // solid parts in the convex-pieces form
            Example::Solid(part) => serde_json::from_str(&stackplan_geom::io::json::part_json_string(&part))?,
        };
        let mut text = serde_json::to_string_pretty(&value)?;
        text.push('\n');
        out.push((format!("{name}.json"), text));
    }
    Ok(out)
}

/// Writes (or with `check`, compares) the fixtures. Returns false when `check` finds a stale or missing file.
pub fn run(root: &Path, check: bool) -> anyhow::Result<bool> {
    let dir = root.join("fixtures").join("parts");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut fresh = true;
    for (file, text) in generate()? {
        let path = dir.join(&file);
        let current = std::fs::read_to_string(&path).ok();
        if current.as_deref() == Some(text.as_str()) {
            continue;
        }
        if check {
            eprintln!("stale fixture: {} (run `cargo xtask fixtures`)", path.display());
            fresh = false;
        } else {
            let tmp = dir.join(format!(".{file}.tmp"));
            std::fs::write(&tmp, &text).with_context(|| format!("cannot write {}", tmp.display()))?;
            std::fs::rename(&tmp, &path).with_context(|| format!("cannot write {}", path.display()))?;
            println!("wrote {}", path.display());
        }
    }
    if check && fresh {
        println!("fixtures are up to date");
    }
    Ok(fresh)
}
