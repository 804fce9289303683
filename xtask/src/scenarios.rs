//! The regression scenario kinds. Each kind reads its inputs from the scenario JSON and returns named result fields.
//!
//! * `part`: a part file (or built-in example) with a decomposition: component count, volume, centre of gravity,
//!   bounding box, boundary face count.
//! * `place`: one of the placement scenarios of \[A\] Figs. 15-17 (`"scenario"`: `channel`, `triangle`, `complex`;
//!   built by `stackplan::planner::paper_scenarios`): the best placement (theta, cost, position), nesting height, pairs
//!   evaluated over the total, obstacles constructed and extrapolated (\[A\] Table I).
//! * `plan`: a stacking plan (`stackplan::planner::plan_stack`) of `count` parts at weight `w`: parts placed, height,
//!   footprint, total cost, layers (distinct c.g. heights), the largest release drop (a part released above inclined
//!   supports drops onto them), whether every part passed and the whole stack is stable.
//!   Optional assertions, checked in code (a failure is an error, whatever the golden holds): `"expect_shape"`
//!   (`flat`, `column`, `pyramid`: the seed's Fig. 2; adds `layer_counts`, parts per layer bottom up), `"check": true`
//!   (the finished plan passes `stackplan check` with the planner's mu, cup and clearance, the clearance checked at
//!   each part's release position against the parts before it, with the part as the plan file stores it and with the
//!   planner's own; adds `check_ok`) and
//!   `"expect_height_below"` (mm: the stack nests). These add `info_plan_seconds` (planning alone).
//! * `obstacle`: the c-space obstacle of every convex pair of two parts (the fixed one placed by `"fixed_pose"`) at
//!   each angle of `"theta_deg"` (`stackplan::cspace::obstacle`): per angle and pair the vertex and face counts and
//!   the volume, face-kind totals, and the route (Gauss map or hull fallback); every obstacle must pass `validate()`.
//! * `contacts`: the assembly contact state graph of `"moving"` against `"fixed"` (placed by `"fixed_pose"`) within
//!   `"t_min"`/`"t_max"` (mm and degrees) at the default GA settings and `"seed"` (\[P\] V; deterministic at any
//!   thread count): feasible states per level, their labels, and each state's extremal ranges (the \[P\] Table I
//!   rows: lowest and highest x, y, z, rx, ry, rz, mm and radians).
//! * `orient_intervals`: the constant-topology intervals and sweep counts of every convex pair of two parts over a
//!   full turn (`stackplan::orient_interval::regress_summary`).

use crate::regress::Fields;
use anyhow::{Context, bail};
use serde_json::Value;
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_geom::{DVec3, Part, Pose};
use std::path::Path;

/// Runs one scenario (`dir` is the scenario's directory, for relative paths).
pub fn run(scenario: &Value, dir: &Path) -> anyhow::Result<Fields> {
    let kind = scenario.get("kind").and_then(Value::as_str).context("scenario has no \"kind\"")?;
    match kind {
        "part" => part(scenario, dir),
        "place" => place(scenario),
        "plan" => plan(scenario, dir),
        "orient_intervals" => orient_intervals(scenario, dir),
        "obstacle" => obstacle(scenario, dir),
        "contacts" => contacts(scenario, dir),
        other => bail!("unknown scenario kind {other:?}"),
    }
}

fn decomposition(scenario: &Value) -> anyhow::Result<Decomposition> {
    match scenario.get("decomposition").and_then(Value::as_str) {
        None | Some("convex_merge") => Ok(Decomposition::ConvexMerge),
        Some("triangulation") => Ok(Decomposition::Triangulation),
        Some(other) => bail!("unknown decomposition {other:?}"),
    }
}

