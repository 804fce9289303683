//! The assembly contact state graph (ACSG), generated bottom-up with search-range refinement (\[P\] IV-B, steps 1-7,
//! Propositions 1-2).
//!
//! 1. PPCs (f-v, v-f, e-e) between the surfaces ([`all_ppcs`]); a PPC whose elements cannot meet for any
//!    configuration in the box (bounding boxes apart after the largest translation and rotation) is dropped unseen.
//! 2. Each PPC is a level-1 hypothesis. Hypotheses are processed level by level (all of one level in parallel);
//!    every feasible state is combined with every feasible PPC it does not contain (step 2), the combination is mapped
//!    to its highest-level description (step 3, [`ContactState::canonical`]) and queued if new and of higher level.
//! 3. Search range (step 4): the hull of the extremal ranges of the known feasible CLCN states (Proposition 1), and
//!    the intersection of the ranges of the state's single PCs evaluated as states (Proposition 2); a PC known
//!    infeasible, or an empty intersection, makes the hypothesis infeasible without a search. The refined box is
//!    widened by `widen` of the initial widths (the extremals are found numerically) and clipped to the initial box.
//! 4. Feasibility (step 5): the neighbours' witnesses and extremals projected onto the state's manifold and checked
//!    strictly ([`crate::manifold`]); for a single e-e PC the analytic crossings ([`crate::analytic_seeds`]); else
//!    eq. 8 minimised in the refined box with the GA and polish ([`crate::ga`]), and a minimum of at most
//!    `threshold_relative * L` searched for a strict witness nearby. Feasible iff a strict witness is found.
//! 5. Extremals (step 6) of feasible states ([`crate::extremal`]); step 7 repeats until no new hypothesis appears.
//!
//! Finally the CLCN/CMCN relations are computed among the feasible states. Every hypothesis gets its own seed
//! (the user's seed mixed with a stable hash of its PCs), so the graph is identical at any thread count.
//! Cost: one GA run per hypothesis surviving the pruning plus 12 per feasible state; hypotheses per level are at most
//! (feasible states of lower levels) x (feasible PPCs).

use crate::analytic_seeds::edge_edge_candidates;
use crate::criteria::{ContactPart, Objective, Weights, face_point_distance_2d};
use crate::discovery::{contact_samples, state_with_witness};
use crate::extremal::{Extremal, extremals, range_of};
use crate::features::{Features, readable_label};
use crate::ga::{GaSettings, SettingsError, check_count, minimise_with_polish, mix_seed};
use crate::manifold::{Manifolds, Rejection, StrictTolerances, segment_segment_distance};
use crate::pose::{Config, ConfigBox, VARIABLE_NAMES};
use crate::principal_contact::{ContactState, PcType, PrincipalContact, all_ppcs};
use crate::surface::{Element, ElementKind, SurfaceElements};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use stackplan_geom::DVec3;
use std::collections::{BTreeMap, HashMap, HashSet};

/// Settings of the generation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AcsgSettings {
    /// GA settings of the feasibility searches (extremal searches use half the population and generations).
    pub ga: GaSettings,
    /// Candidate threshold relative to the characteristic length `L`: a GA minimum `min f <= threshold_relative * L`
    /// makes the hypothesis a candidate, which is feasible only if the strict check passes near it.
    pub threshold_relative: f64,
    /// Tolerances of the strict check ([`crate::manifold`]).
    pub strict: StrictTolerances,
    /// Random perturbations tried per start when looking for a strict witness.
    pub witness_attempts: usize,
    /// Projections per extremal search.
    pub extremal_budget: usize,
    /// Widening of refined search boxes, as a fraction of the initial box widths.
    pub widen: f64,
    /// Highest level hypothesised.
    pub max_level: usize,
    /// Grid values per angle of the analytic edge-edge candidates ([`crate::analytic_seeds`]; 0 disables them).
    #[serde(default = "default_analytic_steps")]
    pub analytic_steps: usize,
    /// Seeded configurations pushed into contact before the search ([`crate::discovery::contact_samples`]); the
    /// state holding at each is verified there and joins the graph (0 disables them).
    #[serde(default = "default_samples")]
    pub samples: usize,
    /// Highest level whose hypotheses get a GA search when no neighbour's configuration verifies them; above it a
    /// hypothesis is checked from its neighbours' and parents' configurations only, and its states come from the
    /// configurations met ([`crate::discovery`]).
    #[serde(default = "default_ga_max_level")]
    pub ga_max_level: usize,
}

fn default_ga_max_level() -> usize {
    2
}

fn default_samples() -> usize {
    2000
}

fn default_analytic_steps() -> usize {
    5
}

impl Default for AcsgSettings {
    fn default() -> Self {
        Self {
            ga: GaSettings::default(),
            threshold_relative: 1e-4,
            strict: StrictTolerances::default(),
            witness_attempts: 8,
            extremal_budget: 200,
            widen: 0.05,
            max_level: 12,
            analytic_steps: default_analytic_steps(),
            samples: default_samples(),
            ga_max_level: default_ga_max_level(),
        }
    }
}

/// The most analytic grid values per angle ([`AcsgSettings::analytic_steps`]): the candidates of an edge pair grow
/// with its cube.
pub const MAX_ANALYTIC_STEPS: usize = 64;

/// The most objective evaluations the GA searches of one graph may need ([`SettingsError::TotalEffort`], checked
/// before each level with every hypothesis counted as a search; about 15 minutes of one core for the block example's
/// objective, 250 times the default run's 4 million).
pub const MAX_GRAPH_EVALUATIONS: usize = 1_000_000_000;

