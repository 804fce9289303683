//! Suction grasp: upward horizontal faces that hold a suction cup (`docs/algorithms.md`, "Stability, grasp and
//! insertion"; \[A\] II-B condition (iii)).
//!
//! For a part in a pose, the candidate grasp regions are the horizontal planar faces whose outward normal is within
//! [`UP_COS_TOLERANCE`] of +z, and the faces tilted up to [`GraspOptions::max_tilt`] from level, each analysed in its
//! own plane (the part turned so that the face is level; the cup approaches along the face's normal). Coplanar upward component faces at the same height (within the part's tolerance) form
//! one region — a sheet decomposed into prisms presents one top surface — and everything of the part's own material
//! above that height is removed: every component is clipped to `z >= h + tol` and its vertical projection (a convex
//! polygon) is subtracted. Holes of the sheet are not covered by any component face, so they are excluded
//! automatically; so are component faces shared with another component (the neighbour lies above them).
//!
//! The region `R = (union of face polygons) \ (union of projections of material above)` holds a cup of radius `r`
//! centred at `c` iff `d(c) = dist(c, boundary of R) >= r` with `c` in `R`. The largest inscribed disc:
//!
//! * **exact** when `R` is a single convex polygon with nothing above it: the Chebyshev centre, the LP
//!   `max r  s.t.  nu_e . (c - a_e) >= r` for every edge (inward unit normal `nu_e`, a point `a_e`), solved by clarabel;
//! * **approximate** otherwise (non-convex unions, holes, material above): the boundary of `R` is assembled from the
//!   edges of all polygons, split at their mutual intersections and kept where exactly one side lies in `R`; `d` is
//!   evaluated on an `N x N` grid over the region's bounding box (spacing `h`) and the best grid points are refined by
//!   a compass (pattern) search. Since `d` is 1-Lipschitz, the true maximum radius `r*` satisfies
//!   `r_found <= r* <= max_grid d + h / sqrt(2)`; both bounds are reported (`inscribed_radius`,
//!   `radius_upper_bound`). A cup is declared to fit only when `r_found >= r_cup`: never optimistic.
//!
//! Several cups in a pattern (cup centres given relative to a grasp point): the pattern fits at grasp point `g` and
//! rotation `theta` about z iff every cup centre `g + R(theta) o_k` has `d >= r_cup`; searched over the grid and
//! `angle_steps` rotations, then refined by compass search in (x, y, theta). Also conservative (a found placement is
//! verified by evaluating `d` at every cup centre).
//!
//! Only the part's own material is considered: when a part is placed, the parts that will lie above it are not there
//! yet. The robot's approach path beyond the cup is not checked.
//!
//! Cost: O(S^2) to build the boundary (S polygon edges), O(N^2 S) for the grid.

use crate::polygon2d::{
    area, contains as polygon_contains, convex_hull_2d, point_segment_distance, signed_boundary_distance,
};
use crate::world::WorldComponent;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus};
use glam::{DMat3, DVec2, DVec3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use stackplan_geom::Part;

/// A face counts as upward when its outward normal has `n.z >= 1 - UP_COS_TOLERANCE` (about 0.0026 degrees).
pub const UP_COS_TOLERANCE: f64 = 1e-9;

/// The default [`GraspOptions::max_tilt`]: 5 degrees. A suction cup seals on a face a few degrees off level, and the
/// stable resting poses of bent parts often rest on a flange's edge, leaving their largest face a degree or two off
/// level.
pub const DEFAULT_MAX_TILT: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// Options of the grasp analysis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GraspOptions {
    /// Suction cup diameter (mm).
    pub cup_diameter: f64,
    /// Largest tilt from level of a grasp face (radians, in `[0, pi/2)`): a face whose outward normal is within this
    /// angle of +z holds the cup, which approaches along the face's normal; its region is analysed in the face's own
    /// plane (the part turned so that the face is level). 0: level faces only. Default [`DEFAULT_MAX_TILT`].
    #[serde(default)]
    pub max_tilt: f64,
    /// Cup centres relative to the grasp point (mm) for a multi-cup gripper; empty = a single cup.
    pub pattern: Vec<DVec2>,
    /// Grid resolution N of the approximate search (N x N samples).
    pub grid: usize,
    /// Rotations tried for a pattern (over a full turn).
    pub angle_steps: usize,
}

