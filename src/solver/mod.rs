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
//! fixed-point sweeps and Newton's method), or with the previous classical
//! RK4 ([`SolverMethod::Rk4`], kept as the reference, in `rk4`).
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

pub use backend::{Backend, Given, Support, Unsupported};
pub use error::SimulateError;
pub use result::{CableAtNode, CentrelinePoint, PerCable, Simulation, TipFrame, TipPose};
pub use simulate::{
    check_ladder_tension, planar_problem, simulate, simulate_actuator, simulate_held, simulate_spatial, MAX_AUTO_SPATIAL_STEPS_PER_SPAN,
    MAX_AUTO_STEPS_PER_SPAN, MAX_LADDER_TENSION_N,
};
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
    /// A non-finite number appeared in the state.
    #[error("a non-finite value appeared at s = {s_mm:.3} mm; check the actuator parameters, or try smaller tension steps")]
    NonFinite { s_mm: f64 },
    /// The friction tension profile did not settle.
    #[error("the cable tension profile with friction did not converge; try smaller tension steps or a smaller friction coefficient")]
    FrictionNotConverged,
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

/// What a solve does not resolve, by how much, and what to raise (the
/// planar and the 3-D solvers' [`SolveFailure::Unresolved`] and
/// [`super::spatial::SpatialFailure::Unresolved`]).
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
        }
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

/// How the centreline is integrated along each knot span of the routing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum SolverMethod {
    /// Spectral collocation on Chebyshev–Lobatto nodes per span (the
    /// default): strains at `nodes_per_span + 1` points per span, integrals
    /// by the exact integral of the interpolating polynomial; gravity's
    /// distal moment by fixed-point sweeps (no shooting), with Newton's
    /// method and continuation in the weight as the fallback for heavy rods.
    #[default]
    Collocation,
    /// The previous method, kept as the reference: classical RK4 with
    /// `steps_per_span` steps per span and secant shooting on gravity's
    /// base moment.
    Rk4,
}

/// Numerical settings of the solver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverOptions {
    /// Integration method.
    pub method: SolverMethod,
    /// Collocation: Chebyshev–Lobatto intervals per knot span (4–64); the
    /// span's integrands are smooth, so the error falls geometrically with it.
    /// With material stiffening at least [`MIN_NODES_WITH_STIFFENING`] are used.
    pub nodes_per_span: usize,
    /// RK4 steps on each of the routing's two knot spans (even, ≥ 2). With
    /// collocation it sets the centreline's resolution: 2·steps_per_span + 1
    /// evenly spaced points.
    pub steps_per_span: usize,
    /// Last Newton step accepted for the cable angle α, rad (the error left
    /// is of the order of its square).
    pub angle_tolerance_rad: f64,
    /// Convergence of gravity's moment, N·mm: RK4, the residual at the tip;
    /// collocation, the largest change at a node between the last sweeps.
    /// 1e-8 N·mm leaves a curvature error of about 1e-10 /mm (δm/EI): far
    /// below the solver's discretisation error.
    pub moment_tolerance_n_mm: f64,
    /// RK4: most shooting passes before giving up. (Collocation has no
    /// shooting: its sweeps hand over to Newton's method when they stall.)
    pub max_shooting_passes: u32,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            method: SolverMethod::Collocation,
            nodes_per_span: 10,
            steps_per_span: 24,
            angle_tolerance_rad: 1e-7,
            moment_tolerance_n_mm: 1e-8,
            max_shooting_passes: 30,
        }
    }
}

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