/// The most witness attempts per start ([`AcsgSettings::witness_attempts`]), projections per extremal search
/// ([`AcsgSettings::extremal_budget`]) and contact samples ([`AcsgSettings::samples`]).
pub const MAX_ATTEMPTS: usize = 1_000_000;

impl AcsgSettings {
    /// Checks the settings before any search: the GA's sizes ([`GaSettings::check`]), the counts up to
    /// [`MAX_ATTEMPTS`] and [`MAX_ANALYTIC_STEPS`], and the threshold, widening and strict tolerances finite and
    /// non-negative.
    pub fn check(&self) -> Result<(), SettingsError> {
        self.ga.check()?;
        check_count("witness_attempts", self.witness_attempts, 0, MAX_ATTEMPTS)?;
        check_count("extremal_budget", self.extremal_budget, 0, MAX_ATTEMPTS)?;
        check_count("analytic_steps", self.analytic_steps, 0, MAX_ANALYTIC_STEPS)?;
        check_count("samples", self.samples, 0, MAX_ATTEMPTS)?;
        for (name, value) in [
            ("threshold_relative", self.threshold_relative),
            ("widen", self.widen),
            ("strict.hold", self.strict.hold),
            ("strict.clear", self.strict.clear),
        ] {
            if !(value >= 0.0 && value.is_finite()) {
                return Err(SettingsError::Negative { name, value });
            }
        }
        Ok(())
    }
}

/// One evaluated hypothesis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StateRecord {
    /// Index in [`Acsg::states`].
    pub id: usize,
    /// The PCs.
    pub state: ContactState,
    /// Label such as `{f2-v3}` (A's element first).
    pub label: String,
    /// The label with the elements' names where the parts' faces have names ([`crate::features::readable_label`];
    /// the label otherwise).
    #[serde(default)]
    pub name: String,
    /// Level (number of point contacts).
    pub level: usize,
    /// Whether a configuration in the box verifies the state strictly (its PCs and no others in contact, no
    /// penetration; [`crate::manifold::Manifolds::verify`]).
    pub feasible: bool,
    /// Eq. 8 at the witness when feasible, else the GA minimum (`None` when pruned, or when a neighbour's
    /// configuration led to a witness without a GA run).
    pub objective: Option<f64>,
    /// Why a candidate (GA minimum below the threshold, or a projected neighbour configuration) failed the strict
    /// check.
    pub rejection: Option<Rejection>,
    /// Whether a GA search ran (otherwise the hypothesis was pruned or verified from a neighbour's configuration).
    pub searched_by_ga: bool,
    /// Whether the witness is an analytic edge-edge crossing ([`crate::analytic_seeds`]), checked before any GA run.
    #[serde(default)]
    pub analytic_witness: bool,
    /// Whether the state was found at a configuration (a contact sample, or a configuration met while searching
    /// another state) rather than as a hypothesis; the witness is that configuration or its projection.
    #[serde(default)]
    pub discovered: bool,
    /// Why the hypothesis was rejected without a search, if it was.
    pub pruned: Option<String>,
    /// The configuration attaining `objective`.
    pub witness: Option<Config>,
    /// The refined search box (step 4).
    pub search_box: Option<ConfigBox>,
    /// Extremal configurations (feasible states only): for each variable its minimum then maximum.
    pub extremals: Vec<Extremal>,
    /// The range spanned by the extremals.
    pub range: Option<ConfigBox>,
}

/// A CLCN/CMCN relation: `less` is a close less constrained neighbour of `more`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Relation {
    /// Less constrained state id.
    pub less: usize,
    /// More constrained state id.
    pub more: usize,
}

/// Counters of the generation.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct AcsgStats {
    /// PPC candidates.
    pub ppc_candidates: usize,
    /// PPCs dropped because their elements cannot meet within the box.
    pub ppc_unreachable: usize,
    /// Hypotheses evaluated by a search.
    pub searched: usize,
    /// Hypotheses verified from a neighbour's configuration without a GA run.
    pub from_neighbours: usize,
    /// Single e-e hypotheses verified at an analytic crossing without a GA run.
    #[serde(default)]
    pub analytic: usize,
    /// States found at configurations (contact samples, GA minima, extremals, rejected candidates) and verified there
    /// ([`crate::discovery`]).
    #[serde(default)]
    pub discovered: usize,
    /// Hypotheses made by joining two feasible states (one of them a single PC), checked by projecting their
    /// configurations onto the joint manifold without a GA run.
    #[serde(default)]
    pub joined: usize,
    /// Hypotheses with a candidate configuration (a projected neighbour's configuration or a GA minimum below the
    /// threshold) that failed the strict check and were not verified otherwise.
    pub rejected_candidates: usize,
    /// Hypotheses rejected by Propositions 1-2 without a search.
    pub pruned: usize,
    /// Objective evaluations (approximate: GA + polish budgets).
    pub evaluations: usize,
}

/// The graph.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Acsg {
    /// Name of the fixed part A.
    pub fixed: String,
    /// Name of the moving part B.
    pub moving: String,
    /// Initial box (mm, rad).
    pub bounds: ConfigBox,
    /// Settings.
    pub settings: AcsgSettings,
    /// Characteristic length `L` (mm).
    pub length: f64,
    /// Candidate threshold of the GA (mm).
    pub threshold: f64,
    /// Strict contact tolerance `hold * L` (mm).
    pub hold: f64,
    /// Every face, edge and vertex of the fixed part A that a PC can name.
    #[serde(default)]
    pub fixed_features: Features,
    /// Every face, edge and vertex of the moving part B that a PC can name.
    #[serde(default)]
    pub moving_features: Features,
    /// Evaluated hypotheses (feasible and infeasible), in evaluation order.
    pub states: Vec<StateRecord>,
    /// CLCN/CMCN relations between feasible states.
    pub relations: Vec<Relation>,
    /// Counters.
    pub stats: AcsgStats,
}