impl Default for GraspOptions {
    fn default() -> Self {
        Self { cup_diameter: 30.0, max_tilt: DEFAULT_MAX_TILT, pattern: Vec::new(), grid: 48, angle_steps: 24 }
    }
}

/// Where a pattern of cups fits.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PatternFit {
    /// Grasp point (world coordinates, on the face).
    pub point: DVec3,
    /// Rotation of the pattern about z (radians).
    pub angle: f64,
    /// Smallest `d(cup centre) - r_cup` over the cups (>= 0 when it fits).
    pub slack: f64,
}

/// An upward horizontal face region of a posed part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GraspFace {
    /// Height of the face (world z, mm).
    pub height: f64,
    /// The component face polygons making up the region (world coordinates, counter-clockwise from above).
    pub polygons: Vec<Vec<DVec3>>,
    /// Area of the region before removing material above (mm^2).
    pub area: f64,
    /// Radius of the largest inscribed disc found (a lower bound; exact when `exact`).
    pub inscribed_radius: f64,
    /// Upper bound of the largest inscribed disc radius (equal to `inscribed_radius` when `exact`).
    pub radius_upper_bound: f64,
    /// Centre of that disc (world).
    pub center: DVec3,
    /// Whether the radius is exact (single convex polygon, nothing above, LP).
    pub exact: bool,
    /// Whether a single cup of the given diameter fits (`inscribed_radius >= cup_diameter / 2`).
    pub fits_cup: bool,
    /// Best placement of the cup pattern (when a pattern is given).
    pub pattern_fit: Option<PatternFit>,
    /// Tilt of the face from level (radians; 0 for a level face). For a tilted face `height` is the world height of
    /// `center`, and the radii are measured in the face's plane.
    #[serde(default)]
    pub tilt: f64,
}

/// The planar region of one face height: convex pieces minus convex obstacles.
#[derive(Debug, Clone)]
pub struct Region {
    /// Convex face polygons (counter-clockwise).
    pub pieces: Vec<Vec<DVec2>>,
    /// Convex projections of material above (counter-clockwise).
    pub obstacles: Vec<Vec<DVec2>>,
    /// Boundary segments of the region.
    pub boundary: Vec<(DVec2, DVec2)>,
    tol: f64,
}

impl Region {
    /// Builds the region and its boundary.
    pub fn new(pieces: Vec<Vec<DVec2>>, obstacles: Vec<Vec<DVec2>>, tol: f64) -> Self {
        let mut region = Self { pieces, obstacles, boundary: Vec::new(), tol };
        region.boundary = region.build_boundary();
        region
    }

    /// Whether `p` lies in the region (closed pieces, open obstacles, with the tolerance).
    pub fn contains(&self, p: DVec2) -> bool {
        self.pieces.iter().any(|poly| polygon_contains(poly, p, self.tol))
            && !self.obstacles.iter().any(|o| crate::polygon2d::inside_by(p, o, self.tol))
    }

