//! Convex decomposition of sheet-metal models: the example parts and random polygons with holes.
//!
//! Every check here is independent of the decomposition code: face areas come from Newell's formula on the input
//! rings, disjointness from a separating-axis test on the prisms' own face planes, coverage from the area sum plus
//! sampled points of every piece inside the input face (a float crossing-number test written here).

use proptest::prelude::*;
use stackplan_geom::examples;
use stackplan_geom::polytope::newell_normal;
use stackplan_geom::predicates::collinear;
use stackplan_geom::sheet_metal::Ring;
use stackplan_geom::{
    ConvexPolytope, DMat3, DVec2, DVec3, Decomposition, PartOrigin, SheetFace, SheetMetal, SheetMetalError,
};

// ---------------------------------------------------------------- independent reference computations

/// Input rings with consecutive duplicates removed (the model's documented clean-up).
fn distinct(ring: &[DVec3]) -> Vec<DVec3> {
    let mut out: Vec<DVec3> = Vec::new();
    for p in ring {
        if out.last() != Some(p) {
            out.push(*p);
        }
    }
    while out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    out
}

fn ring_area(ring: &[DVec3]) -> f64 {
    newell_normal(ring.iter().copied()).length() / 2.0
}

fn perimeter(face: &SheetFace) -> f64 {
    std::iter::once(&face.outline)
        .chain(&face.holes)
        .map(|r| {
            let r = distinct(r);
            (0..r.len()).map(|i| (r[(i + 1) % r.len()] - r[i]).length()).sum::<f64>()
        })
        .sum()
}

fn boundary_area(part: &stackplan_geom::Part) -> f64 {
    part.boundary().iter().map(|b| ring_area(&b.outline) - b.holes.iter().map(|h| ring_area(h)).sum::<f64>()).sum()
}

fn face_area(face: &SheetFace) -> f64 {
    ring_area(&face.outline) - face.holes.iter().map(|h| ring_area(h)).sum::<f64>()
}

/// Float projection onto the coordinate plane most parallel to the face.
fn projector(face: &SheetFace) -> impl Fn(DVec3) -> DVec2 {
    let n = newell_normal(face.outline.iter().copied()).abs();
    let axis = if n.x >= n.y && n.x >= n.z {
        0
    } else if n.y >= n.z {
        1
    } else {
        2
    };
    move |p: DVec3| match axis {
        0 => DVec2::new(p.y, p.z),
        1 => DVec2::new(p.x, p.z),
        _ => DVec2::new(p.x, p.y),
    }
}

fn crossing_inside(p: DVec2, ring: &[DVec2]) -> bool {
    let mut inside = false;
    let n = ring.len();
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if x > p.x {
                inside = !inside;
            }
        }
    }
    inside
}

fn inside_face(face: &SheetFace, p: DVec3) -> bool {
    let proj = projector(face);
    let ring = |r: &[DVec3]| r.iter().map(|q| proj(*q)).collect::<Vec<_>>();
    let q = proj(p);
    crossing_inside(q, &ring(&face.outline)) && face.holes.iter().all(|h| !crossing_inside(q, &ring(h)))
}

/// Whether two convex polytopes have disjoint interiors (up to `tol`): some face plane of one has all the other's
/// vertices on or outside it. For prisms over coplanar convex polygons, the side faces suffice (2-D separating axes).
fn interiors_disjoint(a: &ConvexPolytope, b: &ConvexPolytope, tol: f64) -> bool {
    let separates = |p: &ConvexPolytope, q: &ConvexPolytope| {
        p.faces().iter().any(|f| q.vertices().iter().all(|v| f.plane.signed_distance(*v) >= -tol))
    };
    separates(a, b) || separates(b, a)
}

/// Full separating-axis test for two convex polytopes: face normals of both and cross products of edge directions.
/// True when some axis separates them (touching within `tol` counts as separated).
fn separated_sat(a: &ConvexPolytope, b: &ConvexPolytope, tol: f64) -> bool {
    let dirs = |p: &ConvexPolytope| {
        p.edges().iter().map(|e| p.vertices()[e.vertices[1]] - p.vertices()[e.vertices[0]]).collect::<Vec<_>>()
    };
    let mut axes: Vec<DVec3> = a.planes().chain(b.planes()).map(|pl| pl.normal).collect();
    for u in dirs(a) {
        for v in dirs(b) {
            let c = u.cross(v);
            if c.length() > 1e-12 * u.length() * v.length() {
                axes.push(c.normalize());
            }
        }
    }
    axes.iter().any(|&n| {
        let range = |p: &ConvexPolytope| {
            p.vertices()
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(n.dot(*v)), hi.max(n.dot(*v))))
        };
        let (a0, a1) = range(a);
        let (b0, b1) = range(b);
        a1 <= b0 + tol || b1 <= a0 + tol
    })
}