/// Loads the scenario's `"part"` (a path relative to the scenario file) with its decomposition.
pub fn load_part(scenario: &Value, key: &str, dir: &Path) -> anyhow::Result<Part> {
    let rel = scenario.get(key).and_then(Value::as_str).with_context(|| format!("scenario has no {key:?}"))?;
    let options = stackplan_geom::io::ReadOptions { decomposition: decomposition(scenario)?, ..Default::default() };
    Ok(stackplan_geom::io::read_part(dir.join(rel), &options)?)
}

fn part(scenario: &Value, dir: &Path) -> anyhow::Result<Fields> {
    let p = load_part(scenario, "part", dir)?;
    let (lo, hi) = p.aabb();
    let mut f = Fields::new();
    f.insert("components".into(), p.components().len().into());
    f.insert("volume".into(), p.mass().volume.into());
    f.insert("center_of_gravity".into(), p.mass().center_of_gravity.to_array().to_vec().into());
    f.insert("bounding_box_min".into(), lo.to_array().to_vec().into());
    f.insert("bounding_box_max".into(), hi.to_array().to_vec().into());
    f.insert("boundary_faces".into(), p.boundary().len().into());
    f.insert("vertices".into(), p.vertex_count().into());
    // a part recognised from CAD: what was recognised
    if let stackplan_geom::PartOrigin::RecognisedSheet { thickness, plates, bends, solid_volume, max_deviation } =
        p.origin
    {
        f.insert("thickness".into(), thickness.into());
        f.insert("plates".into(), plates.into());
        f.insert("bends".into(), bends.into());
        f.insert("solid_volume".into(), solid_volume.into());
        f.insert("max_deviation".into(), max_deviation.into());
    }
    Ok(f)
}

fn place(scenario: &Value) -> anyhow::Result<Fields> {
    use stackplan::planner::paper_scenarios as regress;
    let name = scenario.get("scenario").and_then(Value::as_str).context("place scenario has no \"scenario\"")?;
    let sc = regress::scenario(name)?.with_context(|| format!("unknown placement scenario {name:?}"))?;
    let (_, report) = regress::run(&sc)?;
    let mut f = Fields::new();
    f.insert("stack_parts".into(), report.stack_parts.into());
    f.insert("found".into(), report.placement.is_some().into());
    if let Some(p) = &report.placement {
        f.insert("theta_deg".into(), p.theta_deg.into());
        f.insert("cost".into(), p.cost.into());
        f.insert("position".into(), p.position.to_vec().into());
        f.insert("resting_pose".into(), p.resting_pose.into());
        f.insert("contacts".into(), p.contacts.len().into());
    }
    if let Some(h) = report.height_above_previous {
        f.insert("height_above_previous".into(), h.into());
    }
    f.insert("part_height".into(), report.part_height.into());
    f.insert("pairs_evaluated".into(), report.stats.pairs_evaluated.into());
    f.insert("total_pairs".into(), report.stats.total_pairs.into());
    f.insert("obstacles_constructed".into(), report.stats.obstacles_constructed.into());
    f.insert("obstacles_extrapolated".into(), report.stats.obstacles_extrapolated.into());
    if let Some((e, t)) = report.seed_pairs {
        f.insert("info_seed_fraction_evaluated".into(), (e as f64 / t as f64).into());
    }
    f.insert("info_fraction_evaluated".into(), report.fraction_evaluated.into());
    Ok(f)
}

fn orient_intervals(scenario: &Value, dir: &Path) -> anyhow::Result<Fields> {
    let moving = load_part(scenario, "moving", dir)?;
    let fixed = load_part(scenario, "fixed", dir)?;
    let step = scenario.get("step_deg").and_then(Value::as_f64).unwrap_or(1.0);
    let summary = stackplan::orient_interval::regress_summary(&moving, &fixed, fixed_pose(scenario)?, step);
    let mut f = Fields::new();
    if let Some(Value::Object(totals)) = summary.get("totals") {
        for (k, v) in totals {
            f.insert(format!("total_{k}"), v.clone());
        }
    }
    if let Some(Value::Array(pairs)) = summary.get("pairs") {
        let intervals: Vec<Value> = pairs.iter().map(|p| p.get("intervals").cloned().unwrap_or(Value::Null)).collect();
        f.insert("intervals_per_pair".into(), intervals.into());
    }
    Ok(f)
}