fn stable_hash(state: &ContactState) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |x: u64| {
        for b in x.to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    for pc in &state.pcs {
        for e in [pc.a, pc.b] {
            feed(e.kind as u64);
            feed(e.index as u64);
        }
    }
    h
}

fn element_points(s: &SurfaceElements, e: Element) -> Vec<DVec3> {
    match e.kind {
        ElementKind::Vertex => vec![s.vertices[e.index].position],
        ElementKind::Edge => {
            let (a, b) = s.edge_points(e.index);
            vec![a, b]
        }
        ElementKind::Face => s.faces[e.index].vertices.iter().map(|&v| s.vertices[v].position).collect(),
    }
}

/// Whether the elements of `pc` can meet for some configuration in `bounds`: A's element's bounding box against
/// B's element's bounding box moved by every translation in the box and grown by `|p| theta_max` (a rotation by at
/// most `theta_max` moves `p` by at most `|p| theta_max`). Conservative: never rejects a reachable pair.
pub fn reachable(pc: &PrincipalContact, a: &SurfaceElements, b: &SurfaceElements, bounds: &ConfigBox) -> bool {
    let pa = element_points(a, pc.a);
    let pb = element_points(b, pc.b);
    let theta = bounds.max_rotation_angle().min(2.0);
    let r = pb.iter().map(|p| p.length()).fold(0.0, f64::max) * theta;
    let tol = a.tolerance.max(b.tolerance);
    for k in 0..3 {
        let (alo, ahi) = pa.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| (l.min(p[k]), h.max(p[k])));
        let (blo, bhi) = pb.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| (l.min(p[k]), h.max(p[k])));
        let lo = blo - r + bounds.min[k] - tol;
        let hi = bhi + r + bounds.max[k] + tol;
        if hi < alo || lo > ahi {
            return false;
        }
    }
    true
}

/// Whether face `fa` of A and face `fb` of B can lie flat on each other (opposite normals, the f-f criterion's first
/// term) for some configuration in `bounds`: a rotation by at most `theta` ([`ConfigBox::max_rotation_angle`]) turns
/// B's normal by at most `theta`, so `n_A = -R n_B` needs the angle between `n_A` and `-n_B` to be at most `theta`
/// (`n_A . n_B <= -cos theta`, with `1e-9` for rounding). The hypotheses' mapping merges into f-f only such pairs
/// (the strict check at a configuration only merged PCs that hold there, [`crate::manifold::Manifolds::state_at`]).
pub fn can_face<'s>(
    sa: &'s SurfaceElements,
    sb: &'s SurfaceElements,
    bounds: &ConfigBox,
) -> impl Fn(usize, usize) -> bool + 's {
    let limit = 1e-9 - bounds.max_rotation_angle().cos();
    move |fa, fb| sa.faces[fa].plane.normal.dot(sb.faces[fb].plane.normal) <= limit
}

/// Lower and upper bounds on the distance between points of two elements of one part: the minimum (exact for
/// elements of a valid boundary, which meet only along shared boundary: end points and boundary edges against the
/// other element) and the maximum (over vertex pairs; the elements are convex).
fn element_distance_range(s: &SurfaceElements, x: Element, y: Element) -> (f64, f64) {
    let (px, py) = (element_points(s, x), element_points(s, y));
    let max = px.iter().flat_map(|p| py.iter().map(move |q| (*p - *q).length())).fold(0.0, f64::max);
    let segments = |e: Element| -> Vec<(DVec3, DVec3)> {
        match e.kind {
            ElementKind::Vertex => {
                let p = s.vertices[e.index].position;
                vec![(p, p)]
            }
            ElementKind::Edge => vec![s.edge_points(e.index)],
            ElementKind::Face => s.faces[e.index].edges.iter().map(|&i| s.edge_points(i)).collect(),
        }
    };
    let point_to = |p: DVec3, e: Element| -> f64 {
        match e.kind {
            ElementKind::Face => {
                let f = &s.faces[e.index];
                f.frame.height(p).hypot(face_point_distance_2d(f, f.frame.to_2d(p)))
            }
            _ => segments(e).iter().map(|&(a, b)| segment_segment_distance(p, p, a, b)).fold(f64::INFINITY, f64::min),
        }
    };
    let mut min = f64::INFINITY;
    for (a, b) in segments(x) {
        min = min.min(point_to(a, y)).min(point_to(b, y));
        for (c, d) in segments(y) {
            min = min.min(segment_segment_distance(a, b, c, d));
        }
    }
    for (c, d) in segments(y) {
        min = min.min(point_to(c, x)).min(point_to(d, x));
    }
    (min, max)
}

/// A necessary condition for PCs to hold together: a rigid motion keeps distances, so for two PCs `(a1, b1)`,
/// `(a2, b2)` the distance between their contact points lies both in the distance range of `a1, a2` (in A) and in
/// that of `b1, b2` (in B). Returns the first pair violating it (beyond `slack`).
fn incompatible_pair(
    state: &ContactState,
    sa: &SurfaceElements,
    sb: &SurfaceElements,
    slack: f64,
) -> Option<(PrincipalContact, PrincipalContact)> {
    for (i, p) in state.pcs.iter().enumerate() {
        for q in &state.pcs[i + 1..] {
            let (a_lo, a_hi) = element_distance_range(sa, p.a, q.a);
            let (b_lo, b_hi) = element_distance_range(sb, p.b, q.b);
            if a_lo > b_hi + slack || b_lo > a_hi + slack {
                return Some((*p, *q));
            }
        }
    }
    None
}

