//! Surface elements of a part's boundary: vertices, edges and faces with adjacency and convexity (\[P\] II step 1).
//!
//! The input is a set of planar convex polygons, each counter-clockwise seen from outside: the faces of the convex
//! components of a [`Part`] (whose union is the part), or the 3DFACE / polyface-mesh facets of a DXF file. Faces of
//! two components that lie against each other (a cut between two pieces, also when only partly overlapping, as the
//! wall standing on the floor slab of an L-corner) are not boundary and are removed; coplanar facets of the same
//! orientation that share boundary are merged into one face.
//!
//! Algorithm (all in O(n^2) of the number of facets, fine for the tens to hundreds of facets of a part):
//! 1. group facets by supporting plane (normals parallel within 1e-9 rad-ish, vertices on the plane within the length
//!    tolerance), orient each group by its first normal and map it to 2-D;
//! 2. in each plane, subtract the facets of opposite orientation from each other (convex polygon difference as
//!    convex pieces: `P \ Q = U_i (P ∩ right of edge i of Q ∩ left of edges 0..i-1)`);
//! 3. group the remaining convex pieces of one orientation into faces by shared boundary of positive length;
//! 4. a face's boundary is the union of its pieces' edges minus the parts shared by two of its pieces (1-D interval
//!    arithmetic on collinear edges);
//! 5. boundary segments of all faces are grouped by supporting 3-D line, split at every end point on the line, and
//!    each elementary piece must be traversed once forwards and once backwards (closed 2-manifold); runs of pieces
//!    with the same face pair make one edge. Edge end points, welded within the tolerance, are the vertices.
//!
//! An edge is convex when the outward normals `n0` (face traversing it forwards, `v0 -> v1`) and `n1` satisfy
//! `(n0 x n1) . (v1 - v0) > 0`, concave when `< 0`. A vertex is convex when all its edges are convex (then its
//! neighbourhood is a pointed convex cone and it can touch a face alone). The length tolerance is `1e-7` times the
//! bounding-box diagonal (looser than the kernel's `1e-9` because facets read from files carry printed coordinates).

use serde::{Deserialize, Serialize};
use stackplan_geom::{DVec2, DVec3, Part, Plane};

/// Relative length tolerance used to build the surface.
pub const SURFACE_RELATIVE_TOLERANCE: f64 = 1e-7;

/// Why facets do not make a closed surface.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SurfaceError {
    /// No facets at all.
    #[error("no facets")]
    Empty,
    /// A facet has fewer than three vertices, zero area or a non-finite coordinate.
    #[error("facet {facet} is degenerate (fewer than 3 distinct vertices, zero area or non-finite coordinates)")]
    DegenerateFacet {
        /// Facet index in the input.
        facet: usize,
    },
    /// A facet is not planar or not convex.
    #[error("facet {facet} is not a planar convex polygon")]
    NonConvexFacet {
        /// Facet index in the input.
        facet: usize,
    },
    /// A piece of boundary is not shared by exactly two faces in opposite directions.
    #[error(
        "the surface is not a closed 2-manifold near ({x}, {y}, {z}): {forward} forward and {backward} backward face boundaries"
    )]
    NotManifold {
        /// Point on the offending boundary piece.
        x: f64,
        /// y coordinate.
        y: f64,
        /// z coordinate.
        z: f64,
        /// Faces traversing it forwards.
        forward: usize,
        /// Faces traversing it backwards.
        backward: usize,
    },
}

/// An orthonormal frame of a face plane: `origin + x u + y v`, `u x v = normal`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FaceFrame {
    /// A point of the plane.
    pub origin: DVec3,
    /// First in-plane axis.
    pub u: DVec3,
    /// Second in-plane axis.
    pub v: DVec3,
    /// Unit outward normal.
    pub normal: DVec3,
}

impl FaceFrame {
    /// A frame with the given unit normal through `origin`.
    pub fn new(normal: DVec3, origin: DVec3) -> Self {
        let a = normal.abs();
        let helper = if a.x <= a.y && a.x <= a.z {
            DVec3::X
        } else if a.y <= a.z {
            DVec3::Y
        } else {
            DVec3::Z
        };
        let u = normal.cross(helper).normalize();
        let v = normal.cross(u);
        Self { origin, u, v, normal }
    }

