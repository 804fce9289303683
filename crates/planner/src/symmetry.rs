//! Rotational symmetry of a part about the vertical axis through its c.g. in a resting pose (\[A\] VII-C names the
//! missing speed-up: "symmetry of parts is not exploited").
//!
//! Let `X` be the part's components rotated into the resting pose and `S` the rotation by `2 pi / k` about the
//! vertical line through the c.g. If `S` maps every component's vertex set onto the vertex set of some component
//! (within the tolerance policy's length), the occupied space is invariant, and then
//! `R_z(theta + 2 pi / k) X = R_z(theta) X + t(theta)`: the orientation `theta + 2 pi / k` only translates the part,
//! so every cost that depends on the occupied space and the c.g. (both costs do) has the same optimum value and the
//! search needs one period `[0, 2 pi / k)`. The largest such `k <= MAX_ORDER` is reported.
//!
//! Cost: O(k m^2 V) per tested order (`m` components, `V` vertices each), with a cheap centroid match first.

use glam::{DMat3, DVec3};
use stackplan_geom::Part;

/// The largest symmetry order tested.
pub const MAX_ORDER: usize = 12;

/// The largest `k` (1 when none) such that rotating `part` (already rotated by `rest`) by `2 pi / k` about the vertical
/// axis through its c.g. maps it onto itself within `tol`.
pub fn rotational_order(part: &Part, rest: DMat3, tol: f64) -> usize {
    let comps: Vec<Vec<DVec3>> =
        part.components().iter().map(|c| c.vertices().iter().map(|v| rest * *v).collect()).collect();
    let centroids: Vec<DVec3> =
        comps.iter().map(|vs| vs.iter().fold(DVec3::ZERO, |a, b| a + *b) / vs.len().max(1) as f64).collect();
    let axis = rest * part.mass().center_of_gravity;
    (2..=MAX_ORDER).rev().find(|&k| maps_onto_itself(&comps, &centroids, axis, k, tol)).unwrap_or(1)
}

fn maps_onto_itself(comps: &[Vec<DVec3>], centroids: &[DVec3], axis: DVec3, k: usize, tol: f64) -> bool {
    let rot = DMat3::from_rotation_z(std::f64::consts::TAU / k as f64);
    let map = |v: DVec3| {
        let rel = DVec3::new(v.x - axis.x, v.y - axis.y, v.z);
        let r = rot * rel;
        DVec3::new(r.x + axis.x, r.y + axis.y, r.z)
    };
    let close = |a: DVec3, b: DVec3| (a - b).abs().max_element() <= tol;
    let mut used = vec![false; comps.len()];
    for (i, vs) in comps.iter().enumerate() {
        let target = map(centroids[i]);
        let found = (0..comps.len()).find(|&j| {
            !used[j]
                && comps[j].len() == vs.len()
                && close(centroids[j], target)
                && vs.iter().all(|v| {
                    let w = map(*v);
                    comps[j].iter().any(|u| close(*u, w))
                })
        });
        match found {
            Some(j) => used[j] = true,
            None => return false,
        }
    }
    true
}

/// With `n` uniform angles over a full turn and symmetry order `k`, how many leading angles form one period
/// (`n` when `k` does not divide `n`, so no angle of the set is lost).
pub fn period_length(n: usize, k: usize) -> usize {
    if k > 1 && n.is_multiple_of(k) { n / k } else { n }
}

/// Whether `thetas` is the uniform full-turn set `i 2 pi / n` (within `1e-12` rad).
pub fn is_uniform_full_turn(thetas: &[f64]) -> bool {
    let n = thetas.len();
    n > 0 && thetas.iter().enumerate().all(|(i, t)| (t - i as f64 * std::f64::consts::TAU / n as f64).abs() <= 1e-12)
}

#[cfg(test)]
mod tests {
    use super::*;
    use stackplan_geom::examples;
    use stackplan_geom::sheet_metal::Decomposition;

    #[test]
    fn orders_of_the_examples() {
        let tri = examples::part_by_name("triangle", Decomposition::Triangulation).expect("triangle");
        assert_eq!(rotational_order(&tri, DMat3::IDENTITY, tri.tolerance().linear * 10.0), 3);
        let ch = examples::part_by_name("channel", Decomposition::Triangulation).expect("channel");
        assert_eq!(rotational_order(&ch, DMat3::IDENTITY, ch.tolerance().linear * 10.0), 2);
        let cube = examples::cube();
        assert_eq!(rotational_order(&cube, DMat3::IDENTITY, 1e-9), 4);
        let l = examples::l_corner_part();
        assert_eq!(rotational_order(&l, DMat3::IDENTITY, 1e-9), 1);
        // tilted: a cube on an edge has only the 2-fold symmetry about the vertical
        let tilt = DMat3::from_rotation_x(std::f64::consts::FRAC_PI_4);
        assert_eq!(rotational_order(&cube, tilt, 1e-9), 2);
        assert_eq!(period_length(360, 3), 120);
        assert_eq!(period_length(360, 7), 360);
        assert!(is_uniform_full_turn(&crate::request::uniform_thetas(360)));
        assert!(!is_uniform_full_turn(&[0.0, 0.1]));
    }
}
