//! Node expansion, the loop of the module documentation of [`crate::search`]: pop, cut by a known or a detected
//! obstacle, split into lazily solved children, or record a free optimum.

use super::*;
use crate::cell_qp::{QpOptimum, minimise};
use crate::detect::{CandidateQueue, DetectCounts, SweepAxes};
use crate::interval_obstacles::ObstacleRoute;
use crate::obstacles::DerivedObstacle;
use crate::orientation::rotated_components;
use crate::request::PlacementError;
use glam::DVec3;
use stackplan_freespace::outer_box::{box_is_empty, box_misses_halfspace, grown_outer_box_pruned, tighten_box};
use stackplan_freespace::{Cell, Halfspace, Tag};
use std::sync::Arc;
use std::time::Instant;

impl Search<'_, '_> {
    /// [`Search::advance`] for up to `want` placements of this partition, queued as its look-ahead (`state.ahead`),
    /// within a round: at most `max_pops` pops, stopping where the next key would pop after `bound`.
    pub(super) fn step<const D: usize>(
        &mut self,
        state: &mut RunState<D>,
        want: usize,
        max_cost: f64,
        bound: Option<HeapKey>,
        max_pops: u64,
    ) -> Result<(), PlacementError> {
        let (found, _) = self.advance(state, want, max_cost, bound, max_pops)?;
        let keys = std::mem::take(&mut state.found_keys);
        state.ahead.extend(keys.iter().copied().zip(found));
        state.found_keys = keys;
        Ok(())
    }

    /// Continues the search from `state` until `want` more placements are found, the free space is exhausted or
    /// the cheapest open key exceeds `max_cost` (fewer returned; `true` for the last); the loop of the module
    /// documentation. Stopping after the `want`-th (or at the limit) and calling again continues exactly where one
    /// call with the sum of the `want`s would have been: the state is the whole loop's. A partition's round
    /// ("Partitions" in the module documentation) also stops after `max_pops` pops or where the next key would pop
    /// after `bound` (neither is a limit of the whole search).
    pub(super) fn advance<const D: usize>(
        &mut self,
        state: &mut RunState<D>,
        want: usize,
        max_cost: f64,
        bound: Option<HeapKey>,
        max_pops: u64,
    ) -> Result<(Vec<Placement>, bool), PlacementError> {
        state.found_keys.clear();
        let mut placements: Vec<Placement> = Vec::new();
        if want == 0 {
            return Ok((placements, false));
        }
        let mut limited = false;
        let mut round_pops: u64 = 0;
        loop {
            let heap = &state.heap;
            // the keys are lower bounds of every cost still to come: past the limit, nothing within it is left
            if heap.peek_cost().is_some_and(|cost| cost > max_cost) {
                limited = true;
                break;
            }
            if round_pops >= max_pops || bound.is_some_and(|b| heap.peek_key().is_some_and(|top| pops_after(top, b))) {
                break;
            }
            round_pops += 1;
            let Some(popped) = state.heap.pop() else { break };
            state.pops += 1;
            if state.pops > self.request.tuning.node_budget as u64 {
                let found = state.found_points.len();
                return Err(PlacementError::NodeBudget { budget: self.request.tuning.node_budget, found });
            }
            if state.pops.is_multiple_of(1024) && self.request.deadline.is_some_and(|d| Instant::now() >= d) {
                return Err(PlacementError::TimeLimit { found: state.found_points.len() });
            }
            let node = match popped {
                Popped::Pending { family, id, face } => {
                    self.solve_pending(state, family, id, face)?;
                    continue;
                }
                Popped::Solved(node) => node,
            };
            self.stats.nodes_expanded += 1;
            if !state.considered[node.orientation] {
                state.considered[node.orientation] = true;
                self.first_expansion(node.orientation)?;
            }
            let p = lift(&node.optimum.point, state.fixed_z);
            match self.cutting_obstacle(&node, p)? {
                Some(id) => self.push_children(state, node, id)?,
                None => {
                    if let Some(placement) = self.record_free(state, node, p) {
                        placements.push(placement);
                        if placements.len() >= want {
                            break;
                        }
                    }
                }
            }
        }
        self.stats.orientations_considered = state.considered.iter().filter(|c| **c).count();
        Ok((placements, limited))
    }

