//! Contact-state criteria (\[P\] II-A..C): feature criteria `h_PC(T) >= 0`, zero exactly when the PC holds, the
//! non-penetration term `d_G(T)` from the growth distance, and the objective of \[P\] eq. 8.
//!
//! All criteria are evaluated in the coordinates of the part that owns the face (the fixed part A for f-v, f-e, f-f;
//! the moving part B, through the inverse pose, for v-f, e-f), so face polygons never need transforming.
//! Each criterion is `h = W1 h1 + W2 h2` (\[P\] eq. 3) with an *intersection* condition `h1` and a *bounding*
//! condition `h2`, both lengths in millimetres (angles enter multiplied by the characteristic length `L`):
//!
//! * f-v (face F, vertex p): `h1 = |n.p - d|` (distance to the face plane); `h2 = dist_2(pi(p), F)`, the in-plane
//!   distance from the projection of p to the face polygon (0 when inside). Both vanish iff p lies on the closed face.
//! * v-f: the same with the roles exchanged.
//! * e-e (segments `a0 + s da`, `b0 + t db`): `h1` = distance between the carrier lines (at the closest points
//!   `s*, t*`, from `[[da.da, -da.db], [da.db, -db.db]] (s, t) = (-da.r, -db.r)`, `r = a0 - b0`); `h2 = |da| dist(s*,
//!   [0,1]) + |db| dist(t*, [0,1])`, how far the closest points lie outside the segments. Both vanish iff the
//!   segments meet. Parallel carriers: `h1` = distance of `b0` from line a, `h2` = gap between the projected intervals.
//! * f-e (face F, segment b0 b1): `h1 = |n.b0 - d| + |n.b1 - d|` (zero iff the whole edge line lies in the plane);
//!   `h2` = in-plane distance between the projected segment and the face polygon (0 iff they meet).
//! * e-f: the same with the roles exchanged.
//! * f-f (faces F of A, G of B): `h1 = L |n_F + n_G| + |n_F.c_G - d_F|` (anti-parallel normals and the centroid `c_G`
//!   of G on F's plane: together zero iff G lies in F's plane facing it); `h2` = in-plane distance between F and the
//!   projection of G (0 iff they overlap).
//!
//! `W1 = W2 = 1` (the paper leaves the weights to the implementer; with every term already a length, unit weights keep
//! the feature criteria comparable between PC types, and the feasibility threshold is one length).
//! Non-penetration: `d_G = sum over convex piece pairs of max(0, 1 - sigma)` with `sigma` the growth distance
//! ([`crate::growth_distance`](fn@crate::growth_distance)), weighted by `W3 = L`. The objective of eq. 8 is
//! `f = sum h_PC + W3 d_G`. The bounded-misalignment criterion (eq. 7) is enforced by the optimiser keeping `t` in its
//! box.
//! Cost per evaluation: O(size of the PC's elements) per PC plus one growth distance per piece pair whose bounding
//! boxes overlap.

use crate::growth_distance::{ConvexPiece, growth_distance_capped};
use crate::pose::{Config, Pose};
use crate::principal_contact::{ContactState, PcType, PrincipalContact};
use crate::surface::{SurfaceElements, SurfaceError, SurfaceFace};
use stackplan_geom::{DVec2, DVec3, Part};

/// One part as the contact analysis sees it: surface elements for the feature criteria and convex pieces for
/// non-penetration.
#[derive(Debug, Clone)]
pub struct ContactPart {
    /// Name (for reports).
    pub name: String,
    /// Surface elements of the boundary.
    pub surface: SurfaceElements,
    /// Convex pieces whose union is the part.
    pub pieces: Vec<ConvexPiece>,
    /// Per face, its convex pieces as 3-D polygons (own coordinates).
    pub face_polygons: Vec<Vec<Vec<DVec3>>>,
    /// Per face, the mean of its polygon vertices.
    pub face_centres: Vec<DVec3>,
    /// Per face, its name where the part's faces have names ([`crate::features::face_names`]).
    pub face_names: Vec<Option<String>>,
}