/// All the decomposition invariants for one model: convex valid prisms, per-face volume = thickness x area, pieces
/// of one face pairwise interior-disjoint and inside the face. Returns the number of pieces per face.
fn check_model(model: &SheetMetal, decomposition: Decomposition) -> Vec<usize> {
    let per_face = model.decompose(decomposition).expect("decomposition");
    assert_eq!(per_face.len(), model.faces.len());
    let mut counts = Vec::new();
    for (fi, (face, prisms)) in model.faces.iter().zip(&per_face).enumerate() {
        let area = face_area(face);
        let scale = face.outline.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element())).max(1.0);
        let mut volume = 0.0;
        for (k, prism) in prisms.iter().enumerate() {
            prism.validate().unwrap_or_else(|e| panic!("face {fi} piece {k}: {e}"));
            let v = prism.volume();
            assert!(v > 0.0);
            volume += v;
            // sampled points of the piece's mid-surface polygon lie inside the input face
            let centre = prism.vertex_centroid();
            assert!(inside_face(face, centre), "face {fi} piece {k}: centre outside the face");
            for corner in prism.vertices() {
                let sample = centre + (*corner - centre) * 0.9;
                let on_mid = sample - (sample - centre).project_onto(newell_normal(face.outline.iter().copied()));
                assert!(inside_face(face, on_mid), "face {fi} piece {k}: sample outside the face");
            }
        }
        let expected = model.thickness * area;
        assert!(
            (volume - expected).abs() <= 1e-9 * expected.max(1.0) + 1e-7 * scale * model.thickness,
            "face {fi}: volume {volume} vs thickness x area {expected}"
        );
        let tol = 1e-9 * scale * 10.0;
        for i in 0..prisms.len() {
            for j in i + 1..prisms.len() {
                assert!(interiors_disjoint(&prisms[i], &prisms[j], tol), "face {fi}: pieces {i} and {j} overlap");
            }
        }
        counts.push(prisms.len());
    }
    counts
}

// ---------------------------------------------------------------- examples

#[test]
fn example_component_counts_match_the_seed() {
    for (name, model, expected) in [
        ("channel", examples::channel(), 3),
        ("triangle", examples::triangle(), 6),
        ("complex", examples::complex(), 79),
    ] {
        let counts = check_model(&model, Decomposition::Triangulation);
        assert_eq!(counts.iter().sum::<usize>(), expected, "{name}");
        let part = model.build_part(name, 1.0, Decomposition::Triangulation).expect("part");
        assert_eq!(part.components().len(), expected, "{name}");
        assert_eq!(part.origin, PartOrigin::SheetMetal { thickness: 2.0 });
        let merged = check_model(&model, Decomposition::ConvexMerge);
        assert!(merged.iter().sum::<usize>() <= expected, "{name}: merging gave more pieces");
        // the cuts inside faces are internal whichever way the faces were split
        let merged_part = model.build_part(name, 1.0, Decomposition::ConvexMerge).expect("part");
        let (a, b) = (boundary_area(&part), boundary_area(&merged_part));
        assert!((a - b).abs() <= 1e-9 * a, "{name}: boundary area {a} (triangles) vs {b} (merged)");
        for (m, t) in merged.iter().zip(&counts) {
            assert!(m <= t);
        }
    }
}

#[test]
fn complex_part_counts() {
    // per face: base 48, tall flanges 14 each, short flanges and lip 1 each (see the doc comment of `complex`)
    let counts = check_model(&examples::complex(), Decomposition::Triangulation);
    assert_eq!(counts, vec![48, 14, 14, 1, 1, 1]);
    let merged = check_model(&examples::complex(), Decomposition::ConvexMerge);
    // a rectangle with 7 convex holes needs at least 8 convex pieces (each hole blocks a vertex of the plate's
    // convexity); Hertel-Mehlhorn guarantees at most 4x optimal, in practice far fewer than the 48 triangles
    assert!(merged[0] >= 8 && merged[0] <= 32, "base pieces {}", merged[0]);
    assert!(merged[1] >= 4 && merged[1] <= 14, "tall flange pieces {}", merged[1]);
}

