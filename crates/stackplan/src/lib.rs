//! # stackplan
//!
//! Interference-free stacking of polyhedral sheet-metal parts (Ayyadevara, Bourne, Shimada, Sturges, IEEE T-RA 2002)
//! and assembly contact states (Pan, Schimmels, ICRA 2004). This crate is a thin facade: each module re-exports one
//! focused crate, so library users can depend on `stackplan` alone or on the single crates they need.
//!
//! A stacking plan for six Channel parts, checked again by the stability crate, and the c-space obstacle of one pair
//! of convex components (the vector types are `glam`'s, re-exported as `stackplan::geom::{DVec3, DMat3}`):
//!
//! ```
//! use stackplan::geom::{DMat3, Decomposition, examples};
//! use stackplan::planner::{FloorVolume, PlanOptions, plan_stack};
//! use stackplan::stability::check_stack;
//!
//! // the seed's Channel part (three convex components), density 1
//! let part = examples::part_by_name("channel", Decomposition::ConvexMerge).expect("a built-in example");
//!
//! // six parts on a 600 x 600 mm floor, at most 400 mm high, w = 0.5, 15-degree steps, 5 mm clearance
//! let mut options = PlanOptions::new(6, FloorVolume::rectangle(-300.0, -300.0, 300.0, 300.0, 400.0));
//! options.w = 0.5;
//! options.dtheta = 15f64.to_radians();
//! let plan = plan_stack(&part, &options)?;
//! assert!(plan.stopped.is_none() && plan.parts.len() == 6 && plan.stack_stable);
//!
//! // each planned part's pose (world vertex = rotation . v + position)
//! let first = plan.parts[0].pose();
//! assert!(first.position.z >= 0.0);
//!
//! // the plan checked again as `stackplan check` checks it: its friction, clearance, cup and release drops
//! let report = check_stack(&plan.stack(&part), &plan.check_options())?;
//! assert!(report.ok, "{report:?}");
//!
//! // the c-space obstacle of component 0 turned by 30 degrees about z against component 1 (both unplaced):
//! // translations p with the turned component 0 at p overlapping component 1
//! let obstacle = stackplan::cspace::minkowski::obstacle(
//!     &part.components()[0],
//!     DMat3::from_rotation_z(30f64.to_radians()),
//!     &part.components()[1],
//! )?;
//! assert!(obstacle.polytope().volume() > 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use stackplan_contact_states as contact_states;
pub use stackplan_cspace as cspace;
pub use stackplan_freespace as freespace;
pub use stackplan_geom as geom;
pub use stackplan_orient_interval as orient_interval;
pub use stackplan_planner as planner;
pub use stackplan_stability as stability;
