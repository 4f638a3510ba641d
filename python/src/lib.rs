//! `cablemap._native`: the Rust side of the Python package `cablemap`.
//!
//! A thin layer: each function takes a request as JSON (built by the
//! Python functions in `python/cablemap/__init__.py` from keyword
//! arguments), deserialises it into the library's request (the one the
//! matching command in `src/cli/` fills), runs it, and hands back the
//! library's record as JSON
//! and numeric series as little-endian `f64` bytes (numpy reads them without
//! a copy per element). Errors are raised as the package's exceptions
//! (`cablemap.errors`): bad input, a failed solve (with its status), or a
//! file that cannot be read.

use cablemap::io::SettingNames;
use cablemap::model::{Actuator, ActuatorError, Rod, Routing, REGISTRY};
use cablemap::solver::request::{SimulateRequest, SimulateRequestError};
use cablemap::solver::spatial::SpatialError;
use cablemap::solver::{Backend, Given, SimulateError, Simulator, SolverOptions, SolverSettings};
use cablemap::shape::LengthBasis;
use cablemap::sweep::solve::{planar_routing, Stored};
use cablemap::sweep::spec::Ladder;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use rayon::prelude::*;
use serde::Deserialize;
use serde_json::{Map, Value};

mod reports;

/// What went wrong, as the Python exception it becomes.
#[derive(Debug)]
enum Failure {
    /// Input the library refuses (`cablemap.BadInputError`).
    BadInput(String),
    /// A solve that produced no result, with the status a sweep stores for
    /// it (`cablemap.SolveError`).
    Solve { status: String, message: String },
    /// A file that cannot be read or parsed (`cablemap.FileFormatError`).
    File(String),
}

impl Failure {
    fn into_py(self, py: Python<'_>) -> PyErr {
        let (class, args): (&str, Vec<String>) = match self {
            Failure::BadInput(m) => ("BadInputError", vec![m]),
            Failure::Solve { status, message } => ("SolveError", vec![message, status]),
            Failure::File(m) => ("FileFormatError", vec![m]),
        };
        match py.import("cablemap.errors").and_then(|m| m.getattr(class)) {
            Ok(cls) => match cls.call1(pyo3::types::PyTuple::new(py, args).expect("a tuple of strings")) {
                Ok(instance) => PyErr::from_value(instance),
                Err(e) => e,
            },
            Err(e) => e,
        }
    }
}

impl From<SpatialError> for Failure {
    fn from(e: SpatialError) -> Self {
        match (&e, e.failure_status()) {
            (_, Some(status)) => Failure::Solve { status: status.to_string(), message: e.to_string() },
            (SpatialError::Actuator(ActuatorError::Read { .. } | ActuatorError::Toml { .. }), None) => Failure::File(e.to_string()),
            _ => Failure::BadInput(e.to_string()),
        }
    }
}

impl From<ActuatorError> for Failure {
    fn from(e: ActuatorError) -> Self {
        SpatialError::from(e).into()
    }
}

impl From<SimulateError> for Failure {
    fn from(e: SimulateError) -> Self {
        match &e {
            SimulateError::Solve(f) => Failure::Solve { status: f.status().to_string(), message: e.to_string() },
            SimulateError::Parameter(_) | SimulateError::Unresolved(_) | SimulateError::Unsupported(_) => Failure::BadInput(e.to_string()),
        }
    }
}

type Result<T> = std::result::Result<T, Failure>;

mod data;

fn bad(message: impl Into<String>) -> Failure {
    Failure::BadInput(message.into())
}

fn from_json<T: for<'de> Deserialize<'de>>(text: &str, what: &str) -> Result<T> {
    serde_json::from_str(text).map_err(|e| bad(format!("{what}: {e}")))
}

fn to_json<T: serde::Serialize>(value: &T) -> String {
    serde_json::to_string(value).expect("library records serialise to JSON")
}

/// `f64` values as bytes, in the machine's order (numpy's `frombuffer`).
fn f64_bytes<'py>(py: Python<'py>, values: &[f64]) -> Bound<'py, PyBytes> {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_ne_bytes()).collect();
    PyBytes::new(py, &bytes)
}

// ---------------------------------------------------------------- actuator

/// Fields of the actuator itself rather than of its rod.
const ACTUATOR_FIELDS: [&str; 3] = ["gj_n_mm2", "gravity_direction", "cables"];

