//! `cablemap calibrate DATA`: fits EA, GA, EI (thesis eq. 2.14) to
//! measurements and reports them with standard errors, correlations and the
//! RMS error per routing.

use super::ActuatorArgs;
use crate::calibrate::diagnose::{fit_json, split_holdout};
use crate::calibrate::fit::rms_per_routing;
use crate::calibrate::predict::predict;
use crate::calibrate::fit::fit_observed;
use crate::calibrate::{read_measurements, Effect, FitSpec};
use crate::model::{Actuator, SolverOptions};
use anyhow::bail;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `cablemap calibrate`.
#[derive(Debug, Clone, Args)]
pub struct CalibrateArgs {
    /// Measurement file (CSV, or Parquet by its .parquet extension); see docs/measurements.md.
    pub data: PathBuf,
    /// Leave this routing out of the fit and report the error on it.
    #[arg(long, value_name = "ROUTING")]
    pub holdout: Option<String>,
    /// Weight of the tip angle in mm per degree (1: 1° counts like 1 mm).
    #[arg(long, default_value_t = 1.0, value_name = "MM_PER_DEG")]
    pub angle_weight: f64,
    /// Also fit this effect's parameter (repeatable): friction, gravity, stiffening, clamp_compliance, channel_offset, creep.
    #[arg(long = "effect", value_name = "EFFECT")]
    pub effects: Vec<String>,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
    /// Starting values and fixed parameters.
    #[command(flatten)]
    pub actuator: ActuatorArgs,
}

/// Parses effect names, naming the bad one.
pub fn parse_effects(names: &[String]) -> anyhow::Result<Vec<Effect>> {
    let mut out = Vec::new();
    for n in names {
        let Some(e) = Effect::parse(n) else {
            let all: Vec<&str> = Effect::ALL.iter().map(|e| e.name()).collect();
            bail!("--effect {n}: unknown effect; use one of {}", all.join(", "));
        };
        if !out.contains(&e) {
            out.push(e);
        }
    }
    Ok(out)
}

/// Measurement files from this many rows on get a stated cost before fitting.
const LARGE_DATA_ROWS: usize = 2000;

/// Runs `cablemap calibrate`.
pub fn run(args: &CalibrateArgs) -> anyhow::Result<()> {
    let base = args.actuator.apply(&Actuator::default());
    base.validate()?;
    let options = args.actuator.solver_options(&SolverOptions::default());
    let data = read_measurements(&args.data)?;
    let (train, held) = split_holdout(&data, args.holdout.as_deref())?;
    let spec = FitSpec { effects: parse_effects(&args.effects)?, angle_weight_mm_per_deg: args.angle_weight };
    let large = data.rows.len() >= LARGE_DATA_ROWS;
    if large {
        // A fit re-simulates every reading (1 + parameters) times per
        // iteration: state the cost of one pass up front for large files,
        // so a long silent run is expected rather than mistaken for a hang.
        let started = std::time::Instant::now();
        predict(&base, &options, &data, &train, false)?;
        let pass_s = started.elapsed().as_secs_f64();
        // Central differences: two passes per parameter for the Jacobian,
        // plus the trial steps (at least two).
        let passes = 2 * (3 + spec.effects.len()) + 2;
        let per_iteration_s = pass_s * passes as f64;
        eprintln!(
            "calibrate: {} readings; one pass over them takes {pass_s:.2} s, an iteration about {passes} passes \
             (≈ {per_iteration_s:.1} s); typically 5-30 iterations, at most 200",
            data.rows.len()
        );
    }
    let result = fit_observed(&base, &options, &data, &train, &spec, &mut |p| {
        if large {
            eprintln!("calibrate: iteration {} (of at most 200): RMS {:.4} mm", p.iteration, p.rms_mm);
        }
    })?;
    let holdout_rms = match &held {
        Some(g) => {
            let g = std::slice::from_ref(g);
            let preds = predict(&result.actuator, &options, &data, g, false)?;
            Some(rms_per_routing(&data, g, &preds, args.angle_weight)[0].clone())
        }
        None => None,
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        let mut v = fit_json(&result);
        v["holdout"] = serde_json::to_value(&holdout_rms)?;
        writeln!(out, "{v}")?;
        return Ok(());
    }
    writeln!(out, "fit of {} readings on {} routings (eq. 2.14, θ weight {} mm/°)", result.n_residuals / 3, train.len(), args.angle_weight)?;
    for p in &result.parameters {
        writeln!(out, "  {:<30} {:>14.6} ± {:<12.4e}", p.name, p.value, p.se)?;
    }
    writeln!(out, "correlations:")?;
    write!(out, "  {:<30}", "")?;
    for p in &result.parameters {
        write!(out, " {:>9}", &p.name[..p.name.len().min(9)])?;
    }
    writeln!(out)?;
    for (p, row) in result.parameters.iter().zip(&result.correlation) {
        write!(out, "  {:<30}", p.name)?;
        for c in row {
            write!(out, " {c:>+9.3}")?;
        }
        writeln!(out)?;
    }
    writeln!(out, "RMS per routing (x, y in mm and θ weighted, together; then tip position and angle):")?;
    for r in &result.per_routing {
        writeln!(out, "  {:<20} {:>3} rows  {:>8.4} mm   {:>8.4} mm  {:>8.4}°", r.routing, r.rows, r.rms_mm, r.rms_position_mm, r.rms_angle_deg)?;
    }
    if let Some(r) = holdout_rms {
        writeln!(out, "  {:<20} {:>3} rows  {:>8.4} mm   {:>8.4} mm  {:>8.4}°  (held out)", r.routing, r.rows, r.rms_mm, r.rms_position_mm, r.rms_angle_deg)?;
    }
    writeln!(out, "overall RMS {:.4} mm, {} iterations{}", result.rms_mm, result.iterations, if result.converged { "" } else { " (iteration cap reached)" })?;
    writeln!(out, "cable stretch is not fitted: under tension control it is not identifiable")?;
    Ok(())
}
