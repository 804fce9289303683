//! The scenarios of \[A\] Figs. 15-17: the Triangle part nests, every placement is valid, statistics are recorded.

use stackplan_planner::paper_scenarios::{run, scenario};
use stackplan_planner::reference::violations;
use stackplan_planner::{PlacedPart, PlacementRequest};

fn check(name: &str) -> stackplan_planner::paper_scenarios::ScenarioReport {
    let sc = scenario(name).expect("stack built").expect("known scenario");
    let (result, report) = run(&sc).expect("placement");
    let best = result.placements.first().expect("a placement");
    let stack: Vec<PlacedPart<'_>> = sc.stack.iter().map(|p| PlacedPart { part: &sc.part, pose: *p }).collect();
    let mut req = PlacementRequest::new(&sc.part, stack.clone(), sc.floor.clone());
    req.fixed_z = sc.fixed_z;
    let pose = best.pose();
    let v = violations(&sc.part, pose.rotation, pose.position, &stack, &req, 1e-6, 5.0);
    assert!(v.is_empty(), "{name}: {v:?}");
    assert!(report.stats.pairs_evaluated <= report.stats.total_pairs);
    assert!(report.stats.pairs_evaluated > 0, "{name}: the new part must meet the stack");
    report
}

#[test]
fn triangle_nests_in_a_three_part_stack() {
    let r = check("triangle");
    let above = r.height_above_previous.expect("height");
    assert!(
        above >= -1e-6 && above < 0.25 * r.part_height,
        "height above previous {above} vs part height {}",
        r.part_height
    );
}

#[test]
fn channel_joins_a_three_part_stack() {
    let r = check("channel");
    assert_eq!(r.stack_parts, 3);
}

#[test]
fn complex_on_a_one_part_stack_at_fixed_height() {
    let r = check("complex");
    assert_eq!(r.stack_parts, 1);
    // the seed evaluates under 1 % of the pairs for this part
    assert!(r.fraction_evaluated < 0.05, "fraction {}", r.fraction_evaluated);
}