/// `base` (the thesis's rod and no cables when `None`) with `fields` set:
/// a rod field by its name in the TOML (`length_mm`, `ei_n_mm2`,
/// `radius_profile_mm`, `effects = {…}`, …; `gravity` a bool turns
/// self-weight on or off, as `--no-gravity` does, or a table), an effect
/// by its registry name (`stiffening_alpha`, as its flag), or `gj_n_mm2`,
/// `gravity_direction`, `cables` (a list of `[[cable]]` tables) of the
/// actuator.
fn actuator_with(base: Option<Actuator>, fields: Map<String, Value>) -> Result<Actuator> {
    let mut actuator = base.unwrap_or_else(|| Actuator::with_cables(Rod::default(), Vec::new()));
    let mut rod = serde_json::to_value(&actuator.rod).expect("a rod serialises");
    let rod_fields = serde_json::to_value(Rod::default()).expect("a rod serialises");
    let mut effects = Vec::new();
    for (key, value) in fields {
        if let Some(info) = REGISTRY.iter().find(|i| i.name == key) {
            let v = value.as_f64().ok_or_else(|| bad(format!("{key}: expected a number, got {value}")))?;
            effects.push((info, v));
        } else if key == "gravity" && value.is_boolean() {
            rod["gravity"]["enabled"] = value;
        } else if key == "gj_n_mm2" {
            actuator.gj_n_mm2 = from_json(&value.to_string(), "gj_n_mm2")?;
        } else if key == "gravity_direction" {
            actuator.gravity_direction = from_json(&value.to_string(), "gravity_direction (3 numbers X, Y, Z)")?;
        } else if key == "cables" {
            actuator.cables = from_json(&value.to_string(), "cables (a list of [[cable]] tables: y_mm, z_mm, tension_n or displacement_mm, cable_ea_n, anchor_mm)")?;
        } else if rod_fields.get(&key).is_some() || matches!(key.as_str(), "radius_profile_mm" | "segments" | "cable_anchor_mm" | "rest_curvature_per_mm") {
            rod[key.as_str()] = value;
        } else {
            let mut known: Vec<String> = rod_fields.as_object().map(|o| o.keys().cloned().collect()).unwrap_or_default();
            known.extend(["radius_profile_mm", "segments", "cable_anchor_mm", "rest_curvature_per_mm"].map(String::from));
            known.extend(REGISTRY.iter().map(|i| i.name.to_string()));
            known.extend(ACTUATOR_FIELDS.map(String::from));
            return Err(bad(format!("unknown actuator field {key:?}: the fields are {}", known.join(", "))));
        }
    }
    actuator.rod = from_json(&rod.to_string(), "actuator")?;
    for (info, v) in effects {
        (info.set)(&mut actuator.rod, v);
    }
    Ok(actuator)
}

/// The actuator `base_json` (the thesis's when `None`) with the fields of
/// `fields_json` set, as JSON.
#[pyfunction]
#[pyo3(signature = (base_json, fields_json))]
fn actuator_from_fields(py: Python<'_>, base_json: Option<&str>, fields_json: &str) -> PyResult<String> {
    let run = || -> Result<String> {
        let base = base_json.map(|b| from_json::<Actuator>(b, "actuator")).transpose()?;
        let fields: Map<String, Value> = from_json(fields_json, "actuator fields")?;
        let actuator = actuator_with(base, fields)?;
        actuator.rod.validate().map_err(|e| bad(e.to_string()))?;
        Ok(to_json(&actuator))
    };
    run().map_err(|e| e.into_py(py))
}

/// An actuator file (`--actuator FILE.toml`: `[rod]`, `[[cable]]`, …) or,
/// with `rod_only`, a rod file (`--actuator-file FILE`: the rod's fields),
/// read and checked, as JSON.
#[pyfunction]
fn actuator_read(py: Python<'_>, path: &str, rod_only: bool) -> PyResult<String> {
    let run = || -> Result<String> {
        if rod_only {
            let rod = Rod::from_toml_file(std::path::Path::new(path)).map_err(|e| Failure::File(e.to_string()))?;
            return Ok(to_json(&Actuator::with_cables(rod, Vec::new())));
        }
        Ok(to_json(&Actuator::read(std::path::Path::new(path))?))
    };
    run().map_err(|e| e.into_py(py))
}

