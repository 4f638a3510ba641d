//! A diagnosis as a request: the data file (planar measurements, or
//! captures with 3-D markers when an actuator file is given), the starting
//! actuator, the fit settings and the criterion's thresholds in; the
//! diagnosis and the report's files out. The report directory is refused
//! before anything is read.

use super::analysis::diagnose;
use super::captures::diagnose_captures;
use super::diagnosis::{DiagnoseSpec, Diagnosis};
use super::markdown::write_report;
use super::report::DiagnoseReport;
use crate::calibrate::data::read_measurements;
use crate::calibrate::observations::captures::CapturesReport;
use crate::calibrate::observations::measurements::MeasurementsReport;
use crate::calibrate::request::{DataKind, DiagnoseRequest};
use crate::calibrate::fit::FitSpec;
use crate::calibrate::observations::captures::files::read_actuator_set;
use crate::calibrate::observations::captures::files::read_actuator;
use crate::calibrate::request::LossKind;
use crate::calibrate::{CalibrateError, Parameter, Refused};
use std::path::Path;

/// Runs a diagnosis and writes its report (when asked for): a report
/// directory inside a sweep run is refused first, before the measurements
/// are read and the fits run.
pub fn run(request: &DiagnoseRequest) -> Result<DiagnoseReport, CalibrateError> {
    match request.check()? {
        DataKind::Measurements => diagnose_measurements(request).map(DiagnoseReport::Measurements),
        DataKind::Captures { actuator_file } => diagnose_captures_request(request, actuator_file).map(DiagnoseReport::Captures),
    }
}

fn diagnose_measurements(request: &DiagnoseRequest) -> Result<Diagnosis<MeasurementsReport>, CalibrateError> {
    if let Some(dir) = &request.report_dir() {
        crate::io::check_outside_run_dir(dir, "the report directory")?;
    }
    let data = read_measurements(&request.input.data_path)?;
    let actuator = request.input.rod.resolve(data.actuator.as_ref())?;
    actuator.validate()?;
    let (fit, measurements, start, held_effects) = request.input.fit.resolve(&actuator, &data)?;
    let spec = DiagnoseSpec {
        fit,
        settings: measurements,
        options: request.input.options.clone(),
        holdout: request.input.holdout.clone(),
        held_effects,
        threshold: request.threshold,
        margin: request.margin,
        max_effects: request.max_effects.max(1),
        alpha: request.alpha,
    };
    let mut diagnosis = diagnose(&start, &data, &spec)?;
    if let Some(dir) = &request.report_dir() {
        diagnosis.written = write_report(dir, &request.input.data_path, &data, &diagnosis, &spec)?;
    }
    Ok(diagnosis)
}

/// Reads the request's files, runs [`diagnose_captures`] and writes the
/// report directory when asked for (refused first when inside a sweep run,
/// before anything is read); the report's files are in `written`.
fn diagnose_captures_request(request: &DiagnoseRequest, actuator_file: &Path) -> Result<Diagnosis<CapturesReport>, CalibrateError> {
    if !request.input.fit.held.is_empty() {
        return Err(Refused::HeldInCapturesDiagnosis.into());
    }
    let loss = request.input.fit.loss(LossKind::Squares)?;
    if let Some(dir) = &request.report_dir() {
        crate::io::check_outside_run_dir(dir, "the report directory")?;
    }
    let base = read_actuator(actuator_file)?;
    let set = read_actuator_set(&request.input.data_path, request.input.fit.markers.as_deref(), &base)?;
    let mut params: Vec<Parameter> = Parameter::BODY.to_vec();
    if !base.rod.gravity.enabled {
        params.retain(|&p| p != Parameter::Density);
    }
    let spec = DiagnoseSpec {
        fit: FitSpec { params, held: Vec::new(), loss, max_iterations: request.input.fit.max_iterations },
        settings: request.input.fit.noise_mm,
        options: request.input.options.clone(),
        holdout: request.input.holdout_cable,
        held_effects: Vec::new(),
        threshold: request.threshold,
        margin: request.margin,
        max_effects: request.max_effects,
        alpha: request.alpha,
    };
    let mut d = diagnose_captures(&base, &set, &spec)?;
    if let Some(dir) = &request.report_dir() {
        let sources = super::captures_report::ReportSources { captures: &request.input.data_path, markers: request.input.fit.markers.as_deref(), actuator: actuator_file };
        d.written = super::captures_report::write_report(dir, sources, &set, &d, &request.input.options)?;
    }
    Ok(d)
}