    /// A popped pending child: its cell is built and its QP solved now, and a non-empty child is pushed back with
    /// its true cost (not below its key). The children that the box around the parent cell decides empty were never
    /// pushed ([`Search::push_children`]).
    fn solve_pending<const D: usize>(
        &mut self,
        state: &mut RunState<D>,
        family: u32,
        id: u64,
        face: u32,
    ) -> Result<(), PlacementError> {
        let t_cells = Instant::now();
        let RunState { fixed_z, heap, buffers, .. } = state;
        let f = &heap.families[family as usize];
        let orientation = f.orientation;
        let Some(parent) = f.cell.as_ref() else {
            return Err(PlacementError::FreeSpace {
                orientation,
                reason: "a pending child's family has no cell (inconsistent heap)".into(),
            });
        };
        self.child_inequalities::<D>(f.obstacle, face, *fixed_z, f.cuts, &mut buffers.extra);
        let solved = self.solve_child::<D>(orientation, parent, &buffers.extra, &f.start, *fixed_z)?;
        // the path is shared by the family's children: one more reference for a non-empty one
        let applied = solved.as_ref().map(|_| Arc::clone(&f.applied));
        if f.left == 0 {
            // the last child: the family's cell is not needed any more
            heap.families[family as usize].cell = None;
        }
        if let (Some((cell, optimum)), Some(applied)) = (solved, applied) {
            heap.push(Node { cost: optimum.value, orientation, id, cell: Arc::new(cell), optimum, applied });
        }
        self.stats.time_cells_ms += ms(t_cells);
        Ok(())
    }

    /// The first expansion of an orientation in this search: its rotated components (and insertion sweep axes), the
    /// obstacles earlier searches of the plan built at it (their stack parts have not moved: known at once, in a
    /// fixed order), and the region searched elsewhere as an obstacle.
    fn first_expansion(&mut self, orientation: usize) -> Result<(), PlacementError> {
        let t_setup = Instant::now();
        let o = &mut self.orientations[orientation];
        let key = o.rotation.to_cols_array().map(f64::to_bits);
        let part = self.request.part;
        let rotated = self
            .rotated
            .entry(key)
            .or_insert_with(|| RotatedComponents { components: rotated_components(part, o.rotation), sweep: None });
        o.set_components(Arc::clone(&rotated.components));
        if self.request.insertion {
            let sweep = rotated.sweep.get_or_insert_with(|| Arc::new(SweepAxes::new(part, o.rotation, o)));
            self.sweeps[orientation] = Some(Arc::clone(sweep));
        }
        let mut shared = std::mem::take(&mut self.shared_pairs[orientation]);
        shared.sort_unstable();
        for (moving, fixed) in shared {
            self.obstacle_id(orientation, moving, fixed)?;
        }
        if let Some(polygon) = &self.request.tuning.searched_elsewhere {
            let region = DerivedObstacle::searched_elsewhere(&self.orientations[orientation], polygon);
            self.elsewhere[orientation] = Some(self.obstacles.len() as u32);
            self.obstacles.push(Arc::new(region));
        }
        self.stats.time_setup_ms += ms(t_setup);
        Ok(())
    }

