//! Growth distance against clarabel on the LP of Ong & Gilbert, against a brute-force scaling search, and sign
//! agreement with an independent separating-axis interference test.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus};
use proptest::prelude::*;
use stackplan_contact_states::growth_distance::{ConvexPiece, growth_distance, growth_distance_capped};
use stackplan_contact_states::pose::Pose;
use stackplan_geom::{ConvexPolytope, DVec3, convex_hull};

/// Plane data `(n, d)` of a polytope moved by a pose.
fn planes(poly: &ConvexPolytope, pose: &Pose) -> Vec<(DVec3, f64)> {
    poly.planes()
        .map(|p| {
            let n = pose.apply_vector(p.normal);
            (n, p.offset + n.dot(pose.translation))
        })
        .collect()
}

/// clarabel on `min sigma s.t. a_i.(x - p) <= sigma (b_i - a_i.p)`, both polytopes. `None` unless Solved.
fn clarabel_sigma(pa: &[(DVec3, f64)], p: DVec3, pb: &[(DVec3, f64)], q: DVec3) -> Option<f64> {
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut rhs = Vec::new();
    for (planes, seed) in [(pa, p), (pb, q)] {
        for (n, d) in planes {
            rows.push(vec![n.x, n.y, n.z, -(d - n.dot(seed))]);
            rhs.push(n.dot(seed));
        }
    }
    rows.push(vec![0.0, 0.0, 0.0, -1.0]);
    rhs.push(0.0);
    let m = rows.len();
    let a = CscMatrix::from(&rows);
    let pmat = CscMatrix::<f64>::zeros((4, 4));
    let settings = DefaultSettingsBuilder::default().verbose(false).build().ok()?;
    let mut solver =
        DefaultSolver::new(&pmat, &[0.0, 0.0, 0.0, 1.0], &a, &rhs, &[NonnegativeConeT(m)], settings).ok()?;
    solver.solve();
    (solver.solution.status == SolverStatus::Solved).then(|| solver.solution.x[3])
}

fn inside(planes: &[(DVec3, f64)], x: DVec3, slack: f64) -> bool {
    planes.iter().all(|(n, d)| n.dot(x) <= d + slack)
}

/// Exact-enough intersection test of two convex polytopes given by vertices, edges and planes: they meet iff a
/// vertex of one is in the other or an edge of one crosses a face of the other.
fn intersects(
    va: &[DVec3],
    ea: &[(usize, usize)],
    pa: &[(DVec3, f64)],
    vb: &[DVec3],
    eb: &[(usize, usize)],
    pb: &[(DVec3, f64)],
) -> bool {
    let slack = 1e-12;
    if va.iter().any(|v| inside(pb, *v, slack)) || vb.iter().any(|v| inside(pa, *v, slack)) {
        return true;
    }
    let edge_hits = |verts: &[DVec3], edges: &[(usize, usize)], planes: &[(DVec3, f64)]| {
        edges.iter().any(|&(i, j)| {
            // clip the segment against all half-spaces
            let (a, b) = (verts[i], verts[j]);
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for (n, d) in planes {
                let (fa, fb) = (n.dot(a) - d, n.dot(b) - d);
                if fa > slack && fb > slack {
                    return false;
                }
                if fa > 0.0 && fb < 0.0 {
                    lo = lo.max(fa / (fa - fb));
                } else if fa < 0.0 && fb > 0.0 {
                    hi = hi.min(fa / (fa - fb));
                }
            }
            lo <= hi + 1e-12
        })
    };
    edge_hits(va, ea, pb) || edge_hits(vb, eb, pa)
}

struct Scaled {
    v: Vec<DVec3>,
    e: Vec<(usize, usize)>,
    p: Vec<(DVec3, f64)>,
}

fn scaled(poly: &ConvexPolytope, pose: &Pose, seed: DVec3, s: f64) -> Scaled {
    let v: Vec<DVec3> = poly.vertices().iter().map(|x| seed + (pose.apply(*x) - seed) * s).collect();
    let e = poly.edges().iter().map(|e| (e.vertices[0], e.vertices[1])).collect();
    let p = planes(poly, pose).into_iter().map(|(n, d)| (n, n.dot(seed) + s * (d - n.dot(seed)))).collect();
    Scaled { v, e, p }
}

