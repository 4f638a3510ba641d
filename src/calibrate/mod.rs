//! Calibration and the model-discrepancy workflow (issue 6): measurement
//! files, synthetic data with a hidden effect, the fit of EA, GA, EI (thesis
//! eq. 2.14) with or without extra effects, and the diagnosis that names the
//! missing effect.

pub mod captures;
pub mod data;
pub mod diagnose;
pub mod effect;
pub mod fit;
pub mod predict;
pub mod rng;
pub mod run;
pub mod stats;
pub mod synth;

pub use data::{read_measurements, Dataset, Direction, Measurement};
pub use effect::Effect;
pub use fit::{fit, FitResult, FitSpec};
pub use run::{run, CalibrateReport, CalibrateRequest, FitSettings};

/// Errors of the calibration layer.
#[derive(Debug, thiserror::Error)]
pub enum CalibrateError {
    /// A file could not be read or written.
    #[error("{context}: {source}")]
    Io { context: String, source: std::io::Error },
    /// The file has no data rows.
    #[error("{path}: the file has no data rows; give a header line and at least one measurement")]
    Empty { path: String },
    /// A required column is missing.
    #[error("{path}: missing column '{column}' (found: {found}); see docs/measurements.md for the required columns")]
    MissingColumn { path: String, column: String, found: String },
    /// A cell does not hold what its column needs.
    #[error("{path}: row {row}, column '{column}': '{value}' is not valid, expected {expected}")]
    BadValue { path: String, row: usize, column: String, value: String, expected: String },
    /// A row cannot be split into fields (or the file cannot be decoded).
    #[error("{path}: row {row}: {message}")]
    Malformed { path: String, row: usize, message: String },
    /// The file's geometry header (`# key = value` lines before the CSV
    /// header) is invalid.
    #[error("{path}: the geometry header (the '#' lines before the column names): {message}; see docs/measurements.md")]
    Geometry { path: String, message: String },
    /// Rows contradict each other.
    #[error("{path}: row {row}: {message}")]
    Inconsistent { path: String, row: usize, message: String },
    /// A routing in the data is not a valid routing for the actuator.
    #[error("routing '{routing}' (first on row {row}): {source}")]
    Routing { routing: String, row: usize, source: crate::model::RoutingError },
    /// The model could not be solved for a measurement.
    // The failure is part of the message, not the error's source, so that
    // `{:#}` (cause chains) does not print it twice on one line.
    #[error("routing '{routing}', row {row} ({tension_n} N): {failure}")]
    Solve { routing: String, row: usize, tension_n: f64, failure: crate::solver::SolveFailure },
    /// Invalid actuator or fit settings.
    #[error(transparent)]
    Parameter(#[from] crate::model::ParameterError),
    /// The solver refused the rod or its settings.
    #[error(transparent)]
    Simulate(#[from] crate::solver::SimulateError),
    /// The request cannot be carried out on this data.
    #[error("{0}")]
    Invalid(String),
    /// The routing to hold out is not one the data can spare.
    #[error("{0}")]
    Holdout(String),
    /// The measurement noise is not a standard deviation > 0.
    #[error("{0}")]
    Noise(String),
    /// A value to hold a parameter at is not valid.
    #[error(transparent)]
    Held(Box<CalibrateError>),
    /// An effect is both fitted and held.
    #[error("--effect {0} and --fix {1}=…: an effect is either fitted or held, not both", .effect.name(), .effect.parameter_name())]
    FittedAndHeld { effect: Effect },
    /// The report directory is, or lies inside, a sweep's run directory.
    #[error(transparent)]
    ReportDir(#[from] crate::io::InsideRunDir),
    /// The actuator file to start from cannot be used.
    #[error(transparent)]
    ActuatorFile(#[from] crate::model::rod::ActuatorFileError),
    /// Drawing a plot.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    /// The actuator of a 3-D calibration cannot be used.
    #[error("the actuator: {0}")]
    Actuator(crate::solver::spatial::SpatialError),
    /// The 3-D model could not be solved for a capture.
    #[error("capture {measurement} (row {row} of the captures file): {failure}")]
    Capture { measurement: i64, row: usize, failure: crate::solver::spatial::SpatialError },
}
