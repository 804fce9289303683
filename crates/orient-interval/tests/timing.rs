//! Rough per-call timing of extrapolation vs construction on the example parts' component pairs, in the test
//! profile (our crates at opt-level 1, dependencies at 3; the criterion bench in benches/ is the release figure).
//! Asserts only that extrapolating the geometry is cheaper than building; prints the ratios for docs/benchmarks.md.

use stackplan_cspace::minkowski::obstacle;
use stackplan_geom::examples;
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_geom::{DMat3, DVec3};
use stackplan_orient_interval::{ExtrapolatedGeometry, ObstacleStructure, PairEvents, rotation_z};
use std::time::Instant;

#[test]
fn extrapolation_is_cheaper_than_construction() {
    for name in ["channel", "triangle", "complex", "l-corner"] {
        let part = examples::part_by_name(name, Decomposition::Triangulation).expect("example");
        let c = &part.components;
        let (a, b) = (c[0].clone(), c[c.len() / 2].transformed(DMat3::from_rotation_z(0.3), DVec3::new(5.0, 3.0, 2.0)));
        let events = PairEvents::new(&a, &b);
        let s = ObstacleStructure::build(&a, &b, 0.2, &events).expect("structure");
        let t = 0.2 + 0.5 * (s.interval().end - 0.2).min(0.1);
        let n = 2000;
        let start = Instant::now();
        for _ in 0..n {
            std::hint::black_box(obstacle(&a, rotation_z(std::hint::black_box(t)), &b).expect("obstacle"));
        }
        let build = start.elapsed().as_secs_f64() / n as f64;
        let start = Instant::now();
        for _ in 0..n {
            std::hint::black_box(s.extrapolate(&a, &b, std::hint::black_box(t)).expect("inside"));
        }
        let full = start.elapsed().as_secs_f64() / n as f64;
        let mut g = ExtrapolatedGeometry::default();
        let start = Instant::now();
        for _ in 0..n {
            s.extrapolate_geometry(&a, &b, std::hint::black_box(t), &mut g).expect("inside");
            std::hint::black_box(&g);
        }
        let geometry = start.elapsed().as_secs_f64() / n as f64;
        let start = Instant::now();
        for _ in 0..200 {
            std::hint::black_box(PairEvents::new(&a, &b));
        }
        let ev = start.elapsed().as_secs_f64() / 200.0;
        #[allow(clippy::print_stderr)]
        {
            eprintln!(
                "{name}: construction {:.2} us, extrapolate obstacle {:.2} us ({:.1}%), extrapolate geometry {:.3} us ({:.1}%), pair events {:.2} us, faces {}",
                build * 1e6,
                full * 1e6,
                100.0 * full / build,
                geometry * 1e6,
                100.0 * geometry / build,
                ev * 1e6,
                s.template().polytope().faces().len()
            );
        }
        assert!(geometry < build, "{name}: extrapolating the geometry should be cheaper than building");
    }
}
