//! The workflows behind `cablemap predict` and `cablemap calibrate` with
//! `--actuator FILE.toml --markers MARKERS`: requests in, reports out.
//!
//! [`predict`] simulates every capture with the given actuator (no
//! fitting) and reports the markers' 3-D errors. [`calibrate`] fits the
//! rigidities, the weight and any effect asked for, optionally on the
//! captures where one cable does not pull (the others held out and
//! predicted), and writes `calibrated.toml` and `fit.json`.

use super::errors::ErrorReport;
use super::files::{read_capture_set, CaptureSet};
use crate::calibrate::fit::{fit, FitResult, FitSpec, Status};
use crate::calibrate::observations::captures::{Captures, CapturesReport};
use crate::calibrate::Parameter;
use super::simulate::solve_captures;
use super::diagnose::{diagnose_captures, Diagnose3Spec, Diagnosis3};
use crate::calibrate::request::{DiagnoseRequest, LossKind};
use crate::calibrate::Refused;
use crate::calibrate::{CalibrateError, CalibrateRequest};
use crate::solver::SolverOptions;
use crate::model::{Actuator, RodOverrides};
use serde::Serialize;
use std::fmt;
use std::path::{Path, PathBuf};

/// What `predict` needs.
#[derive(Debug, Clone)]
pub struct PredictRequest {
    /// The captures file.
    pub captures: PathBuf,
    /// The markers file (optional when the captures file has tip columns).
    pub markers: Option<PathBuf>,
    /// The actuator file.
    pub actuator: PathBuf,
    /// Rod settings: refused, the rod is the actuator file's.
    pub rod: RodOverrides,
    /// The 3-D solver's settings.
    pub options: SolverOptions,
}

/// The markers' errors of a prediction; serialises to `predict --json`.
#[derive(Debug, Clone, Serialize)]
pub struct PredictReport {
    /// The actuator file used.
    pub actuator: String,
    /// The errors.
    #[serde(flatten)]
    pub errors: ErrorReport,
}

fn read_actuator(path: &Path) -> Result<Actuator, CalibrateError> {
    Actuator::read(path).map_err(|e| CalibrateError::Actuator(e.into()))
}

fn read_set(captures: &Path, markers: Option<&Path>, actuator: &Actuator) -> Result<CaptureSet, CalibrateError> {
    read_capture_set(captures, markers, actuator.cables.len(), actuator.rod.length_mm)
}

/// Simulates every capture with the request's actuator and reports the errors.
pub fn predict(request: &PredictRequest) -> Result<PredictReport, CalibrateError> {
    if !request.rod.is_empty() {
        return Err(Refused::RodOnPredict.into());
    }
    let actuator = read_actuator(&request.actuator)?;
    let set = read_set(&request.captures, request.markers.as_deref(), &actuator)?;
    let solutions = solve_captures(&actuator, &request.options, &set)?;
    Ok(PredictReport { actuator: request.actuator.display().to_string(), errors: ErrorReport::of(&set, &solutions) })
}

impl PredictReport {
    /// The `--json` object on one line.
    pub fn to_json_line(&self) -> String {
        serde_json::to_value(self).expect("a report serialises").to_string()
    }
}

impl fmt::Display for PredictReport {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(out, "prediction with {} (no fitting)", self.actuator)?;
        write!(out, "{}", self.errors)
    }
}

/// A finished calibration on captures with 3-D markers; serialises to `fit.json`.
#[derive(Debug, Clone, Serialize)]
pub struct CapturesCalibration {
    /// The fit on the fitted captures.
    #[serde(flatten)]
    pub fit: FitResult<CapturesReport>,
    /// Parameters held at a given value (`--fix`).
    pub held: Vec<(String, f64)>,
    /// The held-out cable (1-based), if any.
    pub holdout_cable: Option<usize>,
    /// The errors on the held-out captures, predicted with the fitted actuator.
    pub holdout: Option<ErrorReport>,
    /// Captures fitted.
    pub captures_fitted: usize,
    /// Wall time of the fit, s.
    pub elapsed_s: f64,
    /// The files written.
    #[serde(skip)]
    pub written: Vec<PathBuf>,
}

impl CapturesCalibration {
    /// `fit.json`'s text (pretty-printed).
    pub fn to_json_pretty(&self) -> String {
        serde_json::to_string_pretty(self).expect("a report serialises")
    }

    /// One line of JSON.
    pub fn to_json_line(&self) -> String {
        serde_json::to_value(self).expect("a report serialises").to_string()
    }
}

