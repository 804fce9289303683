//! Benchmarks: the whole-stack check of 15 parts (boxes staggered in a brick pattern), the contact analysis, and
//! equilibrium solves for one added part and for the whole stack.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DMat3, DVec3};
use stackplan_geom::{Part, PartOrigin, convex_hull};
use stackplan_stability::check::{CheckOptions, check_stack};
use stackplan_stability::contacts::analyse_contacts;
use stackplan_stability::equilibrium::{EquilibriumOptions, solve_equilibrium};
use stackplan_stability::world::{PlacedPart, stack_tolerance, world_stack};
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
            stack.push(PlacedPart { part, rotation: DMat3::IDENTITY, position: DVec3::new(x, 0.0, 50.0 * row as f64) });
        }
    }
    stack
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
    let plain = EquilibriumOptions { mu: 0.5, directions: 0 };
    c.bench_function("equilibrium: one added part", |b| {
        b.iter(|| solve_equilibrium(black_box(&parts), &movable, &contacts.patches, &plain).expect("solve"))
    });
    let all = vec![true; parts.len()];
    c.bench_function("equilibrium: whole 15-part stack", |b| {
        b.iter(|| solve_equilibrium(black_box(&parts), &all, &contacts.patches, &plain).expect("solve"))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
