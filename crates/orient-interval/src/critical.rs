//! Critical orientations: the angles of rotation about world `z` at which the structure of the c-space obstacle
//! `C(A, B) = B (+) (-R(theta) A)` of a convex pair changes.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) section IV-A (manuscript 4.1), eq. 4-5, and Appendix C, eq. 13-16;
//! `docs/algorithms.md`, "Critical orientations and extrapolation". The vertices move as `P_ij(theta) = V_j^B -
//! R(theta) V_i^A` (eq. 4). Every event function below is `alpha cos(theta) + beta sin(theta) + gamma` ([`Trig`]) and
//! is solved in closed form.
//!
//! # Event kinds
//!
//! The faces of `C` are the vertices of the overlay of the Gauss map of `B` with the Gauss map of `-RA`; the overlay
//! changes combinatorially exactly when a Gauss-map vertex (face normal) of one polytope meets an edge arc of the
//! other (a vertex passing another vertex meets the arcs ending there). So the complete event set is:
//!
//! * **(b) a face normal crossing an edge arc** ([`EventKind::FixedNormalOnMovingArc`]: `n_g^B . R e^A = 0` with
//!   `n_g^B` inside the arc of `-RA`'s edge; [`EventKind::MovingNormalOnFixedArc`]: `R n_f^A . e^B = 0` with `-R n_f^A`
//!   inside `B`'s arc). In c-space terms: two adjacent faces of `C` become coplanar, an edge of `C` vanishes, and a
//!   point that was not on a face reaches that face's plane. With `u . R v = (u_x v_x + u_y v_y) cos +
//!   (u_y v_x - u_x v_y) sin + u_z v_z` both are linear in `(cos, sin)`. Cost O(F_B E_A + F_A E_B) per full turn.
//! * **(c) the permanently degenerate families.** Rotation about `z` keeps horizontal faces' normals at the poles and
//!   vertical faces' normals and vertical edges' arcs on the equator; for a pole normal against a horizontal edge, or
//!   an equator normal against a vertical edge, the (b) function vanishes identically (the normal lies on the arc's
//!   circle for every `theta`). Their events are one-dimensional:
//!   - [`EventKind::PolarArcsAligned`]: around a pole, the arcs of both maps that end at or pass through the pole
//!     leave it in fixed horizontal directions `d^B` and `-R d^A`; the overlay changes when two of them coincide
//!     (two horizontal edges become parallel, an edge of the sum's horizontal face degenerates):
//!     `(d^B x R d^A)_z = 0` with `d^B . R d^A < 0`;
//!   - [`EventKind::EquatorNormalsCoincide`]: two vertical faces' normals pass each other on the equator (this also
//!     moves a normal past the end of a vertical edge's arc): `(n^B x R n^A)_z = 0` with `n^B . R n^A < 0`.
//! * **(a) a point crossing a face plane** ([`EventKind::PointCrossesFace`], [`point_face_event`]), the seed's test
//!   (eq. 5, 14), evaluated for every point `P_ij` not incident to the face (extreme points too, not only interior
//!   ones: the seed's restriction misses edge flips). With the face normal written from its generating features
//!   (fixed `n^B`, moving `-R n^A`, edge-edge `e^B x R e^A`), `(P - F0) . N` is again degree one in `(cos, sin)`.
//!   Within a constant structure every such root coincides with a (b) or (c) event (a point can only reach a
//!   supporting plane when the support set grows, i.e. a normal meets an arc), so (a) is used as an independent
//!   cross-check of the Gauss-map events (O(F_C n_A n_B) per interval) and is not needed for conservativeness.
//!
//! # Tolerance bands and conservativeness
//!
//! The c-space construction (`stackplan_cspace::minkowski`) treats a normal within [`ANGULAR_TOLERANCE`] of an arc's
//! circle as lying on it, merges normals closer than half of it, and drops nearly collinear corners of merged faces.
//! So a structure is constant between the *bands* where some (b) or (c) function is small (gated by "the normal lies
//! within the arc" at the band's root, ends and centre, with a generous slack). Each band is computed in closed form
//! ([`Trig::band`]) with the tolerance widened by [`BAND_SAFETY`] `* (1 + L_max / L_min)`, and an interval ends at the
//! entry of the next band: never later than the true change (verified against sampling + bisection in the tests).
//! An angle inside a band is a degenerate configuration whose structure is only known to hold at that angle.
//! A band whose gate passes only through the slack, or a tangential touch that does not change the overlay, makes an
//! interval shorter than the true one (a *conservative* event); the property tests count these.