struct Context<'a> {
    fixed: &'a ContactPart,
    moving: &'a ContactPart,
    manifolds: Manifolds<'a>,
    bounds: ConfigBox,
    settings: AcsgSettings,
    weights: Weights,
    threshold: f64,
}

impl Context<'_> {
    /// Evaluates a hypothesis; also returns the configurations met on the way that may lie in other states (the GA
    /// minimum, candidates rejected as another state, the extremals), for [`crate::discovery`].
    fn evaluate(
        &self,
        state: &ContactState,
        known: &HashMap<ContactState, StateRecord>,
        feasible_ids: &[&StateRecord],
        parents: &[&StateRecord],
    ) -> (StateRecord, Vec<Config>) {
        let mut found = Vec::new();
        let record = self.evaluate_into(state, known, feasible_ids, parents, &mut found);
        (record, found)
    }

    fn evaluate_into(
        &self,
        state: &ContactState,
        known: &HashMap<ContactState, StateRecord>,
        feasible_ids: &[&StateRecord],
        parents: &[&StateRecord],
        found: &mut Vec<Config>,
    ) -> StateRecord {
        // a joined hypothesis (two feasible states' contacts together) is checked from their configurations only
        let joined = !parents.is_empty();
        let (sa, sb) = (&self.fixed.surface, &self.moving.surface);
        let mut record = StateRecord {
            id: 0,
            state: state.clone(),
            label: state.label(),
            name: String::new(),
            level: state.level(),
            feasible: false,
            objective: None,
            rejection: None,
            searched_by_ga: false,
            analytic_witness: false,
            discovered: false,
            pruned: None,
            witness: None,
            search_box: None,
            extremals: Vec::new(),
            range: None,
        };
        if let Some(pc) = state.pcs.iter().find(|pc| !reachable(pc, sa, sb, &self.bounds)) {
            record.pruned = Some(format!("{} cannot be reached within the bounds", pc.label()));
            return record;
        }
        if let Some((p, q)) = incompatible_pair(state, sa, sb, self.manifolds.clear()) {
            record.pruned =
                Some(format!("{} and {} cannot hold together (distance ranges disjoint)", p.label(), q.label()));
            return record;
        }
        // Proposition 1: hull of the CLCN states' ranges
        let clcn: Vec<&&StateRecord> = feasible_ids.iter().filter(|r| r.state.is_clcn_of(state, sa, sb)).collect();
        let mut search = self.bounds;
        // a joined hypothesis starts from its parents' witnesses and a few of their extremals
        let mut seeds: Vec<Config> = parents.iter().filter_map(|r| r.witness).collect();
        let mut extremal_seeds: Vec<Config> =
            parents.iter().flat_map(|r| r.extremals.iter().filter(|e| e.converged).take(3).map(|e| e.t)).collect();
        if !clcn.is_empty() {
            let mut hull: Option<ConfigBox> = None;
            for r in &clcn {
                if let Some(range) = r.range {
                    hull = Some(hull.map_or(range, |h| h.hull(&range)));
                }
                if let Some(w) = r.witness {
                    seeds.push(w);
                }
                extremal_seeds.extend(r.extremals.iter().filter(|e| e.converged).map(|e| e.t));
            }
            seeds.append(&mut extremal_seeds);
            if let Some(h) = hull {
                search = match search.intersect(&h) {
                    Some(b) => b,
                    None => {
                        record.pruned = Some("empty range by Proposition 1".into());
                        return record;
                    }
                };
            }
        }
        // Proposition 2: intersection of the single PCs' ranges
        if state.pcs.len() > 1 {
            for pc in &state.pcs {
                if let Some(single) = known.get(&ContactState::single(*pc)) {
                    // a PC that holds nowhere in the box (no candidate, or candidates apart) cannot hold in the
                    // state; one that holds only together with other contacts (rejected as another state) can
                    let holds_elsewhere = matches!(
                        single.rejection,
                        Some(Rejection::OtherState { .. } | Rejection::Ambiguous { .. } | Rejection::NotExact { .. })
                    );
                    if !single.feasible && !holds_elsewhere {
                        record.pruned = Some(format!("{} alone is infeasible (Proposition 2)", pc.label()));
                        return record;
                    }
                    if let Some(range) = single.range {
                        search = match search.intersect(&range.widened_within(&self.bounds, self.settings.widen)) {
                            Some(b) => b,
                            None => {
                                record.pruned = Some("empty range by Proposition 2".into());
                                return record;
                            }
                        };
                    }
                }
            }
        }
        let search = search.widened_within(&self.bounds, self.settings.widen);
        record.search_box = Some(search);
        let objective = Objective { fixed: self.fixed, moving: self.moving, state, weights: self.weights };
        let hypothesis_seed = mix_seed(self.settings.ga.seed, stable_hash(state));
        // the neighbours' configurations, projected onto this state's manifold, usually verify it without a GA run
        let mut witness = None;
        if !seeds.is_empty() {
            // the witnesses first, then the extremals; a dozen starts are plenty
            seeds.truncate(if joined { 8 } else { 12 });
            match self.manifolds.interior_witness_with(
                state,
                &seeds,
                &self.bounds,
                hypothesis_seed,
                if joined { 2 } else { self.settings.witness_attempts },
                false,
                found,
            ) {
                Ok(w) => witness = Some(w),
                Err(e) => record.rejection = Some(e),
            }
        }
        // a single e-e contact: crossings built analytically, checked in a fixed order (deterministic; the GA minimum
        // of such a thin state usually lies in a neighbouring f-e / e-f / f-f state)
        if witness.is_none()
            && !joined
            && self.settings.analytic_steps > 0
            && let [pc] = state.pcs.as_slice()
            && pc.kind() == PcType::EdgeEdge
        {
            let steps = self.settings.analytic_steps;
            witness = edge_edge_candidates(sa, pc.a.index, sb, pc.b.index, &self.bounds, steps, steps + 3)
                .into_iter()
                .find(|t| self.manifolds.verify(state, t, &self.bounds).is_ok());
            record.analytic_witness = witness.is_some();
        }
        if witness.is_none() && !joined && state.level() <= self.settings.ga_max_level {
            let f = |t: &Config| objective.value(t);
            let smooth = |t: &Config| objective.smooth_value(t);
            let ga = GaSettings { seed: hypothesis_seed, ..self.settings.ga };
            seeds.truncate(ga.population / 2);
            let m = minimise_with_polish(&f, &smooth, &search, &ga, &seeds);
            record.searched_by_ga = true;
            record.objective = Some(m.value);
            record.witness = Some(m.t);
            found.push(m.t);
            if m.value <= self.threshold {
                match self.manifolds.interior_witness_with(
                    state,
                    &[m.t],
                    &self.bounds,
                    mix_seed(hypothesis_seed, 1),
                    // single PPCs have no neighbours to start from, and every state above grows from them
                    self.settings.witness_attempts * if state.pcs.len() == 1 && state.level() == 1 { 6 } else { 2 },
                    true,
                    found,
                ) {
                    Ok(w) => witness = Some(w),
                    Err(e) => record.rejection = Some(e),
                }
            }
        }
        if let Some(w) = witness {
            record.feasible = true;
            record.rejection = None;
            record.witness = Some(w);
            record.objective = Some(objective.value(&w));
            record.extremals = extremals(&self.manifolds, state, &self.bounds, w, self.settings.extremal_budget);
            record.range = Some(range_of(&record.extremals, &self.bounds));
            found.extend(record.extremals.iter().map(|e| e.t));
        }
        tracing::debug!(state = %record.label, value = ?record.objective, feasible = record.feasible, "hypothesis evaluated");
        record
    }
}

