//! Memo of the rigid-body problems of one stack check (the support-tree edges of [`super::tree`] and the margin units
//! of [`super::margin`]).
//!
//! The checks of a stack solve many identical problems: the edge "part `j` on the part below" appears in the check of
//! `j` on fixed supports, in every prefix stack containing `j` and in the whole stack. A problem is keyed by the exact
//! bits of everything its answer depends on (the rigid union's mass, c.g. and box, every contact point's position and
//! frame, in order, the friction coefficient, and for margins the number of directions and the certificate's bound
//! `m`); the answer of a problem is a deterministic function of these, so a hit returns exactly what a new solve
//! would (the patch labels of the points are not part of the key: they do not enter the solve). Cost: O(K) per
//! lookup; the memo lives as long as the check.

use super::instability::Mechanism;
use super::{Point, Rigid, Verdict};
use glam::DVec3;
use std::collections::HashMap;
use std::sync::Mutex;

/// A memoised equilibrium answer: the verdict and the forces on the rigid body.
type EquilibriumAnswer = (Verdict, Vec<DVec3>);

/// A memo of equilibrium and margin solves, shared by the calls of one stack check (see [`super::solve_equilibrium_with`]).
#[derive(Debug, Default)]
pub struct SolveCache {
    equilibria: Mutex<HashMap<Vec<u64>, EquilibriumAnswer>>,
    margins: Mutex<HashMap<Vec<u64>, Vec<Option<f64>>>>,
    /// Verified certificates of instability of earlier solves, the most recent first (at most [`MECHANISMS`] each):
    /// of groups (twists of parts), and of support-tree edges (the twist of the edge's rigid union).
    mechanisms: Mutex<[Vec<Mechanism>; 2]>,
}

/// How many certificates of instability the memo keeps.
pub(super) const MECHANISMS: usize = 8;

/// The exact key of a rigid-body problem: `extra` values, the body, then every point.
pub(super) fn key(extra: &[f64], body: &Rigid, points: &[Point]) -> Vec<u64> {
    let mut out = Vec::with_capacity(extra.len() + 10 + 12 * points.len());
    out.extend(extra.iter().map(|x| x.to_bits()));
    out.push(body.mass.to_bits());
    for v in [body.cg, body.aabb.0, body.aabb.1] {
        out.extend(v.to_array().map(f64::to_bits));
    }
    for pt in points {
        out.extend(pt.p.to_array().map(f64::to_bits));
        for axis in pt.frame {
            out.extend(axis.to_array().map(f64::to_bits));
        }
        // the fixed side: whether there is one (the units' points have none, their groups' points may)
        out.push(pt.a.map_or(u64::MAX, |a| a as u64));
        out.push(pt.b as u64);
    }
    out
}

impl SolveCache {
    /// An empty memo.
    pub fn new() -> Self {
        Self::default()
    }

    pub(super) fn equilibrium(
        &self,
        key: Vec<u64>,
        solve: impl FnOnce() -> Result<(Verdict, Vec<DVec3>), super::EquilibriumError>,
    ) -> Result<(Verdict, Vec<DVec3>), super::EquilibriumError> {
        memo(&self.equilibria, key, solve)
    }

    /// Keeps a verified certificate of instability of a group (`edge` false) or of a support-tree edge (`edge` true)
    /// for later problems (dropping the oldest beyond [`MECHANISMS`]).
    pub(super) fn remember(&self, edge: bool, mechanism: Mechanism) {
        if let Ok(mut lists) = self.mechanisms.lock() {
            let list = &mut lists[usize::from(edge)];
            list.insert(0, mechanism);
            list.truncate(MECHANISMS);
        }
    }

    /// Whether `proves` holds for a remembered certificate of a group (`edge` false) or of an edge (`edge` true); the
    /// first that does moves to the front.
    pub(super) fn any_mechanism(&self, edge: bool, proves: impl Fn(&Mechanism) -> bool) -> bool {
        let Ok(mut lists) = self.mechanisms.lock() else { return false };
        let list = &mut lists[usize::from(edge)];
        match list.iter().position(proves) {
            Some(k) => {
                let hit = list.remove(k);
                list.insert(0, hit);
                true
            }
            None => false,
        }
    }

    pub(super) fn margin(
        &self,
        key: Vec<u64>,
        solve: impl FnOnce() -> Result<Vec<Option<f64>>, super::EquilibriumError>,
    ) -> Result<Vec<Option<f64>>, super::EquilibriumError> {
        memo(&self.margins, key, solve)
    }
}

/// The value under `key`, or `solve()`'s stored under it (a poisoned lock only disables the memo).
fn memo<V: Clone, E>(
    map: &Mutex<HashMap<Vec<u64>, V>>,
    key: Vec<u64>,
    solve: impl FnOnce() -> Result<V, E>,
) -> Result<V, E> {
    if let Some(hit) = map.lock().ok().and_then(|m| m.get(&key).cloned()) {
        return Ok(hit);
    }
    let value = solve()?;
    if let Ok(mut m) = map.lock() {
        m.insert(key, value.clone());
    }
    Ok(value)
}
