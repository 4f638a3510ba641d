//! `cablemap bench`: prints solver timings (see [`crate::bench`]).

use super::ActuatorArgs;
use crate::bench::{bench_solver, sample_thesis_routings};
use crate::model::{Actuator, SolverOptions};
use clap::Args;

/// Arguments of `cablemap bench`.
#[derive(Debug, Clone, Args)]
pub struct BenchArgs {
    /// Thesis-grid routings to sample.
    #[arg(long, default_value_t = 400)]
    pub routings: usize,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub actuator: ActuatorArgs,
}

/// Runs the solver benchmark with gravity on and off.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    anyhow::ensure!(args.routings > 0, "--routings must be at least 1");
    let base = args.actuator.apply(&Actuator::default());
    let options = args.actuator.solver_options(&SolverOptions::default());
    let routings = sample_thesis_routings(args.routings, base.radius_mm);
    let mut rows = Vec::new();
    for gravity in [true, false] {
        let mut a = base.clone();
        a.gravity.enabled = gravity;
        let label = if gravity { "gravity on" } else { "gravity off" };
        rows.push(bench_solver(&a, &options, &routings, 1.0, 2.0, 21, label)?);
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(());
    }
    println!(
        "single thread, {} thesis-grid routings x 21 tensions (1.0..2.0 N, continuation), {} RK4 steps per span",
        args.routings, options.steps_per_span
    );
    println!("{:<12} {:>12} {:>10} {:>10} {:>8} {:>9}", "case", "median µs", "p10 µs", "p90 µs", "passes", "failures");
    for r in &rows {
        println!(
            "{:<12} {:>12.2} {:>10.2} {:>10.2} {:>8.2} {:>9}",
            r.label, r.median_us_per_solve, r.p10_us_per_solve, r.p90_us_per_solve, r.mean_passes, r.failures
        );
    }
    Ok(())
}
