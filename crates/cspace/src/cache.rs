//! A cache of convex-pair obstacles with construction and hit counters (\[A\] Table I reports these counts).
//!
//! Key: (moving component index, fixed part index, fixed component index, rotation key). The rotation key is the exact
//! bit pattern of the rotation matrix, so two rotations share an entry only if they are bit-identical (the planner
//! evaluates the same discrete angles repeatedly, e.g. `DMat3::from_rotation_z(k * step)`); the caller is responsible
//! for passing the fixed component already placed in the world.
//!
//! The key names the moving part and the fixed parts by index only, so one cache serves one moving part and one
//! stack (which may grow). [`ObstacleCache::claim`] records fingerprints of both and refuses a caller whose part or
//! stack differs from what the entries were built for (the planner claims before every search, so a cache passed
//! to the placement of another part, or into another stack, is a typed error instead of wrong obstacles).
//!
//! Concurrency: the map sits behind a `Mutex` and the counters are atomics, so one cache can be shared by reference
//! between threads (`ObstacleCache: Send + Sync`); obstacles are returned as `Arc<Obstacle>`. Construction happens
//! outside the lock, so two threads asking for the same missing key at once may both construct it (both constructions
//! are counted; the first stored wins). Where contention matters, give each thread its own cache: it is cheap
//! (an empty `HashMap`) and the counters of several caches add up.

use crate::minkowski::{Obstacle, ObstacleError, obstacle};
use glam::DMat3;
use stackplan_geom::polytope::ConvexPolytope;
use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// Exact bit pattern of a rotation matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RotationKey([u64; 9]);

impl RotationKey {
    /// The key of `rotation`.
    pub fn of(rotation: &DMat3) -> Self {
        let a = rotation.to_cols_array();
        Self(std::array::from_fn(|k| a[k].to_bits()))
    }
}

/// Cache key: moving component, fixed part, fixed component, rotation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ObstacleKey {
    /// Component of the moving part.
    pub moving_piece: usize,
    /// Placed part index.
    pub fixed_part: usize,
    /// Component of the placed part.
    pub fixed_piece: usize,
    /// The moving part's rotation.
    pub rotation: RotationKey,
}

/// Counters of a cache.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct CacheStats {
    /// Obstacles constructed.
    pub constructions: u64,
    /// Lookups answered from the cache.
    pub hits: u64,
    /// Entries stored.
    pub entries: u64,
}

/// The obstacle cache. See the module documentation.
#[derive(Debug, Default)]
pub struct ObstacleCache {
    map: Mutex<HashMap<ObstacleKey, Arc<Obstacle>>>,
    constructions: AtomicU64,
    hits: AtomicU64,
    context: Mutex<Context>,
}

/// What the entries are for ([`ObstacleCache::claim`]): the moving part's fingerprint and each fixed part's (`None`:
/// not known, e.g. after [`ObstacleCache::invalidate_part`]).
#[derive(Debug, Default)]
struct Context {
    moving: Option<u64>,
    fixed: Vec<Option<u64>>,
}