    /// `d(p)`: distance to the boundary when inside, 0 outside. A region without boundary has no area (a bounded
    /// region with interior has a boundary): material above covers its pieces exactly, and `contains` holds only
    /// within the tolerance of their edges, so every point gets 0.
    ///
    /// `d(p)` is also at most the distance from `p` to the nearest obstacle (the segment from `p` to it leaves the
    /// region, so this changes nothing where the boundary is complete). The assembled boundary leaves out the edges
    /// of parts of the region thinner than its side test's offset, and of parts without area: a face whose edge
    /// material above covers exactly keeps that edge's points (in the closed face, not inside the open obstacle),
    /// with no boundary near them. Measured to the boundary alone, such a point, which the grid hits where the edge
    /// lies on a grid line (a face's edge on the box's side), got the distance to the nearest boundary elsewhere:
    /// a 214 mm disc on a 4 mm strip of an STL part.
    pub fn clearance(&self, p: DVec2) -> f64 {
        if self.boundary.is_empty() || !self.contains(p) {
            return 0.0;
        }
        let to_boundary =
            self.boundary.iter().map(|&(a, b)| point_segment_distance(p, a, b)).fold(f64::INFINITY, f64::min);
        self.obstacles.iter().map(|o| (-signed_boundary_distance(p, o)).max(0.0)).fold(to_boundary, f64::min)
    }

