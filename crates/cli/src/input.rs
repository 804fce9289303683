//! Reading parts for every command: a file (`.json`, `.stl`, `.obj`) or a built-in example (`example:NAME`).

use anyhow::Context;
use stackplan_geom::Part;
use stackplan_geom::sheet_metal::Decomposition;

/// Where a part comes from, shared by every command that reads one.
#[derive(Debug, Clone, clap::Args)]
pub struct PartArgs {
    /// Part file (.json, .stl, .obj) or a built-in example `example:NAME` (channel, triangle, complex, cube,
    /// l-corner, block).
    pub part: String,
    /// Split concave sheet-metal faces by plain triangulation (the seed's component counts) instead of merging
    /// triangles into larger convex pieces.
    #[arg(long)]
    pub triangulate: bool,
    /// Decompose non-convex mesh shells approximately (VHACD) instead of rejecting them.
    #[arg(long)]
    pub decompose: bool,
}

impl PartArgs {
    /// The decomposition the flags ask for.
    pub fn decomposition(&self) -> Decomposition {
        if self.triangulate { Decomposition::Triangulation } else { Decomposition::ConvexMerge }
    }
}

/// Reads the part named by `args`.
pub fn load_part(args: &PartArgs) -> anyhow::Result<Part> {
    load_part_spec(&args.part, args.decomposition(), args.decompose)
}

/// Reads a part from a path or `example:NAME`.
pub fn load_part_spec(spec: &str, decomposition: Decomposition, decompose_mesh: bool) -> anyhow::Result<Part> {
    if let Some(name) = spec.strip_prefix("example:") {
        return stackplan_geom::examples::part_by_name(name, decomposition).with_context(|| {
            format!("no built-in example named {name:?} (try channel, triangle, complex, cube, l-corner, block)")
        });
    }
    let options = stackplan_geom::io::ReadOptions { decomposition, decompose_mesh, ..Default::default() };
    Ok(stackplan_geom::io::read_part(std::path::Path::new(spec), &options)?)
}
