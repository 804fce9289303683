//! # stackplan-orient-interval
//!
//! Critical orientations, constant-structure ("constant topology") orientation intervals and extrapolation of
//! convex-pair c-space obstacles as the moving component rotates about world `z` (Ayyadevara et al. 2002, \[A\]
//! section IV and Appendix C; `docs/algorithms.md`, "Critical orientations and extrapolation"):
//!
//! * [`trig`]: closed-form roots and tolerance bands of `alpha cos + beta sin + gamma` (\[A\] eq. 14-16);
//! * [`critical`]: every event kind (normal crossing arc, the permanently degenerate polar and equatorial families,
//!   and the seed's point-crosses-face test) and the intervals between them, per angle and over a full turn;
//! * [`extrapolate`]: the obstacle at any angle of an interval from the stored structure (\[A\] eq. 4), O(size);
//! * [`sweep`](mod@sweep): obstacles over a list of angles, building at interval starts and extrapolating elsewhere,
//!   with counters (\[A\] Table I);
//! * [`structure`]: structure comparison (faces by kind and provenance, as sets);
//! * [`pair_summary`]: the regression summary for `cargo xtask regress`.

pub mod critical;
pub mod extrapolate;
pub mod pair_summary;
pub mod structure;
pub mod sweep;
pub mod trig;

pub use critical::{Event, EventBand, EventKind, Interval, PairEvents, Pole, TurnInterval, point_face_event};
pub use extrapolate::{ExtrapolateError, ExtrapolatedGeometry, ObstacleStructure, extrapolate_from, rotation_z};
pub use pair_summary::regress_summary;
pub use sweep::{PairSweep, SweepStats, degree_steps, sweep, uniform_angles};
pub use trig::Trig;
