//! One linear inequality `normal . p <= offset` in `D` variables with its provenance [`Tag`] (\[A\] VI-A-1: "each
//! convex component of free space is represented as a set of linear inequalities"). The tag maps an active
//! constraint of a placement back to an obstacle face or a wall of the floor volume. A leaf module.

use serde::{Deserialize, Serialize};

/// Where an inequality of a cell comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Tag {
    /// Side `side` (from vertex `side` to `side + 1`) of the floor polygon: the part touches that wall.
    FloorSide {
        /// Index of the polygon edge.
        side: u32,
    },
    /// The floor `z >= 0`: the part rests on the floor.
    Floor,
    /// The maximum stack height `z <= H`.
    Ceiling,
    /// The position is outside a c-space obstacle across its face `face` (`n . p >= d`): when active, the part
    /// touches the obstacle with the contact that face describes.
    ObstacleFace {
        /// Caller's identifier of the obstacle.
        obstacle: u64,
        /// Face index within the obstacle.
        face: u32,
    },
    /// The inside of an obstacle face (`n . p <= d`), a cut that splits free space into convex pieces: not a contact
    /// by itself.
    ObstacleCut {
        /// Caller's identifier of the obstacle.
        obstacle: u64,
        /// Face index within the obstacle.
        face: u32,
    },
    /// Anything else, labelled by the caller.
    User(u64),
}

/// One inequality `normal . p <= offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Halfspace<const D: usize> {
    /// Outward normal (unit length once inside a cell).
    pub normal: [f64; D],
    /// Offset.
    pub offset: f64,
    /// Provenance.
    pub tag: Tag,
}

impl<const D: usize> Halfspace<D> {
    /// A half-space `normal . p <= offset`.
    pub fn new(normal: [f64; D], offset: f64, tag: Tag) -> Self {
        Self { normal, offset, tag }
    }

    /// Signed distance-like slack `normal . p - offset` (a distance when the normal is unit).
    #[inline]
    pub fn excess(&self, p: &[f64; D]) -> f64 {
        let mut s = -self.offset;
        for i in 0..D {
            s += self.normal[i] * p[i];
        }
        s
    }

    /// The complementary closed half-space `normal . p >= offset`, i.e. `-normal . p <= -offset`.
    pub fn flipped(&self, tag: Tag) -> Self {
        Self { normal: self.normal.map(|c| -c), offset: -self.offset, tag }
    }
}
