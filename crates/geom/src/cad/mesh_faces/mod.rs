//! A closed triangle mesh of a bent sheet-metal part segmented into the faces of a [`Brep`]: planar regions, and
//! circular cylinders fitted to the chains of facets that tessellate bends.
//!
//! **Adjacency.** Every directed edge `a -> b` of a triangle must be traversed backwards (`b -> a`) by exactly one
//! other triangle, else the mesh is open or non-manifold and the offending triangle is named. O(T) expected
//! (hashing).
//!
//! **Planar regions.** Two triangles across an edge are coplanar when the angle between their unit normals is below
//! `1e-3 + t/8 (1/h1 + 1/h2)` rad (`h1`, `h2` their heights above the shared edge: what rounding the vertices
//! by `t/16` can turn the normals by) and the far vertex of each
//! lies within the planar tolerance `max(10 t, 1e-4 mm)` of the other's plane (`t` the mesh's length tolerance, a few
//! `f32` roundings of its largest coordinate). Regions are the connected components of that relation (union-find),
//! numbered by their first triangle in input order. A triangle whose height is within `t` of zero has no reliable
//! normal; it joins the region of its neighbour across its longest edge. A region's outward normal is the
//! area-weighted mean of its triangles' normals and its point their area-weighted centroid.
//!
//! **Bends.** Two regions sharing edges are smoothly joined when their normals differ by less than 35 degrees (the
//! facets of a tessellated cylinder, and a flat skin with the first facet of a bend), sharply otherwise (the cut
//! edges of the sheet). Seen along the direction `d` of their shared edges, a chain `skin, facet, ..., facet, skin`
//! of smoothly joined regions whose shared lines are all parallel to `d` is a polyline `Q0, Q1, ...` in the plane
//! perpendicular to `d`: each region a segment, each shared line a point. It tessellates a bend when one circle is
//! tangent to the first skin at the first point and to the last skin at the last point, and passes through every
//! point between, all within `1e-5 r + 10` `f32` roundings (`r` the radius; the fit is a Gauss-Newton least-squares
//! fit of centre and radius to these conditions). A chord cannot pass for a skin: three points of the arc fix its
//! circle, which is not tangent to a chord at its end. Only a run of a single facet has just two points, and inside a
//! uniformly tessellated arc the facets on either side of one facet look like skins of a smaller circle; such a run is
//! rejected when the chain continues on one circle beyond both of its skins.
//!
//! Runs are searched from every smooth shared line, with either region as the first skin, walking while the next
//! region is the only one smoothly joined to the current one along a parallel line and the points stay within 2 % of
//! the radius of the circle tangent to the first skin at the first point through the last. A walk is abandoned at its
//! third point when the first skin is itself a chord of the arc (its own far shared line lies on the circle through
//! the first three points, within ten fit tolerances: a true skin's far line is off that circle by about
//! `sqrt(r^2 + L^2) - r` for a skin of width `L`), so a closed chain of facets (a tessellated hole wall) costs O(1) per facet. Once a walk has five
//! points, the full fit is tried only where the current region is tangent, within a hundred fit tolerances, to the
//! circle tangent to the first skin through the last point. The longest runs are taken first, and a region is the
//! facet of at most one run (a skin may serve two runs: the base of a U-channel). The facets of a run become one
//! cylindrical face, its axis the mean direction of its shared lines, refitted; seen along the axis, every vertex of a
//! facet must lie on the facet's chord (between the points of its two shared lines, which are on the circle) within
//! four fit tolerances, else the run is no bend (a fan of facets on a cone or a torus can have parallel shared lines
//! whose points happen to fit a circle). Regions with smooth neighbours that
//! are not the facets of a run (tessellated hole walls, chamfers) stay planar faces.
//!
//! **Loops.** A face's boundary is its triangles' directed edges whose partner belongs to another face, chained at
//! each vertex by turning about it through the face's own triangles (so a face touching itself at a vertex still
//! gives simple loops); vertices within the planar tolerance of the line through their kept neighbours are dropped.
//! As the triangles are counter-clockwise seen from outside, the face lies to the left of its boundary: a planar
//! face's outer loop (the one of largest area) comes out counter-clockwise about the outward normal and is put
//! first, its holes clockwise.
//!
//! **Volume**: the divergence theorem over the triangles about the centre of the bounding box.
//!
//! Cost: O(T log T) for T triangles, plus O(k^2) for each bend tessellated into k facets (the walks from its two
//! skins, each step checking every point so far). With the usual angular deflection of 0.2 rad, k is at most 16 for
//! a bend of 180 degrees.

use super::{Brep, BrepFace, FaceSource, Segment, Surface};
use crate::accurate_normal::accurate_cross;
use crate::io::Place;
use crate::io::mesh::MeshPolygon;
use crate::union_find::{find, union};
use glam::{DMat3, DVec2, DVec3};
use std::collections::HashMap;

