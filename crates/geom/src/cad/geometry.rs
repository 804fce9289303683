//! The exact curves and surfaces of B-rep faces and edges, with the parametrisations of ISO 10303-42 (section 4.4,
//! geometry schema): points and first derivatives, the inverse map from a point to its parameters (closed form for
//! lines, conics and the elementary surfaces; Gauss-Newton projection from a coarse search for B-splines and
//! extrusions, as in Piegl & Tiller, *The NURBS Book*, section 6.1, point inversion), and the sampling of an edge
//! within a chord tolerance.
//!
//! Parametrisations (`o` the placement's origin, `x`, `y`, `z` its axes):
//! * `PLANE`: `o + u x + v y`;
//! * `CYLINDRICAL_SURFACE` of radius `r`: `o + r (cos u x + sin u y) + v z`;
//! * `CONICAL_SURFACE` of radius `r` at `v = 0` and semi-angle `a`: `o + (r + v tan a) (cos u x + sin u y) + v z`;
//! * `SPHERICAL_SURFACE`: `o + r cos v (cos u x + sin u y) + r sin v z`;
//! * `TOROIDAL_SURFACE` (major `R`, minor `r`): `o + (R + r cos v) (cos u x + sin u y) + r sin v z`;
//! * `SURFACE_OF_LINEAR_EXTRUSION` of a curve `C` along a vector `V`: `C(u) + v V`;
//! * `B_SPLINE_SURFACE_WITH_KNOTS` and its rational form: [`BSplineSurface`].
//!
//! Curves: `LINE` `p + t d`, `CIRCLE` `o + r (cos t x + sin t y)`, `ELLIPSE` `o + a cos t x + b sin t y`,
//! `POLYLINE` (parameter `k + s` on its `k`-th segment) and B-spline curves ([`BSplineCurve`]).
//!
//! Edge sampling: a circle or an ellipse at equal parameter steps, as many as keep the sagitta within the tolerance
//! (the steps depend only on the curve and the swept parameter range, so coaxial arcs of one bend are sampled at the
//! same angles); a B-spline span by span, each bisected until the points at a quarter, half and three quarters of
//! every piece lie within the tolerance of its chord (the same pieces for curves of the same knots); a polyline and
//! a line at their vertices.
//!
//! Complexity: evaluation O(1) for the elementary surfaces and as in [`super::nurbs`] for B-splines; an inversion by
//! projection is one coarse search of O(s) points (s about 8 per knot span, at most 64 each way) and at most 40
//! Gauss-Newton steps, or O(1) steps from a nearby hint; sampling an edge costs O(n) evaluations for n samples.

use super::nurbs::{BSplineCurve, BSplineSurface};
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// Deepest bisection of a B-spline piece when sampling (2^24 pieces per span at most).
const MAX_DEPTH: usize = 24;

/// An orthonormal placement: origin and axes (`AXIS2_PLACEMENT_3D`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Origin.
    pub origin: DVec3,
    /// First axis (the reference direction, made perpendicular to `z`).
    pub x: DVec3,
    /// `z x x`.
    pub y: DVec3,
    /// Unit axis.
    pub z: DVec3,
}

impl Frame {
    /// The frame of a location, a unit axis and an optional reference direction (any direction not along `z`;
    /// without one, or with one along `z`, an arbitrary perpendicular).
    pub fn new(origin: DVec3, z: DVec3, reference: Option<DVec3>) -> Frame {
        let x = reference
            .map(|r| r - z * r.dot(z))
            .filter(|r| r.length() > 1e-12)
            .map_or_else(|| z.any_orthonormal_vector(), DVec3::normalize);
        Frame { origin, x, y: z.cross(x), z }
    }

    /// `cos t x + sin t y`.
    fn radial(&self, t: f64) -> DVec3 {
        let (s, c) = t.sin_cos();
        c * self.x + s * self.y
    }

    /// The coordinates of `p` in the frame.
    fn local(&self, p: DVec3) -> DVec3 {
        let d = p - self.origin;
        DVec3::new(d.dot(self.x), d.dot(self.y), d.dot(self.z))
    }
}