use crate::trig::{AngleArc, Band, Trig, wrap};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use stackplan_cspace::minkowski::{ANGULAR_TOLERANCE, FaceKind, Feature, Obstacle};
use stackplan_geom::polytope::ConvexPolytope;
use std::f64::consts::TAU;

/// Tolerance of the bands: the construction's tolerance.
pub const BAND_TOLERANCE: f64 = ANGULAR_TOLERANCE;

/// Safety factor on the band tolerance. The construction's decisions near a degenerate configuration are not all
/// taken on the same normalised quantity: "normal on arc" is `|c_e . n| <= tol`, two normals merge within
/// `tol / 2`, and the 2-D sums of merged faces drop collinear corners by the sine of the angle between a long and a
/// short polygon edge, which amplifies the turning angle by up to `1 + L_max / L_min`. Every band is therefore
/// computed with `tol * BAND_SAFETY * (1 + L_max / L_min)` (edge lengths of both polytopes): a few 1e-7 rad for
/// sheet-metal components, far below any sweep step. Measured: without the length factor, the structure was seen to
/// change up to 12 tol before a band.
pub const BAND_SAFETY: f64 = 4.0;

/// Longest over shortest edge of the two polytopes.
fn edge_length_ratio(a: &ConvexPolytope, b: &ConvexPolytope) -> f64 {
    let mut lo = f64::INFINITY;
    let mut hi = 0.0f64;
    for p in [a, b] {
        for e in p.edges() {
            let l = (p.vertices()[e.vertices[1]] - p.vertices()[e.vertices[0]]).length();
            lo = lo.min(l);
            hi = hi.max(l);
        }
    }
    if lo > 0.0 && hi.is_finite() { hi / lo } else { 1.0 }
}

/// Slack of the "normal lies within the arc" gate (sine of an angle): generous, since an unneeded band only shortens
/// an interval.
pub const ARC_GATE_SLACK: f64 = 1e-6;

/// Which pole.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Pole {
    /// `+z`.
    North,
    /// `-z`.
    South,
}

impl Pole {
    fn direction(self) -> DVec3 {
        match self {
            Pole::North => DVec3::Z,
            Pole::South => DVec3::NEG_Z,
        }
    }
}

/// What happens at a critical orientation, with the features involved (indices into the moving `A`'s and the fixed
/// `B`'s vertices, edges and faces).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum EventKind {
    /// (b) Normal of face `face_b` of `B` crosses the arc of edge `edge_a` of `-RA`: `n^B . R e^A = 0`.
    FixedNormalOnMovingArc {
        /// Face of `B`.
        face_b: usize,
        /// Edge of `A`.
        edge_a: usize,
    },
    /// (b) Normal `-R n^A` of face `face_a` of `-RA` crosses the arc of edge `edge_b` of `B`: `R n^A . e^B = 0`.
    MovingNormalOnFixedArc {
        /// Face of `A`.
        face_a: usize,
        /// Edge of `B`.
        edge_b: usize,
    },
    /// (c) At a pole, the arc of `edge_b` of `B` and the arc of `edge_a` of `-RA` leave the pole in the same
    /// direction (two horizontal edges become parallel).
    PolarArcsAligned {
        /// The pole (of the sum's Gauss map).
        pole: Pole,
        /// Edge of `A`.
        edge_a: usize,
        /// Edge of `B`.
        edge_b: usize,
    },
    /// (c) The normals of vertical faces `face_a` (as `-R n^A`) and `face_b` coincide on the equator.
    EquatorNormalsCoincide {
        /// Face of `A`.
        face_a: usize,
        /// Face of `B`.
        face_b: usize,
    },
    /// (a) The point `V_j^B - R V_i^A` (`point = [i, j]`) reaches the plane of the obstacle face generated by `face`.
    PointCrossesFace {
        /// The face (by its generating features).
        face: FaceKind,
        /// The point's `[i, j]`.
        point: [usize; 2],
    },
}