#[test]
fn example_volumes_and_shapes() {
    let channel = examples::channel().build_part("channel", 1.0, Decomposition::ConvexMerge).expect("channel");
    // three plates: 200 x 100 + 2 x (200 x 50), thickness 2
    assert!((channel.mass().volume - 2.0 * (20000.0 + 20000.0)).abs() < 1e-6);
    let (lo, hi) = channel.aabb();
    assert!(
        (lo - DVec3::new(0.0, -1.0, -1.0)).length() < 1e-12 && (hi - DVec3::new(200.0, 101.0, 50.0)).length() < 1e-12
    );

    let triangle = examples::triangle().build_part("triangle", 1.0, Decomposition::ConvexMerge).expect("triangle");
    assert_eq!(triangle.components().len(), 6);
    let (lo, hi) = triangle.aabb();
    assert!(lo.z < 0.0 && hi.z > 40.0 && hi.z < 42.0);

    let cube = examples::cube();
    assert_eq!(cube.components().len(), 1);
    assert!((cube.mass().volume - 1.0).abs() < 1e-15);
    let corner = examples::l_corner_part();
    assert_eq!(corner.components().len(), 3);
    assert!((corner.mass().volume - (150.0 * 150.0 * 20.0 + 20.0 * 150.0 * 100.0 + 130.0 * 20.0 * 100.0)).abs() < 1e-6);
    let block = examples::block_part();
    assert!((block.mass().volume - 80.0 * 80.0 * 100.0).abs() < 1e-6);
    // every name resolves, both decompositions
    for name in examples::NAMES {
        for d in [Decomposition::ConvexMerge, Decomposition::Triangulation] {
            let part = examples::part_by_name(name, d).expect("known example");
            assert_eq!(part.name, name);
            for c in part.components() {
                c.validate().expect("valid component");
            }
        }
    }
    assert!(examples::by_name("l_corner").is_some());
    assert!(examples::by_name("nonsense").is_none());
}

#[test]
fn triangle_parts_nest_in_one_orientation() {
    let part = examples::triangle().build_part("triangle", 1.0, Decomposition::ConvexMerge).expect("part");
    // a copy 4.5 mm higher (> t * sqrt(5) = 4.47) touches nothing; 4.4 mm is too little (the walls' 2 mm slabs are
    // then 4.4 / sqrt(5) = 1.97 mm apart). The separating-axis test is complete for convex pairs.
    let shifted = |dz: f64| -> Vec<ConvexPolytope> {
        part.components().iter().map(|c| c.transformed(DMat3::IDENTITY, DVec3::new(0.0, 0.0, dz))).collect()
    };
    let all_separated =
        |upper: &[ConvexPolytope]| upper.iter().all(|a| part.components().iter().all(|b| separated_sat(a, b, 1e-9)));
    let dz = 4.5;
    assert!(all_separated(&shifted(dz)));
    assert!(!all_separated(&shifted(4.4)));
    // and it is nested: the copy's lowest point is far below the lower part's top
    let (lo, hi) = part.aabb();
    assert!(lo.z + dz < hi.z - 30.0);
}

fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    stackplan_geom::convex_hull(&corners).expect("box").polytope
}

#[test]
fn boundary_faces_with_t_junctions_and_partial_contact() {
    // A's face x = 2 is covered by two faces of B1 and B2 (a T-junction): it is internal, the union is a 3 x 1 x 1 box
    let a = cuboid(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0));
    let b1 = cuboid(DVec3::new(2.0, 0.0, 0.0), DVec3::new(3.0, 0.5, 1.0));
    let b2 = cuboid(DVec3::new(2.0, 0.5, 0.0), DVec3::new(3.0, 1.0, 1.0));
    let part = stackplan_geom::Part::from_components("t", vec![a.clone(), b1, b2], 1.0, PartOrigin::ConvexPieces)
        .expect("part");
    assert!((boundary_area(&part) - 14.0).abs() < 1e-12, "{}", boundary_area(&part));
    assert!(part.boundary().iter().all(|f| f.outline.iter().any(|p| p.x != 2.0) || f.plane.normal.x.abs() < 0.5));
    // partial contact: B covers the upper half of A's face x = 2 only; the lower half stays boundary
    let b = cuboid(DVec3::new(2.0, 0.0, 0.5), DVec3::new(3.0, 1.0, 1.0));
    let part = stackplan_geom::Part::from_components("p", vec![a, b], 1.0, PartOrigin::ConvexPieces).expect("part");
    // surface of A (10) + surface of B (2 x (1 x 0.5) + 2 x (1 x 0.5) + 2 x (1 x 1) = 4) - 2 x 0.5 (contact)
    assert!((boundary_area(&part) - 13.0).abs() < 1e-12, "{}", boundary_area(&part));
    let at_x2: f64 = part
        .boundary()
        .iter()
        .filter(|f| f.plane.normal.x > 0.5 && f.outline.iter().all(|p| (p.x - 2.0).abs() < 1e-12))
        .map(|f| ring_area(&f.outline))
        .sum();
    assert!((at_x2 - 0.5).abs() < 1e-12, "uncovered part of A's face: {at_x2}");
}

