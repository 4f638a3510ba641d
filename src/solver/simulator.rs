//! The planar backends by name — [`PlanarCollocation`] (the default) and
//! [`PlanarRk4`] (the reference) — and [`Simulator`], the one of them
//! `options.method` asks for, for callers that pick it at run time.

use super::collocation::Colloc;
use super::error::SimulateError;
use super::planar::{Integrator, PlanarSolver};
use super::rk4::ShootingRk4;
use super::{Backend, CentrelinePoint, Hold, SolveFailure, Solver, SolverMethod, SolverOptions, TipPose};
use crate::model::parameter::ParameterError;
use crate::model::{Rod, Routing};
use crate::shape::LengthBasis;

/// The planar spectral collocation (the default planar backend).
pub type PlanarCollocation = PlanarSolver<Colloc>;
/// The planar RK4 reference: classical RK4 with secant shooting, the
/// plain scheme the collocation is checked against.
pub type PlanarRk4 = PlanarSolver<ShootingRk4>;

/// The planar backend `options.method` asks for, for callers that pick
/// it at run time: each call goes to that backend's own (statically
/// dispatched) solver.
#[derive(Debug, Clone)]
pub enum Simulator {
    /// [`PlanarCollocation`].
    Collocation(PlanarCollocation),
    /// [`PlanarRk4`].
    Rk4(PlanarRk4),
}

/// `$body` with `$s` bound to the backend a [`Simulator`] holds.
macro_rules! each {
    ($sim:expr, $s:ident => $body:expr) => {
        match $sim {
            Simulator::Collocation($s) => $body,
            Simulator::Rk4($s) => $body,
        }
    };
}

impl Simulator {
    /// The planar backend of `options.method` for `rod`; fails on invalid parameters.
    pub fn new(rod: &Rod, options: &SolverOptions) -> Result<Self, SimulateError> {
        Ok(match options.method {
            SolverMethod::Collocation => Simulator::Collocation(PlanarSolver::new(rod, options)?),
            SolverMethod::Rk4 => Simulator::Rk4(PlanarSolver::new(rod, options)?),
        })
    }

    /// The rod this solver was built for.
    pub fn rod(&self) -> &Rod {
        each!(self, s => s.rod())
    }

    /// [`PlanarSolver::set_routing_mm`].
    pub fn set_routing_mm(&mut self, y_mm: &[f64]) -> Result<(), crate::model::routing::RoutingError> {
        each!(self, s => s.set_routing_mm(y_mm))
    }

    /// [`PlanarSolver::set_routing`].
    pub fn set_routing(&mut self, routing: &Routing) {
        each!(self, s => s.set_routing(routing))
    }

    /// [`PlanarSolver::set_cable_stiffness`].
    pub fn set_cable_stiffness(&mut self, cable_ea_n: Option<f64>) {
        each!(self, s => s.set_cable_stiffness(cable_ea_n))
    }

    /// [`PlanarSolver::reset_warm_start`].
    pub fn reset_warm_start(&mut self) {
        each!(self, s => s.reset_warm_start())
    }

    /// [`PlanarSolver::reset_history`].
    pub fn reset_history(&mut self) {
        each!(self, s => s.reset_history())
    }

    /// [`PlanarSolver::set_hold`].
    pub fn set_hold(&mut self, hold: Hold) -> Result<(), ParameterError> {
        each!(self, s => s.set_hold(hold))
    }

    /// [`PlanarSolver::solve`].
    pub fn solve(&mut self, tension_n: f64) -> Result<TipPose, SolveFailure> {
        each!(self, s => s.solve(tension_n))
    }

    /// [`PlanarSolver::resolution`].
    pub fn resolution(&self) -> usize {
        each!(self, s => s.resolution())
    }

    /// [`PlanarSolver::coefficients_into`].
    pub fn coefficients_into(&mut self, basis: LengthBasis, out: &mut [f64]) {
        each!(self, s => s.coefficients_into(basis, out))
    }

    /// [`PlanarSolver::coefficient_error_per_mm`].
    pub fn coefficient_error_per_mm(&self) -> (f64, usize) {
        each!(self, s => s.coefficient_error_per_mm())
    }

    /// [`PlanarSolver::coefficients_checked`].
    pub fn coefficients_checked(&mut self, basis: LengthBasis, out: &mut [f64]) -> Result<(), SolveFailure> {
        each!(self, s => s.coefficients_checked(basis, out))
    }

    /// [`PlanarSolver::centreline`].
    pub fn centreline(&self) -> Vec<CentrelinePoint> {
        each!(self, s => s.centreline())
    }
}

impl Solver for Simulator {
    type Error = SolveFailure;
    fn backend(&self) -> Backend {
        each!(self, s => s.backend())
    }
    fn solve_tensions(&mut self, tensions_n: &[f64]) -> Result<TipPose, SolveFailure> {
        each!(self, s => s.solve_tensions(tensions_n))
    }
    fn hold_next(&mut self, hold: Hold) {
        each!(self, s => s.hold_next(hold))
    }
    fn centreline(&self) -> Vec<CentrelinePoint> {
        each!(self, s => Solver::centreline(s))
    }
    fn coefficients(&mut self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], SolveFailure> {
        each!(self, s => Solver::coefficients(s, order, basis))
    }
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
