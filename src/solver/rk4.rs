//! The reference integration method ([`super::SolverMethod::Rk4`]), a
//! plain scheme the collocation is checked against: classical RK4 forward from the clamp with
//! `steps_per_span` steps on each knot span, and secant shooting on
//! gravity's base moment M(0), warm-started across the continuation in
//! tension (`continuation`). Per-point buffers are indexed by stage point,
//! 2n + 1 per span of n steps (the knot appears in both spans).

use super::continuation::Continuation;
use super::result::{PerCable, PlanarPoint};
use super::planar::{Integrator, PlanarSolver};
use super::{
    bending_moment, friction, rotate, CentrelinePoint, ChannelSample, Routing, SolveFailure, SolverOptions, Strains, TipPose,
    CLAMP_MAX_ITERATIONS, CLAMP_TOLERANCE_RAD,
};
use crate::model::Rod;
use crate::numerics::{rk4_step, Rk4Scratch};
use crate::shape::{self, LengthBasis};

/// Integration state: position, frame angle, gravity's distal moment, arc length.
#[derive(Debug, Clone, Copy, Default)]
struct State {
    x: f64,
    y: f64,
    phi: f64,
    moment: f64,
    sigma: f64,
}

/// Position of φ in [`State::to_array`] (the stepper's state).
const PHI: usize = 2;

impl State {
    /// The state as the shared RK4 stepper's array: x, y, φ, moment, σ.
    #[inline]
    fn to_array(self) -> [f64; 5] {
        [self.x, self.y, self.phi, self.moment, self.sigma]
    }
    /// The inverse of [`State::to_array`].
    #[inline]
    fn from_array([x, y, phi, moment, sigma]: [f64; 5]) -> State {
        State { x, y, phi, moment, sigma }
    }
    fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.phi.is_finite() && self.moment.is_finite() && self.sigma.is_finite()
    }
}

/// [`rotate`] for the pair in `sin_cos` order, (sin a, cos a).
#[inline]
fn rotate_sin_cos((s, c): (f64, f64), delta: f64) -> (f64, f64) {
    let (c, s) = rotate((c, s), delta);
    (s, c)
}

/// The planar RK4 integrator, shooting on the tip conditions: the step
/// grid, the nodes of the last pass and the warm start of the shooting.
#[derive(Debug, Clone)]
pub struct ShootingRk4 {
    /// Step length on each span, mm.
    step_mm: [f64; 2],
    /// Span starts, mm.
    span_start_mm: [f64; 2],
    /// Per-node results of the last pass (n + 1 nodes per span, the knot shared).
    nodes_state: Vec<State>,
    nodes_strain: Vec<Strains>,
    /// Scratch for shape coefficients.
    theta: Vec<f64>,
    speed: Vec<f64>,
    sigma: Vec<f64>,
    /// The same at the nodes of the error estimate's coarse pass (at
    /// twice the step: every other node).
    coarse_theta: Vec<f64>,
    coarse_speed: Vec<f64>,
    coarse_sigma: Vec<f64>,
    /// Set during the error estimate's coarse pass: the stage points are
    /// evaluated without recording anything (warm starts, friction's cable
    /// angles, creep's moments belong to the solution).
    probe: bool,
    /// Warm start of the shooting across the continuation in tension.
    continuation: Continuation,
}

impl ShootingRk4 {
    /// Buffers for `n` steps per span.
    pub(super) fn new(n: usize) -> Self {
        let nodes = 2 * n + 1;
        Self {
            step_mm: [0.0; 2],
            span_start_mm: [0.0; 2],
            nodes_state: vec![State::default(); nodes],
            nodes_strain: vec![Strains::default(); nodes],
            theta: vec![0.0; nodes],
            speed: vec![0.0; nodes],
            sigma: vec![0.0; nodes],
            coarse_theta: vec![0.0; n + 1],
            coarse_speed: vec![0.0; n + 1],
            coarse_sigma: vec![0.0; n + 1],
            probe: false,
            continuation: Continuation::default(),
        }
    }

    /// Forgets the warm start of the shooting.
    pub(super) fn forget(&mut self) {
        self.continuation = Continuation::default();
    }

    /// Records node `node` of the error estimate's coarse pass: state `st`, strains `e`.
    fn record_coarse(&mut self, node: usize, st: &State, e: &Strains) {
        self.coarse_theta[node] = st.phi + e.v2.atan2(e.v1);
        self.coarse_speed[node] = e.v1.hypot(e.v2);
        self.coarse_sigma[node] = st.sigma;
    }
}