/// The actuator as the TOML of an actuator file (`--actuator FILE.toml`).
#[pyfunction]
fn actuator_to_toml(py: Python<'_>, actuator_json: &str) -> PyResult<String> {
    let run = || -> Result<String> {
        let actuator: Actuator = from_json(actuator_json, "actuator")?;
        toml::to_string(&actuator).map_err(|e| bad(format!("the actuator has no TOML form: {e}")))
    };
    run().map_err(|e| e.into_py(py))
}

// ---------------------------------------------------------------- simulate

/// The library's simulate errors as the package's exceptions: a failed
/// solve keeps its own message and status (without the routing it solved).
fn simulate_failure(e: SimulateRequestError) -> Failure {
    match e.solve_error() {
        Some(solve) => solve.clone().into(),
        None => bad(e.to_string()),
    }
}

/// Columns of the centreline array `simulate` returns.
const CENTRELINE: [&str; 9] = ["s_mm", "x_mm", "y_mm", "z_mm", "frame_angle_rad", "tangent_angle_rad", "arc_length_mm", "u_y_per_mm", "u_z_per_mm"];

/// One simulation: `(record JSON, centreline bytes (rows × columns, row
/// major), column names)`; the record is `simulate --json`'s.
#[pyfunction]
fn simulate<'py>(py: Python<'py>, request_json: &str) -> PyResult<(String, Bound<'py, PyBytes>, Vec<&'static str>)> {
    let request: SimulateRequest = from_json(request_json, "simulate").map_err(|e| e.into_py(py))?;
    let report = py.detach(|| request.run(SettingNames::Keys)).map_err(|e| simulate_failure(e).into_py(py))?;
    let values: Vec<f64> = report
        .simulation
        .centreline
        .iter()
        .flat_map(|c| [c.s_mm, c.x_mm, c.y_mm, c.z_mm, c.frame_angle_rad, c.tangent_angle_rad, c.arc_length_mm, c.u_per_mm[1], c.u_per_mm[2]])
        .collect();
    Ok((report.to_json(), f64_bytes(py, &values), CENTRELINE.to_vec()))
}

// ---------------------------------------------------------------- batches

/// The per-solve fields of a batch, each an (n, m) array.
const BATCH_FIELDS: [&str; 9] =
    ["tension_n", "displacement_mm", "tip_x_mm", "tip_y_mm", "tip_angle_rad", "tip_frame_angle_rad", "base_angle_rad", "length_mm", "iterations"];

