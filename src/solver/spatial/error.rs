//! Why an actuator or a spatial solve was rejected ([`SpatialError`]), and
//! why the spatial solver found no solution ([`SpatialFailure`]).

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
    /// A tension scale that is negative or not finite.
    #[error("spatial solver: tension scale {0} must be finite and ≥ 0")]
    TensionScale(f64),
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
    Solve(#[from] SpatialFailure),
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

/// Why a spatial solve produced no result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpatialFailure {
    /// The local equations at a point did not converge.
    #[error("the cut equations did not converge at s = {s_mm:.3} mm (tension too high for this routing, or a cable pulls straight through the axis); lower the tension or raise --steps-per-span")]
    Local { s_mm: f64 },
    /// Gravity's moment iteration did not converge.
    #[error("gravity's moment did not converge in {passes} passes (residual {residual_n_mm:.3e} N·mm); the rod may be too heavy for its stiffness")]
    Gravity { passes: u32, residual_n_mm: f64 },
    /// A number of the result is not finite.
    #[error("the solve gave a non-finite tip or coefficient; check the rod's parameters (rigidities, length, density) for absurd values")]
    NonFinite,
    /// A displacement-driven cable's displacement was not met.
    #[error(transparent)]
    DisplacementNotMet(crate::solver::actuation::DisplacementNotMet),
    /// The cables' tension profiles with friction did not settle.
    #[error("the cable tension profiles with friction did not converge; try smaller tension steps or a smaller friction coefficient")]
    Friction,
    /// The steps do not resolve the solution: its difference to the same
    /// solve at half the steps is above the tolerance, up to the most steps
    /// tried ([`crate::solver::simulate_spatial`]), or the tip lies farther from the
    /// clamp than the stretched rod is long.
    #[error(transparent)]
    Unresolved(crate::solver::Unresolved),
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

impl SpatialFailure {
    /// Short machine-readable status (as the planar solver's
    /// [`crate::solver::SolveFailure::status`]).
    pub fn status(&self) -> &'static str {
        match self {
            SpatialFailure::Local { .. } => "cut_equations_not_converged",
            SpatialFailure::Gravity { .. } => "gravity_not_converged",
            SpatialFailure::NonFinite => "non_finite",
            SpatialFailure::Friction => "friction_not_converged",
            SpatialFailure::DisplacementNotMet(_) => "displacement_not_met",
            SpatialFailure::Unresolved(_) => "unresolved",
        }
    }
}