    /// In-plane coordinates of `p` (its orthogonal projection).
    #[inline]
    pub fn to_2d(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.u), d.dot(self.v))
    }

    /// The 3-D point of in-plane coordinates `q`.
    #[inline]
    pub fn to_3d(&self, q: DVec2) -> DVec3 {
        self.origin + self.u * q.x + self.v * q.y
    }

    /// Signed distance of `p` from the plane (positive outside).
    #[inline]
    pub fn height(&self, p: DVec3) -> f64 {
        (p - self.origin).dot(self.normal)
    }
}

/// A face of the boundary: a planar region given as convex pieces, with its boundary edges and vertices.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceFace {
    /// Supporting plane, outward unit normal.
    pub plane: Plane,
    /// In-plane frame (`frame.normal == plane.normal`).
    pub frame: FaceFrame,
    /// The region as convex pieces with disjoint interiors, counter-clockwise in `frame` coordinates.
    pub pieces: Vec<Vec<DVec2>>,
    /// Boundary edges (indices into [`SurfaceElements::edges`]).
    pub edges: Vec<usize>,
    /// Boundary vertices (indices into [`SurfaceElements::vertices`]).
    pub vertices: Vec<usize>,
    /// Area of the region.
    pub area: f64,
}

/// An edge of the boundary: a straight segment where two faces meet at an angle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceEdge {
    /// End vertices.
    pub vertices: [usize; 2],
    /// The face traversing it `vertices[0] -> vertices[1]` counter-clockwise seen from outside, then the other.
    pub faces: [usize; 2],
    /// Whether the solid angle along the edge is below 180 degrees (a ridge, not a valley).
    pub convex: bool,
}

/// A vertex of the boundary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceVertex {
    /// Position.
    pub position: DVec3,
    /// Incident edges.
    pub edges: Vec<usize>,
    /// Incident faces.
    pub faces: Vec<usize>,
    /// Whether every incident edge is convex.
    pub convex: bool,
}

/// Which kind of surface element.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ElementKind {
    /// A vertex.
    Vertex,
    /// An edge.
    Edge,
    /// A face.
    Face,
}

/// A surface element of one part: kind and index.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Element {
    /// Vertex, edge or face.
    pub kind: ElementKind,
    /// Index into the corresponding list.
    pub index: usize,
}

impl Element {
    /// Vertex `i`.
    pub fn vertex(i: usize) -> Self {
        Self { kind: ElementKind::Vertex, index: i }
    }
    /// Edge `i`.
    pub fn edge(i: usize) -> Self {
        Self { kind: ElementKind::Edge, index: i }
    }
    /// Face `i`.
    pub fn face(i: usize) -> Self {
        Self { kind: ElementKind::Face, index: i }
    }
    /// Dimension: 0, 1 or 2.
    pub fn dimension(&self) -> usize {
        match self.kind {
            ElementKind::Vertex => 0,
            ElementKind::Edge => 1,
            ElementKind::Face => 2,
        }
    }
    /// The paper's label: `v3`, `e2`, `f0`.
    pub fn label(&self) -> String {
        let c = match self.kind {
            ElementKind::Vertex => 'v',
            ElementKind::Edge => 'e',
            ElementKind::Face => 'f',
        };
        format!("{c}{}", self.index)
    }
}

/// The surface elements of a part with their adjacency.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceElements {
    /// Vertices.
    pub vertices: Vec<SurfaceVertex>,
    /// Edges.
    pub edges: Vec<SurfaceEdge>,
    /// Faces.
    pub faces: Vec<SurfaceFace>,
    /// The length tolerance used to build them.
    pub tolerance: f64,
}

impl SurfaceElements {
    /// The surface of a part: the boundary of the union of its convex components.
    pub fn from_part(part: &Part) -> Result<Self, SurfaceError> {
        let facets: Vec<Vec<DVec3>> = part
            .components()
            .iter()
            .flat_map(|c| c.faces().iter().map(move |f| f.vertices.iter().map(|&v| c.vertices()[v]).collect()))
            .collect();
        Self::from_facets(&facets)
    }

