//! Vertex enumeration of cells, for pictures and tests.
//!
//! Brute force, which is adequate for the small cells of \[A\] VI-A: in 3-D every triple of inequalities whose planes
//! meet in one point (|det| above a relative threshold) gives a candidate; candidates that satisfy all inequalities
//! within the tolerance are the vertices (duplicates from degenerate vertices merged within 10 x tolerance). Each
//! face lists the vertices on its plane, sorted counter-clockwise seen from outside (by angle around their mean).
//! In 2-D, pairs of lines give the vertices of the polygon, sorted counter-clockwise. O(m^3 * m) in 3-D and
//! O(m^2 * m) in 2-D for m inequalities; call [`Cell::without_redundant`] first for large cells.

use crate::cell::Cell;

/// The boundary of a 3-D cell: vertices and, per inequality that carries a 2-D face, its vertex cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct CellPolyhedron {
    /// Vertices.
    pub vertices: Vec<[f64; 3]>,
    /// `(inequality index, vertex indices counter-clockwise seen from outside)` for each face with >= 3 vertices.
    pub faces: Vec<(usize, Vec<usize>)>,
}

fn push_unique<const D: usize>(list: &mut Vec<[f64; D]>, p: [f64; D], merge: f64) {
    let close = |q: &[f64; D]| (0..D).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>().sqrt() <= merge;
    if !list.iter().any(close) {
        list.push(p);
    }
}

fn det3(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])
}

impl Cell<3> {
    /// Vertices and faces of the cell (empty for an empty cell). See the module documentation.
    pub fn polyhedron(&self) -> CellPolyhedron {
        let hs = self.halfspaces();
        let tol = self.tolerance().linear;
        let mut vertices: Vec<[f64; 3]> = Vec::new();
        if self.is_empty() {
            return CellPolyhedron { vertices, faces: Vec::new() };
        }
        let m = hs.len();
        for i in 0..m {
            for j in i + 1..m {
                for k in j + 1..m {
                    let (a, b, c) = (hs[i].normal, hs[j].normal, hs[k].normal);
                    let det = det3(a, b, c);
                    if det.abs() <= 1e-12 {
                        continue;
                    }
                    let r = [hs[i].offset, hs[j].offset, hs[k].offset];
                    // Cramer's rule on the rows a, b, c
                    let col = |x: usize| {
                        let mut m3 = [a, b, c];
                        for (row, rv) in m3.iter_mut().zip(r) {
                            row[x] = rv;
                        }
                        det3(m3[0], m3[1], m3[2]) / det
                    };
                    let p = [col(0), col(1), col(2)];
                    if hs.iter().all(|h| h.excess(&p) <= tol) {
                        push_unique(&mut vertices, p, 10.0 * tol);
                    }
                }
            }
        }
        let mut faces = Vec::new();
        for (f, h) in hs.iter().enumerate() {
            let on: Vec<usize> = (0..vertices.len()).filter(|&v| h.excess(&vertices[v]).abs() <= 10.0 * tol).collect();
            if on.len() < 3 {
                continue;
            }
            let mean =
                on.iter().fold([0.0; 3], |s, &v| [s[0] + vertices[v][0], s[1] + vertices[v][1], s[2] + vertices[v][2]]);
            let mean = mean.map(|c| c / on.len() as f64);
            let n = h.normal;
            // a basis (u, w) of the face plane with u x w = n
            let helper = if n[0].abs() < 0.6 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
            let u = normalize(cross(helper, n));
            let w = cross(n, u);
            let angle = |v: usize| {
                let d = [vertices[v][0] - mean[0], vertices[v][1] - mean[1], vertices[v][2] - mean[2]];
                (d[0] * w[0] + d[1] * w[1] + d[2] * w[2]).atan2(d[0] * u[0] + d[1] * u[1] + d[2] * u[2])
            };
            let mut cycle = on;
            cycle.sort_by(|&a, &b| angle(a).total_cmp(&angle(b)));
            faces.push((f, cycle));
        }
        CellPolyhedron { vertices, faces }
    }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|c| c / l)
}

