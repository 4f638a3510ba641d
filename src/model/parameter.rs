//! Why a rod's parameter or a numerical setting was refused, and the
//! plausible ranges parameters are checked against. Every file of the
//! model that checks a parameter uses these; this file uses none of them.

use super::body::BodyError;

/// A plausible range of a parameter: far beyond any rod cablemap models,
/// yet refusing values whose products in the solver overflow or vanish.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlausibleRange {
    /// Smallest value accepted.
    pub min: f64,
    /// Largest value accepted.
    pub max: f64,
    /// The range and an example in words, for the error.
    pub expected: &'static str,
}

impl PlausibleRange {
    /// Refuses `value` of parameter `name` outside the range.
    pub fn check(&self, name: &'static str, value: f64) -> Result<(), ParameterError> {
        if (self.min..=self.max).contains(&value) {
            Ok(())
        } else {
            Err(ParameterError::OutOfRange { name, value, expected: self.expected })
        }
    }
}

/// Why a parameter set was rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParameterError {
    /// A parameter that must be positive and finite is not.
    #[error("parameter {name} = {} must be a positive, finite number", crate::io::fmt_num(*value))]
    NotPositive { name: &'static str, value: f64 },
    /// A parameter that must be finite is not, or lies outside its range.
    #[error("parameter {name} = {} is out of range: {expected}", crate::io::fmt_num(*value))]
    OutOfRange { name: &'static str, value: f64, expected: &'static str },
    /// The body along s (radius profile, segments, cable anchor) is invalid.
    #[error(transparent)]
    Body(#[from] BodyError),
}