/// The `contacts` kind (see the module documentation).
fn contacts(scenario: &Value, dir: &Path) -> anyhow::Result<Fields> {
    use stackplan::contact_states::acsg::{AcsgSettings, generate};
    use stackplan::contact_states::criteria::ContactPart;
    use stackplan::contact_states::ga::GaSettings;
    use stackplan::contact_states::pose::ConfigBox;
    let moving = load_part(scenario, "moving", dir)?;
    let fixed = load_part(scenario, "fixed", dir)?;
    let (rotation, position) = fixed_pose(scenario)?;
    let placed = fixed.components().iter().map(|c| c.transformed(rotation, position)).collect();
    let fixed = Part::from_components(fixed.name.clone(), placed, fixed.density(), fixed.origin.clone())?;
    let bound = |key: &str| -> anyhow::Result<[f64; 6]> {
        let v: [f64; 6] = serde_json::from_value(scenario.get(key).cloned().with_context(|| format!("no {key:?}"))?)?;
        Ok([v[0], v[1], v[2], v[3].to_radians(), v[4].to_radians(), v[5].to_radians()])
    };
    let bounds = ConfigBox::new(bound("t_min")?, bound("t_max")?)?;
    let seed = scenario.get("seed").and_then(Value::as_u64).unwrap_or(2004);
    let settings = AcsgSettings { ga: GaSettings { seed, ..GaSettings::default() }, ..AcsgSettings::default() };
    let started = std::time::Instant::now();
    let graph = generate(&ContactPart::from_part(&fixed)?, &ContactPart::from_part(&moving)?, bounds, settings)?;
    let seconds = started.elapsed().as_secs_f64();
    let per_level = graph.counts_per_level();
    let mut ranges = serde_json::Map::new();
    for state in graph.feasible() {
        let range = state.range.as_ref().map(|r| [r.min, r.max]);
        ranges.insert(state.label.clone(), serde_json::to_value(range)?);
    }
    let mut f = Fields::new();
    f.insert("total_states".into(), per_level.iter().sum::<usize>().into());
    f.insert("states_per_level".into(), per_level.into());
    f.insert("extremal_ranges".into(), Value::Object(ranges));
    f.insert("info_seconds".into(), ((seconds * 1e3).round() / 1e3).into());
    Ok(f)
}

/// The scenario's `"fixed_pose"` (`position`, row-major `rotation`), identity when absent.
fn fixed_pose(scenario: &Value) -> anyhow::Result<(stackplan_geom::DMat3, DVec3)> {
    let pose = scenario.get("fixed_pose");
    let position = pose
        .and_then(|p| p.get("position"))
        .map(|v| serde_json::from_value::<[f64; 3]>(v.clone()))
        .transpose()?
        .unwrap_or([0.0; 3]);
    let rows = pose
        .and_then(|p| p.get("rotation"))
        .map(|v| serde_json::from_value::<[[f64; 3]; 3]>(v.clone()))
        .transpose()?
        .unwrap_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    Ok((stackplan_geom::DMat3::from_cols_array_2d(&rows).transpose(), DVec3::from_array(position)))
}

