//! Principal contacts (PCs), primitive principal contacts (PPCs) and contact states (\[P\] I-A, II steps 1-3, IV-A).
//!
//! A PC is a pair of surface elements in contact, one of the fixed part **A** and one of the moving part **B**
//! (the paper's `se^A - se^B`, e.g. `f2-v3` = face 2 of A touches vertex 3 of B), that are not boundaries of other
//! elements in contact. Six types are non-degenerate: f-v, v-f, e-e (crossing), f-e, e-f, f-f. PPCs are the
//! one-point contacts f-v, v-f, e-e. A contact state is a set of PCs; its *level* is the number of point contacts it
//! stands for (f-v, v-f, e-e: 1; f-e, e-f: 2; f-f: 3), the amount of kinematic constraint.
//!
//! **Highest-level description** (\[P\] II step 3). Combining a state with a PPC can describe the same contact with
//! lower-level PCs; the mapping replaces two PCs `(x1, y1)`, `(x2, y2)` by `(X, Y)` with `X = join(x1, x2)`,
//! `Y = join(y1, y2)` (the lowest element having both within it, see [`SurfaceElements::join`]) when `(X, Y)` is f-e,
//! e-f or f-f and the contact points force it:
//! * f-e / e-f: the two contacts give two distinct points of the edge on the face's plane, so the edge lies in it
//!   (two f-v at the ends of one edge -> f-e; an e-e plus an f-v with the edge of A on the face and the vertex of B on
//!   the edge -> f-e);
//! * f-f: at least three contact points (an f-e plus an f-v on the same face, two f-e, an f-e plus an e-f), or two
//!   point contacts of the same face with two elements of one face of the other part that share no edge: the chord
//!   between them crosses that face's interior, and with non-penetration the face must lie flat (a cube touching a
//!   plane with two diagonal corners lies on its face).
//!
//! The rules assume contact points in general position. At a known configuration a merge is made only when the merged
//! PC holds there ([`ContactState::canonical_with`] with its criterion): collinear points force coplanar faces with
//! *equal* normals together (the side faces of two aligned stacked cubes, touching only along a common edge line), and
//! an e-e contact at an edge's end is the same point as that end's vertex contact; neither makes an f-f or f-e PC.
//! Without a configuration (the hypotheses of the ACSG) f-f merges are made only for faces that can face each other
//! within the box ([`crate::acsg::can_face`]).
//!
//! Then PCs whose elements both lie within another PC's elements are dropped (they are not principal).
//!
//! **Neighbours** (\[P\] IV-A): `pa` is a close less constrained neighbour (CLCN) PC of `pb` when one element is the
//! same and the other element of `pa` is on the immediate boundary of that of `pb`. State `a` is a CLCN of state `b`
//! when they have equally many PCs and differ in one pair `pa`, `pb` with `pa` a CLCN PC of `pb`, or when `b` has one
//! more PC, a PPC, and contains `a`. Costs: the mapping is O(k^2) joins per pass for k PCs.

use crate::surface::{Element, ElementKind, SurfaceElements};
use serde::{Deserialize, Serialize};

/// The six non-degenerate PC types, named fixed-part element first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum PcType {
    /// Face of A, vertex of B.
    #[serde(rename = "f-v")]
    FaceVertex,
    /// Vertex of A, face of B.
    #[serde(rename = "v-f")]
    VertexFace,
    /// Crossing edges.
    #[serde(rename = "e-e")]
    EdgeEdge,
    /// Face of A, edge of B.
    #[serde(rename = "f-e")]
    FaceEdge,
    /// Edge of A, face of B.
    #[serde(rename = "e-f")]
    EdgeFace,
    /// Face of A, face of B.
    #[serde(rename = "f-f")]
    FaceFace,
}

impl PcType {
    /// The type of a pair of element kinds, `None` for the degenerate ones (v-v, v-e, e-v).
    pub fn of(a: ElementKind, b: ElementKind) -> Option<Self> {
        use ElementKind::*;
        match (a, b) {
            (Face, Vertex) => Some(Self::FaceVertex),
            (Vertex, Face) => Some(Self::VertexFace),
            (Edge, Edge) => Some(Self::EdgeEdge),
            (Face, Edge) => Some(Self::FaceEdge),
            (Edge, Face) => Some(Self::EdgeFace),
            (Face, Face) => Some(Self::FaceFace),
            _ => None,
        }
    }

