//! Contacts along an element's boundary: a PC whose contact set lies on the boundary of one of its elements is the
//! contact of that boundary element, and when another PC of the state already holds there it is not a contact of
//! its own.
//!
//! The block of \[P\] is exactly as tall as the walls of the L-corner. Pressed against a wall with a vertical edge,
//! that edge's top vertex lies on the wall's top edge, so it also touches the wall's top face (distance 0 to the closed
//! face), and the wall's top edge lies in the plane of the block's top face, touching it at that vertex. Both are
//! contacts of closed elements, but neither constrains anything the edge on the wall does not: the contact point lies on
//! the boundary of the wall's top face across a *convex* edge, the same point as seen from the wall's side face.
//!
//! Rule (at a configuration, after the highest-level mapping): the contact set `X` of each PC (its contact point, the
//! part of an edge lying on a face, [`Manifolds::contact_points`]) is located on each part: the lowest element whose
//! closure holds all of `X` within `hold`, descending from the PC's element only through *convex* boundary elements
//! (a convex edge of a face, a convex end vertex of an edge). A PC whose located pair differs from its own elements
//! is dropped when the located pair lies within (element by element, [`SurfaceElements::is_within`]) the located pair
//! of another PC of the state and is not equal to it. Concave boundaries are never descended: a vertex in the concave
//! floor-wall edge touches both faces, two real contacts. f-f contact sets (polygons) are not located; an f-f PC is
//! kept and serves as a container with its own elements. Cost: O(k^2) for k PCs, each location O(size of the
//! element's boundary).

use super::check::{Manifolds, segment_closest};
use crate::criteria::face_point_distance_2d;
use crate::pose::Pose;
use crate::principal_contact::{ContactState, PcType, PrincipalContact};
use crate::surface::{Element, ElementKind, SurfaceElements};
use stackplan_geom::{DVec2, DVec3};

/// Distance from `p` to segment `a b`.
fn point_segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let len2 = d.dot(d);
    let s = if len2 > 0.0 { ((p - a).dot(d) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a + d * s - p).length()
}

/// Distance from `p` (the part's coordinates) to the closed element `e` of `s`.
pub fn element_point_distance(s: &SurfaceElements, e: Element, p: DVec3) -> f64 {
    match e.kind {
        ElementKind::Vertex => (p - s.vertices[e.index].position).length(),
        ElementKind::Edge => {
            let (a, b) = s.edge_points(e.index);
            point_segment_distance(p, a, b)
        }
        ElementKind::Face => {
            let f = &s.faces[e.index];
            f.frame.height(p).hypot(face_point_distance_2d(f, f.frame.to_2d(p)))
        }
    }
}

fn is_convex(s: &SurfaceElements, e: Element) -> bool {
    match e.kind {
        ElementKind::Vertex => s.vertices[e.index].convex,
        ElementKind::Edge => s.edges[e.index].convex,
        ElementKind::Face => true,
    }
}

/// The lowest element whose closure holds every point of `points` within `tol`, descending from `e` through convex
/// boundary elements only; with the distance of the points from a convex boundary element they are not within `tol`
/// of but within `band` of (nearly but not clearly on the boundary), if any.
pub fn locate(s: &SurfaceElements, e: Element, points: &[DVec3], tol: f64, band: f64) -> (Element, Option<f64>) {
    let mut current = e;
    loop {
        let mut next = None;
        let mut near: Option<f64> = None;
        for b in s.immediate_boundary(current).into_iter().filter(|b| is_convex(s, *b)) {
            let d = points.iter().map(|p| element_point_distance(s, b, *p)).fold(0.0, f64::max);
            if d <= tol {
                next = Some(b);
                break;
            }
            if d <= band {
                near = Some(near.map_or(d, |m: f64| m.min(d)));
            }
        }
        match next {
            Some(b) => current = b,
            None => return (current, near),
        }
    }
}

