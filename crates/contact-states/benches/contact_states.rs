//! Benchmarks: growth distance of a box pair, one feasibility test (GA + polish at default settings), and the whole
//! ACSG of the block / L-corner example at default GA settings.

use criterion::{Criterion, criterion_group, criterion_main};
use stackplan_contact_states::acsg::{AcsgSettings, generate};
use stackplan_contact_states::criteria::{ContactPart, Objective, Weights, penetration};
use stackplan_contact_states::ga::{GaSettings, minimise};
use stackplan_contact_states::growth_distance::{ConvexPiece, growth_distance};
use stackplan_contact_states::manifold::{Manifolds, StrictTolerances};
use stackplan_contact_states::pose::{Config, ConfigBox, Pose};
use stackplan_contact_states::principal_contact::{ContactState, PrincipalContact, all_ppcs};
use stackplan_contact_states::surface::Element;
use stackplan_geom::{DMat3, DVec3, Part, PartOrigin};
use std::hint::black_box;

fn parts() -> (ContactPart, ContactPart) {
    let l = stackplan_geom::examples::l_corner_part();
    let shifted: Vec<_> = l.components().iter().map(|c| c.transformed(DMat3::IDENTITY, DVec3::splat(-20.0))).collect();
    let l = Part::from_components("l-corner", shifted, 1.0, PartOrigin::ConvexPieces).expect("part");
    (
        ContactPart::from_part(&l).expect("surface"),
        ContactPart::from_part(&stackplan_geom::examples::block_part()).expect("surface"),
    )
}

fn bounds() -> ConfigBox {
    let d = 9f64.to_radians();
    ConfigBox::new([-5.0, -5.0, 0.0, -d, -d, -d], [5.0, 5.0, 240.0, d, d, d]).expect("box")
}

fn bench(c: &mut Criterion) {
    let (fixed, moving) = parts();
    let a = fixed.pieces[0].clone();
    let b: ConvexPiece = moving.pieces[0].transformed(&Pose::from_config(&[3.0, 4.0, 10.0, 0.1, -0.05, 0.12]));
    c.bench_function("growth_distance_box_pair", |bench| bench.iter(|| growth_distance(black_box(&a), black_box(&b))));
    // the same pair through the general vertex enumeration (the parallelepiped form removed), for the ratio
    let (ga, gb) =
        (ConvexPiece { parallelepiped: None, ..a.clone() }, ConvexPiece { parallelepiped: None, ..b.clone() });
    c.bench_function("growth_distance_box_pair_vertex_enumeration", |bench| {
        bench.iter(|| growth_distance(black_box(&ga), black_box(&gb)))
    });
    let pose = Pose::from_config(&[3.0, 4.0, 10.0, 0.1, -0.05, 0.12]);
    c.bench_function("penetration_block_l_corner", |bench| {
        bench.iter(|| penetration(black_box(&fixed), black_box(&moving), black_box(&pose)))
    });

    let floor = fixed
        .surface
        .faces
        .iter()
        .position(|f| (f.plane.normal - DVec3::Z).length() < 1e-9 && f.frame.height(DVec3::ZERO).abs() < 1e-9)
        .expect("floor");
    let v = moving.surface.vertices.iter().position(|v| v.position == DVec3::new(80.0, 80.0, 0.0)).expect("vertex");
    let state = ContactState::single(PrincipalContact::new(Element::face(floor), Element::vertex(v)).expect("pc"));
    let objective = Objective { fixed: &fixed, moving: &moving, state: &state, weights: Weights::for_parts(&moving) };
    let t: Config = [1.0, 2.0, 5.0, 0.05, 0.05, 0.0];
    c.bench_function("objective_eq8_one_evaluation", |bench| bench.iter(|| objective.value(black_box(&t))));
    let f = |t: &Config| objective.value(t);
    let bx = bounds();
    c.bench_function("feasibility_test_default_ga", |bench| {
        bench.iter(|| minimise(&f, &bx, &GaSettings::default(), &[]))
    });
    // the exact machinery: projection of a nearby configuration onto the f-v manifold, and the strict check
    let manifolds =
        Manifolds::new(&fixed, &moving, all_ppcs(&fixed.surface, &moving.surface), StrictTolerances::default());
    let near: Config = [1.0, 2.0, 0.4, 0.05, 0.05, 0.0];
    let on = manifolds.project(&state, &near, &bx, &[false; 6]).expect("projects");
    c.bench_function("projection_onto_f_v_manifold", |bench| {
        bench.iter(|| manifolds.project(&state, black_box(&near), &bx, &[false; 6]))
    });
    c.bench_function("strict_check_f_v", |bench| bench.iter(|| manifolds.verify(&state, black_box(&on), &bx)));
    let mut group = c.benchmark_group("acsg");
    group.sample_size(10);
    group.bench_function("block_l_corner_default_ga", |bench| {
        bench.iter(|| generate(&fixed, &moving, bx, AcsgSettings::default()).expect("default settings"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
