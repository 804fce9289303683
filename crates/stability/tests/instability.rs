//! The certificates of instability (`equilibrium::instability`: tipping sets, remembered solver mechanisms) and the
//! pre-check must never change a verdict: random stacks against one plain SOCP per group
//! (`EquilibriumOptions::equilibrium_by_socp_only`), with one `SolveCache` shared by every solve of a case as in the
//! planner (so remembered mechanisms are tried on the next problems):
//!
//! * a candidate brick on a staggered brick wall at random offsets (resting on one or two bricks, overhanging,
//!   side contacts with its neighbours when it drops between two), every prefix of the stack;
//! * an inverted-L part on a stepped base: supports at two heights (the friction couple), side contacts between its
//!   leg and the high step, a load on it at a random offset;
//! * bridged box columns with boxes on the bridge at random offsets (groups without a support tree);
//!
//! and the pre-check's fix: a part on supports at two heights with its c.g. beyond them, held by friction.
//!
//! Where the plain SOCP ends unsure (`Unknown`, e.g. `AlmostPrimalInfeasible` for a part far off a single edge), a
//! certificate may decide `Unstable`; a stable verdict never changes.

use crate::common;

use common::{at, box_layers, box_part, boxes_part, build};
use glam::DVec3;
use proptest::prelude::*;
use stackplan_stability::PlacedPart;
use stackplan_stability::contacts::analyse_contacts;
use stackplan_stability::equilibrium::{EquilibriumOptions, SolveCache, Verdict, solve_equilibrium_with};
use stackplan_stability::world::{stack_tolerance, world_stack};

/// Counts of the verdicts compared (to check that the samples contain both kinds).
#[derive(Debug, Default)]
struct Tally {
    stable: usize,
    unstable: usize,
}

/// The verdict of `stack` with the parts of `movable` movable (all when `None`), by the fast solve (verdict only and
/// full, with the shared `cache`) and by the plain SOCPs: asserts they agree, returns the verdict.
fn compare(stack: &[PlacedPart<'_>], movable: Option<&[bool]>, mu: f64, cache: &SolveCache, what: &str) -> Verdict {
    let parts = world_stack(stack).expect("world");
    let tol = stack_tolerance(&parts).linear;
    let contacts = analyse_contacts(&parts, tol, |_| true);
    let movable = movable.map_or_else(|| vec![true; parts.len()], <[bool]>::to_vec);
    let full = EquilibriumOptions::new(mu, 0);
    let verdict_only = EquilibriumOptions { verdict_only: true, ..full };
    let plain = EquilibriumOptions { equilibrium_by_socp_only: true, ..full };
    let solve = |options: &EquilibriumOptions, cache: &SolveCache| {
        solve_equilibrium_with(&parts, &movable, &contacts.patches, options, cache).expect("solve").verdict
    };
    let reference = solve(&plain, &SolveCache::new());
    for (options, label) in [(&verdict_only, "verdict only"), (&full, "full")] {
        let fast = solve(options, cache);
        match &reference {
            // the solver unsure of a degenerate problem (`AlmostPrimalInfeasible`): a certificate may decide it
            Verdict::Unknown(_) => assert!(fast == reference || fast == Verdict::Unstable, "{what}: {label}: {fast:?}"),
            _ => assert_eq!(fast, reference, "{what}: {label}"),
        }
    }
    reference
}

fn count(tally: &mut Tally, verdict: &Verdict) {
    match verdict {
        Verdict::Stable => tally.stable += 1,
        Verdict::Unstable => tally.unstable += 1,
        Verdict::Unknown(_) => {}
    }
}

/// The staggered wall of `rows` rows of 200 x 100 x 50 bricks, row `r` shifted by `r * shift`.
fn wall<'a>(brick: &'a stackplan_geom::Part, rows: usize, shift: f64) -> Vec<PlacedPart<'a>> {
    let mut stack = Vec::new();
    for row in 0..rows {
        for k in 0..(rows - row) {
            stack.push(at(brick, DVec3::new(shift * row as f64 + 200.0 * k as f64, 0.0, 50.0 * row as f64)));
        }
    }
    stack
}