/// Coplanar triangles: the largest angle (rad) between their normals, before the rounding allowance.
const COPLANAR_ANGLE: f64 = 1e-3;
/// Smoothly joined regions: the largest angle between their normals (35 degrees).
const SMOOTH_ANGLE: f64 = 35.0 * std::f64::consts::PI / 180.0;
/// Parallel shared lines: the largest sine of the angle between them.
const PARALLEL_SINE: f64 = 1e-3;
/// The circle fit's tolerance relative to the radius.
const FIT_RELATIVE: f64 = 1e-5;
/// The walk's gate: how far (relative to the radius) points may stray from the circle tangent to the first skin.
const GATE_RELATIVE: f64 = 0.02;

/// Why a mesh cannot be segmented into faces.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshFaceError {
    /// No triangles.
    #[error("the mesh has no triangles")]
    Empty,
    /// A polygon that is not a triangle.
    #[error("the polygon at {place} has {count} vertices, not 3")]
    NotTriangle {
        /// Where it is in the file.
        place: Place,
        /// Its vertex count.
        count: usize,
    },
    /// A vertex index past the end of the points.
    #[error("the triangle at {place} refers to vertex {index}, but there are only {count} vertices")]
    BadIndex {
        /// Where the triangle is in the file.
        place: Place,
        /// The index.
        index: usize,
        /// The number of points.
        count: usize,
    },
    /// A vertex with a coordinate that is not finite.
    #[error("the triangle at {place} has a vertex with a coordinate that is not finite")]
    NotFinite {
        /// Where the triangle is in the file.
        place: Place,
    },
    /// A triangle naming one vertex twice.
    #[error("the triangle at {place} names vertex {vertex} twice")]
    RepeatedVertex {
        /// Where the triangle is in the file.
        place: Place,
        /// The repeated vertex.
        vertex: usize,
    },
    /// A directed edge with no partner.
    #[error("open mesh: the triangle at {place} has an edge that no other triangle traverses backwards")]
    Open {
        /// Where the triangle is in the file.
        place: Place,
    },
    /// A directed edge traversed by two triangles.
    #[error(
        "non-manifold edge: the triangle at {place} traverses an edge in the same direction as the triangle at {other}"
    )]
    NonManifold {
        /// Where the later triangle is in the file.
        place: Place,
        /// Where the earlier one is.
        other: Place,
    },
    /// Coplanar triangles that enclose no area together.
    #[error("the region of triangles starting at {place} has no area")]
    Degenerate {
        /// Where its first triangle is in the file.
        place: Place,
    },
    /// The boundary of a face does not chain into loops (a bug if it ever shows).
    #[error("the boundary of the face starting at the triangle at {place} does not close")]
    Boundary {
        /// Where the face's first triangle is in the file.
        place: Place,
    },
}

/// Segments a closed mesh into planar and cylindrical faces. See the module documentation.
///
/// `points` are welded vertices (neighbouring triangles share vertex indices), `triangles` have three vertex
/// indices each, counter-clockwise seen from outside, and `tolerance` is the mesh's length tolerance
/// ([`crate::io::mesh`]).
pub(crate) fn mesh_faces(points: &[DVec3], triangles: &[MeshPolygon], tolerance: f64) -> Result<Brep, MeshFaceError> {
    let mesh = Mesh::new(points, triangles, tolerance)?;
    let regions = mesh.planar_regions()?;
    let lines = mesh.shared_lines(&regions);
    let bends = mesh.bends(&regions, &lines)?;
    let faces = mesh.faces(&regions, &bends)?;
    let volume = mesh.volume();
    tracing::debug!(
        triangles = triangles.len(),
        regions = regions.regions.len(),
        bends = bends.len(),
        faces = faces.len(),
        volume,
        "mesh faces"
    );
    Ok(Brep { faces, volume: Some(volume), tessellation: None })
}

/// The validated mesh with triangle adjacency and per-triangle geometry.
struct Mesh<'a> {
    points: &'a [DVec3],
    input: &'a [MeshPolygon],
    tris: Vec<[usize; 3]>,
    /// The triangle across edge `k` (`v[k] -> v[k + 1]`) of each triangle.
    partner: Vec<[usize; 3]>,
    /// `(b - a) x (c - a)` of each triangle.
    cross: Vec<DVec3>,
    /// The mesh's length tolerance.
    tolerance: f64,
    /// The planar tolerance, `max(10 t, 1e-4 mm)`.
    planar: f64,
    /// The centre of the bounding box, the origin of sums and projections.
    centre: DVec3,
}

/// The planar regions.
struct Regions {
    /// The region of each triangle.
    of: Vec<usize>,
    regions: Vec<Region>,
}

struct Region {
    triangles: Vec<usize>,
    normal: DVec3,
    point: DVec3,
}

/// Where two regions meet.
struct SharedLine {
    regions: [usize; 2],
    smooth: bool,
    /// The extreme points of the shared edges, along the line.
    start: DVec3,
    end: DVec3,
}

impl SharedLine {
    fn direction(&self) -> DVec3 {
        (self.end - self.start).normalize_or_zero()
    }

    fn middle(&self) -> DVec3 {
        0.5 * (self.start + self.end)
    }

