//! The permissible set Omega(R): positions at which the rotated part lies inside the floor volume.
//!
//! \[A\] eq. (3) (Ayyadevara et al. 2002, section 2.1): `p in Omega(theta) <=> Lambda(p, theta) ⊆ Sigma`. With the
//! floor volume `Sigma = {x : a_k . x <= b_k}` (a convex floor polygon times `[0, H]`) and the part's vertices `v` at
//! orientation `R` (a vertex sits at `R v + p`), a convex part lies in the convex `Sigma` iff all its vertices do, so
//!
//! ```text
//! Omega = { p : a_k . p <= b_k - max_v a_k . (R v) }.
//! ```
//!
//! With `p_z` fixed (\[A\] VII-A-2) the same inequalities in `(p_x, p_y)`, plus a check that `p_z` is within the
//! z-range. An empty Omega (floor too small for the part at `R`) is an empty [`Cell`], not an error. Omega is
//! bounded (by the floor polygon and `[0, H]`). O(n k) for n part vertices and k polygon sides; the convexity check
//! of the polygon is O(k^2) exact `orient2d` tests.

use crate::cell::{Cell, CellError, Halfspace, Tag};
use geom::predicates::orient2d;
use geom::{DMat3, DVec2, DVec3, Part, Tolerance};
use serde::{Deserialize, Serialize};
use stackplan_geom as geom;
use std::cmp::Ordering;

/// Why a floor volume or Omega cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OmegaError {
    /// The floor polygon has fewer than three vertices.
    #[error("the floor polygon has {count} vertices; it needs at least 3")]
    TooFewVertices {
        /// Number of vertices.
        count: usize,
    },
    /// A floor polygon vertex is not finite.
    #[error("floor polygon vertex {vertex} is not finite")]
    NonFinite {
        /// Vertex index.
        vertex: usize,
    },
    /// The polygon is not strictly convex and counter-clockwise: `vertex` is not strictly left of side `side`.
    #[error("the floor polygon is not strictly convex counter-clockwise: vertex {vertex} is not left of side {side}")]
    NotConvex {
        /// Side index (from vertex `side` to `side + 1`).
        side: usize,
        /// The offending vertex.
        vertex: usize,
    },
    /// The stack height is not positive and finite.
    #[error("the maximum stack height must be positive and finite, got {0}")]
    BadHeight(f64),
    /// The part has no vertices, or a non-finite one.
    #[error("the part's vertices are missing or not finite")]
    BadPart,
    /// Building the cell failed.
    #[error(transparent)]
    Cell(#[from] CellError),
}

/// The floor volume Sigma: a convex counter-clockwise floor polygon (z = 0) extruded to height `H`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FloorVolume {
    polygon: Vec<DVec2>,
    height: f64,
}

impl FloorVolume {
    /// Checks the polygon (at least 3 finite vertices, strictly convex, counter-clockwise, exact predicates) and
    /// the height (positive, finite).
    pub fn new(polygon: Vec<DVec2>, height: f64) -> Result<Self, OmegaError> {
        let n = polygon.len();
        if n < 3 {
            return Err(OmegaError::TooFewVertices { count: n });
        }
        if let Some(vertex) = polygon.iter().position(|v| !v.is_finite()) {
            return Err(OmegaError::NonFinite { vertex });
        }
        if !(height > 0.0 && height.is_finite()) {
            return Err(OmegaError::BadHeight(height));
        }
        for side in 0..n {
            let (a, b) = (polygon[side], polygon[(side + 1) % n]);
            for vertex in 0..n {
                if vertex == side || vertex == (side + 1) % n {
                    continue;
                }
                if orient2d(a, b, polygon[vertex]) != Ordering::Greater {
                    return Err(OmegaError::NotConvex { side, vertex });
                }
            }
        }
        Ok(Self { polygon, height })
    }