    /// The obstacle that cuts a popped node at its optimum `p` (`None`: `p` is free). The region searched elsewhere
    /// first; then an obstacle of this orientation built earlier that holds `p` in its interior (the deepest
    /// holding one, as the detection's order prefers the deepest violation); only when none does, the exact
    /// interference detection, whose candidates (deepest first) are tried until one's obstacle holds `p` in its
    /// interior. Obstacles applied on the node's path are skipped.
    fn cutting_obstacle<const D: usize>(&mut self, node: &Node<D>, p: DVec3) -> Result<Option<u32>, PlacementError> {
        let tol = self.tol.linear;
        let elsewhere = self.elsewhere[node.orientation]
            .filter(|&id| !node.applied.contains(&id) && self.obstacles[id as usize].interior_contains(p, tol));
        let known = elsewhere.or_else(|| {
            let mut best: Option<(f64, u32)> = None;
            let known = &self.by_orientation[node.orientation];
            for (k, &id) in known.ids.iter().enumerate() {
                // the interior test exits at the first plane p* is outside of: cheaper than the path lookup
                if let Some(depth) = known.interior_depth(k, p, tol)
                    && best.is_none_or(|(d, _)| depth > d)
                    && !node.applied.contains(&id)
                {
                    best = Some((depth, id));
                }
            }
            best.map(|(_, id)| id)
        });
        if known.is_some() {
            self.stats.known_obstacle_cuts += 1;
            return Ok(known);
        }
        let t_det = Instant::now();
        let mut counts = DetectCounts::default();
        let mut queue = CandidateQueue::new(
            &self.scene,
            &self.orientations[node.orientation],
            self.sweeps[node.orientation].as_deref(),
            p,
            self.request.clearance,
            self.request.horizontal_clearance,
            tol,
            &mut self.detect_scratch,
            &mut counts,
        );
        self.stats.interference_tests += 1;
        self.stats.narrow_phase_tests += counts.narrow_phase;
        self.stats.time_interference_ms += ms(t_det);
        // the queue finishes the pairs' separating-axis scans only as far as this needs
        let mut cutting = None;
        loop {
            let t_det = Instant::now();
            let next =
                queue.next(&self.scene, &self.orientations[node.orientation], self.sweeps[node.orientation].as_deref());
            self.stats.time_interference_ms += ms(t_det);
            let Some(c) = next else { break };
            let id = self.obstacle_id(node.orientation, c.moving, c.fixed)?;
            if node.applied.contains(&id) {
                continue;
            }
            if self.obstacles[id as usize].interior_contains(p, tol) {
                cutting = Some(id);
                break;
            }
        }
        queue.recycle(&mut self.detect_scratch);
        Ok(cutting)
    }

    /// A free optimum: kept as a free node (the carried frontier), and a placement unless it repeats one already
    /// found at the same orientation (cells share boundaries).
    fn record_free<const D: usize>(&self, state: &mut RunState<D>, node: Node<D>, p: DVec3) -> Option<Placement> {
        let tol = self.tol.linear;
        let dup = state
            .found_points
            .iter()
            .any(|(oi, q)| *oi == node.orientation && (*q - p).abs().max_element() <= 1e3 * tol);
        let found = (!dup).then(|| self.placement(&node.cell, &node.optimum, node.orientation, p));
        let orientation = node.orientation;
        let key = HeapKey::new(node.cost, orientation, node.id, 0);
        state.free_nodes.push(node);
        if found.is_some() {
            state.found_keys.push(key);
            state.found_points.push((orientation, p));
        }
        found
    }

