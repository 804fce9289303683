//! Tightness and conservativeness of the reported intervals: `reported / true` forward length from random angles,
//! the true end found by sampling the from-scratch structure every 0.25 degree and bisecting the first change (test
//! only). The reported end must never lie after the true end; the distribution is printed (docs/benchmarks.md).

use crate::common;

use common::{cases, example_components, pair};
use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::TestRunner;
use stackplan_cspace::minkowski::obstacle;
use stackplan_geom::ConvexPolytope;
use stackplan_orient_interval::structure::same_structure;
use stackplan_orient_interval::{PairEvents, rotation_z};
use std::f64::consts::TAU;

/// First angle after `t0` where the from-scratch structure differs (sampling + bisection to 1e-12 rad).
fn true_end(a: &ConvexPolytope, b: &ConvexPolytope, t0: f64, limit: f64) -> f64 {
    let start = obstacle(a, rotation_z(t0), b).expect("obstacle");
    let same = |t: f64| same_structure(&start, &obstacle(a, rotation_z(t), b).expect("obstacle"));
    let step = 0.25f64.to_radians();
    let mut lo = t0;
    let mut hi = t0 + step;
    while hi < t0 + limit {
        if !same(hi) {
            while hi - lo > 1e-12 {
                let mid = 0.5 * (lo + hi);
                if same(mid) { lo = mid } else { hi = mid }
            }
            return hi;
        }
        lo = hi;
        hi += step;
    }
    t0 + limit
}

fn measure(a: &ConvexPolytope, b: &ConvexPolytope, t0: f64, ratios: &mut Vec<f64>) {
    let iv = PairEvents::new(a, b).interval_around(t0);
    let reported = (iv.end - t0).min(TAU);
    // sample a little past the reported end so that a non-conservative interval is caught
    let truth = true_end(a, b, t0, (reported + 2.0f64.to_radians()).min(TAU)) - t0;
    assert!(
        reported <= truth + 1e-12,
        "interval not conservative: reported {reported} > true {truth} (t0 {t0}, end event {:?})",
        iv.end_event.map(|e| e.kind)
    );
    if truth > 0.0 {
        ratios.push(reported / truth);
    }
}

fn summary(name: &str, mut r: Vec<f64>) -> (f64, f64) {
    r.sort_by(f64::total_cmp);
    let q = |p: f64| r[((r.len() - 1) as f64 * p).round() as usize];
    let (median, p10) = (q(0.5), q(0.1));
    let exact = r.iter().filter(|&&x| x > 1.0 - 1e-6).count();
    #[allow(clippy::print_stderr)]
    {
        eprintln!(
            "{name}: n = {}, reported/true: median {median:.6}, 10th percentile {p10:.6}, min {:.6}, {} of {} within 1e-6 of 1",
            r.len(),
            r[0],
            exact,
            r.len()
        );
    }
    (median, p10)
}

#[test]
fn random_pairs_intervals_are_conservative_and_tight() {
    let mut runner = TestRunner::deterministic();
    let strategy = (pair(), 0.0..TAU);
    let mut ratios = Vec::new();
    for _ in 0..cases() {
        let ((a, b), t0) = strategy.new_tree(&mut runner).expect("value").current();
        measure(&a, &b, t0, &mut ratios);
    }
    let (median, _) = summary("random pairs", ratios);
    assert!(median > 0.99, "intervals are not tight: median ratio {median}");
}

#[test]
fn example_part_pairs_intervals_are_conservative_and_tight() {
    let comps = example_components();
    let mut ratios = Vec::new();
    let n = comps.len();
    let mut k = 0usize;
    for i in (0..n).step_by(3) {
        for j in (1..n).step_by(5) {
            k += 1;
            let t0 = (k as f64 * 0.731).rem_euclid(TAU);
            measure(&comps[i], &comps[j], t0, &mut ratios);
        }
    }
    let (median, _) = summary("example-part component pairs", ratios);
    assert!(median > 0.99, "intervals are not tight: median ratio {median}");
}
