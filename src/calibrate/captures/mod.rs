//! Calibration, prediction and diagnosis with several cables and 3-D
//! markers: captures with one actuation column per cable,
//! body-fixed markers measured in the clamp frame, an actuator file, and
//! the 3-D solver ([`crate::solver::spatial::SpatialSolver`]).
//!
//! - [`files`]: reading the captures and markers files (CSV, Parquet).
//! - [`simulate`]: solving captures in warm-started chains; markers on the body.
//! - [`errors`]: the markers' 3-D errors per capture, per marker and overall.
//! - [`synth`]: synthetic captures with a hidden effect and noise.
//! - [`run`]: the `predict` and `calibrate` requests and their reports.
//! - [`diagnose`]: the planar diagnosis's verdicts over the registry's effects in 3-D.
//! - [`report`]: a diagnosis's report directory (`report.md`, a picture per capture).

pub mod diagnose;
pub mod errors;
pub mod files;
pub mod report;
pub mod run;
pub mod simulate;
pub mod synth;

pub use diagnose::{diagnose_captures, Diagnose3Spec, Diagnosis3};
pub use errors::ErrorReport;
pub use files::{read_capture_set, Actuation, Capture, CaptureSet, MarkerReading};
pub use run::{calibrate, calibrated_toml, diagnose_request, predict, CapturesCalibration, PredictReport, PredictRequest};
pub use simulate::{solve_captures, CaptureSolution};
