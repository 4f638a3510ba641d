//! Feasibility check and cable-routing design (thesis §3.4, Ch. 5; eq. 3.17).
//!
//! - [`target`]: what the designer asks for (tip, curvature coefficients, weights).
//! - [`objective`]: eq. 3.17 as weighted residuals, and the bounds.
//! - [`optimise`]: multi-start bounded Levenberg–Marquardt.
//! - [`map`]: reading a feasibility map directory (`docs/maps.md`).
//! - [`feasible`]: the map's verdict on a target before any optimisation.
//! - [`record`]: design.json, its fields, writer and reader.
//! - [`export`]: the design's files: design.json, channel CSV, 1:1 mould SVG, achieved-vs-target PNG.
//! - [`run`]: the whole workflow of `cablemap design` (its request);
//!   [`report`]: what it returns and the text it prints.

pub mod cables;
pub mod export;
pub mod feasible;
pub mod map;
pub mod objective;
pub mod optimise;
pub mod record;
pub mod report;
pub mod run;
pub mod target;

pub use objective::{Bounds, Evaluation, Objective};
pub use optimise::{compare, design, ComponentResult, DesignOutcome, SearchOptions, Seed, SeedSource};
pub use target::{Component, Target, Weights};

/// Why a feasibility check or a design could not be made.
#[derive(Debug, thiserror::Error)]
pub enum DesignError {
    /// The target is malformed or asks for what the solver cannot resolve.
    #[error("bad target: {0}")]
    BadTarget(String),
    /// The weights are malformed or inconsistent with the target.
    #[error("bad weights: {0}")]
    BadWeights(String),
    /// A search setting is unusable (tolerance, number of starts).
    #[error("bad search setting: {0}")]
    BadSearch(String),
    /// The export directory lies in a sweep's run directory.
    #[error(transparent)]
    ExportDir {
        /// Where it lies.
        #[from]
        source: crate::io::InsideRunDir,
    },
    /// A design.json that cannot be read back.
    #[error("{} {message}; give a design.json written by `cablemap design --out`", path.display())]
    DesignFile {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// Re-simulating a design (for its drawing) failed.
    #[error("re-simulating the design: {0}")]
    Simulate(#[from] crate::solver::SimulateError),
    /// The designed routing is not a valid channel.
    #[error(transparent)]
    Routing(#[from] crate::model::RoutingError),
    /// Building or writing the moulds.
    #[error(transparent)]
    Mould(#[from] crate::mould::MouldError),
    /// No design can reach the targets (found before any search).
    #[error("unreachable: {0}")]
    Unreachable(String),
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
    Map {
        /// The map directory or file.
        path: String,
        /// What is wrong, and what to do.
        message: String,
    },
    /// A map table cannot be read.
    #[error(transparent)]
    MapTable(#[from] crate::reduce::tables::ReadError),
    /// Reading a design or writing an export.
    #[error(transparent)]
    File(#[from] crate::io::FileError),
    /// Drawing a picture.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    /// A study directory's record (`feasible --study`).
    #[error(transparent)]
    Study(#[from] Box<crate::study::StudyError>),
    /// A study variant's map.
    #[error("variant {index} ({label}): run the study to finish its map: {source}")]
    Variant {
        /// Variant number.
        index: usize,
        /// Its settings.
        label: String,
        /// Why its map cannot be read.
        source: Box<DesignError>,
    },
}
