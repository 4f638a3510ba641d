//! The physical model: routing, actuator parameters and effects (with their
//! registry, [`effects`]), and the
//! static rod–cable solver.

pub mod actuator;
pub mod cable;
pub mod rod;
pub mod rod_overrides;
pub mod body;
pub mod effects;
pub mod record;
pub mod routing;
pub mod resolution;
pub mod solver;
pub mod spatial;

pub use body::{Body, BodyError, Segment};
pub use actuator::Actuator;
pub use cable::{Cable, MAX_CABLES};
pub use rod::{Rod, Effects, Gravity, LoadDirection, ParameterError, Unmodelled};
pub use rod_overrides::RodOverrides;
pub use effects::{EffectInfo, REGISTRY};
pub use routing::{ControlPoints, Routing, RoutingError};
pub use solver::{Backend, Given, Unsupported};
pub use solver::{simulate, simulate_held, CentrelinePoint, Hold, SimulateError, Simulation, Simulator, SolveFailure, SolverMethod, SolverOptions, TipPose, Unresolved, STATUS_OK};
