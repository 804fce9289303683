//! Convex polytopes with a full boundary representation.
//!
//! A [`ConvexPolytope`] carries its vertices, its polygonal faces (outward, counter-clockwise seen from outside,
//! exactly-coplanar facets already merged), its edges with the two faces that meet there, and a unit-normal plane per
//! face (`n . x <= d` inside). Construction from an explicit face list costs O(V + E + F); [`ConvexPolytope::validate`]
//! checks Euler's formula, that every vertex is on or inside every face plane, and strict convexity across every edge.

use crate::predicates;
use crate::tolerance::Tolerance;
use crate::vertex_cycle::VertexCycle;
use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};
use std::cmp::Ordering;

/// An oriented plane `normal . x = offset`; the inside half-space is `normal . x <= offset`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Plane {
    /// Unit outward normal.
    pub normal: DVec3,
    /// Offset: `normal . x = offset` on the plane.
    pub offset: f64,
}

impl Plane {
    /// Signed distance of `p` (positive outside, i.e. on the normal's side).
    #[inline]
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.offset
    }
}

/// A polygonal face: vertex indices counter-clockwise seen from outside, and its plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Face {
    /// Indices into [`ConvexPolytope::vertices`], counter-clockwise seen from outside (a quadrilateral or smaller
    /// without a heap allocation).
    pub vertices: VertexCycle,
    /// The face's plane with unit outward normal.
    pub plane: Plane,
}

/// An edge between two vertices and the two faces that share it.
///
/// `faces[0]` traverses the edge as `vertices[0] -> vertices[1]` in its counter-clockwise order (the face on the
/// left when walking from `vertices[0]` to `vertices[1]` seen from outside); `faces[1]` traverses it backwards.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Edge {
    /// The edge's two end vertices.
    pub vertices: [usize; 2],
    /// The face traversing it forwards, then the face traversing it backwards.
    pub faces: [usize; 2],
}

/// Why a face list is not the boundary of a convex polytope.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PolytopeError {
    /// A face has fewer than three vertices.
    #[error("face {face} has {count} vertices; a face needs at least 3")]
    FaceTooSmall {
        /// Face index.
        face: usize,
        /// Number of vertices it has.
        count: usize,
    },
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {vertex}, but there are only {len} vertices")]
    BadVertexIndex {
        /// Face index.
        face: usize,
        /// The bad index.
        vertex: usize,
        /// Number of vertices.
        len: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// Vertex index.
        vertex: usize,
    },
    /// The same directed edge appears in two faces, or an edge has only one face: not a closed 2-manifold.
    #[error("edge {a}-{b} is not shared by exactly two consistently oriented faces")]
    NotManifold {
        /// First vertex.
        a: usize,
        /// Second vertex.
        b: usize,
    },
    /// Euler's formula fails.
    #[error("Euler characteristic V - E + F = {v} - {e} + {f} != 2")]
    Euler {
        /// Vertices.
        v: usize,
        /// Edges.
        e: usize,
        /// Faces.
        f: usize,
    },
    /// A vertex lies outside a face plane.
    #[error("vertex {vertex} lies outside the plane of face {face} by {distance}")]
    VertexOutside {
        /// Vertex index.
        vertex: usize,
        /// Face index.
        face: usize,
        /// Signed distance (positive = outside).
        distance: f64,
    },
    /// A face's vertices are not coplanar.
    #[error("face {face} is not planar: vertex {vertex} is off its plane by {distance}")]
    NonPlanarFace {
        /// Face index.
        face: usize,
        /// Vertex index.
        vertex: usize,
        /// Distance from the plane.
        distance: f64,
    },
    /// Two faces sharing an edge are coplanar or bend the wrong way.
    #[error("the polytope is not strictly convex across edge {a}-{b}")]
    NotStrictlyConvex {
        /// First vertex.
        a: usize,
        /// Second vertex.
        b: usize,
    },
    /// More vertices than the edge table can index.
    #[error("{count} vertices: a polytope may have at most 2^31")]
    TooManyVertices {
        /// Number of vertices given.
        count: usize,
    },
    /// A face has zero area (its normal is undefined).
    #[error("face {face} is degenerate (zero area)")]
    DegenerateFace {
        /// Face index.
        face: usize,
    },
}

/// The most vertices a polytope may have (the edge table packs two vertex indices into one 64-bit key).
pub const MAX_VERTICES: usize = 1 << 31;

/// A convex polytope in boundary representation. See the module documentation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConvexPolytope {
    vertices: Vec<DVec3>,
    faces: Vec<Face>,
    edges: Vec<Edge>,
    /// `face_edges.of(f)[k]` is the edge from `faces[f].vertices[k]` to `faces[f].vertices[k + 1]`.
    face_edges: FaceEdgeTable,
}

/// Where a point is relative to a polytope, under a tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Containment {
    /// Strictly inside every face plane by more than the tolerance.
    Interior,
    /// Within the tolerance of the boundary.
    Boundary,
    /// Outside some face plane by more than the tolerance.
    Exterior,
}