// ---------------------------------------------------------------- random polygons with holes

/// Dyadic-grid "histogram" polygon: columns of width 4 and integer heights (equal neighbours give collinear runs and
/// duplicate points), with convex holes strictly inside chosen columns.
fn histogram_face() -> impl Strategy<Value = (Vec<DVec2>, Vec<Vec<DVec2>>)> {
    (2usize..8).prop_flat_map(|k| (prop::collection::vec(2u32..10, k), prop::collection::vec(0u8..5, k))).prop_map(
        |(heights, hole_kinds)| {
            let w = 4.0;
            let k = heights.len();
            let mut outline = vec![DVec2::new(0.0, 0.0), DVec2::new(k as f64 * w, 0.0)];
            for i in (0..k).rev() {
                let h = heights[i] as f64;
                outline.push(DVec2::new((i + 1) as f64 * w, h));
                outline.push(DVec2::new(i as f64 * w, h));
            }
            let mut holes = Vec::new();
            for (i, &kind) in hole_kinds.iter().enumerate() {
                let (x0, x1) = (i as f64 * w + 0.5, (i + 1) as f64 * w - 0.5);
                let (y0, y1) = (0.5, heights[i] as f64 - 0.5);
                let (xm, ym) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
                let hole = match kind {
                    0 => continue,
                    1 => vec![DVec2::new(x0, y0), DVec2::new(x1, y0), DVec2::new(x1, y1), DVec2::new(x0, y1)],
                    2 => vec![DVec2::new(xm, y0), DVec2::new(x1, ym), DVec2::new(xm, y1), DVec2::new(x0, ym)],
                    3 => vec![DVec2::new(x0, y0), DVec2::new(x1, y0), DVec2::new(xm, y1)],
                    _ => vec![
                        DVec2::new(x0, ym),
                        DVec2::new(xm, y0),
                        DVec2::new(x1, y0),
                        DVec2::new(x1, ym),
                        DVec2::new(x1, y1),
                        DVec2::new(x0, y1),
                    ],
                };
                holes.push(hole);
            }
            (outline, holes)
        },
    )
}

/// Star-shaped polygon about the origin with radii in [10, 40], rounded to a 1/16 grid, and up to three small holes
/// (squares or diamonds) near the centre.
fn star_face() -> impl Strategy<Value = (Vec<DVec2>, Vec<Vec<DVec2>>)> {
    (8usize..24)
        .prop_flat_map(|n| (prop::collection::vec((0.0f64..0.3, 10.0f64..40.0), n), prop::collection::vec(0u8..3, 3)))
        .prop_map(|(rays, hole_kinds)| {
            let n = rays.len();
            let grid = |x: f64| (x * 16.0).round() / 16.0;
            let outline: Vec<DVec2> = rays
                .iter()
                .enumerate()
                .map(|(k, &(jitter, r))| {
                    let a = (k as f64 + jitter) * std::f64::consts::TAU / n as f64;
                    DVec2::new(grid(r * a.cos()), grid(r * a.sin()))
                })
                .collect();
            let mut holes = Vec::new();
            for (centre, kind) in
                [DVec2::new(-4.0, 0.0), DVec2::new(4.0, 0.0), DVec2::new(0.0, 4.0)].iter().zip(hole_kinds)
            {
                let c = *centre;
                match kind {
                    1 => holes.push(vec![
                        c + DVec2::new(-1.0, -1.0),
                        c + DVec2::new(1.0, -1.0),
                        c + DVec2::new(1.0, 1.0),
                        c + DVec2::new(-1.0, 1.0),
                    ]),
                    2 => holes.push(vec![
                        c + DVec2::new(0.0, -1.5),
                        c + DVec2::new(1.5, 0.0),
                        c + DVec2::new(0.0, 1.5),
                        c + DVec2::new(-1.5, 0.0),
                    ]),
                    _ => {}
                }
            }
            (outline, holes)
        })
}