/// The inverted L: a leg `[0, 40] x [0, 100] x [0, leg]` under a slab `[0, 200] x [0, 100] x [leg, leg + 20]`.
fn inverted_l(leg: f64) -> stackplan_geom::Part {
    boxes_part(
        "inverted L",
        &[
            (DVec3::ZERO, DVec3::new(40.0, 100.0, leg)),
            (DVec3::new(0.0, 0.0, leg), DVec3::new(200.0, 100.0, leg + 20.0)),
        ],
    )
}

#[test]
fn random_samples_contain_both_verdicts() {
    // a fixed sample of the generators below: the comparisons are not vacuous
    let brick = box_part("brick", DVec3::new(200.0, 100.0, 50.0));
    let cache = SolveCache::new();
    let mut tally = Tally::default();
    for k in 0..24 {
        let dx = -150.0 + 25.0 * k as f64;
        let mut stack = wall(&brick, 3, 60.0);
        stack.push(at(&brick, DVec3::new(dx, 10.0, 150.0)));
        count(&mut tally, &compare(&stack, None, 0.5, &cache, &format!("brick at {dx}")));
    }
    assert!(tally.stable >= 4 && tally.unstable >= 4, "{tally:?}");
}

#[test]
fn a_part_on_supports_at_two_heights_is_held_by_friction_beyond_their_hull() {
    // the pre-check's case: a plate leg on the floor at x in [0, 2] and a slab resting on a fixed block at x in
    // [12, 20], 50 higher; the slab reaches x = 60, so the c.g. (x = 25.9) lies beyond the supports (x <= 20). In
    // the plane: supports at (a, 0) and (b, h) hold a c.g. up to a + (b - a + mu h) / 2 when mu h > b - a (friction
    // pushes the foot outwards and the slab back: a couple), so a pre-check by the hull of the supports is wrong here
    let block = box_part("block", DVec3::new(8.0, 20.0, 50.0));
    let part = boxes_part(
        "stepped",
        &[(DVec3::ZERO, DVec3::new(2.0, 20.0, 50.0)), (DVec3::new(0.0, 0.0, 50.0), DVec3::new(60.0, 20.0, 60.0))],
    );
    let stack = [at(&block, DVec3::new(12.0, 0.0, 0.0)), at(&part, DVec3::ZERO)];
    let movable = [false, true];
    let cg_x = (2.0 * 50.0 * 1.0 + 60.0 * 10.0 * 30.0) / (2.0 * 50.0 + 60.0 * 10.0);
    for (mu, expected) in
        [(1.0, Verdict::Stable), (0.6, Verdict::Stable), (0.55, Verdict::Unstable), (0.3, Verdict::Unstable)]
    {
        // the innermost pair (x = 2 low, x = 20 high; spacing 18) gives the farthest reach
        let limit = if 50.0 * mu > 18.0 { 2.0 + (18.0 + 50.0 * mu) / 2.0 } else { 20.0 };
        assert_eq!(cg_x > limit, expected == Verdict::Unstable, "mu {mu}: c.g. {cg_x} vs limit {limit}");
        let verdict = compare(&stack, Some(&movable), mu, &SolveCache::new(), &format!("mu {mu}"));
        assert_eq!(verdict, expected, "mu {mu}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: common::cases(24), ..ProptestConfig::default() })]

    /// Candidate bricks on a wall, tested one after the other with one memo (as the planner tests candidates).
    #[test]
    fn candidates_on_a_brick_wall_decide_like_the_plain_socp(
        rows in 2usize..=3,
        shift in prop_oneof![Just(100.0), Just(0.0), 0.0f64..140.0],
        candidates in prop::collection::vec((-180.0f64..380.0, prop_oneof![Just(0.0), -60.0f64..60.0]), 1..6),
        mu in prop_oneof![Just(0.0), 0.1f64..1.2],
    ) {
        let brick = box_part("brick", DVec3::new(200.0, 100.0, 50.0));
        let cache = SolveCache::new();
        let base = wall(&brick, rows, shift);
        for (k, &(dx, dy)) in candidates.iter().enumerate() {
            let mut stack = base.clone();
            // on the top row, or dropped into the row below it (between two bricks: side contacts)
            let z = if k % 2 == 0 { 50.0 * rows as f64 } else { 50.0 * (rows - 1) as f64 };
            stack.push(at(&brick, DVec3::new(dx, dy, z)));
            let parts = world_stack(&stack).expect("world");
            let tol = stack_tolerance(&parts).linear;
            if !analyse_contacts(&parts, tol, |_| true).interferences.is_empty() {
                continue;
            }
            for i in 0..stack.len() {
                compare(&stack[..=i], None, mu, &cache, &format!("candidate {k} at ({dx}, {dy}, {z}), prefix {i}"));
            }
        }
    }

    /// The inverted L on a stepped base (low block, high block): supports at two heights, side contacts between the
    /// leg and the high block, a load box on the slab.
    #[test]
    fn an_inverted_l_on_a_stepped_base_decides_like_the_plain_socp(
        leg in 20.0f64..120.0,
        dx in prop_oneof![Just(160.0), Just(0.0), -60.0f64..160.0],
        dy in -60.0f64..60.0,
        load in prop::option::of(-40.0f64..220.0),
        mu in prop_oneof![Just(0.0), 0.05f64..1.5],
    ) {
        let low = box_part("low", DVec3::new(200.0, 100.0, 50.0));
        let high = box_part("high", DVec3::new(200.0, 100.0, 50.0 + leg));
        let l = inverted_l(leg);
        let weight = box_part("load", DVec3::new(40.0, 40.0, 30.0));
        let mut stack = vec![at(&low, DVec3::ZERO), at(&high, DVec3::new(200.0, 0.0, 0.0)), at(&l, DVec3::new(dx, dy, 50.0))];
        if let Some(x) = load {
            stack.push(at(&weight, DVec3::new(dx + x, dy + 30.0, 70.0 + leg)));
        }
        let parts = world_stack(&stack).expect("world");
        let tol = stack_tolerance(&parts).linear;
        prop_assume!(analyse_contacts(&parts, tol, |_| true).interferences.is_empty());
        let cache = SolveCache::new();
        for movable in [None, Some(vec![false, false, true, true][..stack.len()].to_vec())] {
            compare(&stack, movable.as_deref(), mu, &cache, &format!("L at ({dx}, {dy}), leg {leg}, {movable:?}"));
        }
    }

    /// Bridged box columns with boxes on the bridge (groups without a support tree, parts resting on two parts).
    #[test]
    fn boxes_on_bridged_columns_decide_like_the_plain_socp(
        columns in 2usize..=3,
        layers in box_layers(10.0f64..40.0, 25.0, 20.0f64..70.0),
        bridge in (-30.0f64..30.0, 5.0f64..20.0),
        riders in prop::collection::vec((-60.0f64..460.0, -40.0f64..40.0, 10.0f64..80.0), 1..4),
        mu in 0.1f64..1.2,
    ) {
        let layout = build(&layers, columns);
        let mut parts: Vec<_> = layout.iter().enumerate().map(|(k, (_, _, size))| box_part(&format!("b{k}"), *size)).collect();
        let mut placed: Vec<DVec3> = layout.iter().map(|(_, lo, _)| *lo).collect();
        let top = layers.iter().map(|l| l.0).sum::<f64>();
        let (shift, thickness) = bridge;
        parts.push(box_part("plank", DVec3::new(200.0 * (columns - 1) as f64 + 40.0, 40.0, thickness)));
        placed.push(DVec3::new(-20.0 + shift.clamp(-10.0, 10.0), -20.0, top));
        // riders side by side on the plank (each on the plank, possibly overhanging it)
        let mut x0 = f64::NEG_INFINITY;
        for (k, &(x, y, size)) in riders.iter().enumerate() {
            let x = x.max(x0);
            parts.push(box_part(&format!("rider{k}"), DVec3::new(size, size, size)));
            placed.push(DVec3::new(x, y - size / 2.0, top + thickness));
            x0 = x + size;
        }
        let stack: Vec<PlacedPart<'_>> = parts.iter().zip(&placed).map(|(p, lo)| at(p, *lo)).collect();
        let cache = SolveCache::new();
        for i in 0..stack.len() {
            compare(&stack[..=i], None, mu, &cache, &format!("prefix {i}"));
        }
    }
}
