//! # stackplan
//!
//! Interference-free stacking of polyhedral sheet-metal parts (Ayyadevara, Bourne, Shimada, Sturges, IEEE T-RA 2002)
//! and assembly contact states (Pan, Schimmels, ICRA 2004). This crate is a thin facade: each module re-exports one
//! focused crate, so library users can depend on `stackplan` alone or on the single crates they need.

pub use stackplan_contact_states as contact_states;
pub use stackplan_cspace as cspace;
pub use stackplan_freespace as freespace;
pub use stackplan_geom as geom;
pub use stackplan_orient_interval as orient_interval;
pub use stackplan_planner as planner;
pub use stackplan_stability as stability;
