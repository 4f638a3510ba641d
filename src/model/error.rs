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
    /// The `--cable` text could not be read.
    #[error("cable \"{text}\": {why} (expected \"y=Y0,Y1,Y2,Y3,Y4 z=Z0,Z1,Z2,Z3,Z4 tension=T\" or displacement=D in place of tension=T; z=, ea=EA (the cable's stiffness, N) and anchor=S optional)")]
    CableSpec { text: String, why: String },
    /// An actuator file is not valid TOML or has unknown fields.
    #[error("actuator file {source_name}: {message}(see docs/schema.md, \"Spatial actuator file\")")]
    Toml { source_name: String, message: String },
    /// An actuator file cannot be read.
    #[error("reading actuator file {path}: {message}")]
    Read {
        /// The file.
        path: String,
        /// The cause (as text: this error is cloned and compared).
        message: String,
    },
}