/// The 3-D curve of an edge.
#[derive(Debug, Clone, PartialEq)]
pub enum Curve {
    /// `point + t direction`.
    Line {
        /// A point.
        point: DVec3,
        /// The direction (any length).
        direction: DVec3,
    },
    /// A circle of `radius` in the frame's x-y plane.
    Circle {
        /// The placement.
        frame: Frame,
        /// Radius (> 0).
        radius: f64,
    },
    /// An ellipse of semi-axes `a` (along x) and `b` (along y).
    Ellipse {
        /// The placement.
        frame: Frame,
        /// Semi-axis along x (> 0).
        a: f64,
        /// Semi-axis along y (> 0).
        b: f64,
    },
    /// Straight segments through the points.
    Polyline(Vec<DVec3>),
    /// A B-spline curve.
    BSpline(BSplineCurve),
}

impl Curve {
    /// The point at `t` and the first derivative there.
    pub fn eval(&self, t: f64) -> (DVec3, DVec3) {
        match self {
            Curve::Line { point, direction } => (*point + t * *direction, *direction),
            Curve::Circle { frame, radius } => {
                (frame.origin + *radius * frame.radial(t), *radius * frame.radial(t + PI / 2.0))
            }
            Curve::Ellipse { frame, a, b } => {
                let (s, c) = t.sin_cos();
                (frame.origin + a * c * frame.x + b * s * frame.y, -a * s * frame.x + b * c * frame.y)
            }
            Curve::Polyline(points) => {
                let last = points.len().saturating_sub(2);
                let k = (t.floor().max(0.0) as usize).min(last);
                let (p, q) = (points[k], points[(k + 1).min(points.len() - 1)]);
                (p + (t - k as f64) * (q - p), q - p)
            }
            Curve::BSpline(c) => c.eval(t),
        }
    }

    /// The period of a closed conic, `None` otherwise.
    pub fn period(&self) -> Option<f64> {
        matches!(self, Curve::Circle { .. } | Curve::Ellipse { .. }).then_some(TAU)
    }

    /// The parameter range of a bounded curve.
    pub fn domain(&self) -> Option<(f64, f64)> {
        match self {
            Curve::Polyline(points) => Some((0.0, points.len().saturating_sub(1) as f64)),
            Curve::BSpline(c) => Some(c.domain()),
            _ => None,
        }
    }