    fn other(&self, region: usize) -> usize {
        if self.regions[0] == region { self.regions[1] } else { self.regions[0] }
    }
}

/// A run of facets between two skins, and its fitted circle.
#[derive(Debug, Clone)]
struct Run {
    skins: [usize; 2],
    facets: Vec<usize>,
    /// The shared lines in order: skin-facet, facet-facet, ..., facet-skin.
    lines: Vec<usize>,
}

/// A fitted bend: the run and its cylinder.
#[derive(Debug)]
struct Bend {
    facets: Vec<usize>,
    point: DVec3,
    axis: DVec3,
    radius: f64,
    convex: bool,
}

/// An orthonormal frame with `d` the projection direction.
#[derive(Debug, Clone, Copy)]
struct Frame {
    origin: DVec3,
    u: DVec3,
    v: DVec3,
    d: DVec3,
}

impl Frame {
    fn new(origin: DVec3, d: DVec3) -> Self {
        let u = d.any_orthonormal_vector();
        Frame { origin, u, v: d.cross(u), d }
    }

    fn project(&self, p: DVec3) -> DVec2 {
        let w = p - self.origin;
        DVec2::new(w.dot(self.u), w.dot(self.v))
    }

    fn project_direction(&self, n: DVec3) -> DVec2 {
        DVec2::new(n.dot(self.u), n.dot(self.v)).normalize_or_zero()
    }

    fn lift(&self, q: DVec2) -> DVec3 {
        self.origin + q.x * self.u + q.y * self.v
    }
}

/// A circle in a frame's plane.
#[derive(Debug, Clone, Copy)]
struct Circle {
    centre: DVec2,
    radius: f64,
}

impl<'a> Mesh<'a> {
    fn new(points: &'a [DVec3], input: &'a [MeshPolygon], tolerance: f64) -> Result<Self, MeshFaceError> {
        if input.is_empty() {
            return Err(MeshFaceError::Empty);
        }
        let mut tris = Vec::with_capacity(input.len());
        for polygon in input {
            let place = || polygon.place.clone();
            let &[a, b, c] = polygon.vertices.as_slice() else {
                return Err(MeshFaceError::NotTriangle { place: place(), count: polygon.vertices.len() });
            };
            for v in [a, b, c] {
                let Some(p) = points.get(v) else {
                    return Err(MeshFaceError::BadIndex { place: place(), index: v, count: points.len() });
                };
                if !p.is_finite() {
                    return Err(MeshFaceError::NotFinite { place: place() });
                }
            }
            if a == b || a == c || b == c {
                let vertex = if a == b || a == c { a } else { b };
                return Err(MeshFaceError::RepeatedVertex { place: place(), vertex });
            }
            tris.push([a, b, c]);
        }
        let mut directed: HashMap<(usize, usize), usize> = HashMap::with_capacity(3 * tris.len());
        for (t, v) in tris.iter().enumerate() {
            for k in 0..3 {
                if let Some(other) = directed.insert((v[k], v[(k + 1) % 3]), t) {
                    return Err(MeshFaceError::NonManifold {
                        place: input[t].place.clone(),
                        other: input[other].place.clone(),
                    });
                }
            }
        }
        let mut partner = Vec::with_capacity(tris.len());
        for (t, v) in tris.iter().enumerate() {
            let mut across = [0; 3];
            for k in 0..3 {
                let Some(&s) = directed.get(&(v[(k + 1) % 3], v[k])) else {
                    return Err(MeshFaceError::Open { place: input[t].place.clone() });
                };
                across[k] = s;
            }
            partner.push(across);
        }
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for v in &tris {
            for &i in v {
                lo = lo.min(points[i]);
                hi = hi.max(points[i]);
            }
        }
        let centre = 0.5 * (lo + hi);
        let cross = tris.iter().map(|v| accurate_cross(points[v[0]], points[v[1]], points[v[2]])).collect();
        let tolerance = if tolerance.is_finite() && tolerance > 0.0 { tolerance } else { 0.0 };
        Ok(Mesh { points, input, tris, partner, cross, tolerance, planar: (10.0 * tolerance).max(1e-4), centre })
    }

    fn place(&self, t: usize) -> Place {
        self.input[t].place.clone()
    }

    fn point(&self, t: usize, k: usize) -> DVec3 {
        self.points[self.tris[t][k % 3]]
    }

    /// The height of a triangle above its longest edge.
    fn height(&self, t: usize) -> f64 {
        let longest = (0..3).map(|k| (self.point(t, k + 1) - self.point(t, k)).length()).fold(0.0, f64::max);
        if longest > 0.0 { self.cross[t].length() / longest } else { 0.0 }
    }

