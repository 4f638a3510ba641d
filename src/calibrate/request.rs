//! What `calibrate`, `diagnose` and `predict` are asked, as given. The
//! input decides the kind of data: with an actuator file they are captures
//! with 3-D markers (one actuation column per cable, the 3-D solver),
//! without one planar measurements (tip readings of one in-plane cable).
//! Each request checks once what its kind refuses ([`Refused`]); the
//! command line and Python only fill the fields.

use super::fit::Loss;
use super::observations::measurements::Noise;
use super::{CalibrateError, Effect, HeldError, InvalidRequest, NoiseError, Parameter, Refused};
use crate::model::RodOverrides;
use crate::solver::{SolverOptions, SolverSettings};
use serde::{Deserialize, Deserializer};
use std::path::{Path, PathBuf};

/// The loss on the noise-whitened residuals, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LossKind {
    /// Huber's: quadratic up to `huber_k` σ, linear beyond.
    Huber,
    /// Plain squares.
    Squares,
}

impl LossKind {
    /// `huber` or `squares`.
    pub fn parse(name: &str) -> Result<LossKind, InvalidRequest> {
        match name {
            "huber" => Ok(LossKind::Huber),
            "squares" => Ok(LossKind::Squares),
            other => Err(InvalidRequest::Loss { name: other.to_string() }),
        }
    }
}

/// Settings every fit shares (calibrate and diagnose), as given; the kind
/// of data fills what is left open. Deserialises from the flags' names.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct FitSettings {
    /// Noise of tip x, y, centreline points and markers (planar rows
    /// without their own), and the system's noise added to each 3-D
    /// marker's own, mm.
    pub noise_mm: f64,
    /// Noise of the tip angle (planar rows without their own), degrees.
    pub noise_deg: f64,
    /// Parameters held at a value instead of fitted (`--fix NAME=VALUE`, each).
    #[serde(rename = "fix", deserialize_with = "held_items")]
    pub held: Vec<(Parameter, f64)>,
    /// The loss; `None`: Huber's for tip readings, squares for 3-D markers.
    #[serde(deserialize_with = "loss_name")]
    pub loss: Option<LossKind>,
    /// Where Huber's loss turns linear, in σ.
    pub huber_k: f64,
    /// Most Levenberg–Marquardt iterations per fit.
    pub max_iterations: usize,
    /// Measured centreline points (planar: measurement, x_mm, y_mm).
    pub centrelines: Option<PathBuf>,
    /// Markers: off the planar centreline, or the 3-D markers of captures.
    pub markers: Option<PathBuf>,
    /// Weight of the tip angle in reported mm-equivalent RMS values, mm per degree.
    #[serde(rename = "angle_weight")]
    pub angle_weight_mm_per_deg: f64,
}

impl Default for FitSettings {
    fn default() -> Self {
        let noise = Noise::default();
        Self {
            noise_mm: noise.mm,
            noise_deg: noise.deg,
            held: Vec::new(),
            loss: None,
            huber_k: 3.0,
            max_iterations: 200,
            centrelines: None,
            markers: None,
            angle_weight_mm_per_deg: 1.0,
        }
    }
}

impl FitSettings {
    /// The loss asked for, else `default`; Huber's `k` is checked when it is used.
    pub fn loss(&self, default: LossKind) -> Result<Loss, InvalidRequest> {
        match self.loss.unwrap_or(default) {
            LossKind::Squares => Ok(Loss::Squared),
            LossKind::Huber if self.huber_k.is_finite() && self.huber_k > 0.0 => Ok(Loss::Huber { k: self.huber_k }),
            LossKind::Huber => Err(InvalidRequest::HuberK { k: self.huber_k }),
        }
    }

    /// The planar rows' noise.
    pub fn noise(&self) -> Noise {
        Noise { mm: self.noise_mm, deg: self.noise_deg }
    }
}

/// The kind of data a request reads, decided by its input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DataKind<'a> {
    /// Planar measurements: tip readings of one in-plane cable.
    Measurements,
    /// Captures with 3-D markers of the actuator in this file.
    Captures {
        /// The actuator file.
        actuator_file: &'a Path,
    },
}