impl ContactPart {
    /// From a geometry-kernel part (its components are the convex pieces).
    pub fn from_part(part: &Part) -> Result<Self, SurfaceError> {
        let surface = SurfaceElements::from_part(part)?;
        let pieces = part.components().iter().map(ConvexPiece::from_polytope).collect();
        let names = crate::features::face_names(part, &surface);
        Ok(Self { face_names: names, ..Self::new(part.name.clone(), surface, pieces) })
    }

    /// From a surface and its convex pieces.
    pub fn new(name: String, surface: SurfaceElements, pieces: Vec<ConvexPiece>) -> Self {
        let face_polygons: Vec<Vec<Vec<DVec3>>> = (0..surface.faces.len()).map(|f| surface.face_pieces_3d(f)).collect();
        let face_centres = face_polygons
            .iter()
            .map(|ps| {
                let n = ps.iter().map(Vec::len).sum::<usize>().max(1);
                ps.iter().flatten().copied().sum::<DVec3>() / n as f64
            })
            .collect();
        let face_names = vec![None; surface.faces.len()];
        Self { name, surface, pieces, face_polygons, face_centres, face_names }
    }

    /// Bounding box of the pieces.
    pub fn aabb(&self) -> (DVec3, DVec3) {
        self.pieces
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p.aabb.0), hi.max(p.aabb.1)))
    }
}

/// Weights of the criteria.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Weights {
    /// `W1`, intersection conditions.
    pub intersection: f64,
    /// `W2`, bounding conditions.
    pub bounding: f64,
    /// `L`: characteristic length multiplying angular terms, and `W3` (non-penetration weight).
    pub length: f64,
}

impl Weights {
    /// Unit weights and `L` = the bounding-box diagonal of the moving part (at least 1 mm).
    pub fn for_parts(moving: &ContactPart) -> Self {
        let (lo, hi) = moving.aabb();
        Self { intersection: 1.0, bounding: 1.0, length: (hi - lo).length().max(1.0) }
    }
}

