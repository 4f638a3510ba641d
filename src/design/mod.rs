//! Feasibility check and cable-routing design (thesis §3.4, Ch. 5; eq. 3.17)
//! of an actuator with 1–8 cables: one search for the thesis's one planar
//! cable and one target (`design --target`) and for several cables, targets
//! or a trajectory (`design --targets`, docs/design.md).
//!
//! - [`target`]: the thesis's `--target` list and its weights, over the
//!   same [`targets::Quantity`] as a targets file;
//!   [`targets`]: a targets file (`[[target]]`, `[trajectory]`).
//! - [`actuator`]: the actuator file with what each cable may change.
//! - [`objective`]: eq. 3.17 of one planar cable as weighted residuals, and
//!   its bounds; [`sequence`]: eq. 3.17 summed over targets, for 1–N cables.
//! - [`search`]: the one multi-start bounded Levenberg–Marquardt, over
//!   either problem.
//! - [`map`], [`map_channels`]: reading a feasibility map directory
//!   (`docs/maps.md`) and its designs as seeds; [`feasible`], [`reach`]:
//!   the map's verdict on a target before any optimisation;
//!   [`feasible_request`]: the request of `cablemap feasible`.
//! - [`record`]: design.json, its fields, writer and reader;
//!   [`export`], [`sequence_export`]: the design's files.
//! - [`trajectory`]: the tip path between waypoints.
//! - [`request`]: the one request of `cablemap design` and its check;
//!   [`run`], [`sequence_run`]: its workflow; [`report`]: what the
//!   one-target design returns.

pub mod actuator;
pub mod export;
pub mod feasible;
pub mod feasible_request;
pub mod map;
pub mod map_channels;
pub mod objective;
pub mod reach;
pub mod record;
pub mod report;
pub mod request;
pub mod run;
pub mod search;
pub mod sequence;
pub mod sequence_export;
pub mod sequence_report;
pub mod sequence_run;
pub mod target;
pub mod targets;
pub mod trajectory;

pub use objective::{compare, Bounds, Evaluation, Objective};
pub use search::{SearchOptions, SeedSource, StartReport, Termination};
pub use request::DesignRequest;
pub use run::{run, DesignReport};
pub use target::{Target, Weights};
pub use targets::{ComponentOutcome, Quantity};

/// A target's tip farther from the clamp than the rod is long (its asked
/// components alone): no design reaches it.
#[derive(Debug, Clone, PartialEq)]
pub struct TipBeyondReach {
    /// The target's name.
    pub target: String,
    /// The tip's asked components (x, y, z), mm.
    pub tip_mm: [Option<f64>; 3],
    /// Their distance from the clamp, mm.
    pub distance_mm: f64,
    /// The rod's length L, mm.
    pub length_mm: f64,
}

impl std::fmt::Display for TipBeyondReach {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let given: Vec<String> = ["x", "y", "z"].iter().zip(self.tip_mm).filter_map(|(k, v)| v.map(|v| format!("{k} = {v}"))).collect();
        write!(
            f,
            "{}: the tip ({}) is {} mm from the clamp, beyond the rod's length L = {} mm: it misses by at least {} mm",
            self.target,
            given.join(", "),
            sequence_report::fmt6(self.distance_mm),
            self.length_mm,
            sequence_report::fmt6(self.distance_mm - self.length_mm)
        )
    }
}