/// Newell's normal of a polygon (twice its vector area); robust for nearly-degenerate polygons.
pub fn newell_normal(points: impl Iterator<Item = DVec3> + Clone) -> DVec3 {
    let mut n = DVec3::ZERO;
    let first = points.clone().next();
    let mut it = points.peekable();
    while let Some(p) = it.next() {
        let q = match it.peek() {
            Some(q) => *q,
            None => match first {
                Some(f) => f,
                None => break,
            },
        };
        n.x += (p.y - q.y) * (p.z + q.z);
        n.y += (p.z - q.z) * (p.x + q.x);
        n.z += (p.x - q.x) * (p.y + q.y);
    }
    n
}

impl ConvexPolytope {
    /// Builds a polytope from vertices and counter-clockwise (seen from outside) faces.
    ///
    /// Checks indices, finiteness and that the faces form a closed, consistently oriented 2-manifold; computes edges
    /// and face planes (Newell normal, offset = the largest `n . v` over the face's vertices, so every face vertex
    /// satisfies its own inequality). Convexity is checked by [`Self::validate`], not here.
    pub fn new(vertices: Vec<DVec3>, faces: Vec<Vec<usize>>) -> Result<Self, PolytopeError> {
        check_vertices(&vertices)?;
        let (edges, face_edges) = edge_table(vertices.len(), &faces, |f| f.as_slice())?;
        let mut out = Vec::with_capacity(faces.len());
        for (f, face) in faces.into_iter().enumerate() {
            let plane = plane_of(&vertices, &face).ok_or(PolytopeError::DegenerateFace { face: f })?;
            out.push(Face { vertices: face.into(), plane });
        }
        Ok(Self { vertices, faces: out, edges, face_edges })
    }