/// Brute force: bisection on the scale factor with the geometric intersection test.
fn brute_force_sigma(a: &ConvexPolytope, pa: &Pose, b: &ConvexPolytope, pb: &Pose) -> f64 {
    let p = pa.apply(a.vertex_centroid());
    let q = pb.apply(b.vertex_centroid());
    let meet = |s: f64| {
        let x = scaled(a, pa, p, s);
        let y = scaled(b, pb, q, s);
        intersects(&x.v, &x.e, &x.p, &y.v, &y.e, &y.p)
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    while !meet(hi) {
        lo = hi;
        hi *= 2.0;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if meet(mid) { hi = mid } else { lo = mid }
    }
    0.5 * (lo + hi)
}

/// Independent interference test by separating axes (face normals and edge cross products): `true` if some axis
/// separates the polytopes by more than `gap`.
fn separated_by_axis(
    va: &[DVec3],
    ea: &[DVec3],
    na: &[DVec3],
    vb: &[DVec3],
    eb: &[DVec3],
    nb: &[DVec3],
    gap: f64,
) -> bool {
    let mut axes: Vec<DVec3> = na.iter().chain(nb.iter()).copied().collect();
    for x in ea {
        for y in eb {
            let c = x.cross(*y);
            if c.length() > 1e-9 {
                axes.push(c.normalize());
            }
        }
    }
    axes.iter().any(|n| {
        let (amin, amax) =
            va.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(n.dot(*v)), h.max(n.dot(*v))));
        let (bmin, bmax) =
            vb.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(n.dot(*v)), h.max(n.dot(*v))));
        bmin > amax + gap || amin > bmax + gap
    })
}

fn random_polytope() -> impl Strategy<Value = ConvexPolytope> {
    prop_oneof![
        // boxes
        (0.5f64..5.0, 0.5f64..5.0, 0.5f64..5.0).prop_map(|(x, y, z)| {
            let pts: Vec<DVec3> = (0..8)
                .map(|i| {
                    DVec3::new(
                        if i & 1 == 0 { -x } else { x },
                        if i & 2 == 0 { -y } else { y },
                        if i & 4 == 0 { -z } else { z },
                    )
                })
                .collect();
            convex_hull(&pts).expect("box").polytope
        }),
        // random hulls
        prop::collection::vec((-3.0f64..3.0, -3.0f64..3.0, -3.0f64..3.0), 6..14).prop_filter_map("flat", |pts| {
            let pts: Vec<DVec3> = pts.into_iter().map(|(x, y, z)| DVec3::new(x, y, z)).collect();
            let h = convex_hull(&pts).ok()?;
            (h.polytope.volume() > 0.5).then_some(h.polytope)
        }),
    ]
}

fn pose() -> impl Strategy<Value = Pose> {
    (-6.0f64..6.0, -6.0f64..6.0, -6.0f64..6.0, -3.2f64..3.2, -1.6f64..1.6, -3.2f64..3.2)
        .prop_map(|(x, y, z, a, b, c)| Pose::from_config(&[x, y, z, a, b, c]))
}

/// A cube sheared and scaled by a random integer matrix (a general parallelepiped; integer coordinates keep its
/// faces exactly planar, so the hull has 6 faces), kept away from flat ones.
fn sheared_box() -> impl Strategy<Value = ConvexPolytope> {
    prop::array::uniform9(-3i32..=3).prop_filter_map("flat", |m| {
        let m = m.map(f64::from);
        let cols = [DVec3::new(m[0], m[1], m[2]), DVec3::new(m[3], m[4], m[5]), DVec3::new(m[6], m[7], m[8])];
        if cols[0].dot(cols[1].cross(cols[2])).abs() < 1.0 {
            return None;
        }
        let pts: Vec<DVec3> = (0..8)
            .map(|i| {
                let s = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
                cols[0] * s(1) + cols[1] * s(2) + cols[2] * s(4) + DVec3::new(0.5, -0.25, 1.0)
            })
            .collect();
        convex_hull(&pts).ok().map(|h| h.polytope)
    })
}

