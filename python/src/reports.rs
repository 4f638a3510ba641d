//! The workflows that answer with a report: `design`, `feasible`,
//! `calibrate`, `diagnose` and `predict` (the functions
//! `cablemap.design`, … of `python/cablemap/_reports.py`).
//!
//! Each function takes the library's request as JSON (the command's flags
//! by their names, built from keyword arguments), runs it with the GIL
//! released and returns `(the --json object, the command's text report,
//! the pictures the request wrote)`. Errors become the package's
//! exceptions with the library's messages.

use super::{bad, Failure, Result};
use cablemap::calibrate::diagnose::DiagnoseRequest;
use cablemap::calibrate::predict::run as run_predict;
use cablemap::calibrate::predict::PredictRequest;
use cablemap::calibrate::{CalibrateError, CalibrateRequest};
use cablemap::design::feasible_request::FeasibleRequest;
use cablemap::design::{DesignError, DesignRequest};
use pyo3::prelude::*;
use serde::Deserialize;
use std::path::Path;

/// A finished workflow: its `--json` object (as JSON text), the command's
/// text report, and the paths of the pictures it wrote (PNG, SVG).
type Finished = (String, String, Vec<String>);

/// The library's design errors as the package's exceptions.
fn design_failure(e: DesignError) -> Failure {
    let message = e.to_string();
    match e {
        DesignError::Simulate(s) => s.into(),
        DesignError::NoSeed => Failure::Solve { status: "failed".into(), message },
        DesignError::File(_) | DesignError::MapTable(_) | DesignError::Map { .. } | DesignError::Study(_) | DesignError::Plot(_) => {
            Failure::File(message)
        }
        // The keyword, not the flag: the Python package's words.
        DesignError::TargetOnly { setting } => Failure::BadInput(format!("{} does not apply to targets=: give {}", setting.key(), setting.instead().replace("--actuator", "the actuator file"))),
        DesignError::TargetOrTargets => Failure::BadInput("give either target=… or targets=FILE.toml".into()),
        DesignError::NoMapOrStudy => Failure::BadInput("give map=MAP_DIR (a `cablemap reduce` output) or study=DIR (a `cablemap study` output)".into()),
        DesignError::MapAndStudy => Failure::BadInput("give map= or study=, not both".into()),
        DesignError::TargetsNeedMap => Failure::BadInput("targets= needs map=: the map of a cable sweep".into()),
        DesignError::Variant { source, .. } => match design_failure(*source) {
            Failure::File(_) => Failure::File(message),
            Failure::Solve { status, .. } => Failure::Solve { status, message },
            Failure::BadInput(_) => Failure::BadInput(message),
        },
        _ => Failure::BadInput(message),
    }
}

/// The library's calibration errors as the package's exceptions.
fn calibrate_failure(e: CalibrateError) -> Failure {
    let message = e.to_string();
    match e {
        CalibrateError::Io { .. }
        | CalibrateError::Empty { .. }
        | CalibrateError::MissingColumn { .. }
        | CalibrateError::BadValue { .. }
        | CalibrateError::Malformed { .. }
        | CalibrateError::Geometry { .. }
        | CalibrateError::Inconsistent { .. }
        | CalibrateError::ActuatorFile(_)
        | CalibrateError::Plot(_) => Failure::File(message),
        CalibrateError::Solve { failure, .. } => Failure::Solve { status: failure.status().to_string(), message },
        CalibrateError::Actuator(s) | CalibrateError::Capture { failure: s, .. } => match Failure::from(s) {
            Failure::File(_) => Failure::File(message),
            Failure::Solve { status, .. } => Failure::Solve { status, message },
            Failure::BadInput(_) => Failure::BadInput(message),
        },
        CalibrateError::Held(_) => Failure::BadInput(format!("fix: {message}")),
        _ => Failure::BadInput(message),
    }
}