    /// The parameter of the point of the curve nearest `p` (closed form for lines and circles; an ellipse's and a
    /// B-spline's by projection).
    pub fn inverse(&self, p: DVec3) -> f64 {
        match self {
            Curve::Line { point, direction } => (p - *point).dot(*direction) / direction.length_squared(),
            Curve::Circle { frame, .. } => {
                let l = frame.local(p);
                l.y.atan2(l.x)
            }
            Curve::Ellipse { frame, a, b } => {
                let l = frame.local(p);
                let start = (l.y / b).atan2(l.x / a);
                newton_curve(self, p, start, None)
            }
            Curve::Polyline(points) => {
                let mut best = (f64::INFINITY, 0.0);
                for (k, w) in points.windows(2).enumerate() {
                    let d = w[1] - w[0];
                    let s = if d.length_squared() > 0.0 {
                        ((p - w[0]).dot(d) / d.length_squared()).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    let dist = (w[0] + s * d - p).length();
                    if dist < best.0 {
                        best = (dist, k as f64 + s);
                    }
                }
                best.1
            }
            Curve::BSpline(c) => {
                let breaks = c.breaks();
                let per = (8 * c.degree()).clamp(4, 64);
                let mut best = (f64::INFINITY, breaks[0]);
                for w in breaks.windows(2) {
                    for k in 0..=per {
                        let t = w[0] + (w[1] - w[0]) * k as f64 / per as f64;
                        let d = (c.point(t) - p).length_squared();
                        if d < best.0 {
                            best = (d, t);
                        }
                    }
                }
                newton_curve(self, p, best.1, Some(c.domain()))
            }
        }
    }

    /// The points strictly between parameters `t0` and `t1` (either order) that keep every chord within `tol` of
    /// the curve, in order from `t0`.
    pub fn samples(&self, t0: f64, t1: f64, tol: f64) -> Vec<DVec3> {
        match self {
            Curve::Line { .. } => Vec::new(),
            Curve::Circle { radius, .. } => {
                let n = conic_steps(*radius, (t1 - t0).abs(), tol);
                (1..n).map(|k| self.eval(t0 + (t1 - t0) * k as f64 / n as f64).0).collect()
            }
            Curve::Ellipse { a, b, .. } => {
                // the sagitta of a step h is at most max|C''| h^2 / 8, and |C''| <= max(a, b)
                let big = a.max(*b);
                let h = (8.0 * tol / big).sqrt().min(PI / 4.0);
                let n = ((t1 - t0).abs() / h).ceil().clamp(1.0, 1e6) as usize;
                (1..n).map(|k| self.eval(t0 + (t1 - t0) * k as f64 / n as f64).0).collect()
            }
            Curve::Polyline(points) => {
                let (lo, hi) = (t0.min(t1), t0.max(t1));
                let mut out: Vec<DVec3> =
                    (0..points.len()).filter(|&k| (k as f64) > lo && (k as f64) < hi).map(|k| points[k]).collect();
                if t1 < t0 {
                    out.reverse();
                }
                out
            }
            Curve::BSpline(c) => {
                let (lo, hi) = (t0.min(t1), t0.max(t1));
                let mut cuts = vec![lo];
                cuts.extend(c.breaks().into_iter().filter(|&u| u > lo && u < hi));
                cuts.push(hi);
                let mut params = Vec::new();
                for w in cuts.windows(2) {
                    bisect(&|t| c.point(t), w[0], w[1], tol, 0, &mut params);
                    params.push(w[1]);
                }
                params.pop();
                let mut out: Vec<DVec3> = params.into_iter().map(|t| c.point(t)).collect();
                if t1 < t0 {
                    out.reverse();
                }
                out
            }
        }
    }
}

/// Steps of an arc of radius `r` sweeping `sweep` radians with sagitta within `tol`: at least one per 90 degrees.
pub fn conic_steps(r: f64, sweep: f64, tol: f64) -> usize {
    let c = 1.0 - (tol / r).min(1.0);
    let delta = (2.0 * c.acos()).min(PI / 2.0);
    if delta > 0.0 { (sweep / delta).ceil().clamp(1.0, 1e6) as usize } else { 1 }
}

/// Parameters strictly inside `(a, b)`, in order, at which a path `f` is cut so that each piece lies within `tol`
/// of its chord (bisection, as for B-spline edges).
pub fn chord_params(f: &dyn Fn(f64) -> DVec3, a: f64, b: f64, tol: f64) -> Vec<f64> {
    let mut out = Vec::new();
    bisect(f, a, b, tol, 0, &mut out);
    out
}

/// Parameters strictly inside `(a, b)` that bisect it until each piece is within `tol` of its chord.
fn bisect(f: &dyn Fn(f64) -> DVec3, a: f64, b: f64, tol: f64, depth: usize, out: &mut Vec<f64>) {
    let (pa, pb) = (f(a), f(b));
    let flat = [0.25, 0.5, 0.75].iter().all(|s| segment_distance(f(a + (b - a) * s), pa, pb) <= tol);
    if flat || depth >= MAX_DEPTH {
        return;
    }
    let m = 0.5 * (a + b);
    bisect(f, a, m, tol, depth + 1, out);
    out.push(m);
    bisect(f, m, b, tol, depth + 1, out);
}

/// The distance of `p` from the segment `ab`.
pub fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 { ((p - a).dot(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a + s * ab - p).length()
}

/// Gauss-Newton projection of `p` onto a curve from `t`, within `domain` if bounded.
fn newton_curve(curve: &Curve, p: DVec3, mut t: f64, domain: Option<(f64, f64)>) -> f64 {
    for _ in 0..40 {
        let (c, d) = curve.eval(t);
        let dd = d.length_squared();
        if dd <= 0.0 {
            break;
        }
        let step = (c - p).dot(d) / dd;
        let next = match domain {
            Some((a, b)) => (t - step).clamp(a, b),
            None => t - step,
        };
        if !next.is_finite() {
            break;
        }
        let moved = (next - t).abs();
        t = next;
        if moved <= 1e-15 * t.abs().max(1.0) {
            break;
        }
    }
    t
}

/// The surface of a face.
#[derive(Debug, Clone, PartialEq)]
pub enum FaceSurface {
    /// A plane.
    Plane(Frame),
    /// A circular cylinder.
    Cylinder {
        /// Placement (z the axis).
        frame: Frame,
        /// Radius.
        radius: f64,
    },
    /// A circular cone.
    Cone {
        /// Placement (z the axis).
        frame: Frame,
        /// Radius at `v = 0`.
        radius: f64,
        /// Semi-angle (radians, in `(0, pi / 2)`).
        semi_angle: f64,
    },
    /// A sphere.
    Sphere {
        /// Placement.
        frame: Frame,
        /// Radius.
        radius: f64,
    },
    /// A torus.
    Torus {
        /// Placement (z the axis).
        frame: Frame,
        /// Distance of the tube's centre from the axis.
        major: f64,
        /// Radius of the tube.
        minor: f64,
    },
    /// A curve swept along a vector.
    Extrusion {
        /// The swept curve (u).
        curve: Curve,
        /// The sweep vector (v from 0 to 1 covers it once).
        vector: DVec3,
    },
    /// A B-spline surface.
    BSpline(BSplineSurface),
}

impl FaceSurface {
    /// The point at `(u, v)` and the partial derivatives `S_u`, `S_v`.
    pub fn eval(&self, q: DVec2) -> (DVec3, DVec3, DVec3) {
        let (u, v) = (q.x, q.y);
        match self {
            FaceSurface::Plane(f) => (f.origin + u * f.x + v * f.y, f.x, f.y),
            FaceSurface::Cylinder { frame: f, radius } => {
                (f.origin + *radius * f.radial(u) + v * f.z, *radius * f.radial(u + PI / 2.0), f.z)
            }
            FaceSurface::Cone { frame: f, radius, semi_angle } => {
                let t = semi_angle.tan();
                let r = radius + v * t;
                (f.origin + r * f.radial(u) + v * f.z, r * f.radial(u + PI / 2.0), t * f.radial(u) + f.z)
            }
            FaceSurface::Sphere { frame: f, radius } => {
                let (sv, cv) = v.sin_cos();
                (
                    f.origin + radius * (cv * f.radial(u) + sv * f.z),
                    radius * cv * f.radial(u + PI / 2.0),
                    radius * (-sv * f.radial(u) + cv * f.z),
                )
            }
            FaceSurface::Torus { frame: f, major, minor } => {
                let (sv, cv) = v.sin_cos();
                let r = major + minor * cv;
                (
                    f.origin + r * f.radial(u) + minor * sv * f.z,
                    r * f.radial(u + PI / 2.0),
                    minor * (-sv * f.radial(u) + cv * f.z),
                )
            }
            FaceSurface::Extrusion { curve, vector } => {
                let (c, d) = curve.eval(u);
                (c + v * *vector, d, *vector)
            }
            FaceSurface::BSpline(s) => s.eval(q.x, q.y),
        }
    }

    /// The point at `(u, v)`.
    pub fn point(&self, q: DVec2) -> DVec3 {
        self.eval(q).0
    }

    /// The periods in u and v (`None`: not periodic).
    pub fn periods(&self) -> (Option<f64>, Option<f64>) {
        match self {
            FaceSurface::Plane(_) | FaceSurface::BSpline(_) => (None, None),
            FaceSurface::Cylinder { .. } | FaceSurface::Cone { .. } | FaceSurface::Sphere { .. } => (Some(TAU), None),
            FaceSurface::Torus { .. } => (Some(TAU), Some(TAU)),
            FaceSurface::Extrusion { curve, .. } => (curve.period(), None),
        }
    }

    /// Whether the surface is a plane.
    pub fn is_plane(&self) -> bool {
        matches!(self, FaceSurface::Plane(_))
    }

    /// The parameters of the point of the surface nearest `p`: closed form for the elementary surfaces (periodic
    /// parameters in `(-pi, pi]`), projection for the others, from `hint` when given. Periodic parameters are then
    /// moved by whole periods to the representative nearest `hint`.
    pub fn inverse(&self, p: DVec3, hint: Option<DVec2>) -> DVec2 {
        let q = match self {
            FaceSurface::Plane(f) => {
                let l = f.local(p);
                DVec2::new(l.x, l.y)
            }
            FaceSurface::Cylinder { frame: f, .. } => {
                let l = f.local(p);
                DVec2::new(l.y.atan2(l.x), l.z)
            }
            FaceSurface::Cone { frame: f, radius, semi_angle } => {
                // the nearest point on the generator through p: along the slant from the v = 0 circle
                let l = f.local(p);
                let rho = l.x.hypot(l.y);
                let (s, c) = semi_angle.sin_cos();
                let along = (rho - radius) * s + l.z * c;
                DVec2::new(l.y.atan2(l.x), along * c)
            }
            FaceSurface::Sphere { frame: f, .. } => {
                let l = f.local(p);
                DVec2::new(l.y.atan2(l.x), l.z.atan2(l.x.hypot(l.y)))
            }
            FaceSurface::Torus { frame: f, major, .. } => {
                let l = f.local(p);
                DVec2::new(l.y.atan2(l.x), l.z.atan2(l.x.hypot(l.y) - major))
            }
            FaceSurface::Extrusion { curve, vector } => {
                let start = match hint {
                    Some(h) => h,
                    None => {
                        // the curve point nearest p moved back along the vector: exact when the vector is square
                        // to the curve's plane, a start for the projection otherwise
                        let w = vector.normalize_or_zero();
                        let v = (p - curve.eval(curve.inverse(p)).0).dot(w) / vector.length().max(1e-300);
                        DVec2::new(curve.inverse(p - v * *vector), v)
                    }
                };
                self.newton(p, start)
            }
            FaceSurface::BSpline(s) => {
                let start = hint.unwrap_or_else(|| coarse_search(s, p));
                self.newton(p, start)
            }
        };
        let (pu, pv) = self.periods();
        let near = |x: f64, period: Option<f64>, h: Option<f64>| match (period, h) {
            (Some(t), Some(h)) => x + t * ((h - x) / t).round(),
            _ => x,
        };
        DVec2::new(near(q.x, pu, hint.map(|h| h.x)), near(q.y, pv, hint.map(|h| h.y)))
    }

    /// Gauss-Newton projection of `p` from `q` (clamped to a B-spline's domain).
    fn newton(&self, p: DVec3, mut q: DVec2) -> DVec2 {
        let domain = match self {
            FaceSurface::BSpline(s) => Some(s.domain()),
            _ => None,
        };
        for _ in 0..40 {
            let (s, su, sv) = self.eval(q);
            let r = s - p;
            let (a, b, c) = (su.dot(su), su.dot(sv), sv.dot(sv));
            let det = a * c - b * b;
            if !(det.is_finite() && det > 0.0) {
                break;
            }
            let (gu, gv) = (r.dot(su), r.dot(sv));
            let step = DVec2::new((c * gu - b * gv) / det, (a * gv - b * gu) / det);
            let mut next = q - step;
            if let Some(((u0, u1), (v0, v1))) = domain {
                next = DVec2::new(next.x.clamp(u0, u1), next.y.clamp(v0, v1));
            }
            if !next.is_finite() {
                break;
            }
            let moved = (next - q).length();
            q = next;
            if moved <= 1e-15 * q.length().max(1.0) {
                break;
            }
        }
        q
    }
}

/// The sample of a B-spline surface's domain nearest `p`: about 8 points per knot span each way, at most 64.
fn coarse_search(s: &BSplineSurface, p: DVec3) -> DVec2 {
    let (bu, bv) = s.breaks();
    let grid = |b: &[f64]| -> Vec<f64> {
        let per = (64 / b.len().saturating_sub(1).max(1)).clamp(2, 8);
        let mut out = Vec::new();
        for w in b.windows(2) {
            for k in 0..per {
                out.push(w[0] + (w[1] - w[0]) * k as f64 / per as f64);
            }
        }
        if let Some(&last) = b.last() {
            out.push(last);
        }
        out
    };
    let (gu, gv) = (grid(&bu), grid(&bv));
    let mut best = (f64::INFINITY, DVec2::new(bu[0], bv[0]));
    for &u in &gu {
        for &v in &gv {
            let d = (s.point(u, v) - p).length_squared();
            if d < best.0 {
                best = (d, DVec2::new(u, v));
            }
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        Frame::new(DVec3::new(1.0, -2.0, 0.5), DVec3::new(1.0, 1.0, 1.0).normalize(), Some(DVec3::X))
    }

    #[test]
    fn points_of_cones_spheres_and_tori_satisfy_their_implicit_equations_and_invert() {
        let f = frame();
        let (r, a) = (2.75, 0.6);
        let surfaces = [
            FaceSurface::Cylinder { frame: f, radius: r },
            FaceSurface::Cone { frame: f, radius: r, semi_angle: a },
            FaceSurface::Sphere { frame: f, radius: r },
            FaceSurface::Torus { frame: f, major: 8.0, minor: 1.5 },
        ];
        for s in &surfaces {
            for i in 0..12 {
                for j in 0..7 {
                    let q = DVec2::new(-3.0 + 0.5 * i as f64, -1.2 + 0.4 * j as f64);
                    let (p, su, sv) = s.eval(q);
                    let l = f.local(p);
                    let rho = l.x.hypot(l.y);
                    let off = match s {
                        FaceSurface::Cylinder { .. } => rho - r,
                        FaceSurface::Cone { .. } => rho - (r + l.z * a.tan()),
                        FaceSurface::Sphere { .. } => l.length() - r,
                        FaceSurface::Torus { major, minor, .. } => (rho - major).hypot(l.z) - minor,
                        _ => unreachable!(),
                    };
                    assert!(off.abs() < 1e-13, "{s:?} at {q}: {off}");
                    // the derivatives match central differences
                    let h = 1e-6;
                    let du = (s.point(q + DVec2::X * h) - s.point(q - DVec2::X * h)) / (2.0 * h);
                    let dv = (s.point(q + DVec2::Y * h) - s.point(q - DVec2::Y * h)) / (2.0 * h);
                    assert!((du - su).length() < 1e-7 * su.length().max(1.0) && (dv - sv).length() < 1e-7);
                    // the inverse finds the point again (u to a period, near the given hint)
                    let back = s.inverse(p, Some(q));
                    assert!((s.point(back) - p).length() < 1e-12, "{s:?} at {q}: {back}");
                    if !matches!(s, FaceSurface::Sphere { .. }) || q.y.abs() < PI / 2.0 {
                        assert!((back - q).length() < 1e-12, "{s:?}: {back} vs {q}");
                    }
                }
            }
        }
    }

    #[test]
    fn b_spline_curves_and_surfaces_invert_by_projection() {
        let poles: Vec<DVec3> =
            (0..6).map(|k| DVec3::new(k as f64 * 10.0, (k as f64 * 1.3).sin() * 8.0, (k * k) as f64)).collect();
        let curve = BSplineCurve::new(3, &[4, 1, 1, 4], &[0.0, 0.3, 0.7, 1.0], &poles, None).expect("valid");
        let c = Curve::BSpline(curve.clone());
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            assert!((c.inverse(curve.point(t)) - t).abs() < 1e-10, "{t}");
        }
        let extrusion = FaceSurface::Extrusion { curve: c.clone(), vector: DVec3::new(0.5, 0.0, 3.0) };
        for k in 0..=10 {
            let q = DVec2::new(k as f64 / 10.0, 0.1 * k as f64);
            let back = extrusion.inverse(extrusion.point(q), None);
            assert!((back - q).length() < 1e-9, "{q}: {back}");
        }
    }

    #[test]
    fn edge_samples_keep_chords_within_the_tolerance_and_match_for_coaxial_arcs() {
        let f = frame();
        let circle = Curve::Circle { frame: f, radius: 5.0 };
        let shifted = Curve::Circle { frame: Frame { origin: f.origin + 3.0 * f.z, ..f }, radius: 5.0 };
        let (a, b) = (circle.samples(0.3, 2.0, 0.01), shifted.samples(0.3, 2.0, 0.01));
        assert_eq!(a.len(), b.len());
        for (p, q) in a.iter().zip(&b) {
            assert!((*q - *p - 3.0 * f.z).length() < 1e-12);
        }
        let mut all = vec![circle.eval(0.3).0];
        all.extend(a);
        all.push(circle.eval(2.0).0);
        for w in all.windows(2) {
            let mid = f.origin + 5.0 * ((w[0] + w[1]) / 2.0 - f.origin).normalize();
            assert!(segment_distance(mid, w[0], w[1]) <= 0.01 + 1e-12);
        }
        // a B-spline sampled backwards gives the same points in the other order
        let poles: Vec<DVec3> = (0..5).map(|k| DVec3::new(k as f64, (k % 2) as f64 * 4.0, 0.0)).collect();
        let spline =
            Curve::BSpline(BSplineCurve::new(2, &[3, 1, 1, 3], &[0.0, 1.0, 2.0, 3.0], &poles, None).expect("ok"));
        let forward = spline.samples(0.0, 3.0, 0.005);
        let mut backward = spline.samples(3.0, 0.0, 0.005);
        backward.reverse();
        assert_eq!(forward, backward);
        let mut all = vec![spline.eval(0.0).0];
        all.extend(forward);
        all.push(spline.eval(3.0).0);
        for w in all.windows(2) {
            let (t0, t1) = (spline.inverse(w[0]), spline.inverse(w[1]));
            for s in 1..8 {
                let p = spline.eval(t0 + (t1 - t0) * s as f64 / 8.0).0;
                assert!(segment_distance(p, w[0], w[1]) <= 0.005 * 1.2, "{t0} {t1}");
            }
        }
    }
}
