//! Reading part surfaces from DXF files (\[P\] II step 1: "generate the set of PPCs from DXF files of the parts").
//!
//! Two kinds of entity describe a polyhedral surface in DXF: `3DFACE` (a triangle or quadrilateral; the fourth
//! corner equals the third for a triangle) and the polyface mesh (`POLYLINE` with flag 64 followed by position
//! `VERTEX` records (flags 64 + 128) and face records (flag 128 only) whose codes 71-74 hold 1-based vertex indices,
//! negative for an invisible edge, 0 when absent). Facets must be counter-clockwise seen from outside, as CAD systems
//! write closed meshes; when the signed volume of the whole surface is negative every facet is reversed. Parsing is
//! done by the `dxf` crate; this module only collects facets, O(number of entities).

use crate::surface::{SurfaceElements, SurfaceError};
use dxf::entities::EntityType;
use stackplan_geom::DVec3;
use std::path::Path;

/// Why a DXF file does not give a surface. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum DxfError {
    /// The file could not be read or parsed.
    #[error("{file}: cannot read DXF: {message}")]
    Read {
        /// File name.
        file: String,
        /// The parser's message.
        message: String,
    },
    /// No 3DFACE or polyface mesh entity.
    #[error("{file}: no 3DFACE entity or polyface mesh found")]
    NoFacets {
        /// File name.
        file: String,
    },
    /// A polyface face record refers to a vertex that does not exist.
    #[error(
        "{file}: polyface mesh (entity handle {handle:X}) face {face} refers to vertex {index}, but the mesh has {count} vertices"
    )]
    BadPolyfaceIndex {
        /// File name.
        file: String,
        /// Entity handle.
        handle: u64,
        /// Face record index within the mesh.
        face: usize,
        /// The bad (1-based) index.
        index: i32,
        /// Number of position vertices.
        count: usize,
    },
    /// A facet has fewer than three distinct corners.
    #[error("{file}: {entity} (entity handle {handle:X}) has fewer than three distinct corners")]
    DegenerateFacet {
        /// File name.
        file: String,
        /// Entity type name.
        entity: &'static str,
        /// Entity handle.
        handle: u64,
    },
    /// The surface is not convex: non-penetration needs convex pieces, which a DXF surface does not give.
    #[error(
        "{file}: the surface has {concave} concave edges; only convex DXF parts can be used for contact states (give non-convex parts as convex pieces)"
    )]
    NotConvex {
        /// File name.
        file: String,
        /// Number of concave edges.
        concave: usize,
    },
    /// The convex hull of the surface's vertices failed.
    #[error("{file}: convex hull of the vertices failed: {message}")]
    Hull {
        /// File name.
        file: String,
        /// The hull's message.
        message: String,
    },
    /// The facets do not bound a surface.
    #[error("{file}: {source}")]
    Surface {
        /// File name.
        file: String,
        /// What is wrong with the surface.
        source: SurfaceError,
    },
}

