//! `cablemap calibrate DATA`: fits EA, GA, EI (thesis eq. 2.14) to
//! measurements and reports them with standard errors, correlations and the
//! RMS error per routing.

use anyhow::Context;
use super::ActuatorArgs;
use cablemap::calibrate::data::{read_centrelines, read_markers, Dataset};
use cablemap::calibrate::diagnose::{fit_json, split_holdout};
use cablemap::calibrate::fit::{apply_held, parse_held, rms_per_routing, Held, Loss, Noise, ShapeData};
use cablemap::calibrate::predict::predict;
use cablemap::calibrate::fit::fit_observed;
use cablemap::calibrate::{read_measurements, Effect, FitSpec};
use cablemap::model::{Rod, SolverOptions};
use anyhow::bail;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;

/// Settings every fit shares (calibrate and diagnose).
#[derive(Debug, Clone, Args)]
pub struct FitArgs {
    /// Noise (standard deviation) of tip x, y, centreline points and markers, mm; a `noise_mm` column overrides it per row.
    #[arg(long, default_value_t = 0.4, value_name = "MM")]
    pub noise_mm: f64,
    /// Noise of the tip angle, degrees; a `noise_deg` column overrides it per row.
    #[arg(long, default_value_t = 1.0, value_name = "DEG")]
    pub noise_deg: f64,
    /// Hold a parameter at a value instead of fitting it (repeatable): EA, GA, EI or an effect parameter, e.g. GA=1.70866 or friction_mu=0.05.
    #[arg(long = "fix", value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Loss on the noise-whitened residuals: huber (robust to a few bad readings) or squares.
    #[arg(long, default_value = "huber", value_name = "LOSS")]
    pub loss: String,
    /// Where the Huber loss turns linear, in noise σ.
    #[arg(long, default_value_t = 3.0, value_name = "SIGMA")]
    pub huber_k: f64,
    /// Most Levenberg–Marquardt iterations per fit.
    #[arg(long, default_value_t = 200)]
    pub max_iterations: usize,
    /// Measured centreline points (measurement,x_mm,y_mm), fitted as distances to the simulated centreline.
    #[arg(long, value_name = "FILE")]
    pub centrelines: Option<PathBuf>,
    /// Markers off the centreline (measurement,s_mm,offset_mm,x_mm,y_mm), fitted by position.
    #[arg(long, value_name = "FILE")]
    pub markers: Option<PathBuf>,
    /// Weight of the tip angle in the reported mm-equivalent RMS, mm per degree (the fit weights by the noise).
    #[arg(long, default_value_t = 1.0, value_name = "MM_PER_DEG")]
    pub angle_weight: f64,
}

impl FitArgs {
    /// The fit settings and the starting actuator with held values set;
    /// also returns the held effects.
    pub fn spec(&self, base: &Rod, data: &Dataset) -> anyhow::Result<(FitSpec, Rod, Vec<Effect>)> {
        let mut held: Vec<(Held, f64)> = Vec::new();
        for item in &self.fix {
            let Some((name, value)) = item.split_once('=') else {
                bail!("--fix {item}: expected NAME=VALUE, e.g. GA=1.70866");
            };
            let Some(h) = parse_held(name) else {
                let effects: Vec<&str> = Effect::ALL.iter().map(|e| e.parameter_name()).collect();
                bail!("--fix {item}: unknown parameter '{name}'; use EA, GA, EI or one of {}", effects.join(", "));
            };
            let Ok(v) = value.trim().parse::<f64>() else {
                bail!("--fix {item}: '{value}' is not a number");
            };
            held.push((h, v));
        }
        let (start, fixed_rigidities, held_effects) = apply_held(base, &held).context("--fix")?;
        let loss = match self.loss.as_str() {
            "huber" => {
                if !(self.huber_k.is_finite() && self.huber_k > 0.0) {
                    bail!("--huber-k {}: must be a number of σ > 0", self.huber_k);
                }
                Loss::Huber { k: self.huber_k }
            }
            "squares" => Loss::Squared,
            other => bail!("--loss {other}: use huber or squares"),
        };
        if self.max_iterations == 0 {
            bail!("--max-iterations must be at least 1");
        }
        let mut shapes = ShapeData::default();
        if let Some(p) = &self.centrelines {
            shapes.centrelines = read_centrelines(p, data)?;
        }
        if let Some(p) = &self.markers {
            shapes.markers = read_markers(p, data, start.length_mm)?;
        }
        let noise = Noise { mm: self.noise_mm, deg: self.noise_deg };
        noise.validate().context("--noise-mm / --noise-deg")?;
        let spec = FitSpec {
            effects: Vec::new(),
            angle_weight_mm_per_deg: self.angle_weight,
            noise,
            loss,
            fixed_rigidities,
            max_iterations: self.max_iterations,
            shapes: Arc::new(shapes),
        };
        Ok((spec, start, held_effects))
    }
}