    /// Splits a node by obstacle `id` into its children (\[A\] VI-A-3) and pushes them as one family of pending
    /// children keyed by lower bounds of their costs; the children that the box around the cell proves empty are
    /// never pushed (their ids are still taken, so the others' ids and the search's order are unchanged).
    fn push_children<const D: usize>(
        &mut self,
        state: &mut RunState<D>,
        node: Node<D>,
        id: u32,
    ) -> Result<(), PlacementError> {
        let t_cells = Instant::now();
        let RunState { fixed_z, heap, next_id, buffers, .. } = state;
        let fixed_z = *fixed_z;
        let tol = self.tol.linear;
        let optimum = &node.optimum;
        self.split::<D>(node.orientation, id, fixed_z, &mut buffers.outside)?;
        // one allocation (an exact-size iterator collected into the shared slice)
        let applied: Arc<[u32]> = node.applied.iter().copied().chain(std::iter::once(id)).collect();
        let q = restrict_quadratic::<D>(&self.orientations[node.orientation].quadratic, fixed_z);
        // the box around the cell grown by the tolerance decides most empty children here, while the cell is at
        // hand: a child whose outside half-space misses the box is empty even with every offset grown by the
        // tolerance, as its phase 1 would find (`box_misses_halfspace`), and is never pushed (only when every
        // plane is finite: the phase 1 rejects the others with an error)
        let finite = buffers.outside.iter().all(|((n, d), _)| d.is_finite() && n.iter().all(|c| c.is_finite()));
        // (the children are built from the cell without the inequalities that box proves redundant)
        let (reach, pruned) = grown_outer_box_pruned(&node.cell);
        let masked = self.obstacles[id as usize].planes.len() <= 128;
        let family_cuts =
            |kept: u128| if masked { InsideCuts::Kept(kept) } else { InsideCuts::Reach(finite.then_some(reach)) };
        let mut kept_faces = 0u128;
        let children = &mut buffers.children;
        children.clear();
        // the parent's box tightened by the inside cuts kept so far (in face order)
        let mut inside_box = reach;
        for &(outside, face) in &buffers.outside {
            if finite && box_misses_halfspace(&reach, &outside.0, outside.1, tol) {
                // the id is still taken: the other children's ids, hence the search's order, are unchanged
                self.stats.cells_empty += 1;
                *next_id += 1;
                continue;
            }
            // the box of the child: the parent's tightened by the inside cuts kept before this face and by its
            // outside half-space, each grown by the tolerance, so that it holds the child grown by the
            // tolerance (the set on which its phase 1 decides emptiness)
            let child_box = finite.then(|| {
                let mut b = inside_box;
                tighten_box(&mut b, &outside.0.map(|c| -c), tol - outside.1);
                b
            });
            // this face's inside cut is kept by the later children (`InsideCuts`)
            if masked {
                kept_faces |= 1 << face;
            }
            if finite {
                tighten_box(&mut inside_box, &outside.0, outside.1 + tol);
            }
            if child_box.is_some_and(|b| box_is_empty(&b, tol)) {
                // empty (the box propagation is a relaxation of the phase 1): never pushed, its id still taken
                debug_assert!(
                    self.child_is_empty(&node, (id, face), fixed_z, family_cuts(kept_faces), reach),
                    "a child the box proves empty is not empty"
                );
                self.stats.cells_empty += 1;
                *next_id += 1;
                continue;
            }
            self.stats.nodes_pushed += 1;
            // key: a lower bound of the child's cost, the largest of the parent's cost, the cost's minimum over
            // the child's half-space outside the obstacle face (slack: twice the cell tolerance), the bound
            // from the parent's optimality conditions, which grows with the face's distance from p*
            // (`Quadratic::lower_bound_beyond`: the child lies in the parent's cell), and the cost's minimum over
            // the child's box (`Quadratic::box_lower_bound`)
            let bound = q
                .halfspace_lower_bound(&outside.0, outside.1, 2.0 * tol)
                .max(q.lower_bound_beyond(optimum, &outside.0, outside.1, 2.0 * tol, tol))
                .max(child_box.map_or(f64::NEG_INFINITY, |b| q.box_lower_bound(&b.0, &b.1)));
            debug_assert!(
                *next_id % 8 != 0
                    || self.child_cost_is_at_least(&node, (id, face), fixed_z, family_cuts(kept_faces), bound),
                "a child's key is above its cost"
            );
            children.push((node.cost.max(bound), *next_id, face));
            *next_id += 1;
        }
        let family = Family {
            orientation: node.orientation,
            cell: Some(pruned.map_or_else(|| Arc::clone(&node.cell), Arc::new)),
            applied,
            obstacle: id,
            start: optimum.point,
            cuts: family_cuts(kept_faces),
            first: 0,
            left: 0,
        };
        heap.push_family(family, children);
        self.stats.time_cells_ms += ms(t_cells);
        Ok(())
    }