    /// An axis-aligned rectangle `[x0, x1] x [y0, y1] x [0, H]`.
    pub fn rectangle(lo: DVec2, hi: DVec2, height: f64) -> Result<Self, OmegaError> {
        Self::new(vec![lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)], height)
    }

    /// The floor polygon (counter-clockwise).
    pub fn polygon(&self) -> &[DVec2] {
        &self.polygon
    }

    /// The maximum stack height H.
    pub fn height(&self) -> f64 {
        self.height
    }

    /// Area centroid of the floor polygon (the default reference `(x0, y0)` of cost (1)).
    pub fn centroid(&self) -> DVec2 {
        let o = self.polygon[0];
        let (mut area, mut c) = (0.0, DVec2::ZERO);
        for k in 1..self.polygon.len() - 1 {
            let (a, b) = (self.polygon[k] - o, self.polygon[k + 1] - o);
            let t = 0.5 * a.perp_dot(b);
            area += t;
            c += t * (a + b) / 3.0;
        }
        o + c / area
    }

    /// The default reference point of cost (1): the floor centroid at z0 = 0.
    pub fn default_reference(&self) -> DVec3 {
        self.centroid().extend(0.0)
    }

    /// Outward unit normal and offset of side k of the polygon.
    fn side(&self, k: usize) -> (DVec2, f64) {
        let a = self.polygon[k];
        let b = self.polygon[(k + 1) % self.polygon.len()];
        let d = b - a;
        let n = DVec2::new(d.y, -d.x) / d.length();
        (n, n.dot(a))
    }

    /// Sigma itself as inequalities: the sides, then the floor `z >= 0`, then the ceiling `z <= H`.
    pub fn halfspaces(&self) -> Vec<Halfspace<3>> {
        let mut hs: Vec<Halfspace<3>> = (0..self.polygon.len())
            .map(|k| {
                let (n, b) = self.side(k);
                Halfspace::new([n.x, n.y, 0.0], b, Tag::FloorSide { side: k as u32 })
            })
            .collect();
        hs.push(Halfspace::new([0.0, 0.0, -1.0], 0.0, Tag::Floor));
        hs.push(Halfspace::new([0.0, 0.0, 1.0], self.height, Tag::Ceiling));
        hs
    }

    /// The tolerance policy for this floor volume and a part of bounding-box diagonal `part_size`.
    pub fn tolerance(&self, part_size: f64) -> Tolerance {
        let (lo, hi) = self.polygon.iter().fold((self.polygon[0], self.polygon[0]), |(l, h), v| (l.min(*v), h.max(*v)));
        Tolerance::for_scale((hi - lo).length().max(self.height).max(part_size))
    }

    fn support(&self, rotated: &[DVec3]) -> Result<(Vec<f64>, f64, f64, f64), OmegaError> {
        if rotated.is_empty() || rotated.iter().any(|v| !v.is_finite()) {
            return Err(OmegaError::BadPart);
        }
        let sides = (0..self.polygon.len())
            .map(|k| {
                let (n, _) = self.side(k);
                rotated.iter().map(|v| n.x * v.x + n.y * v.y).fold(f64::NEG_INFINITY, f64::max)
            })
            .collect();
        let zmin = rotated.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
        let zmax = rotated.iter().map(|v| v.z).fold(f64::NEG_INFINITY, f64::max);
        Ok((sides, zmin, zmax, geom::tolerance::bounding_diagonal(rotated)))
    }
}

/// Omega for the part's vertices already rotated (`R v`): see the module documentation.
pub fn omega(floor: &FloorVolume, rotated_vertices: &[DVec3]) -> Result<Cell<3>, OmegaError> {
    let (sides, zmin, zmax, size) = floor.support(rotated_vertices)?;
    let mut hs = floor.halfspaces();
    for (k, s) in sides.iter().enumerate() {
        hs[k].offset -= s;
    }
    let m = hs.len();
    hs[m - 2].offset = zmin; // -p_z <= 0 - max_v(-z_v)
    hs[m - 1].offset = floor.height - zmax;
    Ok(Cell::build(hs, floor.tolerance(size), false)?)
}

/// Omega for `part` at orientation `rotation`.
pub fn omega_for_part(floor: &FloorVolume, part: &Part, rotation: DMat3) -> Result<Cell<3>, OmegaError> {
    let rotated: Vec<DVec3> = part.all_vertices().map(|v| rotation * v).collect();
    omega(floor, &rotated)
}

