//! The backends by name — [`PlanarCollocation`] (the default planar one)
//! and [`PlanarRk4`] (its reference), the spatial ones in `spatial` — and
//! [`Simulator`], the one place a backend is picked and built: the backend
//! serving an actuator ([`Simulator::serving`], by [`Backend::serving`]'s
//! capability table), or, for callers that set a rod's one in-plane cable's
//! routing solve by solve, the backend serving that rod
//! ([`Simulator::for_rod`]). Each call goes to the backend held, by a
//! `match` (static dispatch, no trait object).

use super::collocation::Colloc;
use super::error::SimulateError;
use super::planar::{Integrator, PlanarSolver};
use super::rk4::ShootingRk4;
use super::spatial::{SpatialCollocation, SpatialError, SpatialRk4};
use super::{Backend, CentrelinePoint, Given, Hold, SolveFailure, Solver, SolverMethod, SolverOptions, TipPose};
use crate::model::parameter::ParameterError;
use crate::model::{Actuation, Actuator, Rod, Routing};
use crate::shape::LengthBasis;

/// The planar spectral collocation (the default planar backend).
pub type PlanarCollocation = PlanarSolver<Colloc>;
/// The planar RK4 reference: classical RK4 with secant shooting, the
/// plain scheme the collocation is checked against.
pub type PlanarRk4 = PlanarSolver<ShootingRk4>;

/// The backend picked for an actuator, ready to solve it repeatedly.
#[derive(Debug, Clone)]
pub enum Simulator {
    /// [`PlanarCollocation`].
    PlanarCollocation(PlanarCollocation),
    /// [`PlanarRk4`].
    PlanarRk4(PlanarRk4),
    /// [`SpatialCollocation`].
    SpatialCollocation(SpatialCollocation),
    /// [`SpatialRk4`].
    SpatialRk4(SpatialRk4),
}

/// `$body` with `$s` bound to the backend a [`Simulator`] holds.
macro_rules! each {
    ($sim:expr, $s:ident => $body:expr) => {
        match $sim {
            Simulator::PlanarCollocation($s) => $body,
            Simulator::PlanarRk4($s) => $body,
            Simulator::SpatialCollocation($s) => $body,
            Simulator::SpatialRk4($s) => $body,
        }
    };
}

/// `$body` with `$s` bound to the planar backend a [`Simulator`] holds: the
/// operations on a rod's one in-plane cable (its routing, its tension).
/// Only [`Simulator::for_rod`] is asked for them; a spatial backend there is
/// a caller's mistake.
macro_rules! planar {
    ($sim:expr, $s:ident => $body:expr) => {
        match $sim {
            Simulator::PlanarCollocation($s) => $body,
            Simulator::PlanarRk4($s) => $body,
            Simulator::SpatialCollocation(_) | Simulator::SpatialRk4(_) => {
                panic!("a rod's one in-plane cable is solved by the backend Simulator::for_rod picks, not a spatial one")
            }
        }
    };
}

impl Simulator {
    /// The backend serving `actuator` ([`Backend::serving`]: the planar one
    /// of `options.method` for one in-plane cable with gravity in its plane,
    /// else the spatial one), built for it; refused if that backend does not
    /// model the actuator or a setting `given` explicitly.
    pub fn serving(actuator: &Actuator, options: &SolverOptions, given: Given) -> Result<Self, SpatialError> {
        actuator.channels()?;
        let backend = Backend::serving(actuator, options, given)?;
        Self::build(backend, actuator, options)
    }

    /// `backend` (the one [`Backend::serving`] picked) built for `actuator`.
    pub fn build(backend: Backend, actuator: &Actuator, options: &SolverOptions) -> Result<Self, SpatialError> {
        let options = SolverOptions { method: backend.support().method, ..options.clone() };
        Ok(match backend {
            Backend::PlanarCollocation | Backend::PlanarRk4 => {
                let (rod, routing) = planar_problem(actuator)?;
                let mut sim = Self::for_rod(&rod, &options)?;
                sim.set_routing(&routing);
                sim.set_cable_stiffness(actuator.cables[0].cable_ea_n);
                sim
            }
            Backend::SpatialCollocation => Simulator::SpatialCollocation(SpatialCollocation::new(actuator, &options)?),
            Backend::SpatialRk4 => Simulator::SpatialRk4(SpatialRk4::new(actuator, &options)?),
        })
    }

