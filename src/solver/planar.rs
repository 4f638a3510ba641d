//! The planar backends: one cable in the plane of gravity, solved by
//! spectral collocation ([`super::PlanarCollocation`], the default) or by
//! the RK4 reference ([`super::PlanarRk4`]). Each is a [`PlanarSolver`]
//! over its integrator ([`Integrator`]: its own points, warm starts and
//! outputs), sharing one [`PlanarState`] (rod, routing, hold, friction,
//! creep's load history, the cut equations); the solve around the
//! integration — the checks, the warm start's bookkeeping, the refusal of
//! an unresolved result — is written once here.

use super::error::SimulateError;
use super::{
    span_boundaries, tip_tolerance_mm, Backend, CentrelinePoint, ChannelSample, Creep, Friction, Given, Hold, PlanarState, SolveFailure, Solver,
    SolverMethod, SolverOptions, TipPose, Unresolved, MAX_NODES_PER_SPAN, MAX_STEPS_PER_SPAN,
};
use super::{resolution, resolution_advice};
use crate::model::parameter::ParameterError;
use crate::model::{Rod, Routing};
use crate::shape::LengthBasis;

/// One planar integration method: its own state beside the shared
/// [`PlanarState`], and the steps [`PlanarSolver`] runs it through.
pub trait Integrator: Sized + Clone + std::fmt::Debug {
    /// The method it integrates by.
    const METHOD: SolverMethod;

    /// Its state for `rod` with `options`, on `spans` knot spans, and the
    /// number of points the shared per-point buffers need.
    fn build(rod: &Rod, options: &SolverOptions, spans: usize) -> (Self, usize);

    /// Places its points on the routing `built` (offset already applied)
    /// and samples the channel there.
    fn set_routing(p: &mut PlanarSolver<Self>, built: &Routing);

    /// Forgets its warm start.
    fn forget(&mut self);

    /// Solves at `tension` from the warm start: the pose, and the estimated
    /// errors of the tangent angle (rad) and of the tip (mm).
    fn solve(p: &mut PlanarSolver<Self>, tension: f64) -> Result<(TipPose, (f64, f64)), SolveFailure>;

    /// Its resolution: collocation intervals or RK4 steps per span.
    fn resolution(p: &PlanarSolver<Self>) -> usize;

    /// The last solve's coefficients into `out` in `basis`, and their
    /// estimated error (the largest, mm⁻¹, and its order).
    fn coefficients(p: &mut PlanarSolver<Self>, basis: LengthBasis, out: &mut [f64]) -> (f64, usize);

    /// The last solve's centreline, clamp to tip.
    fn centreline(p: &PlanarSolver<Self>) -> Vec<CentrelinePoint>;

    /// A finer solve's pose at `tension_n` that settles an estimate above
    /// the tolerance; `None` where the method has none.
    fn probe_pose(_p: &mut PlanarSolver<Self>, _tension_n: f64) -> Option<Result<TipPose, SolveFailure>> {
        None
    }

    /// The largest difference of the coefficients `a` to a finer solve's,
    /// and its order; `None` where the method has none.
    fn probe_coefficient_difference(_p: &mut PlanarSolver<Self>, _basis: LengthBasis, _a: &[f64]) -> Option<(f64, usize)> {
        None
    }
}

/// A planar backend: the shared state and one integrator. Set a routing,
/// then solve tensions (in rising order for the best warm starts); it holds
/// all buffers it needs.
#[derive(Debug, Clone)]
pub struct PlanarSolver<I> {
    pub(super) state: PlanarState,
    pub(super) integrator: I,
}