impl PlanarSolver<ShootingRk4> {
    /// Places the stage points on the knot spans of `built` and samples the
    /// channel there.
    fn rk4_set_routing(&mut self, built: &Routing) {
        let n = self.state.options.planar_steps_per_span;
        let knot = built.knot_mm();
        let length = self.state.rod.length_mm;
        self.integrator.span_start_mm = [0.0, knot];
        self.integrator.step_mm = [knot / n as f64, (length - knot) / n as f64];
        for span in 0..2 {
            for j in 0..=2 * n {
                let s = self.integrator.span_start_mm[span] + 0.5 * j as f64 * self.integrator.step_mm[span];
                let c = built.channel_at(s);
                self.state.channel[span * (2 * n + 1) + j] = ChannelSample { y: c.y_mm, dy: c.dy_ds };
            }
        }
    }

    /// Right-hand side of the forward ODE at stage point `k` (index into the
    /// channel samples); `(sp, cp)` = sin, cos of the state's φ.
    #[inline]
    fn derivative(
        &mut self,
        s: f64,
        k: usize,
        st: &State,
        (sp, cp): (f64, f64),
        tension: f64,
    ) -> Result<(State, Strains), SolveFailure> {
        let ch = self.state.channel[k];
        let local_tension = tension * self.state.friction.ratio(k);
        let creep_offset = self.state.creep.offset(k);
        let section = self.state.section_at(s);
        let (e, dir) = self.state.strains_at(s, &section, ch, (sp, cp), st.moment, local_tension, self.state.cable_dir[k], creep_offset)?;
        if self.integrator.probe {
            return Ok((self.rates(s, &e, (sp, cp)), e));
        }
        self.state.cable_dir[k] = dir;
        // Only friction (cable angles) and creep (moments) need these.
        if self.state.friction.is_on() {
            self.state.friction.record_cable_direction(k, (sp, cp), dir);
        }
        if self.state.creep.is_on() {
            let ei = section.ei_n_mm2;
            self.state.creep.record_moment(k, bending_moment(local_tension, ch.y, dir.0, st.moment), ei);
        }
        Ok((self.rates(s, &e, (sp, cp)), e))
    }

    /// The state's rates at `s` from the strains `e`; `(sp, cp)` = sin, cos of φ.
    #[inline]
    fn rates(&self, s: f64, e: &Strains, (sp, cp): (f64, f64)) -> State {
        let dx = e.v1 * cp - e.v2 * sp;
        let dy = e.v1 * sp + e.v2 * cp;
        let wl = self.state.distal_weight_n(s);
        State {
            x: dx,
            y: dy,
            phi: e.u,
            moment: wl * (dy * self.state.gravity_cos - dx * self.state.gravity_sin),
            sigma: (e.v1 * e.v1 + e.v2 * e.v2).sqrt(),
        }
    }

    /// Frame angle at the clamp: 0 for a rigid clamp; with clamp compliance
    /// φ(0) = m(0)/k_θ with m(0) the bending moment there (fixed point, as
    /// m(0) depends on φ(0) only through the weight's direction).
    fn clamp_angle(&mut self, moment0: f64, tension: f64) -> Result<f64, SolveFailure> {
        let Some(k_theta) = self.state.rod.effects.clamp_stiffness_n_mm_per_rad else {
            return Ok(0.0);
        };
        let ch = self.state.channel[0];
        let mut phi: f64 = 0.0;
        for _ in 0..CLAMP_MAX_ITERATIONS {
            let (_, (ca, _)) =
                self.state.strains_at(0.0, &self.state.section_at(0.0), ch, phi.sin_cos(), moment0, tension, self.state.cable_dir[0], self.state.creep.offset(0))?;
            let m = bending_moment(tension, ch.y, ca, moment0);
            let next = m / k_theta;
            if (next - phi).abs() < CLAMP_TOLERANCE_RAD {
                return Ok(next);
            }
            phi = next;
        }
        Err(SolveFailure::ClampNotConverged)
    }

    /// One forward pass from the clamp with base moment `moment0`; records
    /// the nodes and returns gravity's moment left at the tip (0 at the solution).
    fn integrate(&mut self, tension: f64, moment0: f64) -> Result<f64, SolveFailure> {
        Ok(self.integrate_strided(tension, moment0, 1)?.moment)
    }

