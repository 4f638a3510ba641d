//! Why an actuator (its rod, cables or gravity direction) or its file was
//! refused, whichever solver is to serve it.

use crate::model::routing::RoutingError;
use crate::model::ParameterError;

/// Why an actuator or an actuator file was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ActuatorError {
    /// Too few or too many cables.
    #[error("an actuator needs 1 to {max} cables, got {count}")]
    CableCount { count: usize, max: usize },
    /// A tension is negative or not finite.
    #[error("cable {cable}: tension {} N is invalid: a cable pulls with a finite tension ≥ 0 N", crate::io::fmt_num(*tension_n))]
    Tension { cable: usize, tension_n: f64 },
    /// A displacement is negative, not finite, or longer than the cable.
    #[error("cable {cable}: displacement_mm = {} mm is invalid: {problem}", crate::io::fmt_num(*displacement_mm))]
    Displacement { cable: usize, displacement_mm: f64, problem: DisplacementProblem },
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
    /// The `--cable` text could not be read.
    #[error("cable \"{given}\": {problem} (expected \"y=Y0,Y1,Y2,Y3,Y4 z=Z0,Z1,Z2,Z3,Z4 tension=T\" or displacement=D in place of tension=T; z=, ea=EA (the cable's stiffness, N) and anchor=S optional)")]
    CableSpec { given: String, problem: CableSpecProblem },
    /// An actuator file is not valid TOML or has unknown fields.
    #[error("actuator file {source_name}: {source}(see docs/schema.md, \"Spatial actuator file\")")]
    Toml { source_name: String, source: toml::de::Error },
    /// An actuator file cannot be read.
    #[error("reading actuator file {}: {source}", path.display())]
    Read { path: std::path::PathBuf, source: crate::io::SharedIoError },
}

/// Why a cable's displacement is refused ([`ActuatorError::Displacement`]).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum DisplacementProblem {
    /// Not a finite number.
    #[error("give a finite pulled-in length, mm")]
    NotFinite,
    /// Below zero: it would push the cable.
    #[error("a cable pulls: a negative displacement would push it; give the pulled-in length ≥ 0 mm")]
    Negative,
    /// At least the cable's length in the unloaded rod.
    #[error("the cable is only {} mm long in the unloaded rod; it cannot be pulled in by that much", crate::io::fmt_num((rest_length_mm * 1e3).round() / 1e3))]
    LongerThanCable { rest_length_mm: f64 },
}

/// What is wrong with a `--cable` text ([`ActuatorError::CableSpec`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CableSpecProblem {
    /// A field's value is not a number.
    #[error("{key}: '{value}' is not a number")]
    NotANumber { key: String, value: String },
    /// A list of control points of the wrong length.
    #[error("{key} needs {expected} control points, got {got}")]
    ControlPointCount { key: String, expected: usize, got: usize },
    /// A field without `=`.
    #[error("'{field}' is not key=value")]
    NotKeyValue { field: String },
    /// A field given twice.
    #[error("{key}= is given twice")]
    GivenTwice { key: String },
    /// A field the form does not have.
    #[error("unknown field '{key}' (fields: y, z, tension, displacement, ea, anchor)")]
    UnknownField { key: String },
    /// No `y=`.
    #[error("y= is missing")]
    MissingY,
    /// Both `tension=` and `displacement=`.
    #[error("give tension= or displacement=, not both")]
    TensionAndDisplacement,
    /// Neither `tension=` nor `displacement=`.
    #[error("tension= (N) or displacement= (mm) is missing")]
    NoActuation,
}
