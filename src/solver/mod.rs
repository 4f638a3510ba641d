//! Static solver for the coupled Cosserat rod–cable model (Rucker & Webster
//! 2011) in the equilibrium-at-a-cut form of model-notes §3b.
//!
//! Cutting the rod at s and taking the distal part as a free body gives the
//! strains at s from the cable tension τ(s), the cable direction in the body
//! frame, and the loads of distributed external forces beyond the cut. Writing
//! the cable direction as t_c = (cos α, sin α) leaves one scalar equation per
//! point (t_c ∥ v + u × r_c + r_c'), solved by Newton. The centreline then
//! follows by integrating from the clamp on each knot span of the routing,
//! where the routing is a polynomial: by default with spectral collocation
//! on Chebyshev–Lobatto nodes ([`SolverMethod::Collocation`], in the
//! `collocation` submodule, which also replaces the shooting below by
//! fixed-point sweeps and Newton's method), or with classical RK4
//! ([`SolverMethod::Rk4`], the reference the collocation is checked against, in `rk4`).
//!
//! One file per piece: this file holds the cut equations shared by both
//! integrators ([`Simulator::strains_at`]) and the public API; `collocation`
//! and `rk4` are the two integrators; `continuation` is RK4's warm-start
//! predictor; `friction` and `creep` are the two effects with state.
//!
//! Gravity's moment beyond the cut, M_W(s), depends on the distal shape; it
//! obeys M_W' = w (L − s)(y' cos β − x' sin β) with M_W(L) = 0, so its value at
//! the clamp is the one unknown of a scalar shooting (secant, warm-started
//! across a continuation in tension). Without distributed loads there is no
//! shooting at all.
//!
//! Effects (model-notes §6) enter as local terms: the bending law
//! ([`Simulator::bending_curvature`]), the clamp boundary (`clamp_angle` in
//! each integrator), the routing (channel offset) and the weight.
//! The section's rigidities and the weight beyond a cut are looked up in one
//! place each ([`Simulator::section_at`], [`Simulator::distal_weight_n`]),
//! and the bending moment at a cut is one function ([`bending_moment`]).
//!
//! Two effects carry state beyond one point, each a small state type with
//! the few hooks the integrators call:
//! - **Cable–channel friction** (`friction`: capstan law
//!   dτ/ds = −η μ τ |ψ'| with the slip sign η): a tension profile τ(s)/τ(0)
//!   updated from the cable angles of the last pass until it settles.
//! - **Viscoelastic creep in bending** (`creep`: standard linear solid): a
//!   local, linear law at the end of each held step, and the internal
//!   curvature q(s) advanced after the solve. `set_routing` and
//!   `reset_history` clear that history.
//!
//! (σ is the deformed arc length throughout.)
//!
//! The hot paths (RK4's `integrate`, collocation's sweeps) work in buffers
//! allocated once per [`Simulator`]; solving allocates nothing, except in
//! collocation's Newton fallback for heavy rods (a dense Jacobian).

use crate::model::parameter::ParameterError;
use crate::model::rod::{LoadDirection, Rod};
use crate::model::body::{merge_sorted, Body};
use crate::model::routing::Routing;
use crate::shape::LengthBasis;
use serde::{Deserialize, Serialize};

pub mod actuation;
pub mod backend;
mod error;
pub mod interface;
pub mod ladder;
pub mod record;
pub mod resolution;
pub mod spatial;
pub(crate) mod collocation;
mod continuation;
pub(crate) mod creep;
pub(crate) mod friction;
mod probe;
pub mod result;
mod rk4;
pub mod simulate;
pub mod options;

pub use backend::{Backend, Given, Support, Unsupported};
pub use error::SimulateError;
pub use interface::{until_resolved, Solver};
pub use result::{CableAtNode, CentrelinePoint, PerCable, Simulation, TipFrame, TipPose};
pub use simulate::{
    check_ladder_tension, planar_problem, simulate, simulate_actuator, simulate_held, simulate_spatial, MAX_AUTO_SPATIAL_STEPS_PER_SPAN,
    MAX_AUTO_STEPS_PER_SPAN, MAX_LADDER_TENSION_N,
};
pub use options::{SolverMethod, SolverOptions};
use creep::Creep;
use friction::Friction;

