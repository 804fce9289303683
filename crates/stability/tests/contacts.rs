//! Contact patches and interference depths against analytic values.

use crate::common;
use stackplan_geom::Pose;

use common::{at, box_part, cuboid};
use glam::{DMat3, DVec2, DVec3};
use proptest::prelude::*;
use stackplan_geom::{Part, PartOrigin, convex_hull};
use stackplan_stability::contacts::{Body, PatchKind, analyse_contacts};
use stackplan_stability::polygon2d::{area, convex_hull_2d};
use stackplan_stability::world::{PlacedPart, world_stack};

fn analyse(stack: &[PlacedPart<'_>]) -> stackplan_stability::ContactAnalysis {
    let parts = world_stack(stack).expect("world");
    analyse_contacts(&parts, 1e-9, |_| true)
}

fn xy_area(points: &[DVec3]) -> f64 {
    area(&convex_hull_2d(&points.iter().map(|p| DVec2::new(p.x, p.y)).collect::<Vec<_>>(), 1e-12))
}

fn hull_part(name: &str, pts: &[DVec3]) -> Part {
    let hull = convex_hull(pts).expect("hull").polytope;
    Part::from_components(name, vec![hull], 1.0, PartOrigin::ConvexPieces).expect("part")
}

#[test]
fn face_on_face_gives_the_overlap_polygon() {
    let a = box_part("a", DVec3::new(10.0, 10.0, 2.0));
    let b = box_part("b", DVec3::new(10.0, 5.0, 2.0));
    let c = analyse(&[at(&a, DVec3::ZERO), at(&b, DVec3::new(4.0, 3.0, 2.0))]);
    assert!(c.interferences.is_empty());
    let floor: Vec<_> = c.patches.iter().filter(|p| p.a == Body::Floor).collect();
    assert_eq!(floor.len(), 1);
    assert!((xy_area(&floor[0].points) - 100.0).abs() < 1e-9);
    let ab: Vec<_> = c.patches.iter().filter(|p| p.a == Body::Part(0)).collect();
    assert_eq!(ab.len(), 1);
    assert_eq!(ab[0].kind, PatchKind::Polygon);
    assert!((ab[0].normal - DVec3::Z).length() < 1e-12);
    assert!((xy_area(&ab[0].points) - 30.0).abs() < 1e-9, "{:?}", ab[0].points);
    assert!(ab[0].points.iter().all(|p| (p.z - 2.0).abs() < 1e-12));
}

#[test]
fn side_by_side_boxes_touch_on_a_vertical_face() {
    let a = box_part("a", DVec3::new(10.0, 10.0, 10.0));
    let c = analyse(&[at(&a, DVec3::ZERO), at(&a, DVec3::new(10.0, 5.0, 0.0))]);
    let ab: Vec<_> = c.patches.iter().filter(|p| p.a == Body::Part(0)).collect();
    assert_eq!(ab.len(), 1);
    assert!((ab[0].normal - DVec3::X).length() < 1e-12);
    assert_eq!(ab[0].points.len(), 4);
    let ys: Vec<f64> = ab[0].points.iter().map(|p| p.y).collect();
    assert!(ys.iter().all(|&y| (5.0 - 1e-9..=10.0 + 1e-9).contains(&y)));
}

#[test]
fn edge_on_face_gives_a_segment() {
    let a = box_part("a", DVec3::new(20.0, 20.0, 2.0));
    // a cube standing on one edge (rotated 45 degrees about x), edge along x at height 2
    let cube = box_part("cube", DVec3::splat(4.0));
    let r = DMat3::from_rotation_x(std::f64::consts::FRAC_PI_4);
    let c = analyse(&[
        at(&a, DVec3::ZERO),
        PlacedPart { part: &cube, pose: Pose { rotation: r, position: DVec3::new(5.0, 10.0, 2.0) } },
    ]);
    let ab: Vec<_> = c.patches.iter().filter(|p| p.a == Body::Part(0)).collect();
    assert_eq!(ab.len(), 1, "{c:?}");
    assert_eq!(ab[0].kind, PatchKind::Segment);
    let len = (ab[0].points[0] - ab[0].points[1]).length();
    assert!((len - 4.0).abs() < 1e-9);
    assert!((ab[0].normal - DVec3::Z).length() < 1e-9);
}

#[test]
fn crossing_ridges_give_a_point_and_vertex_on_face_too() {
    let l = 5.0;
    let ridge_x = hull_part(
        "rx",
        &[-1.0f64, 1.0]
            .iter()
            .flat_map(|&s| [DVec3::new(s * l, -1.0, 0.0), DVec3::new(s * l, 1.0, 0.0), DVec3::new(s * l, 0.0, 1.0)])
            .collect::<Vec<_>>(),
    );
    let ridge_y = hull_part(
        "ry",
        &[-1.0f64, 1.0]
            .iter()
            .flat_map(|&s| [DVec3::new(-1.0, s * l, 2.0), DVec3::new(1.0, s * l, 2.0), DVec3::new(0.0, s * l, 1.0)])
            .collect::<Vec<_>>(),
    );
    let c = analyse(&[at(&ridge_x, DVec3::ZERO), at(&ridge_y, DVec3::ZERO)]);
    let ab: Vec<_> = c.patches.iter().filter(|p| p.a == Body::Part(0)).collect();
    assert_eq!(ab.len(), 1);
    assert_eq!(ab[0].kind, PatchKind::Point);
    assert!((ab[0].points[0] - DVec3::new(0.0, 0.0, 1.0)).length() < 1e-9);
    assert!(ab[0].normal.z > 0.99);
    // an upside-down pyramid with its apex on a box
    let base = box_part("base", DVec3::new(10.0, 10.0, 2.0));
    let pyramid = hull_part(
        "pyr",
        &[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(-2.0, -2.0, 3.0),
            DVec3::new(2.0, -2.0, 3.0),
            DVec3::new(2.0, 2.0, 3.0),
            DVec3::new(-2.0, 2.0, 3.0),
        ],
    );
    let c = analyse(&[at(&base, DVec3::ZERO), at(&pyramid, DVec3::new(5.0, 5.0, 2.0))]);
    let ab: Vec<_> = c.patches.iter().filter(|p| p.a == Body::Part(0)).collect();
    assert_eq!(ab.len(), 1);
    assert_eq!(ab[0].kind, PatchKind::Point);
    assert!((ab[0].points[0] - DVec3::new(5.0, 5.0, 2.0)).length() < 1e-9);
    assert!((ab[0].normal - DVec3::Z).length() < 1e-9);
}

#[test]
fn floor_penetration_and_part_penetration_depths() {
    let a = box_part("a", DVec3::splat(10.0));
    let c = analyse(&[at(&a, DVec3::new(0.0, 0.0, -0.5)), at(&a, DVec3::new(8.0, 3.0, -0.5))]);
    let floor_depths: Vec<f64> = c.interferences.iter().filter(|x| x.a == Body::Floor).map(|x| x.depth).collect();
    assert_eq!(floor_depths.len(), 2);
    assert!(floor_depths.iter().all(|d| (d - 0.5).abs() < 1e-12));
    let ab: Vec<f64> = c.interferences.iter().filter(|x| x.a == Body::Part(0)).map(|x| x.depth).collect();
    assert_eq!(ab.len(), 1);
    assert!((ab[0] - 2.0).abs() < 1e-12);
}

#[test]
fn decomposed_part_on_floor_has_a_patch_per_component() {
    let l = common::boxes_part(
        "L",
        &[(DVec3::ZERO, DVec3::new(10.0, 4.0, 2.0)), (DVec3::new(0.0, 4.0, 0.0), DVec3::new(4.0, 10.0, 2.0))],
    );
    let c = analyse(&[at(&l, DVec3::ZERO)]);
    assert_eq!(c.patches.len(), 2);
    let total: f64 = c.patches.iter().map(|p| xy_area(&p.points)).sum();
    assert!((total - 64.0).abs() < 1e-9);
    let _ = cuboid(DVec3::ZERO, DVec3::ONE);
}

proptest! {
    /// Axis-aligned boxes placed at random: the penetration depth is the smallest overlap width, the contact patch of
    /// a box set on top of another is the overlap rectangle.
    #[test]
    fn random_boxes_match_closed_forms(
        sa in (1.0f64..20.0, 1.0f64..20.0, 1.0f64..20.0),
        sb in (1.0f64..20.0, 1.0f64..20.0, 1.0f64..20.0),
        p in (-20.0f64..20.0, -20.0f64..20.0, -20.0f64..20.0),
    ) {
        let a = box_part("a", DVec3::new(sa.0, sa.1, sa.2));
        let b = box_part("b", DVec3::new(sb.0, sb.1, sb.2));
        let lift = DVec3::new(0.0, 0.0, 30.0);
        let pb = DVec3::new(p.0, p.1, p.2) + lift;
        let c = analyse(&[at(&a, lift), at(&b, pb)]);
        let overlap = |lo_a: f64, hi_a: f64, lo_b: f64, hi_b: f64| hi_a.min(hi_b) - lo_a.max(lo_b);
        let ox = overlap(0.0, sa.0, p.0, p.0 + sb.0);
        let oy = overlap(0.0, sa.1, p.1, p.1 + sb.1);
        let oz = overlap(0.0, sa.2, p.2, p.2 + sb.2);
        // the minimum translation along an axis pushes b out on the nearer side
        let push = |lo_a: f64, hi_a: f64, lo_b: f64, hi_b: f64| (hi_a - lo_b).min(hi_b - lo_a);
        let depth = push(0.0, sa.0, p.0, p.0 + sb.0).min(push(0.0, sa.1, p.1, p.1 + sb.1)).min(push(0.0, sa.2, p.2, p.2 + sb.2));
        let found: Vec<f64> = c.interferences.iter().map(|x| x.depth).collect();
        if ox > 1e-6 && oy > 1e-6 && oz > 1e-6 {
            prop_assert_eq!(found.len(), 1);
            prop_assert!((found[0] - depth).abs() < 1e-9, "{} vs {}", found[0], depth);
        } else if ox < -1e-6 || oy < -1e-6 || oz < -1e-6 {
            prop_assert!(found.is_empty() && c.patches.is_empty());
        }
        // now set b exactly on top of a
        let pb = DVec3::new(p.0, p.1, sa.2) + lift;
        let c = analyse(&[at(&a, lift), at(&b, pb)]);
        prop_assert!(c.interferences.is_empty());
        if ox > 1e-6 && oy > 1e-6 {
            prop_assert_eq!(c.patches.len(), 1);
            prop_assert!((xy_area(&c.patches[0].points) - ox * oy).abs() < 1e-8 * (1.0 + ox * oy));
            prop_assert!((c.patches[0].normal - DVec3::Z).length() < 1e-12);
        } else if ox < -1e-6 || oy < -1e-6 {
            prop_assert!(c.patches.is_empty());
        }
    }
}

/// A part lying across the seam of two coplanar tops of one part below: an L-corner standing on its edge (rest pose
/// 1 of the planner, its foot along +y) put on the top of another in the same pose, as the 15-part L-corner plan at
/// w = 0.9 placed its ninth part. Each of the upper part's components touches the lower part's other component along
/// the seam line only, where a horizontal and the vertical axis separate them equally. Those contacts are vertical
/// (`contacts::contact_axis`) at every quarter turn of the pair about z (which reorders the faces the test meets
/// first), and the part, whose centre of gravity lies beyond its supports, is unstable. With the first tied axis
/// as the normal, two opposite sideways contacts on the seam line pinched it and held it by friction ("stable"),
/// and `stackplan check` on the plan's file, whose re-hulled pieces list their faces in another order, disagreed
/// with the planner.
#[test]
fn seam_contacts_are_vertical_and_do_not_pinch() {
    use stackplan_geom::examples::part_by_name;
    use stackplan_geom::sheet_metal::Decomposition;
    use stackplan_stability::check::{CheckOptions, check_stack};
    let part = part_by_name("l-corner", Decomposition::ConvexMerge).expect("example");
    let rows = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
    let rest = DMat3::from_cols_array_2d(&rows).transpose();
    for quarter in 0..4 {
        let turn = DMat3::from_rotation_z(f64::from(quarter) * std::f64::consts::FRAC_PI_2);
        let stack = [
            PlacedPart {
                part: &part,
                pose: Pose { rotation: turn * rest, position: turn * DVec3::new(0.0, 65.0, 60.0) },
            },
            PlacedPart {
                part: &part,
                pose: Pose { rotation: turn * rest, position: turn * DVec3::new(-75.0, 65.0, 210.0) },
            },
        ];
        let analysis = analyse(&stack);
        let between: Vec<_> = analysis.patches.iter().filter(|p| p.a == Body::Part(0) && p.b == 1).collect();
        assert!(between.len() >= 3, "quarter {quarter}: {between:?}");
        for p in &between {
            assert!(p.normal.z > 1.0 - 1e-9, "quarter {quarter}: a sideways contact {p:?}");
        }
        let check = check_stack(&stack, &CheckOptions::default()).expect("check");
        assert!(!check.parts[1].stable.is_stable(), "quarter {quarter}: the part across the seam held by a pinch");
    }
}
