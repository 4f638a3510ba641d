//! `cablemap calibrate DATA`: fits EA, GA, EI (thesis eq. 2.14) to
//! measurements and reports them with standard errors, correlations and the
//! RMS error per routing.

use super::ActuatorArgs;
use cablemap::calibrate::request::{effects_by_name, FitInput};
use cablemap::calibrate::{run_observed, CalibrateError, CalibrateRequest, FitSettings, HoldoutError, LossKind, Parameter};
use cablemap::solver::SolverOptions;
use clap::Args;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Settings every fit shares (calibrate and diagnose).
#[derive(Debug, Clone, Args)]
pub struct FitArgs {
    /// Noise (standard deviation) of tip x, y, centreline points and markers, mm; a `noise_mm` column overrides it per row.
    #[arg(long, default_value_t = 0.4, value_name = "MM")]
    pub noise_mm: f64,
    /// Noise of the tip angle, degrees; a `noise_deg` column overrides it per row.
    #[arg(long, default_value_t = 1.0, value_name = "DEG")]
    pub noise_deg: f64,
    /// Hold a parameter at a value instead of fitting it (repeatable): EA, GA, EI or an effect parameter, e.g. GA=1.70866.
    #[arg(long = "fix", value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Loss on the noise-whitened residuals: huber (robust to a few bad readings) or squares
    /// [default: huber; squares for captures with --actuator].
    #[arg(long, value_name = "LOSS")]
    pub loss: Option<String>,
    /// Where the Huber loss turns linear, in noise σ.
    #[arg(long, default_value_t = 3.0, value_name = "SIGMA")]
    pub huber_k: f64,
    /// Most Levenberg–Marquardt iterations per fit.
    #[arg(long, default_value_t = 200)]
    pub max_iterations: usize,
    /// Measured centreline points (measurement,x_mm,y_mm), fitted as distances to the simulated centreline.
    #[arg(long, value_name = "FILE")]
    pub centrelines: Option<PathBuf>,
    /// Markers off the centreline (measurement,s_mm,offset_mm,x_mm,y_mm), fitted by position; with
    /// --actuator, 3-D markers (measurement,marker,s_mm,offset_y_mm,offset_z_mm,x_mm,y_mm,z_mm[,sd_mm]).
    #[arg(long, value_name = "FILE")]
    pub markers: Option<PathBuf>,
    /// Weight of the tip angle in the reported mm-equivalent RMS, mm per degree (the fit weights by the noise).
    #[arg(long, default_value_t = 1.0, value_name = "MM_PER_DEG")]
    pub angle_weight: f64,
}

impl FitArgs {
    /// What the fit is given: the data (captures with `actuator_file`),
    /// the rod and solver flags, these settings and what is held out.
    pub fn input(&self, data: &Path, actuator_file: Option<&Path>, actuator: &ActuatorArgs, holdout: Option<&str>, holdout_cable: Option<usize>) -> anyhow::Result<FitInput> {
        Ok(FitInput {
            data_path: data.to_path_buf(),
            actuator_file: actuator_file.map(Path::to_path_buf),
            rod: actuator.overrides(),
            options: actuator.solver_options(&SolverOptions::default()),
            fit: self.settings()?,
            holdout: holdout.map(str::to_string),
            holdout_cable,
        })
    }

    /// The fit settings the flags describe.
    pub fn settings(&self) -> anyhow::Result<FitSettings> {
        let held = self.fix.iter().map(|item| Parameter::parse_held(item)).collect::<Result<Vec<_>, _>>()?;
        Ok(FitSettings {
            noise_mm: self.noise_mm,
            noise_deg: self.noise_deg,
            held,
            loss: self.loss.as_deref().map(LossKind::parse).transpose()?,
            huber_k: self.huber_k,
            max_iterations: self.max_iterations,
            centrelines: self.centrelines.clone(),
            markers: self.markers.clone(),
            angle_weight_mm_per_deg: self.angle_weight,
        })
    }
}

/// Names the flag behind a fit's setting errors (`--holdout` too, with `holdout_flag`).
pub fn with_flag(e: CalibrateError, holdout_flag: bool) -> anyhow::Error {
    match e {
        CalibrateError::Held(inner) => anyhow::Error::new(inner).context("--fix"),
        CalibrateError::ActuatorFile(_) => anyhow::Error::new(e).context("--actuator-file"),
        CalibrateError::Noise(_) => anyhow::Error::new(e).context("--noise-mm / --noise-deg"),
        CalibrateError::Holdout(HoldoutError::UnknownRouting { .. } | HoldoutError::OnlyRouting { .. }) if holdout_flag => anyhow::Error::new(e).context("--holdout"),
        e => anyhow::Error::new(e),
    }
}

/// Arguments of `cablemap calibrate`.
#[derive(Debug, Clone, Args)]
pub struct CalibrateArgs {
    /// Measurement file (CSV, or Parquet by its .parquet extension); with --actuator, the captures
    /// file (one tension_K_n or displacement_K_mm column per cable); see docs/measurements.md.
    pub data: PathBuf,
    /// A whole actuator (rod, torsion, gravity, cables) as TOML: calibrate several-cable captures
    /// against 3-D markers (--markers) with the 3-D solver; the start and everything not fitted.
    #[arg(long = "actuator", value_name = "FILE.toml")]
    pub spatial_actuator: Option<PathBuf>,
    /// With --actuator: write DIR/calibrated.toml (the fitted actuator) and DIR/fit.json.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// With --actuator: fit on the captures where cable K does not pull, predict the others.
    #[arg(long, value_name = "K")]
    pub holdout_cable: Option<usize>,
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

/// Runs `cablemap calibrate`.
pub fn run(args: &CalibrateArgs) -> anyhow::Result<()> {
    let request = CalibrateRequest {
        input: args.fit.input(&args.data, args.spatial_actuator.as_deref(), &args.actuator, args.holdout.as_deref(), args.holdout_cable)?,
        effects: effects_by_name(&args.effects)?,
        out: args.out.clone(),
    };
    // Progress on stderr (stdout may be --json).
    let report = run_observed(&request, &mut |p| eprintln!("{p}")).map_err(|e| with_flag(e, true))?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", report.to_json_line())?;
    } else {
        write!(out, "{report}")?;
    }
    Ok(())
}