fn obstacle(scenario: &Value, dir: &Path) -> anyhow::Result<Fields> {
    use stackplan::cspace::{Route, obstacle};
    let moving = load_part(scenario, "moving", dir)?;
    let fixed = load_part(scenario, "fixed", dir)?;
    let (rotation, translation) = fixed_pose(scenario)?;
    let placed: Vec<_> = fixed.components().iter().map(|c| c.transformed(rotation, translation)).collect();
    let angles: Vec<f64> = scenario
        .get("theta_deg")
        .map(|v| serde_json::from_value(v.clone()))
        .transpose()?
        .context("obstacle scenario has no \"theta_deg\" list")?;
    let (mut vertices, mut faces, mut volumes) = (Vec::new(), Vec::new(), Vec::new());
    let mut kinds: std::collections::BTreeMap<&'static str, usize> = Default::default();
    let mut hull_route = 0usize;
    for theta in &angles {
        let r = stackplan_geom::DMat3::from_rotation_z(stackplan_geom::pose::radians_mod_turn(*theta));
        let (mut v_row, mut f_row, mut vol_row) = (Vec::new(), Vec::new(), Vec::new());
        for (i, a) in moving.components().iter().enumerate() {
            for (j, b) in placed.iter().enumerate() {
                let o = obstacle(a, r, b).with_context(|| format!("theta {theta} deg, pair ({i}, {j})"))?;
                o.polytope().validate().with_context(|| format!("theta {theta} deg, pair ({i}, {j}): invalid"))?;
                v_row.push(o.polytope().vertices().len());
                f_row.push(o.polytope().faces().len());
                vol_row.push(o.polytope().volume());
                for k in o.face_kinds() {
                    *kinds.entry(k.name()).or_default() += 1;
                }
                hull_route += usize::from(o.route() != Route::GaussMap);
            }
        }
        vertices.push(v_row);
        faces.push(f_row);
        volumes.push(vol_row);
    }
    let mut f = Fields::new();
    f.insert("vertices_per_angle_and_pair".into(), serde_json::to_value(vertices)?);
    f.insert("faces_per_angle_and_pair".into(), serde_json::to_value(faces)?);
    f.insert("volume_per_angle_and_pair".into(), serde_json::to_value(volumes)?);
    f.insert("face_kinds".into(), serde_json::to_value(kinds)?);
    f.insert("hull_route_obstacles".into(), hull_route.into());
    Ok(f)
}

fn plan(scenario: &Value, dir: &Path) -> anyhow::Result<Fields> {
    use stackplan::planner::{FloorVolume, PlanOptions, plan_stack};
    let part = load_part(scenario, "part", dir)?;
    let num = |k: &str| scenario.get(k).and_then(Value::as_f64);
    let count = num("count").context("plan scenario has no \"count\"")? as usize;
    let floor: [f64; 4] = serde_json::from_value(scenario.get("floor").cloned().context("no \"floor\"")?)?;
    let height = num("height").context("plan scenario has no \"height\"")?;
    let mut options = PlanOptions::new(count, FloorVolume::rectangle(floor[0], floor[1], floor[2], floor[3], height));
    options.w = num("w").unwrap_or(0.5);
    options.clearance = num("clearance").unwrap_or(5.0);
    options.dtheta = num("dtheta_deg").unwrap_or(1.0).to_radians();
    options.cup_diameter = num("cup_diameter").unwrap_or(options.cup_diameter);
    let started = std::time::Instant::now();
    let plan = plan_stack(&part, &options)?;
    let plan_seconds = started.elapsed().as_secs_f64();
    let mut layers: Vec<f64> = plan.parts.iter().map(|p| (p.cg_height * 1e6).round() / 1e6).collect();
    layers.sort_by(f64::total_cmp);
    layers.dedup();
    let mut f = Fields::new();
    f.insert("placed".into(), plan.parts.len().into());
    f.insert("complete".into(), plan.stopped.is_none().into());
    f.insert("height".into(), plan.height.into());
    f.insert("footprint_x".into(), (plan.footprint[1][0] - plan.footprint[0][0]).into());
    f.insert("footprint_y".into(), (plan.footprint[1][1] - plan.footprint[0][1]).into());
    f.insert("total_cost".into(), plan.total_cost.into());
    f.insert("layers".into(), layers.len().into());
    f.insert("stack_stable".into(), plan.stack_stable.into());
    f.insert("stage_1_parts".into(), plan.parts.iter().filter(|p| p.stage == 1).count().into());
    f.insert("max_release_drop".into(), plan.parts.iter().map(|p| p.release_drop).fold(0.0, f64::max).into());
    f.insert("info_searches".into(), plan.stats.searches.into());
    f.insert("info_pairs_evaluated".into(), plan.stats.pairs_evaluated.into());
    // optional assertions, in code: the result fails the scenario (an error) whatever the golden says
    let poses: Vec<Pose> = plan
        .parts
        .iter()
        .map(|p| Pose::from_rows(p.rotation, DVec3::from_array(p.position)))
        .collect::<Result<_, _>>()?;
    if let Some(shape) = scenario.get("expect_shape").and_then(Value::as_str) {
        let counts = layer_counts(&part, &poses);
        f.insert("layer_counts".into(), counts.clone().into());
        f.insert("info_plan_seconds".into(), ((plan_seconds * 1e3).round() / 1e3).into());
        expect_shape(shape, count, &plan.parts.len(), &counts)?;
    }
    if scenario.get("check").and_then(Value::as_bool) == Some(true) {
        f.insert("info_plan_seconds".into(), ((plan_seconds * 1e3).round() / 1e3).into());
        let drops = plan.parts.iter().map(|p| p.release_drop).collect();
        f.insert("check_ok".into(), check_plan(&part, &poses, drops, &options)?.into());
    }
    if let Some(limit) = num("expect_height_below") {
        anyhow::ensure!(
            plan.height < limit,
            "the stack is {} mm high, expected below {limit} mm (nesting)",
            plan.height
        );
    }
    Ok(f)
}