    /// The surface bounded by convex planar facets, each counter-clockwise seen from outside. See the module docs.
    pub fn from_facets(facets: &[Vec<DVec3>]) -> Result<Self, SurfaceError> {
        if facets.is_empty() {
            return Err(SurfaceError::Empty);
        }
        let all: Vec<DVec3> = facets.iter().flatten().copied().collect();
        let (lo, hi) = all.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), p| (l.min(*p), h.max(*p)));
        let scale = (hi - lo).length().max(1.0);
        let eps = SURFACE_RELATIVE_TOLERANCE * scale;
        let planes = facet_planes(facets, eps)?;
        let groups = group_planes(&planes, facets, eps);
        let mut faces: Vec<SurfaceFace> = Vec::new();
        for group in &groups {
            let frame = group.frame;
            for sign in [1.0, -1.0] {
                let (mine, theirs): (Vec<Vec<DVec2>>, Vec<Vec<DVec2>>) = {
                    let mut mine = Vec::new();
                    let mut theirs = Vec::new();
                    for &(fi, s) in &group.members {
                        let mut poly: Vec<DVec2> = facets[fi].iter().map(|p| frame.to_2d(*p)).collect();
                        if s < 0.0 {
                            poly.reverse();
                        }
                        if s == sign { mine.push(poly) } else { theirs.push(poly) }
                    }
                    (mine, theirs)
                };
                let mut pieces = mine;
                for q in &theirs {
                    pieces = pieces.iter().flat_map(|p| difference(p, q, eps)).collect();
                }
                if pieces.is_empty() {
                    continue;
                }
                for component in connected_pieces(&pieces, eps) {
                    let normal = frame.normal * sign;
                    let face_frame = if sign > 0.0 {
                        frame
                    } else {
                        // mirror the frame so that u x v = -normal stays right-handed: swap u and v
                        FaceFrame { origin: frame.origin, u: frame.v, v: frame.u, normal }
                    };
                    let comp_pieces: Vec<Vec<DVec2>> = component
                        .iter()
                        .map(|&i| {
                            let poly = &pieces[i];
                            if sign > 0.0 {
                                poly.clone()
                            } else {
                                // re-express in the swapped frame (x <-> y, a reflection) and reverse the order to
                                // stay counter-clockwise
                                poly.iter().rev().map(|q| DVec2::new(q.y, q.x)).collect()
                            }
                        })
                        .collect();
                    let area = comp_pieces.iter().map(|p| polygon_area(p)).sum();
                    let offset = normal.dot(frame.origin);
                    faces.push(SurfaceFace {
                        plane: Plane { normal, offset },
                        frame: face_frame,
                        pieces: comp_pieces,
                        edges: Vec::new(),
                        vertices: Vec::new(),
                        area,
                    });
                }
            }
        }
        let segments: Vec<(usize, DVec3, DVec3)> = faces
            .iter()
            .enumerate()
            .flat_map(|(fi, f)| {
                boundary_segments(&f.pieces, eps)
                    .into_iter()
                    .map(move |(a, b)| (fi, f.frame.to_3d(a), f.frame.to_3d(b)))
            })
            .collect();
        let (vertices_pos, edges) = build_edges(&segments, &faces, eps)?;
        let mut vertices: Vec<SurfaceVertex> = vertices_pos
            .into_iter()
            .map(|position| SurfaceVertex { position, edges: Vec::new(), faces: Vec::new(), convex: true })
            .collect();
        for (ei, e) in edges.iter().enumerate() {
            for &v in &e.vertices {
                vertices[v].edges.push(ei);
                vertices[v].convex &= e.convex;
                for &f in &e.faces {
                    if !vertices[v].faces.contains(&f) {
                        vertices[v].faces.push(f);
                    }
                }
            }
            for &f in &e.faces {
                faces[f].edges.push(ei);
                for &v in &e.vertices {
                    if !faces[f].vertices.contains(&v) {
                        faces[f].vertices.push(v);
                    }
                }
            }
        }
        for v in &mut vertices {
            v.faces.sort_unstable();
        }
        for f in &mut faces {
            f.vertices.sort_unstable();
        }
        tracing::debug!(v = vertices.len(), e = edges.len(), f = faces.len(), "surface elements built");
        Ok(Self { vertices, edges, faces, tolerance: eps })
    }

    /// Number of elements of each kind `(V, E, F)`.
    pub fn counts(&self) -> (usize, usize, usize) {
        (self.vertices.len(), self.edges.len(), self.faces.len())
    }

    /// Whether `inner` is `outer` or lies on its boundary (a vertex of an edge or face, an edge of a face).
    pub fn is_within(&self, inner: Element, outer: Element) -> bool {
        if inner == outer {
            return true;
        }
        match (inner.kind, outer.kind) {
            (ElementKind::Vertex, ElementKind::Edge) => self.edges[outer.index].vertices.contains(&inner.index),
            (ElementKind::Vertex, ElementKind::Face) => self.faces[outer.index].vertices.contains(&inner.index),
            (ElementKind::Edge, ElementKind::Face) => self.edges[inner.index].faces.contains(&outer.index),
            _ => false,
        }
    }

    /// The immediate boundary of an element: the end vertices of an edge, the edges of a face.
    pub fn immediate_boundary(&self, element: Element) -> Vec<Element> {
        match element.kind {
            ElementKind::Vertex => Vec::new(),
            ElementKind::Edge => self.edges[element.index].vertices.iter().map(|&v| Element::vertex(v)).collect(),
            ElementKind::Face => self.faces[element.index].edges.iter().map(|&e| Element::edge(e)).collect(),
        }
    }

    /// The lowest-dimensional element having both `a` and `b` within it (see [`Self::is_within`]), if it is unique.
    pub fn join(&self, a: Element, b: Element) -> Option<Element> {
        if self.is_within(a, b) {
            return Some(b);
        }
        if self.is_within(b, a) {
            return Some(a);
        }
        if a.kind == ElementKind::Vertex && b.kind == ElementKind::Vertex {
            let shared: Vec<usize> = self.vertices[a.index]
                .edges
                .iter()
                .copied()
                .filter(|e| self.edges[*e].vertices.contains(&b.index))
                .collect();
            if shared.len() == 1 {
                return Some(Element::edge(shared[0]));
            }
            if shared.len() > 1 {
                return None;
            }
        }
        let faces_of = |x: Element| -> Vec<usize> {
            match x.kind {
                ElementKind::Vertex => self.vertices[x.index].faces.clone(),
                ElementKind::Edge => self.edges[x.index].faces.to_vec(),
                ElementKind::Face => vec![x.index],
            }
        };
        let fb = faces_of(b);
        let shared: Vec<usize> = faces_of(a).into_iter().filter(|f| fb.contains(f)).collect();
        if shared.len() == 1 { Some(Element::face(shared[0])) } else { None }
    }

    /// End points of edge `e`.
    pub fn edge_points(&self, e: usize) -> (DVec3, DVec3) {
        let [a, b] = self.edges[e].vertices;
        (self.vertices[a].position, self.vertices[b].position)
    }

    /// The convex pieces of face `f` as 3-D polygons.
    pub fn face_pieces_3d(&self, f: usize) -> Vec<Vec<DVec3>> {
        let face = &self.faces[f];
        face.pieces.iter().map(|p| p.iter().map(|q| face.frame.to_3d(*q)).collect()).collect()
    }

    /// All vertex positions.
    pub fn positions(&self) -> Vec<DVec3> {
        self.vertices.iter().map(|v| v.position).collect()
    }
}