impl EventKind {
    /// Snake-case name used in JSON.
    pub fn name(&self) -> &'static str {
        match self {
            Self::FixedNormalOnMovingArc { .. } => "fixed_normal_on_moving_arc",
            Self::MovingNormalOnFixedArc { .. } => "moving_normal_on_fixed_arc",
            Self::PolarArcsAligned { .. } => "polar_arcs_aligned",
            Self::EquatorNormalsCoincide { .. } => "equator_normals_coincide",
            Self::PointCrossesFace { .. } => "point_crosses_face",
        }
    }
}

/// A critical orientation: the angle, what happens, and the event equation `f(theta) = 0` it solves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// The angle (radians, in `[0, 2 pi)`): a root of `function` (or, for a tangential near-touch, the point of
    /// smallest `|function|`).
    pub angle: f64,
    /// What happens.
    pub kind: EventKind,
    /// The event function.
    pub function: Trig,
    /// The band tolerance on `|function|` within which the construction sees the degenerate configuration.
    pub tolerance: f64,
}

/// An event with its band: the closed arc of angles where the configuration is degenerate for the construction.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EventBand {
    /// Band start (radians, `[0, 2 pi)`).
    pub lo: f64,
    /// Band end (`lo <= hi < lo + 2 pi`).
    pub hi: f64,
    /// The event.
    pub event: Event,
}

/// A constant-structure interval around an angle: the structure built at any angle of `[start, end]` (unwrapped,
/// `start <= end`) is the same. Each end is the entry of the nearest event band (or the edge of the band the angle
/// is in).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    /// First angle (radians; may be below 0 when the interval wraps).
    pub start: f64,
    /// Last angle (radians, `>= start`; the structure may change right after it).
    pub end: f64,
    /// The event that bounds the interval below (`None` when nothing changes over a full turn).
    pub start_event: Option<Event>,
    /// The event that bounds the interval above.
    pub end_event: Option<Event>,
    /// Whether the angle it was computed for lies inside an event band (a degenerate configuration).
    pub degenerate: bool,
    /// The angle it was computed for.
    pub at: f64,
}

impl Interval {
    /// Whether `theta` (any representative) lies in the interval: the angle it was computed for, or strictly
    /// between its ends (the ends are band entries, where the structure may already change: `[theta0, theta1)`
    /// forwards, `(theta_-1, theta0]` backwards).
    pub fn contains(&self, theta: f64) -> bool {
        if self.end - self.start >= TAU || wrap(theta - self.at) == 0.0 {
            return true;
        }
        let d = wrap(theta - self.start);
        d > 0.0 && d < self.end - self.start
    }

    /// Length (radians).
    pub fn length(&self) -> f64 {
        self.end - self.start
    }
}

/// One interval of the full-turn partition: a constant structure over `[start, end]`, or an event window (a cluster
/// of overlapping event bands) when `degenerate`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TurnInterval {
    /// Start (radians, `[0, 2 pi)`): bit for bit the previous interval's `end` ([`PairEvents::full_turn`]).
    pub start: f64,
    /// End (radians, `> start`): bit for bit the next interval's `start`; for the last interval of the turn the first
    /// one's `start + 2 pi`, above `2 pi` when it wraps.
    pub end: f64,
    /// Whether this is an event window rather than a constant-structure interval.
    pub degenerate: bool,
    /// For a constant interval: the event that ends it. For a window: its events.
    pub events: Vec<Event>,
}

