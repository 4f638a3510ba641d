//! The simulate workflow ([`SimulateRequest`]): one actuator solved once,
//! as `cablemap simulate` and `cablemap.simulate` ask it. The request
//! decides from its input which record reports the solve: one routing on
//! a rod alone is the planar record's (a tension, a displacement, a
//! stiffness, the thesis's coefficient route); an actuator given by its
//! cables, its torsion or a gravity direction is the actuator's. Either
//! way the solve is the backend that serves the actuator
//! ([`Backend::serving`]), and every check is made here once.

use super::record::{self, SimulationRecord};
use super::resolution::max_order;
use super::spatial::SpatialError;
use super::{simulate_actuator, simulate_held, Backend, Given, Hold, Simulation, SolverSettings, Unsupported};
use crate::io::{fmt_num, SettingNames};
use crate::model::{Actuation, Actuator, Cable, LoadDirection, ParameterError, Routing, RoutingError};
use crate::shape::{thesis_coefficients, LengthBasis, ShapeError};
use serde::Deserialize;
use std::path::Path;

/// Most resampling intervals of the thesis route.
pub const MAX_N_D: usize = 100_000;

/// Resampling intervals of the thesis route unless asked otherwise (the thesis's).
pub const DEFAULT_N_D: usize = 40;

/// Which definition of the curvature coefficients to report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CoefficientRoute {
    /// a_i = (2i+1)/ℓ ∫ P_i dθ, exactly (model-notes §4).
    #[default]
    Exact,
    /// The thesis's discrete route (§3.3, eq. 3.12), from the centreline
    /// points resampled at `n_d` equal arc-length intervals.
    Thesis,
}

/// What a simulate asks: the fields of `cablemap simulate` (the actuator
/// resolved from its files and flags), by the keys `cablemap.simulate`
/// sends.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulateRequest {
    /// The actuator: its rod, and its cables, torsion or gravity direction
    /// when given by them.
    pub actuator: Actuator,
    /// One planar cable's control points y0..y4, mm (replacing the actuator's cables).
    #[serde(default)]
    pub routing_mm: Option<Vec<f64>>,
    /// The routing's cable tension, N.
    #[serde(default)]
    pub tension_n: Option<f64>,
    /// The routing's cable displacement, mm (the tension is found).
    #[serde(default)]
    pub displacement_mm: Option<f64>,
    /// The routing's cable's axial stiffness EA, N (`None`: inextensible).
    #[serde(default)]
    pub cable_ea_n: Option<f64>,
    /// Highest Legendre order n of the coefficients a_0..a_n.
    pub order: usize,
    /// The length the coefficients are normalised by.
    pub length_basis: LengthBasis,
    /// Direction of the last tension change (friction's sign) [default: load].
    #[serde(default)]
    pub direction: Option<LoadDirection>,
    /// Seconds held at the tension before the reading (creep) [default: the rod's creep_hold_s].
    #[serde(default)]
    pub dwell_s: Option<f64>,
    /// The solver settings given.
    #[serde(default)]
    pub solver: SolverSettings,
    /// How the coefficients are computed.
    #[serde(default)]
    pub coefficients: CoefficientRoute,
    /// Intervals n_d of the thesis route.
    #[serde(default = "default_n_d")]
    pub n_d: usize,
}

fn default_n_d() -> usize {
    DEFAULT_N_D
}

/// Which record reports a simulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordKind {
    /// One routing on a rod alone: the planar record (`simulate --json`'s
    /// `routing_mm`, `tension_n`, `a`, …).
    Routing,
    /// An actuator given by its cables: the actuator's record (per-cable
    /// tensions, the 3-D tip, the three coefficient series).
    Actuator,
}

/// A simulate's answer: the solve, the actuator asked for and the record
/// that reports it.
#[derive(Debug, Clone)]
pub struct SimulateReport {
    /// The solve.
    pub simulation: Simulation,
    /// The actuator solved, its cables as given (a routing's one cable included).
    pub actuator: Actuator,
    /// Which record reports it.
    pub record: RecordKind,
}

