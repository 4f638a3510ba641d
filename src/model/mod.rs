//! The physical model: the actuator (rod and cables, routing, effects with
//! their registry, [`effects`]) and why one is refused. It knows no solver:
//! the backends that solve it live in [`crate::solver`].

pub mod actuator;
pub mod rod_overrides;
pub mod body;
pub mod cable;
pub mod effect_parameters;
pub mod effects;
pub mod error;
pub mod parameter;
pub mod rod;
pub mod routing;
mod validation;

pub use actuator::Actuator;
pub use body::{Body, BodyError, Segment};
pub use cable::{Actuation, Cable, MAX_CABLES};
pub use effect_parameters::{Effects, LoadDirection};
pub use parameter::{ParameterError, PlausibleRange};
pub use rod::{Gravity, Rod};
pub use rod_overrides::RodOverrides;
pub use effects::{EffectInfo, REGISTRY};
pub use error::{ActuatorError, CableSpecProblem, DisplacementProblem};
pub use routing::{ControlPoints, Routing, RoutingError};