/// Parts per layer, bottom up: the parts' lowest points sorted, a new layer wherever the gap to the previous lowest
/// point exceeds 1% of the part's height (computed here independently of the CLI's `sweep`).
fn layer_counts(part: &Part, poses: &[Pose]) -> Vec<usize> {
    let (lo, hi) = part.aabb();
    let gap = 0.01 * (hi.z - lo.z);
    let mut bottoms: Vec<f64> = poses
        .iter()
        .map(|p| {
            part.components().iter().flat_map(|c| c.vertices()).map(|v| p.apply(*v).z).fold(f64::INFINITY, f64::min)
        })
        .collect();
    bottoms.sort_by(f64::total_cmp);
    let mut counts = Vec::new();
    for (k, b) in bottoms.iter().enumerate() {
        if k == 0 || b - bottoms[k - 1] > gap {
            counts.push(0usize);
        }
        if let Some(last) = counts.last_mut() {
            *last += 1;
        }
    }
    counts
}

/// The shapes of the seed's Fig. 2: `flat` (w = 0: one layer, every part on the floor), `column` (w = 1: one part
/// per layer), `pyramid` (in between: more than one layer, fewer than parts, each layer no larger than the one below
/// and the bottom layer larger than the top one).
fn expect_shape(shape: &str, count: usize, placed: &usize, counts: &[usize]) -> anyhow::Result<()> {
    anyhow::ensure!(*placed == count, "{placed} of {count} parts placed");
    let layers = counts.len();
    match shape {
        "flat" => anyhow::ensure!(layers == 1, "expected one layer on the floor, got layers {counts:?}"),
        "column" => anyhow::ensure!(counts.iter().all(|&c| c == 1), "expected a single column, got layers {counts:?}"),
        "pyramid" => {
            anyhow::ensure!(1 < layers && layers < count, "expected between 1 and {count} layers, got {counts:?}");
            anyhow::ensure!(
                counts.windows(2).all(|w| w[0] >= w[1]) && counts[0] > counts[layers - 1],
                "expected lower layers larger than upper ones, got {counts:?}"
            );
        }
        other => bail!("unknown expect_shape {other:?} (flat, column, pyramid)"),
    }
    Ok(())
}