/// Why a solve produced no result. The sweep stores [`SolveFailure::status`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveFailure {
    /// The tension is negative or not finite.
    #[error("tension {} N is invalid: a cable pulls with a finite tension ≥ 0 N", crate::io::fmt_num(*.0))]
    InvalidTension(f64),
    /// The per-point cable-direction equation did not converge.
    #[error("the cable-direction equation did not converge at s = {s_mm:.3} mm; try smaller tension steps from a lower tension")]
    CableDirectionNotConverged { s_mm: f64 },
    /// The cable tangent vanished (v + u × r_c + r_c' = 0 or points backwards).
    #[error("the cable tangent is degenerate at s = {s_mm:.3} mm (the cable would leave the channel backwards); try smaller tension steps from a lower tension, or a lower tension")]
    CableTangentDegenerate { s_mm: f64 },
    /// Axial stretch fell to zero or below: the rod would collapse.
    #[error("the rod collapses axially (v1 ≤ 0) at s = {s_mm:.3} mm: the load exceeds the axial rigidity EA; lower the tension")]
    RodCollapsed { s_mm: f64 },
    /// The shooting on gravity's base moment did not converge.
    #[error("the shooting on the base moment did not converge after {iterations} passes (residual {residual_n_mm:.3e} N·mm); try smaller tension steps, or the default collocation method")]
    ShootingNotConverged { iterations: u32, residual_n_mm: f64 },
    /// The clamp-compliance fixed point did not converge.
    #[error("the clamp rotation did not converge; try a stiffer clamp (clamp stiffness) or smaller tension steps")]
    ClampNotConverged,
    /// A non-finite number appeared in the state at `s_mm` (planar), or in
    /// the tip or a coefficient (spatial: `None`).
    #[error("{}", non_finite_sentence(*s_mm))]
    NonFinite { s_mm: Option<f64> },
    /// The cables' tension profiles with friction did not settle.
    #[error("the cable tension profile with friction did not converge; try smaller tension steps or a smaller friction coefficient")]
    FrictionNotConverged,
    /// The spatial cut equations at a point did not converge.
    #[error("the cut equations did not converge at s = {s_mm:.3} mm (tension too high for this routing, or a cable pulls straight through the axis); lower the tension or raise --steps-per-span")]
    CutEquationsNotConverged { s_mm: f64 },
    /// The spatial backends' iteration on gravity's moment did not converge.
    #[error("gravity's moment did not converge in {passes} passes (residual {residual_n_mm:.3e} N·mm); the rod may be too heavy for its stiffness")]
    GravityNotConverged { passes: u32, residual_n_mm: f64 },
    /// The equilibrium under the rod's own weight was not found, even by
    /// Newton's method with continuation in the weight.
    #[error("the equilibrium under the rod's weight did not converge (reached {reached_percent:.0} % of the weight); try smaller tension steps from a lower tension, more nodes per span, or a smaller gravity scale")]
    WeightNotConverged { reached_percent: f64 },
    /// The discretisation does not resolve the solution: the a posteriori
    /// error estimate of something reported is above its tolerance (or
    /// the tip lies farther from the clamp than the stretched rod is long).
    #[error(transparent)]
    Unresolved(Unresolved),
    /// A displacement-driven cable's displacement was not met.
    #[error(transparent)]
    DisplacementNotMet(actuation::DisplacementNotMet),
}

/// What a solve does not resolve, by how much, and what to raise
/// ([`SolveFailure::Unresolved`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the solver's discretisation does not resolve this shape: {what} is off by about {} {unit} (tolerance {} {unit}); {advice}",
    crate::io::fmt_sig(*estimate, 3),
    crate::io::fmt_sig(*tolerance, 3)
)]
pub struct Unresolved {
    /// What is off: "the tip position", "a_11", "a_bend_z[3]", ….
    pub what: String,
    /// Its estimated error.
    pub estimate: f64,
    /// The error accepted.
    pub tolerance: f64,
    /// The unit of both.
    pub unit: &'static str,
    /// Which setting to raise, and how.
    pub advice: String,
}

impl SolveFailure {
    /// Short machine-readable status, as stored in sweep rows.
    pub fn status(&self) -> &'static str {
        match self {
            SolveFailure::InvalidTension(_) => "invalid_tension",
            SolveFailure::CableDirectionNotConverged { .. } => "cable_direction_not_converged",
            SolveFailure::CableTangentDegenerate { .. } => "cable_tangent_degenerate",
            SolveFailure::RodCollapsed { .. } => "rod_collapsed",
            SolveFailure::ShootingNotConverged { .. } => "shooting_not_converged",
            SolveFailure::ClampNotConverged => "clamp_not_converged",
            SolveFailure::NonFinite { .. } => "non_finite",
            SolveFailure::FrictionNotConverged => "friction_not_converged",
            SolveFailure::WeightNotConverged { .. } => "weight_not_converged",
            SolveFailure::Unresolved(_) => "unresolved",
            SolveFailure::DisplacementNotMet(_) => "displacement_not_met",
            SolveFailure::CutEquationsNotConverged { .. } => "cut_equations_not_converged",
            SolveFailure::GravityNotConverged { .. } => "gravity_not_converged",
        }
    }
}

/// [`SolveFailure::NonFinite`]'s sentence: where the value appeared, if known.
fn non_finite_sentence(s_mm: Option<f64>) -> String {
    match s_mm {
        Some(s) => format!("a non-finite value appeared at s = {s:.3} mm; check the actuator parameters, or try smaller tension steps"),
        None => "the solve gave a non-finite tip or coefficient; check the rod's parameters (rigidities, length, density) for absurd values".into(),
    }
}

