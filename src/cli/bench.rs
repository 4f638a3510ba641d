//! `cablemap bench`: prints solver timings (see [`cablemap::bench`]).

use super::ActuatorArgs;
use cablemap::bench::{bench_with_reference, sample_thesis_routings};
use cablemap::solver::SolverOptions;
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
    /// Skip the previous method (RK4, 24 steps per span), which is otherwise timed in the same run for the speed-up.
    #[arg(long)]
    pub no_reference: bool,
    #[command(flatten)]
    pub actuator: ActuatorArgs,
}

/// Runs the solver benchmark with gravity on and off.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        (1..=cablemap::bench::MAX_ROUTINGS).contains(&args.routings),
        "--routings {} must be 1 … {} (the thesis grid's 9⁵ routings)",
        args.routings,
        cablemap::bench::MAX_ROUTINGS
    );
    let base = args.actuator.resolve()?;
    let options = args.actuator.solver_options(&SolverOptions::default());
    let routings = sample_thesis_routings(args.routings, base.radius_mm);
    let rows = bench_with_reference(&base, &options, &routings, !args.no_reference)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(());
    }
    println!(
        "single thread, {} thesis-grid routings x 21 tensions (1.0..2.0 N, continuation), a_0..a_3 included",
        args.routings
    );
    println!(
        "{:<12} {:<16} {:>10} {:>8} {:>8} {:>8} {:>9}",
        "case", "method", "median µs", "p10 µs", "p90 µs", "passes", "failures"
    );
    for r in &rows {
        for f in std::iter::once(r).chain(r.reference.as_deref()) {
            println!(
                "{:<12} {:<16} {:>10.2} {:>8.2} {:>8.2} {:>8.2} {:>9}",
                f.label, f.method, f.median_us_per_solve, f.p10_us_per_solve, f.p90_us_per_solve, f.mean_passes, f.failures
            );
        }
    }
    // Actuation by displacement (the collocation): the same routings driven
    // through a displacement ladder, each tension found; its ratio to the
    // tension-driven solve of this run.
    if options.method == cablemap::solver::SolverMethod::Collocation {
        let f = cablemap::bench::bench_displacement(&base, &options, &routings, 0.5, 5.0, 21, "displacement")?;
        println!(
            "displacement-driven, the same routings x 21 displacements (0.5..5.0 mm, continuation, tension found), gravity {}",
            if base.gravity.enabled { "on" } else { "off" }
        );
        println!(
            "{:<12} {:<16} {:>10.2} {:>8.2} {:>8.2} {:>8.2} {:>9}",
            f.label, f.method, f.median_us_per_solve, f.p10_us_per_solve, f.p90_us_per_solve, f.mean_passes, f.failures
        );
        let same_gravity = if base.gravity.enabled { "gravity on" } else { "gravity off" };
        if let Some(p) = rows.iter().find(|r| r.label == same_gravity) {
            println!("displacement-driven solve {:.2} µs = {:.2}x the tension-driven {:.2} µs (medians, same run)", f.median_us_per_solve, f.median_us_per_solve / p.median_us_per_solve, p.median_us_per_solve);
        }
    }
    // The 3-D solver: two spatial cables, in the table only (the JSON
    // array keeps its two planar rows), with its RK4 reference unless
    // --no-reference, and its ratio to the planar single-cable solve of this run.
    let spatial_options = cablemap::solver::SolverOptions { nodes_per_span: options.nodes_per_span, ..Default::default() };
    let rk4_options = cablemap::solver::SolverOptions { method: cablemap::solver::SolverMethod::Rk4, ..Default::default() };
    let pairs = cablemap::bench::sample_spatial_pairs(args.routings.div_ceil(4), base.radius_mm);
    println!(
        "3-D solver, {} two-cable spatial actuators x 21 tensions (tau1 1.0..2.0 N, tau2 = tau1/2, continuation), twist and both bending series a_0..a_3 included",
        pairs.len()
    );
    println!("{:<22} {:<24} {:>10} {:>8} {:>8} {:>8} {:>9}", "case", "method", "median µs", "p10 µs", "p90 µs", "passes", "failures");
    let cases = [(Some([1.0, 0.0, 0.0]), "gravity +x (hanging)"), (Some([0.0, 0.6, 0.8]), "gravity (0, .6, .8)"), (None, "gravity off")];
    let mut ratios = Vec::new();
    for (gravity, label) in cases {
        let mut methods = vec![&spatial_options];
        if !args.no_reference {
            methods.push(&rk4_options);
        }
        for (k, o) in methods.into_iter().enumerate() {
            let f = cablemap::bench::bench_spatial(&base, o, &pairs, 21, gravity, label)?;
            println!(
                "{:<22} {:<24} {:>10.2} {:>8.2} {:>8.2} {:>8.2} {:>9}",
                f.label, f.method, f.median_us_per_solve, f.p10_us_per_solve, f.p90_us_per_solve, f.mean_passes, f.failures
            );
            // The planar row of the same gravity (on: the first; off: the second).
            let planar = if gravity.is_some() { rows.first() } else { rows.get(1) };
            if let (0, Some(p)) = (k, planar) {
                ratios.push(format!("{label}: two-cable 3-D {:.2} µs = {:.2}x the planar single-cable {:.2} µs", f.median_us_per_solve, f.median_us_per_solve / p.median_us_per_solve, p.median_us_per_solve));
            }
        }
    }
    for r in ratios {
        println!("{r} (medians, same run)");
    }
    for r in &rows {
        if let (Some(s), Some(reference)) = (r.speedup, r.reference.as_deref()) {
            println!("{}: {} is {:.1}x faster than {} (medians, same run)", r.label, r.method, s, reference.method);
        }
    }
    Ok(())
}