/// Runs the stack check on a plan with the planner's friction, cup and (horizontal) clearance less 1e-6 mm; fails
/// the scenario naming every part that does not pass.
fn check_plan(
    part: &Part,
    poses: &[Pose],
    release_drops: Vec<f64>,
    options: &stackplan::planner::PlanOptions,
) -> anyhow::Result<bool> {
    // the part as the plan's file stores it (convex pieces, re-hulled when read, so its faces may come in another
    // order), as `stackplan check PLAN` sees it, then the planner's own part
    let as_filed = stackplan_geom::io::json::parse_part_json(
        stackplan_geom::io::json::part_json_string(part).as_bytes(),
        Path::new("plan.json"),
        &stackplan_geom::io::ReadOptions::default(),
    )?;
    check_plan_with(&as_filed, poses, release_drops.clone(), options).context("the part as the plan file stores it")?;
    check_plan_with(part, poses, release_drops, options)
}

fn check_plan_with(
    part: &Part,
    poses: &[Pose],
    release_drops: Vec<f64>,
    options: &stackplan::planner::PlanOptions,
) -> anyhow::Result<bool> {
    use stackplan::stability::check::{CheckOptions, check_stack};
    use stackplan::stability::grasp::GraspOptions;
    use stackplan::stability::world::PlacedPart;
    let stack: Vec<PlacedPart<'_>> = poses.iter().map(|p| PlacedPart { part, pose: *p }).collect();
    let check = CheckOptions {
        mu: options.mu,
        clearance: (options.clearance - 1e-6).max(0.0),
        grasp: GraspOptions { cup_diameter: options.cup_diameter, ..GraspOptions::default() },
        release_drops,
        ..CheckOptions::default()
    };
    let report = check_stack(&stack, &check)?;
    let failed: Vec<String> = report
        .parts
        .iter()
        .filter(|p| !p.ok)
        .map(|p| {
            format!(
                "part {}: interference {:.3e}, clearance met {}, stable {}, stack stable {}, graspable {}, insertable {}, removable {}",
                p.index,
                p.interference,
                p.clearance_met,
                p.stable.is_stable(),
                p.stack_stable.is_stable(),
                p.graspable,
                p.insertable,
                p.removable
            )
        })
        .collect();
    anyhow::ensure!(report.ok, "the plan fails the stack check: {}", failed.join("; "));
    Ok(report.ok)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_of_fig_2_are_told_apart() {
        assert!(expect_shape("flat", 4, &4, &[4]).is_ok());
        assert!(expect_shape("flat", 4, &3, &[3]).is_err(), "a part missing");
        assert!(expect_shape("flat", 4, &4, &[3, 1]).is_err());
        assert!(expect_shape("column", 3, &3, &[1, 1, 1]).is_ok());
        assert!(expect_shape("column", 3, &3, &[2, 1]).is_err());
        assert!(expect_shape("pyramid", 14, &14, &[9, 4, 1]).is_ok());
        assert!(expect_shape("pyramid", 6, &6, &[3, 3]).is_err(), "the bottom must be larger than the top");
        assert!(expect_shape("pyramid", 6, &6, &[2, 3, 1]).is_err(), "a layer larger than the one below");
        assert!(expect_shape("pyramid", 4, &4, &[4]).is_err());
        assert!(expect_shape("cone", 4, &4, &[4]).is_err());
    }

    #[test]
    fn layers_are_resting_heights_of_the_lowest_points() {
        let cube = stackplan_geom::examples::part_by_name("cube", Decomposition::ConvexMerge).expect("cube");
        let at = |x: f64, z: f64| Pose::from_translation(DVec3::new(x, 0.0, z));
        let poses = [at(0.0, 0.0), at(2.0, 0.0), at(1.0, 1.0), at(5.0, 0.005)];
        // 0.005 is within 1% of the cube's height of the floor: the same layer
        assert_eq!(layer_counts(&cube, &poses), vec![3, 1]);
    }
}