/// Distance from `p` to a convex counter-clockwise polygon (0 inside).
pub fn point_polygon_distance(p: DVec2, poly: &[DVec2]) -> f64 {
    let n = poly.len();
    // inside (the usual case at a contact) costs one cross product per edge; distances only when outside
    let mut prev = match poly.last() {
        Some(&v) => v,
        None => return 0.0,
    };
    let mut inside = true;
    for &a in poly {
        if (a - prev).perp_dot(p - prev) < 0.0 {
            inside = false;
            break;
        }
        prev = a;
    }
    if inside {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for i in 0..n {
        best = best.min(point_segment_distance(p, poly[i], poly[(i + 1) % n]));
    }
    best
}

fn point_segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let l2 = d.length_squared();
    let t = if l2 > 0.0 { ((p - a).dot(d) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (a + d * t - p).length()
}

fn segments_intersect(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let o = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let (d1, d2, d3, d4) = (o(c, d, a), o(c, d, b), o(a, b, c), o(a, b, d));
    ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
}

fn segment_segment_distance_2d(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> f64 {
    if segments_intersect(a, b, c, d) {
        return 0.0;
    }
    point_segment_distance(a, c, d)
        .min(point_segment_distance(b, c, d))
        .min(point_segment_distance(c, a, b))
        .min(point_segment_distance(d, a, b))
}

/// Distance from segment `ab` to a convex counter-clockwise polygon (0 when they meet).
pub fn segment_polygon_distance(a: DVec2, b: DVec2, poly: &[DVec2]) -> f64 {
    let n = poly.len();
    let mut best = point_polygon_distance(a, poly).min(point_polygon_distance(b, poly));
    for i in 0..n {
        if best == 0.0 {
            break;
        }
        best = best.min(segment_segment_distance_2d(a, b, poly[i], poly[(i + 1) % n]));
    }
    best
}

/// Distance between two convex counter-clockwise polygons (0 when they overlap or touch).
pub fn polygon_polygon_distance(p: &[DVec2], q: &[DVec2]) -> f64 {
    let mut best = f64::INFINITY;
    for i in 0..p.len() {
        best = best.min(segment_polygon_distance(p[i], p[(i + 1) % p.len()], q));
        if best == 0.0 {
            return 0.0;
        }
    }
    // q inside p entirely
    if let Some(&v) = q.first() {
        best = best.min(point_polygon_distance(v, p));
    }
    best
}

/// In-plane distance from `p` (face-frame coordinates) to the face's region (0 inside).
pub fn face_point_distance_2d(face: &SurfaceFace, p: DVec2) -> f64 {
    face.pieces.iter().map(|poly| point_polygon_distance(p, poly)).fold(f64::INFINITY, f64::min)
}

fn face_segment_distance(face: &SurfaceFace, a: DVec2, b: DVec2) -> f64 {
    face.pieces.iter().map(|poly| segment_polygon_distance(a, b, poly)).fold(f64::INFINITY, f64::min)
}

/// `(h1, h2)` of a face against a point given in the face's part coordinates.
pub fn face_vertex_terms(face: &SurfaceFace, p: DVec3) -> (f64, f64) {
    (face.frame.height(p).abs(), face_point_distance_2d(face, face.frame.to_2d(p)))
}

/// `(h1, h2)` of a face against a segment given in the face's part coordinates.
pub fn face_edge_terms(face: &SurfaceFace, b0: DVec3, b1: DVec3) -> (f64, f64) {
    let h1 = face.frame.height(b0).abs() + face.frame.height(b1).abs();
    (h1, face_segment_distance(face, face.frame.to_2d(b0), face.frame.to_2d(b1)))
}

/// `(h1, h2)` of two segments crossing (same coordinates for both).
pub fn edge_edge_terms(a0: DVec3, a1: DVec3, b0: DVec3, b1: DVec3) -> (f64, f64) {
    let da = a1 - a0;
    let db = b1 - b0;
    let r = a0 - b0;
    let (aa, ab, bb) = (da.dot(da), da.dot(db), db.dot(db));
    let (d, e) = (da.dot(r), db.dot(r));
    let den = aa * bb - ab * ab;
    let outside = |s: f64| (-s).max(s - 1.0).max(0.0);
    if den > 1e-14 * aa * bb {
        let s = (ab * e - bb * d) / den;
        let t = (aa * e - ab * d) / den;
        let h1 = ((a0 + da * s) - (b0 + db * t)).length();
        let h2 = aa.sqrt() * outside(s) + bb.sqrt() * outside(t);
        (h1, h2)
    } else {
        let u = da / aa.sqrt();
        let w = b0 - a0;
        let h1 = (w - u * w.dot(u)).length();
        let (t0, t1) = (w.dot(u), (b1 - a0).dot(u));
        let (lo, hi) = (t0.min(t1), t0.max(t1));
        let len = aa.sqrt();
        let h2 = (lo - len).max(-hi).max(0.0);
        (h1, h2)
    }
}

/// `(h1, h2)` of face `fa` of A against face `fb` of B, where `to_a` maps B's coordinates into A's.
pub fn face_face_terms(a: &ContactPart, fa: usize, b: &ContactPart, fb: usize, to_a: &Pose, length: f64) -> (f64, f64) {
    let face = &a.surface.faces[fa];
    let nb = to_a.apply_vector(b.surface.faces[fb].plane.normal);
    let cb = to_a.apply(b.face_centres[fb]);
    let h1 = length * (face.plane.normal + nb).length() + face.frame.height(cb).abs();
    let mut h2 = f64::INFINITY;
    for poly_b in &b.face_polygons[fb] {
        let mut projected: Vec<DVec2> = poly_b.iter().map(|p| face.frame.to_2d(to_a.apply(*p))).collect();
        // seen from A's face, B's face (facing it) runs clockwise: reverse to keep counter-clockwise
        if crate::surface::polygon_area(&projected) < 0.0 {
            projected.reverse();
        }
        for poly_a in &face.pieces {
            h2 = h2.min(polygon_polygon_distance(poly_a, &projected));
        }
    }
    (h1, h2)
}

/// The feature criterion `h_PC(T) = W1 h1 + W2 h2` (\[P\] eq. 3) of `pc` at pose `pose` of the moving part B.
pub fn pc_criterion(pc: &PrincipalContact, a: &ContactPart, b: &ContactPart, pose: &Pose, w: &Weights) -> f64 {
    let (h1, h2) = pc_terms(pc, a, b, pose, w.length);
    w.intersection * h1 + w.bounding * h2
}

/// The intersection and bounding terms `(h1, h2)` of `pc` at `pose`.
pub fn pc_terms(pc: &PrincipalContact, a: &ContactPart, b: &ContactPart, pose: &Pose, length: f64) -> (f64, f64) {
    let (sa, sb) = (&a.surface, &b.surface);
    match pc.kind() {
        PcType::FaceVertex => face_vertex_terms(&sa.faces[pc.a.index], pose.apply(sb.vertices[pc.b.index].position)),
        PcType::VertexFace => {
            face_vertex_terms(&sb.faces[pc.b.index], pose.inverse_apply(sa.vertices[pc.a.index].position))
        }
        PcType::EdgeEdge => {
            let (a0, a1) = sa.edge_points(pc.a.index);
            let (b0, b1) = sb.edge_points(pc.b.index);
            edge_edge_terms(a0, a1, pose.apply(b0), pose.apply(b1))
        }
        PcType::FaceEdge => {
            let (b0, b1) = sb.edge_points(pc.b.index);
            face_edge_terms(&sa.faces[pc.a.index], pose.apply(b0), pose.apply(b1))
        }
        PcType::EdgeFace => {
            let (a0, a1) = sa.edge_points(pc.a.index);
            face_edge_terms(&sb.faces[pc.b.index], pose.inverse_apply(a0), pose.inverse_apply(a1))
        }
        PcType::FaceFace => face_face_terms(a, pc.a.index, b, pc.b.index, pose, length),
    }
}

/// The penetration measure `d_G = sum over piece pairs of max(0, 1 - sigma)` (\[P\] eq. 5 with Ong-Gilbert growth
/// distances), zero iff no pair of convex pieces penetrates.
pub fn penetration(a: &ContactPart, b: &ContactPart, pose: &Pose) -> f64 {
    thread_local! {
        // the moved piece's buffers, reused: no allocation per evaluation
        static MOVED: std::cell::RefCell<Option<ConvexPiece>> = const { std::cell::RefCell::new(None) };
    }
    MOVED.with(|cell| {
        let mut moved = cell.borrow_mut();
        penetration_with(a, b, pose, &mut moved)
    })
}

fn penetration_with(a: &ContactPart, b: &ContactPart, pose: &Pose, moved: &mut Option<ConvexPiece>) -> f64 {
    let mut total = 0.0;
    for pb in &b.pieces {
        let m = moved.get_or_insert_with(|| pb.clone());
        pb.transform_into(pose, m);
        for pa in &a.pieces {
            let (alo, ahi) = pa.aabb;
            let (blo, bhi) = m.aabb;
            if alo.cmpgt(bhi).any() || blo.cmpgt(ahi).any() {
                continue;
            }
            // capped at 1: only penetrating pairs need the exact value. (Counting pairs within 1e-12 of sigma = 1 as
            // touching would end more enumerations early, but the GA's polish works at that level: the free-rotation
            // cube test then loses states.)
            total += (1.0 - growth_distance_capped(pa, pa.seed, m, m.seed, 1.0)).max(0.0);
        }
    }
    total
}

/// The objective of \[P\] eq. 8 for a hypothesised state: `f(T) = sum h_PC(T) + W3 d_G(T)` with `W3 = L`.
#[derive(Debug, Clone, Copy)]
pub struct Objective<'a> {
    /// Fixed part A.
    pub fixed: &'a ContactPart,
    /// Moving part B.
    pub moving: &'a ContactPart,
    /// The PCs that must hold.
    pub state: &'a ContactState,
    /// Weights.
    pub weights: Weights,
}

impl Objective<'_> {
    /// `f(t)`.
    pub fn value(&self, t: &Config) -> f64 {
        let pose = Pose::from_config(t);
        let h: f64 =
            self.state.pcs.iter().map(|pc| pc_criterion(pc, self.fixed, self.moving, &pose, &self.weights)).sum();
        h + self.weights.length * penetration(self.fixed, self.moving, &pose)
    }

    /// The smooth companion used by the local polish: `sum (W1 h1)^2 + (W2 h2)^2 + (W3 d_G)^2`, zero exactly where
    /// `f` is (every term of `f` is non-negative).
    pub fn smooth_value(&self, t: &Config) -> f64 {
        let pose = Pose::from_config(t);
        let w = &self.weights;
        let h: f64 = self
            .state
            .pcs
            .iter()
            .map(|pc| {
                let (h1, h2) = pc_terms(pc, self.fixed, self.moving, &pose, w.length);
                (w.intersection * h1).powi(2) + (w.bounding * h2).powi(2)
            })
            .sum();
        h + (w.length * penetration(self.fixed, self.moving, &pose)).powi(2)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::surface::Element;
    use stackplan_geom::convex_hull;

    pub(crate) fn box_part(name: &str, lo: DVec3, hi: DVec3) -> ContactPart {
        let pts: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect();
        let poly = convex_hull(&pts).expect("box").polytope;
        let part =
            Part::from_components(name, vec![poly], 1.0, stackplan_geom::PartOrigin::ConvexPieces).expect("part");
        ContactPart::from_part(&part).expect("surface")
    }

    fn find_face(p: &ContactPart, normal: DVec3) -> usize {
        p.surface.faces.iter().position(|f| (f.plane.normal - normal).length() < 1e-12).expect("face")
    }

    fn find_vertex(p: &ContactPart, at: DVec3) -> usize {
        p.surface.vertices.iter().position(|v| (v.position - at).length() < 1e-12).expect("vertex")
    }

    fn find_edge(p: &ContactPart, a: DVec3, b: DVec3) -> usize {
        p.surface
            .edges
            .iter()
            .position(|e| {
                let (x, y) = (p.surface.vertices[e.vertices[0]].position, p.surface.vertices[e.vertices[1]].position);
                ((x - a).length() < 1e-12 && (y - b).length() < 1e-12)
                    || ((x - b).length() < 1e-12 && (y - a).length() < 1e-12)
            })
            .expect("edge")
    }

    #[test]
    fn polygon_distances() {
        let sq = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        assert_eq!(point_polygon_distance(DVec2::splat(0.5), &sq), 0.0);
        assert!((point_polygon_distance(DVec2::new(2.0, 0.5), &sq) - 1.0).abs() < 1e-15);
        assert!((point_polygon_distance(DVec2::new(2.0, 2.0), &sq) - 2f64.sqrt()).abs() < 1e-15);
        assert_eq!(segment_polygon_distance(DVec2::new(-1.0, 0.5), DVec2::new(2.0, 0.5), &sq), 0.0);
        assert!((segment_polygon_distance(DVec2::new(-1.0, 2.0), DVec2::new(2.0, 2.0), &sq) - 1.0).abs() < 1e-15);
        let far: Vec<DVec2> = sq.iter().map(|p| *p + DVec2::new(3.0, 0.0)).collect();
        assert!((polygon_polygon_distance(&sq, &far) - 2.0).abs() < 1e-15);
        let inner: Vec<DVec2> = sq.iter().map(|p| *p * 0.2 + DVec2::splat(0.4)).collect();
        assert_eq!(polygon_polygon_distance(&sq, &inner), 0.0);
        assert_eq!(polygon_polygon_distance(&inner, &sq), 0.0);
    }

    /// A 10-cube fixed at [0,10]^3 and a unit cube [0,1]^3 moving.
    fn parts() -> (ContactPart, ContactPart) {
        (box_part("A", DVec3::ZERO, DVec3::splat(10.0)), box_part("B", DVec3::ZERO, DVec3::ONE))
    }

    #[test]
    fn face_vertex_known_values() {
        let (a, b) = parts();
        let top = find_face(&a, DVec3::Z);
        let v0 = find_vertex(&b, DVec3::ZERO);
        let pc = PrincipalContact::new(Element::face(top), Element::vertex(v0)).expect("pc");
        let w = Weights::for_parts(&b);
        // vertex on the top face, inside: both zero
        let on = Pose::from_config(&[3.0, 4.0, 10.0, 0.3, 0.2, 0.1]);
        assert!(pc_criterion(&pc, &a, &b, &on, &w) < 1e-12);
        // 2 above the face, inside: h1 = 2, h2 = 0
        let (h1, h2) = pc_terms(&pc, &a, &b, &Pose::from_config(&[3.0, 4.0, 12.0, 0.0, 0.0, 0.0]), w.length);
        assert!((h1 - 2.0).abs() < 1e-12 && h2 == 0.0);
        // on the plane but 3 beyond the face's edge x = 10: h1 = 0, h2 = 3
        let (h1, h2) = pc_terms(&pc, &a, &b, &Pose::from_config(&[13.0, 4.0, 10.0, 0.0, 0.0, 0.0]), w.length);
        assert!(h1.abs() < 1e-12 && (h2 - 3.0).abs() < 1e-12);
        // v-f: A's corner (10,10,10) against B's bottom face (z = 0 of B), B placed with that corner inside it
        let va = find_vertex(&a, DVec3::splat(10.0));
        let fb = find_face(&b, -DVec3::Z);
        let vf = PrincipalContact::new(Element::vertex(va), Element::face(fb)).expect("pc");
        let pose = Pose::from_config(&[9.5, 9.5, 10.0, 0.0, 0.0, 0.0]);
        assert!(pc_criterion(&vf, &a, &b, &pose, &w) < 1e-12);
        let (h1, h2) = pc_terms(&vf, &a, &b, &Pose::from_config(&[11.0, 9.5, 10.5, 0.0, 0.0, 0.0]), w.length);
        assert!((h1 - 0.5).abs() < 1e-12 && (h2 - 1.0).abs() < 1e-12, "{h1} {h2}");
    }

    #[test]
    fn edge_edge_known_values() {
        // crossing segments: x-axis segment and a y-direction segment 2 above, crossing over it
        let (h1, h2) = edge_edge_terms(DVec3::ZERO, DVec3::X, DVec3::new(0.5, -1.0, 2.0), DVec3::new(0.5, 1.0, 2.0));
        assert!((h1 - 2.0).abs() < 1e-15 && h2.abs() < 1e-15);
        // touching
        let (h1, h2) = edge_edge_terms(DVec3::ZERO, DVec3::X, DVec3::new(0.5, -1.0, 0.0), DVec3::new(0.5, 1.0, 0.0));
        assert!(h1 < 1e-15 && h2 < 1e-15);
        // lines cross but b's segment stops 1.5 short of the crossing point (t* = -1.5/0.5... length 0.5)
        let (h1, h2) = edge_edge_terms(DVec3::ZERO, DVec3::X, DVec3::new(0.5, 1.5, 0.0), DVec3::new(0.5, 2.0, 0.0));
        assert!(h1 < 1e-15 && (h2 - 1.5).abs() < 1e-12, "{h2}");
        // and a's segment is 1 short as well
        let (_, h2) = edge_edge_terms(DVec3::ZERO, DVec3::X, DVec3::new(2.0, 1.5, 0.0), DVec3::new(2.0, 2.0, 0.0));
        assert!((h2 - 2.5).abs() < 1e-12, "{h2}");
        // parallel: distance between the lines and gap of the intervals
        let (h1, h2) = edge_edge_terms(DVec3::ZERO, DVec3::X, DVec3::new(3.0, 1.0, 0.0), DVec3::new(4.0, 1.0, 0.0));
        assert!((h1 - 1.0).abs() < 1e-15 && (h2 - 2.0).abs() < 1e-15);
    }

    #[test]
    fn face_edge_and_face_face_known_values() {
        let (a, b) = parts();
        let w = Weights::for_parts(&b);
        let top = find_face(&a, DVec3::Z);
        let e = find_edge(&b, DVec3::ZERO, DVec3::X);
        let fe = PrincipalContact::new(Element::face(top), Element::edge(e)).expect("pc");
        // B rotated 0.3 about x around its origin: the edge along x stays at z = 0 of B -> lies on the top face
        let pose = Pose::from_config(&[2.0, 2.0, 10.0, 0.3, 0.0, 0.0]);
        assert!(pc_criterion(&fe, &a, &b, &pose, &w) < 1e-12);
        // tilt about y by a small angle: one end rises by sin(angle)
        let ang: f64 = 0.1;
        let (h1, h2) = pc_terms(&fe, &a, &b, &Pose::from_config(&[2.0, 2.0, 10.0, 0.0, -ang, 0.0]), w.length);
        assert!((h1 - ang.sin()).abs() < 1e-12 && h2 == 0.0, "{h1}");
        // f-f: B's bottom face on A's top face
        let fb = find_face(&b, -DVec3::Z);
        let ff = PrincipalContact::new(Element::face(top), Element::face(fb)).expect("pc");
        assert!(pc_criterion(&ff, &a, &b, &Pose::from_config(&[2.0, 2.0, 10.0, 0.0, 0.0, 0.7]), &w) < 1e-12);
        // lifted by 1 and 4 beyond the x edge (B spans x in [14, 15], A ends at 10)
        let (h1, h2) = pc_terms(&ff, &a, &b, &Pose::from_config(&[14.0, 2.0, 11.0, 0.0, 0.0, 0.0]), w.length);
        assert!((h1 - 1.0).abs() < 1e-12 && (h2 - 4.0).abs() < 1e-12, "{h1} {h2}");
        // flipped upside down (B's bottom face now faces up, 1 above A's top): normals parallel -> 2 L + 1
        let (h1, _) =
            pc_terms(&ff, &a, &b, &Pose::from_config(&[2.0, 2.0, 11.0, std::f64::consts::PI, 0.0, 0.0]), w.length);
        assert!((h1 - 2.0 * w.length - 1.0).abs() < 1e-9, "{h1}");
        // e-f: A's top edge along y at x = 10 against B's bottom face
        let ea = find_edge(&a, DVec3::new(10.0, 0.0, 10.0), DVec3::new(10.0, 10.0, 10.0));
        let ef = PrincipalContact::new(Element::edge(ea), Element::face(fb)).expect("pc");
        assert!(pc_criterion(&ef, &a, &b, &Pose::from_config(&[9.5, 3.0, 10.0, 0.0, 0.0, 0.0]), &w) < 1e-12);
        let (h1, h2) = pc_terms(&ef, &a, &b, &Pose::from_config(&[12.0, 3.0, 10.0, 0.0, 0.0, 0.0]), w.length);
        assert!(h1 < 1e-12 && (h2 - 2.0).abs() < 1e-12, "{h1} {h2}");
    }

    #[test]
    fn penetration_measure() {
        let (a, b) = parts();
        assert_eq!(penetration(&a, &b, &Pose::from_config(&[2.0, 2.0, 10.0, 0.0, 0.0, 0.0])), 0.0);
        assert_eq!(penetration(&a, &b, &Pose::from_config(&[2.0, 2.0, 30.0, 0.0, 0.0, 0.0])), 0.0);
        let deep = penetration(&a, &b, &Pose::from_config(&[2.0, 2.0, 9.0, 0.0, 0.0, 0.0]));
        // seeds (5,5,5) and (2.5,2.5,9.5): the z faces limit: sigma = 4.5 / (5 + 0.5) -> 1 - sigma = 1/11
        assert!((deep - (1.0 - 4.5 / 5.5)).abs() < 1e-12, "{deep}");
    }
}