proptest! {
    /// The closed-form path for two parallelepipeds (`sum |n.a_i| + sum |n.b_j|`) against the vertex enumeration of
    /// the same pieces with the parallelepiped form removed, capped and uncapped.
    #[test]
    fn parallelepiped_path_matches_vertex_enumeration(
        a in sheared_box(), b in sheared_box(), pa in pose(), pb in pose(), cap in 0.5f64..2.0,
    ) {
        let ga = ConvexPiece::from_polytope(&a).transformed(&pa);
        let gb = ConvexPiece::from_polytope(&b).transformed(&pb);
        prop_assert!(ga.parallelepiped.is_some() && gb.parallelepiped.is_some());
        let general = |p: &ConvexPiece| ConvexPiece { parallelepiped: None, ..p.clone() };
        let (va, vb) = (general(&ga), general(&gb));
        let fast = growth_distance(&ga, &gb);
        let slow = growth_distance(&va, &vb);
        prop_assert!((fast - slow).abs() <= 1e-9 * (1.0 + slow), "fast {} enumeration {}", fast, slow);
        let fast = growth_distance_capped(&ga, ga.seed, &gb, gb.seed, cap);
        let slow = growth_distance_capped(&va, va.seed, &vb, vb.seed, cap);
        if slow < cap - 1e-9 {
            prop_assert!((fast - slow).abs() <= 1e-9 * (1.0 + slow), "capped: fast {} enumeration {}", fast, slow);
        } else {
            prop_assert!(fast >= cap - 1e-9, "capped: fast {} enumeration {} cap {}", fast, slow, cap);
        }
    }

    #[test]
    fn matches_clarabel(a in random_polytope(), b in random_polytope(), pa in pose(), pb in pose()) {
        let ga = ConvexPiece::from_polytope(&a).transformed(&pa);
        let gb = ConvexPiece::from_polytope(&b).transformed(&pb);
        let ours = growth_distance(&ga, &gb);
        if let Some(reference) = clarabel_sigma(&planes(&a, &pa), ga.seed, &planes(&b, &pb), gb.seed) {
            prop_assert!((ours - reference).abs() <= 1e-6 * (1.0 + reference), "ours {} clarabel {}", ours, reference);
        }
    }

    #[test]
    fn matches_brute_force_scaling(a in random_polytope(), b in random_polytope(), pa in pose(), pb in pose()) {
        let ga = ConvexPiece::from_polytope(&a).transformed(&pa);
        let gb = ConvexPiece::from_polytope(&b).transformed(&pb);
        let ours = growth_distance(&ga, &gb);
        let brute = brute_force_sigma(&a, &pa, &b, &pb);
        prop_assert!((ours - brute).abs() <= 1e-7 * (1.0 + brute), "ours {} brute {}", ours, brute);
    }

    #[test]
    fn sign_agrees_with_separating_axis_test(a in random_polytope(), b in random_polytope(), pa in pose(), pb in pose()) {
        let ga = ConvexPiece::from_polytope(&a).transformed(&pa);
        let gb = ConvexPiece::from_polytope(&b).transformed(&pb);
        let sigma = growth_distance(&ga, &gb);
        let ea: Vec<DVec3> = a.edges().iter().map(|e| pa.apply_vector(a.vertices()[e.vertices[1]] - a.vertices()[e.vertices[0]])).collect();
        let eb: Vec<DVec3> = b.edges().iter().map(|e| pb.apply_vector(b.vertices()[e.vertices[1]] - b.vertices()[e.vertices[0]])).collect();
        let separated = separated_by_axis(&ga.vertices, &ea, &ga.normals, &gb.vertices, &eb, &gb.normals, 1e-9);
        let overlapping = !separated_by_axis(&ga.vertices, &ea, &ga.normals, &gb.vertices, &eb, &gb.normals, -1e-9);
        if sigma > 1.0 + 1e-9 { prop_assert!(separated, "sigma {} but no separating axis", sigma); }
        if sigma < 1.0 - 1e-9 { prop_assert!(overlapping, "sigma {} but separated", sigma); }
        if separated { prop_assert!(sigma > 1.0); }
        if overlapping { prop_assert!(sigma < 1.0 + 1e-12); }
    }

    /// Sign agreement with the c-space crate's interference test (`classify_pair`, separating axes with its own
    /// tolerance): penetrating iff `sigma < 1`, separated iff `sigma > 1`, away from the tolerance band.
    #[test]
    fn sign_agrees_with_cspace_interference(a in random_polytope(), b in random_polytope(), pa in pose(), pb in pose()) {
        use stackplan_cspace::interference::{PairContact, PlacedConvex, classify_pair};
        let ga = ConvexPiece::from_polytope(&a).transformed(&pa);
        let gb = ConvexPiece::from_polytope(&b).transformed(&pb);
        let sigma = growth_distance(&ga, &gb);
        let ca = PlacedConvex::new(&a, pa.rotation, pa.translation);
        let cb = PlacedConvex::new(&b, pb.rotation, pb.translation);
        let tol = 1e-9;
        match classify_pair(&ca, &cb, tol, 0.0) {
            PairContact::Penetrating { depth } => prop_assert!(sigma < 1.0, "c-space: penetrating by {}, sigma {}", depth, sigma),
            PairContact::Separated { gap } => prop_assert!(sigma > 1.0, "c-space: separated by {}, sigma {}", gap, sigma),
            PairContact::Touching { .. } => prop_assert!((sigma - 1.0).abs() < 1e-6, "c-space: touching, sigma {}", sigma),
        }
    }

    /// The capped growth distance used by the penetration term: exact below the cap, at least the cap otherwise.
    #[test]
    fn capped_growth_distance(a in random_polytope(), b in random_polytope(), pa in pose(), pb in pose()) {
        let ga = ConvexPiece::from_polytope(&a).transformed(&pa);
        let gb = ConvexPiece::from_polytope(&b).transformed(&pb);
        let sigma = growth_distance(&ga, &gb);
        let capped = growth_distance_capped(&ga, ga.seed, &gb, gb.seed, 1.0);
        if sigma < 1.0 { prop_assert_eq!(capped, sigma); } else { prop_assert!(capped >= 1.0, "{} {}", capped, sigma); }
    }
}

