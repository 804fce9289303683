//! The faces of a convex hull from its Quickhull triangles ([`crate::quickhull`]): adjacent triangles that are
//! exactly coplanar (exact `orient3d == 0`) join into one convex polygonal face, and a vertex is kept only where at
//! least three faces meet; with a merge tolerance, adjacent facets that lie in one plane within it join too
//! ("Creases" in [`crate::hull`], which also says why this is correct). Union-find over the triangles, then one
//! boundary walk per face: O(triangles) plus the crease merge's O(triangles x the size of the groups joined).

use crate::accurate_normal::accurate_cross;
use crate::polytope::{ConvexPolytope, Face, Plane, PolytopeError};
use crate::predicates::side;
use crate::quickhull::{NONE, Tri};
use glam::DVec3;
use std::cmp::Ordering;

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        parent[x as usize] = parent[parent[x as usize] as usize];
        x = parent[x as usize];
    }
    x
}

/// Joins, in the union-find `parent` over the triangles (exactly coplanar ones joined already), adjacent facets that
/// lie in one plane within the length tolerance `tol` (module documentation, "Creases"): across each edge, when the
/// smaller facet's vertices all lie within `tol` of the larger one's plane (normals on the same side), their two
/// groups join, provided all the vertices of both lie within `tol` of the joined group's plane (the area-weighted
/// normal of its facets). So no joined face bends by more than `tol` (creases adding up to a fold stay apart), and a
/// sliver in the planes of two faces joins one of them. The edges are visited in the order of the triangles, which
/// decides only which of two faces such a sliver joins (its vertices, within `tol` of both, are dropped either way).
/// O(triangles x the size of the groups joined).
/// Joins the exact facets (the groups of `parent`) that lie in one plane within `tol` (the module documentation,
/// "Creases"); returns, per triangle index, whether it is the root of a face joined from two or more exact facets
/// (a creased face: exactly coplanar facets are never two, the exact merge joined them).
fn merge_creases(p: &[DVec3], tris: &[Tri], triangle_normal: &[DVec3], parent: &mut [u32], tol: f64) -> Vec<bool> {
    let n = tris.len();
    // each exact facet (at its root): twice its area times its unit normal, accurately; its vertices
    let mut facet_normal = vec![DVec3::ZERO; n];
    let facet_of: Vec<u32> =
        (0..n as u32).map(|i| if tris[i as usize].alive { find(parent, i) } else { NONE }).collect();
    for (i, t) in tris.iter().enumerate() {
        if t.alive {
            facet_normal[facet_of[i] as usize] += triangle_normal[i];
        }
    }
    let unit = |v: DVec3| v.try_normalize().unwrap_or(DVec3::ZERO);
    // the triangles of each facet, by a counting sort (`members[start[f]..start[f + 1]]`)
    let mut start = vec![0u32; n + 1];
    for &f in &facet_of {
        if f != NONE {
            start[f as usize + 1] += 1;
        }
    }
    for f in 0..n {
        start[f + 1] += start[f];
    }
    let mut fill = start.clone();
    let mut members = vec![0u32; start[n] as usize];
    for (i, &f) in facet_of.iter().enumerate() {
        if f != NONE {
            members[fill[f as usize] as usize] = i as u32;
            fill[f as usize] += 1;
        }
    }
    // the largest distance of a facet's vertices from the plane of normal `u` through the point `at`
    let off_plane = |facet: u32, u: DVec3, at: DVec3| {
        members[start[facet as usize] as usize..start[facet as usize + 1] as usize]
            .iter()
            .flat_map(|&i| tris[i as usize].v)
            .map(|v| u.dot(p[v as usize] - at).abs())
            .fold(0.0f64, f64::max)
    };
    // the joined groups: union-find over the facets' roots, each root with the facets joined to it (besides itself:
    // no allocation for a facet that joins nothing) and the sum of their normals
    let mut joined: Vec<u32> = (0..n as u32).collect();
    let mut group_facets: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut group_normal = facet_normal.clone();
    for (i, t) in tris.iter().enumerate() {
        if !t.alive {
            continue;
        }
        for (k, &j) in t.nbr.iter().enumerate() {
            let (fi, fj) = (facet_of[i], facet_of[j as usize]);
            if fj == NONE || fi >= fj {
                continue;
            }
            let (ga, gb) = (find(&mut joined, fi), find(&mut joined, fj));
            let (ni, nj) = (facet_normal[fi as usize], facet_normal[fj as usize]);
            if ga == gb || ni.dot(nj) <= 0.0 {
                continue;
            }
            // the smaller facet against the larger one's plane, through a point of their shared edge
            let (small, large) = if ni.length_squared() <= nj.length_squared() { (fi, nj) } else { (fj, ni) };
            if off_plane(small, unit(large), p[t.v[k] as usize]) > tol {
                continue;
            }
            // the two groups as one face: all their vertices within `tol` of its plane (so a sliver that lies in two
            // faces' planes joins one of them, never both into one face)
            let u = unit(group_normal[ga as usize] + group_normal[gb as usize]);
            let (mut high, mut low) = (f64::NEG_INFINITY, f64::INFINITY);
            let facets = [ga, gb].into_iter().chain(group_facets[ga as usize].iter().copied());
            for f in facets.chain(group_facets[gb as usize].iter().copied()) {
                for &m in &members[start[f as usize] as usize..start[f as usize + 1] as usize] {
                    for v in tris[m as usize].v {
                        let h = u.dot(p[v as usize]);
                        high = high.max(h);
                        low = low.min(h);
                    }
                }
            }
            if high - low > tol {
                continue;
            }
            let (root, other) = (ga.min(gb), ga.max(gb));
            joined[other as usize] = root;
            let moved = std::mem::take(&mut group_facets[other as usize]);
            group_facets[root as usize].push(other);
            group_facets[root as usize].extend(moved);
            let added = group_normal[other as usize];
            group_normal[root as usize] += added;
        }
    }
    let mut creased_root = vec![false; n];
    for f in 0..n {
        if facet_of[f] == f as u32 {
            let g = find(&mut joined, f as u32);
            if g != f as u32 {
                parent[f] = g;
                creased_root[g as usize] = true;
            }
        }
    }
    creased_root
}