    /// Whether triangle `t` and its partner across edge `k` are coplanar (both with reliable normals).
    fn coplanar(&self, t: usize, k: usize) -> bool {
        let s = self.partner[t][k];
        let (a, b) = (self.tris[t][k], self.tris[t][(k + 1) % 3]);
        let (pa, pb) = (self.points[a], self.points[b]);
        let pc = self.point(t, k + 2);
        let Some(&d) = self.tris[s].iter().find(|&&v| v != a && v != b) else {
            return false;
        };
        let pd = self.points[d];
        let edge = (pb - pa).length();
        if edge <= 0.0 {
            return false;
        }
        let (ct, cs) = (self.cross[t], self.cross[s]);
        let (ht, hs) = (ct.length() / edge, cs.length() / edge);
        if ht <= self.tolerance || hs <= self.tolerance {
            return false;
        }
        let (nt, ns) = (ct.normalize(), cs.normalize());
        let angle = nt.cross(ns).length().atan2(nt.dot(ns));
        let allowed = COPLANAR_ANGLE + self.tolerance / 8.0 * (1.0 / ht + 1.0 / hs);
        angle <= allowed && (pd - pa).dot(nt).abs() <= self.planar && (pc - pa).dot(ns).abs() <= self.planar
    }

    fn planar_regions(&self) -> Result<Regions, MeshFaceError> {
        let n = self.tris.len();
        let mut parent: Vec<usize> = (0..n).collect();
        let degenerate: Vec<bool> = (0..n).map(|t| self.height(t) <= self.tolerance).collect();
        for t in 0..n {
            for k in 0..3 {
                let s = self.partner[t][k];
                if t < s && !degenerate[t] && !degenerate[s] && self.coplanar(t, k) {
                    union(&mut parent, t, s);
                }
            }
        }
        for t in (0..n).filter(|&t| degenerate[t]) {
            // the neighbour across the longest edge, preferring one with a reliable normal
            let mut order: Vec<usize> = (0..3).collect();
            let length = |k: usize| (self.point(t, k + 1) - self.point(t, k)).length();
            order.sort_by(|&x, &y| length(y).total_cmp(&length(x)));
            let s = order
                .iter()
                .map(|&k| self.partner[t][k])
                .find(|&s| !degenerate[s])
                .unwrap_or(self.partner[t][order[0]]);
            union(&mut parent, t, s);
        }
        let mut of = vec![0; n];
        let mut index_of_root: HashMap<usize, usize> = HashMap::new();
        let mut regions: Vec<Region> = Vec::new();
        for t in 0..n {
            let root = find(&mut parent, t);
            let next = regions.len();
            let r = *index_of_root.entry(root).or_insert(next);
            if r == next {
                regions.push(Region { triangles: Vec::new(), normal: DVec3::ZERO, point: DVec3::ZERO });
            }
            regions[r].triangles.push(t);
            of[t] = r;
        }
        for region in &mut regions {
            let (mut sum, mut weighted, mut area) = (DVec3::ZERO, DVec3::ZERO, 0.0);
            for &t in &region.triangles {
                let c = self.cross[t];
                let a = c.length();
                sum += c;
                area += a;
                let centroid = (self.point(t, 0) + self.point(t, 1) + self.point(t, 2)) / 3.0 - self.centre;
                weighted += a * centroid;
            }
            let normal = sum.normalize_or_zero();
            if normal == DVec3::ZERO || area <= 0.0 {
                return Err(MeshFaceError::Degenerate { place: self.place(region.triangles[0]) });
            }
            region.normal = normal;
            region.point = self.centre + weighted / area;
        }
        Ok(Regions { of, regions })
    }

    /// The lines where regions meet, each pair of regions once.
    fn shared_lines(&self, regions: &Regions) -> Vec<SharedLine> {
        let mut index: HashMap<(usize, usize), usize> = HashMap::new();
        let mut edges: Vec<Vec<(usize, usize)>> = Vec::new();
        for (t, v) in self.tris.iter().enumerate() {
            for k in 0..3 {
                let (rt, rs) = (regions.of[t], regions.of[self.partner[t][k]]);
                if rt < rs {
                    let next = edges.len();
                    let i = *index.entry((rt, rs)).or_insert(next);
                    if i == next {
                        edges.push(Vec::new());
                    }
                    edges[i].push((v[k], v[(k + 1) % 3]));
                }
            }
        }
        let mut pairs: Vec<((usize, usize), usize)> = index.into_iter().collect();
        pairs.sort_unstable();
        pairs
            .into_iter()
            .map(|((ra, rb), i)| {
                let (na, nb) = (regions.regions[ra].normal, regions.regions[rb].normal);
                let angle = na.cross(nb).length().atan2(na.dot(nb));
                let e = &edges[i];
                let (a0, b0) = (self.points[e[0].0], self.points[e[0].1]);
                let dir = (b0 - a0).normalize_or_zero();
                let (mut start, mut end) = (a0, b0);
                let (mut lo, mut hi) = (0.0, (b0 - a0).dot(dir));
                for &(a, b) in e {
                    for p in [self.points[a], self.points[b]] {
                        let s = (p - a0).dot(dir);
                        if s < lo {
                            lo = s;
                            start = p;
                        }
                        if s > hi {
                            hi = s;
                            end = p;
                        }
                    }
                }
                SharedLine { regions: [ra, rb], smooth: angle < SMOOTH_ANGLE, start, end }
            })
            .collect()
    }