/// What every fit is given (calibrate and diagnose): the data, the
/// actuator file that makes them captures, the rod's overrides, the
/// solver's and the fit's settings and what is held out. Deserialises
/// from the Python keywords' names, flat in each request.
#[derive(Debug, Clone, Deserialize)]
pub struct FitInput {
    /// The measurement file, or (with `actuator_file`) the captures file
    /// (CSV, or Parquet by its extension).
    #[serde(rename = "data")]
    pub data_path: PathBuf,
    /// A whole actuator (rod, torsion, gravity, cables) as TOML: the data
    /// are captures with 3-D markers, and it is the start and everything
    /// not fitted.
    #[serde(rename = "actuator", default)]
    pub actuator_file: Option<PathBuf>,
    /// Planar data: starting values and fixed parameters, overrides on the
    /// rod file's, else the measurement file's, else the thesis's rod
    /// (validated here).
    #[serde(rename = "rod_fields", default)]
    pub rod: RodOverrides,
    /// The solver's settings.
    #[serde(rename = "solver", default, deserialize_with = "SolverSettings::deserialize_options")]
    pub options: SolverOptions,
    /// Noise, held parameters, loss, shapes.
    #[serde(flatten)]
    pub fit: FitSettings,
    /// Planar data: a routing left out of every fit, whose error is reported.
    #[serde(default)]
    pub holdout: Option<String>,
    /// Captures: fit on those where this cable (1-based) does not pull,
    /// predict (or, diagnosing, show the gap on) the others.
    #[serde(default)]
    pub holdout_cable: Option<usize>,
}

impl FitInput {
    /// A fit of `data_path` with the defaults (planar unless an actuator
    /// file is set).
    pub fn new(data_path: PathBuf) -> Self {
        Self {
            data_path,
            actuator_file: None,
            rod: RodOverrides::default(),
            options: SolverOptions::default(),
            fit: FitSettings::default(),
            holdout: None,
            holdout_cable: None,
        }
    }

    /// The kind of data, with what captures refuse, the markers' noise and
    /// the held parameters planar data cannot hold checked.
    fn check(&self) -> Result<DataKind<'_>, CalibrateError> {
        let kind = match &self.actuator_file {
            Some(actuator_file) => DataKind::Captures { actuator_file },
            None => DataKind::Measurements,
        };
        let fit = &self.fit;
        if let DataKind::Captures { .. } = kind {
            if self.holdout.is_some() {
                return Err(Refused::RoutingHoldoutOnCaptures.into());
            }
            if fit.centrelines.is_some() {
                return Err(Refused::CentrelinesOnCaptures.into());
            }
            if !self.rod.is_empty() {
                return Err(Refused::RodOnCaptures.into());
            }
            if !(fit.noise_mm.is_finite() && fit.noise_mm > 0.0) {
                return Err(NoiseError::Markers { value: fit.noise_mm }.into());
            }
        }
        if fit.max_iterations == 0 {
            return Err(Refused::NoIterations.into());
        }
        if kind == DataKind::Measurements {
            if let Some(&(p, _)) = fit.held.iter().find(|(p, _)| !p.is_planar()) {
                return Err(CalibrateError::Held(HeldError::NotPlanar { name: p.name() }));
            }
        }
        Ok(kind)
    }
}

/// Everything a calibration needs.
#[derive(Debug, Clone, Deserialize)]
pub struct CalibrateRequest {
    /// The data and the fit's settings.
    #[serde(flatten)]
    pub input: FitInput,
    /// Effects whose parameters are fitted with the rigidities (by name,
    /// each once).
    #[serde(default, deserialize_with = "effect_names")]
    pub effects: Vec<Effect>,
    /// Captures: where to write `calibrated.toml` and `fit.json`.
    #[serde(default)]
    pub out: Option<PathBuf>,
}

impl CalibrateRequest {
    /// A request on `data_path` with the defaults (planar unless an
    /// actuator file is set).
    pub fn new(data_path: PathBuf) -> Self {
        Self { input: FitInput::new(data_path), effects: Vec::new(), out: None }
    }