/// The faces of the hull of `p` triangulated by `tris` as a polytope, and the input index of each of its vertices.
pub(crate) fn merge(
    p: &[DVec3],
    tris: &[Tri],
    merge_tolerance: Option<f64>,
) -> Result<(ConvexPolytope, Vec<usize>), PolytopeError> {
    let n = tris.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for (i, t) in tris.iter().enumerate() {
        if !t.alive {
            continue;
        }
        for k in 0..3 {
            let j = t.nbr[k] as usize;
            if j < i {
                continue;
            }
            // the vertex of the neighbour opposite the shared edge
            let nt = &tris[j];
            let far = nt.v.iter().copied().find(|v| !t.v.contains(v)).unwrap_or(nt.v[0]);
            // the static filter settles "not coplanar" for almost every edge; only near-zero values go exact
            let float_side = t.normal.dot(p[far as usize] - p[t.v[0] as usize]);
            if float_side.abs() <= t.filter
                && side(p[t.v[0] as usize], p[t.v[1] as usize], p[t.v[2] as usize], p[far as usize]) == Ordering::Equal
            {
                let (a, b) = (find(&mut parent, i as u32), find(&mut parent, j as u32));
                if a != b {
                    parent[a as usize] = b;
                }
            }
        }
    }
    // with a merge tolerance: each triangle's accurate normal (twice its area), for the creases and the planes
    let triangle_normal: Vec<DVec3> = match merge_tolerance {
        Some(_) => tris
            .iter()
            .map(|t| {
                if t.alive {
                    accurate_cross(p[t.v[0] as usize], p[t.v[1] as usize], p[t.v[2] as usize])
                } else {
                    DVec3::ZERO
                }
            })
            .collect(),
        None => Vec::new(),
    };
    let creased_root = match merge_tolerance {
        Some(tol) => merge_creases(p, tris, &triangle_normal, &mut parent, tol),
        None => Vec::new(),
    };
    // group ids
    let mut group_of = vec![u32::MAX; n];
    let mut group_of_root = vec![u32::MAX; n];
    let mut group_count = 0u32;
    // per group: joined from two or more exact facets across creases (its plane is then its facets' area normal)
    let mut creased: Vec<bool> = Vec::new();
    for i in 0..n {
        if tris[i].alive {
            let r = find(&mut parent, i as u32) as usize;
            if group_of_root[r] == u32::MAX {
                group_of_root[r] = group_count;
                group_count += 1;
                creased.push(creased_root.get(r).copied().unwrap_or(false));
            }
            group_of[i] = group_of_root[r];
        }
    }
    // distinct groups per vertex, counted up to 3 (a vertex is extreme iff at least 3 faces meet there)
    let mut vgroups: Vec<[u32; 3]> = vec![[u32::MAX; 3]; p.len()];
    let mut vcount: Vec<u8> = vec![0; p.len()];
    for (i, t) in tris.iter().enumerate() {
        if !t.alive {
            continue;
        }
        let g = group_of[i];
        for &v in &t.v {
            let (slots, count) = (&mut vgroups[v as usize], &mut vcount[v as usize]);
            if (*count as usize) < 3 && !slots[..*count as usize].contains(&g) {
                slots[*count as usize] = g;
                *count += 1;
            }
        }
    }
    // boundary half-edges of each group, chained into a cycle
    // (one flat list bucketed by group with a counting sort: no allocation per group)
    let mut bucket_start: Vec<u32> = vec![0; group_count as usize + 1];
    for (i, t) in tris.iter().enumerate() {
        if t.alive {
            for k in 0..3 {
                if group_of[t.nbr[k] as usize] != group_of[i] {
                    bucket_start[group_of[i] as usize + 1] += 1;
                }
            }
        }
    }
    for g in 0..group_count as usize {
        bucket_start[g + 1] += bucket_start[g];
    }
    let mut fill = bucket_start.clone();
    let mut flat: Vec<(u32, u32)> = vec![(0, 0); bucket_start[group_count as usize] as usize];
    for (i, t) in tris.iter().enumerate() {
        if t.alive {
            for k in 0..3 {
                if group_of[t.nbr[k] as usize] != group_of[i] {
                    let g = group_of[i] as usize;
                    flat[fill[g] as usize] = (t.v[k], t.v[(k + 1) % 3]);
                    fill[g] += 1;
                }
            }
        }
    }
    // per group, the triangle whose float normal is longest: the best-conditioned of its exactly coplanar triangles,
    // whose accurate normal is the face's; for a group of facets merged across creases, the sum of its triangles'
    // accurate normals (twice their areas) instead
    let mut representative: Vec<u32> = vec![NONE; group_count as usize];
    let mut area_normal: Vec<DVec3> = vec![DVec3::ZERO; group_count as usize];
    for (i, t) in tris.iter().enumerate() {
        if t.alive {
            let g = group_of[i] as usize;
            let r = &mut representative[g];
            if *r == NONE || t.normal.length_squared() > tris[*r as usize].normal.length_squared() {
                *r = i as u32;
            }
            if merge_tolerance.is_some() {
                area_normal[g] += triangle_normal[i];
            }
        }
    }
    let boundary = (0..group_count as usize).map(|g| &flat[bucket_start[g] as usize..bucket_start[g + 1] as usize]);
    let mut next: Vec<u32> = vec![NONE; p.len()];
    let mut new_index: Vec<u32> = vec![NONE; p.len()];
    let mut vertices = Vec::new();
    let mut source = Vec::new();
    let mut faces = Vec::with_capacity(group_count as usize);
    for (g, (b, &r)) in boundary.zip(&representative).enumerate() {
        let Some(&(start, _)) = b.iter().min_by_key(|e| e.0) else { continue };
        for &(a, c) in b {
            next[a as usize] = c;
        }
        let mut cycle = Vec::with_capacity(b.len());
        let mut v = start;
        for _ in 0..b.len() {
            if vcount[v as usize] >= 3 {
                if new_index[v as usize] == NONE {
                    new_index[v as usize] = vertices.len() as u32;
                    vertices.push(p[v as usize]);
                    source.push(v as usize);
                }
                cycle.push(new_index[v as usize] as usize);
            }
            v = next[v as usize];
        }
        // (cannot happen for exact facets; a merge that leaves a face with fewer corners falls back to them)
        if cycle.len() < 3 {
            return Err(PolytopeError::DegenerateFace { face: faces.len() });
        }
        // the face's plane through its representative triangle, computed accurately (a sliver's plain cross product
        // can point anywhere); the offset is the largest `n . v` over the face's vertices, as `ConvexPolytope::new`
        let n = if creased[g] {
            area_normal[g]
        } else {
            let [a, b, c] = tris[r as usize].v.map(|v| p[v as usize]);
            accurate_cross(a, b, c)
        };
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            return Err(PolytopeError::DegenerateFace { face: faces.len() });
        }
        if creased[g] {
            // a face planar only to the tolerance: its cycle starts at its lexicographically smallest corner, so that
            // the fans of its triangles (its mass properties, its mesh triangles) depend on the face, not on the order
            // of the input points
            let first = (0..cycle.len())
                .min_by(|&x, &y| {
                    vertices[cycle[x]].to_array().partial_cmp(&vertices[cycle[y]].to_array()).unwrap_or(Ordering::Equal)
                })
                .unwrap_or(0);
            cycle.rotate_left(first);
        }
        let normal = n / len;
        let offset = cycle.iter().map(|&i| normal.dot(vertices[i])).fold(f64::NEG_INFINITY, f64::max);
        faces.push(Face { vertices: cycle.into(), plane: Plane { normal, offset } });
    }
    // every face has a positive area: it is a union of triangles that are not exactly degenerate (see the module
    // documentation), and its plane was computed above
    let polytope = ConvexPolytope::from_faces_with_area(vertices, faces)?;
    Ok((polytope, source))
}