    /// Number of point contacts it stands for (the level of a one-PC state).
    pub fn points(self) -> usize {
        match self {
            Self::FaceVertex | Self::VertexFace | Self::EdgeEdge => 1,
            Self::FaceEdge | Self::EdgeFace => 2,
            Self::FaceFace => 3,
        }
    }

    /// The paper's short name.
    pub fn name(self) -> &'static str {
        match self {
            Self::FaceVertex => "f-v",
            Self::VertexFace => "v-f",
            Self::EdgeEdge => "e-e",
            Self::FaceEdge => "f-e",
            Self::EdgeFace => "e-f",
            Self::FaceFace => "f-f",
        }
    }
}

/// A principal contact: element `a` of the fixed part A against element `b` of the moving part B.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct PrincipalContact {
    /// Element of the fixed part A.
    pub a: Element,
    /// Element of the moving part B.
    pub b: Element,
}

impl PrincipalContact {
    /// A PC; `None` for a degenerate pair of kinds.
    pub fn new(a: Element, b: Element) -> Option<Self> {
        PcType::of(a.kind, b.kind).map(|_| Self { a, b })
    }

    /// Its type.
    pub fn kind(&self) -> PcType {
        // invariant: constructed through `new` or from a valid join
        PcType::of(self.a.kind, self.b.kind).unwrap_or(PcType::FaceFace)
    }

    /// Whether it is a primitive (one-point, 5-DOF) contact.
    pub fn is_ppc(&self) -> bool {
        self.kind().points() == 1
    }

    /// Label such as `f2-v3`.
    pub fn label(&self) -> String {
        format!("{}-{}", self.a.label(), self.b.label())
    }

    /// Whether both elements lie within those of `other`.
    pub fn is_within(&self, other: &Self, sa: &SurfaceElements, sb: &SurfaceElements) -> bool {
        sa.is_within(self.a, other.a) && sb.is_within(self.b, other.b)
    }
}

/// All PPCs between two surfaces: faces against convex vertices (f-v, v-f) and convex edges against convex edges
/// that are not parallel (e-e). Concave elements cannot make a non-degenerate one-point contact.
pub fn all_ppcs(sa: &SurfaceElements, sb: &SurfaceElements) -> Vec<PrincipalContact> {
    let mut out = Vec::new();
    for f in 0..sa.faces.len() {
        for (v, vert) in sb.vertices.iter().enumerate() {
            if vert.convex {
                out.push(PrincipalContact { a: Element::face(f), b: Element::vertex(v) });
            }
        }
    }
    for (v, vert) in sa.vertices.iter().enumerate() {
        if vert.convex {
            for f in 0..sb.faces.len() {
                out.push(PrincipalContact { a: Element::vertex(v), b: Element::face(f) });
            }
        }
    }
    // parallel edges can cross after a rotation, so every pair of convex edges is a candidate
    for (i, ea) in sa.edges.iter().enumerate() {
        for (j, eb) in sb.edges.iter().enumerate() {
            if ea.convex && eb.convex {
                out.push(PrincipalContact { a: Element::edge(i), b: Element::edge(j) });
            }
        }
    }
    out
}

/// A contact state: a sorted set of PCs in highest-level form.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct ContactState {
    /// The PCs, sorted.
    pub pcs: Vec<PrincipalContact>,
}

impl ContactState {
    /// The state of one PC.
    pub fn single(pc: PrincipalContact) -> Self {
        Self { pcs: vec![pc] }
    }

    /// The highest-level description of a combination of PCs (see the module docs), merging wherever the contact
    /// points force it (no configuration known). At a known configuration use [`Self::canonical_with`].
    pub fn canonical(pcs: Vec<PrincipalContact>, sa: &SurfaceElements, sb: &SurfaceElements) -> Self {
        Self::canonical_with(pcs, sa, sb, |_| true)
    }

