//! One partition's search state and its roots: the loop's state between calls, the permissible sets `Omega`, the
//! root cells and a carried frontier widened to a larger floor.

use super::*;
use crate::cell_qp::{QpOptimum, Quadratic, minimise};
use crate::detect::{DetectScratch, StackScene, SweepAxes};
use crate::interval_obstacles::IntervalObstacles;
use crate::obstacles::DerivedObstacle;
use crate::orientation::Orientation;
use crate::request::{FloorVolume, PlacementError, PlacementRequest};
use glam::DVec3;
use rayon::prelude::*;
use stackplan_cspace::ObstacleCache;
use stackplan_freespace::{Cell, Halfspace, Tag};
use stackplan_geom::Tolerance;
use std::collections::{HashMap, VecDeque};
use std::sync::Arc;
use std::time::Instant;

/// The state of the search's loop between calls ([`Search::advance`]): the open nodes, the next node id, the
/// orientations expanded so far, the placements found so far (orientation, position) and the pops so far.
#[derive(Clone)]
pub(super) struct RunState<const D: usize> {
    pub(super) fixed_z: f64,
    pub(super) heap: NodeHeap<D>,
    pub(super) next_id: u64,
    pub(super) considered: Vec<bool>,
    pub(super) found_points: Vec<(usize, DVec3)>,
    pub(super) pops: u64,
    /// Solved nodes whose optimum was found free (placements and their duplicates on shared boundaries): with the
    /// heap they cover every position not inside an obstacle applied so far, so a search into the grown stack can
    /// continue from both ([`SearchCaches::carrying_frontiers`]).
    pub(super) free_nodes: Vec<Node<D>>,
    /// Lists reused from node to node (no allocation per node once warm).
    pub(super) buffers: Buffers<D>,
    /// The keys of the nodes of the placements the last [`Search::advance`] returned, in order.
    pub(super) found_keys: Vec<HeapKey>,
    /// A partition's placements found but not yet returned, cheapest first, with their nodes' keys (the merge's
    /// look-ahead, see "Partitions" in the module documentation); their nodes are in `free_nodes`.
    pub(super) ahead: VecDeque<(HeapKey, Placement)>,
}

/// The loop's reusable lists: a child's extra inequalities, a split's outside half-spaces and its children's keys.
#[derive(Clone)]
pub(super) struct Buffers<const D: usize> {
    pub(super) extra: Vec<Halfspace<D>>,
    pub(super) outside: Vec<Outside<D>>,
    pub(super) children: Vec<(f64, u64, u32)>,
}

impl<const D: usize> Default for Buffers<D> {
    fn default() -> Self {
        Self { extra: Vec::new(), outside: Vec::new(), children: Vec::new() }
    }
}

impl<const D: usize> RunState<D> {
    /// The state for a search into the grown stack: the free nodes are open again, nothing is found or considered
    /// yet (the orientations' components are rebuilt when first popped).
    pub(super) fn reopened(mut self) -> Self {
        for node in std::mem::take(&mut self.free_nodes) {
            self.heap.push(node);
        }
        self.considered.fill(false);
        self.found_points.clear();
        self.pops = 0;
        self.found_keys.clear();
        self.ahead.clear();
        self
    }
}

/// The point of `D` variables in the world (`p_z = fixed_z` when `D = 2`).
pub(super) fn lift<const D: usize>(p: &[f64; D], fixed_z: f64) -> DVec3 {
    if D == 3 { DVec3::new(p[0], p[1], p[2]) } else { DVec3::new(p[0], p[1], fixed_z) }
}

/// A world plane restricted to the `D` variables: `Ok(halfspace)`, or `Err(holds)` when it does not depend on them
/// (`holds`: satisfied by every point, within `tol`).
pub(super) fn restrict<const D: usize>(
    normal: DVec3,
    offset: f64,
    fixed_z: f64,
    tol: f64,
) -> Result<([f64; D], f64), bool> {
    if D == 3 {
        return Ok((std::array::from_fn(|i| normal[i]), offset));
    }
    let off = offset - normal.z * fixed_z;
    if normal.x.hypot(normal.y) <= 1e-12 {
        return Err(off >= -tol);
    }
    Ok((std::array::from_fn(|i| normal[i]), off))
}

