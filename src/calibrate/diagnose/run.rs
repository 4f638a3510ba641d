//! A diagnosis as a request: the data file (planar measurements, or
//! captures with 3-D markers when an actuator file is given), the starting
//! actuator, the fit settings and the criterion's thresholds in; the
//! diagnosis and the report's files out. The report directory is refused
//! before anything is read.

use super::analysis::{diagnose, DiagnoseSpec};
use super::markdown::write_report;
use super::report::{DiagnoseReport, MeasurementsDiagnosis};
use crate::calibrate::data::read_measurements;
use crate::calibrate::request::{DataKind, DiagnoseRequest};
use crate::calibrate::CalibrateError;

/// Runs a diagnosis and writes its report (when asked for): a report
/// directory inside a sweep run is refused first, before the measurements
/// are read and the fits run.
pub fn run(request: &DiagnoseRequest) -> Result<DiagnoseReport, CalibrateError> {
    match request.check()? {
        DataKind::Measurements => diagnose_measurements(request).map(DiagnoseReport::Measurements),
        DataKind::Captures { actuator_file } => crate::calibrate::captures::run::diagnose_request(request, actuator_file).map(DiagnoseReport::Captures),
    }
}

fn diagnose_measurements(request: &DiagnoseRequest) -> Result<MeasurementsDiagnosis, CalibrateError> {
    if let Some(dir) = &request.report_dir {
        crate::io::check_outside_run_dir(dir, "the report directory")?;
    }
    let data = read_measurements(&request.data_path)?;
    let actuator = request.rod.resolve(data.actuator.as_ref())?;
    actuator.validate()?;
    let (fit, measurements, start, held_effects) = request.fit.resolve(&actuator, &data)?;
    let spec = DiagnoseSpec {
        holdout: request.holdout.clone(),
        fit,
        measurements,
        threshold: request.threshold,
        margin: request.margin,
        max_effects: request.max_effects.max(1),
        alpha: request.alpha,
        held_effects,
    };
    let diagnosis = diagnose(&start, &request.options, &data, &spec)?;
    let report = match &request.report_dir {
        Some(dir) => Some(write_report(dir, &request.data_path, &data, &diagnosis, &spec)?),
        None => None,
    };
    Ok(MeasurementsDiagnosis { diagnosis, report })
}