    /// The fit tolerance for a circle of radius `r`: relative, plus ten `f32` roundings.
    fn fit_tolerance(&self, r: f64) -> f64 {
        FIT_RELATIVE * r + self.tolerance * 10.0 / 16.0
    }

    /// Finds the bends: see the module documentation.
    fn bends(&self, regions: &Regions, lines: &[SharedLine]) -> Result<Vec<Bend>, MeshFaceError> {
        let mut smooth_at: Vec<Vec<usize>> = vec![Vec::new(); regions.regions.len()];
        for (i, line) in lines.iter().enumerate() {
            if line.smooth {
                smooth_at[line.regions[0]].push(i);
                smooth_at[line.regions[1]].push(i);
            }
        }
        let mut runs: Vec<Run> = Vec::new();
        for (i, line) in lines.iter().enumerate() {
            if !line.smooth {
                continue;
            }
            for skin in line.regions {
                if let Some(run) = self.walk(regions, lines, &smooth_at, skin, i) {
                    runs.push(run);
                }
            }
        }
        runs.sort_by(|x, y| y.facets.len().cmp(&x.facets.len()).then(x.skins.cmp(&y.skins)));
        #[derive(Clone, Copy, PartialEq)]
        enum Role {
            Free,
            Skin,
            Facet,
        }
        let mut role = vec![Role::Free; regions.regions.len()];
        let mut bends = Vec::new();
        for run in runs {
            if run.facets.iter().any(|&f| role[f] != Role::Free) || run.skins.iter().any(|&s| role[s] == Role::Facet) {
                continue;
            }
            let Some(bend) = self.fit_bend(regions, lines, &run) else {
                continue;
            };
            for &f in &run.facets {
                role[f] = Role::Facet;
            }
            for &s in &run.skins {
                role[s] = Role::Skin;
            }
            tracing::debug!(
                skins = ?run.skins,
                facets = run.facets.len(),
                radius = bend.radius,
                convex = bend.convex,
                "bend"
            );
            bends.push(bend);
        }
        Ok(bends)
    }

    /// The smooth lines of `region` parallel to `d` other than `except`.
    fn parallel_lines(
        &self,
        lines: &[SharedLine],
        smooth_at: &[Vec<usize>],
        region: usize,
        except: usize,
        d: DVec3,
    ) -> Vec<usize> {
        smooth_at[region]
            .iter()
            .copied()
            .filter(|&l| l != except && lines[l].direction().cross(d).length() <= PARALLEL_SINE)
            .collect()
    }

    /// The longest valid run starting with `skin` across `first` (a smooth line of `skin`).
    fn walk(
        &self,
        regions: &Regions,
        lines: &[SharedLine],
        smooth_at: &[Vec<usize>],
        skin: usize,
        first: usize,
    ) -> Option<Run> {
        let d = lines[first].direction();
        if d == DVec3::ZERO {
            return None;
        }
        let frame = Frame::new(self.centre, d);
        let tangent_normal = frame.project_direction(regions.regions[skin].normal);
        let mut run = Run { skins: [skin, skin], facets: Vec::new(), lines: vec![first] };
        let mut points = vec![frame.project(lines[first].middle())];
        let mut current = lines[first].other(skin);
        let before = match self.parallel_lines(lines, smooth_at, skin, first, d).as_slice() {
            &[b] => Some(frame.project(lines[b].middle())),
            _ => None,
        };
        let mut best: Option<Run> = None;
        let limit = regions.regions.len();
        while run.facets.len() < limit {
            if !run.facets.is_empty() && self.tangent_at_end(&points, tangent_normal, &frame, regions, current) {
                // `current` as the end skin
                let candidate = Run { skins: [skin, current], facets: run.facets.clone(), lines: run.lines.clone() };
                if self.valid(regions, lines, &candidate, &frame, smooth_at) {
                    best = Some(candidate);
                }
            }
            let Some(&last) = run.lines.last() else { break };
            let next = self.parallel_lines(lines, smooth_at, current, last, d);
            let &[line] = next.as_slice() else { break };
            let following = lines[line].other(current);
            if following == skin || run.facets.contains(&following) {
                break;
            }
            run.facets.push(current);
            run.lines.push(line);
            points.push(frame.project(lines[line].middle()));
            if points.len() == 3
                && let Some(before) = before
                && let Some(c) = circumcircle(points[0], points[1], points[2])
                && ((before - c.centre).length() - c.radius).abs() <= 10.0 * self.fit_tolerance(c.radius)
            {
                // the skin is itself a chord of the arc that the walk follows
                return None;
            }
            if !gate(&points, tangent_normal) {
                break;
            }
            current = following;
        }
        best
    }

    /// A cheap test before the fit, once a run is long enough for the circle tangent to the first skin through the
    /// last point to be well determined: whether `end` is nearly tangent to that circle at the last point.
    fn tangent_at_end(&self, points: &[DVec2], normal: DVec2, frame: &Frame, regions: &Regions, end: usize) -> bool {
        let (Some(&p0), Some(&pl)) = (points.first(), points.last()) else { return false };
        if points.len() < 5 {
            return true;
        }
        let Some(c) = tangent_circle(p0, normal, pl) else { return false };
        let t = frame.project_direction(regions.regions[end].normal).perp();
        (c.centre - pl).dot(t).abs() <= 100.0 * self.fit_tolerance(c.radius)
    }

