//! The model-discrepancy workflow behind `cablemap diagnose`: fit the thesis
//! model, judge it against the noise, refit with each candidate effect, name
//! the effect the data call for (or none, or the two it cannot tell apart,
//! or that no library effect explains the data), and write the report.
//!
//! [`run`] takes a [`DiagnoseRequest`] and returns a [`DiagnoseReport`],
//! which serialises itself (the `--json` object) and displays itself (the
//! summary). The naming rule (shared with the 3-D diagnosis of captures) is in
//! [`criterion`], the planar workflow in [`analysis`], the Markdown report and its
//! plots in [`markdown`].

pub mod analysis;
pub mod criterion;
pub mod markdown;
pub mod report;
pub mod rounds;
pub mod run;
pub mod verdict;

pub use analysis::{diagnose, model_name, DiagnoseSpec, Diagnosis};
pub use criterion::{Candidate, NamedEffect};
pub use report::{DiagnoseReport, MeasurementsDiagnosis};
pub use crate::calibrate::request::DiagnoseRequest;
pub use run::run;
pub use verdict::Verdict;