impl Context<'_> {
    /// The states holding at `configs` (drained) that are not yet feasible, verified there
    /// ([`state_with_witness`]), with their extremals, recorded as feasible and `discovered`; the configurations met
    /// by their extremal searches are classified in turn. Returns the new feasible states.
    fn discover(
        &self,
        configs: &mut Vec<Config>,
        known: &mut HashMap<ContactState, StateRecord>,
        order: &mut Vec<ContactState>,
        stats: &mut AcsgStats,
    ) -> Vec<ContactState> {
        let mut out = Vec::new();
        while !configs.is_empty() {
            let classified: Vec<Option<(ContactState, Config)>> = configs
                .par_iter()
                .map(|t| {
                    let s = self.manifolds.state_at(t);
                    if s.pcs.is_empty() || known.get(&s).is_some_and(|r| r.feasible) {
                        return None;
                    }
                    state_with_witness(&self.manifolds, t, &self.bounds)
                })
                .collect();
            configs.clear();
            // the first configuration of each new state, in the order met
            let mut fresh: Vec<(ContactState, Config)> = Vec::new();
            for (s, w) in classified.into_iter().flatten() {
                if !known.get(&s).is_some_and(|r| r.feasible) && !fresh.iter().any(|(f, _)| f == &s) {
                    fresh.push((s, w));
                }
            }
            let records: Vec<StateRecord> = fresh
                .par_iter()
                .map(|(s, w)| {
                    let objective =
                        Objective { fixed: self.fixed, moving: self.moving, state: s, weights: self.weights };
                    let extremals = extremals(&self.manifolds, s, &self.bounds, *w, self.settings.extremal_budget);
                    StateRecord {
                        id: 0,
                        state: s.clone(),
                        label: s.label(),
                        name: String::new(),
                        level: s.level(),
                        feasible: true,
                        objective: Some(objective.value(w)),
                        rejection: None,
                        searched_by_ga: false,
                        analytic_witness: false,
                        discovered: true,
                        pruned: None,
                        witness: Some(*w),
                        search_box: None,
                        range: Some(range_of(&extremals, &self.bounds)),
                        extremals,
                    }
                })
                .collect();
            for r in records {
                tracing::debug!(state = %r.label, "state found at a configuration");
                configs.extend(r.extremals.iter().map(|e| e.t));
                stats.discovered += 1;
                out.push(r.state.clone());
                if !known.contains_key(&r.state) {
                    order.push(r.state.clone());
                }
                known.insert(r.state.clone(), r);
            }
        }
        out
    }
}

