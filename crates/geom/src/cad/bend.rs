//! A sheet-metal bend and its conservative convex decomposition.
//!
//! A bend is the region between two coaxial circular cylinders of radii `r` (inner) and `R = r + t` (outer, `t` the
//! sheet thickness), over an angle `phi` about the axis and an interval of the axis: an annular sector extruded along
//! the axis. It is not convex, so it is cut at `n` equal angles `Delta = phi / n` into segments, and each segment is
//! replaced by the convex prism bounded by
//! - the two radial planes of the cut (shared exactly with the neighbouring segments, and with the flat plates at the
//!   two ends: the tangent lines of a bend lie on its first and last radial planes);
//! - the chord of the inner arc (the chord lies nearer the axis than the arc: the segment contains the inner arc);
//! - the two tangents of the outer arc at the cut angles, which meet at radius `R / cos(Delta / 2)` (they lie outside
//!   the arc: the segment contains the outer arc);
//! - the two planes that end the axial interval.
//!
//! So the union of the segments contains the bend, and a segment stands outside it by at most
//! `max(R (1 / cos(Delta / 2) - 1), r (1 - cos(Delta / 2)))` ([`Bend::deviation`]); [`Bend::segments_within`] picks
//! the fewest segments that keep this below a tolerance. The segments of one bend share their radial faces, so their
//! interiors are disjoint. This is the "outer arc by tangent segments, inner arc by chords" rule of a conservative
//! decomposition: interference-free for the pieces implies interference-free for the steel.
//!
//! Cost: O(n) per bend.

use crate::polytope::{ConvexPolytope, PolytopeError};
use crate::sheet_metal::prism_between;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// One bend: an annular sector of two coaxial cylinders, extruded along their axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bend {
    /// A point of the axis; the axial interval is measured from it.
    pub center: DVec3,
    /// Unit direction of the axis; angles turn counter-clockwise about it.
    pub axis: DVec3,
    /// Inner radius `r` (mm), > 0.
    pub inner_radius: f64,
    /// Outer radius `R` (mm), > `r`.
    pub outer_radius: f64,
    /// Unit vector perpendicular to the axis at angle 0 (the start of the bend).
    pub start: DVec3,
    /// Swept angle `phi` (radians), in `(0, 2 pi)`.
    pub angle: f64,
    /// The axial interval `[lo, hi]` (mm along `axis` from `center`).
    pub axial: [f64; 2],
}

impl Bend {
    /// The unit radial direction at angle `a`.
    pub fn radial(&self, a: f64) -> DVec3 {
        let w = self.axis.cross(self.start);
        self.start * a.cos() + w * a.sin()
    }

    /// The largest distance by which the `n`-segment decomposition stands outside the bend (mm).
    pub fn deviation(&self, n: usize) -> f64 {
        let half = self.angle / (2.0 * n.max(1) as f64);
        let outer = self.outer_radius * (1.0 / half.cos() - 1.0);
        let inner = self.inner_radius * (1.0 - half.cos());
        outer.max(inner)
    }