/// What gates a band: the condition that makes the root a real overlay change.
#[derive(Debug, Clone, Copy)]
enum Gate {
    /// Fixed normal `u` within the arc of moving edge with face normals `p`, `q` (in `A`'s frame, before `-R`).
    FixedInMovingArc { u: DVec3, p: DVec3, q: DVec3 },
    /// Moving normal `m` (in `A`'s frame; the map vertex is `-R m`) within the fixed arc `p`, `q`.
    MovingInFixedArc { m: DVec3, p: DVec3, q: DVec3 },
    /// Fixed horizontal direction `u` and moving direction `v` (map direction `-R v`): `u . R v < 0`.
    Opposite { u: DVec3, v: DVec3 },
}

fn rot(theta: f64, v: DVec3) -> DVec3 {
    let (s, c) = theta.sin_cos();
    DVec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
}

/// Whether unit `u` lies within the closed great-circle arc from `p` to `q` (shorter arc), with slack.
fn in_arc(u: DVec3, p: DVec3, q: DVec3, slack: f64) -> bool {
    let c = p.cross(q);
    let n = c.length();
    if n <= 1e-300 {
        return (u - p).length() <= slack;
    }
    p.cross(u).dot(c) >= -slack * n && u.cross(q).dot(c) >= -slack * n
}

impl Gate {
    fn passes(&self, theta: f64) -> bool {
        match *self {
            Gate::FixedInMovingArc { u, p, q } => in_arc(u, -rot(theta, p), -rot(theta, q), ARC_GATE_SLACK),
            Gate::MovingInFixedArc { m, p, q } => in_arc(-rot(theta, m), p, q, ARC_GATE_SLACK),
            Gate::Opposite { u, v } => u.dot(rot(theta, v)) < 0.0,
        }
    }
}

fn is_horizontal(v: DVec3) -> bool {
    v.z.abs() <= ANGULAR_TOLERANCE * v.length()
}

fn horizontal_unit(v: DVec3) -> Option<DVec3> {
    let h = DVec3::new(v.x, v.y, 0.0);
    let l = h.length();
    (l > 1e-6).then(|| h / l)
}

/// `theta -> (u x R v)_z = (u_x v_y - u_y v_x) cos + (u_x v_x + u_y v_y) sin`.
fn rotated_cross_z(u: DVec3, v: DVec3) -> Trig {
    Trig { alpha: u.x * v.y - u.y * v.x, beta: u.x * v.x + u.y * v.y, gamma: 0.0 }
}

/// Unit direction of edge `e` of `p` and the normals of its two faces.
fn edge_data(p: &ConvexPolytope, e: usize) -> (DVec3, DVec3, DVec3) {
    let edge = p.edges()[e];
    let d = (p.vertices()[edge.vertices[1]] - p.vertices()[edge.vertices[0]]).normalize();
    (d, p.faces()[edge.faces[0]].plane.normal, p.faces()[edge.faces[1]].plane.normal)
}

/// The event bands of a convex pair over a full turn: all (b) and (c) events. Query it for the constant-structure
/// interval around any angle ([`PairEvents::interval_around`]) or the full-turn partition ([`PairEvents::full_turn`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairEvents {
    bands: Vec<EventBand>,
}