    /// The axis-aligned box `[lo, hi]`, built directly (no hull): vertex `i` has x from `hi` when bit 0 of `i` is
    /// set, y when bit 1 is, z when bit 2 is. An error when the box is empty or flat in some axis, or not finite.
    pub fn cuboid(lo: DVec3, hi: DVec3) -> Result<Self, PolytopeError> {
        let vertices: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect();
        let faces = vec![
            vec![0, 2, 3, 1], // z = lo.z, normal -z
            vec![4, 5, 7, 6], // z = hi.z
            vec![0, 1, 5, 4], // y = lo.y
            vec![2, 6, 7, 3], // y = hi.y
            vec![0, 4, 6, 2], // x = lo.x
            vec![1, 3, 7, 5], // x = hi.x
        ];
        let extent = hi - lo;
        // the face reported is the low face of the first empty axis (z, y, x); NaN extents are rejected too
        for (face, e) in [(0, extent.z), (2, extent.y), (4, extent.x)] {
            if e.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return Err(PolytopeError::DegenerateFace { face });
            }
        }
        Self::new(vertices, faces)
    }

    /// Builds a polytope whose face planes are given (for computed polytopes whose planes are known more accurately
    /// than a fit to rounded vertices, e.g. Minkowski sums). Same checks as [`Self::new`]; the planes' normals must be
    /// unit length.
    pub fn with_planes(
        vertices: Vec<DVec3>,
        faces: Vec<Vec<usize>>,
        planes: Vec<Plane>,
    ) -> Result<Self, PolytopeError> {
        check_vertices(&vertices)?;
        let (edges, face_edges) = edge_table(vertices.len(), &faces, |f| f.as_slice())?;
        let mut out = Vec::with_capacity(faces.len());
        let mut planes = planes.into_iter();
        for (f, face) in faces.into_iter().enumerate() {
            // the same degenerate-face check as `new`; the computed plane is only kept where none is given
            let plane = match planes.next() {
                Some(given) if has_area(&vertices, &face) => given,
                given => {
                    let computed = plane_of(&vertices, &face).ok_or(PolytopeError::DegenerateFace { face: f })?;
                    given.unwrap_or(computed)
                }
            };
            out.push(Face { vertices: face.into(), plane });
        }
        Ok(Self { vertices, faces: out, edges, face_edges })
    }

    /// Builds a polytope from vertices and faces that carry their planes: the same result and checks as
    /// [`Self::with_planes`] with the faces' vertex cycles and planes as separate lists (the planes' normals must be
    /// unit length), without allocating those lists.
    pub fn from_faces(vertices: Vec<DVec3>, faces: Vec<Face>) -> Result<Self, PolytopeError> {
        check_vertices(&vertices)?;
        let (edges, face_edges) = edge_table(vertices.len(), &faces, |f| f.vertices.as_slice())?;
        for (f, face) in faces.iter().enumerate() {
            // the same degenerate-face check as `new`
            if !has_area(&vertices, &face.vertices) && plane_of(&vertices, &face.vertices).is_none() {
                return Err(PolytopeError::DegenerateFace { face: f });
            }
        }
        Ok(Self { vertices, faces, edges, face_edges })
    }

    /// [`Self::from_faces`] without its zero-area check of every face (the edge table, the manifold and index checks
    /// and the finiteness check are the same): for constructions that give every face a positive area by design, such
    /// as the Gauss-map Minkowski sums of `stackplan-cspace`, whose faces each contain a translated face of a summand
    /// or are parallelograms of two non-parallel edges. The faces' planes must have unit normals.
    pub fn from_faces_with_area(vertices: Vec<DVec3>, faces: Vec<Face>) -> Result<Self, PolytopeError> {
        check_vertices(&vertices)?;
        let (edges, face_edges) = edge_table(vertices.len(), &faces, |f| f.vertices.as_slice())?;
        Ok(Self { vertices, faces, edges, face_edges })
    }

    /// [`Self::from_faces_with_area`] with the edge table built by the caller: `edges` in the order the edge table of
    /// [`Self::new`] gives them (increasing (smaller vertex, larger vertex); `vertices[0] < vertices[1]`, `faces[0]` the
    /// face traversing the edge from the smaller to the larger vertex) and `face_edges` the edge of every face's
    /// half-edges in face order (`face_edges[start(f) + k]` joins corner `k` and `k + 1` of face `f`, where `start(f)`
    /// is the total length of the faces before `f`): for constructions that know their edges, such as the Gauss-map
    /// Minkowski sums of `stackplan-cspace`. O(V + F); the vertices' finiteness and count are checked as in
    /// [`Self::new`]; the table itself is trusted, and checked against the one [`Self::new`] would build only in debug
    /// builds. When `face_edges` does not have one entry per half-edge, the table is built here (same checks as
    /// [`Self::from_faces_with_area`]). The faces' starts in `face_edges` are kept in its spare capacity when it has
    /// room for one more entry than there are faces (else it grows once).
    pub fn from_faces_and_edges(
        vertices: Vec<DVec3>,
        faces: Vec<Face>,
        edges: Vec<Edge>,
        face_edges: Vec<usize>,
    ) -> Result<Self, PolytopeError> {
        let total: usize = faces.iter().map(|face| face.vertices.len()).sum();
        if face_edges.len() != total {
            return Self::from_faces_with_area(vertices, faces);
        }
        check_vertices(&vertices)?;
        let face_edges = FaceEdgeTable::new(face_edges, faces.iter().map(|face| face.vertices.len()));
        #[cfg(debug_assertions)]
        {
            let built = edge_table(vertices.len(), &faces, |f| f.vertices.as_slice());
            let same = matches!(&built, Ok((e, t)) if *e == edges && *t == face_edges);
            debug_assert!(same, "the caller's edge table differs from the one geom builds: {built:?}");
        }
        Ok(Self { vertices, faces, edges, face_edges })
    }

    /// The same topology (faces, edges) with new vertex coordinates and face planes, in O(V + F) without any
    /// search: for computed polytopes whose structure is known to be unchanged (e.g. c-space obstacles extrapolated
    /// within a constant-topology interval). `None` when the lengths do not match this polytope's.
    pub fn with_geometry(&self, vertices: Vec<DVec3>, planes: Vec<Plane>) -> Option<Self> {
        if vertices.len() != self.vertices.len() || planes.len() != self.faces.len() {
            return None;
        }
        let faces =
            self.faces.iter().zip(planes).map(|(f, plane)| Face { vertices: f.vertices.clone(), plane }).collect();
        Some(Self { vertices, faces, edges: self.edges.clone(), face_edges: self.face_edges.clone() })
    }

    /// The vertices.
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// The faces.
    pub fn faces(&self) -> &[Face] {
        &self.faces
    }

    /// The edges.
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// Edge indices of face `f`, aligned with its vertex cycle (`face_edges(f)[k]` joins vertex `k` and `k + 1`).
    pub fn face_edges(&self, f: usize) -> &[usize] {
        self.face_edges.of(f)
    }

    /// The face planes, in face order.
    pub fn planes(&self) -> impl ExactSizeIterator<Item = &Plane> + '_ {
        self.faces.iter().map(|f| &f.plane)
    }

    /// Axis-aligned bounding box `(min, max)`.
    pub fn aabb(&self) -> (DVec3, DVec3) {
        let first = self.vertices[0];
        self.vertices.iter().fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
    }

    /// The policy tolerance for this polytope (scale = its bounding-box diagonal).
    pub fn tolerance(&self) -> Tolerance {
        Tolerance::for_points(&self.vertices)
    }

    /// Index of a vertex maximising `dir . v` (the support point).
    pub fn support(&self, dir: DVec3) -> usize {
        let mut best = 0;
        let mut best_value = f64::NEG_INFINITY;
        for (i, v) in self.vertices.iter().enumerate() {
            let value = dir.dot(*v);
            if value > best_value {
                best_value = value;
                best = i;
            }
        }
        best
    }

    /// The image under `x -> rotation * x + translation` (same topology, planes transformed exactly as vectors).
    pub fn transformed(&self, rotation: DMat3, translation: DVec3) -> Self {
        let vertices = self.vertices.iter().map(|v| rotation * *v + translation).collect();
        let faces = self
            .faces
            .iter()
            .map(|f| {
                let normal = (rotation * f.plane.normal).normalize();
                // offset of the transformed plane: n' . (R x + t) = n . x + n' . t for a rotation R
                let offset = f.plane.offset + normal.dot(translation);
                Face { vertices: f.vertices.clone(), plane: Plane { normal, offset } }
            })
            .collect();
        Self { vertices, faces, edges: self.edges.clone(), face_edges: self.face_edges.clone() }
    }

    /// Classifies `p` against the face planes with the tolerance `tol`.
    pub fn containment(&self, p: DVec3, tol: Tolerance) -> Containment {
        let mut on_boundary = false;
        for f in &self.faces {
            match tol.sign(f.plane.signed_distance(p)) {
                1 => return Containment::Exterior,
                0 => on_boundary = true,
                _ => {}
            }
        }
        if on_boundary { Containment::Boundary } else { Containment::Interior }
    }

    /// Volume, by the divergence theorem over fan-triangulated faces. O(V + F).
    pub fn volume(&self) -> f64 {
        let c = self.vertex_centroid();
        let mut v = 0.0;
        for f in &self.faces {
            let a = self.vertices[f.vertices[0]] - c;
            for k in 1..f.vertices.len() - 1 {
                let b = self.vertices[f.vertices[k]] - c;
                let d = self.vertices[f.vertices[k + 1]] - c;
                v += a.dot(b.cross(d));
            }
        }
        v / 6.0
    }

    /// Mean of the vertices (an interior point of a full-dimensional polytope, not its centroid).
    pub fn vertex_centroid(&self) -> DVec3 {
        self.vertices.iter().copied().sum::<DVec3>() / self.vertices.len() as f64
    }

    /// Checks the polytope with the policy tolerance: Euler's formula, planarity of every face, every vertex on or
    /// inside every face plane, strict convexity across every edge (the far vertices of the neighbouring face lie
    /// strictly below the plane). Suited to computed polytopes whose coordinates carry rounding error.
    pub fn validate(&self) -> Result<(), PolytopeError> {
        self.validate_with(self.tolerance())
    }

    /// [`Self::validate`] with an explicit tolerance.
    pub fn validate_with(&self, tol: Tolerance) -> Result<(), PolytopeError> {
        self.check_euler()?;
        for (fi, f) in self.faces.iter().enumerate() {
            for &v in &f.vertices {
                let d = f.plane.signed_distance(self.vertices[v]);
                if d.abs() > tol.linear {
                    return Err(PolytopeError::NonPlanarFace { face: fi, vertex: v, distance: d });
                }
            }
            for (vi, v) in self.vertices.iter().enumerate() {
                let d = f.plane.signed_distance(*v);
                if d > tol.linear {
                    return Err(PolytopeError::VertexOutside { vertex: vi, face: fi, distance: d });
                }
            }
        }
        for e in &self.edges {
            let f = &self.faces[e.faces[0]];
            let g = &self.faces[e.faces[1]];
            let strictly_below = g
                .vertices
                .iter()
                .filter(|v| !e.vertices.contains(v))
                .any(|&v| f.plane.signed_distance(self.vertices[v]) < -tol.linear);
            if !strictly_below {
                return Err(PolytopeError::NotStrictlyConvex { a: e.vertices[0], b: e.vertices[1] });
            }
        }
        Ok(())
    }

    /// The exact version of [`Self::validate`]: planarity, containment and strict convexity decided with exact
    /// predicates on the vertex coordinates. For polytopes built from input points (hulls, input pieces).
    pub fn validate_exact(&self) -> Result<(), PolytopeError> {
        self.check_euler()?;
        for (fi, f) in self.faces.iter().enumerate() {
            let Some((a, b, c)) = self.face_frame(fi) else {
                return Err(PolytopeError::DegenerateFace { face: fi });
            };
            for &v in &f.vertices {
                if predicates::side(a, b, c, self.vertices[v]) != Ordering::Equal {
                    let distance = f.plane.signed_distance(self.vertices[v]);
                    return Err(PolytopeError::NonPlanarFace { face: fi, vertex: v, distance });
                }
            }
            for (vi, v) in self.vertices.iter().enumerate() {
                if predicates::side(a, b, c, *v) == Ordering::Greater {
                    let distance = f.plane.signed_distance(*v);
                    return Err(PolytopeError::VertexOutside { vertex: vi, face: fi, distance });
                }
            }
        }
        for e in &self.edges {
            let Some((a, b, c)) = self.face_frame(e.faces[0]) else {
                return Err(PolytopeError::DegenerateFace { face: e.faces[0] });
            };
            let g = &self.faces[e.faces[1]];
            let strictly_below = g
                .vertices
                .iter()
                .filter(|v| !e.vertices.contains(v))
                .any(|&v| predicates::side(a, b, c, self.vertices[v]) == Ordering::Less);
            if !strictly_below {
                return Err(PolytopeError::NotStrictlyConvex { a: e.vertices[0], b: e.vertices[1] });
            }
        }
        Ok(())
    }

    /// Three vertices of face `f` that are not collinear, in the face's counter-clockwise order (so that
    /// [`predicates::side`] on them is positive outside). `None` if all the face's vertices are collinear.
    pub fn face_frame(&self, f: usize) -> Option<(DVec3, DVec3, DVec3)> {
        let idx = &self.faces[f].vertices;
        let n = idx.len();
        // A convex polygon: any three consecutive non-collinear vertices have the face's orientation.
        for k in 0..n {
            let a = self.vertices[idx[k]];
            let b = self.vertices[idx[(k + 1) % n]];
            let c = self.vertices[idx[(k + 2) % n]];
            if !predicates::collinear(a, b, c) {
                return Some((a, b, c));
            }
        }
        None
    }

    fn check_euler(&self) -> Result<(), PolytopeError> {
        let (v, e, f) = (self.vertices.len(), self.edges.len(), self.faces.len());
        // every vertex must be used, otherwise V is overcounted
        if v + f != e + 2 {
            return Err(PolytopeError::Euler { v, e, f });
        }
        Ok(())
    }
}