    /// One forward pass with steps `stride` times the grid's (1: the
    /// solution's pass, which records the nodes; 2: the error estimate's
    /// coarse pass, on every other stage point). Returns the tip state.
    fn integrate_strided(&mut self, tension: f64, moment0: f64, stride: usize) -> Result<State, SolveFailure> {
        let n = self.state.options.planar_steps_per_span;
        let record = stride == 1;
        let mut st = State { phi: self.clamp_angle(moment0, tension)?, moment: moment0, ..State::default() };
        let mut scratch = Rk4Scratch::default();
        for span in 0..2 {
            let h = self.integrator.step_mm[span] * stride as f64;
            let base = span * (2 * n + 1);
            for step in 0..n / stride {
                let s = self.integrator.span_start_mm[span] + step as f64 * h;
                let k = base + 2 * stride * step;
                // One sin/cos per step; the stages rotate it by small angles.
                let trig = st.phi.sin_cos();
                let mut y = st.to_array();
                rk4_step(&mut y, h, &mut scratch, |stage, dy| {
                    let point = k + stride * stage.half_steps;
                    let stage_trig = if stage.index == 0 { trig } else { rotate_sin_cos(trig, stage.offset * stage.slope[PHI]) };
                    let stage_state = State::from_array(*stage.state);
                    let (d, e) = self.derivative(s + stage.offset, point, &stage_state, stage_trig, tension)?;
                    if stage.index == 0 {
                        if record {
                            let node = span * n + step;
                            self.integrator.nodes_state[node] = stage_state;
                            self.integrator.nodes_strain[node] = e;
                        } else {
                            self.integrator.record_coarse(span * (n / stride) + step, &stage_state, &e);
                        }
                    }
                    *dy = d.to_array();
                    Ok::<(), SolveFailure>(())
                })?;
                st = State::from_array(y);
                if !st.is_finite() {
                    return Err(SolveFailure::NonFinite { s_mm: Some(s + h) });
                }
            }
        }
        // Tip node.
        let k_tip = 2 * (2 * n + 1) - 1;
        let (_, e) = self.derivative(self.state.rod.length_mm, k_tip, &st, st.phi.sin_cos(), tension)?;
        if record {
            let tip = 2 * n;
            self.integrator.nodes_state[tip] = st;
            self.integrator.nodes_strain[tip] = e;
        } else {
            self.integrator.record_coarse(2 * (n / stride), &st, &e);
        }
        Ok(st)
    }

    /// A posteriori error estimate of the last solve: the errors of the
    /// tangent angle (rad) and of the tip (mm) as their differences to a
    /// pass at twice the step from the same base moment. RK4's error falls
    /// as h⁴, so Richardson's rule would take 1/15 of the difference; on
    /// random bodies that fell short of the error by up to 3.7 times, while
    /// the whole difference was at least 4 times it (and 15 at the median).
    fn rk4_error_estimate(&mut self, tension: f64) -> Result<(f64, f64), SolveFailure> {
        let n = self.state.options.planar_steps_per_span;
        let fine = self.integrator.nodes_state[2 * n];
        let moment0 = self.integrator.nodes_state[0].moment;
        self.integrator.probe = true;
        let coarse = self.integrate_strided(tension, moment0, 2);
        self.integrator.probe = false;
        let coarse = coarse?;
        let theta_error = (fine.phi - coarse.phi).abs();
        let tip_error = (fine.x - coarse.x).hypot(fine.y - coarse.y);
        Ok((theta_error, tip_error))
    }

    /// Secant shooting on gravity's base moment `m0` from the given guess
    /// and slope dM(L)/dM(0) (both updated in place). Returns the passes used.
    fn shoot(&mut self, tension: f64, m0: &mut f64, slope: &mut f64) -> Result<u32, SolveFailure> {
        let mut passes = 1u32;
        let mut f0 = self.integrate(tension, *m0)?;
        let mut prev: Option<(f64, f64)> = None;
        while f0.abs() > self.state.options.planar_moment_tolerance_n_mm {
            if passes >= self.state.options.max_shooting_passes {
                return Err(SolveFailure::ShootingNotConverged { iterations: passes, residual_n_mm: f0 });
            }
            if let Some((mp, fp)) = prev {
                let secant = (f0 - fp) / (*m0 - mp);
                if secant.is_finite() && secant != 0.0 {
                    *slope = secant;
                }
            }
            prev = Some((*m0, f0));
            *m0 -= f0 / *slope;
            f0 = self.integrate(tension, *m0)?;
            passes += 1;
        }
        Ok(passes)
    }