impl PairEvents {
    /// All event bands of moving `A` (rotated about `z` from its given coordinates) against fixed `B` (already
    /// placed). O(F_B E_A + F_A E_B + H_A H_B + V_A V_B) where `H` counts horizontal edges and `V` vertical faces.
    pub fn new(moving: &ConvexPolytope, fixed: &ConvexPolytope) -> Self {
        let mut bands = Vec::new();
        // every band tolerance is widened by the pair's amplification factor (see BAND_SAFETY)
        let amplification = BAND_SAFETY * (1.0 + edge_length_ratio(moving, fixed));
        let mut push = |f: Trig, tol: f64, kind: EventKind, gate: Gate| {
            let tol = tol * amplification;
            let arcs: Vec<AngleArc> = match f.band(tol) {
                Band::Empty | Band::Whole => return,
                Band::One(a) => vec![a],
                Band::Two(a, b) => vec![a, b],
            };
            for arc in arcs {
                let center = arc.lo + 0.5 * (arc.hi - arc.lo);
                if gate.passes(arc.root) || gate.passes(arc.lo) || gate.passes(arc.hi) || gate.passes(center) {
                    let event = Event { angle: arc.root, kind, function: f, tolerance: tol };
                    bands.push(EventBand { lo: arc.lo, hi: arc.hi, event });
                }
            }
        };
        let fixed_normals: Vec<DVec3> = fixed.faces().iter().map(|f| f.plane.normal).collect();
        let moving_normals: Vec<DVec3> = moving.faces().iter().map(|f| f.plane.normal).collect();
        // (b) fixed normal vs moving arc: n^B . R e^A
        for e in 0..moving.edges().len() {
            let (d, p, q) = edge_data(moving, e);
            for (g, &u) in fixed_normals.iter().enumerate() {
                let f = Trig::rotated_dot(u, d);
                push(
                    f,
                    BAND_TOLERANCE,
                    EventKind::FixedNormalOnMovingArc { face_b: g, edge_a: e },
                    Gate::FixedInMovingArc { u, p, q },
                );
            }
        }
        // (b) moving normal vs fixed arc: e^B . R n^A
        for e in 0..fixed.edges().len() {
            let (d, p, q) = edge_data(fixed, e);
            for (fa, &m) in moving_normals.iter().enumerate() {
                let f = Trig::rotated_dot(d, m);
                push(
                    f,
                    BAND_TOLERANCE,
                    EventKind::MovingNormalOnFixedArc { face_a: fa, edge_b: e },
                    Gate::MovingInFixedArc { m, p, q },
                );
            }
        }
        // (c) poles: directions in which arcs leave the pole
        for pole in [Pole::North, Pole::South] {
            let z = pole.direction();
            // B's map at the pole; -RA's map at the pole = A's map at -pole, directions negated (then rotated)
            let b_dirs = polar_directions(fixed, z);
            let a_dirs = polar_directions(moving, -z);
            for &(edge_b, d_b, r_b) in &b_dirs {
                for &(edge_a, d_a, r_a) in &a_dirs {
                    // A's arc leaves -z in direction d_a, so -RA's arc leaves z in direction -R d_a: the two coincide
                    // when (d_b x R d_a)_z = 0 and d_b . R d_a < 0
                    let f = rotated_cross_z(d_b, d_a);
                    let tol = 2.0 * BAND_TOLERANCE / r_a.min(r_b).max(1e-3);
                    push(
                        f,
                        tol,
                        EventKind::PolarArcsAligned { pole, edge_a, edge_b },
                        Gate::Opposite { u: d_b, v: d_a },
                    );
                }
            }
        }
        // (c) equator: vertical faces' normals coincide: n^B = -R n^A
        let vertical_b: Vec<usize> = (0..fixed_normals.len()).filter(|&g| is_horizontal(fixed_normals[g])).collect();
        let vertical_a: Vec<usize> = (0..moving_normals.len()).filter(|&f| is_horizontal(moving_normals[f])).collect();
        for &g in &vertical_b {
            for &fa in &vertical_a {
                let (u, v) = (fixed_normals[g], moving_normals[fa]);
                let f = rotated_cross_z(u, v);
                push(
                    f,
                    2.0 * BAND_TOLERANCE,
                    EventKind::EquatorNormalsCoincide { face_a: fa, face_b: g },
                    Gate::Opposite { u, v },
                );
            }
        }
        bands.sort_by(|a, b| a.lo.total_cmp(&b.lo));
        tracing::trace!(bands = bands.len(), "event bands of a pair");
        Self { bands }
    }

    /// The event bands, sorted by start.
    pub fn bands(&self) -> &[EventBand] {
        &self.bands
    }