impl<I: Integrator> PlanarSolver<I> {
    /// Creates a solver for `rod`; fails on invalid parameters.
    pub fn new(rod: &Rod, options: &SolverOptions) -> Result<Self, SimulateError> {
        rod.validate().map_err(ParameterError::from)?;
        // The upper bound keeps a typo (2e9 steps) from exhausting memory.
        if options.planar_steps_per_span < 2 || options.planar_steps_per_span % 2 != 0 || options.planar_steps_per_span > MAX_STEPS_PER_SPAN {
            return Err(ParameterError::OutOfRange {
                name: "steps_per_span",
                value: options.planar_steps_per_span as f64,
                expected: "an even number from 2 to 100000",
            }
            .into());
        }
        if I::METHOD == SolverMethod::Collocation && !(4..=MAX_NODES_PER_SPAN).contains(&options.nodes_per_span) {
            return Err(ParameterError::OutOfRange { name: "nodes_per_span", value: options.nodes_per_span as f64, expected: "between 4 and 64" }.into());
        }
        let options = SolverOptions { method: I::METHOD, ..options.clone() };
        let body = rod.body().map_err(ParameterError::from)?;
        Backend::check_planar(rod, &options, Given::default())?;
        let spans = span_boundaries(rod, body.as_ref(), 0.5 * rod.cable_length_mm()).len() - 1;
        let (integrator, points) = I::build(rod, &options, spans);
        let beta = rod.gravity.direction_rad;
        // A non-uniform body's weight is this factor times ∫ ρ r² (Body).
        let weight_n_per_mm = match &body {
            None => rod.weight_n_per_mm(),
            Some(_) if !rod.gravity.enabled => 0.0,
            Some(_) => rod.gravity.scale * 1e-6 * std::f64::consts::PI * rod.gravity.g_m_s2,
        };
        let state = PlanarState {
            rod: rod.clone(),
            options,
            weight_n_per_mm,
            gravity_cos: beta.cos(),
            gravity_sin: beta.sin(),
            routing: None,
            channel: vec![ChannelSample::default(); points],
            cable_dir: vec![(1.0, 0.0); points],
            last_tension_n: None,
            friction: Friction::new(rod.effects.friction_mu, rod.effects.load_direction.slip_sign(), points),
            creep: Creep::new(&rod.effects, rod.ei_n_mm2, points),
            body,
            cable_end: points,
            cable_rest_length_mm: 0.0,
            cable_ea_n: None,
            theta_error_rad: 0.0,
            coefficient_error: (0.0, 0),
            given_routing: None,
            hold: Hold::default(),
            probe: None,
            is_probe: false,
        };
        let mut sim = Self { state, integrator };
        // Outside a protocol every solve is held like this from a virgin rod.
        let hold = Hold { direction: rod.effects.load_direction, dwell_s: rod.effects.creep_hold_s };
        hold.check()?;
        sim.apply_hold(hold);
        Ok(sim)
    }

    /// The rod this solver was built for.
    pub fn rod(&self) -> &Rod {
        &self.state.rod
    }

    /// Validates `y_mm` against the rod and sets it as the routing.
    pub fn set_routing_mm(&mut self, y_mm: &[f64]) -> Result<(), crate::model::routing::RoutingError> {
        let routing = Routing::for_actuator(y_mm, &self.state.rod)?;
        self.set_routing(&routing);
        Ok(())
    }

    /// Sets the routing (precomputing the channel at every point) and
    /// forgets the warm start. The routing must span the cable's length
    /// (build it with [`Routing::for_actuator`]).
    pub fn set_routing(&mut self, routing: &Routing) {
        let rod = &self.state.rod;
        debug_assert!((routing.length_mm() - rod.cable_length_mm()).abs() <= 1e-9 * rod.length_mm);
        let delta = rod.effects.channel_offset_mm;
        let built = if delta != 0.0 { routing.shifted(delta) } else { routing.clone() };
        I::set_routing(self, &built);
        let s = &mut self.state;
        s.routing = Some(built);
        s.given_routing = Some(routing.clone());
        if let Some(p) = s.probe.as_mut() {
            p.stale();
        }
        self.reset_warm_start();
        self.reset_history();
        self.state.last_tension_n = None;
    }

    /// Sets the cable's axial stiffness EA, N (`None`: inextensible), which
    /// the pose's displacement adds the cable's stretch with (collocation;
    /// RK4 reports no displacement).
    pub fn set_cable_stiffness(&mut self, cable_ea_n: Option<f64>) {
        self.state.cable_ea_n = cable_ea_n;
    }

    /// Forgets the warm start (the next solve starts cold). The creep
    /// history is physical state and is kept.
    pub fn reset_warm_start(&mut self) {
        self.integrator.forget();
        self.state.cable_dir.iter_mut().for_each(|d| *d = (1.0, 0.0));
        self.state.friction.forget();
    }

    /// Forgets the load history (creep): the material is as new, unloaded.
    pub fn reset_history(&mut self) {
        self.state.creep.forget();
    }