    /// Solves for `tension` from the warm start; returns the passes used.
    fn rk4_solve(&mut self, tension: f64) -> Result<u32, SolveFailure> {
        let has_moment = self.state.weight_n_per_mm != 0.0;
        let has_friction = self.state.friction.acts_at(tension);
        let n = self.state.options.planar_steps_per_span;
        let mut passes;
        if has_moment {
            let (mut m0, mut slope) = self.integrator.continuation.predict(tension);
            passes = self.shoot(tension, &mut m0, &mut slope)?;
            if has_friction {
                passes += friction::settle(
                    self,
                    |sim| sim.state.friction.update_from_rk4_nodes(n),
                    |sim| sim.shoot(tension, &mut m0, &mut slope),
                )?;
            }
            self.integrator.continuation.record(tension, m0, slope);
        } else {
            self.integrate(tension, 0.0)?;
            passes = 1;
            if has_friction {
                passes += friction::settle(
                    self,
                    |sim| sim.state.friction.update_from_rk4_nodes(n),
                    |sim| sim.integrate(tension, 0.0).map(|_| 1),
                )?;
            }
        }
        Ok(passes)
    }

    /// The pose of the last pass.
    fn rk4_pose(&self, tension: f64, passes: u32) -> TipPose {
        let n_nodes = self.integrator.nodes_state.len();
        let base = self.integrator.nodes_state[0];
        let tip = self.integrator.nodes_state[n_nodes - 1];
        let (e0, et) = (self.integrator.nodes_strain[0], self.integrator.nodes_strain[n_nodes - 1]);
        TipPose {
            tensions_n: PerCable::one(tension),
            displacements_mm: PerCable::one(f64::NAN),
            tip_x_mm: tip.x,
            tip_y_mm: tip.y,
            tip_angle_rad: tip.phi + et.v2.atan2(et.v1),
            tip_frame_angle_rad: tip.phi,
            base_angle_rad: base.phi + e0.v2.atan2(e0.v1),
            length_mm: tip.sigma,
            iterations: passes,
            tip_z_mm: 0.0,
            frame_3d: None,
        }
    }

    /// Legendre coefficients of the last solve from the tangent at the nodes.
    ///
    /// Returns the estimated error of the largest a_n, mm⁻¹, and n: its
    /// difference to the coefficients of the error estimate's coarse pass
    /// (see [`PlanarSolver::rk4_error_estimate`]), which differ in both the
    /// angles and the quadrature.
    fn rk4_coefficients(&mut self, basis: LengthBasis, out: &mut [f64]) -> (f64, usize) {
        let r = &mut self.integrator;
        for (i, (st, e)) in r.nodes_state.iter().zip(&r.nodes_strain).enumerate() {
            r.theta[i] = st.phi + e.v2.atan2(e.v1);
            r.speed[i] = e.v1.hypot(e.v2);
            r.sigma[i] = st.sigma;
        }
        // Nodes are evenly spaced in s: the knot is at L/2 for the clamped
        // spline with evenly spaced control points.
        let h = r.step_mm[0];
        debug_assert!((r.step_mm[0] - r.step_mm[1]).abs() < 1e-12);
        shape::legendre_from_tangent(&r.theta, &r.sigma, &r.speed, h, out);
        let mut coarse = [0.0f64; super::ESTIMATED_ORDERS];
        let estimated = out.len().min(super::ESTIMATED_ORDERS);
        shape::legendre_from_tangent(&r.coarse_theta, &r.coarse_sigma, &r.coarse_speed, 2.0 * h, &mut coarse[..estimated]);
        let ell = r.sigma[r.sigma.len() - 1] - r.sigma[0];
        let errors = out.iter().enumerate().map(|(n, a)| coarse.get(n).map_or(f64::INFINITY, |c| (a - c).abs()));
        let worst = super::largest_error(errors, basis, ell, self.state.rod.length_mm);
        basis.convert_from_deformed(out, ell, self.state.rod.length_mm);
        worst
    }