/// Touching configurations (sigma = 1 exactly by construction): face-face, edge-face, vertex-face on boxes.
#[test]
fn touching_is_one() {
    let cube = |h: f64| {
        let pts: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { -h } else { h },
                    if i & 2 == 0 { -h } else { h },
                    if i & 4 == 0 { -h } else { h },
                )
            })
            .collect();
        ConvexPiece::from_polytope(&convex_hull(&pts).expect("cube").polytope)
    };
    let a = cube(1.0);
    let b = cube(0.5);
    // face-face with an offset in x
    let s = growth_distance(&a, &b.transformed(&Pose::from_config(&[0.7, 0.2, 1.5, 0.0, 0.0, 0.3])));
    assert!((s - 1.0).abs() < 1e-12, "{s}");
    // vertex down: rotate so that a body diagonal is vertical; lowest vertex at depth sqrt(3)/2
    let tilt = (1.0f64 / 2f64.sqrt()).atan();
    let lowest = 0.5 * 3f64.sqrt();
    let s = growth_distance(
        &a,
        &b.transformed(&Pose::from_config(&[0.1, -0.2, 1.0 + lowest, std::f64::consts::FRAC_PI_4, tilt, 0.0])),
    );
    assert!((s - 1.0).abs() < 1e-9, "{s}");
}

/// The per-call benchmark figure of docs/benchmarks.md relies on this shape of problem: check the box pair case is exact.
#[test]
fn box_pair_example() {
    let pts = |lo: DVec3, hi: DVec3| -> Vec<DVec3> {
        (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect()
    };
    let a = ConvexPiece::from_polytope(&convex_hull(&pts(DVec3::ZERO, DVec3::new(4.0, 2.0, 2.0))).expect("a").polytope);
    let b = ConvexPiece::from_polytope(
        &convex_hull(&pts(DVec3::new(3.0, 0.0, 0.0), DVec3::new(5.0, 2.0, 2.0))).expect("b").polytope,
    );
    // seeds (2,1,1) and (4,1,1): x faces limit: sigma = 2 / (2 + 1) ... grows A's +x face (at 2 from p) and B's -x
    // face (at 1 from q): sigma (2 + 1) = 2
    assert!((growth_distance(&a, &b) - 2.0 / 3.0).abs() < 1e-15);
}
