//! Property tests of critical orientations, intervals and extrapolation (the heart of the issue).

use crate::common;

use common::{cases, mirrored, pair};
use proptest::prelude::*;
use stackplan_cspace::minkowski::{Route, obstacle};
use stackplan_orient_interval::structure::{relative_difference, same_structure};
use stackplan_orient_interval::{ObstacleStructure, PairEvents, point_face_event, rotation_z, sweep};
use std::f64::consts::TAU;

fn build(a: &stackplan_geom::ConvexPolytope, b: &stackplan_geom::ConvexPolytope, t: f64) -> stackplan_cspace::Obstacle {
    obstacle(a, rotation_z(t), b).expect("obstacle of valid polytopes")
}

/// The full-turn partition is exact: starts in `[0, 2 pi)` in increasing order, each end bit for bit the next start,
/// the last end the first start plus `2 pi`, windows and constant intervals alternating.
fn check_partition(events: &PairEvents) -> Result<(), TestCaseError> {
    let turn = events.full_turn();
    prop_assert!(!turn.is_empty());
    for (k, t) in turn.iter().enumerate() {
        prop_assert!((0.0..TAU).contains(&t.start) && t.end > t.start, "interval {k}: [{}, {}]", t.start, t.end);
        let expected_end = turn.get(k + 1).map_or(turn[0].start + TAU, |next| next.start);
        prop_assert_eq!(
            t.end.to_bits(),
            expected_end.to_bits(),
            "interval {} ends at {}, not at {}",
            k,
            t.end,
            expected_end
        );
        if let Some(next) = turn.get(k + 1) {
            prop_assert!(t.degenerate != next.degenerate, "intervals {} and {} of one kind", k, k + 1);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    /// [`check_partition`] on random pairs (each turned to a random start, so that bands straddle 0 and 2 pi).
    #[test]
    fn the_full_turn_is_an_exact_partition((a, b) in pair(), turn in 0.0..TAU) {
        let b = b.transformed(rotation_z(turn), glam::DVec3::ZERO);
        check_partition(&PairEvents::new(&a, &b))?;
    }

    /// Inside [theta0, theta1) (and the backward part of the interval) the extrapolated obstacle equals the one
    /// built from scratch: same structure and provenance, coordinates within 1e-9 relative.
    #[test]
    fn extrapolation_equals_construction_inside_the_interval((a, b) in pair(), t0 in 0.0..TAU) {
        let events = PairEvents::new(&a, &b);
        let built = build(&a, &b, t0);
        // hull-route obstacles (input within rounding of a degenerate configuration) are not extrapolated from
        prop_assume!(built.route() == Route::GaussMap);
        let s = ObstacleStructure::from_obstacle(built, &a, &b, t0, events.interval_around(t0)).expect("structure");
        let iv = *s.interval();
        prop_assert!(iv.start <= t0 && t0 <= iv.end);
        for u in [0.0, 0.2, 0.5, 0.9, 0.999, 0.999_999] {
            for t in [t0 + u * (iv.end - t0).min(TAU), t0 - u * (t0 - iv.start).min(TAU)] {
                let scratch = build(&a, &b, t);
                let ex = s.extrapolate(&a, &b, t).expect("inside the interval");
                prop_assert!(same_structure(&ex, &scratch), "structure differs at {t} in [{}, {}] (t0 {t0})", iv.start, iv.end);
                let d = relative_difference(&ex, &scratch).expect("same structure");
                prop_assert!(d <= 1e-9, "coordinates differ by {d} at {t}");
            }
        }
    }

    /// Every reported event angle satisfies its event equation.
    #[test]
    fn event_angles_solve_their_equations((a, b) in pair()) {
        let events = PairEvents::new(&a, &b);
        for band in events.bands() {
            let e = band.event;
            let r = e.function.eval(e.angle).abs();
            prop_assert!(r <= e.tolerance + 1e-12, "{:?}: |f| = {r} > {}", e.kind, e.tolerance);
            prop_assert!(band.lo <= e.angle + 1e-12 || band.lo <= e.angle + TAU);
            // the band is where |f| <= tol: its ends are on the boundary or the band is the whole near-tangent arc
            prop_assert!(e.function.eval(band.lo).abs() <= e.tolerance * 1.001 + 1e-12);
            prop_assert!(e.function.eval(band.hi).abs() <= e.tolerance * 1.001 + 1e-12);
        }
    }

    /// Reflecting both parts through a vertical plane turns forward events into backward events.
    #[test]
    fn mirrored_pair_swaps_forward_and_backward((a, b) in pair(), t0 in 0.0..TAU) {
        let (ma, mb) = (mirrored(&a), mirrored(&b));
        let iv = PairEvents::new(&a, &b).interval_around(t0);
        let mv = PairEvents::new(&ma, &mb).interval_around(-t0);
        let (fwd, bwd) = ((iv.end - t0).min(TAU), (t0 - iv.start).min(TAU));
        let (mfwd, mbwd) = ((mv.end + t0).min(TAU), (-t0 - mv.start).min(TAU));
        prop_assert!((fwd - mbwd).abs() <= 1e-9, "forward {fwd} vs mirrored backward {mbwd}");
        prop_assert!((bwd - mfwd).abs() <= 1e-9, "backward {bwd} vs mirrored forward {mfwd}");
        // the events themselves: same angle up to the mirror (several events may share an angle, so the kinds of
        // the bounding ones can differ)
        if let (Some(e), Some(m)) = (iv.end_event, mv.start_event) {
            let d = stackplan_orient_interval::trig::wrap(e.angle + m.angle);
            prop_assert!(d.min(TAU - d) <= 1e-6, "end event at {} vs mirrored start event at {}", e.angle, m.angle);
        }
    }

    /// The seed's test (a): no point crosses a face plane of the structure before the interval ends (an independent
    /// check that the Gauss-map and degenerate-family events are complete).
    #[test]
    fn no_point_crosses_a_face_inside_the_interval((a, b) in pair(), t0 in 0.0..TAU) {
        let events = PairEvents::new(&a, &b);
        let iv = events.interval_around(t0);
        prop_assume!(!iv.degenerate && iv.length() < TAU);
        let o = build(&a, &b, t0);
        prop_assume!(o.route() == Route::GaussMap);
        if let Some((t, e)) = point_face_event(&o, &a, &b, t0, true) {
            prop_assert!(t >= iv.end - 1e-6, "point event {:?} at {t} before the interval end {}", e.kind, iv.end);
            prop_assert!(e.function.eval(e.angle).abs() <= 1e-9 * (1.0 + e.function.amplitude()));
        }
        if let Some((t, e)) = point_face_event(&o, &a, &b, t0, false) {
            prop_assert!(t <= iv.start + 1e-6, "point event {:?} at {t} after the interval start {}", e.kind, iv.start);
        }
    }

    /// The sweep over 360 one-degree steps returns exactly what building every obstacle from scratch returns.
    #[test]
    fn sweep_equals_construction_at_every_step((a, b) in pair()) {
        let angles = stackplan_orient_interval::degree_steps(1.0);
        let (all, stats) = sweep(&a, &b, &angles).expect("sweep");
        prop_assert_eq!(all.len(), 360);
        prop_assert_eq!(stats.constructions + stats.extrapolations, 360);
        for (k, o) in all.iter().enumerate() {
            let scratch = build(&a, &b, angles[k]);
            prop_assert!(same_structure(o, &scratch), "structure differs at step {k}");
            let d = relative_difference(o, &scratch).expect("same structure");
            prop_assert!(d <= 1e-9, "coordinates differ by {d} at step {k}");
        }
    }
}

/// Just past the end of an interval, the structure built from scratch differs from the one at the start (inside the
/// end event's band or right after it), unless the event is a conservative one. Counts both; at most a minority may
/// be conservative. Deterministic pairs from the generators.
/// Every pair of the example parts' components (the audit found ends and starts a few ulps apart, where an interval
/// had been shifted by a turn, at 15 of the 558 joins of Triangle against Channel).
#[test]
fn example_turns_are_exact_partitions() {
    let parts = common::example_components();
    for a in &parts {
        for b in &parts {
            check_partition(&PairEvents::new(a, b)).unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

#[test]
fn structure_changes_at_the_reported_end() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let strategy = (pair(), 0.0..TAU);
    let (mut changed, mut conservative) = (0usize, 0usize);
    for _ in 0..cases().max(16) {
        let ((a, b), t0) = strategy.new_tree(&mut runner).expect("value").current();
        let events = PairEvents::new(&a, &b);
        let iv = events.interval_around(t0);
        let Some(end_event) = iv.end_event else { continue };
        let start = build(&a, &b, t0);
        let band = events.bands().iter().find(|bd| bd.event == end_event).expect("band of the event");
        let probes = [end_event.angle, iv.end + 1e-12, band.lo + 0.5 * (band.hi - band.lo), band.hi + 1e-7];
        if probes.iter().any(|&t| !same_structure(&start, &build(&a, &b, t))) {
            changed += 1;
        } else {
            conservative += 1;
        }
    }
    #[allow(clippy::print_stderr)]
    {
        eprintln!("interval ends: structure changed {changed}, conservative {conservative}");
    }
    assert!(changed > 0);
    assert!(
        conservative * 2 <= changed + conservative,
        "too many conservative events: {conservative} of {}",
        changed + conservative
    );
}