    /// The id of the derived obstacle of a pair at an orientation, building it on first use: the pair's own, or the
    /// merged one that stands for it (`plates.rs`; the pair may also be a merged obstacle's key from the shared
    /// tables).
    pub(super) fn obstacle_id(
        &mut self,
        orientation: usize,
        moving: usize,
        fixed: usize,
    ) -> Result<u32, PlacementError> {
        if let Some(id) = self.obstacle_ids.get(&(orientation, moving, fixed)) {
            return Ok(*id);
        }
        // a pair whose pieces merge into a plate takes the merged obstacle (`plates.rs`) under the merged key, and
        // the pair's own key becomes an alias of it (the rule depends only on the orientation and the stack, which
        // every search sharing these tables has in common)
        let merged = if self.moving_plate_of.is_empty() {
            None
        } else {
            crate::plates::merged_pair(
                self.request,
                &self.moving_plate_of,
                &self.scene,
                self.orientations[orientation].rotation,
                moving,
                fixed,
                self.tol.linear,
            )
        };
        let key = merged.map_or((moving, fixed), |m| m.key);
        if let Some(&id) = self.obstacle_ids.get(&(orientation, key.0, key.1)) {
            self.obstacle_ids.insert((orientation, moving, fixed), id);
            return Ok(id);
        }
        let t = Instant::now();
        if let Some(shared) = self.derived.get(&(orientation, key.0, key.1)) {
            let id = self.obstacles.len() as u32;
            self.obstacles.push(Arc::clone(shared));
            self.obstacle_ids.insert((orientation, key.0, key.1), id);
            self.obstacle_ids.insert((orientation, moving, fixed), id);
            self.by_orientation[orientation].push(id, shared);
            self.stats.pairs_evaluated += 1;
            self.stats.time_obstacles_ms += ms(t);
            return Ok(id);
        }
        if moving >= crate::plates::VIRTUAL || fixed >= crate::plates::VIRTUAL {
            // a merged obstacle's key names no pair: it is known from the shared tables or not at all
            return Err(PlacementError::FreeSpace {
                orientation,
                reason: format!("no merged obstacle under the key ({moving}, {fixed})"),
            });
        }
        let asked = (moving, fixed);
        let (moving, fixed) = merged.map_or((moving, fixed), |m| (m.moving, m.fixed));
        let o = &self.orientations[orientation];
        let sc = &self.scene.components[fixed];
        let to_error = |reason| PlacementError::Obstacle {
            moving_piece: moving,
            fixed_part: sc.part,
            fixed_piece: sc.piece,
            reason,
        };
        let raw = if let Some(pair) = &merged {
            crate::plates::merged_obstacle(self.request, &self.scene, self.cache, pair, o.rotation)
                .map_err(|e| to_error(format!("the merged plates' obstacle: {e}")))?
        } else if self.request.tuning.extrapolate {
            let rest_rotation = self.request.resting_rotations[o.rest];
            let (raw, route) = self
                .intervals
                .obstacle(self.request.part, moving, o.rest, rest_rotation, o.theta, o.rotation, fixed, sc, self.cache)
                .map_err(to_error)?;
            if route == ObstacleRoute::Extrapolated {
                self.stats.obstacles_extrapolated += 1;
            }
            raw
        } else {
            self.cache
                .get_or_build(moving, sc.part, sc.piece, &self.request.part.components()[moving], o.rotation, &sc.world)
                .map_err(|e| to_error(e.to_string()))?
        };
        let mut built = DerivedObstacle::from_obstacle(
            &raw,
            moving,
            fixed,
            self.request.clearance,
            self.request.horizontal_clearance,
            self.request.insertion,
        );
        built.moving_plate = merged.and_then(|m| m.moving_plate);
        built.fixed_plate = merged.and_then(|m| m.fixed_plate);
        let built = Arc::new(built);
        self.derived.insert((orientation, key.0, key.1), Arc::clone(&built));
        let id = self.obstacles.len() as u32;
        self.by_orientation[orientation].push(id, &built);
        self.obstacles.push(built);
        self.obstacle_ids.insert((orientation, key.0, key.1), id);
        self.obstacle_ids.insert((orientation, asked.0, asked.1), id);

        self.stats.pairs_evaluated += 1;
        self.stats.time_obstacles_ms += ms(t);
        Ok(id)
    }

