//! # stackplan-cspace
//!
//! Translational configuration-space obstacles of convex component pairs (\[A\] App. B) and what the planner derives
//! from them:
//!
//! * [`minkowski`]: `C(A, B) = B (+) (-R A)` by Gauss-map overlay with vertex and face provenance (the obstacle's
//!   types in a leaf module, re-exported there; the 2-D sums of merged faces and the z-prism fast path in modules of
//!   their own);
//! * [`offset`]: clearance (mitred plane offset, \[A\] eq. 10-11), insertion obstacles (`C (+) {-t z}`, \[A\]
//!   condition 4) and slices at constant `p_z`;
//! * [`interference`]: interference pairs between placed parts (\[A\] eq. 6-8): a BVH broad phase and an exact
//!   separating-axis narrow phase reporting penetrating vs touching;
//! * [`distance`]: the distance of two disjoint convex polytopes by closest features (the separated pairs within a
//!   clearance);
//! * [`cache`]: an obstacle cache with construction/hit counters.

pub mod cache;
pub mod distance;
mod edge_table;
pub mod interference;
pub mod minkowski;
pub mod offset;
mod planar;
mod types;
mod z_prism;

pub use cache::{CacheStats, ObstacleCache};
pub use interference::{InterferencePair, PairContact, PlacedConvex, PlacedScene};
pub use minkowski::{FaceKind, Feature, Obstacle, ObstacleError, Route, facet_bound, obstacle, obstacle_by_hull};
pub use offset::{HalfSpaces, clearance, insertion, insertion_polytope, slice};
