//! The placement clearance of a plan whose parts are released above their supports ([`CheckOptions::release_drops`]):
//! each part at its release position against the parts placed before it.

use crate::common;

use common::{at, box_part};
use glam::DVec3;
use stackplan_stability::StabilityError;
use stackplan_stability::check::{CheckOptions, check_stack};

#[test]
fn release_drops_check_each_part_at_its_release_position_against_the_earlier_parts() {
    // two 10 mm boxes on the floor, 2 mm apart in x, with a required clearance of 5 mm
    let cube = box_part("cube", DVec3::splat(10.0));
    let stack = [at(&cube, DVec3::ZERO), at(&cube, DVec3::new(12.0, 0.0, 0.0))];
    let options = CheckOptions { clearance: 5.0, margin_directions: 0, ..CheckOptions::default() };
    // symmetric (no drops): both parts are too close to each other
    let report = check_stack(&stack, &options).expect("check");
    for p in &report.parts {
        assert!(!p.clearance_met);
        assert!((p.min_horizontal_clearance.expect("measured") - 2.0).abs() < 1e-6);
    }
    // in placement order with no drop: the first part has nothing before it, the second is 2 mm from it
    let ordered = CheckOptions { release_drops: vec![0.0, 0.0], ..options.clone() };
    let report = check_stack(&stack, &ordered).expect("check");
    assert!(report.parts[0].clearance_met && report.parts[0].min_horizontal_clearance.is_none());
    assert!(!report.parts[1].clearance_met);
    assert!((report.parts[1].min_horizontal_clearance.expect("measured") - 2.0).abs() < 1e-6);
    // released 12 mm above its resting place the second box is above the first one's height range: exempt
    let dropped = CheckOptions { release_drops: vec![0.0, 12.0], ..options.clone() };
    let report = check_stack(&stack, &dropped).expect("check");
    assert!(report.parts.iter().all(|p| p.clearance_met), "{:?}", report.parts);
    // released 5 mm above, the height ranges still overlap: 2 mm is still too close
    let low = CheckOptions { release_drops: vec![0.0, 5.0], ..options.clone() };
    assert!(!check_stack(&stack, &low).expect("check").parts[1].clearance_met);
    // the drops must match the stack and be finite and non-negative
    for bad in [vec![0.0], vec![0.0, -1.0], vec![0.0, f64::NAN]] {
        let options = CheckOptions { release_drops: bad, ..options.clone() };
        assert!(matches!(check_stack(&stack, &options), Err(StabilityError::BadOption(_))));
    }
}