/// Generates the ACSG of the moving part B against the fixed part A within `bounds`.
///
/// # Errors
/// Settings that [`AcsgSettings::check`] rejects, before any search; [`SettingsError::TotalEffort`] before a level
/// whose GA searches could take the graph beyond [`MAX_GRAPH_EVALUATIONS`] objective evaluations (level 1, the
/// reachable PPCs, is checked before any search).
pub fn generate(
    fixed: &ContactPart,
    moving: &ContactPart,
    bounds: ConfigBox,
    settings: AcsgSettings,
) -> Result<Acsg, SettingsError> {
    settings.check()?;
    let weights = Weights::for_parts(moving);
    let threshold = settings.threshold_relative * weights.length;
    let (sa, sb) = (&fixed.surface, &moving.surface);
    let mut stats = AcsgStats::default();
    let candidates = all_ppcs(sa, sb);
    stats.ppc_candidates = candidates.len();
    let ppcs: Vec<PrincipalContact> = candidates.into_iter().filter(|pc| reachable(pc, sa, sb, &bounds)).collect();
    let manifolds = Manifolds::new(fixed, moving, ppcs.clone(), settings.strict);
    let hold = manifolds.hold();
    let ctx = Context { fixed, moving, manifolds, bounds, settings, weights, threshold };
    stats.ppc_unreachable = stats.ppc_candidates - ppcs.len();
    tracing::info!(candidates = stats.ppc_candidates, reachable = ppcs.len(), "PPCs");

    let mut known: HashMap<ContactState, StateRecord> = HashMap::new();
    let mut order: Vec<ContactState> = Vec::new();
    let mut queue: BTreeMap<usize, Vec<ContactState>> = BTreeMap::new();
    let mut seen: HashSet<ContactState> = HashSet::new();
    // joined hypotheses (checked from their parents' configurations only) and their two parents
    let mut parents: HashMap<ContactState, [ContactState; 2]> = HashMap::new();
    for pc in &ppcs {
        let s = ContactState::single(*pc);
        if seen.insert(s.clone()) {
            queue.entry(1).or_default().push(s);
        }
    }
    let faces_can_face = can_face(sa, sb, &bounds);
    // level 1's GA work within the graph's limit, before any search (the samples' states have extremal searches)
    let per_search = settings.ga.evaluations_per_search();
    let level_one = queue.get(&1).map_or(0, Vec::len);
    if level_one.saturating_mul(per_search) > MAX_GRAPH_EVALUATIONS {
        return Err(SettingsError::TotalEffort {
            level: 1,
            hypotheses: level_one,
            per_search,
            spent: 0,
            max: MAX_GRAPH_EVALUATIONS,
        });
    }
    // states found at configurations: first the contact samples
    let mut configs = contact_samples(&ctx.manifolds, &bounds, settings.samples, mix_seed(settings.ga.seed, 0x5a));
    // feasible states not yet combined with the others (combinations start once every PPC is evaluated)
    let mut uncombined: Vec<ContactState> = ctx.discover(&mut configs, &mut known, &mut order, &mut stats);
    let mut level_one_done = false;
    loop {
        if let Some((level, batch)) = queue.pop_first() {
            if level > settings.max_level {
                break;
            }
            // the level's GA work, every hypothesis counted as a search, within the graph's limit (before any search)
            let searches = if level <= settings.ga_max_level {
                batch.iter().filter(|s| !parents.contains_key(*s)).count()
            } else {
                0
            };
            if stats.evaluations.saturating_add(searches.saturating_mul(per_search)) > MAX_GRAPH_EVALUATIONS {
                return Err(SettingsError::TotalEffort {
                    level,
                    hypotheses: searches,
                    per_search,
                    spent: stats.evaluations,
                    max: MAX_GRAPH_EVALUATIONS,
                });
            }
            // a state discovered meanwhile is not evaluated again
            let batch: Vec<ContactState> =
                batch.into_iter().filter(|s| known.get(s).is_none_or(|r| !r.feasible)).collect();
            let feasible_so_far: Vec<&StateRecord> =
                order.iter().filter_map(|s| known.get(s)).filter(|r| r.feasible).collect();
            let results: Vec<(StateRecord, Vec<Config>)> = batch
                .par_iter()
                .map(|s| {
                    let from: Vec<&StateRecord> =
                        parents.get(s).map(|p| p.iter().filter_map(|q| known.get(q)).collect()).unwrap_or_default();
                    ctx.evaluate(s, &known, &feasible_so_far, &from)
                })
                .collect();
            let mut new_feasible = 0;
            for (r, mut found) in results {
                if r.pruned.is_some() {
                    stats.pruned += 1;
                } else if parents.contains_key(&r.state) {
                    stats.joined += 1;
                } else if r.analytic_witness {
                    stats.analytic += 1;
                } else if !r.searched_by_ga {
                    stats.from_neighbours += usize::from(r.feasible);
                } else {
                    stats.searched += 1;
                    stats.evaluations += per_search;
                }
                if !r.feasible && r.rejection.is_some() {
                    stats.rejected_candidates += 1;
                }
                configs.append(&mut found);
                if known.get(&r.state).is_some_and(|k| k.feasible) {
                    continue;
                }
                if r.feasible {
                    new_feasible += 1;
                    uncombined.push(r.state.clone());
                }
                if !known.contains_key(&r.state) {
                    order.push(r.state.clone());
                }
                known.insert(r.state.clone(), r);
            }
            tracing::info!(level, hypotheses = batch.len(), feasible = new_feasible, "level evaluated");
            if level == 1 {
                level_one_done = true;
            }
        } else if configs.is_empty() && (uncombined.is_empty() || !level_one_done) {
            break;
        }
        // the configurations met while searching: their states, and the configurations met while those are searched
        uncombined.extend(ctx.discover(&mut configs, &mut known, &mut order, &mut stats));
        if !level_one_done {
            continue;
        }
        // combinations (step 2): each new feasible state with every feasible PPC (the GA route of [P]), and with
        // every feasible single-PC state (joined: contacts that the bounds force together, such as two faces flat)
        let feasible: Vec<&StateRecord> = order.iter().filter_map(|s| known.get(s)).filter(|r| r.feasible).collect();
        let singles: Vec<&StateRecord> = feasible.iter().copied().filter(|r| r.state.pcs.len() == 1).collect();
        let combine = |pcs: Vec<PrincipalContact>| {
            ContactState::canonical_with(pcs, sa, sb, |m| {
                m.kind() != PcType::FaceFace || faces_can_face(m.a.index, m.b.index)
            })
        };
        for s in std::mem::take(&mut uncombined) {
            let Some(rs) = known.get(&s) else { continue };
            for t in &singles {
                let p = t.state.pcs[0];
                if s.pcs.contains(&p) {
                    continue;
                }
                let mut pcs = s.pcs.clone();
                pcs.push(p);
                let c = combine(pcs);
                if c.level() <= s.level().max(t.level) || known.get(&c).is_some_and(|r| r.feasible) {
                    continue;
                }
                if p.is_ppc() {
                    // the GA route; a queued joined hypothesis gets the GA as well
                    if seen.insert(c.clone()) {
                        queue.entry(c.level()).or_default().push(c);
                    } else if !known.contains_key(&c) {
                        parents.remove(&c);
                    }
                    continue;
                }
                // joined: only where the two states' ranges meet (the joint state lies in both closures)
                let meet = match (rs.range, t.range) {
                    (Some(a), Some(b)) => a
                        .widened_within(&bounds, settings.widen)
                        .intersect(&b.widened_within(&bounds, settings.widen))
                        .is_some(),
                    _ => false,
                };
                if meet && seen.insert(c.clone()) {
                    parents.insert(c.clone(), [s.clone(), t.state.clone()]);
                    queue.entry(c.level()).or_default().push(c);
                }
            }
        }
    }
    let mut states: Vec<StateRecord> = order.iter().filter_map(|s| known.remove(s)).collect();
    let fixed_features = Features::new(sa, &fixed.face_names);
    let moving_features = Features::new(sb, &moving.face_names);
    for (i, r) in states.iter_mut().enumerate() {
        r.id = i;
        r.name = readable_label(&r.state, &fixed_features, &moving_features);
    }
    let feasible: Vec<&StateRecord> = states.iter().filter(|r| r.feasible).collect();
    let mut relations = Vec::new();
    for a in &feasible {
        for b in &feasible {
            if a.level < b.level && a.state.is_clcn_of(&b.state, sa, sb) {
                relations.push(Relation { less: a.id, more: b.id });
            }
        }
    }
    Ok(Acsg {
        fixed: fixed.name.clone(),
        moving: moving.name.clone(),
        bounds,
        settings,
        length: weights.length,
        threshold,
        hold,
        fixed_features,
        moving_features,
        states,
        relations,
        stats,
    })
}