/// Arguments of `cablemap calibrate`.
#[derive(Debug, Clone, Args)]
pub struct CalibrateArgs {
    /// Measurement file (CSV, or Parquet by its .parquet extension); see docs/measurements.md.
    pub data: PathBuf,
    /// Leave this routing out of the fit and report the error on it.
    #[arg(long, value_name = "ROUTING")]
    pub holdout: Option<String>,
    /// Noise, held parameters, loss, shapes.
    #[command(flatten)]
    pub fit: FitArgs,
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
    let data = read_measurements(&args.data)?;
    let base = args.actuator.resolve(data.actuator.as_ref())?;
    base.validate()?;
    let options = args.actuator.solver_options(&SolverOptions::default());
    let (train, held) = split_holdout(&data, args.holdout.as_deref()).context("--holdout")?;
    let (mut spec, start, held_effects) = args.fit.spec(&base, &data)?;
    spec.effects = parse_effects(&args.effects)?;
    if let Some(e) = spec.effects.iter().find(|e| held_effects.contains(e)) {
        bail!("--effect {0} and --fix {1}=…: an effect is either fitted or held, not both", e.name(), e.parameter_name());
    }
    let large = data.rows.len() >= LARGE_DATA_ROWS;
    if large {
        // A fit re-simulates every reading (1 + parameters) times per
        // iteration: state the cost of one pass up front for large files,
        // so a long silent run is expected rather than mistaken for a hang.
        let started = std::time::Instant::now();
        predict(&start, &options, &data, &train, false)?;
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
    let result = fit_observed(&start, &options, &data, &train, &spec, &mut |p| {
        if large {
            eprintln!("calibrate: iteration {} (of at most 200): RMS {:.4} mm", p.iteration, p.rms_mm);
        }
    })?;
    let holdout_rms = match &held {
        Some(g) => {
            let g = std::slice::from_ref(g);
            let preds = predict(&result.actuator, &options, &data, g, false)?;
            Some(rms_per_routing(&data, g, &preds, spec.angle_weight_mm_per_deg)[0].clone())
        }
        None => None,
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        let mut v = fit_json(&result);
        v["holdout"] = serde_json::to_value(&holdout_rms)?;
        let held: serde_json::Map<String, serde_json::Value> =
            held_effects.iter().map(|e| (e.parameter_name().to_string(), serde_json::json!(e.current(&start).unwrap_or(0.0)))).collect();
        v["held_effects"] = serde_json::Value::Object(held);
        writeln!(out, "{v}")?;
        return Ok(());
    }
    let readings: usize = train.iter().map(|g| g.rows.len()).sum();
    writeln!(
        out,
        "fit of {readings} readings on {} routings ({} residuals weighted by noise {} mm, {}°; {})",
        train.len(),
        result.n_residuals,
        spec.noise.mm,
        spec.noise.deg,
        spec.loss.describe()
    )?;
    for p in &result.parameters {
        if p.fixed {
            writeln!(out, "  {:<30} {:>14.6}   (held)", p.name, p.value)?;
        } else {
            writeln!(out, "  {:<30} {:>14.6} ± {}", p.name, p.value, cablemap::io::fmt_sig(p.se, 3))?;
        }
    }
    for e in &held_effects {
        let v = e.current(&start).unwrap_or(0.0);
        writeln!(out, "  {:<30} {:>14.6}   (held)", e.parameter_name(), v)?;
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
            if c.is_finite() {
                write!(out, " {c:>+9.3}")?;
            } else {
                write!(out, " {:>9}", "—")?;
            }
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
    writeln!(
        out,
        "overall tip RMS {:.4} mm; χ² = {:.1} on {} dof (χ²/dof = {:.3}, {}){}",
        result.rms_mm,
        result.chi2,
        result.dof,
        result.reduced_chi2,
        cablemap::calibrate::report::p_text(result.p_value),
        if result.p_value < 1e-3 { ": well above the stated noise (p < 1e-3)" } else { ": consistent with the stated noise" }
    )?;
    if !result.outliers.is_empty() {
        writeln!(out, "outliers set aside in the χ² test (measurement ids): {:?}", result.outliers)?;
    }
    writeln!(out, "{} iterations{}", result.iterations, if result.converged { ", converged" } else { ": NOT converged (iteration cap or an unsolvable model near the optimum); do not trust these values" })?;
    for f in &result.flags {
        writeln!(out, "warning: {f}")?;
    }
    writeln!(out, "cable stretch is not fitted: under tension control it is not identifiable")?;
    Ok(())
}