/// The actuator file of a fit: the start with the fitted values, and a
/// header saying where they came from.
pub fn calibrated_toml(report: &CapturesCalibration, source: &Path) -> Result<String, CalibrateError> {
    let body = toml::to_string(&report.fit.actuator).map_err(crate::calibrate::InvalidRequest::CalibratedToml)?;
    let mut head = format!("# cablemap calibrate: {} fitted to {} captures, starting from {}\n", fitted_names(&report.fit), report.captures_fitted, source.display());
    for p in &report.fit.parameters {
        match p.status {
            Status::Fitted => head.push_str(&format!("#   {} = {} ± {}\n", p.name, p.value, crate::io::fmt_sig(p.se, 3))),
            Status::Held => head.push_str(&format!("#   {} = {} (held)\n", p.name, p.value)),
            Status::Undetermined => head.push_str(&format!("#   {} = {} (undetermined by the data: held at its start)\n", p.name, p.value)),
            Status::AtBound => head.push_str(&format!("#   {} = {} (run to the bound of its range: the data do not call for it)\n", p.name, p.value)),
        }
    }
    head.push_str(&format!("#   marker RMS {:.3} mm; χ²/dof {:.3}\n", report.fit.errors.rms_mm, report.fit.reduced_chi2));
    Ok(head + &body)
}

fn fitted_names(fit: &FitResult<CapturesReport>) -> String {
    let names: Vec<&str> = fit.parameters.iter().filter(|p| p.status == Status::Fitted).map(|p| p.name.as_str()).collect();
    if names.is_empty() {
        "nothing".into()
    } else {
        names.join(", ")
    }
}

/// Runs a calibration of the actuator in `actuator_file` on the request's
/// captures, reporting each accepted step to `observe`.
pub fn calibrate(request: &CalibrateRequest, actuator_file: &Path, observe: &mut dyn FnMut(crate::numerics::lm::Step)) -> Result<CapturesCalibration, CalibrateError> {
    let started = std::time::Instant::now();
    let loss = request.fit.loss(LossKind::Squares)?;
    let mut base = read_actuator(actuator_file)?;
    let set = read_set(&request.data_path, request.fit.markers.as_deref(), &base)?;
    for &(p, v) in &request.fit.held {
        if !(v.is_finite() && (matches!(p, Parameter::Effect(_)) || v > 0.0)) {
            return Err(CalibrateError::Held(crate::calibrate::HeldError::NotPositive { name: p.name(), value: v }));
        }
        p.set(&mut base, v);
    }
    let is_held = |p: Parameter| request.fit.held.iter().any(|(h, _)| *h == p);
    if let Some(&e) = request.effects.iter().find(|&&e| is_held(Parameter::Effect(e))) {
        return Err(CalibrateError::FittedAndHeld { effect: e });
    }
    let mut params: Vec<Parameter> = Parameter::BODY.iter().copied().filter(|&p| !is_held(p)).collect();
    if !base.rod.gravity.enabled {
        params.retain(|&p| p != Parameter::Density);
    }
    params.extend(request.effects.iter().map(|&e| Parameter::Effect(e)));
    let (train, test) = match request.holdout_cable {
        None => (set, None),
        Some(k) => {
            if k == 0 || k > base.cables.len() {
                return Err(crate::calibrate::HoldoutError::NoSuchCable { cable: k, cables: base.cables.len() }.into());
            }
            let train = set.subset(|c| !c.pulling_cables().contains(&k));
            let test = set.subset(|c| c.pulling_cables().contains(&k));
            if train.captures.is_empty() || test.captures.is_empty() {
                return Err(crate::calibrate::HoldoutError::NotSeparable { cable: k, pulling: test.captures.len(), others: train.captures.len() }.into());
            }
            (train, Some(test))
        }
    };
    let spec = FitSpec { params, held: Vec::new(), loss, max_iterations: request.fit.max_iterations };
    let fit = fit(&base, &Captures::new(&train, request.fit.noise_mm, &request.options), &spec, observe)?;
    let holdout = match &test {
        Some(t) => Some(ErrorReport::of(t, &solve_captures(&fit.actuator, &request.options, t)?)),
        None => None,
    };
    let mut report = CapturesCalibration {
        held: request.fit.held.iter().map(|(p, v)| (p.name().to_string(), *v)).collect(),
        holdout_cable: request.holdout_cable,
        holdout,
        captures_fitted: train.captures.len(),
        elapsed_s: started.elapsed().as_secs_f64(),
        written: Vec::new(),
        fit,
    };
    if let Some(dir) = &request.out {
        let io = |context: String| move |source| CalibrateError::Io { context, source };
        std::fs::create_dir_all(dir).map_err(io(format!("creating {}", dir.display())))?;
        let toml_path = dir.join("calibrated.toml");
        std::fs::write(&toml_path, calibrated_toml(&report, actuator_file)?).map_err(io(format!("writing {}", toml_path.display())))?;
        let json_path = dir.join("fit.json");
        std::fs::write(&json_path, report.to_json_pretty() + "\n").map_err(io(format!("writing {}", json_path.display())))?;
        report.written = vec![toml_path, json_path];
    }
    Ok(report)
}