    /// The constant-structure interval containing `theta`: bounded by the nearest band entries on either side; when
    /// `theta` lies in a band (a degenerate configuration), the single angle `theta`. O(number of bands).
    pub fn interval_around(&self, theta: f64) -> Interval {
        let mut fwd = TAU;
        let mut bwd = -TAU;
        let mut fwd_event = None;
        let mut bwd_event = None;
        let mut degenerate = false;
        for b in &self.bands {
            let width = b.hi - b.lo;
            let d = wrap(b.lo - theta); // forward distance to the band's start
            let (f, bk) = if d == 0.0 || d + width >= TAU {
                // theta is inside a band: the configuration is degenerate and several of the construction's
                // thresholds lie within the band, so the structure is only known to hold at theta itself
                degenerate = true;
                (0.0, 0.0)
            } else {
                (d, -(TAU - d - width))
            };
            if f < fwd {
                fwd = f;
                fwd_event = Some(b.event);
            }
            if bk > bwd {
                bwd = bk;
                bwd_event = Some(b.event);
            }
        }
        if fwd_event.is_none() {
            return Interval {
                start: theta - TAU,
                end: theta + TAU,
                start_event: None,
                end_event: None,
                degenerate,
                at: theta,
            };
        }
        Interval {
            start: theta + bwd,
            end: theta + fwd,
            start_event: bwd_event,
            end_event: fwd_event,
            degenerate,
            at: theta,
        }
    }

    /// The next critical orientation after `theta` (forwards) or before it (backwards): the interval's end event.
    pub fn next_event(&self, theta: f64, forwards: bool) -> Option<(f64, Event)> {
        let i = self.interval_around(theta);
        if forwards { i.end_event.map(|e| (i.end, e)) } else { i.start_event.map(|e| (i.start, e)) }
    }

    /// The full-turn partition of `[0, 2 pi)`: constant-structure intervals alternating with event windows
    /// (clusters of overlapping bands). The closed-form description of the obstacle in `{p, theta}` space: inside
    /// each constant interval the obstacle is the stored structure with vertices `V_j^B - R(theta) V_i^A`.
    ///
    /// The partition is exact: sorted by start, each interval ends at bit for bit the next one's start and the last
    /// at the first one's start plus `2 pi` (each boundary is wrapped into `[0, 2 pi)` once and shared by its two
    /// intervals, rather than each interval shifted by its own multiple of `2 pi`, which left gaps and overlaps of a
    /// few ulps at 1-2 % of the joins).
    pub fn full_turn(&self) -> Vec<TurnInterval> {
        if self.bands.is_empty() {
            return vec![TurnInterval { start: 0.0, end: TAU, degenerate: false, events: Vec::new() }];
        }
        // merge bands (sorted by lo) into clusters
        let mut clusters: Vec<(f64, f64, Vec<Event>)> = Vec::new();
        for b in &self.bands {
            match clusters.last_mut() {
                Some(c) if b.lo <= c.1 => {
                    c.1 = c.1.max(b.hi);
                    c.2.push(b.event);
                }
                _ => clusters.push((b.lo, b.hi, vec![b.event])),
            }
        }
        // wrap-around: the last cluster may reach into the first ones
        while clusters.len() > 1 {
            let last_hi = clusters[clusters.len() - 1].1;
            if last_hi - TAU >= clusters[0].0 {
                let first = clusters.remove(0);
                let last = clusters.last_mut().expect("more than one cluster");
                last.1 = last.1.max(first.1 + TAU);
                last.2.extend(first.2);
            } else {
                break;
            }
        }
        if clusters.len() == 1 && clusters[0].1 - clusters[0].0 >= TAU {
            let c = clusters.remove(0);
            let start = wrap(c.0);
            return vec![TurnInterval { start, end: start + TAU, degenerate: true, events: c.2 }];
        }
        // the intervals in turn order by their starts (unwrapped): window k from its cluster's `lo`, the constant
        // interval after it from its `hi`; each ends where the next one starts
        let n = clusters.len();
        let mut starts: Vec<(f64, bool, Vec<Event>)> = Vec::with_capacity(2 * n);
        for k in 0..n {
            let (lo, hi, events) = &clusters[k];
            starts.push((*lo, true, events.clone()));
            let next = &clusters[(k + 1) % n];
            let next_lo = if k + 1 == n { next.0 + TAU } else { next.0 };
            if next_lo > *hi {
                let first_event = next.2.iter().min_by(|a, b| wrap(a.angle - hi).total_cmp(&wrap(b.angle - hi)));
                starts.push((*hi, false, first_event.copied().into_iter().collect()));
            }
        }
        // each boundary wrapped once; sorted, the turn order rotated to start at the least
        for s in &mut starts {
            s.0 = wrap(s.0);
        }
        starts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let first = starts[0].0;
        let ends: Vec<f64> = starts.iter().skip(1).map(|s| s.0).chain(std::iter::once(first + TAU)).collect();
        starts
            .into_iter()
            .zip(ends)
            .map(|((start, degenerate, events), end)| TurnInterval { start, end, degenerate, events })
            .collect()
    }
}