/// The library's request from its JSON (the keywords by their names); a
/// refused value is named by the request's own sentence, without serde's
/// position in the JSON text the package wrote.
fn request_of<T: for<'de> Deserialize<'de>>(json: &str) -> Result<T> {
    serde_json::from_str(json).map_err(|e| {
        let text = e.to_string();
        let position = format!(" at line {} column {}", e.line(), e.column());
        bad(text.strip_suffix(&position).unwrap_or(&text))
    })
}

/// Runs `work` with the GIL released and turns its failure into the
/// package's exception.
fn detached<T: Send>(py: Python<'_>, work: impl FnOnce() -> Result<T> + Send) -> PyResult<T> {
    py.detach(work).map_err(|e| e.into_py(py))
}

/// `dir/name` for each picture among `names` (PNG and SVG files).
fn pictures(dir: Option<&Path>, names: &[String]) -> Vec<String> {
    let Some(dir) = dir else { return Vec::new() };
    names.iter().filter(|n| n.ends_with(".png") || n.ends_with(".svg")).map(|n| dir.join(n).display().to_string()).collect()
}

// ---------------------------------------------------------------- design

/// `cablemap design`: the request of the keywords, run by the library.
#[pyfunction]
pub(crate) fn design(py: Python<'_>, request_json: &str) -> PyResult<Finished> {
    let request: DesignRequest = request_of(request_json).map_err(|e| e.into_py(py))?;
    detached(py, move || {
        let done = cablemap::design::run(&request).map_err(design_failure)?;
        let (out, exported) = done.exported();
        let pictures = pictures(out, exported);
        Ok((done.to_json().to_string(), done.to_string(), pictures))
    })
}

// ---------------------------------------------------------------- feasible

/// `cablemap feasible`: a map's (or a study's maps') verdict on a target,
/// or a cable sweep's map on a targets file.
#[pyfunction]
pub(crate) fn feasible(py: Python<'_>, request_json: &str) -> PyResult<Finished> {
    let request: FeasibleRequest = request_of(request_json).map_err(|e| e.into_py(py))?;
    detached(py, move || {
        let report = cablemap::design::feasible_request::run(&request).map_err(design_failure)?;
        Ok((super::to_json(&report), report.to_string(), Vec::new()))
    })
}

// ---------------------------------------------------------------- fits

/// `cablemap calibrate`: fits the rod to measurements (planar) or the
/// actuator to captures and 3-D markers (with `actuator`).
#[pyfunction]
pub(crate) fn calibrate(py: Python<'_>, request_json: &str) -> PyResult<Finished> {
    let request: CalibrateRequest = request_of(request_json).map_err(|e| e.into_py(py))?;
    detached(py, move || {
        let report = cablemap::calibrate::run(&request).map_err(calibrate_failure)?;
        Ok((report.to_json_line(), report.to_string(), Vec::new()))
    })
}

/// `cablemap diagnose`: finds, names and adds the effect the model misses.
#[pyfunction]
pub(crate) fn diagnose(py: Python<'_>, request_json: &str) -> PyResult<Finished> {
    let request: DiagnoseRequest = request_of(request_json).map_err(|e| e.into_py(py))?;
    detached(py, move || {
        let done = cablemap::calibrate::diagnose::run(&request).map_err(calibrate_failure)?;
        let pictures = done.pictures().iter().map(|p| p.display().to_string()).collect();
        Ok((done.to_json_line(), done.to_string(), pictures))
    })
}

/// `cablemap predict`: the markers' errors of an actuator on captures, no fitting.
#[pyfunction]
pub(crate) fn predict(py: Python<'_>, request_json: &str) -> PyResult<Finished> {
    let request: PredictRequest = request_of(request_json).map_err(|e| e.into_py(py))?;
    detached(py, move || {
        let report = run_predict(&request).map_err(calibrate_failure)?;
        Ok((report.to_json_line(), report.to_string(), Vec::new()))
    })
}

/// Adds the report workflows to the module `cablemap._native`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(design, m)?)?;
    m.add_function(wrap_pyfunction!(feasible, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(predict, m)?)?;
    Ok(())
}
