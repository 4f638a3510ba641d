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
    /// A numerical setting is bad.
    #[error("spatial solver: {0}")]
    Option(String),
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
            return Err(SpatialError::Option(format!("{} tensions given for {cables} cables", tensions_n.len())));
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

