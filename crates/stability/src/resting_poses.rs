//! Resting poses of a part on a flat floor (`docs/algorithms.md`, "Stability, grasp and insertion"; \[A\] II-B, the
//! orientation parameters (phi, psi)).
//!
//! A rigid body resting on a plane touches it with the convex hull of its contact set, which is a face of the convex
//! hull of the body (\[A\] leaves this to the author's thesis; it is the classical "stable faces" analysis). The body
//! rests stably on hull face `F` iff its centre of gravity projects (along the face normal) strictly inside `F`; the
//! stability margin is the distance from the projected c.g. to the boundary of `F` (for a convex polygon and an
//! interior point, the smallest distance to an edge line). A face is reported when the margin exceeds the part's
//! tolerance (`Tolerance::linear`).
//!
//! Rotation convention: the orientation that puts a face with outward unit normal `n = (nx, ny, nz)` down is
//! `R0 = Ry(psi) Rx(phi)` with
//!
//! ```text
//! phi = -pi/2 - atan2(nz, ny)        (Rx(phi) turns n into the xz-plane with  z = -sqrt(ny^2 + nz^2))
//! psi =  pi   - atan2(nx, -rho),  rho = sqrt(ny^2 + nz^2)   (Ry(psi) turns that onto -z)
//! ```
//!
//! both wrapped into (-pi, pi]. The remaining free rotation theta about the vertical (the planner's third
//! orientation parameter, \[A\] Fig. 4) is fixed at 0, and the position puts the face on z = 0 with the c.g. above the
//! origin, so `rotation`, `position` are deterministic. Full orientation: `Rz(theta) Ry(psi) Rx(phi)`.
//!
//! Sorting: by c.g. height ascending, then by margin descending, then by face index (deterministic).
//!
//! The faces are those of the hull with its rounding creases merged (`stackplan_geom::convex_hull_merged`): a part
//! turned in its file, or a sheet-metal face rotated into place, has faces planar only to rounding, which the exact
//! hull splits into facets; on a split face the c.g. projects onto a crease, inside no facet (a turned block had no
//! resting pose at all, and the built-in Triangle's bottom face a margin of 56.4 mm instead of 65.0).
//!
//! Cost: one 3-D hull of all component vertices (exact Quickhull, O(n log n) expected) plus O(F V) for the faces.

use crate::StabilityError;
use crate::polygon2d::signed_boundary_distance;
use glam::{DMat3, DVec2, DVec3};
use serde::{Deserialize, Serialize};
use stackplan_geom::{Part, convex_hull_merged};

/// One stable resting pose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RestingPose {
    /// Index of the face in the hull (`ConvexPolytope::faces` of `hull_of_part`).
    pub hull_face: usize,
    /// Outward unit normal of the face in part coordinates (it points down, -z, in the pose).
    pub face_normal: DVec3,
    /// Rotation angle about x (radians), see the module documentation.
    pub phi: f64,
    /// Rotation angle about y (radians).
    pub psi: f64,
    /// `Ry(psi) Rx(phi)`.
    pub rotation: DMat3,
    /// Translation putting the face on z = 0 with the c.g. over the origin.
    pub position: DVec3,
    /// Height of the c.g. above the floor (mm).
    pub cg_height: f64,
    /// Distance from the projected c.g. to the face boundary (mm).
    pub margin: f64,
    /// The face polygon on the floor (z = 0), counter-clockwise seen from above, world coordinates of the pose.
    pub footprint: Vec<DVec3>,
}

/// Wraps an angle into (-pi, pi].
fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let mut x = a % t;
    if x <= -std::f64::consts::PI {
        x += t;
    } else if x > std::f64::consts::PI {
        x -= t;
    }
    x
}

/// The angles (phi, psi) of the module documentation for outward normal `n` (unit).
pub fn face_down_angles(n: DVec3) -> (f64, f64) {
    let rho = (n.y * n.y + n.z * n.z).sqrt();
    let phi = wrap(-std::f64::consts::FRAC_PI_2 - n.z.atan2(n.y));
    let psi = wrap(std::f64::consts::PI - n.x.atan2(-rho));
    (phi, psi)
}

/// `Ry(psi) Rx(phi)`.
pub fn rotation_from_angles(phi: f64, psi: f64) -> DMat3 {
    DMat3::from_rotation_y(psi) * DMat3::from_rotation_x(phi)
}

/// The rotation that puts outward normal `n` onto -z, by the convention of the module documentation.
pub fn face_down_rotation(n: DVec3) -> DMat3 {
    let (phi, psi) = face_down_angles(n);
    rotation_from_angles(phi, psi)
}

/// The stable resting poses of `part`, sorted as in the module documentation.
pub fn resting_poses(part: &Part) -> Result<Vec<RestingPose>, StabilityError> {
    let points: Vec<DVec3> = part.all_vertices().collect();
    let hull = convex_hull_merged(&points).map_err(|e| StabilityError::Hull(e.to_string()))?.polytope;
    let tol = part.tolerance().linear;
    let cg = part.mass().center_of_gravity;
    let mut poses = Vec::new();
    for (f, face) in hull.faces().iter().enumerate() {
        let n = face.plane.normal;
        let rotation = face_down_rotation(n);
        let rotated: Vec<DVec3> = face.vertices.iter().map(|&v| rotation * hull.vertices()[v]).collect();
        let floor = rotated.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
        let c = rotation * cg;
        // the face seen from above after turning it down is clockwise: reverse to counter-clockwise
        let poly: Vec<DVec2> = rotated.iter().rev().map(|v| DVec2::new(v.x, v.y)).collect();
        let margin = signed_boundary_distance(DVec2::new(c.x, c.y), &poly);
        if margin <= tol {
            continue;
        }
        let position = DVec3::new(-c.x, -c.y, -floor);
        let (phi, psi) = face_down_angles(n);
        poses.push(RestingPose {
            hull_face: f,
            face_normal: n,
            phi,
            psi,
            rotation,
            position,
            cg_height: c.z - floor,
            margin,
            footprint: rotated.iter().rev().map(|v| DVec3::new(v.x - c.x, v.y - c.y, 0.0)).collect(),
        });
    }
    poses.sort_by(|a, b| {
        a.cg_height.total_cmp(&b.cg_height).then(b.margin.total_cmp(&a.margin)).then(a.hull_face.cmp(&b.hull_face))
    });
    tracing::debug!(part = %part.name, faces = hull.faces().len(), stable = poses.len(), "resting poses");
    Ok(poses)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_put_every_normal_down() {
        let normals = [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(1.0, 2.0, 3.0).normalize(),
            DVec3::new(-1.0, 0.5, -0.2).normalize(),
            DVec3::new(0.0, 0.0, -1.0),
        ];
        for n in normals {
            let r = face_down_rotation(n);
            assert!((r * n - DVec3::NEG_Z).length() < 1e-12, "{n} -> {}", r * n);
        }
        // a face that already points down needs no rotation
        let (phi, psi) = face_down_angles(DVec3::NEG_Z);
        assert!(phi.abs() < 1e-15 && psi.abs() < 1e-15, "{phi} {psi}");
    }
}