    /// Whether a run's points fit one circle tangent to both skins (and, for a single facet, the chain does not
    /// continue on that circle beyond both skins).
    fn valid(
        &self,
        regions: &Regions,
        lines: &[SharedLine],
        run: &Run,
        frame: &Frame,
        smooth_at: &[Vec<usize>],
    ) -> bool {
        let Some((circle, residual)) = fit_run(regions, lines, run, frame) else {
            return false;
        };
        if residual > self.fit_tolerance(circle.radius) {
            return false;
        }
        if run.facets.len() == 1 {
            let (Some(&first), Some(&last)) = (run.lines.first(), run.lines.last()) else {
                return false;
            };
            let before = self.parallel_lines(lines, smooth_at, run.skins[0], first, frame.d);
            let after = self.parallel_lines(lines, smooth_at, run.skins[1], last, frame.d);
            if let (&[b], &[a]) = (before.as_slice(), after.as_slice()) {
                let q = [lines[b].middle(), lines[first].middle(), lines[last].middle(), lines[a].middle()]
                    .map(|p| frame.project(p));
                if let Some(c) = circumcircle(q[0], q[1], q[2])
                    && ((q[3] - c.centre).length() - c.radius).abs() <= self.fit_tolerance(c.radius)
                {
                    return false;
                }
            }
        }
        true
    }

    /// The cylinder of an accepted run, its axis the mean direction of its lines; `None` if the refined fit fails.
    fn fit_bend(&self, regions: &Regions, lines: &[SharedLine], run: &Run) -> Option<Bend> {
        let &first = run.lines.first()?;
        let reference = lines[first].direction();
        let mut sum = DVec3::ZERO;
        for &l in &run.lines {
            let v = lines[l].end - lines[l].start;
            sum += if v.dot(reference) < 0.0 { -v } else { v };
        }
        let axis = sum.normalize_or_zero();
        if axis == DVec3::ZERO {
            return None;
        }
        let frame = Frame::new(self.centre, axis);
        let (circle, residual) = fit_run(regions, lines, run, &frame)?;
        let tolerance = self.fit_tolerance(circle.radius);
        if residual > tolerance {
            tracing::debug!(residual, tolerance, "the refined fit of a run fails");
            return None;
        }
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut worst: Option<(f64, usize, usize)> = None;
        for (i, &f) in run.facets.iter().enumerate() {
            // the facet's chord: every vertex of the facet projects onto it
            let q0 = frame.project(lines[run.lines[i]].middle());
            let q1 = frame.project(lines[run.lines[i + 1]].middle());
            for &t in &regions.regions[f].triangles {
                for &v in &self.tris[t] {
                    let p = self.points[v];
                    let s = (p - frame.origin).dot(axis);
                    lo = lo.min(s);
                    hi = hi.max(s);
                    let off = segment_distance(frame.project(p), q0, q1);
                    if worst.is_none_or(|(w, _, _)| off > w) {
                        worst = Some((off, v, t));
                    }
                }
            }
        }
        let point = frame.lift(circle.centre) + 0.5 * (lo + hi) * axis;
        if let Some((distance, vertex, t)) = worst
            && distance > 4.0 * tolerance
        {
            // the shared lines fit a circle but the facets between them do not follow it (a fan of facets on a
            // cone or a torus whose shared lines happen to be parallel): no bend, its regions stay planar faces
            let place = self.place(t);
            tracing::debug!(%place, vertex, distance, radius = circle.radius, "a run of facets is not a cylinder");
            return None;
        }
        // convex: the middle facet's outward normal points away from the axis
        let m = run.facets.len() / 2;
        let middle =
            0.5 * (frame.project(lines[run.lines[m]].middle()) + frame.project(lines[run.lines[m + 1]].middle()));
        let normal = frame.project_direction(regions.regions[run.facets[m]].normal);
        let convex = normal.dot(middle - circle.centre) > 0.0;
        Some(Bend { facets: run.facets.clone(), point, axis, radius: circle.radius, convex })
    }

