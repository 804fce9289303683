//! The surface elements a PC can name, for people: every face (unit outward normal, centroid, area), edge (end
//! points, its two faces, convexity) and vertex (position), with the labels `f3`, `e7`, `v2` of the PCs and, where the
//! part's faces have names, those names.
//!
//! *Names.* A sheet-metal part (`PartOrigin::SheetMetal`) is a set of plates, one per face of its model; a merged
//! surface face lying in a face plane of plate `k`'s filled outline (same outward normal, centroid on the plane within
//! the surface tolerance) is `plate{k}.front` when its normal is the plate's normal, `plate{k}.back` when opposite, and
//! `plate{k}.rim` otherwise (`k` from 1). An edge whose two faces are named is `name0|name1`. Parts of other origins
//! have no names; their elements keep their labels. Cost O(faces x plates x faces of a plate).

use crate::principal_contact::ContactState;
use crate::surface::{Element, ElementKind, SurfaceElements};
use serde::{Deserialize, Serialize};
use stackplan_geom::{DVec3, Part, PartOrigin};

/// One face.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FaceFeature {
    /// Index (`f{index}` in labels).
    pub index: usize,
    /// Label, `f{index}`.
    pub label: String,
    /// Its name, when the part's faces have names.
    pub name: Option<String>,
    /// Unit outward normal.
    pub normal: [f64; 3],
    /// Centroid of its area (mm).
    pub centroid: [f64; 3],
    /// Area (mm^2).
    pub area: f64,
}

/// One edge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EdgeFeature {
    /// Index (`e{index}`).
    pub index: usize,
    /// Label, `e{index}`.
    pub label: String,
    /// `name0|name1` when both faces are named.
    pub name: Option<String>,
    /// Its end points (mm), those of `vertices`.
    pub endpoints: [[f64; 3]; 2],
    /// Its end vertices (indices).
    pub vertices: [usize; 2],
    /// The two faces meeting at it (indices).
    pub faces: [usize; 2],
    /// Whether it is convex (only convex edges make e-e PPCs).
    pub convex: bool,
}

/// One vertex.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VertexFeature {
    /// Index (`v{index}`).
    pub index: usize,
    /// Label, `v{index}`.
    pub label: String,
    /// Position (mm).
    pub position: [f64; 3],
    /// Whether it is convex (only convex vertices make f-v / v-f PPCs).
    pub convex: bool,
}

/// Every element of one part's surface.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Features {
    /// Faces, by index.
    pub faces: Vec<FaceFeature>,
    /// Edges, by index.
    pub edges: Vec<EdgeFeature>,
    /// Vertices, by index.
    pub vertices: Vec<VertexFeature>,
}

