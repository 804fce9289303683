//! Mass properties (volume, centre of gravity, inertia tensor) of convex polytopes and of unions of them.
//!
//! Each face is fanned into triangles; each triangle with a reference point forms a signed tetrahedron whose volume,
//! first moment and second moment (covariance) have closed forms (F. Tonon, *Explicit exact formulas for the 3-D
//! tetrahedron inertia tensor in terms of its vertex coordinates*, J. Math. Stat. 1(1), 2004; the covariance form of
//! J. Blow and A. Binstock, *How to find the inertia tensor (or other mass properties) of a 3D solid body represented
//! by a triangle mesh*, 2004). O(V + F) per polytope. Components of a part have disjoint interiors, so the part's
//! properties are the sums of its components'.
//!
//! A part is summed about a point within its size of it (its bounding box's centre rounded to a power-of-two grid as
//! coarse as the part, `part::moment_reference`; the origin for a part near it; [`Moments::of_polytope_about`]), not
//! always about the world origin: second moments about the origin of a part far from it are dominated by `|c.g.|^2 V`, and removing
//! that again (the parallel-axis step in [`Moments::properties`]) cancels about `2 log10(|c.g.| / size)` digits (a
//! 100 mm part 1e7 mm from the origin kept 6 of its inertia's 16 digits).

use crate::polytope::ConvexPolytope;
use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};

/// Mass properties of a rigid body of uniform density.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MassProperties {
    /// Volume (mm^3).
    pub volume: f64,
    /// Mass = density x volume (in the density's mass unit; density 1 by default, so mass = volume).
    pub mass: f64,
    /// Centre of gravity (mm).
    pub center_of_gravity: DVec3,
    /// Inertia tensor about the centre of gravity, in world axes (mass x mm^2).
    pub inertia: DMat3,
}

/// Raw moments accumulated over tetrahedra: volume, first moment, second moment (covariance about the origin).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moments {
    /// Signed volume.
    pub volume: f64,
    /// Integral of x over the body.
    pub first: DVec3,
    /// Integral of x x^T over the body.
    pub second: DMat3,
}

impl Default for Moments {
    fn default() -> Self {
        // not derived: glam's `DMat3::default()` is the identity, not zero
        Self { volume: 0.0, first: DVec3::ZERO, second: DMat3::ZERO }
    }
}

impl Moments {
    /// Moments of one convex polytope (or any closed, outward-oriented polygonal surface).
    pub fn of_polytope(p: &ConvexPolytope) -> Self {
        Self::of_polytope_about(p, DVec3::ZERO)
    }

    /// Moments of `p` about `reference`: those of `p` moved by `-reference`. Sum the components of a part about one
    /// point near it and pass the same point to [`Moments::properties_about`].
    pub fn of_polytope_about(p: &ConvexPolytope, reference: DVec3) -> Self {
        let v = p.vertices();
        // Reference point inside the body reduces cancellation.
        let o = p.vertex_centroid() - reference;
        let mut m = Moments::default();
        for f in p.faces() {
            let a = v[f.vertices[0]] - reference;
            for k in 1..f.vertices.len() - 1 {
                m.add_tetrahedron(o, a, v[f.vertices[k]] - reference, v[f.vertices[k + 1]] - reference);
            }
        }
        m
    }

    /// Adds the signed tetrahedron (o, a, b, c).
    pub fn add_tetrahedron(&mut self, o: DVec3, a: DVec3, b: DVec3, c: DVec3) {
        let (a0, b0, c0) = (a - o, b - o, c - o);
        let det = a0.dot(b0.cross(c0));
        let vol = det / 6.0;
        // covariance of the tetrahedron (0, a0, b0, c0) about 0: det/120 * (sum v v^T + (sum v)(sum v)^T)
        let s = a0 + b0 + c0;
        let outer = |x: DVec3, y: DVec3| DMat3::from_cols(x * y.x, x * y.y, x * y.z);
        let cov0 = (outer(a0, a0) + outer(b0, b0) + outer(c0, c0) + outer(s, s)) * (det / 120.0);
        let centroid0 = s / 4.0;
        // shift from reference o to the world origin: x = x0 + o
        let first0 = centroid0 * vol;
        self.volume += vol;
        self.first += first0 + o * vol;
        self.second += cov0 + outer(first0, o) + outer(o, first0) + outer(o, o) * vol;
    }

    /// Sum of two sets of moments (bodies with disjoint interiors).
    pub fn add(&mut self, other: &Moments) {
        self.volume += other.volume;
        self.first += other.first;
        self.second += other.second;
    }