struct PlaneGroup {
    frame: FaceFrame,
    /// (facet, +1 if oriented like the frame normal, -1 if opposite)
    members: Vec<(usize, f64)>,
}

fn facet_planes(facets: &[Vec<DVec3>], eps: f64) -> Result<Vec<(DVec3, DVec3)>, SurfaceError> {
    let mut out = Vec::with_capacity(facets.len());
    for (i, f) in facets.iter().enumerate() {
        if f.len() < 3 || f.iter().any(|p| !p.is_finite()) {
            return Err(SurfaceError::DegenerateFacet { facet: i });
        }
        let n = stackplan_geom::polytope::newell_normal(f.iter().copied());
        let len = n.length();
        if len.is_nan() || len <= eps * eps {
            return Err(SurfaceError::DegenerateFacet { facet: i });
        }
        let normal = n / len;
        let centroid = f.iter().copied().sum::<DVec3>() / f.len() as f64;
        if f.iter().any(|p| (*p - centroid).dot(normal).abs() > eps) {
            return Err(SurfaceError::NonConvexFacet { facet: i });
        }
        // convexity: every turn is to the left (seen from outside), allowing collinear vertices
        let k = f.len();
        for j in 0..k {
            let a = f[j];
            let b = f[(j + 1) % k];
            let c = f[(j + 2) % k];
            let turn = (b - a).cross(c - b).dot(normal);
            if turn < -eps * ((b - a).length() + (c - b).length()) {
                return Err(SurfaceError::NonConvexFacet { facet: i });
            }
        }
        out.push((normal, centroid));
    }
    Ok(out)
}