/// The facets (counter-clockwise seen from outside) of all 3DFACE entities and polyface meshes in a drawing.
pub fn facets_from_drawing(drawing: &dxf::Drawing, file: &str) -> Result<Vec<Vec<DVec3>>, DxfError> {
    let point = |p: &dxf::Point| DVec3::new(p.x, p.y, p.z);
    let mut facets = Vec::new();
    for entity in drawing.entities() {
        let handle = entity.common.handle.0;
        match &entity.specific {
            EntityType::Face3D(f) => {
                let corners = [&f.first_corner, &f.second_corner, &f.third_corner, &f.fourth_corner];
                let facet = distinct(corners.iter().map(|p| point(p)).collect());
                if facet.len() < 3 {
                    return Err(DxfError::DegenerateFacet { file: file.to_string(), entity: "3DFACE", handle });
                }
                facets.push(facet);
            }
            EntityType::Polyline(poly) if poly.is_polyface_mesh() => {
                let mut positions = Vec::new();
                let mut records = Vec::new();
                for v in poly.vertices() {
                    // position records carry flags 64 + 128 and no indices; face records flag 128 and indices (some
                    // writers, the `dxf` crate among them, drop the 64, so the indices decide)
                    let indices = [
                        v.polyface_mesh_vertex_index1,
                        v.polyface_mesh_vertex_index2,
                        v.polyface_mesh_vertex_index3,
                        v.polyface_mesh_vertex_index4,
                    ];
                    if v.is_3d_polygon_mesh() || indices.iter().all(|&i| i == 0) {
                        positions.push(point(&v.location));
                    } else {
                        records.push(indices);
                    }
                }
                for (face, rec) in records.iter().enumerate() {
                    let mut facet = Vec::with_capacity(4);
                    for &index in rec.iter().filter(|&&i| i != 0) {
                        let k = index.unsigned_abs() as usize;
                        let Some(p) = positions.get(k.wrapping_sub(1)) else {
                            return Err(DxfError::BadPolyfaceIndex {
                                file: file.to_string(),
                                handle,
                                face,
                                index,
                                count: positions.len(),
                            });
                        };
                        facet.push(*p);
                    }
                    let facet = distinct(facet);
                    if facet.len() < 3 {
                        return Err(DxfError::DegenerateFacet { file: file.to_string(), entity: "POLYLINE", handle });
                    }
                    facets.push(facet);
                }
            }
            _ => {}
        }
    }
    if facets.is_empty() {
        return Err(DxfError::NoFacets { file: file.to_string() });
    }
    // orient outwards: a closed surface has positive signed volume when its facets are counter-clockwise outside
    let volume: f64 =
        facets.iter().map(|f| (1..f.len() - 1).map(|k| f[0].dot(f[k].cross(f[k + 1]))).sum::<f64>()).sum::<f64>() / 6.0;
    if volume < 0.0 {
        tracing::debug!(file, "DXF facets are clockwise; reversing all");
        for f in &mut facets {
            f.reverse();
        }
    }
    Ok(facets)
}

/// The surface elements of the part in a DXF file.
pub fn read_dxf_surface(path: &Path) -> Result<SurfaceElements, DxfError> {
    let file = path.display().to_string();
    let drawing =
        dxf::Drawing::load_file(path).map_err(|e| DxfError::Read { file: file.clone(), message: e.to_string() })?;
    let facets = facets_from_drawing(&drawing, &file)?;
    SurfaceElements::from_facets(&facets).map_err(|source| DxfError::Surface { file, source })
}

/// A contact part from a DXF file: its surface, and as its single convex piece the hull of its vertices. The surface
/// must be convex (every edge convex).
pub fn read_dxf_part(path: &Path) -> Result<crate::criteria::ContactPart, DxfError> {
    let file = path.display().to_string();
    let surface = read_dxf_surface(path)?;
    let concave = surface.edges.iter().filter(|e| !e.convex).count();
    if concave > 0 {
        return Err(DxfError::NotConvex { file, concave });
    }
    let hull = stackplan_geom::convex_hull(&surface.positions())
        .map_err(|e| DxfError::Hull { file: file.clone(), message: e.to_string() })?;
    let piece = crate::growth_distance::ConvexPiece::from_polytope(&hull.polytope);
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or(file);
    Ok(crate::criteria::ContactPart::new(name, surface, vec![piece]))
}

/// Drops consecutive repeated corners (a triangle written as a quadrilateral repeats its third corner).
fn distinct(mut facet: Vec<DVec3>) -> Vec<DVec3> {
    facet.dedup();
    while facet.len() > 1 && facet.first() == facet.last() {
        facet.pop();
    }
    facet
}

#[cfg(test)]
mod tests {
    use super::*;
    use dxf::entities::{Entity, Face3D, Polyline, Vertex};

