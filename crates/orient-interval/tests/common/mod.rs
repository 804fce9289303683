//! Shared generators for the property tests: random convex polytopes (hulls of dyadic points), boxes, prisms with
//! shared face directions (sheet-metal-like: horizontal caps, vertical sides), and example-part components.
#![allow(dead_code)]

use proptest::prelude::*;
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_geom::{ConvexPolytope, DMat3, DVec3, convex_hull, examples};

pub fn cases() -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(64)
}

fn dyadic(range: i32) -> impl Strategy<Value = f64> {
    (-range..=range).prop_map(|k| k as f64 / 4.0)
}

/// Hull of 5-10 random dyadic points (rejected if flat).
pub fn random_hull() -> impl Strategy<Value = ConvexPolytope> {
    prop::collection::vec((dyadic(12), dyadic(12), dyadic(12)), 5..10).prop_filter_map("flat", |pts| {
        let pts: Vec<DVec3> = pts.into_iter().map(|(x, y, z)| DVec3::new(x, y, z)).collect();
        convex_hull(&pts).ok().map(|h| h.polytope)
    })
}

pub fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
    ConvexPolytope::cuboid(lo, hi).expect("box")
}

/// Axis-aligned box with dyadic corners.
pub fn random_box() -> impl Strategy<Value = ConvexPolytope> {
    ((dyadic(8), dyadic(8), dyadic(8)), (1..=12i32, 1..=12i32, 1..=12i32)).prop_map(|((x, y, z), (a, b, c))| {
        let lo = DVec3::new(x, y, z);
        cuboid(lo, lo + DVec3::new(a as f64 / 2.0, b as f64 / 2.0, c as f64 / 2.0))
    })
}

/// Directions shared by the prisms: multiples of 45 degrees (exact for 0/90/180/270, rounded for the diagonals,
/// which are given with exact dyadic components (1, 1)).
const DIRS: [(f64, f64); 8] =
    [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0), (-1.0, -1.0), (0.0, -1.0), (1.0, -1.0)];

/// A convex prism (horizontal caps, vertical sides) whose side normals are drawn from the shared 8 directions:
/// the polygon is the intersection of half-planes `d_k . x <= r_k` for a random subset of the directions (at least
/// the 4 axis ones, so it is bounded), built as the hull of its corners extruded between two heights.
pub fn random_prism() -> impl Strategy<Value = ConvexPolytope> {
    (prop::collection::vec(2..=8i32, 8), prop::collection::vec(any::<bool>(), 4), dyadic(8), 1..=8i32).prop_filter_map(
        "degenerate prism",
        |(radii, diag, z0, h)| {
            let mut lines: Vec<(DVec3, f64)> = Vec::new();
            for (k, &(dx, dy)) in DIRS.iter().enumerate() {
                if k % 2 == 1 && !diag[k / 2] {
                    continue;
                }
                let r = radii[k] as f64 * if k % 2 == 1 { 1.5 } else { 1.0 };
                lines.push((DVec3::new(dx, dy, 0.0), r));
            }
            // corners: intersections of consecutive lines that satisfy all constraints
            let mut corners = Vec::new();
            for a in 0..lines.len() {
                for b in a + 1..lines.len() {
                    let (n1, r1) = lines[a];
                    let (n2, r2) = lines[b];
                    let det = n1.x * n2.y - n1.y * n2.x;
                    if det == 0.0 {
                        continue;
                    }
                    let x = (r1 * n2.y - r2 * n1.y) / det;
                    let y = (n1.x * r2 - n2.x * r1) / det;
                    let p = DVec3::new(x, y, 0.0);
                    if lines.iter().all(|(n, r)| n.dot(p) <= *r + 1e-12) {
                        corners.push(p);
                    }
                }
            }
            let z1 = z0 + h as f64 / 2.0;
            let mut pts = Vec::new();
            for c in corners {
                pts.push(DVec3::new(c.x, c.y, z0));
                pts.push(DVec3::new(c.x, c.y, z1));
            }
            convex_hull(&pts).ok().map(|h| h.polytope)
        },
    )
}

/// Convex components of the example parts (sheet-metal ones triangulated, the seed's decomposition).
pub fn example_components() -> Vec<ConvexPolytope> {
    let mut out = Vec::new();
    for name in examples::NAMES {
        if let Some(p) = examples::part_by_name(name, Decomposition::Triangulation) {
            out.extend(p.components().iter().take(12).cloned());
        }
    }
    out
}

pub fn example_component() -> impl Strategy<Value = ConvexPolytope> {
    let comps = example_components();
    (0..comps.len()).prop_map(move |k| comps[k].clone())
}

/// Any kind of polytope.
pub fn any_polytope() -> impl Strategy<Value = ConvexPolytope> {
    prop_oneof![random_hull(), random_box(), random_prism(), example_component()]
}

/// A pair (moving, fixed) of the same family most of the time (shared face directions matter), the fixed one
/// placed by a z-rotation of k * 45 degrees or a random dyadic-degree angle.
pub fn pair() -> impl Strategy<Value = (ConvexPolytope, ConvexPolytope)> {
    let same_family = prop_oneof![
        (random_hull(), random_hull()),
        (random_box(), random_box()),
        (random_prism(), random_prism()),
        (example_component(), example_component()),
        (any_polytope(), any_polytope()),
    ];
    (same_family, 0..4u8, -20..20i32).prop_map(|((a, b), pose, deg)| {
        let b = match pose {
            0 | 1 => b,
            2 => b.transformed(DMat3::from_rotation_z(std::f64::consts::FRAC_PI_2), DVec3::ZERO),
            _ => b.transformed(DMat3::from_rotation_z((deg as f64 * 7.5).to_radians()), DVec3::new(0.5, -0.25, 0.0)),
        };
        (a, b)
    })
}

/// Reflection through the vertical plane x = 0: vertices mirrored, face cycles reversed (same topology; a hull of
/// the mirrored points could split faces whose rounded vertices are no longer exactly coplanar).
pub fn mirrored(p: &ConvexPolytope) -> ConvexPolytope {
    let pts: Vec<DVec3> = p.vertices().iter().map(|v| DVec3::new(-v.x, v.y, v.z)).collect();
    let faces = p.faces().iter().map(|f| f.vertices.iter().rev().copied().collect()).collect();
    ConvexPolytope::new(pts, faces).expect("mirror of a polytope")
}
