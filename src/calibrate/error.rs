//! The calibration layer's errors: each variant carries typed fields, the
//! sentence is made by `Display`.

use super::Effect;

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
    #[error("{path}: row {row}: {problem}")]
    Malformed { path: String, row: usize, problem: TableProblem },
    /// The file's geometry header (`# key = value` lines before the CSV
    /// header) is invalid.
    #[error("{path}: the geometry header (the '#' lines before the column names): {problem}; see docs/measurements.md")]
    Geometry { path: String, problem: GeometryProblem },
    /// Rows contradict each other.
    #[error("{path}: row {row}: {conflict}")]
    Inconsistent { path: String, row: usize, conflict: RowConflict },
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
    /// A setting the request's kind of data cannot use.
    #[error(transparent)]
    Refused(#[from] Refused),
    /// The request cannot be carried out on this data.
    #[error(transparent)]
    Invalid(#[from] InvalidRequest),
    /// The routing or cable to hold out is not one the data can spare.
    #[error(transparent)]
    Holdout(#[from] HoldoutError),
    /// The measurement noise is not a standard deviation.
    #[error(transparent)]
    Noise(#[from] NoiseError),
    /// A value to hold a parameter at is not valid.
    #[error(transparent)]
    Held(HeldError),
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

/// A request the data or the settings cannot carry out.
#[derive(Debug, thiserror::Error)]
pub enum InvalidRequest {
    /// A synthetic marker off the rod, or not finite.
    #[error("marker at s = {s_mm} mm, offset {offset_mm} mm: s must lie on the rod (0 … {length_mm} mm) and both must be finite")]
    MarkerOffRod { s_mm: f64, offset_mm: f64, length_mm: f64 },
    /// A loading protocol without a tension or a step.
    #[error("the protocol needs a top tension > 0 N and at least one load step (got {max_tension_n} N, {load_steps} steps)")]
    Protocol { max_tension_n: f64, load_steps: usize },
    /// A setting that must be finite and ≥ 0.
    #[error("{name} = {value} must be a finite number ≥ 0")]
    Negative { name: &'static str, value: f64 },
    /// A synthetic data set without routings.
    #[error("give at least one routing")]
    NoRoutings,
    /// More load steps than a bench protocol uses.
    #[error("load_steps = {load_steps} is more than the {max} a bench protocol uses: give --load-steps ≤ {max}")]
    TooManyLoadSteps { load_steps: usize, max: usize },
    /// More centreline points per reading than the files take.
    #[error("{points} centreline points per reading is more than {max}: give --centreline-points ≤ {max}")]
    TooManyCentrelinePoints { points: usize, max: usize },
    /// A clamp tilt that is not finite.
    #[error("routing {routing}: clamp tilt {tilt_rad} must be finite")]
    ClampTilt { routing: String, tilt_rad: f64 },
    /// Measured tips farther from the clamp than the rod can reach.
    #[error(
        "the measurements are absurdly far from any shape the rod can take: the tips are up to {}× farther from the clamp than \
         the rod is long (tip_x_mm = {}, tip_y_mm = {} on row {row}; L = {} mm){}; give the tips in mm (check the units, the \
         column order and the rod length)",
        crate::io::fmt_sig(*.ratio, 3),
        crate::io::fmt_num(*.tip_x_mm),
        crate::io::fmt_num(*.tip_y_mm),
        crate::io::fmt_num(*.length_mm),
        if (300.0..3000.0).contains(.ratio) { " — are they in µm?" } else { "" }
    )]
    TipsOutOfReach { ratio: f64, tip_x_mm: f64, tip_y_mm: f64, row: usize, length_mm: f64 },
    /// An angle weight that is negative or not finite.
    #[error("the angle weight must be a finite number ≥ 0 mm per degree, got {value}")]
    AngleWeight { value: f64 },
    /// Fewer tip residuals than parameters.
    #[error("{residuals} residuals ({readings} readings) cannot determine {parameters} parameters; measure more steps or routings, or hold parameters fixed (--fix)")]
    TooFewResiduals { residuals: usize, readings: usize, parameters: usize },
    /// Fewer marker coordinates than parameters.
    #[error("{coordinates} marker coordinates cannot determine {parameters} parameters; measure more markers or captures, or hold parameters (--fix)")]
    TooFewMarkerCoordinates { coordinates: usize, parameters: usize },
    /// Residuals so large that no step can lower them.
    #[error(
        "the measurements are absurdly far from any shape the actuator can take (a tip coordinate of {} mm, a \
         residual of {} noise widths): check the units (mm and degrees) and the column order of the data",
        crate::io::fmt_num(*.farthest_mm),
        crate::io::fmt_num(*.worst_noise_widths)
    )]
    AbsurdResiduals { farthest_mm: f64, worst_noise_widths: f64 },
    /// The noise test's level outside (0, 1).
    #[error("the noise test's level must lie in (0, 1), got {alpha}")]
    Alpha { alpha: f64 },
    /// The density fitted while gravity is off.
    #[error("the density is fitted through the weight, but the actuator's gravity is off; hold it or switch gravity on")]
    DensityWithoutGravity,
    /// A captures file with a column for a cable the actuator does not have.
    #[error("{}: column '{column}' names cable {cable}, but the actuator has {cables} cable(s); give one [[cable]] table per cable in the actuator file, in the columns' order", .path.display())]
    CableColumnBeyond { path: std::path::PathBuf, column: String, cable: usize, cables: usize },
    /// A cable driven both by its tension and by its displacement.
    #[error("{}: both '{tension}' and '{displacement}' are given; cable {cable} is driven either by its tension or by its displacement", .path.display())]
    BothDrives { path: std::path::PathBuf, tension: String, displacement: String, cable: usize },
    /// An effect of no known name.
    #[error("--effect {name}: unknown effect; use one of {}", super::Effect::ALL.map(super::Effect::name).join(", "))]
    UnknownEffect { name: String },
    /// A loss of no known name.
    #[error("--loss {name}: use huber or squares")]
    Loss { name: String },
    /// Huber's k not a number of σ > 0.
    #[error("--huber-k {k}: must be a number of σ > 0")]
    HuberK { k: f64 },
    /// The fitted actuator cannot be written as TOML.
    #[error("writing the calibrated actuator: {0}")]
    CalibratedToml(#[source] toml::ser::Error),
}

/// A routing or cable to hold out that the data cannot spare.
#[derive(Debug, thiserror::Error)]
pub enum HoldoutError {
    /// No routing of that id.
    #[error("no routing '{routing}' in the data to hold out (routings: {})", .routings.join(", "))]
    UnknownRouting { routing: String, routings: Vec<String> },
    /// The only routing.
    #[error("routing {routing} is the only routing; holding it out would leave nothing to fit")]
    OnlyRouting { routing: String },
    /// No cable of that number.
    #[error("cable {cable}: the actuator has cables 1 to {cables}")]
    NoSuchCable { cable: usize, cables: usize },
    /// Every capture, or none, pulls the cable.
    #[error("cable {cable}: {pulling} captures pull it and {others} do not; holding it out needs both")]
    NotSeparable { cable: usize, pulling: usize, others: usize },
}

/// A noise level that is not a standard deviation.
#[derive(Debug, thiserror::Error)]
pub enum NoiseError {
    /// The measurement noise of a fit (`noise_mm`, `noise_deg`).
    #[error("{name} = {value}: the measurement noise must be a standard deviation > 0")]
    Measurement { name: &'static str, value: f64 },
    /// The markers' noise of a 3-D fit.
    #[error("noise_mm = {value}: the markers' noise must be a standard deviation > 0")]
    Markers { value: f64 },
    /// The noise of synthetic captures.
    #[error("noise_mm = {value}: the noise must be a standard deviation ≥ 0")]
    Synthetic { value: f64 },
}

/// A value to hold a parameter at (`--fix`) that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum HeldError {
    /// Not a finite number.
    #[error("held value {value} is not a finite number")]
    NotFinite { value: f64 },
    /// A rigidity or density that is not a finite number > 0.
    #[error("{name} = {value}: a held value must be a finite number (> 0 for a rigidity or the density)")]
    NotPositive { name: &'static str, value: f64 },
    /// A `--fix` item that cannot be read.
    #[error("--fix {item}: {reason}")]
    Item { item: String, reason: HeldItem },
    /// GJ or the density held on planar data.
    #[error("{name}: GJ and the density are fitted or held only on captures with 3-D markers (--actuator FILE.toml); planar data fit EA, GA, EI and effects")]
    NotPlanar { name: &'static str },
    /// The rod with the held values is not valid.
    #[error(transparent)]
    Rod(#[from] crate::model::ParameterError),
}

/// Why a `--fix NAME=VALUE` item cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum HeldItem {
    /// No `=`.
    #[error("expected NAME=VALUE, e.g. GA=1.70866")]
    NoValue,
    /// No parameter of that name.
    #[error("unknown parameter '{name}'; use EI, EA, GA, GJ, density or one of {}", Effect::ALL.iter().map(|e| e.parameter_name()).collect::<Vec<_>>().join(", "))]
    Unknown { name: String },
    /// The value is not a number.
    #[error("'{value}' is not a number")]
    NotANumber { value: String },
}

/// A setting the request's kind of data cannot use.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Refused {
    /// A routing to hold out, with captures.
    #[error("--holdout takes a routing of planar data; with --actuator, hold out a cable's captures by --holdout-cable K")]
    RoutingHoldoutOnCaptures,
    /// Planar centreline points, with captures.
    #[error("--centrelines: planar centreline points; with --actuator, give 3-D markers by --markers")]
    CentrelinesOnCaptures,
    /// Rod settings, with captures: the rod is the actuator file's.
    #[error("with --actuator the rod and its effects come from FILE.toml's [rod] table; edit it instead of giving rod flags")]
    RodOnCaptures,
    /// Held values in a diagnosis of captures.
    #[error("--fix with --actuator: set the value in FILE.toml instead (a diagnosis fits the body the data determine)")]
    HeldInCapturesDiagnosis,
    /// The captures' outputs and held-out cable, on planar data.
    #[error("--out and --holdout-cable calibrate captures against 3-D markers: give the actuator with --actuator FILE.toml")]
    CapturesSettingsOnMeasurements,
    /// A cable to hold out, in a diagnosis of planar data.
    #[error("--holdout-cable holds out a cable's captures: give the actuator with --actuator FILE.toml")]
    CableHoldoutOnMeasurements,
    /// Rod settings in a prediction: the rod is the actuator file's.
    #[error("predict takes the rod from --actuator FILE.toml's [rod] table; edit it instead of giving rod flags")]
    RodOnPredict,
    /// No Levenberg–Marquardt iteration.
    #[error("--max-iterations must be at least 1")]
    NoIterations,
}

/// Why a table cannot be split into rows and cells.
#[derive(Debug, thiserror::Error)]
pub enum TableProblem {
    /// A CSV line that cannot be split into fields.
    #[error(transparent)]
    Line(#[from] CsvLineError),
    /// A header of one column holding another delimiter.
    #[error(
        "the header is one column with {name}s in it: the file looks {name}-separated, but measurement \
         CSV files are comma-separated (docs/measurements.md); save or export it with commas"
    )]
    OtherDelimiter { name: &'static str },
    /// A row with another number of fields than the header.
    #[error("{fields} fields, but the header has {header}")]
    FieldCount { fields: usize, header: usize },
    /// A column named twice (1-based positions).
    #[error("the header names column '{name}' twice (columns {first} and {second}); give each column once, so it is clear which values are meant")]
    DuplicateColumn { name: String, first: usize, second: usize },
    /// Not a Parquet file.
    #[error("not a readable Parquet file: {0}")]
    NotParquet(#[source] parquet::errors::ParquetError),
    /// Parquet data that cannot be decoded.
    #[error("reading Parquet data: {0}")]
    ParquetData(#[source] arrow::error::ArrowError),
    /// A Parquet column of a type without a text form.
    #[error("unsupported column type: {0}")]
    ColumnType(#[source] arrow::error::ArrowError),
}

/// Why a CSV line cannot be split into fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum CsvLineError {
    /// `a"b`: a quote inside a field that did not start with one.
    #[error("a quote in the middle of an unquoted field")]
    StrayQuote,
    /// `"a,b`: the line ends inside a quoted field.
    #[error("a quoted field is not closed")]
    Unclosed,
}

/// Why a measurement file's geometry header cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum GeometryProblem {
    /// Not TOML.
    #[error("{}", .0.to_string().trim_end())]
    Toml(#[source] toml::de::Error),
    /// `actuator_file` not a quoted file name.
    #[error("actuator_file = {value} must be a file name in quotes")]
    ActuatorFileName { value: String },
    /// The rod file it names is not valid.
    #[error(transparent)]
    RodFile(#[from] crate::model::rod::ActuatorFileError),
    /// The rod it describes is not valid.
    #[error(transparent)]
    Rod(#[from] crate::model::rod::RodTextError),
    /// The merged rod cannot be written back as TOML.
    #[error("{0}")]
    Merge(#[source] toml::ser::Error),
}

/// How a row contradicts another.
#[derive(Debug, thiserror::Error)]
pub enum RowConflict {
    /// A measurement id used twice in a measurement file.
    #[error("measurement id {measurement} already used on row {first}; ids must be unique")]
    MeasurementId { measurement: i64, first: usize },
    /// A routing's step given twice.
    #[error("routing '{routing}' has step {step} twice (rows {first} and {row}); steps order the protocol")]
    StepTwice { routing: String, step: i64, first: usize, row: usize },
    /// A routing id with other control points or tilt than before.
    #[error("routing '{routing}' has control points {y_mm:?} mm and clamp tilt {tilt_rad} rad here but {first_y_mm:?} mm and {first_tilt_rad} rad on row {first}; give each routing its own id")]
    RoutingChanged {
        routing: String,
        y_mm: [f64; crate::model::routing::CONTROL_POINTS],
        tilt_rad: f64,
        first_y_mm: [f64; crate::model::routing::CONTROL_POINTS],
        first_tilt_rad: f64,
        first: usize,
    },
    /// A capture id used twice.
    #[error("measurement id {measurement} is used again (first on row {first}); give each capture its own id")]
    CaptureId { measurement: i64, first: usize },
    /// A marker given twice in one capture.
    #[error("marker '{marker}' of measurement {measurement} is given twice (first on row {first}); name each marker once per capture")]
    MarkerTwice { marker: String, measurement: i64, first: usize },
    /// A marker named like the captures file's tip columns.
    #[error("marker '{marker}' of measurement {measurement} is also the captures file's tip columns; rename it")]
    MarkerIsTip { marker: String, measurement: i64 },
    /// A capture without any measured point.
    #[error("capture {measurement} has no measured point: give its markers in the markers file (--markers) or tip_x_mm, tip_y_mm, tip_z_mm columns")]
    NoPoint { measurement: i64 },
}
