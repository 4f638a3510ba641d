//! The calibration workflow behind `cablemap calibrate`: fit EA, GA, EI
//! (thesis eq. 2.14) and any chosen effects to planar measurements, and
//! report them with standard errors, correlations and the RMS error per
//! routing (and on a held-out routing); or, on captures with 3-D markers,
//! the actuator's rigidities, weight and effects
//! (`calibrate_captures`).
//!
//! [`run`] takes a [`CalibrateRequest`] and returns a [`CalibrateReport`],
//! which serialises itself (the `--json` object) and displays itself (the
//! text report).

use super::data::{read_centrelines, read_markers, read_measurements, split_holdout, Dataset};
use super::fit::{FitResult, FitSpec, Loss};
use super::observations::measurements::{apply_held, fit_measurements, planar_spec, rms_per_routing, FitProgress, MeasurementSettings, MeasurementsReport, Noise, RoutingRms, ShapeData};
use super::predict::predict;
use super::request::{DataKind, FitSettings, LossKind};
use super::{CalibrateError, CalibrateRequest, Effect};
use crate::model::Rod;
use crate::numerics::lm;
use super::fit::{fit, Status};
use super::observations::captures::errors::ErrorReport;
use super::observations::captures::files::{read_actuator, read_actuator_set};
use super::observations::captures::simulate::solve_captures;
use super::observations::captures::{Captures, CapturesReport};
use super::Parameter;
use serde::{Serialize, Serializer};
use std::path::PathBuf;
use std::fmt;
use std::path::Path;
use std::sync::Arc;

impl FitSettings {
    /// A planar fit's parameters (the rigidities, without effects) and
    /// weighing, and the starting rod with the held values set; also the
    /// held effects. Reads the shape files.
    pub fn resolve(&self, base: &Rod, data: &Dataset) -> Result<(FitSpec, MeasurementSettings, Rod, Vec<Effect>), CalibrateError> {
        let loss = self.loss(LossKind::Huber)?;
        let (start, fixed_rigidities, held_effects) = apply_held(base, &self.held)?;
        let mut shapes = ShapeData::default();
        if let Some(p) = &self.centrelines {
            shapes.centrelines = read_centrelines(p, data)?;
        }
        if let Some(p) = &self.markers {
            shapes.markers = read_markers(p, data, start.length_mm)?;
        }
        let noise = self.noise();
        noise.validate()?;
        let settings = MeasurementSettings { angle_weight_mm_per_deg: self.angle_weight_mm_per_deg, noise, shapes: Arc::new(shapes) };
        Ok((planar_spec(&[], fixed_rigidities, loss, self.max_iterations), settings, start, held_effects))
    }
}

/// What a running calibration reports (only for large data files, from
/// [`LARGE_DATA_ROWS`] readings on, so that a long silent run is expected
/// rather than mistaken for a hang).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CalibrateProgress {
    /// Before the fit: the cost of one pass over the readings.
    Cost {
        /// Readings in the file.
        readings: usize,
        /// Wall time of one pass (every reading simulated once), s.
        pass_s: f64,
        /// Passes per iteration.
        passes: usize,
    },
    /// After every accepted step.
    Iteration(FitProgress),
    /// After every accepted step of a fit to 3-D markers.
    MarkerStep(lm::Step),
}

impl fmt::Display for CalibrateProgress {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            CalibrateProgress::Cost { readings, pass_s, passes } => write!(
                f,
                "calibrate: {readings} readings; one pass over them takes {pass_s:.2} s, an iteration about {passes} passes \
                 (≈ {:.1} s); typically 5-30 iterations, at most 200",
                pass_s * passes as f64
            ),
            CalibrateProgress::Iteration(p) => write!(f, "calibrate: iteration {} (of at most 200): RMS {:.4} mm", p.iteration, p.rms_mm),
            CalibrateProgress::MarkerStep(s) => write!(f, "calibrate: iteration {}: marker RMS {:.3} σ", s.iteration, (s.cost / s.residuals as f64).sqrt()),
        }
    }
}

/// Measurement files from this many rows on report their cost and progress.
pub const LARGE_DATA_ROWS: usize = 2000;

/// A finished calibration, of either kind of data. Serialises to the
/// `--json` object, displays as the text report.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum CalibrateReport {
    /// Planar measurements.
    Measurements(MeasurementsCalibration),
    /// Captures with 3-D markers.
    Captures(CapturesCalibration),
}