/// Most Newton iterations of material stiffening's cubic curvature law.
const STIFFENING_MAX_ITERATIONS: usize = 60;
/// Relative Newton step accepted as converged in the stiffening law.
const STIFFENING_TOLERANCE: f64 = 1e-15;
/// Most Newton iterations of the cable-direction equation at one point.
const CABLE_ANGLE_MAX_ITERATIONS: usize = 50;
/// Most fixed-point iterations of the compliant clamp's rotation (RK4).
const CLAMP_MAX_ITERATIONS: usize = 100;
/// Change of the clamp rotation accepted as converged, rad.
const CLAMP_TOLERANCE_RAD: f64 = 1e-14;

/// Collocation intervals per span used at least when material stiffening is on.
pub const MIN_NODES_WITH_STIFFENING: usize = 16;

/// Tip position error a solve may have, mm: its a posteriori estimate must
/// stay below this plus [`TIP_TOLERANCE_PER_LENGTH`] times the rod's length
/// ([`tip_tolerance_mm`]), or the solve is refused as unresolved.
pub const TIP_TOLERANCE_MM: f64 = 5e-4;
/// The part of the tip tolerance proportional to the rod's length.
pub const TIP_TOLERANCE_PER_LENGTH: f64 = 1e-5;

/// The tip position error accepted on a rod of `length_mm`, mm.
pub fn tip_tolerance_mm(length_mm: f64) -> f64 {
    TIP_TOLERANCE_MM + TIP_TOLERANCE_PER_LENGTH * length_mm
}

/// Most collocation intervals per span.
pub const MAX_NODES_PER_SPAN: usize = 64;
/// Most RK4 steps per span.
pub const MAX_STEPS_PER_SPAN: usize = 100_000;

/// Orders a_0 … a_{ESTIMATED_ORDERS−1} get an error estimate (above the
/// highest order any check allows).
const ESTIMATED_ORDERS: usize = 24;

/// Status string of a successful solve.
pub const STATUS_OK: &str = "ok";

/// Strains at one point.
#[derive(Debug, Clone, Copy, Default)]
struct Strains {
    v1: f64,
    v2: f64,
    u: f64,
}

/// Channel sample (y_c, dy_c/ds) at one stage point.
#[derive(Debug, Clone, Copy, Default)]
struct ChannelSample {
    y: f64,
    dy: f64,
}

/// Rigidities of the cross-section at one point.
#[derive(Debug, Clone, Copy)]
struct Section {
    /// Axial rigidity EA, N.
    ea_n: f64,
    /// Shear rigidity GA, N.
    ga_n: f64,
    /// Bending rigidity EI, N·mm².
    ei_n_mm2: f64,
    /// Radius r, mm (material stiffening's α r²).
    radius_mm: f64,
}

/// Bending moment at a cut, N·mm: the cable's moment τ y_c cos α about the
/// centreline (`tension` at the cut, channel offset `channel_y_mm`, cable
/// direction cos α) plus gravity's distal moment M.
#[inline]
fn bending_moment(tension: f64, channel_y_mm: f64, cos_alpha: f64, distal_moment: f64) -> f64 {
    tension * channel_y_mm * cos_alpha + distal_moment
}

/// A reusable solver for one actuator: set a routing, then solve tensions
/// (in rising order for the best warm starts). Holds all buffers it needs.
#[derive(Debug, Clone)]
pub struct Simulator {
    actuator: Rod,
    options: SolverOptions,
    weight_n_per_mm: f64,
    gravity_cos: f64,
    gravity_sin: f64,
    routing: Option<Routing>,
    /// Channel at the 2N+1 stage points of each span, span 0 then span 1.
    channel: Vec<ChannelSample>,
    /// Cable direction (cos α, sin α) at each stage point, kept as the Newton start.
    cable_dir: Vec<(f64, f64)>,
    /// The tension of the last successful solve, N (`None` after a failure).
    last_tension_n: Option<f64>,
    /// Cable–channel friction: slip sign and tension profile per point.
    friction: Friction,
    /// Creep: the hold and the load history per point.
    creep: Creep,
    /// Collocation state (`None` with the RK4 method).
    col: Option<Box<collocation::Colloc>>,
    /// RK4 state (also sized with collocation: it is small).
    rk4: rk4::Rk4,
    /// The non-uniform body (radius profile, segments); `None` for the
    /// uniform cylinder, solved on the fast path.
    body: Option<Body>,
    /// Index of the first point beyond the cable's anchor (the number of
    /// points when the cable is knotted at the tip): from there on the cut
    /// carries no cable load.
    cable_end: usize,
    /// The cable's path length in the straight, unloaded rod, mm (collocation).
    cable_rest_length_mm: f64,
    /// The cable's axial stiffness EA, N (`None`: inextensible), for its
    /// displacement's stretch.
    cable_ea_n: Option<f64>,
    /// The estimated error of the tangent angle along the last solve, rad
    /// (the coefficients' error estimate starts from it).
    theta_error_rad: f64,
    /// The estimated error of the largest coefficient asked for in the
    /// last [`Simulator::coefficients_into`], mm⁻¹, and its index.
    coefficient_error: (f64, usize),
    /// The routing as given (before the channel offset), for the probe.
    given_routing: Option<Routing>,
    /// The hold of the solves (the probe's are held alike).
    hold: Hold,
    /// A finer solver that settles an error estimate above the tolerance
    /// by a solve at twice the intervals ([`probe`]); made when first needed.
    probe: Option<Box<probe::Probe>>,
    /// Whether this solver is itself a probe (its solves are the
    /// reference: they are not estimated).
    is_probe: bool,
}

