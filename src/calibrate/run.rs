//! The calibration workflow behind `cablemap calibrate`: fit EA, GA, EI
//! (thesis eq. 2.14) and any chosen effects to planar measurements, and
//! report them with standard errors, correlations and the RMS error per
//! routing (and on a held-out routing); or, on captures with 3-D markers,
//! the actuator's rigidities, weight and effects
//! ([`crate::calibrate::captures::run`]).
//!
//! [`run`] takes a [`CalibrateRequest`] and returns a [`CalibrateReport`],
//! which serialises itself (the `--json` object) and displays itself (the
//! text report).

use super::data::{read_centrelines, read_markers, read_measurements, split_holdout, Dataset};
use super::captures::run::CapturesCalibration;
use super::fit::{FitResult, FitSpec, Loss};
use super::observations::measurements::{apply_held, fit_measurements, planar_spec, rms_per_routing, FitProgress, MeasurementSettings, MeasurementsReport, Noise, RoutingRms, ShapeData};
use super::predict::predict;
use super::request::{DataKind, FitSettings, LossKind};
use super::{CalibrateError, CalibrateRequest, Effect};
use crate::model::Rod;
use crate::numerics::lm;
use serde::{Serialize, Serializer};
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

fn calibrate_captures(request: &CalibrateRequest, actuator_file: &Path, observe: &mut dyn FnMut(CalibrateProgress)) -> Result<CapturesCalibration, CalibrateError> {
    super::captures::run::calibrate(request, actuator_file, &mut |step| observe(CalibrateProgress::MarkerStep(step)))
}

fn calibrate_measurements(request: &CalibrateRequest, observe: &mut dyn FnMut(CalibrateProgress)) -> Result<MeasurementsCalibration, CalibrateError> {
    let data = &read_measurements(&request.data_path)?;
    let actuator = request.rod.resolve(data.actuator.as_ref())?;
    actuator.validate()?;
    let options = &request.options;
    let (train, held) = split_holdout(data, request.holdout.as_deref())?;
    let (spec, settings, start, held_effects) = request.fit.resolve(&actuator, data)?;
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