/// The edge indices of every face in one flat list, and where every face's start in it, in one buffer: face `f`'s
/// edges are `data[starts[f]..starts[f + 1]]` with `starts = data[split..]` (one allocation instead of one per face, or
/// two). Serialised and debug-printed exactly as the list of per-face lists it replaces.
#[derive(Clone, PartialEq, Eq)]
struct FaceEdgeTable {
    data: Vec<usize>,
    split: usize,
}

impl FaceEdgeTable {
    /// The table of the half-edges' edges `edges` (face order) for faces of the given lengths (which must add up to
    /// `edges.len()`); the starts go into `edges`' spare capacity when it has room.
    fn new(mut edges: Vec<usize>, lengths: impl ExactSizeIterator<Item = usize>) -> Self {
        let split = edges.len();
        edges.reserve(lengths.len() + 1);
        let mut start = 0;
        edges.push(start);
        for length in lengths {
            start += length;
            edges.push(start);
        }
        Self { data: edges, split }
    }

    fn starts(&self) -> &[usize] {
        &self.data[self.split..]
    }

    fn of(&self, f: usize) -> &[usize] {
        let starts = self.starts();
        &self.data[starts[f]..starts[f + 1]]
    }

    fn lists(&self) -> impl Iterator<Item = &[usize]> + '_ {
        self.starts().windows(2).map(|w| &self.data[w[0]..w[1]])
    }
}