    /// The fewest segments whose [`Bend::deviation`] is at most `tolerance` (mm, > 0), and at least one per 60
    /// degrees (so that a tangent corner never runs far out even for a coarse tolerance). At most 10 000.
    pub fn segments_within(&self, tolerance: f64) -> usize {
        let min_by_angle = (self.angle / std::f64::consts::FRAC_PI_3).ceil().max(1.0) as usize;
        let mut n = min_by_angle;
        // the deviation falls monotonically with n; a doubling search then a bisection
        if self.deviation(n) <= tolerance {
            return n;
        }
        let mut hi = n;
        while self.deviation(hi) > tolerance && hi < 10_000 {
            n = hi;
            hi = (hi * 2).min(10_000);
        }
        if self.deviation(hi) > tolerance {
            return hi;
        }
        let mut lo = n; // deviation(lo) > tolerance >= deviation(hi)
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if self.deviation(mid) <= tolerance { hi = mid } else { lo = mid }
        }
        hi
    }

    /// The exact volume of the bend: `phi (R^2 - r^2) / 2` times the axial length (mm^3).
    pub fn volume(&self) -> f64 {
        self.angle * (self.outer_radius.powi(2) - self.inner_radius.powi(2)) / 2.0 * (self.axial[1] - self.axial[0])
    }

    /// The `n` convex segments at equal angles (see the module documentation), in order of angle.
    pub fn segments(&self, n: usize) -> Result<Vec<ConvexPolytope>, PolytopeError> {
        let n = n.max(1);
        let cuts: Vec<f64> = (0..=n).map(|k| self.angle * k as f64 / n as f64).collect();
        self.segments_at(&cuts)
    }

    /// The largest distance by which the segments between the increasing angles `cuts` stand outside the bend.
    pub fn deviation_at(&self, cuts: &[f64]) -> f64 {
        cuts.windows(2)
            .map(|w| {
                let half = (w[1] - w[0]) / 2.0;
                (self.outer_radius * (1.0 / half.cos() - 1.0)).max(self.inner_radius * (1.0 - half.cos()))
            })
            .fold(0.0, f64::max)
    }

    /// The convex segments between the increasing angles `cuts` (radians from [`Bend::start`], each step below pi).
    /// A bend tessellated by chords (a mesh) is cut at some of its own vertices, so that each segment's inner chord
    /// lies nearer the axis than the tessellation's chords it spans: the segments then contain the tessellated
    /// bend, not only the true one.
    pub fn segments_at(&self, cuts: &[f64]) -> Result<Vec<ConvexPolytope>, PolytopeError> {
        let (z0, z1) = (self.axis * self.axial[0], self.axis * self.axial[1]);
        cuts.windows(2)
            .map(|w| {
                let (a0, a1) = (w[0], w[1]);
                let delta = a1 - a0;
                let corner_radius = self.outer_radius / (delta / 2.0).cos();
                // counter-clockwise about the axis: outer arc forwards, inner chord backwards
                let ring = [
                    self.radial(a0) * self.outer_radius,
                    self.radial(a0 + delta / 2.0) * corner_radius,
                    self.radial(a1) * self.outer_radius,
                    self.radial(a1) * self.inner_radius,
                    self.radial(a0) * self.inner_radius,
                ];
                let piece = prism_between(
                    ring.iter().map(|q| self.center + *q + z0).collect(),
                    ring.iter().map(|q| self.center + *q + z1).collect(),
                )?;
                piece.validate()?;
                Ok(piece)
            })
            .collect()
    }

    /// Cut angles among `vertices` (angles of a tessellation's vertices, radians from [`Bend::start`]) with the
    /// fewest segments whose deviation stays within `tolerance` where the tessellation allows (a step between two
    /// neighbouring vertices is never split): greedy, the farthest vertex within the largest allowed step each time.
    /// Always starts at 0 and ends at [`Bend::angle`]; vertices within a milliradian of an end or of each other count
    /// as one (their angles come from rounded coordinates).
    pub fn cuts_among(&self, vertices: &[f64], tolerance: f64) -> Vec<f64> {
        let n = self.segments_within(tolerance);
        let step = self.angle / n as f64;
        // vertices measured from rounded coordinates: those within a milliradian of an end or of each other are one
        let close = 1e-3;
        let mut inner: Vec<f64> = vertices.iter().copied().filter(|a| *a > close && *a < self.angle - close).collect();
        inner.sort_by(f64::total_cmp);
        inner.dedup_by(|a, b| (*a - *b).abs() <= close);
        let mut cuts = vec![0.0];
        let mut k = 0;
        let mut at = 0.0;
        while at < self.angle {
            if self.angle - at <= step * (1.0 + 1e-9) {
                break;
            }
            // the farthest vertex within one step, else the next vertex
            let mut next = None;
            while k < inner.len() && inner[k] <= at + step * (1.0 + 1e-9) {
                next = Some(inner[k]);
                k += 1;
            }
            let chosen = match next {
                Some(a) => a,
                None if k < inner.len() => {
                    k += 1;
                    inner[k - 1]
                }
                None => break,
            };
            cuts.push(chosen);
            at = chosen;
        }
        cuts.push(self.angle);
        cuts
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn quarter() -> Bend {
        Bend {
            center: DVec3::new(1.0, 2.0, 3.0),
            axis: DVec3::Z,
            inner_radius: 3.0,
            outer_radius: 5.0,
            start: DVec3::X,
            angle: FRAC_PI_2,
            axial: [-10.0, 30.0],
        }
    }

    fn inside(pieces: &[ConvexPolytope], p: DVec3) -> bool {
        pieces.iter().any(|c| c.planes().all(|pl| pl.signed_distance(p) <= 1e-9))
    }

    #[test]
    fn segments_contain_the_bend_and_stay_within_the_deviation() {
        let bend = quarter();
        for tolerance in [0.5, 0.1, 0.01] {
            let n = bend.segments_within(tolerance);
            assert!(bend.deviation(n) <= tolerance);
            assert!(n == 1 || bend.deviation(n - 1) > tolerance || n == 2, "n = {n} is not the fewest");
            let pieces = bend.segments(n).expect("segments");
            assert_eq!(pieces.len(), n);
            // points of the true bend (on both arcs, in between, at the axial ends) lie in the union
            for i in 0..=200 {
                let a = bend.angle * i as f64 / 200.0;
                for s in [0.0, 0.3, 1.0] {
                    let rho = bend.inner_radius + s * (bend.outer_radius - bend.inner_radius);
                    for z in [bend.axial[0], 0.0, bend.axial[1]] {
                        let p = bend.center + bend.radial(a) * rho + bend.axis * z;
                        assert!(inside(&pieces, p), "tolerance {tolerance}: {p} outside the segments");
                    }
                }
            }
            // every vertex lies within the deviation of the bend's annular sector
            for c in &pieces {
                for v in c.vertices() {
                    let d = *v - bend.center;
                    let rho = (d - bend.axis * d.dot(bend.axis)).length();
                    assert!(rho >= bend.inner_radius * (1.0 - 1e-12) - tolerance);
                    assert!(rho <= bend.outer_radius + tolerance + 1e-12);
                }
            }
            // volume: at least the bend's, and within the deviation times the surface
            let volume: f64 = pieces.iter().map(ConvexPolytope::volume).sum();
            assert!(volume >= bend.volume() * (1.0 - 1e-12));
            let surface = bend.angle * (bend.inner_radius + bend.outer_radius) * (bend.axial[1] - bend.axial[0]);
            assert!(volume - bend.volume() <= tolerance * surface);
        }
    }

    #[test]
    fn neighbouring_segments_share_their_cut_exactly_and_do_not_overlap() {
        let bend = Bend { angle: PI * 0.75, ..quarter() };
        let pieces = bend.segments(5).expect("segments");
        let volume: f64 = pieces.iter().map(ConvexPolytope::volume).sum();
        // a point just past a cut lies in one segment only
        for k in 1..5 {
            let a = bend.angle * k as f64 / 5.0;
            let p = bend.center + bend.radial(a + 1e-6) * 4.0;
            let count = pieces.iter().filter(|c| c.planes().all(|pl| pl.signed_distance(p) < -1e-9)).count();
            assert_eq!(count, 1, "cut {k}");
        }
        assert!(volume > bend.volume());
    }

    #[test]
    fn cuts_among_a_tessellation_keep_its_vertices_and_contain_its_chords() {
        let bend = quarter();
        for mesh_step in [0.05, 0.2, 0.5] {
            // a tessellation at uneven angles: vertices on both arcs
            let mut angles = vec![0.0];
            let mut a: f64 = 0.0;
            let mut k = 0;
            while a < bend.angle {
                a = (a + mesh_step * (0.7 + 0.6 * ((k * 7 % 5) as f64 / 4.0))).min(bend.angle);
                angles.push(a);
                k += 1;
            }
            let cuts = bend.cuts_among(&angles, 0.1);
            assert_eq!(cuts.first(), Some(&0.0));
            assert_eq!(cuts.last(), Some(&bend.angle));
            assert!(cuts.iter().all(|c| angles.iter().any(|a| (a - c).abs() < 1e-12)), "cuts off the vertices");
            assert!(cuts.windows(2).all(|w| w[1] > w[0]));
            let pieces = bend.segments_at(&cuts).expect("segments");
            // points on the tessellation's chords (inner and outer), at the axial middle, lie in the segments
            for w in angles.windows(2) {
                for t in 0..=20 {
                    let s = t as f64 / 20.0;
                    for r in [bend.inner_radius, bend.outer_radius] {
                        let p = bend.radial(w[0]) * r * (1.0 - s) + bend.radial(w[1]) * r * s;
                        let p = bend.center + p + bend.axis * 10.0;
                        assert!(inside(&pieces, p), "step {mesh_step}: chord point {p} outside");
                    }
                }
            }
            // where the tessellation is fine enough, the deviation is within the tolerance
            if mesh_step <= 0.05 {
                assert!(bend.deviation_at(&cuts) <= 0.1);
            }
        }
    }

    #[test]
    fn segment_count_follows_the_tolerance() {
        let bend = quarter();
        assert!(bend.segments_within(0.01) > bend.segments_within(0.1));
        assert_eq!(bend.segments_within(1e3), 2, "at least one segment per 60 degrees");
        assert_eq!(Bend { angle: 0.1, ..bend }.segments_within(1.0), 1);
    }
}
