//! Feasibility check and cable-routing design (thesis §3.4, Ch. 5; eq. 3.17).
//!
//! - [`target`]: what the designer asks for (tip, curvature coefficients, weights).
//! - [`objective`]: eq. 3.17 as weighted residuals, and the bounds.
//! - [`optimise`]: multi-start bounded Levenberg–Marquardt.
//! - [`map`]: reading a feasibility map directory (`docs/maps.md`).
//! - [`feasible`]: the map's verdict on a target before any optimisation.
//! - [`export`]: design JSON, channel CSV, 1:1 mould SVG, achieved-vs-target PNG.

pub mod export;
pub mod feasible;
pub mod map;
pub mod objective;
pub mod optimise;
pub mod target;

pub use objective::{Bounds, Evaluation, Objective};
pub use optimise::{compare, design, ComponentResult, DesignOutcome, SearchOptions, Seed, SeedSource};
pub use target::{Component, Target, Weights};

/// Why a feasibility check or a design could not be made.
#[derive(Debug, thiserror::Error)]
pub enum DesignError {
    /// The `--target` text is malformed.
    #[error("bad --target: {0}")]
    BadTarget(String),
    /// The `--weights` text is malformed or inconsistent with the target.
    #[error("bad --weights: {0}")]
    BadWeights(String),
    /// Tension or offset bounds are unusable.
    #[error("bad bounds: {0}")]
    BadBounds(String),
    /// Invalid actuator parameters.
    #[error(transparent)]
    Parameter(#[from] crate::model::ParameterError),
    /// No seed design could be simulated, so there is nothing to refine.
    #[error("no starting design could be simulated within the bounds; check the actuator parameters and tension bounds")]
    NoSeed,
    /// A map directory is missing a file or breaks the map contract.
    #[error("map {path}: {message}")]
    Map { path: String, message: String },
    /// Writing an export.
    #[error("{context}: {source}")]
    Io { context: String, source: std::io::Error },
    /// Drawing a picture.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
}