/// How a solve is held: the direction of the last tension change (friction)
/// and the dwell before the reading (creep).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Hold {
    /// Tension rising (load) or falling (unload).
    pub direction: LoadDirection,
    /// Seconds held at the tension before the reading.
    pub dwell_s: f64,
}

impl Hold {
    /// Refuses a dwell that is not a finite time ≥ 0 s.
    pub fn check(&self) -> Result<(), ParameterError> {
        if !(self.dwell_s.is_finite() && self.dwell_s >= 0.0) {
            return Err(ParameterError::OutOfRange { name: "dwell_s", value: self.dwell_s, expected: "a finite time ≥ 0 s" });
        }
        Ok(())
    }
}

impl Simulator {
    /// Creates a solver for `actuator`; fails on invalid parameters.
    pub fn new(rod: &Rod, options: &SolverOptions) -> Result<Self, SimulateError> {
        rod.validate().map_err(ParameterError::from)?;
        // The upper bound keeps a typo (2e9 steps) from exhausting memory.
        if options.planar_steps_per_span < 2 || options.planar_steps_per_span % 2 != 0 || options.planar_steps_per_span > MAX_STEPS_PER_SPAN {
            return Err(ParameterError::OutOfRange {
                name: "steps_per_span",
                value: options.planar_steps_per_span as f64,
                expected: "an even number from 2 to 100000",
            }.into());
        }
        if options.method == SolverMethod::Collocation && !(4..=MAX_NODES_PER_SPAN).contains(&options.nodes_per_span) {
            return Err(ParameterError::OutOfRange {
                name: "nodes_per_span",
                value: options.nodes_per_span as f64,
                expected: "between 4 and 64",
            }.into());
        }
        let n = options.planar_steps_per_span;
        // Material stiffening's curvature law u(m) has complex branch points
        // near the real axis (1 + 3 α r² u² = 0), which slows the spectral
        // convergence: 10 intervals leave 2e-6 rad there, 16 leave 1e-8.
        let m = if rod.effects.stiffening_alpha > 0.0 {
            options.nodes_per_span.max(MIN_NODES_WITH_STIFFENING)
        } else {
            options.nodes_per_span
        };
        let body = rod.body().map_err(ParameterError::from)?;
        Backend::check_planar(rod, options, Given::default())?;
        let spans = span_boundaries(rod, body.as_ref(), 0.5 * rod.cable_length_mm()).len() - 1;
        // Per-point buffers: RK4 stage points, or collocation nodes.
        let points = match options.method {
            SolverMethod::Rk4 => 2 * (2 * n + 1),
            SolverMethod::Collocation => spans * (m + 1),
        };
        let col = (options.method == SolverMethod::Collocation).then(|| Box::new(collocation::Colloc::new(m, spans)));
        let beta = rod.gravity.direction_rad;
        // A non-uniform body's weight is this factor times ∫ ρ r² (Body).
        let weight_n_per_mm = match &body {
            None => rod.weight_n_per_mm(),
            Some(_) if !rod.gravity.enabled => 0.0,
            Some(_) => rod.gravity.scale * 1e-6 * std::f64::consts::PI * rod.gravity.g_m_s2,
        };
        Ok(Self {
            actuator: rod.clone(),
            options: options.clone(),
            weight_n_per_mm,
            gravity_cos: beta.cos(),
            gravity_sin: beta.sin(),
            routing: None,
            channel: vec![ChannelSample::default(); points],
            cable_dir: vec![(1.0, 0.0); points],
            last_tension_n: None,
            friction: Friction::new(rod.effects.friction_mu, rod.effects.load_direction.slip_sign(), points),
            creep: Creep::new(&rod.effects, rod.ei_n_mm2, points),
            col,
            rk4: rk4::Rk4::new(n),
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
        })
        .and_then(|mut sim: Simulator| {
            // Outside a protocol every solve is held like this from a virgin rod.
            let hold = Hold { direction: rod.effects.load_direction, dwell_s: rod.effects.creep_hold_s };
            hold.check()?;
            sim.apply_hold(hold);
            Ok(sim)
        })
    }

