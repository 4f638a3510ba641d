//! Calibration and the model-discrepancy workflow: the observations a fit
//! fits (planar measurement files, captures with 3-D markers:
//! [`observations`]), synthetic data with a hidden effect, the one fit of
//! the rigidities (thesis eq. 2.14), the weight and the effects ([`fit`]),
//! and the one diagnosis that names the missing effect ([`diagnose`]).

pub mod data;
pub mod diagnose;
pub mod effect;
pub mod error;
pub mod fit;
pub mod observations;
pub mod parameter;
pub mod predict;
pub mod request;
pub mod rng;
pub mod run;
pub mod stats;
pub mod synth;

pub use data::{read_measurements, Dataset, Direction, Measurement};
pub use effect::Effect;
pub use error::{CalibrateError, HeldError, HeldItem, HoldoutError, InvalidRequest, NoiseError, Refused};
pub use parameter::Parameter;
pub use fit::{fit, FitResult, FitSpec, FittedParameter, Status};
pub use request::{CalibrateRequest, DataKind, FitSettings, LossKind};
pub use run::{run, run_observed, CalibrateProgress, CalibrateReport, CapturesCalibration, MeasurementsCalibration};