/// Arcs of polytope `p` that end at or pass through the pole `z`: `(edge, direction in
/// which the arc leaves the pole (horizontal unit), horizontal length of the far end's normal)`.
fn polar_directions(p: &ConvexPolytope, z: DVec3) -> Vec<(usize, DVec3, f64)> {
    let mut out = Vec::new();
    let at_pole = |n: DVec3| (n - z).length() <= ANGULAR_TOLERANCE;
    for e in 0..p.edges().len() {
        let (d, n0, n1) = edge_data(p, e);
        let mut add = |far: DVec3| {
            if let Some(h) = horizontal_unit(far) {
                out.push((e, h, DVec3::new(far.x, far.y, 0.0).length()));
            }
        };
        if at_pole(n0) {
            add(n1);
        } else if at_pole(n1) {
            add(n0);
        } else if is_horizontal(d) && in_arc(z, n0, n1, ANGULAR_TOLERANCE) {
            add(n0);
            add(n1);
        }
    }
    out
}

/// The normal of an obstacle face as a function of `theta`, from its generating features.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NormalRecipe {
    /// A face of `B` (kinds `FixedFace`, `FixedFaceMovingEdge`, `FaceFace`): the constant `n^B`.
    Fixed(DVec3),
    /// A face of `-RA` (kinds `MovingFace`, `MovingFaceFixedEdge`): `-R n^A`, `n^A` stored.
    Moving(DVec3),
    /// A parallelogram: `sign * (e^B x R e^A)` normalised; `e^B`, `e^A` stored (unit).
    EdgeEdge {
        /// Direction of `B`'s edge.
        e_b: DVec3,
        /// Direction of `A`'s edge (in `A`'s frame).
        e_a: DVec3,
        /// `+1` or `-1`, fixed when the structure was built.
        sign: f64,
    },
}

impl NormalRecipe {
    /// The recipe of face `face` of `obstacle` (`None` for an unclassified face). For edge-edge faces the sign is
    /// taken from the obstacle's own normal.
    pub fn of(obstacle: &Obstacle, face: usize, moving: &ConvexPolytope, fixed: &ConvexPolytope) -> Option<Self> {
        let kind = obstacle.face_kinds()[face];
        Some(match kind {
            FaceKind::FixedFace { face_b, .. }
            | FaceKind::FixedFaceMovingEdge { face_b, .. }
            | FaceKind::FaceFace { face_b, .. } => Self::Fixed(fixed.faces()[face_b].plane.normal),
            FaceKind::MovingFace { face_a, .. } | FaceKind::MovingFaceFixedEdge { face_a, .. } => {
                Self::Moving(moving.faces()[face_a].plane.normal)
            }
            FaceKind::EdgeEdge { edge_a, edge_b } => {
                let (e_a, _, _) = edge_data(moving, edge_a);
                let (e_b, _, _) = edge_data(fixed, edge_b);
                let n = e_b.cross(obstacle.rotation() * e_a);
                let sign = if n.dot(obstacle.polytope().faces()[face].plane.normal) >= 0.0 { 1.0 } else { -1.0 };
                Self::EdgeEdge { e_b, e_a, sign }
            }
            FaceKind::Unclassified => return None,
        })
    }

    /// The unit normal at rotation `rotation` (a rotation about `z`).
    #[inline]
    pub fn normal(&self, rotation: &glam::DMat3) -> DVec3 {
        match *self {
            Self::Fixed(n) => n,
            Self::Moving(m) => -(*rotation * m).normalize(),
            Self::EdgeEdge { e_b, e_a, sign } => (e_b.cross(*rotation * e_a) * sign).normalize(),
        }
    }

