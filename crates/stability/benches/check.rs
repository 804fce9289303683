//! Benchmarks: the whole-stack check of 15 parts (with margins in 8 directions and every prefix stack, the defaults):
//!
//! * bricks staggered in a pyramid (one connected group: the worst case for the group decomposition);
//! * 15 Channel parts as planned by `stackplan plan example:channel` (w = 0.5; `stacks/channel-plan-15.json`);
//! * 15 copies of each fixture part (Channel, Triangle, Complex, Cube, L-corner, Block) in 5 columns of 3 (lowest resting pose, each part lowered straight onto
//!   the one below until they touch: Channel 51 mm apart, Triangle nested 4.47 mm apart, Complex 151 mm apart; fixed
//!   stacks written before the planner planned these parts, kept so that the figures stay comparable);
//!
//! then the contact analysis, equilibrium solves for one added part and for the whole brick stack, and the horizontal
//! clearance test of the pairs of a planned 15-part Triangle stack (`stacks/triangle-plan-15.json`).

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DMat3, DVec3};
use stackplan_geom::Pose;
use stackplan_geom::examples::part_by_name;
use stackplan_geom::io::stack::read_stack;
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_geom::{Part, PartOrigin, convex_hull};
use stackplan_stability::check::{CheckOptions, check_stack};
use stackplan_stability::clearance::{
    horizontal_distance_at_least, horizontal_distance_bound_by_axes, horizontal_distance_by_slice, vertically_separated,
};
use stackplan_stability::contacts::analyse_contacts;
use stackplan_stability::equilibrium::{EquilibriumOptions, solve_equilibrium};
use stackplan_stability::resting_poses::resting_poses;
use stackplan_stability::world::{PlacedPart, WorldComponent, stack_tolerance, world_stack};
use std::hint::black_box;

fn box_part(size: DVec3) -> Part {
    let pts: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { 0.0 } else { size.x },
                if i & 2 == 0 { 0.0 } else { size.y },
                if i & 4 == 0 { 0.0 } else { size.z },
            )
        })
        .collect();
    let hull = convex_hull(&pts).expect("box").polytope;
    Part::from_components("brick", vec![hull], 1.0, PartOrigin::ConvexPieces).expect("part")
}

/// 15 bricks 200 x 100 x 50 in a staggered wall: 5 + 4 + 3 + 2 + 1 (a pyramid), each upper brick on two below.
fn brick_pyramid(part: &Part) -> Vec<PlacedPart<'_>> {
    let mut stack = Vec::new();
    for row in 0..5 {
        for k in 0..(5 - row) {
            let x = 100.0 * row as f64 + 200.0 * k as f64;
            stack.push(PlacedPart {
                part,
                pose: Pose { rotation: DMat3::IDENTITY, position: DVec3::new(x, 0.0, 50.0 * row as f64) },
            });
        }
    }
    stack
}