impl Cell<2> {
    /// Vertices of the polygon, counter-clockwise (empty for an empty cell).
    pub fn polygon(&self) -> Vec<[f64; 2]> {
        let hs = self.halfspaces();
        let tol = self.tolerance().linear;
        let mut vertices: Vec<[f64; 2]> = Vec::new();
        if self.is_empty() {
            return vertices;
        }
        for i in 0..hs.len() {
            for j in i + 1..hs.len() {
                let (a, b) = (hs[i].normal, hs[j].normal);
                let det = a[0] * b[1] - a[1] * b[0];
                if det.abs() <= 1e-12 {
                    continue;
                }
                let p = [
                    (hs[i].offset * b[1] - a[1] * hs[j].offset) / det,
                    (a[0] * hs[j].offset - hs[i].offset * b[0]) / det,
                ];
                if hs.iter().all(|h| h.excess(&p) <= tol) {
                    push_unique(&mut vertices, p, 10.0 * tol);
                }
            }
        }
        if vertices.is_empty() {
            return vertices;
        }
        let n = vertices.len() as f64;
        let mean = vertices.iter().fold([0.0; 2], |s, v| [s[0] + v[0] / n, s[1] + v[1] / n]);
        vertices.sort_by(|a, b| {
            let ta = (a[1] - mean[1]).atan2(a[0] - mean[0]);
            let tb = (b[1] - mean[1]).atan2(b[0] - mean[0]);
            ta.total_cmp(&tb)
        });
        vertices
    }
}

#[cfg(test)]
mod tests {
    use crate::cell::Cell;
    use crate::halfspace::{Halfspace, Tag};
    use stackplan_geom::Tolerance;

    #[test]
    fn cube_with_a_cut_corner() {
        let mut hs = Vec::new();
        for i in 0..3 {
            let mut n = [0.0; 3];
            n[i] = 1.0;
            hs.push(Halfspace::new(n, 1.0, Tag::User(0)));
            n[i] = -1.0;
            hs.push(Halfspace::new(n, 0.0, Tag::User(1)));
        }
        hs.push(Halfspace::new([1.0, 1.0, 1.0], 2.5, Tag::User(2)));
        let c = Cell::new(hs, Tolerance::for_scale(2.0)).expect("cell");
        let p = c.polyhedron();
        assert_eq!(p.vertices.len(), 10);
        assert_eq!(p.faces.len(), 7);
        // V - E + F = 2 with E = sum of face sizes / 2
        let e: usize = p.faces.iter().map(|f| f.1.len()).sum::<usize>() / 2;
        assert_eq!(p.vertices.len() + p.faces.len() - e, 2);
        // each face cycle is counter-clockwise seen from outside: (v1 - v0) x (v2 - v0) . n > 0
        for (f, cyc) in &p.faces {
            let n = c.halfspaces()[*f].normal;
            let (a, b, d) = (p.vertices[cyc[0]], p.vertices[cyc[1]], p.vertices[cyc[2]]);
            let x = super::cross([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [d[0] - a[0], d[1] - a[1], d[2] - a[2]]);
            assert!(x[0] * n[0] + x[1] * n[1] + x[2] * n[2] > 0.0);
        }
        let sq = Cell::new(
            vec![
                Halfspace::new([1.0, 0.0], 1.0, Tag::User(0)),
                Halfspace::new([-1.0, 0.0], 0.0, Tag::User(0)),
                Halfspace::new([0.0, 1.0], 1.0, Tag::User(0)),
                Halfspace::new([0.0, -1.0], 0.0, Tag::User(0)),
                Halfspace::new([1.0, 1.0], 1.5, Tag::User(0)),
            ],
            Tolerance::for_scale(2.0),
        )
        .expect("cell");
        let poly = sq.polygon();
        assert_eq!(poly.len(), 5);
        let area: f64 = (0..5).map(|i| poly[i][0] * poly[(i + 1) % 5][1] - poly[(i + 1) % 5][0] * poly[i][1]).sum();
        assert!((area / 2.0 - 0.875).abs() < 1e-12);
    }
}
