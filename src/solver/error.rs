//! Why a single simulation produced no result ([`SimulateError`]).

use super::resolution::OrderError;
use super::backend::Unsupported;
use super::SolveFailure;
use crate::model::ParameterError;

/// Why [`super::simulate`] or [`super::simulate_held`] produced no result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimulateError {
    /// The actuator, solver options or hold are invalid.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// A coefficient order the discretisation does not resolve
    /// ([`crate::solver::resolution`]).
    #[error(transparent)]
    Unresolved(#[from] OrderError),
    /// The backend asked for does not model this rod ([`super::Backend::check`]).
    #[error(transparent)]
    Unsupported(#[from] Unsupported),
    /// A solve of the tension ladder failed.
    #[error(transparent)]
    Solve(#[from] SolveFailure),
}
