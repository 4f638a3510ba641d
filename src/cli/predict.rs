//! `cablemap predict CAPTURES --actuator A.toml --markers MARKERS`:
//! simulates every capture with the given actuator (no fitting) and reports
//! the markers' 3-D errors per capture, per marker and overall.

use super::ActuatorArgs;
use cablemap::calibrate::predict;
use cablemap::calibrate::predict::PredictRequest;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `cablemap predict`.
#[derive(Debug, Clone, Args)]
pub struct PredictArgs {
    /// Captures file (CSV, or Parquet by its .parquet extension): one tension_K_n or
    /// displacement_K_mm column per cable; see docs/measurements.md.
    pub captures: PathBuf,
    /// The actuator (rod, torsion, gravity, cables) as TOML, e.g. a calibrate's calibrated.toml.
    #[arg(long, value_name = "FILE.toml")]
    pub actuator: PathBuf,
    /// 3-D markers (measurement,marker,s_mm,offset_y_mm,offset_z_mm,x_mm,y_mm,z_mm[,sd_mm]).
    #[arg(long, value_name = "FILE")]
    pub markers: Option<PathBuf>,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
    /// Solver settings (--nodes-per-span, --steps-per-span, --method); rod flags are refused:
    /// the rod is the actuator file's.
    #[command(flatten)]
    pub solver: ActuatorArgs,
}

/// Runs `cablemap predict`.
pub fn run(args: &PredictArgs) -> anyhow::Result<()> {
    let request = PredictRequest {
        captures: args.captures.clone(),
        markers: args.markers.clone(),
        actuator: args.actuator.clone(),
        rod: args.solver.overrides(),
        options: args.solver.solver_options(&cablemap::solver::SolverOptions::default()),
    };
    let report = predict::run(&request)?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", report.to_json_line())?;
    } else {
        write!(out, "{report}")?;
    }
    Ok(())
}
