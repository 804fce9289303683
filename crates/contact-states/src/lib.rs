//! # stackplan-contact-states
//!
//! Assembly contact states of two polyhedral parts and their extremal configurations, after F. Pan and
//! J. M. Schimmels, *Robust procedures for obtaining assembly contact state extremal configurations*, ICRA 2004
//! (\[P\]):
//!
//! * [`surface`]: vertices, edges, faces of a part's boundary with adjacency and edge convexity; [`dxf_input`] reads
//!   them from DXF (3DFACE, polyface meshes);
//! * [`principal_contact`]: the six principal contact types, PPCs, contact states and their highest-level form;
//! * [`pose`]: configurations `t = (x, y, z, rx, ry, rz)` (`R = Rz Ry Rx` about the moving part's origin) and boxes;
//! * [`criteria`]: feature criteria, the growth-distance penetration term and the objective of \[P\] eq. 8;
//! * [`growth_distance`](mod@growth_distance): Ong & Gilbert's growth distance of convex pieces;
//! * [`ga`]: the seeded real-coded GA with a local polish; [`extremal`]: extremal configurations (\[P\] eq. 11-12);
//! * [`manifold`]: projection onto a state's contact manifold, the strict check of a state at a configuration,
//!   extremals by a compass search on the manifold;
//! * [`analytic_seeds`]: deterministic edge-edge crossing configurations that seed the thin e-e states;
//! * [`acsg`]: the bottom-up ACSG with CLCN/CMCN relations and search-range refinement, JSON and DOT output.
//!
//! Part A is the fixed part, part B the moving one; PC labels name A's element first (`f2-v3`).

pub mod acsg;
pub mod analytic_seeds;
pub mod criteria;
pub mod discovery;
pub mod dxf_input;
pub mod extremal;
pub mod features;
pub mod ga;
pub mod growth_distance;
pub mod manifold;
pub mod pose;
pub mod principal_contact;
pub mod surface;

pub use acsg::{Acsg, AcsgSettings, StateRecord, generate};
pub use criteria::{ContactPart, Objective, Weights};
pub use ga::GaSettings;
pub use ga::SettingsError;
pub use growth_distance::{ConvexPiece, growth_distance};
pub use pose::{Config, ConfigBox, Pose};
pub use principal_contact::{ContactState, PcType, PrincipalContact};
pub use surface::{Element, ElementKind, SurfaceElements, SurfaceError};