impl CalibrateReport {
    /// The `--json` object on one line (keys in alphabetical order).
    pub fn to_json_line(&self) -> String {
        serde_json::to_value(self).expect("a report serialises").to_string()
    }
}

impl fmt::Display for CalibrateReport {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CalibrateReport::Measurements(r) => r.fmt(out),
            CalibrateReport::Captures(r) => r.fmt(out),
        }
    }
}

/// A finished calibration on planar measurements. Serialises to the
/// `--json` object: the fit's fields, `holdout` and `held_effects`.
#[derive(Debug, Clone, Serialize)]
pub struct MeasurementsCalibration {
    /// The fit.
    #[serde(flatten)]
    pub fit: FitResult<MeasurementsReport>,
    /// The error on the held-out routing.
    pub holdout: Option<RoutingRms>,
    /// Effects held at a value (`--fix`), with it.
    #[serde(serialize_with = "as_map")]
    pub held_effects: Vec<(Effect, f64)>,
    /// Readings fitted.
    #[serde(skip)]
    pub readings: usize,
    /// Routings fitted.
    #[serde(skip)]
    pub routings: usize,
    /// The noise of rows that do not give their own.
    #[serde(skip)]
    pub noise: Noise,
    /// The loss minimised.
    #[serde(skip)]
    pub loss: Loss,
}

/// Held effects as `{parameter name: value}`.
fn as_map<S: Serializer>(held: &[(Effect, f64)], serializer: S) -> Result<S::Ok, S::Error> {
    serializer.collect_map(held.iter().map(|(e, v)| (e.parameter_name(), v)))
}

/// Runs a calibration.
pub fn run(request: &CalibrateRequest) -> Result<CalibrateReport, CalibrateError> {
    run_observed(request, &mut |_| {})
}

/// [`run`], reporting the cost and progress of a fit on large data, and
/// every step of a fit to 3-D markers.
pub fn run_observed(request: &CalibrateRequest, observe: &mut dyn FnMut(CalibrateProgress)) -> Result<CalibrateReport, CalibrateError> {
    match request.check()? {
        DataKind::Measurements => calibrate_measurements(request, observe).map(CalibrateReport::Measurements),
        DataKind::Captures { actuator_file } => calibrate_captures(request, actuator_file, observe).map(CalibrateReport::Captures),
    }
}

fn calibrate_measurements(request: &CalibrateRequest, observe: &mut dyn FnMut(CalibrateProgress)) -> Result<MeasurementsCalibration, CalibrateError> {
    let data = &read_measurements(&request.input.data_path)?;
    let actuator = request.input.rod.resolve(data.actuator.as_ref())?;
    actuator.validate()?;
    let options = &request.input.options;
    let (train, held) = split_holdout(data, request.input.holdout.as_deref())?;
    let (spec, settings, start, held_effects) = request.input.fit.resolve(&actuator, data)?;
    let mut effects = spec.effects();
    for &e in &request.effects {
        if !effects.contains(&e) {
            effects.push(e);
        }
    }
    if let Some(&effect) = effects.iter().find(|e| held_effects.contains(e)) {
        return Err(CalibrateError::FittedAndHeld { effect });
    }
    let spec = spec.with_effects(&effects);
    let large = data.rows.len() >= LARGE_DATA_ROWS;
    if large {
        // A fit re-simulates every reading (1 + parameters) times per
        // iteration: state the cost of one pass up front.
        let started = std::time::Instant::now();
        predict(&start, options, data, &train, false)?;
        // Central differences: two passes per parameter for the Jacobian,
        // plus the trial steps (at least two).
        let passes = 2 * (3 + effects.len()) + 2;
        observe(CalibrateProgress::Cost { readings: data.rows.len(), pass_s: started.elapsed().as_secs_f64(), passes });
    }
    let fit = fit_measurements(&start, options, data, &train, &settings, &spec, &mut |step| {
        if large {
            observe(CalibrateProgress::Iteration(FitProgress::of(step)));
        }
    })?;
    let holdout = match &held {
        Some(g) => {
            let g = std::slice::from_ref(g);
            let preds = predict(fit.rod(), options, data, g, false)?;
            Some(rms_per_routing(data, g, &preds, settings.angle_weight_mm_per_deg)[0].clone())
        }
        None => None,
    };
    Ok(MeasurementsCalibration {
        holdout,
        held_effects: held_effects.iter().map(|e| (*e, e.current(&start).unwrap_or(0.0))).collect(),
        readings: train.iter().map(|g| g.rows.len()).sum(),
        routings: train.len(),
        noise: settings.noise,
        loss: spec.loss,
        fit,
    })
}

