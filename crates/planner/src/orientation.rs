//! One discrete orientation of the new part: rotation, the permissible set `Omega` (\[A\] eq. 3) and the cost as a
//! separable quadratic (`cell_qp::Quadratic::of_cost`; `docs/algorithms.md`, "Free space and the placement QP").
//!
//! With `Sigma = {x : a_k . x <= b_k}` and the rotated vertices `R v`,
//! `Omega(R) = {p : a_k . p <= b_k - max_v a_k . (R v)}`: one inequality per side of the floor polygon, the floor
//! `p_z >= -min_v (R v)_z` and the ceiling `p_z <= H - max_v (R v)_z`. At a fixed `p_z` the floor and ceiling become
//! a test of that value and the sides stay. O(V (S + 2)) for `V` vertices and `S` floor sides.

use crate::cell_qp::Quadratic;
use crate::request::{Cost, FloorVolume, polygon_side_planes};
use glam::{DMat3, DVec2, DVec3};
use stackplan_cspace::PlacedConvex;
use stackplan_freespace::{Halfspace, Tag};
use stackplan_geom::Part;
use std::sync::Arc;

/// The components of `part` rotated by `rotation`, at position zero.
pub fn rotated_components(part: &Part, rotation: DMat3) -> Arc<[PlacedConvex]> {
    part.components().iter().map(|c| PlacedConvex::new(c, rotation, DVec3::ZERO)).collect()
}

/// A discrete orientation with everything the search needs at it.
#[derive(Debug, Clone)]
pub struct Orientation {
    /// Index in the search's orientation list.
    pub index: usize,
    /// Resting-pose index.
    pub rest: usize,
    /// Index into the theta set.
    pub theta_index: usize,
    /// The angle about world z (radians).
    pub theta: f64,
    /// `R = R_z(theta) R_rest`.
    pub rotation: DMat3,
    /// Lowest corner of the rotated vertices (relative to the position).
    pub lo: DVec3,
    /// Highest corner of the rotated vertices.
    pub hi: DVec3,
    /// Rotated c.g. offset `R g`.
    pub cg: DVec3,
    /// The components rotated, at position zero (empty until [`Orientation::build_components`]; [`Orientation::new`]
    /// builds them at once).
    pub components: Arc<[PlacedConvex]>,
    /// The rotated vertices of every component, component by component (for `Omega`).
    vertices: Vec<DVec3>,
    /// The cost at this orientation.
    pub quadratic: Quadratic<3>,
}

impl Orientation {
    /// Builds the orientation data with its rotated components. O(total size of the part).
    pub fn new(
        part: &Part,
        index: usize,
        rest: usize,
        theta_index: usize,
        theta: f64,
        rest_rotation: DMat3,
        cost: &Cost,
    ) -> Self {
        let mut o = Self::without_components(part, index, rest, theta_index, theta, rest_rotation, cost);
        o.build_components(part);
        o
    }

    /// The orientation data without the rotated components (rotation, extents, `Omega`, cost): what the roots of the
    /// search need. O(number of vertices). The components follow on demand ([`Orientation::build_components`]), only
    /// for orientations the search expands.
    pub fn without_components(
        part: &Part,
        index: usize,
        rest: usize,
        theta_index: usize,
        theta: f64,
        rest_rotation: DMat3,
        cost: &Cost,
    ) -> Self {
        let rotation = DMat3::from_rotation_z(theta) * rest_rotation;
        // the same arithmetic as `PlacedConvex::new(c, rotation, DVec3::ZERO)`, so the extents are bit-identical
        let vertices: Vec<DVec3> =
            part.components().iter().flat_map(|c| c.vertices().iter().map(|v| rotation * *v + DVec3::ZERO)).collect();
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for v in &vertices {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let cg = rotation * part.mass().center_of_gravity;
        let quadratic = Quadratic::of_cost(cost, lo, hi, cg);
        Self { index, rest, theta_index, theta, rotation, lo, hi, cg, components: Arc::new([]), vertices, quadratic }
    }

    /// Builds the rotated components if they are missing. O(total size of the part).
    pub fn build_components(&mut self, part: &Part) {
        if self.components.is_empty() {
            self.components = rotated_components(part, self.rotation);
        }
    }

    /// Takes `components` (the part's components rotated by [`Orientation::rotation`], as
    /// [`Orientation::build_components`] builds them, e.g. kept from an earlier search of the same part) if the
    /// components are missing.
    pub fn set_components(&mut self, components: Arc<[PlacedConvex]>) {
        if self.components.is_empty() {
            self.components = components;
        }
    }

    /// `max_v d . (R v)` over the rotated vertices.
    pub(crate) fn support(&self, d: DVec3) -> f64 {
        self.vertices.iter().map(|v| d.dot(*v)).fold(f64::NEG_INFINITY, f64::max)
    }

    /// The sides of the permissible set of the convex polygon `polygon` (counter-clockwise): per side `(n, d)`,
    /// the positions `p` with `n . (p_x, p_y) <= d - h(n)`, `h` the rotated part's support function — those at which
    /// the part's shadow lies inside the polygon. O(sides x vertices).
    pub fn sides_within(&self, polygon: &[DVec2]) -> Vec<(DVec2, f64)> {
        polygon_side_planes(polygon)
            .into_iter()
            .map(|(n, d)| (n, d - self.support(DVec3::new(n.x, n.y, 0.0))))
            .collect()
    }

    /// The 3-D permissible set's inequalities (sides, floor, ceiling) in that order.
    pub fn omega_3d(&self, floor: &FloorVolume) -> Vec<Halfspace<3>> {
        let mut out = Vec::with_capacity(floor.polygon.len() + 2);
        for (side, (n, d)) in self.sides_within(&floor.polygon).into_iter().enumerate() {
            out.push(Halfspace::new([n.x, n.y, 0.0], d, Tag::FloorSide { side: side as u32 }));
        }
        out.push(Halfspace::new([0.0, 0.0, -1.0], self.lo.z, Tag::Floor));
        out.push(Halfspace::new([0.0, 0.0, 1.0], floor.height - self.hi.z, Tag::Ceiling));
        out
    }

    /// The 2-D permissible set at `p_z = z`: the sides only, or `None` when `z` violates the floor or the ceiling by
    /// more than `tol` (the part would leave `Sigma`).
    pub fn omega_2d(&self, floor: &FloorVolume, z: f64, tol: f64) -> Option<Vec<Halfspace<2>>> {
        if z + self.lo.z < -tol || z + self.hi.z > floor.height + tol {
            return None;
        }
        Some(
            self.sides_within(&floor.polygon)
                .into_iter()
                .enumerate()
                .map(|(side, (n, d))| Halfspace::new([n.x, n.y], d, Tag::FloorSide { side: side as u32 }))
                .collect(),
        )
    }
}