/// The parameter interval of the segment `a b` (2-D) inside the convex polygon `poly` (counter-clockwise) grown by
/// `tol` (Cyrus-Beck clipping); `None` when it misses.
fn clip_segment(a: DVec2, b: DVec2, poly: &[DVec2], tol: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    let n = poly.len();
    for i in 0..n {
        let (q0, q1) = (poly[i], poly[(i + 1) % n]);
        let e = q1 - q0;
        let len = e.length();
        if len <= 0.0 {
            continue;
        }
        // inside: e x (p - q0) >= -tol |e|, linear in the parameter
        let f0 = e.perp_dot(a - q0) + tol * len;
        let f1 = e.perp_dot(b - q0) + tol * len;
        if f0 < 0.0 && f1 < 0.0 {
            return None;
        }
        if f0 < 0.0 {
            lo = lo.max(f0 / (f0 - f1));
        } else if f1 < 0.0 {
            hi = hi.min(f0 / (f0 - f1));
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// The end points of the part of segment `p q` (the face's part coordinates) lying on the face (within `tol` of its
/// pieces, after projection into its plane): the lowest and highest parameter over the pieces.
fn segment_on_face(s: &SurfaceElements, face: usize, p: DVec3, q: DVec3, tol: f64) -> Option<[DVec3; 2]> {
    let f = &s.faces[face];
    let (a, b) = (f.frame.to_2d(p), f.frame.to_2d(q));
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for piece in &f.pieces {
        if let Some((l, h)) = clip_segment(a, b, piece, tol) {
            lo = lo.min(l);
            hi = hi.max(h);
        }
    }
    (lo <= hi).then(|| [p + (q - p) * lo, p + (q - p) * hi])
}

impl Manifolds<'_> {
    /// The contact set of a PC at `pose`, as points in A's coordinates (the world): the contact point of a PPC (the
    /// vertex, or the middle of the closest points of two edges), the two ends of the part of an edge lying on a face
    /// (f-e, e-f); `None` for f-f and when an edge's part on the face is empty.
    pub fn contact_points(&self, pc: &PrincipalContact, pose: &Pose) -> Option<Vec<DVec3>> {
        let (sa, sb) = (&self.fixed.surface, &self.moving.surface);
        let tol = self.hold();
        match pc.kind() {
            PcType::FaceVertex => Some(vec![pose.apply(sb.vertices[pc.b.index].position)]),
            PcType::VertexFace => Some(vec![sa.vertices[pc.a.index].position]),
            PcType::EdgeEdge => {
                let (a0, a1) = sa.edge_points(pc.a.index);
                let (b0, b1) = sb.edge_points(pc.b.index);
                let (b0, b1) = (pose.apply(b0), pose.apply(b1));
                let (_, s, t) = segment_closest(a0, a1, b0, b1);
                Some(vec![(a0 + (a1 - a0) * s + b0 + (b1 - b0) * t) * 0.5])
            }
            PcType::FaceEdge => {
                let (b0, b1) = sb.edge_points(pc.b.index);
                segment_on_face(sa, pc.a.index, pose.apply(b0), pose.apply(b1), tol).map(|x| x.to_vec())
            }
            PcType::EdgeFace => {
                let (a0, a1) = sa.edge_points(pc.a.index);
                let (p, q) = (pose.inverse_apply(a0), pose.inverse_apply(a1));
                segment_on_face(sb, pc.b.index, p, q, tol).map(|x| x.iter().map(|y| pose.apply(*y)).collect())
            }
            PcType::FaceFace => None,
        }
    }

    /// The pair of elements where a PC's contact set lies ([`locate`] on each part, `hold` with the band `clear`);
    /// the PC's own elements for f-f. With the distance from a boundary element the contact set is nearly but not
    /// clearly on, if any.
    pub fn located_pair(&self, pc: &PrincipalContact, pose: &Pose) -> ((Element, Element), Option<f64>) {
        let Some(points) = self.contact_points(pc, pose) else {
            return ((pc.a, pc.b), None);
        };
        let (tol, band) = (self.hold(), self.clear());
        let in_b: Vec<DVec3> = points.iter().map(|p| pose.inverse_apply(*p)).collect();
        let (a, near_a) = locate(&self.fixed.surface, pc.a, &points, tol, band);
        let (b, near_b) = locate(&self.moving.surface, pc.b, &in_b, tol, band);
        ((a, b), near_a.into_iter().chain(near_b).reduce(f64::min))
    }

    /// The state without the PCs that only touch along a boundary where another PC holds (the module's rule), and
    /// the PC (with its distance) whose contact set is nearly but not clearly on a boundary, if any: the rule's
    /// verdict there is ambiguous.
    pub(super) fn without_boundary_contacts(
        &self,
        state: ContactState,
        pose: &Pose,
    ) -> (ContactState, Option<(PrincipalContact, f64)>) {
        if state.pcs.len() < 2 {
            return (state, None);
        }
        let (sa, sb) = (&self.fixed.surface, &self.moving.surface);
        let mut ambiguous: Option<(PrincipalContact, f64)> = None;
        let located: Vec<(Element, Element)> = state
            .pcs
            .iter()
            .map(|pc| {
                let (pair, near) = self.located_pair(pc, pose);
                if let Some(d) = near
                    && ambiguous.is_none_or(|(_, best)| d < best)
                {
                    ambiguous = Some((*pc, d));
                }
                pair
            })
            .collect();
        let pcs = state
            .pcs
            .iter()
            .zip(&located)
            .enumerate()
            .filter(|(i, (pc, own))| {
                let moved = **own != (pc.a, pc.b);
                let covered = located.iter().enumerate().any(|(j, other)| {
                    j != *i && other != *own && sa.is_within(own.0, other.0) && sb.is_within(own.1, other.1)
                });
                !(moved && covered)
            })
            .map(|(_, (pc, _))| *pc)
            .collect();
        (ContactState { pcs }, ambiguous)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_a_segment_by_a_square() {
        let square = [DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0), DVec2::new(1.0, 1.0), DVec2::new(0.0, 1.0)];
        let (lo, hi) = clip_segment(DVec2::new(-1.0, 0.5), DVec2::new(3.0, 0.5), &square, 0.0).expect("crosses");
        assert!((lo - 0.25).abs() < 1e-15 && (hi - 0.5).abs() < 1e-15, "{lo} {hi}");
        // along the boundary line: inside within the tolerance
        let (lo, hi) = clip_segment(DVec2::new(-1.0, 1.0), DVec2::new(3.0, 1.0), &square, 1e-12).expect("on it");
        assert!((lo - 0.25).abs() < 1e-12 && (hi - 0.5).abs() < 1e-12, "{lo} {hi}");
        assert!(clip_segment(DVec2::new(-1.0, 1.1), DVec2::new(3.0, 1.1), &square, 1e-12).is_none());
    }
}