fn arr(p: DVec3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// Area and area centroid of a planar polygon (fan triangulation; convex pieces).
fn polygon_area_centroid(poly: &[DVec3]) -> (f64, DVec3) {
    let (mut area, mut moment) = (0.0, DVec3::ZERO);
    for i in 1..poly.len().saturating_sub(1) {
        let (a, b, c) = (poly[0], poly[i], poly[i + 1]);
        let w = 0.5 * (b - a).cross(c - a).length();
        area += w;
        moment += (a + b + c) / 3.0 * w;
    }
    (area, moment)
}

impl Features {
    /// The elements of `surface`, with the face names `names` (by face index; missing or `None` entries unnamed).
    pub fn new(surface: &SurfaceElements, names: &[Option<String>]) -> Self {
        let name = |f: usize| names.get(f).cloned().flatten();
        let faces = (0..surface.faces.len())
            .map(|f| {
                let (mut area, mut moment) = (0.0, DVec3::ZERO);
                for poly in surface.face_pieces_3d(f) {
                    let (a, m) = polygon_area_centroid(&poly);
                    area += a;
                    moment += m;
                }
                let centroid = if area > 0.0 { moment / area } else { surface.faces[f].frame.origin };
                FaceFeature {
                    index: f,
                    label: Element::face(f).label(),
                    name: name(f),
                    normal: arr(surface.faces[f].plane.normal),
                    centroid: arr(centroid),
                    area,
                }
            })
            .collect();
        let edges = surface
            .edges
            .iter()
            .enumerate()
            .map(|(e, edge)| {
                let (p, q) = surface.edge_points(e);
                EdgeFeature {
                    index: e,
                    label: Element::edge(e).label(),
                    name: name(edge.faces[0]).zip(name(edge.faces[1])).map(|(a, b)| format!("{a}|{b}")),
                    endpoints: [arr(p), arr(q)],
                    vertices: edge.vertices,
                    faces: edge.faces,
                    convex: edge.convex,
                }
            })
            .collect();
        let vertices = surface
            .vertices
            .iter()
            .enumerate()
            .map(|(v, vertex)| VertexFeature {
                index: v,
                label: Element::vertex(v).label(),
                position: arr(vertex.position),
                convex: vertex.convex,
            })
            .collect();
        Self { faces, edges, vertices }
    }

    /// The readable name of an element: its name when it has one, else its label.
    pub fn element_name(&self, e: Element) -> String {
        let named = match e.kind {
            ElementKind::Face => self.faces.get(e.index).and_then(|f| f.name.clone()),
            ElementKind::Edge => self.edges.get(e.index).and_then(|f| f.name.clone()),
            ElementKind::Vertex => None,
        };
        named.unwrap_or_else(|| e.label())
    }

    /// Whether any face is named.
    pub fn has_names(&self) -> bool {
        self.faces.iter().any(|f| f.name.is_some())
    }
}

/// The state's label with readable element names (`{plate1.front-v3, ...}`); the plain label when neither part has
/// names.
pub fn readable_label(state: &ContactState, fixed: &Features, moving: &Features) -> String {
    if !fixed.has_names() && !moving.has_names() {
        return state.label();
    }
    let parts: Vec<String> =
        state.pcs.iter().map(|pc| format!("{}-{}", fixed.element_name(pc.a), moving.element_name(pc.b))).collect();
    format!("{{{}}}", parts.join(", "))
}

/// The names of `surface`'s faces from the plates of a sheet-metal `part` (see the module documentation); all `None`
/// for other parts.
pub fn face_names(part: &Part, surface: &SurfaceElements) -> Vec<Option<String>> {
    let mut out = vec![None; surface.faces.len()];
    if !matches!(part.origin, PartOrigin::SheetMetal { .. }) {
        return out;
    }
    let tol = surface.tolerance;
    for (f, face) in surface.faces.iter().enumerate() {
        let n = face.plane.normal;
        let pieces = surface.face_pieces_3d(f);
        let count = pieces.iter().map(Vec::len).sum::<usize>().max(1);
        let centre = pieces.iter().flatten().copied().sum::<DVec3>() / count as f64;
        for (k, plate) in part.plates().iter().enumerate() {
            let on_plate =
                plate.filled.planes().any(|p| p.normal.dot(n) > 1.0 - 1e-9 && p.signed_distance(centre).abs() <= tol);
            if on_plate {
                let along = n.dot(plate.normal);
                let side = if along > 0.5 {
                    "front"
                } else if along < -0.5 {
                    "back"
                } else {
                    "rim"
                };
                out[f] = Some(format!("plate{}.{side}", k + 1));
                break;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_channels_faces_are_named_after_its_plates() {
        let part = stackplan_geom::examples::part_by_name("channel", Default::default()).expect("channel");
        let surface = SurfaceElements::from_part(&part).expect("surface");
        let names = face_names(&part, &surface);
        let features = Features::new(&surface, &names);
        // the base's two sides, each flange's two sides
        for name in ["plate1.front", "plate1.back", "plate2.front", "plate2.back", "plate3.front", "plate3.back"] {
            assert!(names.iter().flatten().any(|n| n == name), "{name} in {names:?}");
        }
        // every face named; a front face's normal is its plate's normal
        assert!(names.iter().all(Option::is_some), "{names:?}");
        for f in &features.faces {
            let name = f.name.as_deref().expect("named");
            let k: usize = name[5..name.find('.').expect("dot")].parse().expect("plate number");
            let n = DVec3::from_array(f.normal).dot(part.plates()[k - 1].normal);
            match &name[name.find('.').expect("dot") + 1..] {
                "front" => assert!(n > 0.999, "{name} {n}"),
                "back" => assert!(n < -0.999, "{name} {n}"),
                _ => assert!(n.abs() < 0.5, "{name} {n}"),
            }
        }
        // an edge between two named faces has both names
        assert!(features.edges.iter().all(|e| e.name.as_deref().is_some_and(|n| n.contains('|'))));
    }

    #[test]
    fn a_block_has_no_names_and_its_centroids_are_its_face_centres() {
        let part = stackplan_geom::examples::block_part();
        let surface = SurfaceElements::from_part(&part).expect("surface");
        let names = face_names(&part, &surface);
        assert!(names.iter().all(Option::is_none));
        let features = Features::new(&surface, &names);
        assert_eq!((features.vertices.len(), features.edges.len(), features.faces.len()), (8, 12, 6));
        for f in &features.faces {
            let (c, n) = (DVec3::from_array(f.centroid), DVec3::from_array(f.normal));
            // the centre of the block's face with that normal
            let expected = DVec3::new(40.0, 40.0, 50.0) + n * DVec3::new(40.0, 40.0, 50.0);
            assert!((c - expected).length() < 1e-9, "{} {c:?} {expected:?}", f.label);
        }
        for e in &features.edges {
            let (p, q) = (DVec3::from_array(e.endpoints[0]), DVec3::from_array(e.endpoints[1]));
            // both end points lie on both faces
            for &f in &e.faces {
                let plane = &surface.faces[f].plane;
                assert!(plane.signed_distance(p).abs() < 1e-9 && plane.signed_distance(q).abs() < 1e-9);
            }
        }
    }
}
