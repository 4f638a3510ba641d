//! The `cablemap` command: parses arguments and calls the library.

mod cli;
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
    #[command(allow_negative_numbers = true)]
    Simulate(cli::simulate::SimulateArgs),
    /// Design the cable routing and tension for a target shape (thesis eq. 3.17).
    #[command(allow_negative_numbers = true)]
    Design(cli::design::DesignArgs),
    /// Is a target shape reachable? Verdict from a feasibility map, with the nearest designs.
    #[command(allow_negative_numbers = true)]
    Feasible(cli::feasible::FeasibleArgs),
    /// Printable moulds (binary STL, mm) for a routing: tray, lid with the channel's protrusion, cover.
    Mould(cli::mould::MouldArgs),
    /// Print solver timings (median µs per solve, single thread).
    #[command(allow_negative_numbers = true)]
    Bench(cli::bench::BenchArgs),
    /// Sweep a routing grid through a tension ladder into Parquet chunks (sharded, resumable).
    #[command(allow_negative_numbers = true)]
    Sweep(cli::sweep::SweepArgs),
    /// Report a sweep directory: rows done per shard, failures, completeness.
    #[command(allow_negative_numbers = true)]
    Status(cli::sweep::StatusArgs),
    /// Bin a sweep into feasibility maps: Parquet tables, PNG pictures, index.html.
    #[command(allow_negative_numbers = true)]
    Reduce(cli::reduce::ReduceArgs),
    /// The main job: sweep (resumable) then reduce; the thesis sweep when no SPEC is given.
    #[command(allow_negative_numbers = true)]
    Map(cli::reduce::MapArgs),
    /// Maps of actuator variants: a sweep and map per variant of a study spec, compared side by side.
    #[command(allow_negative_numbers = true)]
    Study(cli::study::StudyArgs),
    /// Fit EA, GA, EI (and optionally effects) to measurements (thesis eq. 2.14).
    #[command(allow_negative_numbers = true)]
    Calibrate(cli::calibrate::CalibrateArgs),
    /// Simulate captures with an actuator file (no fitting): the 3-D markers' errors per capture and marker.
    #[command(allow_negative_numbers = true)]
    Predict(cli::predict::PredictArgs),
    /// Find, name and add the effect the model is missing; report and plots.
    #[command(allow_negative_numbers = true)]
    Diagnose(cli::diagnose::DiagnoseArgs),
    /// Generate measurement files from the model with a hidden effect and noise.
    #[command(allow_negative_numbers = true)]
    Synth(cli::synth::SynthArgs),
}

fn main() -> ExitCode {
    restore_sigpipe();
    let cli: Cli = cli::parse_args();
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
        Command::Study(args) => cli::study::run(args),
        Command::Calibrate(args) => cli::calibrate::run(args),
        Command::Diagnose(args) => cli::diagnose::run(args),
        Command::Predict(args) => cli::predict::run(args),
        Command::Synth(args) => cli::synth::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", cli::error_text(&e));
            ExitCode::FAILURE
        }
    }
}

/// Rust ignores SIGPIPE, so printing into a closed pipe (`cablemap status
/// DIR | head -1`) makes `println!` panic. Like other command-line tools,
/// cablemap instead ends quietly when its reader has gone: the default
/// action. Work on disk is safe at any moment (atomic files).
fn restore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in main, before any thread exists; setting
    // a signal's disposition to the default has no other effect.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