    fn bbox(&self) -> (DVec2, DVec2) {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for p in self.pieces.iter().flatten() {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        (lo, hi)
    }

    fn build_boundary(&self) -> Vec<(DVec2, DVec2)> {
        let mut segments = Vec::new();
        for poly in self.pieces.iter().chain(self.obstacles.iter()) {
            for k in 0..poly.len() {
                segments.push((poly[k], poly[(k + 1) % poly.len()]));
            }
        }
        let (lo, hi) = self.bbox();
        let eps = (1e-7 * (hi - lo).length()).max(100.0 * self.tol);
        // each segment's pieces on the boundary, in parallel and collected in the segments' order (the same list as
        // a sequential loop)
        let per_segment = |(i, &(a, b)): (usize, &(DVec2, DVec2))| {
            let mut out = Vec::new();
            let d = b - a;
            let len = d.length();
            if len <= self.tol {
                return out;
            }
            let mut cuts = vec![0.0, 1.0];
            for (j, &(c, e)) in segments.iter().enumerate() {
                if i == j {
                    continue;
                }
                let f = e - c;
                let denom = d.perp_dot(f);
                if denom.abs() <= 1e-14 * len * f.length() {
                    // parallel: the endpoints of a collinear neighbour cut this segment
                    for q in [c, e] {
                        if point_segment_distance(q, a, b) <= self.tol {
                            cuts.push(((q - a).dot(d) / (len * len)).clamp(0.0, 1.0));
                        }
                    }
                    continue;
                }
                let t = (c - a).perp_dot(f) / denom;
                let s = (c - a).perp_dot(d) / denom;
                if (-1e-12..=1.0 + 1e-12).contains(&t) && (-1e-12..=1.0 + 1e-12).contains(&s) {
                    cuts.push(t.clamp(0.0, 1.0));
                }
            }
            cuts.sort_by(f64::total_cmp);
            let normal = DVec2::new(-d.y, d.x) / len;
            for w in cuts.windows(2) {
                if (w[1] - w[0]) * len <= self.tol {
                    continue;
                }
                let m = a + d * (0.5 * (w[0] + w[1]));
                if self.contains(m + normal * eps) != self.contains(m - normal * eps) {
                    out.push((a + d * w[0], a + d * w[1]));
                }
            }
            out
        };
        segments.par_iter().enumerate().flat_map_iter(per_segment).collect()
    }

    /// Largest inscribed disc by grid sampling and compass refinement: `(centre, radius found, upper bound)`. The
    /// refinements start from the eight best samples and from the centroid of each piece: a part of the region
    /// narrower than the grid's spacing may hold no sample (a strip of a face beside material above), and is found
    /// from its piece's centroid. The grid's columns and the refinements run in parallel; the samples and the
    /// refinements are taken in the sequential order, so the result does not depend on the threads.
    pub fn largest_disc_sampled(&self, grid: usize) -> (DVec2, f64, f64) {
        let (lo, hi) = self.bbox();
        let n = grid.max(4);
        let h = (hi - lo).max_element() / n as f64;
        let nx = ((hi.x - lo.x) / h).ceil() as usize + 1;
        let ny = ((hi.y - lo.y) / h).ceil() as usize + 1;
        let mut samples: Vec<(f64, DVec2)> = (0..nx)
            .into_par_iter()
            .flat_map_iter(|i| {
                (0..ny).filter_map(move |j| {
                    let p = DVec2::new(lo.x + h * i as f64, lo.y + h * j as f64);
                    let d = self.clearance(p);
                    (d > 0.0).then_some((d, p))
                })
            })
            .collect();
        let grid_best = samples.iter().map(|s| s.0).fold(0.0, f64::max);
        samples.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut best = (DVec2::ZERO, 0.0);
        if let Some(first) = samples.first() {
            best = (first.1, first.0);
        }
        let starts: Vec<DVec2> = samples[..samples.len().min(8)]
            .iter()
            .map(|s| s.1)
            .chain(self.pieces.iter().map(|p| p.iter().copied().sum::<DVec2>() / p.len() as f64))
            .collect();
        let refined: Vec<(DVec2, f64)> =
            starts.par_iter().map(|&start| compass(|q| self.clearance(q), start, h, h * 1e-6)).collect();
        for (p, d) in refined {
            if d > best.1 {
                best = (p, d);
            }
        }
        (best.0, best.1, grid_best + h * std::f64::consts::FRAC_1_SQRT_2)
    }

    /// Best placement of a cup pattern: `(grasp point, angle, slack)`.
    pub fn fit_pattern(
        &self,
        offsets: &[DVec2],
        cup_radius: f64,
        grid: usize,
        angle_steps: usize,
    ) -> Option<(DVec2, f64, f64)> {
        if offsets.is_empty() {
            return None;
        }
        let slack = |g: DVec2, angle: f64| {
            let (s, c) = angle.sin_cos();
            offsets
                .iter()
                .map(|o| self.clearance(g + DVec2::new(c * o.x - s * o.y, s * o.x + c * o.y)) - cup_radius)
                .fold(f64::INFINITY, f64::min)
        };
        let (lo, hi) = self.bbox();
        let n = grid.max(4);
        let h = (hi - lo).max_element() / n as f64;
        let steps = angle_steps.max(1);
        let mut best: Option<(DVec2, f64, f64)> = None;
        let nx = ((hi.x - lo.x) / h).ceil() as usize + 1;
        let ny = ((hi.y - lo.y) / h).ceil() as usize + 1;
        for k in 0..steps {
            let angle = std::f64::consts::TAU * k as f64 / steps as f64;
            for i in 0..nx {
                for j in 0..ny {
                    let g = DVec2::new(lo.x + h * i as f64, lo.y + h * j as f64);
                    let s = slack(g, angle);
                    if best.is_none_or(|b| s > b.2) {
                        best = Some((g, angle, s));
                    }
                }
            }
        }
        let (g, angle, _) = best?;
        // compass search in (x, y, angle) with the angle scaled by the pattern's size
        let size = offsets.iter().map(|o| o.length()).fold(0.0, f64::max).max(h);
        let (p, _) = compass3(
            |x: DVec3| slack(DVec2::new(x.x, x.y), x.z / size),
            DVec3::new(g.x, g.y, angle * size),
            h,
            h * 1e-6,
        );
        let angle = p.z / size;
        let g = DVec2::new(p.x, p.y);
        Some((g, angle, slack(g, angle)))
    }
}

/// The least gain of a compass move per unit of its length: a move that gains less follows a ridge of the clearance
/// too flat to be worth following (along it the clearance grows by less than 1e-6 of the ridge's length), and the
/// search goes on at a smaller step instead. Such ridges are strips whose edges are nearly, not exactly, parallel to
/// an axis (a face read from single-precision data, or turned into a tilted face's frame): no search direction
/// follows the ridge, and a move along an axis gains the step times the edges' slope (1e-8 in an STL part) until it
/// crosses the ridge, which at the smallest steps took 20 million moves and 20 s for a strip 1.4 mm wide.
const COMPASS_MIN_SLOPE: f64 = 1e-6;

/// The most evaluations of one compass search ([`compass`], [`compass3`]): a search reaches its smallest step in a
/// few hundred. The bound holds where a ridge steeper than [`COMPASS_MIN_SLOPE`] still leads nowhere fast; the
/// value found is a clearance that was evaluated, so still a lower bound.
const COMPASS_EVALUATIONS: usize = 4096;

/// Maximises `f` by compass search from `start` with initial step `step` down to `min_step`, within
/// [`COMPASS_EVALUATIONS`] evaluations of `f`.
fn compass(f: impl Fn(DVec2) -> f64, start: DVec2, step: f64, min_step: f64) -> (DVec2, f64) {
    let dirs = [
        DVec2::X,
        DVec2::NEG_X,
        DVec2::Y,
        DVec2::NEG_Y,
        DVec2::ONE,
        -DVec2::ONE,
        DVec2::new(1.0, -1.0),
        DVec2::new(-1.0, 1.0),
    ];
    pattern_search(f, start, &dirs, step, min_step)
}

/// [`compass`] in three dimensions (the axis directions).
fn compass3(f: impl Fn(DVec3) -> f64, start: DVec3, step: f64, min_step: f64) -> (DVec3, f64) {
    pattern_search(f, start, &[DVec3::X, DVec3::NEG_X, DVec3::Y, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z], step, min_step)
}

/// Compass search over the directions `dirs`: the first direction that improves `f` by more than
/// [`COMPASS_MIN_SLOPE`] times the current step is taken, and the step is halved when none does, until it is at most
/// `min_step` or [`COMPASS_EVALUATIONS`] are spent.
fn pattern_search<V>(f: impl Fn(V) -> f64, start: V, dirs: &[V], step: f64, min_step: f64) -> (V, f64)
where
    V: Copy + std::ops::Add<Output = V> + std::ops::Mul<f64, Output = V> + std::fmt::Debug,
{
    let mut p = start;
    let mut value = f(p);
    let mut evaluations = 1;
    let mut h = step;
    'search: while h > min_step {
        let mut improved = false;
        for &d in dirs {
            if evaluations >= COMPASS_EVALUATIONS {
                tracing::debug!(?p, value, step = h, "compass search stopped after {COMPASS_EVALUATIONS} evaluations");
                break 'search;
            }
            evaluations += 1;
            let q = p + d * h;
            let v = f(q);
            if v > value + COMPASS_MIN_SLOPE * h {
                p = q;
                value = v;
                improved = true;
                break;
            }
        }
        if !improved {
            h *= 0.5;
        }
    }
    (p, value)
}

