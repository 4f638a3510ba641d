//! The `cablemap` command: parses arguments and calls the library.

use cablemap::cli;
use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Design planar cable-driven soft actuators: simulate, sweep, map, design.
#[derive(Debug, Parser)]
#[command(name = "cablemap", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Simulate one actuator at one tension: tip pose, shape coefficients, centreline.
    Simulate(cli::simulate::SimulateArgs),
    /// Design the cable routing and tension for a target shape (thesis eq. 3.17).
    Design(cli::design::DesignArgs),
    /// Is a target shape reachable? Verdict from a feasibility map, with the nearest designs.
    Feasible(cli::feasible::FeasibleArgs),
    /// Printable moulds (binary STL, mm) for a routing: tray, lid with the channel's protrusion, cover.
    Mould(cli::mould::MouldArgs),
    /// Print solver timings (median µs per solve, single thread).
    Bench(cli::bench::BenchArgs),
    /// Sweep a routing grid through a tension ladder into Parquet chunks (sharded, resumable).
    Sweep(cli::sweep::SweepArgs),
    /// Report a sweep directory: rows done per shard, failures, completeness.
    Status(cli::sweep::StatusArgs),
    /// Bin a sweep into feasibility maps: Parquet tables, PNG pictures, index.html.
    Reduce(cli::reduce::ReduceArgs),
    /// The main job: sweep (resumable) then reduce; the thesis sweep when no SPEC is given.
    Map(cli::reduce::MapArgs),
    /// Fit EA, GA, EI (and optionally effects) to measurements (thesis eq. 2.14).
    Calibrate(cli::calibrate::CalibrateArgs),
    /// Find, name and add the effect the model is missing; report and plots.
    Diagnose(cli::diagnose::DiagnoseArgs),
    /// Generate measurement files from the model with a hidden effect and noise.
    Synth(cli::synth::SynthArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Simulate(args) => cli::simulate::run(args),
        Command::Bench(args) => cli::bench::run(args),
        Command::Design(args) => cli::design::run(args),
        Command::Feasible(args) => cli::feasible::run(args),
        Command::Mould(args) => cli::mould::run(args),
        Command::Sweep(args) => cli::sweep::run(args),
        Command::Status(args) => cli::sweep::run_status_command(args),
        Command::Reduce(args) => cli::reduce::run(args),
        Command::Map(args) => cli::reduce::run_map(args),
        Command::Calibrate(args) => cli::calibrate::run(args),
        Command::Diagnose(args) => cli::diagnose::run(args),
        Command::Synth(args) => cli::synth::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
