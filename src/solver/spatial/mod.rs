//! The spatial (3-D) backends (the thesis's future work): the
//! thesis's rod ([`crate::model::Rod`]) with 1–8 cables, each routed along
//! r_c,i(s) = (0, y_i(s), z_i(s)) in the body frame, torsion (GJ, default
//! EI/1.5: ν = 0.5, incompressible silicone) and gravity along any global
//! direction, solved by the equilibrium-at-a-cut form generalised to three
//! dimensions ([`solver`]). Single solves and the result type are the
//! solver interface's ([`crate::solver`]: `simulate_spatial`,
//! `simulate_actuator`, `Simulation`); the planar backends are the fast path
//! for one in-plane cable, and the two agree on planar cases.

pub mod collocation;
pub mod error;
pub mod solver;

pub use crate::model::actuator::{Actuator, EI_OVER_GJ};
pub use crate::model::cable::{self, Cable, MAX_CABLES};
pub use crate::solver::simulate_spatial;
pub use error::SpatialError;
pub use collocation::SpatialCollocation;
pub use solver::{check_order, validated_channels, SpatialRk4, MAX_SPATIAL_ORDER};