fn group_planes(planes: &[(DVec3, DVec3)], facets: &[Vec<DVec3>], eps: f64) -> Vec<PlaneGroup> {
    let mut groups: Vec<PlaneGroup> = Vec::new();
    for (i, &(n, c)) in planes.iter().enumerate() {
        let found = groups.iter_mut().find(|g| {
            g.frame.normal.cross(n).length() <= 1e-9 && facets[i].iter().all(|p| g.frame.height(*p).abs() <= eps)
        });
        match found {
            Some(g) => {
                let s = if g.frame.normal.dot(n) > 0.0 { 1.0 } else { -1.0 };
                g.members.push((i, s));
            }
            None => groups.push(PlaneGroup { frame: FaceFrame::new(n, c), members: vec![(i, 1.0)] }),
        }
    }
    groups
}

/// Twice-signed area / 2 of a polygon (positive counter-clockwise).
pub fn polygon_area(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>() / 2.0
}

/// `poly ∩ {x : cross(b - a, x - a) * keep_left >= 0}` (Sutherland-Hodgman against one line).
fn clip(poly: &[DVec2], a: DVec2, b: DVec2, keep_left: f64) -> Vec<DVec2> {
    let d = b - a;
    let side = |p: DVec2| d.perp_dot(p - a) * keep_left;
    let mut out = Vec::with_capacity(poly.len() + 1);
    let n = poly.len();
    for i in 0..n {
        let p = poly[i];
        let q = poly[(i + 1) % n];
        let (sp, sq) = (side(p), side(q));
        if sp >= 0.0 {
            out.push(p);
        }
        if (sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0) {
            let t = sp / (sp - sq);
            out.push(p + (q - p) * t);
        }
    }
    out
}

/// `p \ q` for convex counter-clockwise polygons, as convex pieces (pieces of area below `eps * perimeter` dropped).
fn difference(p: &[DVec2], q: &[DVec2], eps: f64) -> Vec<Vec<DVec2>> {
    let significant = |poly: &[DVec2]| {
        poly.len() >= 3 && {
            let per: f64 = (0..poly.len()).map(|i| (poly[(i + 1) % poly.len()] - poly[i]).length()).sum();
            polygon_area(poly) > eps * per.max(eps)
        }
    };
    let mut inter = p.to_vec();
    for i in 0..q.len() {
        inter = clip(&inter, q[i], q[(i + 1) % q.len()], 1.0);
        if inter.is_empty() {
            break;
        }
    }
    if !significant(&inter) {
        return vec![p.to_vec()];
    }
    let mut out = Vec::new();
    let mut rest = p.to_vec();
    for i in 0..q.len() {
        let (a, b) = (q[i], q[(i + 1) % q.len()]);
        let outside = clip(&rest, a, b, -1.0);
        if significant(&outside) {
            out.push(outside);
        }
        rest = clip(&rest, a, b, 1.0);
        if rest.len() < 3 {
            break;
        }
    }
    out
}

/// Overlap (as a parameter interval along `a -> b`) of segment `c -> d` lying on the same line in the opposite
/// direction; `None` when not collinear, not opposite, or overlapping in less than `eps`.
fn opposite_overlap(a: DVec2, b: DVec2, c: DVec2, d: DVec2, eps: f64) -> Option<(f64, f64)> {
    let len = (b - a).length();
    let dir = (b - a) / len;
    if dir.perp_dot(c - a).abs() > eps || dir.perp_dot(d - a).abs() > eps || dir.dot(d - c) >= 0.0 {
        return None;
    }
    let (s0, s1) = (dir.dot(d - a), dir.dot(c - a));
    let (lo, hi) = (s0.max(0.0), s1.min(len));
    if hi - lo > eps { Some((lo, hi)) } else { None }
}