    /// The actuator this solver was built for.
    pub fn actuator(&self) -> &Rod {
        &self.actuator
    }

    /// Validates `y_mm` against the actuator and sets it as the routing.
    pub fn set_routing_mm(&mut self, y_mm: &[f64]) -> Result<(), crate::model::routing::RoutingError> {
        let routing = Routing::for_actuator(y_mm, &self.actuator)?;
        self.set_routing(&routing);
        Ok(())
    }

    /// Sets the routing (precomputing the channel at every stage point) and
    /// forgets the warm start. The routing must span the cable's length
    /// (build it with [`Routing::for_actuator`]).
    pub fn set_routing(&mut self, routing: &Routing) {
        debug_assert!((routing.length_mm() - self.actuator.cable_length_mm()).abs() <= 1e-9 * self.actuator.length_mm);
        let delta = self.actuator.effects.channel_offset_mm;
        let built = if delta != 0.0 { routing.shifted(delta) } else { routing.clone() };
        if self.col.is_some() {
            self.colloc_set_routing(&built);
        } else {
            self.rk4_set_routing(&built);
        }
        self.routing = Some(built);
        self.given_routing = Some(routing.clone());
        if let Some(p) = self.probe.as_mut() {
            p.stale();
        }
        self.reset_warm_start();
        self.reset_history();
        self.last_tension_n = None;
    }

    /// Sets the cable's axial stiffness EA, N (`None`: inextensible), which
    /// the pose's displacement adds the cable's stretch with (collocation;
    /// RK4 reports no displacement).
    pub fn set_cable_stiffness(&mut self, cable_ea_n: Option<f64>) {
        self.cable_ea_n = cable_ea_n;
    }

    /// Forgets the warm start (the next solve starts cold). The creep
    /// history is physical state and is kept.
    pub fn reset_warm_start(&mut self) {
        self.rk4.forget();
        if let Some(col) = self.col.as_mut() {
            col.forget();
        }
        self.cable_dir.iter_mut().for_each(|d| *d = (1.0, 0.0));
        self.friction.forget();
    }

    /// Forgets the load history (creep): the material is as new, unloaded.
    pub fn reset_history(&mut self) {
        self.creep.forget();
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
        self.creep.follow_protocol();
        self.apply_hold(hold);
        Ok(())
    }

    /// Hands a checked `hold` to friction (slip sign) and creep (dwell).
    fn apply_hold(&mut self, hold: Hold) {
        self.friction.set_slip_sign(hold.direction.slip_sign());
        self.creep.set_dwell(hold.dwell_s);
        self.hold = hold;
        if let Some(p) = self.probe.as_mut() {
            p.stale();
        }
    }

    /// The section's rigidities at reference arc length `s` (mm): the
    /// actuator's, or the non-uniform body's ([`Body::section_at`]), with
    /// the stiffness gradient.
    #[inline]
    fn section_at(&self, s: f64) -> Section {
        self.section_at_side(s, false)
    }

    /// [`Simulator::section_at`], where a section that jumps at `s` (a
    /// segment's end) is taken from the left with `left` (the last node of
    /// a span), from the right otherwise.
    #[inline]
    fn section_at_side(&self, s: f64, left: bool) -> Section {
        let a = &self.actuator;
        let mut section = match &self.body {
            None => Section { ea_n: a.ea_n, ga_n: a.ga_n, ei_n_mm2: a.ei_n_mm2, radius_mm: a.radius_mm },
            Some(b) => {
                let x = b.section_at_side(s, left);
                Section { ea_n: x.ea_n, ga_n: x.ga_n, ei_n_mm2: x.ei_n_mm2, radius_mm: x.radius_mm }
            }
        };
        let beta = a.effects.stiffness_gradient_beta;
        if beta != 0.0 {
            section.ei_n_mm2 *= (beta * (s / a.length_mm - 0.5)).exp();
        }
        section
    }

    /// The rod's weight beyond the cut at `s` (mm), N: w·(L − s) for the
    /// uniform rod, the closed-form ∫_s^L w dσ for a non-uniform body.
    #[inline]
    fn distal_weight_n(&self, s: f64) -> f64 {
        match &self.body {
            None => self.weight_n_per_mm * (self.actuator.length_mm - s),
            Some(b) => self.weight_n_per_mm * b.distal_density_area(s),
        }
    }

    /// The cable tension at point `i` for base tension `tension`: friction's
    /// profile, and none beyond the cable's anchor.
    #[inline]
    fn tension_at(&self, i: usize, tension: f64) -> f64 {
        if i >= self.cable_end {
            return 0.0;
        }
        tension * self.friction.ratio(i)
    }

