//! The one multi-start search of a design, after argmin: a design problem
//! ([`Problem`]) says what its unknowns are (a unit box), how a point is
//! solved and differentiated, where its starts come from and how it
//! explores; one start is one bounded Levenberg–Marquardt run
//! ([`start::refine`], on the library's [`crate::numerics::lm`]) and the
//! multi-start ([`multistart::search`]) runs the starts in parallel and
//! keeps the first exact fit, else the least cost.
//!
//! The problems:
//! - [`routing`]: one cable in the bending plane, its five control points
//!   y_0…y_4 and its tension τ (the thesis's eq. 3.17 for one target);
//! - [`channels`]: every free channel coordinate of 1–N cables and one
//!   actuation per cable and target (eq. 3.17 summed over the targets).

pub mod channels;
pub mod multistart;
pub mod routing;
pub mod start;

use crate::numerics::lm;
use nalgebra::DMatrix;
use serde::Serialize;
use std::fmt;
use std::sync::atomic::{AtomicUsize, Ordering};

pub use multistart::{search, Found};
pub use start::{refine, Start};

/// An objective this small is an exact fit: errors near 1e-10 mm and
/// 1e-11 /mm, below the solver's own discretisation error. Reaching it ends
/// the search (without it, a zero-residual problem keeps LM iterating).
pub const COST_FLOOR: f64 = 1e-20;

/// Finite-difference step in the unit box (1e-5 mm in y at the thesis's
/// bounds): large against the solver's convergence noise (~1e-10 in a_i),
/// small against curvature.
pub const FD_STEP: f64 = 2e-6;

/// Settings of the multi-start search.
#[derive(Debug, Clone, Serialize)]
pub struct SearchOptions {
    /// Levels per control point of the routing problem's seed grid, as
    /// fractions of the largest offset (symmetric about 0).
    pub grid_levels: Vec<f64>,
    /// Tensions of the routing problem's seed grid, as fractions of [τ_l, τ_u].
    pub grid_tension_fractions: Vec<f64>,
    /// How many starts to refine to convergence.
    pub starts: usize,
    /// Most solves per converging start (per target: see [`Problem::budget`]).
    pub max_evaluations: usize,
}

/// Starts of the thesis's one-target design (`design --target`).
pub const ROUTING_STARTS: usize = 8;

/// Starts of a design for a sequence of targets (`design --targets`): each
/// start solves every target, so fewer.
pub const SEQUENCE_STARTS: usize = 4;

impl Default for SearchOptions {
    fn default() -> Self {
        Self {
            grid_levels: vec![-0.8, -0.4, 0.0, 0.4, 0.8],
            grid_tension_fractions: vec![0.0, 0.25, 0.5, 0.75, 1.0],
            starts: ROUTING_STARTS,
            max_evaluations: 1500,
        }
    }
}

/// Origin of a start.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SeedSource {
    /// The problem's own seed grid.
    Grid,
    /// A simulated design of a feasibility map.
    Map,
}

/// A starting point of a refinement, in the problem's unit box.
#[derive(Debug, Clone, PartialEq)]
pub struct Seed {
    /// The unit-box coordinates.
    pub point: Vec<f64>,
    /// Where it came from.
    pub source: SeedSource,
}

/// The starts a problem offers, best first, and what it simulated to rank them.
#[derive(Debug, Clone)]
pub struct Seeds {
    /// The chosen starting points.
    pub seeds: Vec<Seed>,
    /// Designs simulated to seed the search.
    pub simulated: usize,
}

/// A short first pass from many seeds before the converging one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exploration {
    /// Seeds explored per converging start.
    pub seeds_per_start: usize,
    /// Evaluation budget of each explored seed.
    pub evaluations: usize,
}

/// A start stops when its best cost fell by less than `fraction` over
/// `iterations` iterations: a flat valley, where the remaining gain is
/// below what any target's tolerance resolves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stall {
    /// Iterations looked back over.
    pub iterations: usize,
    /// Least relative fall of the best cost over them.
    pub fraction: f64,
}

/// A design problem as the search sees it: unknowns in a unit box, the
/// weighted residuals of eq. 3.17 at a point, their Jacobian, and the seeds.
pub trait Problem: Sync {
    /// What a solve at a point yields (the design and what it achieved).
    type Solution: Clone + Send + Sync;
    /// One start's solver state (a warm-started solver, the last solve).
    type Worker;

