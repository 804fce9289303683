//! Test parts (boxes and wedges built with the exact hull), nested fixture columns, and the margin comparison.
#![allow(dead_code)]

use glam::{DMat3, DVec3};
use stackplan_geom::Pose;
use stackplan_geom::{ConvexPolytope, Part, PartOrigin, convex_hull};
use stackplan_stability::PlacedPart;
use stackplan_stability::contacts::analyse_contacts;
use stackplan_stability::resting_poses::resting_poses;
use stackplan_stability::world::{stack_tolerance, world_stack};

/// Number of proptest cases: `PROPTEST_CASES` if set, else `default`.
pub fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

/// Runs `f(label, part, stack)` on the fixture columns of every fixture part ([`fixture_parts`]) in its two lowest
/// resting poses, for each shift `(dx, dy)` of `shifts` ([`fixture_columns`]).
pub fn for_each_fixture_column(shifts: &[(f64, f64)], mut f: impl FnMut(&str, &Part, &[PlacedPart<'_>])) {
    for (file, part) in &fixture_parts() {
        for pose in 0..2 {
            for &(dx, dy) in shifts {
                let stack = fixture_columns(part, pose, dx, dy);
                f(&format!("{} pose {pose} shift ({dx}, {dy})", file.display()), part, &stack);
            }
        }
    }
}

/// The box `[lo, hi]`.
pub fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
    ConvexPolytope::cuboid(lo, hi).expect("box")
}

/// A box part `[0, size]` with density 1.
pub fn box_part(name: &str, size: DVec3) -> Part {
    Part::from_components(name, vec![cuboid(DVec3::ZERO, size)], 1.0, PartOrigin::ConvexPieces).expect("box part")
}

/// A part made of several boxes.
pub fn boxes_part(name: &str, boxes: &[(DVec3, DVec3)]) -> Part {
    let comps = boxes.iter().map(|(lo, hi)| cuboid(*lo, *hi)).collect();
    Part::from_components(name, comps, 1.0, PartOrigin::ConvexPieces).expect("boxes part")
}

/// A wedge: the triangle (0,0), (length,0), (0,height) in xz extruded over y in [0, width]; its sloped face rises
/// towards -x with angle atan(height / length).
pub fn wedge_part(name: &str, length: f64, height: f64, width: f64) -> Part {
    let tri = [DVec3::ZERO, DVec3::new(length, 0.0, 0.0), DVec3::new(0.0, 0.0, height)];
    let pts: Vec<DVec3> = tri.iter().flat_map(|&p| [p, p + DVec3::Y * width]).collect();
    let hull = convex_hull(&pts).expect("wedge").polytope;
    Part::from_components(name, vec![hull], 1.0, PartOrigin::ConvexPieces).expect("wedge part")
}

/// A placement with identity rotation.
pub fn at(part: &Part, position: DVec3) -> PlacedPart<'_> {
    PlacedPart { part, pose: Pose { rotation: DMat3::IDENTITY, position } }
}

/// Margins agree within 1e-6 relative (both absent, or both present).
pub fn same_margin(fast: Option<f64>, plain: Option<f64>) -> bool {
    match (fast, plain) {
        (Some(f), Some(p)) => (f - p).abs() <= 1e-6 * (1.0 + p.abs()),
        (f, p) => f.is_none() && p.is_none(),
    }
}