/// A placement of the 2-D face in space: exact (axis permutation, signs, dyadic offset) or a general rotation.
#[derive(Debug, Clone)]
enum Placement {
    Exact { axes: [usize; 3], flip: [bool; 3], offset: DVec3 },
    Rotated { rotation: DMat3, offset: DVec3 },
}

impl Placement {
    fn apply(&self, p: DVec2, height: f64) -> DVec3 {
        let local = [p.x, p.y, height];
        match self {
            Placement::Exact { axes, flip, offset } => {
                let mut out = [0.0; 3];
                for k in 0..3 {
                    out[axes[k]] = if flip[k] { -local[k] } else { local[k] };
                }
                DVec3::from_array(out) + *offset
            }
            Placement::Rotated { rotation, offset } => *rotation * DVec3::from_array(local) + *offset,
        }
    }
}

fn placement() -> impl Strategy<Value = Placement> {
    let exact = (0usize..6, prop::array::uniform3(any::<bool>()), prop::array::uniform3(-64i32..64)).prop_map(
        |(perm, flip, off)| {
            let perms = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
            let offset = DVec3::new(off[0] as f64 * 0.25, off[1] as f64 * 0.25, off[2] as f64 * 0.25);
            Placement::Exact { axes: perms[perm], flip, offset }
        },
    );
    let rotated = (-3.2f64..3.2, -1.6f64..1.6, -3.2f64..3.2, prop::array::uniform3(-200.0f64..200.0)).prop_map(
        |(a, b, c, off)| Placement::Rotated {
            rotation: DMat3::from_euler(glam::EulerRot::ZYX, a, b, c),
            offset: DVec3::from_array(off),
        },
    );
    prop_oneof![exact, rotated]
}

fn place(shape: &(Vec<DVec2>, Vec<Vec<DVec2>>), placement: &Placement, reverse: bool) -> SheetFace {
    let map = |ring: &[DVec2]| {
        let mut r: Vec<DVec3> = ring.iter().map(|p| placement.apply(*p, 0.0)).collect();
        if reverse {
            r.reverse();
        }
        r
    };
    SheetFace { outline: map(&shape.0), holes: shape.1.iter().map(|h| map(h)).collect() }
}

fn check_random_face(shape: (Vec<DVec2>, Vec<Vec<DVec2>>), placement: Placement, reverse: bool, thickness: f64) {
    let face = place(&shape, &placement, reverse);
    let model = SheetMetal { thickness, faces: vec![face.clone()] };
    model.validate().expect("generated faces are valid");
    let triangles = check_model(&model, Decomposition::Triangulation)[0];
    let merged = check_model(&model, Decomposition::ConvexMerge)[0];
    assert!(merged <= triangles, "merging gave {merged} pieces from {triangles} triangles");
    // the boundary of a single extruded face: two caps and the side walls along every ring; cuts are internal
    let expected = 2.0 * face_area(&face) + thickness * perimeter(&face);
    for d in [Decomposition::Triangulation, Decomposition::ConvexMerge] {
        let part = model.build_part("random", 1.0, d).expect("part");
        let got = boundary_area(&part);
        assert!((got - expected).abs() <= 1e-9 * expected, "{d:?}: boundary area {got} vs {expected}");
    }
    if let Placement::Exact { .. } = placement {
        // exact coordinates: the triangulation has n + 2h - 2 triangles unless the face is convex without holes, where
        // n counts the vertices that are not straight (straight vertices of collinear runs are removed first)
        let corners = |r: &[DVec3]| {
            let r = distinct(r);
            let m = r.len();
            (0..m).filter(|&i| !collinear(r[(i + m - 1) % m], r[i], r[(i + 1) % m])).count()
        };
        let n = corners(&face.outline) + face.holes.iter().map(|h| corners(h)).sum::<usize>();
        // Hertel-Mehlhorn bound: at most 2r + 1 pieces for r reflex vertices of the domain (hole corners count as
        // reflex when the hole turns convexly); exact here since the coordinates are dyadic
        let reflex = |r: &[DVec3], outer: bool| {
            let r = distinct(r);
            let m = r.len();
            let normal = newell_normal(r.iter().copied());
            (0..m)
                .filter(|&i| {
                    let turn = (r[i] - r[(i + m - 1) % m]).cross(r[(i + 1) % m] - r[i]).dot(normal);
                    if outer { turn < 0.0 } else { turn > 0.0 }
                })
                .count()
        };
        let r = reflex(&face.outline, true) + face.holes.iter().map(|h| reflex(h, false)).sum::<usize>();
        assert!(merged <= 2 * r + 1, "Hertel-Mehlhorn gave {merged} pieces with {r} reflex vertices");
        let h = face.holes.len();
        if triangles != 1 {
            assert_eq!(triangles, n + 2 * h - 2);
        } else {
            assert!(h == 0);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::default())]

    #[test]
    fn random_histogram_polygons(shape in histogram_face(), placement in placement(), reverse: bool,
                                 thickness in 0.5f64..4.0) {
        check_random_face(shape, placement, reverse, thickness);
    }

    #[test]
    fn random_star_polygons(shape in star_face(), placement in placement(), reverse: bool, thickness in 0.5f64..4.0) {
        check_random_face(shape, placement, reverse, thickness);
    }
}

