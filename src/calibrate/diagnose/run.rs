//! A diagnosis as a request: the measurements, the starting actuator, the
//! fit settings and the criterion's thresholds in; the diagnosis and the
//! report's path out.

use super::analysis::{diagnose, DiagnoseSpec};
use super::markdown::write_report;
use super::report::DiagnoseReport;
use crate::calibrate::data::Dataset;
use crate::calibrate::run::FitSettings;
use crate::calibrate::CalibrateError;
use crate::model::{Rod, SolverOptions};
use std::path::{Path, PathBuf};

/// Everything a diagnosis needs.
#[derive(Debug, Clone)]
pub struct DiagnoseRequest {
    /// Where the measurements came from (named in the report).
    pub data_path: PathBuf,
    /// The measurements.
    pub data: Dataset,
    /// Starting values and fixed parameters (validated here).
    pub actuator: Rod,
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

/// Runs a diagnosis and writes its report (when asked for).
pub fn run(request: &DiagnoseRequest) -> Result<DiagnoseReport, CalibrateError> {
    if let Some(dir) = &request.report_dir {
        // Before the fits, not after them.
        crate::io::check_not_in_run_dir(dir, "the report directory").map_err(|message| CalibrateError::ReportDir { message })?;
    }
    request.actuator.validate()?;
    let (fit, start, held_effects) = request.fit.resolve(&request.actuator, &request.data)?;
    let spec = DiagnoseSpec {
        holdout: request.holdout.clone(),
        fit,
        threshold: request.threshold,
        margin: request.margin,
        max_effects: request.max_effects.max(1),
        alpha: request.alpha,
        held_effects,
    };
    let diagnosis = diagnose(&start, &request.options, &request.data, &spec)?;
    let report = match &request.report_dir {
        Some(dir) => Some(write_report(dir, &request.data_path, &request.data, &diagnosis, &spec)?),
        None => None,
    };
    Ok(DiagnoseReport { diagnosis, report })
}
