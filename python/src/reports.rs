//! The workflows that answer with a report: `design`, `feasible`,
//! `calibrate`, `diagnose` and `predict` (the functions
//! `cablemap.design`, … of `python/cablemap/_reports.py`).
//!
//! Each function takes a request as JSON (the command's flags by their
//! names, built from keyword arguments), builds the library's request the
//! way the command in `src/cli/` does, runs it with the GIL released and
//! returns `(the --json object, the command's text report, the pictures
//! the request wrote)`. Errors become the package's exceptions with the
//! library's messages.

use super::{actuator_with, bad, Failure, Result};
use cablemap::solver::SolverSettings;
use cablemap::calibrate::predict::run as run_predict;
use cablemap::calibrate::predict::PredictRequest;
use cablemap::calibrate::diagnose::DiagnoseRequest;
use cablemap::calibrate::{CalibrateError, CalibrateRequest};
use cablemap::design::actuator::DesignActuator;
use cablemap::design::feasible_request::{FeasibleRequest, MapSource};
use cablemap::design::targets::TargetSet;
use cablemap::design::{DesignError, DesignRequest, SearchOptions, Target, Weights};
use cablemap::model::{Actuator, Rod};
use cablemap::mould::MouldSettings;
use cablemap::shape::LengthBasis;
use pyo3::prelude::*;
use serde::Deserialize;
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

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

/// The length basis by its name (`rest` or `deformed`).
fn length_basis(name: &str) -> Result<LengthBasis> {
    super::from_json(&format!("\"{name}\""), "length_basis (\"rest\" or \"deformed\")")
}

// ---------------------------------------------------------------- design

/// What `cablemap.design` asks: the flags of `cablemap design`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DesignPy {
    /// The rod (with its fields set), when no design actuator file is given.
    actuator: Actuator,
    /// `--actuator FILE.toml` with `--targets`: the actuator to design.
    design_actuator: Option<PathBuf>,
    /// Rod fields set on the design actuator file's rod (the rod flags).
    #[serde(default)]
    rod_fields: Map<String, Value>,
    /// `--target K=V,…`.
    target: Option<String>,
    /// `--targets FILE.toml`.
    targets: Option<PathBuf>,
    weights: Option<String>,
    map: Option<PathBuf>,
    tension_min_n: Option<f64>,
    tension_max_n: Option<f64>,
    max_offset_mm: Option<f64>,
    length_basis: String,
    starts: Option<usize>,
    max_evaluations: Option<usize>,
    tolerance_pct: Option<f64>,
    out: Option<PathBuf>,
    #[serde(default)]
    moulds: bool,
    #[serde(default)]
    mould: MouldSettings,
    #[serde(default)]
    solver: SolverSettings,
}

/// The design request of `cablemap.design`'s keywords (the flags of `cablemap design`).
fn design_request(r: DesignPy) -> Result<DesignRequest> {
    let actuator = match &r.design_actuator {
        Some(path) => {
            // The rod fields apply to the file's rod; the first refusal is kept.
            let refused = std::cell::RefCell::new(None);
            let apply = |rod: &Rod| match actuator_with(Some(Actuator::with_cables(rod.clone(), Vec::new())), r.rod_fields.clone()) {
                Ok(a) => a.rod,
                Err(e) => {
                    refused.borrow_mut().get_or_insert(e);
                    rod.clone()
                }
            };
            let design = DesignActuator::read(path, apply).map_err(design_failure);
            if let Some(e) = refused.into_inner() {
                return Err(e);
            }
            Some(design?)
        }
        None => None,
    };
    if r.targets.is_none() && (!r.actuator.cables.is_empty() || r.actuator.gj_n_mm2.is_some() || r.actuator.gravity_direction.is_some()) {
        return Err(bad(
            "design(target=…) designs one planar cable on a rod: give the rod alone (no cables, gj_n_mm2 or gravity_direction), or targets=FILE.toml with actuator=FILE.toml for several cables",
        ));
    }
    let targets = match &r.targets {
        // The rod's length sets the targets' default weights.
        Some(path) => Some(TargetSet::read(path, actuator.as_ref().map_or(r.actuator.rod.length_mm, |a| a.actuator.rod.length_mm)).map_err(design_failure)?),
        None => None,
    };
    Ok(DesignRequest {
        rod: r.actuator.rod,
        actuator,
        options: r.solver.options(),
        target: r.target.as_deref().map(Target::parse).transpose().map_err(|e| bad(format!("target: {e}")))?,
        targets,
        weights: r.weights.as_deref().map(Weights::parse).transpose().map_err(|e| bad(format!("weights: {e}")))?,
        tension_min_n: r.tension_min_n,
        tension_max_n: r.tension_max_n,
        max_offset_mm: r.max_offset_mm,
        length_basis: length_basis(&r.length_basis)?,
        map: r.map,
        starts: r.starts,
        max_evaluations: r.max_evaluations.unwrap_or(SearchOptions::default().max_evaluations),
        tolerance_pct: r.tolerance_pct,
        out: r.out,
        mould: r.mould.params(),
        write_moulds: r.moulds,
    })
}