// ---------------------------------------------------------------- errors

fn square(z: f64) -> Vec<DVec3> {
    vec![DVec3::new(0.0, 0.0, z), DVec3::new(10.0, 0.0, z), DVec3::new(10.0, 10.0, z), DVec3::new(0.0, 10.0, z)]
}

fn hole(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<DVec3> {
    vec![DVec3::new(x0, y0, 0.0), DVec3::new(x0, y1, 0.0), DVec3::new(x1, y1, 0.0), DVec3::new(x1, y0, 0.0)]
}

fn model(faces: Vec<SheetFace>) -> SheetMetal {
    SheetMetal { thickness: 2.0, faces }
}

fn err(m: &SheetMetal) -> SheetMetalError {
    let e = m.validate().expect_err("invalid model");
    // build_part reports the same error, never panics
    // (compared as text: NaN thicknesses are not equal to themselves)
    assert_eq!(m.build_part("x", 1.0, Decomposition::ConvexMerge).expect_err("invalid").to_string(), e.to_string());
    assert_eq!(m.build_part("x", 1.0, Decomposition::Triangulation).expect_err("invalid").to_string(), e.to_string());
    e
}

#[test]
fn error_thickness_and_empty() {
    let good = SheetFace { outline: square(0.0), holes: vec![] };
    for t in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let m = SheetMetal { thickness: t, faces: vec![good.clone()] };
        assert!(matches!(err(&m), SheetMetalError::BadThickness(_)));
    }
    assert_eq!(err(&model(vec![])), SheetMetalError::NoFaces);
}

#[test]
fn error_non_finite() {
    let mut outline = square(0.0);
    outline[2].y = f64::NAN;
    let m = model(vec![SheetFace { outline: square(0.0), holes: vec![] }, SheetFace { outline, holes: vec![] }]);
    assert_eq!(err(&m), SheetMetalError::NonFinite { face: 1, ring: Ring::Outline, vertex: 2 });
    let mut h = hole(2.0, 2.0, 4.0, 4.0);
    h[3].z = f64::NEG_INFINITY;
    let m = model(vec![SheetFace { outline: square(0.0), holes: vec![hole(6.0, 6.0, 8.0, 8.0), h] }]);
    assert_eq!(err(&m), SheetMetalError::NonFinite { face: 0, ring: Ring::Hole(1), vertex: 3 });
}

#[test]
fn error_too_few_vertices() {
    let p = DVec3::new(1.0, 2.0, 3.0);
    let q = DVec3::new(4.0, 2.0, 3.0);
    let m = model(vec![SheetFace { outline: vec![p, q, q, p], holes: vec![] }]);
    assert_eq!(err(&m), SheetMetalError::TooFewVertices { face: 0, ring: Ring::Outline, count: 2 });
    let m = model(vec![SheetFace { outline: vec![], holes: vec![] }]);
    assert_eq!(err(&m), SheetMetalError::TooFewVertices { face: 0, ring: Ring::Outline, count: 0 });
    let m = model(vec![SheetFace { outline: square(0.0), holes: vec![vec![DVec3::new(5.0, 5.0, 0.0)]] }]);
    assert_eq!(err(&m), SheetMetalError::TooFewVertices { face: 0, ring: Ring::Hole(0), count: 1 });
}

