//! `ConvexPolytope::from_faces_and_edges` (an edge table built by the caller) gives exactly the polytope of
//! `from_faces_with_area` when the table is the one geom builds, and builds the table itself when the caller's does
//! not fit the faces.

use proptest::prelude::*;
use stackplan_geom::{ConvexPolytope, DVec3, convex_hull};

fn grid_cloud() -> impl Strategy<Value = ConvexPolytope> {
    prop::collection::vec((-8i32..=8, -8i32..=8, -8i32..=8), 4..30).prop_filter_map("flat cloud", |v| {
        let pts: Vec<DVec3> = v.into_iter().map(|(a, b, c)| DVec3::new(a as f64, b as f64, c as f64) * 0.25).collect();
        convex_hull(&pts).ok().map(|h| h.polytope)
    })
}

/// The polytope's own edge table in the constructor's input form.
fn table(p: &ConvexPolytope) -> (Vec<stackplan_geom::Edge>, Vec<usize>) {
    let flat = (0..p.faces().len()).flat_map(|f| p.face_edges(f).to_vec()).collect();
    (p.edges().to_vec(), flat)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn equals_from_faces_with_area(p in grid_cloud()) {
        let (edges, face_edges) = table(&p);
        let q = ConvexPolytope::from_faces_and_edges(p.vertices().to_vec(), p.faces().to_vec(), edges, face_edges)
            .expect("valid table");
        let r = ConvexPolytope::from_faces_with_area(p.vertices().to_vec(), p.faces().to_vec()).expect("valid faces");
        prop_assert_eq!(format!("{q:?}"), format!("{r:?}"));
        prop_assert_eq!(&q, &p);
    }
}

#[test]
fn a_table_of_the_wrong_length_is_rebuilt() {
    let c = ConvexPolytope::cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)).expect("box");
    let (edges, mut face_edges) = table(&c);
    face_edges.pop();
    let q = ConvexPolytope::from_faces_and_edges(c.vertices().to_vec(), c.faces().to_vec(), edges.clone(), face_edges)
        .expect("rebuilt");
    assert_eq!(q, c);
    // and then the manifold check applies: a box without its top is rejected
    let mut open = c.faces().to_vec();
    open.pop();
    assert!(ConvexPolytope::from_faces_and_edges(c.vertices().to_vec(), open, edges, Vec::new()).is_err());
}

#[test]
fn non_finite_vertices_are_rejected() {
    let c = ConvexPolytope::cuboid(DVec3::ZERO, DVec3::ONE).expect("box");
    let (edges, face_edges) = table(&c);
    let mut vertices = c.vertices().to_vec();
    vertices[3].y = f64::NAN;
    assert!(ConvexPolytope::from_faces_and_edges(vertices, c.faces().to_vec(), edges, face_edges).is_err());
}