    /// A fresh worker (one per start).
    fn worker(&self) -> Self::Worker;

    /// The unit box and the free variables.
    fn settings(&self) -> lm::Settings;

    /// The residuals and the solution at `x`, counting each model solve in
    /// `evaluations`; `None` when the model cannot be solved there.
    fn solve(&self, worker: &mut Self::Worker, x: &[f64], evaluations: &mut usize) -> Option<(Vec<f64>, Self::Solution)>;

    /// The Jacobian at `x` (residuals `r`) over the variables `free`;
    /// its trial points go through [`Start::evaluate`] where they are whole
    /// designs (and may become the start's best).
    fn jacobian(start: &mut Start<'_, Self>, x: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>>
    where
        Self: Sized;

    /// Up to `count` starting points, best first.
    fn seeds(&self, count: usize) -> Result<Seeds, super::DesignError>;

    /// A converging start's budget for `max_evaluations` (per target where
    /// a point solves several).
    fn budget(&self, max_evaluations: usize) -> usize {
        max_evaluations
    }

    /// The short first pass, if the problem explores before converging.
    fn exploration(&self) -> Option<Exploration> {
        None
    }

    /// Where a start of the converging pass continues from, given the best
    /// point and solution of its exploration.
    fn resume_point(&self, x: &[f64], _solution: &Self::Solution) -> Vec<f64> {
        x.to_vec()
    }

    /// Whether two points have the same channels (the variables that are not
    /// an actuation): only one of them goes on to the converging pass.
    fn same_channels(&self, a: &[f64], b: &[f64]) -> bool;

    /// The stalling rule, if a start ends in a flat valley.
    fn stall(&self) -> Option<Stall> {
        None
    }
}

/// Why a start stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Termination {
    /// The cost reached [`COST_FLOOR`].
    ExactFit,
    /// A start before it in its pass fitted exactly.
    EarlierStartFitted,
    /// The evaluation budget is spent.
    Budget,
    /// The cost fell too little for too long ([`Stall`]).
    Stalled(Stall),
    /// The start itself could not be solved.
    Unsolvable,
    /// Levenberg–Marquardt's own ending.
    Minimiser(lm::Termination),
}

impl fmt::Display for Termination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Termination::ExactFit => f.write_str("exact fit (objective at the noise floor)"),
            Termination::EarlierStartFitted => f.write_str("stopped: an earlier start fitted exactly"),
            Termination::Budget => f.write_str("evaluation budget reached"),
            Termination::Stalled(s) => write!(f, "stalled: the cost fell by less than {} % over {} iterations", 100.0 * s.fraction, s.iterations),
            Termination::Unsolvable => f.write_str("the start could not be solved"),
            Termination::Minimiser(t) => write!(f, "{t}"),
        }
    }
}

impl Serialize for Termination {
    /// As its sentence (the text design.json has always held).
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

/// One start's refinement.
#[derive(Debug, Clone, Serialize)]
pub struct StartReport {
    /// The point it started from (unit box).
    #[serde(skip)]
    pub seed: Vec<f64>,
    /// Where that point came from.
    pub source: SeedSource,
    /// Cost at the start (inf when it could not be solved).
    pub seed_cost: f64,
    /// Cost at the end (inf when nothing was solved).
    pub cost: f64,
    /// Model solves used.
    pub evaluations: usize,
    /// Why it stopped.
    pub termination: Termination,
}

/// The lowest start index of a pass that reached [`COST_FLOOR`]. A start
/// stops once a start *before* it has fitted exactly, never for one after it:
/// so the first start that fits exactly always runs as if alone, and the
/// design chosen (the first exact fit, else the least cost) does not depend
/// on which thread finished first.
#[derive(Debug)]
pub struct ExactFit(AtomicUsize);

impl ExactFit {
    /// No start has fitted exactly yet.
    pub fn new() -> Self {
        ExactFit(AtomicUsize::new(usize::MAX))
    }

    fn record(&self, index: usize) {
        self.0.fetch_min(index, Ordering::Relaxed);
    }

    /// Whether a start before `index` fitted exactly.
    fn before(&self, index: usize) -> bool {
        self.0.load(Ordering::Relaxed) < index
    }

    /// Whether any start fitted exactly.
    pub fn any(&self) -> bool {
        self.0.load(Ordering::Relaxed) != usize::MAX
    }
}

impl Default for ExactFit {
    fn default() -> Self {
        Self::new()
    }
}