impl Acsg {
    /// The feasible states.
    pub fn feasible(&self) -> impl Iterator<Item = &StateRecord> + '_ {
        self.states.iter().filter(|s| s.feasible)
    }

    /// Number of feasible states per level (index = level).
    pub fn counts_per_level(&self) -> Vec<usize> {
        let max = self.feasible().map(|s| s.level).max().unwrap_or(0);
        let mut out = vec![0; max + 1];
        for s in self.feasible() {
            out[s.level] += 1;
        }
        out
    }

    /// The graph in Graphviz DOT: feasible states as nodes ranked by level, CLCN -> CMCN arrows.
    pub fn to_dot(&self) -> String {
        let mut s = String::from("digraph acsg {\n  rankdir=TB;\n  node [shape=box, fontsize=10];\n");
        let mut levels: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for r in self.feasible() {
            levels.entry(r.level).or_default().push(r.id);
            let name = if r.name.is_empty() { &r.label } else { &r.name };
            s.push_str(&format!("  s{} [label=\"{}\\nlevel {}\"];\n", r.id, name.replace('"', "'"), r.level));
        }
        for ids in levels.values() {
            let names: Vec<String> = ids.iter().map(|i| format!("s{i}")).collect();
            s.push_str(&format!("  {{ rank=same; {}; }}\n", names.join("; ")));
        }
        for rel in &self.relations {
            s.push_str(&format!("  s{} -> s{};\n", rel.less, rel.more));
        }
        s.push_str("}\n");
        s
    }

    /// A \[P\] Table I-style table: state, objective, feasibility, lower and upper bounds of its extremal
    /// configurations (`range`: mm and radians, as the header says), one line per state searched.
    pub fn extremal_table(&self) -> String {
        let mut out = format!(
            "{:<32} {:>11} {:<11} {:<60} {:<60}\n",
            "CS", "objective", "feasibility", "lower bounds [x y z (mm) rx ry rz (rad)]", "upper bounds [same units]"
        );
        for r in &self.states {
            if r.pruned.is_some() {
                continue;
            }
            let fmt = |b: &[f64; 6]| b.iter().map(|v| format!("{v:.3e}")).collect::<Vec<_>>().join(" ");
            let (lo, hi) = match &r.range {
                Some(b) => (fmt(&b.min), fmt(&b.max)),
                None => (String::new(), String::new()),
            };
            out.push_str(&format!(
                "{:<32} {:>11.3e} {:<11} {:<60} {:<60}\n",
                r.label,
                r.objective.unwrap_or(f64::NAN),
                if r.feasible { "feasible" } else { "infeasible" },
                lo,
                hi
            ));
        }
        out
    }

    /// Names of the configuration variables, in order.
    pub fn variable_names() -> [&'static str; 6] {
        VARIABLE_NAMES
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criteria::tests::box_part;

    #[test]
    fn settings_beyond_their_ranges_are_errors_before_any_search() {
        let slab = box_part("slab", DVec3::new(-50.0, -50.0, -10.0), DVec3::new(50.0, 50.0, 0.0));
        let cube = box_part("cube", DVec3::splat(-0.5), DVec3::splat(0.5));
        let bounds = ConfigBox::new([-1.0, -1.0, 0.4, -0.1, -0.1, -0.1], [1.0, 1.0, 0.6, 0.1, 0.1, 0.1]).expect("box");
        let base = AcsgSettings::default();
        assert_eq!(base.check(), Ok(()));
        let with_ga = |ga: GaSettings| AcsgSettings { ga, ..base };
        // a population of usize::MAX was a capacity-overflow panic in the GA
        for (settings, name) in [
            (with_ga(GaSettings { population: usize::MAX, ..base.ga }), "population"),
            (with_ga(GaSettings { population: 3, ..base.ga }), "population"),
            (with_ga(GaSettings { generations: usize::MAX, ..base.ga }), "generations"),
            (with_ga(GaSettings { polish_evaluations: usize::MAX, ..base.ga }), "polish_evaluations"),
            // each size within its range, but 1e10 evaluations per search (hours per hypothesis)
            (with_ga(GaSettings { population: 100_000, generations: 100_000, ..base.ga }), "population x (generations"),
            (AcsgSettings { analytic_steps: 65, ..base }, "analytic_steps"),
            (AcsgSettings { witness_attempts: usize::MAX, ..base }, "witness_attempts"),
            (AcsgSettings { extremal_budget: usize::MAX, ..base }, "extremal_budget"),
            (AcsgSettings { threshold_relative: f64::NAN, ..base }, "threshold_relative"),
            (AcsgSettings { widen: -0.1, ..base }, "widen"),
        ] {
            let err = generate(&slab, &cube, bounds, settings).expect_err(name);
            assert!(err.to_string().starts_with(name), "{name}: {err}");
        }
    }

    #[test]
    fn the_whole_graphs_ga_effort_is_bounded_before_any_search() {
        // 1e7 evaluations per search is allowed, but not for the 240 PPCs of two cubes that can touch anywhere
        let a = box_part("a", DVec3::splat(-0.5), DVec3::splat(0.5));
        let b = box_part("b", DVec3::splat(-0.5), DVec3::splat(0.5));
        let bounds = ConfigBox::new([-1.5, -1.5, -1.5, -0.1, -0.1, -0.1], [1.5, 1.5, 1.5, 0.1, 0.1, 0.1]).expect("box");
        let ga = GaSettings { population: 10_000, generations: 999, polish_evaluations: 0, seed: 1 };
        let settings = AcsgSettings { ga, ..AcsgSettings::default() };
        assert_eq!(settings.check(), Ok(()));
        let start = std::time::Instant::now();
        match generate(&a, &b, bounds, settings) {
            Err(SettingsError::TotalEffort { level: 1, hypotheses, per_search: 10_000_000, spent: 0, max }) => {
                assert_eq!(max, MAX_GRAPH_EVALUATIONS);
                assert!(hypotheses * 10_000_000 > max, "{hypotheses}");
            }
            other => panic!("{other:?}"),
        }
        // no search ran (one would take seconds)
        assert!(start.elapsed().as_secs_f64() < 1.0, "{:?}", start.elapsed());
        // the message names the settings to lower
        let err = generate(&a, &b, bounds, settings).expect_err("effort").to_string();
        assert!(err.contains("population, generations or polish_evaluations"), "{err}");
    }

    #[test]
    fn distance_ranges_prune_pcs_that_cannot_hold_together() {
        // a unit cube (diameter sqrt 3) cannot touch the top and the bottom face of a 10 mm slab at once
        let slab = box_part("slab", DVec3::new(-50.0, -50.0, -10.0), DVec3::new(50.0, 50.0, 0.0));
        let cube = box_part("cube", DVec3::splat(-0.5), DVec3::splat(0.5));
        let (sa, sb) = (&slab.surface, &cube.surface);
        let face = |n: DVec3| sa.faces.iter().position(|f| (f.plane.normal - n).length() < 1e-12).expect("face");
        let (top, bottom) = (face(DVec3::Z), face(-DVec3::Z));
        let pc = |f: usize, v: usize| PrincipalContact::new(Element::face(f), Element::vertex(v)).expect("pc");
        let apart = ContactState { pcs: vec![pc(top, 0), pc(bottom, 7)] };
        assert!(incompatible_pair(&apart, sa, sb, 1e-9).is_some());
        // two vertices on the top face: compatible
        let together = ContactState { pcs: vec![pc(top, 0), pc(top, 7)] };
        assert!(incompatible_pair(&together, sa, sb, 1e-9).is_none());
        // exact ranges: top and bottom faces are 10 apart at least, the cube's extreme vertices sqrt 3
        let (lo, hi) = element_distance_range(sa, Element::face(top), Element::face(bottom));
        assert!((lo - 10.0).abs() < 1e-12 && hi > 141.0, "{lo} {hi}");
        let (lo, hi) = element_distance_range(sb, Element::vertex(0), Element::vertex(7));
        assert!(lo == hi && lo > 1.0, "{lo} {hi}");
    }
}