/// The 2-D Omega in `(p_x, p_y)` at fixed `p_z` (\[A\] VII-A-2); empty when `p_z` puts the part below the floor or
/// above the ceiling (by more than the tolerance).
pub fn omega_fixed_z(floor: &FloorVolume, rotated_vertices: &[DVec3], pz: f64) -> Result<Cell<2>, OmegaError> {
    if !pz.is_finite() {
        return Err(OmegaError::BadPart);
    }
    let (sides, zmin, zmax, size) = floor.support(rotated_vertices)?;
    let mut hs: Vec<Halfspace<2>> = (0..floor.polygon.len())
        .map(|k| {
            let (n, b) = floor.side(k);
            Halfspace::new([n.x, n.y], b - sides[k], Tag::FloorSide { side: k as u32 })
        })
        .collect();
    // zero-normal inequalities: kept (and the cell empty) only when violated
    hs.push(Halfspace::new([0.0, 0.0], zmin + pz, Tag::Floor));
    hs.push(Halfspace::new([0.0, 0.0], floor.height - zmax - pz, Tag::Ceiling));
    Ok(Cell::build(hs, floor.tolerance(size), false)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_polygon_checks() {
        let sq = vec![DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(1.0, 1.0), DVec2::new(0.0, 1.0)];
        assert!(FloorVolume::new(sq.clone(), 1.0).is_ok());
        let mut cw = sq.clone();
        cw.reverse();
        assert!(matches!(FloorVolume::new(cw, 1.0), Err(OmegaError::NotConvex { .. })));
        let mut dent = sq.clone();
        dent.insert(1, DVec2::new(0.5, 0.2));
        assert!(matches!(FloorVolume::new(dent, 1.0), Err(OmegaError::NotConvex { side: 0, .. })));
        let mut straight = sq.clone();
        straight.insert(1, DVec2::new(0.5, 0.0));
        assert!(matches!(FloorVolume::new(straight, 1.0), Err(OmegaError::NotConvex { .. })));
        assert_eq!(FloorVolume::new(sq[..2].to_vec(), 1.0), Err(OmegaError::TooFewVertices { count: 2 }));
        assert_eq!(FloorVolume::new(sq.clone(), 0.0), Err(OmegaError::BadHeight(0.0)));
        let mut nan = sq;
        nan[2].x = f64::NAN;
        assert_eq!(FloorVolume::new(nan, 1.0), Err(OmegaError::NonFinite { vertex: 2 }));
        // a star pentagon turns left everywhere but winds twice: rejected
        let star: Vec<DVec2> = (0..5)
            .map(|k| {
                let t = (2 * k) as f64 * std::f64::consts::TAU / 5.0;
                DVec2::new(t.cos(), t.sin())
            })
            .collect();
        assert!(matches!(FloorVolume::new(star, 1.0), Err(OmegaError::NotConvex { .. })));
    }

    #[test]
    fn omega_of_a_box_part() {
        let floor = FloorVolume::rectangle(DVec2::ZERO, DVec2::new(10.0, 6.0), 5.0).expect("floor");
        assert!((floor.centroid() - DVec2::new(5.0, 3.0)).length() < 1e-12);
        let part: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64 * 2.0 - 1.0, (i >> 1 & 1) as f64 * 4.0, (i >> 2 & 1) as f64 + 0.5))
            .collect();
        let om = omega(&floor, &part).expect("omega");
        // p_x in [1, 9], p_y in [0, 2], p_z in [-0.5, 3.5]
        let expect = [0.0, 9.0, 2.0, -1.0, 0.5, 3.5];
        let got: Vec<f64> = om.halfspaces().iter().map(|h| h.offset).collect();
        for (a, b) in got.iter().zip(expect) {
            assert!((a - b).abs() < 1e-12, "{got:?}");
        }
        let tiny = FloorVolume::rectangle(DVec2::ZERO, DVec2::new(1.0, 6.0), 5.0).expect("floor");
        assert!(omega(&tiny, &part).expect("omega").is_empty());
        let o2 = omega_fixed_z(&floor, &part, 0.0).expect("2d");
        assert!(o2.is_solid() && o2.len() == 4);
        assert!(omega_fixed_z(&floor, &part, -0.6).expect("2d").is_empty());
        assert!(omega_fixed_z(&floor, &part, 3.6).expect("2d").is_empty());
        assert_eq!(omega(&floor, &[]), Err(OmegaError::BadPart));
    }
}