    /// Curvature u from the bending moment `m` (N·mm) on `section` and du/dm.
    /// Linear (m = EI u) unless material stiffening makes it
    /// m = EI u (1 + α (r u)²); a rod cured bent adds its rest curvature u*
    /// (m = EI (u − u*), [`Rod::rest_curvature_per_mm`]).
    #[inline]
    fn bending_curvature(&self, m: f64, section: &Section) -> (f64, f64) {
        let (u, du_dm) = self.elastic_curvature(m, section.ei_n_mm2, section.radius_mm);
        (u + self.actuator.rest_curvature_per_mm, du_dm)
    }

    /// The elastic part of [`Simulator::bending_curvature`] with rigidity
    /// `ei` and radius `radius_mm`.
    #[inline]
    fn elastic_curvature(&self, m: f64, ei: f64, radius_mm: f64) -> (f64, f64) {
        let alpha = self.actuator.effects.stiffening_alpha;
        if alpha == 0.0 {
            return (m / ei, 1.0 / ei);
        }
        // Monotone cubic EI (u + c u³) = m, c = α r²: Newton from the linear guess.
        let c = alpha * radius_mm.powi(2);
        let mut u = m / ei;
        for _ in 0..STIFFENING_MAX_ITERATIONS {
            let f = ei * (u + c * u * u * u) - m;
            let df = ei * (1.0 + 3.0 * c * u * u);
            let du = f / df;
            u -= du;
            if du.abs() <= STIFFENING_TOLERANCE * (1.0 + u.abs()) {
                break;
            }
        }
        (u, 1.0 / (ei * (1.0 + 3.0 * c * u * u)))
    }