/// Chebyshev centre of a convex counter-clockwise polygon by LP: `(centre, radius)`; None if the LP is not Solved.
pub fn chebyshev_center(poly: &[DVec2]) -> Option<(DVec2, f64)> {
    let n = poly.len();
    if n < 3 {
        return None;
    }
    let (mut ri, mut ci, mut vi, mut b) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut row = 0;
    for k in 0..n {
        let a = poly[k];
        let e = poly[(k + 1) % n] - a;
        let len = e.length();
        if len == 0.0 {
            continue;
        }
        let nu = DVec2::new(-e.y, e.x) / len; // inward for counter-clockwise
        // nu . (c - a) >= r   <=>   -nu . c + r <= -nu . a
        for (c, v) in [(0, -nu.x), (1, -nu.y), (2, 1.0)] {
            ri.push(row);
            ci.push(c);
            vi.push(v);
        }
        b.push(-nu.dot(a));
        row += 1;
    }
    let a = CscMatrix::new_from_triplets(row, 3, ri, ci, vi);
    let p = CscMatrix::zeros((3, 3));
    let q = [0.0, 0.0, -1.0];
    let settings = DefaultSettingsBuilder::default().verbose(false).build().ok()?;
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &[NonnegativeConeT(row)], settings).ok()?;
    solver.solve();
    if solver.solution.status != SolverStatus::Solved {
        return None;
    }
    let x = &solver.solution.x;
    Some((DVec2::new(x[0], x[1]), x[2]))
}

