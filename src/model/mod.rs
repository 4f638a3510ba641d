//! The physical model: the actuator (rod and cables, routing, effects with
//! their registry, [`effects`]), the static rod–cable solvers behind one
//! interface and their one result ([`solver`]), and what a simulation
//! writes ([`record`]).

pub mod actuator;
pub mod rod_overrides;
pub mod body;
pub mod cable;
pub mod effect_parameters;
pub mod effects;
pub mod parameter;
pub mod record;
pub mod resolution;
pub mod rod;
pub mod routing;
pub mod solver;
pub mod spatial;
mod validation;

pub use actuator::Actuator;
pub use body::{Body, BodyError, Segment};
pub use cable::{Cable, MAX_CABLES};
pub use effect_parameters::{Effects, LoadDirection};
pub use parameter::{ParameterError, PlausibleRange};
pub use rod::{Gravity, Rod};
pub use rod_overrides::RodOverrides;
pub use effects::{EffectInfo, REGISTRY};
pub use routing::{ControlPoints, Routing, RoutingError};
pub use solver::{Backend, Given, Unsupported};
pub use solver::{
    simulate, simulate_actuator, simulate_held, simulate_spatial, CableAtNode, CentrelinePoint, Hold, PerCable, SimulateError, Simulation, Simulator, SolveFailure,
    SolverMethod, SolverOptions, TipFrame, TipPose, Unresolved, STATUS_OK,
};