/// The smallest upward shift at which a copy of the placed `part` straight above it does not interfere (bisection on
/// the contact analysis' interference test): the nesting height of a column of copies.
fn nesting_height(part: &Part, placed: PlacedPart<'_>, upper_bound: f64) -> f64 {
    let interferes = |dz: f64| {
        let top = PlacedPart {
            pose: Pose { position: placed.pose.position + DVec3::new(0.0, 0.0, dz), ..placed.pose },
            ..placed
        };
        let parts = world_stack(&[PlacedPart { part, ..placed }, top]).expect("world");
        let tol = stack_tolerance(&parts).linear;
        !analyse_contacts(&parts, tol, |_| true).interferences.is_empty()
    };
    let (mut lo, mut hi) = (0.0, upper_bound);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if interferes(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// 15 copies of `part` in its lowest resting pose: 5 columns of 3 side by side (10 mm apart along x), each part
/// lowered straight onto the one below until they touch (nested when the shape allows it).
fn columns(part: &Part) -> Vec<PlacedPart<'_>> {
    let pose = resting_poses(part).expect("poses").into_iter().next().expect("a resting pose");
    let placed = PlacedPart { part, pose: Pose { rotation: pose.rotation, position: pose.position } };
    let world: Vec<DVec3> = part.all_vertices().map(|v| pose.rotation * v + pose.position).collect();
    let lo = world.iter().fold(DVec3::splat(f64::INFINITY), |a, b| a.min(*b));
    let hi = world.iter().fold(DVec3::splat(f64::NEG_INFINITY), |a, b| a.max(*b));
    let size = hi - lo;
    let rise = nesting_height(part, placed, size.z + 1.0);
    (0..15)
        .map(|k| {
            let (column, level) = (k % 5, k / 5);
            let shift = DVec3::new((size.x + 10.0) * column as f64, 0.0, rise * level as f64);
            PlacedPart { pose: Pose { position: pose.position + shift, ..placed.pose }, ..placed }
        })
        .collect()
}

fn bench_fixtures(c: &mut Criterion) {
    let options = CheckOptions::default();
    let channel = part_by_name("channel", Decomposition::ConvexMerge).expect("channel");
    let triangle = part_by_name("triangle", Decomposition::ConvexMerge).expect("triangle");
    let complex = part_by_name("complex", Decomposition::ConvexMerge).expect("complex");
    let cube = part_by_name("cube", Decomposition::ConvexMerge).expect("cube");
    let l_corner = part_by_name("l-corner", Decomposition::ConvexMerge).expect("l-corner");
    let block = part_by_name("block", Decomposition::ConvexMerge).expect("block");
    let plan = read_stack(concat!(env!("CARGO_MANIFEST_DIR"), "/benches/stacks/channel-plan-15.json")).expect("plan");
    let planned: Vec<PlacedPart<'_>> =
        plan.placements.iter().map(|p| PlacedPart { part: &plan.part, pose: *p }).collect();
    let cases = [
        ("check_stack 15 Channel (planned, w = 0.5)", planned),
        ("check_stack 15 Channel (5 columns of 3)", columns(&channel)),
        ("check_stack 15 Triangle (5 nested columns of 3)", columns(&triangle)),
        ("check_stack 15 Complex (5 columns of 3)", columns(&complex)),
        ("check_stack 15 Cube (5 columns of 3)", columns(&cube)),
        ("check_stack 15 L-corner (5 columns of 3)", columns(&l_corner)),
        ("check_stack 15 Block (5 columns of 3)", columns(&block)),
    ];
    for (name, stack) in &cases {
        assert_eq!(stack.len(), 15);
        let report = check_stack(stack, &options).expect("check");
        assert!(
            report.stack.verdict.is_stable() && report.stack.margin.is_some(),
            "{name}: {:?}",
            report.stack.verdict
        );
        c.bench_function(name, |b| b.iter(|| check_stack(black_box(stack), &options).expect("check")));
    }
}

fn bench(c: &mut Criterion) {
    let brick = box_part(DVec3::new(200.0, 100.0, 50.0));
    let stack = brick_pyramid(&brick);
    let options = CheckOptions::default();
    assert!(check_stack(&stack, &options).expect("check").ok);
    c.bench_function("check_stack 15 bricks (margins 8 directions)", |b| {
        b.iter(|| check_stack(black_box(&stack), &options).expect("check"))
    });
    let fast = CheckOptions { margin_directions: 0, prefix_stability: false, ..CheckOptions::default() };
    c.bench_function("check_stack 15 bricks (no margins, whole stack only)", |b| {
        b.iter(|| check_stack(black_box(&stack), &fast).expect("check"))
    });
    let parts = world_stack(&stack).expect("world");
    let tol = stack_tolerance(&parts).linear;
    let contacts = analyse_contacts(&parts, tol, |_| true);
    c.bench_function("contacts 15 bricks", |b| b.iter(|| analyse_contacts(black_box(&parts), tol, |_| true)));
    let last = parts.len() - 1;
    let movable: Vec<bool> = (0..parts.len()).map(|i| i == last).collect();
    let plain = EquilibriumOptions::new(0.5, 0);
    c.bench_function("equilibrium: one added part", |b| {
        b.iter(|| solve_equilibrium(black_box(&parts), &movable, &contacts.patches, &plain).expect("solve"))
    });
    let all = vec![true; parts.len()];
    c.bench_function("equilibrium: whole 15-part stack", |b| {
        b.iter(|| solve_equilibrium(black_box(&parts), &all, &contacts.patches, &plain).expect("solve"))
    });
}

/// The horizontal clearance test (5 mm) of the 15-part Triangle plan (`stackplan plan example:triangle --w 0.5`,
/// `stacks/triangle-plan-15.json`: the parts nest, so many pairs come near the clearance), on the pairs `check_stack`
/// tests: each part at its release position (lifted by its `release_drop`) against the components of the parts
/// placed before it whose boxes come within the clearance and whose z-ranges overlap. The whole test
/// (`horizontal_distance_at_least`), and its two filters alone: the separating axes' bound and the slice of the
/// Minkowski difference (which the bound spares most of these pairs).
fn bench_clearance(c: &mut Criterion) {
    let plan = read_stack(concat!(env!("CARGO_MANIFEST_DIR"), "/benches/stacks/triangle-plan-15.json")).expect("plan");
    let placed = |lift: &dyn Fn(usize) -> f64| -> Vec<PlacedPart<'_>> {
        (plan.placements.iter().enumerate())
            .map(|(k, p)| PlacedPart {
                part: &plan.part,
                pose: Pose { rotation: p.rotation, position: p.position + DVec3::Z * lift(k) },
            })
            .collect()
    };
    let drop = |k: usize| plan.extras[k].get("release_drop").and_then(|v| v.as_f64()).expect("release_drop");
    let rest = world_stack(&placed(&|_| 0.0)).expect("world");
    let released = world_stack(&placed(&drop)).expect("world");
    let tol = stack_tolerance(&rest).linear;
    let delta = 5.0;
    let near = |a: &(DVec3, DVec3), b: &(DVec3, DVec3)| {
        (a.0 - b.1).max_element() <= delta && (b.0 - a.1).max_element() <= delta
    };
    let mut pairs = Vec::new();
    for (i, lifted) in released.iter().enumerate() {
        for below in &rest[..i] {
            for a in &lifted.components {
                for b in &below.components {
                    if near(&a.aabb, &b.aabb) && !vertically_separated(a, b, tol) {
                        pairs.push((a, b));
                    }
                }
            }
        }
    }
    // the plan keeps its clearance (up to the tolerance), so the test finds no pair closer
    let closer = |pairs: &[(&WorldComponent, &WorldComponent)]| {
        let too_close = |(a, b): &&(&WorldComponent, &WorldComponent)| {
            horizontal_distance_at_least(a, b, delta, tol).is_some_and(|d| d < delta - tol)
        };
        pairs.iter().filter(too_close).count()
    };
    assert_eq!(closer(&pairs), 0);
    let name = format!("clearance 15 Triangle (planned, {} pairs)", pairs.len());
    c.bench_function(&format!("{name}: horizontal_distance_at_least"), |bench| {
        bench.iter(|| black_box(closer(&pairs)))
    });
    c.bench_function(&format!("{name}: separating axes' bound only"), |bench| {
        bench.iter(|| pairs.iter().map(|(a, b)| horizontal_distance_bound_by_axes(a, b, tol)).fold(0.0, f64::max))
    });
    c.bench_function(&format!("{name}: slice only"), |bench| {
        bench.iter(|| pairs.iter().filter_map(|(a, b)| horizontal_distance_by_slice(a, b, tol)).fold(0.0, f64::max))
    });
}

criterion_group!(benches, bench, bench_fixtures, bench_clearance);
criterion_main!(benches);