pub(super) fn restrict_quadratic<const D: usize>(q: &Quadratic<3>, fixed_z: f64) -> Quadratic<D> {
    let mut constant = q.constant;
    if D == 2 {
        constant += q.h[2] * (fixed_z - q.c[2]).powi(2);
    }
    Quadratic { h: std::array::from_fn(|i| q.h[i]), c: std::array::from_fn(|i| q.c[i]), constant }
}

/// A child of a split: the face's outside half-space `normal . p >= offset` and the face's index.
pub(super) type Outside<const D: usize> = (([f64; D], f64), u32);

/// The obstacles known at one orientation, their planes stored contiguously (the known-obstacle test of every popped
/// node scans them all; one flat array instead of a pointer chase per obstacle).
#[derive(Debug, Default)]
pub(super) struct KnownObstacles {
    /// Obstacle ids, in the order they became known.
    pub(super) ids: Vec<u32>,
    /// `planes[starts[k]..starts[k + 1]]` are obstacle `ids[k]`'s planes `(normal, offset)`.
    pub(super) starts: Vec<u32>,
    pub(super) planes: Vec<(DVec3, f64)>,
}

impl KnownObstacles {
    pub(super) fn push(&mut self, id: u32, obstacle: &DerivedObstacle) {
        if self.starts.is_empty() {
            self.starts.push(0);
        }
        self.ids.push(id);
        self.planes.extend(obstacle.planes.iter().map(|pl| (pl.normal, pl.offset)));
        self.starts.push(self.planes.len() as u32);
    }

    /// How deep `p` lies in the interior of obstacle `ids[k]` (the smallest slack `d_k - n_k . p`, its distance to
    /// the boundary), when it lies inside by more than `tol` (`DerivedObstacle::interior_contains`); `None` otherwise.
    #[inline]
    pub(super) fn interior_depth(&self, k: usize, p: DVec3, tol: f64) -> Option<f64> {
        let mut depth = f64::INFINITY;
        for &(normal, offset) in &self.planes[self.starts[k] as usize..self.starts[k + 1] as usize] {
            let slack = offset - tol - normal.dot(p);
            if slack <= 0.0 {
                return None;
            }
            depth = depth.min(slack);
        }
        Some(depth + tol)
    }
}

/// The search state of one partition of the orientations (the whole search when there is one): everything the loop
/// changes, for the orientations `lane_of(i) == lane` (the other orientations' entries stay untouched).
pub(super) struct Search<'r, 'a> {
    pub(super) request: &'r PlacementRequest<'a>,
    /// This partition's index and the number of partitions.
    pub(super) lane: usize,
    pub(super) lanes: usize,
    pub(super) orientations: Vec<Orientation>,
    pub(super) sweeps: Vec<Option<Arc<SweepAxes>>>,
    pub(super) scene: Arc<StackScene>,
    pub(super) tol: Tolerance,
    pub(super) cache: &'r ObstacleCache,
    pub(super) obstacles: Vec<Arc<DerivedObstacle>>,
    pub(super) derived: HashMap<(usize, usize, usize), Arc<DerivedObstacle>>,
    pub(super) obstacle_ids: HashMap<(usize, usize, usize), u32>,
    /// The obstacles built (or taken from the shared caches) for each orientation, in order.
    pub(super) by_orientation: Vec<KnownObstacles>,
    /// Per orientation, the (moving, stack component) pairs whose derived obstacle an earlier search of the plan
    /// built (indexed once per search; taken when the orientation is first expanded).
    pub(super) shared_pairs: Vec<Vec<(usize, usize)>>,
    /// Per orientation, the id of this search's region searched elsewhere
    /// ([`crate::request::SearchTuning::searched_elsewhere`], [`DerivedObstacle::searched_elsewhere`]), added to the obstacle
    /// table when the orientation is first expanded; it cuts before any known obstacle.
    pub(super) elsewhere: Vec<Option<u32>>,
    pub(super) rotated: HashMap<[u64; 9], RotatedComponents>,
    pub(super) detect_scratch: DetectScratch,
    pub(super) intervals: IntervalObstacles,
    /// Per moving component, its plate when the request merges plates (`plates.rs`).
    pub(super) moving_plate_of: Arc<[Option<u32>]>,
    pub(super) stats: PlacementStats,
    /// Rounds of the partitioned loop run (first partition only; for the debug log).
    pub(super) rounds: u64,
}

