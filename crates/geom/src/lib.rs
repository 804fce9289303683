//! # stackplan-geom
//!
//! The geometry kernel of stackplan: `f64` everywhere, lengths in millimetres, angles in radians.
//!
//! * [`predicates`]: the exact orientation predicates every combinatorial decision goes through;
//! * [`tolerance`]: the one tolerance policy for computed quantities (touching vs penetrating);
//! * [`polytope`]: convex polytopes with faces, edges and planes, and their validation;
//! * [`hull`]: a robust 3-D convex hull (Quickhull with exact predicates and exact coplanar merging);
//! * [`accurate_normal`]: the normal of the plane through three points, accurate for slivers (the hull's face planes);
//! * [`mass`]: volume, centre of gravity and inertia tensor;
//! * [`part`]: rigid parts as unions of convex components, with boundary faces;
//! * [`plate`]: the flat plates of sheet-metal parts, and when two plates' pieces may stand for their filled outlines;
//! * [`pose`]: rigid poses (rotation and position) of placed parts;
//! * [`cad`]: parts from CAD (STEP, single-shell meshes) recognised as sheet metal;
//! * [`io`]: file formats (part JSON, STL, OBJ, glTF export, stack files) with located errors.

pub mod accurate_normal;
pub mod cad;
pub mod convex_merge;
pub mod examples;
pub mod hull;
mod hull_faces;
pub mod io;
pub mod mass;
pub mod part;
pub mod plate;
pub mod polygon;
pub mod polytope;
pub mod pose;
pub mod predicates;
mod quickhull;
pub mod sheet_metal;
pub mod tolerance;
pub mod triangulate;
mod union_find;
pub mod vertex_cycle;

pub use glam::{DMat3, DVec2, DVec3};
pub use hull::{
    ConvexHull, HullError, MAX_HULL_COORDINATE, MIN_COORDINATE, convex_hull, convex_hull_merged,
    convex_hull_merged_within,
};
pub use io::{IoError, ReadOptions, read_part, write_part};
pub use mass::MassProperties;
pub use part::{BoundaryFace, Part, PartError, PartOrigin};
pub use polytope::{Containment, ConvexPolytope, Edge, Face, Plane, PolytopeError};
pub use pose::{PlacedPart, Pose, PoseError};
pub use sheet_metal::{Decomposition, SheetFace, SheetMetal, SheetMetalError};
pub use tolerance::Tolerance;
pub use vertex_cycle::VertexCycle;