/// Clips a convex polytope to `z >= h` and projects it onto the xy-plane (convex hull; may be degenerate).
fn projection_above(component: &WorldComponent, h: f64, tol: f64) -> Vec<DVec2> {
    let v = component.polytope.vertices();
    let mut pts: Vec<DVec2> = v.iter().filter(|p| p.z >= h).map(|p| DVec2::new(p.x, p.y)).collect();
    for e in component.polytope.edges() {
        let (a, b) = (v[e.vertices[0]], v[e.vertices[1]]);
        if (a.z - h) * (b.z - h) < 0.0 {
            let t = (h - a.z) / (b.z - a.z);
            let x = a + (b - a) * t;
            pts.push(DVec2::new(x.x, x.y));
        }
    }
    convex_hull_2d(&pts, tol)
}

/// Grasp faces of a posed part (`world = rotation * v + position`), largest inscribed radius first.
pub fn grasp_faces(part: &Part, rotation: DMat3, position: DVec3, options: &GraspOptions) -> Vec<GraspFace> {
    let components: Vec<WorldComponent> =
        part.components().iter().map(|c| WorldComponent::new(c.transformed(rotation, position))).collect();
    grasp_faces_of_components(&components, part.tolerance().linear, options)
}

/// Grasp faces of world-coordinate components (see [`grasp_faces`]): the level faces, and with
/// [`GraspOptions::max_tilt`] the faces tilted up to it, each family of parallel faces analysed with the part turned
/// so that they are level (the minimal rotation taking their normal to +z), then turned back. A tilted family whose
/// faces add up to less area than one cup is left out: no cup fits on it.
///
/// Parallel means parallel to the tolerance of the level test ([`UP_COS_TOLERANCE`], about 4.5e-5 rad): a face whose
/// normal is that close to a family's normal is level in the family's turned frame, and is analysed there with the
/// family's faces, so a family of its own would only repeat it. Faces of one plane read from single-precision data
/// (STL) have normals that differ by rounding (1e-8 to 1e-5 rad); they are one family, whose normal is that of its
/// largest face ([`tilted_families`]).
pub fn grasp_faces_of_components(components: &[WorldComponent], tol: f64, options: &GraspOptions) -> Vec<GraspFace> {
    let mut out = level_faces(components, tol, options);
    if options.max_tilt > 0.0 {
        let cup_area = std::f64::consts::PI * (0.5 * options.cup_diameter).powi(2);
        // a family with less area than the cup cannot hold it (nor a pattern of cups), and is not analysed
        for family in tilted_families(components, options.max_tilt).into_iter().filter(|f| f.area >= cup_area) {
            out.extend(tilted_faces(components, family.normal, tol, options));
        }
        out.sort_by(|a, b| b.inscribed_radius.total_cmp(&a.inscribed_radius).then(b.height.total_cmp(&a.height)));
    }
    out
}

/// A family of parallel upward faces tilted from level: see [`tilted_families`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TiltedFamily {
    /// The family's unit normal (world): the normal of its largest face.
    pub normal: DVec3,
    /// The faces' total area (mm^2).
    pub area: f64,
    /// How many component faces it has.
    pub faces: usize,
}

