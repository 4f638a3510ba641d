//! cablemap: configuration design of planar cable-driven soft actuators.
//!
//! The pipeline runs one way: [`model`] (routing, rod, effects, solver) →
//! [`shape`] (Legendre curvature coefficients) → [`sweep`] → reduce → design
//! and calibrate. Each layer has its own error enum, joined here in
//! [`Error`].
//!
//! Workflows are requests in, reports out (each report serialises to the
//! JSON `--json` prints and displays as the text the command prints):
//! [`map::run`] (sweep and reduce of any [`job::Job`]), [`study::run`],
//! [`design::run`], [`design::feasible_request::run`], [`synth::run`].

pub mod bench;
pub mod calibrate;
pub mod design;
pub mod io;
pub mod job;
pub mod map;
pub mod model;
pub mod mould;
pub mod numerics;
pub mod plot;
pub mod reduce;
pub mod shape;
pub mod solver;
pub mod study;
pub mod sweep;
pub mod synth;

/// Any error of the library, by layer.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Invalid routing.
    #[error(transparent)]
    Routing(#[from] model::RoutingError),
    /// Invalid actuator parameters.
    #[error(transparent)]
    Parameter(#[from] model::ParameterError),
    /// A solve failed.
    #[error(transparent)]
    Solve(#[from] crate::solver::SolveFailure),
    /// A single simulation (parameters or a solve) failed.
    #[error(transparent)]
    Simulate(#[from] crate::solver::SimulateError),
    /// Spatial (several-cable) actuator or solve.
    #[error(transparent)]
    Spatial(#[from] crate::solver::spatial::SpatialError),
    /// Shape coefficients could not be computed.
    #[error(transparent)]
    Shape(#[from] shape::ShapeError),
    /// Calibration and diagnosis.
    #[error(transparent)]
    Calibrate(#[from] calibrate::CalibrateError),
    /// Reducing a run into maps.
    #[error(transparent)]
    Reduce(#[from] reduce::ReduceError),
    /// Drawing a picture.
    #[error(transparent)]
    Plot(#[from] plot::PlotError),
    /// Feasibility check or design.
    #[error(transparent)]
    Design(#[from] design::DesignError),
    /// Running, checking or reading a sweep.
    #[error(transparent)]
    Sweep(#[from] sweep::SweepError),
    /// Building or writing moulds.
    #[error(transparent)]
    Mould(#[from] mould::MouldError),
    /// A job spec.
    #[error(transparent)]
    Job(#[from] job::JobError),
    /// A map of a job or a run.
    #[error(transparent)]
    Map(#[from] map::MapError),
    /// A study.
    #[error(transparent)]
    Study(#[from] study::StudyError),
    /// Synthetic measurements.
    #[error(transparent)]
    Synth(#[from] synth::SynthError),
    /// Reading or writing a file.
    #[error(transparent)]
    File(#[from] io::FileError),
}
