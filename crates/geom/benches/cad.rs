//! Parts from CAD: reading, recognising and decomposing the six real parts of `fixtures/realparts/` (BenDFM), from
//! STEP and from STL (`read_part`: parse, B-rep or mesh segmentation, sheet-metal recognition, plates' and bends'
//! convex pieces, mass properties and boundary faces of the part); and the parts of `fixtures/cad/` with faces on
//! cones, tori, B-spline surfaces and extrusions, which are tessellated and go through the mesh route.

use criterion::{Criterion, criterion_group, criterion_main};
use stackplan_geom::io::{ReadOptions, read_part};
use std::hint::black_box;
use std::path::Path;

fn bench(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/realparts");
    let mut group = c.benchmark_group("realparts");
    group.sample_size(20);
    for n in 0..6 {
        for ext in ["stp", "stl"] {
            let path = dir.join(format!("bendfm_{n}.{ext}"));
            group.bench_function(format!("bendfm_{n}.{ext}"), |b| {
                b.iter(|| black_box(read_part(&path, &ReadOptions::default()).expect("part")))
            });
        }
    }
    group.finish();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/cad");
    let mut group = c.benchmark_group("cad");
    group.sample_size(20);
    for name in ["countersink_plate", "flange_nurbs", "spline_plate"] {
        let path = dir.join(format!("{name}.step"));
        group.bench_function(format!("{name}.step"), |b| {
            b.iter(|| black_box(read_part(&path, &ReadOptions::default()).expect("part")))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
