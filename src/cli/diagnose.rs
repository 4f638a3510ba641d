//! `cablemap diagnose DATA`: finds, names and adds the missing effect, with
//! a Markdown report and plots.

use super::calibrate::{with_flag, FitArgs};
use super::ActuatorArgs;
use cablemap::calibrate::diagnose::{self, DiagnoseRequest};
use cablemap::calibrate::CalibrateError;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `cablemap diagnose`.
#[derive(Debug, Clone, Args)]
pub struct DiagnoseArgs {
    /// Measurement file (CSV, or Parquet by its .parquet extension); with --actuator, the captures
    /// file (one tension_K_n or displacement_K_mm column per cable); see docs/measurements.md.
    pub data: PathBuf,
    /// A whole actuator (rod, torsion, gravity, cables) as TOML: diagnose several-cable captures
    /// against 3-D markers (--markers) with the 3-D solver.
    #[arg(long = "actuator", value_name = "FILE.toml")]
    pub spatial_actuator: Option<PathBuf>,
    /// With --actuator: fit on the captures where cable K does not pull; the gap on the others
    /// is shown before and after.
    #[arg(long, value_name = "K")]
    pub holdout_cable: Option<usize>,
    /// Routing left out of every fit; the gap on it is shown before and after.
    #[arg(long, value_name = "ROUTING")]
    pub holdout: Option<String>,
    /// Report directory (report.md and PNG plots; with --actuator a picture per capture) [default:
    /// DATA's name with `-diagnosis`, beside the data file: measurements.csv → measurements-diagnosis/].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Skip the report and plots.
    #[arg(long)]
    pub no_report: bool,
    /// Noise, held parameters, loss, shapes.
    #[command(flatten)]
    pub fit: FitArgs,
    /// A model is consistent with the noise when the chi-square test's p ≥ this.
    #[arg(long, default_value_t = 1e-3, value_name = "P")]
    pub alpha: f64,
    /// BIC decrease an effect needs against the model without it.
    #[arg(long, default_value_t = 10.0)]
    pub threshold: f64,
    /// BIC lead an effect needs over the runner-up.
    #[arg(long, default_value_t = 10.0)]
    pub margin: f64,
    /// Most effects added (forward-stepwise).
    #[arg(long, default_value_t = 2)]
    pub max_effects: usize,
    /// Print one JSON object instead of a summary.
    #[arg(long)]
    pub json: bool,
    /// Starting values and fixed parameters (e.g. --creep-time-s).
    #[command(flatten)]
    pub actuator: ActuatorArgs,
}

/// Runs `cablemap diagnose`.
pub fn run(args: &DiagnoseArgs) -> anyhow::Result<()> {
    let request = DiagnoseRequest {
        input: args.fit.input(&args.data, args.spatial_actuator.as_deref(), &args.actuator, args.holdout.as_deref(), args.holdout_cable)?,
        alpha: args.alpha,
        threshold: args.threshold,
        margin: args.margin,
        max_effects: args.max_effects,
        out: args.out.clone(),
        write_report: !args.no_report,
    };
    let report = diagnose::run(&request).map_err(|e| match e {
        CalibrateError::ReportDir(_) => anyhow::Error::new(e).context("--out"),
        e => with_flag(e, false),
    })?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", report.to_json_line())?;
    } else {
        write!(out, "{report}")?;
    }
    Ok(())
}