impl SimulateReport {
    /// The record as one line of JSON (`simulate --json`).
    pub fn to_json(&self) -> String {
        match self.record {
            RecordKind::Routing => SimulationRecord::from(&self.simulation).to_json_line(),
            RecordKind::Actuator => record::simulation_json(&self.simulation).to_string(),
        }
    }

    /// Writes the centreline (and the cables' paths) as CSV.
    pub fn write_centreline_csv(&self, path: &Path) -> std::io::Result<()> {
        match self.record {
            RecordKind::Routing => record::write_planar_centreline_csv(path, &self.simulation),
            RecordKind::Actuator => record::write_actuator_centreline_csv(path, &self.simulation),
        }
    }
}

impl std::fmt::Display for SimulateReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.record {
            RecordKind::Routing => f.write_str(&record::planar_report(&self.simulation)),
            RecordKind::Actuator => f.write_str(&record::report(&self.simulation)),
        }
    }
}

/// Why a [`SimulateRequest`] has no report; a setting is named by its flag
/// or its key (`names`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimulateRequestError {
    /// Neither a routing with its actuation nor cables.
    #[error("say what to simulate: {}", match names {
        SettingNames::Flags => "--routing Y0,..,Y4 with --tension-n T or --displacement-mm D (one planar cable), --cable \"y=.. z=.. tension=T\" (repeatable), or --actuator FILE.toml",
        SettingNames::Keys => "routing_mm=[y0, .., y4] with tension_n=T or displacement_mm=D (one planar cable), or cables=[{y_mm: [..], z_mm: [..], tension_n: T}, ..], or an actuator with cables",
    })]
    NothingToSimulate {
        /// How settings are named.
        names: SettingNames,
    },
    /// A routing without its actuation, or an actuation without a routing.
    #[error("{}", match names {
        SettingNames::Flags => "--routing needs its actuation: --tension-n T (N) or --displacement-mm D (mm, the length pulled in at the base)",
        SettingNames::Keys => "routing_mm needs its actuation (tension_n or displacement_mm) and the other way round",
    })]
    RoutingWithoutActuation {
        /// How settings are named.
        names: SettingNames,
    },
    /// Both a tension and a displacement for the routing's cable.
    #[error("give {} or {}, not both", names.name("tension_n"), names.name("displacement_mm"))]
    TensionAndDisplacement {
        /// How settings are named.
        names: SettingNames,
    },
    /// An actuator given by its torsion or gravity direction, without cables.
    #[error("no cables: {}", match names {
        SettingNames::Flags => "give --cable \"y=.. z=.. tension=T\" (repeatable), --routing/--tension, or [[cable]] tables in --actuator",
        SettingNames::Keys => "give cables=[...], routing_mm with tension_n, or an actuator with cables",
    })]
    NoCables {
        /// How settings are named.
        names: SettingNames,
    },
    /// More resampling intervals than the thesis route takes.
    #[error(
        "{} {n_d} is more than {MAX_N_D} intervals (the thesis uses 40; the solver has only 2 × steps-per-span nodes to resample)",
        names.name("n_d")
    )]
    TooManyIntervals {
        /// How settings are named.
        names: SettingNames,
        /// The intervals asked for.
        n_d: usize,
    },
    /// The routing is refused.
    #[error("{}: {source}", names.either("routing_mm", "--routing"))]
    Routing {
        /// How settings are named.
        names: SettingNames,
        /// Why.
        #[source]
        source: RoutingError,
    },
    /// The rod is refused.
    #[error(transparent)]
    Rod(#[from] ParameterError),
    /// The planar backend asked for does not model the rod or a setting given.
    #[error(transparent)]
    Unsupported(#[from] Unsupported),
    /// The routing's solve failed.
    #[error("simulating routing {routing_mm:?} at {}: {source}", describe(*actuation))]
    RoutingSolve {
        /// The routing's control points, mm.
        routing_mm: Vec<f64>,
        /// Its actuation.
        actuation: Actuation,
        /// Why.
        #[source]
        source: SpatialError,
    },
    /// The actuator's solve failed, or the actuator is refused.
    #[error(transparent)]
    Solve(#[from] SpatialError),
    /// The thesis's coefficient route failed.
    #[error("thesis coefficient route: {0}")]
    ThesisCoefficients(#[source] ShapeError),
}

impl SimulateRequestError {
    /// The failed solve, whatever it solved: its status is
    /// [`SpatialError::failure_status`]; `None` for input refused.
    pub fn solve_error(&self) -> Option<&SpatialError> {
        match self {
            SimulateRequestError::RoutingSolve { source, .. } | SimulateRequestError::Solve(source) => Some(source),
            _ => None,
        }
    }
}

/// An actuation in words, for messages.
fn describe(actuation: Actuation) -> String {
    match actuation {
        Actuation::Tension(t) => format!("{} N", fmt_num(t)),
        Actuation::Displacement(d) => format!("a displacement of {} mm", fmt_num(d)),
    }
}

/// The routing's one cable on `y_mm`, driven by `actuation`, with stiffness `cable_ea_n`.
fn routing_cable(actuation: Actuation, y_mm: [f64; 5], cable_ea_n: Option<f64>) -> Cable {
    Cable { cable_ea_n, ..Cable::planar(y_mm, 0.0) }.actuated(actuation)
}

impl SimulateRequest {
    /// Solves the request, its messages naming settings by `names`.
    pub fn run(&self, names: SettingNames) -> Result<SimulateReport, SimulateRequestError> {
        let actuation = match (self.tension_n, self.displacement_mm) {
            (Some(_), Some(_)) => return Err(SimulateRequestError::TensionAndDisplacement { names }),
            (Some(t), None) => Some(Actuation::Tension(t)),
            (None, Some(d)) => Some(Actuation::Displacement(d)),
            (None, None) => None,
        };
        if self.routing_mm.is_some() != actuation.is_some() {
            return Err(SimulateRequestError::RoutingWithoutActuation { names });
        }
        let routed = self.routing_mm.as_deref().zip(actuation);
        if self.by_cables() {
            self.run_actuator(routed, names)
        } else {
            let Some((y, actuation)) = routed else {
                return Err(SimulateRequestError::NothingToSimulate { names });
            };
            self.run_routing(y, actuation, names)
        }
    }

    /// Whether the actuator is given by its cables, torsion or gravity
    /// direction (the actuator's record) rather than as a rod alone for
    /// one routing (the planar record).
    pub fn by_cables(&self) -> bool {
        !self.actuator.is_rod_alone()
    }

    /// The settings given rather than left at their defaults: the backend
    /// serving the request must read each ([`Backend::check`]).
    fn given(&self) -> Given {
        Given {
            hold: self.direction == Some(LoadDirection::Unload) || self.dwell_s.is_some(),
            thesis_coefficients: self.coefficients == CoefficientRoute::Thesis,
            ..self.solver.given()
        }
    }

    /// The final tension's hold: loading unless asked otherwise, for the
    /// dwell asked or the rod's creep hold.
    fn hold(&self, actuator: &Actuator) -> Hold {
        Hold { direction: self.direction.unwrap_or(LoadDirection::Load), dwell_s: self.dwell_s.unwrap_or(actuator.rod.effects.creep_hold_s) }
    }

    /// Refuses more thesis-route intervals than [`MAX_N_D`].
    fn check_n_d(&self, names: SettingNames) -> Result<(), SimulateRequestError> {
        if self.n_d > MAX_N_D {
            return Err(SimulateRequestError::TooManyIntervals { names, n_d: self.n_d });
        }
        Ok(())
    }

    /// The order the solver computes: the thesis route computes its own
    /// coefficients from the centreline (its order is limited by n_d,
    /// checked there), so the solver's exact ones are only needed up to
    /// what the steps resolve.
    fn solver_order(&self, options: &super::SolverOptions) -> usize {
        match self.coefficients {
            CoefficientRoute::Exact => self.order,
            CoefficientRoute::Thesis => self.order.min(max_order(options)),
        }
    }

    /// The thesis route's coefficients a_bend_z of `sim`'s planar centreline.
    fn thesis_route(&self, sim: &Simulation, length_mm: f64) -> Result<Vec<f64>, SimulateRequestError> {
        let points: Vec<[f64; 2]> = sim.centreline.iter().map(|c| [c.x_mm, c.y_mm]).collect();
        let coefficients = thesis_coefficients(&points, self.order, self.n_d).map_err(SimulateRequestError::ThesisCoefficients)?;
        Ok(coefficients.in_basis(self.length_basis, length_mm).a)
    }

    /// One routing `y` on the rod, driven by `actuation`: the planar record.
    fn run_routing(&self, y: &[f64], actuation: Actuation, names: SettingNames) -> Result<SimulateReport, SimulateRequestError> {
        let rod = &self.actuator.rod;
        rod.validate()?;
        let options = self.solver.options();
        self.check_n_d(names)?;
        let routing = Routing::for_actuator(y, rod).map_err(|source| SimulateRequestError::Routing { names, source })?;
        // The one check: a setting the planar backend of the method does not read is refused.
        Backend::check_planar(rod, &options, self.given())?;
        let hold = self.hold(&self.actuator);
        let order = self.solver_order(&options);
        let actuator = Actuator::with_cables(rod.clone(), vec![routing_cable(actuation, routing.control_points_mm().0, self.cable_ea_n)]);
        let solved = match actuation {
            Actuation::Tension(t) if self.cable_ea_n.is_none() => {
                simulate_held(rod, &options, &routing, t, order, self.length_basis, hold).map_err(SpatialError::from)
            }
            // A displacement, or a stiffness: the actuator's one cable,
            // checked and solved as every actuator's (the same planar backend).
            _ => simulate_actuator(&actuator, &options, self.given(), Some(hold), order, self.length_basis),
        };
        let mut sim = solved.map_err(|source| SimulateRequestError::RoutingSolve { routing_mm: y.to_vec(), actuation, source })?;
        if self.coefficients == CoefficientRoute::Thesis {
            sim.a_bend_z = self.thesis_route(&sim, rod.length_mm)?;
        }
        Ok(SimulateReport { simulation: sim, actuator, record: RecordKind::Routing })
    }

    /// The actuator by its cables (the routing's one cable in their place
    /// when `routed`): the actuator's record.
    fn run_actuator(&self, routed: Option<(&[f64], Actuation)>, names: SettingNames) -> Result<SimulateReport, SimulateRequestError> {
        let mut actuator = self.actuator.clone();
        if let Some((y, actuation)) = routed {
            let y: [f64; 5] = y
                .try_into()
                .map_err(|_| SimulateRequestError::Routing { names, source: RoutingError::WrongCount(y.len()) })?;
            actuator.cables = vec![routing_cable(actuation, y, self.cable_ea_n)];
        }
        if actuator.cables.is_empty() {
            return Err(SimulateRequestError::NoCables { names });
        }
        self.check_n_d(names)?;
        let options = self.solver.options();
        let hold = self.hold(&actuator);
        let mut sim = simulate_actuator(&actuator, &options, self.given(), Some(hold), self.solver_order(&options), self.length_basis)?;
        // The thesis route needs a planar centreline: the one check refused it otherwise.
        if self.coefficients == CoefficientRoute::Thesis && sim.backend != Backend::SpatialCollocation {
            sim.a_bend_z = self.thesis_route(&sim, actuator.rod.length_mm)?;
            sim.a_bend_y = vec![0.0; sim.a_bend_z.len()];
            sim.a_twist = vec![0.0; sim.a_bend_z.len()];
        }
        Ok(SimulateReport { simulation: sim, actuator, record: RecordKind::Actuator })
    }
}