    /// Sets how the next solves are held: the load direction (sign of
    /// friction) and the dwell time before the reading (creep). From then
    /// on solves follow a protocol: the creep history carries over from
    /// solve to solve (a dwell of 0 s leaves it unchanged).
    ///
    /// Without this call every solve is held `effects.creep_hold_s` on a
    /// rod with no load history, in `effects.load_direction`.
    pub fn set_hold(&mut self, hold: Hold) -> Result<(), ParameterError> {
        hold.check()?;
        self.state.creep.follow_protocol();
        self.apply_hold(hold);
        Ok(())
    }

    /// Hands a checked `hold` to friction (slip sign) and creep (dwell).
    pub(super) fn apply_hold(&mut self, hold: Hold) {
        let s = &mut self.state;
        s.friction.set_slip_sign(hold.direction.slip_sign());
        s.creep.set_dwell(hold.dwell_s);
        s.hold = hold;
        if let Some(p) = s.probe.as_mut() {
            p.stale();
        }
    }

    /// Solves the statics for `tension_n` (N) on the current routing,
    /// warm-started from the previous solves of this routing.
    ///
    /// # Panics
    /// If no routing was set.
    pub fn solve(&mut self, tension_n: f64) -> Result<TipPose, SolveFailure> {
        assert!(self.state.routing.is_some(), "PlanarSolver::solve called before set_routing");
        if !(tension_n.is_finite() && tension_n >= 0.0) {
            return Err(SolveFailure::InvalidTension(tension_n));
        }
        self.state.creep.begin_solve();
        if let Some(p) = self.state.probe.as_mut() {
            p.forget_solve();
        }
        let result = self.solve_inner(tension_n);
        match &result {
            Ok(pose) => self.state.last_tension_n = Some(pose.tension_n()),
            Err(_) => {
                self.state.last_tension_n = None;
                self.reset_warm_start();
            }
        }
        result
    }

    fn solve_inner(&mut self, tension: f64) -> Result<TipPose, SolveFailure> {
        // The error estimate comes before the creep history moves on, so
        // that a refused solve leaves the history as it was.
        let (pose, (theta_error, tip_error)) = I::solve(self, tension)?;
        self.state.theta_error_rad = self.check_resolved(&pose, theta_error, tip_error)?;
        self.state.creep.end_solve();
        Ok(pose)
    }

    /// Refuses a pose with a non-finite number, an estimated tip error
    /// `tip_error_mm` above [`tip_tolerance_mm`] (unless a probe at twice
    /// the intervals agrees to within it), or a tip farther from the
    /// clamp than the stretched rod is long (which no curve can do).
    /// Returns the estimated error of the tangent angle, rad.
    fn check_resolved(&mut self, pose: &TipPose, theta_error_rad: f64, tip_error_mm: f64) -> Result<f64, SolveFailure> {
        let scalars = [pose.tip_x_mm, pose.tip_y_mm, pose.tip_angle_rad, pose.tip_frame_angle_rad, pose.base_angle_rad, pose.length_mm];
        let length_mm = self.state.rod.length_mm;
        if !scalars.iter().all(|v| v.is_finite()) {
            return Err(SolveFailure::NonFinite { s_mm: Some(length_mm) });
        }
        if self.state.is_probe {
            return Ok(0.0);
        }
        let tolerance = tip_tolerance_mm(length_mm);
        let reach = pose.tip_x_mm.hypot(pose.tip_y_mm);
        if reach > pose.length_mm + tolerance {
            return Err(self.unresolved(
                format!("the tip (|tip| = {} mm is more than the stretched length ℓ = {} mm)", crate::io::fmt_num(reach), crate::io::fmt_num(pose.length_mm)),
                reach - pose.length_mm,
                tolerance,
                "mm",
            ));
        }
        if tip_error_mm <= tolerance {
            return Ok(theta_error_rad);
        }
        // The estimate is an upper bound, often far above the error: a
        // solve at twice the intervals tells.
        match I::probe_pose(self, pose.tension_n()) {
            Some(Ok(fine)) => {
                let difference = (pose.tip_x_mm - fine.tip_x_mm).hypot(pose.tip_y_mm - fine.tip_y_mm);
                if difference <= tolerance {
                    return Ok((pose.tip_angle_rad - fine.tip_angle_rad).abs());
                }
                Err(self.unresolved("the tip position".into(), difference, tolerance, "mm"))
            }
            _ => Err(self.unresolved("the tip position".into(), tip_error_mm, tolerance, "mm")),
        }
    }