impl Search<'_, '_> {
    /// Moves the shared caches' contents back into `caches` (this partition's).
    pub(super) fn give_back(&mut self, caches: &mut LaneCaches) {
        caches.detect_scratch = std::mem::take(&mut self.detect_scratch);
        caches.rotated = std::mem::take(&mut self.rotated);
        caches.derived = std::mem::take(&mut self.derived);
        caches.intervals = std::mem::take(&mut self.intervals);
    }

    /// The permissible set `Omega(theta)` of orientation `o` in `floor` as half-spaces in the `D` variables
    /// (`None`: empty at the fixed height).
    pub(super) fn omega<const D: usize>(
        &self,
        o: &Orientation,
        floor: &FloorVolume,
        fixed_z: f64,
    ) -> Option<Vec<Halfspace<D>>> {
        if D == 3 {
            let hs = o.omega_3d(floor);
            Some(
                hs.into_iter().map(|h| Halfspace::new(std::array::from_fn(|i| h.normal[i]), h.offset, h.tag)).collect(),
            )
        } else {
            let hs = o.omega_2d(floor, fixed_z, self.tol.linear)?;
            Some(
                hs.into_iter().map(|h| Halfspace::new(std::array::from_fn(|i| h.normal[i]), h.offset, h.tag)).collect(),
            )
        }
    }

    /// A carried state ([`SearchCaches::carrying_frontiers`]) widened from the floor volume `old` (inside the
    /// request's) to the request's: its cells lie in the old permissible set, so the difference
    /// `Omega_new(theta) \ Omega_old(theta)` of every orientation is added as new roots, split as a subtraction
    /// (\[A\] VI-A-3 with `Omega_old` as the convex set taken away): child `j` is `Omega_new` with `Omega_old`'s
    /// half-space `j` reversed and those before it kept (tagged as cuts, not as floor sides). Sides the two sets
    /// share give no child. O(orientations x sides) cells and QPs, in parallel (one boundedness check in all).
    pub(super) fn widen<const D: usize>(
        &mut self,
        mut state: RunState<D>,
        old: Option<&FloorVolume>,
    ) -> Result<RunState<D>, PlacementError> {
        let Some(old) = old else {
            return Ok(state);
        };
        let t_roots = Instant::now();
        let fixed_z = state.fixed_z;
        let tol = self.tol;
        // every added cell lies in `Omega_new(theta)`, whose normals (the floor's sides, the floor and the ceiling)
        // are the same at every orientation: the first non-empty root's boundedness check answers for all of them,
        // as in `Search::start`, and the cells are built without their own (`2 D` LPs each)
        for o in self.orientations.iter().filter(|o| self.owns(o.index)) {
            if let Some(root) = self.root_cell::<D>(o, fixed_z)? {
                root.check_bounded()
                    .map_err(|e| PlacementError::FreeSpace { orientation: o.index, reason: e.to_string() })?;
                break;
            }
        }
        let added: Vec<Result<Vec<(Cell<D>, QpOptimum<D>)>, PlacementError>> = self
            .orientations
            .par_iter()
            .map(|o| {
                if !self.owns(o.index) {
                    return Ok(Vec::new());
                }
                let fs_err = |reason: String| PlacementError::FreeSpace { orientation: o.index, reason };
                let Some(new_hs) = self.omega::<D>(o, &self.request.floor, fixed_z) else {
                    return Ok(Vec::new());
                };
                let q = restrict_quadratic::<D>(&o.quadratic, fixed_z);
                let solve = |hs: Vec<Halfspace<D>>| -> Result<Option<(Cell<D>, QpOptimum<D>)>, PlacementError> {
                    let cell = Cell::new_unchecked_bounds(hs, tol).map_err(|e| fs_err(e.to_string()))?;
                    if cell.is_empty() {
                        return Ok(None);
                    }
                    Ok(minimise(&cell, &q).map_err(fs_err)?.map(|opt| (cell, opt)))
                };
                let Some(old_hs) = self.omega::<D>(o, old, fixed_z) else {
                    // nothing of this orientation was open before: its whole new set is a root
                    return Ok(solve(new_hs)?.into_iter().collect());
                };
                let mut out = Vec::new();
                for (j, h) in old_hs.iter().enumerate() {
                    if new_hs.iter().any(|g| g.normal == h.normal && g.offset == h.offset) {
                        continue;
                    }
                    let mut hs = new_hs.clone();
                    hs.extend(old_hs[..j].iter().map(|g| Halfspace::new(g.normal, g.offset, Tag::User(2 * j as u64))));
                    hs.push(h.flipped(Tag::User(2 * j as u64 + 1)));
                    out.extend(solve(hs)?);
                }
                Ok(out)
            })
            .collect();
        for (i, cells) in added.into_iter().enumerate() {
            for (cell, optimum) in cells? {
                self.stats.qp_solves += 1;
                self.stats.nodes_pushed += 1;
                state.heap.push(Node {
                    cost: optimum.value,
                    orientation: i,
                    id: state.next_id,
                    cell: Arc::new(cell),
                    optimum,
                    applied: Arc::from([]),
                });
                state.next_id += 1;
            }
        }
        self.stats.time_roots_ms += ms(t_roots);
        Ok(state)
    }