    /// The children of a cell cut by obstacle `id` (\[A\] VI-A-3): child `k` adds `n_k . p >= d_k` and `n_j . p <= d_j`
    /// for `j < k` ([`Search::child_inequalities`]); here only each child's outside half-space and face index. The
    /// children are built and solved lazily.
    pub(super) fn split<const D: usize>(
        &mut self,
        orientation: usize,
        id: u32,
        fixed_z: f64,
        children: &mut Vec<Outside<D>>,
    ) -> Result<(), PlacementError> {
        let tol = self.tol.linear;
        let obstacle = &self.obstacles[id as usize];
        children.clear();
        for (k, plane) in obstacle.planes.iter().enumerate() {
            match restrict::<D>(plane.normal, plane.offset, fixed_z, tol) {
                Ok(outside) => children.push((outside, k as u32)),
                // a horizontal plane at fixed z: satisfied everywhere (no outside child, no cut needed) or nowhere
                // (the slice of the obstacle is empty: nothing to cut; cannot happen for an obstacle holding p*)
                Err(true) => {}
                Err(false) => {
                    return Err(PlacementError::FreeSpace {
                        orientation,
                        reason: format!(
                            "obstacle {id} holds the optimum but its slice at p_z = {fixed_z} is empty (inconsistent)"
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// The extra inequalities of child `face` of obstacle `id`: the inside cuts `n_j . p <= d_j` of the faces before
    /// it that the family keeps ([`InsideCuts`]; restricted to the `D` variables; planes that do not depend on them
    /// are skipped, as in [`Search::split`]) and the outside `n_face . p >= d_face`, into `extra` (cleared first).
    /// The cuts left out are those the box around the parent cell proves redundant (it lies strictly inside them):
    /// the child is the same set. O(kept faces) with the mask, O(faces) with the box; the same values every time.
    pub(super) fn child_inequalities<const D: usize>(
        &self,
        id: u32,
        face: u32,
        fixed_z: f64,
        cuts: InsideCuts<D>,
        extra: &mut Vec<Halfspace<D>>,
    ) {
        let tol = self.tol.linear;
        let planes = &self.obstacles[id as usize].planes;
        extra.clear();
        let mut inside_cut = |k: usize| {
            if let Ok((normal, offset)) = restrict::<D>(planes[k].normal, planes[k].offset, fixed_z, tol) {
                extra.push(Halfspace::new(
                    normal,
                    offset,
                    Tag::ObstacleCut { obstacle: u64::from(id), face: k as u32 },
                ));
            }
        };
        match cuts {
            InsideCuts::Kept(mask) => {
                // the faces before `face` whose inside cuts are kept, in increasing order
                let mut before = mask & ((1u128 << face) - 1);
                while before != 0 {
                    inside_cut(before.trailing_zeros() as usize);
                    before &= before - 1;
                }
            }
            InsideCuts::Reach(reach) => {
                for (k, plane) in planes.iter().enumerate().take(face as usize) {
                    if let Ok((normal, offset)) = restrict::<D>(plane.normal, plane.offset, fixed_z, tol)
                        && !reach.as_ref().is_some_and(|b| box_misses_halfspace(b, &normal, offset, tol))
                    {
                        inside_cut(k);
                    }
                }
            }
        }
        let plane = &planes[face as usize];
        if let Ok((normal, offset)) = restrict::<D>(plane.normal, plane.offset, fixed_z, tol) {
            let tag = Tag::ObstacleFace { obstacle: u64::from(id), face };
            extra.push(Halfspace::new(normal, offset, tag).flipped(tag));
        }
    }

    /// [`Search::child_inequalities`] into a new list (the debug checks below).
    pub(super) fn child_list<const D: usize>(
        &self,
        id: u32,
        face: u32,
        fixed_z: f64,
        cuts: InsideCuts<D>,
    ) -> Vec<Halfspace<D>> {
        let mut extra = Vec::new();
        self.child_inequalities::<D>(id, face, fixed_z, cuts, &mut extra);
        extra
    }

    /// Debug check of a child that the box propagation drops at a split (`cuts`: the family's): the exact phase 1
    /// finds it empty, and its inside cuts are those that the box test per face keeps.
    pub(super) fn child_is_empty<const D: usize>(
        &self,
        node: &Node<D>,
        (id, face): (u32, u32),
        fixed_z: f64,
        cuts: InsideCuts<D>,
        reach: ([f64; D], [f64; D]),
    ) -> bool {
        let extra = self.child_list(id, face, fixed_z, cuts);
        extra == self.child_list(id, face, fixed_z, InsideCuts::Reach(Some(reach)))
            && node.cell.is_empty_with(extra, &node.optimum.point).unwrap_or(false)
    }

    /// Debug check of a child's key (`cuts`: the family's): the child's cost, when it is not empty, is not below
    /// `bound`, up to the relative rounding that the heap's order ignores.
    pub(super) fn child_cost_is_at_least<const D: usize>(
        &self,
        node: &Node<D>,
        (id, face): (u32, u32),
        fixed_z: f64,
        cuts: InsideCuts<D>,
        bound: f64,
    ) -> bool {
        let extra = self.child_list(id, face, fixed_z, cuts);
        let q = restrict_quadratic::<D>(&self.orientations[node.orientation].quadratic, fixed_z);
        match node.cell.with_halfspaces_from(&extra, &node.optimum.point) {
            Ok(Some(cell)) => match minimise(&cell, &q) {
                Ok(Some(opt)) => opt.value >= bound - 1e-12 * (bound.abs() + opt.value.abs()),
                _ => true,
            },
            _ => true,
        }
    }

    /// Builds a pending child's cell and solves its QP (`None` when empty).
    pub(super) fn solve_child<const D: usize>(
        &mut self,
        orientation: usize,
        parent: &Cell<D>,
        extra: &[Halfspace<D>],
        start: &[f64; D],
        fixed_z: f64,
    ) -> Result<Option<(Cell<D>, QpOptimum<D>)>, PlacementError> {
        // the child from the parent's optimum (it satisfies the parent and the obstacle's inside cuts; only the
        // child's outside face is violated): emptiness by a phase 1 from it (most children are empty), and a
        // non-empty child's interior point by a second phase 1 on the exact cell instead of the Chebyshev LP
        // (`Cell::with_halfspaces_from`; a cell thinner than the tolerance still gets the Chebyshev build). The QP's
        // optimum equals a cold build's up to rounding in the last bits.
        let built = match parent.with_halfspaces_from(extra, start) {
            Ok(built) => built,
            // the cell's LPs (phase 1, Chebyshev centre) failed: skipped and counted as an unsolved QP (below)
            Err(e) => {
                self.stats.cells_unsolved += 1;
                tracing::warn!(orientation, reason = %e, "a free-space cell could not be built: skipped");
                return Ok(None);
            }
        };
        let Some(cell) = built else {
            self.stats.cells_empty += 1;
            return Ok(None);
        };
        if cell.is_empty() {
            self.stats.cells_empty += 1;
            return Ok(None);
        }
        self.stats.qp_solves += 1;
        let q = restrict_quadratic::<D>(&self.orientations[orientation].quadratic, fixed_z);
        match minimise(&cell, &q) {
            Ok(Some(opt)) => Ok(Some((cell, opt))),
            Ok(None) => {
                self.stats.cells_empty += 1;
                Ok(None)
            }
            // no solver could find the cell's optimum: the cell is skipped (no placement is ever taken from it, so
            // nothing returned interferes), and counted, since the search is then no longer exact
            Err(reason) => {
                self.stats.cells_unsolved += 1;
                tracing::warn!(orientation, %reason, "a free-space cell could not be solved: skipped");
                Ok(None)
            }
        }
    }
}
