//! Why an actuator or a spatial solve was rejected ([`SpatialError`]), and
//! why the spatial solver found no solution ([`SpatialFailure`]).

use crate::model::cable::MAX_CABLES;
use crate::model::routing::RoutingError;
use crate::model::ParameterError;

/// Why a spatial actuator or solve was rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpatialError {
    /// Too few or too many cables.
    #[error("an actuator needs 1 to {MAX_CABLES} cables, got {0}")]
    CableCount(usize),
    /// A tension is negative or not finite.
    #[error("cable {cable}: tension {} N is invalid: a cable pulls with a finite tension ≥ 0 N", crate::io::fmt_num(*tension_n))]
    Tension { cable: usize, tension_n: f64 },
    /// A displacement is negative, not finite, or longer than the cable.
    #[error("cable {cable}: displacement_mm = {} mm is invalid: {why}", crate::io::fmt_num(*displacement_mm))]
    Displacement { cable: usize, displacement_mm: f64, why: String },
    /// A cable stiffness is not a positive number.
    #[error("cable {cable}: cable_ea_n = {} N must be a finite stiffness > 0 N (leave it out for an inextensible cable)", crate::io::fmt_num(*cable_ea_n))]
    CableStiffness { cable: usize, cable_ea_n: f64 },
    /// A control point is bad.
    #[error("cable {cable}, {axis} control points: {source}")]
    Routing { cable: usize, axis: char, source: RoutingError },
    /// The channel leaves the body between control points.
    #[error("cable {cable}: the channel reaches {distance_mm:.3} mm from the axis at s = {s_mm:.2} mm, on or outside the radius r = {radius_mm} mm; move its control points toward the axis (|r_c(s)| = √(y² + z²) must stay below r everywhere)")]
    OutsideBody { cable: usize, s_mm: f64, distance_mm: f64, radius_mm: f64 },
    /// Two cables share one channel.
    #[error("cables {first} and {second} have the same path (identical y and z control points); two cables cannot share a channel: merge them into one cable with the summed tension, or move one")]
    SamePath { first: usize, second: usize },
    /// An anchor lies outside the rod.
    #[error("cable {cable}: anchor s_k = {} mm must lie in (0, L = {} mm]", crate::io::fmt_num(*anchor_mm), crate::io::fmt_num(*length_mm))]
    Anchor { cable: usize, anchor_mm: f64, length_mm: f64 },
    /// Gravity direction is zero or not finite.
    #[error("gravity direction {0:?} must be a finite, non-zero 3-vector (it is normalised; the weight per length comes from the density)")]
    GravityDirection([f64; 3]),
    /// A rod parameter is bad.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// The solver serving the request does not model part of it
    /// ([`crate::model::Backend::check`]).
    #[error(transparent)]
    Unsupported(#[from] crate::model::Unsupported),
    /// A planar solve (the fast path of a one-cable in-plane actuator) failed.
    #[error(transparent)]
    Planar(#[from] crate::model::SimulateError),
    /// The `--cable` text could not be read.
    #[error("cable \"{text}\": {why} (expected \"y=Y0,Y1,Y2,Y3,Y4 z=Z0,Z1,Z2,Z3,Z4 tension=T\" or displacement=D in place of tension=T; z=, ea=EA (the cable's stiffness, N) and anchor=S optional)")]
    CableSpec { text: String, why: String },
    /// An actuator file is not valid TOML or has unknown fields.
    #[error("actuator file {source_name}: {message}(see docs/schema.md, \"Spatial actuator file\")")]
    Toml { source_name: String, message: String },
    /// A numerical setting is bad.
    #[error("spatial solver: {0}")]
    Option(String),
    /// The solve failed.
    #[error(transparent)]
    Solve(#[from] SpatialFailure),
    /// An actuator file cannot be read.
    #[error("reading actuator file {path}: {message}")]
    Read {
        /// The file.
        path: String,
        /// The cause (as text: this error is cloned and compared).
        message: String,
    },
}

impl SpatialError {
    /// The status a sweep stores for a failed solve (`unresolved`,
    /// `non_finite`, …), whichever backend failed; `None` for bad input.
    pub fn failure_status(&self) -> Option<&'static str> {
        match self {
            SpatialError::Solve(f) => Some(f.status()),
            SpatialError::Planar(crate::model::SimulateError::Solve(f)) => Some(f.status()),
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
    DisplacementNotMet(crate::model::solver::actuation::DisplacementNotMet),
    /// The cables' tension profiles with friction did not settle.
    #[error("the cable tension profiles with friction did not converge; try smaller tension steps or a smaller friction coefficient")]
    Friction,
    /// The steps do not resolve the solution: its difference to the same
    /// solve at half the steps is above the tolerance, up to the most steps
    /// tried ([`crate::model::simulate_spatial`]), or the tip lies farther from the
    /// clamp than the stretched rod is long.
    #[error(transparent)]
    Unresolved(crate::model::solver::Unresolved),
}

impl SpatialError {
    /// Checks a solve's tensions: one per cable, each finite and ≥ 0.
    pub fn check_tensions(tensions_n: &[f64], cables: usize) -> Result<(), SpatialError> {
        if tensions_n.len() != cables {
            return Err(SpatialError::Option(format!("{} tensions given for {cables} cables", tensions_n.len())));
        }
        for (i, &t) in tensions_n.iter().enumerate() {
            if !(t.is_finite() && t >= 0.0) {
                return Err(SpatialError::Tension { cable: i + 1, tension_n: t });
            }
        }
        Ok(())
    }
}

impl SpatialFailure {
    /// Short machine-readable status (as the planar solver's
    /// [`crate::model::SolveFailure::status`]).
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