/// Why a feasibility check or a design could not be made.
#[derive(Debug, thiserror::Error)]
pub enum DesignError {
    /// The target is malformed.
    #[error("bad target: {problem}")]
    BadTarget {
        /// What is wrong.
        problem: target::ListProblem,
    },
    /// The weights are malformed or inconsistent with the target.
    #[error("bad weights: {problem}")]
    BadWeights {
        /// What is wrong.
        problem: target::ListProblem,
    },
    /// Both or neither of a target and a targets file.
    #[error("give either a target (--target) or a targets file (--targets)")]
    TargetOrTargets,
    /// An actuator file with the one-target design, which designs one planar cable on a rod.
    #[error("--target designs one planar cable on a rod: give the rod alone, or --targets FILE.toml with --actuator FILE.toml for several cables")]
    ActuatorWithTarget,
    /// A setting of the one-target design given with a targets file.
    #[error("{} does not apply to --targets: give {}", setting.flag(), setting.instead())]
    TargetOnly {
        /// Which.
        setting: request::TargetOnly,
    },
    /// A rod file beside an actuator file, which holds the rod.
    #[error("give the rod either in --actuator FILE's [rod] table or by --actuator-file, not both")]
    RodTwice,
    /// `feasible` with neither a map nor a study.
    #[error("give --map MAP_DIR or --study DIR")]
    NoMapOrStudy,
    /// `feasible` with both a map and a study.
    #[error("give --map or --study, not both")]
    MapAndStudy,
    /// `--targets` with a study: the map of a cable sweep answers a targets file.
    #[error("--targets needs --map: the map of a cable sweep")]
    TargetsNeedMap,
    /// The tolerance is not a finite percentage ≥ 0.
    #[error("bad search setting: the tolerance must be a finite number ≥ 0 %, got {tolerance_pct}")]
    Tolerance {
        /// The tolerance given, %.
        tolerance_pct: f64,
    },
    /// No start to refine.
    #[error("bad search setting: the number of starts must be at least 1")]
    NoStarts,
    /// The largest control-point offset is outside the body.
    #[error("bad bounds: the largest control-point offset must lie in (0, r) = (0, {radius_mm}) mm, got {max_offset_mm} mm")]
    MaxOffset {
        /// The offset asked, mm.
        max_offset_mm: f64,
        /// The channel radius r, mm.
        radius_mm: f64,
    },
    /// The tension bounds are unusable for the one-cable search.
    #[error("bad bounds: tension bounds must satisfy 0 < τ_l ≤ τ_u (finite), got τ_l = {tension_min_n} N, τ_u = {tension_max_n} N")]
    TensionBounds {
        /// τ_l, N.
        tension_min_n: f64,
        /// τ_u, N.
        tension_max_n: f64,
    },
    /// The target asks for coefficients the solver's steps cannot resolve.
    #[error("bad target: {source}")]
    Resolution {
        /// What the solver settings resolve.
        #[source]
        source: crate::solver::resolution::OrderError,
    },
    /// Re-solving the design found by `simulate`'s own path failed.
    #[error("bad search setting: re-simulating the design found: {source}")]
    Resimulate {
        /// Why.
        #[source]
        source: crate::solver::spatial::SpatialError,
    },
    /// The export directory lies in a sweep's run directory.
    #[error(transparent)]
    ExportDir {
        /// Where it lies.
        #[from]
        source: crate::io::InsideRunDir,
    },
    /// A design.json that cannot be read back.
    #[error("{} {problem}; give a design.json written by `cablemap design --out`", path.display())]
    DesignFile {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong with it.
        problem: record::DesignFileProblem,
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
    #[error("unreachable: {}", tips.iter().map(ToString::to_string).collect::<Vec<_>>().join("; "))]
    Unreachable {
        /// Each target whose tip lies beyond the rod's length.
        tips: Vec<TipBeyondReach>,
    },
    /// A targets file that cannot be read or breaks its format (docs/design.md).
    #[error("bad target: {}{message}", path.as_ref().map_or(String::new(), |p| format!("{}: ", p.display())))]
    TargetsFile {
        /// The file, when read from one.
        path: Option<std::path::PathBuf>,
        /// What the file gets wrong, in the file's own terms.
        message: String,
    },
    /// An actuator file of a design that cannot be read or breaks its format.
    #[error("bad bounds: {file}: {message}")]
    ActuatorFile {
        /// The file (or the text's name).
        file: String,
        /// What the file gets wrong, in the file's own terms.
        message: String,
    },
    /// The designed channels are no channels (written to the design's files).
    #[error("bad bounds: the designed channels: {source}")]
    Channels {
        /// Why.
        source: crate::model::ActuatorError,
    },
    /// Writing a target's actuator file.
    #[error("bad bounds: writing the actuator of {target}: {source}")]
    ActuatorToml {
        /// The target's name.
        target: String,
        /// Why.
        source: toml::ser::Error,
    },
    /// Re-solving a target's design for its picture.
    #[error("bad bounds: re-simulating {target}: {source}")]
    ResimulateTarget {
        /// The target's name.
        target: String,
        /// Why.
        source: crate::solver::spatial::SpatialError,
    },
    /// Invalid actuator parameters.
    #[error(transparent)]
    Parameter(#[from] crate::model::ParameterError),
    /// No seed design could be simulated, so there is nothing to refine.
    #[error("no starting design could be simulated within the bounds; check the actuator parameters and tension bounds")]
    NoSeed,
    /// A map directory breaks the map contract, or was made for another
    /// actuator or basis than the design's.
    #[error("map {}: {problem}", path.display())]
    Map {
        /// The map directory.
        path: std::path::PathBuf,
        /// What is wrong, and what to do.
        problem: map::MapMismatch,
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