    /// The centreline of the last solve at the nodes.
    fn rk4_centreline(&self) -> Vec<CentrelinePoint> {
        let n = self.state.options.planar_steps_per_span;
        let tension = self.state.last_tension_n.unwrap_or(0.0);
        (0..self.integrator.nodes_state.len())
            .map(|i| {
                let (span, j) = if i < n { (0, i) } else { (1, i - n) };
                let s = self.integrator.span_start_mm[span] + j as f64 * self.integrator.step_mm[span];
                let k = span * (2 * n + 1) + 2 * j;
                let st = self.integrator.nodes_state[i];
                let e = self.integrator.nodes_strain[i];
                let yc = self.state.channel[k].y;
                CentrelinePoint::from(PlanarPoint {
                    s_mm: s,
                    x_mm: st.x,
                    y_mm: st.y,
                    frame_angle_rad: st.phi,
                    frame_sin_cos: st.phi.sin_cos(),
                    tangent_angle_rad: st.phi + e.v2.atan2(e.v1),
                    arc_length_mm: st.sigma,
                    v1: e.v1,
                    v2: e.v2,
                    u_per_mm: e.u,
                    channel_y_mm: yc,
                    cable_tension_n: tension * self.state.friction.ratio(k),
                })
            })
            .collect()
    }
}


/// The planar RK4 reference.
impl Integrator for ShootingRk4 {
    const METHOD: super::SolverMethod = super::SolverMethod::Rk4;

    fn build(_rod: &Rod, options: &SolverOptions, _spans: usize) -> (Self, usize) {
        let n = options.planar_steps_per_span;
        (ShootingRk4::new(n), 2 * (2 * n + 1))
    }

    fn set_routing(p: &mut PlanarSolver<Self>, built: &Routing) {
        p.rk4_set_routing(built);
    }

    fn forget(&mut self) {
        ShootingRk4::forget(self);
    }

    fn solve(p: &mut PlanarSolver<Self>, tension: f64) -> Result<(TipPose, (f64, f64)), SolveFailure> {
        let passes = p.rk4_solve(tension)?;
        Ok((p.rk4_pose(tension, passes), p.rk4_error_estimate(tension)?))
    }

    fn resolution(p: &PlanarSolver<Self>) -> usize {
        p.state.options.planar_steps_per_span
    }

    fn coefficients(p: &mut PlanarSolver<Self>, basis: LengthBasis, out: &mut [f64]) -> (f64, usize) {
        p.rk4_coefficients(basis, out)
    }

    fn centreline(p: &PlanarSolver<Self>) -> Vec<CentrelinePoint> {
        p.rk4_centreline()
    }
}

#[cfg(test)]
mod tests {
    use crate::model::Routing;
    use crate::solver::{simulate, SolverOptions};
    use crate::shape::LengthBasis;

    /// RK4's estimates (the differences to a pass at twice the step) bound
    /// its errors against a collocation solve at 64 intervals, on random
    /// bodies, routings and tensions.
    #[test]
    fn the_error_estimates_bound_the_errors() {
        let mut rng = crate::calibrate::rng::Rng::new(11);
        let mut checked = 0;
        for _ in 0..12 {
            let (a, y, tension) = super::super::tests::random_case(&mut rng);
            let fine = SolverOptions { nodes_per_span: 64, ..SolverOptions::default() };
            let Ok(reference) = simulate(&a, &fine, &Routing::for_actuator(&y, &a).unwrap(), tension, 5, LengthBasis::Rest) else { continue };
            for n in [8, 16, 24] {
                let mut sim = crate::solver::PlanarRk4::new(&a, &SolverOptions { planar_steps_per_span: n, ..SolverOptions::default() }).unwrap();
                sim.set_routing_mm(&y).unwrap();
                let rungs = crate::solver::ladder::tension_rungs(tension);
                let mut solved = None;
                for k in 1..=rungs {
                    let t = tension * k as f64 / rungs as f64;
                    let Ok(passes) = sim.rk4_solve(t) else { break };
                    solved = (k == rungs).then(|| sim.rk4_pose(t, passes));
                    sim.state.last_tension_n = Some(t);
                }
                let Some(pose) = solved else { continue };
                let (_, tip_error) = sim.rk4_error_estimate(tension).unwrap();
                let mut c = [0.0; 6];
                let (a_error, _) = sim.rk4_coefficients(LengthBasis::Rest, &mut c);
                let off = (pose.tip_x_mm - reference.pose.tip_x_mm).hypot(pose.tip_y_mm - reference.pose.tip_y_mm);
                assert!(off <= tip_error + 1e-7, "{n} steps: tip off by {off:e} mm, estimated {tip_error:e}");
                for k in 0..6 {
                    assert!((c[k] - reference.a_bend_z[k]).abs() <= a_error + 1e-9, "{n} steps: a_{k} off by {:e}, estimated {a_error:e}", (c[k] - reference.a_bend_z[k]).abs());
                }
                checked += 1;
            }
        }
        assert!(checked >= 20, "only {checked} cases solved");
    }
}