    /// [`SolveFailure::Unresolved`] with the setting to raise for this
    /// solver's method.
    fn unresolved(&self, what: String, estimate: f64, tolerance: f64, unit: &'static str) -> SolveFailure {
        SolveFailure::Unresolved(Unresolved { what, estimate, tolerance, unit, advice: resolution_advice(&self.state.options, self.resolution()) })
    }

    /// The resolution in use: collocation intervals per span (at least
    /// [`super::MIN_NODES_WITH_STIFFENING`] with stiffening), or RK4 steps per span.
    pub fn resolution(&self) -> usize {
        I::resolution(self)
    }

    /// Legendre curvature coefficients a_0 … a_{n−1} (n = `out.len()`) of the
    /// last successful solve in `basis`, by the exact definition
    /// (model-notes §4), computed from the solver's nodes without allocating.
    ///
    /// # Panics
    /// If the last solve failed or none was made.
    ///
    /// Also estimates their error ([`PlanarSolver::coefficient_error_per_mm`]);
    /// [`PlanarSolver::coefficients_checked`] refuses coefficients the
    /// discretisation does not resolve.
    pub fn coefficients_into(&mut self, basis: LengthBasis, out: &mut [f64]) {
        assert!(self.state.last_tension_n.is_some(), "coefficients_into needs a successful solve");
        let estimate = I::coefficients(self, basis, out);
        self.state.coefficient_error = if estimate.0 <= resolution::ORDER_TOLERANCE_PER_MM || self.state.is_probe {
            estimate
        } else {
            // As for the tip: a solve at twice the intervals tells.
            I::probe_coefficient_difference(self, basis, out).unwrap_or(estimate)
        };
    }

    /// The estimated error of the coefficients of the last
    /// [`PlanarSolver::coefficients_into`]: the largest over a_0 … a_n, mm⁻¹,
    /// and the index k of the a_k it belongs to.
    pub fn coefficient_error_per_mm(&self) -> (f64, usize) {
        self.state.coefficient_error
    }

    /// [`PlanarSolver::coefficients_into`], refusing coefficients whose
    /// estimated error is above [`resolution::ORDER_TOLERANCE_PER_MM`]
    /// or that are not finite.
    pub fn coefficients_checked(&mut self, basis: LengthBasis, out: &mut [f64]) -> Result<(), SolveFailure> {
        self.coefficients_into(basis, out);
        if !out.iter().all(|a| a.is_finite()) {
            return Err(SolveFailure::NonFinite { s_mm: Some(self.state.rod.length_mm) });
        }
        let (error, k) = self.state.coefficient_error;
        let tolerance = resolution::ORDER_TOLERANCE_PER_MM;
        if !(error <= tolerance) {
            return Err(self.unresolved(format!("a_{k}"), error, tolerance, "mm⁻¹"));
        }
        Ok(())
    }

    /// The centreline of the last successful solve, clamp to tip.
    pub fn centreline(&self) -> Vec<CentrelinePoint> {
        assert!(self.state.last_tension_n.is_some(), "centreline needs a successful solve");
        I::centreline(self)
    }
}

/// Each planar backend, one cable in the plane.
impl<I: Integrator> Solver for PlanarSolver<I> {
    type Error = SolveFailure;
    fn backend(&self) -> Backend {
        Backend::planar(I::METHOD)
    }
    fn solve_tensions(&mut self, tensions_n: &[f64]) -> Result<TipPose, SolveFailure> {
        self.solve(tensions_n[0])
    }
    fn hold_next(&mut self, hold: Hold) {
        self.state.creep.follow_protocol();
        self.apply_hold(hold);
    }
    fn centreline(&self) -> Vec<CentrelinePoint> {
        PlanarSolver::centreline(self)
    }
    /// Bending about body z only: twist and bending about y are zero in the plane.
    fn coefficients(&mut self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], SolveFailure> {
        let mut a = vec![0.0; order + 1];
        self.coefficients_checked(basis, &mut a)?;
        Ok([vec![0.0; order + 1], vec![0.0; order + 1], a])
    }
}
