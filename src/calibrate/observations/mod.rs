//! What a fit fits against: the kinds of observations, each read from its
//! files and each able to say how far a simulated actuator is from it.
//!
//! - [`measurements`]: planar measurement files (tip readings of one
//!   in-plane cable, with centreline points and markers).
//! - [`captures`]: several-cable captures with body-fixed 3-D markers.
//!
//! The one fit ([`crate::calibrate::fit`]) and the one diagnosis
//! ([`crate::calibrate::diagnose::rounds`]) work over either.

pub mod captures;
pub mod measurements;

pub use super::fit::Observations;