    /// `(P - F0) . N(theta)` for `P - F0 = b - R a` (`b`, `a` differences of `B`'s and `A`'s vertices), with the
    /// unnormalised `N`: linear in `(cos, sin)` (see the module documentation and README).
    pub fn plane_test(&self, b: DVec3, a: DVec3) -> Trig {
        match *self {
            // (b - R a) . n = b . n - n . R a
            Self::Fixed(n) => Trig::constant(b.dot(n)) + Trig::rotated_dot(n, a).scale(-1.0),
            // (b - R a) . (-R m) = -b . R m + a . m
            Self::Moving(m) => Trig::rotated_dot(b, m).scale(-1.0) + Trig::constant(a.dot(m)),
            // (b - R a) . (e_B x R e_A) = (b x e_B) . R e_A - e_B . R (e_A x a)
            Self::EdgeEdge { e_b, e_a, sign } => {
                (Trig::rotated_dot(b.cross(e_b), e_a) + Trig::rotated_dot(e_b, e_a.cross(a)).scale(-1.0)).scale(sign)
            }
        }
    }
}

/// Vertices of a feature of `p`.
fn feature_vertices(p: &ConvexPolytope, f: Feature) -> Vec<usize> {
    match f {
        Feature::Vertex(v) => vec![v],
        Feature::Edge(e) => p.edges()[e].vertices.to_vec(),
        Feature::Face(f) => p.faces()[f].vertices.to_vec(),
    }
}

/// Kind (a): the first angle after `theta0` (forwards) or before it (backwards) at which a point `P_ij` not incident
/// to a face of `obstacle` (built at `theta0`) reaches that face's extrapolated plane. All `n_A n_B` points against
/// every face: O(F_C n_A n_B). Roots within `1e-9` rad of `theta0` are ignored (points on a plane at `theta0` itself
/// belong to a degenerate configuration that the (b)/(c) bands describe). `None` if no face has a recipe.
pub fn point_face_event(
    obstacle: &Obstacle,
    moving: &ConvexPolytope,
    fixed: &ConvexPolytope,
    theta0: f64,
    forwards: bool,
) -> Option<(f64, Event)> {
    let poly = obstacle.polytope();
    let (av, bv) = (moving.vertices(), fixed.vertices());
    let mut best: Option<(f64, Event)> = None;
    let mut incident = vec![false; av.len() * bv.len()];
    for (fi, face) in poly.faces().iter().enumerate() {
        let kind = obstacle.face_kinds()[fi];
        let recipe = NormalRecipe::of(obstacle, fi, moving, fixed)?;
        let (Some(ff), Some(mf)) = (kind.fixed_feature(), kind.moving_feature()) else { return None };
        let js = feature_vertices(fixed, ff);
        let is = feature_vertices(moving, mf);
        incident.iter_mut().for_each(|x| *x = false);
        for &i in &is {
            for &j in &js {
                incident[i * bv.len() + j] = true;
            }
        }
        let [i0, j0] = obstacle.vertex_pairs()[face.vertices[0]];
        for i in 0..av.len() {
            let a = av[i] - av[i0];
            for j in 0..bv.len() {
                if incident[i * bv.len() + j] {
                    continue;
                }
                let b = bv[j] - bv[j0];
                let f = recipe.plane_test(b, a);
                let magnitude = a.length() + b.length();
                if f.amplitude() <= 1e-12 * magnitude {
                    continue; // identically on or off the plane: a (c) family or never
                }
                for r in f.roots() {
                    let d = if forwards { wrap(r - theta0) } else { wrap(theta0 - r) };
                    if d <= 1e-9 {
                        continue;
                    }
                    if best.as_ref().is_none_or(|(bd, _)| d < *bd) {
                        let event = Event {
                            angle: r,
                            kind: EventKind::PointCrossesFace { face: kind, point: [i, j] },
                            function: f,
                            tolerance: 0.0,
                        };
                        best = Some((d, event));
                    }
                }
            }
        }
    }
    best.map(|(d, e)| (if forwards { theta0 + d } else { theta0 - d }, e))
}