impl std::fmt::Debug for FaceEdgeTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.lists()).finish()
    }
}

impl Serialize for FaceEdgeTable {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.lists())
    }
}

impl<'de> Deserialize<'de> for FaceEdgeTable {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let lists = Vec::<Vec<usize>>::deserialize(deserializer)?;
        let mut edges = Vec::with_capacity(lists.iter().map(Vec::len).sum::<usize>() + lists.len() + 1);
        for list in &lists {
            edges.extend_from_slice(list);
        }
        Ok(Self::new(edges, lists.iter().map(Vec::len)))
    }
}

/// Finite coordinates and at most [`MAX_VERTICES`] vertices.
fn check_vertices(vertices: &[DVec3]) -> Result<(), PolytopeError> {
    // `x - x` is 0 for a finite `x` and NaN for an infinite or NaN one, so the sum is 0 exactly when every coordinate
    // is finite: one branch-free pass (vectorised), and the scan below only to name the first offending vertex
    #[expect(clippy::eq_op, reason = "`v - v` is the finiteness test: 0 for finite coordinates, NaN otherwise")]
    let zero = vertices.iter().fold(DVec3::ZERO, |sum, &v| sum + (v - v));
    if zero == DVec3::ZERO && vertices.len() <= MAX_VERTICES {
        return Ok(());
    }
    for (i, v) in vertices.iter().enumerate() {
        if !v.is_finite() {
            return Err(PolytopeError::NonFinite { vertex: i });
        }
    }
    if vertices.len() > MAX_VERTICES {
        return Err(PolytopeError::TooManyVertices { count: vertices.len() });
    }
    Ok(())
}

