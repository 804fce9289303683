//! The sheet-metal part model of [A] V-A-1: planar mid-surface polygons (with holes) plus a thickness.
//!
//! Each face of the zero-thickness model is extruded by the sheet thickness (symmetrically about the mid-surface,
//! `thickness / 2` to each side) into convex prisms: a convex face without holes gives one prism; a concave face or a
//! face with holes is first decomposed into convex polygons (see [`Decomposition`]).

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A zero-thickness sheet-metal model: planar faces with holes, and the sheet thickness.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SheetMetal {
    /// Sheet thickness (mm), > 0.
    pub thickness: f64,
    /// Planar mid-surface faces.
    pub faces: Vec<SheetFace>,
}

/// One planar mid-surface face: an outline and holes, all coplanar.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SheetFace {
    /// Outer boundary (either orientation; normalised when building).
    pub outline: Vec<DVec3>,
    /// Holes strictly inside the outline.
    #[serde(default)]
    pub holes: Vec<Vec<DVec3>>,
}

/// How concave faces and faces with holes are split into convex polygons before extrusion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Decomposition {
    /// Triangulate, then merge triangles into larger convex polygons (Hertel-Mehlhorn): few components.
    #[default]
    ConvexMerge,
    /// The plain triangulation of [A]: reproduces the seed's component counts (Channel 3, Triangle 6, Complex 79).
    Triangulation,
}