    /// [`Self::canonical`], making a merged PC only when `accept` says it can hold (at a configuration: its
    /// criterion vanishes). The rules assume contact points in general position; at a degenerate configuration they
    /// can name a PC that does not hold: two aligned stacked cubes touch along the common edge lines of their side
    /// faces, whose points force those coplanar faces together, but the faces' normals are equal, not opposite (no
    /// f-f contact); an e-e contact at the end of an edge is the same point as that end's vertex contact, not a
    /// second point of the edge (no f-e / e-f contact).
    pub fn canonical_with<F>(
        mut pcs: Vec<PrincipalContact>,
        sa: &SurfaceElements,
        sb: &SurfaceElements,
        accept: F,
    ) -> Self
    where
        F: Fn(&PrincipalContact) -> bool,
    {
        pcs.sort();
        pcs.dedup();
        loop {
            let mut merged = None;
            'search: for i in 0..pcs.len() {
                for j in i + 1..pcs.len() {
                    if let Some(m) = merge(&pcs[i], &pcs[j], sa, sb).filter(|m| accept(m)) {
                        merged = Some((i, j, m));
                        break 'search;
                    }
                }
            }
            match merged {
                Some((i, j, m)) => {
                    pcs.remove(j);
                    pcs.remove(i);
                    pcs.push(m);
                    pcs.sort();
                    pcs.dedup();
                }
                None => break,
            }
        }
        let keep: Vec<PrincipalContact> =
            pcs.iter().copied().filter(|p| !pcs.iter().any(|q| q != p && p.is_within(q, sa, sb))).collect();
        Self { pcs: keep }
    }

    /// Level: the number of point contacts.
    pub fn level(&self) -> usize {
        self.pcs.iter().map(|p| p.kind().points()).sum()
    }

    /// Label such as `{f2-v3, e1-e4}`.
    pub fn label(&self) -> String {
        let parts: Vec<String> = self.pcs.iter().map(|p| p.label()).collect();
        format!("{{{}}}", parts.join(", "))
    }

    /// Whether `self` is a close less constrained neighbour of `other` (\[P\] IV-A).
    pub fn is_clcn_of(&self, other: &Self, sa: &SurfaceElements, sb: &SurfaceElements) -> bool {
        let only_self: Vec<&PrincipalContact> = self.pcs.iter().filter(|p| !other.pcs.contains(p)).collect();
        let only_other: Vec<&PrincipalContact> = other.pcs.iter().filter(|p| !self.pcs.contains(p)).collect();
        if self.pcs.len() == other.pcs.len() {
            only_self.len() == 1 && only_other.len() == 1 && clcn_pcs(only_other[0], sa, sb).contains(only_self[0])
        } else if self.pcs.len() + 1 == other.pcs.len() {
            only_self.is_empty() && only_other.len() == 1 && only_other[0].is_ppc()
        } else {
            false
        }
    }
}

/// The CLCN PCs of `pc`: one element replaced by an element of its immediate boundary, degenerate pairs dropped.
pub fn clcn_pcs(pc: &PrincipalContact, sa: &SurfaceElements, sb: &SurfaceElements) -> Vec<PrincipalContact> {
    let mut out: Vec<PrincipalContact> =
        sa.immediate_boundary(pc.a).into_iter().filter_map(|a| PrincipalContact::new(a, pc.b)).collect();
    out.extend(sb.immediate_boundary(pc.b).into_iter().filter_map(|b| PrincipalContact::new(pc.a, b)));
    out
}