/// The edges and the per-face edge indices of a face list, checking that it is a closed, consistently oriented
/// 2-manifold.
///
/// Half-edges `(a, b, face, position)` are grouped by undirected edge by sorting: each group must be exactly one
/// `a -> b` and one `b -> a`. The undirected edge and the direction are packed into one integer key,
/// `(min << 33) | (max << 1) | (a > b)`; edges come out in increasing key order, i.e. ordered by (smaller vertex,
/// larger vertex), each with the face traversing it from the smaller to the larger vertex first. The sort is a
/// counting sort on the smaller vertex followed by an insertion sort (which only moves half-edges within one
/// vertex's bucket): O(V + H + sum of squared bucket sizes) for H half-edges, linear for bounded vertex degree, no
/// hashing.
fn edge_table<F>(
    nv: usize,
    faces: &[F],
    cycle: impl Fn(&F) -> &[usize],
) -> Result<(Vec<Edge>, FaceEdgeTable), PolytopeError> {
    let mut small_counts = [0u32; 129];
    let mut large_counts = Vec::new();
    let counts: &mut [u32] = if nv < small_counts.len() {
        &mut small_counts[..=nv]
    } else {
        large_counts.resize(nv + 1, 0u32);
        &mut large_counts
    };
    // pass 1: checks in face order (the first failure is reported) and bucket sizes by the smaller vertex
    let mut total = 0usize;
    for (f, face) in faces.iter().enumerate() {
        let face = cycle(face);
        if face.len() < 3 {
            return Err(PolytopeError::FaceTooSmall { face: f, count: face.len() });
        }
        for (k, &a) in face.iter().enumerate() {
            if a >= nv {
                return Err(PolytopeError::BadVertexIndex { face: f, vertex: a, len: nv });
            }
            let b = if k + 1 < face.len() { face[k + 1] } else { face[0] };
            if a == b {
                return Err(PolytopeError::NotManifold { a, b });
            }
            counts[a.min(b) + 1] += 1;
        }
        total += face.len();
    }
    for v in 0..nv {
        counts[v + 1] += counts[v];
    }
    // pass 2: place every half-edge in its bucket, then sort by the full key (moves stay inside buckets)
    let mut half: Vec<(u64, u32, u32)> = vec![(0, 0, 0); total];
    for (f, face) in faces.iter().enumerate() {
        let face = cycle(face);
        for (k, &a) in face.iter().enumerate() {
            let b = if k + 1 < face.len() { face[k + 1] } else { face[0] };
            let key = ((a.min(b) as u64) << 33) | ((a.max(b) as u64) << 1) | u64::from(a > b);
            let slot = &mut counts[a.min(b)];
            half[*slot as usize] = (key, f as u32, k as u32);
            *slot += 1;
        }
    }
    for i in 1..half.len() {
        let h = half[i];
        let mut j = i;
        while j > 0 && half[j - 1].0 > h.0 {
            half[j] = half[j - 1];
            j -= 1;
        }
        half[j] = h;
    }
    let ends = |key: u64| -> (usize, usize) {
        let (lo, hi) = ((key >> 33) as usize, ((key >> 1) & 0xFFFF_FFFF) as usize);
        if key & 1 == 1 { (hi, lo) } else { (lo, hi) }
    };
    let mut face_edges = Vec::with_capacity(total + faces.len() + 1);
    face_edges.resize(total, usize::MAX);
    let mut face_edges = FaceEdgeTable::new(face_edges, faces.iter().map(|face| cycle(face).len()));
    let mut edges = Vec::with_capacity(half.len() / 2);
    let mut i = 0;
    while i < half.len() {
        let (key, f, k) = half[i];
        let (a, b) = ends(key);
        let Some(&(key2, g, j)) = half.get(i + 1) else {
            return Err(PolytopeError::NotManifold { a, b });
        };
        // the pair must be a -> b and b -> a, and no third half-edge on the same vertices
        let third = half.get(i + 2).is_some_and(|h| h.0 >> 1 == key >> 1);
        if key2 != key ^ 1 || key & 1 == 1 || third {
            return Err(PolytopeError::NotManifold { a, b });
        }
        let e = edges.len();
        edges.push(Edge { vertices: [a, b], faces: [f as usize, g as usize] });
        let (forward, backward) =
            (face_edges.starts()[f as usize] + k as usize, face_edges.starts()[g as usize] + j as usize);
        face_edges.data[forward] = e;
        face_edges.data[backward] = e;
        i += 2;
    }
    Ok((edges, face_edges))
}

/// Whether [`plane_of`] finds a plane for the face because its Newell normal is non-zero (the usual case; when it is
/// zero, `plane_of` tries a fallback, so `false` means "ask `plane_of`", not "degenerate").
fn has_area(vertices: &[DVec3], face: &[usize]) -> bool {
    // Newell's normal as `newell_normal` computes it (the same terms summed in the same order, so bit for bit the
    // same vector), by index; its squared length decides exactly what its length would (`sqrt` keeps 0, NaN and
    // infinity)
    let Some(&start) = face.first() else { return false };
    let first = vertices[start];
    let mut n = DVec3::ZERO;
    let mut p = first;
    for k in 1..=face.len() {
        let q = if k == face.len() { first } else { vertices[face[k]] };
        n.x += (p.y - q.y) * (p.z + q.z);
        n.y += (p.z - q.z) * (p.x + q.x);
        n.z += (p.x - q.x) * (p.y + q.y);
        p = q;
    }
    let len_sq = n.length_squared();
    len_sq > 0.0 && len_sq.is_finite()
}