/// The smallest upward shift at which a copy of `placed` moved by `(dx, dy)` and lifted does not interfere with it
/// (bisection on the interference test): the copy then rests on (or nests in) the one below.
pub fn nesting_height(placed: PlacedPart<'_>, dx: f64, dy: f64, upper: f64) -> f64 {
    let interferes = |dz: f64| {
        let top = PlacedPart {
            pose: Pose { position: placed.pose.position + DVec3::new(dx, dy, dz), ..placed.pose },
            ..placed
        };
        let parts = world_stack(&[placed, top]).expect("world");
        let tol = stack_tolerance(&parts).linear;
        !analyse_contacts(&parts, tol, |_| true).interferences.is_empty()
    };
    let (mut lo, mut hi) = (0.0, upper);
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if interferes(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// Every fixture part (`fixtures/parts/*.json`, sorted by file name) with its file, as the library reads it.
pub fn fixture_parts() -> Vec<(std::path::PathBuf, Part)> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/parts");
    let mut files: Vec<_> = std::fs::read_dir(dir).expect("fixtures").flatten().map(|e| e.path()).collect();
    files.sort();
    let parts: Vec<_> = files
        .into_iter()
        .filter(|f| f.extension().is_some_and(|e| e == "json"))
        .map(|f| {
            let part = stackplan_geom::io::read_part(&f, &Default::default()).expect("fixture part");
            (f, part)
        })
        .collect();
    assert!(parts.len() >= 6, "the six fixture parts: {parts:?}");
    parts
}

/// Two columns of three copies of `part` in resting pose `pose`, each copy shifted by `(dx, dy)` from the one below
/// and lowered onto it.
pub fn fixture_columns(part: &Part, pose: usize, dx: f64, dy: f64) -> Vec<PlacedPart<'_>> {
    let poses = resting_poses(part).expect("poses");
    let pose = &poses[pose.min(poses.len() - 1)];
    let base = PlacedPart { part, pose: Pose { rotation: pose.rotation, position: pose.position } };
    let parts = world_stack(&[base]).expect("world");
    let size = parts[0].aabb.1 - parts[0].aabb.0;
    let rise = nesting_height(base, dx, dy, size.z + 1.0);
    let mut out = Vec::new();
    for level in 0..3 {
        for column in 0..2 {
            let shift =
                DVec3::new((size.x + 20.0) * column as f64 + dx * level as f64, dy * level as f64, rise * level as f64);
            out.push(PlacedPart { pose: Pose { position: base.pose.position + shift, ..base.pose }, ..base });
        }
    }
    out
}

/// A layer of box columns: its height and per column (centre offset x, y, size x, y).
pub type Layer = (f64, Vec<(f64, f64, f64, f64)>);

/// Stacks the boxes given per layer and column (columns 200 mm apart): (column, lower corner, size) per box in
/// placement order.
pub fn build(layers: &[Layer], columns: usize) -> Vec<(usize, DVec3, DVec3)> {
    let mut out = Vec::new();
    let mut z = 0.0;
    for (height, boxes) in layers {
        for (c, &(cx, cy, sx, sy)) in boxes.iter().take(columns).enumerate() {
            let centre = DVec3::new(200.0 * c as f64 + cx, cy, z);
            out.push((c, centre - DVec3::new(sx / 2.0, sy / 2.0, 0.0), DVec3::new(sx, sy, *height)));
        }
        z += height;
    }
    out
}

/// One to three layers of [`Layer`]s (three columns each; [`build`] takes the first `columns`): heights in `height`,
/// centre offsets within `+-offset`, sizes in `size`.
pub fn box_layers(
    height: std::ops::Range<f64>,
    offset: f64,
    size: std::ops::Range<f64>,
) -> impl proptest::strategy::Strategy<Value = Vec<Layer>> {
    use proptest::prelude::*;
    prop::collection::vec(
        (height, prop::collection::vec((-offset..offset, -offset..offset, size.clone(), size), 3)),
        1..=3,
    )
}

/// The planner's 15-part Channel stack (`benches/stacks/channel-plan-15.json`: flipped channels straddling a flange
/// of the one below).
pub fn planned_channels() -> stackplan_geom::io::stack::StackFile {
    stackplan_geom::io::stack::read_stack(concat!(env!("CARGO_MANIFEST_DIR"), "/benches/stacks/channel-plan-15.json"))
        .expect("plan")
}

/// The placements of a stack file.
pub fn placements(plan: &stackplan_geom::io::stack::StackFile) -> Vec<PlacedPart<'_>> {
    plan.placements.iter().map(|p| PlacedPart { part: &plan.part, pose: *p }).collect()
}