    /// The backend serving `rod` with its one in-plane cable (the planar one
    /// of `options.method`), for callers that hold the rod and set the
    /// cable's routing solve by solve ([`Simulator::set_routing`]): the
    /// planar routing sweep, the routing design, the planar measurements'
    /// predictions. Fails on invalid parameters or a rod it does not model.
    pub fn for_rod(rod: &Rod, options: &SolverOptions) -> Result<Self, SimulateError> {
        Ok(match options.method {
            SolverMethod::Collocation => Simulator::PlanarCollocation(PlanarSolver::new(rod, options)?),
            SolverMethod::Rk4 => Simulator::PlanarRk4(PlanarSolver::new(rod, options)?),
        })
    }

    /// The rod this solver was built for.
    pub fn rod(&self) -> &Rod {
        each!(self, s => s.rod())
    }

    /// The centreline of the last successful solve, clamp to tip.
    pub fn centreline(&self) -> Vec<CentrelinePoint> {
        each!(self, s => Solver::centreline(s))
    }

    /// [`PlanarSolver::set_routing_mm`] (a rod's one in-plane cable).
    pub fn set_routing_mm(&mut self, y_mm: &[f64]) -> Result<(), crate::model::routing::RoutingError> {
        planar!(self, s => s.set_routing_mm(y_mm))
    }

    /// [`PlanarSolver::set_routing`] (a rod's one in-plane cable).
    pub fn set_routing(&mut self, routing: &Routing) {
        planar!(self, s => s.set_routing(routing))
    }

    /// [`PlanarSolver::set_cable_stiffness`] (a rod's one in-plane cable).
    pub fn set_cable_stiffness(&mut self, cable_ea_n: Option<f64>) {
        planar!(self, s => s.set_cable_stiffness(cable_ea_n))
    }

    /// [`PlanarSolver::reset_warm_start`] (a rod's one in-plane cable).
    pub fn reset_warm_start(&mut self) {
        planar!(self, s => s.reset_warm_start())
    }

    /// [`PlanarSolver::reset_history`] (a rod's one in-plane cable).
    pub fn reset_history(&mut self) {
        planar!(self, s => s.reset_history())
    }

    /// [`PlanarSolver::set_hold`] (a rod's one in-plane cable).
    pub fn set_hold(&mut self, hold: Hold) -> Result<(), ParameterError> {
        planar!(self, s => s.set_hold(hold))
    }

    /// [`PlanarSolver::solve`]: the one in-plane cable at `tension_n`.
    pub fn solve(&mut self, tension_n: f64) -> Result<TipPose, SolveFailure> {
        planar!(self, s => s.solve(tension_n))
    }

    /// [`Solver::solve`] of the one in-plane cable's `actuation`, its
    /// tension found from (and left in) `tension_n`.
    pub fn solve_actuation(&mut self, actuation: Actuation, tension_n: &mut [f64; 1]) -> Result<TipPose, SolveFailure> {
        planar!(self, s => Solver::solve(s, &[actuation], &mut tension_n[..]))
    }

    /// [`Solver::simulate`] of the one in-plane cable of `actuator` (its
    /// routing set), the final tension held by `hold`.
    pub fn simulate_in_plane(&mut self, actuator: &Actuator, hold: Hold, order: usize, basis: LengthBasis) -> Result<super::Simulation, SolveFailure> {
        planar!(self, s => s.simulate(actuator, Some(hold), order, basis))
    }

    /// [`PlanarSolver::resolution`] (a rod's one in-plane cable).
    pub fn resolution(&self) -> usize {
        planar!(self, s => s.resolution())
    }

    /// [`PlanarSolver::coefficients_into`] (a rod's one in-plane cable).
    pub fn coefficients_into(&mut self, basis: LengthBasis, out: &mut [f64]) {
        planar!(self, s => s.coefficients_into(basis, out))
    }

    /// [`PlanarSolver::coefficient_error_per_mm`] (a rod's one in-plane cable).
    pub fn coefficient_error_per_mm(&self) -> (f64, usize) {
        planar!(self, s => s.coefficient_error_per_mm())
    }

    /// [`PlanarSolver::coefficients_checked`] (a rod's one in-plane cable).
    pub fn coefficients_checked(&mut self, basis: LengthBasis, out: &mut [f64]) -> Result<(), SolveFailure> {
        planar!(self, s => s.coefficients_checked(basis, out))
    }
}