fn plane_of(vertices: &[DVec3], face: &[usize]) -> Option<Plane> {
    let mut n = newell_normal(face.iter().map(|&i| vertices[i]));
    let mut len = n.length();
    if len.is_nan() || len <= 0.0 || !len.is_finite() {
        // A sliver face (a few ulps wide, e.g. between nearly coincident computed points) can make Newell's sums
        // cancel to zero. The cross products of consecutive edges of a convex counter-clockwise polygon all point
        // outwards, and for such slivers one of them is still non-zero: take the largest.
        let k = face.len();
        n = (0..k)
            .map(|i| {
                let (a, b, c) = (vertices[face[i]], vertices[face[(i + 1) % k]], vertices[face[(i + 2) % k]]);
                (b - a).cross(c - b)
            })
            .max_by(|x, y| x.length_squared().total_cmp(&y.length_squared()))
            .unwrap_or(DVec3::ZERO);
        len = n.length();
        if len.is_nan() || len <= 0.0 || !len.is_finite() {
            return None;
        }
    }
    let normal = n / len;
    let offset = face.iter().map(|&i| normal.dot(vertices[i])).fold(f64::NEG_INFINITY, f64::max);
    Some(Plane { normal, offset })
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn unit_cube() -> ConvexPolytope {
        ConvexPolytope::cuboid(DVec3::ZERO, DVec3::ONE).expect("cube")
    }

    #[test]
    fn from_faces_with_area_equals_from_faces_on_proper_faces() {
        let c = unit_cube();
        let faces = c.faces().to_vec();
        let a = ConvexPolytope::from_faces(c.vertices().to_vec(), faces.clone()).expect("checked");
        let b = ConvexPolytope::from_faces_with_area(c.vertices().to_vec(), faces.clone()).expect("unchecked area");
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
        // the manifold check stays
        let mut open = faces;
        open.pop();
        assert!(ConvexPolytope::from_faces_with_area(c.vertices().to_vec(), open).is_err());
    }

    #[test]
    fn has_area_decides_as_the_newell_length() {
        // the index loop must give exactly the decision of `newell_normal(..).length()`, slivers and zeros included
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..400 {
            let n = 3 + case % 5;
            let scale = [1.0, 1e-160, 1e155, 1e-300][case % 4];
            let vertices: Vec<DVec3> = (0..n)
                .map(|k| {
                    if case % 7 == 0 {
                        DVec3::new(k as f64, 2.0 * k as f64, 0.5) * scale // collinear: zero area
                    } else {
                        DVec3::new(next(), next(), next()) * scale
                    }
                })
                .collect();
            let face: Vec<usize> = (0..n).collect();
            let len = newell_normal(face.iter().map(|&i| vertices[i])).length();
            let expected = !len.is_nan() && len > 0.0 && len.is_finite();
            assert_eq!(has_area(&vertices, &face), expected, "case {case}");
        }
        assert!(!has_area(&[], &[]));
    }

    #[test]
    fn cuboid_is_valid_and_rejects_flat_boxes() {
        let b = ConvexPolytope::cuboid(DVec3::new(-1.0, 2.0, 0.0), DVec3::new(3.0, 2.5, 2.0)).expect("box");
        b.validate_exact().expect("valid");
        assert!((b.volume() - 4.0 * 0.5 * 2.0).abs() < 1e-12);
        assert!(ConvexPolytope::cuboid(DVec3::ZERO, DVec3::new(1.0, 0.0, 1.0)).is_err());
        assert!(ConvexPolytope::cuboid(DVec3::ZERO, DVec3::new(1.0, 1.0, f64::NAN)).is_err());
        assert!(ConvexPolytope::cuboid(DVec3::ONE, DVec3::ZERO).is_err());
    }

    #[test]
    fn cube_is_valid() {
        let c = unit_cube();
        assert_eq!(c.edges().len(), 12);
        c.validate().expect("valid");
        c.validate_exact().expect("valid exact");
        assert!((c.volume() - 1.0).abs() < 1e-15);
        assert_eq!(c.faces()[0].plane.normal, -DVec3::Z);
        assert_eq!(c.containment(DVec3::splat(0.5), c.tolerance()), Containment::Interior);
        assert_eq!(c.containment(DVec3::new(0.5, 0.5, 1.0), c.tolerance()), Containment::Boundary);
        assert_eq!(c.containment(DVec3::new(0.5, 0.5, 1.1), c.tolerance()), Containment::Exterior);
        for (ei, e) in c.edges().iter().enumerate() {
            for (side, &f) in e.faces.iter().enumerate() {
                let k = c.face_edges(f).iter().position(|&x| x == ei).expect("edge in face");
                let fv = &c.faces()[f].vertices;
                let (a, b) = (fv[k], fv[(k + 1) % fv.len()]);
                if side == 0 {
                    assert_eq!([a, b], e.vertices);
                } else {
                    assert_eq!([b, a], e.vertices);
                }
            }
        }
    }

    #[test]
    fn rejects_bad_face_lists() {
        let c = unit_cube();
        let v = c.vertices().to_vec();
        let mut faces: Vec<Vec<usize>> = c.faces().iter().map(|f| f.vertices.to_vec()).collect();
        faces.pop();
        assert!(matches!(ConvexPolytope::new(v.clone(), faces.clone()), Err(PolytopeError::NotManifold { .. })));
        faces.push(vec![1, 3]);
        assert!(matches!(ConvexPolytope::new(v.clone(), faces), Err(PolytopeError::FaceTooSmall { .. })));
        let mut bad = v.clone();
        bad[3].x = f64::NAN;
        let faces: Vec<Vec<usize>> = c.faces().iter().map(|f| f.vertices.to_vec()).collect();
        assert!(matches!(ConvexPolytope::new(bad, faces.clone()), Err(PolytopeError::NonFinite { vertex: 3 })));
        // every vertex and coordinate, every kind of non-finite value, also with a second bad vertex after it
        for (i, axis, value) in
            (0..8).flat_map(|i| (0..3).flat_map(move |a| [f64::NAN, f64::INFINITY, -f64::INFINITY].map(|x| (i, a, x))))
        {
            let mut bad = v.clone();
            bad[i][axis] = value;
            if i < 7 {
                bad[7].z = f64::NAN;
            }
            let got = ConvexPolytope::new(bad, faces.clone());
            assert!(
                matches!(got, Err(PolytopeError::NonFinite { vertex }) if vertex == i),
                "{i} {axis} {value}: {got:?}"
            );
        }
        // huge but finite coordinates whose sum overflows are accepted
        let huge: Vec<DVec3> = v.iter().map(|&p| p * f64::MAX).collect();
        assert!(!matches!(ConvexPolytope::new(huge, faces.clone()), Err(PolytopeError::NonFinite { .. })));
        // a dented cube: vertex 7 pushed inwards makes the polytope non-convex
        let mut dented = v;
        dented[7] = DVec3::splat(0.6);
        let p = ConvexPolytope::new(dented, faces).expect("manifold");
        assert!(p.validate_exact().is_err());
    }

    #[test]
    fn new_geometry_keeps_topology() {
        let c = unit_cube();
        let moved: Vec<DVec3> = c.vertices().iter().map(|v| *v * 2.0).collect();
        let planes: Vec<Plane> = c.planes().map(|p| Plane { normal: p.normal, offset: p.offset * 2.0 }).collect();
        let d = c.with_geometry(moved, planes).expect("same sizes");
        assert_eq!(d.edges(), c.edges());
        d.validate().expect("valid");
        assert!((d.volume() - 8.0).abs() < 1e-12);
        assert!(c.with_geometry(vec![DVec3::ZERO], Vec::new()).is_none());
    }

    #[test]
    fn face_edge_table_keeps_the_nested_list_format() {
        let c = unit_cube();
        let nested: Vec<Vec<usize>> = (0..c.faces().len()).map(|f| c.face_edges(f).to_vec()).collect();
        // Debug and JSON show the per-face lists exactly as a `Vec<Vec<usize>>` field did
        assert_eq!(format!("{:?}", c.face_edges), format!("{nested:?}"));
        let json = serde_json::to_value(&c).expect("serialise");
        assert_eq!(json["face_edges"], serde_json::to_value(&nested).expect("serialise lists"));
        let back: ConvexPolytope = serde_json::from_value(json).expect("deserialise");
        assert_eq!(back, c);
        assert_eq!(back.face_edges(5), c.face_edges(5));
    }

    #[test]
    fn edge_table_orders_edges_by_their_vertices() {
        // edges sorted by (smaller vertex, larger vertex), faces[0] traversing smaller -> larger, for any face order
        let c = unit_cube();
        let keys: Vec<[usize; 2]> = c.edges().iter().map(|e| e.vertices).collect();
        assert!(keys.windows(2).all(|w| w[0] < w[1]));
        assert!(keys.iter().all(|k| k[0] < k[1]));
        let mut faces: Vec<Vec<usize>> = c.faces().iter().map(|f| f.vertices.to_vec()).collect();
        faces.reverse();
        let r = ConvexPolytope::new(c.vertices().to_vec(), faces).expect("cube");
        assert_eq!(r.edges().iter().map(|e| e.vertices).collect::<Vec<_>>(), keys);
        // more vertices than the on-stack bucket table holds: a prism over a 100-gon
        let n = 100;
        let mut vertices = Vec::new();
        for k in 0..n {
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            vertices.push(DVec3::new(t.cos(), t.sin(), 0.0));
            vertices.push(DVec3::new(t.cos(), t.sin(), 1.0));
        }
        let mut faces = vec![(0..n).rev().map(|k| 2 * k).collect::<Vec<_>>(), (0..n).map(|k| 2 * k + 1).collect()];
        for k in 0..n {
            let m = (k + 1) % n;
            faces.push(vec![2 * k, 2 * m, 2 * m + 1, 2 * k + 1]);
        }
        let p = ConvexPolytope::new(vertices, faces).expect("prism");
        p.validate().expect("valid");
        assert_eq!(p.edges().len(), 3 * n);
        assert!(p.edges().windows(2).all(|w| w[0].vertices < w[1].vertices));
    }

    #[test]
    fn from_faces_equals_with_planes() {
        let c = unit_cube();
        let planes: Vec<Plane> = c.planes().map(|p| Plane { normal: p.normal, offset: p.offset + 0.5 }).collect();
        let faces: Vec<Vec<usize>> = c.faces().iter().map(|f| f.vertices.to_vec()).collect();
        let a = ConvexPolytope::with_planes(c.vertices().to_vec(), faces.clone(), planes.clone()).expect("cube");
        let given: Vec<Face> =
            faces.iter().zip(&planes).map(|(v, p)| Face { vertices: v.as_slice().into(), plane: *p }).collect();
        let b = ConvexPolytope::from_faces(c.vertices().to_vec(), given.clone()).expect("cube");
        assert_eq!(a, b);
        // fewer planes than faces: the rest are computed, as `new` does
        let c2 = ConvexPolytope::with_planes(c.vertices().to_vec(), faces.clone(), planes[..2].to_vec()).expect("cube");
        assert_eq!(c2.faces()[1].plane, planes[1]);
        assert_eq!(c2.faces()[2].plane, c.faces()[2].plane);
        // the same errors: a zero-area face, a non-manifold list
        let mut flat = c.vertices().to_vec();
        for v in [1, 3, 5, 7] {
            flat[v].x = 0.0;
        }
        let with_planes = ConvexPolytope::with_planes(flat.clone(), faces.clone(), planes.clone());
        assert!(matches!(with_planes, Err(PolytopeError::DegenerateFace { face: 0 })), "{with_planes:?}");
        assert_eq!(ConvexPolytope::from_faces(flat, given.clone()), with_planes);
        let mut open = given;
        open.pop();
        assert!(matches!(
            ConvexPolytope::from_faces(c.vertices().to_vec(), open),
            Err(PolytopeError::NotManifold { .. })
        ));
    }

    #[test]
    fn transform_keeps_validity() {
        let c = unit_cube();
        let r = DMat3::from_rotation_z(0.3) * DMat3::from_rotation_x(1.1);
        let t = c.transformed(r, DVec3::new(5.0, -2.0, 1.0));
        t.validate().expect("valid");
        assert!((t.volume() - 1.0).abs() < 1e-12);
    }
}
