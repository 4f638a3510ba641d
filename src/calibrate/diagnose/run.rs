//! A diagnosis as a request: the measurement file, the starting actuator,
//! the fit settings and the criterion's thresholds in; the diagnosis and
//! the report's path out. The report directory is refused before anything
//! is read.

use super::analysis::{diagnose, DiagnoseSpec};
use super::markdown::write_report;
use super::report::DiagnoseReport;
use crate::calibrate::data::read_measurements;
use crate::calibrate::run::FitSettings;
use crate::calibrate::CalibrateError;
use crate::model::RodOverrides;
use crate::solver::SolverOptions;
use std::path::{Path, PathBuf};

/// Everything a diagnosis needs.
#[derive(Debug, Clone)]
pub struct DiagnoseRequest {
    /// The measurement file (CSV, or Parquet by its extension).
    pub data_path: PathBuf,
    /// Starting values and fixed parameters: overrides on the rod file's,
    /// else the measurement file's, else the thesis's rod (validated here).
    pub actuator: RodOverrides,
    /// Solver settings.
    pub options: SolverOptions,
    /// Noise, held parameters, loss, shapes.
    pub fit: FitSettings,
    /// Routing left out of every fit; the gap on it is shown before and after.
    pub holdout: Option<String>,
    /// A model is consistent with the noise when the χ² test's p ≥ this.
    pub alpha: f64,
    /// BIC decrease an effect needs against the model without it.
    pub threshold: f64,
    /// BIC lead an effect needs over the runner-up.
    pub margin: f64,
    /// Most effects added (forward-stepwise; at least 1).
    pub max_effects: usize,
    /// Report directory (report.md and PNG plots); none for no report.
    pub report_dir: Option<PathBuf>,
}

impl DiagnoseRequest {
    /// The report directory when none is given: beside the data file, named
    /// after it (measurements.csv → measurements-diagnosis/), so that a run
    /// never litters the current directory.
    pub fn default_report_dir(data_path: &Path) -> PathBuf {
        let stem = data_path.file_stem().map_or_else(|| "measurements".into(), |s| s.to_string_lossy().into_owned());
        data_path.with_file_name(format!("{stem}-diagnosis"))
    }
}

/// Runs a diagnosis and writes its report (when asked for): a report
/// directory inside a sweep run is refused first, before the measurements
/// are read and the fits run.
pub fn run(request: &DiagnoseRequest) -> Result<DiagnoseReport, CalibrateError> {
    if let Some(dir) = &request.report_dir {
        crate::io::check_outside_run_dir(dir, "the report directory")?;
    }
    let data = read_measurements(&request.data_path)?;
    let actuator = request.actuator.resolve(data.actuator.as_ref())?;
    actuator.validate()?;
    let (fit, start, held_effects) = request.fit.resolve(&actuator, &data)?;
    let spec = DiagnoseSpec {
        holdout: request.holdout.clone(),
        fit,
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
    Ok(DiagnoseReport { diagnosis, report })
}
