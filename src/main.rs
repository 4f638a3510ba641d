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
    /// Print solver timings (median µs per solve, single thread).
    Bench(cli::bench::BenchArgs),
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