fn merge(
    p: &PrincipalContact,
    q: &PrincipalContact,
    sa: &SurfaceElements,
    sb: &SurfaceElements,
) -> Option<PrincipalContact> {
    let x = sa.join(p.a, q.a)?;
    let y = sb.join(p.b, q.b)?;
    let m = PrincipalContact::new(x, y)?;
    let points = p.kind().points() + q.kind().points();
    match m.kind() {
        PcType::FaceEdge | PcType::EdgeFace => Some(m),
        PcType::FaceFace => {
            let chord = p.is_ppc()
                && q.is_ppc()
                && ((p.a == q.a && p.a.kind == ElementKind::Face) || (p.b == q.b && p.b.kind == ElementKind::Face));
            (points >= 3 || chord).then_some(m)
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use stackplan_geom::DVec3;

    fn cube() -> SurfaceElements {
        let p = |i: usize| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
        let facets: Vec<Vec<DVec3>> =
            [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
                .iter()
                .map(|f| f.iter().map(|&i| p(i)).collect())
                .collect();
        SurfaceElements::from_facets(&facets).expect("cube")
    }

    fn pc(a: Element, b: Element) -> PrincipalContact {
        PrincipalContact::new(a, b).expect("valid")
    }

    #[test]
    fn types_and_levels() {
        use ElementKind::*;
        assert_eq!(PcType::of(Vertex, Vertex), None);
        assert_eq!(PcType::of(Vertex, Edge), None);
        assert_eq!(PcType::of(Edge, Vertex), None);
        assert_eq!(PcType::of(Face, Face).map(PcType::points), Some(3));
        assert!(pc(Element::face(0), Element::vertex(1)).is_ppc());
        assert!(!pc(Element::face(0), Element::edge(1)).is_ppc());
        assert_eq!(pc(Element::face(2), Element::vertex(3)).label(), "f2-v3");
    }

    #[test]
    fn mapping_to_highest_level() {
        let a = cube();
        let b = cube();
        let fa = Element::face(0);
        let e = &b.edges[0];
        let (v0, v1) = (Element::vertex(e.vertices[0]), Element::vertex(e.vertices[1]));
        // two f-v at the ends of one edge -> f-e
        let s = ContactState::canonical(vec![pc(fa, v0), pc(fa, v1)], &a, &b);
        assert_eq!(s.pcs, vec![pc(fa, Element::edge(0))]);
        assert_eq!(s.level(), 2);
        // f-e plus an f-v of the same face of B -> f-f
        let face_b = e.faces[0];
        let other_v = *b.faces[face_b].vertices.iter().find(|v| !e.vertices.contains(v)).expect("vertex");
        let s = ContactState::canonical(vec![pc(fa, Element::edge(0)), pc(fa, Element::vertex(other_v))], &a, &b);
        assert_eq!(s.pcs, vec![pc(fa, Element::face(face_b))]);
        // two diagonal corners of a face of B on one face of A -> f-f (chord rule)
        let fv = &b.faces[face_b].vertices;
        let diag = *fv
            .iter()
            .find(|&&v| v != fv[0] && b.join(Element::vertex(fv[0]), Element::vertex(v)) == Some(Element::face(face_b)))
            .expect("diagonal");
        let s = ContactState::canonical(vec![pc(fa, Element::vertex(fv[0])), pc(fa, Element::vertex(diag))], &a, &b);
        assert_eq!(s.pcs, vec![pc(fa, Element::face(face_b))]);
        // body-diagonal corners share nothing: stay two PCs
        let p0 = b.vertices[fv[0]].position;
        let far = b.vertices.iter().position(|v| (v.position - p0).length() > 1.7).expect("far");
        let s = ContactState::canonical(vec![pc(fa, Element::vertex(fv[0])), pc(fa, Element::vertex(far))], &a, &b);
        assert_eq!(s.pcs.len(), 2);
        assert_eq!(s.level(), 2);
        // e-e plus f-v with the edge of A on the face and the vertex on the edge of B -> f-e
        let ea = a.faces[0].edges[0];
        let s = ContactState::canonical(vec![pc(Element::edge(ea), Element::edge(0)), pc(fa, v0)], &a, &b);
        assert_eq!(s.pcs, vec![pc(fa, Element::edge(0))]);
        // a v-f and an f-v with two single points: not enough for f-f (wedge contact)
        let va = Element::vertex(a.faces[0].vertices[0]);
        let s = ContactState::canonical(vec![pc(va, Element::face(face_b)), pc(fa, Element::vertex(fv[0]))], &a, &b);
        assert_eq!(s.pcs.len(), 2);
        // a PC within another is dropped
        let s = ContactState::canonical(vec![pc(fa, Element::edge(0)), pc(fa, v0)], &a, &b);
        assert_eq!(s.pcs, vec![pc(fa, Element::edge(0))]);
    }

    #[test]
    fn neighbours() {
        let a = cube();
        let b = cube();
        let fa = Element::face(0);
        let e = &b.edges[0];
        let fe = ContactState::single(pc(fa, Element::edge(0)));
        let fv = ContactState::single(pc(fa, Element::vertex(e.vertices[0])));
        assert!(fv.is_clcn_of(&fe, &a, &b));
        assert!(!fe.is_clcn_of(&fv, &a, &b));
        let far = ContactState::single(pc(
            fa,
            Element::vertex(b.edges.iter().map(|x| x.vertices[0]).find(|v| !e.vertices.contains(v)).expect("v")),
        ));
        assert!(!far.is_clcn_of(&fe, &a, &b));
        // f-f has 4 f-e (edges of B's face) and 4 e-f (edges of A's face) CLCN PCs
        let ff = pc(fa, Element::face(1));
        let n = clcn_pcs(&ff, &a, &b);
        assert_eq!(n.len(), 8);
        assert!(n.iter().all(|p| p.kind() == PcType::FaceEdge || p.kind() == PcType::EdgeFace));
        // adding a PPC
        let two =
            ContactState::canonical(vec![pc(fa, Element::edge(0)), pc(Element::vertex(0), Element::face(3))], &a, &b);
        assert_eq!(two.pcs.len(), 2);
        assert!(fe.is_clcn_of(&two, &a, &b));
        assert_eq!(all_ppcs(&a, &b).len(), 6 * 8 * 2 + 12 * 12);
    }
}
