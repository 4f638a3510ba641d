//! The model-discrepancy workflow behind `cablemap diagnose`: fit the thesis
//! model, judge it against the noise, refit with each candidate effect, name
//! the effect the data call for (or none, or the two it cannot tell apart,
//! or that no library effect explains the data), and write the report.
//!
//! [`run`] takes a [`DiagnoseRequest`] and returns a [`DiagnoseReport`],
//! which serialises itself (the `--json` object) and displays itself (the
//! summary). The rounds and the verdict are one state machine for both
//! kinds of data ([`rounds`]), the naming rule in [`criterion`]; each kind
//! gives its refits and report: planar measurements in [`analysis`] (the
//! Markdown report in [`markdown`]), captures with 3-D markers in
//! [`captures`] (the report in [`captures_report`]).

pub mod analysis;
pub mod captures;
pub mod captures_report;
pub mod criterion;
pub mod diagnosis;
pub mod markdown;
pub mod report;
pub mod rounds;
pub mod run;
pub mod verdict;

pub use analysis::{diagnose, model_name};
pub use diagnosis::{DiagnoseSpec, Diagnosis, DiagnosisKind, Signature};
pub use criterion::{Candidate, NamedEffect};
pub use report::DiagnoseReport;
pub use crate::calibrate::request::DiagnoseRequest;
pub use run::run;
pub use verdict::Verdict;