fn connected_pieces(pieces: &[Vec<DVec2>], eps: f64) -> Vec<Vec<usize>> {
    let n = pieces.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    for i in 0..n {
        for j in i + 1..n {
            let (p, q) = (&pieces[i], &pieces[j]);
            let touching = (0..p.len()).any(|k| {
                (0..q.len())
                    .any(|l| opposite_overlap(p[k], p[(k + 1) % p.len()], q[l], q[(l + 1) % q.len()], eps).is_some())
            });
            if touching {
                let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                parent[a] = b;
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut root_index: Vec<Option<usize>> = vec![None; n];
    for i in 0..n {
        let r = find(&mut parent, i);
        match root_index[r] {
            Some(g) => groups[g].push(i),
            None => {
                root_index[r] = Some(groups.len());
                groups.push(vec![i]);
            }
        }
    }
    groups
}

/// Boundary of a union of interior-disjoint convex pieces: piece edges minus the parts shared with another piece.
fn boundary_segments(pieces: &[Vec<DVec2>], eps: f64) -> Vec<(DVec2, DVec2)> {
    let mut out = Vec::new();
    for (i, p) in pieces.iter().enumerate() {
        for k in 0..p.len() {
            let (a, b) = (p[k], p[(k + 1) % p.len()]);
            let len = (b - a).length();
            if len <= eps {
                continue;
            }
            let mut covered: Vec<(f64, f64)> = Vec::new();
            for (j, q) in pieces.iter().enumerate() {
                if i == j {
                    continue;
                }
                for l in 0..q.len() {
                    if let Some(iv) = opposite_overlap(a, b, q[l], q[(l + 1) % q.len()], eps) {
                        covered.push(iv);
                    }
                }
            }
            covered.sort_by(|x, y| x.0.total_cmp(&y.0));
            let dir = (b - a) / len;
            let mut s = 0.0;
            for (lo, hi) in covered {
                if lo - s > eps {
                    out.push((a + dir * s, a + dir * lo));
                }
                s = f64::max(s, hi);
            }
            if len - s > eps {
                out.push((a + dir * s, b));
            }
        }
    }
    out
}

type EdgeBuild = (Vec<DVec3>, Vec<SurfaceEdge>);

fn build_edges(segments: &[(usize, DVec3, DVec3)], faces: &[SurfaceFace], eps: f64) -> Result<EdgeBuild, SurfaceError> {
    // group segments by supporting line
    struct Line {
        origin: DVec3,
        dir: DVec3,
        members: Vec<usize>,
    }
    let mut lines: Vec<Line> = Vec::new();
    for (si, &(_, a, b)) in segments.iter().enumerate() {
        let d = (b - a).normalize();
        let on = |l: &Line, p: DVec3| {
            let w = p - l.origin;
            (w - l.dir * w.dot(l.dir)).length() <= eps
        };
        match lines.iter_mut().find(|l| l.dir.cross(d).length() <= 1e-7 && on(l, a) && on(l, b)) {
            Some(l) => l.members.push(si),
            None => lines.push(Line { origin: a, dir: d, members: vec![si] }),
        }
    }
    let mut points: Vec<DVec3> = Vec::new();
    let vertex_of = |p: DVec3, points: &mut Vec<DVec3>| -> usize {
        if let Some(i) = points.iter().position(|q| (*q - p).length() <= 2.0 * eps) {
            i
        } else {
            points.push(p);
            points.len() - 1
        }
    };
    let mut edges = Vec::new();
    for line in &lines {
        let param = |p: DVec3| (p - line.origin).dot(line.dir);
        let mut cuts: Vec<f64> = Vec::new();
        for &si in &line.members {
            cuts.push(param(segments[si].1));
            cuts.push(param(segments[si].2));
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup_by(|a, b| (*a - *b).abs() <= eps);
        // (start, end, forward face, backward face) of elementary pieces, merged in runs
        let mut run: Option<(f64, f64, usize, usize)> = None;
        let flush = |run: Option<(f64, f64, usize, usize)>, points: &mut Vec<DVec3>, edges: &mut Vec<SurfaceEdge>| {
            if let Some((s, e, ff, fb)) = run {
                let pa = line.origin + line.dir * s;
                let pb = line.origin + line.dir * e;
                let va = vertex_of(pa, points);
                let vb = vertex_of(pb, points);
                let (n0, n1) = (faces[ff].plane.normal, faces[fb].plane.normal);
                let convex = n0.cross(n1).dot(line.dir) > 0.0;
                edges.push(SurfaceEdge { vertices: [va, vb], faces: [ff, fb], convex });
            }
        };
        for w in cuts.windows(2) {
            let (s0, s1) = (w[0], w[1]);
            let mid = 0.5 * (s0 + s1);
            let mut forward = Vec::new();
            let mut backward = Vec::new();
            for &si in &line.members {
                let (f, a, b) = segments[si];
                let (ta, tb) = (param(a), param(b));
                if ta.min(tb) < mid && mid < ta.max(tb) {
                    if tb > ta { forward.push(f) } else { backward.push(f) }
                }
            }
            if forward.is_empty() && backward.is_empty() {
                flush(run.take(), &mut points, &mut edges);
                continue;
            }
            if forward.len() != 1 || backward.len() != 1 {
                let p = line.origin + line.dir * mid;
                return Err(SurfaceError::NotManifold {
                    x: p.x,
                    y: p.y,
                    z: p.z,
                    forward: forward.len(),
                    backward: backward.len(),
                });
            }
            let (ff, fb) = (forward[0], backward[0]);
            match run {
                Some((s, _, rf, rb)) if rf == ff && rb == fb => run = Some((s, s1, ff, fb)),
                _ => {
                    flush(run.take(), &mut points, &mut edges);
                    run = Some((s0, s1, ff, fb));
                }
            }
        }
        flush(run.take(), &mut points, &mut edges);
    }
    Ok((points, edges))
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn box_facets(lo: DVec3, hi: DVec3) -> Vec<Vec<DVec3>> {
        let p = |i: usize| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
            .iter()
            .map(|f| f.iter().map(|&i| p(i)).collect())
            .collect()
    }

    #[test]
    fn cube_elements() {
        let s = SurfaceElements::from_facets(&box_facets(DVec3::ZERO, DVec3::ONE)).expect("cube");
        assert_eq!(s.counts(), (8, 12, 6));
        assert!(s.edges.iter().all(|e| e.convex));
        assert!(s.vertices.iter().all(|v| v.convex && v.edges.len() == 3 && v.faces.len() == 3));
        assert!(s.faces.iter().all(|f| f.edges.len() == 4 && f.vertices.len() == 4 && (f.area - 1.0).abs() < 1e-12));
        // edge orientation: faces[0] traverses v0 -> v1 counter-clockwise seen from outside
        for e in &s.edges {
            let (a, b) = (s.vertices[e.vertices[0]].position, s.vertices[e.vertices[1]].position);
            let f0 = &s.faces[e.faces[0]];
            // the face's interior is on the left of a -> b seen from outside: normal x (b - a) points inwards
            let inward = f0.plane.normal.cross(b - a);
            let centre = f0.frame.to_3d(f0.pieces[0].iter().copied().sum::<DVec2>() / f0.pieces[0].len() as f64);
            assert!(inward.dot(centre - a) > 0.0);
        }
    }

    #[test]
    fn split_facets_merge_into_one_face() {
        // a 2x1x1 box given as two unit cubes sharing the face x = 1 (removed) with coplanar sides (merged)
        let mut f = box_facets(DVec3::ZERO, DVec3::ONE);
        f.extend(box_facets(DVec3::new(1.0, 0.0, 0.0), DVec3::new(2.0, 1.0, 1.0)));
        let s = SurfaceElements::from_facets(&f).expect("box");
        assert_eq!(s.counts(), (8, 12, 6));
        let areas: Vec<f64> = s.faces.iter().map(|f| f.area).collect();
        assert!((areas.iter().sum::<f64>() - 10.0).abs() < 1e-12, "{areas:?}");
    }

    #[test]
    fn l_corner_has_one_concave_edge() {
        // floor slab and a wall standing on it: the wall's bottom covers only part of the floor's top
        let mut f = box_facets(DVec3::new(-10.0, -2.0, -2.0), DVec3::new(10.0, 15.0, 0.0));
        f.extend(box_facets(DVec3::new(-10.0, -2.0, 0.0), DVec3::new(10.0, 0.0, 10.0)));
        let s = SurfaceElements::from_facets(&f).expect("L");
        assert_eq!(s.counts(), (12, 18, 8));
        let concave: Vec<&SurfaceEdge> = s.edges.iter().filter(|e| !e.convex).collect();
        assert_eq!(concave.len(), 1);
        let (a, b) = (s.vertices[concave[0].vertices[0]].position, s.vertices[concave[0].vertices[1]].position);
        assert!(a.y.abs() < 1e-12 && a.z.abs() < 1e-12 && b.y.abs() < 1e-12 && (a.x - b.x).abs() == 20.0);
        // its end vertices are not convex; 10 other vertices are
        assert_eq!(s.vertices.iter().filter(|v| v.convex).count(), 10);
        // the two L-shaped end faces (x = +-10) are single faces of area 17*2 + 2*10
        let ends: Vec<&SurfaceFace> = s.faces.iter().filter(|f| f.plane.normal.x.abs() > 0.5).collect();
        assert_eq!(ends.len(), 2);
        for e in ends {
            assert!((e.area - 54.0).abs() < 1e-9);
            assert_eq!(e.vertices.len(), 6);
            assert_eq!(e.edges.len(), 6);
        }
        let (v, e, fc) = s.counts();
        assert_eq!(v + fc, e + 2);
    }

    #[test]
    fn relations() {
        let s = SurfaceElements::from_facets(&box_facets(DVec3::ZERO, DVec3::ONE)).expect("cube");
        let e = &s.edges[0];
        let (v0, v1) = (Element::vertex(e.vertices[0]), Element::vertex(e.vertices[1]));
        assert_eq!(s.join(v0, v1), Some(Element::edge(0)));
        assert!(s.is_within(v0, Element::edge(0)));
        assert!(s.is_within(Element::edge(0), Element::face(e.faces[0])));
        // opposite corners of a face join to that face; body-diagonal corners join to nothing
        let f = &s.faces[0];
        let diag: Vec<usize> = f
            .vertices
            .iter()
            .copied()
            .filter(|&v| !s.edges.iter().any(|e| e.vertices == [f.vertices[0], v] || e.vertices == [v, f.vertices[0]]))
            .collect();
        let far = diag.iter().copied().find(|&v| v != f.vertices[0]).expect("diagonal vertex");
        assert_eq!(s.join(Element::vertex(f.vertices[0]), Element::vertex(far)), Some(Element::face(0)));
        let p0 = s.vertices[f.vertices[0]].position;
        let opposite = s.vertices.iter().position(|v| (v.position - p0).length() > 1.7).expect("opposite");
        assert_eq!(s.join(Element::vertex(f.vertices[0]), Element::vertex(opposite)), None);
        assert_eq!(s.immediate_boundary(Element::face(0)).len(), 4);
    }

    #[test]
    fn errors() {
        assert_eq!(SurfaceElements::from_facets(&[]), Err(SurfaceError::Empty));
        let mut f = box_facets(DVec3::ZERO, DVec3::ONE);
        f.pop();
        assert!(matches!(SurfaceElements::from_facets(&f), Err(SurfaceError::NotManifold { .. })));
        let mut f = box_facets(DVec3::ZERO, DVec3::ONE);
        f[2] = vec![DVec3::ZERO, DVec3::X];
        assert_eq!(SurfaceElements::from_facets(&f), Err(SurfaceError::DegenerateFacet { facet: 2 }));
        // a dart (reflex vertex at (0.5, 1)) is planar but not convex
        let dart = vec![DVec3::ZERO, DVec3::new(2.0, 1.0, 0.0), DVec3::new(0.0, 2.0, 0.0), DVec3::new(0.5, 1.0, 0.0)];
        assert_eq!(SurfaceElements::from_facets(&[dart]), Err(SurfaceError::NonConvexFacet { facet: 0 }));
        // a bow-tie has no area
        let mut f = box_facets(DVec3::ZERO, DVec3::ONE);
        f[0].swap(1, 2);
        assert_eq!(SurfaceElements::from_facets(&f), Err(SurfaceError::DegenerateFacet { facet: 0 }));
    }
}