/// The families of upward component faces tilted from level by at most `max_tilt` (and not level: `n.z < 1 -`
/// [`UP_COS_TOLERANCE`]), largest face first. A face joins the first family (of those started by larger faces) whose
/// normal `m` has `n . m >= 1 - UP_COS_TOLERANCE`, the level test of the family's turned frame; otherwise it starts a
/// family. Families of distinct faces of a part are degrees apart; faces of one plane read from single-precision data
/// are 1e-8 to 1e-5 rad apart. O(F G) for F tilted faces in G families.
pub fn tilted_families(components: &[WorldComponent], max_tilt: f64) -> Vec<TiltedFamily> {
    let min_z = max_tilt.min(std::f64::consts::FRAC_PI_2 - 1e-6).cos();
    let mut faces: Vec<(DVec3, f64)> = Vec::new();
    for c in components {
        let v = c.polytope.vertices();
        for f in c.polytope.faces() {
            let n = f.plane.normal;
            if n.z < min_z || n.z >= 1.0 - UP_COS_TOLERANCE {
                continue;
            }
            let face_area = stackplan_geom::polytope::newell_normal(f.vertices.iter().map(|&i| v[i])).length() / 2.0;
            faces.push((n, face_area));
        }
    }
    // largest first (stable: equal areas keep the components' order), so that a family's normal is that of its
    // largest face, the one that rounding turns least
    faces.sort_by(|a, b| b.1.total_cmp(&a.1));
    let mut families: Vec<TiltedFamily> = Vec::new();
    for (n, face_area) in faces {
        match families.iter_mut().find(|g| g.normal.dot(n) >= 1.0 - UP_COS_TOLERANCE) {
            Some(g) => {
                g.area += face_area;
                g.faces += 1;
            }
            None => families.push(TiltedFamily { normal: n, area: face_area, faces: 1 }),
        }
    }
    families
}

/// The grasp faces of the family of faces with unit normal `normal`: the part turned so that they are level (the
/// minimal rotation taking `normal` to +z), its level faces, turned back.
fn tilted_faces(components: &[WorldComponent], normal: DVec3, tol: f64, options: &GraspOptions) -> Vec<GraspFace> {
    let turn = DMat3::from_quat(glam::DQuat::from_rotation_arc(normal, DVec3::Z));
    let back = turn.transpose();
    let turned: Vec<WorldComponent> =
        components.iter().map(|c| WorldComponent::new(c.polytope.transformed(turn, DVec3::ZERO))).collect();
    let tilt = normal.z.clamp(-1.0, 1.0).acos();
    level_faces(&turned, tol, options)
        .into_iter()
        .map(|mut f| {
            f.polygons = f.polygons.iter().map(|p| p.iter().map(|q| back * *q).collect()).collect();
            f.center = back * f.center;
            f.height = f.center.z;
            if let Some(fit) = &mut f.pattern_fit {
                fit.point = back * fit.point;
            }
            f.tilt = tilt;
            f
        })
        .collect()
}

/// Upward faces of one height: their polygons, the height of the first (the mean of its vertices' heights) and the
/// lowest and highest vertex of all.
struct HeightGroup {
    height: f64,
    low: f64,
    high: f64,
    polygons: Vec<Vec<DVec3>>,
}

/// The upward faces (`n.z >= 1 - UP_COS_TOLERANCE`) of world-coordinate components grouped by height: faces whose
/// vertices' height ranges come within `tol` of each other are one group (transitively). A face that is level only
/// to the tolerance of the level test, or whose vertices lie in its plane only to rounding (single-precision data),
/// spans a range of heights; a range, not its mean, is what decides whether faces of one plane are one group.
fn height_groups(components: &[WorldComponent], tol: f64) -> Vec<HeightGroup> {
    let mut groups: Vec<HeightGroup> = Vec::new();
    for c in components {
        let v = c.polytope.vertices();
        for f in c.polytope.faces() {
            if f.plane.normal.z < 1.0 - UP_COS_TOLERANCE {
                continue;
            }
            let poly: Vec<DVec3> = f.vertices.iter().map(|&i| v[i]).collect();
            let height = poly.iter().map(|p| p.z).sum::<f64>() / poly.len() as f64;
            let low = poly.iter().map(|p| p.z).fold(height, f64::min);
            let high = poly.iter().map(|p| p.z).fold(height, f64::max);
            let meets = |g: &HeightGroup| low <= g.high + tol && g.low <= high + tol;
            let hits: Vec<usize> = (0..groups.len()).filter(|&i| meets(&groups[i])).collect();
            let Some(&k) = hits.first() else {
                groups.push(HeightGroup { height, low, high, polygons: vec![poly] });
                continue;
            };
            // the face may bridge this group and later ones: they become one, in the order of their first faces
            let later: Vec<HeightGroup> = hits[1..].iter().rev().map(|&i| groups.remove(i)).collect();
            let group = &mut groups[k];
            for g in later.into_iter().rev() {
                group.low = group.low.min(g.low);
                group.high = group.high.max(g.high);
                group.polygons.extend(g.polygons);
            }
            group.low = group.low.min(low);
            group.high = group.high.max(high);
            group.polygons.push(poly);
        }
    }
    groups
}