    /// The faces: cylinders for the bends, planes for the other regions, numbered by their first triangle.
    fn faces(&self, regions: &Regions, bends: &[Bend]) -> Result<Vec<BrepFace>, MeshFaceError> {
        let nr = regions.regions.len();
        // group of each region: bends first, then the remaining regions
        let mut group: Vec<Option<usize>> = vec![None; nr];
        for (b, bend) in bends.iter().enumerate() {
            for &f in &bend.facets {
                group[f] = Some(b);
            }
        }
        let mut next = bends.len();
        let group: Vec<usize> = group
            .into_iter()
            .map(|g| {
                g.unwrap_or_else(|| {
                    next += 1;
                    next - 1
                })
            })
            .collect();
        // first triangle of each group, and the face order
        let mut first = vec![usize::MAX; next];
        for (r, region) in regions.regions.iter().enumerate() {
            first[group[r]] = first[group[r]].min(region.triangles[0]);
        }
        let mut order: Vec<usize> = (0..next).collect();
        order.sort_by_key(|&g| first[g]);
        let mut face_of_group = vec![0; next];
        for (f, &g) in order.iter().enumerate() {
            face_of_group[g] = f;
        }
        let face_of: Vec<usize> = (0..self.tris.len()).map(|t| face_of_group[group[regions.of[t]]]).collect();
        let loops = self.boundary_loops(&face_of, order.len())?;
        let mut faces = Vec::with_capacity(order.len());
        let mut region_of_group = vec![0; next];
        for (r, &g) in group.iter().enumerate() {
            region_of_group[g] = r;
        }
        for (f, (&g, face_loops)) in order.iter().zip(loops).enumerate() {
            let source = FaceSource::Mesh { region: f, first_triangle: self.place(first[g]).to_string() };
            let (surface, loops) = if let Some(bend) = bends.get(g) {
                let surface =
                    Surface::Cylinder { point: bend.point, axis: bend.axis, radius: bend.radius, convex: bend.convex };
                let loops = face_loops.iter().map(|l| self.simplify(l)).collect();
                (surface, loops)
            } else {
                let region = &regions.regions[region_of_group[g]];
                let normal = region.normal;
                let mut loops: Vec<Vec<DVec3>> = face_loops.iter().map(|l| self.simplify(l)).collect();
                let area = |l: &Vec<DVec3>| signed_area(l, normal).abs();
                if let Some((outer, _)) = loops.iter().enumerate().max_by(|(_, x), (_, y)| area(x).total_cmp(&area(y)))
                {
                    loops.swap(0, outer);
                }
                (Surface::Plane { point: region.point, normal }, loops)
            };
            let loops = loops
                .into_iter()
                .map(|l| (0..l.len()).map(|i| Segment::Line { start: l[i], end: l[(i + 1) % l.len()] }).collect())
                .collect();
            faces.push(BrepFace { source, surface, loops });
        }
        Ok(faces)
    }

    /// The boundary loops of each face (as points), chained by turning about each vertex through the face.
    fn boundary_loops(&self, face_of: &[usize], faces: usize) -> Result<Vec<Vec<Vec<DVec3>>>, MeshFaceError> {
        let n = self.tris.len();
        let boundary = |t: usize, k: usize| face_of[self.partner[t][k]] != face_of[t];
        let mut seen = vec![[false; 3]; n];
        let mut out: Vec<Vec<Vec<DVec3>>> = vec![Vec::new(); faces];
        for t0 in 0..n {
            for k0 in 0..3 {
                if seen[t0][k0] || !boundary(t0, k0) {
                    continue;
                }
                let face = face_of[t0];
                let mut lp = Vec::new();
                let (mut t, mut k) = (t0, k0);
                loop {
                    if seen[t][k] {
                        if (t, k) == (t0, k0) {
                            break;
                        }
                        return Err(MeshFaceError::Boundary { place: self.place(t0) });
                    }
                    seen[t][k] = true;
                    lp.push(self.point(t, k));
                    // the next boundary edge out of the end vertex b, turning through the face's triangles
                    let b = self.tris[t][(k + 1) % 3];
                    let (mut u, mut j) = (t, (k + 1) % 3);
                    let mut steps = 0;
                    while !boundary(u, j) {
                        u = self.partner[u][j];
                        let Some(pos) = self.tris[u].iter().position(|&v| v == b) else {
                            return Err(MeshFaceError::Boundary { place: self.place(t0) });
                        };
                        j = pos;
                        steps += 1;
                        if steps > n {
                            return Err(MeshFaceError::Boundary { place: self.place(t0) });
                        }
                    }
                    (t, k) = (u, j);
                }
                out[face].push(lp);
            }
        }
        Ok(out)
    }

    /// A closed loop without the vertices within the planar tolerance of the line through their kept neighbours.
    fn simplify(&self, lp: &[DVec3]) -> Vec<DVec3> {
        let n = lp.len();
        if n < 4 {
            return lp.to_vec();
        }
        let off = |p: DVec3, a: DVec3, b: DVec3| {
            let ab = b - a;
            let len2 = ab.length_squared();
            if len2 > 0.0 { (p - a).cross(ab).length() / len2.sqrt() } else { (p - a).length() }
        };
        // start at the sharpest corner
        let anchor = (0..n)
            .max_by(|&x, &y| {
                let dev = |i: usize| off(lp[i], lp[(i + n - 1) % n], lp[(i + 1) % n]);
                dev(x).total_cmp(&dev(y))
            })
            .unwrap_or(0);
        let at = |i: usize| lp[(anchor + i) % n];
        let mut kept = vec![at(0)];
        let mut i = 0;
        while i < n {
            let mut j = i + 1;
            while j < n && (i + 1..=j).all(|m| off(at(m), at(i), at(j + 1)) <= self.planar) {
                j += 1;
            }
            if j < n {
                kept.push(at(j));
            }
            i = j;
        }
        if kept.len() < 3 { lp.to_vec() } else { kept }
    }