/// `cablemap design`: the request of the keywords, run by the library.
#[pyfunction]
pub(crate) fn design(py: Python<'_>, request_json: &str) -> PyResult<Finished> {
    let request: DesignPy = super::from_json(request_json, "design").map_err(|e| e.into_py(py))?;
    detached(py, move || {
        let request = design_request(request)?;
        let done = cablemap::design::run(&request).map_err(design_failure)?;
        let (out, exported) = done.exported();
        let pictures = pictures(out, exported);
        Ok((done.to_json().to_string(), done.to_string(), pictures))
    })
}

// ---------------------------------------------------------------- feasible

/// What `cablemap.feasible` asks: the flags of `cablemap feasible`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FeasiblePy {
    map: Option<PathBuf>,
    study: Option<PathBuf>,
    target: Option<String>,
    targets: Option<PathBuf>,
    weights: Option<String>,
    nearest: usize,
    length_basis: String,
}

fn feasible_run(r: FeasiblePy) -> Result<Finished> {
    let basis = length_basis(&r.length_basis)?;
    // As the command: the rod's length only sets the targets' default weights.
    let targets = r.targets.as_deref().map(|file| TargetSet::read(file, Rod::default().length_mm)).transpose().map_err(design_failure)?;
    let target = r.target.as_deref().map(Target::parse).transpose().map_err(|e| bad(format!("target: {e}")))?;
    let weights = r.weights.as_deref().map(Weights::parse).transpose().map_err(|e| bad(format!("weights: {e}")))?;
    let source = match (r.map, r.study) {
        (Some(_), Some(_)) => return Err(bad("give map= or study=, not both")),
        (Some(map), None) => MapSource::Map(map),
        (None, Some(study)) => MapSource::Study(study),
        (None, None) => return Err(bad("give map=MAP_DIR (a `cablemap reduce` output) or study=DIR (a `cablemap study` output)")),
    };
    let request = FeasibleRequest { source, target, targets, weights, length_basis: basis, nearest: r.nearest };
    let report = cablemap::design::feasible_request::run(&request).map_err(design_failure)?;
    Ok((super::to_json(&report), report.to_string(), Vec::new()))
}

/// `cablemap feasible`: a map's (or a study's maps') verdict on a target,
/// or a cable sweep's map on a targets file.
#[pyfunction]
pub(crate) fn feasible(py: Python<'_>, request_json: &str) -> PyResult<Finished> {
    let request: FeasiblePy = super::from_json(request_json, "feasible").map_err(|e| e.into_py(py))?;
    detached(py, move || feasible_run(request))
}

// ---------------------------------------------------------------- fits

/// `cablemap calibrate`: fits the rod to measurements (planar) or the
/// actuator to captures and 3-D markers (with `actuator`).
#[pyfunction]
pub(crate) fn calibrate(py: Python<'_>, request_json: &str) -> PyResult<Finished> {
    let request: CalibrateRequest = super::from_json(request_json, "calibrate").map_err(|e| e.into_py(py))?;
    detached(py, move || {
        let report = cablemap::calibrate::run(&request).map_err(calibrate_failure)?;
        Ok((report.to_json_line(), report.to_string(), Vec::new()))
    })
}

/// `cablemap diagnose`: finds, names and adds the effect the model misses.
#[pyfunction]
pub(crate) fn diagnose(py: Python<'_>, request_json: &str) -> PyResult<Finished> {
    let request: DiagnoseRequest = super::from_json(request_json, "diagnose").map_err(|e| e.into_py(py))?;
    detached(py, move || {
        let done = cablemap::calibrate::diagnose::run(&request).map_err(calibrate_failure)?;
        let pictures = done.pictures().iter().map(|p| p.display().to_string()).collect();
        Ok((done.to_json_line(), done.to_string(), pictures))
    })
}

/// `cablemap predict`: the markers' errors of an actuator on captures, no fitting.
#[pyfunction]
pub(crate) fn predict(py: Python<'_>, request_json: &str) -> PyResult<Finished> {
    let request: PredictRequest = super::from_json(request_json, "predict").map_err(|e| e.into_py(py))?;
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