/// Solves every routing of `routings_mm` (n × 5, row major) through the
/// rising tensions `tensions_n` (m), warm-starting each solve from the
/// previous one of its routing (the sweep's planar ladder,
/// [`planar_routing`]), routings in parallel (rayon) with the GIL released.
/// Returns a dict of bytes: each of [`BATCH_FIELDS`] (n × m), `a`
/// (n × m × (order + 1)), and `status` (a list of n × m strings: `ok`, a
/// failure's status, or `invalid_routing`); failed solves are NaN.
#[pyfunction]
#[pyo3(signature = (actuator_json, routings_mm, tensions_n, order, length_basis, solver_json, threads=None))]
fn solve_batch<'py>(
    py: Python<'py>,
    actuator_json: &str,
    routings_mm: Vec<f64>,
    tensions_n: Vec<f64>,
    order: usize,
    length_basis: &str,
    solver_json: &str,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let prepare = || -> Result<(Rod, SolverOptions, LengthBasis)> {
        let actuator: Actuator = from_json(actuator_json, "actuator")?;
        if !actuator.is_rod_alone() {
            return Err(bad("solve_batch solves one planar cable per routing: give the rod alone (no cables, gj_n_mm2 or gravity_direction)"));
        }
        let solver: SolverSettings = from_json(solver_json, "solver")?;
        let options = solver.options();
        let basis: LengthBasis = from_json(&format!("\"{length_basis}\""), "length_basis (\"rest\" or \"deformed\")")?;
        if routings_mm.len() % 5 != 0 {
            return Err(bad(format!("routings_mm: expected an (n, 5) array of control points, got {} numbers", routings_mm.len())));
        }
        for (j, &t) in tensions_n.iter().enumerate() {
            if !(t.is_finite() && t >= 0.0) {
                return Err(bad(format!("tensions_n[{j}] = {t}: a cable pulls with a finite tension ≥ 0 N")));
            }
        }
        cablemap::solver::simulate::check_ladder_tension("tensions_n", tensions_n.iter().copied().fold(0.0, f64::max))
            .map_err(|e| bad(e.to_string()))?;
        cablemap::solver::resolution::check_order(order, &options).map_err(|e| bad(e.to_string()))?;
        let rod = actuator.rod;
        Backend::check_planar(&rod, &options, Given::default()).map_err(|e| bad(e.to_string()))?;
        // Checks the rod once, before the threads start.
        Simulator::for_rod(&rod, &options).map_err(|e| bad(e.to_string()))?;
        Ok((rod, options, basis))
    };
    let (rod, options, basis) = prepare().map_err(|e| e.into_py(py))?;
    let n = routings_mm.len() / 5;
    let m = tensions_n.len();
    let k = order + 1;
    let stored = Stored { order, length_basis: basis, centreline: false };
    let ladder = Ladder::TensionN(tensions_n);
    let solve_all = || -> Vec<(Vec<[f64; BATCH_FIELDS.len()]>, Vec<f64>, Vec<&'static str>)> {
        routings_mm
            .par_chunks(5)
            .enumerate()
            .map_init(
                || Simulator::for_rod(&rod, &options).expect("checked before the threads"),
                |sim, (i, y)| {
                    let mut fields = vec![[f64::NAN; BATCH_FIELDS.len()]; m];
                    let mut a = vec![f64::NAN; m * k];
                    let Ok(routing) = Routing::for_actuator(y, &rod) else {
                        return (fields, a, vec![cablemap::sweep::schema::STATUS_INVALID_ROUTING; m]);
                    };
                    let y5: [f64; 5] = y.try_into().expect("chunks of 5");
                    let solved = planar_routing(sim, i as u64, cablemap::model::ControlPoints(y5), &routing, &ladder, stored);
                    let mut status = Vec::with_capacity(m);
                    for (j, row) in solved.rows.iter().enumerate() {
                        status.push(row.status);
                        if let Some(p) = &row.pose {
                            fields[j] = [
                                row.tension_n,
                                row.displacement_mm,
                                p.tip_x_mm,
                                p.tip_y_mm,
                                p.tip_angle_rad,
                                p.tip_frame_angle_rad,
                                p.base_angle_rad,
                                p.length_mm,
                                f64::from(p.iterations),
                            ];
                            a[j * k..(j + 1) * k].copy_from_slice(&row.a);
                        } else {
                            fields[j][0] = row.tension_n;
                        }
                    }
                    (fields, a, status)
                },
            )
            .collect()
    };
    let solved = py.detach(|| match threads {
        Some(t) => rayon::ThreadPoolBuilder::new().num_threads(t.max(1)).build().map(|pool| pool.install(solve_all)).map_err(|e| e.to_string()),
        None => Ok(solve_all()),
    });
    let solved = solved.map_err(|e| Failure::BadInput(format!("threads: {e}")).into_py(py))?;
    let out = PyDict::new(py);
    for (f, name) in BATCH_FIELDS.iter().enumerate() {
        let values: Vec<f64> = solved.iter().flat_map(|(fields, _, _)| fields.iter().map(move |row| row[f])).collect();
        out.set_item(*name, f64_bytes(py, &values))?;
    }
    let a: Vec<f64> = solved.iter().flat_map(|(_, a, _)| a.iter().copied()).collect();
    out.set_item("a", f64_bytes(py, &a))?;
    let status: Vec<&str> = solved.iter().flat_map(|(_, _, s)| s.iter().copied()).collect();
    out.set_item("status", status)?;
    out.set_item("shape", (n, m, k))?;
    Ok(out)
}

/// The extension module `cablemap._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(actuator_from_fields, m)?)?;
    m.add_function(wrap_pyfunction!(actuator_read, m)?)?;
    m.add_function(wrap_pyfunction!(actuator_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(solve_batch, m)?)?;
    data::register(m)?;
    reports::register(m)?;
    m.add("CENTRELINE_COLUMNS", CENTRELINE.to_vec())?;
    m.add("BATCH_FIELDS", BATCH_FIELDS.to_vec())?;
    Ok(())
}