impl Simulator {
    /// Creates a solver for `actuator`; fails on invalid parameters.
    pub fn new(actuator: &Rod, options: &SolverOptions) -> Result<Self, SimulateError> {
        actuator.validate().map_err(ParameterError::from)?;
        // The upper bound keeps a typo (2e9 steps) from exhausting memory.
        if options.steps_per_span < 2 || options.steps_per_span % 2 != 0 || options.steps_per_span > MAX_STEPS_PER_SPAN {
            return Err(ParameterError::OutOfRange {
                name: "steps_per_span",
                value: options.steps_per_span as f64,
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
        let n = options.steps_per_span;
        // Material stiffening's curvature law u(m) has complex branch points
        // near the real axis (1 + 3 α r² u² = 0), which slows the spectral
        // convergence: 10 intervals leave 2e-6 rad there, 16 leave 1e-8.
        let m = if actuator.effects.stiffening_alpha > 0.0 {
            options.nodes_per_span.max(MIN_NODES_WITH_STIFFENING)
        } else {
            options.nodes_per_span
        };
        let body = actuator.body().map_err(ParameterError::from)?;
        Backend::check_planar(actuator, options, Given::default())?;
        let spans = span_boundaries(actuator, body.as_ref(), 0.5 * actuator.cable_length_mm()).len() - 1;
        // Per-point buffers: RK4 stage points, or collocation nodes.
        let points = match options.method {
            SolverMethod::Rk4 => 2 * (2 * n + 1),
            SolverMethod::Collocation => spans * (m + 1),
        };
        let col = (options.method == SolverMethod::Collocation).then(|| Box::new(collocation::Colloc::new(m, spans)));
        let beta = actuator.gravity.direction_rad;
        // A non-uniform body's weight is this factor times ∫ ρ r² (Body).
        let weight_n_per_mm = match &body {
            None => actuator.weight_n_per_mm(),
            Some(_) if !actuator.gravity.enabled => 0.0,
            Some(_) => actuator.gravity.scale * 1e-6 * std::f64::consts::PI * actuator.gravity.g_m_s2,
        };
        Ok(Self {
            actuator: actuator.clone(),
            options: options.clone(),
            weight_n_per_mm,
            gravity_cos: beta.cos(),
            gravity_sin: beta.sin(),
            routing: None,
            channel: vec![ChannelSample::default(); points],
            cable_dir: vec![(1.0, 0.0); points],
            last_tension_n: None,
            friction: Friction::new(actuator.effects.friction_mu, actuator.effects.load_direction.slip_sign(), points),
            creep: Creep::new(&actuator.effects, actuator.ei_n_mm2, points),
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
            let hold = Hold { direction: actuator.effects.load_direction, dwell_s: actuator.effects.creep_hold_s };
            sim.apply_hold(hold)?;
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
        self.creep.follow_protocol();
        self.apply_hold(hold)
    }

    /// Checks `hold` and hands it to friction (slip sign) and creep (dwell).
    fn apply_hold(&mut self, hold: Hold) -> Result<(), ParameterError> {
        if !(hold.dwell_s.is_finite() && hold.dwell_s >= 0.0) {
            return Err(ParameterError::OutOfRange { name: "dwell_s", value: hold.dwell_s, expected: "a finite time ≥ 0 s" });
        }
        self.friction.set_slip_sign(hold.direction.slip_sign());
        self.creep.set_dwell(hold.dwell_s);
        self.hold = hold;
        if let Some(p) = self.probe.as_mut() {
            p.stale();
        }
        Ok(())
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
            return Err(SolveFailure::NonFinite { s_mm: self.actuator.length_mm });
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
            None => self.options.steps_per_span,
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
            return Err(SolveFailure::NonFinite { s_mm: self.actuator.length_mm });
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

/// A random rod far from the thesis's (length, radius, rigidities, with or
/// without gravity), a routing within ±0.8 r and a tension bending it by
/// about 0.3–3 rad: the error estimates' test cases.
#[cfg(test)]
fn random_case(rng: &mut crate::calibrate::rng::Rng) -> (Rod, Vec<f64>, f64) {
    let mut span = |lo: f64, hi: f64| lo * (hi / lo).powf(rng.uniform());
    let mut a = Rod::default();
    (a.length_mm, a.radius_mm, a.ei_n_mm2, a.ea_n, a.ga_n) = (span(30.0, 300.0), span(2.0, 8.0), span(20.0, 400.0), span(15.0, 60.0), span(1.0, 5.0));
    let tension = span(0.3, 3.0) * a.ei_n_mm2 / a.length_mm / a.radius_mm;
    a.gravity.enabled = rng.uniform() < 0.5;
    let y = (0..5).map(|_| (2.0 * rng.uniform() - 1.0) * 0.8 * a.radius_mm).collect();
    (a, y, tension)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thesis rod without gravity on a straight routing y_i = `d_mm`: the
    /// cable direction is α = 0 everywhere, so the effects have closed forms.
    fn straight(effects: impl FnOnce(&mut Rod), d_mm: f64) -> Simulator {
        let mut a = Rod::default();
        a.gravity.enabled = false;
        effects(&mut a);
        let mut sim = Simulator::new(&a, &SolverOptions::default()).unwrap();
        sim.set_routing_mm(&[d_mm; 5]).unwrap();
        sim
    }

    fn ladder(sim: &mut Simulator, tension: f64) -> TipPose {
        let mut pose = None;
        for k in 1..=8 {
            pose = Some(sim.solve(tension * k as f64 / 8.0).unwrap());
        }
        pose.unwrap()
    }

    /// Every effect, collocation against the previous RK4 method (at 192
    /// steps per span, well converged), on a curved routing with gravity:
    /// a tension ladder up and down, with creep holds.
    #[test]
    fn collocation_agrees_with_rk4_for_every_effect() {
        type Setup = fn(&mut Rod);
        let cases: [(&str, Setup); 9] = [
            ("thesis", |_| {}),
            ("gravity scale", |a| a.gravity.scale = 2.5),
            ("gravity direction", |a| a.gravity.direction_rad = 0.7),
            ("stiffening", |a| a.effects.stiffening_alpha = 2.0),
            ("clamp", |a| a.effects.clamp_stiffness_n_mm_per_rad = Some(40.0)),
            ("offset", |a| a.effects.channel_offset_mm = 0.5),
            ("friction", |a| a.effects.friction_mu = 0.2),
            ("creep", |a| {
                a.effects.creep_fraction = 0.3;
                a.effects.creep_time_s = 10.0;
            }),
            ("no gravity", |a| a.gravity.enabled = false),
        ];
        let rk4 = SolverOptions { method: SolverMethod::Rk4, steps_per_span: 192, ..SolverOptions::default() };
        for (name, setup) in cases {
            let mut a = Rod::default();
            setup(&mut a);
            let mut sims = [Simulator::new(&a, &SolverOptions::default()).unwrap(), Simulator::new(&a, &rk4).unwrap()];
            for route in [[1.0, -2.0, 4.0, 4.0, -4.0], [-3.0, 1.0, -1.0, 0.0, -2.0]] {
                let mut poses = [Vec::new(), Vec::new()];
                for (sim, out) in sims.iter_mut().zip(&mut poses) {
                    sim.set_routing_mm(&route).unwrap();
                    for k in 1..=8 {
                        out.push(sim.solve(0.25 * k as f64).unwrap());
                    }
                    sim.set_hold(Hold { direction: LoadDirection::Unload, dwell_s: 5.0 }).unwrap();
                    for k in (0..8).rev() {
                        out.push(sim.solve(0.25 * k as f64).unwrap());
                    }
                    let mut coefficients = [0.0; 4];
                    sim.coefficients_into(LengthBasis::Rest, &mut coefficients);
                    out.push(TipPose { tip_x_mm: coefficients[1], tip_y_mm: coefficients[3], ..out[out.len() - 1] });
                }
                for (p, q) in poses[0].iter().zip(&poses[1]) {
                    let tip = (p.tip_x_mm - q.tip_x_mm).hypot(p.tip_y_mm - q.tip_y_mm);
                    let angle = (p.tip_angle_rad - q.tip_angle_rad).abs().max((p.base_angle_rad - q.base_angle_rad).abs());
                    // With friction τ(s) has kinks where the cable turns back
                    // (|ψ'|), so both methods converge only algebraically there:
                    // RK4 at 24 steps is itself 1.3e-4 mm off at 2 N.
                    let (tip_tol, angle_tol) = if name == "friction" { (5e-4, 3e-5) } else { (2e-5, 1e-6) };
                    assert!(tip < tip_tol && angle < angle_tol, "{name} {route:?} at {} N: tip {tip} mm, angle {angle} rad", p.tension_n());
                }
            }
        }
    }

    #[test]
    fn simulate_reports_its_own_errors_with_the_lower_layers_as_sources() {
        let (a, options) = (Rod::default(), SolverOptions::default());
        let routing = Routing::new(&[1.0, -2.0, 4.0, 4.0, -4.0], a.length_mm, a.radius_mm).unwrap();
        let err = simulate(&a, &options, &routing, -1.0, 3, LengthBasis::Rest).unwrap_err();
        assert!(matches!(err, SimulateError::Solve(SolveFailure::InvalidTension(t)) if t == -1.0), "{err:?}");
        assert_eq!(err.to_string(), SolveFailure::InvalidTension(-1.0).to_string());
        let hold = Hold { direction: LoadDirection::Load, dwell_s: f64::NAN };
        let err = simulate_held(&a, &options, &routing, 1.0, 3, LengthBasis::Rest, hold).unwrap_err();
        assert!(matches!(err, SimulateError::Parameter(ParameterError::OutOfRange { name: "dwell_s", .. })), "{err:?}");
    }

    #[test]
    fn bending_moment_adds_the_cable_moment_to_the_distal_moment() {
        assert_eq!(bending_moment(2.0, 3.0, 0.5, 0.25), 2.0 * 3.0 * 0.5 + 0.25);
    }

    #[test]
    fn friction_matches_the_capstan_closed_form() {
        // ψ' = u = τ(s) d / EI and dτ/ds = −η μ τ ψ' (slip sign η) give
        // τ(s) = τ0 / (1 + η μ τ0 d s / EI), φ(L) = η ln(1 + η μ τ0 d L / EI) / μ.
        let (mu, tau, d) = (0.1, 2.0, 4.0);
        let a = Rod::default();
        for direction in [LoadDirection::Load, LoadDirection::Unload] {
            let slip = direction.slip_sign();
            let mut sim = straight(|a| a.effects.friction_mu = mu, d);
            sim.set_hold(Hold { direction, dwell_s: 0.0 }).unwrap();
            let pose = ladder(&mut sim, tau);
            let expected = slip * (1.0 + slip * mu * tau * d * a.length_mm / a.ei_n_mm2).ln() / mu;
            assert!((pose.tip_angle_rad - expected).abs() < 2e-4, "{direction:?}: {} vs {expected}", pose.tip_angle_rad);
            let line = sim.centreline();
            let tip = line.last().unwrap();
            let tip_tension = tau / (1.0 + slip * mu * tau * d * a.length_mm / a.ei_n_mm2);
            assert!((tip.cables[0].tension_n - tip_tension).abs() < 1e-4, "{} vs {tip_tension}", tip.cables[0].tension_n);
        }
        // Without friction the profile is flat and load = unload.
        let mut sim = straight(|_| {}, d);
        let pose = ladder(&mut sim, tau);
        assert!((pose.tip_angle_rad - tau * d * a.length_mm / a.ei_n_mm2).abs() < 1e-6);
    }

    #[test]
    fn friction_makes_a_hysteresis_loop_on_a_curved_routing_with_gravity() {
        let mut a = Rod::default();
        a.effects.friction_mu = 0.2;
        let mut sim = Simulator::new(&a, &SolverOptions::default()).unwrap();
        sim.set_routing_mm(&[1.0, -2.0, 4.0, 4.0, -4.0]).unwrap();
        let load = ladder(&mut sim, 1.5);
        sim.set_hold(Hold { direction: LoadDirection::Unload, dwell_s: 0.0 }).unwrap();
        let unload = sim.solve(1.5).unwrap();
        // Unloading, the distal tension is higher: the rod bends further.
        assert!((unload.tip_y_mm - load.tip_y_mm).abs() > 0.5, "{load:?} {unload:?}");
        let line = sim.centreline();
        assert!(line.last().unwrap().cables[0].tension_n > 1.5);
    }

    #[test]
    fn creep_follows_the_standard_linear_solid() {
        let (f, t_s, tau, d) = (0.3, 10.0, 1.0, 3.0);
        let a = Rod::default();
        let mut sim = straight(
            |a| {
                a.effects.creep_fraction = f;
                a.effects.creep_time_s = t_s;
            },
            d,
        );
        let (d1, d2) = (7.0, 4.0);
        let m = tau * d;
        let ei = a.ei_n_mm2;
        // Load step held d1 from a virgin rod (the ladder below holds 0 s).
        for k in 1..8 {
            sim.solve(tau * k as f64 / 8.0).unwrap();
        }
        sim.set_hold(Hold { direction: LoadDirection::Load, dwell_s: d1 }).unwrap();
        let held = sim.solve(tau).unwrap();
        let e1 = (-(1.0 - f) * d1 / t_s).exp();
        let u1 = m / ei * (1.0 + f * (1.0 - e1) / (1.0 - f));
        assert!((held.tip_angle_rad - u1 * a.length_mm).abs() < 1e-9, "{} vs {}", held.tip_angle_rad, u1 * a.length_mm);
        // Released and held d2: the residual bend of the recovering dashpot.
        sim.set_hold(Hold { direction: LoadDirection::Unload, dwell_s: d2 }).unwrap();
        let rest = sim.solve(0.0).unwrap();
        let q1 = m / (ei * (1.0 - f)) * (1.0 - e1);
        let e2 = (-(1.0 - f) * d2 / t_s).exp();
        assert!((rest.tip_angle_rad - f * e2 * q1 * a.length_mm).abs() < 1e-9, "{}", rest.tip_angle_rad);
        assert!(rest.tip_angle_rad > 0.01);
        // A long hold reaches the relaxed rigidity EI (1 − f).
        sim.reset_history();
        sim.set_hold(Hold { direction: LoadDirection::Load, dwell_s: 1e4 }).unwrap();
        let relaxed = sim.solve(tau).unwrap();
        assert!((relaxed.tip_angle_rad - m / (ei * (1.0 - f)) * a.length_mm).abs() < 1e-9);
        // Outside a protocol (sweeps, design) every tension is held
        // `creep_hold_s` on a fresh rod: the same as the first held step.
        let mut fresh = straight(
            |a| {
                a.effects.creep_fraction = f;
                a.effects.creep_time_s = t_s;
                a.effects.creep_hold_s = d1;
            },
            d,
        );
        for _ in 0..3 {
            let pose = ladder(&mut fresh, tau);
            assert!((pose.tip_angle_rad - u1 * a.length_mm).abs() < 1e-9);
        }
    }

    #[test]
    fn clamp_compliance_rotates_the_rod_rigidly() {
        let (k_theta, tau, d) = (40.0, 1.2, 2.5);
        let stiff = ladder(&mut straight(|_| {}, d), tau);
        let soft = ladder(&mut straight(|a| a.effects.clamp_stiffness_n_mm_per_rad = Some(k_theta), d), tau);
        let phi0 = tau * d / k_theta;
        let (s, c) = phi0.sin_cos();
        assert!((soft.tip_angle_rad - stiff.tip_angle_rad - phi0).abs() < 1e-9);
        assert!((soft.tip_x_mm - (c * stiff.tip_x_mm - s * stiff.tip_y_mm)).abs() < 1e-9);
        assert!((soft.tip_y_mm - (s * stiff.tip_x_mm + c * stiff.tip_y_mm)).abs() < 1e-9);
        // No moment at the clamp (y_c(0) = 0, no gravity): no rotation.
        let mut a = Rod::default();
        a.gravity.enabled = false;
        let route = [0.0, 2.0, 3.0, 1.0, 2.0];
        let mut rigid = Simulator::new(&a, &SolverOptions::default()).unwrap();
        rigid.set_routing_mm(&route).unwrap();
        a.effects.clamp_stiffness_n_mm_per_rad = Some(k_theta);
        let mut compliant = Simulator::new(&a, &SolverOptions::default()).unwrap();
        compliant.set_routing_mm(&route).unwrap();
        assert!((ladder(&mut rigid, tau).tip_y_mm - ladder(&mut compliant, tau).tip_y_mm).abs() < 1e-12);
    }

    #[test]
    fn stiffening_and_channel_offset_follow_their_laws() {
        // Straight routing: constant moment τ d, curvature solves EI (u + α r² u³) = τ d.
        let (alpha, tau, d) = (2.0, 2.0, 3.0);
        let a = Rod::default();
        let pose = ladder(&mut straight(|a| a.effects.stiffening_alpha = alpha, d), tau);
        let u = pose.tip_angle_rad / a.length_mm;
        let m = a.ei_n_mm2 * (u + alpha * a.radius_mm.powi(2) * u.powi(3));
        assert!((m - tau * d).abs() < 1e-6, "{m}");
        // Channel offset δ on y_i = d is the routing y_i = d + δ.
        let shifted = ladder(&mut straight(|a| a.effects.channel_offset_mm = 0.5, d), tau);
        let direct = ladder(&mut straight(|_| {}, d + 0.5), tau);
        assert!((shifted.tip_y_mm - direct.tip_y_mm).abs() < 1e-12);
    }

    #[test]
    fn a_rest_curvature_and_a_stiff_base_segment_follow_their_laws() {
        // Straight routing: u = τ d / EI_local + u*, so φ(L) = ∫ u ds.
        let (tau, d, u0) = (1.5, 3.0, 0.004);
        let a = Rod::default();
        let curved = ladder(&mut straight(|a| a.rest_curvature_per_mm = u0, d), tau);
        let want = tau * d * a.length_mm / a.ei_n_mm2 + u0 * a.length_mm;
        assert!((curved.tip_angle_rad - want).abs() < 1e-6, "{} vs {want}", curved.tip_angle_rad);
        // At rest the rod keeps its cured-in bend.
        let mut rest = straight(|a| a.rest_curvature_per_mm = u0, d);
        assert!((rest.solve(0.0).unwrap().tip_angle_rad - u0 * a.length_mm).abs() < 1e-9);
        // A stiff 5 mm at the clamp is a body segment of its own material.
        let glued = ladder(
            &mut straight(
                |a| {
                    a.segments = vec![
                        crate::model::Segment { end_mm: 5.0, ea_n: None, ga_n: None, ei_n_mm2: Some(5.0 * a.ei_n_mm2), density_g_cm3: None },
                        crate::model::Segment { end_mm: a.length_mm, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
                    ]
                },
                d,
            ),
            tau,
        );
        let want = tau * d / a.ei_n_mm2 * (a.length_mm - 5.0 + 5.0 / 5.0);
        assert!((glued.tip_angle_rad - want).abs() < 1e-9 * want, "{} vs {want}", glued.tip_angle_rad);
    }
}

#[cfg(test)]
mod body_tests {
    //! Non-uniform bodies (radius profile, segments, cable anchor) and the
    //! stiffness gradient against closed forms and equilibrium.
    use super::*;
    use crate::model::body::Segment;

    /// Gauss–Legendre 8-point nodes and weights on [−1, 1].
    const GL8: [(f64, f64); 8] = [
        (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
        (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
        (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
        (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
        (0.183_434_642_495_649_8, 0.362_683_783_378_362),
        (0.525_532_409_916_329, 0.313_706_645_877_887_3),
        (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
        (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    ];

    /// ∫_a^b f by composite 8-point Gauss–Legendre on `n` panels.
    fn quad(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
        let h = (b - a) / n as f64;
        (0..n)
            .map(|k| {
                let c = a + (k as f64 + 0.5) * h;
                GL8.iter().map(|&(x, w)| w * f(c + 0.5 * h * x)).sum::<f64>() * 0.5 * h
            })
            .sum()
    }

    /// The tip of a rod with curvature `kappa(s)` and stretch `v1(s)` (no
    /// shear), integrated piecewise between `cuts` (where the integrands kink).
    fn tip_by_quadrature(kappa: &dyn Fn(f64) -> f64, v1: &dyn Fn(f64) -> f64, cuts: &[f64]) -> (f64, f64, f64) {
        let phi = |s: f64| -> f64 {
            let mut total = 0.0;
            for w in cuts.windows(2) {
                if s <= w[0] {
                    break;
                }
                total += quad(kappa, w[0], s.min(w[1]), 4);
            }
            total
        };
        let (mut x, mut y) = (0.0, 0.0);
        for w in cuts.windows(2) {
            x += quad(|s| v1(s) * phi(s).cos(), w[0], w[1], 40);
            y += quad(|s| v1(s) * phi(s).sin(), w[0], w[1], 40);
        }
        (x, y, phi(cuts[cuts.len() - 1]))
    }

    fn tapered_thesis_rod() -> Rod {
        let mut a = Rod::default();
        a.radius_profile_mm = vec![(0.0, 6.0), (30.0, 5.0), (65.0, 4.0)];
        a
    }

    #[test]
    fn straight_routing_bends_as_tau_d_over_ei_of_s() {
        let (tau, d) = (1.5, 3.0);
        for beta in [0.0, -0.7] {
            let mut a = tapered_thesis_rod();
            a.gravity.enabled = false;
            a.effects.stiffness_gradient_beta = beta;
            a.segments = vec![
                Segment { end_mm: 20.0, ea_n: Some(40.0), ga_n: None, ei_n_mm2: Some(150.0), density_g_cm3: None },
                Segment { end_mm: 65.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
            ];
            let body = a.body().unwrap().unwrap();
            let ei = |s: f64| body.section_at(s).ei_n_mm2 * (beta * (s / a.length_mm - 0.5)).exp();
            let kappa = |s: f64| tau * d / ei(s);
            let v1 = |s: f64| 1.0 - tau / body.section_at(s).ea_n;
            let (x, y, phi) = tip_by_quadrature(&kappa, &v1, &[0.0, 20.0, 30.0, 65.0]);
            let options = SolverOptions { nodes_per_span: 24, ..SolverOptions::default() };
            let mut sim = Simulator::new(&a, &options).unwrap();
            sim.set_routing_mm(&[d; 5]).unwrap();
            let pose = sim.solve(tau).unwrap();
            let err = (pose.tip_x_mm - x).hypot(pose.tip_y_mm - y);
            eprintln!("angle {} vs {phi}; ell {}", pose.tip_angle_rad, pose.length_mm);
            for p in sim.centreline().iter().step_by(6) { eprintln!("{} {} {} {}", p.s_mm, p.u_per_mm[2], kappa(p.s_mm), p.v[0] - v1(p.s_mm)); }
            assert!(err < 1e-8, "β {beta}: tip ({}, {}) vs ({x}, {y}): {err:e} mm", pose.tip_x_mm, pose.tip_y_mm);
            assert!((pose.tip_angle_rad - phi).abs() < 1e-10);
            // The curvature along the centreline is τ d / EI(s).
            for p in sim.centreline().iter().step_by(7) {
                assert!((p.u_per_mm[2] - kappa(p.s_mm)).abs() < 1e-7 * kappa(p.s_mm), "s {}: {} vs {}", p.s_mm, p.u_per_mm[2], kappa(p.s_mm));
            }
        }
    }

    #[test]
    fn beyond_the_anchor_the_rod_stays_straight_without_gravity() {
        let (tau, d, anchor) = (1.2, 2.5, 45.0);
        let mut a = tapered_thesis_rod();
        a.gravity.enabled = false;
        a.cable_anchor_mm = Some(anchor);
        let mut sim = Simulator::new(&a, &SolverOptions::default()).unwrap();
        sim.set_routing_mm(&[d; 5]).unwrap();
        let pose = sim.solve(tau).unwrap();
        let line = sim.centreline();
        let at_anchor = line.iter().find(|p| p.s_mm > anchor).unwrap();
        let body = a.body().unwrap().unwrap();
        let phi_k = quad(|s| tau * d / body.section_at(s).ei_n_mm2, 0.0, 30.0, 8) + quad(|s| tau * d / body.section_at(s).ei_n_mm2, 30.0, anchor, 8);
        assert!((pose.tip_angle_rad - phi_k).abs() < 1e-9, "{} vs {phi_k}", pose.tip_angle_rad);
        for p in line.iter().filter(|p| p.s_mm > anchor) {
            assert!(p.u_per_mm[2].abs() < 1e-12 && p.cables[0].tension_n == 0.0, "{p:?}");
            assert!((p.tangent_angle_rad - pose.tip_angle_rad).abs() < 1e-12);
            // On one straight line.
            let (dx, dy) = (p.x_mm - at_anchor.x_mm, p.y_mm - at_anchor.y_mm);
            assert!((dx * phi_k.sin() - dy * phi_k.cos()).abs() < 1e-9, "{p:?}");
        }
        // A routing spans the cable only: its control points sit on [0, s_k].
        let r = Routing::for_actuator([d; 5], &a).unwrap();
        assert_eq!(r.length_mm(), anchor);
        assert!(Simulator::new(&a, &SolverOptions { method: SolverMethod::Rk4, ..SolverOptions::default() }).is_err());
    }

    #[test]
    fn a_tapered_rod_under_its_weight_balances_the_base_moment() {
        for (profile, direction) in [(vec![(0.0, 7.0), (65.0, 3.0)], 1.0), (vec![(0.0, 6.0), (30.0, 5.0), (65.0, 4.0)], 0.4)] {
            let mut a = Rod::default();
            a.radius_profile_mm = profile;
            a.gravity.direction_rad = direction;
            a.gravity.scale = 20.0;
            a.segments = vec![
                Segment { end_mm: 40.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: Some(1.5) },
                Segment { end_mm: 65.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
            ];
            let options = SolverOptions { steps_per_span: 2000, ..SolverOptions::default() };
            let mut sim = Simulator::new(&a, &options).unwrap();
            sim.set_routing_mm(&[0.0; 5]).unwrap();
            let pose = sim.solve(0.0).unwrap();
            let line = sim.centreline();
            let body = a.body().unwrap().unwrap();
            let g = a.gravity.scale * a.gravity.g_m_s2 * 1e-6 * std::f64::consts::PI;
            let w = |s: f64| g * body.density_at(s) * body.radius_at(s).powi(2);
            let (c, sn) = (direction.cos(), direction.sin());
            let (x0, y0) = (line[0].x_mm, line[0].y_mm);
            // Trapezoid over the centreline (fine: 4001 points).
            let mut moment = 0.0;
            for pair in line.windows(2) {
                let f = |p: &CentrelinePoint| w(p.s_mm) * ((p.y_mm - y0) * c - (p.x_mm - x0) * sn);
                moment -= 0.5 * (f(&pair[0]) + f(&pair[1])) * (pair[1].s_mm - pair[0].s_mm);
            }
            let base = body.section_at(0.0).ei_n_mm2 * line[0].u_per_mm[2];
            assert!(pose.tip_y_mm.abs() > 5.0, "the rod should bend: {pose:?}");
            assert!((base - moment).abs() < 1e-5 * moment.abs(), "base moment {base} vs ∫ w lever {moment}");
        }
    }

    #[test]
    fn a_uniform_profile_and_one_material_match_the_uniform_rod() {
        // The same spans: agreement to the fixed point's tolerance (the
        // weight is summed differently, so rounding takes another path; the
        // sweeps stop at 1e-9 rad, about 1e-7 mm at the tip); an extra
        // breakpoint at 20 mm changes the discretisation, well below its error.
        let mut flat = Rod::default();
        flat.radius_profile_mm = vec![(0.0, 5.0), (65.0, 5.0)];
        flat.segments = vec![Segment { end_mm: 65.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None }];
        flat.cable_anchor_mm = Some(65.0);
        let mut split = flat.clone();
        split.radius_profile_mm = vec![(0.0, 5.0), (20.0, 5.0), (65.0, 5.0)];
        let route = [1.0, -2.0, 4.0, 4.0, -4.0];
        let mut poses = Vec::new();
        for a in [Rod::default(), flat, split] {
            let mut sim = Simulator::new(&a, &SolverOptions::default()).unwrap();
            sim.set_routing_mm(&route).unwrap();
            poses.push((1..=8).map(|k| sim.solve(0.25 * k as f64).unwrap()).collect::<Vec<_>>());
        }
        for (k, tol) in [(1, 1e-6), (2, 1e-6)] {
            for (p, q) in poses[0].iter().zip(&poses[k]) {
                assert!((p.tip_x_mm - q.tip_x_mm).abs() < tol && (p.tip_y_mm - q.tip_y_mm).abs() < tol, "{p:?} {q:?}");
            }
        }
    }

    #[test]
    fn rk4_agrees_with_collocation_on_a_cone_with_gravity() {
        let mut a = Rod::default();
        a.radius_profile_mm = vec![(0.0, 6.5), (65.0, 4.0)];
        a.effects.stiffness_gradient_beta = -0.5;
        let rk4 = SolverOptions { method: SolverMethod::Rk4, steps_per_span: 192, ..SolverOptions::default() };
        let mut sims = [Simulator::new(&a, &SolverOptions::default()).unwrap(), Simulator::new(&a, &rk4).unwrap()];
        let mut poses = [Vec::new(), Vec::new()];
        for (sim, out) in sims.iter_mut().zip(&mut poses) {
            sim.set_routing_mm(&[1.0, -2.0, 3.5, 3.5, -3.5]).unwrap();
            for k in 1..=8 {
                out.push(sim.solve(0.25 * k as f64).unwrap());
            }
        }
        for (p, q) in poses[0].iter().zip(&poses[1]) {
            let tip = (p.tip_x_mm - q.tip_x_mm).hypot(p.tip_y_mm - q.tip_y_mm);
            assert!(tip < 2e-5 && (p.tip_angle_rad - q.tip_angle_rad).abs() < 1e-6, "{p:?} {q:?}");
        }
    }

    #[test]
    fn the_real_tentacle_solves_up_to_7_7_n() {
        // 360 mm, r 15.4 → 6.4 → 4.8 mm, tendon knotted at 305 mm, full gravity.
        let mut a = Rod { length_mm: 360.0, cable_anchor_mm: Some(305.0), ..Rod::default() };
        a.radius_profile_mm = vec![(0.0, 15.4), (305.0, 6.4), (360.0, 4.8)];
        let mut sim = Simulator::new(&a, &SolverOptions::default()).unwrap();
        sim.set_routing_mm(&[4.0; 5]).unwrap();
        let mut last = None;
        for k in 1..=31 {
            last = Some(sim.solve(7.7 * k as f64 / 31.0).unwrap());
        }
        let pose = last.unwrap();
        assert!(pose.tip_angle_rad > 3.0, "{pose:?}");
    }
}

#[cfg(test)]
mod anchor_edge_tests {
    use super::*;

    /// An anchor a hair above a profile point is merged with it: the span
    /// from there on carries no cable, as with the anchor exactly there.
    #[test]
    fn an_anchor_merged_into_a_breakpoint_ends_the_cable_there() {
        let mut poses = Vec::new();
        for anchor in [50.0, 50.0 + 1e-12] {
            let mut a = Rod::default();
            a.gravity.enabled = false;
            a.radius_profile_mm = vec![(0.0, 6.0), (50.0, 5.0), (65.0, 4.0)];
            a.cable_anchor_mm = Some(anchor);
            let mut sim = Simulator::new(&a, &SolverOptions::default()).unwrap();
            sim.set_routing_mm(&[2.0; 5]).unwrap();
            let pose = sim.solve(1.0).unwrap();
            assert!(sim.centreline().iter().filter(|p| p.s_mm > 50.5).all(|p| p.u_per_mm[2] == 0.0));
            poses.push(pose);
        }
        assert!((poses[0].tip_angle_rad - poses[1].tip_angle_rad).abs() < 1e-9, "{poses:?}");
    }
}



/// The planar solver of one cable as a [`actuation::TensionSolve`].
impl actuation::TensionSolve for Simulator {
    type Error = SolveFailure;
    fn solve_tensions(&mut self, tensions_n: &[f64]) -> Result<TipPose, SolveFailure> {
        self.solve(tensions_n[0])
    }
    fn not_met(e: actuation::DisplacementNotMet) -> SolveFailure {
        SolveFailure::DisplacementNotMet(e)
    }
}
