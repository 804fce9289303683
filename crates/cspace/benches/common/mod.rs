//! Shapes shared by the cspace benchmarks.
#![allow(dead_code)]

use glam::DVec3;
use stackplan_geom::{ConvexPolytope, convex_hull};

/// The box `[0, hi]`.
pub fn cuboid(hi: DVec3) -> ConvexPolytope {
    ConvexPolytope::cuboid(DVec3::ZERO, hi).expect("box")
}

/// A sheet-metal piece: a convex hexagon extruded by 2 mm.
pub fn hexagon_prism(scale: f64) -> ConvexPolytope {
    let outline = [(0.0, 0.0), (60.0, 0.0), (90.0, 30.0), (80.0, 70.0), (20.0, 80.0), (-10.0, 40.0)];
    let mut pts = Vec::new();
    for (x, y) in outline {
        pts.push(DVec3::new(x * scale, y * scale, 0.0));
        pts.push(DVec3::new(x * scale, y * scale, 2.0));
    }
    convex_hull(&pts).expect("prism").polytope
}

/// The hull of `n` pseudo-random points on a sphere of radius 50 (all extreme).
pub fn random_polytope(n: usize, seed: u64) -> ConvexPolytope {
    let mut s = seed;
    let mut next = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pts: Vec<DVec3> = (0..n)
        .map(|_| {
            let z = 2.0 * next() - 1.0;
            let phi = 2.0 * std::f64::consts::PI * next();
            let r = (1.0 - z * z).sqrt();
            DVec3::new(r * phi.cos(), r * phi.sin(), z) * 50.0
        })
        .collect();
    convex_hull(&pts).expect("random").polytope
}
