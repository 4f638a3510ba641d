//! `cablemap diagnose DATA`: finds, names and adds the missing effect, with
//! a Markdown report and plots.

use super::ActuatorArgs;
use crate::calibrate::data::read_centrelines;
use crate::calibrate::diagnose::{diagnose, DiagnoseSpec};
use crate::calibrate::read_measurements;
use crate::calibrate::report::write_report;
use crate::model::{Actuator, SolverOptions};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `cablemap diagnose`.
#[derive(Debug, Clone, Args)]
pub struct DiagnoseArgs {
    /// Measurement file (CSV, or Parquet by its .parquet extension); see docs/measurements.md.
    pub data: PathBuf,
    /// Routing left out of every fit; the gap on it is shown before and after.
    #[arg(long, value_name = "ROUTING")]
    pub holdout: Option<String>,
    /// Measured centreline points (measurement,x_mm,y_mm), drawn in the shape plot.
    #[arg(long, value_name = "FILE")]
    pub centrelines: Option<PathBuf>,
    /// Report directory (report.md and PNG plots).
    #[arg(long, default_value = "diagnose-report", value_name = "DIR")]
    pub out: PathBuf,
    /// Skip the report and plots.
    #[arg(long)]
    pub no_report: bool,
    /// Weight of the tip angle in mm per degree (1: 1° counts like 1 mm).
    #[arg(long, default_value_t = 1.0, value_name = "MM_PER_DEG")]
    pub angle_weight: f64,
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
    if !args.no_report {
        // Before the fits, not after them.
        crate::io::check_not_in_run_dir(&args.out, "--out").map_err(anyhow::Error::msg)?;
    }
    let base = args.actuator.apply(&Actuator::default());
    base.validate()?;
    let options = args.actuator.solver_options(&SolverOptions::default());
    let data = read_measurements(&args.data)?;
    let centrelines = args.centrelines.as_ref().map(|p| read_centrelines(p, &data)).transpose()?;
    let spec = DiagnoseSpec {
        holdout: args.holdout.clone(),
        angle_weight_mm_per_deg: args.angle_weight,
        threshold: args.threshold,
        margin: args.margin,
        max_effects: args.max_effects.max(1),
    };
    let d = diagnose(&base, &options, &data, &spec)?;
    let report = if args.no_report {
        None
    } else {
        Some(write_report(&args.out, &args.data, &data, &d, centrelines.as_ref(), args.angle_weight)?)
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        let mut v = d.to_json();
        v["report"] = serde_json::to_value(report.as_ref().map(|p| p.display().to_string()))?;
        writeln!(out, "{v}")?;
        return Ok(());
    }
    writeln!(out, "verdict: {}", d.verdict)?;
    for n in &d.named {
        writeln!(out, "  {} {} = {} ± {:.3e} (ΔBIC {:.1})", n.effect, n.parameter_name, value(n.parameter), n.parameter_se, n.delta_bic)?;
    }
    if let Some(m) = &d.separating_measurement {
        writeln!(out, "  cannot tell {} from {}: {m}", d.ambiguous_between[0], d.ambiguous_between[1])?;
    }
    writeln!(out, "candidates (ΔBIC against the thesis model):")?;
    for c in &d.candidates {
        writeln!(
            out,
            "  {}. {:<17} {:<30} {:>12} ± {:<10.3e} ΔBIC {:>9.2}{}",
            c.rank,
            c.effect,
            c.parameter_name,
            value(c.parameter),
            c.parameter_se,
            c.delta_bic,
            if c.plausible { "" } else { "  (implausible or failed)" }
        )?;
    }
    if let (Some(h), Some(b), Some(a)) = (&d.holdout, d.holdout_rms_before, d.holdout_rms_after) {
        writeln!(out, "held-out routing {h}: RMS {b:.4} mm before, {a:.4} mm after")?;
    }
    writeln!(out, "criterion: {}", d.criterion)?;
    if let Some(p) = report {
        writeln!(out, "report: {}", p.display())?;
    }
    Ok(())
}

/// A parameter value for the summary: fixed point unless very large or small.
fn value(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:.5e}")
    } else {
        format!("{v:.5}")
    }
}