#[test]
fn error_zero_area() {
    let line = vec![DVec3::ZERO, DVec3::new(1.0, 1.0, 1.0), DVec3::new(3.0, 3.0, 3.0)];
    let m = model(vec![SheetFace { outline: line, holes: vec![] }]);
    assert_eq!(err(&m), SheetMetalError::ZeroArea { face: 0, ring: Ring::Outline });
    let flat_hole = vec![DVec3::new(2.0, 2.0, 0.0), DVec3::new(3.0, 3.0, 0.0), DVec3::new(4.0, 4.0, 0.0)];
    let m = model(vec![SheetFace { outline: square(0.0), holes: vec![flat_hole] }]);
    assert_eq!(err(&m), SheetMetalError::ZeroArea { face: 0, ring: Ring::Hole(0) });
}

#[test]
fn error_non_planar_and_tolerance() {
    let mut outline = square(0.0);
    outline.insert(2, DVec3::new(10.0, 5.0, 0.5));
    let m = model(vec![SheetFace { outline, holes: vec![] }]);
    match err(&m) {
        SheetMetalError::NonPlanar { face: 0, ring: Ring::Outline, vertex: _, distance, tolerance } => {
            assert!(distance.abs() > tolerance && tolerance > 0.0);
        }
        e => panic!("unexpected {e}"),
    }
    // a hole lifted off the plane
    let mut h = hole(2.0, 2.0, 4.0, 4.0);
    for p in &mut h {
        p.z = 0.01;
    }
    let m = model(vec![SheetFace { outline: square(0.0), holes: vec![h] }]);
    assert!(matches!(err(&m), SheetMetalError::NonPlanar { face: 0, ring: Ring::Hole(0), .. }));
    // deviations far below the documented tolerance (1e-6 x face diagonal) are accepted
    let mut outline = square(0.0);
    outline[1].z = 1e-9;
    let m = model(vec![SheetFace { outline, holes: vec![] }]);
    m.validate().expect("nearly planar face accepted");
    m.build_part("x", 1.0, Decomposition::ConvexMerge).expect("part");
}

#[test]
fn error_self_intersecting() {
    let bowtie = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(10.0, 10.0, 0.0),
        DVec3::new(10.0, 0.0, 0.0),
        DVec3::new(0.0, 10.0, 0.0),
    ];
    let m = model(vec![SheetFace { outline: bowtie, holes: vec![] }]);
    // a symmetric bow tie has zero vector area; an asymmetric one is caught as self-intersecting
    assert_eq!(err(&m), SheetMetalError::ZeroArea { face: 0, ring: Ring::Outline });
    let bowtie = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(10.0, 10.0, 0.0),
        DVec3::new(10.0, 0.0, 0.0),
        DVec3::new(0.0, 4.0, 0.0),
    ];
    let m = model(vec![SheetFace { outline: bowtie, holes: vec![] }]);
    assert_eq!(err(&m), SheetMetalError::SelfIntersecting { face: 0, ring: Ring::Outline, edge_a: 0, edge_b: 2 });
    let twisted_hole = vec![
        DVec3::new(2.0, 2.0, 0.0),
        DVec3::new(6.0, 6.0, 0.0),
        DVec3::new(6.0, 2.0, 0.0),
        DVec3::new(2.0, 3.0, 0.0),
    ];
    let m = model(vec![SheetFace { outline: square(0.0), holes: vec![twisted_hole] }]);
    assert!(matches!(err(&m), SheetMetalError::SelfIntersecting { face: 0, ring: Ring::Hole(0), .. }));
    // indices refer to the input, before duplicates are removed
    let mut outline = vec![DVec3::ZERO, DVec3::ZERO];
    outline.extend([DVec3::new(10.0, 10.0, 0.0), DVec3::new(10.0, 0.0, 0.0), DVec3::new(0.0, 4.0, 0.0)]);
    let m = model(vec![SheetFace { outline, holes: vec![] }]);
    assert_eq!(err(&m), SheetMetalError::SelfIntersecting { face: 0, ring: Ring::Outline, edge_a: 0, edge_b: 3 });
}