    /// Solves the cut equations at one point (arc length `s`, cross-section
    /// `section`) for the cable angle α and the
    /// strains, starting Newton from the direction `dir0` = (cos α, sin α);
    /// `(sp, cp)` = sin, cos of φ; `tension` is the cable tension at the cut
    /// and `creep_offset` the creep's held curvature f E q₀ (1/mm). Returns
    /// the strains and (cos α, sin α).
    ///
    /// Newton converges quadratically, so once a step is below
    /// `angle_tolerance_rad` the remaining error is of the order of its
    /// square: the strains are then corrected to first order in that step
    /// instead of being re-evaluated (one sin/cos per iteration).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn strains_at(
        &self,
        s: f64,
        section: &Section,
        ch: ChannelSample,
        (sp, cp): (f64, f64),
        moment: f64,
        tension: f64,
        dir0: (f64, f64),
        creep_offset: f64,
    ) -> Result<(Strains, (f64, f64)), SolveFailure> {
        let (ea, ga) = (section.ea_n, section.ga_n);
        let creep_gain = self.creep.gain(section.ei_n_mm2);
        // Weight beyond the cut, in the body frame: Rᵀ W.
        let wl = self.distal_weight_n(s);
        let w1 = wl * (cp * self.gravity_cos + sp * self.gravity_sin);
        let w2 = wl * (cp * self.gravity_sin - sp * self.gravity_cos);
        let (mut ca, mut sa) = dir0;
        for _ in 0..CABLE_ANGLE_MAX_ITERATIONS {
            let v1 = 1.0 + (w1 - tension * ca) / ea;
            let v2 = (w2 - tension * sa) / ga;
            let m = bending_moment(tension, ch.y, ca, moment);
            let (u_el, du_dm_el) = self.bending_curvature(m, section);
            let u = u_el + creep_gain * m + creep_offset;
            let du_dm = du_dm_el + creep_gain;
            let p = v1 - u * ch.y;
            let q = v2 + ch.dy;
            let g = p * sa - q * ca;
            // Derivatives of v1, v2, u with respect to α.
            let dv1 = tension * sa / ea;
            let dv2 = -tension * ca / ga;
            let du = -tension * ch.y * sa * du_dm;
            let dg = (dv1 - du * ch.y) * sa + p * ca - dv2 * ca + q * sa;
            let step = g / dg;
            if !step.is_finite() {
                return Err(SolveFailure::CableTangentDegenerate { s_mm: s });
            }
            let (ca_next, sa_next) = rotate((ca, sa), -step);
            if step.abs() <= self.options.angle_tolerance_rad {
                let e = Strains { v1: v1 - dv1 * step, v2: v2 - dv2 * step, u: u - du * step };
                // α and α + π both solve g = 0; the cable runs along +t_c.
                let along = p * ca + q * sa;
                if along <= 1e-12 {
                    return Err(SolveFailure::CableTangentDegenerate { s_mm: s });
                }
                if e.v1 <= 0.0 {
                    return Err(SolveFailure::RodCollapsed { s_mm: s });
                }
                return Ok((e, (ca_next, sa_next)));
            }
            (ca, sa) = (ca_next, sa_next);
        }
        Err(SolveFailure::CableDirectionNotConverged { s_mm: s })
    }

    /// Solves the statics for `tension_n` (N) on the current routing,
    /// warm-started from the previous solves of this routing.
    ///
    /// # Panics
    /// If no routing was set.
    pub fn solve(&mut self, tension_n: f64) -> Result<TipPose, SolveFailure> {
        assert!(self.routing.is_some(), "Simulator::solve called before set_routing");
        if !(tension_n.is_finite() && tension_n >= 0.0) {
            return Err(SolveFailure::InvalidTension(tension_n));
        }
        self.creep.begin_solve();
        if let Some(p) = self.probe.as_mut() {
            p.forget_solve();
        }
        let result = self.solve_inner(tension_n);
        match &result {
            Ok(pose) => self.last_tension_n = Some(pose.tension_n()),
            Err(_) => {
                self.last_tension_n = None;
                self.reset_warm_start();
            }
        }
        result
    }

    fn solve_inner(&mut self, tension: f64) -> Result<TipPose, SolveFailure> {
        // The error estimate comes before the creep history moves on, so
        // that a refused solve leaves the history as it was.
        let (pose, (theta_error, tip_error)) = if self.col.is_some() {
            let passes = self.colloc_solve(tension)?;
            (self.colloc_pose(tension, passes), self.colloc_error_estimate())
        } else {
            let passes = self.rk4_solve(tension)?;
            (self.rk4_pose(tension, passes), self.rk4_error_estimate(tension)?)
        };
        self.theta_error_rad = self.check_resolved(&pose, theta_error, tip_error)?;
        self.creep.end_solve();
        Ok(pose)
    }

    /// Refuses a pose with a non-finite number, an estimated tip error
    /// `tip_error_mm` above [`tip_tolerance_mm`] (unless a probe at twice
    /// the intervals agrees to within it), or a tip farther from the
    /// clamp than the stretched rod is long (which no curve can do).
    /// Returns the estimated error of the tangent angle, rad.
    fn check_resolved(&mut self, pose: &TipPose, theta_error_rad: f64, tip_error_mm: f64) -> Result<f64, SolveFailure> {
        let scalars = [pose.tip_x_mm, pose.tip_y_mm, pose.tip_angle_rad, pose.tip_frame_angle_rad, pose.base_angle_rad, pose.length_mm];
        if !scalars.iter().all(|v| v.is_finite()) {
            return Err(SolveFailure::NonFinite { s_mm: Some(self.actuator.length_mm) });
        }
        if self.is_probe {
            return Ok(0.0);
        }
        let tolerance = tip_tolerance_mm(self.actuator.length_mm);
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
        match self.probe_pose(pose.tension_n()) {
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
        SolveFailure::Unresolved(Unresolved { what, estimate, tolerance, unit, advice: resolution_advice(&self.options, self.resolution()) })
    }

    /// The resolution in use: collocation intervals per span (at least
    /// [`MIN_NODES_WITH_STIFFENING`] with stiffening), or RK4 steps per span.
    pub fn resolution(&self) -> usize {
        match &self.col {
            Some(c) => c.intervals(),
            None => self.options.planar_steps_per_span,
        }
    }

    /// Legendre curvature coefficients a_0 … a_{n−1} (n = `out.len()`) of the
    /// last successful solve in `basis`, by the exact definition
    /// (model-notes §4), computed from the solver's nodes without allocating.
    ///
    /// # Panics
    /// If the last solve failed or none was made.
    ///
    /// Also estimates their error ([`Simulator::coefficient_error_per_mm`]);
    /// [`Simulator::coefficients_checked`] refuses coefficients the
    /// discretisation does not resolve.
    pub fn coefficients_into(&mut self, basis: LengthBasis, out: &mut [f64]) {
        assert!(self.last_tension_n.is_some(), "coefficients_into needs a successful solve");
        let estimate = if self.col.is_some() { self.colloc_coefficients(basis, out) } else { self.rk4_coefficients(basis, out) };
        self.coefficient_error = if estimate.0 <= resolution::ORDER_TOLERANCE_PER_MM || self.is_probe {
            estimate
        } else {
            // As for the tip: a solve at twice the intervals tells.
            self.probe_coefficient_difference(basis, out).unwrap_or(estimate)
        };
    }

    /// The estimated error of the coefficients of the last
    /// [`Simulator::coefficients_into`]: the largest over a_0 … a_n, mm⁻¹,
    /// and the index k of the a_k it belongs to.
    pub fn coefficient_error_per_mm(&self) -> (f64, usize) {
        self.coefficient_error
    }

    /// [`Simulator::coefficients_into`], refusing coefficients whose
    /// estimated error is above [`resolution::ORDER_TOLERANCE_PER_MM`]
    /// or that are not finite.
    pub fn coefficients_checked(&mut self, basis: LengthBasis, out: &mut [f64]) -> Result<(), SolveFailure> {
        self.coefficients_into(basis, out);
        if !out.iter().all(|a| a.is_finite()) {
            return Err(SolveFailure::NonFinite { s_mm: Some(self.actuator.length_mm) });
        }
        let (error, k) = self.coefficient_error;
        let tolerance = resolution::ORDER_TOLERANCE_PER_MM;
        if !(error <= tolerance) {
            return Err(self.unresolved(format!("a_{k}"), error, tolerance, "mm⁻¹"));
        }
        Ok(())
    }

    /// The centreline of the last successful solve, clamp to tip.
    pub fn centreline(&self) -> Vec<CentrelinePoint> {
        assert!(self.last_tension_n.is_some(), "centreline needs a successful solve");
        if self.col.is_some() {
            return self.colloc_centreline();
        }
        self.rk4_centreline()
    }
}