/// Every backend's solves, each call statically dispatched to the one held;
/// a planar backend's failure is the one [`SolveFailure`], as a spatial one's.
impl Solver for Simulator {
    type Error = SpatialError;
    fn backend(&self) -> Backend {
        each!(self, s => s.backend())
    }
    fn solve_tensions(&mut self, tensions_n: &[f64]) -> Result<TipPose, SpatialError> {
        match self {
            Simulator::PlanarCollocation(s) => Ok(s.solve_tensions(tensions_n)?),
            Simulator::PlanarRk4(s) => Ok(s.solve_tensions(tensions_n)?),
            Simulator::SpatialCollocation(s) => s.solve_tensions(tensions_n),
            Simulator::SpatialRk4(s) => s.solve_tensions(tensions_n),
        }
    }
    fn hold_next(&mut self, hold: Hold) {
        each!(self, s => s.hold_next(hold))
    }
    fn centreline(&self) -> Vec<CentrelinePoint> {
        each!(self, s => Solver::centreline(s))
    }
    fn coefficients(&mut self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], SpatialError> {
        match self {
            Simulator::PlanarCollocation(s) => Ok(Solver::coefficients(s, order, basis)?),
            Simulator::PlanarRk4(s) => Ok(Solver::coefficients(s, order, basis)?),
            Simulator::SpatialCollocation(s) => Solver::coefficients(s, order, basis),
            Simulator::SpatialRk4(s) => Solver::coefficients(s, order, basis),
        }
    }
}

/// The planar solver's input for a planar `actuator` (one cable, z ≡ 0,
/// gravity in the x–y plane): the rod with the cable's anchor and gravity's
/// in-plane direction, and the cable's routing over [0, anchor].
pub fn planar_problem(actuator: &Actuator) -> Result<(Rod, Routing), SpatialError> {
    let cable = &actuator.cables[0];
    let mut rod = actuator.rod.clone();
    if let Some(anchor) = cable.anchor_mm {
        if rod.cable_anchor_mm.is_some_and(|k| k != anchor) {
            return Err(SpatialError::AnchorTwice { cable_mm: anchor, rod_mm: rod.cable_anchor_mm.unwrap_or(anchor) });
        }
        rod.cable_anchor_mm = Some(anchor);
    }
    if let (Some(g), true) = (actuator.gravity_direction, rod.gravity.enabled) {
        rod.gravity.direction_rad = g[1].atan2(g[0]);
    }
    let routing = Routing::for_actuator(cable.y_mm, &rod)
        .map_err(|source| crate::model::ActuatorError::Routing { cable: 1, axis: 'y', source })?;
    Ok((rod, routing))
}

/// The planar spectral collocation.
impl Integrator for Colloc {
    const METHOD: SolverMethod = SolverMethod::Collocation;

    fn build(rod: &Rod, options: &SolverOptions, spans: usize) -> (Self, usize) {
        // Material stiffening's curvature law u(m) has complex branch points
        // near the real axis (1 + 3 α r² u² = 0), which slows the spectral
        // convergence: 10 intervals leave 2e-6 rad there, 16 leave 1e-8.
        let m = if rod.effects.stiffening_alpha > 0.0 { options.nodes_per_span.max(super::MIN_NODES_WITH_STIFFENING) } else { options.nodes_per_span };
        (Colloc::new(m, spans), spans * (m + 1))
    }

    fn set_routing(p: &mut PlanarSolver<Self>, built: &Routing) {
        p.state.colloc_set_routing(&mut p.integrator, built);
    }

    fn forget(&mut self) {
        Colloc::forget(self);
    }

    fn solve(p: &mut PlanarSolver<Self>, tension: f64) -> Result<(TipPose, (f64, f64)), SolveFailure> {
        let passes = p.state.colloc_solve(&mut p.integrator, tension)?;
        Ok((p.state.colloc_pose(&p.integrator, tension, passes), p.state.colloc_error_estimate(&p.integrator)))
    }

    fn resolution(p: &PlanarSolver<Self>) -> usize {
        p.integrator.intervals()
    }

    fn coefficients(p: &mut PlanarSolver<Self>, basis: LengthBasis, out: &mut [f64]) -> (f64, usize) {
        p.state.colloc_coefficients(&p.integrator, basis, out)
    }

    fn centreline(p: &PlanarSolver<Self>) -> Vec<CentrelinePoint> {
        p.state.colloc_centreline(&p.integrator)
    }

    fn probe_pose(p: &mut PlanarSolver<Self>, tension_n: f64) -> Option<Result<TipPose, SolveFailure>> {
        p.probe_pose(tension_n)
    }

    fn probe_coefficient_difference(p: &mut PlanarSolver<Self>, basis: LengthBasis, a: &[f64]) -> Option<(f64, usize)> {
        p.probe_coefficient_difference(basis, a)
    }
}