    /// Mass properties for a uniform density. `None` when the volume is not positive.
    pub fn properties(&self, density: f64) -> Option<MassProperties> {
        if self.volume.is_nan() || self.volume <= 0.0 {
            return None;
        }
        let cg = self.first / self.volume;
        let outer = DMat3::from_cols(cg * cg.x, cg * cg.y, cg * cg.z);
        let cov_cg = (self.second - outer * self.volume) * density;
        let trace = cov_cg.x_axis.x + cov_cg.y_axis.y + cov_cg.z_axis.z;
        let inertia = DMat3::from_diagonal(DVec3::splat(trace)) - cov_cg;
        Some(MassProperties { volume: self.volume, mass: self.volume * density, center_of_gravity: cg, inertia })
    }

    /// [`Moments::properties`] of moments taken about `reference` ([`Moments::of_polytope_about`]): the same inertia
    /// (about the c.g.), the c.g. moved back by `reference`.
    pub fn properties_about(&self, density: f64, reference: DVec3) -> Option<MassProperties> {
        self.properties(density).map(|m| MassProperties { center_of_gravity: m.center_of_gravity + reference, ..m })
    }
}

/// Mass properties of one convex polytope at the given density.
pub fn polytope_mass_properties(p: &ConvexPolytope, density: f64) -> Option<MassProperties> {
    Moments::of_polytope(p).properties(density)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::convex_hull;

    fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
        ConvexPolytope::cuboid(lo, hi).expect("box")
    }

    #[test]
    fn box_against_closed_form() {
        let (a, b, c) = (2.0, 3.0, 5.0);
        let p = cuboid(DVec3::new(1.0, -1.0, 4.0), DVec3::new(1.0 + a, -1.0 + b, 4.0 + c));
        let m = polytope_mass_properties(&p, 7.8).expect("props");
        let mass = 7.8 * a * b * c;
        assert!((m.volume - a * b * c).abs() < 1e-12);
        assert!((m.mass - mass).abs() < 1e-9);
        assert!((m.center_of_gravity - DVec3::new(2.0, 0.5, 6.5)).length() < 1e-12);
        let expect = DVec3::new(b * b + c * c, a * a + c * c, a * a + b * b) * (mass / 12.0);
        let got = DVec3::new(m.inertia.x_axis.x, m.inertia.y_axis.y, m.inertia.z_axis.z);
        assert!((got - expect).length() < 1e-9 * expect.length(), "{got} vs {expect}");
        assert!(m.inertia.x_axis.y.abs() < 1e-9 && m.inertia.x_axis.z.abs() < 1e-9 && m.inertia.y_axis.z.abs() < 1e-9);
    }

    /// The built-in Complex part moved 1e7 mm away has the same inertia (about its c.g.) to 1e-10; summed about the
    /// origin it kept only about 6 digits (relative error 1.4e-6 here).
    #[test]
    fn a_part_far_from_the_origin_keeps_its_inertia() {
        let part = crate::examples::part_by_name("complex", Default::default()).expect("complex");
        for shift in [DVec3::new(1e7, -3e6, 2e6), DVec3::new(-5e5, 0.0, 0.0)] {
            let moved: Vec<ConvexPolytope> =
                part.components.iter().map(|c| c.transformed(DMat3::IDENTITY, shift)).collect();
            let far =
                crate::part::Part::from_components("far", moved, part.density, part.origin.clone()).expect("part");
            let (near, far) = (part.mass, far.mass);
            let scale = near.inertia.abs().to_cols_array().into_iter().fold(0.0, f64::max);
            let worst = (far.inertia - near.inertia).abs().to_cols_array().into_iter().fold(0.0, f64::max);
            assert!(worst <= 1e-10 * scale, "shift {shift}: inertia off by {:e} of its scale", worst / scale);
            assert!((far.volume - near.volume).abs() <= 1e-12 * near.volume);
            let cg_error = (far.center_of_gravity - (near.center_of_gravity + shift)).length();
            assert!(cg_error <= 1e-15 * shift.length() + 1e-9, "c.g. off by {cg_error}");
        }
    }

    #[test]
    fn triangular_prism_against_closed_form() {
        // right triangle legs (a, b) in xy, extruded by h along z: cg at (a/3, b/3, h/2)
        let (a, b, h) = (3.0, 6.0, 2.0);
        let base = [DVec3::ZERO, DVec3::new(a, 0.0, 0.0), DVec3::new(0.0, b, 0.0)];
        let pts: Vec<DVec3> = base.iter().flat_map(|&p| [p, p + DVec3::Z * h]).collect();
        let p = convex_hull(&pts).expect("prism").polytope;
        let m = polytope_mass_properties(&p, 1.0).expect("props");
        assert!((m.volume - a * b * h / 2.0).abs() < 1e-12);
        assert!((m.center_of_gravity - DVec3::new(a / 3.0, b / 3.0, h / 2.0)).length() < 1e-12);
        // I_zz about the cg of a right-triangle prism: m (a^2 + b^2) / 18
        let izz = m.mass * (a * a + b * b) / 18.0;
        assert!((m.inertia.z_axis.z - izz).abs() < 1e-9 * izz);
    }
}