/// The largest of the per-order coefficient `errors` (one that is not a
/// number counts as largest) and its order, converted like the
/// coefficients from the deformed basis into `basis`.
fn largest_error(errors: impl Iterator<Item = f64>, basis: LengthBasis, deformed_length_mm: f64, rest_length_mm: f64) -> (f64, usize) {
    let mut worst = (0.0f64, 0usize);
    for (n, error) in errors.enumerate() {
        if !(error <= worst.0) {
            worst = (error, n);
        }
    }
    let mut error = [worst.0];
    basis.convert_from_deformed(&mut error, deformed_length_mm, rest_length_mm);
    (error[0], worst.1)
}

/// What to raise when a solve at `resolution` (intervals or steps per
/// span) with `options` is not resolved.
fn resolution_advice(options: &SolverOptions, resolution: usize) -> String {
    match options.method {
        SolverMethod::Collocation if resolution < MAX_NODES_PER_SPAN => format!(
            "raise --nodes-per-span (now {resolution}, at most {MAX_NODES_PER_SPAN}; sweep spec: [solver] nodes_per_span), e.g. --nodes-per-span {}",
            (2 * resolution).min(MAX_NODES_PER_SPAN)
        ),
        SolverMethod::Collocation => format!(
            "{MAX_NODES_PER_SPAN} intervals per span, the most, do not resolve it: use --method rk4 with more --steps-per-span \
             (sweep spec: [solver] method = \"rk4\", steps_per_span), or a lower tension"
        ),
        SolverMethod::Rk4 => format!(
            "raise --steps-per-span (now {resolution}, at most {MAX_STEPS_PER_SPAN}; sweep spec: [solver] steps_per_span), e.g. --steps-per-span {}",
            (4 * resolution).min(MAX_STEPS_PER_SPAN)
        ),
    }
}

/// The collocation's span boundaries from the clamp to the tip: the
/// routing's knot `knot_mm`, the cable's anchor and the body's breakpoints
/// (so that every span's integrands are smooth); [0, knot, L] for the
/// uniform rod.
fn span_boundaries(a: &Rod, body: Option<&Body>, knot_mm: f64) -> Vec<f64> {
    let length = a.length_mm;
    let mut cuts = vec![0.0, knot_mm, a.cable_length_mm(), length];
    if let Some(b) = body {
        cuts.extend(b.breakpoints_mm());
    }
    merge_sorted(cuts, length)
}

/// Rotates the unit vector (cos a, sin a) by `delta` rad. Small angles (the
/// usual case: Newton corrections, RK4 stage offsets) use a Taylor series
/// accurate to rounding, which is several times cheaper than sin/cos.
#[inline]
fn rotate((c, s): (f64, f64), delta: f64) -> (f64, f64) {
    let (sd, cd) = if delta.abs() < 0.125 {
        let d2 = delta * delta;
        // Errors below δ¹⁰/10! and δ¹¹/11!: < 1e-16 for |δ| < 1/8.
        let cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0 * (1.0 - d2 / 90.0))));
        let sd = delta * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0 * (1.0 - d2 / 72.0 * (1.0 - d2 / 110.0)))));
        (sd, cd)
    } else {
        delta.sin_cos()
    };
    (c * cd - s * sd, s * cd + c * sd)
}

/// The planar backends (collocation, or the RK4 reference by
/// `options.method`) of one cable in the plane.
impl Solver for Simulator {
    type Error = SolveFailure;
    fn backend(&self) -> Backend {
        Backend::planar(self.options.method)
    }
    fn solve_tensions(&mut self, tensions_n: &[f64]) -> Result<TipPose, SolveFailure> {
        self.solve(tensions_n[0])
    }
    fn hold_next(&mut self, hold: Hold) {
        self.creep.follow_protocol();
        self.apply_hold(hold);
    }
    fn centreline(&self) -> Vec<CentrelinePoint> {
        Simulator::centreline(self)
    }
    /// Bending about body z only: twist and bending about y are zero in the plane.
    fn coefficients(&mut self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], SolveFailure> {
        let mut a = vec![0.0; order + 1];
        self.coefficients_checked(basis, &mut a)?;
        Ok([vec![0.0; order + 1], vec![0.0; order + 1], a])
    }
}

impl From<actuation::DisplacementNotMet> for SolveFailure {
    fn from(e: actuation::DisplacementNotMet) -> Self {
        SolveFailure::DisplacementNotMet(e)
    }
}

#[cfg(test)]
mod tests;