impl fmt::Display for MeasurementsCalibration {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        let result = &self.fit;
        writeln!(
            out,
            "fit of {} readings on {} routings ({} residuals weighted by noise {} mm, {}°; {})",
            self.readings,
            self.routings,
            result.n_residuals,
            self.noise.mm,
            self.noise.deg,
            self.loss.describe()
        )?;
        for p in &result.parameters {
            if p.status == super::fit::Status::Held {
                writeln!(out, "  {:<30} {:>14.6}   (held)", p.name, p.value)?;
            } else {
                writeln!(out, "  {:<30} {:>14.6} ± {}", p.name, p.value, crate::io::fmt_sig(p.se, 3))?;
            }
        }
        for (e, v) in &self.held_effects {
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
        if let Some(r) = &self.holdout {
            writeln!(out, "  {:<20} {:>3} rows  {:>8.4} mm   {:>8.4} mm  {:>8.4}°  (held out)", r.routing, r.rows, r.rms_mm, r.rms_position_mm, r.rms_angle_deg)?;
        }
        writeln!(
            out,
            "overall tip RMS {:.4} mm; χ² = {:.1} on {} dof (χ²/dof = {:.3}, {}){}",
            result.rms_mm,
            result.chi2,
            result.dof,
            result.reduced_chi2,
            super::stats::p_text(result.p_value),
            if result.p_value < 1e-3 { ": well above the stated noise (p < 1e-3)" } else { ": consistent with the stated noise" }
        )?;
        if !result.outliers.is_empty() {
            writeln!(out, "outliers set aside in the χ² test (measurement ids): {:?}", result.outliers)?;
        }
        writeln!(
            out,
            "{} iterations{}",
            result.iterations,
            if result.converged { ", converged" } else { ": NOT converged (iteration cap or an unsolvable model near the optimum); do not trust these values" }
        )?;
        for f in &result.flags {
            writeln!(out, "warning: {f}")?;
        }
        writeln!(out, "cable stretch is not fitted: under tension control it is not identifiable")
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
fn calibrate_captures(request: &CalibrateRequest, actuator_file: &Path, observe: &mut dyn FnMut(CalibrateProgress)) -> Result<CapturesCalibration, CalibrateError> {
    let started = std::time::Instant::now();
    let loss = request.input.fit.loss(LossKind::Squares)?;
    let mut base = read_actuator(actuator_file)?;
    let set = read_actuator_set(&request.input.data_path, request.input.fit.markers.as_deref(), &base)?;
    for &(p, v) in &request.input.fit.held {
        if !(v.is_finite() && (matches!(p, Parameter::Effect(_)) || v > 0.0)) {
            return Err(CalibrateError::Held(crate::calibrate::HeldError::NotPositive { name: p.name(), value: v }));
        }
        p.set(&mut base, v);
    }
    let is_held = |p: Parameter| request.input.fit.held.iter().any(|(h, _)| *h == p);
    if let Some(&e) = request.effects.iter().find(|&&e| is_held(Parameter::Effect(e))) {
        return Err(CalibrateError::FittedAndHeld { effect: e });
    }
    let mut params: Vec<Parameter> = Parameter::BODY.iter().copied().filter(|&p| !is_held(p)).collect();
    if !base.rod.gravity.enabled {
        params.retain(|&p| p != Parameter::Density);
    }
    params.extend(request.effects.iter().map(|&e| Parameter::Effect(e)));
    let (train, test) = set.hold_out_cable(request.input.holdout_cable, base.cables.len())?;
    let spec = FitSpec { params, held: Vec::new(), loss, max_iterations: request.input.fit.max_iterations };
    let fit = fit(&base, &Captures::new(&train, request.input.fit.noise_mm, &request.input.options), &spec, &mut |step| observe(CalibrateProgress::MarkerStep(step)))?;
    let holdout = match &test {
        Some(t) => Some(ErrorReport::of(t, &solve_captures(&fit.actuator, &request.input.options, t)?)),
        None => None,
    };
    let mut report = CapturesCalibration {
        held: request.input.fit.held.iter().map(|(p, v)| (p.name().to_string(), *v)).collect(),
        holdout_cable: request.input.holdout_cable,
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
