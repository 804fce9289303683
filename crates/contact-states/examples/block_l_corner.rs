//! Times the ACSG of the block / L-corner example (\[P\] V) and prints the states per level, the counters and the
//! Table I-style extremal table. `cargo run --profile dev -p stackplan-contact-states --example block_l_corner --
//! [population generations polish seed extremal_budget analytic_steps]` (defaults: the crate's default settings, seed
//! 2004).

#![allow(clippy::print_stdout)] // a command-line timing tool: printing is its output

use stackplan_contact_states::acsg::{AcsgSettings, generate};
use stackplan_contact_states::criteria::ContactPart;
use stackplan_contact_states::ga::GaSettings;
use stackplan_contact_states::pose::ConfigBox;
use stackplan_geom::{DMat3, DVec3, Part, PartOrigin};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<u64> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let defaults = GaSettings::default();
    let ga = GaSettings {
        population: args.first().map_or(defaults.population, |&v| v as usize),
        generations: args.get(1).map_or(defaults.generations, |&v| v as usize),
        polish_evaluations: args.get(2).map_or(defaults.polish_evaluations, |&v| v as usize),
        seed: args.get(3).copied().unwrap_or(2004),
    };
    let l = stackplan_geom::examples::l_corner_part();
    let shifted: Vec<_> = l.components().iter().map(|c| c.transformed(DMat3::IDENTITY, DVec3::splat(-20.0))).collect();
    let l = Part::from_components("l-corner", shifted, 1.0, PartOrigin::ConvexPieces)?;
    let fixed = ContactPart::from_part(&l)?;
    let moving = ContactPart::from_part(&stackplan_geom::examples::block_part())?;
    let d = 9f64.to_radians();
    let bounds = ConfigBox::new([-5.0, -5.0, 0.0, -d, -d, -d], [5.0, 5.0, 240.0, d, d, d])?;
    let start = Instant::now();
    let extremal_budget = args.get(4).map_or(AcsgSettings::default().extremal_budget, |&v| v as usize);
    let analytic_steps = args.get(5).map_or(AcsgSettings::default().analytic_steps, |&v| v as usize);
    let g = generate(
        &fixed,
        &moving,
        bounds,
        AcsgSettings { ga, extremal_budget, analytic_steps, ..AcsgSettings::default() },
    )?;
    let seconds = start.elapsed().as_secs_f64();
    let per_level = g.counts_per_level();
    println!("GA {ga:?}");
    println!("time {seconds:.2} s, per level {per_level:?}, total {}", per_level.iter().sum::<usize>());
    println!("stats {:?}", g.stats);
    for s in g.states.iter().filter(|s| !s.feasible && s.objective.is_some_and(|v| v <= g.threshold)) {
        println!("candidate rejected by the strict check: {} f = {:?}: {:?}", s.label, s.objective, s.rejection);
    }
    println!("{}", g.extremal_table());
    Ok(())
}