    /// The kind of data, with the settings it refuses checked.
    pub fn check(&self) -> Result<DataKind<'_>, CalibrateError> {
        let kind = self.input.check()?;
        if kind == DataKind::Measurements && (self.out.is_some() || self.input.holdout_cable.is_some()) {
            return Err(Refused::CapturesSettingsOnMeasurements.into());
        }
        Ok(kind)
    }
}

/// Everything a diagnosis needs.
#[derive(Debug, Clone, Deserialize)]
pub struct DiagnoseRequest {
    /// The data and the fits' settings.
    #[serde(flatten)]
    pub input: FitInput,
    /// A model is consistent with the noise when the χ² test's p ≥ this.
    pub alpha: f64,
    /// BIC decrease an effect needs against the model without it.
    pub threshold: f64,
    /// BIC lead an effect needs over the runner-up.
    pub margin: f64,
    /// Most effects added (forward-stepwise; at least 1).
    pub max_effects: usize,
    /// Report directory (report.md and PNG pictures); with `write_report`
    /// and none, [`DiagnoseRequest::default_report_dir`].
    #[serde(default)]
    pub out: Option<PathBuf>,
    /// Write the report and its pictures (`--no-report` turns it off).
    #[serde(rename = "report")]
    pub write_report: bool,
}

impl DiagnoseRequest {
    /// A request on `data_path` with the defaults of `diagnose`: α = 1e-3,
    /// BIC threshold and margin 10, at most two effects, no report.
    pub fn new(data_path: PathBuf) -> Self {
        Self { input: FitInput::new(data_path), alpha: 1e-3, threshold: 10.0, margin: 10.0, max_effects: 2, out: None, write_report: false }
    }

    /// The kind of data, with the settings it refuses checked.
    pub fn check(&self) -> Result<DataKind<'_>, CalibrateError> {
        let kind = self.input.check()?;
        if kind == DataKind::Measurements && self.input.holdout_cable.is_some() {
            return Err(Refused::CableHoldoutOnMeasurements.into());
        }
        Ok(kind)
    }

    /// Where the report goes: `out`, else beside the data; none without
    /// `write_report`.
    pub fn report_dir(&self) -> Option<PathBuf> {
        self.write_report.then(|| self.out.clone().unwrap_or_else(|| Self::default_report_dir(&self.input.data_path)))
    }

    /// The report directory when none is given: beside the data file, named
    /// after it (measurements.csv → measurements-diagnosis/), so that a run
    /// never litters the current directory.
    pub fn default_report_dir(data_path: &Path) -> PathBuf {
        let stem = data_path.file_stem().map_or_else(|| "measurements".into(), |s| s.to_string_lossy().into_owned());
        data_path.with_file_name(format!("{stem}-diagnosis"))
    }
}

/// The effects of `names` (`--effect`, each; Python's `effects=`), each
/// once, in order.
pub fn effects_by_name(names: &[String]) -> Result<Vec<Effect>, InvalidRequest> {
    let mut effects = Vec::new();
    for name in names {
        let effect = Effect::parse(name).ok_or_else(|| InvalidRequest::UnknownEffect { name: name.clone() })?;
        if !effects.contains(&effect) {
            effects.push(effect);
        }
    }
    Ok(effects)
}

/// Effects by name, each once.
fn effect_names<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<Effect>, D::Error> {
    effects_by_name(&Vec::<String>::deserialize(deserializer)?).map_err(serde::de::Error::custom)
}

/// Held parameters from their `NAME=VALUE` items (`--fix`, each).
fn held_items<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<(Parameter, f64)>, D::Error> {
    Vec::<String>::deserialize(deserializer)?.iter().map(|item| Parameter::parse_held(item)).collect::<Result<_, _>>().map_err(serde::de::Error::custom)
}

/// The loss by its name, or none.
fn loss_name<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Option<LossKind>, D::Error> {
    Option::<String>::deserialize(deserializer)?.as_deref().map(LossKind::parse).transpose().map_err(serde::de::Error::custom)
}