/// The level grasp faces of world-coordinate components. Material above a group of faces is what lies higher than
/// `tol` above its highest vertex: a face of the group is never material above the group, even where rounding tilts
/// it (were its own component clipped at the group's mean height, the part of it above would be subtracted from it,
/// leaving a region bounded by nearly coincident edges of a face and of its own shadow).
fn level_faces(components: &[WorldComponent], tol: f64, options: &GraspOptions) -> Vec<GraspFace> {
    let cup_radius = 0.5 * options.cup_diameter;
    let mut out = Vec::new();
    for HeightGroup { height: h, high, polygons: polys, .. } in height_groups(components, tol) {
        let pieces: Vec<Vec<DVec2>> = polys
            .iter()
            .map(|p| convex_hull_2d(&p.iter().map(|q| DVec2::new(q.x, q.y)).collect::<Vec<_>>(), tol))
            .filter(|p| p.len() >= 3)
            .collect();
        if pieces.is_empty() {
            continue;
        }
        let total_area: f64 = pieces.iter().map(|p| area(p)).sum();
        let above = high.max(h) + tol;
        let obstacles: Vec<Vec<DVec2>> = components
            .iter()
            .filter(|c| c.aabb.1.z > above)
            .map(|c| projection_above(c, above, tol))
            .filter(|p| p.len() >= 3 && area(p) > tol * tol)
            .collect();
        let region = Region::new(pieces, obstacles, tol);
        let lp = if region.pieces.len() == 1 && region.obstacles.is_empty() {
            chebyshev_center(&region.pieces[0])
        } else {
            None
        };
        let (center, radius, upper, exact) = match lp {
            Some((c, r)) => (c, r, r, true),
            None => {
                let (c, r, u) = region.largest_disc_sampled(options.grid);
                (c, r, u, false)
            }
        };
        let pattern_fit = region
            .fit_pattern(&options.pattern, cup_radius, options.grid / 2, options.angle_steps)
            .map(|(g, angle, slack)| PatternFit { point: DVec3::new(g.x, g.y, h), angle, slack });
        out.push(GraspFace {
            height: h,
            polygons: polys,
            area: total_area,
            inscribed_radius: radius,
            radius_upper_bound: upper,
            center: DVec3::new(center.x, center.y, h),
            exact,
            fits_cup: radius >= cup_radius,
            pattern_fit,
            tilt: 0.0,
        });
    }
    out.sort_by(|a, b| b.inscribed_radius.total_cmp(&a.inscribed_radius).then(b.height.total_cmp(&a.height)));
    out
}

/// Whether the posed part can be grasped: some face fits a cup (and the pattern, when one is given).
pub fn is_graspable(faces: &[GraspFace], options: &GraspOptions) -> bool {
    faces
        .iter()
        .any(|f| if options.pattern.is_empty() { f.fits_cup } else { f.pattern_fit.is_some_and(|p| p.slack >= 0.0) })
}
