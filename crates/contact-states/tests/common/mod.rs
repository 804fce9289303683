//! Shared by the tests: an independent check of a contact state at a configuration.

use stackplan_contact_states::criteria::{ContactPart, Weights};
use stackplan_contact_states::pose::{Config, Pose};
use stackplan_contact_states::principal_contact::{ContactState, PrincipalContact};
use stackplan_contact_states::surface::Element;
use stackplan_cspace::interference::{PairContact, PlacedConvex, classify_pair};
use stackplan_geom::{DMat3, DVec3, Part};

/// Independent check of a state at a configuration (parry3d-f64 distances and the c-space crate's interference
/// test, nothing from this crate's criteria): every PC of the state is in contact (element distance within `tol`,
/// and for f-e / e-f / f-f the edge or face lies in the face's plane with, for f-f, opposite normals), no pair of
/// convex pieces penetrates deeper than `tol` (`cspace::interference::classify_pair`), and the PPCs in contact
/// (parry distance within `tol`) map to exactly this state. Returns a description of the first failure.
pub fn independent_check(
    a: &ContactPart,
    a_part: &Part,
    b: &ContactPart,
    b_part: &Part,
    state: &ContactState,
    t: &Config,
    tol: f64,
) -> Result<(), String> {
    use parry3d_f64::math::Pose as PPose;
    use parry3d_f64::query::{PointQuery, distance};
    use parry3d_f64::shape::{Segment, Triangle};
    use stackplan_contact_states::principal_contact::{PcType, all_ppcs};
    use stackplan_contact_states::surface::ElementKind;
    let pose = Pose::from_config(t);
    // world geometry of an element: points, segments, triangles
    enum Geo {
        Point(DVec3),
        Seg(Segment),
        Tris(Vec<Triangle>),
    }
    let geo = |part: &ContactPart, e: Element, moved: bool| -> Geo {
        let s = &part.surface;
        let map = |p: DVec3| if moved { pose.apply(p) } else { p };
        match e.kind {
            ElementKind::Vertex => Geo::Point(map(s.vertices[e.index].position)),
            ElementKind::Edge => {
                let (p, q) = s.edge_points(e.index);
                Geo::Seg(Segment::new(map(p), map(q)))
            }
            ElementKind::Face => Geo::Tris(
                s.face_pieces_3d(e.index)
                    .iter()
                    .flat_map(|poly| (1..poly.len() - 1).map(move |i| (poly[0], poly[i], poly[i + 1])))
                    .map(|(p, q, r)| Triangle::new(map(p), map(q), map(r)))
                    .collect(),
            ),
        }
    };
    let id = PPose::IDENTITY;
    let dist = |x: &Geo, y: &Geo| -> f64 {
        match (x, y) {
            (Geo::Point(p), Geo::Tris(ts)) | (Geo::Tris(ts), Geo::Point(p)) => {
                ts.iter().map(|tr| tr.distance_to_local_point(*p, true)).fold(f64::INFINITY, f64::min)
            }
            (Geo::Seg(s1), Geo::Seg(s2)) => distance(&id, s1, &id, s2).map(|d| d.distance).unwrap_or(f64::INFINITY),
            (Geo::Seg(sg), Geo::Tris(ts)) | (Geo::Tris(ts), Geo::Seg(sg)) => ts
                .iter()
                .map(|tr| distance(&id, sg, &id, tr).map(|d| d.distance).unwrap_or(f64::INFINITY))
                .fold(f64::INFINITY, f64::min),
            (Geo::Tris(t1), Geo::Tris(t2)) => t1
                .iter()
                .flat_map(|x| {
                    t2.iter().map(move |y| distance(&id, x, &id, y).map(|d| d.distance).unwrap_or(f64::INFINITY))
                })
                .fold(f64::INFINITY, f64::min),
            _ => f64::INFINITY,
        }
    };
    let pc_distance = |pc: &PrincipalContact| dist(&geo(a, pc.a, false), &geo(b, pc.b, true));
    // a PC's elements in contact, with the planarity (and for f-f the opposite normals) of the higher PCs
    let (sa, sb) = (&a.surface, &b.surface);
    let off_plane = |plane_normal: DVec3, plane_point: DVec3, pts: &[DVec3]| {
        pts.iter().map(|p| (p - plane_point).dot(plane_normal).abs()).fold(0.0, f64::max)
    };
    let not_flat = |pc: &PrincipalContact| match pc.kind() {
        PcType::FaceEdge => {
            let f = &sa.faces[pc.a.index];
            let (p, q) = sb.edge_points(pc.b.index);
            off_plane(f.plane.normal, sa.vertices[f.vertices[0]].position, &[pose.apply(p), pose.apply(q)])
        }
        PcType::EdgeFace => {
            let f = &sb.faces[pc.b.index];
            let (p, q) = sa.edge_points(pc.a.index);
            let n = pose.apply_vector(f.plane.normal);
            off_plane(n, pose.apply(sb.vertices[f.vertices[0]].position), &[p, q])
        }
        PcType::FaceFace => {
            let (fa, fb) = (&sa.faces[pc.a.index], &sb.faces[pc.b.index]);
            let pts: Vec<DVec3> = fb.vertices.iter().map(|&v| pose.apply(sb.vertices[v].position)).collect();
            let normals =
                (fa.plane.normal + pose.apply_vector(fb.plane.normal)).length() * Weights::for_parts(b).length;
            off_plane(fa.plane.normal, sa.vertices[fa.vertices[0]].position, &pts).max(normals)
        }
        _ => 0.0,
    };
    for pc in &state.pcs {
        let d = pc_distance(pc);
        if d > tol {
            return Err(format!("{} apart by {d:e}", pc.label()));
        }
        let worst = not_flat(pc);
        if worst > tol {
            return Err(format!("{} not flat: {worst:e}", pc.label()));
        }
    }
    // no penetration, by the c-space crate's separating-axis classification
    let (rotation, position) = (pose.rotation, pose.translation);
    for (i, ca) in a_part.components().iter().enumerate() {
        let pa = PlacedConvex::new(ca, DMat3::IDENTITY, DVec3::ZERO);
        for (j, cb) in b_part.components().iter().enumerate() {
            let pb = PlacedConvex::new(cb, rotation, position);
            if let PairContact::Penetrating { depth } = classify_pair(&pa, &pb, tol, 0.0) {
                return Err(format!("pieces {i} and {j} penetrate by {depth:e}"));
            }
        }
    }
    // exactly this state in contact
    let holding: Vec<PrincipalContact> =
        all_ppcs(&a.surface, &b.surface).into_iter().filter(|pc| pc_distance(pc) <= tol).collect();
    // merged PCs only where they hold (the mapping's rules assume contact points in general position)
    let actual = ContactState::canonical_with(holding, sa, sb, |m| pc_distance(m) <= tol && not_flat(m) <= tol);
    if &actual != state {
        return Err(format!("in contact: {} instead", actual.label()));
    }
    Ok(())
}