    pub(super) fn root_cell<const D: usize>(
        &self,
        o: &Orientation,
        fixed_z: f64,
    ) -> Result<Option<Cell<D>>, PlacementError> {
        let fs_err = |e: stackplan_freespace::CellError| PlacementError::FreeSpace {
            orientation: o.index,
            reason: e.to_string(),
        };
        let Some(hs) = self.omega::<D>(o, &self.request.floor, fixed_z) else {
            return Ok(None);
        };
        // bounded iff the first non-empty root is (the normals do not depend on the orientation): checked in `run`
        let cell = Cell::new_unchecked_bounds(hs, self.tol).map_err(fs_err)?;
        Ok((!cell.is_empty()).then_some(cell))
    }

    /// Whether orientation `i` belongs to this partition.
    pub(super) fn owns(&self, i: usize) -> bool {
        lane_of(i, self.lanes) == self.lane
    }

    /// The roots of this partition's orientations (one QP per orientation, in parallel) and its state (an empty
    /// heap when Omega is empty at every one of them).
    pub(super) fn start<const D: usize>(&mut self, fixed_z: f64) -> Result<RunState<D>, PlacementError> {
        let t_roots = Instant::now();
        // roots in parallel, collected in orientation order; Omega's normals are those of the floor's sides and
        // (3-D) of the floor and the ceiling at every orientation, only the offsets change, so the first non-empty
        // root's boundedness check (as `Cell::new` makes it) answers for all of them
        let cells: Vec<Result<Option<Cell<D>>, PlacementError>> = self
            .orientations
            .par_iter()
            .map(|o| if self.owns(o.index) { self.root_cell::<D>(o, fixed_z) } else { Ok(None) })
            .collect();
        let mut cells: Vec<Option<Cell<D>>> = cells.into_iter().collect::<Result<_, _>>()?;
        if let Some((i, cell)) = cells.iter().enumerate().find_map(|(i, c)| c.as_ref().map(|c| (i, c))) {
            cell.check_bounded().map_err(|e| PlacementError::FreeSpace { orientation: i, reason: e.to_string() })?;
        }
        let roots: Vec<Result<Option<(Cell<D>, QpOptimum<D>)>, PlacementError>> = self
            .orientations
            .par_iter()
            .zip(cells.par_iter_mut())
            .map(|(o, cell)| {
                let Some(cell) = cell.take() else {
                    return Ok(None);
                };
                let q = restrict_quadratic::<D>(&o.quadratic, fixed_z);
                let opt =
                    minimise(&cell, &q).map_err(|reason| PlacementError::FreeSpace { orientation: o.index, reason })?;
                Ok(opt.map(|opt| (cell, opt)))
            })
            .collect();
        let mut heap: NodeHeap<D> = NodeHeap::default();
        let mut next_id: u64 = 0;
        for (i, r) in roots.into_iter().enumerate() {
            match r? {
                Some((cell, optimum)) => {
                    self.stats.qp_solves += 1;
                    heap.push(Node {
                        cost: optimum.value,
                        orientation: i,
                        id: next_id,
                        cell: Arc::new(cell),
                        optimum,
                        applied: Arc::from([]),
                    });
                }
                None if self.owns(i) => self.stats.orientations_empty_omega += 1,
                None => {}
            }
            next_id += 1;
        }
        self.stats.nodes_pushed = heap.len() as u64;
        self.stats.time_roots_ms = ms(t_roots);
        Ok(RunState {
            fixed_z,
            heap,
            next_id,
            considered: vec![false; self.orientations.len()],
            found_points: Vec::new(),
            pops: 0,
            free_nodes: Vec::new(),
            buffers: Buffers::default(),
            found_keys: Vec::new(),
            ahead: VecDeque::new(),
        })
    }
}