impl fmt::Display for CapturesCalibration {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        let fit = &self.fit;
        writeln!(
            out,
            "3-D fit of {} captures ({} marker coordinates, noise √(sd² + {} mm²) each); {:.1} s",
            self.captures_fitted,
            fit.n_residuals,
            fit.noise_mm,
            self.elapsed_s
        )?;
        for p in &fit.parameters {
            match p.status {
                Status::Fitted => writeln!(out, "  {:<24} {:>14.6} ± {:<10}  (start {})", p.name, p.value, crate::io::fmt_sig(p.se, 3), crate::io::fmt_sig(p.start, 6))?,
                Status::Held => writeln!(out, "  {:<24} {:>14.6}   (held)", p.name, p.value)?,
                Status::Undetermined => writeln!(out, "  {:<24} {:>14.6}   undetermined by these data: held at its start", p.name, p.value)?,
                Status::AtBound => writeln!(out, "  {:<24} {:>14.6}   at the bound of its range: the data do not call for it", p.name, p.value)?,
            }
        }
        for (name, v) in &self.held {
            writeln!(out, "  {name:<24} {v:>14.6}   (held)")?;
        }
        write!(out, "{}", fit.errors)?;
        writeln!(
            out,
            "χ² = {:.1} on {} dof (χ²/dof = {:.3}, {}){}",
            fit.chi2,
            fit.dof,
            fit.reduced_chi2,
            crate::calibrate::stats::p_text(fit.p_value),
            if fit.p_value < 1e-3 { ": the model misses the markers by more than the stated noise" } else { ": consistent with the stated noise" }
        )?;
        writeln!(out, "{} iterations: {}", fit.iterations, fit.report.termination)?;
        if let (Some(k), Some(h)) = (self.holdout_cable, &self.holdout) {
            writeln!(out, "held out: the {} captures where cable {k} pulls, predicted with the fitted actuator:", h.captures.len())?;
            write!(out, "{h}")?;
        }
        for p in &self.written {
            writeln!(out, "wrote {}", p.display())?;
        }
        Ok(())
    }
}

/// Reads the request's files, runs [`diagnose_captures`] and writes the
/// report directory when asked for (refused first when inside a sweep run,
/// before anything is read); the report's files are in `written`.
pub fn diagnose_request(request: &DiagnoseRequest, actuator_file: &Path) -> Result<Diagnosis3, CalibrateError> {
    if !request.fit.held.is_empty() {
        return Err(Refused::HeldInCapturesDiagnosis.into());
    }
    let loss = request.fit.loss(LossKind::Squares)?;
    if let Some(dir) = &request.report_dir {
        crate::io::check_outside_run_dir(dir, "the report directory")?;
    }
    let base = Actuator::read(actuator_file).map_err(|e| CalibrateError::Actuator(e.into()))?;
    let set = read_capture_set(&request.data_path, request.fit.markers.as_deref(), base.cables.len(), base.rod.length_mm)?;
    let mut params: Vec<Parameter> = Parameter::BODY.to_vec();
    if !base.rod.gravity.enabled {
        params.retain(|&p| p != Parameter::Density);
    }
    let spec = Diagnose3Spec {
        fit: FitSpec { params, held: Vec::new(), loss, max_iterations: request.fit.max_iterations },
        noise_mm: request.fit.noise_mm,
        options: request.options.clone(),
        holdout_cable: request.holdout_cable,
        threshold: request.threshold,
        margin: request.margin,
        max_effects: request.max_effects,
        alpha: request.alpha,
    };
    let mut d = diagnose_captures(&base, &set, &spec)?;
    if let Some(dir) = &request.report_dir {
        let sources = super::report::ReportSources { captures: &request.data_path, markers: request.fit.markers.as_deref(), actuator: actuator_file };
        d.written = super::report::write_report(dir, sources, &set, &d, &request.options)?;
    }
    Ok(d)
}
