//! Shared generators of the property tests: a seeded RNG and random cells, costs and obstacles.
#![allow(dead_code)]

use stackplan_freespace::{Cell, CostError, Halfspace, SeparableCost, Tag};
use stackplan_geom::{DVec3, Tolerance};

/// SplitMix64: a tiny deterministic RNG driven by a proptest seed.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    pub fn unit3(&mut self) -> [f64; 3] {
        loop {
            let v = [self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0)];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if l > 0.2 && l <= 1.0 {
                return v.map(|c| c / l);
            }
        }
    }
}

/// A random unit normal: axis-aligned, vertical (horizontal normal) or general — the first two are the normal case
/// for sheet metal.
pub fn sheet_normal(rng: &mut Rng) -> [f64; 3] {
    match rng.below(3) {
        0 => {
            let mut n = [0.0; 3];
            n[rng.below(3)] = 1.0;
            n
        }
        1 => {
            let t = rng.range(0.0, std::f64::consts::TAU);
            [t.cos(), t.sin(), 0.0]
        }
        _ => rng.unit3(),
    }
}

/// The inequalities of the box `[lo, hi]` (tags 0..6: +x, -x, +y, -y, +z, -z).
pub fn boxed(lo: [f64; 3], hi: [f64; 3]) -> Vec<Halfspace<3>> {
    let mut hs = Vec::new();
    for i in 0..3 {
        let mut n = [0.0; 3];
        n[i] = 1.0;
        hs.push(Halfspace::new(n, hi[i], Tag::User(2 * i as u64)));
        n[i] = -1.0;
        hs.push(Halfspace::new(n, -lo[i], Tag::User(2 * i as u64 + 1)));
    }
    hs
}

/// The part-dependent constants of cost (1) of \[A\] at one orientation: the rotated part's extents in x and y and
/// its rotated centre of gravity (the height `zc` is its z).
#[derive(Debug, Clone, Copy)]
pub struct Extents {
    pub x_max: f64,
    pub x_min: f64,
    pub y_max: f64,
    pub y_min: f64,
    pub center_of_gravity: DVec3,
}

/// Random rotated extents of a part for cost (1) (x and y spans around 0, a c.g. offset).
pub fn random_extents(rng: &mut Rng) -> Extents {
    Extents {
        x_max: rng.range(0.5, 3.0),
        x_min: rng.range(-3.0, -0.5),
        y_max: rng.range(0.5, 3.0),
        y_min: rng.range(-3.0, -0.5),
        center_of_gravity: DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(0.0, 2.0)),
    }
}

/// Cost (1) of \[A\] at a fixed orientation, `w [(p_x + xmax - x0)^2 + (p_x + xmin - x0)^2 + (p_y + ymax - y0)^2 +
/// (p_y + ymin - y0)^2] + 4 (1 - w) (p_z + zc - z0)^2`, expanded into `1/2 h p^2 + g p + c` per axis (the tests'
/// reference; the planner derives the same cost in its own form, `stackplan-planner`'s `qp::Quadratic::of_cost`).
pub fn stacking_cost(w: f64, e: &Extents, reference: DVec3) -> Result<SeparableCost<3>, CostError> {
    assert!((0.0..=1.0).contains(&w), "w = {w}");
    let (ax, bx) = (e.x_max - reference.x, e.x_min - reference.x);
    let (ay, by) = (e.y_max - reference.y, e.y_min - reference.y);
    let z = e.center_of_gravity.z - reference.z;
    let h = [4.0 * w, 4.0 * w, 8.0 * (1.0 - w)];
    let g = [2.0 * w * (ax + bx), 2.0 * w * (ay + by), 8.0 * (1.0 - w) * z];
    let c = w * (ax * ax + bx * bx + ay * ay + by * by) + 4.0 * (1.0 - w) * z * z;
    SeparableCost::new(h, g, c)
}

/// The squared distance of the part's c.g. (at `p + R c`) to `desired` (\[A\] VII-A): `h = 2`, `g = 2 (R c - p_d)`.
pub fn desired_position_cost(rotated_cg: DVec3, desired: DVec3) -> Result<SeparableCost<3>, CostError> {
    let o = rotated_cg - desired;
    SeparableCost::new([2.0; 3], [2.0 * o.x, 2.0 * o.y, 2.0 * o.z], o.length_squared())
}

pub fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The kinds of random cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// Full-dimensional.
    Solid,
    /// A face: two opposite inequalities through the centre.
    Face,
    /// An edge: two such pairs.
    Edge,
}

/// A random bounded cell around `c` (inside it): a box plus `extra` random cuts; degenerate when asked.
pub fn random_cell(rng: &mut Rng, extra: usize, shape: Shape) -> Cell<3> {
    let c = [rng.range(-5.0, 5.0), rng.range(-5.0, 5.0), rng.range(0.0, 5.0)];
    let mut hs = Vec::new();
    for i in 0..3 {
        let mut n = [0.0; 3];
        n[i] = 1.0;
        hs.push(Halfspace::new(n, c[i] + rng.range(1.0, 6.0), Tag::User(hs.len() as u64)));
        n[i] = -1.0;
        hs.push(Halfspace::new(n, -c[i] + rng.range(1.0, 6.0), Tag::User(hs.len() as u64)));
    }
    for _ in 0..extra {
        let n = rng.unit3();
        let d = dot(&n, &c) + rng.range(0.3, 4.0);
        hs.push(Halfspace::new(n, d, Tag::User(hs.len() as u64)));
    }
    let pairs = match shape {
        Shape::Solid => 0,
        Shape::Face => 1,
        Shape::Edge => 2,
    };
    for _ in 0..pairs {
        let n = sheet_normal(rng);
        let d = dot(&n, &c);
        hs.push(Halfspace::new(n, d, Tag::User(hs.len() as u64)));
        hs.push(Halfspace::new(n.map(|x| -x), -d, Tag::User(hs.len() as u64)));
    }
    // shuffle so that the special inequalities are not always last
    for i in (1..hs.len()).rev() {
        let j = rng.below(i + 1);
        hs.swap(i, j);
    }
    Cell::new(hs, Tolerance::for_scale(30.0)).expect("random cells are bounded and finite")
}

/// Random points of a convex body: `count` points in a ball of radius `r` around `c`.
pub fn random_points(rng: &mut Rng, c: DVec3, r: f64, count: usize) -> Vec<DVec3> {
    (0..count)
        .map(|_| {
            let u = rng.unit3();
            let s = r * rng.range(0.3, 1.0);
            c + DVec3::new(u[0], u[1], u[2]) * s
        })
        .collect()
}

/// The axis-aligned bounding box of a 3-D cell from its vertices.
pub fn bbox(cell: &Cell<3>) -> ([f64; 3], [f64; 3]) {
    let p = cell.polyhedron();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in &p.vertices {
        for i in 0..3 {
            lo[i] = lo[i].min(v[i]);
            hi[i] = hi[i].max(v[i]);
        }
    }
    (lo, hi)
}