    /// The enclosed volume, by the divergence theorem about the bounding box's centre.
    fn volume(&self) -> f64 {
        let o = self.centre;
        self.tris
            .iter()
            .map(|v| {
                let (a, b, c) = (self.points[v[0]] - o, self.points[v[1]] - o, self.points[v[2]] - o);
                a.dot(b.cross(c))
            })
            .sum::<f64>()
            / 6.0
    }
}

/// The distance of `p` from the segment `ab`.
fn segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 { ((p - a).dot(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (p - a - s * ab).length()
}

/// Whether the points stay near the circle tangent to the first skin (2-D unit normal `normal`) at the first point
/// and through the last.
fn gate(points: &[DVec2], normal: DVec2) -> bool {
    let (Some(&p0), Some(&pl)) = (points.first(), points.last()) else { return false };
    let Some(c) = tangent_circle(p0, normal, pl) else { return false };
    let allowed = GATE_RELATIVE * c.radius;
    points.iter().all(|&p| ((p - c.centre).length() - c.radius).abs() <= allowed)
}

/// The circle tangent at `p` to the line with normal `normal` and through `q`.
fn tangent_circle(p: DVec2, normal: DVec2, q: DVec2) -> Option<Circle> {
    let w = p - q;
    let denominator = 2.0 * normal.dot(w);
    if denominator.abs() <= 1e-12 * w.length() || !denominator.is_finite() {
        return None;
    }
    let s = -w.length_squared() / denominator;
    Some(Circle { centre: p + s * normal, radius: s.abs() })
}

/// The circle through three points.
fn circumcircle(a: DVec2, b: DVec2, c: DVec2) -> Option<Circle> {
    let (b, c) = (b - a, c - a);
    let d = 2.0 * b.perp_dot(c);
    if d.abs() <= 1e-300 {
        return None;
    }
    let (bb, cc) = (b.length_squared(), c.length_squared());
    let centre = DVec2::new(c.y * bb - b.y * cc, b.x * cc - c.x * bb) / d;
    let radius = centre.length();
    radius.is_finite().then_some(Circle { centre: a + centre, radius })
}

/// The least-squares circle through a run's points, tangent to both skins: its points are the projections of the
/// run's shared lines; the residuals are each point's distance from the circle and the distance of the centre from
/// each skin's normal line through its point. Returns the circle and the largest residual.
fn fit_run(regions: &Regions, lines: &[SharedLine], run: &Run, frame: &Frame) -> Option<(Circle, f64)> {
    let points: Vec<DVec2> = run.lines.iter().map(|&l| frame.project(lines[l].middle())).collect();
    let (&p0, &pl) = (points.first()?, points.last()?);
    let [ma, mb] = run.skins.map(|s| frame.project_direction(regions.regions[s].normal));
    if ma == DVec2::ZERO || mb == DVec2::ZERO {
        return None;
    }
    let (ta, tb) = (ma.perp(), mb.perp());
    let start = tangent_circle(p0, ma, pl)?;
    let (mut c, mut r) = (start.centre, start.radius);
    let residuals = |c: DVec2, r: f64| {
        let mut out: Vec<(f64, DVec3)> = points
            .iter()
            .map(|&p| {
                let w = c - p;
                let len = w.length();
                let g = if len > 0.0 { w / len } else { DVec2::ZERO };
                (len - r, DVec3::new(g.x, g.y, -1.0))
            })
            .collect();
        out.push(((c - p0).dot(ta), DVec3::new(ta.x, ta.y, 0.0)));
        out.push(((c - pl).dot(tb), DVec3::new(tb.x, tb.y, 0.0)));
        out
    };
    for _ in 0..8 {
        let rows = residuals(c, r);
        let mut normal = DMat3::ZERO;
        let mut rhs = DVec3::ZERO;
        for (e, g) in &rows {
            normal += DMat3::from_cols(g * g.x, g * g.y, g * g.z);
            rhs += g * *e;
        }
        if normal.determinant().abs() <= 1e-300 {
            return None;
        }
        let step = normal.inverse() * rhs;
        if !step.is_finite() {
            return None;
        }
        c -= DVec2::new(step.x, step.y);
        r -= step.z;
        if step.length() <= 1e-15 * r.abs().max(1.0) {
            break;
        }
    }
    let worst = residuals(c, r).iter().map(|(e, _)| e.abs()).fold(0.0, f64::max);
    (r > 0.0 && r.is_finite() && worst.is_finite()).then_some((Circle { centre: c, radius: r }, worst))
}

/// Twice the signed area of a closed polygon about `normal`, halved.
fn signed_area(lp: &[DVec3], normal: DVec3) -> f64 {
    let Some(&o) = lp.first() else { return 0.0 };
    let mut sum = DVec3::ZERO;
    for i in 1..lp.len().saturating_sub(1) {
        sum += (lp[i] - o).cross(lp[i + 1] - o);
    }
    0.5 * sum.dot(normal)
}

#[cfg(test)]
mod tests;