impl ObstacleCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// The obstacle of `moving` (rotated by `rotation`) against the placed `fixed`, built on a miss.
    pub fn get_or_build(
        &self,
        moving_piece: usize,
        fixed_part: usize,
        fixed_piece: usize,
        moving: &ConvexPolytope,
        rotation: DMat3,
        fixed: &ConvexPolytope,
    ) -> Result<Arc<Obstacle>, ObstacleError> {
        let key = ObstacleKey { moving_piece, fixed_part, fixed_piece, rotation: RotationKey::of(&rotation) };
        if let Some(o) = self.lock().get(&key) {
            self.hits.fetch_add(1, Ordering::Relaxed);
            return Ok(Arc::clone(o));
        }
        let built = Arc::new(obstacle(moving, rotation, fixed)?);
        self.constructions.fetch_add(1, Ordering::Relaxed);
        Ok(Arc::clone(self.lock().entry(key).or_insert(built)))
    }

    /// Records that the caller uses the cache for the moving part with fingerprint `moving` against the fixed parts
    /// with fingerprints `fixed` (`fixed[i]` for the keys' `fixed_part = i`). The fingerprints are the caller's (the
    /// planner hashes the part's vertex bits, and each stack part's vertex bits and pose bits). Returns `false`, and
    /// changes nothing, when the entries may belong to another part or stack: the moving part differs from the one
    /// recorded, or a fixed part recorded at the same index differs. Otherwise the recorded context takes the claim's
    /// (a longer stack extends it; a shorter one, a prefix of the same stack, keeps the rest) and `true` is returned.
    pub fn claim(&self, moving: u64, fixed: &[u64]) -> bool {
        let mut context = self.context.lock().unwrap_or_else(|e| e.into_inner());
        let same_moving = context.moving.is_none_or(|m| m == moving);
        let same_fixed = context.fixed.iter().zip(fixed).all(|(known, &f)| known.is_none_or(|k| k == f));
        if !(same_moving && same_fixed) {
            return false;
        }
        context.moving = Some(moving);
        for (i, &f) in fixed.iter().enumerate() {
            match context.fixed.get_mut(i) {
                Some(known) => *known = Some(f),
                None => context.fixed.push(Some(f)),
            }
        }
        true
    }

    /// The counters.
    pub fn stats(&self) -> CacheStats {
        CacheStats {
            constructions: self.constructions.load(Ordering::Relaxed),
            hits: self.hits.load(Ordering::Relaxed),
            entries: self.lock().len() as u64,
        }
    }

    /// Drops every entry whose fixed part is `fixed_part` (after it moved), and forgets that part's fingerprint (the
    /// next [`Self::claim`] records it); counters are kept.
    pub fn invalidate_part(&self, fixed_part: usize) {
        self.lock().retain(|k, _| k.fixed_part != fixed_part);
        if let Some(known) = self.context.lock().unwrap_or_else(|e| e.into_inner()).fixed.get_mut(fixed_part) {
            *known = None;
        }
    }

    /// Drops every entry and the recorded context ([`Self::claim`]); counters are kept.
    pub fn clear(&self) {
        self.lock().clear();
        *self.context.lock().unwrap_or_else(|e| e.into_inner()) = Context::default();
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<ObstacleKey, Arc<Obstacle>>> {
        // a poisoned lock only means another thread panicked while inserting; the map is still consistent
        self.map.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use stackplan_geom::convex_hull;

    #[test]
    fn claims_accept_a_growing_stack_and_refuse_another_part_or_stack() {
        let cache = ObstacleCache::new();
        assert!(cache.claim(7, &[]));
        assert!(cache.claim(7, &[1, 2]));
        // a longer stack with the same first parts, then a prefix of it
        assert!(cache.claim(7, &[1, 2, 3]));
        assert!(cache.claim(7, &[1]));
        // another moving part, or another part at a recorded index: refused, nothing recorded
        assert!(!cache.claim(8, &[1, 2, 3]));
        assert!(!cache.claim(7, &[1, 9]));
        assert!(cache.claim(7, &[1, 2, 3, 4]));
        // a part that moved: its entries dropped and its fingerprint forgotten
        cache.invalidate_part(1);
        assert!(cache.claim(7, &[1, 9, 3]));
        assert!(!cache.claim(7, &[1, 2, 3]));
        cache.clear();
        assert!(cache.claim(8, &[5]));
    }

    #[test]
    fn counts_hits_and_constructions_across_threads() {
        let pts: Vec<DVec3> =
            (0..8).map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64)).collect();
        let cube = convex_hull(&pts).expect("cube").polytope;
        let cache = ObstacleCache::new();
        let r = DMat3::from_rotation_z(0.25);
        let a = cache.get_or_build(0, 0, 0, &cube, r, &cube).expect("built");
        let b = cache.get_or_build(0, 0, 0, &cube, r, &cube).expect("hit");
        assert!(Arc::ptr_eq(&a, &b));
        std::thread::scope(|s| {
            for t in 0..2 {
                let (cache, cube) = (&cache, &cube);
                s.spawn(move || {
                    cache.get_or_build(1, t, 0, cube, DMat3::IDENTITY, cube).expect("built");
                });
            }
        });
        let st = cache.stats();
        assert_eq!(st, CacheStats { constructions: 3, hits: 1, entries: 3 });
        cache.invalidate_part(1);
        assert_eq!(cache.stats().entries, 2);
    }
}
