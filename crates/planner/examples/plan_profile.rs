//! Times a stacking plan of a fixture part (for profiling): `cargo run -p stackplan-planner --example plan_profile
//! -- PART.json [COUNT] [W] [DTHETA_DEG] [HALF_SIZE] [HEIGHT] [CLEARANCE] [CUP_DIAMETER] [PARTITIONS]`. Prints the
//! plan's totals and statistics as JSON (default floor 660 x 660 mm centred at the origin, height 400 mm; 5 mm
//! clearance and a 10 mm cup, as the Channel plan regression scenarios; the 121 unit cubes of Fig. 2: `cube.json 121
//! 0.5 90 5.5 126 0 0.5`; PARTITIONS: the placement searches' partitions of the orientations, default 2).

use stackplan_geom::io::{ReadOptions, read_part};
use stackplan_planner::{FloorVolume, PlanOptions, plan_stack};

#[allow(clippy::print_stdout)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).ok_or(
        "usage: plan_profile PART.json [COUNT] [W] [DTHETA_DEG] [HALF_SIZE] [HEIGHT] [CLEARANCE] [CUP_DIAMETER] \
         [PARTITIONS]",
    )?;
    let count: usize = args.get(2).map_or(Ok(15), |s| s.parse())?;
    let w: f64 = args.get(3).map_or(Ok(0.5), |s| s.parse())?;
    let dtheta: f64 = args.get(4).map_or(Ok(5.0), |s| s.parse())?;
    let half: f64 = args.get(5).map_or(Ok(330.0), |s| s.parse())?;
    let height: f64 = args.get(6).map_or(Ok(400.0), |s| s.parse())?;
    let clearance: Option<f64> = args.get(7).map(|s| s.parse()).transpose()?;
    let cup: Option<f64> = args.get(8).map(|s| s.parse()).transpose()?;
    let partitions: Option<usize> = args.get(9).map(|s| s.parse()).transpose()?;
    let part = read_part(path, &ReadOptions::default())?;
    let mut options = PlanOptions::new(count, FloorVolume::rectangle(-half, -half, half, half, height));
    options.w = w;
    options.dtheta = dtheta.to_radians();
    options.clearance = clearance.unwrap_or(options.clearance);
    options.cup_diameter = cup.unwrap_or(options.cup_diameter);
    options.tuning.partitions = partitions.unwrap_or(options.tuning.partitions);
    let started = std::time::Instant::now();
    let plan = plan_stack(&part, &options)?;
    let seconds = started.elapsed().as_secs_f64();
    let summary = serde_json::json!({
        "placed": plan.parts.len(),
        "total_cost": plan.total_cost,
        "height": plan.height,
        "footprint": plan.footprint,
        "seconds": seconds,
        "stats": plan.stats,
    });
    println!("{}", serde_json::to_string_pretty(&summary)?);
    Ok(())
}
