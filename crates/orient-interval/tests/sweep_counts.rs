//! Sweep counters on the example parts over 1-degree steps (\[A\] Table I reports 6-21 extrapolations per
//! construction): every obstacle equals the from-scratch one, and the counts are printed for docs/benchmarks.md.

use stackplan_cspace::minkowski::obstacle;
use stackplan_geom::examples;
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_geom::{DMat3, DVec3};
use stackplan_orient_interval::structure::same_structure;
use stackplan_orient_interval::{PairSweep, degree_steps, regress_summary, rotation_z};

#[test]
fn example_sweeps_count_constructions_and_extrapolations() {
    let angles = degree_steps(1.0);
    for name in ["channel", "triangle", "l-corner"] {
        let part = examples::part_by_name(name, Decomposition::Triangulation).expect("example");
        let c = &part.components();
        let mut total = (0u64, 0u64, 0usize);
        for (i, j) in [(0, c.len() - 1), (c.len() / 2, 0)] {
            let fixed = c[j].transformed(DMat3::from_rotation_z(0.3), DVec3::new(5.0, 3.0, 2.0));
            let mut sweep = PairSweep::new(c[i].clone(), fixed.clone(), angles.clone());
            for k in 0..angles.len() {
                let o = sweep.obstacle_at(k).expect("index").expect("obstacle");
                let scratch = obstacle(&c[i], rotation_z(angles[k]), &fixed).expect("obstacle");
                assert!(same_structure(&o, &scratch), "{name} pair ({i}, {j}) step {k}");
            }
            let s = sweep.stats();
            assert_eq!(s.constructions + s.extrapolations, 360);
            total.0 += s.constructions;
            total.1 += s.extrapolations;
            total.2 += sweep.events().full_turn().iter().filter(|t| !t.degenerate).count();
        }
        #[allow(clippy::print_stderr)]
        {
            eprintln!(
                "{name}: 2 pairs, constructions {}, extrapolations {}, per construction {:.1}, constant intervals per turn {:.1}",
                total.0,
                total.1,
                total.1 as f64 / total.0 as f64,
                total.2 as f64 / 2.0
            );
        }
        assert!(total.1 > total.0, "{name}: extrapolation should dominate over 1-degree steps");
    }
}

#[test]
fn regress_summary_counts_add_up() {
    let block = examples::block_part();
    let corner = examples::l_corner_part();
    let v = regress_summary(&block, &corner, (DMat3::IDENTITY, DVec3::new(30.0, 30.0, 20.0)), 1.0);
    let pairs = v["pairs"].as_array().expect("pairs");
    assert_eq!(pairs.len(), 3);
    for p in pairs {
        let c = p["constructions"].as_u64().expect("constructions");
        let e = p["extrapolations"].as_u64().expect("extrapolations");
        assert_eq!(c + e, 360);
        assert_eq!(p["errors"].as_u64(), Some(0));
        // box against box: the structure changes only where vertical faces align, every 90 degrees
        assert_eq!(p["intervals"].as_u64(), Some(4), "{p}");
    }
    assert_eq!(v["totals"]["pairs"].as_u64(), Some(3));
}
