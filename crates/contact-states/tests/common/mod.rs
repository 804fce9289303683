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
    let actual = classify(a, a_part, b, b_part, Some(state), t, tol)?;
    if &actual != state {
        return Err(format!("in contact: {} instead", actual.label()));
    }
    Ok(())
}

/// The state in contact at `t`, classified independently (see [`independent_check`]); an error when the parts
/// penetrate.
pub fn independent_state(
    a: &ContactPart,
    a_part: &Part,
    b: &ContactPart,
    b_part: &Part,
    t: &Config,
    tol: f64,
) -> Result<ContactState, String> {
    classify(a, a_part, b, b_part, None, t, tol)
}

/// With `state`, its PCs are checked to hold first.
fn classify(
    a: &ContactPart,
    a_part: &Part,
    b: &ContactPart,
    b_part: &Part,
    state: Option<&ContactState>,
    t: &Config,
    tol: f64,
) -> Result<ContactState, String> {
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
            (Geo::Point(p), Geo::Point(q)) => (*p - *q).length(),
            (Geo::Point(p), Geo::Seg(sg)) | (Geo::Seg(sg), Geo::Point(p)) => sg.distance_to_local_point(*p, true),
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
    for pc in state.iter().flat_map(|s| s.pcs.iter()) {
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
    // the point of an element (world) and the distance of a world point to an element
    let point_distance =
        |part: &ContactPart, e: Element, moved: bool, p: DVec3| -> f64 { dist(&geo(part, e, moved), &Geo::Point(p)) };
    // edges touching at an end point of either touch with a vertex there: no e-e contact
    let crossing_inside = |pc: &PrincipalContact| -> bool {
        if pc.kind() != PcType::EdgeEdge {
            return true;
        }
        let (p0, p1) = sa.edge_points(pc.a.index);
        let (q0, q1) = sb.edge_points(pc.b.index);
        let (s, t) = closest_parameters(p0, p1, pose.apply(q0), pose.apply(q1));
        let (la, lb) = ((p1 - p0).length(), (q1 - q0).length());
        s.min(1.0 - s) * la > tol && t.min(1.0 - t) * lb > tol
    };
    // exactly this state in contact
    let holding: Vec<PrincipalContact> = all_ppcs(&a.surface, &b.surface)
        .into_iter()
        .filter(|pc| pc_distance(pc) <= tol && crossing_inside(pc))
        .collect();
    // merged PCs only where they hold (the mapping's rules assume contact points in general position)
    let merged = ContactState::canonical_with(holding, sa, sb, |m| pc_distance(m) <= tol && not_flat(m) <= tol);
    // contacts only along a convex boundary where another PC holds are no contacts of their own: the contact set
    // (sampled along an edge) located on each part by descending through convex boundary elements
    let contact_set = |pc: &PrincipalContact| -> Option<Vec<DVec3>> {
        let samples = |p: DVec3, q: DVec3| (0..=200).map(move |i| p + (q - p) * (i as f64 / 200.0));
        match pc.kind() {
            PcType::FaceVertex => Some(vec![pose.apply(sb.vertices[pc.b.index].position)]),
            PcType::VertexFace => Some(vec![sa.vertices[pc.a.index].position]),
            PcType::EdgeEdge => {
                let (p0, p1) = sa.edge_points(pc.a.index);
                let (q0, q1) = sb.edge_points(pc.b.index);
                let (q0, q1) = (pose.apply(q0), pose.apply(q1));
                let (s, t) = closest_parameters(p0, p1, q0, q1);
                Some(vec![(p0 + (p1 - p0) * s + q0 + (q1 - q0) * t) * 0.5])
            }
            PcType::FaceEdge => {
                let (q0, q1) = sb.edge_points(pc.b.index);
                let x: Vec<DVec3> = samples(pose.apply(q0), pose.apply(q1))
                    .filter(|p| point_distance(a, pc.a, false, *p) <= tol)
                    .collect();
                (!x.is_empty()).then_some(x)
            }
            PcType::EdgeFace => {
                let (p0, p1) = sa.edge_points(pc.a.index);
                let x: Vec<DVec3> = samples(p0, p1).filter(|p| point_distance(b, pc.b, true, *p) <= tol).collect();
                (!x.is_empty()).then_some(x)
            }
            PcType::FaceFace => None,
        }
    };
    let locate = |part: &ContactPart, e: Element, moved: bool, x: &[DVec3]| -> Element {
        let s = &part.surface;
        let mut current = e;
        loop {
            let boundary: Vec<Element> = match current.kind {
                ElementKind::Face => s.faces[current.index].edges.iter().map(|&i| Element::edge(i)).collect(),
                ElementKind::Edge => s.edges[current.index].vertices.iter().map(|&i| Element::vertex(i)).collect(),
                ElementKind::Vertex => Vec::new(),
            };
            let convex = |e: &Element| match e.kind {
                ElementKind::Edge => s.edges[e.index].convex,
                ElementKind::Vertex => s.vertices[e.index].convex,
                ElementKind::Face => true,
            };
            match boundary
                .into_iter()
                .find(|c| convex(c) && x.iter().all(|p| point_distance(part, *c, moved, *p) <= tol))
            {
                Some(c) => current = c,
                None => return current,
            }
        }
    };
    let located: Vec<(Element, Element)> = merged
        .pcs
        .iter()
        .map(|pc| match contact_set(pc) {
            Some(x) => (locate(a, pc.a, false, &x), locate(b, pc.b, true, &x)),
            None => (pc.a, pc.b),
        })
        .collect();
    let pcs: Vec<PrincipalContact> = merged
        .pcs
        .iter()
        .enumerate()
        .filter(|(i, pc)| {
            let own = located[*i];
            let moved = own != (pc.a, pc.b);
            let covered = located.iter().enumerate().any(|(j, other)| {
                j != *i && *other != own && sa.is_within(own.0, other.0) && sb.is_within(own.1, other.1)
            });
            !(moved && covered)
        })
        .map(|(_, pc)| *pc)
        .collect();
    Ok(ContactState { pcs })
}

/// Parameters `(s, t)` of the closest points of segments `p0 p1` and `q0 q1`: the stationary point of the squared
/// distance when it lies inside the unit square, else the best of the four edges of the square (each a point against
/// a segment, by clamped projection).
pub fn closest_parameters(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> (f64, f64) {
    let (u, v, w) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, b, c, d, e) = (u.dot(u), u.dot(v), v.dot(v), u.dot(w), v.dot(w));
    let det = a * c - b * b;
    if det > 1e-12 * a * c {
        let s = (b * e - c * d) / det;
        let t = (a * e - b * d) / det;
        if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) {
            return (s, t);
        }
    }
    let on = |x: DVec3, o: DVec3, dir: DVec3| {
        let l = dir.dot(dir);
        if l > 0.0 { ((x - o).dot(dir) / l).clamp(0.0, 1.0) } else { 0.0 }
    };
    let candidates = [(0.0, on(p0, q0, v)), (1.0, on(p1, q0, v)), (on(q0, p0, u), 0.0), (on(q1, p0, u), 1.0)];
    candidates
        .into_iter()
        .min_by(|x, y| {
            let d = |(s, t): (f64, f64)| ((p0 + u * s) - (q0 + v * t)).length();
            d(*x).total_cmp(&d(*y))
        })
        .unwrap_or((0.0, 0.0))
}