#[test]
fn error_holes_outside_touching_overlapping() {
    let face = |holes| model(vec![SheetFace { outline: square(0.0), holes }]);
    assert_eq!(err(&face(vec![hole(12.0, 2.0, 14.0, 4.0)])), SheetMetalError::HoleNotInside { face: 0, hole: 0 });
    assert_eq!(err(&face(vec![hole(0.0, 2.0, 4.0, 4.0)])), SheetMetalError::HoleNotInside { face: 0, hole: 0 });
    assert_eq!(err(&face(vec![hole(8.0, 2.0, 12.0, 4.0)])), SheetMetalError::HoleNotInside { face: 0, hole: 0 });
    assert_eq!(
        err(&face(vec![hole(1.0, 1.0, 2.0, 2.0), hole(2.0, 2.0, 4.0, 4.0)])),
        SheetMetalError::HolesOverlap { face: 0, hole_a: 0, hole_b: 1 }
    );
    assert_eq!(
        err(&face(vec![hole(1.0, 1.0, 8.0, 8.0), hole(2.0, 2.0, 4.0, 4.0)])),
        SheetMetalError::HolesOverlap { face: 0, hole_a: 0, hole_b: 1 }
    );
    assert_eq!(
        err(&face(vec![hole(1.0, 1.0, 3.0, 3.0), hole(5.0, 5.0, 6.0, 6.0), hole(2.0, 2.0, 5.5, 5.5)])),
        SheetMetalError::HolesOverlap { face: 0, hole_a: 0, hole_b: 2 }
    );
    // the hole is the outline: touching everywhere
    let m = model(vec![SheetFace { outline: square(0.0), holes: vec![square(0.0)] }]);
    assert_eq!(err(&m), SheetMetalError::HoleNotInside { face: 0, hole: 0 });
}

#[test]
fn error_no_such_face() {
    let m = model(vec![SheetFace { outline: square(0.0), holes: vec![] }]);
    assert_eq!(
        m.decompose_face(3, Decomposition::ConvexMerge).expect_err("no face 3"),
        SheetMetalError::NoSuchFace { face: 3, count: 1 }
    );
    assert_eq!(m.decompose_face(0, Decomposition::ConvexMerge).expect("face 0").pieces.len(), 1);
}

#[test]
fn error_bad_density_is_reported() {
    let m = model(vec![SheetFace { outline: square(0.0), holes: vec![] }]);
    assert!(matches!(m.build_part("x", -1.0, Decomposition::ConvexMerge), Err(SheetMetalError::Part(_))));
}

#[test]
fn error_messages_name_the_place() {
    let e = SheetMetalError::NonFinite { face: 3, ring: Ring::Hole(2), vertex: 7 };
    assert_eq!(e.to_string(), "face 3, hole 2, vertex 7: coordinate is not finite");
    let e = SheetMetalError::HolesOverlap { face: 1, hole_a: 0, hole_b: 4 };
    assert_eq!(e.to_string(), "face 1: holes 0 and 4 overlap or touch");
}

#[test]
fn orientation_and_duplicates_do_not_matter() {
    // the same L-shaped face given clockwise, counter-clockwise, with duplicated points and with a closing point
    let l = vec![
        DVec3::new(0.0, 0.0, 5.0),
        DVec3::new(40.0, 0.0, 5.0),
        DVec3::new(40.0, 20.0, 5.0),
        DVec3::new(20.0, 20.0, 5.0),
        DVec3::new(20.0, 40.0, 5.0),
        DVec3::new(0.0, 40.0, 5.0),
    ];
    let mut variants = vec![l.clone()];
    let mut rev = l.clone();
    rev.reverse();
    variants.push(rev);
    let mut dup = l.clone();
    dup.insert(3, dup[3]);
    dup.push(dup[0]);
    variants.push(dup);
    for outline in variants {
        let m = model(vec![SheetFace { outline, holes: vec![] }]);
        let counts = check_model(&m, Decomposition::Triangulation);
        assert_eq!(counts, vec![4]);
        assert_eq!(check_model(&m, Decomposition::ConvexMerge), vec![2]);
        let part = m.build_part("l", 1.0, Decomposition::ConvexMerge).expect("part");
        assert!((part.mass().volume - 2.0 * 1200.0).abs() < 1e-9);
        assert!((part.mass().center_of_gravity.z - 5.0).abs() < 1e-12);
    }
}

#[test]
fn serde_shape() {
    let m = model(vec![SheetFace { outline: square(0.0), holes: vec![hole(2.0, 2.0, 4.0, 4.0)] }]);
    let json = serde_json::to_value(&m).expect("json");
    assert_eq!(json["thickness"], 2.0);
    assert_eq!(json["faces"][0]["outline"][1], serde_json::json!([10.0, 0.0, 0.0]));
    assert_eq!(json["faces"][0]["holes"][0][2], serde_json::json!([4.0, 4.0, 0.0]));
    let back: SheetMetal =
        serde_json::from_str(r#"{"thickness": 1.5, "faces": [{"outline": [[0,0,0],[1,0,0],[0,1,0]]}]}"#)
            .expect("parse");
    assert!(back.faces[0].holes.is_empty());
}
