//! Obstacles of pairs rotated about `z` by angles around the angular tolerance: the exactly-defined behaviour of the
//! merged faces (faces whose normals are within `tol / 2` are one face; edges within `tol / 2` of parallel in such a
//! face are one edge), checked against the generic structure of a small but clearly non-degenerate angle.

use glam::{DMat3, DVec3};
use stackplan_cspace::minkowski::{ANGULAR_TOLERANCE, FaceKind, Obstacle, Route, gauss_map_obstacle, obstacle_by_hull};
use stackplan_geom::ConvexPolytope;

use crate::common;

fn cuboid(hi: DVec3) -> ConvexPolytope {
    common::cuboid(DVec3::ZERO, hi)
}

/// The benchmarks' sheet-metal piece: a convex hexagon (scaled) extruded by 2 mm.
fn hexagon_prism(scale: f64) -> ConvexPolytope {
    let outline = [(0.0, 0.0), (60.0, 0.0), (90.0, 30.0), (80.0, 70.0), (20.0, 80.0), (-10.0, 40.0)];
    let scaled: Vec<(f64, f64)> = outline.iter().map(|&(x, y)| (x * scale, y * scale)).collect();
    common::prism(&scaled, 0.0, 2.0, 2).expect("prism")
}

fn check_provenance(a: &ConvexPolytope, r: DMat3, b: &ConvexPolytope, o: &Obstacle) {
    for (v, &[i, j]) in o.vertex_pairs().iter().enumerate() {
        assert_eq!(o.polytope().vertices()[v], b.vertices()[j] - r * a.vertices()[i]);
    }
    let h = obstacle_by_hull(a, r, b).expect("hull");
    let (vo, vh) = (o.polytope().volume(), h.polytope().volume());
    assert!((vo - vh).abs() <= 1e-8 * vh, "volume {vo} vs hull {vh}");
}

#[test]
fn below_half_the_tolerance_faces_and_edges_merge() {
    let pairs = [
        (cuboid(DVec3::new(100.0, 50.0, 2.0)), cuboid(DVec3::new(80.0, 60.0, 2.0))),
        (hexagon_prism(1.0), hexagon_prism(1.0)),
    ];
    for (a, b) in &pairs {
        let aligned = gauss_map_obstacle(a, DMat3::IDENTITY, b).expect("aligned");
        if a.faces().len() == 6 {
            // boxes: every face of the sum is a pair of parallel faces (a box)
            assert!(aligned.face_kinds().iter().all(|k| matches!(k, FaceKind::FaceFace { .. })));
            assert_eq!(aligned.polytope().vertices().len(), 8);
        }
        for factor in [1e-6, 0.1, 0.3, 0.45] {
            let t = factor * ANGULAR_TOLERANCE;
            for theta in [t, -t] {
                let r = DMat3::from_rotation_z(theta);
                let o = gauss_map_obstacle(a, r, b).unwrap_or_else(|e| panic!("theta {theta}: {e}"));
                assert_eq!(o.route(), Route::GaussMap);
                // the faces of the aligned pair: the same merged faces with the same corners
                assert_eq!(o.structure(), aligned.structure(), "theta {theta}");
                check_provenance(a, r, b, &o);
            }
        }
    }
}

#[test]
fn above_half_the_tolerance_the_structure_is_the_generic_one() {
    let pairs = [
        (cuboid(DVec3::new(100.0, 50.0, 2.0)), cuboid(DVec3::new(80.0, 60.0, 2.0))),
        (hexagon_prism(1.0), hexagon_prism(1.0)),
        (hexagon_prism(1.0), hexagon_prism(0.7)),
    ];
    for (a, b) in &pairs {
        for sign in [1.0, -1.0] {
            // the structure of a clearly generic small angle: only the horizontal faces merge
            let generic = gauss_map_obstacle(a, DMat3::from_rotation_z(sign * 1e-4), b).expect("generic");
            generic.polytope().validate().expect("valid");
            for factor in [0.55, 0.8, 1.0, 1.5, 3.0, 10.0, 100.0] {
                let theta = sign * factor * ANGULAR_TOLERANCE;
                let r = DMat3::from_rotation_z(theta);
                let o = gauss_map_obstacle(a, r, b).unwrap_or_else(|e| panic!("theta {theta}: {e}"));
                // the vertical faces are not merged and neither are the edges of the horizontal faces: the sum keeps
                // its short edges (length ~ theta * size) and the corners between them
                assert_eq!(o.structure(), generic.structure(), "theta {theta}");
                check_provenance(a, r, b, &o);
            }
        }
    }
}