    fn cube_quads() -> Vec<[DVec3; 4]> {
        let p = |i: usize| DVec3::new((i & 1) as f64 * 2.0, ((i >> 1) & 1) as f64 * 3.0, ((i >> 2) & 1) as f64);
        [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]].map(|f| f.map(p)).to_vec()
    }

    fn pt(p: DVec3) -> dxf::Point {
        dxf::Point::new(p.x, p.y, p.z)
    }

    #[test]
    fn three_d_faces_round_trip() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("box.dxf");
        let mut drawing = dxf::Drawing::new();
        for q in cube_quads() {
            // split each square into two triangles written with a repeated fourth corner
            for tri in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                let f = Face3D::new(pt(tri[0]), pt(tri[1]), pt(tri[2]), pt(tri[2]));
                drawing.add_entity(Entity::new(EntityType::Face3D(f)));
            }
        }
        drawing.save_file(&path).expect("save");
        let s = read_dxf_surface(&path).expect("surface");
        assert_eq!(s.counts(), (8, 12, 6));
        assert!(s.edges.iter().all(|e| e.convex));
        let total: f64 = s.faces.iter().map(|f| f.area).sum();
        assert!((total - 2.0 * (6.0 + 2.0 + 3.0)).abs() < 1e-9);
    }

    #[test]
    fn clockwise_facets_are_reversed() {
        let mut drawing = dxf::Drawing::new();
        for q in cube_quads() {
            let f = Face3D::new(pt(q[3]), pt(q[2]), pt(q[1]), pt(q[0]));
            drawing.add_entity(Entity::new(EntityType::Face3D(f)));
        }
        let facets = facets_from_drawing(&drawing, "mem").expect("facets");
        let s = SurfaceElements::from_facets(&facets).expect("surface");
        assert_eq!(s.counts(), (8, 12, 6));
        assert!(s.faces.iter().all(|f| f.plane.offset > -1e-12), "outward normals");
    }

    fn polyface(drawing: &mut dxf::Drawing, records: &[[i32; 4]]) {
        let mut poly = Polyline::default();
        poly.set_is_polyface_mesh(true);
        let p = |i: usize| DVec3::new((i & 1) as f64 * 2.0, ((i >> 1) & 1) as f64 * 3.0, ((i >> 2) & 1) as f64);
        for i in 0..8 {
            let mut v = Vertex::new(pt(p(i)));
            v.set_is_3d_polygon_mesh(true);
            v.set_is_polyface_mesh_vertex(true);
            poly.add_vertex(drawing, v);
        }
        for r in records {
            let mut v = Vertex::default();
            v.set_is_polyface_mesh_vertex(true);
            v.polyface_mesh_vertex_index1 = r[0];
            v.polyface_mesh_vertex_index2 = r[1];
            v.polyface_mesh_vertex_index3 = r[2];
            v.polyface_mesh_vertex_index4 = r[3];
            poly.add_vertex(drawing, v);
        }
        drawing.add_entity(Entity::new(EntityType::Polyline(poly)));
    }

    #[test]
    fn polyface_mesh_round_trip() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("mesh.dxf");
        let mut drawing = dxf::Drawing::new();
        drawing.header.version = dxf::enums::AcadVersion::R2000;
        // 1-based indices, negative marks an invisible edge
        let records = [[1, 3, 4, 2], [5, 6, 8, 7], [1, 2, 6, 5], [3, 7, 8, 4], [1, 5, 7, -3], [2, 4, 8, 6]];
        polyface(&mut drawing, &records);
        drawing.save_file(&path).expect("save");
        let s = read_dxf_surface(&path).expect("surface");
        assert_eq!(s.counts(), (8, 12, 6));
    }

    #[test]
    fn errors_name_file_and_entity() {
        let mut drawing = dxf::Drawing::new();
        polyface(&mut drawing, &[[1, 3, 40, 2]]);
        let e = facets_from_drawing(&drawing, "bad.dxf").expect_err("bad index");
        assert!(matches!(e, DxfError::BadPolyfaceIndex { index: 40, count: 8, face: 0, .. }), "{e}");
        assert!(e.to_string().starts_with("bad.dxf:"));
        let empty = dxf::Drawing::new();
        assert!(matches!(facets_from_drawing(&empty, "e.dxf"), Err(DxfError::NoFacets { .. })));
        let mut d = dxf::Drawing::new();
        let f = Face3D::new(pt(DVec3::ZERO), pt(DVec3::X), pt(DVec3::X), pt(DVec3::ZERO));
        d.add_entity(Entity::new(EntityType::Face3D(f)));
        assert!(matches!(facets_from_drawing(&d, "d.dxf"), Err(DxfError::DegenerateFacet { entity: "3DFACE", .. })));
        let missing = read_dxf_surface(Path::new("/nonexistent/x.dxf")).expect_err("missing");
        assert!(missing.to_string().contains("/nonexistent/x.dxf"));
        // an open box: a surface error naming the file
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("open.dxf");
        let mut d = dxf::Drawing::new();
        for q in cube_quads().into_iter().skip(1) {
            d.add_entity(Entity::new(EntityType::Face3D(Face3D::new(pt(q[0]), pt(q[1]), pt(q[2]), pt(q[3])))));
        }
        d.save_file(&path).expect("save");
        let e = read_dxf_surface(&path).expect_err("open");
        assert!(matches!(e, DxfError::Surface { .. }) && e.to_string().contains("open.dxf"), "{e}");
    }
}
