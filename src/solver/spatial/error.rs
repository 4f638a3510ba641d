//! Why an actuator or a spatial solve was rejected ([`SpatialError`]); why
//! a solve found no solution is the one [`crate::solver::SolveFailure`].

use crate::model::{ActuatorError, ParameterError};

/// Why a spatial actuator or solve was rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpatialError {
    /// The actuator itself is refused, whichever backend serves it.
    #[error(transparent)]
    Actuator(#[from] ActuatorError),
    /// A rod parameter is bad.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// The solver serving the request does not model part of it
    /// ([`crate::solver::Backend::check`]).
    #[error(transparent)]
    Unsupported(#[from] crate::solver::Unsupported),
    /// A planar solve (the fast path of a one-cable in-plane actuator) failed.
    #[error(transparent)]
    Planar(#[from] crate::solver::error::SimulateError),
    /// Too few RK4 steps per span.
    #[error("spatial solver: steps_per_span = {0} must be at least 2")]
    StepsPerSpan(usize),
    /// Collocation intervals per span outside 4 … `max`.
    #[error("spatial solver: nodes_per_span = {nodes} must be between 4 and {max}")]
    NodesPerSpan { nodes: usize, max: usize },
    /// A moment tolerance that is not a positive number.
    #[error("spatial solver: moment_tolerance_n_mm must be a positive number")]
    MomentTolerance,
    /// Not one tension per cable.
    #[error("spatial solver: {given} tensions given for {cables} cables")]
    TensionCount { given: usize, cables: usize },
    /// The body along s (radius profile, segments) is invalid.
    #[error("spatial solver: {0}")]
    Body(crate::model::BodyError),
    /// A dwell that is not a finite time ≥ 0 s.
    #[error("spatial solver: dwell_s = {0} must be a finite time ≥ 0 s")]
    Dwell(f64),
    /// A coefficient order above every the solver resolves.
    #[error("spatial solver: order {order} is above the spatial solver's highest order {max}")]
    OrderAbove { order: usize, max: usize },
    /// A coefficient order the RK4 reference's steps do not resolve.
    #[error("spatial solver: order {order} needs at least {need} RK4 steps per span to be resolved (have {have}); raise --steps-per-span (spec: steps_per_span) or lower the order")]
    OrderSteps { order: usize, need: usize, have: usize },
    /// A planar cable's anchor given both on the cable and on the rod, differently.
    #[error(
        "spatial solver: cable 1 has anchor={} mm and the rod cable_anchor_mm = {} mm: give the anchor once",
        crate::io::fmt_num(*cable_mm),
        crate::io::fmt_num(*rod_mm)
    )]
    AnchorTwice { cable_mm: f64, rod_mm: f64 },
    /// The solve failed.
    #[error(transparent)]
    Solve(#[from] crate::solver::SolveFailure),
}

impl SpatialError {
    /// The status a sweep stores for a failed solve (`unresolved`,
    /// `non_finite`, …), whichever backend failed; `None` for bad input.
    pub fn failure_status(&self) -> Option<&'static str> {
        match self {
            SpatialError::Solve(f) => Some(f.status()),
            SpatialError::Planar(crate::solver::error::SimulateError::Solve(f)) => Some(f.status()),
            _ => None,
        }
    }
}

impl SpatialError {
    /// Checks a solve's tensions: one per cable, each finite and ≥ 0.
    pub fn check_tensions(tensions_n: &[f64], cables: usize) -> Result<(), SpatialError> {
        if tensions_n.len() != cables {
            return Err(SpatialError::TensionCount { given: tensions_n.len(), cables });
        }
        for (i, &t) in tensions_n.iter().enumerate() {
            if !(t.is_finite() && t >= 0.0) {
                return Err(ActuatorError::Tension { cable: i + 1, tension_n: t }.into());
            }
        }
        Ok(())
    }
}
